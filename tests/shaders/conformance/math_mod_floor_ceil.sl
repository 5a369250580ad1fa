/* mod (RenderMan's: the sign of the divisor), floor, ceil */
displacement math_mod_floor_ceil()
{
    P = point(mod(s * 7, 2) + floor(t * 5), ceil(s * 3) - mod(-t * 3, 1),
              mod(s * 10, 0.3) * 2);
}
