/* light shaders: the standard ambientlight */
light light_ambient(float intensity = 1; color lightcolor = 1)
{
    Cl = intensity * lightcolor;
}
