/*
 * du_smoothstep.sl: a step in s softened by a width of a few du (the
 * global du: the u spacing of the shading grid).
 * Idiom: `float fw = 4 * du` then smoothstep(edge - fw, edge + fw, s)
 * (issue 9, finding 1).
 */
displacement du_smoothstep(float Km = 0.03, edge0 = 0.5)
{
    float fw = 4 * du;
    float h = smoothstep(edge0 - fw, edge0 + fw, s);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}
