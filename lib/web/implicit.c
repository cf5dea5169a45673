/* The implicit film step: linearly implicit backward Euler, solved by conjugate gradients
 * (web/implicit.h says the scheme; docs/theory.md, "The implicit film", why this one). */
#include "web/implicit.h"

#include "web/coupled.h"
#include "web/multigrid.h"

#include <float.h>
#include <string.h>

/* Doubles of each per-node array: xyz vectors and symmetric blocks. */
#define VEC(n) (3 * (size_t)(n))
#define SYMS(n) (WS_SYM * (size_t)(n))
#define OPS(ns) (5 * (size_t)((ns) ? (ns) : 1))

static size_t scratch_doubles(uint32_t n)
{
    return 8 * VEC(n) + 4 * SYMS(n); /* f fs b dv r z p q, kc dc pinv nd */
}

/* The block of node i: a grid web's rows, ws_web_block_rows at a time; a mesh web's one. */
static uint32_t block_of(const ws_web *web, uint32_t rows, uint32_t i)
{
    return web->nx > 0 ? i / (uint32_t)web->nx / rows : 0u;
}

/* Spring s, its ends in block k as `ends` says (WS_RUN_*), into the block's runs, whose last
 * ends at last[k] with those ends (lends[k]): counted in the block's r1, and with fill written
 * at rng's r1 too. */
static void run_add(ws_implicit *im, uint32_t k, uint32_t s, uint32_t ends, uint32_t *last,
                    uint32_t *lends, int fill)
{
    ws_iblock *B = &im->blk[k];
    if (last[k] == s && lends[k] == ends) {
        if (fill)
            im->rng[B->r1 - 1].end = s + 1;
    } else {
        if (fill)
            im->rng[B->r1] = (ws_irun){s, s + 1, ends};
        B->r1++;
    }
    last[k] = s + 1;
    lends[k] = ends;
}

/* Every spring into the runs of the blocks of its ends, in the springs' order (last, lends:
 * room for nblk each). */
static void runs_walk(ws_implicit *im, const ws_web *web, uint32_t rows, uint32_t *last, int fill)
{
    uint32_t *lends = last + im->nblk;
    for (uint32_t k = 0; k < im->nblk; k++)
        last[k] = UINT32_MAX;
    for (uint32_t s = 0; s < web->ns; s++) {
        const uint32_t a = block_of(web, rows, web->sa[s]), b = block_of(web, rows, web->sb[s]);
        run_add(im, a, s, b == a ? WS_RUN_AB : WS_RUN_A, last, lends, fill);
        if (b != a)
            run_add(im, b, s, WS_RUN_B, last, lends, fill);
    }
}

/* The solve's blocks and their runs of springs (ws_iblock). 0, or -1 when out of memory. */
static int blocks_make(ws_mem *mem, const ws_web *web, ws_implicit *im)
{
    const uint32_t rows = ws_web_block_rows(web), cnt = web->nx > 0 ? ws_web_block_count(web) : 1;
    im->nblk = cnt ? cnt : 1;
    uint32_t *last = ws_mem_calloc(mem, 2 * (size_t)im->nblk, sizeof *last);
    im->blk = ws_mem_calloc(mem, im->nblk, sizeof *im->blk);
    im->part = ws_mem_calloc(mem, (size_t)im->nblk * WS_PARTS, sizeof(double));
    if (!last || !im->blk || !im->part) {
        ws_mem_free(mem, last, last ? 2 * (size_t)im->nblk * sizeof *last : 0);
        return -1;
    }
    runs_walk(im, web, rows, last, 0); /* each block's runs counted in its r1 */
    uint32_t at = 0;
    for (uint32_t k = 0; k < im->nblk; k++) {
        ws_iblock *B = &im->blk[k];
        const uint32_t runs = B->r1, row = (uint32_t)(web->nx > 0 ? web->nx : 0);
        const uint64_t n0 = row ? (uint64_t)k * rows * row : 0, n1 = row ? n0 + rows * row : web->n;
        B->r0 = B->r1 = at;
        at += runs;
        B->n0 = (uint32_t)(n0 < web->n ? n0 : web->n);
        B->n1 = (uint32_t)(n1 < web->n ? n1 : web->n);
    }
    im->nrng = at;
    im->rng = ws_mem_calloc(mem, im->nrng ? im->nrng : 1, sizeof *im->rng);
    if (im->rng)
        runs_walk(im, web, rows, last, 1);
    ws_mem_free(mem, last, 2 * (size_t)im->nblk * sizeof *last);
    return im->rng ? 0 : -1;
}

int ws_implicit_reserve(ws_mem *mem, ws_web *web)
{
    if (web->imp)
        return 0;
    ws_implicit *im = ws_mem_calloc(mem, 1, sizeof *im);
    if (!im)
        return -1;
    web->imp = im;
    const uint32_t n = web->n, ns = web->ns;
    im->n = n;
    im->ns = ns;
    double *blk = ws_mem_calloc(mem, scratch_doubles(n), sizeof(double));
    im->f = blk;
    im->sp = ws_mem_calloc(mem, ns ? ns : 1, sizeof(ws_ispring));
    im->op = ws_mem_calloc(mem, OPS(ns), sizeof(double));
    im->sf = ws_mem_calloc(mem, VEC(ns ? ns : 1), sizeof(double));
    /* The springs by node: the bodies' coarse space is set up over the springs at their
     * nodes (ws_rigid_coarse_matrix). */
    if (!blk || !im->sp || !im->op || !im->sf || blocks_make(mem, web, im) != 0 ||
        ws_mg_reserve(mem, web, &im->mg) != 0 || ws_web_spring_index(mem, web) != 0) {
        ws_implicit_free(mem, web);
        return -1;
    }
    double *q = blk;
    im->f = q, q += VEC(n);
    im->b = q, q += VEC(n);
    im->dv = q, q += VEC(n);
    im->r = q, q += VEC(n);
    im->z = q, q += VEC(n);
    im->p = q, q += VEC(n);
    im->q = q, q += VEC(n);
    im->fs = q, q += VEC(n);
    im->kc = q, q += SYMS(n);
    im->dc = q, q += SYMS(n);
    im->pinv = q, q += SYMS(n);
    im->nd = q;
    return 0;
}

