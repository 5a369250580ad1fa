/*
 * noises.h: noise sums of the corpus shaders (issue 9): signed noise,
 * fBm and turbulence whose octave count follows the filter width (the loop
 * stops when an octave is finer than the footprint), a fixed-octave fBm,
 * Musgrave's ridged multifractal, written for aafarm in the style of the
 * public shader headers.
 */
#ifndef CORPUS_NOISES_H
#define CORPUS_NOISES_H

#include "filterwidth.h"

#define snoise(p)    (2 * (noise(p)) - 1)
#define vsnoise(p)   (2 * (vector noise(p)) - 1)

/* noise faded to its mean (0) as its features (size 1) shrink below fw */
float filteredsnoise(point p; float fw)
{
    return snoise(p) * (1 - smoothstep(0.2, 0.75, fw));
}

/* fBm: octaves until the next one is finer than the filter width */
float fBm(point p; float fw; float maxoctaves; float lacunarity; float gain)
{
    float sum = 0, amp = 1, i;
    float w = fw;
    point pp = p;
    for (i = 0; i < maxoctaves && w < 1; i += 1) {
        sum += amp * filteredsnoise(pp, w);
        amp *= gain;
        pp *= lacunarity;
        w *= lacunarity;
    }
    return sum;
}

/* turbulence: the same sum of |snoise| */
float turbulence(point p; float fw; float maxoctaves; float lacunarity; float gain)
{
    float sum = 0, amp = 1, i;
    float w = fw;
    point pp = p;
    for (i = 0; i < maxoctaves && w < 1; i += 1) {
        sum += amp * abs(filteredsnoise(pp, w));
        amp *= gain;
        pp *= lacunarity;
        w *= lacunarity;
    }
    return sum;
}

/* fBm with a fixed octave count */
float fBm_fixed(point p; float octaves; float lacunarity; float gain)
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

/* ridged multifractal (Musgrave): each octave is weighted by the previous
 * signal, so ridges get sharper detail than valleys */
float ridgedmf(point p; float octaves; float lacunarity; float H; float offset; float gain)
{
    float signal = offset - abs(snoise(p));
    signal *= signal;
    float result = signal, weight = 1, freqexp = 1, i;
    point pp = p;
    for (i = 1; i < octaves; i += 1) {
        pp *= lacunarity;
        freqexp *= pow(lacunarity, -H);
        weight = clamp(signal * gain, 0, 1);
        signal = offset - abs(snoise(pp));
        signal *= signal * weight;
        result += signal * freqexp;
    }
    return result;
}

#endif
