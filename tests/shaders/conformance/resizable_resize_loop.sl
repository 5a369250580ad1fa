/* RSL 2 resizable arrays: resize, reserve, filled in a loop and passed to
 * a function taking an unsized array (its length follows the array) */
float total(float a[]) {
    float i, sum = 0;
    for (i = 0; i < arraylength(a); i += 1)
        sum += a[i];
    return sum;
}

displacement resizable_resize_loop(float n = 5)
{
    float a[];
    reserve(a, 16);
    resize(a, n);
    float i;
    for (i = 0; i < arraylength(a); i += 1)
        a[i] = pow(s, i);
    float before = total(a);
    resize(a, 2);
    P = point(before, total(a) + t, arraylength(a));
}
