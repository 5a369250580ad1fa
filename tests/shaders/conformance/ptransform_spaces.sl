/* ptransform, the older name of transform for points, with named spaces
 * and a matrix; vtransform beside it */
displacement ptransform_spaces()
{
    point Pobj = ptransform("object", P);
    point back = ptransform("object", "current", Pobj);
    point m = ptransform(matrix "object" 1, point (s, t, 0));
    P = point(xcomp(Pobj), ycomp(back) + xcomp(m), zcomp(m) + ycomp(vtransform("object", vector (0, t, 0))));
}
