/* Optional libccd gate: MPR on the convex hulls inflated by the contact layers and half the
 * margin. A pair that MPR proves apart cannot produce a candidate, so skipping it changes no
 * result; it only saves the feature loops. libccd's types stay inside this file. */
#include "contact/contact.h"

#ifdef WS_HAVE_CCD
#include <ccd/ccd.h>

typedef struct gate_obj {
    const ws_shape *shape;
    const m3 *A;
    v3 r;
    double inflate;
} gate_obj;

static void support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out)
{
    const gate_obj *g = obj;
    v3 d = v3_make(dir->v[0], dir->v[1], dir->v[2]);
    v3 s = ws_shape_support(g->shape, m3_tmul_v(g->A, d));
    v3 p = v3_add(g->r, m3_mul_v(g->A, s));
    double n = v3_norm(d);
    if (n > 0.0)
        p = v3_madd(p, d, g->inflate / n);
    out->v[0] = p.x;
    out->v[1] = p.y;
    out->v[2] = p.z;
}

static void center(const void *obj, ccd_vec3_t *out)
{
    const gate_obj *g = obj;
    out->v[0] = g->r.x;
    out->v[1] = g->r.y;
    out->v[2] = g->r.z;
}

int ws_ccd_may_touch_at(const ws_body_store *b, int cur, uint32_t i, uint32_t j, double margin)
{
    if (!b->shape[i]->convex || !b->shape[j]->convex)
        return 1;
    double extra = 1e-6 * (b->shape[i]->radius + b->shape[j]->radius);
    gate_obj oi = {b->shape[i], &b->A[i], b->st[cur].r[i], b->layer[i] + 0.5 * margin + extra};
    gate_obj oj = {b->shape[j], &b->A[j], b->st[cur].r[j], b->layer[j] + 0.5 * margin + extra};
    ccd_t ccd;
    CCD_INIT(&ccd);
    ccd.support1 = support;
    ccd.support2 = support;
    ccd.center1 = center;
    ccd.center2 = center;
    ccd.max_iterations = 100;
    ccd.mpr_tolerance = 1e-9;
    ccd.epa_tolerance = 1e-9;
    ccd.dist_tolerance = 1e-9;
    return ccdMPRIntersect(&oi, &oj, &ccd) ? 1 : 0;
}
#else
int ws_ccd_may_touch_at(const ws_body_store *b, int cur, uint32_t i, uint32_t j, double margin)
{
    (void)b;
    (void)cur;
    (void)i;
    (void)j;
    (void)margin;
    return 1;
}
#endif
