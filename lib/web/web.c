#include "web/forces.h"
#include "web/implicit.h"

#include <float.h>
#include <string.h>

int ws_nodes_alloc(ws_mem *mem, ws_nodes3 *a, uint32_t n)
{
    double *p = ws_mem_calloc(mem, 3 * (size_t)n + WS_WEB_PAD, sizeof(double));
    a->x = p;
    a->y = p ? p + n : NULL;
    a->z = p ? p + 2 * (size_t)n : NULL;
    return p != NULL;
}

void ws_nodes_free(ws_mem *mem, ws_nodes3 *a, uint32_t n)
{
    ws_mem_free(mem, a->x, (3 * (size_t)n + WS_WEB_PAD) * sizeof(double));
    a->x = a->y = a->z = NULL;
}

ws_status ws_web_alloc(ws_mem *mem, ws_web *web, uint32_t n, uint32_t ns)
{
    memset(web, 0, sizeof *web);
    web->n = n;
    web->ns = ns;
    web->first_spring = UINT32_MAX;
    int ok = 1;
    for (int k = 0; k < 2; k++) {
        ok &= ws_nodes_alloc(mem, &web->x[k], n) & ws_nodes_alloc(mem, &web->v[k], n);
        ok &= (web->fc[k] = ws_mem_calloc(mem, n, sizeof(v3))) != NULL;
    }
    ok &= ws_nodes_alloc(mem, &web->fmem, n);
    web->f = web->fmem;
    ok &= ws_nodes_alloc(mem, &web->xsub, n) & ws_nodes_alloc(mem, &web->vsub, n);
    ok &= (web->tmp = ws_mem_calloc(mem, WS_WEB_TMP, sizeof(double))) != NULL;
    ok &= (web->m = ws_mem_calloc(mem, n, sizeof(double))) != NULL;
    ok &= (web->inv_m = ws_mem_calloc(mem, n, sizeof(double))) != NULL;
    ok &= (web->sa = ws_mem_calloc(mem, ns ? ns : 1, sizeof(uint32_t))) != NULL;
    ok &= (web->sb = ws_mem_calloc(mem, ns ? ns : 1, sizeof(uint32_t))) != NULL;
    ok &= (web->inv_l0 = ws_mem_calloc(mem, (size_t)ns + WS_WEB_PAD, sizeof(double))) != NULL;
    ok &= (web->kind = ws_mem_calloc(mem, ns ? ns : 1, sizeof(uint8_t))) != NULL;
    if (!ok)
        ws_web_free(mem, web);
    return ok ? WS_OK : WS_ERR_OUT_OF_MEMORY;
}

void ws_web_free(ws_mem *mem, ws_web *web)
{
    size_t n = web->n, ns = web->ns ? web->ns : 1;
    for (int k = 0; k < 2; k++) {
        ws_nodes_free(mem, &web->x[k], web->n);
        ws_nodes_free(mem, &web->v[k], web->n);
        ws_mem_free(mem, web->fc[k], n * sizeof(v3));
        ws_mem_free(mem, web->fct[k], web->fct_cap[k] * sizeof(uint32_t));
        ws_mem_free(mem, web->bforce[k], web->bcap * sizeof(v3));
        ws_mem_free(mem, web->bmoment[k], web->bcap * sizeof(v3));
    }
    ws_nodes_free(mem, &web->fmem, web->n);
    ws_nodes_free(mem, &web->xsub, web->n);
    ws_nodes_free(mem, &web->vsub, web->n);
    ws_mem_free(mem, web->tmp, WS_WEB_TMP * sizeof(double));
    ws_mem_free(mem, web->m, n * sizeof(double));
    ws_mem_free(mem, web->inv_m, n * sizeof(double));
    ws_mem_free(mem, web->sa, ns * sizeof(uint32_t));
    ws_mem_free(mem, web->sb, ns * sizeof(uint32_t));
    ws_mem_free(mem, web->inv_l0, ((size_t)web->ns + WS_WEB_PAD) * sizeof(double));
    ws_mem_free(mem, web->kind, ns * sizeof(uint8_t));
    ws_mem_free(mem, web->kscale, web->kscale ? (size_t)web->ns * sizeof(double) : 0);
    ws_mem_free(mem, web->inc0, web->inc0 ? (n + 1) * sizeof(uint32_t) : 0);
    ws_mem_free(mem, web->inc, web->inc ? 2 * ns * sizeof(uint32_t) : 0);
    ws_mem_free(mem, web->sf, web->sf ? ns * sizeof(v3) : 0);
    ws_mem_free(mem, web->son, web->son ? ns : 0);
    ws_mem_free(mem, web->hist, web->hist ? (size_t)web->ns * web->nstate * sizeof(double) : 0);
    ws_mem_free(mem, web->broken, web->broken ? (size_t)web->ns + WS_WEB_PAD : 0);
    ws_mem_free_str(mem, web->name);
    ws_implicit_free(mem, web);
    memset(web, 0, sizeof *web);
}

