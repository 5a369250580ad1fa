/* RSL 2 co-shaders are not supported (each shader compiles on its own) */
displacement coshader(string layer = "base")
{
    shader base = getshader(layer);
    P += base->height(s) * N;
}
