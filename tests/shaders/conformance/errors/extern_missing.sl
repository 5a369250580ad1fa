/* must stay an error: extern of a variable no enclosing scope has */
displacement extern_missing()
{
    float helper() { extern float Kd; return Kd; }
    P += helper() * N;
}
