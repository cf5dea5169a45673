/* Rigid bodies in an implicit web's solve (web/coupled.h says the system; docs/theory.md,
 * section 8b, why). */
#include "web/coupled.h"

#include <stdlib.h>
#include <string.h>

/* sign J_i^T C J_j into the block of bodies i (rows) and j (columns) of the n x n A (row-major):
 * column k is J_i^T C J_j e_k, with J_j e_k body j's point at lever rj moving for a unit
 * velocity (k < 3) or spin (k >= 3) and J_i^T g = (g, ri x g). */
static void add_coupling(double *A, size_t n, uint32_t i, v3 ri, uint32_t j, v3 rj,
                         const double *C, double sign)
{
    double *B = A + 6 * (size_t)i * n + 6 * (size_t)j;
    for (int k = 0; k < 6; k++) {
        v3 e = v3_make(k % 3 == 0, k % 3 == 1, k % 3 == 2);
        const v3 a = k < 3 ? e : v3_cross(e, rj);
        double g[3] = {0.0, 0.0, 0.0};
        ws_sym_madd(C, a.x, a.y, a.z, g);
        const v3 gv = v3_make(g[0], g[1], g[2]), m = v3_cross(ri, gv);
        const double col[6] = {g[0], g[1], g[2], m.x, m.y, m.z};
        for (int q = 0; q < 6; q++)
            B[n * (size_t)q + (size_t)k] += sign * col[q];
    }
}

/* The envelope of the symmetric n x n A (row-major) into env (2 n words): row i's first entry
 * that is not zero, env[i], and column j's last, env[n + j] (the largest i with env[i] <= j;
 * j itself when none is later). */
static void envelope(const double *A, size_t n, uint32_t *env)
{
    for (size_t i = 0; i < n; i++) {
        size_t f = 0;
        while (f < i && A[n * i + f] == 0.0)
            f++;
        env[i] = (uint32_t)f;
        env[n + i] = (uint32_t)i;
    }
    for (size_t i = 0; i < n; i++) /* row i reaches down to column env[i] */
        if (env[n + env[i]] < i)
            env[n + env[i]] = (uint32_t)i;
    for (size_t j = 1; j < n; j++) /* and so every column after it, up to i */
        if (env[n + j] < env[n + j - 1])
            env[n + j] = env[n + j - 1];
}

/* The lower Cholesky factor of the symmetric n x n B (row-major), in place, over the envelope
 * env (envelope(); row i's entries before column env[i] are zero, and stay zero in the factor;
 * NULL: all of each row): the products of zeros a dense factor would add are left out. 0, or
 * -1 when not positive definite. */
static int cholesky(double *B, size_t n, const uint32_t *env)
{
    for (size_t j = 0; j < n; j++) {
        const size_t fj = env ? env[j] : 0, last = env ? env[n + j] : n - 1;
        double d = B[n * j + j];
        for (size_t k = fj; k < j; k++)
            d -= B[n * j + k] * B[n * j + k];
        if (!(d > 0.0) || !isfinite(d))
            return -1;
        const double l = sqrt(d);
        B[n * j + j] = l;
        for (size_t i = j + 1; i <= last; i++) {
            const size_t fi = env ? env[i] : 0;
            if (fi > j)
                continue; /* outside the envelope: zero */
            double s = B[n * i + j];
            for (size_t k = fi > fj ? fi : fj; k < j; k++)
                s -= B[n * i + k] * B[n * j + k];
            B[n * i + j] = s / l;
        }
    }
    return 0;
}

/* z = (L L^T)^-1 r for the factor L of cholesky over the envelope env (NULL: none; z may be
 * r). */
static void cholesky_solve(const double *L, size_t n, const uint32_t *env, const double *r,
                           double *z)
{
    for (size_t i = 0; i < n; i++) {
        double s = r[i];
        for (size_t k = env ? env[i] : 0; k < i; k++)
            s -= L[n * i + k] * z[k];
        z[i] = s / L[n * i + i];
    }
    for (size_t i = n; i-- > 0;) {
        double s = z[i];
        const size_t last = env ? env[n + i] : n - 1;
        for (size_t k = i + 1; k <= last; k++)
            if (!env || env[k] <= i)
                s -= L[n * k + i] * z[k];
        z[i] = s / L[n * i + i];
    }
}