void ws_implicit_free(ws_mem *mem, ws_web *web)
{
    ws_implicit *im = web->imp;
    if (!im)
        return;
    ws_mg_free(mem, im->mg);
    if (im->f)
        ws_mem_free(mem, im->f, scratch_doubles(im->n) * sizeof(double));
    if (im->sp)
        ws_mem_free(mem, im->sp, (im->ns ? im->ns : 1) * sizeof(ws_ispring));
    if (im->op)
        ws_mem_free(mem, im->op, OPS(im->ns) * sizeof(double));
    if (im->sf)
        ws_mem_free(mem, im->sf, VEC(im->ns ? im->ns : 1) * sizeof(double));
    if (im->blk)
        ws_mem_free(mem, im->blk, im->nblk * sizeof *im->blk);
    if (im->part)
        ws_mem_free(mem, im->part, (size_t)im->nblk * WS_PARTS * sizeof(double));
    if (im->rng)
        ws_mem_free(mem, im->rng, (im->nrng ? im->nrng : 1) * sizeof *im->rng);
    ws_mem_free(mem, im, sizeof *im);
    web->imp = NULL;
}

void ws_implicit_blocks_run(const ws_implicit *im, ws_block_fn *fn, void *ctx)
{
    ws_runner_for(&im->run, im->nblk, fn, ctx);
}

/* A spring in a state (x, v): its direction e (unit, a to b), the velocity of b relative to a,
 * its length l, strain and strain rate; then its law's force F there and the force's
 * derivatives by the strain (Fu) and by the rate (Fud). */
typedef struct spring_state {
    v3 e, dvel;
    double l, eps, rate;
    double F, Fu, Fud;
} spring_state;

/* Spring s at (x, v): its geometry into q. 0 when its ends coincide (no direction: it then
 * neither pulls nor enters the matrix). */
static int spring_geometry(const ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s,
                           spring_state *q)
{
    const uint32_t a = web->sa[s], b = web->sb[s];
    const v3 d = v3_sub(nodes_get(x, b), nodes_get(x, a));
    const double l2 = v3_dot(d, d);
    if (!(l2 > 0.0))
        return 0;
    q->l = sqrt(l2);
    q->e = v3_scale(d, 1.0 / q->l);
    q->dvel = v3_sub(nodes_get(v, b), nodes_get(v, a));
    q->eps = q->l * web->inv_l0[s] - 1.0;
    q->rate = v3_dot(q->dvel, q->e) * web->inv_l0[s];
    return 1;
}

/* Spring s's law at q's strain and rate, at t, since after its history was committed: force
 * and derivatives into q, times its stiffness scale (a mesh web's film layers). 1 when the law
 * failed. */
static int spring_law(const ws_web *web, uint32_t s, double t, double since, spring_state *q)
{
    const double *hist = web->nstate ? web->hist + (size_t)s * web->nstate : NULL;
    if (ws_law_eval(web->law[web->kind[s]], hist, &q->eps, &q->rate, t, since, &q->F, &q->Fu,
                    &q->Fud) != 0)
        return 1;
    if (web->kscale) {
        const double k = web->kscale[s];
        q->F *= k;
        q->Fu *= k;
        q->Fud *= k;
    }
    return 0;
}

/* A broken spring carries nothing (rupture). */
static int spring_broken(const ws_web *web, uint32_t s)
{
    return web->nbroken && web->broken && web->broken[s];
}

/* ws_implicit_begin's passes, block by block: each spring's matrix terms and force F e from
 * its law, by the block of its end a (begin_springs); then each node's force, gravity and drag
 * and its springs' forces in their order (begin_nodes). */
typedef struct begin_pass {
    ws_web *web;
    ws_nodes3 x, v;
    v3 gravity;
    double t, since;
} begin_pass;

