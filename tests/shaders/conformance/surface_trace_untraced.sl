/* trace() and shadow() in a surface shader, run where the renderer gives
 * no ray tracer (the suite's VM): trace() is black and shadow() 0, in
 * every mode (test_trace_rays checks them with the renderer's tracer) */
surface surface_trace_untraced(float Kr = 1)
{
    normal Nf = faceforward(normalize(N), I);
    color mirror = Kr * trace(P, reflect(normalize(I), Nf));
    float lit = 1 - shadow("nomap", P, "samples", 16);
    color C = 0;
    illuminance(P, Nf, PI / 2)
        C += Cl * (1 - shadow("nomap", P)) * normalize(L) . Nf;
    Ci = mirror + lit * 0.8 * C;
    Oi = color(lit, 1 - lit, comp(mirror, 1));
}
