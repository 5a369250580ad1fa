/*
 * filterwidth.h: the antialiasing vocabulary of production displacement
 * shaders, written for the aafarm corpus (issue 9): the filter width of a
 * quantity from its screen derivatives, box-filtered steps and pulses, and
 * the unfiltered pulse/boxstep macros they replace when the width is tiny.
 *
 * Idioms: `filterwidth(x)` as |Du(x) du| + |Dv(x) dv| clamped below, the
 * point version from area(P), box filters written as the integral of the
 * step over [x - w/2, x + w/2] divided by w.
 */
#ifndef CORPUS_FILTERWIDTH_H
#define CORPUS_FILTERWIDTH_H

#define MINFILTWIDTH 1.0e-6

/* footprint of a float / of a point on the surface */
#define filterwidth(x)   max(abs(Du(x) * du) + abs(Dv(x) * dv), MINFILTWIDTH)
#define filterwidthp(p)  max(sqrt(area(p)), MINFILTWIDTH)

/* unfiltered shapes */
#define pulse(a, b, x)        (step((a), (x)) - step((b), (x)))
#define boxstep(a, b, x)      clamp(((x) - (a)) / ((b) - (a)), 0, 1)
#define smoothpulse(e0, e1, e2, e3, x) \
    (smoothstep((e0), (e1), (x)) - smoothstep((e2), (e3), (x)))
#define repeatpulse(a, b, period, x)  pulse((a), (b), mod((x), (period)))

/* step(edge, x) averaged over a box of width w centred on x */
float filterstep(float edge; float x; float w)
{
    return clamp((x + 0.5 * w - edge) / w, 0, 1);
}

/* pulse(edge0, edge1, x) averaged over a box of width w centred on x */
float filteredpulse(float edge0; float edge1; float x; float w)
{
    float lo = x - 0.5 * w;
    float hi = lo + w;
    return max(0, (min(hi, edge1) - max(lo, edge0)) / w);
}

/* the integral of a periodic pulse (duty d in [0,1), period 1) from 0 to x */
float pulsetrain_integral(float d; float x)
{
    return d * floor(x) + min(d, x - floor(x));
}

/* a periodic pulse of duty d, box filtered over width w */
float filteredpulsetrain(float d; float x; float w)
{
    float x0 = x - 0.5 * w;
    return (pulsetrain_integral(d, x0 + w) - pulsetrain_integral(d, x0)) / w;
}

/* fade a pattern to its average where its features get smaller than the
 * filter */
#define fadeout(g, gavg, featuresize, fw) \
    mix((g), (gavg), smoothstep(0.2, 0.6, (fw) / (featuresize)))

#endif
