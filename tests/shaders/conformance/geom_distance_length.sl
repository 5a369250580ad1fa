/* distance, length and normalize: the spot-centred idioms of the books */
displacement geom_distance_length(point centre = point(0.5, 0.25, 0))
{
    float d = distance(point(s, t, 0), centre);
    vector w = vector(s - 0.5, t - 0.25, 1);
    P = point(d, length(w) + distance(point(s, t, 0), point(1, 1, 0)),
              zcomp(normalize(w)));
}
