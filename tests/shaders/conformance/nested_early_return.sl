/* nested functions: an early return from a loop, after updating an
 * enclosing variable through extern */
displacement nested_early_return()
{
    float count = 0;
    float firstcell(float x)
    {
        extern float count;
        float i;
        for (i = 0; i < 8; i += 1) {
            count += 1;
            if (x < (i + 1) * 0.125)
                return i;
        }
        return -1;
    }
    float c = firstcell(s);
    P = point(c, count, firstcell(t));
}
