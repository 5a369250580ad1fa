/* nested functions: a helper in the shader body updates a local of the
 * body and reads a shader parameter, both declared extern */
displacement nested_extern_accumulate(float Km = 0.5)
{
    float total = 0;
    void add(float x)
    {
        extern float total, Km;
        total += Km * x;
    }
    add(s);
    add(t * t);
    add(1);
    P = point(total, 0, 0);
}
