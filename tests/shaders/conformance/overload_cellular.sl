/* a cellular helper in two overloads, as noise libraries write it: the
 * point-returning overload calls the void one with its output parameters,
 * whichever is defined first; at file level and nested in the shader */
void cellnearest(point p; output float f1; output point c1)
{
    c1 = point(floor(xcomp(p)) + 0.5, floor(ycomp(p)) + 0.5, 0);
    f1 = distance(p, c1);
}

point cellnearest(point p)
{
    float f1;
    point c1;
    cellnearest(p, f1, c1);
    return c1;
}

displacement overload_cellular(float freq = 3)
{
    /* nested: the point overload first, the void one after it */
    float cellrow(point p)
    {
        float f1;
        point c1;
        cellrow(p, f1, c1);
        return ycomp(c1) + f1;
    }
    void cellrow(point p; output float f1; output point c1)
    {
        c1 = cellnearest(p * 2);
        f1 = 0.5 * distance(p * 2, c1);
    }
    float d;
    point c;
    cellnearest(point(s * freq, t * freq, 0), d, c);
    point c2 = cellnearest(point(t * freq, s * freq, 0));
    P = point(d, xcomp(c) + ycomp(c2), cellrow(point(s, t, 0)));
}
