/* The plain scalar explicit loop over a film (bench_plain.c, bench_pallet.c): the film's nodes,
 * their places and masses, its springs with their rest lengths and a tension-compression law,
 * gravity and symplectic Euler, but no bodies; with plain_step_contacts, each node against
 * each box at rest too. Written as a C programmer would write it first: nodes as structures, a
 * list of springs, one loop over the springs and one over the nodes; the including benchmark
 * is compiled without vectors (bench/meson.build). */
#ifndef BENCH_PLAIN_FILM_H
#define BENCH_PLAIN_FILM_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include <wrapsim/wrapsim.h>

typedef struct plain_node {
    double x[3], v[3], f[3];
    double m, inv_m;
} plain_node;

/* A spring from node a to node b: 1 / rest length and its law, the library's film form: in
 * tension kc eps + dk eps + c eps_dot, in compression kc eps + c eps_dot, joined over a strain
 * of w by a quadratic. */
typedef struct plain_spring {
    uint32_t a, b;
    double inv_l0, kc, dk, w, c;
} plain_spring;

static int plain_linear; /* the leanest law: EA eps (set once, before the loop) */

static double plain_law(const plain_spring *s, double eps, double epsd)
{
    if (plain_linear)
        return (s->kc + s->dk) * eps;
    double ramp;
    if (eps >= s->w)
        ramp = eps;
    else if (eps > -s->w)
        ramp = (eps + s->w) * (eps + s->w) * 0.25 / s->w;
    else
        ramp = 0.0;
    return s->kc * eps + s->dk * ramp + s->c * epsd;
}

/* Gravity and the springs' forces into f. */
static void plain_forces(plain_node *nd, size_t n, const plain_spring *sp, size_t ns, double gz)
{
    for (size_t i = 0; i < n; i++) {
        nd[i].f[0] = 0.0;
        nd[i].f[1] = 0.0;
        nd[i].f[2] = nd[i].m * gz;
    }
    for (size_t k = 0; k < ns; k++) {
        plain_node *A = &nd[sp[k].a], *B = &nd[sp[k].b];
        double d[3], l2 = 0.0, ud = 0.0;
        for (int c = 0; c < 3; c++) {
            d[c] = B->x[c] - A->x[c];
            l2 += d[c] * d[c];
            ud += (B->v[c] - A->v[c]) * d[c];
        }
        if (!(l2 > 0.0))
            continue;
        double l = sqrt(l2);
        double t = plain_law(&sp[k], l * sp[k].inv_l0 - 1.0, ud / l * sp[k].inv_l0) / l;
        for (int c = 0; c < 3; c++) {
            A->f[c] += t * d[c];
            B->f[c] -= t * d[c];
        }
    }
}

/* Symplectic Euler over h. */
static void plain_advance(plain_node *nd, size_t n, double h)
{
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            nd[i].v[c] += h * nd[i].inv_m * nd[i].f[c];
            nd[i].x[c] += h * nd[i].v[c];
        }
}

static void plain_step(plain_node *nd, size_t n, const plain_spring *sp, size_t ns, double h,
                       double gz)
{
    plain_forces(nd, n, sp, ns, gz);
    plain_advance(nd, n, h);
}

/* The plain loop's contacts, as a first version would write them: every node against every
 * box, each box at rest (its centre c, rotation rows R, half sizes h grown by the contact
 * layer). A node inside a box is pushed out through the nearest face: normal force k d - c v_n
 * (no pull), friction mu f_n against the tangential velocity, regularised below v_lim as the
 * library's law is (f_t = -mu f_n v_t / max(|v_t|, v_lim)); the box's load (force and moment
 * about c) is summed too, as the bodies would need it. */
typedef struct plain_box {
    double c[3], R[3][3], h[3];
    double f[3], m[3]; /* the load the film puts on the box */
} plain_box;

typedef struct plain_contact {
    double k, c, mu, vlim;
    long touching; /* node contacts evaluated so far */
} plain_contact;

static inline void plain_contacts(plain_node *nd, size_t n, plain_box *bx, size_t nb,
                                  plain_contact *pc)
{
    for (size_t i = 0; i < n; i++)
        for (size_t b = 0; b < nb; b++) {
            plain_box *B = &bx[b];
            double r[3], l[3];
            for (int a = 0; a < 3; a++)
                r[a] = nd[i].x[a] - B->c[a];
            int inside = 1;
            for (int a = 0; a < 3; a++) {
                l[a] = B->R[a][0] * r[0] + B->R[a][1] * r[1] + B->R[a][2] * r[2];
                inside &= fabs(l[a]) < B->h[a];
            }
            if (!inside)
                continue;
            int face = 0;
            double depth = B->h[0] - fabs(l[0]);
            for (int a = 1; a < 3; a++)
                if (B->h[a] - fabs(l[a]) < depth) {
                    depth = B->h[a] - fabs(l[a]);
                    face = a;
                }
            double nrm[3], vn = 0.0, vt[3], st = 0.0;
            for (int a = 0; a < 3; a++) {
                nrm[a] = (l[face] < 0.0 ? -1.0 : 1.0) * B->R[face][a];
                vn += nd[i].v[a] * nrm[a];
            }
            double fn = pc->k * depth - pc->c * vn;
            if (fn <= 0.0)
                continue;
            for (int a = 0; a < 3; a++) {
                vt[a] = nd[i].v[a] - vn * nrm[a];
                st += vt[a] * vt[a];
            }
            st = sqrt(st);
            const double ft = pc->mu * fn / (st > pc->vlim ? st : pc->vlim);
            double f[3];
            for (int a = 0; a < 3; a++) {
                f[a] = fn * nrm[a] - ft * vt[a];
                nd[i].f[a] += f[a];
                B->f[a] -= f[a];
            }
            B->m[0] -= r[1] * f[2] - r[2] * f[1];
            B->m[1] -= r[2] * f[0] - r[0] * f[2];
            B->m[2] -= r[0] * f[1] - r[1] * f[0];
            pc->touching++;
        }
}

