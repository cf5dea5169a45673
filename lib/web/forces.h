/* The film's forces term by term, each written once and inlined wherever a sweep needs it: a
 * spring law of the film form, a spring's strain, one spring's force, a node's gravity and
 * drag. For web.c (a grid web's rows) and mesh.c (a mesh web's springs); nothing else. */
#ifndef WS_WEB_FORCES_H
#define WS_WEB_FORCES_H

#include "web/web.h"

/* The film form's force at (eps, eps_dot): computed, then selected, so it runs on vectors. */
static inline double film_force(const ws_spring_form *p, double eps, double epsd)
{
    double a = eps + p->w;
    a = a > 0.0 ? a : 0.0;
    double quad = a * a * p->qw;
    double ramp = eps >= p->w ? eps : quad;
    return p->kc * eps + p->dk * ramp + p->c * epsd;
}

/* Strain and strain rate of spring s; 0 when its ends coincide (d is then zero too). */
static inline double strain_of(const ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s, v3 *d,
                               double *rate, double *inv_len)
{
    uint32_t a = web->sa[s], b = web->sb[s];
    *d = v3_sub(nodes_get(x, b), nodes_get(x, a));
    double l2 = v3_dot(*d, *d);
    if (!(l2 > 0.0)) {
        *rate = *inv_len = 0.0;
        return -1.0;
    }
    double l = sqrt(l2), il = 1.0 / l, il0 = web->inv_l0[s];
    *rate = v3_dot(v3_sub(nodes_get(v, b), nodes_get(v, a)), *d) * il * il0;
    *inv_len = il;
    return l * il0 - 1.0;
}

/* One spring in any place (the wrap of a closed band, shear diagonals, a mesh web's) and every
 * spring of a general law, which is evaluated with the spring's history as committed, at the
 * sweep's (t, since): its force on its end a into fu, 1; or 0 when it pulls nothing (broken,
 * its ends coincident, its law failed: a user callback, which marks the web, and the step
 * reports it). Inlined into every caller: a call for each cost as much as the spring. */
#define SPRING_INLINE inline __attribute__((always_inline))
static SPRING_INLINE int spring_force(ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s, v3 *fu)
{
    if (web->nbroken && web->broken[s])
        return 0;
    const ws_spring_form *p = &web->form[web->kind[s]];
    v3 d;
    double epsd, il, eps = strain_of(web, x, v, s, &d, &epsd, &il);
    if (il == 0.0)
        return 0; /* no direction to pull along */
    double F = 0.0;
    if (!p->gen) {
        F = film_force(p, eps, epsd);
    } else if (ws_law_eval(p->gen, web->nstate ? web->hist + (size_t)s * web->nstate : NULL, &eps,
                           &epsd, p->t, p->since, &F, NULL, NULL) != 0) {
        web->law_failed = 1;
        return 0;
    }
    if (web->kscale)
        F *= web->kscale[s];
    *fu = v3_scale(d, F * il); /* tension pulls the ends together */
    return 1;
}

/* Gravity and node drag on node i. */
static inline v3 base_force(const ws_web *web, ws_nodes3 v, size_t i)
{
    const v3 g = web->g;
    const double c = web->damping, m = web->same_m ? web->m1 : web->m[i];
    return v3_make(g.x * m - c * v.x[i], g.y * m - c * v.y[i], g.z * m - c * v.z[i]);
}

#endif
