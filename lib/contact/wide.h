/* Lanes of contacts side by side: a value of WS_LANES contacts in one ws_wide, so that a loop
 * over the lanes of a group runs on vectors (the laws of contact/penalty.h are straight-line
 * code for one lane; a hot loop marked WS_VECTOR_LOOP calls them for each lane of a group, and
 * its AVX2 and AVX-512 clones take the four lanes at once). Without vectors a lane is a scalar
 * and the result is the same to the bit: every lane's arithmetic is the scalar code's, in its
 * order, with no fused multiply-add (-ffp-contract=off).
 *
 * Four doubles by value in a struct, not GCC's 32-byte vector type: passed to or from a function
 * that vectors of that size change the calling convention of (for the baseline x86-64 target),
 * which compilers warn about or refuse. */
#ifndef WS_CONTACT_WIDE_H
#define WS_CONTACT_WIDE_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "math/wmath.h"

#define WS_LANES 4

typedef struct ws_wide {
    double v[WS_LANES];
} ws_wide;

/* A vector of each lane, by component. */
typedef struct ws_wide3 {
    ws_wide x, y, z;
} ws_wide3;

static inline v3 ws_lane(const ws_wide3 *a, size_t l)
{
    return v3_make(a->x.v[l], a->y.v[l], a->z.v[l]);
}

static inline void ws_lane_set(ws_wide3 *a, size_t l, v3 p)
{
    a->x.v[l] = p.x;
    a->y.v[l] = p.y;
    a->z.v[l] = p.z;
}

/* A double's bits, and back: the masks of a lane (all bits or none) are kept as doubles in
 * arrays of doubles. */
static inline uint64_t ws_bits(double a)
{
    uint64_t u;
    memcpy(&u, &a, sizeof u);
    return u;
}

static inline double ws_double_of(uint64_t u)
{
    double a;
    memcpy(&a, &u, sizeof a);
    return a;
}

/* a where the bits of mask are set (all or none), else b: by their bits, so that a store of
 * the choice stays a store (as a select, the compiler turns a store of b, the value read from
 * the same place, into a masked store of a, which is slow, or a branch). */
static inline double ws_pick(uint64_t mask, double a, double b)
{
    return ws_double_of((ws_bits(a) & mask) | (ws_bits(b) & ~mask));
}

/* All bits where c holds, none where not. */
static inline uint64_t ws_mask(int c)
{
    return 0 - (uint64_t)(c != 0);
}

#endif
