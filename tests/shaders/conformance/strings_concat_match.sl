/* strings: concat, match (anchors, classes), ==, and format's %d */
displacement strings_concat_match(string base = "brick")
{
    string name = concat(base, "_", "red");
    float a = match("^brick_r", name);
    float b = match("blue$", name);
    float c = name == "brick_red" ? 1 : 0;
    string d = concat(format("%d", floor(s * 4)), "x");
    P = point(a + 2 * b + 4 * c, s + (match("^[0-1]x$", d) ? 1 : 0), t);
}
