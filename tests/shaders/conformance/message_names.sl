/* message passing: the names a renderer may or may not answer; a missing
 * one returns 0 and leaves the variable alone (this suite's VM answers
 * rendererinfo "renderer" and its own attributes, not option "Format",
 * which the renderer sets) */
displacement message_names()
{
    point fmt = point(-1);
    string id = "none", ver = "?";
    float sides = 2;
    float a = option("Format", fmt);
    float b = attribute("identifier:name", id);
    float c = rendererinfo("version", ver);
    float d = attribute("Sides", sides);
    float e = rendererinfo("renderer", ver);
    float f = attribute("displacementbound:sphere", sides);
    P = point(a + 2 * b + 4 * c + 8 * d + 16 * e + 32 * f, xcomp(fmt) + sides,
              (id == "none" ? 1 : 0) + (ver == "aafarm" ? 2 : 0));
}
