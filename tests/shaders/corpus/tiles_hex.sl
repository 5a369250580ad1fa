/*
 * tiles_hex.sl: hexagonal tiles in (s,t): a skewed lattice from floor and
 * mod, the nearest of the candidate centres chosen with if, tile height
 * from a rounded hexagon distance.
 * Idiom: floor/mod lattice, branches choosing a cell.
 */
displacement tiles_hex(float Km = 0.02, frequency = 8, groove = 0.12)
{
    float x = s * frequency, y = t * frequency / 0.866025;
    float row = floor(y);
    if (mod(row, 2) >= 1)
        x += 0.5;
    float col = floor(x);
    float dx = x - col - 0.5, dy = (y - row - 0.5) * 0.866025;
    float d = max(abs(dx), abs(dx) * 0.5 + abs(dy) * 0.866025);
    float h = 1 - smoothstep(0.5 - groove, 0.5, d);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}
