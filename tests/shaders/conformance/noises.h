/*
 * noises.h: signed noise and fractal sums in the style of the widely copied
 * RenderMan headers (written for aafarm's conformance suite): overloads by
 * argument type, a loop per octave, a nested helper.
 */
#ifndef CONF_NOISES_H
#define CONF_NOISES_H

float snoise(float x) { return 2 * noise(x) - 1; }
float snoise(point p) { return 2 * noise(p) - 1; }
vector vsnoise(point p) { return 2 * vector noise(p) - 1; }

/* fractional Brownian motion, over a point and over a float */
float fBm(point p; float octaves, lacunarity, gain)
{
    float sum = 0, amp = 1, i;
    point pp = p;
    for (i = 0; i < octaves; i += 1) {
        sum += amp * snoise(pp);
        amp *= gain;
        pp *= lacunarity;
    }
    return sum;
}

float fBm(float x; float octaves, lacunarity, gain)
{
    float sum = 0, amp = 1, i, xx = x;
    for (i = 0; i < octaves; i += 1) {
        sum += amp * snoise(xx);
        amp *= gain;
        xx *= lacunarity;
    }
    return sum;
}

float turbulence(point p; float octaves)
{
    float octave(point q; float f) { return abs(snoise(q * f)) / f; }
    float sum = 0, f = 1, i;
    for (i = 0; i < octaves; i += 1) {
        sum += octave(p, f);
        f *= 2;
    }
    return sum;
}

#endif