void ws_web_note_masses(ws_web *web)
{
    web->same_m = web->same_inv_m = web->n > 0;
    for (uint32_t i = 1; i < web->n; i++) {
        web->same_m &= web->m[i] == web->m[0];
        web->same_inv_m &= web->inv_m[i] == web->inv_m[0];
    }
    web->m1 = web->n ? web->m[0] : 0.0;
    web->inv_m1 = web->n ? web->inv_m[0] : 0.0;
}

static ws_spring_form form_of(const ws_law *L, double t, double since)
{
    ws_spring_form p = {0.0, 0.0, 1.0, 0.25, 0.0, NULL, t, since};
    if (L && !ws_law_film_form(L, &p.kc, &p.dk, &p.w, &p.c))
        p.gen = L;
    else if (L)
        p.qw = 0.25 / p.w;
    return p;
}

/* The histories of the springs whose law keeps one, advanced at their strains and rates at
 * (x, v), time t, over dt. */
static void commit_laws(ws_web *web, ws_nodes3 x, ws_nodes3 v, double t, double dt)
{
    for (uint32_t s = 0; s < web->ns; s++) {
        const ws_law *L = web->law[web->kind[s]];
        if (!L->nstate)
            continue;
        v3 d;
        double epsd, il, eps = strain_of(web, x, v, s, &d, &epsd, &il);
        ws_law_commit(L, web->hist + (size_t)s * web->nstate, &eps, &epsd, t, dt);
    }
}

int ws_web_law_state(ws_mem *mem, ws_web *web)
{
    uint32_t most = 0;
    for (int k = 0; k < 3; k++)
        if (web->law[k] && web->law[k]->nstate > most)
            most = web->law[k]->nstate;
    web->nstate = most;
    if (!most || !web->ns)
        return 0;
    web->hist = ws_mem_calloc(mem, (size_t)web->ns * most, sizeof(double));
    if (!web->hist)
        return -1;
    /* The film was stretched to its pre-stretch when it was put on: each spring starts with the
     * history of a strain step to where it is now (committed over no time), from which a
     * relaxation law relaxes. */
    for (uint32_t s = 0; s < web->ns; s++)
        ws_law_state_init(web->law[web->kind[s]], web->hist + (size_t)s * most);
    commit_laws(web, web->x[0], web->v[0], 0.0, 0.0);
    return 0;
}

void ws_web_commit(ws_web *web, ws_nodes3 x, ws_nodes3 v, double t, double dt)
{
    web->nbroken_step = 0;
    if (web->rupture > 0.0)
        ws_web_rupture_check(web, x, t);
    if (web->nstate)
        commit_laws(web, x, v, t, dt);
}

/* Tension / length of a spring of film form p whose second end is at d from its first and moves
 * at u relative to it, rest length 1 / il0; none where the ends coincide (no direction to pull
 * along). Computed, then selected, so the loops over springs have no branches. */
static inline double film_pull(const ws_spring_form *p, v3 d, v3 u, double il0)
{
    double l2 = d.x * d.x + d.y * d.y + d.z * d.z;
    double l = sqrt(l2);
    double inv = 1.0 / l;
    double il = l2 > 0.0 ? inv : 0.0;
    double eps = l * il0 - 1.0;
    double epsd = (u.x * d.x + u.y * d.y + u.z * d.z) * il * il0;
    return film_force(p, eps, epsd) * il;
}

/* Node vectors as the vector loops take them, from node i on: restrict, as no two arrays that
 * a loop reads and writes overlap, so the compiler runs the loop on vectors without checking
 * first. GCC honours the restrict of a struct's fields where the struct is a parameter passed
 * by value (also into an inlined function), not where it is reached through a pointer. */
