/* The implicit film's multigrid preconditioner on grid webs (web/multigrid.h says the cycle;
 * docs/theory.md, "The implicit film", why it is this one). */
#include "web/multigrid.h"

#include "web/coupled.h"
#include "web/implicit.h"

#include <string.h>

/* Inlined where a loop's choices are constants at the call (GCC leaves some out of line). */
#if defined(__GNUC__)
#define MG_INLINE inline __attribute__((always_inline))
#else
#define MG_INLINE inline
#endif

#define MG_LEVELS 16   /* levels at most (a grid of 2^15 nodes a side would need them) */
#define MG_COARSEST 16 /* a level of this many nodes or fewer is the coarsest */
/* The film level's smoother: damped block Jacobi, this many sweeps before and after the coarse
 * correction, with weight MG_OMEGA. The film's matrix is at most twice its block diagonal
 * (A = N + sum over springs of E^T K E with E = e_a - e_b, and 2 D - A = N + sum (e_a + e_b)^T
 * K (e_a + e_b) >= 0), so any weight below 1 contracts in A's norm and the cycle stays positive
 * definite; 2/3 is the weight that damps the grid's upper half of frequencies best. */
#define MG_SWEEPS 2
#define MG_OMEGA (2.0 / 3.0)
/* A band's film level halves around only (plan_levels says why) and then takes one sweep
 * before and one after: the coarse level it hands on, twice as fine, does what the second
 * sweep was for (bench/NOTES.md, session 13: 19.6 iterations a step at one sweep on the
 * unrefined band, 18.1 at two, for 10 % less time an iteration). */
#define MG_SWEEPS_SEMI 1
/* A coarse node's row holds its own block and those of its forward neighbours (slots 4 to 8 of
 * the 9 with dx, dy in -1..1, slot 3 (dy + 1) + dx + 1); a backward neighbour's block is that
 * neighbour's forward one (every block is symmetric: P is a scalar weight times the 3x3
 * identity, and the film's blocks are), which halves what a sweep reads. A block is kept as its
 * six numbers (implicit.h's WS_SYM order) in single precision: the coarse levels are a
 * preconditioner's, and halving them halves what a cycle streams (docs/theory.md 8a says why
 * the cycle stays symmetric positive definite); they are summed in double (`acc`) and rounded
 * once. */
/* A coarse level's row along x (around a band) is solved whole in its sweeps where point
 * Jacobi would take less than this share off the error constant along the row and alternating
 * up (row_held_along). Measured on the refined reference band's first coarse level (bench/
 * NOTES.md, session 15): its six outer rows at each edge 0.76-0.92 at 1x, 0.37-0.50 at 2x
 * (solving them whole saved no iteration there), 0.20-0.33 at 4x (it saved a quarter), its
 * middle rows 0.65-0.92; at 4x 0.35 and 0.45 gave the same iterations, 0.3 4 % more. */
#define MG_LINE_RHO 0.35
#define CENTRE 4
#define FOP 8   /* words a film spring in fop: ex ey ez a b, end a, end b, unused */
#define FOP_A 5
#define FOP_B 6
#define STEN (5 * WS_SYM)
#define AT(L, k, o) ((L)->a + STEN * (size_t)(k) + WS_SYM * (size_t)((o) - CENTRE))
#define ACC(acc, k, o) ((acc) + STEN * (size_t)(k) + WS_SYM * (size_t)((o) - CENTRE))

/* One direction's interpolation for one fine index: n coarse indices c with weights w. */
typedef struct map1d {
    int n, c[2];
    double w[2];
} map1d;

typedef struct mg_level {
    int nx, ny, closed; /* grid: node ix + nx iy, closed around (a band) */
    int cx, cy;         /* whether x and y are halved for the next level */
    int lines;          /* how many of its rows its sweeps solve whole (coarse levels) */
    unsigned char *whole; /* ny: whether each row is solved whole (row_held_along) */
    map1d *mx, *my;     /* interpolation from the next level, by ix and by iy */
    uint32_t n;
    float *a;               /* STEN n: each node's row of blocks (coarse levels) */
    double *dinv;           /* WS_SYM n: each node's pivot's inverse, of its own block
                               (point_factor) or of its row's factor (line_factor) */
    double *lff;            /* 9 n: a closed row's multipliers to its last node (line_factor;
                               apart from dinv, which the point sweeps stream alone) */
    double *x, *r, *t;      /* 3 n each: the level's solution, right-hand side, scratch (the
                               film's level has t alone) */
    /* With bodies nested (coarse levels): the coupling of the nodes to them, kept only for the
     * (node, body) pairs that have one: entries gs[i] .. gs[i + 1] - 1 are node i's, sorted by
     * node; entry e couples node gn[e] to body gb[e] by the 3x6 block G + 18 e (row-major; in
     * double precision: converting single-precision blocks cost more time than their halved
     * reading saved, bench/NOTES.md session 14). ng entries, room for gcap. xb, rb: the
     * bodies' solution and right-hand side (6 nb). */
    uint32_t *gs, *gn, *gb;
    double *G;
    size_t ng, gcap;
    double *xb, *rb;
} mg_level;

struct ws_mg {
    int nlev;
    int sweeps;   /* the film level's sweeps before and after: MG_SWEEPS, or MG_SWEEPS_SEMI */
    mg_level lv[MG_LEVELS];
    uint32_t m;   /* unknowns of the coarsest level */
    double *chol; /* its Cholesky factor, lower, m x m */
    double *acc;  /* a coarse level's blocks as they are summed (level 1's size) */
    double *row;  /* a coarse row of vectors (level 1's nx), for restriction and prolongation */
    /* The film level's passes run in the solve's blocks (web/implicit.h's ws_iblock, nblk of
     * them): each block's own coarse row for prolongation (brow, level 1's nx each), every
     * film row restricted along x (rrow, level 0's ny rows of level 1's nx), and with bodies
     * nested each block's first contact (lstart, nblk + 1) and its share of the bodies'
     * residual (bpart, 6 nb a block). */
    uint32_t nblk;
    const ws_iblock *blocks;
    double *brow, *rrow, *bpart;
    double *rpart; /* each row's share of the bodies' sums in a coarse sweep (6 nb a row of
                      level 1's, the largest) */
    size_t *lstart;
    double *sacc; /* level 1's springs' part, kept while the springs' blocks are: made for the
                     step ws_implicit_begin began (its count kept_begun) and the step h */
    int springs_kept;
    uint64_t kept_begun;
    double kept_h;
    double *blk;  /* every array above but the levels' blocks, in one allocation of `doubles` */
    float *fop;   /* the film's springs for the sweeps, FOP words a spring: e, a, b (with
                     sacc), then its ends a and b (uint32_t, set at reserve) in words FOP_A
                     and FOP_B: one record a spring, one stream for the springs' pass */
    float *fnd;   /* the film's nodes' own blocks N (WS_SYM a node; at every setup) */
    float *fpinv; /* w times the inverse of the film's diagonal blocks D (likewise) */
    float *fblk;  /* every float array above, `floats` */
    size_t floats;
    size_t doubles;
    map1d *maps;  /* every level's mx and my, nmaps of them */
    size_t nmaps;
    unsigned char *whole; /* every coarse level's rows' kind (mg_level.whole), rows of them */
    size_t rows;
    /* The bodies of the running solve nested in the hierarchy (ws_mg_bodies; nb 0: none):
     * their six unknowns ride along every coarse level, coupled to its nodes by the levels'
     * entries. bchol: the coarsest level's factor with them ((m + 6 nb)^2), bsc: its vector
     * (m + 6 nb); mark: (node, body) -> entry + 1 while a level's entries are gathered (level
     * 1's n nb). All in the scratch ws_mg_bodies was given. */
    uint32_t nb;
    const ws_rigid *rig;
    double *bchol, *bsc;
    double *brz;  /* a zero residual and an answer for the bodies (12 nb: ws_mg_apply) */
    double *bsum; /* the bodies' right-hand side in a backward sweep (6 nb) */
    uint32_t *mark;
};

/* Interpolation from a coarse level to the finer one, along one direction: fine index i of n
 * takes coarse i / 2 when even, the mean of its two coarse neighbours when odd (the last of
 * an open line of even length takes its one neighbour; a closed line wraps). */
static int map1(int i, int n, int closed, int coarsen, int *c, double *w)
{
    if (!coarsen || !(i & 1)) {
        c[0] = coarsen ? i / 2 : i;
        w[0] = 1.0;
        return 1;
    }
    const int nc = (n + 1) / 2;
    int right = (i + 1) / 2;
    c[0] = (i - 1) / 2;
    if (right == nc) {
        if (!closed) {
            w[0] = 1.0;
            return 1;
        }
        right = 0;
    }
    c[1] = right;
    w[0] = w[1] = 0.5;
    return 2;
}

/* A fine node's row of P: the coarse nodes (coordinates and index) and their weights. */
typedef struct pmap {
    int n;
    int X[8], Y[8];
    uint32_t idx[8];
    double w[8];
} pmap;

static void pmap_of(const mg_level *f, const mg_level *c, int ix, int iy, pmap *p)
{
    const map1d *mx = &f->mx[ix], *my = &f->my[iy];
    int k = 0;
    for (int b = 0; b < my->n; b++)
        for (int a = 0; a < mx->n; a++, k++) {
            p->X[k] = mx->c[a];
            p->Y[k] = my->c[b];
            p->idx[k] = (uint32_t)mx->c[a] + (uint32_t)c->nx * (uint32_t)my->c[b];
            p->w[k] = mx->w[a] * my->w[b];
        }
    p->n = k;
}

/* The slot in the row of (X1, Y1) of its neighbour (X2, Y2) on level c. */
static int slot(const mg_level *c, int X1, int Y1, int X2, int Y2)
{
    int dx = X2 - X1;
    if (c->closed) {
        if (dx == c->nx - 1)
            dx = -1;
        else if (dx == 1 - c->nx)
            dx = 1;
    }
    return (Y2 - Y1 + 1) * 3 + dx + 1;
}

/* The 9 neighbours of (ix, iy) on level L, by slot; -1 beyond the grid's edge. */
static inline void neighbours(const mg_level *L, int ix, int iy, int64_t *j)
{
    int64_t xs[3] = {ix - 1, ix, ix + 1};
    if (ix == 0)
        xs[0] = L->closed ? L->nx - 1 : -1;
    if (ix == L->nx - 1)
        xs[2] = L->closed ? 0 : -1;
    for (int dy = 0; dy < 3; dy++) {
        const int jy = iy + dy - 1;
        for (int dx = 0; dx < 3; dx++)
            j[3 * dy + dx] =
                jy < 0 || jy >= L->ny || xs[dx] < 0 ? -1 : xs[dx] + (int64_t)L->nx * jy;
    }
}

/* A list of coarse nodes with weights, each node once: a fine node's row of P (up to 4), or
 * the difference of two rows (a spring's E P, up to 8). */
static void sym_axpy(double *D, double w, const double *S)
{
    for (int k = 0; k < WS_SYM; k++)
        D[k] += w * S[k];
}

/* Where the block between coarse nodes u and v (u != v, grid neighbours) is kept: the forward
 * one's row. */
static double *pair_block(const mg_level *c, double *acc, const pmap *p, int i, const pmap *q,
                          int j)
{
    const int o = slot(c, p->X[i], p->Y[i], q->X[j], q->Y[j]);
    return o > CENTRE ? ACC(acc, p->idx[i], o) : ACC(acc, q->idx[j], 8 - o);
}

/* acc += (P^T u)(P^T u)^T (x) S for the list p of u's coarse nodes and weights: the Galerkin
 * image of a block S on one fine node, or of a spring's E^T S E (p its E P). */
static void add_outer(const mg_level *c, double *acc, const pmap *p, const double *S)
{
    for (int i = 0; i < p->n; i++) {
        sym_axpy(ACC(acc, p->idx[i], CENTRE), p->w[i] * p->w[i], S);
        for (int j = i + 1; j < p->n; j++)
            sym_axpy(pair_block(c, acc, p, i, p, j), p->w[i] * p->w[j], S);
    }
}

