/* Public calls on laws and webs: validation, id lookup, generators, read-out. */
#include "world/world_internal.h"
#include "contact/node_jacobian.h"
#include "web/multigrid.h"

#include <stdio.h>
#include <string.h>

/* ---- webs ---- */

ws_status ws_lookup_web(const ws_world *w, ws_web_id id, uint32_t *slot)
{
    return ws_lookup_slot(w, id.bits, WS_KIND_WEB, &w->web_slots, "web", slot);
}

int ws_web_is_valid(const ws_world *w, ws_web_id id)
{
    if (!w)
        return 0;
    return ws_slots_is_live(&w->web_slots, id.bits, WS_KIND_WEB);
}

static void web_defaults(ws_web_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->contact_layer = 1e-3;
    def->substeps = 1;
    def->integrator = WS_WEB_EXPLICIT;
    def->solver_tolerance = 1e-3; /* of each row's weight impulse (docs/theory.md 8) */
    def->solver_max_iterations = 1000;
}
WS_DEF_INITS(ws_web_def, web_defaults, name)

static void sheet_defaults(ws_sheet_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->axis_x = v3_make(1, 0, 0);
    def->axis_y = v3_make(0, 1, 0);
}
WS_DEF_INITS(ws_sheet_def, sheet_defaults, pinned_count)

static void band_defaults(ws_band_def *def)
{
    ws_def_reset(def, sizeof *def);
}
WS_DEF_INITS(ws_band_def, band_defaults, shear)

static void web_mesh_defaults(ws_web_mesh_def *def)
{
    ws_def_reset(def, sizeof *def);
}
WS_DEF_INITS(ws_web_mesh_def, web_mesh_defaults, pinned_count)

/* A generator's pre-stretch: rest length spacing / (1 + p), so p > -1, and at most
 * WS_WEB_MAX_PRESTRETCH (web.h says why). */
static int prestretch_ok(double p)
{
    return p > -1.0 && p <= WS_WEB_MAX_PRESTRETCH;
}

/* What every generator shares: the checked web Def and the laws it names. */
typedef struct web_common {
    ws_web_def d;
    uint32_t material;
    ws_law *law[3];
    const char *label;
} web_common;

/* grid: 1 for the sheet and band generators, which can take their masses from an areal
 * density; a mesh web checks its own mass source. */
static ws_status take_common(ws_world *w, const ws_web_def *def, web_common *c, int grid)
{
    ws_web_def_init(&c->d);
    ws_status s = ws_def_take(w, &c->d, sizeof c->d, def, "web");
    if (s != WS_OK)
        return s;
    const ws_web_def *d = &c->d;
    c->label = d->name ? d->name : "(unnamed)";
    /* Which mass source is needed depends on the generator: each checks its own. */
    if (!(isfinite(d->node_mass) && d->node_mass >= 0.0) ||
        !(isfinite(d->areal_density) && d->areal_density >= 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': node_mass and areal_density must be >= 0 (got %g, %g)",
                       c->label, d->node_mass, d->areal_density);
    if (grid && d->node_mass == 0.0 && d->areal_density == 0.0)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': give node_mass > 0 kg or areal_density > 0 kg/m^2", c->label);
    if (!(isfinite(d->contact_layer) && d->contact_layer >= 0.0) ||
        !(isfinite(d->node_damping) && d->node_damping >= 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': contact_layer and node_damping must be >= 0", c->label);
    if (!(isfinite(d->rupture_strain) && d->rupture_strain >= 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': rupture_strain must be finite and >= 0 (0: none), got %g",
                       c->label, d->rupture_strain);
    if (d->substeps < 1 || d->substeps > WS_WEB_MAX_SUBSTEPS)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "web '%s': substeps must be 1..%d, got %d",
                       c->label, WS_WEB_MAX_SUBSTEPS, d->substeps);
    if (d->integrator != WS_WEB_EXPLICIT && d->integrator != WS_WEB_IMPLICIT)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': integrator must be WS_WEB_EXPLICIT (0) or WS_WEB_IMPLICIT (1), "
                       "got %d",
                       c->label, d->integrator);
    if (!(d->solver_tolerance > 0.0 && d->solver_tolerance <= 0.1))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': solver_tolerance must be in (0, 0.1], got %g", c->label,
                       d->solver_tolerance);
    if (d->preconditioner != WS_WEB_PRECONDITIONER_AUTO &&
        d->preconditioner != WS_WEB_PRECONDITIONER_BLOCK_JACOBI &&
        d->preconditioner != WS_WEB_PRECONDITIONER_MULTIGRID)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': preconditioner must be WS_WEB_PRECONDITIONER_AUTO (0), "
                       "_BLOCK_JACOBI (1) or _MULTIGRID (2), got %d",
                       c->label, d->preconditioner);
    if (d->solver_max_iterations < 1 || d->solver_max_iterations > 100000)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': solver_max_iterations must be 1..100000, got %d", c->label,
                       d->solver_max_iterations);
    if (d->hold_bodies != 0 && d->hold_bodies != 1)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': hold_bodies must be 0 (bodies in the implicit solve) or 1 "
                       "(held), got %d",
                       c->label, d->hold_bodies);
    c->material = 0;
    if (d->material.bits && (s = ws_lookup_material(w, d->material, &c->material)) != WS_OK)
        return s;
    uint32_t slot;
    if ((s = ws_lookup_law(w, d->law, &slot)) != WS_OK)
        return ws_fail(w, s, "web '%s': `law` is required: %s", c->label, w->err);
    c->law[0] = w->laws[slot];
    c->law[1] = c->law[0];
    if (d->law_cross.bits) {
        if ((s = ws_lookup_law(w, d->law_cross, &slot)) != WS_OK)
            return s;
        c->law[1] = w->laws[slot];
    }
    c->law[2] = NULL;
    if (d->law_shear.bits) {
        if ((s = ws_lookup_law(w, d->law_shear, &slot)) != WS_OK)
            return s;
        c->law[2] = w->laws[slot];
    }
    static const char *const which[3] = {"law", "law_cross", "law_shear"};
    for (int k = 0; k < 3; k++)
        if (c->law[k] && c->law[k]->dim != 1)
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "web '%s': %s must be a 1D law (a spring has one strain), got a %dD law",
                           c->label, which[k], c->law[k]->dim);
    return WS_OK;
}