int ws_rigid_factor(ws_rigid *R)
{
    const size_t n = 6 * (size_t)R->nb;
    double *A = R->abb;
    memset(A, 0, n * n * sizeof(double));
    const int ix[3][3] = {{WS_SYM_XX, WS_SYM_XY, WS_SYM_XZ},
                          {WS_SYM_XY, WS_SYM_YY, WS_SYM_YZ},
                          {WS_SYM_XZ, WS_SYM_YZ, WS_SYM_ZZ}};
    for (uint32_t j = 0; j < R->nb; j++) {
        double *B = A + 6 * (size_t)j * (n + 1);
        const double *I = R->inertia + WS_SYM * (size_t)j;
        B[0] = B[n + 1] = B[2 * n + 2] = R->mass[j];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                B[n * (size_t)(3 + i) + 3 + (size_t)k] = I[ix[i][k]];
    }
    for (size_t l = 0; l < R->nl; l++) {
        const ws_rigid_link *L = &R->link[l];
        add_coupling(A, n, L->body, L->lever, L->body, L->lever, L->C, 1.0);
    }
    /* A pair's energy (J_b dU_b - J_a dU_a)^T C (J_b dU_b - J_a dU_a): J^T C J at each end
     * of a body in the solve, -J_a^T C J_b and its transpose between the two. */
    for (size_t q = 0; q < R->npair; q++) {
        const ws_rigid_pair *P = &R->pair[q];
        if (P->a != UINT32_MAX)
            add_coupling(A, n, P->a, P->ra, P->a, P->ra, P->C, 1.0);
        if (P->b != UINT32_MAX)
            add_coupling(A, n, P->b, P->rb, P->b, P->rb, P->C, 1.0);
        if (P->a != UINT32_MAX && P->b != UINT32_MAX && !R->apart) {
            add_coupling(A, n, P->a, P->ra, P->b, P->rb, P->C, -1.0);
            add_coupling(A, n, P->b, P->rb, P->a, P->ra, P->C, -1.0);
        }
    }
    /* Each row's envelope: a body's rows start at the first body coupled to it (itself, with
     * no pair to an earlier one), so that the factor of bodies with no pair costs what their
     * own blocks' do. */
    envelope(A, n, R->env);
    memcpy(R->fac, A, n * n * sizeof(double));
    return cholesky(R->fac, n, R->env);
}

void ws_rigid_block_solve(const ws_rigid *R, const double *r, double *z)
{
    cholesky_solve(R->fac, 6 * (size_t)R->nb, R->env, r, z);
}

/* Row i of the symmetric S times (x, y, z): what ws_sym_madd adds, without the add to a
 * zero the product loop would otherwise pay twice a contact. */
static inline double sym_row(const double *S, int i, double x, double y, double z)
{
    static const int ix[3][3] = {{WS_SYM_XX, WS_SYM_XY, WS_SYM_XZ},
                                 {WS_SYM_XY, WS_SYM_YY, WS_SYM_YZ},
                                 {WS_SYM_XZ, WS_SYM_YZ, WS_SYM_ZZ}};
    return S[ix[i][0]] * x + S[ix[i][1]] * y + S[ix[i][2]] * z;
}

/* Y = M_j P: body j's mass and inertia times its six velocities P. */
static void body_mass_apply(const ws_rigid *R, uint32_t j, const double *P, double *Y)
{
    const double m = R->mass[j];
    Y[0] = m * P[0], Y[1] = m * P[1], Y[2] = m * P[2];
    Y[3] = Y[4] = Y[5] = 0.0;
    ws_sym_madd(R->inertia + WS_SYM * (size_t)j, P[3], P[4], P[5], Y + 3);
}

/* The motion J u of the point at lever r of body j for the six velocities u of each body (6
 * a body); zero for a side not in the solve (j UINT32_MAX). */
static v3 point_move(const double *u, uint32_t j, v3 r)
{
    if (j == UINT32_MAX)
        return v3_make(0.0, 0.0, 0.0);
    const double *P = u + 6 * (size_t)j;
    return v3_add(v3_make(P[0], P[1], P[2]), v3_cross(v3_make(P[3], P[4], P[5]), r));
}

/* J^T g at lever r into body j's six rows Y (6 a body), times sign; nothing for a side not in
 * the solve. */
static void point_load(double *Y, uint32_t j, v3 r, v3 g, double sign)
{
    if (j == UINT32_MAX)
        return;
    double *o = Y + 6 * (size_t)j;
    const v3 m = v3_cross(r, g);
    o[0] += sign * g.x, o[1] += sign * g.y, o[2] += sign * g.z;
    o[3] += sign * m.x, o[4] += sign * m.y, o[5] += sign * m.z;
}

/* The pairs' terms of yr = A pr: g = C (J_b p_b - J_a p_a), J_b^T g into b's rows, -J_a^T g
 * into a's. */
static void pairs_apply(const ws_rigid *R, const double *pr, double *yr)
{
    for (size_t q = 0; q < R->npair; q++) {
        const ws_rigid_pair *P = &R->pair[q];
        const v3 d = ws_rigid_pair_slip(R, q, pr);
        double g[3] = {0.0, 0.0, 0.0};
        ws_sym_madd(P->C, d.x, d.y, d.z, g);
        const v3 gv = v3_make(g[0], g[1], g[2]);
        point_load(yr, P->b, P->rb, gv, 1.0);
        point_load(yr, P->a, P->ra, gv, -1.0);
    }
}

/* The film's contacts' terms of ws_rigid_apply for links [l0, l1): -C J pr into y at their
 * nodes (not at pinned ones), the bodies' rows into yr (added to what is there); returns p .
 * (what it added to y). A run of links on one body (a node's neighbours mostly press on the
 * same box) sums its body's row in registers, stored once at the run's end: the same sums in
 * the same order as adding into yr link by link, without a chain of loads and stores through
 * memory. */