/* acc += the image of a fine off-diagonal pair (i, j), block S in both (i, j) and (j, i):
 * (P_i^T P_j + P_j^T P_i) (x) S, p and q their rows of P. */
static void add_cross(const mg_level *c, double *acc, const pmap *p, const pmap *q,
                      const double *S)
{
    for (int i = 0; i < p->n; i++)
        for (int j = 0; j < q->n; j++) {
            const double w = p->w[i] * q->w[j];
            if (p->idx[i] == q->idx[j])
                sym_axpy(ACC(acc, p->idx[i], CENTRE), 2.0 * w, S);
            else
                sym_axpy(pair_block(c, acc, p, i, q, j), w, S);
        }
}

/* The film's node (ix, iy)'s row of P; none for a pinned node (its dv is zero). */
static void film_pmap(const ws_mg *mg, const ws_web *web, uint32_t i, pmap *p)
{
    const mg_level *f = &mg->lv[0];
    if (web->inv_m[i] == 0.0) {
        p->n = 0;
        return;
    }
    pmap_of(f, &mg->lv[1], (int)(i % (uint32_t)f->nx), (int)(i / (uint32_t)f->nx), p);
}

/* d = p - q as one list (a spring's E P from its ends' rows), zero weights dropped. */
static void pmap_diff(const pmap *p, const pmap *q, pmap *d)
{
    *d = *p;
    for (int j = 0; j < q->n; j++) {
        int i = 0;
        while (i < d->n && d->idx[i] != q->idx[j])
            i++;
        if (i == d->n) {
            d->X[i] = q->X[j], d->Y[i] = q->Y[j], d->idx[i] = q->idx[j], d->w[i] = 0.0;
            d->n++;
        }
        d->w[i] -= q->w[j];
    }
    int k = 0;
    for (int i = 0; i < d->n; i++)
        if (d->w[i] != 0.0) {
            d->X[k] = d->X[i], d->Y[k] = d->Y[i], d->idx[k] = d->idx[i], d->w[k] = d->w[i];
            k++;
        }
    d->n = k;
}

/* The part of level 1 that stays over a step h, into mg->sacc: P^T (sum over springs of E^T K
 * E + the nodes' (m + h c) I) P. It changes only when the springs' blocks do (once a step); the
 * contacts, which change between the solves of a step, add to the nodes' blocks. */
static void galerkin_springs(ws_mg *mg, const ws_web *web, double h)
{
    const ws_implicit *im = web->imp;
    const mg_level *c = &mg->lv[1];
    memset(mg->sacc, 0, STEN * (size_t)c->n * sizeof(double));
    pmap p, q, d;
    for (uint32_t s = 0; s < web->ns; s++) {
        const ws_ispring *k = &im->sp[s];
        float *o = mg->fop + FOP * (size_t)s;
        o[0] = (float)k->ex, o[1] = (float)k->ey, o[2] = (float)k->ez;
        o[3] = (float)k->a, o[4] = (float)k->b;
        if (k->a == 0.0 && k->b == 0.0)
            continue;
        const double S[WS_SYM] = {[WS_SYM_XX] = k->a * k->ex * k->ex + k->b,
                                  [WS_SYM_YY] = k->a * k->ey * k->ey + k->b,
                                  [WS_SYM_ZZ] = k->a * k->ez * k->ez + k->b,
                                  [WS_SYM_XY] = k->a * k->ex * k->ey,
                                  [WS_SYM_XZ] = k->a * k->ex * k->ez,
                                  [WS_SYM_YZ] = k->a * k->ey * k->ez};
        film_pmap(mg, web, web->sa[s], &p);
        film_pmap(mg, web, web->sb[s], &q);
        pmap_diff(&p, &q, &d);
        add_outer(c, mg->sacc, &d, S);
    }
    for (uint32_t i = 0; i < web->n; i++) {
        const double m = web->m[i] + h * web->damping;
        const double S[WS_SYM] = {[WS_SYM_XX] = m, [WS_SYM_YY] = m, [WS_SYM_ZZ] = m};
        film_pmap(mg, web, i, &p);
        add_outer(c, mg->sacc, &p, S);
    }
}

/* Level 1 = P^T A P over step h: the part kept over the step and the contacts' blocks of the
 * nodes that have any, h^2 K + h D as operator_for takes them. */
static void galerkin_film(ws_mg *mg, const ws_web *web, double h)
{
    const ws_implicit *im = web->imp;
    const mg_level *c = &mg->lv[1];
    memcpy(mg->acc, mg->sacc, STEN * (size_t)c->n * sizeof(double));
    pmap p;
    for (uint32_t i = 0; i < web->n; i++) {
        const double *kc = im->kc + WS_SYM * (size_t)i, *dc = im->dc + WS_SYM * (size_t)i;
        double S[WS_SYM];
        int any = 0;
        for (int k = 0; k < WS_SYM; k++) {
            S[k] = h * h * kc[k] + h * dc[k];
            any |= S[k] != 0.0;
        }
        if (!any)
            continue;
        film_pmap(mg, web, i, &p);
        add_outer(c, mg->acc, &p, S);
    }
}

/* A float block as doubles. */
static void block_of(const float *B, double *S)
{
    for (int k = 0; k < WS_SYM; k++)
        S[k] = B[k];
}

/* Level k + 1 = P^T A_k P, into mg->acc. */
static void galerkin_level(ws_mg *mg, int k)
{
    const mg_level *f = &mg->lv[k];
    const mg_level *c = &mg->lv[k + 1];
    memset(mg->acc, 0, STEN * (size_t)c->n * sizeof(double));
    pmap p, q;
    int64_t j[9];
    double S[WS_SYM];
    for (int iy = 0; iy < f->ny; iy++)
        for (int ix = 0; ix < f->nx; ix++) {
            const uint32_t i = (uint32_t)ix + (uint32_t)f->nx * (uint32_t)iy;
            pmap_of(f, c, ix, iy, &p);
            neighbours(f, ix, iy, j);
            block_of(AT(f, i, CENTRE), S);
            add_outer(c, mg->acc, &p, S);
            for (int o = CENTRE + 1; o < 9; o++) {
                const float *B = AT(f, i, o);
                if (j[o] < 0 || (B[0] == 0.0f && B[1] == 0.0f && B[2] == 0.0f &&
                                 B[3] == 0.0f && B[4] == 0.0f && B[5] == 0.0f))
                    continue;
                block_of(B, S);
                pmap_of(f, c, (int)(j[o] % f->nx), (int)(j[o] / f->nx), &q);
                add_cross(c, mg->acc, &p, &q, S);
            }
        }
}

/* The level's blocks rounded from the sums in mg->acc. */
static void store_level(ws_mg *mg, int k)
{
    mg_level *L = &mg->lv[k];
    for (size_t q = 0; q < STEN * (size_t)L->n; q++)
        L->a[q] = (float)mg->acc[q];
}

/* o -= S x for a symmetric block S kept in floats. */
static inline void fsym_sub(const float *S, const double *x, double *o)
{
    const double xx = S[WS_SYM_XX], yy = S[WS_SYM_YY], zz = S[WS_SYM_ZZ], xy = S[WS_SYM_XY],
                 xz = S[WS_SYM_XZ], yz = S[WS_SYM_YZ];
    o[0] -= xx * x[0] + xy * x[1] + xz * x[2];
    o[1] -= xy * x[0] + yy * x[1] + yz * x[2];
    o[2] -= xz * x[0] + yz * x[1] + zz * x[2];
}

/* A symmetric block (float, or double) as a full 3x3, row-major. */
static void full_of(const float *S, double *F)
{
    F[0] = S[WS_SYM_XX], F[1] = S[WS_SYM_XY], F[2] = S[WS_SYM_XZ];
    F[3] = S[WS_SYM_XY], F[4] = S[WS_SYM_YY], F[5] = S[WS_SYM_YZ];
    F[6] = S[WS_SYM_XZ], F[7] = S[WS_SYM_YZ], F[8] = S[WS_SYM_ZZ];
}

static void full_of_sym(const double *S, double *F)
{
    F[0] = S[WS_SYM_XX], F[1] = S[WS_SYM_XY], F[2] = S[WS_SYM_XZ];
    F[3] = S[WS_SYM_XY], F[4] = S[WS_SYM_YY], F[5] = S[WS_SYM_YZ];
    F[6] = S[WS_SYM_XZ], F[7] = S[WS_SYM_YZ], F[8] = S[WS_SYM_ZZ];
}

/* C = A B, or C = A B^T (bt), for full 3x3 blocks. */
static void mat_mul(const double *A, const double *B, int bt, double *C)
{
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            double s = 0.0;
            for (int q = 0; q < 3; q++)
                s += A[3 * r + q] * (bt ? B[3 * c + q] : B[3 * q + c]);
            C[3 * r + c] = s;
        }
}

/* S -= the symmetric part of a full block U (U is symmetric but for rounding). */
static void sym_sub_full(double *S, const double *U)
{
    S[WS_SYM_XX] -= U[0];
    S[WS_SYM_YY] -= U[4];
    S[WS_SYM_ZZ] -= U[8];
    S[WS_SYM_XY] -= 0.5 * (U[1] + U[3]);
    S[WS_SYM_XZ] -= 0.5 * (U[2] + U[6]);
    S[WS_SYM_YZ] -= 0.5 * (U[5] + U[7]);
}

/* A node's line factor: its pivot's inverse D^-1 (in dinv) and, on a closed row, its
 * multiplier to the row's last node F (in lff). The multiplier to the next node along the row,
 * C = A_{i+1,i} D^-1, is not kept: the sweeps take it as the coupling block (which the level
 * keeps) times D^-1, for less to read. */

/* Row iy's line block T on coarse level L (the row's nodes and their couplings along it,
 * closed around on a band) as T = L D L^T by block elimination along the row: node i's pivot
 * inverse D_i^-1 into L->dinv and, on a closed row, F_i, the row's last node's multiplier (that
 * node eliminated last: an arrow, no fill but its row), into L->lff; the multiplier along the
 * row, C_i =
 * A_{i+1,i} D_i^-1, is taken from the same numbers in the sweeps, so whatever the rounding the
 * solve L^-T D^-1 L^-1 is symmetric, and positive definite with D^-1 (docs/theory.md 8a). In
 * double precision: a ring's smooth mode around is held only by the mass and the weak
 * couplings up, and single precision lost it (bench/NOTES.md, session 14). A node no fine
 * node reaches has a zero block and no couplings: its pivot is the identity (its right-hand
 * side is always zero). 0, or -1 when a pivot is not positive definite. */