/* Count the web once as a user of each distinct law it has. */
static void law_users(ws_web *web, int delta)
{
    for (int k = 0; k < 3; k++) {
        ws_law *L = web->law[k];
        int seen = 0;
        for (int j = 0; j < k; j++)
            seen |= web->law[j] == L;
        if (L && !seen)
            L->users = (uint32_t)((int)L->users + delta);
    }
}

/* Finish a web whose nodes, springs and rest lengths are set: masses, laws, state, the id. */
static ws_status finish_web(ws_world *w, web_common *c, ws_web *web, const uint32_t *pinned,
                            size_t npinned, int grid_masses, ws_web_id *out)
{
    for (int k = 0; k < 3; k++)
        web->law[k] = c->law[k];
    /* Every spring's kind and law are checked before the law histories are set up, which look
     * up each spring's law by its kind. */
    for (uint32_t s = 0; s < web->ns; s++) {
        if (web->kind[s] > WS_SPRING_SHEAR)
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "web '%s': spring %u has an unknown kind",
                           c->label, s);
        if (!web->law[web->kind[s]])
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "web '%s': shear springs need law_shear", c->label);
        if (!(isfinite(web->inv_l0[s]) && web->inv_l0[s] > 0.0))
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "web '%s': spring %u has a rest length that is not > 0", c->label, s);
    }
    if (ws_web_law_state(&w->mem, web) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c->label);
    if (c->d.node_mass > 0.0) {
        for (uint32_t i = 0; i < web->n; i++)
            web->m[i] = c->d.node_mass;
    } else if (grid_masses) {
        ws_web_grid_masses(web, c->d.areal_density);
    }
    for (uint32_t i = 0; i < web->n; i++) {
        if (!(isfinite(web->m[i]) && web->m[i] > 0.0))
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "web '%s': node %u has no mass (areal density needs a grid of at "
                           "least 2 x 2 nodes; give node_mass instead)",
                           c->label, i);
        web->inv_m[i] = 1.0 / web->m[i];
        v3 p = nodes_get(web->x[0], i);
        if (!ws_is_finite3(&p))
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "web '%s': node %u is not finite",
                           c->label, i);
    }
    for (size_t k = 0; k < npinned; k++) {
        if (pinned[k] >= web->n)
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "web '%s': pinned node %u does not exist",
                           c->label, pinned[k]);
        web->inv_m[pinned[k]] = 0.0;
    }
    ws_web_note_masses(web);
    web->layer = c->d.contact_layer;
    web->material = c->material;
    web->damping = c->d.node_damping;
    web->substeps = c->d.substeps;
    web->rupture = c->d.rupture_strain;
    if (web->rupture > 0.0 && ws_web_rupture_alloc(&w->mem, web) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c->label);
    web->integrator = c->d.integrator;
    web->solver_tol = c->d.solver_tolerance;
    web->solver_maxit = c->d.solver_max_iterations;
    web->precond = c->d.preconditioner;
    if (web->precond == WS_WEB_PRECONDITIONER_MULTIGRID && !ws_mg_grid(web))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': preconditioner WS_WEB_PRECONDITIONER_MULTIGRID needs a grid "
                       "web (sheet or band) of at least %d nodes whose springs all join grid "
                       "neighbours, coarsening to at most %d nodes; this one is not (use "
                       "_AUTO or _BLOCK_JACOBI)",
                       c->label, WS_MG_MIN_NODES, WS_MG_COARSEST_MAX);
    web->hold_bodies = c->d.hold_bodies;
    if (!(web->contact = ws_node_contact_new(&w->mem, web->n)))
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c->label);
    web->contact->list = 0;
    web->contact->refresh = 1;
    web->contact->ref = UINT32_MAX; /* none until a search finds one (a world may have no body) */
    /* Both buffers start equal, so the world's committed index (0 or 1) finds the web. */
    memcpy(web->x[1].x, web->x[0].x, 3 * (size_t)web->n * sizeof(double));
    if (c->d.name && !(web->name = ws_mem_strdup(&w->mem, c->d.name)))
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c->label);
    uint32_t slot;
    if (ws_world_take_slot(w, &w->web_slots, (void ***)&w->webs, &w->web_cap, &slot) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c->label);
    ws_web *keep = ws_mem_alloc(&w->mem, sizeof *keep);
    if (!keep) {
        ws_slots_release(&w->web_slots, slot);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c->label);
    }
    *keep = *web;
    w->webs[slot] = keep;
    law_users(keep, +1);
    w->web_check = 1;
    w->cand_valid = 0;
    out->bits = ws_slots_id(&w->web_slots, WS_KIND_WEB, slot);
    return WS_OK;
}

