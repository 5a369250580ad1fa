/*
 * dents_shader.sl: hammered metal: octaves of |snoise| cubed, pushed in,
 * in shader space (the classic "dented" shape with a power).
 * Idiom: dents, pow of a noise sum, shader space.
 */
#include "include/noises.h"

displacement dents_shader(float Km = 0.03, frequency = 2, power = 3, octaves = 5)
{
    point Psh = transform("shader", P) * frequency;
    float sum = 0, size = 1, i;
    for (i = 0; i < octaves; i += 1) {
        sum += abs(0.5 - noise(Psh * size)) / size;
        size *= 2;
    }
    P -= Km * pow(sum, power) * normalize(N);
    N = calculatenormal(P);
}