static void begin_springs(void *ctx, uint32_t k)
{
    const begin_pass *P = ctx;
    const ws_web *web = P->web;
    ws_implicit *im = web->imp;
    const ws_iblock *B = &im->blk[k];
    int failed = 0;
    for (uint32_t g = B->r0; g < B->r1; g++) {
        if (!(im->rng[g].ends & WS_RUN_A))
            continue; /* their end a's block's */
        for (uint32_t s = im->rng[g].first; s < im->rng[g].end; s++) {
            ws_ispring *q = &im->sp[s];
            double *fe = im->sf + 3 * (size_t)s;
            spring_state z;
            *q = (ws_ispring){0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
            fe[0] = fe[1] = fe[2] = 0.0;
            if (spring_broken(web, s) || !spring_geometry(web, P->x, P->v, s, &z))
                continue;
            if (spring_law(web, s, P->t, P->since, &z) || !isfinite(z.F)) {
                failed = 1;
                continue;
            }
            const v3 e = z.e;
            const double F = z.F, l = z.l, Fu = z.Fu, Fud = z.Fud;
            fe[0] = F * e.x, fe[1] = F * e.y, fe[2] = F * e.z;
            /* -df_a/dx_a = (dF/du / l0 - F / l) e e^T + (F / l) I. In compression F / l is
             * negative and would make the matrix indefinite (the buckling instability of a
             * compressed string): the matrix takes the transverse term only when it pulls, and
             * the axial stiffness never below zero (a softening table law), so it stays
             * positive semi-definite. The rate's dependence on the direction (dF/du_dot times
             * the node's transverse velocity) is left out too: it is not symmetric, and it is
             * small where the film moves slowly across its springs. */
            const double il0 = web->inv_l0[s];
            const double kb = F > 0.0 ? F / l : 0.0;
            double ka = Fu * il0 - kb;
            if (ka < -kb)
                ka = -kb;
            *q = (ws_ispring){e.x, e.y, e.z, ka, kb, Fud > 0.0 ? Fud * il0 : 0.0, 0.0, 0.0};
            failed |= !(isfinite(ka) && isfinite(q->cs));
        }
    }
    im->part[WS_PARTS * (size_t)k + WS_PART_MAX] = failed;
}

static void begin_nodes(void *ctx, uint32_t k)
{
    const begin_pass *P = ctx;
    const ws_web *web = P->web;
    const ws_implicit *im = web->imp;
    const ws_iblock *B = &im->blk[k];
    double *f = im->f;
    const double c = web->damping;
    for (uint32_t i = B->n0; i < B->n1; i++) {
        const double m = web->m[i];
        f[3 * i] = m * P->gravity.x - c * P->v.x[i];
        f[3 * i + 1] = m * P->gravity.y - c * P->v.y[i];
        f[3 * i + 2] = m * P->gravity.z - c * P->v.z[i];
    }
    for (uint32_t g = B->r0; g < B->r1; g++) {
        const uint32_t ends = im->rng[g].ends;
        for (uint32_t s = im->rng[g].first; s < im->rng[g].end; s++) {
            const ws_ispring *q = &im->sp[s];
            if (q->ex == 0.0 && q->ey == 0.0 && q->ez == 0.0)
                continue; /* broken, or its ends together: no force */
            const double *fe = im->sf + 3 * (size_t)s;
            const uint32_t a = web->sa[s], b = web->sb[s];
            if (ends & WS_RUN_A)
                f[3 * a] += fe[0], f[3 * a + 1] += fe[1], f[3 * a + 2] += fe[2];
            if (ends & WS_RUN_B)
                f[3 * b] -= fe[0], f[3 * b + 1] -= fe[1], f[3 * b + 2] -= fe[2];
        }
    }
}

int ws_implicit_begin(ws_web *web, ws_nodes3 x, ws_nodes3 v, v3 gravity, double t, double since)
{
    ws_implicit *im = web->imp;
    im->begun++; /* the springs' blocks are about to change */
    begin_pass P = {web, x, v, gravity, t, since};
    const ws_runner run = im->run;
    /* A law with history or a user's function is not called from the workers (the explicit
     * sweep's rule): the springs' laws then run on this thread. */
    if (!ws_web_sweep_parallel(web))
        im->run.run = NULL;
    ws_implicit_blocks_run(im, begin_springs, &P);
    im->run = run;
    for (uint32_t k = 0; k < im->nblk; k++)
        if (im->part[WS_PARTS * (size_t)k + WS_PART_MAX] != 0.0)
            return 1;
    ws_implicit_blocks_run(im, begin_nodes, &P);
    memcpy(im->fs, im->f, VEC(im->n) * sizeof(double));
    ws_implicit_reset(im);
    return 0;
}

void ws_implicit_reset(ws_implicit *im)
{
    memcpy(im->f, im->fs, VEC(im->n) * sizeof(double));
    memset(im->kc, 0, SYMS(im->n) * sizeof(double));
    memset(im->dc, 0, SYMS(im->n) * sizeof(double));
}

void ws_implicit_add(ws_implicit *im, uint32_t i, v3 f, const double K[WS_SYM],
                     const double D[WS_SYM])
{
    im->f[3 * i] += f.x;
    im->f[3 * i + 1] += f.y;
    im->f[3 * i + 2] += f.z;
    for (int k = 0; k < WS_SYM; k++) {
        im->kc[WS_SYM * (size_t)i + k] += K[k];
        im->dc[WS_SYM * (size_t)i + k] += D[k];
    }
}

/* y = (cm M + cd D + ck K) p, the web's matrices (K = -df/dx, D = -df/dv as the matrix takes
 * them), y zero at pinned nodes: A is cm = 1, cd = h, ck = h^2; the right-hand side's K v0
 * is cm = cd = 0, ck = 1. */
static void combine(const ws_web *web, double cm, double cd, double ck, const double *p,
                    double *y)
{
    const ws_implicit *im = web->imp;
    const uint32_t n = web->n;
    const double drag = cd * web->damping;
    for (uint32_t i = 0; i < n; i++) {
        const double *P = p + 3 * (size_t)i;
        double *Y = y + 3 * (size_t)i;
        const double d = cm * web->m[i] + drag;
        Y[0] = d * P[0];
        Y[1] = d * P[1];
        Y[2] = d * P[2];
        double S[WS_SYM];
        const double *kc = im->kc + WS_SYM * (size_t)i, *dc = im->dc + WS_SYM * (size_t)i;
        for (int k = 0; k < WS_SYM; k++)
            S[k] = ck * kc[k] + cd * dc[k];
        ws_sym_madd(S, P[0], P[1], P[2], Y);
    }
    for (uint32_t s = 0; s < web->ns; s++) {
        const ws_ispring *q = &im->sp[s];
        const double *A = p + 3 * (size_t)web->sa[s], *B = p + 3 * (size_t)web->sb[s];
        const double dx = A[0] - B[0], dy = A[1] - B[1], dz = A[2] - B[2];
        const double a = ck * q->ka + cd * q->cs, b = ck * q->kb;
        const double ed = a * (q->ex * dx + q->ey * dy + q->ez * dz);
        const double tx = ed * q->ex + b * dx, ty = ed * q->ey + b * dy, tz = ed * q->ez + b * dz;
        double *YA = y + 3 * (size_t)web->sa[s], *YB = y + 3 * (size_t)web->sb[s];
        YA[0] += tx;
        YA[1] += ty;
        YA[2] += tz;
        YB[0] -= tx;
        YB[1] -= ty;
        YB[2] -= tz;
    }
    for (uint32_t i = 0; i < n; i++)
        if (web->inv_m[i] == 0.0)
            y[3 * i] = y[3 * i + 1] = y[3 * i + 2] = 0.0;
}

void ws_implicit_apply(const ws_web *web, double h, const double *p, double *y)
{
    combine(web, 1.0, h, h * h, p, y);
}

/* A's parts for step h: each spring's block (a, b) and each node's own block (nd). */
static void operator_for(const ws_web *web, double h)
{
    ws_implicit *im = web->imp;
    const double h2 = h * h;
    for (uint32_t s = 0; s < web->ns; s++) {
        ws_ispring *q = &im->sp[s];
        q->a = h2 * q->ka + h * q->cs;
        q->b = h2 * q->kb;
        double *o = im->op + 5 * (size_t)s;
        o[0] = q->ex, o[1] = q->ey, o[2] = q->ez, o[3] = q->a, o[4] = q->b;
    }
    for (uint32_t i = 0; i < web->n; i++) {
        double *S = im->nd + WS_SYM * (size_t)i;
        const double *kc = im->kc + WS_SYM * (size_t)i, *dc = im->dc + WS_SYM * (size_t)i;
        const double d = web->m[i] + h * web->damping;
        for (int k = 0; k < WS_SYM; k++)
            S[k] = h2 * kc[k] + h * dc[k];
        S[WS_SYM_XX] += d;
        S[WS_SYM_YY] += d;
        S[WS_SYM_ZZ] += d;
    }
}

/* y = A p with the parts operator_for set, and p . y returned. A pinned node's p is zero (its
 * preconditioner is), so its y is not needed: it is set to zero. Block by block (ws_iblock):
 * each node's sum is the springs' order's, whatever the workers. */
typedef struct op_pass {
    const ws_web *web;
    const double *p;
    double *y;
} op_pass;

/* The springs [s0, s1) of a run's terms of y = A p into the ends `ends` names (a constant at
 * each call: its loop tests nothing). */
static inline void op_springs(const ws_web *web, uint32_t s0, uint32_t s1, uint32_t ends,
                              const double *restrict p, double *restrict y)
{
    const ws_implicit *im = web->imp;
    const uint32_t *sa = web->sa, *sb = web->sb;
    for (uint32_t s = s0; s < s1; s++) {
        const double *q = im->op + 5 * (size_t)s; /* ex ey ez a b */
        const uint32_t a = sa[s], b = sb[s];
        const double *A = p + 3 * (size_t)a, *Bp = p + 3 * (size_t)b;
        const double dx = A[0] - Bp[0], dy = A[1] - Bp[1], dz = A[2] - Bp[2];
        const double ed = q[3] * (q[0] * dx + q[1] * dy + q[2] * dz);
        const double tx = ed * q[0] + q[4] * dx, ty = ed * q[1] + q[4] * dy,
                     tz = ed * q[2] + q[4] * dz;
        if (ends & WS_RUN_A) {
            double *YA = y + 3 * (size_t)a;
            YA[0] += tx, YA[1] += ty, YA[2] += tz;
        }
        if (ends & WS_RUN_B) {
            double *YB = y + 3 * (size_t)b;
            YB[0] -= tx, YB[1] -= ty, YB[2] -= tz;
        }
    }
}

static void op_block(void *ctx, uint32_t k)
{
    const op_pass *O = ctx;
    const ws_web *web = O->web;
    const ws_implicit *im = web->imp;
    const ws_iblock *B = &im->blk[k];
    const double *restrict p = O->p;
    double *restrict y = O->y;
    const uint32_t n0 = B->n0;
    for (uint32_t i = n0; i < B->n1; i++) {
        const double *P = p + 3 * (size_t)i, *S = im->nd + WS_SYM * (size_t)i;
        double *Y = y + 3 * (size_t)i;
        Y[0] = S[WS_SYM_XX] * P[0] + S[WS_SYM_XY] * P[1] + S[WS_SYM_XZ] * P[2];
        Y[1] = S[WS_SYM_XY] * P[0] + S[WS_SYM_YY] * P[1] + S[WS_SYM_YZ] * P[2];
        Y[2] = S[WS_SYM_XZ] * P[0] + S[WS_SYM_YZ] * P[1] + S[WS_SYM_ZZ] * P[2];
    }
    for (uint32_t g = B->r0; g < B->r1; g++) {
        const ws_irun *u = &im->rng[g];
        if (u->ends == WS_RUN_AB)
            op_springs(web, u->first, u->end, WS_RUN_AB, p, y);
        else if (u->ends == WS_RUN_A)
            op_springs(web, u->first, u->end, WS_RUN_A, p, y);
        else
            op_springs(web, u->first, u->end, WS_RUN_B, p, y);
    }
    double py = 0.0;
    if (web->same_inv_m) { /* no pinned node */
        for (size_t j = 3 * (size_t)n0; j < 3 * (size_t)B->n1; j++)
            py += p[j] * y[j];
    } else {
        for (uint32_t i = n0; i < B->n1; i++) {
            double *Y = y + 3 * (size_t)i;
            if (web->inv_m[i] == 0.0)
                Y[0] = Y[1] = Y[2] = 0.0;
            py += p[3 * i] * Y[0] + p[3 * i + 1] * Y[1] + p[3 * i + 2] * Y[2];
        }
    }
    im->part[WS_PARTS * (size_t)k + WS_PART_SUM] = py;
}

/* The blocks' sums of slot `slot` added in block order. */
static double parts_sum(const ws_implicit *im, int slot)
{
    double s = 0.0;
    for (uint32_t k = 0; k < im->nblk; k++)
        s += im->part[WS_PARTS * (size_t)k + (size_t)slot];
    return s;
}

double ws_implicit_apply_op(const ws_web *web, const double *restrict p, double *restrict y)
{
    op_pass O = {web, p, y};
    ws_implicit_blocks_run(web->imp, op_block, &O);
    return parts_sum(web->imp, WS_PART_SUM);
}

/* The inverse of every node's diagonal block of A (block Jacobi); a pinned node's is zero, so
 * its dv stays zero. 0, or -1 when a block is not positive definite (NaN, or a matrix broken
 * by its inputs). */
static int preconditioner(const ws_web *web, double h)
{
    const ws_implicit *im = web->imp;
    const uint32_t n = web->n;
    const double h2 = h * h;
    double *P = im->pinv;
    for (uint32_t i = 0; i < n; i++) {
        double *S = P + WS_SYM * (size_t)i;
        const double d = web->m[i] + h * web->damping;
        for (int k = 0; k < WS_SYM; k++)
            S[k] = h2 * im->kc[WS_SYM * (size_t)i + k] + h * im->dc[WS_SYM * (size_t)i + k];
        S[WS_SYM_XX] += d;
        S[WS_SYM_YY] += d;
        S[WS_SYM_ZZ] += d;
    }
    for (uint32_t s = 0; s < web->ns; s++) {
        const ws_ispring *q = &im->sp[s];
        const v3 e = v3_make(q->ex, q->ey, q->ez);
        const double a = h2 * q->ka + h * q->cs, b = h2 * q->kb;
        for (int k = 0; k < 2; k++) {
            double *S = P + WS_SYM * (size_t)(k ? web->sb[s] : web->sa[s]);
            ws_sym_add_outer(S, a, e);
            S[WS_SYM_XX] += b;
            S[WS_SYM_YY] += b;
            S[WS_SYM_ZZ] += b;
        }
    }
    for (uint32_t i = 0; i < n; i++) {
        double *S = P + WS_SYM * (size_t)i;
        if (web->inv_m[i] == 0.0) {
            memset(S, 0, WS_SYM * sizeof(double));
            continue;
        }
        if (ws_sym_invert(S, S) != 0)
            return -1;
    }
    return 0;
}

int ws_sym_invert(const double *S, double *out)
{
    const double a = S[WS_SYM_XX], b = S[WS_SYM_YY], c = S[WS_SYM_ZZ], d = S[WS_SYM_XY],
                 e = S[WS_SYM_XZ], f = S[WS_SYM_YZ];
    /* Cofactors of the symmetric block. */
    const double cxx = b * c - f * f, cyy = a * c - e * e, czz = a * b - d * d,
                 cxy = e * f - d * c, cxz = d * f - b * e, cyz = d * e - a * f;
    const double det = a * cxx + d * cxy + e * cxz;
    if (!(det > 0.0 && a > 0.0 && czz > 0.0) || !isfinite(det))
        return -1;
    const double id = 1.0 / det;
    out[WS_SYM_XX] = cxx * id;
    out[WS_SYM_YY] = cyy * id;
    out[WS_SYM_ZZ] = czz * id;
    out[WS_SYM_XY] = cxy * id;
    out[WS_SYM_XZ] = cxz * id;
    out[WS_SYM_YZ] = cyz * id;
    return 0;
}

static double dot(const double *a, const double *b, size_t m)
{
    double s = 0.0;
    for (size_t k = 0; k < m; k++)
        s += a[k] * b[k];
    return s;
}

/* z = P r, P the block-Jacobi preconditioner; returns r . z. */
static double precondition(const ws_implicit *im, uint32_t n, const double *restrict r,
                           double *restrict z)
{
    double rz = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        const double *R = r + 3 * (size_t)i, *S = im->pinv + WS_SYM * (size_t)i;
        double *Z = z + 3 * (size_t)i;
        Z[0] = S[WS_SYM_XX] * R[0] + S[WS_SYM_XY] * R[1] + S[WS_SYM_XZ] * R[2];
        Z[1] = S[WS_SYM_XY] * R[0] + S[WS_SYM_YY] * R[1] + S[WS_SYM_YZ] * R[2];
        Z[2] = S[WS_SYM_XZ] * R[0] + S[WS_SYM_YZ] * R[1] + S[WS_SYM_ZZ] * R[2];
        rz += R[0] * Z[0] + R[1] * Z[1] + R[2] * Z[2];
    }
    return rz;
}

