/* The implicit film's multigrid preconditioner on grid webs (web/multigrid.h says the cycle;
 * docs/theory.md, "The implicit film", why it is this one). */
#include "web/multigrid.h"

#include "web/implicit.h"

#include <string.h>

#define MG_LEVELS 16   /* levels at most (a grid of 2^15 nodes a side would need them) */
#define MG_COARSEST 64 /* a level of this many nodes or fewer is the coarsest */
#define MG_DENSE 128   /* the coarsest level's nodes at most: its factor is (3 n)^2 doubles */
/* The film level's smoother: damped block Jacobi, this many sweeps before and after the coarse
 * correction, with weight MG_OMEGA. The film's matrix is at most twice its block diagonal
 * (A = N + sum over springs of E^T K E with E = e_a - e_b, and 2 D - A = N + sum (e_a + e_b)^T
 * K (e_a + e_b) >= 0), so any weight below 1 contracts in A's norm and the cycle stays positive
 * definite; 2/3 is the weight that damps the grid's upper half of frequencies best. */
#define MG_SWEEPS 2
#define MG_OMEGA (2.0 / 3.0)
#define BLK 9           /* a full 3x3 block, row-major */
/* A coarse node's row holds its own block and those of its forward neighbours (slots 4 to 8 of
 * the 9 with dx, dy in -1..1, slot 3 (dy + 1) + dx + 1); a backward neighbour's block is the
 * transpose of that neighbour's forward one (the matrix is symmetric), which halves what a
 * sweep reads. */
#define CENTRE 4
#define STEN (5 * BLK)
#define AT(L, k, o) ((L)->a + STEN * (size_t)(k) + BLK * (size_t)((o) - CENTRE))

/* One direction's interpolation for one fine index: n coarse indices c with weights w. */
typedef struct map1d {
    int n, c[2];
    double w[2];
} map1d;

typedef struct mg_level {
    int nx, ny, closed; /* grid: node ix + nx iy, closed around (a band) */
    int cx, cy;         /* whether x and y are halved for the next level */
    map1d *mx, *my;     /* interpolation from the next level, by ix and by iy */
    uint32_t n;
    double *a;              /* STEN n: each node's row of blocks (coarse levels) */
    double *dinv;           /* WS_SYM n: inverse of each node's own block (coarse levels) */
    double *x, *r, *t;      /* 3 n each: the level's solution, right-hand side, scratch (the
                               film's level has t alone) */
} mg_level;