static ws_status fail_web(ws_world *w, ws_web *web, ws_status s)
{
    ws_node_contact_free(&w->mem, web->contact, web->n);
    ws_web_free(&w->mem, web);
    return s;
}

ws_status ws_web_create_sheet(ws_world *w, const ws_web_def *def, const ws_sheet_def *sheet,
                              ws_web_id *out)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_web_create_sheet");
    NEED_OUT(w, out, "ws_web_create_sheet");
    out->bits = 0;
    web_common c;
    ws_status s = take_common(w, def, &c, 1);
    if (s != WS_OK)
        return s;
    ws_sheet_def g;
    ws_sheet_def_init(&g);
    if ((s = ws_def_take(w, &g, sizeof g, sheet, "sheet")) != WS_OK)
        return s;
    double nax = v3_norm(g.axis_x), nay = v3_norm(g.axis_y);
    if (g.nx < 1 || g.ny < 1 || (long)g.nx * g.ny < 2 || (long)g.nx * g.ny > 50000000L ||
        !ws_is_finite3(&g.origin) || !(nax > 0.0 && isfinite(nax)) ||
        !(nay > 0.0 && isfinite(nay)) || !(g.spacing_x > 0.0 && isfinite(g.spacing_x)) ||
        !(g.spacing_y > 0.0 && isfinite(g.spacing_y)) || !prestretch_ok(g.prestretch_x) ||
        !prestretch_ok(g.prestretch_y))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': the sheet needs nx, ny >= 1 with at least 2 nodes, non-zero "
                       "axes, spacings > 0 m and pre-stretches > -1 and <= %g (got %g, %g)",
                       c.label, WS_WEB_MAX_PRESTRETCH, g.prestretch_x, g.prestretch_y);
    ws_web web;
    uint32_t n = (uint32_t)(g.nx * g.ny);
    uint32_t ns = ws_web_sheet_springs(g.nx, g.ny, g.shear && g.nx > 1 && g.ny > 1, 0);
    if (ws_web_alloc(&w->mem, &web, n, ns) != WS_OK)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c.label);
    web.nx = g.nx;
    web.ny = g.ny;
    ws_web_place_sheet(&web, g.origin, v3_scale(g.axis_x, 1.0 / nax),
                       v3_scale(g.axis_y, 1.0 / nay), g.spacing_x, g.spacing_y);
    ws_web_build_grid(&web, g.nx, g.ny, g.shear && g.nx > 1 && g.ny > 1, 0, g.prestretch_x,
                      g.prestretch_y);
    s = finish_web(w, &c, &web, g.pinned, g.pinned ? g.pinned_count : 0, 1, out);
    return s == WS_OK ? s : fail_web(w, &web, s);
}