static int line_factor(mg_level *L, int iy)
{
    const int n = L->nx, m = L->closed ? n - 1 : n; /* m: the nodes of the chain */
    {
        const size_t k0 = (size_t)n * (size_t)iy;
        double Pf[9], Bf[9], Cp[9], Bp[9], f[9], Ff[9], U[9], Pl[WS_SYM];
        if (L->closed) { /* the last node's row: its block and its coupling to node 0 */
            block_of(AT(L, k0 + (size_t)m, CENTRE), Pl);
            full_of(AT(L, k0 + (size_t)m, CENTRE + 1), f);
        }
        for (int i = 0; i < m; i++) {
            const size_t k = k0 + (size_t)i;
            double *o = L->dinv + WS_SYM * k, *oF = L->lff + 9 * k;
            double P[WS_SYM], Pinv[WS_SYM];
            memset(o, 0, WS_SYM * sizeof(double));
            memset(oF, 0, 9 * sizeof(double));
            block_of(AT(L, k, CENTRE), P);
            if (P[WS_SYM_XX] == 0.0 && P[WS_SYM_YY] == 0.0 && P[WS_SYM_ZZ] == 0.0) {
                o[WS_SYM_XX] = o[WS_SYM_YY] = o[WS_SYM_ZZ] = 1.0;
                memset(Cp, 0, sizeof Cp);
                memset(f, 0, sizeof f); /* no coupling: nor any fill */
                continue;
            }
            if (i > 0) { /* P_i = A_i - C_{i-1} A_{i-1,i} */
                mat_mul(Cp, Bp, 0, U);
                sym_sub_full(P, U);
            }
            if (ws_sym_invert(P, Pinv) != 0)
                return -1;
            for (int q = 0; q < WS_SYM; q++)
                o[q] = Pinv[q];
            full_of_sym(Pinv, Pf);
            memset(Cp, 0, sizeof Cp);
            if (i + 1 < m) {
                full_of(AT(L, k, CENTRE + 1), Bf);
                mat_mul(Bf, Pf, 0, Cp);
                memcpy(Bp, Bf, sizeof Bf);
            }
            if (!L->closed)
                continue;
            if (i == m - 1) { /* node m - 1 meets the last node along the row */
                full_of(AT(L, k, CENTRE + 1), Bf);
                for (int q = 0; q < 9; q++)
                    f[q] += Bf[q];
            }
            mat_mul(f, Pf, 0, Ff); /* F_i = f_i D_i^-1; the last pivot loses F_i f_i^T */
            for (int q = 0; q < 9; q++)
                oF[q] = Ff[q];
            mat_mul(Ff, f, 1, U);
            sym_sub_full(Pl, U);
            if (i + 1 < m) { /* the last node's coupling to node i + 1: -F_i A_{i,i+1} */
                mat_mul(Ff, Bp, 0, U);
                for (int q = 0; q < 9; q++)
                    f[q] = -U[q];
            }
        }
        if (!L->closed)
            return 0;
        double *o = L->dinv + WS_SYM * (k0 + (size_t)m);
        memset(o, 0, WS_SYM * sizeof(double));
        memset(L->lff + 9 * (k0 + (size_t)m), 0, 9 * sizeof(double));
        double Pinv[WS_SYM];
        if (Pl[WS_SYM_XX] == 0.0 && Pl[WS_SYM_YY] == 0.0 && Pl[WS_SYM_ZZ] == 0.0) {
            o[WS_SYM_XX] = o[WS_SYM_YY] = o[WS_SYM_ZZ] = 1.0;
            return 0;
        }
        if (ws_sym_invert(Pl, Pinv) != 0)
            return -1;
        for (int q = 0; q < WS_SYM; q++)
            o[q] = Pinv[q];
    }
    return 0;
}

/* Whether row iy of coarse level L is to be solved whole. For each node and each direction of
 * motion q, the quotient v^T A v / v^T D v of the error that is constant along the row about
 * the node and alternates from row to row: the node's diagonal entry q q and its couplings
 * along the row, less those to the rows beside it (the mode's sign flips there), over the
 * diagonal entry: point Jacobi takes 1 - that off such an error a sweep. Where the row is held
 * along itself far more strongly than by its mass and the rows beside it the quotient is
 * small; docs/theory.md 8a derives why it falls under refinement in the rows weakly held up.
 * The row is solved whole when the mean over its nodes of their least quotient (over q: the
 * faces of a band turn its directions; at most 1, a node cleared in one sweep) is under
 * MG_LINE_RHO. */
static int row_held_along(const mg_level *L, int iy)
{
    const int nx = L->nx;
    double sum = 0.0;
    for (int ix = 0; ix < nx; ix++) {
        const size_t k = (size_t)nx * (size_t)iy + (size_t)ix;
        const int xl = ix > 0 ? ix - 1 : L->closed ? nx - 1 : -1;
        const int xr = ix + 1 < nx ? ix + 1 : L->closed ? 0 : -1;
        double least = 1.0;
        for (int q = 0; q < 3; q++) { /* WS_SYM_XX, YY, ZZ */
            const double d = AT(L, k, CENTRE)[q];
            double a = d;
            if (xr >= 0)
                a += AT(L, k, CENTRE + 1)[q];
            if (xl >= 0)
                a += AT(L, k - (size_t)ix + (size_t)xl, CENTRE + 1)[q];
            if (iy + 1 < L->ny)
                for (int o = 6; o < 9; o++)
                    a -= AT(L, k, o)[q];
            if (iy > 0) {
                const size_t b = k - (size_t)nx;
                a -= AT(L, b, 7)[q];
                if (xl >= 0)
                    a -= AT(L, b - (size_t)ix + (size_t)xl, 8)[q];
                if (xr >= 0)
                    a -= AT(L, b - (size_t)ix + (size_t)xr, 6)[q];
            }
            if (d > 0.0 && a < least * d)
                least = a / d;
        }
        sum += least;
    }
    return sum < MG_LINE_RHO * nx;
}

/* The point sweeps' factor of row iy of coarse level L: each node's own block's inverse, or
 * the identity for a node no fine node reaches (its right-hand side is always zero). 0, or -1
 * when a block is not positive definite. */
static int point_factor(mg_level *L, int iy)
{
    for (uint32_t i = (uint32_t)L->nx * (uint32_t)iy; i < (uint32_t)L->nx * (uint32_t)(iy + 1);
         i++) {
        double *o = L->dinv + WS_SYM * (size_t)i, S[WS_SYM];
        block_of(AT(L, i, CENTRE), S);
        if (S[WS_SYM_XX] == 0.0 && S[WS_SYM_YY] == 0.0 && S[WS_SYM_ZZ] == 0.0) {
            memset(o, 0, WS_SYM * sizeof(double));
            o[WS_SYM_XX] = o[WS_SYM_YY] = o[WS_SYM_ZZ] = 1.0;
        } else if (ws_sym_invert(S, o) != 0) {
            return -1;
        }
    }
    return 0;
}

/* The bodies' rows of the coarsest level's dense matrix D (m unknowns, the bodies' after the
 * nodes'): their block A_bb whole (the masses, the film's contacts' J^T C J and the pairs'
 * blocks, between two bodies too: the bodies are the same unknowns on every level) and the
 * nodes' coupling entries in both triangles. */
static void coarsest_bodies(const ws_mg *mg, const mg_level *L, double *D, uint32_t m)
{
    const uint32_t m0 = mg->m;
    const size_t nb6 = 6 * (size_t)mg->nb;
    for (size_t a = 0; a < nb6; a++)
        memcpy(D + (m0 + a) * m + m0, mg->rig->abb + nb6 * a, nb6 * sizeof(double));
    for (size_t e = 0; e < L->ng; e++) {
        const double *G = L->G + 18 * e;
        const size_t i = 3 * (size_t)L->gn[e], o = m0 + 6 * (size_t)L->gb[e];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 6; c++) {
                D[(i + (size_t)r) * m + o + (size_t)c] = G[6 * r + c];
                D[(o + (size_t)c) * m + i + (size_t)r] = G[6 * r + c];
            }
    }
}

/* The coarsest level's dense matrix and its Cholesky factor. 0, or -1 when it is not positive
 * definite. */
static int factor_coarsest(ws_mg *mg)
{
    const mg_level *L = &mg->lv[mg->nlev - 1];
    const uint32_t m = mg->m + 6 * mg->nb;
    double *D = mg->nb ? mg->bchol : mg->chol;
    memset(D, 0, (size_t)m * m * sizeof(double));
    if (mg->nb)
        coarsest_bodies(mg, L, D, m);
    int64_t nb[9];
    for (int iy = 0; iy < L->ny; iy++)
        for (int ix = 0; ix < L->nx; ix++) {
            const uint32_t i = (uint32_t)ix + (uint32_t)L->nx * (uint32_t)iy;
            const float *own = AT(L, i, CENTRE);
            if (own[WS_SYM_XX] == 0.0f && own[WS_SYM_YY] == 0.0f &&
                own[WS_SYM_ZZ] == 0.0f) { /* unreached: identity */
                for (int k = 0; k < 3; k++)
                    D[(3 * (size_t)i + k) * m + 3 * i + k] = 1.0;
                continue;
            }
            neighbours(L, ix, iy, nb);
            for (int o = CENTRE; o < 9; o++) { /* the block and its mirror */
                if (nb[o] < 0)
                    continue;
                const size_t j = (size_t)nb[o];
                double B[9];
                const float *S = AT(L, i, o);
                B[0] = S[WS_SYM_XX], B[1] = S[WS_SYM_XY], B[2] = S[WS_SYM_XZ];
                B[3] = S[WS_SYM_XY], B[4] = S[WS_SYM_YY], B[5] = S[WS_SYM_YZ];
                B[6] = S[WS_SYM_XZ], B[7] = S[WS_SYM_YZ], B[8] = S[WS_SYM_ZZ];
                for (int r = 0; r < 3; r++)
                    for (int col = 0; col < 3; col++) {
                        D[(3 * (size_t)i + r) * m + 3 * j + col] += B[3 * r + col];
                        if (o != CENTRE)
                            D[(3 * j + col) * m + 3 * (size_t)i + r] += B[3 * r + col];
                    }
            }
        }
    for (uint32_t j = 0; j < m; j++) {
        double d = D[(size_t)j * m + j];
        for (uint32_t k = 0; k < j; k++)
            d -= D[(size_t)j * m + k] * D[(size_t)j * m + k];
        if (!(d > 0.0) || !isfinite(d))
            return -1;
        const double l = sqrt(d), il = 1.0 / l;
        D[(size_t)j * m + j] = l;
        for (uint32_t i = j + 1; i < m; i++) {
            double s = D[(size_t)i * m + j];
            for (uint32_t k = 0; k < j; k++)
                s -= D[(size_t)i * m + k] * D[(size_t)j * m + k];
            D[(size_t)i * m + j] = s * il;
        }
    }
    return 0;
}

/* A contact's coupling -C J (3x6 row-major; J = [I, -[r]x], so column 3 + k is -C (e_k x r)). */
static void link_coupling(const ws_rigid_link *L, double *G)
{
    const v3 r = L->lever;
    for (int c = 0; c < 6; c++) {
        const v3 e = v3_make(c % 3 == 0, c % 3 == 1, c % 3 == 2);
        const v3 a = c < 3 ? e : v3_cross(e, r);
        double g[3] = {0.0, 0.0, 0.0};
        ws_sym_madd(L->C, a.x, a.y, a.z, g);
        for (int q = 0; q < 3; q++)
            G[6 * q + c] = -g[q];
    }
}

/* Level c's entries from the pairs marked in mg->mark (node-major, bodies in order), their
 * blocks zeroed; mark then holds each pair's entry + 1. */
static void entries_of_marks(const ws_mg *mg, mg_level *c)
{
    const uint32_t nb = mg->nb;
    uint32_t e = 0;
    for (uint32_t i = 0; i < c->n; i++) {
        c->gs[i] = e;
        for (uint32_t j = 0; j < nb; j++) {
            uint32_t *k = &mg->mark[(size_t)i * nb + j];
            if (!*k)
                continue;
            c->gn[e] = i;
            c->gb[e] = j;
            *k = ++e;
        }
    }
    c->gs[c->n] = e;
    c->ng = e;
    memset(c->G, 0, 18 * (size_t)e * sizeof(double));
}

/* G += w S for 3x6 blocks. */
static inline void g_axpy(double *G, double w, const double *S)
{
    for (int q = 0; q < 18; q++)
        G[q] += w * S[q];
}

/* The bodies' coupling on every coarse level, kept for the (node, body) pairs that have one:
 * level 1's is P^T (-C J) over the contacts, level k + 1's P^T of level k's (P acts on the
 * nodes alone: a body's unknowns are the same on every level). Each level is gathered in two
 * passes, the pairs marked, then the blocks summed; a level's pairs fit the room
 * ws_mg_body_bytes gives (pairs_room), and on a wrapped band they are about its nodes, each
 * near one box. */