typedef struct in3 {
    const double *restrict x, *restrict y, *restrict z;
} in3;
typedef struct out3 {
    double *restrict x, *restrict y, *restrict z;
} out3;

static inline in3 in_at(ws_nodes3 a, size_t i)
{
    return (in3){a.x + i, a.y + i, a.z + i};
}

static inline out3 out_at(ws_nodes3 a, size_t i)
{
    return (out3){a.x + i, a.y + i, a.z + i};
}

/* The web's scratch for the forces of a chunk of springs (WS_WEB_CHUNK of them). */
static inline ws_nodes3 chunk_forces(const ws_web *web)
{
    return (ws_nodes3){web->tmp, web->tmp + WS_WEB_CHUNK, web->tmp + 2 * WS_WEB_CHUNK};
}

/* Springs from node i to node i + 1, i in [0, m), all of the film form p, with rest lengths
 * 1 / il0[i] (x and v from the first end of the first spring): the force on each first end
 * into t. Straight-line code on contiguous arrays, so the compiler runs it on vectors. */
WS_VECTOR_LOOP
static void spring_run(const ws_spring_form *p, in3 x, in3 v, size_t m, const double *restrict il0,
                       out3 t)
{
    const ws_spring_form q = *p; /* a local: loads through p would stay in the loop */
    for (size_t i = 0; i < m; i++) {
        v3 d = v3_make(x.x[i + 1] - x.x[i], x.y[i + 1] - x.y[i], x.z[i + 1] - x.z[i]);
        v3 u = v3_make(v.x[i + 1] - v.x[i], v.y[i + 1] - v.y[i], v.z[i + 1] - v.z[i]);
        double s = film_pull(&q, d, u, il0[i]);
        t.x[i] = d.x * s;
        t.y[i] = d.y * s;
        t.z[i] = d.z * s;
    }
}

/* Springs from node i to node i + stride, i in [0, m), stride >= m (no node is an end of two of
 * them), as spring_run: their forces straight onto both ends, fa[i] += t and fb[i] -= t (fb at
 * stride from fa), in the loop that computes them. */
WS_VECTOR_LOOP
static void spring_apply(const ws_spring_form *p, in3 x, in3 v, size_t stride, size_t m,
                         const double *restrict il0, out3 fa, out3 fb)
{
    const ws_spring_form q = *p;
    for (size_t i = 0; i < m; i++) {
        const size_t k = i + stride;
        v3 d = v3_make(x.x[k] - x.x[i], x.y[k] - x.y[i], x.z[k] - x.z[i]);
        v3 u = v3_make(v.x[k] - v.x[i], v.y[k] - v.y[i], v.z[k] - v.z[i]);
        double s = film_pull(&q, d, u, il0[i]);
        v3 t = v3_make(d.x * s, d.y * s, d.z * s);
        fa.x[i] += t.x;
        fa.y[i] += t.y;
        fa.z[i] += t.z;
        fb.x[i] -= t.x;
        fb.y[i] -= t.y;
        fb.z[i] -= t.z;
    }
}

/* The same onto those of its ends in nodes [lo, hi). */
static SPRING_INLINE void spring_one_in(ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s,
                                        uint32_t lo, uint32_t hi)
{
    v3 fu;
    if (!spring_force(web, x, v, s, &fu))
        return;
    const uint32_t a = web->sa[s], b = web->sb[s];
    if (a >= lo && a < hi)
        nodes_add(web->f, a, fu);
    if (b >= lo && b < hi)
        nodes_add(web->f, b, v3_scale(fu, -1.0));
}

/* The same on nodes [n0, n1), the start of their forces: a row whose springs go one by one,
 * where their laws cost far more than this loop. */
static void base_forces(ws_web *web, ws_nodes3 v, size_t n0, size_t n1)
{
    for (size_t i = n0; i < n1; i++)
        nodes_set(web->f, (uint32_t)i, base_force(web, v, i));
}

/* Nodes i in [1, k) of a row, node i between the around-springs i - 1 and i whose forces on
 * their first ends are t[i - 1] and t[i]: gravity and drag, then + t[i], then - t[i - 1] (the
 * order of the results, the state hash: keep it). Masses m[i], or the one mass m1 when same (m
 * is not read); without drag the velocities are not read. */