/* Standard gravity, m/s^2: the stopping test's weight impulses take it whatever the world's
 * gravity, so that a film in zero g is solved as finely as on earth. */
#define STOP_G 9.81

/* The largest squared residual over the nodes as the velocity change it would give the node's
 * own mass, |r_i|^2 / m_i^2 (m^2/s^2; a pinned node's is zero). */
static double nodes_worst2(const ws_web *web, const double *r)
{
    double w2 = 0.0;
    for (uint32_t i = 0; i < web->n; i++) {
        const double *Q = r + 3 * (size_t)i, u = web->inv_m[i];
        const double s = (Q[0] * Q[0] + Q[1] * Q[1] + Q[2] * Q[2]) * (u * u);
        if (s > w2)
            w2 = s;
    }
    return w2;
}

/* The same over the bodies' rows rr (6 a body): a body's force rows |r_V|^2 / m^2, its turning
 * rows r_W . I^-1 r_W / m, the squared speed (rms over the body's mass) of the spin change
 * r_W would give it. A body whose inertia does not invert (none in the solve: its block
 * factored) is measured by its force rows alone. */
static double bodies_worst2(const ws_rigid *R, const double *rr)
{
    double w2 = 0.0;
    for (uint32_t j = 0; j < R->nb; j++) {
        const double *Q = rr + 6 * (size_t)j, m = R->mass[j];
        const double lin = (Q[0] * Q[0] + Q[1] * Q[1] + Q[2] * Q[2]) / (m * m);
        double Ii[WS_SYM], u[3] = {0.0, 0.0, 0.0}, ang = 0.0;
        if (ws_sym_invert(R->inertia + WS_SYM * (size_t)j, Ii) == 0) {
            ws_sym_madd(Ii, Q[3], Q[4], Q[5], u);
            ang = (Q[3] * u[0] + Q[4] * u[1] + Q[5] * u[2]) / m;
        }
        if (lin > w2)
            w2 = lin;
        if (ang > w2)
            w2 = ang;
    }
    return w2;
}

