/* random(): a fresh sequence every run from the VM's seed, in float and
 * colour form (over a range: [0, 1]) */
displacement random_sequence()
{
    float a = random();
    color c = random();
    float b = random();
    P = point(a + s, comp(c, 0) + comp(c, 2), b * t);
}
