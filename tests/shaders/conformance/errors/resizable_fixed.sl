/* push() needs a resizable array: 'float a[];', not a fixed size */
displacement resizable_fixed()
{
    float a[4];
    push(a, s);
    P += a[0] * N;
}
