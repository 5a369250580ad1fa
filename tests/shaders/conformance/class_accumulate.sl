/* RSL 2: methods updating member variables across calls in a loop (an
 * octave sum kept in the class) */
class class_accumulate(float octaves = 4)
{
    float sum = 0, amp = 1;

    void octave(float f) { sum += amp * sin(f * s); amp *= 0.5; }

    public void displacement(output point P; output normal N)
    {
        float i;
        for (i = 0; i < octaves; i += 1)
            octave(pow(2, i));
        P = point(sum, amp, t);
    }
}