static double links_apply(const ws_rigid *R, const ws_web *web, size_t l0, size_t l1,
                          const double *p, const double *pr, double *y, double *yr)
{
    double added = 0.0;
    size_t l = l0;
    while (l < l1) {
        const uint32_t j = R->link[l].body;
        const double *P = pr + 6 * (size_t)j;
        const v3 V = v3_make(P[0], P[1], P[2]), W = v3_make(P[3], P[4], P[5]);
        double *Y = yr + 6 * (size_t)j;
        double y0 = Y[0], y1 = Y[1], y2 = Y[2], y3 = Y[3], y4 = Y[4], y5 = Y[5];
        for (; l < l1 && R->link[l].body == j; l++) {
            const ws_rigid_link *L = &R->link[l];
            const double *pn = p + 3 * (size_t)L->node;
            /* The contact point's motion J P, the node's relative to it, and C on both. */
            const v3 jp = v3_add(V, v3_cross(W, L->lever));
            const double cj[3] = {sym_row(L->C, 0, jp.x, jp.y, jp.z),
                                  sym_row(L->C, 1, jp.x, jp.y, jp.z),
                                  sym_row(L->C, 2, jp.x, jp.y, jp.z)};
            /* g = C (p_node - J P) */
            const double g[3] = {sym_row(L->C, 0, pn[0], pn[1], pn[2]) - cj[0],
                                 sym_row(L->C, 1, pn[0], pn[1], pn[2]) - cj[1],
                                 sym_row(L->C, 2, pn[0], pn[1], pn[2]) - cj[2]};
            const v3 m = v3_cross(L->lever, v3_make(g[0], g[1], g[2]));
            y0 -= g[0], y1 -= g[1], y2 -= g[2];
            y3 -= m.x, y4 -= m.y, y5 -= m.z;
            if (web->inv_m[L->node] == 0.0)
                continue; /* a pinned node's row stays zero (its dv is) */
            double *yn = y + 3 * (size_t)L->node;
            yn[0] -= cj[0], yn[1] -= cj[1], yn[2] -= cj[2];
            added -= pn[0] * cj[0] + pn[1] * cj[1] + pn[2] * cj[2];
        }
        Y[0] = y0, Y[1] = y1, Y[2] = y2, Y[3] = y3, Y[4] = y4, Y[5] = y5;
    }
    return added;
}

/* links_apply over the links of the solve's block b (R->bstart), the bodies' rows into the
 * block's share (R->bpart), what it adds to p . y into the solve's block sums. */
typedef struct rigid_pass {
    const ws_rigid *R;
    const ws_web *web;
    const double *p, *pr;
    double *y;
} rigid_pass;

static void rigid_block(void *ctx, uint32_t b)
{
    const rigid_pass *P = ctx;
    const ws_rigid *R = P->R;
    double *part = R->bpart + 6 * (size_t)R->nb * b;
    memset(part, 0, 6 * (size_t)R->nb * sizeof(double));
    P->web->imp->part[WS_PARTS * (size_t)b + WS_PART_SUM] =
        links_apply(R, P->web, R->bstart[b], R->bstart[b + 1], P->p, P->pr, P->y, part);
}

void ws_rigid_block_starts(const ws_rigid *R, const ws_iblock *blk, uint32_t nblk, size_t *start)
{
    size_t l = 0;
    for (uint32_t k = 0; k < nblk; k++) {
        while (l < R->nl && R->link[l].node < blk[k].n0)
            l++;
        start[k] = l;
    }
    start[nblk] = R->nl;
}

double ws_rigid_apply(const ws_rigid *R, const ws_web *web, const double *p, const double *pr,
                      double *y, double *yr)
{
    for (uint32_t j = 0; j < R->nb; j++)
        body_mass_apply(R, j, pr + 6 * (size_t)j, yr + 6 * (size_t)j);
    double added = 0.0;
    if (R->bstart && R->blocked) {
        /* Block by block on the workers (the links are in node order, each block's its
         * nodes'); the blocks' shares added in block order. */
        const ws_implicit *im = web->imp;
        rigid_pass P = {R, web, p, pr, y};
        ws_implicit_blocks_run(im, rigid_block, &P);
        for (uint32_t b = 0; b < im->nblk; b++) {
            const double *part = R->bpart + 6 * (size_t)R->nb * b;
            for (size_t q = 0; q < 6 * (size_t)R->nb; q++)
                yr[q] += part[q];
            added += im->part[WS_PARTS * (size_t)b + WS_PART_SUM];
        }
    } else {
        added = links_apply(R, web, 0, R->nl, p, pr, y, yr);
    }
    pairs_apply(R, pr, yr);
    return added + ws_rigid_dot(R, pr, yr);
}

v3 ws_rigid_pair_slip(const ws_rigid *R, size_t q, const double *dU)
{
    const ws_rigid_pair *P = &R->pair[q];
    return v3_sub(point_move(dU, P->b, P->rb), point_move(dU, P->a, P->ra));
}

/* Whether link l is the first of its node's links with its body: a node on two faces of one
 * body moves with it once in Phi (its links are next to each other, sorted by node). */
static int first_of_pair(const ws_rigid *R, size_t l)
{
    const ws_rigid_link *L = &R->link[l];
    for (size_t k = l; k-- > 0 && R->link[k].node == L->node;)
        if (R->link[k].body == L->body)
            return 0;
    return 1;
}

/* The coarse space's contacts: the first link of each node-body pair, pinned nodes left out,
 * copied once a solve into R's arrays (node, body, lever), so that the CG's restriction and
 * prolongation pass over them alone, contiguously, without the tests. */
