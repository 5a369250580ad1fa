/* overloading on array parameters: float[] and color[] */
float total(float a[])
{
    float i, t = 0;
    for (i = 0; i < arraylength(a); i += 1)
        t += a[i];
    return t;
}

float total(color a[])
{
    float i, t = 0;
    for (i = 0; i < arraylength(a); i += 1)
        t += comp(a[i], 1);
    return t;
}

displacement overload_arrays()
{
    float f[3] = {s, t, 1};
    color c[2] = {(0, s, 0), (0, t * 2, 0)};
    P = point(total(f), total(c), 0);
}
