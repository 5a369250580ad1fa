/* getshaders(): the list of co-shaders is not supported */
displacement coshader_getshaders()
{
    float n = arraylength(getshaders());
    P += n * N;
}
