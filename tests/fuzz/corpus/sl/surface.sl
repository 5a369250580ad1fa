surface shiny(float Ka = 1, Kd = 0.5, Ks = 0.5, roughness = 0.1;
              color specularcolor = 1; string name = "x") {
    normal Nf = faceforward(normalize(N), I);
    vector V = -normalize(I);
    color c = Cs * (Ka * ambient() + Kd * diffuse(Nf));
    c += specularcolor * Ks * specular(Nf, V, roughness);
    illuminance(P, Nf, PI / 2) {
        c += Cl * max(0, normalize(L) . Nf) * 0.1;
    }
    float s2 = mod(s * 10, 1), t2 = smoothstep(0.2, 0.8, t);
    matrix m = matrix "camera" 1;
    point q = transform("object", P);
    Oi = Os;
    Ci = Oi * mix(c, color(s2, t2, xcomp(q)), step(0.5, s)) + spline(t, 0, 1, 0.5, 1);
}
