/* light shaders: the standard distantlight, solar along the direction from
 * "from" to "to" */
light light_distant(float intensity = 1; color lightcolor = 1;
                    point from = point "shader" (0, 0, 0);
                    point to = point "shader" (0, 0, 1))
{
    solar(to - from, 0)
        Cl = intensity * lightcolor;
}
