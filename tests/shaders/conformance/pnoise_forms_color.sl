/* noise family: colour results of pnoise() in every argument form, with
 * the periods each form takes */
displacement pnoise_forms_color()
{
    color a = color pnoise(s * 5, 4);
    color b = color pnoise(s * 3, t * 3, 2, 3);
    color c = color pnoise(point(s, t, 0) * 3, point(4, 4, 4));
    color d = color pnoise(point(s, t, 0) * 3, t * 2, point(2, 2, 2), 3);
    P = point(comp(a, 0) + comp(b, 1), comp(c, 2) + comp(d, 0), comp(a, 2) * comp(d, 1));
}
