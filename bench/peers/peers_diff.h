/*
 * peers_diff.h: which pixels of a peer's image differ from a reference
 * (bench/peers/): one ray per pixel, so alpha is the hit mask. A pixel
 * differs when its hit mask differs (alpha on different sides of 1/2) or,
 * hit in both, when a colour channel differs by more than tol.
 */
#ifndef PEERS_DIFF_H
#define PEERS_DIFF_H

typedef struct peers_diff {
    long holes;     /* the reference hits, the test misses */
    long extra;     /* the test hits, the reference misses */
    long colour;    /* hit in both, a channel differs by more than tol */
} peers_diff;

/* test, ref: w*h*4 floats (RGBA). pic (may be NULL): w*h*4 floats, a
 * picture of the differences: the test's grey level, holes red, extra
 * pixels blue, colour differences yellow. */
peers_diff peers_diff_images(const float *test, const float *ref, int w, int h,
                             double tol, float *pic);

#endif