/* Where the residual sits at the end of a solve, by kind of row (ws_implicit's last_worst and
 * last_rr): a node with a contact block (K or D) is a pressed one. */
static void residual_sites(ws_implicit *im, const ws_web *web, const ws_rigid *R, double gh)
{
    for (int k = 0; k < 3; k++)
        im->last_worst[k] = im->last_rr[k] = 0.0;
    for (uint32_t i = 0; i < web->n; i++) {
        const double *Q = im->r + 3 * (size_t)i, mi = web->inv_m[i];
        const double *kc = im->kc + WS_SYM * (size_t)i, *dc = im->dc + WS_SYM * (size_t)i;
        int pressed = 0;
        for (int k = 0; k < WS_SYM; k++)
            pressed |= kc[k] != 0.0 || dc[k] != 0.0;
        const double s = Q[0] * Q[0] + Q[1] * Q[1] + Q[2] * Q[2];
        im->last_rr[pressed] += s;
        im->last_worst[pressed] = fmax(im->last_worst[pressed], sqrt(s) * mi / gh);
    }
    if (R) {
        im->last_rr[2] = ws_rigid_dot(R, R->r, R->r);
        im->last_worst[2] = sqrt(bodies_worst2(R, R->r)) / gh;
    }
}

/* A bench's probe (ws_implicit_probe): each kind's largest row measure of the residual (r, and
 * R's rows) over the goal and its rows above 1 into top and above, the largest row of all into
 * *row, *kind, *value. */