ws_status ws_web_create_band(ws_world *w, const ws_web_def *def, const ws_band_def *band,
                             ws_web_id *out)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_web_create_band");
    NEED_OUT(w, out, "ws_web_create_band");
    out->bits = 0;
    web_common c;
    ws_status s = take_common(w, def, &c, 1);
    if (s != WS_OK)
        return s;
    ws_band_def g;
    ws_band_def_init(&g);
    if ((s = ws_def_take(w, &g, sizeof g, band, "band")) != WS_OK)
        return s;
    if (!g.bodies || g.body_count == 0 || g.n_around < 3 || g.n_up < 1 ||
        (long)g.n_around * g.n_up > 50000000L || !isfinite(g.z_bottom) || !isfinite(g.z_top) ||
        g.z_top < g.z_bottom || (g.n_up > 1 && g.z_top == g.z_bottom) ||
        !prestretch_ok(g.prestretch_around) || !prestretch_ok(g.prestretch_up) ||
        !(isfinite(g.gap) && g.gap >= 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': the band needs bodies, n_around >= 3, n_up >= 1, z_top > "
                       "z_bottom, pre-stretches > -1 and <= %g (got %g, %g) and gap >= 0",
                       c.label, WS_WEB_MAX_PRESTRETCH, g.prestretch_around, g.prestretch_up);
    /* The footprint: every vertex of the bodies, projected along z. */
    size_t np = 0;
    double layer = 0.0;
    for (size_t k = 0; k < g.body_count; k++) {
        uint32_t slot;
        if ((s = ws_lookup_body(w, g.bodies[k], &slot)) != WS_OK)
            return s;
        np += w->bodies.shape[slot]->vertex_count;
        layer = fmax(layer, w->bodies.layer[slot]);
    }
    double *pts = ws_mem_alloc(&w->mem, 2 * np * sizeof *pts);
    uint32_t *hull = ws_mem_alloc(&w->mem, (2 * np + 2) * sizeof *hull);
    if (!pts || !hull) {
        ws_mem_free(&w->mem, pts, pts ? 2 * np * sizeof *pts : 0);
        ws_mem_free(&w->mem, hull, hull ? (2 * np + 2) * sizeof *hull : 0);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c.label);
    }
    size_t q = 0;
    for (size_t k = 0; k < g.body_count; k++) {
        uint32_t slot;
        ws_lookup_body(w, g.bodies[k], &slot);
        const ws_shape *sh = w->bodies.shape[slot];
        m3 A = qt_to_m3(w->bodies.st[w->cur].p[slot]);
        v3 r = w->bodies.st[w->cur].r[slot];
        for (uint32_t v = 0; v < sh->vertex_count; v++) {
            v3 p = v3_add(r, m3_mul_v(&A, sh->vertices[v]));
            pts[q++] = p.x;
            pts[q++] = p.y;
        }
    }
    ws_web web;
    uint32_t n = (uint32_t)(g.n_around * g.n_up);
    int shear = g.shear && g.n_up > 1;
    uint32_t ns = ws_web_sheet_springs(g.n_around, g.n_up, shear, 1);
    s = WS_OK;
    if (ws_web_alloc(&w->mem, &web, n, ns) != WS_OK) {
        s = ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c.label);
    } else {
        web.nx = g.n_around;
        web.ny = g.n_up;
        if (ws_web_place_band(&web, pts, np, hull, layer + c.d.contact_layer + g.gap, g.z_bottom,
                              g.z_top) != 0)
            s = ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                        "web '%s': the bodies' footprint has no area to wrap", c.label);
    }
    ws_mem_free(&w->mem, pts, 2 * np * sizeof *pts);
    ws_mem_free(&w->mem, hull, (2 * np + 2) * sizeof *hull);
    if (s != WS_OK)
        return web.n ? fail_web(w, &web, s) : s;
    ws_web_build_grid(&web, g.n_around, g.n_up, shear, 1, g.prestretch_around, g.prestretch_up);
    s = finish_web(w, &c, &web, NULL, 0, 1, out);
    return s == WS_OK ? s : fail_web(w, &web, s);
}

