/* filterstep: the books' antialiased pulse and pulse train built from two
 * filtered steps, over explicit intervals */
float fpulse(float a, b, x, w)
{
    return filterstep(a, x - w / 2, x + w / 2) - filterstep(b, x - w / 2, x + w / 2);
}

displacement filterstep_pulse(float width = 0.08)
{
    float x = mod(s * 4, 1);
    P = point(fpulse(0.3, 0.7, x, width), fpulse(0.2, 0.4, t, width * 2),
              filterstep(0.5, s) - filterstep(0.8, s));
}
