/* message passing, the receiver: the surface reads the displacement
 * shader's outputs (0 when there is no such output) */
surface surface_message()
{
    float h = -1;
    color tint = 0;
    float found = displacement("height", h) + displacement("tint", tint);
    float none = displacement("nothing", h);
    Ci = tint + color (h, found, none);
    Oi = 1;
}