static void phi_list(ws_rigid *R, const ws_web *web)
{
    size_t k = 0;
    for (size_t l = 0; l < R->nl; l++) {
        const ws_rigid_link *L = &R->link[l];
        if (web->inv_m[L->node] == 0.0 || !first_of_pair(R, l))
            continue;
        R->phi_node[k] = L->node;
        R->phi_body[k] = L->body;
        R->phi_lever[3 * k] = L->lever.x;
        R->phi_lever[3 * k + 1] = L->lever.y;
        R->phi_lever[3 * k + 2] = L->lever.z;
        k++;
    }
    R->nphi = k;
}

/* yf += the film part of Phi c (c: 6 a body). */
static void phi_apply(const ws_rigid *R, const double *c, double *yf)
{
    for (size_t k = 0; k < R->nphi; k++) {
        const double *C = c + 6 * (size_t)R->phi_body[k], *r = R->phi_lever + 3 * k;
        const v3 u = v3_add(v3_make(C[0], C[1], C[2]),
                            v3_cross(v3_make(C[3], C[4], C[5]), v3_make(r[0], r[1], r[2])));
        double *y = yf + 3 * (size_t)R->phi_node[k];
        y[0] += u.x, y[1] += u.y, y[2] += u.z;
    }
}

/* out = Phi^T (rf, rr); a run of one body's contacts sums in registers (as in
 * ws_rigid_apply: the same sums in the same order). */
static void phi_transpose(const ws_rigid *R, const double *rf, const double *rr, double *out)
{
    memcpy(out, rr, 6 * (size_t)R->nb * sizeof(double));
    size_t k = 0;
    while (k < R->nphi) {
        const uint32_t j = R->phi_body[k];
        double *o = out + 6 * (size_t)j;
        double o0 = o[0], o1 = o[1], o2 = o[2], o3 = o[3], o4 = o[4], o5 = o[5];
        for (; k < R->nphi && R->phi_body[k] == j; k++) {
            const double *f = rf + 3 * (size_t)R->phi_node[k], *r = R->phi_lever + 3 * k;
            const v3 fv = v3_make(f[0], f[1], f[2]), m = v3_cross(v3_make(r[0], r[1], r[2]), fv);
            o0 += f[0], o1 += f[1], o2 += f[2];
            o3 += m.x, o4 += m.y, o5 += m.z;
        }
        o[0] = o0, o[1] = o1, o[2] = o2, o[3] = o3, o[4] = o4, o[5] = o5;
    }
}

/* The film part of Phi's unit column q (< 6) at a node of lever r: e_q for a velocity, e_(q-3) x
 * r for a spin, written out. phi_apply's cross product multiplies by exact zeros and ones, so
 * these are its values (the sign of a zero aside). */
static inline v3 phi_unit(int q, const double *r)
{
    switch (q) {
    case 0:
        return v3_make(1.0, 0.0, 0.0);
    case 1:
        return v3_make(0.0, 1.0, 0.0);
    case 2:
        return v3_make(0.0, 0.0, 1.0);
    case 3:
        return v3_make(0.0, -r[2], r[1]);
    case 4:
        return v3_make(r[2], 0.0, -r[0]);
    default:
        return v3_make(-r[1], r[0], 0.0);
    }
}

/* The coarse space's rows: every node of Phi (any body) gets one, in crow (UINT32_MAX for the
 * others); their number returned. */
static uint32_t coarse_rows(ws_rigid *R, const ws_web *web)
{
    memset(R->crow, 0xff, (size_t)web->n * sizeof *R->crow);
    uint32_t rows = 0;
    for (size_t k = 0; k < R->nphi; k++)
        if (R->crow[R->phi_node[k]] == UINT32_MAX)
            R->crow[R->phi_node[k]] = rows++;
    return rows;
}

/* The set-up's tables in R->cwork: by row of Phi, its contacts (in the links' order) and its
 * entries of Phi (in Phi's order); by body, its contacts and its entries; and room for the
 * lists of one body's columns (rows; contacts, then entries). */
typedef struct coarse_tables {
    uint32_t rows;
    uint32_t *row_link0, *row_link, *row_phi0, *row_phi;
    uint32_t *body_link0, *body_link, *body_phi0, *body_phi;
    uint32_t *list_rows, *list;
} coarse_tables;

size_t ws_rigid_coarse_words(size_t cap, uint32_t nb)
{
    /* the envelope of the coarse factor (12 nb), then the tables: rows, contacts and entries
     * are each at most cap */
    return 12 * (size_t)nb + 2 * (cap + 1) + 2 * ((size_t)nb + 1) + 6 * cap;
}

/* Items [0, count) grouped by key (key[k] < groups; UINT32_MAX: left out) into start (groups +
 * 1) and idx, each group's items in their order. */
static void group_by(const uint32_t *key, size_t count, uint32_t groups, uint32_t *start,
                     uint32_t *idx)
{
    memset(start, 0, ((size_t)groups + 1) * sizeof *start);
    for (size_t k = 0; k < count; k++)
        if (key[k] != UINT32_MAX)
            start[key[k] + 1]++;
    for (uint32_t g = 0; g < groups; g++)
        start[g + 1] += start[g];
    for (size_t k = 0; k < count; k++)
        if (key[k] != UINT32_MAX)
            idx[start[key[k]]++] = (uint32_t)k;
    for (uint32_t g = groups; g > 0; g--) /* each start moved on by its group's count */
        start[g] = start[g - 1];
    start[0] = 0;
}

