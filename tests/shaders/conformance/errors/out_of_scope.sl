/* must stay an error: a nested function called outside its block */
displacement out_of_scope()
{
    {
        float twice(float x) { return 2 * x; }
    }
    P += twice(s) * N;
}
