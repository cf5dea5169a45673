/* The plain scalar explicit loop over a film (bench_plain.c, bench_pallet.c): the film's nodes,
 * their places and masses, its springs with their rest lengths and a tension-compression law,
 * gravity and symplectic Euler, but no contacts and no bodies. Written as a C programmer would
 * write it first: nodes as structures, a list of springs, one loop over the springs and one over
 * the nodes; the including benchmark is compiled without vectors (bench/meson.build). */
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

static void plain_step(plain_node *nd, size_t n, const plain_spring *sp, size_t ns, double h,
                       double gz)
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
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            nd[i].v[c] += h * nd[i].inv_m * nd[i].f[c];
            nd[i].x[c] += h * nd[i].v[c];
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
