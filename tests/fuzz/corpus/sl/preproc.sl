#define SQ(x) ((x) * (x))
#define CAT(a, b) a ## b
#define STR(x) #x
#if defined(SQ) && (1 + 2 * 3 == 7)
#  ifdef NOPE
#    error "never"
#  elif 0
#  else
#    define K 0.25
#  endif
#endif
#undef NOPE
displacement pp(float CAT(K, m) = K) {
    float CAT(a, 1) = SQ(u - 0.5) + SQ(v - 0.5);
    string s = STR(hello world);
    P += Km * a1 * N;
}