static void probe_rows(const ws_implicit *im, const ws_web *web, const ws_rigid *R,
                       const double *r, double goal, double *top, uint32_t *above,
                       uint32_t *row, int *kind, double *value)
{
    const uint8_t *state = im->probe->state;
    for (int k = 0; k < WS_PROBE_KINDS; k++)
        top[k] = 0.0, above[k] = 0;
    *value = -1.0;
    for (uint32_t i = 0; i < web->n; i++) {
        const double *Q = r + 3 * (size_t)i, *kc = im->kc + WS_SYM * (size_t)i;
        const double *dc = im->dc + WS_SYM * (size_t)i;
        int pressed = 0;
        for (int k = 0; k < WS_SYM; k++)
            pressed |= kc[k] != 0.0 || dc[k] != 0.0;
        const int kd = !pressed ? 0 : state && state[i] == 3 ? 2 : 1;
        const double s = sqrt(Q[0] * Q[0] + Q[1] * Q[1] + Q[2] * Q[2]) * web->inv_m[i] / goal;
        top[kd] = fmax(top[kd], s);
        above[kd] += s > 1.0;
        if (s > *value)
            *value = s, *row = i, *kind = kd;
    }
    for (uint32_t j = 0; R && j < R->nb; j++) {
        ws_rigid one = *R;
        one.nb = 1;
        one.mass = R->mass + j;
        one.inertia = R->inertia + WS_SYM * (size_t)j;
        const double s = sqrt(bodies_worst2(&one, R->r + 6 * (size_t)j)) / goal;
        top[3] = fmax(top[3], s);
        above[3] += s > 1.0;
        if (s > *value)
            *value = s, *row = web->n + j, *kind = 3;
    }
}

/* z = P r over the film's part (r, z) and the bodies' (R->r, R->z; R NULL when none): the
 * multigrid's cycle over both when the bodies are nested in it (nest); otherwise the film's
 * preconditioner (the multigrid mg, or block Jacobi when NULL), then each body's block and the
 * coarse correction added (docs/theory.md 8b). Returns r . z over both parts. */
static double precondition_all(const ws_implicit *im, const ws_web *web, ws_mg *nest, ws_mg *mg,
                               const ws_rigid *R, const double *r, double *z)
{
    if (nest)
        return ws_mg_apply_bodies(nest, web, r, z, R->r, R->z);
    double rz = mg ? ws_mg_apply(mg, web, r, z) : precondition(im, web->n, r, z);
    if (R) /* after the film's part, which its coarse correction adds to */
        rz += ws_rigid_precondition(R, r, z, R->r, R->z);
    return rz;
}

/* A CG iteration's passes over the film's rows, block by block: dv += alpha p and r -= alpha q
 * with each block's sum of |r_i|^2 and largest |r_i|^2 / m_i^2 (cg_step_block), and p = z + beta
 * p (cg_direction_block). */
typedef struct cg_pass {
    const ws_web *web;
    double alpha, beta;
} cg_pass;

static void cg_step_block(void *ctx, uint32_t k)
{
    const cg_pass *C = ctx;
    const ws_web *web = C->web;
    const ws_implicit *im = web->imp;
    const ws_iblock *B = &im->blk[k];
    const double alpha = C->alpha;
    double rr = 0.0, w2 = 0.0;
    for (uint32_t i = B->n0; i < B->n1; i++) {
        double *X = im->dv + 3 * (size_t)i, *Q = im->r + 3 * (size_t)i;
        const double *P = im->p + 3 * (size_t)i, *AP = im->q + 3 * (size_t)i;
        X[0] += alpha * P[0], X[1] += alpha * P[1], X[2] += alpha * P[2];
        Q[0] -= alpha * AP[0], Q[1] -= alpha * AP[1], Q[2] -= alpha * AP[2];
        const double s = Q[0] * Q[0] + Q[1] * Q[1] + Q[2] * Q[2], u = web->inv_m[i];
        rr += s;
        if (s * (u * u) > w2)
            w2 = s * (u * u);
    }
    im->part[WS_PARTS * (size_t)k + WS_PART_SUM] = rr;
    im->part[WS_PARTS * (size_t)k + WS_PART_MAX] = w2;
}