/* plain_step with the contacts between the springs' forces and the integration. */
static inline void plain_step_contacts(plain_node *nd, size_t n, const plain_spring *sp, size_t ns,
                                double h, double gz, plain_box *bx, size_t nb, plain_contact *pc)
{
    plain_forces(nd, n, sp, ns, gz);
    for (size_t b = 0; b < nb; b++)
        for (int a = 0; a < 3; a++)
            bx[b].f[a] = bx[b].m[a] = 0.0;
    plain_contacts(nd, n, bx, nb, pc);
    plain_advance(nd, n, h);
}

/* Box b of the world as it stands: its centre and rotation, half sizes h grown by layer. */
static inline void plain_box_load(ws_world *w, ws_body_id b, const double h[3], double layer,
                           plain_box *B)
{
    ws_vec3 c;
    ws_quat q;
    ws_body_get_position(w, b, &c);
    ws_body_get_orientation(w, b, &q);
    B->c[0] = c.x, B->c[1] = c.y, B->c[2] = c.z;
    /* Rows of R^T (world to body): the body's axes in world coordinates. */
    const double e0 = q.e0, e1 = q.e1, e2 = q.e2, e3 = q.e3;
    const double A[3][3] = {
        {1 - 2 * (e2 * e2 + e3 * e3), 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2)},
        {2 * (e1 * e2 + e0 * e3), 1 - 2 * (e1 * e1 + e3 * e3), 2 * (e2 * e3 - e0 * e1)},
        {2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), 1 - 2 * (e1 * e1 + e2 * e2)}};
    for (int a = 0; a < 3; a++) {
        for (int k = 0; k < 3; k++)
            B->R[a][k] = A[k][a];
        B->h[a] = h[a] + layer;
        B->f[a] = B->m[a] = 0.0;
    }
}

typedef struct plain_film {
    plain_node *nd;
    plain_spring *sp;
    size_t n, ns;
} plain_film;

/* The film of `web` as it stands: places, springs, and each spring's law from its strain and
 * tension (stiffness EA = tension / strain, 1 % of it in compression, damping EA x
 * damping_per_ea, the default transition of 1e-3); every node gets the film's mean mass.
 * Returns 0, or -1 when the film cannot be read. */
static int plain_film_load(ws_world *w, ws_web_id web, double damping_per_ea, plain_film *pf)
{
    ws_web_info info;
    size_t n = 0, ns = 0, got = 0;
    ws_web_get_info(w, web, &info);
    ws_web_copy_positions(w, web, NULL, 0, &n);
    ws_web_copy_springs(w, web, NULL, 0, &ns);
    double *xyz = malloc(3 * n * sizeof *xyz), *eps = malloc(ns * sizeof *eps),
           *ten = malloc(ns * sizeof *ten);
    uint32_t *pairs = malloc(2 * ns * sizeof *pairs);
    pf->nd = calloc(n, sizeof *pf->nd);
    pf->sp = calloc(ns, sizeof *pf->sp);
    pf->n = n;
    pf->ns = ns;
    int ok = xyz && eps && ten && pairs && pf->nd && pf->sp &&
             ws_web_copy_positions(w, web, xyz, n, &got) == WS_OK &&
             ws_web_copy_springs(w, web, pairs, ns, &got) == WS_OK &&
             ws_web_copy_spring_strains(w, web, eps, ns, &got) == WS_OK &&
             ws_web_copy_spring_tensions(w, web, ten, ns, &got) == WS_OK;
    if (ok) {
        const double m = info.mass / n;
        for (size_t i = 0; i < n; i++) {
            for (int c = 0; c < 3; c++)
                pf->nd[i].x[c] = xyz[3 * i + c];
            pf->nd[i].m = m;
            pf->nd[i].inv_m = 1.0 / m;
        }
        /* Each spring is pre-stretched far past the transition, where its tension is EA eps. */
        for (size_t k = 0; k < ns; k++) {
            const double ea = ten[k] / eps[k];
            pf->sp[k] = (plain_spring){pairs[2 * k], pairs[2 * k + 1], 0.0, 0.01 * ea, 0.99 * ea,
                                       1e-3, ea * damping_per_ea};
            const uint32_t a = pf->sp[k].a, b = pf->sp[k].b;
            double l2 = 0.0;
            for (int c = 0; c < 3; c++)
                l2 += (xyz[3 * b + c] - xyz[3 * a + c]) * (xyz[3 * b + c] - xyz[3 * a + c]);
            pf->sp[k].inv_l0 = (1.0 + eps[k]) / sqrt(l2);
        }
    }
    free(xyz);
    free(eps);
    free(ten);
    free(pairs);
    return ok ? 0 : -1;
}

/* The sum of the nodes' heights: finite unless the loop ran away. */
static double plain_film_check(const plain_film *pf)
{
    double sum = 0.0;
    for (size_t i = 0; i < pf->n; i++)
        sum += pf->nd[i].x[2];
    return sum;
}

static void plain_film_free(plain_film *pf)
{
    free(pf->nd);
    free(pf->sp);
}

#endif
