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
    for (size_t l = 0; l < R->nl; l++) {
        const ws_rigid_link *L = &R->link[l];
        const double *P = pr + 6 * (size_t)L->body, *pn = p + 3 * (size_t)L->node;
        double *Y = yr + 6 * (size_t)L->body;
        /* The contact point's motion J P, the node's relative to it, and C on both. */
        const v3 jp =
            v3_add(v3_make(P[0], P[1], P[2]), v3_cross(v3_make(P[3], P[4], P[5]), L->lever));
        double cj[3] = {0.0, 0.0, 0.0};
        ws_sym_madd(L->C, jp.x, jp.y, jp.z, cj);
        double g[3] = {0.0, 0.0, 0.0};
        ws_sym_madd(L->C, pn[0], pn[1], pn[2], g);
        g[0] -= cj[0], g[1] -= cj[1], g[2] -= cj[2]; /* C (p_node - J P) */
        const v3 m = v3_cross(L->lever, v3_make(g[0], g[1], g[2]));
        Y[0] -= g[0], Y[1] -= g[1], Y[2] -= g[2];
        Y[3] -= m.x, Y[4] -= m.y, Y[5] -= m.z;
        if (web->inv_m[L->node] == 0.0)
            continue; /* a pinned node's row stays zero (its dv is) */
        double *yn = y + 3 * (size_t)L->node;
        yn[0] -= cj[0], yn[1] -= cj[1], yn[2] -= cj[2];
        added -= pn[0] * cj[0] + pn[1] * cj[1] + pn[2] * cj[2];
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

/* yf += the film part of Phi c (c: 6 a body), pinned nodes left out. */
static void phi_apply(const ws_rigid *R, const ws_web *web, const double *c, double *yf)
{
    for (size_t l = 0; l < R->nl; l++) {
        const ws_rigid_link *L = &R->link[l];
        if (web->inv_m[L->node] == 0.0 || !first_of_pair(R, l))
            continue;
        const double *C = c + 6 * (size_t)L->body;
        const v3 u =
            v3_add(v3_make(C[0], C[1], C[2]), v3_cross(v3_make(C[3], C[4], C[5]), L->lever));
        double *y = yf + 3 * (size_t)L->node;
        y[0] += u.x, y[1] += u.y, y[2] += u.z;
    }
}

/* out = Phi^T (rf, rr). */
static void phi_transpose(const ws_rigid *R, const ws_web *web, const double *rf, const double *rr,
                          double *out)
{
    memcpy(out, rr, 6 * (size_t)R->nb * sizeof(double));
    for (size_t l = 0; l < R->nl; l++) {
        const ws_rigid_link *L = &R->link[l];
        if (web->inv_m[L->node] == 0.0 || !first_of_pair(R, l))
            continue;
        const double *f = rf + 3 * (size_t)L->node;
        const v3 fv = v3_make(f[0], f[1], f[2]), m = v3_cross(L->lever, fv);
        double *o = out + 6 * (size_t)L->body;
        o[0] += f[0], o[1] += f[1], o[2] += f[2];
        o[3] += m.x, o[4] += m.y, o[5] += m.z;
    }
}

int ws_rigid_coarse(ws_rigid *R, const ws_web *web)
{
    const size_t nc = 6 * (size_t)R->nb, m = 3 * (size_t)web->n;
    double *A = R->coarse;
    for (size_t c = 0; c < nc; c++) {
        memset(R->cb, 0, nc * sizeof(double));
        memset(R->fa, 0, m * sizeof(double));
        R->cb[c] = 1.0;
        phi_apply(R, web, R->cb, R->fa);
        (void)ws_implicit_apply_op(web, R->fa, R->fb);
        (void)ws_rigid_apply(R, web, R->fa, R->cb, R->fb, R->cq);
        phi_transpose(R, web, R->fb, R->cq, R->cb);
        for (size_t d = 0; d < nc; d++)
            A[nc * d + c] = R->cb[d];
    }
    for (size_t c = 0; c < nc; c++) /* symmetric to round-off: its mean */
        for (size_t d = c + 1; d < nc; d++)
            A[nc * d + c] = A[nc * c + d] = 0.5 * (A[nc * d + c] + A[nc * c + d]);
    return cholesky(A, nc);
}

double ws_rigid_precondition(const ws_rigid *R, const ws_web *web, const double *rf, double *zf,
                             const double *rr, double *zr)
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
    phi_transpose(R, web, rf, rr, c);
    double *g = R->cb;
    cholesky_solve(R->coarse, nc, c, g);
    for (size_t k = 0; k < nc; k++) {
        rz += c[k] * g[k];
        zr[k] += g[k];
    }
    phi_apply(R, web, g, zf);
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
