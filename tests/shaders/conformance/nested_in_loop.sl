/* nested functions: defined in a loop body, reading the loop counter */
displacement nested_in_loop()
{
    float i, acc = 0;
    for (i = 1; i <= 3; i += 1) {
        float term(float x) { extern float i; return pow(x, i) / i; }
        acc += term(s);
    }
    P = point(acc, 0, 0);
}
