/* RSL 2 resizable arrays: push, pop, arraylength */
displacement resizable_push_pop()
{
    float a[];
    push(a, s);
    push(a, t);
    push(a, s * t);
    float last = pop(a);
    push(a, 10);
    P = point(a[0] + a[1], last + a[2], arraylength(a));
}
