/* RSL 2 resizable arrays of colours: push under a condition (in range
 * modes the length may be undecided: every element it can reach is
 * merged) */
displacement resizable_colors()
{
    color c[];
    push(c, color(s, t, 1));
    if (s > 0.5)
        push(c, color(1, 0, t));
    push(c, color(0.5));
    color top = pop(c);
    P = point(comp(c[0], 0) + comp(top, 1), arraylength(c), comp(c[arraylength(c) - 1], 2));
}
