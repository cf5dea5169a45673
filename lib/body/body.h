/* Rigid bodies in structure-of-arrays pools, indexed by id slot. The state (r, p, v, omega') is
 * double-buffered: a step writes the other buffer and the world swaps on success, so a failed
 * step leaves the committed state untouched. Knows shape (and math, drive). */
#ifndef WS_BODY_H
#define WS_BODY_H

#include <wrapsim/body.h>

#include "base/base.h"
#include "drive/drive.h"
#include "math/wmath.h"
#include "shape/shape.h"

typedef struct ws_body_state {
    v3 *r;  /* CoG, global */
    qt *p;  /* Euler parameters */
    v3 *v;  /* CoG velocity, global */
    v3 *w;  /* angular velocity omega', body frame */
} ws_body_state;

typedef struct ws_body_store {
    size_t capacity;
    size_t slots; /* slots ever used (alive or not): loops run to here */
    size_t alive_count;
    uint8_t *alive;
    uint8_t *type; /* ws_body_type */
    ws_shape **shape;
    uint32_t *material;
    double *layer;
    double *mass, *inv_mass;
    m3 *J, *Jinv;
    m3 *Q;  /* principal axes of J in the body frame (columns): J = Q diag(Ip) Q^T */
    v3 *Ip; /* principal moments */
    ws_body_state st[2];
    /* Per-step scratch, from the committed state at t. */
    m3 *A;    /* rotation */
    v3 *wg;   /* omega in the global frame */
    v3 *f;    /* force accumulator, global */
    v3 *m;    /* moment accumulator about the CoG, global */
    v3 *lo, *hi; /* global bounding box inflated by layer + margin/2 */
    uint8_t *has_drive;
    ws_drive *drive;
    char **name;
    void **user;
} ws_body_store;

/* Make room for `n` slots. 0 on success, -1 out of memory (nothing lost). */
int ws_bodies_reserve(ws_mem *mem, ws_body_store *b, size_t n);
void ws_bodies_free(ws_mem *mem, ws_body_store *b);

/* Integrate dynamic body i from state `cur` to `nxt` over dt with the accumulated force and
 * moment (global). */
void ws_body_integrate_symplectic(ws_body_store *b, size_t i, int cur, int nxt, double dt);
void ws_body_integrate_paper(ws_body_store *b, size_t i, int cur, int nxt, double dt);

/* Inertia of a shape for a mass (kg): inertia_unit * mass / volume. */
m3 ws_body_inertia_from_shape(const ws_shape *s, double mass);

#endif
