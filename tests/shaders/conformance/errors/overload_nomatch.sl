/* must stay an error: no overload takes a string */
float w(float x) { return x; }
float w(color c) { return comp(c, 0); }

displacement overload_nomatch()
{
    P += w("heavy") * N;
}