static void galerkin_bodies(ws_mg *mg, const ws_web *web)
{
    const uint32_t nb = mg->nb;
    const ws_rigid *R = mg->rig;
    mg_level *c = &mg->lv[1];
    pmap p;
    double G0[18];
    memset(mg->mark, 0, (size_t)c->n * nb * sizeof(uint32_t));
    for (size_t l = 0; l < R->nl; l++) {
        film_pmap(mg, web, R->link[l].node, &p);
        for (int i = 0; i < p.n; i++)
            mg->mark[(size_t)p.idx[i] * nb + R->link[l].body] = 1;
    }
    entries_of_marks(mg, c);
    for (size_t l = 0; l < R->nl; l++) {
        const ws_rigid_link *L = &R->link[l];
        film_pmap(mg, web, L->node, &p);
        if (!p.n)
            continue;
        link_coupling(L, G0);
        for (int i = 0; i < p.n; i++)
            g_axpy(c->G + 18 * ((size_t)mg->mark[(size_t)p.idx[i] * nb + L->body] - 1),
                   p.w[i], G0);
    }
    for (int k = 1; k + 1 < mg->nlev; k++) {
        const mg_level *f = &mg->lv[k];
        c = &mg->lv[k + 1];
        memset(mg->mark, 0, (size_t)c->n * nb * sizeof(uint32_t));
        for (int pass = 0; pass < 2; pass++) {
            for (size_t e = 0; e < f->ng; e++) {
                const uint32_t i = f->gn[e], j = f->gb[e];
                pmap_of(f, c, (int)(i % (uint32_t)f->nx), (int)(i / (uint32_t)f->nx), &p);
                for (int a = 0; a < p.n; a++) {
                    uint32_t *mk = &mg->mark[(size_t)p.idx[a] * nb + j];
                    if (pass == 0)
                        *mk = 1;
                    else
                        g_axpy(c->G + 18 * ((size_t)*mk - 1), p.w[a], f->G + 18 * e);
                }
            }
            if (pass == 0)
                entries_of_marks(mg, c);
        }
    }
}

/* The room for level k's (node, body) pairs with nb bodies and nl contacts: at most its nodes
 * times the bodies, and at most 4 a pair of the level above (a row of P has at most four
 * coarse nodes), level 1's 4 a contact. */
static size_t pairs_room(const ws_mg *mg, int k, uint32_t nb, size_t nl)
{
    size_t room = nl;
    for (int i = 1; i <= k; i++) {
        const size_t all = (size_t)mg->lv[i].n * nb;
        room = 4 * room < all ? 4 * room : all;
    }
    return room;
}

size_t ws_mg_body_bytes(const ws_mg *mg, uint32_t nb, size_t nl)
{
    if (!mg || !nb || nb > WS_MG_NEST_BODIES_MAX)
        return 0;
    const size_t m = mg->m + 6 * (size_t)nb;
    size_t d = m * m + m + 18 * (size_t)nb + 6 * (size_t)nb * (mg->nblk + (size_t)mg->lv[1].ny) +
               mg->nblk + 1,
           u = (size_t)mg->lv[1].n * nb;
    for (int k = 1; k < mg->nlev; k++) {
        const size_t pairs = pairs_room(mg, k, nb, nl);
        d += 12 * (size_t)nb + 18 * pairs;
        u += (size_t)mg->lv[k].n + 1 + 2 * pairs;
    }
    return d * sizeof(double) + u * sizeof(uint32_t) + sizeof(double);
}

int ws_mg_bodies(ws_mg *mg, const ws_rigid *R, void *buf)
{
    mg->nb = 0;
    mg->rig = NULL;
    if (!R || !buf || !R->nb || R->nb > WS_MG_NEST_BODIES_MAX || R->nl > R->cap)
        return 0;
    for (size_t l = 1; l < R->nl; l++) /* the film level walks them in node order */
        if (R->link[l].node < R->link[l - 1].node)
            return 0;
    mg->nb = R->nb;
    mg->rig = R;
    const uint32_t nb = mg->nb;
    const size_t m = mg->m + 6 * (size_t)nb;
    /* doubles first, from the buffer's first 8-aligned byte; then the indices */
    double *q = (double *)(((uintptr_t)buf + 7) & ~(uintptr_t)7);
    mg->bchol = q, q += m * m;
    mg->bsc = q, q += m;
    mg->brz = q, q += 12 * (size_t)nb;
    mg->bsum = q, q += 6 * (size_t)nb;
    mg->bpart = q, q += 6 * (size_t)nb * mg->nblk;
    mg->rpart = q, q += 6 * (size_t)nb * (size_t)mg->lv[1].ny;
    mg->lstart = (size_t *)(void *)q, q += mg->nblk + 1;
    ws_rigid_block_starts(R, mg->blocks, mg->nblk, mg->lstart);
    for (int k = 1; k < mg->nlev; k++) {
        mg_level *L = &mg->lv[k];
        L->xb = q, q += 6 * (size_t)nb;
        L->rb = q, q += 6 * (size_t)nb;
    }
    for (int k = 1; k < mg->nlev; k++) {
        mg_level *L = &mg->lv[k];
        L->gcap = pairs_room(mg, k, nb, R->cap);
        L->G = q, q += 18 * L->gcap;
    }
    uint32_t *u = (uint32_t *)q;
    mg->mark = u, u += (size_t)mg->lv[1].n * nb;
    for (int k = 1; k < mg->nlev; k++) {
        mg_level *L = &mg->lv[k];
        L->gs = u, u += L->n + 1;
        L->gn = u, u += L->gcap;
        L->gb = u, u += L->gcap;
    }
    return 1;
}



int ws_mg_setup(ws_mg *mg, const ws_web *web, uint64_t begun, double h)
{
    if (!mg->springs_kept || begun != mg->kept_begun || h != mg->kept_h) {
        galerkin_springs(mg, web, h);
        mg->springs_kept = 1;
        mg->kept_begun = begun;
        mg->kept_h = h;
    }
    const ws_implicit *im = web->imp;
    for (size_t q = 0; q < WS_SYM * (size_t)web->n; q++) {
        mg->fnd[q] = (float)im->nd[q];
        mg->fpinv[q] = (float)(MG_OMEGA * im->pinv[q]);
    }
    galerkin_film(mg, web, h);
    store_level(mg, 1);
    for (int k = 1; k + 1 < mg->nlev; k++) {
        galerkin_level(mg, k);
        store_level(mg, k + 1);
    }
    for (int k = 1; k + 1 < mg->nlev; k++) {
        mg_level *L = &mg->lv[k];
        L->lines = 0;
        for (int iy = 0; iy < L->ny; iy++) {
            L->whole[iy] = (unsigned char)row_held_along(L, iy);
            L->lines += L->whole[iy];
            if ((L->whole[iy] ? line_factor(L, iy) : point_factor(L, iy)) != 0)
                return -1;
        }
    }
    if (mg->nb)
        galerkin_bodies(mg, web);
    return factor_coarsest(mg);
}

/* A_kj of coarse level L for k's neighbour j in slot o (o != CENTRE). */
static inline const float *off_block(const mg_level *L, size_t k, int o, int64_t j)
{
    return o > CENTRE ? AT(L, k, o) : AT(L, (size_t)j, 8 - o);
}

/* s -= G u for a coupling block G (3x6 row-major) and a body's u (6). */
static inline void g_sub(const double *G, const double *u, double *s)
{
    for (int r = 0; r < 3; r++) {
        const double *g = G + 6 * r;
        s[r] -= g[0] * u[0] + g[1] * u[1] + g[2] * u[2] + g[3] * u[3] + g[4] * u[4] +
                g[5] * u[5];
    }
}

/* s -= G^T x for a coupling block G and a node's x (3) into a body's s (6). */
static inline void gt_sub(const double *G, const double *x, double *s)
{
    for (int c = 0; c < 6; c++)
        s[c] -= G[c] * x[0] + G[6 + c] * x[1] + G[12 + c] * x[2];
}

/* o -= M x (tr: M^T x) for a full 3x3 block M. */
static inline void fmat_sub(const double *M, int tr, const double *x, double *o)
{
    if (tr) {
        o[0] -= M[0] * x[0] + M[3] * x[1] + M[6] * x[2];
        o[1] -= M[1] * x[0] + M[4] * x[1] + M[7] * x[2];
        o[2] -= M[2] * x[0] + M[5] * x[1] + M[8] * x[2];
    } else {
        o[0] -= M[0] * x[0] + M[1] * x[1] + M[2] * x[2];
        o[1] -= M[3] * x[0] + M[4] * x[1] + M[5] * x[2];
        o[2] -= M[6] * x[0] + M[7] * x[1] + M[8] * x[2];
    }
}

/* The line solve's forward step at node ix of a row (X: the row's x, holding its right-hand
 * side s up to ix): g_ix = s_ix - A_{ix,ix-1} D_{ix-1}^-1 g_{ix-1}, and on a closed row the
 * last node's g_m = s_m - sum F_i g_i (the sum gathered in acc as the row goes). */
static inline void line_down(const mg_level *L, size_t k0, int ix, double *X, double *acc)
{
    const int m = L->closed ? L->nx - 1 : L->nx;
    double *Xi = X + 3 * (size_t)ix;
    if (ix == m) { /* the closed row's last node */
        Xi[0] += acc[0], Xi[1] += acc[1], Xi[2] += acc[2];
        return;
    }
    if (ix > 0) {
        double u[3] = {0.0, 0.0, 0.0};
        const double *D = L->dinv + WS_SYM * (k0 + (size_t)ix - 1);
        ws_sym_madd(D, Xi[-3], Xi[-2], Xi[-1], u);
        fsym_sub(AT(L, k0 + (size_t)ix - 1, CENTRE + 1), u, Xi);
    }
    if (L->closed)
        fmat_sub(L->lff + 9 * (k0 + (size_t)ix), 0, Xi, acc);
}

/* The line solve's backward step at node ix (the nodes after it, and the last, solved):
 * x_ix = D^-1 (g_ix - A_{ix,ix+1} x_{ix+1}) - F_ix^T x_m. */
static inline void line_up(const mg_level *L, size_t k0, int ix, double *X)
{
    const int m = L->closed ? L->nx - 1 : L->nx;
    const double *o = L->dinv + WS_SYM * (k0 + (size_t)ix);
    double *Xi = X + 3 * (size_t)ix;
    double g[3] = {Xi[0], Xi[1], Xi[2]};
    if (ix + 1 < m)
        fsym_sub(AT(L, k0 + (size_t)ix, CENTRE + 1), Xi + 3, g);
    const double xx = o[WS_SYM_XX], yy = o[WS_SYM_YY], zz = o[WS_SYM_ZZ], xy = o[WS_SYM_XY],
                 xz = o[WS_SYM_XZ], yz = o[WS_SYM_YZ];
    Xi[0] = xx * g[0] + xy * g[1] + xz * g[2];
    Xi[1] = xy * g[0] + yy * g[1] + yz * g[2];
    Xi[2] = xz * g[0] + yz * g[1] + zz * g[2];
    if (ix < m && L->closed)
        fmat_sub(L->lff + 9 * (k0 + (size_t)ix), 1, X + 3 * (size_t)m, Xi);
}

/* The neighbours of (ix, iy) on level L in the row iy + dy (dy -1 or 1), by dx = -1, 0, 1
 * (slots 3 (dy + 1) + dx + 1); -1 beyond the grid's edge. */
static inline void row_beside(const mg_level *L, int ix, int iy, int dy, int64_t *j)
{
    const int jy = iy + dy;
    if (jy < 0 || jy >= L->ny) {
        j[0] = j[1] = j[2] = -1;
        return;
    }
    const int64_t b = (int64_t)L->nx * jy;
    j[0] = ix > 0 ? b + ix - 1 : L->closed ? b + L->nx - 1 : -1;
    j[1] = b + ix;
    j[2] = ix + 1 < L->nx ? b + ix + 1 : L->closed ? b : -1;
}

/* A coarse level's rows are swept in two colours: forward the even rows, then the odd ones;
 * backward the odd rows, then the even ones, each row's nodes in reverse (the forward sweep's
 * exact reverse, so that B_k stays symmetric). The stencil reaches the rows beside a row alone,
 * so the rows of one colour do not meet: they run on the workers at once, and the sweep is the
 * same whatever their number (the bodies' sums are each row's, added in the sweep's order). In
 * the forward sweep from x = 0 an even row meets no other row (the odd ones are still zero),
 * and an odd row both even rows beside it (KNOWN_BELOW | KNOWN_ABOVE). */
