/* RSL 2: methods call each other whatever their order in the class, and a
 * method's parameter hides the member of the same name */
class class_method_order(float gain = 2)
{
    float offset = 0.5, count = 0;

    float outer(float x) { count += 1; return inner(x) * gain; }
    float inner(float offset) { return offset * offset + twice(offset); }
    float twice(float x) { return 2 * x; }

    public void construct() { offset = 0.75; }

    public void displacement(output point P; output normal N)
    {
        float a = outer(s);
        float b = outer(t) + offset;
        P = point(a, b, count);
    }
}
