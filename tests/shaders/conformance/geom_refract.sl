/* refract: into glass (eta 1/1.5) and out of it (eta 1.5), where steep
 * rays are totally reflected and refract gives (0, 0, 0) */
displacement geom_refract()
{
    vector I1 = normalize(vector (s - 0.5, t - 0.5, -1));
    vector I2 = normalize(vector (3 * s - 1.5, 0.5, -1));
    normal Nn = normal (0, 0, 1);
    vector Tin = refract(I1, Nn, 1 / 1.5);
    vector Tout = refract(I2, Nn, 1.5);
    P = point(xcomp(Tin) + zcomp(Tin), ycomp(Tin), xcomp(Tout) + zcomp(Tout));
}