static inline void row_forces_of(const ws_web *web, in3 v, in3 t, out3 f, const double *restrict m,
                                 size_t k, int same, int drag)
{
    const v3 g = web->g;
    const double c = web->damping, m1 = web->m1;
    for (size_t i = 1; i < k; i++) {
        const double mi = same ? m1 : m[i];
        if (drag) {
            f.x[i] = g.x * mi - c * v.x[i] + t.x[i] - t.x[i - 1];
            f.y[i] = g.y * mi - c * v.y[i] + t.y[i] - t.y[i - 1];
            f.z[i] = g.z * mi - c * v.z[i] + t.z[i] - t.z[i - 1];
        } else {
            f.x[i] = g.x * mi + t.x[i] - t.x[i - 1];
            f.y[i] = g.y * mi + t.y[i] - t.y[i - 1];
            f.z[i] = g.z * mi + t.z[i] - t.z[i - 1];
        }
    }
}

/* The same for the row's nodes from node q, t the web's chunk scratch. */
WS_VECTOR_LOOP
static void row_forces(ws_web *web, ws_nodes3 v, size_t q, size_t k)
{
    const in3 vq = in_at(v, q), t = in_at(chunk_forces(web), 0);
    const out3 f = out_at(web->f, q);
    if (web->same_m && web->no_drag)
        row_forces_of(web, vq, t, f, NULL, k, 1, 0);
    else if (web->same_m)
        row_forces_of(web, vq, t, f, NULL, k, 1, 1);
    else
        row_forces_of(web, vq, t, f, web->m + q, k, 0, 1);
}

/* Rupture in the sweep. While no spring of the web is broken (nbroken 0) none of this runs
 * and the sweep is what it is without rupture. After a break: a chunk of around-springs is
 * computed as before and the broken ones' forces are then set to zero (cut_chunk); a broken
 * wrap spring counts as one whose ends coincide (no force); a row of up-springs with a broken
 * one among them goes spring by spring (spring_one_in, which skips the broken), as the springs
 * of a general law do.
 *
 * cut_chunk: the forces t of springs s0 + i, i in [0, m), zero where broken. Selected, not
 * multiplied, so a broken spring stretched to any length gives a zero. */
WS_VECTOR_LOOP
static void cut_chunk(const uint8_t *restrict broken, size_t m, out3 t)
{
    for (size_t i = 0; i < m; i++) {
        t.x[i] = broken[i] ? 0.0 : t.x[i];
        t.y[i] = broken[i] ? 0.0 : t.y[i];
        t.z[i] = broken[i] ? 0.0 : t.z[i];
    }
}

/* The wrap springs of a closed band (node nx - 1 of a row to its node 0) by film_pull,
 * WS_WEB_WRAPS rows at once as the lanes of a vector. in, seven arrays of WS_WEB_WRAPS: the
 * second end's place (dx, dy, dz) and velocity (ux, uy, uz) relative to the first, 1 / rest
 * length; out, four: the force on the first end (tx, ty, tz), and 1 where the ends lie apart,
 * 0 where they coincide. Apart from its row, a wrap's division and square root do not hold up
 * the rest of the row's forces. */
WS_VECTOR_LOOP
static void wrap_lanes(const double *restrict in, ws_spring_form p, double *restrict out)
{
    enum { L = WS_WEB_WRAPS };
    for (size_t i = 0; i < L; i++) {
        v3 d = v3_make(in[i], in[L + i], in[2 * L + i]);
        v3 u = v3_make(in[3 * L + i], in[4 * L + i], in[5 * L + i]);
        double q = film_pull(&p, d, u, in[6 * L + i]);
        out[i] = d.x * q;
        out[L + i] = d.y * q;
        out[2 * L + i] = d.z * q;
        out[3 * L + i] = d.x * d.x + d.y * d.y + d.z * d.z > 0.0 ? 1.0 : 0.0;
    }
}

/* The wrap springs of rows [r, r + WS_WEB_WRAPS) (those below ny) into the web's scratch
 * (wrap_lanes' out); lanes past the last row have ends that coincide. */
