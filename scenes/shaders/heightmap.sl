/*
 * heightmap.sl: displacement by a height map (issue 16), in the style of
 * the texture displacement shaders that ship with RenderMan renderers: the
 * map's value, re-centred on `offset`, times Km along the normal; the
 * lookup blurred by the filter width of the texture coordinates so that
 * a far-away terrain reads the map's coarser levels; an optional detail
 * layer of the same map tiled `detailrepeat` times. The normal follows the
 * displaced surface (calculatenormal).
 */
displacement heightmap(float Km = 0.1, offset = 0, repeat = 1, detail = 0,
                       detailrepeat = 8, blur = 1;
                       string mapname = "")
{
    if (mapname != "") {
        float ss = s * repeat, tt = t * repeat;
        float fw = max(abs(Du(ss) * du) + abs(Dv(ss) * dv),
                       abs(Du(tt) * du) + abs(Dv(tt) * dv));
        float h = texture(mapname[0], ss, tt, "blur", blur * fw) - offset;
        if (detail != 0)
            h += detail * texture(mapname[0], ss * detailrepeat, tt * detailrepeat,
                                  "blur", blur * fw * detailrepeat);
        P += Km * h * normalize(N);
        N = calculatenormal(P);
    }
}
