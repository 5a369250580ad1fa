/* light shaders: the standard spotlight, a cone with a smooth edge and a
 * falloff towards it */
light light_spot(float intensity = 1; color lightcolor = 1;
                 point from = point "shader" (0, 0, 0);
                 point to = point "shader" (0, 0, 1);
                 float coneangle = radians(30); float conedeltaangle = radians(5);
                 float beamdistribution = 2)
{
    uniform vector A = (to - from) / length(to - from);
    illuminate(from, A, coneangle) {
        float cosangle = L . A / length(L);
        float atten = pow(cosangle, beamdistribution) / (L . L);
        atten *= smoothstep(cos(coneangle), cos(coneangle - conedeltaangle), cosangle);
        Cl = atten * intensity * lightcolor;
    }
}
