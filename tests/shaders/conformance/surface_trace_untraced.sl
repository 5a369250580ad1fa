/* trace() and shadow() in a surface shader, run where the renderer gives
 * no ray tracer (the suite's VM): trace() is black and shadow() 0, in
 * every mode (test_trace_rays checks them with the renderer's tracer).
 * shadow()'s map parameters, as shaders written for shadow maps pass
 * them: accepted, one warning per name (the suite's expected warnings) */
surface surface_trace_untraced(float Kr = 1)
{
    normal Nf = faceforward(normalize(N), I);
    color mirror = Kr * trace(P, reflect(normalize(I), Nf));
    float lit = 1 - shadow("nomap", P, "samples", 16, "blur", 0.01, "bias", 0.05,
                           "filter", "gaussian", "width", 2);
    color C = 0;
    illuminance(P, Nf, PI / 2)
        C += Cl * (1 - shadow("nomap", P, "samples", 4)) * normalize(L) . Nf;
    Ci = mirror + lit * 0.8 * C;
    Oi = color(lit, 1 - lit, comp(mirror, 1));
}
