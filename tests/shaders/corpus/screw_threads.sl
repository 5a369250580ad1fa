/*
 * screw_threads.sl: a screw thread: a helical triangle wave in t advancing
 * with s (mod of a sum), damped near both ends with smoothstep.
 * Idiom: threads (mod-based helix), smoothstep damping.
 */
displacement screw_threads(float Km = 0.03, frequency = 8, dampzone = 0.1)
{
    float x = mod(t * frequency + s, 1);
    float tri = 1 - 2 * abs(x - 0.5);
    float damp = smoothstep(0, dampzone, t) * (1 - smoothstep(1 - dampzone, 1, t));
    P += Km * tri * damp * normalize(N);
    N = calculatenormal(P);
}