struct ws_mg {
    int nlev;
    mg_level lv[MG_LEVELS];
    uint32_t m;   /* unknowns of the coarsest level */
    double *chol; /* its Cholesky factor, lower, m x m */
    double *blk;  /* every array above, in one allocation of `doubles` */
    size_t doubles;
    map1d *maps;  /* every level's mx and my, nmaps of them */
    size_t nmaps;
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
    int X[4], Y[4];
    uint32_t idx[4];
    double w[4];
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
static void neighbours(const mg_level *L, int ix, int iy, int64_t *j)
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

/* Coarse level c += s P_p^T B P_q: block B between fine rows p and q, through P (its centre
 * and forward blocks; the caller adds the pair (q, p, B^T) too). */
static void galerkin_add(mg_level *c, const pmap *p, const pmap *q, const double *B, double s)
{
    for (int i = 0; i < p->n; i++)
        for (int j = 0; j < q->n; j++) {
            const int o = slot(c, p->X[i], p->Y[i], q->X[j], q->Y[j]);
            if (o < CENTRE)
                continue; /* the transpose of (J, I)'s, which the pair (q, p) adds */
            double *D = AT(c, p->idx[i], o);
            const double w = s * p->w[i] * q->w[j];
            for (int k = 0; k < BLK; k++)
                D[k] += w * B[k];
        }
}

static void sym_full(const double *S, double *B)
{
    B[0] = S[WS_SYM_XX], B[1] = S[WS_SYM_XY], B[2] = S[WS_SYM_XZ];
    B[3] = S[WS_SYM_XY], B[4] = S[WS_SYM_YY], B[5] = S[WS_SYM_YZ];
    B[6] = S[WS_SYM_XZ], B[7] = S[WS_SYM_YZ], B[8] = S[WS_SYM_ZZ];
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

/* Level 1 = P^T A P from the film's nodes and springs as operator_for set them. */
static void galerkin_film(ws_mg *mg, const ws_web *web)
{
    const ws_implicit *im = web->imp;
    mg_level *c = &mg->lv[1];
    memset(c->a, 0, STEN * (size_t)c->n * sizeof(double));
    double B[BLK];
    pmap p, q;
    for (uint32_t i = 0; i < web->n; i++) {
        film_pmap(mg, web, i, &p);
        sym_full(im->nd + WS_SYM * (size_t)i, B);
        galerkin_add(c, &p, &p, B, 1.0);
    }
    for (uint32_t s = 0; s < web->ns; s++) {
        const ws_ispring *k = &im->sp[s];
        if (k->a == 0.0 && k->b == 0.0)
            continue;
        const double e[3] = {k->ex, k->ey, k->ez};
        for (int r = 0; r < 3; r++)
            for (int col = 0; col < 3; col++)
                B[3 * r + col] = k->a * e[r] * e[col] + (r == col ? k->b : 0.0);
        film_pmap(mg, web, web->sa[s], &p);
        film_pmap(mg, web, web->sb[s], &q);
        galerkin_add(c, &p, &p, B, 1.0);
        galerkin_add(c, &q, &q, B, 1.0);
        galerkin_add(c, &p, &q, B, -1.0);
        galerkin_add(c, &q, &p, B, -1.0);
    }
}

/* Level k + 1 = P^T A_k P. */
static void galerkin_level(ws_mg *mg, int k)
{
    const mg_level *f = &mg->lv[k];
    mg_level *c = &mg->lv[k + 1];
    memset(c->a, 0, STEN * (size_t)c->n * sizeof(double));
    pmap p, q;
    int64_t j[9];
    for (int iy = 0; iy < f->ny; iy++)
        for (int ix = 0; ix < f->nx; ix++) {
            const uint32_t i = (uint32_t)ix + (uint32_t)f->nx * (uint32_t)iy;
            pmap_of(f, c, ix, iy, &p);
            neighbours(f, ix, iy, j);
            galerkin_add(c, &p, &p, AT(f, i, CENTRE), 1.0);
            for (int o = CENTRE + 1; o < 9; o++) {
                const double *B = AT(f, i, o);
                if (j[o] < 0 || (B[0] == 0.0 && B[4] == 0.0 && B[8] == 0.0 && B[1] == 0.0 &&
                                 B[2] == 0.0 && B[5] == 0.0 && B[3] == 0.0 && B[6] == 0.0 &&
                                 B[7] == 0.0))
                    continue;
                double Bt[BLK];
                for (int r = 0; r < 3; r++)
                    for (int col = 0; col < 3; col++)
                        Bt[3 * col + r] = B[3 * r + col];
                pmap_of(f, c, (int)(j[o] % f->nx), (int)(j[o] / f->nx), &q);
                galerkin_add(c, &p, &q, B, 1.0);
                galerkin_add(c, &q, &p, Bt, 1.0);
            }
        }
}

/* o -= M x, or o -= M^T x when transposed (M a row-major 3x3 block). */
static inline void block_sub(const double *M, int transposed, const double *x, double *o)
{
    if (transposed) {
        o[0] -= M[0] * x[0] + M[3] * x[1] + M[6] * x[2];
        o[1] -= M[1] * x[0] + M[4] * x[1] + M[7] * x[2];
        o[2] -= M[2] * x[0] + M[5] * x[1] + M[8] * x[2];
    } else {
        o[0] -= M[0] * x[0] + M[1] * x[1] + M[2] * x[2];
        o[1] -= M[3] * x[0] + M[4] * x[1] + M[5] * x[2];
        o[2] -= M[6] * x[0] + M[7] * x[1] + M[8] * x[2];
    }
}

/* The inverse of a node's own block (symmetrised), or zeros for a node no fine node reaches
 * (all of its fine nodes pinned: its right-hand side is always zero). 0, or -1 when the block
 * is not positive definite. */
static int own_inverse(const double *B, double *S)
{
    const double sym[WS_SYM] = {[WS_SYM_XX] = B[0],
                                [WS_SYM_YY] = B[4],
                                [WS_SYM_ZZ] = B[8],
                                [WS_SYM_XY] = 0.5 * (B[1] + B[3]),
                                [WS_SYM_XZ] = 0.5 * (B[2] + B[6]),
                                [WS_SYM_YZ] = 0.5 * (B[5] + B[7])};
    if (sym[WS_SYM_XX] == 0.0 && sym[WS_SYM_YY] == 0.0 && sym[WS_SYM_ZZ] == 0.0) {
        memset(S, 0, WS_SYM * sizeof(double));
        return 0;
    }
    return ws_sym_invert(sym, S);
}

/* The coarsest level's dense matrix and its Cholesky factor. 0, or -1 when it is not positive
 * definite. */
static int factor_coarsest(ws_mg *mg)
{
    const mg_level *L = &mg->lv[mg->nlev - 1];
    const uint32_t m = mg->m;
    double *D = mg->chol;
    memset(D, 0, (size_t)m * m * sizeof(double));
    int64_t nb[9];
    for (int iy = 0; iy < L->ny; iy++)
        for (int ix = 0; ix < L->nx; ix++) {
            const uint32_t i = (uint32_t)ix + (uint32_t)L->nx * (uint32_t)iy;
            const double *own = AT(L, i, CENTRE);
            if (own[0] == 0.0 && own[4] == 0.0 && own[8] == 0.0) { /* unreached: identity */
                for (int k = 0; k < 3; k++)
                    D[(3 * (size_t)i + k) * m + 3 * i + k] = 1.0;
                continue;
            }
            neighbours(L, ix, iy, nb);
            for (int o = CENTRE; o < 9; o++) { /* the block and its transpose */
                if (nb[o] < 0)
                    continue;
                const size_t j = (size_t)nb[o];
                const double *B = AT(L, i, o);
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

int ws_mg_setup(ws_mg *mg, const ws_web *web)
{
    galerkin_film(mg, web);
    for (int k = 1; k + 1 < mg->nlev; k++)
        galerkin_level(mg, k);
    for (int k = 1; k + 1 < mg->nlev; k++) {
        const mg_level *L = &mg->lv[k];
        for (uint32_t i = 0; i < L->n; i++)
            if (own_inverse(AT(L, i, CENTRE),
                            L->dinv + WS_SYM * (size_t)i) != 0)
                return -1;
    }
    return factor_coarsest(mg);
}

/* s -= sum over node k's neighbours j of A_kj x_j: those before k (side < 0), after k (side >
 * 0) or all (side 0), its own block left out. */
static void row_times(const mg_level *L, size_t k, const int64_t *j, int side, double *s)
{
    for (int o = 0; o < 9; o++) {
        if (j[o] < 0 || o == CENTRE || (side < 0 && (size_t)j[o] > k) ||
            (side > 0 && (size_t)j[o] < k))
            continue;
        const double *X = L->x + 3 * (size_t)j[o];
        if (o > CENTRE) {
            const double *B = AT(L, k, o);
            s[0] -= B[0] * X[0] + B[1] * X[1] + B[2] * X[2];
            s[1] -= B[3] * X[0] + B[4] * X[1] + B[5] * X[2];
            s[2] -= B[6] * X[0] + B[7] * X[1] + B[8] * X[2];
        } else { /* the neighbour's forward block, transposed */
            const double *B = AT(L, j[o], 8 - o);
            s[0] -= B[0] * X[0] + B[3] * X[1] + B[6] * X[2];
            s[1] -= B[1] * X[0] + B[4] * X[1] + B[7] * X[2];
            s[2] -= B[2] * X[0] + B[5] * X[1] + B[8] * X[2];
        }
    }
}

/* One sweep of block Gauss-Seidel on coarse level L: forward from x = 0 (a node then meets
 * only the nodes before it, those after being still zero), which leaves the residual r - A x
 * in t (at node k, what the nodes after it add since: -sum over them of A_kj x_j, each added
 * as that node is solved, with the block its own solve has just read); or backward from the x
 * there is. */
static void gauss_seidel(mg_level *L, int backward)
{
    const int nx = L->nx, ny = L->ny;
    int64_t j[9];
    if (!backward)
        memset(L->t, 0, 3 * (size_t)L->n * sizeof(double));
    for (int q = 0; q < nx * ny; q++) {
        const int k = backward ? nx * ny - 1 - q : q;
        neighbours(L, k % nx, k / nx, j);
        const double *R = L->r + 3 * (size_t)k;
        double s[3] = {R[0], R[1], R[2]};
        if (backward) {
            row_times(L, (size_t)k, j, 0, s);
        } else {
            /* A_kj for the nodes j before k: the transpose of j's forward block, or k's own
             * forward block across a band's seam. */
            const double *B[9];
            int tr[9];
            for (int o = 0; o < 9; o++) {
                B[o] = NULL;
                if (j[o] < 0 || o == CENTRE || j[o] > k)
                    continue;
                tr[o] = o < CENTRE;
                B[o] = tr[o] ? AT(L, j[o], 8 - o) : AT(L, k, o);
                const double *X = L->x + 3 * (size_t)j[o], *M = B[o];
                block_sub(M, tr[o], X, s);
            }
            const double *S = L->dinv + WS_SYM * (size_t)k;
            double *X = L->x + 3 * (size_t)k;
            X[0] = X[1] = X[2] = 0.0;
            ws_sym_madd(S, s[0], s[1], s[2], X);
            for (int o = 0; o < 9; o++) { /* t_j -= A_jk x_k, A_jk = A_kj^T */
                if (!B[o])
                    continue;
                const double *M = B[o];
                double *T = L->t + 3 * (size_t)j[o];
                block_sub(M, !tr[o], X, T);
            }
            continue;
        }
        const double *S = L->dinv + WS_SYM * (size_t)k;
        double *X = L->x + 3 * (size_t)k;
        X[0] = X[1] = X[2] = 0.0;
        ws_sym_madd(S, s[0], s[1], s[2], X);
    }
}

/* c->r = P^T (r - t), or P^T t when r is NULL (r, t level-f vectors; f the film's when web is
 * given, its pinned nodes then left out), and prolongation x += P c->x. */
static void restrict_to(const ws_mg *mg, const ws_web *web, int k, const double *r,
                        const double *t)
{
    const mg_level *f = &mg->lv[k];
    const mg_level *c = &mg->lv[k + 1];
    memset(c->r, 0, 3 * (size_t)c->n * sizeof(double));
    pmap p;
    for (int iy = 0; iy < f->ny; iy++)
        for (int ix = 0; ix < f->nx; ix++) {
            const uint32_t i = (uint32_t)ix + (uint32_t)f->nx * (uint32_t)iy;
            if (web && web->inv_m[i] == 0.0)
                continue;
            pmap_of(f, c, ix, iy, &p);
            const double *T = t + 3 * (size_t)i;
            double d[3] = {T[0], T[1], T[2]};
            if (r) {
                const double *F = r + 3 * (size_t)i;
                d[0] = F[0] - d[0], d[1] = F[1] - d[1], d[2] = F[2] - d[2];
            }
            for (int q = 0; q < p.n; q++) {
                double *R = c->r + 3 * (size_t)p.idx[q];
                R[0] += p.w[q] * d[0];
                R[1] += p.w[q] * d[1];
                R[2] += p.w[q] * d[2];
            }
        }
}

static void prolong_add(const ws_mg *mg, const ws_web *web, int k, double *x)
{
    const mg_level *f = &mg->lv[k];
    const mg_level *c = &mg->lv[k + 1];
    pmap p;
    for (int iy = 0; iy < f->ny; iy++)
        for (int ix = 0; ix < f->nx; ix++) {
            const uint32_t i = (uint32_t)ix + (uint32_t)f->nx * (uint32_t)iy;
            if (web && web->inv_m[i] == 0.0)
                continue;
            pmap_of(f, c, ix, iy, &p);
            double *X = x + 3 * (size_t)i;
            for (int q = 0; q < p.n; q++) {
                const double *C = c->x + 3 * (size_t)p.idx[q];
                X[0] += p.w[q] * C[0];
                X[1] += p.w[q] * C[1];
                X[2] += p.w[q] * C[2];
            }
        }
}

/* x = L^-T L^-1 r on the coarsest level. */
static void solve_coarsest(ws_mg *mg)
{
    const mg_level *L = &mg->lv[mg->nlev - 1];
    const uint32_t m = mg->m;
    const double *F = mg->chol;
    double *x = L->x;
    for (uint32_t i = 0; i < m; i++) {
        double s = L->r[i];
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
}

/* x_k = B_k r_k on coarse level k: Gauss-Seidel forward, the coarser correction, Gauss-Seidel
 * backward (the two sweeps each other's transpose, so B_k is symmetric). */
static void cycle(ws_mg *mg, int k)
{
    if (k == mg->nlev - 1) {
        solve_coarsest(mg);
        return;
    }
    mg_level *L = &mg->lv[k];
    gauss_seidel(L, 0);
    restrict_to(mg, NULL, k, NULL, L->t);
    cycle(mg, k + 1);
    prolong_add(mg, NULL, k, L->x);
    gauss_seidel(L, 1);
}

/* z += w P^-1 (r - t) with the film's block-Jacobi inverses (t NULL: z = w P^-1 r). */
static void jacobi(const ws_web *web, const double *r, const double *t, double *z)
{
    const double *pinv = web->imp->pinv;
    for (uint32_t i = 0; i < web->n; i++) {
        const double *R = r + 3 * (size_t)i, *S = pinv + WS_SYM * (size_t)i;
        double *Z = z + 3 * (size_t)i;
        double d[3] = {R[0], R[1], R[2]};
        if (t) {
            const double *T = t + 3 * (size_t)i;
            d[0] -= T[0], d[1] -= T[1], d[2] -= T[2];
        } else {
            Z[0] = Z[1] = Z[2] = 0.0;
        }
        d[0] *= MG_OMEGA, d[1] *= MG_OMEGA, d[2] *= MG_OMEGA;
        ws_sym_madd(S, d[0], d[1], d[2], Z);
    }
}

double ws_mg_apply(ws_mg *mg, const ws_web *web, const double *r, double *z)
{
    double *t = mg->lv[0].t;
    const size_t m = 3 * (size_t)web->n;
    jacobi(web, r, NULL, z);
    for (int s = 1; s < MG_SWEEPS; s++) {
        (void)ws_implicit_apply_op(web, z, t);
        jacobi(web, r, t, z);
    }
    (void)ws_implicit_apply_op(web, z, t);
    restrict_to(mg, web, 0, r, t);
    cycle(mg, 1);
    prolong_add(mg, web, 0, z);
    for (int s = 0; s < MG_SWEEPS; s++) {
        (void)ws_implicit_apply_op(web, z, t);
        jacobi(web, r, t, z);
    }
    double rz = 0.0;
    for (size_t j = 0; j < m; j++)
        rz += r[j] * z[j];
    return rz;
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

int ws_mg_reserve(ws_mem *mem, const ws_web *web, ws_mg **out)
{
    *out = NULL;
    if (web->nx <= 0 || web->ny <= 0 || (uint64_t)web->nx * (uint64_t)web->ny != web->n ||
        (web->closed && web->nx < 3) || !springs_on_grid(web))
        return 0;
    mg_level lv[MG_LEVELS];
    memset(lv, 0, sizeof lv);
    lv[0] = (mg_level){.nx = web->nx, .ny = web->ny, .closed = web->closed, .n = web->n};
    int k = 0;
    while (k + 1 < MG_LEVELS && lv[k].n > MG_COARSEST) {
        mg_level *L = &lv[k];
        L->cx = L->closed ? L->nx >= 5 : L->nx >= 3;
        L->cy = L->ny >= 3;
        if (!L->cx && !L->cy)
            break;
        const int nx = L->cx ? (L->nx + 1) / 2 : L->nx, ny = L->cy ? (L->ny + 1) / 2 : L->ny;
        lv[k + 1] = (mg_level){.nx = nx, .ny = ny, .closed = L->closed,
                               .n = (uint32_t)nx * (uint32_t)ny};
        k++;
    }
    const int nlev = k + 1;
    if (nlev < 2 || lv[k].n > MG_DENSE)
        return 0;
    const uint32_t m = 3 * lv[k].n;
    size_t doubles = 3 * (size_t)web->n + (size_t)m * m;
    for (int i = 1; i < nlev; i++)
        doubles += (STEN + WS_SYM + 9) * (size_t)lv[i].n;
    size_t nmaps = 0;
    for (int i = 0; i + 1 < nlev; i++)
        nmaps += (size_t)lv[i].nx + (size_t)lv[i].ny;
    ws_mg *mg = ws_mem_calloc(mem, 1, sizeof *mg);
    double *blk = mg ? ws_mem_calloc(mem, doubles, sizeof(double)) : NULL;
    map1d *maps = blk ? ws_mem_calloc(mem, nmaps, sizeof(map1d)) : NULL;
    if (!maps) {
        if (blk)
            ws_mem_free(mem, blk, doubles * sizeof(double));
        if (mg)
            ws_mem_free(mem, mg, sizeof *mg);
        return -1;
    }
    mg->maps = maps;
    mg->nmaps = nmaps;
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
    mg->m = m;
    mg->blk = blk;
    mg->doubles = doubles;
    memcpy(mg->lv, lv, sizeof lv);
    double *q = blk;
    mg->lv[0].t = q, q += 3 * (size_t)web->n;
    mg->chol = q, q += (size_t)m * m;
    for (int i = 1; i < nlev; i++) {
        mg_level *L = &mg->lv[i];
        L->a = q, q += STEN * (size_t)L->n;
        L->dinv = q, q += WS_SYM * (size_t)L->n;
        L->x = q, q += 3 * (size_t)L->n;
        L->r = q, q += 3 * (size_t)L->n;
        L->t = q, q += 3 * (size_t)L->n;
    }
    *out = mg;
    return 0;
}

void ws_mg_free(ws_mem *mem, ws_mg *mg)
{
    if (!mg)
        return;
    ws_mem_free(mem, mg->maps, mg->nmaps * sizeof(map1d));
    ws_mem_free(mem, mg->blk, mg->doubles * sizeof(double));
    ws_mem_free(mem, mg, sizeof *mg);
}
