/*
 * tex_filtered.sl: the four-corner form of texture(): the lookup filters
 * the quadrilateral that the shading footprint covers in (s, t), from
 * Du(s) du and Dv(t) dv, times "width"; the map is clamped at its edges.
 * Idiom: texture(name, s1, t1, s2, t2, s3, t3, s4, t4, "width", w).
 */
displacement tex_filtered(float Km = 0.05, width = 1;
                          string mapname = "corpus_height.exr")
{
    float ds = Du(s) * du, dt = Dv(t) * dv;
    float ss = s * 1.5 - 0.25, tt = t * 1.5 - 0.25;
    float h = texture(mapname, ss, tt, ss + ds, tt, ss, tt + dt, ss + ds, tt + dt,
                      "width", width, "swrap", "clamp", "twrap", "clamp");
    P += Km * h * normalize(N);
}
