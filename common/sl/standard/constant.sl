/*
 * constant.sl: the RI Specification's standard constant surface, built into
 * aafarm (docs/shading-language.md, "Standard shaders"): the surface colour,
 * unlit, times its opacity.
 */
surface constant()
{
    Oi = Os;
    Ci = Os * Cs;
}
