/* arrays: an unsized parameter, arraylength, a size from the initializer */
float weighted(float w[]; float x)
{
    float i, sum = 0, total = 0;
    for (i = 0; i < arraylength(w); i += 1) {
        sum += w[i] * pow(x, i);
        total += w[i];
    }
    return sum / total;
}

displacement array_unsized_param()
{
    float a[3] = {1, 2, 3}, b[] = {4, 0, 0, 1};
    P = point(weighted(a, s), weighted(b, t), arraylength(b));
}
