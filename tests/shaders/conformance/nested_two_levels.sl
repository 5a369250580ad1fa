/* nested functions: the innermost of three levels reads the outermost's
 * local through extern in each level */
float outer(float a)
{
    float b = a * 2;
    float mid(float c)
    {
        extern float b;
        float inner(float d) { extern float b; return b * d; }
        return inner(c) + 1;
    }
    return mid(a + 1);
}

displacement nested_two_levels()
{
    P = point(outer(s), outer(t), 0);
}
