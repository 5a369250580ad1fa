/*
 * wood.sl: wood grain: concentric rings around the shader-space x axis
 * (the trunk), their radius perturbed by vector noise so they wander, and
 * each ring shading from light early wood to dark late wood; a fine grain
 * of noise darkens it further. Lit like plastic with a weak highlight.
 * (The UFO of Heidrich & Seidel 1998, Figure 7, wears a wood shader.)
 */
surface wood(
    float Ka = 1, Kd = 0.75, Ks = 0.15, roughness = 0.2;
    float ringscale = 10;          /* rings per unit of radius */
    float swirl = 0.3;             /* how far noise moves the rings */
    float grain = 0.2;             /* strength of the fine grain */
    color lightwood = color (0.69, 0.44, 0.25);
    color darkwood = color (0.35, 0.22, 0.08))
{
    point PP = transform("shader", P);
    PP += swirl * (vector noise(PP * 2) - 0.5);
    float y = ycomp(PP), z = zcomp(PP);
    float r = sqrt(y * y + z * z) * ringscale;
    float ring = mod(r, 1);
    float late = smoothstep(0.6, 0.85, ring) * (1 - smoothstep(0.9, 1, ring));
    float fine = grain * noise(PP * 40);
    color Ct = mix(lightwood, darkwood, late) * (1 - fine);

    normal Nf = faceforward(normalize(N), I);
    vector V = -normalize(I);
    Oi = Os;
    Ci = Os * (Ct * (Ka * ambient() + Kd * diffuse(Nf)) + Ks * specular(Nf, V, roughness));
}
