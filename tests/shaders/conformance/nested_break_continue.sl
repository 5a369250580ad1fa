/* nested functions: break and continue inside a nested function's loop */
displacement nested_break_continue()
{
    float sumodd(float n)
    {
        float i, acc = 0;
        for (i = 0; i < 100; i += 1) {
            if (i >= n)
                break;
            if (mod(i, 2) == 0)
                continue;
            acc += i;
        }
        return acc;
    }
    P = point(sumodd(floor(s * 10)), sumodd(7), 0);
}
