/* printf writes to the worker's log in float mode only, at most 100 lines
 * per VM and then one note (the suite runs it 150 times and counts) */
displacement printf_rate_limit()
{
    printf("printf_rate_limit: s = %.3f, t = %.3f\n", s, t);
    P = point(s, t, 1);
}
