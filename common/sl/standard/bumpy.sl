/*
 * bumpy.sl: the RI Specification's standard bumpy displacement, built into
 * aafarm: P moves along the unit normal by Km times the first channel of a
 * map read at (s, t), and N follows the moved surface. With no map named,
 * the surface stays where it is. aafarm traces the displaced surface itself
 * (docs/renderer.md), so the bumps are true geometry, silhouettes included.
 */
displacement bumpy(float Km = 1; string texturename = "")
{
    if (texturename != "") {
        float amp = Km * float texture(texturename[0], s, t);
        P += amp * normalize(N);
        N = calculatenormal(P);
    }
}
