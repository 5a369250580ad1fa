/* shadow() takes the shadow map parameters by name: a misspelt one is an
 * error */
light shadow_param(string map = "spot.shd")
{
    illuminate(point "shader" (0, 0, 0))
        Cl = 1 - shadow(map, Ps, "bluur", 0.1);
}
