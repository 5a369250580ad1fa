/* message passing: attribute(), option() and rendererinfo() return 1 and
 * set the variable when the renderer has the value, 0 and leave it alone
 * when not (the suite sets displacementbound:sphere, user:frequency and
 * user:tint) */
displacement message_attribute()
{
    float bound = 0, freq = 1, missing = 7;
    string renderer = "";
    color tint = 0;
    float a = attribute("displacementbound:sphere", bound);
    float b = option("user:frequency", freq);
    float c = attribute("user:missing", missing);
    float d = rendererinfo("renderer", renderer);
    float e = attribute("user:tint", tint);
    P = point(a + b * 10 + c * 100 + d * 1000 + e * 10000, bound + freq * sin(s * 4),
              missing + comp(tint, 1) + (renderer == "aafarm" ? 1 : 0));
}
