/* RSL 2: a member array with an initializer and a colour member, read by
 * a method through the generated extern (a loop over the array) */
class class_member_array(float Kd = 0.5)
{
    float weights[3] = {1, 2, 4};
    color tint = color(0.5, 0.25, 1);

    float blend(float x) {
        float i, sum = 0;
        for (i = 0; i < 3; i += 1)
            sum += weights[i] * pow(x, i);
        return sum;
    }

    public void displacement(output point P; output normal N)
    {
        P = point(blend(s) * Kd, comp(tint, 1) + t, weights[2] - blend(t));
    }
}
