/* must stay an error: overloads that differ only by return type, called
 * where the context gives no type */
float pick(point p) { return xcomp(p); }
color pick(point p) { return color(ycomp(p)); }

displacement ambiguous()
{
    P += pick(P);
}