enum { KNOWN_BELOW = 1, KNOWN_ABOVE = 2 };

/* Whether node k's neighbour j in slot o is known in a forward sweep: one before it in its
 * row, or in a row beside that `known` names. */
static inline int known_before(int64_t k, int o, int64_t j, int known)
{
    const int dy = o / 3 - 1;
    if (j < 0)
        return 0;
    if (dy == 0)
        return j < k;
    return (known & (dy < 0 ? KNOWN_BELOW : KNOWN_ABOVE)) != 0;
}

/* s -= A_kj x_j over node (ix, iy)'s neighbours in the rows beside that `known` names. */
static inline void rows_take(const mg_level *L, int ix, int iy, int known, double *s)
{
    const int64_t k = ix + (int64_t)L->nx * iy;
    int64_t j[3];
    for (int dy = -1; dy <= 1; dy += 2) {
        if (!(known & (dy < 0 ? KNOWN_BELOW : KNOWN_ABOVE)))
            continue;
        row_beside(L, ix, iy, dy, j);
        for (int o = 0; o < 3; o++)
            if (j[o] >= 0)
                fsym_sub(off_block(L, (size_t)k, 3 * (dy + 1) + o, j[o]), L->x + 3 * (size_t)j[o],
                         s);
    }
}

/* Forward, row iy solved whole (its factor from line_factor) against the rows beside it that
 * `known` names and the bodies; the bodies take -G^T x into rbn (NULL: none). The row itself is
 * solved exactly: its own couplings leave nothing in t. */
static void line_row_forward(const ws_mg *mg, mg_level *L, int iy, int known, int write_below,
                             double *rbn)
{
    const size_t nb6 = 6 * (size_t)mg->nb;
    const size_t k0 = (size_t)L->nx * (size_t)iy;
    double *Xr = L->x + 3 * k0, acc[3] = {0.0, 0.0, 0.0};
    for (int ix = 0; ix < L->nx; ix++) {
        const int64_t k = (int64_t)k0 + ix;
        const double *R = L->r + 3 * (size_t)k;
        double *X = L->x + 3 * (size_t)k;
        X[0] = R[0], X[1] = R[1], X[2] = R[2];
        rows_take(L, ix, iy, known, X);
        const uint32_t e0 = nb6 ? L->gs[k] : 0, e1 = nb6 ? L->gs[k + 1] : 0;
        for (uint32_t e = e0; e < e1; e++)
            g_sub(L->G + 18 * (size_t)e, L->xb + 6 * (size_t)L->gb[e], X);
        line_down(L, k0, ix, Xr, acc);
    }
    for (int ix = L->nx - 1; ix >= 0; ix--) {
        const int64_t k = (int64_t)k0 + ix;
        line_up(L, k0, ix, Xr);
        const double *X = L->x + 3 * (size_t)k;
        if (write_below) { /* t_j -= A_jk x_k for the row before in the chunk */
            int64_t j[3];
            row_beside(L, ix, iy, -1, j);
            for (int o = 0; o < 3; o++)
                if (j[o] >= 0)
                    fsym_sub(AT(L, (size_t)j[o], 8 - o), X, L->t + 3 * (size_t)j[o]);
        }
        const uint32_t e0 = nb6 ? L->gs[k] : 0, e1 = nb6 ? L->gs[k + 1] : 0;
        for (uint32_t e = e0; e < e1; e++)
            gt_sub(L->G + 18 * (size_t)e, X, rbn + 6 * (size_t)L->gb[e]);
    }
}

/* Backward, row iy solved whole against both rows beside it and the bodies; its new x taken
 * off the bodies' right-hand side sb. */
static void line_row_backward(const ws_mg *mg, mg_level *L, int iy, double *sb)
{
    const size_t nb6 = 6 * (size_t)mg->nb;
    const size_t k0 = (size_t)L->nx * (size_t)iy;
    double *Xr = L->x + 3 * k0, acc[3] = {0.0, 0.0, 0.0};
    int64_t j[9];
    for (int ix = 0; ix < L->nx; ix++) {
        const int64_t k = (int64_t)k0 + ix;
        row_beside(L, ix, iy, -1, j);
        row_beside(L, ix, iy, 1, j + 6);
        const double *R = L->r + 3 * (size_t)k;
        double *X = L->x + 3 * (size_t)k;
        X[0] = R[0], X[1] = R[1], X[2] = R[2];
        for (int o = 0; o < 3; o++) {
            if (j[o] >= 0)
                fsym_sub(AT(L, (size_t)j[o], 8 - o), L->x + 3 * (size_t)j[o], X);
            if (j[6 + o] >= 0)
                fsym_sub(AT(L, (size_t)k, 6 + o), L->x + 3 * (size_t)j[6 + o], X);
        }
        const uint32_t e0 = nb6 ? L->gs[k] : 0, e1 = nb6 ? L->gs[k + 1] : 0;
        for (uint32_t e = e0; e < e1; e++)
            g_sub(L->G + 18 * (size_t)e, L->xb + 6 * (size_t)L->gb[e], X);
        line_down(L, k0, ix, Xr, acc);
    }
    for (int ix = L->nx - 1; ix >= 0; ix--) {
        const int64_t k = (int64_t)k0 + ix;
        line_up(L, k0, ix, Xr);
        const uint32_t e0 = nb6 ? L->gs[k] : 0, e1 = nb6 ? L->gs[k + 1] : 0;
        for (uint32_t e = e0; e < e1; e++)
            gt_sub(L->G + 18 * (size_t)e, L->x + 3 * (size_t)k, sb + 6 * (size_t)L->gb[e]);
    }
}

/* x_k = D_k^-1 s (the inverse of the node's own block, point_factor). */
static inline void gs_solve(const mg_level *L, int64_t k, const double *s)
{
    const double *S = L->dinv + WS_SYM * (size_t)k;
    double *X = L->x + 3 * (size_t)k;
    X[0] = X[1] = X[2] = 0.0;
    ws_sym_madd(S, s[0], s[1], s[2], X);
}

/* Forward, row iy node by node: a node meets the nodes known before it (known_before) and the
 * bodies; each node before it in its row takes -A_jk x_k into t (with the block its own solve
 * has just read; the rows beside gather theirs, row_gather), the bodies -G^T x_k into rbn. */
static void point_row_forward(const ws_mg *mg, mg_level *L, int iy, int known, int write_below,
                              double *rbn)
{
    const size_t nb6 = 6 * (size_t)mg->nb;
    for (int ix = 0; ix < L->nx; ix++) {
        const int64_t k = ix + (int64_t)L->nx * iy;
        int64_t j[9];
        neighbours(L, ix, iy, j);
        const double *R = L->r + 3 * (size_t)k;
        double s[3] = {R[0], R[1], R[2]};
        const float *B[9];
        for (int o = 0; o < 9; o++) {
            B[o] = NULL;
            if (o == CENTRE || !known_before(k, o, j[o], known))
                continue;
            B[o] = off_block(L, (size_t)k, o, j[o]);
            fsym_sub(B[o], L->x + 3 * (size_t)j[o], s);
        }
        const uint32_t e0 = nb6 ? L->gs[k] : 0, e1 = nb6 ? L->gs[k + 1] : 0;
        for (uint32_t e = e0; e < e1; e++)
            g_sub(L->G + 18 * (size_t)e, L->xb + 6 * (size_t)L->gb[e], s);
        gs_solve(L, k, s);
        const double *X = L->x + 3 * (size_t)k;
        for (int o = write_below ? 0 : CENTRE - 1; o <= CENTRE + 1; o++)
            if (B[o]) /* t_j -= A_jk x_k, A_jk = A_kj */
                fsym_sub(B[o], X, L->t + 3 * (size_t)j[o]);
        for (uint32_t e = e0; e < e1; e++)
            gt_sub(L->G + 18 * (size_t)e, X, rbn + 6 * (size_t)L->gb[e]);
    }
}

/* Backward, row iy node by node in reverse: a node meets every neighbour and the bodies, and
 * its new x is taken off the bodies' right-hand side sb. */
static void point_row_backward(const ws_mg *mg, mg_level *L, int iy, double *sb)
{
    const size_t nb6 = 6 * (size_t)mg->nb;
    for (int ix = L->nx - 1; ix >= 0; ix--) {
        const int64_t k = ix + (int64_t)L->nx * iy;
        int64_t j[9];
        neighbours(L, ix, iy, j);
        const double *R = L->r + 3 * (size_t)k;
        double s[3] = {R[0], R[1], R[2]};
        for (int o = 0; o < 9; o++)
            if (o != CENTRE && j[o] >= 0)
                fsym_sub(off_block(L, (size_t)k, o, j[o]), L->x + 3 * (size_t)j[o], s);
        const uint32_t e0 = nb6 ? L->gs[k] : 0, e1 = nb6 ? L->gs[k + 1] : 0;
        for (uint32_t e = e0; e < e1; e++)
            g_sub(L->G + 18 * (size_t)e, L->xb + 6 * (size_t)L->gb[e], s);
        gs_solve(L, k, s);
        const double *X = L->x + 3 * (size_t)k;
        for (uint32_t e = e0; e < e1; e++)
            gt_sub(L->G + 18 * (size_t)e, X, sb + 6 * (size_t)L->gb[e]);
    }
}

/* A coarse level's rows in chunks of MG_CHUNK_ROWS, chunk c rows [c R, (c + 1) R). */
#define MG_CHUNK_ROWS 8

static int chunk_count(const mg_level *L)
{
    return (L->ny + MG_CHUNK_ROWS - 1) / MG_CHUNK_ROWS;
}

/* One colour of a coarse level's sweep (sweep_chunks): chunk 2 i + colour for item i. */
typedef struct sweep_pass {
    const ws_mg *mg;
    mg_level *L;
    int colour, forward;
} sweep_pass;

/* The bodies' share of row iy in a sweep (6 nb doubles; NULL without bodies). */
static double *row_part(const ws_mg *mg, int iy)
{
    return mg->nb ? mg->rpart + 6 * (size_t)mg->nb * (size_t)iy : NULL;
}

static void sweep_chunk(void *ctx, uint32_t i)
{
    const sweep_pass *P = ctx;
    const ws_mg *mg = P->mg;
    mg_level *L = P->L;
    const int c = 2 * (int)i + P->colour, y0 = c * MG_CHUNK_ROWS;
    const int y1 = y0 + MG_CHUNK_ROWS < L->ny ? y0 + MG_CHUNK_ROWS : L->ny;
    for (int q = 0; q < y1 - y0; q++) {
        const int iy = P->forward ? y0 + q : y1 - 1 - q;
        double *part = row_part(mg, iy);
        if (part)
            memset(part, 0, 6 * (size_t)mg->nb * sizeof(double));
        if (!P->forward) {
            if (L->whole[iy])
                line_row_backward(mg, L, iy, part);
            else
                point_row_backward(mg, L, iy, part);
            continue;
        }
        /* The row below is known within the chunk, or in an even chunk below an odd one; the
         * row above only in an even chunk above an odd one. */
        const int inside = iy > y0, odd = P->colour;
        const int known =
            (inside || odd ? KNOWN_BELOW : 0) | (iy + 1 == y1 && odd ? KNOWN_ABOVE : 0);
        if (L->whole[iy])
            line_row_forward(mg, L, iy, known, inside, part);
        else
            point_row_forward(mg, L, iy, known, inside, part);
    }
}

/* After the forward sweep, an even chunk's edge rows take -A_kj x_j from the odd chunks' rows
 * beside them. */