ws_status ws_web_create_mesh(ws_world *w, const ws_web_def *def, const ws_web_mesh_def *mesh,
                             ws_web_id *out)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_web_create_mesh");
    NEED_OUT(w, out, "ws_web_create_mesh");
    out->bits = 0;
    web_common c;
    ws_status s = take_common(w, def, &c, 0);
    if (s != WS_OK)
        return s;
    ws_web_mesh_def g;
    ws_web_mesh_def_init(&g);
    if ((s = ws_def_take(w, &g, sizeof g, mesh, "web_mesh")) != WS_OK)
        return s;
    if (!g.positions || g.node_count == 0 || g.node_count > 50000000u ||
        (g.spring_count && !g.springs) || g.spring_count > 200000000u)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': a mesh web needs positions and, for springs, index pairs",
                       c.label);
    if (c.d.node_mass == 0.0 && !g.node_masses)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': a mesh web needs node_mass or node_masses", c.label);
    ws_web web;
    if (ws_web_alloc(&w->mem, &web, (uint32_t)g.node_count, (uint32_t)g.spring_count) != WS_OK)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c.label);
    for (uint32_t i = 0; i < web.n; i++) {
        nodes_set(web.x[0], i, v3_load(g.positions + 3 * i));
        if (g.node_masses)
            web.m[i] = g.node_masses[i];
    }
    for (uint32_t k = 0; k < web.ns; k++) {
        uint32_t a = g.springs[2 * k], b = g.springs[2 * k + 1];
        if (a >= web.n || b >= web.n || a == b) {
            s = ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                        "web '%s': spring %u joins nodes %u and %u: need two different nodes "
                        "below %u",
                        c.label, k, a, b, web.n);
            return fail_web(w, &web, s);
        }
        web.sa[k] = a;
        web.sb[k] = b;
        web.kind[k] = g.kinds ? g.kinds[k] : WS_SPRING_AROUND;
        double l0 = g.rest_lengths ? g.rest_lengths[k]
                                   : v3_norm(v3_sub(nodes_get(web.x[0], b),
                                                    nodes_get(web.x[0], a)));
        web.inv_l0[k] = 1.0 / l0;
    }
    if (g.stiffness_scales && web.ns) {
        if (!(web.kscale = ws_mem_alloc(&w->mem, (size_t)web.ns * sizeof(double)))) {
            s = ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c.label);
            return fail_web(w, &web, s);
        }
        for (uint32_t k = 0; k < web.ns; k++) {
            double q = g.stiffness_scales[k];
            if (!(isfinite(q) && q > 0.0 && q <= 1e6)) {
                s = ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                            "web '%s': spring %u has stiffness scale %g: need a finite value > 0 "
                            "and <= 1e6",
                            c.label, k, q);
                return fail_web(w, &web, s);
            }
            web.kscale[k] = q;
        }
    }
    if (ws_web_mesh_index(&w->mem, &web) != 0) {
        s = ws_fail(w, WS_ERR_OUT_OF_MEMORY, "web '%s': out of memory", c.label);
        return fail_web(w, &web, s);
    }
    if (c.d.node_mass > 0.0 && g.node_masses)
        c.d.node_mass = 0.0; /* the per-node masses win */
    s = finish_web(w, &c, &web, g.pinned, g.pinned ? g.pinned_count : 0, 0, out);
    return s == WS_OK ? s : fail_web(w, &web, s);
}

ws_status ws_web_destroy(ws_world *w, ws_web_id id)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_web_destroy");
    uint32_t slot;
    ws_status s = ws_lookup_web(w, id, &slot);
    if (s != WS_OK)
        return s;
    law_users(w->webs[slot], -1);
    ws_node_contact_free(&w->mem, w->webs[slot]->contact, w->webs[slot]->n);
    ws_web_free(&w->mem, w->webs[slot]);
    ws_mem_free(&w->mem, w->webs[slot], sizeof *w->webs[slot]);
    w->webs[slot] = NULL;
    ws_slots_release(&w->web_slots, slot);
    return WS_OK;
}

void ws_world_free_webs(ws_world *w)
{
    for (size_t i = 0; i < w->web_cap && i < w->web_slots.slot_count; i++) {
        if (w->web_slots.dense[i] != UINT32_MAX && w->webs[i]) {
            ws_node_contact_free(&w->mem, w->webs[i]->contact, w->webs[i]->n);
            ws_web_free(&w->mem, w->webs[i]);
            ws_mem_free(&w->mem, w->webs[i], sizeof *w->webs[i]);
        }
    }
    ws_mem_free(&w->mem, w->webs, w->web_cap * sizeof *w->webs);
    ws_slots_destroy(&w->mem, &w->web_slots);
    ws_mem_free(&w->mem, w->node_par, w->node_par_cap * sizeof *w->node_par);
}

static ws_status get_web(const ws_world *w, ws_web_id id, const ws_web **web)
{
    uint32_t slot;
    ws_status s = ws_lookup_web(w, id, &slot);
    if (s == WS_OK)
        *web = w->webs[slot];
    return s;
}

ws_status ws_web_get_info(const ws_world *w, ws_web_id id, ws_web_info *info)
{
    NEED_WORLD(w);
    NEED_OUT(w, info, "ws_web_get_info");
    const ws_web *web;
    ws_status s = get_web(w, id, &web);
    if (s != WS_OK)
        return s;
    memset(info, 0, sizeof *info);
    info->node_count = web->n;
    info->spring_count = web->ns;
    info->nx = web->nx;
    info->ny = web->ny;
    info->closed = web->closed;
    info->substeps = web->substeps;
    info->min_node_mass = INFINITY;
    for (uint32_t i = 0; i < web->n; i++) {
        info->mass += web->m[i];
        info->min_node_mass = fmin(info->min_node_mass, web->m[i]);
    }
    return WS_OK;
}

int ws_world_node_params(ws_world *w, uint32_t mat)
{
    if (ws_array_reserve(&w->mem, (void **)&w->node_par, &w->node_par_cap, w->pair_dim,
                         sizeof *w->node_par) != 0)
        return -1;
    for (size_t b = 0; b < w->pair_dim; b++) {
        const ws_pair_params *p = &w->params[w->pair_index[mat * w->pair_dim + b]];
        w->node_par[b] = (ws_node_params){p->k, p->c, p->mu, p->vlim};
    }
    return 0;
}

/* The stiffest and most damped contact the web can meet: its material against the materials of
 * the bodies now in the world. */
