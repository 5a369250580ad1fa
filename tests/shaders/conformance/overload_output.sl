/* overloading on output parameters: the variable's type picks */
void unit(output float x) { x = 1; }
void unit(output color c) { c = color(0.5, 0.25, 0.125); }
void unit(output point p) { p = point(0, 0, 1); }

displacement overload_output()
{
    float f = s;
    color c;
    point q;
    unit(f);
    unit(c);
    unit(q);
    P = point(f + s, comp(c, 2), zcomp(q) + t);
}
