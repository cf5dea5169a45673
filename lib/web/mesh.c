/* A mesh web's sweep: its springs by node, their forces computed in pieces (any worker) and
 * gathered node by node in spring order (web.h, "A sub-step sweeps the nodes in blocks"). */
#include "web/forces.h"

int ws_web_spring_index(ws_mem *mem, ws_web *web)
{
    if (web->inc0)
        return 0;
    const size_t n = web->n, ns = web->ns ? web->ns : 1;
    web->inc0 = ws_mem_calloc(mem, n + 1, sizeof(uint32_t));
    web->inc = ws_mem_calloc(mem, 2 * ns, sizeof(uint32_t));
    if (!web->inc0 || !web->inc)
        return -1; /* ws_web_free lets go of those made */
    /* Counted by node, then placed in spring order: each node's springs ascending. */
    for (uint32_t s = 0; s < web->ns; s++) {
        web->inc0[web->sa[s] + 1]++;
        web->inc0[web->sb[s] + 1]++;
    }
    for (size_t i = 0; i < n; i++)
        web->inc0[i + 1] += web->inc0[i];
    for (uint32_t s = 0; s < web->ns; s++) {
        web->inc[web->inc0[web->sa[s]]++] = 2 * s;
        web->inc[web->inc0[web->sb[s]]++] = 2 * s + 1;
    }
    for (size_t i = n; i > 0; i--) /* each start moved on by its node's count: back one node */
        web->inc0[i] = web->inc0[i - 1];
    web->inc0[0] = 0;
    return 0;
}

int ws_web_mesh_index(ws_mem *mem, ws_web *web)
{
    const size_t ns = web->ns ? web->ns : 1;
    if (ws_web_spring_index(mem, web) != 0)
        return -1;
    web->sf = ws_mem_calloc(mem, ns, sizeof(v3));
    web->son = ws_mem_calloc(mem, ns, 1);
    return web->sf && web->son ? 0 : -1; /* ws_web_free lets go of those made */
}

/* Springs [s0, s0 + m) of a mesh web, all of the film form q: spring_force's arithmetic,
 * computed then selected (pulls: the ends apart), so that the loop runs on vectors (the arrays
 * restrict, in a struct passed by value: web.c, in_at). Their ends are a0 + i and b0 + i when
 * `affine` (a row's springs: contiguous loads), else gathered by index (signed: a web has
 * fewer than 2^31 nodes); scaled by ks when `scaled`. A broken spring is left to the caller. */
typedef struct mesh_run {
    const double *restrict x, *restrict y, *restrict z, *restrict vx, *restrict vy, *restrict vz;
    const int32_t *restrict sa, *restrict sb;
    const double *restrict il0, *restrict ks;
    double *restrict sf;
    uint8_t *restrict on;
} mesh_run;

static SPRING_INLINE void mesh_pulls_of(const mesh_run r, const ws_spring_form q, uint32_t s0,
                                        uint32_t m, int affine, int scaled)
{
    const ptrdiff_t a0 = r.sa[s0], b0 = r.sb[s0];
    for (size_t i = 0; i < m; i++) {
        const size_t s = s0 + i;
        const ptrdiff_t a = affine ? a0 + (ptrdiff_t)i : r.sa[s];
        const ptrdiff_t b = affine ? b0 + (ptrdiff_t)i : r.sb[s];
        const double dx = r.x[b] - r.x[a], dy = r.y[b] - r.y[a], dz = r.z[b] - r.z[a];
        const double l2 = dx * dx + dy * dy + dz * dz;
        const double l = sqrt(l2), il = 1.0 / l;
        const double eps = l * r.il0[s] - 1.0;
        const double ud =
            (r.vx[b] - r.vx[a]) * dx + (r.vy[b] - r.vy[a]) * dy + (r.vz[b] - r.vz[a]) * dz;
        double F = film_force(&q, eps, ud * il * r.il0[s]);
        if (scaled)
            F *= r.ks[s];
        const double t = F * il;
        r.sf[3 * s] = dx * t;
        r.sf[3 * s + 1] = dy * t;
        r.sf[3 * s + 2] = dz * t;
        r.on[s] = l2 > 0.0;
    }
}

WS_VECTOR_LOOP
static void mesh_pulls(const ws_web *web, const ws_spring_form *p, ws_nodes3 x, ws_nodes3 v,
                       uint32_t s0, uint32_t m, int affine)
{
    const mesh_run r = {x.x,
                        x.y,
                        x.z,
                        v.x,
                        v.y,
                        v.z,
                        (const int32_t *)web->sa,
                        (const int32_t *)web->sb,
                        web->inv_l0,
                        web->kscale,
                        &web->sf[0].x,
                        web->son};
    if (affine && web->kscale)
        mesh_pulls_of(r, *p, s0, m, 1, 1);
    else if (affine)
        mesh_pulls_of(r, *p, s0, m, 1, 0);
    else if (web->kscale)
        mesh_pulls_of(r, *p, s0, m, 0, 1);
    else
        mesh_pulls_of(r, *p, s0, m, 0, 0);
}

/* Where the springs from s on stop following one another (spring i + 1 joins the nodes after
 * spring i's): a run of a mesh web's row, or s + 1. */
static uint32_t affine_end(const ws_web *web, uint32_t s, uint32_t e)
{
    uint32_t k = s + 1;
    while (k < e && web->sa[k] == web->sa[k - 1] + 1 && web->sb[k] == web->sb[k - 1] + 1)
        k++;
    return k;
}

void ws_web_mesh_springs(ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s0, uint32_t s1)
{
    /* Runs of one kind of the film form on vectors; a general law's springs one by one. */
    for (uint32_t s = s0, e; s < s1; s = e) {
        const uint8_t k = web->kind[s];
        for (e = s + 1; e < s1 && web->kind[e] == k;)
            e++;
        if (web->form[k].gen) {
            for (uint32_t i = s; i < e; i++)
                web->son[i] = (uint8_t)spring_force(web, x, v, i, &web->sf[i]);
            continue;
        }
        /* Runs of 16 or more on contiguous loads, the springs between gathered. */
        for (uint32_t i = s, g = s, r; i < e; i = r) {
            r = affine_end(web, i, e);
            if (r - i >= 16 || r == e) {
                if (i > g)
                    mesh_pulls(web, &web->form[k], x, v, g, i - g, 0);
                mesh_pulls(web, &web->form[k], x, v, i, r - i, r - i >= 16);
                g = r;
            }
        }
        for (uint32_t i = s; web->nbroken && i < e; i++)
            web->son[i] &= (uint8_t)!web->broken[i];
    }
}

/* A mesh web's nodes [n0, n1): gravity and drag, then their springs' forces in spring order,
 * + on end a and - on end b, as f + (-1) g: f + (-g) is f - g to the bit, the scatter's sums
 * (and no branch on the end to mispredict). */
void ws_web_mesh_gather(ws_web *web, ws_nodes3 v, uint32_t n0, uint32_t n1)
{
    static const double sign[2] = {1.0, -1.0};
    const uint32_t *restrict inc0 = web->inc0, *restrict inc = web->inc;
    const v3 *restrict sf = web->sf;
    const uint8_t *restrict on = web->son;
    const ws_nodes3 f = web->f;
    for (uint32_t i = n0; i < n1; i++) {
        v3 t = base_force(web, v, i);
        for (uint32_t q = inc0[i]; q < inc0[i + 1]; q++) {
            const uint32_t e = inc[q], s = e >> 1;
            if (on[s])
                t = v3_add(t, v3_scale(sf[s], sign[e & 1u]));
        }
        nodes_set(f, i, t);
    }
}
