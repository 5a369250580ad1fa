/* arrays: a function fills an output array parameter */
void fill(output float a[4]; float x)
{
    float i;
    for (i = 0; i < 4; i += 1)
        a[i] = pow(x, i);
}

displacement array_output_fill()
{
    float p[4];
    fill(p, s + 0.5);
    P = point(p[1] + p[2], p[3], p[t * 4]);
}
