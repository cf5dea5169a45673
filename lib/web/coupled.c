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

/* The lower Cholesky factor of the symmetric 6x6 B, in place. 0, or -1 when not positive
 * definite. */
static int cholesky6(double *B)
{
    for (int j = 0; j < 6; j++) {
        double d = B[6 * j + j];
        for (int k = 0; k < j; k++)
            d -= B[6 * j + k] * B[6 * j + k];
        if (!(d > 0.0) || !isfinite(d))
            return -1;
        const double l = sqrt(d);
        B[6 * j + j] = l;
        for (int i = j + 1; i < 6; i++) {
            double s = B[6 * i + j];
            for (int k = 0; k < j; k++)
                s -= B[6 * i + k] * B[6 * j + k];
            B[6 * i + j] = s / l;
        }
    }
    return 0;
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
        if (cholesky6(R->fac + 36 * (size_t)j) != 0)
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
        const v3 jp = v3_add(v3_make(P[0], P[1], P[2]),
                             v3_cross(v3_make(P[3], P[4], P[5]), L->lever));
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

double ws_rigid_precondition(const ws_rigid *R, const double *r, double *z)
{
    double rz = 0.0;
    for (uint32_t j = 0; j < R->nb; j++) {
        const double *L = R->fac + 36 * (size_t)j, *rv = r + 6 * (size_t)j;
        double *zv = z + 6 * (size_t)j;
        for (int i = 0; i < 6; i++) { /* L w = r */
            double s = rv[i];
            for (int k = 0; k < i; k++)
                s -= L[6 * i + k] * zv[k];
            zv[i] = s / L[6 * i + i];
        }
        for (int i = 5; i >= 0; i--) { /* L^T z = w */
            double s = zv[i];
            for (int k = i + 1; k < 6; k++)
                s -= L[6 * k + i] * zv[k];
            zv[i] = s / L[6 * i + i];
        }
        for (int i = 0; i < 6; i++)
            rz += rv[i] * zv[i];
    }
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
