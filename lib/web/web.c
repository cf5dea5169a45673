#include "web/web.h"

#include <string.h>

ws_status ws_web_alloc(ws_mem *mem, ws_web *web, uint32_t n, uint32_t ns)
{
    memset(web, 0, sizeof *web);
    web->n = n;
    web->ns = ns;
    int ok = 1;
    for (int k = 0; k < 2; k++) {
        ok &= (web->x[k] = ws_mem_calloc(mem, n, sizeof(v3))) != NULL;
        ok &= (web->v[k] = ws_mem_calloc(mem, n, sizeof(v3))) != NULL;
        ok &= (web->fc[k] = ws_mem_calloc(mem, n, sizeof(v3))) != NULL;
    }
    ok &= (web->f = ws_mem_calloc(mem, n, sizeof(v3))) != NULL;
    ok &= (web->m = ws_mem_calloc(mem, n, sizeof(double))) != NULL;
    ok &= (web->inv_m = ws_mem_calloc(mem, n, sizeof(double))) != NULL;
    ok &= (web->sa = ws_mem_calloc(mem, ns ? ns : 1, sizeof(uint32_t))) != NULL;
    ok &= (web->sb = ws_mem_calloc(mem, ns ? ns : 1, sizeof(uint32_t))) != NULL;
    ok &= (web->inv_l0 = ws_mem_calloc(mem, ns ? ns : 1, sizeof(double))) != NULL;
    ok &= (web->kind = ws_mem_calloc(mem, ns ? ns : 1, sizeof(uint8_t))) != NULL;
    if (!ok) {
        ws_web_free(mem, web);
        return WS_ERR_OUT_OF_MEMORY;
    }
    return WS_OK;
}

void ws_web_free(ws_mem *mem, ws_web *web)
{
    size_t n = web->n, ns = web->ns ? web->ns : 1;
    for (int k = 0; k < 2; k++) {
        ws_mem_free(mem, web->x[k], n * sizeof(v3));
        ws_mem_free(mem, web->v[k], n * sizeof(v3));
        ws_mem_free(mem, web->fc[k], n * sizeof(v3));
        ws_mem_free(mem, web->cand[k], web->capcand[k] * sizeof(ws_ncand));
        if (k == 0)
            ws_mem_free(mem, web->act, web->act_cap * sizeof(ws_nact));
        ws_mem_free(mem, web->bforce[k], web->bcap * sizeof(v3));
        ws_mem_free(mem, web->bmoment[k], web->bcap * sizeof(v3));
    }
    ws_mem_free(mem, web->f, n * sizeof(v3));
    ws_mem_free(mem, web->m, n * sizeof(double));
    ws_mem_free(mem, web->inv_m, n * sizeof(double));
    ws_mem_free(mem, web->sa, ns * sizeof(uint32_t));
    ws_mem_free(mem, web->sb, ns * sizeof(uint32_t));
    ws_mem_free(mem, web->inv_l0, ns * sizeof(double));
    ws_mem_free(mem, web->kind, ns * sizeof(uint8_t));
    ws_mem_free_str(mem, web->name);
    memset(web, 0, sizeof *web);
}

void ws_web_internal_forces(ws_web *web, const v3 *x, const v3 *v, v3 g)
{
    v3 *f = web->f;
    const double c = web->damping;
    for (uint32_t i = 0; i < web->n; i++)
        f[i] = v3_madd(v3_scale(g, web->m[i]), v[i], -c);
    /* The laws' parameters by spring kind, hoisted out of the loop. Linear laws have
     * kc = k, so their ramp term vanishes and one formula serves every law type:
     * F = kc eps + (k - kc) g(eps) + c eps_dot (lib/law/law.h). */
    double K[3] = {0}, DK[3] = {0}, W[3] = {1, 1, 1}, C[3] = {0};
    for (int k = 0; k < 3; k++) {
        const ws_law1d *L = web->law[k];
        if (!L)
            continue;
        K[k] = L->kc;
        DK[k] = L->k - L->kc;
        W[k] = L->w;
        C[k] = L->c;
    }
    for (uint32_t s = 0; s < web->ns; s++) {
        uint32_t a = web->sa[s], b = web->sb[s];
        v3 d = v3_sub(x[b], x[a]);
        double l2 = v3_dot(d, d);
        if (!(l2 > 0.0))
            continue; /* coincident ends: no direction to pull along */
        double l = sqrt(l2), il = 1.0 / l, il0 = web->inv_l0[s];
        double eps = l * il0 - 1.0;
        double epsd = v3_dot(v3_sub(v[b], v[a]), d) * il * il0;
        int kd = web->kind[s];
        double ramp = 0.0;
        if (DK[kd] != 0.0) {
            double w = W[kd];
            ramp = eps >= w ? eps : eps <= -w ? 0.0 : (eps + w) * (eps + w) / (4.0 * w);
        }
        double F = K[kd] * eps + DK[kd] * ramp + C[kd] * epsd;
        v3 fu = v3_scale(d, F * il); /* tension pulls the ends together */
        f[a] = v3_add(f[a], fu);
        f[b] = v3_sub(f[b], fu);
    }
}

