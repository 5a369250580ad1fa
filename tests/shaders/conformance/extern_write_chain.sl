/* nested functions: a helper two levels in counts into the shader body's
 * variable through extern */
displacement extern_write_chain()
{
    float hits = 0;
    void mark(float x)
    {
        void bump() { extern float hits; hits += 1; }
        if (x > 0.5)
            bump();
        bump();
    }
    mark(s);
    mark(t);
    mark(1);
    P = point(hits, 0, 0);
}