static void gather_chunk(void *ctx, uint32_t i)
{
    const sweep_pass *P = ctx;
    mg_level *L = P->L;
    const int y0 = 2 * (int)i * MG_CHUNK_ROWS;
    const int y1 = y0 + MG_CHUNK_ROWS < L->ny ? y0 + MG_CHUNK_ROWS : L->ny;
    for (int e = 0; e < 2; e++) {
        const int iy = e ? y1 - 1 : y0, known = e ? KNOWN_ABOVE : KNOWN_BELOW;
        for (int ix = 0; ix < L->nx; ix++)
            rows_take(L, ix, iy, known, L->t + 3 * ((size_t)ix + (size_t)L->nx * (size_t)iy));
    }
}

/* The chunks of a colour on the workers, a level large enough to share (a smaller one's on
 * this thread: the same sums either way). */
#define MG_SHARED_NODES 256

static void sweep_chunks(const ws_mg *mg, const ws_runner *run, mg_level *L, int colour,
                         int forward, ws_item_fn *fn)
{
    sweep_pass P = {mg, L, colour, forward};
    const uint32_t chunks = (uint32_t)((chunk_count(L) - colour + 1) / 2);
    ws_runner_for(L->n >= MG_SHARED_NODES ? run : NULL, chunks, fn, &P);
}

/* out = base + the rows' shares in a forward sweep's order (the even chunks' rows, then the odd
 * chunks'; backward: its reverse). */
static void rows_sum(const ws_mg *mg, const mg_level *L, int forward, const double *base,
                     double *out)
{
    const size_t nb6 = 6 * (size_t)mg->nb;
    if (base)
        memcpy(out, base, nb6 * sizeof(double));
    else
        memset(out, 0, nb6 * sizeof(double));
    const int chunks = chunk_count(L);
    for (int pass = 0; pass < 2; pass++) {
        const int colour = forward ? pass : 1 - pass;
        for (int k = 0; k < chunks; k++) {
            const int c = forward ? k : chunks - 1 - k;
            if ((c & 1) != colour)
                continue;
            for (int q = 0; q < MG_CHUNK_ROWS; q++) {
                const int iy = forward ? c * MG_CHUNK_ROWS + q : (c + 1) * MG_CHUNK_ROWS - 1 - q;
                if (iy >= L->ny)
                    continue;
                const double *part = row_part(mg, iy);
                for (size_t z = 0; z < nb6; z++)
                    out[z] += part[z];
            }
        }
    }
}

/* The sweeps of symmetric block Gauss-Seidel on a coarse level L, the blocks a level's rows
 * solved whole (L->whole) and its other nodes one by one, the rows in two colours (above):
 * the bodies nested (mg->nb) first in the forward sweep and last in the backward one, which
 * takes the same blocks in reverse, so that the two mirror each other (B_k symmetric) and
 * every coupling term is taken in the node loops, where the node's x is at hand. Forward from
 * x = 0: the bodies from their right-hand side alone, then each block meets only the blocks
 * known before it (the others are still zero) and the bodies; the sweep leaves the residual
 * r - A x in t (each block's own couplings are solved exactly, so what is left at a node is
 * what the blocks after it add since: a row's later nodes as each is solved, the odd rows'
 * into the even rows' beside them at the end) and the bodies' residual, rb - A_bb xb - G^T x =
 * -G^T x, in rbn (the next level's: the bodies are the same unknowns there; A_bb is solved
 * whole, the pairs' coupling between bodies with it, or that residual would keep it). */
static void gauss_seidel_forward(const ws_mg *mg, const ws_runner *run, mg_level *L, double *rbn)
{
    memset(L->t, 0, 3 * (size_t)L->n * sizeof(double));
    if (mg->nb)
        ws_rigid_block_solve(mg->rig, L->rb, L->xb);
    sweep_chunks(mg, run, L, 0, 1, sweep_chunk);
    sweep_chunks(mg, run, L, 1, 1, sweep_chunk);
    sweep_chunks(mg, run, L, 0, 1, gather_chunk);
    if (mg->nb)
        rows_sum(mg, L, 1, NULL, rbn);
}

/* Backward from the x and xb there are: the blocks in reverse, each against every neighbour
 * and the bodies, its new x taken off the bodies' right-hand side (in mg->bsum), which they
 * are solved with at the end. */
static void gauss_seidel_backward(const ws_mg *mg, const ws_runner *run, mg_level *L)
{
    sweep_chunks(mg, run, L, 1, 0, sweep_chunk);
    sweep_chunks(mg, run, L, 0, 0, sweep_chunk);
    if (mg->nb) { /* the bodies last: xb = A_bb^-1 (rb - G^T x) */
        rows_sum(mg, L, 0, L->rb, mg->bsum);
        ws_rigid_block_solve(mg->rig, mg->bsum, L->xb);
    }
}

/* Whether fine node i of level k is left out of P (a pinned film node: its dv is zero). */
static inline int left_out(const ws_web *web, int k, uint32_t i)
{
    return k == 0 && !web->same_inv_m && web->inv_m[i] == 0.0;
}

/* Fine row iy of level k's t restricted along x into u (level k + 1's nx vectors). */
static void restrict_row(const ws_mg *mg, const ws_web *web, int k, const double *t, int iy,
                         double *u)
{
    const mg_level *f = &mg->lv[k];
    memset(u, 0, 3 * (size_t)mg->lv[k + 1].nx * sizeof(double));
    for (int ix = 0; ix < f->nx; ix++) {
        const uint32_t i = (uint32_t)ix + (uint32_t)f->nx * (uint32_t)iy;
        if (left_out(web, k, i))
            continue;
        const map1d *mx = &f->mx[ix];
        const double *T = t + 3 * (size_t)i;
        for (int a = 0; a < mx->n; a++) {
            double *U = u + 3 * (size_t)mx->c[a];
            const double w = mx->w[a];
            U[0] += w * T[0];
            U[1] += w * T[1];
            U[2] += w * T[2];
        }
    }
}

/* The film level's rows restricted along x, block by block, into rrow (restrict_to). */
typedef struct restrict_pass {
    const ws_mg *mg;
    const ws_web *web;
    const double *t;
} restrict_pass;

static void restrict_block(void *ctx, uint32_t b)
{
    const restrict_pass *P = ctx;
    const ws_mg *mg = P->mg;
    const uint32_t nx = (uint32_t)mg->lv[0].nx;
    const size_t row = 3 * (size_t)mg->lv[1].nx;
    for (uint32_t iy = mg->blocks[b].n0 / nx; iy < mg->blocks[b].n1 / nx; iy++)
        restrict_row(mg, P->web, 0, P->t, (int)iy, mg->rrow + row * iy);
}

/* c->r = P^T t (t a level-k vector; the film's pinned nodes left out). P is a map along x
 * times one along y: each fine row is restricted along x (the film's level's rows block by
 * block into rrow, a coarse level's into mg->row), then added to the coarse rows it maps to
 * in the rows' order. */
static void restrict_to(const ws_mg *mg, const ws_web *web, int k, const double *t)
{
    const mg_level *f = &mg->lv[k];
    const mg_level *c = &mg->lv[k + 1];
    const size_t row = 3 * (size_t)c->nx;
    if (k == 0) {
        restrict_pass P = {mg, web, t};
        ws_implicit_blocks_run(web->imp, restrict_block, &P);
    }
    memset(c->r, 0, 3 * (size_t)c->n * sizeof(double));
    for (int iy = 0; iy < f->ny; iy++) {
        double *u = k == 0 ? mg->rrow + row * (size_t)iy : mg->row;
        if (k != 0)
            restrict_row(mg, web, k, t, iy, u);
        const map1d *my = &f->my[iy];
        for (int b = 0; b < my->n; b++) {
            double *R = c->r + row * (size_t)my->c[b];
            const double w = my->w[b];
            for (size_t q = 0; q < row; q++)
                R[q] += w * u[q];
        }
    }
}

/* The film level's coupling to the nested bodies, taken inside its node passes: the solve's
 * contacts are sorted by node (ws_mg_bodies checks it), so a pass over the nodes walks them
 * with a cursor *l and meets node i's contacts when it is at node i, its z or t in hand. */
/* rbo += J^T C Z over node i's contacts (the bodies' residual takes -A_bf z). */
static MG_INLINE void node_to_bodies(const ws_rigid *R, size_t *l, uint32_t i, const double *Z,
                                  double *rbo)
{
    for (; *l < R->nl && R->link[*l].node == i; (*l)++) {
        const ws_rigid_link *L = &R->link[*l];
        double g[3] = {0.0, 0.0, 0.0};
        ws_sym_madd(L->C, Z[0], Z[1], Z[2], g);
        const v3 m = v3_cross(L->lever, v3_make(g[0], g[1], g[2]));
        double *o = rbo + 6 * (size_t)L->body;
        o[0] += g[0], o[1] += g[1], o[2] += g[2];
        o[3] += m.x, o[4] += m.y, o[5] += m.z;
    }
}

/* T += C J zb over node i's contacts (T, the film's residual, takes -A_fb zb). */
static MG_INLINE void bodies_to_node(const ws_rigid *R, size_t *l, uint32_t i, const double *zb,
                                  double *T)
{
    for (; *l < R->nl && R->link[*l].node == i; (*l)++) {
        const ws_rigid_link *L = &R->link[*l];
        const double *U = zb + 6 * (size_t)L->body;
        const v3 u = v3_add(v3_make(U[0], U[1], U[2]),
                            v3_cross(v3_make(U[3], U[4], U[5]), L->lever));
        ws_sym_madd(L->C, u.x, u.y, u.z, T);
    }
}

/* Fine row iy of level k: x += P x_c there, u the row's room (level k + 1's nx vectors); on
 * the film's level with r given, t = r - N x - A_fb zb over the row too, *l the contacts'
 * cursor. */
static MG_INLINE void prolong_row(const ws_mg *mg, const ws_web *web, int k, int iy, double *u,
                                  double *x, const double *r, double *t, const double *zb,
                                  size_t *l)
{
    const mg_level *f = &mg->lv[k];
    const mg_level *c = &mg->lv[k + 1];
    const map1d *my = &f->my[iy];
    const double *C0 = c->x + 3 * (size_t)c->nx * (size_t)my->c[0];
    if (my->n == 1) {
        memcpy(u, C0, 3 * (size_t)c->nx * sizeof(double));
    } else {
        const double *C1 = c->x + 3 * (size_t)c->nx * (size_t)my->c[1];
        const double w0 = my->w[0], w1 = my->w[1];
        for (size_t q = 0; q < 3 * (size_t)c->nx; q++)
            u[q] = w0 * C0[q] + w1 * C1[q];
    }
    for (int ix = 0; ix < f->nx; ix++) {
        const uint32_t i = (uint32_t)ix + (uint32_t)f->nx * (uint32_t)iy;
        double *X = x + 3 * (size_t)i;
        if (!left_out(web, k, i)) {
            const map1d *mx = &f->mx[ix];
            for (int a = 0; a < mx->n; a++) {
                const double *U = u + 3 * (size_t)mx->c[a];
                const double w = mx->w[a];
                X[0] += w * U[0];
                X[1] += w * U[1];
                X[2] += w * U[2];
            }
        }
        if (r) {
            const double *R = r + 3 * (size_t)i;
            double *T = t + 3 * (size_t)i;
            T[0] = R[0], T[1] = R[1], T[2] = R[2];
            fsym_sub(mg->fnd + WS_SYM * (size_t)i, X, T);
            if (zb)
                bodies_to_node(mg->rig, l, i, zb, T);
        }
    }
}

/* The film level's prolongation, block by block (prolong_add). */
typedef struct prolong_pass {
    const ws_mg *mg;
    const ws_web *web;
    double *x, *t;
    const double *r, *zb;
} prolong_pass;

static void prolong_block(void *ctx, uint32_t b)
{
    const prolong_pass *P = ctx;
    const ws_mg *mg = P->mg;
    const uint32_t nx = (uint32_t)mg->lv[0].nx;
    double *u = mg->brow + 3 * (size_t)mg->lv[1].nx * b;
    size_t l = P->zb ? mg->lstart[b] : 0;
    for (uint32_t iy = mg->blocks[b].n0 / nx; iy < mg->blocks[b].n1 / nx; iy++) {
        if (P->zb) /* each choice its own loop */
            prolong_row(mg, P->web, 0, (int)iy, u, P->x, P->r, P->t, P->zb, &l);
        else if (P->r)
            prolong_row(mg, P->web, 0, (int)iy, u, P->x, P->r, P->t, NULL, &l);
        else
            prolong_row(mg, P->web, 0, (int)iy, u, P->x, NULL, NULL, NULL, &l);
    }
}

