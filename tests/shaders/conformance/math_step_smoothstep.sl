/* step and smoothstep, with varying edges */
displacement math_step_smoothstep()
{
    P = point(step(0.5, s) + smoothstep(0.2, 0.8, t), smoothstep(0, 1, s * t),
              step(t, s) * 2);
}