static void web_contact_bounds(const ws_world *w, const ws_web *web, double *kc, double *cc)
{
    const ws_body_store *b = &w->bodies;
    *kc = *cc = 0.0;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        const ws_pair_params *p =
            &w->params[w->pair_index[web->material * w->pair_dim + b->material[i]]];
        *kc = fmax(*kc, p->k);
        *cc = fmax(*cc, p->c);
    }
}

double ws_world_web_stable_dt(ws_world *w, const ws_web *web)
{
    double kc, cc;
    web_contact_bounds(w, web, &kc, &cc);
    return ws_web_node_limits(web, kc, cc, 0.0).dt;
}

double ws_world_web_mass_for(ws_world *w, const ws_web *web, double h)
{
    double kc, cc;
    web_contact_bounds(w, web, &kc, &cc);
    return ws_web_node_limits(web, kc, cc, h).mass;
}

ws_status ws_web_get_stable_dt(const ws_world *w, ws_web_id id, double *dt)
{
    NEED_WORLD(w);
    NEED_OUT(w, dt, "ws_web_get_stable_dt");
    const ws_web *web;
    ws_status s = get_web(w, id, &web);
    if (s != WS_OK)
        return s;
    *dt = ws_world_web_stable_dt((ws_world *)w, web);
    return WS_OK;
}

ws_status ws_web_get_solver_stats(const ws_world *w, ws_web_id id, ws_web_solver_stats *stats)
{
    NEED_WORLD(w);
    NEED_OUT(w, stats, "ws_web_get_solver_stats");
    const ws_web *web;
    ws_status s = get_web(w, id, &web);
    if (s != WS_OK)
        return s;
    const ws_implicit *im = web->imp;
    *stats = (ws_web_solver_stats){0, 0, 0, 0.0};
    if (im)
        *stats = (ws_web_solver_stats){im->solves, im->iterations, im->last_iterations,
                                       im->last_residual};
    return WS_OK;
}

ws_status ws_web_set_substeps(ws_world *w, ws_web_id id, int substeps)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_web_set_substeps");
    uint32_t slot;
    ws_status s = ws_lookup_web(w, id, &slot);
    if (s != WS_OK)
        return s;
    if (substeps < 1 || substeps > WS_WEB_MAX_SUBSTEPS)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_web_set_substeps: 1..%d, got %d",
                       WS_WEB_MAX_SUBSTEPS, substeps);
    w->webs[slot]->substeps = substeps;
    w->web_check = 1;
    return WS_OK;
}

/* Shared part of the bulk copies: checks, count, and how many to copy. */
static ws_status bulk(const ws_world *w, ws_web_id id, const void *buf, size_t cap, size_t *count,
                      int springs, const char *fn, const ws_web **web, size_t *m)
{
    NEED_WORLD(w);
    NEED_OUT(w, count, fn);
    ws_status s = get_web(w, id, web);
    if (s != WS_OK)
        return s;
    if (cap && !buf)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: buffer is NULL but capacity is not 0",
                       fn);
    size_t n = springs ? (*web)->ns : (*web)->n;
    *count = n;
    *m = cap < n ? cap : n;
    return WS_OK;
}

static ws_status bulk_done(const ws_world *w, const void *buf, size_t cap, size_t n,
                           const char *fn)
{
    if (buf && cap < n)
        return ws_fail(w, WS_ERR_BUFFER_TOO_SMALL, "%s: room for %zu, there are %zu", fn, cap,
                       n);
    return WS_OK;
}

static ws_status copy_v3(const ws_world *w, ws_web_id id, double *xyz, size_t cap, size_t *count,
                         int which, const char *fn)
{
    const ws_web *web = NULL;
    size_t m = 0;
    ws_status s = bulk(w, id, xyz, cap, count, 0, fn, &web, &m);
    if (s != WS_OK)
        return s;
    if (which == 2) {
        if (m)
            memcpy(xyz, web->fc[w->cur], m * sizeof(v3));
    } else {
        /* Interleave the structure-of-arrays state into x, y, z triples. */
        ws_nodes3 src = which == 0 ? web->x[w->cur] : web->v[w->cur];
        for (size_t i = 0; i < m; i++) {
            xyz[3 * i] = src.x[i];
            xyz[3 * i + 1] = src.y[i];
            xyz[3 * i + 2] = src.z[i];
        }
    }
    return bulk_done(w, xyz, cap, *count, fn);
}

ws_status ws_web_copy_positions(const ws_world *w, ws_web_id id, double *xyz, size_t cap,
                                size_t *count)
{
    return copy_v3(w, id, xyz, cap, count, 0, "ws_web_copy_positions");
}

ws_status ws_web_copy_velocities(const ws_world *w, ws_web_id id, double *xyz, size_t cap,
                                 size_t *count)
{
    return copy_v3(w, id, xyz, cap, count, 1, "ws_web_copy_velocities");
}

