/*
 * tex_seams.sl: a colour map tiled three times, its lookups crossing the
 * periodic seam s = 0 / 1 and a black edge in t, the channel picked by an
 * index past which "fill" answers; mixed with noise of the position, and a
 * map lookup that steers a branch.
 * Idiom: color texture("map"[channel], ...), wrap modes, noise mixtures.
 */
displacement tex_seams(float Km = 0.03; string colors = "corpus_rgb.exr")
{
    float ss = s * 3 - 1, tt = t * 1.2 - 0.1;
    color c = texture(colors[1], ss, tt, "twrap", "black", "fill", 0.5);
    float n = noise(transform("object", P) * 4);
    float h = comp(c, 0) - comp(c, 2) + 0.5 * (n - 0.5);
    if (texture(colors, ss + 0.2 * n, tt, "blur", 0.01) > 0.5)
        h += 0.5 * comp(c, 1);
    P += Km * h * normalize(N);
}