static void wrap_rows(ws_web *web, ws_nodes3 x, ws_nodes3 v, size_t r)
{
    enum { L = WS_WEB_WRAPS };
    const size_t nx = (size_t)web->nx, ny = (size_t)web->ny;
    const double *from[6] = {x.x, x.y, x.z, v.x, v.y, v.z};
    double in[7 * L];
    for (size_t i = 0; i < L; i++) {
        const size_t b = nx * (r + i), a = b + nx - 1; /* the spring from a to b */
        const int row = r + i < ny;
        for (size_t q = 0; q < 6; q++)
            in[q * L + i] = row ? from[q][b] - from[q][a] : 0.0;
        in[6 * L + i] = row ? web->inv_l0[nx * (r + i + 1) - 1] : 0.0;
    }
    double *out = web->tmp + 3 * WS_WEB_CHUNK;
    wrap_lanes(in, web->form[WS_SPRING_AROUND], out);
    if (web->nbroken)
        for (size_t i = 0; i < L && r + i < ny; i++)
            if (web->broken[nx * (r + i + 1) - 1])
                out[3 * L + i] = 0.0; /* broken: no force, as for coincident ends */
}

/* The around-springs of row r of a grid, one law of film form, with the base forces of its
 * nodes: in chunks small enough for the scratch to stay in the first-level cache, each chunk's
 * forces computed, then put on its nodes in one pass. A node at the start of a chunk after the
 * first has had the previous chunk's spring already and gets its right-hand one after it. The
 * wrap spring of a closed band (from the row's last node to its first, in wrap_rows' out) goes
 * onto those two nodes last. */
static void around_row(ws_web *web, ws_nodes3 x, ws_nodes3 v, size_t r)
{
    const size_t nx = (size_t)web->nx, m = nx - 1, a = nx * r;
    const size_t s0 = (web->closed ? nx : nx - 1) * r; /* ws_web_build_grid's numbering */
    const ws_nodes3 f = web->f, t = chunk_forces(web);
    const double *wrap = web->tmp + 3 * WS_WEB_CHUNK + r % WS_WEB_WRAPS;
    v3 fw = v3_make(0.0, 0.0, 0.0);
    if (web->closed && wrap[3 * WS_WEB_WRAPS] != 0.0) /* else no wrap, or coincident ends */
        fw = v3_make(wrap[0], wrap[WS_WEB_WRAPS], wrap[2 * WS_WEB_WRAPS]);
    else
        wrap = NULL;
    for (size_t o = 0; o < m; o += WS_WEB_CHUNK) {
        size_t q = a + o, k = m - o < WS_WEB_CHUNK ? m - o : WS_WEB_CHUNK;
        /* Whole vectors: up to three springs more, whose forces are not used, from the nodes
         * after the row (the next row's, or the padding after the last) and the rest lengths
         * after its springs. Cheaper than the left-over springs one at a time. */
        spring_run(&web->form[WS_SPRING_AROUND], in_at(x, q), in_at(v, q), (k + 3) & ~(size_t)3,
                   web->inv_l0 + s0 + o, out_at(t, 0));
        if (web->nbroken)
            cut_chunk(web->broken + s0 + o, k, out_at(t, 0));
        if (o == 0) {
            v3 fa = v3_add(base_force(web, v, q), nodes_get(t, 0));
            nodes_set(f, (uint32_t)q, wrap ? v3_add(fa, v3_scale(fw, -1.0)) : fa);
        } else {
            nodes_add(f, (uint32_t)q, nodes_get(t, 0));
        }
        row_forces(web, v, q, k);
        v3 fb = v3_sub(base_force(web, v, q + k), nodes_get(t, (uint32_t)(k - 1)));
        nodes_set(f, (uint32_t)(q + k), wrap && o + k == m ? v3_add(fb, fw) : fb);
    }
}

/* Row r of a grid: its base forces and its around-springs (ws_web_build_grid numbers them row
 * by row, cols a row: node nx r + i to the next, and the wrap of a closed band last). A sweep
 * starts rows in order from row 0, so the first of each WS_WEB_WRAPS rows finds the wraps of
 * them all; the first row of a lane (lane_first) finds its group's as that row would. */
static void grid_row(ws_web *web, ws_nodes3 x, ws_nodes3 v, size_t r, int lane_first)
{
    const size_t nx = (size_t)web->nx, cols = web->closed ? nx : nx - 1;
    const ws_spring_form *p = &web->form[WS_SPRING_AROUND];
    if (p->gen || !web->law[WS_SPRING_AROUND] || nx < 2) {
        base_forces(web, v, nx * r, nx * (r + 1));
        for (size_t s = cols * r; p->gen && nx >= 2 && s < cols * (r + 1); s++)
            spring_one_in(web, x, v, (uint32_t)s, 0, UINT32_MAX);
        return;
    }
    if (web->closed && (r % WS_WEB_WRAPS == 0 || lane_first))
        wrap_rows(web, x, v, r - r % WS_WEB_WRAPS);
    around_row(web, x, v, r);
}