/* x += P c->x on level k (the film's pinned nodes left out): each fine row's coarse values
 * interpolated along y into a row of room, then along x, the film's level's rows block by
 * block. On the film's level (r given) the node pass of the product that follows is taken on
 * the way: t = r - N x, and with the bodies nested (zb given) t -= A_fb zb. */
static void prolong_add(const ws_mg *mg, const ws_web *web, int k, double *x, const double *r,
                        double *t, const double *zb)
{
    if (k == 0) {
        prolong_pass P = {mg, web, x, t, r, zb};
        ws_implicit_blocks_run(web->imp, prolong_block, &P);
        return;
    }
    size_t l = 0;
    for (int iy = 0; iy < mg->lv[k].ny; iy++)
        prolong_row(mg, web, k, iy, mg->row, x, r, t, zb, &l);
}

/* x = L^-T L^-1 r on the coarsest level. */
static void solve_coarsest(ws_mg *mg)
{
    mg_level *L = &mg->lv[mg->nlev - 1];
    const uint32_t m = mg->m + 6 * mg->nb;
    const double *F = mg->nb ? mg->bchol : mg->chol;
    double *x = mg->nb ? mg->bsc : L->x;
    const double *rhs = L->r;
    if (mg->nb) { /* nodes and bodies as one vector */
        memcpy(x, L->r, mg->m * sizeof(double));
        memcpy(x + mg->m, L->rb, 6 * (size_t)mg->nb * sizeof(double));
        rhs = x;
    }
    for (uint32_t i = 0; i < m; i++) {
        double s = rhs[i];
        for (uint32_t k = 0; k < i; k++)
            s -= F[(size_t)i * m + k] * x[k];
        x[i] = s / F[(size_t)i * m + i];
    }
    for (uint32_t i = m; i-- > 0;) {
        double s = x[i];
        for (uint32_t k = i + 1; k < m; k++)
            s -= F[(size_t)k * m + i] * x[k];
        x[i] = s / F[(size_t)i * m + i];
    }
    if (mg->nb) {
        memcpy(L->x, x, mg->m * sizeof(double));
        memcpy(L->xb, x + mg->m, 6 * (size_t)mg->nb * sizeof(double));
    }
}

/* x_k = B_k r_k on coarse level k: Gauss-Seidel forward, the coarser correction, Gauss-Seidel
 * backward (the two sweeps each other's transpose, so B_k is symmetric). */
static void cycle(ws_mg *mg, const ws_web *web, int k)
{
    if (k == mg->nlev - 1) {
        solve_coarsest(mg);
        return;
    }
    mg_level *L = &mg->lv[k];
    gauss_seidel_forward(mg, &web->imp->run, L, mg->lv[k + 1].rb);
    restrict_to(mg, web, k, L->t);
    cycle(mg, web, k + 1);
    prolong_add(mg, web, k, L->x, NULL, NULL, NULL);
    for (size_t q = 0; q < 6 * (size_t)mg->nb; q++)
        L->xb[q] += mg->lv[k + 1].xb[q];
    gauss_seidel_backward(mg, &web->imp->run, L);
}

/* The film level's node pass of a Jacobi sweep over block b's nodes: z_i = J_i r_i (how
 * JACOBI_SET), z_i += J_i t_i (JACOBI_ADD) or z left (JACOBI_NONE), then, with residual, t_i =
 * r_i - N_i z_i (the springs' part follows in film_springs). J = w D^-1 and N, the nodes' own
 * blocks, as the level keeps them (single precision). With the bodies nested, zb given: t_i -=
 * (A_fb zb)_i too; rbo given: the block's share of -A_bf z with the new z into its bpart
 * (never both). Without residual, r . z over the block into the solve's block sums. */
enum { JACOBI_NONE, JACOBI_SET, JACOBI_ADD };

typedef struct film_pass {
    const ws_mg *mg;
    const ws_web *web;
    const double *r;
    double *t, *z;
    int how, residual, rbo;
    const double *zb;
} film_pass;

/* The node pass over nodes [n0, n1) with the contacts' cursor at l (the pass's own choices
 * constants at each call, so each of film_nodes_block's loops tests none of them); returns
 * r . z over them without residual. */
static MG_INLINE double nodes_run(const ws_mg *mg, uint32_t n0, uint32_t n1, size_t l,
                                  const double *restrict r, double *restrict t,
                                  double *restrict z, int how, int residual, const double *zb,
                                  double *rbo)
{
    double rz = 0.0;
    for (uint32_t i = n0; i < n1; i++) {
        const double *R = r + 3 * (size_t)i;
        double *Z = z + 3 * (size_t)i, *T = t + 3 * (size_t)i;
        if (how != JACOBI_NONE) {
            const float *J = mg->fpinv + WS_SYM * (size_t)i;
            const double *D = how == JACOBI_SET ? R : T;
            const double xx = J[WS_SYM_XX], yy = J[WS_SYM_YY], zz = J[WS_SYM_ZZ],
                         xy = J[WS_SYM_XY], xz = J[WS_SYM_XZ], yz = J[WS_SYM_YZ];
            const double u0 = xx * D[0] + xy * D[1] + xz * D[2],
                         u1 = xy * D[0] + yy * D[1] + yz * D[2],
                         u2 = xz * D[0] + yz * D[1] + zz * D[2];
            if (how == JACOBI_SET)
                Z[0] = u0, Z[1] = u1, Z[2] = u2;
            else
                Z[0] += u0, Z[1] += u1, Z[2] += u2;
        }
        if (rbo)
            node_to_bodies(mg->rig, &l, i, Z, rbo);
        if (residual) {
            T[0] = R[0], T[1] = R[1], T[2] = R[2];
            fsym_sub(mg->fnd + WS_SYM * (size_t)i, Z, T);
            if (zb)
                bodies_to_node(mg->rig, &l, i, zb, T);
        } else {
            rz += R[0] * Z[0] + R[1] * Z[1] + R[2] * Z[2];
        }
    }
    return rz;
}

static void film_nodes_block(void *ctx, uint32_t b)
{
    const film_pass *F = ctx;
    const ws_mg *mg = F->mg;
    const ws_iblock *B = &mg->blocks[b];
    double *rbo = F->rbo ? mg->bpart + 6 * (size_t)mg->nb * b : NULL;
    if (rbo)
        memset(rbo, 0, 6 * (size_t)mg->nb * sizeof(double));
    const size_t l = mg->rig && mg->nb ? mg->lstart[b] : 0;
    const uint32_t n0 = B->n0, n1 = B->n1;
    double rz = 0.0;
    /* The apply's passes (ws_mg's apply): each its own loop. */
    if (!F->residual)
        rz = nodes_run(mg, n0, n1, l, F->r, F->t, F->z, JACOBI_ADD, 0, NULL, NULL);
    else if (F->zb)
        nodes_run(mg, n0, n1, l, F->r, F->t, F->z, JACOBI_ADD, 1, F->zb, NULL);
    else if (F->how == JACOBI_SET && rbo)
        nodes_run(mg, n0, n1, l, F->r, F->t, F->z, JACOBI_SET, 1, NULL, rbo);
    else if (F->how == JACOBI_SET)
        nodes_run(mg, n0, n1, l, F->r, F->t, F->z, JACOBI_SET, 1, NULL, NULL);
    else if (rbo)
        nodes_run(mg, n0, n1, l, F->r, F->t, F->z, F->how, 1, NULL, rbo);
    else
        nodes_run(mg, n0, n1, l, F->r, F->t, F->z, F->how, 1, NULL, NULL);
    F->web->imp->part[WS_PARTS * (size_t)b + WS_PART_SUM] = rz;
}

/* The node pass over the film's blocks (film_nodes_block); with rbo, the blocks' shares of
 * -A_bf z added to it in block order. Returns r . z (without residual). */
static double film_nodes(const ws_mg *mg, const ws_web *web, const double *r, double *t, double *z,
                         int how, int residual, const double *zb, double *rbo)
{
    film_pass F = {mg, web, r, t, z, how, residual, rbo != NULL, zb};
    ws_implicit_blocks_run(web->imp, film_nodes_block, &F);
    for (uint32_t b = 0; rbo && b < mg->nblk; b++)
        for (size_t q = 0; q < 6 * (size_t)mg->nb; q++)
            rbo[q] += mg->bpart[6 * (size_t)mg->nb * b + q];
    double rz = 0.0;
    for (uint32_t b = 0; !residual && b < mg->nblk; b++)
        rz += web->imp->part[WS_PARTS * (size_t)b + WS_PART_SUM];
    return rz;
}

/* t -= the springs' part of A z over the springs [s0, s1) of a run, into the ends `ends`
 * names (a constant at each call), with the springs' blocks as the level keeps them (e, a, b
 * in single precision). */
static inline void film_run(const ws_mg *mg, uint32_t s0, uint32_t s1, uint32_t ends,
                            const double *restrict z, double *restrict t)
{
    for (uint32_t s = s0; s < s1; s++) {
        const float *q = mg->fop + FOP * (size_t)s; /* ex ey ez a b, ends */
        const double ex = q[0], ey = q[1], ez = q[2], a = q[3], bb = q[4];
        uint32_t ia, ib;
        memcpy(&ia, q + FOP_A, sizeof ia);
        memcpy(&ib, q + FOP_B, sizeof ib);
        const double *A = z + 3 * (size_t)ia, *Bz = z + 3 * (size_t)ib;
        const double dx = A[0] - Bz[0], dy = A[1] - Bz[1], dz = A[2] - Bz[2];
        const double ed = a * (ex * dx + ey * dy + ez * dz);
        const double tx = ed * ex + bb * dx, ty = ed * ey + bb * dy, tz = ed * ez + bb * dz;
        if (ends & WS_RUN_A) {
            double *TA = t + 3 * (size_t)ia;
            TA[0] -= tx, TA[1] -= ty, TA[2] -= tz;
        }
        if (ends & WS_RUN_B) {
            double *TB = t + 3 * (size_t)ib;
            TB[0] += tx, TB[1] += ty, TB[2] += tz;
        }
    }
}

/* film_run over block b's runs of springs, in their order. */
static void film_springs_block(void *ctx, uint32_t b)
{
    const film_pass *F = ctx;
    const ws_implicit *im = F->web->imp;
    const ws_iblock *B = &F->mg->blocks[b];
    for (uint32_t g = B->r0; g < B->r1; g++) {
        const ws_irun *u = &im->rng[g];
        if (u->ends == WS_RUN_AB)
            film_run(F->mg, u->first, u->end, WS_RUN_AB, F->z, F->t);
        else if (u->ends == WS_RUN_A)
            film_run(F->mg, u->first, u->end, WS_RUN_A, F->z, F->t);
        else
            film_run(F->mg, u->first, u->end, WS_RUN_B, F->z, F->t);
    }
}

static void film_springs(const ws_mg *mg, const ws_web *web, const double *z, double *t)
{
    film_pass F = {mg, web, NULL, t, (double *)(uintptr_t)z, JACOBI_NONE, 0, 0, NULL};
    ws_implicit_blocks_run(web->imp, film_springs_block, &F);
}

/* z = B r (and zb = B rb with bodies nested): on the film's level mg->sweeps Jacobi sweeps
 * from zero (the bodies held at zero), the residual restricted (the bodies' with it), the
 * coarse cycle, its correction interpolated, mg->sweeps sweeps more against the bodies'
 * correction. Each sweep's product is the node pass (which also finishes the sweep before)
 * and the springs' pass. */
