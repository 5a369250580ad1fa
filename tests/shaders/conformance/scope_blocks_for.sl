/* scopes: one name in nested blocks and in a for loop's declaration */
displacement scope_blocks_for()
{
    float x = 1, i;
    for (i = 0; i < 3; i += 1) {
        float x = i * s;
        {
            float x = 100;
        }
        P += point(x, 0, 0);
    }
    float acc = 0;
    for (float u = 0; u < 2; u += 1)
        acc += u;
    P = point(xcomp(P), x, acc + u);
}
