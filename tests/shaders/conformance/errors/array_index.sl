/* must stay an error: a constant index outside the array */
displacement array_index()
{
    float a[3] = {1, 2, 3};
    P += a[3] * N;
}
