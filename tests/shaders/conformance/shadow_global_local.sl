/* scopes: a local named s hides the global s inside its block only */
displacement shadow_global_local()
{
    float a = s;
    {
        float s = t * 3;
        a += s * s;
    }
    P = point(a, s, 0);
}
