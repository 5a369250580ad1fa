/* strings: concat, format (%d %f %c %s %%) and match, as shaders build
 * texture names and labels */
displacement strings_format()
{
    float k = floor(s * 10);
    string name = concat("tex_", format("%03d", k), ".tx");
    float x = k + 10 * match("^tex_00[0-9]\\.tx$", name);
    float y = match("^a+b?c*$", concat("aa", "b", "ccc")) + 2 * match("[xyz]", "hello") +
              4 * match("l+o$", "hello");
    float z = (format("%c", color (1, 0.5, 0)) == "1.000000 0.500000 0.000000" ? 1 : 0) +
              2 * (format("%s-%s", "a", "b") == "a-b" ? 1 : 0) +
              4 * (format("%d%%", 5) == "5%" ? 1 : 0) +
              8 * (format("%.2f", t) == format("%.2f", t) ? 1 : 0);
    P = point(x, y + t, z);
}
