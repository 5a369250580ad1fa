/* never ends: the instruction budget stops it in every mode */
displacement spin() {
    float i = 0;
    while (1) { i += 1; }
    P += i * N;
}
