/* RSL 2 resizable arrays reached from a nested function through extern,
 * pushed there under a condition */
displacement resizable_nested_extern()
{
    float stack[];
    void keep(float x) {
        extern float stack[];
        if (x > 0.3)
            push(stack, x);
    }
    keep(s);
    keep(t);
    keep(0.5);
    float n = arraylength(stack);
    P = point(n, pop(stack), stack[0]);
}
