/* ctransform takes the color spaces of the specification only */
displacement color_space()
{
    color c = ctransform("cmyk", Cs);
    P += comp(c, 0) * N;
}
