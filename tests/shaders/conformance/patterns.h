/*
 * patterns.h: filtered pattern helpers in the style of the widely copied
 * RenderMan headers (written for aafarm's conformance suite): nested helper
 * functions, parameters named like the predefined variables, overloads.
 */
#ifndef CONF_PATTERNS_H
#define CONF_PATTERNS_H

/* |x| box-filtered over [x - dx/2, x + dx/2]: the integral of |t| is a
 * nested helper, as in the classic header */
float filteredabs(float x, dx)
{
    float integral(float t) { return sign(t) * 0.5 * t * t; }
    float x0 = x - 0.5 * dx;
    float x1 = x0 + dx;
    return (integral(x1) - integral(x0)) / dx;
}

/* 1 on [edge0, edge1), 0 elsewhere; box-filtered over width dx */
float pulse(float edge0, edge1, x) { return step(edge0, x) - step(edge1, x); }

float filteredpulse(float edge0, edge1, x, dx)
{
    float x0 = x - dx / 2;
    float x1 = x0 + dx;
    return max(0, (min(x1, edge1) - max(x0, edge0)) / dx);
}

/* the pulse of a colour: overloaded on the value's type */
color pulse(color a; float edge0, edge1, x) { return a * pulse(edge0, edge1, x); }

float smoothpulse(float e0, e1, e2, e3, x)
{
    return smoothstep(e0, e1, x) - smoothstep(e2, e3, x);
}

/* a tile coordinate: parameters named s and t, like the globals */
float tilecoord(float s, t; float freq)
{
    float ss = mod(s * freq, 1), tt = mod(t * freq, 1);
    return ss * tt;
}

#endif