/* The up-springs and shear pairs from row j to row j + 1 onto their ends in rows [r0, r1): all
 * rows for both ends, or at a lane's edge its own row's side (web.h, "Lanes"). */
static void pair_springs(ws_web *web, ws_nodes3 x, ws_nodes3 v, size_t j, size_t r0, size_t r1)
{
    const size_t nx = (size_t)web->nx, ny = (size_t)web->ny;
    const size_t cols = web->closed ? nx : nx - 1, a = nx * j;
    const uint32_t lo = (uint32_t)(nx * r0), hi = (uint32_t)(nx * r1);
    const size_t s0 = cols * ny + nx * j;
    const ws_spring_form *p = &web->form[WS_SPRING_UP];
    /* Spring by spring: a general law's, or a row with a broken one (a flag of 1). */
    if (web->law[WS_SPRING_UP] && (p->gen || (web->nbroken && memchr(web->broken + s0, 1, nx)))) {
        for (size_t i = 0; i < nx; i++)
            spring_one_in(web, x, v, (uint32_t)(s0 + i), lo, hi);
    } else if (web->law[WS_SPRING_UP]) {
        /* The side that is not the lane's goes to the scratch. */
        const int up = j >= r0 && j < r1, down = j + 1 >= r0 && j + 1 < r1;
        const ws_nodes3 f = web->f, t = chunk_forces(web);
        for (size_t o = 0; o < nx; o += WS_WEB_CHUNK) {
            const size_t q = a + o, m = nx - o < WS_WEB_CHUNK ? nx - o : WS_WEB_CHUNK;
            spring_apply(p, in_at(x, q), in_at(v, q), nx, m, web->inv_l0 + s0 + o,
                         out_at(up ? f : t, up ? q : 0), out_at(down ? f : t, down ? q + nx : 0));
        }
    }
    size_t shear0 = cols * ny + nx * (ny - 1) + 2 * cols * j;
    if (shear0 < web->ns)
        for (size_t s = shear0; s < shear0 + 2 * cols; s++)
            spring_one_in(web, x, v, (uint32_t)s, lo, hi);
}

uint32_t ws_web_rows(const ws_web *web)
{
    if (web->nx > 0)
        return web->ny > 0 ? (uint32_t)web->ny : 0u;
    return web->n >= WS_WEB_MESH_ROW ? web->n / WS_WEB_MESH_ROW : 1u;
}

uint32_t ws_web_row_len(const ws_web *web)
{
    return web->nx > 0 ? (uint32_t)web->nx : WS_WEB_MESH_ROW;
}

uint32_t ws_web_block_rows(const ws_web *web)
{
    const uint32_t len = ws_web_row_len(web), rows = ws_web_rows(web);
    const uint32_t r = (WS_WEB_BLOCK_NODES + len - 1) / len;
    return rows == 0 ? 1u : r < rows ? r : rows;
}

uint32_t ws_web_block_count(const ws_web *web)
{
    const uint32_t r = ws_web_block_rows(web);
    return (ws_web_rows(web) + r - 1) / r;
}

void ws_web_sweep_laws(ws_web *web, v3 g, double t, double since)
{
    for (int q = 0; q < 3; q++)
        web->form[q] = form_of(web->law[q], t, since);
    web->g = g;
    /* Without drag, gravity and drag m g - c v is m g to the bit: c v is a zero (the
     * velocities are finite, or the step fails on them), which leaves any m g but -0 as
     * it is. */
    web->no_drag = web->damping == 0.0 && !signbit(web->damping) && !(g.x == 0.0 && signbit(g.x)) &&
                   !(g.y == 0.0 && signbit(g.y)) && !(g.z == 0.0 && signbit(g.z));
}

int ws_web_laws_on_workers(const ws_web *web)
{
    double kc, dk, w, c;
    for (int q = 0; q < 3; q++)
        if (web->law[q] && !ws_law_film_form(web->law[q], &kc, &dk, &w, &c))
            return 0;
    return 1;
}

