/* a class is one shader: a surface and a displacement method must be
 * split into two classes */
class twokinds() {
    public void surface(output color Ci, Oi) { Ci = 1; }
    public void displacement(output point P; output normal N) { P += N; }
}
