/* the camera's projective spaces, as shaders that lay patterns out on the
 * image write them: raster and NDC coordinates of a point in front of the
 * camera, a point given in NDC, and a round trip through "screen" */
displacement space_ndc_raster()
{
    point Pc = P + vector(0, 0, 3 + s);        /* in front of the camera */
    point r = transform("raster", Pc);
    point ndc = transform("current", "NDC", Pc);
    float sz = zcomp(transform("screen", Pc));
    point centre = point "NDC" (0.5, 0.5, sz);  /* on the axis, at Pc's depth */
    point back = transform("screen", "current", transform("screen", Pc));
    P = point(xcomp(r) / 100 + ycomp(ndc), ycomp(r) / 100 - xcomp(ndc),
              zcomp(centre) * sz + (zcomp(back) - zcomp(Pc)) + xcomp(centre));
}
