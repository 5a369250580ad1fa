/* arrays: elements written in a loop under a condition on s, read back by
 * an index that varies with t */
displacement array_store_loop()
{
    color ramp[4];
    float i;
    for (i = 0; i < 4; i += 1) {
        if (s > 0.25 * i)
            ramp[i] = color(i, i * i, 1);
        else
            ramp[i] = color(-1);
    }
    color c = ramp[t * 4];
    P = point(comp(c, 0), comp(c, 1), comp(c, 2));
}
