/*
 * filterwidth.h: filter widths in the style of the widely copied RenderMan
 * header (written for aafarm's conformance suite), as overloaded functions
 * for a float and for a point rather than two macros.
 */
#ifndef CONF_FILTERWIDTH_H
#define CONF_FILTERWIDTH_H

#define MINFILTWIDTH 1.0e-6

float filterwidth(float x)
{
    return max(abs(Du(x) * du) + abs(Dv(x) * dv), MINFILTWIDTH);
}

float filterwidth(point p) { return max(sqrt(area(p)), MINFILTWIDTH); }

#endif
