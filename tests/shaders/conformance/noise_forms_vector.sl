/* noise family: vector results of noise() in every argument form (a
 * float, two floats, a point, a point and a float) */
displacement noise_forms_vector()
{
    vector a = vector noise(s * 5);
    vector b = vector noise(s * 3, t * 3);
    vector c = vector noise(point(s, t, 0.5) * 2);
    vector d = vector noise(point(s, t, 0.5) * 2, t * 2);
    P = point(xcomp(a) + ycomp(b), zcomp(c) + xcomp(d), ycomp(a) - zcomp(d));
}
