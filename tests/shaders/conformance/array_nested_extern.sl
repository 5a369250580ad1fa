/* arrays: a nested helper reaching the shader's array through extern */
displacement array_nested_extern(float freq = 2)
{
    float octaves[3] = {1, 0.5, 0.25};
    float layer(float k; float x)
    {
        extern float octaves[];
        return octaves[k] * sin(x * pow(2, k));
    }
    P = point(layer(0, s * freq) + layer(1, s * freq) + layer(2, s * freq), layer(t * 3, 1), 0);
}
