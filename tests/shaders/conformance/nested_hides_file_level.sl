/* nested functions: a nested bias() hides the file-level one in its block */
float bias(float b, x) { return pow(x, log(b) / log(0.5)); }

displacement nested_hides_file_level()
{
    float a = bias(0.7, s);
    {
        float bias(float b, x) { return x / ((1 / b - 2) * (1 - x) + 1); }
        a -= bias(0.7, s);
    }
    P = point(a, bias(0.3, t), 0);
}