static double apply(ws_mg *mg, const ws_web *web, const double *r, double *z, const double *rb,
                    double *zb)
{
    double *t = mg->lv[0].t;
    const size_t nb6 = 6 * (size_t)mg->nb;
    /* The bodies' right-hand side for level 1, rb - A_bf z, taken with the last pre-sweep's z. */
    double *rbo = nb6 ? mg->lv[1].rb : NULL;
    if (nb6)
        memcpy(rbo, rb, nb6 * sizeof(double));
    (void)film_nodes(mg, web, r, t, z, JACOBI_SET, 1, NULL, mg->sweeps == 1 ? rbo : NULL);
    film_springs(mg, web, z, t);
    for (int s = 1; s < mg->sweeps; s++) { /* after it, t = r - A z */
        (void)film_nodes(mg, web, r, t, z, JACOBI_ADD, 1, NULL, s + 1 == mg->sweeps ? rbo : NULL);
        film_springs(mg, web, z, t);
    }
    restrict_to(mg, web, 0, t);
    cycle(mg, web, 1);
    if (nb6)
        memcpy(zb, mg->lv[1].xb, nb6 * sizeof(double));
    prolong_add(mg, web, 0, z, r, t, nb6 ? zb : NULL); /* and t = r - N z - A_fb zb */
    film_springs(mg, web, z, t);
    for (int s = 1; s < mg->sweeps; s++) {
        (void)film_nodes(mg, web, r, t, z, JACOBI_ADD, 1, nb6 ? zb : NULL, NULL);
        film_springs(mg, web, z, t);
    }
    double rz = film_nodes(mg, web, r, t, z, JACOBI_ADD, 0, NULL, NULL);
    for (size_t q = 0; q < nb6; q++)
        rz += rb[q] * zb[q];
    return rz;
}

double ws_mg_apply(ws_mg *mg, const ws_web *web, const double *r, double *z)
{
    if (!mg->nb)
        return apply(mg, web, r, z, NULL, NULL);
    /* With bodies nested, the film's block of the cycle: their residual zero, their part of
     * the answer dropped (a principal block of a symmetric positive definite map is one). */
    memset(mg->brz, 0, 6 * (size_t)mg->nb * sizeof(double));
    return apply(mg, web, r, z, mg->brz, mg->brz + 6 * (size_t)mg->nb);
}

double ws_mg_apply_bodies(ws_mg *mg, const ws_web *web, const double *r, double *z,
                          const double *rb, double *zb)
{
    return apply(mg, web, r, z, rb, zb);
}

int ws_mg_rows(const ws_mg *mg, int k, int *whole)
{
    *whole = 0;
    if (k < 1 || k + 1 >= mg->nlev)
        return 0;
    *whole = mg->lv[k].lines;
    return mg->lv[k].ny;
}

int ws_mg_set_row(ws_mg *mg, int k, int iy, int whole)
{
    if (k < 1 || k + 1 >= mg->nlev || iy < 0 || iy >= mg->lv[k].ny)
        return -1;
    mg_level *L = &mg->lv[k];
    L->lines += (whole != 0) - L->whole[iy];
    L->whole[iy] = whole != 0;
    return whole ? line_factor(L, iy) : point_factor(L, iy);
}

int ws_mg_levels(const ws_mg *mg)
{
    return mg ? mg->nlev : 1;
}

/* Whether every spring of the web joins grid neighbours (dx, dy in -1..1, around the band's
 * seam for a closed one), so that the film's matrix is a grid stencil. */
static int springs_on_grid(const ws_web *web)
{
    const uint32_t nx = (uint32_t)web->nx;
    for (uint32_t s = 0; s < web->ns; s++) {
        const uint32_t a = web->sa[s], b = web->sb[s];
        int dx = (int)(b % nx) - (int)(a % nx);
        const int dy = (int)(b / nx) - (int)(a / nx);
        if (web->closed && (dx == (int)nx - 1 || dx == 1 - (int)nx))
            dx = dx > 0 ? -1 : 1;
        if (a == b || dx < -1 || dx > 1 || dy < -1 || dy > 1)
            return 0;
    }
    return 1;
}

/* The levels' sizes of a web into lv; their number, or 0 when the multigrid cannot serve it
 * (ws_mg_grid). */
static int plan_levels(const ws_web *web, mg_level *lv)
{
    if (web->nx <= 0 || web->ny <= 0 || (uint64_t)web->nx * (uint64_t)web->ny != web->n ||
        (web->closed && web->nx < 3) || !springs_on_grid(web))
        return 0;
    memset(lv, 0, MG_LEVELS * sizeof *lv);
    lv[0] = (mg_level){.nx = web->nx, .ny = web->ny, .closed = web->closed, .n = web->n};
    int k = 0;
    while (k + 1 < MG_LEVELS && lv[k].n > MG_COARSEST) {
        mg_level *L = &lv[k];
        L->cx = L->closed ? L->nx >= 5 : L->nx >= 3;
        /* A band's film level halves around only. Its up springs' tension falls toward
         * nothing at the band's free edges (their transverse stiffness in the edge rows a
         * quarter of its median, 5 % at the least; the around springs' and every axial one
         * within 15 % of their median everywhere), so near the edges a node is held around
         * far more strongly than up (out of the film's plane and along it), and a point smoother
         * leaves the error that is smooth around and rough up: only a level that keeps every
         * row can take it. Halving both there made the iterations grow with refinement (the
         * rows of weak coupling grow in number); halving around once makes the next level's
         * around couplings 4x weaker against its up ones, about even, and the levels after
         * halve both (bench/NOTES.md, session 13). */
        L->cy = L->ny >= 3 && !(k == 0 && L->closed && L->cx);
        if (!L->cx && !L->cy)
            break;
        const int nx = L->cx ? (L->nx + 1) / 2 : L->nx, ny = L->cy ? (L->ny + 1) / 2 : L->ny;
        lv[k + 1] = (mg_level){.nx = nx, .ny = ny, .closed = L->closed,
                               .n = (uint32_t)nx * (uint32_t)ny};
        k++;
    }
    return k < 1 || lv[k].n > WS_MG_COARSEST_MAX ? 0 : k + 1;
}

int ws_mg_grid(const ws_web *web)
{
    mg_level lv[MG_LEVELS];
    return plan_levels(web, lv) > 0;
}

int ws_mg_chosen(const ws_web *web)
{
    if (web->precond == WS_WEB_PRECONDITIONER_BLOCK_JACOBI ||
        (web->precond == WS_WEB_PRECONDITIONER_AUTO && web->n < WS_WEB_MULTIGRID_AUTO_NODES))
        return 0;
    return ws_mg_grid(web);
}

int ws_mg_reserve(ws_mem *mem, const ws_web *web, ws_mg **out)
{
    *out = NULL;
    mg_level lv[MG_LEVELS];
    const int nlev = ws_mg_chosen(web) ? plan_levels(web, lv) : 0;
    if (nlev < 2)
        return 0;
    const int k = nlev - 1;
    const uint32_t m = 3 * lv[k].n;
    const uint32_t nblk = web->imp->nblk;
    size_t doubles = 3 * (size_t)web->n + (size_t)m * m + 2 * STEN * (size_t)lv[1].n +
                     3 * (size_t)lv[1].nx * (1 + (size_t)nblk + (size_t)lv[0].ny),
           floats = 0;
    for (int i = 1; i < nlev; i++) {
        doubles += (9 + WS_SYM + 9) * (size_t)lv[i].n;
        floats += STEN * (size_t)lv[i].n;
    }
    floats += FOP * (size_t)(web->ns ? web->ns : 1) + 2 * WS_SYM * (size_t)web->n;
    size_t nmaps = 0, rows = 0;
    for (int i = 0; i + 1 < nlev; i++)
        nmaps += (size_t)lv[i].nx + (size_t)lv[i].ny;
    for (int i = 1; i < nlev; i++)
        rows += (size_t)lv[i].ny;
    ws_mg *mg = ws_mem_calloc(mem, 1, sizeof *mg);
    double *blk = mg ? ws_mem_calloc(mem, doubles, sizeof(double)) : NULL;
    float *fblk = blk ? ws_mem_calloc(mem, floats, sizeof(float)) : NULL;
    map1d *maps = fblk ? ws_mem_calloc(mem, nmaps, sizeof(map1d)) : NULL;
    unsigned char *whole = maps ? ws_mem_calloc(mem, rows, 1) : NULL;
    if (!whole) {
        if (maps)
            ws_mem_free(mem, maps, nmaps * sizeof(map1d));
        if (fblk)
            ws_mem_free(mem, fblk, floats * sizeof(float));
        if (blk)
            ws_mem_free(mem, blk, doubles * sizeof(double));
        if (mg)
            ws_mem_free(mem, mg, sizeof *mg);
        return -1;
    }
    mg->maps = maps;
    mg->nmaps = nmaps;
    mg->whole = whole;
    mg->rows = rows;
    map1d *mp = maps;
    for (int i = 0; i + 1 < nlev; i++) {
        lv[i].mx = mp, mp += lv[i].nx;
        lv[i].my = mp, mp += lv[i].ny;
        for (int x = 0; x < lv[i].nx; x++)
            lv[i].mx[x].n = map1(x, lv[i].nx, lv[i].closed, lv[i].cx, lv[i].mx[x].c,
                                 lv[i].mx[x].w);
        for (int y = 0; y < lv[i].ny; y++)
            lv[i].my[y].n = map1(y, lv[i].ny, 0, lv[i].cy, lv[i].my[y].c, lv[i].my[y].w);
    }
    mg->nlev = nlev;
    mg->sweeps = lv[0].cy ? MG_SWEEPS : MG_SWEEPS_SEMI;
    mg->m = m;
    mg->blk = blk;
    mg->doubles = doubles;
    mg->fblk = fblk;
    mg->floats = floats;
    memcpy(mg->lv, lv, sizeof lv);
    double *q = blk;
    float *fq = fblk;
    mg->fop = fq, fq += FOP * (size_t)(web->ns ? web->ns : 1);
    for (uint32_t s = 0; s < web->ns; s++) { /* the ends, fixed for the web */
        memcpy(mg->fop + FOP * (size_t)s + FOP_A, &web->sa[s], sizeof(uint32_t));
        memcpy(mg->fop + FOP * (size_t)s + FOP_B, &web->sb[s], sizeof(uint32_t));
    }
    mg->fnd = fq, fq += WS_SYM * (size_t)web->n;
    mg->fpinv = fq, fq += WS_SYM * (size_t)web->n;
    mg->lv[0].t = q, q += 3 * (size_t)web->n;
    mg->chol = q, q += (size_t)m * m;
    mg->acc = q, q += STEN * (size_t)lv[1].n;
    mg->sacc = q, q += STEN * (size_t)lv[1].n;
    mg->row = q, q += 3 * (size_t)lv[1].nx;
    mg->nblk = nblk;
    mg->blocks = web->imp->blk;
    mg->brow = q, q += 3 * (size_t)lv[1].nx * nblk;
    mg->rrow = q, q += 3 * (size_t)lv[1].nx * (size_t)lv[0].ny;
    for (int i = 1; i < nlev; i++) {
        mg_level *L = &mg->lv[i];
        L->a = fq, fq += STEN * (size_t)L->n;
        L->dinv = q, q += WS_SYM * (size_t)L->n;
        L->lff = q, q += 9 * (size_t)L->n;
        L->x = q, q += 3 * (size_t)L->n;
        L->r = q, q += 3 * (size_t)L->n;
        L->t = q, q += 3 * (size_t)L->n;
        L->whole = whole, whole += L->ny;
    }
    *out = mg;
    return 0;
}

void ws_mg_free(ws_mem *mem, ws_mg *mg)
{
    if (!mg)
        return;
    ws_mem_free(mem, mg->whole, mg->rows);
    ws_mem_free(mem, mg->maps, mg->nmaps * sizeof(map1d));
    ws_mem_free(mem, mg->blk, mg->doubles * sizeof(double));
    ws_mem_free(mem, mg->fblk, mg->floats * sizeof(float));
    ws_mem_free(mem, mg, sizeof *mg);
}
