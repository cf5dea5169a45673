/* Film rupture: at the end of each step, springs strained past the web's rupture strain break,
 * and the first break is recorded for the report (docs/guide.md, chapter 5, "Rupture"). The
 * sweep (web.c) gives a broken spring no force. */
#include "web/web.h"

int ws_web_rupture_alloc(ws_mem *mem, ws_web *web)
{
    if (web->broken)
        return 0;
    web->broken = ws_mem_calloc(mem, (size_t)web->ns + WS_WEB_PAD, 1);
    return web->broken ? 0 : -1;
}

/* The rupture check's pass over the springs: springs broken so far in it, and the most
 * strained of them. q is a little under (1 + limit)^2: a spring whose squared stretch
 * (l / l0)^2 is not above it cannot have a strain above the limit, whatever the rounding, and
 * needs no square root. */
typedef struct rupture_pass {
    double lim, q;
    uint32_t most;
    double most_eps;
} rupture_pass;

/* Springs [s0, s1): each intact one strained past the limit breaks. */
static void break_range(ws_web *web, ws_nodes3 x, uint32_t s0, uint32_t s1, rupture_pass *r)
{
    for (uint32_t s = s0; s < s1; s++) {
        if (web->broken[s])
            continue;
        const uint32_t a = web->sa[s], b = web->sb[s];
        const double dx = x.x[b] - x.x[a], dy = x.y[b] - x.y[a], dz = x.z[b] - x.z[a];
        const double il0 = web->inv_l0[s];
        if (!((dx * dx + dy * dy + dz * dz) * il0 * il0 > r->q))
            continue;
        /* The strain as every read-out gives it decides. */
        double eps = ws_web_spring_strain(web, x, s);
        if (!(eps > r->lim))
            continue;
        web->broken[s] = 1;
        web->nbroken++;
        web->nbroken_step++;
        if (r->most == UINT32_MAX || eps > r->most_eps) {
            r->most = s;
            r->most_eps = eps;
        }
    }
}

/* How many of the springs from node i to node i + stride, i in [0, m), rest lengths
 * 1 / il0[i], have a squared stretch above q: a count, so the loop runs on vectors. */
WS_VECTOR_LOOP
static size_t stretched(const double *restrict x, const double *restrict y,
                        const double *restrict z, size_t stride, size_t m,
                        const double *restrict il0, double q)
{
    size_t hits = 0;
    for (size_t i = 0; i < m; i++) {
        double dx = x[i + stride] - x[i], dy = y[i + stride] - y[i], dz = z[i + stride] - z[i];
        hits += (dx * dx + dy * dy + dz * dz) * il0[i] * il0[i] > q;
    }
    return hits;
}

void ws_web_rupture_check(ws_web *web, ws_nodes3 x, double t)
{
    /* Strains at the end of the step, as the state will be read: a spring breaks once its
     * committed strain passes the limit (a strain above it inside the sub-steps of one step
     * and back below at its end does not break it). NaN never breaks one: the step's health
     * check reports that. A grid web's around- and up-springs are first screened a row at a
     * time on vectors; only a row with a spring near the limit (or a broken one) is gone
     * through spring by spring. */
    const double lim = web->rupture, one = 1.0 + lim;
    rupture_pass r = {lim, one * one * (1.0 - 1e-9), UINT32_MAX, 0.0};
    if (web->nx > 0 && web->ny > 0) {
        const size_t nx = (size_t)web->nx, ny = (size_t)web->ny;
        const size_t cols = web->closed ? nx : nx - 1;
        for (size_t j = 0; j < ny; j++) {
            const size_t a = nx * j, s = cols * j;
            if (nx >= 2 && stretched(x.x + a, x.y + a, x.z + a, 1, nx - 1, web->inv_l0 + s, r.q))
                break_range(web, x, (uint32_t)s, (uint32_t)(s + nx - 1), &r);
            if (web->closed)
                break_range(web, x, (uint32_t)(s + nx - 1), (uint32_t)(s + nx), &r);
        }
        for (size_t j = 0; j + 1 < ny; j++) {
            const size_t a = nx * j, s = cols * ny + nx * j;
            if (stretched(x.x + a, x.y + a, x.z + a, nx, nx, web->inv_l0 + s, r.q))
                break_range(web, x, (uint32_t)s, (uint32_t)(s + nx), &r);
        }
        break_range(web, x, (uint32_t)(cols * ny + nx * (ny - 1)), web->ns, &r); /* shear */
    } else {
        break_range(web, x, 0, web->ns, &r);
    }
    if (r.most == UINT32_MAX || web->first_spring != UINT32_MAX)
        return;
    web->first_spring = r.most;
    web->first_time = t;
    web->first_strain = r.most_eps;
    web->first_at =
        v3_scale(v3_add(nodes_get(x, web->sa[r.most]), nodes_get(x, web->sb[r.most])), 0.5);
}

void ws_web_rupture_recount(ws_web *web)
{
    uint32_t n = 0;
    for (uint32_t s = 0; web->broken && s < web->ns; s++)
        n += web->broken[s] != 0;
    web->nbroken = n;
}