int ws_web_sweep_parallel(const ws_web *web)
{
    return ws_web_block_count(web) >= 2 && ws_web_laws_on_workers(web);
}

void ws_web_forces_rows(ws_web *web, const ws_web_pass *p, uint32_t j0, uint32_t j1, int edges,
                        uint32_t *n0, uint32_t *n1)
{
    const ws_nodes3 x = p->x, v = p->v;
    *n0 = ws_web_row_node(web, j0);
    *n1 = ws_web_row_node(web, j1);
    if (web->nx == 0) {
        ws_web_mesh_gather(web, v, *n0, *n1);
        return;
    }
    /* Row j is complete once row j + 1 is started and the springs between the two are in. */
    const size_t ny = (size_t)web->ny;
    if (j0 == 0) {
        grid_row(web, x, v, 0, 0);
    } else if (edges & WS_WEB_LANE_FIRST) {
        grid_row(web, x, v, j0, 1);
        pair_springs(web, x, v, j0 - 1, j0, j1);
    }
    for (size_t j = j0; j < j1; j++) {
        if (j + 1 == j1 && j1 < ny && (edges & WS_WEB_LANE_LAST)) {
            pair_springs(web, x, v, j, j0, j1); /* the next lane starts row j1 */
        } else if (j + 1 < ny) {
            grid_row(web, x, v, j + 1, 0);
            pair_springs(web, x, v, j, 0, ny);
        }
    }
}

/* Symplectic Euler for m nodes, the three components in one loop: v1 = (v0 + h f / m) (0 when
 * pinned), x1 = x0 + h v1, the force f read from where v1 goes (vd: f in, v1 out); 1 / m is
 * inv_m[i], or inv_m1 > 0 for every node when same (none pinned; the array is not read). The
 * arrays are distinct (restrict), so the loop runs on vectors. Returns how many nodes end
 * faster than sqrt(lim2) or with a NaN speed (!(s <= lim2) counts it): a count, so the loop
 * keeps its vectors, and taken from the new velocity while it is at hand. */
typedef struct advance_run {
    in3 x, v;
    out3 xd, vd;
    const double *restrict inv_m;
    double inv_m1, h, lim2;
    size_t m;
} advance_run;

static inline size_t advance_of(advance_run r, int same)
{
    const double h = r.h;
    size_t bad = 0;
    for (size_t i = 0; i < r.m; i++) {
        /* Computed, then selected: no branch. */
        const double imi = same ? r.inv_m1 : r.inv_m[i];
        double unpinned = (double)(imi != 0.0), hi = h * imi;
        double ux = r.v.x[i] + hi * r.vd.x[i], uy = r.v.y[i] + hi * r.vd.y[i],
               uz = r.v.z[i] + hi * r.vd.z[i];
        if (!same) { /* else none is pinned: the product by 1 would change nothing */
            ux *= unpinned;
            uy *= unpinned;
            uz *= unpinned;
        }
        r.vd.x[i] = ux;
        r.vd.y[i] = uy;
        r.vd.z[i] = uz;
        r.xd.x[i] = r.x.x[i] + h * ux;
        r.xd.y[i] = r.x.y[i] + h * uy;
        r.xd.z[i] = r.x.z[i] + h * uz;
        bad += !(ux * ux + uy * uy + uz * uz <= r.lim2);
    }
    return bad;
}

/* The same for the sweep's nodes [n0, n0 + m), the case chosen outside the loop. */
WS_VECTOR_LOOP
static size_t advance(const ws_web *web, const ws_web_pass *p, size_t n0, size_t m, double lim2)
{
    const int same = web->same_inv_m && web->inv_m1 != 0.0;
    const advance_run r = {in_at(p->x, n0), in_at(p->v, n0), out_at(p->xd, n0),
                           out_at(p->vd, n0), web->inv_m + n0, web->inv_m1, p->h, lim2, m};
    return same ? advance_of(r, 1) : advance_of(r, 0);
}

void ws_web_sweep_begin(ws_web *web, const ws_web_pass *p)
{
    web->f = p->vd;
}

void ws_web_sweep_end(ws_web *web)
{
    web->f = web->fmem;
}

