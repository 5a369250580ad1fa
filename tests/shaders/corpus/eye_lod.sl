/*
 * eye_lod.sl: level of detail by distance to the eye E: the noise octaves
 * fade out with length(P - E).
 * Idiom: the global E (camera position, "current" space).
 */
displacement eye_lod(float Km = 0.03, frequency = 4, fadestart = 3, fadeend = 12)
{
    float d = length(P - E);
    float fade = 1 - smoothstep(fadestart, fadeend, d);
    point pp = transform("shader", P) * frequency;
    float h = (noise(pp) - 0.5) + fade * 0.5 * (noise(pp * 2) - 0.5);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}
