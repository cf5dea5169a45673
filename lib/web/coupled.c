/* Rigid bodies in an implicit web's solve (web/coupled.h says the system; docs/theory.md,
 * section 8b, why). */
#include "web/coupled.h"

#include <string.h>

/* J^T C J of a contact at lever r into the 6x6 block B (row-major): column k is J^T C J e_k,
 * with J e_k the contact point's velocity for a unit velocity (k < 3) or spin (k >= 3) and
 * J^T g = (g, r x g). */
static void add_block(double *B, const double *C, v3 r)
{
    for (int k = 0; k < 6; k++) {
        v3 e = v3_make(k % 3 == 0, k % 3 == 1, k % 3 == 2);
        const v3 a = k < 3 ? e : v3_cross(e, r);
        double g[3] = {0.0, 0.0, 0.0};
        ws_sym_madd(C, a.x, a.y, a.z, g);
        const v3 gv = v3_make(g[0], g[1], g[2]), m = v3_cross(r, gv);
        const double col[6] = {g[0], g[1], g[2], m.x, m.y, m.z};
        for (int i = 0; i < 6; i++)
            B[6 * i + k] += col[i];
    }
}

/* The lower Cholesky factor of the symmetric n x n B (row-major), in place. 0, or -1 when not
 * positive definite. */
static int cholesky(double *B, size_t n)
{
    for (size_t j = 0; j < n; j++) {
        double d = B[n * j + j];
        for (size_t k = 0; k < j; k++)
            d -= B[n * j + k] * B[n * j + k];
        if (!(d > 0.0) || !isfinite(d))
            return -1;
        const double l = sqrt(d);
        B[n * j + j] = l;
        for (size_t i = j + 1; i < n; i++) {
            double s = B[n * i + j];
            for (size_t k = 0; k < j; k++)
                s -= B[n * i + k] * B[n * j + k];
            B[n * i + j] = s / l;
        }
    }
    return 0;
}

/* z = (L L^T)^-1 r for the factor L of cholesky (z may be r). */
static void cholesky_solve(const double *L, size_t n, const double *r, double *z)
{
    for (size_t i = 0; i < n; i++) {
        double s = r[i];
        for (size_t k = 0; k < i; k++)
            s -= L[n * i + k] * z[k];
        z[i] = s / L[n * i + i];
    }
    for (size_t i = n; i-- > 0;) {
        double s = z[i];
        for (size_t k = i + 1; k < n; k++)
            s -= L[n * k + i] * z[k];
        z[i] = s / L[n * i + i];
    }
}

int ws_rigid_factor(ws_rigid *R)
{
    for (uint32_t j = 0; j < R->nb; j++) {
        double *B = R->fac + 36 * (size_t)j;
        const double *I = R->inertia + WS_SYM * (size_t)j;
        memset(B, 0, 36 * sizeof(double));
        B[0] = B[7] = B[14] = R->mass[j];
        const int ix[3][3] = {{WS_SYM_XX, WS_SYM_XY, WS_SYM_XZ},
                              {WS_SYM_XY, WS_SYM_YY, WS_SYM_YZ},
                              {WS_SYM_XZ, WS_SYM_YZ, WS_SYM_ZZ}};
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                B[6 * (3 + i) + 3 + k] = I[ix[i][k]];
    }
    for (size_t l = 0; l < R->nl; l++)
        add_block(R->fac + 36 * (size_t)R->link[l].body, R->link[l].C, R->link[l].lever);
    for (uint32_t j = 0; j < R->nb; j++)
        if (cholesky(R->fac + 36 * (size_t)j, 6) != 0)
            return -1;
    return 0;
}

void ws_rigid_block_solve(const ws_rigid *R, const double *r, double *z)
{
    for (uint32_t j = 0; j < R->nb; j++)
        cholesky_solve(R->fac + 36 * (size_t)j, 6, r + 6 * (size_t)j, z + 6 * (size_t)j);
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

double ws_rigid_apply(const ws_rigid *R, const ws_web *web, const double *p, const double *pr,
                      double *y, double *yr)
{
    double added = 0.0;
    for (uint32_t j = 0; j < R->nb; j++) {
        const double *P = pr + 6 * (size_t)j, *I = R->inertia + WS_SYM * (size_t)j;
        double *Y = yr + 6 * (size_t)j;
        const double m = R->mass[j];
        Y[0] = m * P[0], Y[1] = m * P[1], Y[2] = m * P[2];
        Y[3] = Y[4] = Y[5] = 0.0;
        ws_sym_madd(I, P[3], P[4], P[5], Y + 3);
    }
    /* A run of links on one body (a node's neighbours mostly press on the same box) sums its
     * body's row in registers, stored once at the run's end: the same sums in the same order
     * as adding into yr link by link, without a chain of loads and stores through memory. */
    size_t l = 0;
    while (l < R->nl) {
        const uint32_t j = R->link[l].body;
        const double *P = pr + 6 * (size_t)j;
        const v3 V = v3_make(P[0], P[1], P[2]), W = v3_make(P[3], P[4], P[5]);
        double *Y = yr + 6 * (size_t)j;
        double y0 = Y[0], y1 = Y[1], y2 = Y[2], y3 = Y[3], y4 = Y[4], y5 = Y[5];
        for (; l < R->nl && R->link[l].body == j; l++) {
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
    return added + ws_rigid_dot(R, pr, yr);
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

int ws_rigid_coarse(ws_rigid *R, const ws_web *web)
{
    const size_t nc = 6 * (size_t)R->nb, m = 3 * (size_t)web->n;
    double *A = R->coarse;
    phi_list(R, web);
    for (size_t c = 0; c < nc; c++) {
        memset(R->cb, 0, nc * sizeof(double));
        memset(R->fa, 0, m * sizeof(double));
        R->cb[c] = 1.0;
        phi_apply(R, R->cb, R->fa);
        (void)ws_implicit_apply_op(web, R->fa, R->fb);
        (void)ws_rigid_apply(R, web, R->fa, R->cb, R->fb, R->cq);
        phi_transpose(R, R->fb, R->cq, R->cb);
        for (size_t d = 0; d < nc; d++)
            A[nc * d + c] = R->cb[d];
    }
    for (size_t c = 0; c < nc; c++) /* symmetric to round-off: its mean */
        for (size_t d = c + 1; d < nc; d++)
            A[nc * d + c] = A[nc * c + d] = 0.5 * (A[nc * d + c] + A[nc * c + d]);
    return cholesky(A, nc);
}

double ws_rigid_precondition(const ws_rigid *R, const double *rf, double *zf, const double *rr,
                             double *zr)
{
    double rz = 0.0;
    for (uint32_t j = 0; j < R->nb; j++) {
        const double *L = R->fac + 36 * (size_t)j, *rv = rr + 6 * (size_t)j;
        double *zv = zr + 6 * (size_t)j;
        cholesky_solve(L, 6, rv, zv);
        for (int i = 0; i < 6; i++)
            rz += rv[i] * zv[i];
    }
    if (!R->coarse)
        return rz;
    /* The coarse correction, added (two-level additive Schwarz: a sum of symmetric positive
     * (semi-)definite parts, so CG stays valid). */
    const size_t nc = 6 * (size_t)R->nb;
    double *c = R->cq; /* free while the CG runs */
    phi_transpose(R, rf, rr, c);
    double *g = R->cb;
    cholesky_solve(R->coarse, nc, c, g);
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