size_t ws_web_integrate_block(ws_web *web, const ws_web_pass *p, uint32_t n0, uint32_t n1)
{
    /* A speed whose square overflows counts as too fast even without a limit (max_speed
     * infinite): a node's state never goes infinite unnoticed. */
    return advance(web, p, n0, n1 - n0, fmin(p->vmax * p->vmax, DBL_MAX));
}

double ws_web_fastest(const ws_web *web, ws_nodes3 v)
{
    double most = 0.0;
    for (uint32_t i = 0; i < web->n; i++) {
        double s = hypot(hypot(v.x[i], v.y[i]), v.z[i]); /* no overflow below DBL_MAX */
        most = s <= most ? most : s;                      /* NaN wins */
    }
    return most;
}

ws_web_limits ws_web_node_limits(const ws_web *web, double kc, double cc, double h)
{
    /* Each node's k and c summed in the force scratch: not state, no step is running when this
     * is asked. */
    ws_nodes3 acc = web->f;
    for (uint32_t i = 0; i < web->n; i++)
        acc.x[i] = acc.y[i] = 0.0;
    for (uint32_t s = 0; s < web->ns; s++) {
        const ws_law *L = web->law[web->kind[s]];
        const double q = web->kscale ? web->kscale[s] : 1.0;
        double k = 2.0 * ws_law_max_stiffness(L) * q * web->inv_l0[s];
        double c = 2.0 * ws_law_max_damping(L) * q * web->inv_l0[s];
        acc.x[web->sa[s]] += k;
        acc.x[web->sb[s]] += k;
        acc.y[web->sa[s]] += c;
        acc.y[web->sb[s]] += c;
    }
    ws_web_limits o = {INFINITY, 0.0, INFINITY};
    for (uint32_t i = 0; i < web->n; i++) {
        if (web->inv_m[i] == 0.0)
            continue;
        const double k = acc.x[i] + kc, c = acc.y[i] + cc + web->damping;
        /* Symplectic Euler on m x'' + c x' + k x = 0 is stable for
         * dt < 2/omega (sqrt(1 + z^2) - z), omega^2 = k/m, z = c/(2 m omega). */
        const double om = sqrt(k * web->inv_m[i]);
        if (om > 0.0) {
            double z = c * web->inv_m[i] / (2.0 * om);
            double dt = 2.0 / om * (sqrt(1.0 + z * z) - z);
            o.dt = dt < o.dt ? dt : o.dt;
        }
        /* The same bound in closed form: 2/omega (sqrt(1 + z^2) - z) = (sqrt(c^2 + 4 m k) - c)
         * / k, which is >= h exactly when m >= h^2 k / 4 + h c / 2. A light node is held by its
         * damping (the h c / 2 term), not by its stiffness. */
        const double m = 0.25 * h * h * k + 0.5 * h * c;
        o.mass = m <= o.mass ? o.mass : m; /* NaN wins */
        o.min_mass = fmin(o.min_mass, web->m[i]);
    }
    return o;
}

double ws_web_spring_strain(const ws_web *web, ws_nodes3 x, uint32_t s)
{
    return v3_norm(v3_sub(nodes_get(x, web->sb[s]), nodes_get(x, web->sa[s]))) *
               web->inv_l0[s] -
           1.0;
}

double ws_web_spring_tension(const ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s)
{
    if (web->broken && web->broken[s])
        return 0.0;
    v3 d;
    double epsd, il, eps = strain_of(web, x, v, s, &d, &epsd, &il);
    const double *h = web->nstate ? web->hist + (size_t)s * web->nstate : NULL;
    double F = 0.0;
    if (ws_law_eval(web->law[web->kind[s]], h, &eps, &epsd, 0.0, 0.0, &F, NULL, NULL) != 0)
        return NAN;
    return web->kscale ? F * web->kscale[s] : F;
}

double ws_web_elastic_energy(const ws_web *web, ws_nodes3 x)
{
    double e = 0.0;
    for (uint32_t s = 0; s < web->ns; s++) {
        if (web->broken && web->broken[s])
            continue; /* holds nothing */
        double eps = ws_web_spring_strain(web, x, s);
        const double *h = web->nstate ? web->hist + (size_t)s * web->nstate : NULL;
        double q = web->kscale ? web->kscale[s] : 1.0;
        e += q * ws_law_elastic_energy(web->law[web->kind[s]], h, &eps) / web->inv_l0[s];
    }
    return e;
}