double ws_web_integrate(ws_web *web, const v3 *xs, const v3 *vs, v3 *xd, v3 *vd, double h)
{
    double most = 0.0;
    for (uint32_t i = 0; i < web->n; i++) {
        v3 v = v3_madd(vs[i], web->f[i], h * web->inv_m[i]);
        if (web->inv_m[i] == 0.0)
            v = v3_make(0, 0, 0);
        vd[i] = v;
        xd[i] = v3_madd(xs[i], v, h);
        double s = v3_norm2(v);
        if (!(s <= most)) /* also catches NaN, so the health check sees it */
            most = s;
    }
    return sqrt(most);
}

/* Per free node, into the force scratch (not state; no step is running when this is asked):
 * f.x = 2 sum of its springs' largest stiffness / l0 -- the Gershgorin bound of its row of the
 * stiffness matrix -- and f.y = 2 sum of their damping / l0. */
static void node_bounds(const ws_web *web)
{
    v3 *acc = ((ws_web *)web)->f;
    for (uint32_t i = 0; i < web->n; i++)
        acc[i] = v3_make(0, 0, 0);
    for (uint32_t s = 0; s < web->ns; s++) {
        const ws_law1d *L = web->law[web->kind[s]];
        double k = 2.0 * ws_law1d_max_stiffness(L) * web->inv_l0[s];
        double c = 2.0 * L->c * web->inv_l0[s];
        acc[web->sa[s]].x += k;
        acc[web->sb[s]].x += k;
        acc[web->sa[s]].y += c;
        acc[web->sb[s]].y += c;
    }
}

double ws_web_stable_dt(const ws_web *web, double kc, double cc)
{
    /* Symplectic Euler on m x'' + c x' + k x = 0 is stable for
     * dt < 2/omega (sqrt(1 + z^2) - z), omega^2 = k/m, z = c/(2 m omega). */
    double best = INFINITY;
    node_bounds(web);
    for (uint32_t i = 0; i < web->n; i++) {
        if (web->inv_m[i] == 0.0)
            continue;
        double k = web->f[i].x + kc, c = web->f[i].y + cc + web->damping;
        double om = sqrt(k * web->inv_m[i]);
        if (!(om > 0.0))
            continue;
        double z = c * web->inv_m[i] / (2.0 * om);
        double dt = 2.0 / om * (sqrt(1.0 + z * z) - z);
        if (dt < best)
            best = dt;
    }
    return best;
}

void ws_web_stiffest_node(const ws_web *web, double kc, double *min_mass, double *max_k)
{
    double mm = INFINITY, mk = 0.0;
    node_bounds(web);
    for (uint32_t i = 0; i < web->n; i++) {
        if (web->inv_m[i] == 0.0)
            continue;
        mm = fmin(mm, web->m[i]);
        mk = fmax(mk, web->f[i].x + kc);
    }
    *min_mass = mm;
    *max_k = mk;
}

double ws_web_spring_strain(const ws_web *web, const v3 *x, uint32_t s)
{
    return v3_norm(v3_sub(x[web->sb[s]], x[web->sa[s]])) * web->inv_l0[s] - 1.0;
}

double ws_web_spring_tension(const ws_web *web, const v3 *x, const v3 *v, uint32_t s)
{
    uint32_t a = web->sa[s], b = web->sb[s];
    v3 d = v3_sub(x[b], x[a]);
    double l = v3_norm(d);
    double eps = l * web->inv_l0[s] - 1.0, epsd = 0.0;
    if (l > 0.0)
        epsd = v3_dot(v3_sub(v[b], v[a]), v3_scale(d, 1.0 / l)) * web->inv_l0[s];
    return ws_law1d_eval(web->law[web->kind[s]], eps, epsd, NULL, NULL);
}

double ws_web_elastic_energy(const ws_web *web, const v3 *x)
{
    double e = 0.0;
    for (uint32_t s = 0; s < web->ns; s++)
        e += ws_law1d_energy(web->law[web->kind[s]], ws_web_spring_strain(web, x, s)) /
             web->inv_l0[s];
    return e;
}
