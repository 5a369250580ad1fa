/* RSL 2 co-shaders are not supported (each shader compiles on its own):
 * said once, at the first construct (the method call below is not) */
displacement coshader(string layer = "base")
{
    shader base = getshader(layer);
    P += base->height(s) * N;
}
