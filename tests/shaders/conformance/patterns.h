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

/* a pulse train of the given period, 0 on [0, edge) and 1 on [edge,
 * period) of each period, box-filtered over width dx: its integral from 0
 * is a nested helper that reads the enclosing normalized edge through
 * extern */
float filteredpulsetrain(float edge, period, x, dx)
{
    float w = dx / period;
    float x0 = x / period - w / 2;
    float x1 = x0 + w;
    float nedge = edge / period;
    float integral(float t)
    {
        extern float nedge;
        return (1 - nedge) * floor(t) + max(0, t - floor(t) - nedge);
    }
    return (integral(x1) - integral(x0)) / w;
}

/* a tile coordinate: parameters named s and t, like the globals */
float tilecoord(float s, t; float freq)
{
    float ss = mod(s * freq, 1), tt = mod(t * freq, 1);
    return ss * tt;
}

#endif
