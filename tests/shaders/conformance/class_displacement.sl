/* RSL 2: a shader class with a public displacement method, member
 * variables (one set by begin()), and a private method reading the
 * class's parameter and a member */
class class_displacement(float Km = 0.5; float freq = 3)
{
    float scale = 2;
    varying float phase = 0;

    float ripple(float x) { return Km * scale * sin(freq * x + phase); }

    public void begin() { phase = 0.25; }

    public void displacement(output point P; output normal N)
    {
        P = point(ripple(s), ripple(t) + phase, scale);
    }
}