static void tables_make(ws_rigid *R, uint32_t rows, coarse_tables *T)
{
    const size_t cap = R->cap, nb = R->nb;
    uint32_t *w = R->cwork + 12 * nb; /* after the coarse factor's envelope */
    T->rows = rows;
    T->row_link0 = w, w += cap + 1;
    T->row_phi0 = w, w += cap + 1;
    T->body_link0 = w, w += nb + 1;
    T->body_phi0 = w, w += nb + 1;
    T->row_link = w, w += cap;
    T->row_phi = w, w += cap;
    T->body_link = w, w += cap;
    T->body_phi = w, w += cap;
    T->list_rows = w, w += cap;
    T->list = w;
    uint32_t *key = T->list; /* free until a body's columns are made */
    for (size_t l = 0; l < R->nl; l++)
        key[l] = R->crow[R->link[l].node];
    group_by(key, R->nl, rows, T->row_link0, T->row_link);
    for (size_t l = 0; l < R->nl; l++)
        key[l] = R->link[l].body;
    group_by(key, R->nl, R->nb, T->body_link0, T->body_link);
    for (size_t k = 0; k < R->nphi; k++)
        key[k] = R->crow[R->phi_node[k]];
    group_by(key, R->nphi, rows, T->row_phi0, T->row_phi);
    group_by(R->phi_body, R->nphi, R->nb, T->body_phi0, T->body_phi);
}

static int u32_order(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* The springs' terms of a body's six columns at node i's row y (18 doubles: column, then
 * xyz), at[] the rows' entries of Phi with that body: each spring at the node with an end that
 * moves with the body, in spring order, as ws_implicit_apply_op's second loop adds them (for a
 * velocity column only those with one such end: both ends moving alike do not stretch it). */
static void row_springs(const ws_rigid *R, const ws_web *web, const uint32_t *at, uint32_t i,
                        double *y)
{
    const double *op = web->imp->op;
    for (uint32_t e = web->inc0[i]; e < web->inc0[i + 1]; e++) {
        const uint32_t s = web->inc[e] >> 1, end_b = web->inc[e] & 1;
        const uint32_t ra = R->crow[web->sa[s]], rb = R->crow[web->sb[s]];
        const uint32_t ka = ra == UINT32_MAX ? UINT32_MAX : at[ra],
                       kb = rb == UINT32_MAX ? UINT32_MAX : at[rb];
        if (ka == UINT32_MAX && kb == UINT32_MAX)
            continue;
        const double *o = op + 5 * (size_t)s; /* ex ey ez a b */
        const double *la = ka == UINT32_MAX ? NULL : R->phi_lever + 3 * (size_t)ka,
                     *lb = kb == UINT32_MAX ? NULL : R->phi_lever + 3 * (size_t)kb;
        for (int q = la && lb ? 3 : 0; q < 6; q++) {
            const v3 a = la ? phi_unit(q, la) : v3_make(0.0, 0.0, 0.0);
            const v3 b = lb ? phi_unit(q, lb) : v3_make(0.0, 0.0, 0.0);
            const double dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
            const double ed = o[3] * (o[0] * dx + o[1] * dy + o[2] * dz);
            const double tx = ed * o[0] + o[4] * dx, ty = ed * o[1] + o[4] * dy,
                         tz = ed * o[2] + o[4] * dz;
            double *Y = y + 3 * (size_t)q;
            if (end_b)
                Y[0] -= tx, Y[1] -= ty, Y[2] -= tz;
            else
                Y[0] += tx, Y[1] += ty, Y[2] += tz;
        }
    }
}

/* The six columns of body j of Phi^T A Phi into A's rows 6 j .. 6 j + 5 (nc x nc, row-major:
 * the product's transpose), A the coupled matrix of the running solve: what
 * ws_implicit_apply_op, ws_rigid_apply and phi_transpose give column by column for Phi e_c,
 * computed for the six at once and only where they are not zero: the rows of the body's nodes
 * and of the nodes its springs reach (cy, 18 doubles a row: column, then xyz), the contacts of
 * body j or of a node that moves with it (a contact at the point Phi moves its node with adds
 * nothing to the body's row), Phi^T over the rows these reach. Each entry takes the same terms
 * in the same order as the column-by-column product (a row's in spring order, then in the
 * links' order; a body's sums in the links' and in Phi's order) and leaves out only exact
 * zeros, so the matrix is the same to the bit (the sign of a zero aside). at[] and reached[]
 * (cphi) are UINT32_MAX and 0 at every row outside the body's. */
