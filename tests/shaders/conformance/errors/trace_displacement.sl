/* trace() has no bound over a range of the surface: not in displacement */
displacement trace_displacement()
{
    color c = trace(P, N);
    P += comp(c, 0) * N;
}