static void cg_direction_block(void *ctx, uint32_t k)
{
    const cg_pass *C = ctx;
    const ws_implicit *im = C->web->imp;
    const ws_iblock *B = &im->blk[k];
    for (size_t j = 3 * (size_t)B->n0; j < 3 * (size_t)B->n1; j++)
        im->p[j] = im->z[j] + C->beta * im->p[j];
}

int ws_implicit_solve(ws_web *web, ws_nodes3 v, double h)
{
    ws_implicit *im = web->imp;
    const uint32_t n = web->n;
    const size_t m = VEC(n);
    double *b = im->b, *x = im->dv, *r = im->r, *z = im->z, *p = im->p, *q = im->q;
    ws_rigid *R = im->rig && im->rig->nb ? im->rig : NULL; /* bodies in the solve */
    im->solves++;
    if (R && R->bstart) { /* each block's first link, when they are in node order */
        R->blocked = 1;
        for (size_t e = 1; e < R->nl; e++)
            R->blocked &= R->link[e].node >= R->link[e - 1].node;
        ws_rigid_block_starts(R, im->blk, im->nblk, R->bstart);
    }
    im->last_iterations = 0;
    /* b = h f + h^2 df/dx v0 = h f - h^2 K v0; and the film's weight over the step, the floor
     * of the earlier relative test's scale (a film at rest, b about 0, was not asked for a
     * residual below round-off; the rows' test's weights are that floor row by row). */
    for (uint32_t i = 0; i < n; i++) {
        z[3 * i] = v.x[i];
        z[3 * i + 1] = v.y[i];
        z[3 * i + 2] = v.z[i];
    }
    combine(web, 0.0, 0.0, 1.0, z, q);
    double weight2 = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            const size_t j = 3 * (size_t)i + (size_t)k;
            b[j] = web->inv_m[i] == 0.0 ? 0.0 : h * im->f[j] - h * h * q[j];
        }
        weight2 += web->m[i] * web->m[i];
    }
    /* The stopping test: every row's residual, as the velocity change it would give its own
     * mass, at most tol g h, each node and body solved to that fraction of its weight over the
     * step (docs/theory.md 8). A norm over the whole film would let the rows where the film
     * holds the boxes (a light pressed node, a box's) keep errors that move the stack's
     * thresholds, and its right-hand side, the pretension's forces, would set the scale. The
     * measure is squared (lim): meas below. stop_relative: the earlier test, the residual's
     * norm against the larger of |b| and the film's weight impulse (the film's alone). */
    const double gh = h * STOP_G;
    const double scale = im->stop_relative ? fmax(sqrt(dot(b, b, m)), gh * sqrt(weight2))
                                                 : gh;
    const double goal = web->solver_tol * scale, lim = goal * goal;
    if (preconditioner(web, h) != 0 || (R && ws_rigid_factor(R) != 0)) {
        im->warm = 0;
        im->last_residual = NAN;
        return -1;
    }
    operator_for(web, h);
    if (!im->warm)
        memset(x, 0, m * sizeof(double));
    for (uint32_t i = 0; i < n; i++) /* a pinned node's dv is zero (the warm start's too) */
        if (web->inv_m[i] == 0.0)
            x[3 * i] = x[3 * i + 1] = x[3 * i + 2] = 0.0;
    if (R && im->warm && !im->cold_bodies) {
        /* The bodies' start from the film's (a block Gauss-Seidel step): dU += A_bb^-1 (b_U -
         * A_bb dU - A_bf dv), the bodies' best velocity change given the warm film. */
        memset(z, 0, m * sizeof(double));
        (void)ws_rigid_apply(R, web, x, R->x, z, R->q);
        for (size_t j = 0; j < 6 * (size_t)R->nb; j++)
            R->r[j] = R->b[j] - R->q[j];
        ws_rigid_block_solve(R, R->r, R->z);
        for (size_t j = 0; j < 6 * (size_t)R->nb; j++)
            R->x[j] += R->z[j];
    }
    (void)ws_implicit_apply_op(web, x, q);
    if (R)
        (void)ws_rigid_apply(R, web, x, R->x, q, R->q);
    for (size_t j = 0; j < m; j++)
        r[j] = b[j] - q[j];
    double rr = dot(r, r, m);
    double meas = im->stop_relative ? rr : nodes_worst2(web, r);
    if (R && !im->stop_relative) {
        for (size_t j = 0; j < 6 * (size_t)R->nb; j++)
            R->r[j] = R->b[j] - R->q[j];
        meas = fmax(meas, bodies_worst2(R, R->r));
    }
    /* The multigrid's coarse levels only for a solve that iterates: a calm film's warm start
     * often meets the tolerance already. The bodies of the solve nested in it when the world
     * gave it room for them. */
    const int nests = im->mg && ws_mg_bodies(im->mg, R, R ? R->mgbuf : NULL);
    ws_mg *mg = im->mg && !im->jacobi_only && !(meas <= lim) &&
                        ws_mg_setup(im->mg, web, im->begun, h) == 0
                    ? im->mg
                    : NULL;
    const int nested = mg && nests;
    /* The bodies' coarse space, unless they are nested in the multigrid (which resolves their
     * modes on every level). */
    if (R && R->coarse && !nested && ws_rigid_coarse(R, web) != 0) {
        im->warm = 0;
        im->last_residual = NAN;
        return -1;
    }
    if (R) {
        for (size_t j = 0; j < 6 * (size_t)R->nb; j++)
            R->r[j] = R->b[j] - R->q[j];
        rr += ws_rigid_dot(R, R->r, R->r);
    }
    double rz = precondition_all(im, web, nested ? mg : NULL, mg, R, r, z);
    if (R)
        memcpy(R->p, R->z, 6 * (size_t)R->nb * sizeof(double));
    if (im->stop_relative)
        meas = rr;
    if (!isfinite(rr))
        meas = NAN; /* a NaN row is never met */
    memcpy(p, z, m * sizeof(double));
    ws_implicit_probe *pr = im->probe;
    const int first = pr && pr->solves == 0;
    double ptop[WS_PROBE_KINDS];
    uint32_t pabove[WS_PROBE_KINDS];
    if (pr) {
        probe_rows(im, web, R, r, goal, ptop, pabove, &pr->bind_row, &pr->bind_kind,
                   &pr->bind_value);
        if (first)
            for (int k = 0; k < WS_PROBE_KINDS; k++) {
                pr->start[k] = ptop[k], pr->above0[k] = pabove[k];
                for (int mk = 0; mk < WS_PROBE_MARKS; mk++)
                    pr->above[mk][k] = 0;
            }
    }
    int it = 0;
    while (!(meas <= lim) && it < web->solver_maxit) {
        if (pr && it > 0)
            probe_rows(im, web, R, r, goal, ptop, pabove, &pr->bind_row, &pr->bind_kind,
                       &pr->bind_value);
        const double pq = ws_implicit_apply_op(web, p, q) +
                          (R ? ws_rigid_apply(R, web, p, R->p, q, R->q) : 0.0);
        if (!(pq > 0.0) || !isfinite(pq))
            break; /* not positive definite along p, or NaN: no progress possible */
        const double alpha = rz / pq;
        rr = R ? ws_rigid_step(R, alpha) : 0.0;
        double w2 = R && !im->stop_relative ? bodies_worst2(R, R->r) : 0.0;
        cg_pass C = {web, alpha, 0.0};
        ws_implicit_blocks_run(im, cg_step_block, &C);
        rr += parts_sum(im, WS_PART_SUM);
        for (uint32_t k = 0; k < im->nblk; k++)
            w2 = fmax(w2, im->part[WS_PARTS * (size_t)k + WS_PART_MAX]);
        meas = !isfinite(rr) ? NAN : im->stop_relative ? rr : w2;
        it++;
        if (first && (it & (it - 1)) == 0 && it <= 32) {
            uint32_t row;
            int kind;
            double value;
            probe_rows(im, web, R, r, goal, ptop, pabove, &row, &kind, &value);
            int mk = 0;
            while ((1 << mk) != it)
                mk++;
            memcpy(pr->above[mk], pabove, sizeof pabove);
        }
        const double rz1 = precondition_all(im, web, nested ? mg : NULL, mg, R, r, z);
        const double beta = rz1 / rz;
        rz = rz1;
        cg_pass D = {web, 0.0, beta};
        ws_implicit_blocks_run(im, cg_direction_block, &D);
        if (R)
            ws_rigid_direction(R, beta);
    }
    im->iterations += (uint64_t)it;
    im->last_iterations = it;
    if (pr) {
        if (pr->solves < WS_PROBE_PASSES)
            pr->it[pr->solves] = (uint32_t)it;
        pr->solves++;
    }
    im->last_residual = scale > 0.0 ? sqrt(meas) / scale : 0.0;
    residual_sites(im, web, R, gh);
    const int ok = meas <= lim;
    im->warm = ok;
    return ok ? 0 : -1;
}

