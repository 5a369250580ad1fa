/*
 * shaders.h: small test shaders whose displaced surfaces have closed forms
 * (so the renderer's depths can be checked against analytic values).
 */
#ifndef TESTS_TRACE_SHADERS_H
#define TESTS_TRACE_SHADERS_H

/* a constant displacement h along the normal */
#define SHADER_CONSTD \
    "displacement constd(float h = 0.1)\n" \
    "{\n" \
    "    P += h * normalize(N);\n" \
    "    N = calculatenormal(P);\n" \
    "}\n"

/* a spike of height h and (s,t)-radius r0 at (0.5, 0.5) */
#define SHADER_SPIKE \
    "displacement spike(float r0 = 0.001, h = 0.5)\n" \
    "{\n" \
    "    float r = distance(point(s, t, 0), point(0.5, 0.5, 0));\n" \
    "    P += h * (1 - smoothstep(0, r0, r)) * normalize(N);\n" \
    "    N = calculatenormal(P);\n" \
    "}\n"

/* a cylinder ("nail head") of (s,t)-radius r0 and height h: vertical walls */
#define SHADER_STEPCYL \
    "displacement stepcyl(float r0 = 0.1, h = 0.3)\n" \
    "{\n" \
    "    float r = distance(point(s, t, 0), point(0.5, 0.5, 0));\n" \
    "    float d = 0;\n" \
    "    if (r < r0)\n" \
    "        d = h;\n" \
    "    P += d * normalize(N);\n" \
    "    N = calculatenormal(P);\n" \
    "}\n"

/* a smooth radial wave (like the library's wave) */
#define SHADER_RIPPLE \
    "displacement ripple(float Km = 0.05, freq = 30)\n" \
    "{\n" \
    "    float r = distance(point(s, t, 0), point(0.5, 0.5, 0));\n" \
    "    P += Km * sin(freq * r) * exp(-3 * r) * normalize(N);\n" \
    "    N = calculatenormal(P);\n" \
    "}\n"

/* Lambertian surface */
#define SHADER_MYMATTE \
    "surface mymatte(float Ka = 0, Kd = 1)\n" \
    "{\n" \
    "    normal Nf = faceforward(normalize(N), I);\n" \
    "    Ci = Os * Cs * (Ka * ambient() + Kd * diffuse(Nf));\n" \
    "    Oi = Os;\n" \
    "}\n"

/* the standard lights' formulas (RI Spec 3.2 Appendix A), written as a
 * user would; "from"/"to" in shader space, which is the light's space */
#define SHADER_MYPOINT \
    "light mypoint(float intensity = 1; color lightcolor = 1;\n" \
    "              point from = point \"shader\" (0, 0, 0))\n" \
    "{\n" \
    "    illuminate(from)\n" \
    "        Cl = intensity * lightcolor / (L . L);\n" \
    "}\n"
#define SHADER_MYSUN \
    "light mysun(float intensity = 1; color lightcolor = 1;\n" \
    "            point from = point \"shader\" (0, 0, 0);\n" \
    "            point to = point \"shader\" (0, 0, 1))\n" \
    "{\n" \
    "    solar(to - from, 0.0)\n" \
    "        Cl = intensity * lightcolor;\n" \
    "}\n"

#endif
