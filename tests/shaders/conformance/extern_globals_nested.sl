/* nested functions: extern of the predefined P and N and of a parameter */
displacement extern_globals_nested(float Km = 0.1)
{
    void push(float amount)
    {
        extern point P;
        extern normal N;
        extern float Km;
        P += Km * amount * normalize(N);
    }
    push(s);
    push(2 * t);
}
