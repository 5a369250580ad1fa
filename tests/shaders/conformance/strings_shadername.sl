/* shadername(): the name of the shader running */
displacement strings_shadername()
{
    string me = shadername();
    P = point(me == "strings_shadername" ? 1 : 0, match("^strings_", me), s);
}