void ws_implicit_velocities(const ws_web *web, ws_nodes3 v, ws_nodes3 vd)
{
    const double *dv = web->imp->dv;
    for (uint32_t i = 0; i < web->n; i++) {
        vd.x[i] = v.x[i] + dv[3 * i];
        vd.y[i] = v.y[i] + dv[3 * i + 1];
        vd.z[i] = v.z[i] + dv[3 * i + 2];
    }
}

size_t ws_implicit_finish(const ws_web *web, ws_nodes3 x, ws_nodes3 xd, ws_nodes3 vd, double h,
                          double vmax)
{
    size_t fast = 0;
    for (uint32_t i = 0; i < web->n; i++) {
        const double ux = vd.x[i], uy = vd.y[i], uz = vd.z[i];
        xd.x[i] = x.x[i] + h * ux;
        xd.y[i] = x.y[i] + h * uy;
        xd.z[i] = x.z[i] + h * uz;
        const double s2 = ux * ux + uy * uy + uz * uz;
        fast += !(s2 <= vmax * vmax) || s2 > DBL_MAX;
    }
    return fast;
}

int ws_implicit_spring_exact(const ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s, double t,
                             double since, double Jx[9], double Jv[9])
{
    spring_state z;
    memset(Jx, 0, 9 * sizeof(double));
    memset(Jv, 0, 9 * sizeof(double));
    if (spring_broken(web, s) || !spring_geometry(web, x, v, s, &z))
        return 0;
    if (spring_law(web, s, t, since, &z))
        return 1;
    const v3 e = z.e, dvel = z.dvel;
    const double F = z.F, l = z.l, Fu = z.Fu, Fud = z.Fud;
    /* f_a = F e: d/dx_b = e dF/dx_b + F de/dx_b, with de/dx_b = (I - e e^T) / l, deps/dx_b =
     * e^T / l0 and drate/dx_b = dvel^T (I - e e^T) / (l l0); d/dv_b = Fud e e^T / l0. */
    const double il0 = web->inv_l0[s];
    const double ev[3] = {e.x, e.y, e.z}, dv[3] = {dvel.x, dvel.y, dvel.z};
    double g[3]; /* dvel^T (I - e e^T) */
    const double de = v3_dot(dvel, e);
    for (int k = 0; k < 3; k++)
        g[k] = dv[k] - de * ev[k];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            const double P = (i == k) - ev[i] * ev[k];
            Jx[3 * i + k] = ev[i] * (Fu * il0 * ev[k] + Fud * il0 * g[k] / l) + F * P / l;
            Jv[3 * i + k] = Fud * il0 * ev[i] * ev[k];
        }
    return 0;
}
