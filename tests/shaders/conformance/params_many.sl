/* user functions with many parameters, as exporters' shaders and layered
 * shader libraries write them: 9 with two outputs, 16 (a blend of eight
 * layers), 40 (38 inputs summed with weights, two outputs) */
void layer9(float Ka, Kd, Ks, roughness, base, top, mask; output float mixed;
            output float spec)
{
    mixed = mix(base, top, mask) * (Ka + Kd);
    spec = Ks / (1 + roughness);
}

float blend16(float w1, w2, w3, w4, w5, w6, w7, w8;
              float x1, x2, x3, x4, x5, x6, x7, x8)
{
    return (w1 * x1 + w2 * x2 + w3 * x3 + w4 * x4 + w5 * x5 + w6 * x6 + w7 * x7 +
            w8 * x8) / (w1 + w2 + w3 + w4 + w5 + w6 + w7 + w8);
}

void sum40(float a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10, a11, a12, a13, a14, a15,
           a16, a17, a18, a19, a20, a21, a22, a23, a24, a25, a26, a27, a28, a29, a30,
           a31, a32, a33, a34, a35, a36, a37;
           output float total; output float last)
{
    total = a0 * 1 + a1 * 2 + a2 * 3 + a3 * 4 + a4 * 5 + a5 * 1 + a6 * 2 + a7 * 3 + a8 * 4 +
            a9 * 5 + a10 * 1 + a11 * 2 + a12 * 3 + a13 * 4 + a14 * 5 + a15 * 1 + a16 * 2
            + a17 * 3 + a18 * 4 + a19 * 5 + a20 * 1 + a21 * 2 + a22 * 3 + a23 * 4 +
            a24 * 5 + a25 * 1 + a26 * 2 + a27 * 3 + a28 * 4 + a29 * 5 + a30 * 1 +
            a31 * 2 + a32 * 3 + a33 * 4 + a34 * 5 + a35 * 1 + a36 * 2 + a37 * 3;
    last = a37;
}

displacement params_many()
{
    float mixed, spec, total, last;
    layer9(0.25, 0.5, 0.8, 0.3, s, t, s * t, mixed, spec);
    float b = blend16(1, 2, 3, 4, 5, 6, 7, 8, s, t, s * t, s + t, s - t, 2 * s, 2 * t, 1);
    sum40(t * 1, s * 2, t * 3, s * 4, t * 5, s * 6, t * 7, s * 8, t * 9, s * 10, t * 11,
          s * 12, t * 13, s * 14, t * 15, s * 16, t * 17, s * 18, t * 19, s * 20,
          t * 21, s * 22, t * 23, s * 24, t * 25, s * 26, t * 27, s * 28, t * 29,
          s * 30, t * 31, s * 32, t * 33, s * 34, t * 35, s * 36, t * 37, s * 38,
          total, last);
    P = point(mixed + spec, b, total / 100 + last);
}