ws_status ws_web_copy_contact_forces(const ws_world *w, ws_web_id id, double *xyz, size_t cap,
                                     size_t *count)
{
    return copy_v3(w, id, xyz, cap, count, 2, "ws_web_copy_contact_forces");
}

ws_status ws_web_copy_springs(const ws_world *w, ws_web_id id, uint32_t *pairs, size_t cap,
                              size_t *count)
{
    const ws_web *web;
    size_t m;
    ws_status s = bulk(w, id, pairs, cap, count, 1, "ws_web_copy_springs", &web, &m);
    if (s != WS_OK)
        return s;
    for (size_t k = 0; k < m; k++) {
        pairs[2 * k] = web->sa[k];
        pairs[2 * k + 1] = web->sb[k];
    }
    return bulk_done(w, pairs, cap, *count, "ws_web_copy_springs");
}

ws_status ws_web_copy_spring_strains(const ws_world *w, ws_web_id id, double *out, size_t cap,
                                     size_t *count)
{
    const ws_web *web;
    size_t m;
    ws_status s = bulk(w, id, out, cap, count, 1, "ws_web_copy_spring_strains", &web, &m);
    if (s != WS_OK)
        return s;
    for (size_t k = 0; k < m; k++)
        out[k] = ws_web_spring_strain(web, web->x[w->cur], (uint32_t)k);
    return bulk_done(w, out, cap, *count, "ws_web_copy_spring_strains");
}

ws_status ws_web_copy_spring_tensions(const ws_world *w, ws_web_id id, double *out, size_t cap,
                                      size_t *count)
{
    const ws_web *web;
    size_t m;
    ws_status s = bulk(w, id, out, cap, count, 1, "ws_web_copy_spring_tensions", &web, &m);
    if (s != WS_OK)
        return s;
    for (size_t k = 0; k < m; k++)
        out[k] = ws_web_spring_tension(web, web->x[w->cur], web->v[w->cur], (uint32_t)k);
    return bulk_done(w, out, cap, *count, "ws_web_copy_spring_tensions");
}

ws_status ws_web_get_body_force(const ws_world *w, ws_web_id id, ws_body_id body, ws_vec3 *force,
                                ws_vec3 *moment)
{
    NEED_WORLD(w);
    NEED_OUT(w, force, "ws_web_get_body_force");
    const ws_web *web;
    uint32_t b;
    ws_status s = get_web(w, id, &web);
    if (s != WS_OK || (s = ws_lookup_body(w, body, &b)) != WS_OK)
        return s;
    int c = w->cur;
    *force = b < web->bcap && web->bforce[c] ? web->bforce[c][b] : v3_make(0, 0, 0);
    if (moment)
        *moment = b < web->bcap && web->bmoment[c] ? web->bmoment[c][b] : v3_make(0, 0, 0);
    return WS_OK;
}

ws_status ws_web_get_containment(const ws_world *w, ws_web_id id, ws_containment_band *bands,
                                 size_t count)
{
    NEED_WORLD(w);
    NEED_OUT(w, bands, "ws_web_get_containment");
    const ws_web *web;
    ws_status s = get_web(w, id, &web);
    if (s != WS_OK)
        return s;
    if (web->nx == 0 || count < 1 || count > (size_t)web->ny)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_web_get_containment: needs a grid web and 1..%d bands, got %zu",
                       web->ny, count);
    const ws_nodes3 x = web->x[w->cur], v = web->v[w->cur];
    const v3 *fc = web->fc[w->cur];
    int cols = web->closed ? web->nx : web->nx - 1;
    /* Row pitch from the mean heights of the first and last rows (not one column, which may
     * sag or lean). */
    double zfirst = 0.0, zlast = 0.0;
    for (int i = 0; i < web->nx; i++) {
        zfirst += x.z[i];
        zlast += x.z[(size_t)i + (size_t)web->nx * (size_t)(web->ny - 1)];
    }
    double pitch = web->ny > 1 ? (zlast - zfirst) / web->nx / (web->ny - 1) : 0.0;
    for (size_t k = 0; k < count; k++) {
        int j0 = (int)(k * (size_t)web->ny / count), j1 = (int)((k + 1) * (size_t)web->ny / count);
        double zlo = INFINITY, zhi = -INFINITY, tsum = 0.0, nsum = 0.0;
        for (int j = j0; j < j1; j++) {
            double z = 0.0;
            for (int i = 0; i < web->nx; i++) {
                uint32_t a = (uint32_t)(i + web->nx * j);
                z += x.z[a];
                nsum += v3_norm(fc[a]); /* normal + friction; friction is small across a band */
            }
            z /= web->nx;
            zlo = fmin(zlo, z);
            zhi = fmax(zhi, z);
            /* Around-springs of row j are numbered j cols .. j cols + cols - 1. */
            for (int i = 0; i < cols; i++)
                tsum += ws_web_spring_tension(web, x, v, (uint32_t)(j * cols + i));
        }
        int rows = j1 - j0;
        ws_containment_band *o = &bands[k];
        o->z_low = zlo;
        o->z_high = zhi;
        o->hoop_tension = rows ? tsum / (rows * cols) : 0.0;
        o->line_load = pitch != 0.0 ? o->hoop_tension / fabs(pitch) : 0.0;
        o->contact_force = nsum;
    }
    return WS_OK;
}