static void coarse_body(ws_rigid *R, const ws_web *web, const coarse_tables *T, uint32_t j,
                        double *A)
{
    const ws_implicit *im = web->imp;
    const size_t nc = 6 * (size_t)R->nb;
    uint32_t *at = R->cphi;                /* a row's entry of Phi with body j */
    uint32_t *reached = R->cphi + T->rows; /* whether a term of body j's columns reaches a row */
    uint32_t *rl = T->list_rows, *list = T->list;
    double *Y = R->cy;
    uint32_t nr = 0;
    for (uint32_t e = T->body_phi0[j]; e < T->body_phi0[j + 1]; e++) {
        const uint32_t k = T->body_phi[e], r = R->crow[R->phi_node[k]];
        at[r] = k;
        if (!reached[r])
            reached[r] = 1, rl[nr++] = r;
    }
    const uint32_t own = nr;
    for (uint32_t u = 0; u < own; u++) {
        const uint32_t i = R->phi_node[at[rl[u]]];
        for (uint32_t e = web->inc0[i]; e < web->inc0[i + 1]; e++) {
            const uint32_t s = web->inc[e] >> 1;
            const uint32_t ro = R->crow[web->inc[e] & 1 ? web->sa[s] : web->sb[s]];
            if (ro != UINT32_MAX && !reached[ro])
                reached[ro] = 1, rl[nr++] = ro;
        }
    }
    /* Each row: the film's own block (ws_implicit_apply_op's first loop), then its springs. */
    for (uint32_t u = 0; u < nr; u++) {
        const uint32_t r = rl[u], i = R->phi_node[T->row_phi[T->row_phi0[r]]];
        const double *S = im->nd + WS_SYM * (size_t)i;
        double *y = Y + 18 * (size_t)r;
        for (int q = 0; q < 6; q++) {
            const v3 p = at[r] == UINT32_MAX ? v3_make(0.0, 0.0, 0.0)
                                             : phi_unit(q, R->phi_lever + 3 * (size_t)at[r]);
            double *yq = y + 3 * (size_t)q;
            yq[0] = S[WS_SYM_XX] * p.x + S[WS_SYM_XY] * p.y + S[WS_SYM_XZ] * p.z;
            yq[1] = S[WS_SYM_XY] * p.x + S[WS_SYM_YY] * p.y + S[WS_SYM_YZ] * p.z;
            yq[2] = S[WS_SYM_XZ] * p.x + S[WS_SYM_YZ] * p.y + S[WS_SYM_ZZ] * p.z;
        }
        row_springs(R, web, at, i, y);
    }
    /* The bodies' rows (ws_rigid_apply), yr of column q in cyr + q nc, and the contacts'
     * coupling: body j's contacts off Phi's rows (at pinned nodes) and every contact at its
     * rows, in the links' order. */
    double *yr = R->cyr;
    for (int q = 0; q < 6; q++)
        for (uint32_t k = 0; k < R->nb; k++) {
            double P[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
            if (k == j)
                P[q] = 1.0;
            body_mass_apply(R, k, P, yr + nc * (size_t)q + 6 * (size_t)k);
        }
    size_t nlist = 0;
    for (uint32_t e = T->body_link0[j]; e < T->body_link0[j + 1]; e++) {
        const uint32_t l = T->body_link[e], r = R->crow[R->link[l].node];
        if (r == UINT32_MAX || at[r] == UINT32_MAX)
            list[nlist++] = l;
    }
    for (uint32_t u = 0; u < own; u++)
        for (uint32_t e = T->row_link0[rl[u]]; e < T->row_link0[rl[u] + 1]; e++)
            list[nlist++] = T->row_link[e];
    qsort(list, nlist, sizeof *list, u32_order);
    for (size_t u = 0; u < nlist; u++) {
        const ws_rigid_link *L = &R->link[list[u]];
        const uint32_t k = L->body, rn = R->crow[L->node];
        const uint32_t kn = rn == UINT32_MAX ? UINT32_MAX : at[rn];
        const double lv[3] = {L->lever.x, L->lever.y, L->lever.z};
        const double *ln = kn == UINT32_MAX ? NULL : R->phi_lever + 3 * (size_t)kn;
        for (int q = 0; q < 6; q++) {
            double *Yb = yr + nc * (size_t)q + 6 * (size_t)k;
            const v3 jp = k == j ? phi_unit(q, lv) : v3_make(0.0, 0.0, 0.0);
            const double cj[3] = {sym_row(L->C, 0, jp.x, jp.y, jp.z),
                                  sym_row(L->C, 1, jp.x, jp.y, jp.z),
                                  sym_row(L->C, 2, jp.x, jp.y, jp.z)};
            /* g = C (p_node - J P): zero when Phi moves the node with this very contact point
             * (the same operations on the same numbers). */
            if (!(k == j && ln && ln[0] == lv[0] && ln[1] == lv[1] && ln[2] == lv[2])) {
                const v3 pn = ln ? phi_unit(q, ln) : v3_make(0.0, 0.0, 0.0);
                const double g[3] = {sym_row(L->C, 0, pn.x, pn.y, pn.z) - cj[0],
                                     sym_row(L->C, 1, pn.x, pn.y, pn.z) - cj[1],
                                     sym_row(L->C, 2, pn.x, pn.y, pn.z) - cj[2]};
                const v3 mo = v3_cross(L->lever, v3_make(g[0], g[1], g[2]));
                Yb[0] -= g[0], Yb[1] -= g[1], Yb[2] -= g[2];
                Yb[3] -= mo.x, Yb[4] -= mo.y, Yb[5] -= mo.z;
            }
            if (web->inv_m[L->node] == 0.0 || rn == UINT32_MAX)
                continue; /* a pinned node's row stays zero; no other is outside Phi */
            double *y = Y + 18 * (size_t)rn + 3 * (size_t)q;
            y[0] -= cj[0], y[1] -= cj[1], y[2] -= cj[2];
        }
    }
    /* Phi^T of each column (phi_transpose) over the entries at the rows reached, in Phi's
     * order, into A's columns 6 j + q. */
    size_t ne = 0;
    for (uint32_t u = 0; u < nr; u++)
        for (uint32_t e = T->row_phi0[rl[u]]; e < T->row_phi0[rl[u] + 1]; e++)
            list[ne++] = T->row_phi[e];
    qsort(list, ne, sizeof *list, u32_order);
    for (int q = 0; q < 6; q++) {
        double *out = R->cb;
        memcpy(out, yr + nc * (size_t)q, nc * sizeof(double));
        for (size_t u = 0; u < ne; u++) {
            const uint32_t k = list[u];
            double *o = out + 6 * (size_t)R->phi_body[k];
            const double *f = Y + 18 * (size_t)R->crow[R->phi_node[k]] + 3 * (size_t)q,
                         *lk = R->phi_lever + 3 * (size_t)k;
            const v3 fv = v3_make(f[0], f[1], f[2]),
                     mo = v3_cross(v3_make(lk[0], lk[1], lk[2]), fv);
            o[0] += f[0], o[1] += f[1], o[2] += f[2];
            o[3] += mo.x, o[4] += mo.y, o[5] += mo.z;
        }
        /* Column 6 j + q, stored as a row: ws_rigid_coarse_matrix takes the mean of the
         * matrix and its transpose, which is the same either way. */
        memcpy(A + nc * (6 * (size_t)j + (size_t)q), out, nc * sizeof(double));
    }
    for (uint32_t u = 0; u < nr; u++)
        at[rl[u]] = UINT32_MAX, reached[rl[u]] = 0;
}

void ws_rigid_coarse_matrix(ws_rigid *R, const ws_web *web)
{
    const size_t nc = 6 * (size_t)R->nb;
    double *A = R->coarse;
    phi_list(R, web);
    const uint32_t rows = coarse_rows(R, web);
    coarse_tables T;
    tables_make(R, rows, &T);
    for (uint32_t r = 0; r < rows; r++)
        R->cphi[r] = UINT32_MAX, R->cphi[rows + r] = 0;
    for (uint32_t j = 0; j < R->nb; j++)
        coarse_body(R, web, &T, j, A);
    /* The pairs' terms, Phi's body columns being unit motions of the bodies: column c of body
     * j and direction k gets pairs_apply's rows for that unit motion (in the transpose, row c:
     * the same sums). */
    for (size_t c = 0; c < nc && R->npair; c++) {
        double *e = R->cq, *col = R->cb; /* free until the solve runs */
        memset(e, 0, nc * sizeof(double));
        memset(col, 0, nc * sizeof(double));
        e[c] = 1.0;
        pairs_apply(R, e, col);
        for (size_t d = 0; d < nc; d++)
            A[nc * c + d] += col[d];
    }
    for (size_t c = 0; c < nc; c++) /* symmetric to round-off: its mean */
        for (size_t d = c + 1; d < nc; d++)
            A[nc * d + c] = A[nc * c + d] = 0.5 * (A[nc * d + c] + A[nc * c + d]);
}

int ws_rigid_coarse(ws_rigid *R, const ws_web *web)
{
    ws_rigid_coarse_matrix(R, web);
    /* The factor over the envelope of Phi^T A Phi (R->cwork's first 12 nb words): bodies that
     * share no node, no spring and no pair are not coupled in it, and the products of those
     * exact zeros are left out (the factor is the dense one's to the bit). */
    const size_t n = 6 * (size_t)R->nb;
    envelope(R->coarse, n, R->cwork);
    return cholesky(R->coarse, n, R->cwork);
}

double ws_rigid_precondition(const ws_rigid *R, const double *rf, double *zf, const double *rr,
                             double *zr)
{
    const size_t nc = 6 * (size_t)R->nb;
    cholesky_solve(R->fac, nc, R->env, rr, zr);
    double rz = ws_rigid_dot(R, rr, zr);
    if (!R->coarse)
        return rz;
    /* The coarse correction, added (two-level additive Schwarz: a sum of symmetric positive
     * (semi-)definite parts, so CG stays valid). */
    double *c = R->cq; /* free while the CG runs */
    phi_transpose(R, rf, rr, c);
    double *g = R->cb;
    cholesky_solve(R->coarse, nc, R->cwork, c, g);
    for (size_t k = 0; k < nc; k++) {
        rz += c[k] * g[k];
        zr[k] += g[k];
    }
    phi_apply(R, g, zf);
    return rz;
}

double ws_rigid_step(ws_rigid *R, double alpha)
{
    double rr = 0.0;
    for (size_t k = 0; k < 6 * (size_t)R->nb; k++) {
        R->x[k] += alpha * R->p[k];
        R->r[k] -= alpha * R->q[k];
        rr += R->r[k] * R->r[k];
    }
    return rr;
}

void ws_rigid_direction(ws_rigid *R, double beta)
{
    for (size_t k = 0; k < 6 * (size_t)R->nb; k++)
        R->p[k] = R->z[k] + beta * R->p[k];
}

double ws_rigid_dot(const ws_rigid *R, const double *a, const double *b)
{
    double s = 0.0;
    for (size_t k = 0; k < 6 * (size_t)R->nb; k++)
        s += a[k] * b[k];
    return s;
}

/* y = A x for the bodies and pairs alone: M_j x_j, then the pairs' terms. */
static void pairs_only_apply(const ws_rigid *R, const double *x, double *y)
{
    for (uint32_t j = 0; j < R->nb; j++)
        body_mass_apply(R, j, x + 6 * (size_t)j, y + 6 * (size_t)j);
    pairs_apply(R, x, y);
}

/* z = L^-T L^-1 r for a 6 x 6 lower factor L (row-major) and its diagonal's reciprocals rd. */
static void solve6(const double *L, const double *rd, const double *r, double *z)
{
    double y[6];
    for (int i = 0; i < 6; i++) {
        double s = r[i];
        for (int k = 0; k < i; k++)
            s -= L[6 * i + k] * y[k];
        y[i] = s * rd[i];
    }
    for (int i = 5; i >= 0; i--) {
        double s = y[i];
        for (int k = i + 1; k < 6; k++)
            s -= L[6 * k + i] * z[k];
        z[i] = s * rd[i];
    }
}

/* Each body's own block of A, inverted into R->fac (36 doubles a body): an iteration then
 * multiplies by it, six rows of six, where solving with its factor would take a chain of
 * dependent steps twice. */
static int invert_blocks(ws_rigid *R)
{
    const int ix[3][3] = {{WS_SYM_XX, WS_SYM_XY, WS_SYM_XZ},
                          {WS_SYM_XY, WS_SYM_YY, WS_SYM_YZ},
                          {WS_SYM_XZ, WS_SYM_YZ, WS_SYM_ZZ}};
    memset(R->fac, 0, 36 * (size_t)R->nb * sizeof(double));
    for (uint32_t j = 0; j < R->nb; j++) {
        double *B = R->fac + 36 * (size_t)j;
        const double *I = R->inertia + WS_SYM * (size_t)j;
        B[0] = B[7] = B[14] = R->mass[j];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                B[6 * (3 + i) + 3 + k] = I[ix[i][k]];
    }
    for (size_t q = 0; q < R->npair; q++) {
        const ws_rigid_pair *P = &R->pair[q];
        if (P->a != UINT32_MAX)
            add_coupling(R->fac + 36 * (size_t)P->a, 6, 0, P->ra, 0, P->ra, P->C, 1.0);
        if (P->b != UINT32_MAX)
            add_coupling(R->fac + 36 * (size_t)P->b, 6, 0, P->rb, 0, P->rb, P->C, 1.0);
    }
    for (uint32_t j = 0; j < R->nb; j++) {
        double *B = R->fac + 36 * (size_t)j, rd[6];
        if (cholesky(B, 6, NULL) != 0)
            return -1;
        for (int i = 0; i < 6; i++)
            rd[i] = 1.0 / B[7 * i];
        double inv[36];
        for (int k = 0; k < 6; k++) {
            double e[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}, col[6];
            e[k] = 1.0;
            solve6(B, rd, e, col);
            for (int i = 0; i < 6; i++)
                inv[6 * i + k] = col[i];
        }
        memcpy(B, inv, sizeof inv);
    }
    return 0;
}

/* z = (block of each body)^-1 r; returns r . z. */
static double blocks_solve(const ws_rigid *R, const double *r, double *z)
{
    double rz = 0.0;
    for (uint32_t j = 0; j < R->nb; j++) {
        const size_t o = 6 * (size_t)j;
        const double *B = R->fac + 36 * (size_t)j;
        for (int i = 0; i < 6; i++) {
            double s = 0.0;
            for (int k = 0; k < 6; k++)
                s += B[6 * i + k] * r[o + (size_t)k];
            z[o + (size_t)i] = s;
        }
        for (int k = 0; k < 6; k++)
            rz += r[o + (size_t)k] * z[o + (size_t)k];
    }
    return rz;
}

int ws_rigid_pairs_solve(ws_rigid *R, double tol, int maxit, int *iterations, double *residual)
{
    const size_t n = 6 * (size_t)R->nb;
    *iterations = 0;
    *residual = 0.0;
    if (invert_blocks(R) != 0)
        return -1;
    memset(R->x, 0, n * sizeof(double));
    memcpy(R->r, R->b, n * sizeof(double));
    double rz = blocks_solve(R, R->r, R->z);
    const double rz0 = rz;
    if (!(rz0 > 0.0))
        return rz0 == 0.0 ? 0 : -1; /* no load: no change; a NaN: not solved */
    memcpy(R->p, R->z, n * sizeof(double));
    for (int it = 1; it <= maxit; it++) {
        pairs_only_apply(R, R->p, R->q);
        const double pq = ws_rigid_dot(R, R->p, R->q);
        if (!(pq > 0.0))
            return -1;
        ws_rigid_step(R, rz / pq);
        const double rz_new = blocks_solve(R, R->r, R->z);
        *iterations = it;
        *residual = sqrt(fmax(rz_new, 0.0) / rz0);
        if (*residual <= tol)
            return 0;
        ws_rigid_direction(R, rz_new / rz);
        rz = rz_new;
    }
    return -1;
}
