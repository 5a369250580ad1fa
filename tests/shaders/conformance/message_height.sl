/* message passing, the sender: a displacement shader's output parameters,
 * read by surface_message.sl */
displacement message_height(float Km = 0.1; output varying float height = 0;
                            output varying color tint = 0)
{
    height = Km * sin(s * 6) * cos(t * 4);
    tint = color (s, t, height);
    P += height * normalize(N);
}
