/* must stay an error: an enclosing variable used without extern */
displacement no_extern(float Km = 1)
{
    float bump(float x) { return Km * x; }
    P += bump(s) * N;
}