ws_status ws_web_get_energy(const ws_world *w, ws_web_id id, double *kinetic, double *elastic,
                            double *gravity)
{
    NEED_WORLD(w);
    const ws_web *web;
    ws_status s = get_web(w, id, &web);
    if (s != WS_OK)
        return s;
    const ws_nodes3 x = web->x[w->cur], v = web->v[w->cur];
    double ke = 0.0, pe = 0.0;
    for (uint32_t i = 0; i < web->n; i++) {
        ke += 0.5 * web->m[i] * v3_norm2(nodes_get(v, i));
        pe -= web->m[i] * v3_dot(w->def.gravity, nodes_get(x, i));
    }
    if (kinetic)
        *kinetic = ke;
    if (gravity)
        *gravity = pe;
    if (elastic)
        *elastic = ws_web_elastic_energy(web, x);
    return WS_OK;
}

/* ---- rupture ---- */

ws_status ws_web_set_rupture_strain(ws_world *w, ws_web_id id, double strain)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_web_set_rupture_strain");
    uint32_t slot;
    ws_status s = ws_lookup_web(w, id, &slot);
    if (s != WS_OK)
        return s;
    ws_web *web = w->webs[slot];
    if (!(isfinite(strain) && strain >= 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_web_set_rupture_strain: web '%s': the strain must be finite and >= 0 "
                       "(0: none), got %g",
                       web->name ? web->name : "(unnamed)", strain);
    if (strain > 0.0 && ws_web_rupture_alloc(&w->mem, web) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_web_set_rupture_strain: out of memory");
    web->rupture = strain;
    return WS_OK;
}

ws_status ws_web_get_rupture(const ws_world *w, ws_web_id id, ws_web_rupture *out)
{
    NEED_WORLD(w);
    NEED_OUT(w, out, "ws_web_get_rupture");
    const ws_web *web;
    ws_status s = get_web(w, id, &web);
    if (s != WS_OK)
        return s;
    memset(out, 0, sizeof *out);
    out->rupture_strain = web->rupture;
    out->broken_count = web->nbroken;
    out->broken_last_step = web->nbroken_step;
    out->ruptured = web->first_spring != UINT32_MAX;
    out->first_spring = web->first_spring;
    if (out->ruptured) {
        out->first_time = web->first_time;
        out->first_strain = web->first_strain;
        out->first_position = web->first_at;
    }
    return WS_OK;
}

ws_status ws_web_copy_broken_springs(const ws_world *w, ws_web_id id, uint32_t *springs,
                                     size_t cap, size_t *count)
{
    NEED_WORLD(w);
    NEED_OUT(w, count, "ws_web_copy_broken_springs");
    const ws_web *web;
    ws_status s = get_web(w, id, &web);
    if (s != WS_OK)
        return s;
    if (cap && !springs)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_web_copy_broken_springs: buffer is NULL but capacity is not 0");
    size_t n = 0;
    for (uint32_t k = 0; web->broken && k < web->ns; k++) {
        if (!web->broken[k])
            continue;
        if (n < cap)
            springs[n] = k;
        n++;
    }
    *count = n;
    return bulk_done(w, springs, cap, n, "ws_web_copy_broken_springs");
}

ws_status ws_web_get_peak_strain(const ws_world *w, ws_web_id id, ws_web_peak *out)
{
    NEED_WORLD(w);
    NEED_OUT(w, out, "ws_web_get_peak_strain");
    const ws_web *web;
    ws_status s = get_web(w, id, &web);
    if (s != WS_OK)
        return s;
    memset(out, 0, sizeof *out);
    const ws_nodes3 x = web->x[w->cur];
    for (uint32_t k = 0; k < web->ns; k++) {
        if (web->broken && web->broken[k])
            continue;
        double eps = ws_web_spring_strain(web, x, k);
        if (!out->found || eps > out->strain) {
            out->found = 1;
            out->spring = k;
            out->strain = eps;
        }
    }
    if (!out->found)
        return WS_OK;
    const uint32_t k = out->spring, a = web->sa[k], b = web->sb[k];
    out->tension = ws_web_spring_tension(web, x, web->v[w->cur], k);
    out->node_a = a;
    out->node_b = b;
    out->position_a = nodes_get(x, a);
    out->position_b = nodes_get(x, b);
    return WS_OK;
}
