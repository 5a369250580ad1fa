/* nested functions: output parameters and an extern shader parameter */
displacement nested_output_param(float scale = 3)
{
    void split(float x; output float whole, frac)
    {
        extern float scale;
        whole = floor(x * scale);
        frac = x * scale - whole;
    }
    float w, f;
    split(s, w, f);
    P = point(w, f, 0);
}
