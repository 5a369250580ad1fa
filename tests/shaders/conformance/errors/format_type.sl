/* a format conversion takes the type it names */
displacement format_type()
{
    string label = format("height %f at %p", P, s);
    P += match("height", label) * N;
}
