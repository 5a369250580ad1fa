/* arrays: a bubble sort, element swaps under conditions on s and t */
displacement array_sort()
{
    float a[4] = {s, t, 0.5, 1 - s};
    float i, j;
    for (i = 0; i < 3; i += 1) {
        for (j = 0; j < 3 - i; j += 1) {
            if (a[j] > a[j + 1]) {
                float tmp = a[j];
                a[j] = a[j + 1];
                a[j + 1] = tmp;
            }
        }
    }
    P = point(a[0], a[1], a[3]);
}
