/*
 * threads.sl: screw threads: a sinusoid in t (advancing with s, so it winds
 * around a cylinder as a helix), damped smoothly to nothing near both ends
 * (t = 0 and t = 1) so that the threads run out instead of being cut.
 *
 * Meant for a cylinder or the square [-1,1]^2, Km around 0.1.
 */
displacement threads(
    float Km = 0.1;
    float frequency = 5;     /* turns over t in [0, 1] */
    float phase = 0;
    float offset = 0;        /* added to the sinusoid before damping */
    float dampzone = 0.1)    /* length of the run-out at each end, in t */
{
    float wave = 0.5 * (1 + sin(2 * PI * (frequency * t + s) + phase));
    float damp = smoothstep(0, dampzone, t) * (1 - smoothstep(1 - dampzone, 1, t));
    P += Km * (wave + offset) * damp * normalize(N);
    N = calculatenormal(P);
}
