/* The implicit film integrator (web/implicit.c, contact/node_jacobian.c, world_implicit.c): its
 * derivatives against finite differences, backward Euler's known amplification and phase on a
 * string's mode, the explicit web's analytic answers (row tension, band pressure; the capstan
 * is in test_web.c, capstan_implicit), convergence to the explicit film as dt shrinks, stiffness
 * scales and rupture, and a failed solve leaving the world as it was. */
#include "helpers.h"

#include "contact/node_jacobian.h"
#include "web/coupled.h"
#include "web/implicit.h"
#include "web/multigrid.h"
#include "world/world_internal.h"

#define PI 3.14159265358979323846

static const ws_vec3 NO_G = {0, 0, 0};

static ws_world *world_gw(double dt, ws_vec3 g, int workers)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = dt;
    d.gravity = g;
    d.worker_count = workers;
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    return w;
}

static ws_world *world_g(double dt, ws_vec3 g) { return world_gw(dt, g, 1); }

static ws_law_id make_law(ws_world *w, ws_law_type type, double k, double kc, double c,
                          double tr)
{
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = type;
    d.stiffness = k;
    d.compression_stiffness = kc;
    d.damping = c;
    if (tr > 0.0)
        d.transition = tr;
    ws_law_id id;
    ck_ok(w, ws_law_create(w, &d, &id));
    return id;
}

/* The internal web of an id. */
static ws_web *web_of(ws_world *w, ws_web_id id)
{
    uint32_t slot;
    ck_assert_int_eq(ws_lookup_web(w, id, &slot), WS_OK);
    return w->webs[slot];
}

/* A mesh web of n nodes at pos (xyz), springs pairs, rest lengths rest. */
static ws_web_id mesh_web(ws_world *w, const ws_web_def *wd, size_t n, const double *pos,
                          const uint32_t *pairs, size_t ns, const double *rest,
                          const uint32_t *pins, size_t npins)
{
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = pos;
    md.node_count = n;
    md.springs = pairs;
    md.spring_count = ns;
    md.rest_lengths = rest;
    md.pinned = pins;
    md.pinned_count = npins;
    ws_web_id id;
    ck_ok(w, ws_web_create_mesh(w, wd, &md, &id));
    return id;
}

/* Node vectors of n nodes (one block of 3 n doubles). */
static ws_nodes3 nodes_new(size_t n)
{
    double *p = calloc(3 * n, sizeof *p);
    ck_assert(p);
    return (ws_nodes3){p, p + n, p + 2 * n};
}

static double *comp(ws_nodes3 a, int k)
{
    return k == 0 ? a.x : k == 1 ? a.y : a.z;
}

static double max_abs(const double *a, int n)
{
    double m = 0.0;
    for (int k = 0; k < n; k++)
        m = fmax(m, fabs(a[k]));
    return m;
}

/* ---- 1. derivatives against finite differences ---- */

/* The force on node a of the web's only spring at (x, v) (gravity and drag are zero). */
static v3 spring_force_a(ws_web *web, ws_nodes3 x, ws_nodes3 v)
{
    ck_assert_int_eq(ws_implicit_begin(web, x, v, v3_make(0, 0, 0), 0.0, 0.0), 0);
    const uint32_t a = web->sa[0];
    return v3_make(web->imp->f[3 * a], web->imp->f[3 * a + 1], web->imp->f[3 * a + 2]);
}

/* Central differences of f_a with respect to end b's position (which = 0) or velocity (1),
 * steps hx (m) and hv (m/s): J[3 i + k] = d f_a,i / d (x or v)_b,k. */
static void spring_fd(ws_web *web, ws_nodes3 x, ws_nodes3 v, int which, double step, double *J)
{
    const uint32_t b = web->sb[0];
    ws_nodes3 s = which ? v : x;
    for (int k = 0; k < 3; k++) {
        double *c = comp(s, k), keep = c[b];
        c[b] = keep + step;
        v3 fp = which ? spring_force_a(web, x, s) : spring_force_a(web, s, v);
        c[b] = keep - step;
        v3 fm = which ? spring_force_a(web, x, s) : spring_force_a(web, s, v);
        c[b] = keep;
        J[k] = (fp.x - fm.x) / (2 * step);
        J[3 + k] = (fp.y - fm.y) / (2 * step);
        J[6 + k] = (fp.z - fm.z) / (2 * step);
    }
}

/* One spring of the law at a strain eps and a rate of stretching plus a sideways velocity: the
 * exact derivatives equal central differences to 1e-6 of their size; at rest in tension, the
 * matrix's block (ka e e^T + kb I, cs e e^T) equals them too. */
static void spring_case(ws_law_type type, double kc, double tr, double eps, int at_rest,
                        const char *what)
{
    ws_world *w = world_g(1e-3, NO_G);
    const double EA = 50.0, c = 0.4, l0 = 0.02;
    ws_law_id law = make_law(w, type, EA, kc, c, tr);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-3;
    wd.law = law;
    wd.integrator = WS_WEB_IMPLICIT;
    /* The spring leans out of every axis so that each block entry is tested. */
    const v3 e = v3_scale(v3_make(0.6, -0.48, 0.64), 1.0 / v3_norm(v3_make(0.6, -0.48, 0.64)));
    const double l = l0 * (1 + eps);
    const double pos[6] = {0.01, 0.02, 0.03, 0.01 + l * e.x, 0.02 + l * e.y, 0.03 + l * e.z};
    const uint32_t pair[2] = {0, 1};
    ws_web_id id = mesh_web(w, &wd, 2, pos, pair, 1, &l0, NULL, 0);
    ws_web *web = web_of(w, id);
    ck_assert_int_eq(ws_implicit_reserve(&w->mem, web), 0);
    ws_nodes3 x = nodes_new(2), v = nodes_new(2);
    for (int i = 0; i < 2; i++) {
        x.x[i] = pos[3 * i];
        x.y[i] = pos[3 * i + 1];
        x.z[i] = pos[3 * i + 2];
    }
    if (!at_rest) { /* stretching at 0.05 /s and a sideways velocity */
        v.x[1] = 0.05 * l0 * e.x + 0.03;
        v.y[1] = 0.05 * l0 * e.y + 0.01;
        v.z[1] = 0.05 * l0 * e.z - 0.02;
        v.x[0] = -0.01;
    }
    double Jx[9], Jv[9], Fx[9], Fv[9];
    ck_assert_int_eq(ws_implicit_spring_exact(web, x, v, 0, 0.0, 0.0, Jx, Jv), 0);
    spring_fd(web, x, v, 0, 1e-8, Fx);
    spring_fd(web, x, v, 1, 1e-7, Fv);
    double ex = 0, ev = 0;
    for (int k = 0; k < 9; k++) {
        ex = fmax(ex, fabs(Jx[k] - Fx[k]));
        ev = fmax(ev, fabs(Jv[k] - Fv[k]));
    }
    const double sx = max_abs(Fx, 9), sv = max_abs(Fv, 9);
    report("%s: exact vs finite differences: dx %.2g, dv %.2g of %.3g N/m, %.3g N s/m", what,
           ex / sx, ev / sv, sx, sv);
    ck_assert_msg(ex <= 1e-6 * sx, "%s: df/dx off by %g of %g", what, ex, sx);
    ck_assert_msg(ev <= 1e-6 * sv, "%s: df/dv off by %g of %g", what, ev, sv);
    if (at_rest && eps > tr) {
        (void)spring_force_a(web, x, v); /* the blocks of this state */
        const ws_ispring *q = &web->imp->sp[0];
        const double ev3[3] = {q->ex, q->ey, q->ez};
        double mx = 0, mv = 0;
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++) {
                const double K = q->ka * ev3[i] * ev3[k] + q->kb * (i == k),
                             D = q->cs * ev3[i] * ev3[k];
                mx = fmax(mx, fabs(K - Fx[3 * i + k]));
                mv = fmax(mv, fabs(D - Fv[3 * i + k]));
            }
        report("%s: the matrix's blocks vs finite differences: %.2g, %.2g", what, mx / sx,
               mv / sv);
        ck_assert_msg(mx <= 1e-6 * sx, "%s: matrix stiffness off by %g", what, mx);
        ck_assert_msg(mv <= 1e-6 * sv, "%s: matrix damping off by %g", what, mv);
    }
    free(x.x);
    free(v.x);
    ws_world_destroy(w);
}

/* The nodes on the edge of an nx x ny sheet (row by row) into pins (room for 2 (nx + ny)): a
 * drum's pinned rim. Returns their count. */
static size_t edge_pins(int nx, int ny, uint32_t *pins)
{
    size_t np = 0;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++)
            if (i == 0 || j == 0 || i == nx - 1 || j == ny - 1)
                pins[np++] = (uint32_t)(i + nx * j);
    return np;
}

START_TEST(test_spring_jacobian)
{
    /* Tolerance 1e-6 relative: central differences at a step of 1e-8 m on a 2 cm spring err
     * by (h / l)^2 ~ 1e-12 from the truncation and 1e-16 N / 1e-8 m ~ 1e-8 N/m from round-off,
     * against blocks of 100 N/m and more; the film law's ramp is C1, so its derivative is
     * continuous through the join (its second derivative jumps at +-w, where no case sits). */
    spring_case(WS_LAW_LINEAR_VISCOELASTIC, 0.0, 0.0, 0.3, 0, "Kelvin-Voigt, stretched, moving");
    spring_case(WS_LAW_LINEAR_VISCOELASTIC, 0.0, 0.0, 0.3, 1, "Kelvin-Voigt, stretched, at rest");
    spring_case(WS_LAW_TENSION_COMPRESSION, 0.5, 0.01, 0.2, 0, "film law, tension, moving");
    spring_case(WS_LAW_TENSION_COMPRESSION, 0.5, 0.01, 0.2, 1, "film law, tension, at rest");
    spring_case(WS_LAW_TENSION_COMPRESSION, 0.5, 0.01, 0.004, 0, "film law, in the join");
    spring_case(WS_LAW_TENSION_COMPRESSION, 0.5, 0.01, -0.05, 0, "film law, compressed");
}
END_TEST

/* The contact force on node i: the sum over its active links at (x, v). */
static v3 contact_force(ws_world *w, ws_web *web, const ws_ncand_list *cl, ws_nodes3 x,
                        ws_nodes3 v, ws_node_link *L, uint32_t i, int *count)
{
    const ws_node_pass P = {&w->bodies, w->cur, &w->node_geom, w->node_par, cl->c,
                            x,          v,      0.0,           1.0,         NULL,
                            0};
    size_t n = ws_node_links(&P, web, cl->n, NULL, 0.0, L, NULL);
    v3 f = v3_make(0, 0, 0);
    *count = 0;
    for (size_t k = 0; k < n; k++)
        if (L[k].node == i && L[k].active) {
            f = v3_add(f, L[k].f);
            ++*count;
        }
    return f;
}

static void contact_fd(ws_world *w, ws_web *web, const ws_ncand_list *cl, ws_nodes3 x,
                       ws_nodes3 v, ws_node_link *L, uint32_t i, int which, double step,
                       double *J)
{
    ws_nodes3 s = which ? v : x;
    int cnt;
    for (int k = 0; k < 3; k++) {
        double *c = comp(s, k), keep = c[i];
        c[i] = keep + step;
        v3 fp = which ? contact_force(w, web, cl, x, s, L, i, &cnt)
                      : contact_force(w, web, cl, s, v, L, i, &cnt);
        ck_assert_int_eq(cnt, 1);
        c[i] = keep - step;
        v3 fm = which ? contact_force(w, web, cl, x, s, L, i, &cnt)
                      : contact_force(w, web, cl, s, v, L, i, &cnt);
        ck_assert_int_eq(cnt, 1);
        c[i] = keep;
        J[k] = (fp.x - fm.x) / (2 * step);
        J[3 + k] = (fp.y - fm.y) / (2 * step);
        J[6 + k] = (fp.z - fm.z) / (2 * step);
    }
}

/* The contact Jacobians' world: a 0.2 m box (k 4000 N/m, c 1 N s/m, mu 0.5, v_lim 10 mm/s,
 * layers of 1 mm each) of the body def bd (its shape and material filled in here), and wd an
 * implicit web's def of 1 g nodes, a stiff linear law and the film's material. */
static ws_world *box_and_film(ws_body_def *bd, ws_web_def *wd)
{
    ws_world *w = world_g(1e-5, NO_G);
    ws_shape_id box;
    ck_ok(w, ws_shape_create_box(w, 0.2, 0.2, 0.2, &box));
    ws_material_def md;
    ws_material_def_init(&md);
    ws_material_id film_mat, box_mat;
    ck_ok(w, ws_material_create(w, &md, &film_mat));
    ck_ok(w, ws_material_create(w, &md, &box_mat));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 4000.0;
    cd.damping = 1.0;
    cd.friction = 0.5;
    cd.friction_vlim = 0.01;
    ck_ok(w, ws_world_set_contact(w, film_mat, box_mat, &cd));
    bd->shape = box;
    bd->material = box_mat;
    ws_body_id body;
    ck_ok(w, ws_body_create(w, bd, &body));
    ws_web_def_init(wd);
    wd->node_mass = 1e-3;
    wd->law = make_law(w, WS_LAW_LINEAR_ELASTIC, 1e-3, 0.0, 0.0, 0.0);
    wd->material = film_mat;
    wd->integrator = WS_WEB_IMPLICIT;
    return w;
}

/* The scene of the contact Jacobians: a 0.2 m box of 1 kg moving at (10, 20, 0) mm/s without
 * spin, and a web of two nodes (one spring, implicit): node 0 over its top face 1.5 mm up (the
 * window is 2 mm: two 1 mm layers), node 1 at the rim of its top edge along y, 1.41 mm from
 * it; stepped once, so the candidates are found and the faces prepared. x: the nodes' places. */
static ws_world *box_two_nodes(ws_web **web, ws_nodes3 *x)
{
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.mass = 1.0;
    bd.velocity = v3_make(0.01, 0.02, 0.0);
    ws_web_def wd;
    ws_world *w = box_and_film(&bd, &wd);
    const double r = 1e-3 / sqrt(2.0);
    const double pos[6] = {0.03, -0.02, 0.1 + 1.5e-3, 0.1 + r, 0.05, 0.1 + r};
    const uint32_t pair[2] = {0, 1};
    const double rest = 0.2;
    ws_web_id id = mesh_web(w, &wd, 2, pos, pair, 1, &rest, NULL, 0);
    *web = web_of(w, id);
    ck_ok(w, ws_world_step(w)); /* candidates found, faces prepared */
    *x = nodes_new(2);
    for (int i = 0; i < 2; i++) {
        x->x[i] = pos[3 * i];
        x->y[i] = pos[3 * i + 1];
        x->z[i] = pos[3 * i + 2];
    }
    return w;
}

START_TEST(test_contact_jacobian)
{
    /* A 0.2 m box moving at (10, 20, 0) mm/s without spin, two nodes: node 0 over its top face
     * 1.5 mm up (the window is 2 mm: two 1 mm layers), node 1 at the rim of its top edge along
     * y, 1.41 mm from it. Each slips on the box: node 0 at 5 mm/s (half of v_lim: the
     * polynomial part of eq. 13), node 1 at 20 mm/s (beyond v_lim: mu N), and each approaches
     * it at 1 mm/s. The exact derivatives of their contact forces (normal force, damping,
     * friction; for the rim its turning normal) equal central differences to 1e-6 of their
     * size (steps 1e-8 m and 1e-8 m/s: truncation (1e-8 / 1e-3)^2, round-off 1e-16 N / 1e-8
     * ~ 1e-8 against 1e3 N/m; see below for the rate at rest). At rest on the box (no slip, no approach), the matrix's blocks
     * of the face contact (k n n^T, c n n^T + mu N phi across n) equal them too. */
    ws_web *web;
    ws_nodes3 x, v = nodes_new(2);
    ws_world *w = box_two_nodes(&web, &x);
    const ws_ncand_list *cl = &web->contact->cand[web->contact->list];
    ck_assert_uint_ge(cl->n, 2);
    ws_node_link *L = calloc(cl->n, sizeof *L), *L2 = calloc(cl->n, sizeof *L2);
    ws_node_exact *E = calloc(cl->n, sizeof *E);
    const ws_body_state *st = &w->bodies.st[w->cur];
    const v3 vbody = st->v[0];
    for (int rest_case = 0; rest_case < 2; rest_case++) {
        const v3 slip0 = rest_case ? v3_make(0, 0, 0) : v3_make(0.003, 0.004, -0.001),
                 slip1 = rest_case ? v3_make(0, 0, 0) : v3_make(-7e-4, 0.02, -7e-4);
        v.x[0] = vbody.x + slip0.x, v.y[0] = vbody.y + slip0.y, v.z[0] = vbody.z + slip0.z;
        v.x[1] = vbody.x + slip1.x, v.y[1] = vbody.y + slip1.y, v.z[1] = vbody.z + slip1.z;
        for (uint32_t i = 0; i < 2; i++) {
            if (rest_case && i == 1)
                continue; /* the rim's matrix block leaves out its turning (docs) */
            int cnt;
            (void)contact_force(w, web, cl, x, v, L, i, &cnt);
            ck_assert_int_eq(cnt, 1);
            ws_node_link link;
            ws_node_exact exact;
            const ws_node_pass P = {&w->bodies, w->cur, &w->node_geom, w->node_par, cl->c,
                                    x,          v,      0.0,           1.0,         NULL,
                            0};
            size_t n = ws_node_links(&P, web, cl->n, NULL, 0.0, L, E);
            for (size_t k = 0; k < n; k++)
                if (L[k].node == i && L[k].active) {
                    link = L[k];
                    exact = E[k];
                }
            /* The step asks for no exact derivatives: its contacts must be the same to the
             * bit as those computed with them. */
            ck_assert_uint_eq(ws_node_links(&P, web, cl->n, NULL, 0.0, L2, NULL), n);
            ck_assert_int_eq(memcmp(L, L2, n * sizeof *L), 0);
            double Fx[9], Fv[9];
            contact_fd(w, web, cl, x, v, L, i, 0, 1e-8, Fx);
            /* At rest eq. 13 bends as |t| t / v_lim^2 about zero slip: central differences
             * err by step / (2 v_lim) there, so the step is 1e-10 m/s (5e-9). */
            contact_fd(w, web, cl, x, v, L, i, 1, rest_case ? 1e-10 : 1e-8, Fv);
            const double sx = max_abs(Fx, 9), sv = max_abs(Fv, 9);
            double ex = 0, ev = 0, mx = 0, mv = 0;
            const int sym[9] = {WS_SYM_XX, WS_SYM_XY, WS_SYM_XZ, WS_SYM_XY, WS_SYM_YY,
                                WS_SYM_YZ, WS_SYM_XZ, WS_SYM_YZ, WS_SYM_ZZ};
            for (int k = 0; k < 9; k++) {
                ex = fmax(ex, fabs(exact.Jx[k] - Fx[k]));
                ev = fmax(ev, fabs(exact.Jv[k] - Fv[k]));
                mx = fmax(mx, fabs(-link.K[sym[k]] - Fx[k]));
                mv = fmax(mv, fabs(-link.D[sym[k]] - Fv[k]));
            }
            report("contact, node %u (%s)%s: exact vs finite differences %.2g, %.2g of %.3g "
                   "N/m, %.3g N s/m; matrix %.2g, %.2g",
                   i, i ? "rim" : "face", rest_case ? " at rest" : ", slipping", ex / sx,
                   ev / sv, sx, sv, mx / sx, mv / sv);
            ck_assert_msg(ex <= 1e-6 * sx, "node %u: df/dx off by %g of %g", i, ex, sx);
            ck_assert_msg(ev <= 1e-6 * sv, "node %u: df/dv off by %g of %g", i, ev, sv);
            if (rest_case) {
                ck_assert_msg(mx <= 1e-6 * sx, "node %u: matrix K off by %g", i, mx);
                ck_assert_msg(mv <= 1e-6 * sv, "node %u: matrix D off by %g", i, mv);
            }
        }
    }
    free(L);
    free(L2);
    free(E);
    free(x.x);
    free(v.x);
    ws_world_destroy(w);
}
END_TEST

/* ---- a node past a convex body's edge: the faces' pushes blend (node_force.c) */

/* A 0.2 m box (k 4000 N/m, c 1 N s/m, mu 0.5, v_lim 10 mm/s; 1 mm layers each: a 2 mm window)
 * of 1e6 kg (the nodes' pushes barely move it) turned by 0.3 rad about z, and a web of n nodes
 * (a chain, implicit) at the body-frame places p, stepped once so that the candidates are
 * found; then x: the places again, from the body's frame as it stands after the step. */
static ws_world *yawed_box_nodes(size_t n, const double *p, ws_web **web, ws_nodes3 *x)
{
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.mass = 1e6;
    bd.orientation = (ws_quat){cos(0.15), 0.0, 0.0, sin(0.15)};
    ws_web_def wd;
    ws_world *w = box_and_film(&bd, &wd);
    double *pos = calloc(3 * n, sizeof *pos), *rest = calloc(n, sizeof *rest);
    uint32_t *pair = calloc(2 * n, sizeof *pair);
    ck_assert(pos && rest && pair);
    const m3 A0 = qt_to_m3(bd.orientation);
    for (size_t i = 0; i < n; i++) {
        const v3 g = m3_mul_v(&A0, v3_make(p[3 * i], p[3 * i + 1], p[3 * i + 2]));
        pos[3 * i] = g.x, pos[3 * i + 1] = g.y, pos[3 * i + 2] = g.z;
    }
    for (size_t i = 0; i + 1 < n; i++) {
        pair[2 * i] = (uint32_t)i, pair[2 * i + 1] = (uint32_t)(i + 1);
        rest[i] = 0.2;
    }
    ws_web_id id = mesh_web(w, &wd, n, pos, pair, n - 1, rest, NULL, 0);
    *web = web_of(w, id);
    ck_ok(w, ws_world_step(w)); /* candidates found, faces prepared */
    const ws_body_state *st = &w->bodies.st[w->cur];
    *x = nodes_new(n);
    for (size_t i = 0; i < n; i++) {
        const v3 g = v3_add(st->r[0], m3_mul_v(&w->bodies.A[0],
                                               v3_make(p[3 * i], p[3 * i + 1], p[3 * i + 2])));
        x->x[i] = g.x, x->y[i] = g.y, x->z[i] = g.z;
    }
    free(pos);
    free(rest);
    free(pair);
    return w;
}

/* The body's velocity at every node (no slip, no approach: the pushes alone). */
static ws_nodes3 nodes_at_body(ws_world *w, size_t n)
{
    ws_nodes3 v = nodes_new(n);
    const v3 vb = w->bodies.st[w->cur].v[0];
    for (size_t i = 0; i < n; i++)
        v.x[i] = vb.x, v.y[i] = vb.y, v.z[i] = vb.z;
    return v;
}

START_TEST(test_push_past_edge_continuous)
{
    /* A node pressed past the box's vertical edge (+x, +y) at depth delta below both side
     * faces, on the bisector and 1e-12 m to either side of it. The push must be continuous:
     * its gradient is at most k (hi + delta) / W |n_A - n_B| / 2 ~ 2.5e4 N/m (W: the blend's
     * width, 1 mm, or delta where that is less; hi 2 mm), so 1e-12 m moves it by 2.5e-8 N at
     * most; bound 1e-7 N, against the push k (hi + delta) ~ 10 N, the node's overlap below the
     * surface, along the bisector on it (to 1e-10 of it: round-off of the rotated planes, 1e-17
     * m of depth, turns it by 1e-14), so with no moment about the vertical through the CoG.
     * The shallowest face alone (the law before) turns it by 45 degrees across the bisector.
     * Two depths: 1.5 mm (the width is 1 mm) and 0.4 mm (pinched to the depth). */
    const double depths[2] = {1.5e-3, 0.4e-3}, k = 4000.0, hi = 2e-3, r2 = sqrt(0.5);
    for (int dc = 0; dc < 2; dc++) {
        const double de = depths[dc];
        double p[9];
        for (int j = 0; j < 3; j++) {
            const double o = (j - 1) * 1e-12 * r2; /* across the bisector, 1e-12 m */
            p[3 * j] = 0.1 - de + o, p[3 * j + 1] = 0.1 - de - o, p[3 * j + 2] = 0.0;
        }
        ws_web *web;
        ws_nodes3 x;
        ws_world *w = yawed_box_nodes(3, p, &web, &x);
        ws_nodes3 v = nodes_at_body(w, 3);
        const ws_ncand_list *cl = &web->contact->cand[web->contact->list];
        ws_node_link *L = calloc(cl->n + 1, sizeof *L);
        v3 F[3];
        for (uint32_t i = 0; i < 3; i++) {
            int cnt;
            F[i] = contact_force(w, web, cl, x, v, L, i, &cnt);
            ck_assert_int_ge(cnt, 1);
        }
        const m3 *A = &w->bodies.A[0];
        const v3 bis = m3_mul_v(A, v3_make(r2, r2, 0.0)), r = w->bodies.st[w->cur].r[0];
        const double jm = v3_norm(v3_sub(F[0], F[1])), jp = v3_norm(v3_sub(F[2], F[1]));
        const double want = k * (hi + de), size = v3_norm(F[1]);
        const v3 across = v3_sub(F[1], v3_scale(bis, v3_dot(F[1], bis)));
        const v3 lx = v3_sub(v3_make(x.x[1], x.y[1], x.z[1]), r);
        const double mz = v3_cross(lx, F[1]).z;
        report("push past the edge, %.1f mm deep: %.4f N (want %.4f); jumps %.2g, %.2g N across "
               "the bisector; off it %.2g of the push; moment about z %.2g N m",
               de * 1e3, size, want, jm, jp, v3_norm(across) / size, mz);
        ck_assert_msg(jm <= 1e-7 && jp <= 1e-7, "the push jumps by %g, %g N across the bisector",
                      jm, jp);
        ck_assert_msg(fabs(size - want) <= 1e-9 * want, "push %.12g N, want %.12g", size, want);
        ck_assert_msg(v3_norm(across) <= 1e-10 * size, "push off the bisector by %g N",
                      v3_norm(across));
        ck_assert_msg(fabs(mz) <= 1e-10 * size * v3_norm(lx), "moment about z %g N m", mz);
        free(L);
        free(x.x);
        free(v.x);
        ws_world_destroy(w);
    }
}
END_TEST

START_TEST(test_push_continuous_onto_face)
{
    /* A node 0.5 mm from the box's vertical edge, 1e-12 m inside and outside face A's plane
     * (x = 0.1) and 0.5 mm inside face B's: outside A's plane face A alone holds it (its push
     * k (hi - d_A) along n_A), so just inside A must too. The blend's width is pinched to the
     * depth for this: a fixed 1 mm width would turn the push there to 3/4 n_A + 1/4 n_B (18
     * degrees), a jump of 2.5 N of 8. Bound 1e-7 N as above. */
    const double p[6] = {0.1 - 1e-12, 0.1 - 5e-4, 0.0, 0.1 + 1e-12, 0.1 - 5e-4, 0.0};
    ws_web *web;
    ws_nodes3 x;
    ws_world *w = yawed_box_nodes(2, p, &web, &x);
    ws_nodes3 v = nodes_at_body(w, 2);
    const ws_ncand_list *cl = &web->contact->cand[web->contact->list];
    ws_node_link *L = calloc(cl->n + 1, sizeof *L);
    int c0, c1;
    const v3 F0 = contact_force(w, web, cl, x, v, L, 0, &c0),
             F1 = contact_force(w, web, cl, x, v, L, 1, &c1);
    const double jump = v3_norm(v3_sub(F0, F1));
    report("push onto face A's outside: %.6f N inside, %.6f N outside; jump %.2g N",
           v3_norm(F0), v3_norm(F1), jump);
    ck_assert_int_ge(c0, 1);
    ck_assert_int_ge(c1, 1);
    ck_assert_msg(jump <= 1e-7, "the push jumps by %g N at face A's plane", jump);
    free(L);
    free(x.x);
    free(v.x);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_band_corners_mirror)
{
    /* Four nodes past the box's four vertical edges, on the bisectors, 0.8 mm deep (a refined
     * band's corner columns, 0.4-0.8 mm past the edges): the set is the mirror image of itself
     * (in the box's x-z and y-z planes), so the pushes' moment about the vertical through the
     * CoG must vanish. Round-off (the box turned by 0.3 rad: its planes' depths differ by
     * 1e-17 m) moves each push across by 1e-12 N at most (gradient 2.5e4 N/m times 1e-17 m,
     * see above), a moment of 1e-13 N m; bound 1e-9 N m, against 0.8 N m from a single face's
     * push at one corner (the shallowest face alone picked by round-off). Again with the
     * corners' symmetric noise: each moved 1e-8 m across its bisector, mirror images moved
     * mirror-wise, where each node's moment (1e-5 N m) cancels its image's. */
    for (int noisy = 0; noisy < 2; noisy++) {
        const double de = 0.8e-3, eta = noisy ? 1e-8 * sqrt(0.5) : 0.0;
        double p[12];
        for (int c = 0; c < 4; c++) {
            const double sx = (c & 1) ? -1.0 : 1.0, sy = (c & 2) ? -1.0 : 1.0;
            /* Mirror images in x -> -x and y -> -y: the offset (eta, -eta) mirrored. */
            p[3 * c] = sx * (0.1 - de + eta), p[3 * c + 1] = sy * (0.1 - de - eta);
            p[3 * c + 2] = 0.0;
        }
        ws_web *web;
        ws_nodes3 x;
        ws_world *w = yawed_box_nodes(4, p, &web, &x);
        ws_nodes3 v = nodes_at_body(w, 4);
        const ws_ncand_list *cl = &web->contact->cand[web->contact->list];
        ws_node_link *L = calloc(cl->n + 1, sizeof *L);
        const ws_node_pass P = {&w->bodies, w->cur, &w->node_geom, w->node_par, cl->c,
                                x,          v,      0.0,           1.0,         NULL,
                            0};
        const size_t n = ws_node_links(&P, web, cl->n, NULL, 0.0, L, NULL);
        double mz = 0.0, one = 0.0;
        int act = 0;
        for (size_t k = 0; k < n; k++)
            if (L[k].active) {
                const double m = v3_cross(L[k].lever, L[k].f).z;
                mz += m;
                one = fmax(one, fabs(m));
                act++;
            }
        report("band corners%s: %d pushing contacts, moment about z %.2g N m (largest one's "
               "%.2g)",
               noisy ? ", 1e-8 m mirrored noise" : " on the bisectors", act, mz, one);
        ck_assert_int_ge(act, 4);
        ck_assert_msg(fabs(mz) <= 1e-9, "the corners twist the box: %g N m", mz);
        free(L);
        free(x.x);
        free(v.x);
        ws_world_destroy(w);
    }
}
END_TEST

START_TEST(test_blend_jacobian)
{
    /* The exact derivatives of the contact forces of a node past the box's vertical edge where
     * the faces blend, against central differences (steps 1e-8 m, 1e-8 m/s) to 1e-6 of their
     * size, law by law: the width 1 mm (1.5 and 1.8 mm deep), pinched to the depth (0.3 and
     * 0.4 mm deep), and outside the blend (1 and 3 mm deep: the shallowest face alone), one
     * contact each (the shallower face's, its normal turning with the node in the blend);
     * slipping at (3, 4, -1) mm/s and approaching. Truncation: (1e-8 / 3e-4)^2 ~ 1e-9 of the
     * second derivative's scale. */
    const double cases[3][2] = {{1.5e-3, 1.8e-3}, {0.3e-3, 0.4e-3}, {1e-3, 3e-3}};
    const char *what[3] = {"blend, width 1 mm", "blend, width pinched", "shallowest face"};
    const int links[3] = {1, 1, 1};
    for (int cc = 0; cc < 3; cc++) {
        const double p[3] = {0.1 - cases[cc][0], 0.1 - cases[cc][1], 0.0};
        ws_web *web;
        ws_nodes3 x;
        ws_world *w = yawed_box_nodes(1, p, &web, &x);
        ws_nodes3 v = nodes_at_body(w, 1);
        const m3 *A = &w->bodies.A[0];
        const v3 slip = m3_mul_v(A, v3_make(0.003, 0.004, -0.001));
        v.x[0] += slip.x, v.y[0] += slip.y, v.z[0] += slip.z;
        const ws_ncand_list *cl = &web->contact->cand[web->contact->list];
        ws_node_link *L = calloc(cl->n + 1, sizeof *L);
        ws_node_exact *E = calloc(cl->n + 1, sizeof *E);
        const ws_node_pass P = {&w->bodies, w->cur, &w->node_geom, w->node_par, cl->c,
                                x,          v,      0.0,           1.0,         NULL,
                            0};
        const size_t n = ws_node_links(&P, web, cl->n, NULL, 0.0, L, E);
        double Jx[9] = {0}, Jv[9] = {0};
        int act = 0;
        for (size_t k = 0; k < n; k++)
            if (L[k].active) {
                act++;
                for (int q = 0; q < 9; q++)
                    Jx[q] += E[k].Jx[q], Jv[q] += E[k].Jv[q];
            }
        ck_assert_int_eq(act, links[cc]);
        double Fx[9], Fv[9];
        ws_nodes3 s[2] = {x, v};
        for (int which = 0; which < 2; which++)
            for (int k = 0; k < 3; k++) {
                double *c = comp(s[which], k), keep = c[0];
                int c1, c2;
                c[0] = keep + 1e-8;
                const v3 fp = contact_force(w, web, cl, x, v, L, 0, &c1);
                c[0] = keep - 1e-8;
                const v3 fm = contact_force(w, web, cl, x, v, L, 0, &c2);
                c[0] = keep;
                ck_assert_int_eq(c1, links[cc]);
                ck_assert_int_eq(c2, links[cc]);
                double *J = which ? Fv : Fx;
                J[k] = (fp.x - fm.x) / 2e-8;
                J[3 + k] = (fp.y - fm.y) / 2e-8;
                J[6 + k] = (fp.z - fm.z) / 2e-8;
            }
        const double sx = max_abs(Fx, 9), sv = max_abs(Fv, 9);
        double ex = 0, ev = 0;
        for (int k = 0; k < 9; k++) {
            ex = fmax(ex, fabs(Jx[k] - Fx[k]));
            ev = fmax(ev, fabs(Jv[k] - Fv[k]));
        }
        report("contact past the edge (%s): exact vs finite differences %.2g, %.2g of %.3g N/m, "
               "%.3g N s/m",
               what[cc], ex / sx, ev / sv, sx, sv);
        ck_assert_msg(ex <= 1e-6 * sx, "%s: df/dx off by %g of %g", what[cc], ex, sx);
        ck_assert_msg(ev <= 1e-6 * sv, "%s: df/dv off by %g of %g", what[cc], ev, sv);
        free(L);
        free(E);
        free(x.x);
        free(v.x);
        ws_world_destroy(w);
    }
}
END_TEST

/* ---- 2. backward Euler on a string's mode ---- */

START_TEST(test_string_mode_amplification)
{
    /* A straight string of N + 1 nodes (ends pinned), linear springs k = EA / l0, masses m,
     * moving along its length: a linear system (the springs stay in tension), so the one
     * Newton step is backward Euler exactly. Mode j, u_i = sin(j pi i / N), has omega_j =
     * 2 sqrt(k / m) sin(j pi / (2 N)) and travels at omega_j / kappa_j (kappa_j = j pi / L).
     * Backward Euler on x'' = -omega^2 x over h: z = x + i v / omega goes to z / (1 + i omega
     * h), so each step multiplies the amplitude by 1 / sqrt(1 + omega^2 h^2) and turns the
     * phase by atan(omega h): from rest at amplitude X, x_n = X rho^n cos(n theta). Its wave
     * speed is c_h = theta / (kappa h), slower than omega / kappa by atan(omega h) / (omega h),
     * and it decays. The mode's amplitude after n steps must follow that to 1e-6 of X (the
     * solve's tolerance is 1e-10 a step; a law's strain is l / l0 - 1, linear in the node
     * positions along the string). Two steps: omega h = 0.5 and 2. */
    const int N = 20;
    const double L = 1.0, sp = L / N, pre = 0.1, EA = 20.0, m = 1e-3, X = 1e-4;
    const double l0 = sp / (1 + pre), k = EA / l0, j = 1;
    const double om = 2 * sqrt(k / m) * sin(j * PI / (2 * N)), kappa = j * PI / L;
    const double oh[2] = {0.5, 2.0};
    for (int c = 0; c < 2; c++) {
        const double h = oh[c] / om;
        ws_world *w = world_g(h, NO_G);
        ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, EA, 0.0, 0.0, 0.0);
        ws_web_def wd;
        ws_web_def_init(&wd);
        wd.node_mass = m;
        wd.law = law;
        wd.integrator = WS_WEB_IMPLICIT;
        wd.solver_tolerance = 1e-10;
        double pos[3 * 21] = {0};
        uint32_t pairs[2 * 20];
        double rest[20];
        for (int i = 0; i <= N; i++)
            pos[3 * i] = i * sp + X * sin(j * PI * i / N);
        for (int i = 0; i < N; i++) {
            pairs[2 * i] = (uint32_t)i;
            pairs[2 * i + 1] = (uint32_t)(i + 1);
            rest[i] = l0;
        }
        const uint32_t pins[2] = {0, (uint32_t)N};
        ws_web_id id = mesh_web(w, &wd, (size_t)N + 1, pos, pairs, (size_t)N, rest, pins, 2);
        const double rho = 1 / sqrt(1 + oh[c] * oh[c]), th = atan(oh[c]);
        double worst = 0;
        int steps = 12;
        for (int n = 1; n <= steps; n++) {
            ck_ok(w, ws_world_step(w));
            double xyz[3 * 21];
            size_t cnt;
            ck_ok(w, ws_web_copy_positions(w, id, xyz, 21, &cnt));
            /* The mode's amplitude: projection on sin(j pi i / N) (orthogonal, norm N / 2). */
            double a = 0;
            for (int i = 1; i < N; i++)
                a += (xyz[3 * i] - i * sp) * sin(j * PI * i / N);
            a *= 2.0 / N;
            const double want = X * pow(rho, n) * cos(n * th);
            worst = fmax(worst, fabs(a - want));
        }
        report("string mode, omega h = %.1f: amplification %.6f a step, phase %.6f rad (exact "
               "%.6f); wave speed %.4f of the exact; worst |x_n - X rho^n cos(n theta)| = "
               "%.2g of X",
               oh[c], rho, th, oh[c], th / oh[c], worst / X);
        (void)kappa;
        ck_assert_msg(worst <= 1e-6 * X, "omega h %g: off by %g of X", oh[c], worst / X);
        ws_world_destroy(w);
    }
}
END_TEST

/* ---- 3. analytic answers of the explicit web, on the implicit one ---- */

START_TEST(test_row_tension)
{
    /* The row of tests/test_web.c (row_prestretch_tension): 11 nodes 0.1 m apart, ends pinned,
     * pre-stretch 0.25, EA = 100 N, Kelvin-Voigt c = 0.5 N s, disturbed by a gravity along x
     * for 0.1 s and then left to settle: every spring at T = EA p. Here at dt = 2 ms, 2.7 times
     * the explicit stable step (0.74 ms): backward Euler damps the disturbance further (its
     * amplification is below 1 for every mode), so 2 s settle it below 1e-9 as well. */
    const double dt = 2e-3, EA = 100.0, p = 0.25, sp = 0.1, m = 0.01;
    ws_world *w = world_g(dt, NO_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, EA, 0.0, 0.5, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = m;
    wd.law = law;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = 1e-10;
    wd.name = "row";
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = 11;
    sd.ny = 1;
    sd.spacing_x = sp;
    sd.spacing_y = sp;
    sd.prestretch_x = p;
    uint32_t pins[2] = {0, 10};
    sd.pinned = pins;
    sd.pinned_count = 2;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    double S;
    ck_ok(w, ws_web_get_stable_dt(w, web, &S));
    ck_assert_msg(dt > S, "not beyond the explicit limit: dt %g, stable %g", dt, S);
    ws_vec3 gx = {20.0, 0, 0};
    ck_ok(w, ws_world_set_gravity(w, &gx));
    ck_ok(w, ws_world_step_n(w, 50));
    double T[10];
    size_t ns;
    ck_ok(w, ws_web_copy_spring_tensions(w, web, T, 10, &ns));
    double spread = 0;
    for (int i = 0; i < 10; i++)
        spread = fmax(spread, fabs(T[i] - EA * p) / (EA * p));
    ck_assert_msg(spread > 1e-3, "the disturbance did nothing (%g)", spread);
    ck_ok(w, ws_world_set_gravity(w, &NO_G));
    ck_ok(w, ws_world_step_n(w, 1000));
    ck_ok(w, ws_web_copy_spring_tensions(w, web, T, 10, &ns));
    double worst = 0;
    for (int i = 0; i < 10; i++)
        worst = fmax(worst, fabs(T[i] - EA * p) / (EA * p));
    ws_web_solver_stats st;
    ck_ok(w, ws_web_get_solver_stats(w, web, &st));
    report("implicit row at dt %.0f ms (%.1f x the stable step): disturbed %.3g, settled "
           "|T - EA p| / EA p = %.3g; %.1f CG iterations a step",
           1e3 * dt, dt / S, spread, worst, (double)st.iterations / (double)st.solves);
    ck_assert_msg(worst <= 1e-9, "settled tension off by %g", worst);
    ws_world_destroy(w);
}
END_TEST

/* A pinned chain of n nodes under gravity, released from straight, stepped to time t at dt:
 * the mid node's z. */
static double chain_mid_z(int implicit, double dt, int substeps, double t)
{
    const int n = 21;
    const double sp = 0.05, p = 0.05, EA = 50.0, m = 2e-3;
    ws_world *w = world_g(dt, (ws_vec3){0, 0, -G0});
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, EA, 0.0, 0.02, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = m;
    wd.law = law;
    wd.integrator = implicit ? WS_WEB_IMPLICIT : WS_WEB_EXPLICIT;
    wd.substeps = substeps;
    wd.solver_tolerance = 1e-10;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = n;
    sd.ny = 1;
    sd.spacing_x = sp;
    sd.spacing_y = sp;
    sd.prestretch_x = p;
    uint32_t pins[2] = {0, (uint32_t)n - 1};
    sd.pinned = pins;
    sd.pinned_count = 2;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    ck_ok(w, ws_world_step_n(w, (uint64_t)llround(t / dt)));
    double xyz[3 * 21];
    size_t cnt;
    ck_ok(w, ws_web_copy_positions(w, web, xyz, 21, &cnt));
    ws_world_destroy(w);
    return xyz[3 * 10 + 2];
}

START_TEST(test_converges_to_explicit)
{
    /* A chain released under gravity, its mid node's drop at t = 0.1 s (the fundamental's
     * period is about 0.19 s: mid-swing). The explicit film at 1e-5 s is the reference (its
     * own error is O(h^2) ~ 1e-10 of the sag). Backward Euler is first order: its error at dt
     * 2, 1, 0.5 ms must fall by close to half each time (ratio in 0.4..0.6) and reach below
     * 2 % of the drop at 0.5 ms. */
    const double t = 0.1;
    const double ref = chain_mid_z(0, 1e-5, 1, t);
    const double dts[3] = {2e-3, 1e-3, 5e-4};
    double err[3];
    for (int k = 0; k < 3; k++)
        err[k] = fabs(chain_mid_z(1, dts[k], 1, t) - ref);
    report("chain released, mid drop %.4g m at 0.1 s: implicit errors %.3g, %.3g, %.3g m at dt "
           "2, 1, 0.5 ms (ratios %.3f, %.3f)",
           -ref, err[0], err[1], err[2], err[1] / err[0], err[2] / err[1]);
    ck_assert(ref < -1e-3);
    for (int k = 1; k < 3; k++)
        ck_assert_msg(err[k] / err[k - 1] > 0.4 && err[k] / err[k - 1] < 0.6,
                      "not first order: %g then %g", err[k - 1], err[k]);
    ck_assert_msg(err[2] < 0.02 * fabs(ref), "error %g of drop %g", err[2], ref);
}
END_TEST

static uint64_t band_case(double mu, int workers)
{
    /* The band of tests/test_web.c (band_pressure) on the implicit film: a cylinder R = 0.1 m of
     * 128 sides, kinematic at rest, a band of 64 x 3 nodes pre-stretched 0.2 around, no
     * gravity, EA = 100 N (T ~ 20 N), 1 g nodes with drag 0.5 kg/s, film-cylinder pair k =
     * 4000 N/m, c = 1 kg/s, mu as given; here at dt = 1 ms in one step, 5 times the
     * explicit stable step (the explicit film would need 10 sub-steps at the check's 0.5). After 0.3 s the band is at rest to e^-75 (backward
     * Euler damps every mode at least as the drag does), and at rest a step's contact force is
     * its penalty at the start (the linear terms vanish with v and dv). Each row's contact
     * forces sum to 2 N T sin(pi / N) for the regular 64-gon of nodes (1e-6: settling and
     * round-off), and frictionless each is k times its overlap along the face normal (1e-6). */
    const double R = 0.1, dt = 1e-3, EA = 100.0, kc = 4000.0, reach = 2e-3;
    const int seg = 128, na = 64, nu = 3;
    ws_world *w = world_gw(dt, NO_G, workers);
    ws_shape_id cs;
    ck_ok(w, ws_shape_create_cylinder(w, R, 0.3, seg, &cs));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = cs;
    ws_body_id cyl;
    ck_ok(w, ws_body_create(w, &bd, &cyl));
    ws_material_def md;
    ws_material_def_init(&md);
    ws_material_id film, dflt;
    ck_ok(w, ws_material_create(w, &md, &film));
    ck_ok(w, ws_world_get_default_material(w, &dflt));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = kc;
    cd.damping = 1.0;
    cd.friction = mu;
    ck_ok(w, ws_world_set_contact(w, film, dflt, &cd));
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, EA, 0.0, 0.005, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-3;
    wd.node_damping = 0.5;
    wd.law = law;
    wd.material = film;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = 1e-10;
    ws_band_def bdf;
    ws_band_def_init(&bdf);
    bdf.bodies = &cyl;
    bdf.body_count = 1;
    bdf.z_bottom = -0.05;
    bdf.z_top = 0.05;
    bdf.n_around = na;
    bdf.n_up = nu;
    bdf.prestretch_around = 0.2;
    ws_web_id web;
    ck_ok(w, ws_web_create_band(w, &wd, &bdf, &web));
    double S;
    ck_ok(w, ws_web_get_stable_dt(w, web, &S));
    ck_ok(w, ws_world_step_n(w, 300));
    const size_t nn = (size_t)na * nu;
    double *x = malloc(3 * nn * sizeof *x), *fc = malloc(3 * nn * sizeof *fc);
    double *T = malloc(nn * 2 * sizeof *T);
    ck_assert(x && fc && T);
    size_t cnt;
    ck_ok(w, ws_web_copy_positions(w, web, x, nn, &cnt));
    ck_ok(w, ws_web_copy_contact_forces(w, web, fc, nn, &cnt));
    ck_ok(w, ws_web_copy_spring_tensions(w, web, T, nn * 2, &cnt));
    const double a = R * cos(PI / seg);
    for (int j = 0; j < nu; j++) {
        double Tm = 0.0, F = 0.0, worst_law = 0.0;
        for (int i = 0; i < na; i++) {
            Tm += T[j * na + i] / na;
            const double *p = x + 3 * (j * na + i), *f = fc + 3 * (j * na + i);
            const double fn = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
            F += fn;
            const double ang = atan2(f[1], f[0]);
            const double fidx = floor((ang < 0 ? ang + 2 * PI : ang) / (2 * PI / seg));
            const double thf = (fidx + 0.5) * 2 * PI / seg;
            const double d = p[0] * cos(thf) + p[1] * sin(thf) - a, want = kc * (reach - d);
            if (mu == 0.0)
                worst_law = fmax(worst_law, fabs(fn - want) / want);
        }
        const double pred = 2 * na * Tm * sin(PI / na);
        report("implicit band mu %.1f row %d at dt %.0f ms (%.0f x the explicit stable step): "
               "sum |f| %.6f N, 2 N T sin(pi/N) %.6f N (rel %.2g); contact law %.2g",
               mu, j, 1e3 * dt, dt / S, F, pred, (F - pred) / pred, worst_law);
        ck_assert_msg(fabs(F - pred) <= 1e-6 * pred, "row %d: %.9f vs %.9f", j, F, pred);
        ck_assert_msg(worst_law <= 1e-6, "row %d: contact law off by %g", j, worst_law);
    }
    free(x);
    free(fc);
    free(T);
    uint64_t hash;
    ck_ok(w, ws_world_get_state_hash(w, &hash));
    ws_world_destroy(w);
    return hash;
}

START_TEST(test_band_pressure)
{
    band_case(0.0, 1);
    band_case(0.3, 1);
}
END_TEST

/* An implicit web solves on the calling thread whatever the worker count; a world of 2 and of
 * 3 workers (their lanes run any explicit web beside it) ends in the state of one worker, to
 * the bit. */
START_TEST(test_same_on_workers)
{
    const uint64_t one = band_case(0.3, 1);
    ck_assert_uint_eq(band_case(0.3, 2), one);
    ck_assert_uint_eq(band_case(0.3, 3), one);
}
END_TEST

START_TEST(test_scales_and_rupture)
{
    /* A mesh web's stiffness scales and broken springs on the implicit film. A row of 5 nodes,
     * ends pinned, pre-stretch 0.1, EA = 50 N, every spring scaled by 3: settled with drag, each
     * spring pulls 3 EA 0.1 = 15 N (1e-9). Then a rupture strain of 0.05 breaks them all at the
     * end of the next step, and from then on the free nodes fall with nothing but gravity and
     * their drag: the middle node follows backward Euler's recurrence for a free particle
     * (below) to round-off (1e-12 of its drop). */
    const double dt = 1e-3, sp = 0.05, l0 = sp / 1.1, EA = 50.0;
    ws_world *w = world_g(dt, NO_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, EA, 0.0, 0.1, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-3;
    wd.node_damping = 0.05;
    wd.law = law;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = 1e-10;
    double pos[15] = {0};
    uint32_t pairs[8];
    double rest[4], scale[4];
    for (int i = 0; i < 5; i++)
        pos[3 * i] = i * sp;
    for (int i = 0; i < 4; i++) {
        pairs[2 * i] = (uint32_t)i;
        pairs[2 * i + 1] = (uint32_t)i + 1;
        rest[i] = l0;
        scale[i] = 3.0;
    }
    const uint32_t pins[2] = {0, 4};
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = pos;
    md.node_count = 5;
    md.springs = pairs;
    md.spring_count = 4;
    md.rest_lengths = rest;
    md.pinned = pins;
    md.pinned_count = 2;
    md.stiffness_scales = scale;
    ws_web_id id;
    ck_ok(w, ws_web_create_mesh(w, &wd, &md, &id));
    const ws_vec3 down = {0, 0, -G0};
    ck_ok(w, ws_world_set_gravity(w, &down));
    ck_ok(w, ws_world_step_n(w, 20));
    ck_ok(w, ws_world_set_gravity(w, &NO_G));
    ck_ok(w, ws_world_step_n(w, 3000));
    double T[4];
    size_t cnt;
    ck_ok(w, ws_web_copy_spring_tensions(w, id, T, 4, &cnt));
    for (int i = 0; i < 4; i++)
        ck_assert_msg(fabs(T[i] - 3 * EA * 0.1) <= 1e-9 * 3 * EA * 0.1, "spring %d: %.12g", i,
                      T[i]);
    ck_ok(w, ws_web_set_rupture_strain(w, id, 0.05));
    ck_ok(w, ws_world_set_gravity(w, &down));
    ck_ok(w, ws_world_step(w));
    ws_web_rupture rp;
    ck_ok(w, ws_web_get_rupture(w, id, &rp));
    ck_assert_uint_eq(rp.broken_count, 4);
    double x0[15], v0[15], x1[15];
    ck_ok(w, ws_web_copy_positions(w, id, x0, 5, &cnt));
    ck_ok(w, ws_web_copy_velocities(w, id, v0, 5, &cnt));
    const int K = 50;
    ck_ok(w, ws_world_step_n(w, K));
    ck_ok(w, ws_web_copy_positions(w, id, x1, 5, &cnt));
    /* The middle node alone under gravity and its drag d: backward Euler's step is
     * v' = (m v + h m g) / (m + h d), z' = z + h v'. */
    const double m = 1e-3, d = 0.05;
    double v = v0[3 * 2 + 2], z = x0[3 * 2 + 2];
    for (int k = 0; k < K; k++) {
        v = (m * v + dt * m * -G0) / (m + dt * d);
        z += dt * v;
    }
    const double drop = x0[3 * 2 + 2] - z;
    report("after the break: middle node dropped %.9g m in %d steps, backward Euler's free "
           "fall %.9g m",
           x0[3 * 2 + 2] - x1[3 * 2 + 2], K, drop);
    ck_assert(drop > 1e-3);
    ck_assert_msg(fabs(x1[3 * 2 + 2] - z) <= 1e-12 * drop, "z %.15g vs %.15g", x1[3 * 2 + 2], z);
    ws_world_destroy(w);
    report("scales and rupture on the implicit film: tensions 3 EA p, %u springs broken",
           rp.broken_count);
}
END_TEST

/* ---- 4. a failed solve ---- */

START_TEST(test_failed_solve_leaves_world)
{
    /* One CG iteration at a tolerance of 1e-12 cannot solve a 10-node chain's system (CG needs
     * about as many iterations as distinct eigenvalues): the step fails with WS_ERR_NUMERICAL
     * naming the web, the residual and the iterations, and the state hash is as before. */
    ws_world *w = world_g(1e-3, (ws_vec3){0, 0, -G0});
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, 50.0, 0.0, 0.02, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-3;
    wd.law = law;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = 1e-12;
    wd.solver_max_iterations = 1;
    wd.name = "stiff chain";
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = 10;
    sd.ny = 1;
    sd.spacing_x = 0.05;
    sd.spacing_y = 0.05;
    sd.prestretch_x = 0.05;
    uint32_t pins[1] = {0};
    sd.pinned = pins;
    sd.pinned_count = 1;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    uint64_t h0, h1;
    ck_ok(w, ws_world_get_state_hash(w, &h0));
    ws_status s = ws_world_step(w);
    ck_ok(w, ws_world_get_state_hash(w, &h1));
    const char *msg = ws_world_last_error(w);
    report("failed solve: %s", msg);
    ck_assert_int_eq(s, WS_ERR_NUMERICAL);
    ck_assert_msg(strstr(msg, "stiff chain") && strstr(msg, "residual") &&
                      strstr(msg, "1 iterations"),
                  "message: %s", msg);
    ck_assert_msg(h0 == h1, "state changed: %016llx -> %016llx", (unsigned long long)h0,
                  (unsigned long long)h1);
    double t;
    ck_ok(w, ws_world_get_time(w, &t));
    ck_assert(t == 0.0);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_failed_solve_with_body)
{
    /* A box resting on a pinned sheet (box_on_sheet's scene, here built by hand) whose solve,
     * the box's rows in it, is allowed one CG iteration at a tolerance of 1e-12: the step
     * fails with WS_ERR_NUMERICAL and the world (nodes, box, time) is as before, hash and all. */
    ws_world *w = world_g(1e-3, (ws_vec3){0, 0, -G0});
    ws_shape_id box;
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &box));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = box;
    bd.mass = 0.05;
    bd.position = v3_make(0.0, 0.0, 0.05 + 1.5e-3);
    ws_body_id body;
    ck_ok(w, ws_body_create(w, &bd, &body));
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, 200.0, 0.0, 0.5, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-4;
    wd.law = law;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = 1e-12;
    wd.solver_max_iterations = 1;
    wd.name = "sheet under a box";
    enum { N = 9 };
    uint32_t pins[4 * N];
    const size_t np = edge_pins(N, N, pins);
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = sd.ny = N;
    sd.origin = v3_make(-0.08, -0.08, 0.0);
    sd.spacing_x = sd.spacing_y = 0.02;
    sd.prestretch_x = sd.prestretch_y = 0.05;
    sd.pinned = pins;
    sd.pinned_count = np;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    uint64_t h0, h1;
    ck_ok(w, ws_world_get_state_hash(w, &h0));
    const ws_status s = ws_world_step(w);
    ck_ok(w, ws_world_get_state_hash(w, &h1));
    const char *msg = ws_world_last_error(w);
    report("failed solve with a body in it: %s", msg);
    ck_assert_int_eq(s, WS_ERR_NUMERICAL);
    ck_assert_msg(strstr(msg, "sheet under a box") && strstr(msg, "residual"), "%s", msg);
    ck_assert_msg(h0 == h1, "state changed: %016llx -> %016llx", (unsigned long long)h0,
                  (unsigned long long)h1);
    ws_vec3 r;
    ck_ok(w, ws_body_get_position(w, body, &r));
    ck_assert(r.z == 0.05 + 1.5e-3);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_bad_solver_defs)
{
    ws_world *w = world_g(1e-3, NO_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, 50.0, 0.0, 0.0, 0.0);
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = 3;
    sd.ny = 1;
    sd.spacing_x = sd.spacing_y = 0.05;
    ws_web_def wd;
    ws_web_id web;
    const struct {
        int integrator;
        double tol;
        int maxit, hold;
        const char *says;
    } bad[] = {{2, 1e-6, 10, 0, "integrator"},
               {1, 0.0, 10, 0, "solver_tolerance"},
               {1, NAN, 10, 0, "solver_tolerance"},
               {1, 0.5, 10, 0, "solver_tolerance"},
               {1, 1e-6, 0, 0, "solver_max_iterations"},
               {1, 1e-6, 10, 2, "hold_bodies"},
               {1, 1e-6, 10, -1, "hold_bodies"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        ws_web_def_init(&wd);
        wd.node_mass = 1e-3;
        wd.law = law;
        wd.integrator = bad[k].integrator;
        wd.solver_tolerance = bad[k].tol;
        wd.solver_max_iterations = bad[k].maxit;
        wd.hold_bodies = bad[k].hold;
        ck_assert_int_eq(ws_web_create_sheet(w, &wd, &sd, &web), WS_ERR_INVALID_ARGUMENT);
        ck_assert_msg(strstr(ws_world_last_error(w), bad[k].says), "%s",
                      ws_world_last_error(w));
    }
    ws_web_solver_stats st;
    ck_assert_int_eq(ws_web_get_solver_stats(w, web, &st), WS_ERR_STALE_HANDLE);
    ws_world_destroy(w);
}
END_TEST

/* ---- 7. the multigrid preconditioner ---- */

/* A deterministic pseudo-random vector of a web, zero at its pinned nodes. */
static void random_vector(const ws_web *web, uint64_t seed, double *u)
{
    for (uint32_t i = 0; i < 3 * web->n; i++) {
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        u[i] = web->inv_m[i / 3] == 0.0 ? 0.0 : (double)(seed >> 11) / 9007199254740992.0 - 0.5;
    }
}

static double dot3(const double *a, const double *b, uint32_t n)
{
    double s = 0.0;
    for (uint32_t k = 0; k < 3 * n; k++)
        s += a[k] * b[k];
    return s;
}

/* web's multigrid B as its last solve left it: symmetric (u.By = y.Bu to 1e-12 of |u| |By|, two
 * random vectors u, y: rounding only), positive, and the cycle contracting (below); u (random)
 * and Bu = B u left for the caller (3 n doubles each). */
static void cycle_checks(ws_web *web, const char *what, double *u, double *Bu)
{
    ws_implicit *im = web->imp;
    const uint32_t n = web->n;
    double *y = malloc(3 * n * sizeof(double)), *By = malloc(3 * n * sizeof(double)),
           *e = malloc(3 * n * sizeof(double)), *Ae = malloc(3 * n * sizeof(double)),
           *BAe = malloc(3 * n * sizeof(double));
    ck_assert(y && By && e && Ae && BAe);
    random_vector(web, 1, u);
    random_vector(web, 2, y);
    (void)ws_mg_apply(im->mg, web, u, Bu);
    (void)ws_mg_apply(im->mg, web, y, By);
    const double uBy = dot3(u, By, n), yBu = dot3(y, Bu, n);
    const double scale = sqrt(dot3(u, u, n) * dot3(By, By, n));
    report("multigrid, %s, %d x %d (%d levels): u.By %.12g, y.Bu %.12g (rel %.2g), u.Bu %.6g",
           what, web->nx, web->ny, ws_mg_levels(im->mg), uBy, yBu, (uBy - yBu) / scale,
           dot3(u, Bu, n));
    ck_assert_msg(fabs(uBy - yBu) <= 1e-12 * scale, "%s: B not symmetric: %.17g vs %.17g", what,
                  uBy, yBu);
    ck_assert_msg(dot3(u, Bu, n) > 0.0 && dot3(y, By, n) > 0.0, "%s: B not positive", what);
    /* The cycle as an iteration, e <- (I - B A) e, by power iteration in A's inner product (40
     * steps from a random e): the exact cycle's I - B A has its eigenvalues in [0, 1) (the
     * smoothers and their adjoints around a coarse correction that removes at most all of the
     * error), so B A's lie in (0, 1]. The cycle keeps the film's operator and the coarse
     * levels in single precision, which moves them by the rounding (6e-8 of a block, times the
     * blocks' condition): its factor must stay below 1 (with B symmetric, that is B positive
     * definite) and B A's largest eigenvalue below 1 + 1e-5. */
    double lmax = 0.0, rho = 0.0;
    for (int pass = 0; pass < 2; pass++) { /* B A, then I - B A */
        random_vector(web, 3 + (uint64_t)pass, e);
        for (int k = 0; k < 40; k++) {
            const double eAe = ws_implicit_apply_op(web, e, Ae);
            (void)ws_mg_apply(im->mg, web, Ae, BAe);
            const double lam = dot3(Ae, BAe, n) / eAe; /* (e, B A e)_A / (e, e)_A */
            const double norm = sqrt(eAe);
            for (uint32_t q = 0; q < 3 * n; q++)
                e[q] = (pass ? e[q] - BAe[q] : BAe[q]) / norm;
            if (pass)
                rho = 1.0 - lam;
            else
                lmax = lam;
        }
    }
    report("multigrid, %s: largest eigenvalue of B A %.9f, factor of I - B A %.3f", what, lmax,
           rho);
    ck_assert_msg(lmax > 0.0 && lmax <= 1.0 + 1e-5, "%s: B A's largest eigenvalue %.9f", what,
                  lmax);
    ck_assert_msg(rho < 1.0, "%s: the cycle does not contract: factor %g", what, rho);
    free(y), free(By), free(e), free(Ae), free(BAe);
}

/* The sheet of test_multigrid refined r times in each direction (the same film: a spring's
 * EA and damping with its share of the width, a node's mass with its share of the area), 5
 * steps: its film solve to 1e-11 from zero by multigrid and by block Jacobi, their iterations;
 * with checks, the cycle's symmetry and definiteness and a known solution too. */
static void sheet_case(int r, double pre_x, double pre_y, int checks, int *it_mg_out,
                       int *it_bj_out)
{
    /* A drum: a sheet of 41 x 23 nodes (r = 1) pinned along its whole edge, pre-stretched
     * 40 % and 20 % as the reference film, with shear springs (every neighbour of the grid's
     * 9-point stencil), sagging under gravity at dt 2 ms (a spring's h^2 k 1600 times a
     * node's mass at r = 1). On its matrix, the V-cycle B must be symmetric (u.Bv = v.Bu to
     * round-off, 1e-12 of |u||Bv|) and positive definite (u.Bu > 0), conjugate gradients with
     * it must reach a known solution (to 1e-12 of the residual's scale, so to 1e-8 of the
     * solution with a condition number under 1e4), and the film's solve with it must give
     * block Jacobi's dv (both to residual 1e-11 of its scale: 1e-7 of dv) in fewer
     * iterations. */
    const int nx = 40 * r + 1, ny = 22 * r + 1;
    const double dt = 2e-3;
    ws_world *w = world_g(dt, (ws_vec3){0, 0, -G0});
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, 20.0 / r, 0.0, 0.01 / r, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-4 / (r * r);
    wd.law = law;
    wd.law_shear = law;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = 1e-11;
    wd.solver_max_iterations = 5000;
    wd.preconditioner = WS_WEB_PRECONDITIONER_MULTIGRID;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = nx;
    sd.ny = ny;
    sd.spacing_x = sd.spacing_y = 0.01 / r;
    sd.prestretch_x = pre_x;
    sd.prestretch_y = pre_y;
    sd.shear = 1;
    uint32_t pins[2 * (161 + 89)]; /* the whole edge: a drum */
    ck_assert_int_le(nx, 161);
    ck_assert_int_le(ny, 89);
    const size_t np = edge_pins(nx, ny, pins);
    sd.pinned = pins;
    sd.pinned_count = np;
    ws_web_id id;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &id));
    ck_ok(w, ws_world_step_n(w, 5));
    ws_web *web = web_of(w, id);
    ws_implicit *im = web->imp;
    ck_assert_msg(im && im->mg, "a grid web takes the multigrid preconditioner");
    const uint32_t n = web->n;
    const int cur = w->cur;
    ws_nodes3 x = web->x[cur], v = web->v[cur];
    ck_assert_int_eq(ws_implicit_begin(web, x, v, v3_make(0, 0, -G0), w->time, 0.0), 0);
    double *dv_mg = malloc(3 * n * sizeof(double)), *u = malloc(3 * n * sizeof(double)),
           *Bu = malloc(3 * n * sizeof(double));
    ck_assert(dv_mg && u && Bu);
    im->warm = 0;
    ck_assert_int_eq(ws_implicit_solve(web, v, dt), 0);
    const int it_mg = im->last_iterations;
    memcpy(dv_mg, im->dv, 3 * n * sizeof(double));
    /* B on the operator of this solve (the block-Jacobi solve below leaves it as it is). */
    if (!checks)
        goto jacobi;
    {
        /* A drum held about alike both ways (40 % and 20 %, pinned round its edge, its
         * springs' h^2 k 1600 times a node's mass) has no row held along itself far more
         * strongly than across: the coarse levels sweep point by point (row_held_along). */
        int whole_rows = 0, whole;
        for (int k = 1; k + 1 < ws_mg_levels(im->mg); k++) {
            (void)ws_mg_rows(im->mg, k, &whole);
            whole_rows += whole;
        }
        report("multigrid on a %d x %d sheet: %d coarse rows solved whole", nx, ny, whole_rows);
        ck_assert_msg(whole_rows == 0, "the drum's coarse levels solve %d rows whole",
                      whole_rows);
    }
    cycle_checks(web, "drum", u, Bu);
    /* Conjugate gradients with B on A x = b for a known x (u). */
    {
        double *b = malloc(3 * n * sizeof(double)), *xs = calloc(3 * n, sizeof(double)),
               *res = malloc(3 * n * sizeof(double)), *z = malloc(3 * n * sizeof(double)),
               *p = malloc(3 * n * sizeof(double)), *q = malloc(3 * n * sizeof(double));
        ck_assert(b && xs && res && z && p && q);
        (void)ws_implicit_apply_op(web, u, b);
        memcpy(res, b, 3 * n * sizeof(double));
        double rz = ws_mg_apply(im->mg, web, res, z);
        memcpy(p, z, 3 * n * sizeof(double));
        const double bb = sqrt(dot3(b, b, n));
        int it = 0;
        while (sqrt(dot3(res, res, n)) > 1e-12 * bb && it < 500) {
            const double alpha = rz / ws_implicit_apply_op(web, p, q);
            for (uint32_t k = 0; k < 3 * n; k++) {
                xs[k] += alpha * p[k];
                res[k] -= alpha * q[k];
            }
            const double rz1 = ws_mg_apply(im->mg, web, res, z);
            for (uint32_t k = 0; k < 3 * n; k++)
                p[k] = z[k] + rz1 / rz * p[k];
            rz = rz1;
            it++;
        }
        double err = 0.0;
        for (uint32_t k = 0; k < 3 * n; k++)
            err = fmax(err, fabs(xs[k] - u[k]));
        report("multigrid CG on a known solution: %d iterations, error %.2g of 0.5", it, err);
        ck_assert_msg(it < 500, "multigrid CG did not converge");
        ck_assert_msg(err <= 1e-8 * 0.5, "multigrid CG's solution off by %g", err);
        free(b), free(xs), free(res), free(z), free(p), free(q);
    }
jacobi:
    im->jacobi_only = 1;
    im->warm = 0;
    ck_assert_int_eq(ws_implicit_solve(web, v, dt), 0);
    const int it_bj = im->last_iterations;
    double diff = 0.0, size = 0.0;
    for (uint32_t k = 0; k < 3 * n; k++) {
        diff = fmax(diff, fabs(dv_mg[k] - im->dv[k]));
        size = fmax(size, fabs(im->dv[k]));
    }
    report("sheet %d x %d: film solve to 1e-11: multigrid %d iterations, block Jacobi %d; dv apart "
           "by %.2g of %.3g m/s",
           nx, ny, it_mg, it_bj, diff, size);
    ck_assert_msg(size > 0.0 && diff <= 1e-7 * size, "dv apart by %g of %g", diff, size);
    ck_assert_msg(it_mg < it_bj, "multigrid took %d iterations, block Jacobi %d", it_mg, it_bj);
    free(dv_mg), free(u), free(Bu);
    ws_world_destroy(w);
    *it_mg_out = it_mg;
    *it_bj_out = it_bj;
}

START_TEST(test_multigrid)
{
    /* Refined 2x in each direction, a node's h^2 k / m grows 4x: block Jacobi's iterations
     * about double (at least 1.6x here), the multigrid's must stay within 1.25x (the issue's
     * budget: 16x the nodes at 20x the cost). */
    int mg1, bj1, mg2, bj2;
    sheet_case(1, 0.4, 0.2, 1, &mg1, &bj1);
    if (getenv("WS_TEST_SHORT"))
        return;
    sheet_case(2, 0.4, 0.2, 0, &mg2, &bj2);
    report("refined 2x: multigrid %d -> %d iterations (%.2f x), block Jacobi %d -> %d (%.2f x)",
           mg1, mg2, (double)mg2 / mg1, bj1, bj2, (double)bj2 / bj1);
    ck_assert_msg(bj2 >= 1.6 * bj1, "block Jacobi did not degrade: %d -> %d", bj1, bj2);
    ck_assert_msg(mg2 <= 1.25 * mg1, "multigrid degraded: %d -> %d", mg1, mg2);
}
END_TEST

/* A frictionless band of 64 r x nu nodes, H tall, round a kinematic cylinder of radius 0.1 m,
 * stretched 20 % around and pre_up up, implicit at dt 1 ms without gravity; the solve's
 * settings (tolerance, iterations, preconditioner) taken from *solve. The film is the same at
 * every refinement r: EA per unit height, areal density and the contact's stiffness per unit
 * area stay, so a spring's EA and a node's mass and contact stiffness scale with its share of
 * the film. Its world; the web in *id. */
static ws_world *cylinder_band(int r, double H, int nu, double pre_up, const ws_web_def *solve,
                               ws_web_id *id)
{
    const double E = 2000.0 /* N/m per unit strain */, dz = H / (nu - 1);
    ws_world *w = world_g(1e-3, NO_G);
    ws_shape_id cs;
    ck_ok(w, ws_shape_create_cylinder(w, 0.1, 0.3, 128, &cs));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = cs;
    ws_body_id cyl;
    ck_ok(w, ws_body_create(w, &bd, &cyl));
    ws_material_def md;
    ws_material_def_init(&md);
    ws_material_id film, dflt;
    ck_ok(w, ws_material_create(w, &md, &film));
    ck_ok(w, ws_world_get_default_material(w, &dflt));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 4000.0 / (r * r);
    cd.damping = 1.0 / (r * r);
    cd.friction = 0.0;
    ck_ok(w, ws_world_set_contact(w, film, dflt, &cd));
    /* EA of a row: its share dz of the height (the edge rows a full share, as the band
     * generator makes them; the pressure divides by the rows' shares alike). */
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, E * dz, 0.0, 0.05 * E * dz, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.areal_density = 0.02;
    wd.node_damping = 0.5 / (r * r);
    wd.law = law;
    wd.material = film;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = solve->solver_tolerance;
    wd.solver_max_iterations = solve->solver_max_iterations;
    wd.preconditioner = solve->preconditioner;
    ws_band_def bdf;
    ws_band_def_init(&bdf);
    bdf.bodies = &cyl;
    bdf.body_count = 1;
    bdf.z_bottom = -H / 2;
    bdf.z_top = H / 2;
    bdf.n_around = 64 * r;
    bdf.n_up = nu;
    bdf.prestretch_around = 0.2;
    bdf.prestretch_up = pre_up;
    ck_ok(w, ws_web_create_band(w, &wd, &bdf, id));
    return w;
}

/* The band of cylinder_band refined r times from 64 x 5 (0.1 m tall), settled: the mean
 * contact pressure on the cylinder, Pa; the CG iterations a step into *iters. */
static double refined_band_pressure(int r, double *iters)
{
    const double R = 0.1, H = 0.1;
    const int na = 64 * r, nu = 4 * r + 1;
    const double dz = H / (nu - 1);
    ws_web_def solve;
    ws_web_def_init(&solve);
    solve.solver_tolerance = 1e-8;
    ws_web_id web;
    ws_world *w = cylinder_band(r, H, nu, 0.0, &solve, &web);
    ck_ok(w, ws_world_step_n(w, 300));
    ws_web_solver_stats st0, st;
    ck_ok(w, ws_web_get_solver_stats(w, web, &st0));
    ck_ok(w, ws_world_step_n(w, 20));
    ck_ok(w, ws_web_get_solver_stats(w, web, &st));
    *iters = (double)(st.iterations - st0.iterations) / 20.0;
    const size_t nn = (size_t)na * nu;
    double *fc = malloc(3 * nn * sizeof *fc);
    ck_assert(fc);
    size_t cnt;
    ck_ok(w, ws_web_copy_contact_forces(w, web, fc, nn, &cnt));
    double F = 0.0;
    for (size_t i = 0; i < nn; i++)
        F += sqrt(fc[3 * i] * fc[3 * i] + fc[3 * i + 1] * fc[3 * i + 1] +
                  fc[3 * i + 2] * fc[3 * i + 2]);
    free(fc);
    ck_assert(ws_web_is_valid(w, web));
    ws_world_destroy(w);
    return F / (2 * PI * R * nu * dz);
}

START_TEST(test_refined_band_pressure)
{
    /* The band's contact pressure is its hoop tension over the radius, T / R with T = E
     * (strain) per unit height, whatever the mesh: refining 2 x in each direction must leave
     * it within 2 % (the polygon's chord effect is 2e-4 at 64 around, the contact layer's
     * overlap k / kc 1e-3). */
    const int short_run = getenv("WS_TEST_SHORT") != NULL;
    double it1, it2;
    const double p1 = refined_band_pressure(1, &it1);
    const double p2 = short_run ? p1 : refined_band_pressure(2, &it2);
    if (short_run)
        it2 = it1;
    report("band pressure refined 1 x: %.3f Pa (%.1f CG it/step), 2 x: %.3f Pa (%.1f), rel %.2g",
           p1, it1, p2, it2, (p2 - p1) / p1);
    ck_assert_msg(p1 > 0.0 && fabs(p2 - p1) <= 0.02 * p1, "pressure %g vs %g", p2, p1);
}
END_TEST

/* The band of cylinder_band at 64 r x (16 r + 1) nodes, 0.16 m tall, stretched 20 % around
 * and pre_up up, solved with the multigrid to 1e-10 of each row's weight, after 20 steps of
 * BAND_DT with its next step begun (ws_implicit_begin): the world, its web into *out. */
#define BAND_DT 1e-3
static ws_world *band_begun(int r, double pre_up, ws_web **out)
{
    ws_web_def solve;
    ws_web_def_init(&solve);
    solve.solver_tolerance = 1e-10;
    solve.solver_max_iterations = 5000;
    solve.preconditioner = WS_WEB_PRECONDITIONER_MULTIGRID;
    ws_web_id id;
    ws_world *w = cylinder_band(r, 0.16, 16 * r + 1, pre_up, &solve, &id);
    ck_ok(w, ws_world_step_n(w, 20));
    ws_web *web = web_of(w, id);
    ck_assert_msg(web->imp && web->imp->mg, "the band takes the multigrid");
    const int cur = w->cur;
    ck_assert_int_eq(ws_implicit_begin(web, web->x[cur], web->v[cur], NO_G, w->time, 0.0), 0);
    *out = web;
    return w;
}

/* The film solve of band_begun's next step from zero: its iterations (the levels into
 * *levels). */
static int band_from_zero(int r, double pre_up, int *levels)
{
    const double dt = BAND_DT;
    ws_web *web;
    ws_world *w = band_begun(r, pre_up, &web);
    ws_implicit *im = web->imp;
    ws_nodes3 v = web->v[w->cur];
    im->warm = 0;
    ck_assert_int_eq(ws_implicit_solve(web, v, dt), 0);
    const int it = im->last_iterations;
    *levels = ws_mg_levels(im->mg);
    ws_world_destroy(w);
    return it;
}

START_TEST(test_band_multigrid_refined)
{
    /* Refined 2x in each direction, block Jacobi's iterations double (h^2 k / m grows 4x, the
     * square root of the condition number 2x) and a multigrid that carries the smooth error
     * keeps them flat (the drum of test_multigrid: 1.00x). A band stretched 20 % around and 2 %
     * up is held far more strongly around than up in its x and y motion (its first coarse
     * level 7600x by the blocks to the next node around and up, the next ones 3.1, 2.2, 2.0
     * and 1.6x), as the wrapped band is near its free edges. Point Gauss-Seidel on the coarse
     * levels leaves the error smooth around and rough up: from zero to 1e-10 of each row's
     * weight it took 114 -> 151 iterations refined 2x (and 265 at 4x). The rows where point
     * Jacobi takes under 0.35 off that error are solved whole (test_band_rows_chosen: every
     * row of this band's first two coarse levels): 11 -> 20 (32 at 4x). On this band, held
     * weakly up in every row, the lines' counts grow faster than the point sweeps' (1.8x
     * against 1.3x a refinement) from a tenth of them, so the bounds are absolute: 1.5x the
     * counts, for the contacts' state and the cycle's single-precision blocks; they fail by
     * 5-7x when the rows are swept point by point again. */
    int l1, l2;
    const int it1 = band_from_zero(1, 0.02, &l1);
    ck_assert_msg(it1 <= 17, "multigrid on the band from zero: %d iterations", it1);
    if (getenv("WS_TEST_SHORT"))
        return;
    const int it2 = band_from_zero(2, 0.02, &l2);
    report("band 20 %% around, 2 %% up, refined 2x: multigrid from zero %d (%d levels) -> %d "
           "(%d levels), %.2f x",
           it1, l1, it2, l2, (double)it2 / it1);
    ck_assert_msg(it2 <= 30, "multigrid degraded on the band: %d -> %d", it1, it2);
}
END_TEST

/* The rows of band_begun's band (refined r, up prestretch pre_up) that the first coarse level
 * solves whole, after a solve from zero, into *rows of *total. */
static void band_rows_whole(int r, double pre_up, int *rows, int *total)
{
    ws_web *web;
    ws_world *w = band_begun(r, pre_up, &web);
    ws_implicit *im = web->imp;
    im->warm = 0;
    ck_assert_int_eq(ws_implicit_solve(web, web->v[w->cur], BAND_DT), 0);
    *total = ws_mg_rows(im->mg, 1, rows);
    ws_world_destroy(w);
}

START_TEST(test_band_rows_chosen)
{
    /* Which rows a coarse level solves whole, from its own blocks: those where point Jacobi
     * takes under 0.35 off the error constant along the row and alternating up (multigrid.c,
     * row_held_along). On the band stretched 20 % around and 2 % up the first coarse level's
     * rows are held around about 10x more strongly than by their mass and the rows beside them
     * (the quotient 0.09 in x and y motion, every row alike): every row. Stretched 20 % up as
     * well, the up couplings are the around ones' after the around-only halving makes those 4x
     * weaker (the quotient 1.5 and more): no row, and the sweeps are the point sweeps. */
    int whole, rows;
    band_rows_whole(1, 0.02, &whole, &rows);
    report("band 20 %% around, 2 %% up: first coarse level solves %d of %d rows whole", whole,
           rows);
    ck_assert_msg(rows > 0 && whole == rows, "held 10x around: %d of %d rows whole", whole,
                  rows);
}
END_TEST

/* The checks of test_rows_mixed on web's multigrid as its last solve left it: the first two
 * coarse levels' rows set whole and node by node in turn (two of three, then one of three),
 * then B symmetric, positive, and the cycle contracting. */
static void rows_mixed_checks(ws_web *web, const char *what)
{
    ws_implicit *im = web->imp;
    const uint32_t n = web->n;
    int whole;
    for (int k = 1; k <= 2; k++) {
        const int rows = ws_mg_rows(im->mg, k, &whole);
        ck_assert_int_gt(rows, 2);
        for (int iy = 0; iy < rows; iy++)
            ck_assert_int_eq(ws_mg_set_row(im->mg, k, iy, (iy % 3 == 0) == (k == 2)), 0);
        (void)ws_mg_rows(im->mg, k, &whole);
        ck_assert_msg(whole > 0 && whole < rows, "%s, level %d: %d of %d rows whole", what, k,
                      whole, rows);
    }
    double *u = malloc(3 * n * sizeof(double)), *Bu = malloc(3 * n * sizeof(double));
    ck_assert(u && Bu);
    cycle_checks(web, what, u, Bu);
    ck_assert_int_eq(ws_mg_set_row(im->mg, 0, 0, 1), -1); /* the film's level has no rows */
    ck_assert_int_eq(ws_mg_set_row(im->mg, 1, ws_mg_rows(im->mg, 1, &whole), 1), -1);
    free(u), free(Bu);
}

static ws_world *choice_drum(int nx, int ny, int pre, double tol, ws_web_id *id, ws_status *st);

START_TEST(test_rows_mixed)
{
    /* A level whose rows are partly solved whole and partly node by node: the blocks of its
     * Gauss-Seidel sweeps are those rows and single nodes, taken in the grid's order forward
     * and in reverse backward, so the cycle must stay symmetric (u.Bv = v.Bu to round-off,
     * 1e-12 of |u||Bv|, as sheet_case) and positive definite, and as an iteration contract
     * (I - B A's factor below 1, B A's eigenvalues at most 1 + 1e-5: sheet_case says why).
     * On band_begun's band (closed rows: the last node's arrow) and on a drum (open rows, with
     * shear springs: couplings to the rows beside on the diagonals too). */
    ws_web *web;
    ws_world *w = band_begun(1, 0.02, &web);
    web->imp->warm = 0;
    ck_assert_int_eq(ws_implicit_solve(web, web->v[w->cur], BAND_DT), 0);
    rows_mixed_checks(web, "band");
    ws_world_destroy(w);

    ws_web_id id;
    ws_status st;
    w = choice_drum(41, 23, WS_WEB_PRECONDITIONER_MULTIGRID, 1e-11, &id, &st);
    ck_assert_msg(w, "the drum is made");
    ck_ok(w, ws_world_step_n(w, 5));
    web = web_of(w, id);
    ck_assert_msg(web->imp && web->imp->mg, "the drum takes the multigrid");
    const int cur = w->cur;
    ck_assert_int_eq(
        ws_implicit_begin(web, web->x[cur], web->v[cur], v3_make(0, 0, -G0), w->time, 0.0), 0);
    web->imp->warm = 0;
    ck_assert_int_eq(ws_implicit_solve(web, web->v[cur], 2e-3), 0);
    rows_mixed_checks(web, "drum");
    ws_world_destroy(w);
}
END_TEST

/* Bodies in the film's solve, pressed on the band of cylinder_band: a ws_rigid of nb bodies
 * (1 or 2; centres on the axis) whose contacts hold the first quarter of the band around (every
 * row), each of the band's contact stiffness for its share (4000 / r^2 N/m along the node's
 * radius, a fifth of it across: a stuck contact), 1 / r^2 N s/m of damping along the radius,
 * added to the film's matrix as the world adds a contact. One body: 0.5 kg, inertia 1e-3 kg m^2,
 * the whole quarter. Two: each half of it (body 0 the first eighth around, 0.5 kg; body 1 the
 * second, 0.8 kg; inertias 1e-3 and 2e-3 kg m^2), joined by the friction of a body contact in
 * the solve (ws_rigid_pair) where they meet, on the band's middle row, as a wrapped stack's
 * boxes are: at rest, c = 2 mu N / v_lim = 5e4 N s/m (mu 0.5, N 50 N, v_lim 1 mm/s) across the
 * radius, h c = 50 kg over the step, a hundred times the boxes' masses. The arrays are the
 * caller's to free (free_pressed). */
typedef struct press_case {
    ws_rigid R;
    uint32_t env[24];
    ws_rigid_pair pair;
    double *d;
    void *mgbuf;
} press_case;

static void press_body(ws_web *web, ws_nodes3 x, int r, double h, int nest, uint32_t nb,
                       press_case *o)
{
    ws_implicit *im = web->imp;
    const uint32_t n = web->n, nx = (uint32_t)web->nx, ny = (uint32_t)web->ny;
    const size_t v6 = 6 * (size_t)nb;
    ws_rigid *R = &o->R;
    memset(R, 0, sizeof *R);
    R->nb = nb;
    R->cap = n;
    R->link = calloc(n, sizeof *R->link);
    R->phi_node = calloc(n, sizeof *R->phi_node);
    R->phi_body = calloc(n, sizeof *R->phi_body);
    R->phi_lever = calloc(3 * (size_t)n, sizeof *R->phi_lever);
    R->crow = calloc((size_t)n + 1, sizeof *R->crow);
    R->cphi = calloc(2 * ((size_t)n + 1), sizeof *R->cphi);
    R->cwork = calloc(ws_rigid_coarse_words(n, nb), sizeof *R->cwork);
    o->d = calloc(nb * (1 + WS_SYM) + 3 * v6 * v6 + 8 * v6 + 6 * v6 + 18 * ((size_t)n + 1),
                  sizeof(double));
    ck_assert(R->link && R->phi_node && R->phi_body && R->phi_lever && R->crow && R->cphi &&
              R->cwork && o->d);
    double *d = o->d;
    R->b = d, R->x = d + v6, R->r = d + 2 * v6, R->z = d + 3 * v6, R->p = d + 4 * v6;
    R->q = d + 5 * v6, R->cb = d + 6 * v6, R->cq = d + 7 * v6;
    R->mass = d + 8 * v6;
    R->inertia = R->mass + nb;
    R->abb = R->inertia + nb * WS_SYM;
    R->fac = R->abb + v6 * v6;
    R->coarse = R->fac + v6 * v6;
    R->cyr = R->coarse + v6 * v6;
    R->cy = R->cyr + 6 * v6;
    R->env = o->env;
    for (uint32_t j = 0; j < nb; j++) {
        double *I = R->inertia + WS_SYM * j;
        R->mass[j] = j ? 0.8 : 0.5;
        I[WS_SYM_XX] = I[WS_SYM_YY] = I[WS_SYM_ZZ] = 1e-3 * (1 + j);
    }
    R->b[0] = h * 1.0; /* a newton along x, the rest from the contacts */
    if (nb == 2)
        R->b[7] = -h * 0.5; /* and half a newton along -y on the second body */
    const double k = 4000.0 / (r * r), c = 1.0 / (r * r);
    for (uint32_t i = 0; i < n; i++) {
        if (i % nx >= nx / 4 || web->inv_m[i] == 0.0)
            continue;
        const v3 p = v3_make(x.x[i], x.y[i], x.z[i]);
        const v3 e = v3_scale(v3_make(p.x, p.y, 0.0), 1.0 / sqrt(p.x * p.x + p.y * p.y));
        double K[WS_SYM] = {0}, D[WS_SYM] = {0};
        ws_sym_add_outer(K, 0.8 * k, e);
        K[WS_SYM_XX] += 0.2 * k, K[WS_SYM_YY] += 0.2 * k, K[WS_SYM_ZZ] += 0.2 * k;
        ws_sym_add_outer(D, c, e);
        ws_implicit_add(im, i, v3_make(0, 0, 0), K, D);
        ws_rigid_link *L = &R->link[R->nl++];
        L->node = i;
        L->body = nb == 2 && i % nx >= nx / 8;
        L->lever = p;
        for (int q = 0; q < WS_SYM; q++)
            L->C[q] = h * h * K[q] + h * D[q];
    }
    if (nb == 2) {
        const uint32_t m = nx / 8 + nx * (ny / 2);
        const v3 p = v3_make(x.x[m], x.y[m], x.z[m]);
        const v3 e = v3_scale(v3_make(p.x, p.y, 0.0), 1.0 / sqrt(p.x * p.x + p.y * p.y));
        const double hc = h * 2.0 * 0.5 * 50.0 / 1e-3;
        ws_rigid_pair *P = &o->pair;
        memset(P, 0, sizeof *P);
        P->a = 0, P->b = 1, P->ra = P->rb = p;
        ws_sym_add_outer(P->C, -hc, e);
        P->C[WS_SYM_XX] += hc, P->C[WS_SYM_YY] += hc, P->C[WS_SYM_ZZ] += hc;
        R->pair = P;
        R->npair = 1;
    }
    o->mgbuf = NULL;
    if (nest) {
        const size_t bytes = ws_mg_body_bytes(im->mg, nb, R->cap);
        ck_assert(bytes > 0);
        o->mgbuf = malloc(bytes);
        ck_assert(o->mgbuf);
    }
    R->mgbuf = o->mgbuf;
}

static void free_pressed(press_case *o)
{
    free(o->R.link), free(o->R.phi_node), free(o->R.phi_body), free(o->R.phi_lever);
    free(o->R.crow), free(o->R.cphi), free(o->R.cwork);
    free(o->d), free(o->mgbuf);
}

/* y = A x over the film (x, y) and the body (xb, yb) for the operator the last solve set;
 * returns x . y + xb . yb. */
static double coupled_apply(const ws_web *web, const ws_rigid *R, const double *x,
                            const double *xb, double *y, double *yb)
{
    return ws_implicit_apply_op(web, x, y) + ws_rigid_apply(R, web, x, xb, y, yb);
}

/* The band of band_from_zero (64 r x (16 r + 1) nodes, 20 % around, 2 % up, 20 steps) with
 * the body of press_body in its next solve, from zero to 1e-10 of each row's weight: its
 * iterations, the body nested in the multigrid (nest) or beside it (the block preconditioner
 * with the coarse space). With checks (nested), the cycle's symmetry and definiteness over
 * film and body. */
static int band_pressed(int r, int nest, int checks)
{
    const double dt = BAND_DT;
    ws_web *web;
    ws_world *w = band_begun(r, 0.02, &web);
    ws_implicit *im = web->imp;
    ws_nodes3 x = web->x[w->cur], v = web->v[w->cur];
    press_case pb;
    press_body(web, x, r, dt, nest, 1, &pb);
    ws_rigid *R = &pb.R;
    im->warm = 0;
    im->rig = R;
    ck_assert_int_eq(ws_implicit_solve(web, v, dt), 0);
    const int it = im->last_iterations;
    if (checks) {
        const uint32_t n = web->n;
        double *u = malloc(3 * n * sizeof(double)), *y = malloc(3 * n * sizeof(double)),
               *Bu = malloc(3 * n * sizeof(double)), *By = malloc(3 * n * sizeof(double));
        ck_assert(u && y && Bu && By);
        double ub[6] = {0.3, -0.2, 0.1, 0.05, -0.4, 0.2},
               yb[6] = {-0.1, 0.25, 0.3, -0.2, 0.1, 0.15};
        double Bub[6], Byb[6];
        random_vector(web, 7, u);
        random_vector(web, 8, y);
        /* B on (u, ub) and (y, yb): the nested cycle of the solve just made */
        (void)ws_mg_apply_bodies(im->mg, web, u, Bu, ub, Bub);
        (void)ws_mg_apply_bodies(im->mg, web, y, By, yb, Byb);
        double uBy = dot3(u, By, n), yBu = dot3(y, Bu, n), uBu = dot3(u, Bu, n);
        double nu = dot3(u, u, n), nBy = dot3(By, By, n);
        for (int k = 0; k < 6; k++) {
            uBy += ub[k] * Byb[k], yBu += yb[k] * Bub[k], uBu += ub[k] * Bub[k];
            nu += ub[k] * ub[k], nBy += Byb[k] * Byb[k];
        }
        const double scale = sqrt(nu * nBy);
        report("nested multigrid, band %d x %d with a body (%zu contacts): u.By %.12g, y.Bu "
               "%.12g (rel %.2g), u.Bu %.6g",
               web->nx, web->ny, R->nl, uBy, yBu, (uBy - yBu) / scale, uBu);
        ck_assert_msg(fabs(uBy - yBu) <= 1e-12 * scale, "B not symmetric: %.17g vs %.17g", uBy,
                      yBu);
        ck_assert_msg(uBu > 0.0, "B not positive");
        /* B A by power iteration in A's inner product, as in sheet_case: one V-cycle of the
         * coupled matrix has B A's eigenvalues in (0, 1] (up to the single-precision levels'
         * rounding) and I - B A contracts. */
        double *e = malloc(3 * n * sizeof(double)), *Ae = malloc(3 * n * sizeof(double)),
               *BAe = malloc(3 * n * sizeof(double));
        ck_assert(e && Ae && BAe);
        double lmax = 0.0, rho = 0.0;
        for (int pass = 0; pass < 2; pass++) {
            double eb[6] = {0.1, 0.2, -0.3, 0.4, -0.5, 0.6}, Aeb[6], BAeb[6];
            random_vector(web, 9 + (uint64_t)pass, e);
            for (int k = 0; k < 40; k++) {
                const double eAe = coupled_apply(web, R, e, eb, Ae, Aeb);
                (void)ws_mg_apply_bodies(im->mg, web, Ae, BAe, Aeb, BAeb);
                double lam = dot3(Ae, BAe, n);
                for (int q = 0; q < 6; q++)
                    lam += Aeb[q] * BAeb[q];
                lam /= eAe;
                if (pass)
                    lam = 1.0 - lam;
                const double norm = sqrt(eAe);
                for (uint32_t q = 0; q < 3 * n; q++)
                    e[q] = (pass ? e[q] - BAe[q] : BAe[q]) / norm;
                for (int q = 0; q < 6; q++)
                    eb[q] = (pass ? eb[q] - BAeb[q] : BAeb[q]) / norm;
                if (pass)
                    rho = lam;
                else
                    lmax = lam;
            }
        }
        report("nested cycle: largest eigenvalue of B A %.9f, factor of I - B A %.3f", lmax, rho);
        ck_assert_msg(lmax > 0.0 && lmax <= 1.0 + 1e-5, "B A's largest eigenvalue %.9f", lmax);
        ck_assert_msg(rho < 1.0, "the nested cycle does not contract: factor %g", rho);
        free(u), free(y), free(Bu), free(By), free(e), free(Ae), free(BAe);
    }
    im->rig = NULL;
    free_pressed(&pb);
    ws_world_destroy(w);
    return it;
}

START_TEST(test_band_bodies_nested)
{
    /* The body nested in the multigrid: its cycle over film and body is symmetric (to
     * rounding: 1e-12 of the product's scale, as the film's own in sheet_case) and positive
     * definite, one V-cycle of the coupled matrix (band_pressed's checks). Refined 2x in each
     * direction, the body's coupled modes are resolved on every level, so the coupled solve
     * from zero must grow no more than the film's multigrid did on a band before its coarse
     * levels swept by rows (1.32x, 1.5x allowed; here 1.31x, 130 -> 170 with point sweeps,
     * 1.28x, 124 -> 159 with the line sweeps): 1.5x again, and the nesting must take fewer
     * iterations than the body beside the multigrid (its own block and the coarse space of
     * its rigid motion: 155 and 197), at both sizes, or it is not worth its cost per
     * iteration. */
    const int n1 = band_pressed(1, 1, 1), b1 = band_pressed(1, 0, 0);
    ck_assert_msg(n1 < b1, "nested %d iterations, beside %d", n1, b1);
    if (getenv("WS_TEST_SHORT"))
        return;
    const int n2 = band_pressed(2, 1, 0), b2 = band_pressed(2, 0, 0);
    report("band with a body in the solve, from zero: nested %d -> %d (%.2f x), beside %d -> %d "
           "(%.2f x)",
           n1, n2, (double)n2 / n1, b1, b2, (double)b2 / b1);
    ck_assert_msg(n2 <= 1.5 * n1, "nested multigrid degraded: %d -> %d", n1, n2);
    ck_assert_msg(n2 < b2, "nested %d iterations, beside %d", n2, b2);
}
END_TEST

/* The solve of band_begun's next step (refinement r) from zero with press_body's two bodies in
 * it, nested in the multigrid (nest) or beside it, their block solved together or each alone
 * (apart): its iterations; the film's answer into dv (3 n, malloc'd, n into *n) and the
 * bodies' into xb (12). */
static int band_pair(int r, int nest, int apart, double **dv, uint32_t *n, double *xb)
{
    ws_web *web;
    ws_world *w = band_begun(r, 0.02, &web);
    ws_implicit *im = web->imp;
    press_case pc;
    press_body(web, web->x[w->cur], r, BAND_DT, nest, 2, &pc);
    ws_rigid *R = &pc.R;
    R->apart = apart;
    im->warm = 0;
    im->rig = R;
    ck_assert_int_eq(ws_implicit_solve(web, web->v[w->cur], BAND_DT), 0);
    im->rig = NULL;
    const int it = im->last_iterations;
    *n = web->n;
    *dv = malloc(3 * (size_t)web->n * sizeof(double));
    ck_assert(*dv);
    memcpy(*dv, im->dv, 3 * (size_t)web->n * sizeof(double));
    memcpy(xb, R->x, 12 * sizeof(double));
    free_pressed(&pc);
    ws_world_destroy(w);
    return it;
}

START_TEST(test_bodies_solved_together)
{
    /* Two bodies joined by a strong pair (press_body's two): the preconditioner that holds each body
     * alone leaves the pair's coupling of the two to the coarse space (beside the multigrid) or
     * to nothing at all (nested in it: a coarse level's sweep solves each body against the
     * nodes alone, and the bodies' residual it passes on keeps the pair's term), while
     * solving the bodies' block whole takes it exactly, on every level. The same system, so
     * the same answer (to 1e-9 of its size: both solves stop at 1e-10 of each row's weight
     * impulse, and the iterations differ). Nested, fewer iterations with the bodies together
     * (124 against 153), or the joint block is not worth its set-up. Beside the multigrid the
     * coarse space's Phi^T A Phi has the pair's coupling already (its body columns are the
     * bodies' unknowns) and the joint block adds nothing the additive sum lacked (165 against
     * 161): there it must cost no more than 5 %. */
    for (int nest = 1; nest >= 0; nest--) {
        double *dv1, *dv0, xb1[12], xb0[12];
        uint32_t n1, n0;
        const int together = band_pair(1, nest, 0, &dv1, &n1, xb1);
        const int alone = band_pair(1, nest, 1, &dv0, &n0, xb0);
        ck_assert_uint_eq(n1, n0);
        double dd = 0.0, ss = 0.0, db = 0.0, sb = 0.0;
        for (uint32_t q = 0; q < 3 * n1; q++)
            dd = fmax(dd, fabs(dv1[q] - dv0[q])), ss = fmax(ss, fabs(dv1[q]));
        for (int q = 0; q < 12; q++)
            db = fmax(db, fabs(xb1[q] - xb0[q])), sb = fmax(sb, fabs(xb1[q]));
        report("two bodies with a strong pair, %s the multigrid: %d iterations solved together, "
               "%d each alone; answers differ by %.2g of %.3g (film), %.2g of %.3g (bodies)",
               nest ? "nested in" : "beside", together, alone, dd, ss, db, sb);
        ck_assert_msg(dd <= 1e-9 * ss && db <= 1e-9 * sb, "answers differ: %g, %g", dd / ss,
                      db / sb);
        if (nest)
            ck_assert_msg(together < alone, "nested: together %d iterations, alone %d",
                          together, alone);
        else
            ck_assert_msg(together <= 1.05 * alone, "beside: together %d iterations, alone %d",
                          together, alone);
        free(dv1), free(dv0);
    }
}
END_TEST

START_TEST(test_bodies_warm_start)
{
    /* A step's bodies start from the warm film (ws_implicit_solve): a block Gauss-Seidel step,
     * the bodies' velocity change that solves their rows exactly given the film's start. So
     * when the film's start is the converged answer of the same system (two bodies of
     * press_body, their strong pair, solved to 1e-10 of each row's weight impulse), the
     * bodies' start is that answer too, to the first solve's own residual: the bodies' rows
     * then leave at most 1e-10 m g h of theirs, so their start lies within 1e-9 g h (m/s, and
     * rad/s times the lever of 0.1 m the band's radius gives a turning row) of the first
     * answer, and a second solve at 1e-8 meets its test before any iteration. Started from
     * rest, as every step's bodies were before, the same solve must iterate: its pressed nodes
     * carry C J dU at the start, far above the test. */
    ws_web *web;
    ws_world *w = band_begun(1, 0.02, &web);
    ws_implicit *im = web->imp;
    press_case pc;
    press_body(web, web->x[w->cur], 1, BAND_DT, 1, 2, &pc);
    ws_rigid *R = &pc.R;
    ws_nodes3 v = web->v[w->cur];
    im->warm = 0;
    im->rig = R;
    ck_assert_int_eq(ws_implicit_solve(web, v, BAND_DT), 0);
    const size_t m = 3 * (size_t)web->n;
    double *dv = malloc(m * sizeof(double)), xb[12];
    ck_assert(dv);
    memcpy(dv, im->dv, m * sizeof(double));
    memcpy(xb, R->x, sizeof xb);
    double size = 0.0;
    for (int q = 0; q < 12; q++)
        size = fmax(size, fabs(xb[q]));
    web->solver_tol = 1e-8;
    int its[2];
    for (int cold = 0; cold < 2; cold++) {
        memcpy(im->dv, dv, m * sizeof(double));
        memset(R->x, 0, sizeof xb); /* a new step's bodies */
        im->warm = 1;
        im->cold_bodies = cold;
        ck_assert_int_eq(ws_implicit_solve(web, v, BAND_DT), 0);
        its[cold] = im->last_iterations;
        double d = 0.0;
        for (int q = 0; q < 12; q++)
            d = fmax(d, fabs(R->x[q] - xb[q]) * (q % 6 < 3 ? 1.0 : 0.1));
        report("bodies started %s: %d iterations at 1e-8 from the 1e-10 answer, bodies' answer "
               "%.3g m/s from it (of %.3g)",
               cold ? "from rest" : "from the warm film", its[cold], d, size);
        if (!cold)
            ck_assert_msg(d <= 1e-9 * 9.81 * BAND_DT, "the bodies' start is %g m/s off", d);
    }
    ck_assert_msg(its[0] == 0, "warm bodies: %d iterations", its[0]);
    ck_assert_msg(its[1] > 0, "bodies from rest met the test at once");
    im->rig = NULL;
    im->cold_bodies = 0;
    free(dv);
    free_pressed(&pc);
    ws_world_destroy(w);
}
END_TEST

/* A drum of nx x ny nodes (the sheet of sheet_case at r = 1, its edge pinned) with
 * preconditioner pre and solve tolerance tol: its world, or NULL (the status in *st) when the
 * web is refused. */
static ws_world *choice_drum(int nx, int ny, int pre, double tol, ws_web_id *id, ws_status *st)
{
    ws_world *w = world_g(2e-3, (ws_vec3){0, 0, -G0});
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, 20.0, 0.0, 0.01, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-4;
    wd.law = wd.law_shear = law;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = tol;
    wd.solver_max_iterations = 5000;
    wd.preconditioner = pre;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = nx;
    sd.ny = ny;
    sd.spacing_x = sd.spacing_y = 0.01;
    sd.prestretch_x = 0.4;
    sd.prestretch_y = 0.2;
    sd.shear = 1;
    uint32_t *pins = malloc(2 * (size_t)(nx + ny) * sizeof *pins);
    ck_assert(pins);
    const size_t np = edge_pins(nx, ny, pins);
    sd.pinned = pins;
    sd.pinned_count = np;
    *st = ws_web_create_sheet(w, &wd, &sd, id);
    free(pins);
    if (*st != WS_OK) {
        ws_world_destroy(w);
        return NULL;
    }
    return w;
}

START_TEST(test_preconditioner_choice)
{
    /* Bad values are refused by name; MULTIGRID on a web it cannot serve (a grid of 4 x 4
     * nodes: WS_MG_MIN_NODES is 17, a coarse level and a coarsest one) too; AUTO takes the multigrid on a grid web from WS_WEB_MULTIGRID_AUTO_NODES
     * nodes on and block Jacobi below; BLOCK_JACOBI is taken as asked. */
    ws_web_id id;
    ws_status st;
    const int bad[] = {-1, 3, 99};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        ws_world *w = world_g(2e-3, (ws_vec3){0, 0, -G0});
        ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, 20.0, 0.0, 0.01, 0.0);
        ws_web_def wd;
        ws_web_def_init(&wd);
        ck_assert_int_eq(wd.preconditioner, WS_WEB_PRECONDITIONER_AUTO);
        wd.node_mass = 1e-4;
        wd.law = law;
        wd.integrator = WS_WEB_IMPLICIT;
        wd.preconditioner = bad[k];
        ws_sheet_def sd;
        ws_sheet_def_init(&sd);
        sd.nx = 3;
        sd.ny = 1;
        sd.spacing_x = sd.spacing_y = 0.01;
        ck_assert_int_eq(ws_web_create_sheet(w, &wd, &sd, &id), WS_ERR_INVALID_ARGUMENT);
        ck_assert_msg(strstr(ws_world_last_error(w), "preconditioner must be"), "%s",
                      ws_world_last_error(w));
        ws_world_destroy(w);
    }
    ck_assert_int_eq(WS_MG_MIN_NODES, 17);
    ck_assert_ptr_null(choice_drum(4, 4, WS_WEB_PRECONDITIONER_MULTIGRID, 1e-6, &id, &st));
    ck_assert_int_eq(st, WS_ERR_INVALID_ARGUMENT);
    const int nx = 40, ny = (WS_WEB_MULTIGRID_AUTO_NODES + nx - 1) / nx; /* nx ny >= AUTO */
    const struct {
        int ny, pre, mg;
    } cases[] = {{ny, WS_WEB_PRECONDITIONER_AUTO, 1},
                 {ny - 1, WS_WEB_PRECONDITIONER_AUTO, 0},
                 {ny, WS_WEB_PRECONDITIONER_BLOCK_JACOBI, 0},
                 {ny - 1, WS_WEB_PRECONDITIONER_MULTIGRID, 1}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        ws_world *w = choice_drum(nx, cases[k].ny, cases[k].pre, 1e-6, &id, &st);
        ck_assert_msg(w, "drum %d x %d refused", nx, cases[k].ny);
        ck_ok(w, ws_world_step_n(w, 1));
        const ws_implicit *im = web_of(w, id)->imp;
        ck_assert_msg((im->mg != NULL) == cases[k].mg, "%d x %d nodes, preconditioner %d: %s",
                      nx, cases[k].ny, cases[k].pre,
                      im->mg ? "multigrid" : "block Jacobi");
        ws_world_destroy(w);
    }
}
END_TEST

START_TEST(test_preconditioners_agree)
{
    /* The drum of sheet_case, 10 steps of its sag at tolerance 1e-11 with each preconditioner
     * through the public Def: each solve stops at 1e-11 of its scale, so dv agrees to about
     * that times the condition number (~1e3 here: 1e-7 of dv, as sheet_case measures), and the
     * positions, h times the sum of dv, to 1e-7 of the sag. */
    ws_web_id id[2];
    ws_world *w[2];
    ws_status st;
    double *x[2];
    uint64_t its[2];
    for (int k = 0; k < 2; k++) {
        w[k] = choice_drum(41, 23,
                           k ? WS_WEB_PRECONDITIONER_MULTIGRID
                             : WS_WEB_PRECONDITIONER_BLOCK_JACOBI,
                           1e-11, &id[k], &st);
        ck_assert(w[k]);
        ck_ok(w[k], ws_world_step_n(w[k], 10));
        ws_web_solver_stats ss;
        ck_ok(w[k], ws_web_get_solver_stats(w[k], id[k], &ss));
        its[k] = ss.iterations;
        x[k] = malloc(3 * 41 * 23 * sizeof(double));
        ck_assert(x[k]);
        size_t cnt;
        ck_ok(w[k], ws_web_copy_positions(w[k], id[k], x[k], 41 * 23, &cnt));
    }
    double diff = 0.0, sag = 0.0;
    for (size_t q = 0; q < 41 * 23; q++) {
        diff = fmax(diff, fabs(x[0][3 * q + 2] - x[1][3 * q + 2]));
        diff = fmax(diff, fabs(x[0][3 * q] - x[1][3 * q]));
        diff = fmax(diff, fabs(x[0][3 * q + 1] - x[1][3 * q + 1]));
        sag = fmax(sag, -x[0][3 * q + 2]);
    }
    report("drum 41 x 23, 10 steps at tolerance 1e-11: block Jacobi %llu iterations, multigrid "
           "%llu; positions apart by %.2g m of a sag of %.3g m",
           (unsigned long long)its[0], (unsigned long long)its[1], diff, sag);
    ck_assert_msg(sag > 0.0 && diff <= 1e-7 * sag, "apart by %g of %g", diff, sag);
    ck_assert_msg(its[1] < its[0], "multigrid %llu iterations, block Jacobi %llu",
                  (unsigned long long)its[1], (unsigned long long)its[0]);
    for (int k = 0; k < 2; k++) {
        free(x[k]);
        ws_world_destroy(w[k]);
    }
}
END_TEST

/* ---- 5. rigid bodies in the solve (web/coupled.c) ---- */

/* The contact force on node i with body 0 given velocity vb, spin wb and position rb (the
 * features prepared again at rb). */
static v3 force_with_body(ws_world *w, ws_web *web, const ws_ncand_list *cl, ws_nodes3 x,
                          ws_nodes3 v, ws_node_link *L, uint32_t i, v3 rb, v3 vb, v3 wb)
{
    ws_body_store *b = &w->bodies;
    ws_body_state *st = &b->st[w->cur];
    st->r[0] = rb;
    st->v[0] = vb;
    b->wg[0] = wb;
    w->node_geom.arena = &w->arena;
    ck_assert_int_eq(ws_node_geometry(b, &w->node_geom), 0);
    ws_node_prepare(b, w->cur, &w->node_geom, web);
    int cnt;
    const v3 f = contact_force(w, web, cl, x, v, L, i, &cnt);
    ck_assert_int_eq(cnt, 1);
    return f;
}

START_TEST(test_coupled_jacobian)
{
    /* The box and nodes of contact_jacobian, the box moving at (10, 20, 0) mm/s, the node on
     * the face at rest on it (where the matrix's blocks are the exact derivatives) and the
     * rim node slipping. The contact force's derivatives by the body's velocity V and spin W
     * equal -df/du J (J = [I, -[r]x], r the lever to the contact point) and those by its
     * position -df/dx, to 1e-6 of their size against central differences (steps 1e-8 m,
     * 1e-8 m/s, 1e-8 rad/s; at rest 1e-10 m/s: eq. 13's bend, as in contact_jacobian). Then
     * the coupled matrix's node-body block (ws_rigid_apply) for the face node at h = 1 ms
     * equals -(h df/dU + h^2 df/dr_b) column by column (the spin's position column by the
     * contact point's displacement e x r: the face turning with the body is left out, docs),
     * and its body-node block is its transpose to round-off. */
    ws_web *web;
    ws_nodes3 x, v = nodes_new(2);
    ws_world *w = box_two_nodes(&web, &x);
    const ws_ncand_list *cl = &web->contact->cand[web->contact->list];
    ws_node_link *L = calloc(cl->n + 1, sizeof *L);
    ws_node_exact *E = calloc(cl->n + 1, sizeof *E);
    ws_body_state *st = &w->bodies.st[w->cur];
    const v3 r0 = st->r[0], vb = st->v[0], wb0 = v3_make(0, 0, 0);
    const v3 slip[2] = {v3_make(0, 0, 0), v3_make(-7e-4, 0.02, -7e-4)};
    for (int i = 0; i < 2; i++) {
        v.x[i] = vb.x + slip[i].x, v.y[i] = vb.y + slip[i].y, v.z[i] = vb.z + slip[i].z;
    }
    const double h = 1e-3;
    for (uint32_t i = 0; i < 2; i++) {
        (void)force_with_body(w, web, cl, x, v, L, i, r0, vb, wb0);
        const ws_node_pass P = {&w->bodies, w->cur, &w->node_geom, w->node_par, cl->c,
                                x,          v,      0.0,           1.0,         NULL,
                            0};
        ws_node_exact exact;
        const size_t n = ws_node_links(&P, web, cl->n, NULL, 0.0, L, E);
        ws_node_link link;
        memset(&link, 0, sizeof link);
        memset(&exact, 0, sizeof exact);
        for (size_t k = 0; k < n; k++)
            if (L[k].node == i && L[k].active) {
                link = L[k];
                exact = E[k];
            }
        ck_assert(link.active);
        /* df/dU (3 x 6, velocity then spin) and df/dr_b (3 x 3) by central differences. */
        double FU[18], Fr[9];
        const double sv = i == 0 ? 1e-10 : 1e-8, sx = 1e-8;
        for (int k = 0; k < 6; k++) {
            const v3 e = v3_make(k % 3 == 0, k % 3 == 1, k % 3 == 2);
            const v3 vp = k < 3 ? v3_madd(vb, e, sv) : vb, vm = k < 3 ? v3_madd(vb, e, -sv) : vb;
            const v3 wp = k < 3 ? wb0 : v3_scale(e, sv), wm = k < 3 ? wb0 : v3_scale(e, -sv);
            const v3 fp = force_with_body(w, web, cl, x, v, L, i, r0, vp, wp);
            const v3 fm = force_with_body(w, web, cl, x, v, L, i, r0, vm, wm);
            FU[k] = (fp.x - fm.x) / (2 * sv);
            FU[6 + k] = (fp.y - fm.y) / (2 * sv);
            FU[12 + k] = (fp.z - fm.z) / (2 * sv);
            if (k >= 3)
                continue;
            const v3 gp = force_with_body(w, web, cl, x, v, L, i, v3_madd(r0, e, sx), vb, wb0);
            const v3 gm = force_with_body(w, web, cl, x, v, L, i, v3_madd(r0, e, -sx), vb, wb0);
            Fr[k] = (gp.x - gm.x) / (2 * sx);
            Fr[3 + k] = (gp.y - gm.y) / (2 * sx);
            Fr[6 + k] = (gp.z - gm.z) / (2 * sx);
        }
        (void)force_with_body(w, web, cl, x, v, L, i, r0, vb, wb0);
        /* The exact ones: -Jv J and -Jx. */
        double eU = 0, er = 0;
        for (int k = 0; k < 6; k++) {
            const v3 e = v3_make(k % 3 == 0, k % 3 == 1, k % 3 == 2);
            const v3 a = k < 3 ? e : v3_cross(e, link.lever);
            for (int row = 0; row < 3; row++) {
                const double want = -(exact.Jv[3 * row] * a.x + exact.Jv[3 * row + 1] * a.y +
                                      exact.Jv[3 * row + 2] * a.z);
                eU = fmax(eU, fabs(FU[6 * row + k] - want));
                if (k < 3)
                    er = fmax(er, fabs(Fr[3 * row + k] + exact.Jx[3 * row + k]));
            }
        }
        const double nU = max_abs(FU, 18), nr = max_abs(Fr, 9);
        report("coupled, node %u (%s): df/dU vs -Jv J %.2g of %.3g; df/dr_b vs -Jx %.2g of %.3g", i,
               i ? "rim, slipping" : "face, at rest", eU / nU, nU, er / nr, nr);
        ck_assert_msg(eU <= 1e-6 * nU, "node %u: df/dU off by %g of %g", i, eU, nU);
        ck_assert_msg(er <= 1e-6 * nr, "node %u: df/dr_b off by %g of %g", i, er, nr);
        if (i != 0)
            continue;
        /* The coupled matrix's blocks for this contact alone. */
        ws_rigid_link rl = {i, 0, link.lever, {0}};
        for (int s = 0; s < WS_SYM; s++)
            rl.C[s] = h * h * link.K[s] + h * link.D[s];
        double mass = 1.0, inertia[WS_SYM] = {0.1, 0.1, 0.1, 0, 0, 0};
        double pr[6], yr[6], pn[6] = {0}, yn[6];
        ws_rigid R;
        memset(&R, 0, sizeof R);
        R.nb = 1;
        R.nl = R.cap = 1;
        R.link = &rl;
        R.mass = &mass;
        R.inertia = inertia;
        double Anb[18], Abn[18];
        for (int k = 0; k < 6; k++) {
            memset(pr, 0, sizeof pr);
            memset(yn, 0, sizeof yn);
            pr[k] = 1.0;
            (void)ws_rigid_apply(&R, web, pn, pr, yn, yr);
            for (int row = 0; row < 3; row++)
                Anb[6 * row + k] = yn[row];
        }
        for (int k = 0; k < 3; k++) {
            memset(pr, 0, sizeof pr);
            memset(yn, 0, sizeof yn);
            pn[k] = 1.0;
            (void)ws_rigid_apply(&R, web, pn, pr, yn, yr);
            pn[k] = 0.0;
            for (int row = 0; row < 6; row++)
                Abn[3 * row + k] = yr[row];
        }
        double eA = 0, eT = 0, nA = 0;
        for (int k = 0; k < 6; k++) {
            const v3 e = v3_make(k % 3 == 0, k % 3 == 1, k % 3 == 2);
            const v3 a = k < 3 ? e : v3_cross(e, link.lever);
            for (int row = 0; row < 3; row++) {
                const double pos_part = Fr[3 * row] * a.x + Fr[3 * row + 1] * a.y +
                                        Fr[3 * row + 2] * a.z;
                const double want = -(h * FU[6 * row + k] + h * h * pos_part);
                eA = fmax(eA, fabs(Anb[6 * row + k] - want));
                nA = fmax(nA, fabs(want));
                eT = fmax(eT, fabs(Anb[6 * row + k] - Abn[3 * k + row]));
            }
        }
        report("coupled matrix, face node: node-body block vs -(h df/dU + h^2 df/dr_b) %.2g of "
               "%.3g; body-node block vs its transpose %.2g",
               eA / nA, nA, eT / nA);
        ck_assert_msg(eA <= 1e-6 * nA, "node-body block off by %g of %g", eA, nA);
        ck_assert_msg(eT <= 1e-14 * nA, "blocks not each other's transpose: %g", eT);
    }
    free(L);
    free(E);
    free(x.x);
    free(v.x);
    ws_world_destroy(w);
}
END_TEST

/* A film's and a box's materials in w, their contact 4000 N/m, 1 N s/m, friction 0.5. */
static void film_and_box(ws_world *w, ws_material_id *film, ws_material_id *box)
{
    ws_material_def md;
    ws_material_def_init(&md);
    ck_ok(w, ws_material_create(w, &md, film));
    ck_ok(w, ws_material_create(w, &md, box));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 4000.0;
    cd.damping = 1.0;
    cd.friction = 0.5;
    ck_ok(w, ws_world_set_contact(w, *film, *box, &cd));
}

/* A body def of a 0.1 m cube of the box's material of film_and_box (made here, the film's
 * into *film), at rest at the origin: the caller sets its type, mass and place. */
static void cube_and_film(ws_world *w, ws_material_id *film, ws_body_def *bd)
{
    ws_shape_id cube;
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &cube));
    ws_material_id box_mat;
    film_and_box(w, film, &box_mat);
    ws_body_def_init(bd);
    bd->shape = cube;
    bd->material = box_mat;
}

/* A free square implicit film of n x n nodes of mass m, `spacing` apart from `origin` in the xy
 * plane, its springs at rest length (the linear viscoelastic law, 100 N/m, 0.2 N s/m), of
 * material film, solved to tolerance tol. */
static ws_web_id free_film(ws_world *w, ws_material_id film, double m, double tol, uint32_t n,
                           ws_vec3 origin, double spacing)
{
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = m;
    wd.law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, 100.0, 0.0, 0.2, 0.0);
    wd.material = film;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = tol;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = sd.ny = n;
    sd.origin = origin;
    sd.spacing_x = sd.spacing_y = spacing;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    return web;
}

/* A box of `mass` kg, 0.1 m a side, dropped from rest just touching the middle of a square
 * implicit sheet (0.4 m, 21 x 21 nodes, its border pinned, pre-stretched 5 %) under gravity,
 * at step dt, the box held during the film's solve or in it; after T s: the box's speed, the
 * film's contact forces summed (what holds the box up), the box's largest speed over the last
 * half second, and the step's status. */
typedef struct sling {
    ws_status status;
    double speed, fz, late_speed, drop;
} sling;

static sling box_on_sheet(double dt, double mass, int hold, int plain, double T)
{
    sling o = {WS_OK, NAN, NAN, 0.0, NAN};
    ws_world *w = world_g(dt, (ws_vec3){0, 0, -G0});
    ws_material_id film_mat;
    ws_body_def bd;
    cube_and_film(w, &film_mat, &bd);
    bd.mass = mass;
    bd.position = v3_make(0.0, 0.0, 0.05 + 1.9e-3);
    ws_body_id body;
    ck_ok(w, ws_body_create(w, &bd, &body));
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, 200.0, 0.0, 0.5, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-4;
    wd.node_damping = 0.002;
    wd.law = law;
    wd.material = film_mat;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = 1e-9;
    wd.hold_bodies = hold;
    enum { N = 21 };
    uint32_t pins[4 * N];
    const size_t np = edge_pins(N, N, pins);
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = N;
    sd.ny = N;
    sd.origin = v3_make(-0.2, -0.2, 0.0);
    sd.spacing_x = sd.spacing_y = 0.02;
    sd.prestretch_x = sd.prestretch_y = 0.05;
    sd.pinned = pins;
    sd.pinned_count = np;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    if (plain) { /* block Jacobi, no coarse space: the preconditioners' comparison */
        ck_assert_int_eq(ws_implicit_reserve(&w->mem, web_of(w, web)), 0);
        web_of(w, web)->imp->jacobi_only = 1;
    }
    const long steps = lround(T / dt), late = lround(fmin(0.5, T) / dt);
    ws_vec3 r0, r, vb;
    ck_ok(w, ws_body_get_position(w, body, &r0));
    for (long k = 0; k < steps; k++) {
        if ((o.status = ws_world_step(w)) != WS_OK)
            break;
        ck_ok(w, ws_body_get_velocity(w, body, &vb));
        if (k >= steps - late)
            o.late_speed = fmax(o.late_speed, v3_norm(vb));
    }
    if (o.status == WS_OK) {
        double fc[3 * N * N];
        size_t cnt;
        ck_ok(w, ws_web_copy_contact_forces(w, web, fc, N * N, &cnt));
        o.fz = 0.0;
        for (size_t i = 0; i < cnt; i++)
            o.fz -= fc[3 * i + 2];
        ck_ok(w, ws_body_get_velocity(w, body, &vb));
        ck_ok(w, ws_body_get_position(w, body, &r));
        o.speed = v3_norm(vb);
        o.drop = r0.z - r.z;
    }
    ws_world_destroy(w);
    return o;
}

START_TEST(test_body_on_film)
{
    /* At rest the film holds the box up with its weight: the contact forces on it sum to m g
     * (1e-6: the solve stops at 1e-9 of the step's impulse, and what is left of the settling
     * after 3 s, the box's speed below 0.1 mm/s over the last half second, is checked too).
     * Bodies in the solve, at dt 1 ms and 5 ms: the penalty contacts of the nodes under the
     * box (tens of 4000 N/m on 0.05 kg) would give a held box an explicit spring of omega
     * above 1000 rad/s, past 2 / dt at 5 ms. Held, the same box at 5 ms does not come to
     * rest (its speed over the last half second stays above 1 mm/s, or the step fails): the
     * bodies in the solve are what let the large step settle. */
    const double m = 0.05;
    const double dts[2] = {1e-3, 5e-3};
    for (int k = 0; k < 2; k++) {
        const sling s = box_on_sheet(dts[k], m, 0, 0, 3.0);
        report("box %.2f kg on the film, bodies in the solve, dt %.0f ms: film holds %.6f N "
               "against m g %.6f N (rel %.2g), box drops %.2f mm, speed %.2g m/s (last 0.5 s "
               "<= %.2g)",
               m, 1e3 * dts[k], s.fz, m * G0, (s.fz - m * G0) / (m * G0), 1e3 * s.drop,
               s.speed, s.late_speed);
        ck_assert_int_eq(s.status, WS_OK);
        ck_assert_msg(fabs(s.fz - m * G0) <= 1e-6 * m * G0, "film holds %g, weight %g", s.fz,
                      m * G0);
        ck_assert_msg(s.late_speed < 1e-4, "box still moving at %g m/s", s.late_speed);
    }
    /* After 0.015 s (3 steps, the box still sinking), the preconditioner with the bodies'
     * coarse space and block Jacobi without it reach the same state: the box's drop agrees to
     * 1e-7 of it (solves at 1e-9 of the step's impulse). */
    const sling fast = box_on_sheet(5e-3, m, 0, 0, 0.015),
                plain = box_on_sheet(5e-3, m, 0, 1, 0.015);
    report("after 0.015 s at dt 5 ms: drop %.9g m with the coarse space, %.9g m without (rel %.2g)",
           fast.drop, plain.drop, (fast.drop - plain.drop) / plain.drop);
    ck_assert_int_eq(fast.status, WS_OK);
    ck_assert_int_eq(plain.status, WS_OK);
    ck_assert_msg(fabs(fast.drop - plain.drop) <= 1e-7 * fabs(plain.drop), "%g vs %g", fast.drop,
                  plain.drop);
    const sling held = box_on_sheet(5e-3, m, 1, 0, 3.0);
    report("held at dt 5 ms: status %d, last 0.5 s speed <= %.3g m/s, film holds %.4g N",
           (int)held.status, held.late_speed, held.fz);
    ck_assert_msg(held.status != WS_OK || held.late_speed > 1e-3,
                  "held box settled (%g m/s): the test no longer tells the couplings apart",
                  held.late_speed);
}
END_TEST

START_TEST(test_film_body_momentum)
{
    /* No gravity, nothing pinned: a 0.2 kg box at (0.1, 0.05, -0.4) m/s and spinning at 2
     * rad/s strikes a free square of film (11 x 11 nodes of 0.1 g) off its middle, the box in
     * the film's solve. Whatever the film takes from the box it gives back: the total linear
     * momentum stays that of the start, to 1e-9 of it over 0.3 s at dt 1 ms (the solve's
     * tolerance 1e-11 bounds each step's residual impulse; 300 steps of it). */
    ws_world *w = world_g(1e-3, NO_G);
    ws_material_id film_mat;
    ws_body_def bd;
    cube_and_film(w, &film_mat, &bd);
    const double mb = 0.2, mn = 1e-4;
    bd.mass = mb;
    bd.position = v3_make(0.02, -0.01, 0.053);
    bd.velocity = v3_make(0.1, 0.05, -0.4);
    bd.angular_velocity = v3_make(0.0, 0.0, 2.0);
    ws_body_id body;
    ck_ok(w, ws_body_create(w, &bd, &body));
    enum { N = 11 };
    const ws_web_id web = free_film(w, film_mat, mn, 1e-11, N, v3_make(-0.1, -0.1, 0.0), 0.02);
    double vn[3 * N * N];
    size_t cnt;
    v3 P0 = v3_make(0, 0, 0);
    double worst = 0.0, contact = 0.0;
    for (int k = 0; k <= 300; k++) {
        if (k > 0)
            ck_ok(w, ws_world_step(w));
        ws_vec3 vb;
        ck_ok(w, ws_body_get_velocity(w, body, &vb));
        ck_ok(w, ws_web_copy_velocities(w, web, vn, N * N, &cnt));
        v3 P = v3_scale(vb, mb);
        for (size_t i = 0; i < cnt; i++)
            P = v3_add(P, v3_make(mn * vn[3 * i], mn * vn[3 * i + 1], mn * vn[3 * i + 2]));
        if (k == 0)
            P0 = P;
        worst = fmax(worst, v3_norm(v3_sub(P, P0)));
        double fc[3 * N * N];
        ck_ok(w, ws_web_copy_contact_forces(w, web, fc, N * N, &cnt));
        double F = 0.0;
        for (size_t i = 0; i < cnt; i++)
            F += fabs(fc[3 * i + 2]);
        contact = fmax(contact, F);
    }
    report("box striking a free film, bodies in the solve: total momentum drifts %.2g of %.3g "
           "N s over 0.3 s (largest contact force %.3g N)",
           worst, v3_norm(P0), contact);
    ck_assert_msg(contact > 0.1, "the box never pressed the film (%g N)", contact);
    ck_assert_msg(worst <= 1e-9 * v3_norm(P0), "momentum drifts %g of %g", worst, v3_norm(P0));
    ws_world_destroy(w);
}
END_TEST

/* Every node of the web at velocity u. */
static void film_set_velocity(ws_world *w, ws_web_id web, ws_vec3 u)
{
    const ws_web *wb = web_of(w, web);
    const ws_nodes3 V = wb->v[w->cur];
    for (size_t i = 0; i < wb->n; i++)
        V.x[i] = u.x, V.y[i] = u.y, V.z[i] = u.z;
}

/* After a step, the most a node's velocity is off u (into *dv) and its contact force off
 * (0, 0, fz) (into *df), each kept as the larger of what it holds and the step's. */
static void film_departure(ws_world *w, ws_web_id web, ws_vec3 u, double fz, double *dv,
                           double *df)
{
    enum { MOST = 64 };
    double vn[3 * MOST], fc[3 * MOST];
    size_t nv = 0, nf = 0;
    ck_ok(w, ws_web_copy_velocities(w, web, vn, MOST, &nv));
    ck_ok(w, ws_web_copy_contact_forces(w, web, fc, MOST, &nf));
    ck_assert(nv == nf && nv <= MOST);
    for (size_t i = 0; i < nv; i++) {
        const v3 d = v3_make(vn[3 * i] - u.x, vn[3 * i + 1] - u.y, vn[3 * i + 2] - u.z);
        *dv = fmax(*dv, v3_norm(d));
        *df = fmax(*df, v3_norm(v3_make(fc[3 * i], fc[3 * i + 1], fc[3 * i + 2] - fz)));
    }
}

/* Galilean invariance of the node contacts' active set: no gravity, a free square of film (5 x
 * 5 nodes of 0.1 mg, its springs at rest length) lies flat under a free 0.1 m box, the box's
 * face `gap` outside the contact window (the two 1 mm layers), the box in the film's solve, and
 * both move at velocity u, at dt 1 ms. After `steps` steps: the largest change of any node's
 * velocity and of the box's (m/s), and the largest contact force on a node (N). */
static void film_under_moving_box(ws_vec3 u, double gap, int steps, double out[3])
{
    ws_world *w = world_g(1e-3, NO_G);
    ws_material_id film_mat;
    ws_body_def bd;
    cube_and_film(w, &film_mat, &bd);
    bd.mass = 1.0;
    bd.position = v3_make(0.0, 0.0, 0.05 + 2e-3 + gap);
    bd.velocity = u;
    ws_body_id body;
    ck_ok(w, ws_body_create(w, &bd, &body));
    enum { N = 5 };
    const ws_web_id web = free_film(w, film_mat, 1e-7, 1e-9, N, v3_make(-0.02, -0.02, 0.0), 0.01);
    /* The nodes start at the box's velocity. */
    film_set_velocity(w, web, u);
    out[0] = out[1] = out[2] = 0.0;
    for (int k = 0; k < steps; k++) {
        ck_ok(w, ws_world_step(w));
        film_departure(w, web, u, 0.0, &out[0], &out[2]);
        ws_vec3 vb;
        ck_ok(w, ws_body_get_velocity(w, body, &vb));
        out[1] = fmax(out[1], v3_norm(v3_sub(vb, u)));
    }
    ws_world_destroy(w);
}

START_TEST(test_moving_face_galilean)
{
    /* A film 50 um outside a box's contact window, both at rest, never touches it. Moving
     * together at 0.2 m/s along the face's normal (the box ahead, the film following: it
     * covers 200 um a step, four times the gap, but the gap does not close), or across it,
     * nothing changes either: the nodes and the box keep their velocity (to 1e-12 m/s) and
     * no contact force acts. A node's reach of the face within the step is its motion
     * relative to the face's point, as the solve takes it; by its own speed alone the film
     * would be brought into contact every step and pulled onto the receding face (the
     * stack turning with the platform in case R, docs/theory.md 8b). */
    const ws_vec3 us[3] = {{0, 0, 0}, {0, 0, 0.2}, {0.2, 0, 0}};
    const char *name[3] = {"at rest", "along the normal", "across it"};
    for (int k = 0; k < 3; k++) {
        double o[3];
        film_under_moving_box(us[k], 50e-6, 40, o);
        report("film 50 um off a box's window, %s: node velocity off by <= %.3g m/s, box by "
               "%.3g m/s, contact force <= %.3g N",
               name[k], o[0], o[1], o[2]);
        ck_assert_msg(o[0] <= 1e-12, "%s: nodes' velocity changed by %g m/s", name[k], o[0]);
        ck_assert_msg(o[1] <= 1e-12, "%s: box's velocity changed by %g m/s", name[k], o[1]);
        ck_assert_msg(o[2] == 0.0, "%s: contact force %g N", name[k], o[2]);
    }
}
END_TEST

/* A world element's drive: from the origin at the steady velocity *user, not turning. */
static int steady_drive(void *user, double t, ws_pose *pose, ws_vec3 *v, ws_vec3 *om)
{
    const ws_vec3 *u = user;
    pose->position = v3_scale(*u, t);
    pose->orientation = (ws_quat){1.0, 0.0, 0.0, 0.0};
    *v = *u;
    *om = (ws_vec3){0.0, 0.0, 0.0};
    return 0;
}

/* A film lying on a kinematic box's top face under gravity (5 x 5 nodes of 10 mg, 1 cm apart,
 * its springs at rest length, film_and_box's contact: 4000 N/m, 1 kg/s, mu 0.5), the box and
 * the film moving at velocity u, at dt 1 ms, for `steps` steps from the film resting in the
 * window by its weight's penetration m g / k. The box is a world element (its motion given, not
 * in the film's solve). Out: the largest change of a node's velocity relative to u (m/s), and
 * the largest departure of a node's contact force from its weight (N). */
static void film_on_kinematic_box(ws_vec3 u, int steps, double out[2])
{
    const double dt = 1e-3, m = 1e-5, k = 4000.0;
    ws_world *w = world_g(dt, (ws_vec3){0, 0, -G0});
    ws_material_id film_mat;
    ws_body_def bd;
    cube_and_film(w, &film_mat, &bd);
    bd.type = WS_BODY_KINEMATIC;
    ws_body_id body;
    ck_ok(w, ws_body_create(w, &bd, &body));
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    dd.type = WS_DRIVE_CALLBACK;
    dd.callback = steady_drive;
    dd.callback_user = &u;
    ck_ok(w, ws_body_set_drive(w, body, &dd));
    enum { N = 5 };
    /* In the two 1 mm layers' window, pressed in by its weight. */
    const ws_web_id web =
        free_film(w, film_mat, m, 1e-9, N, v3_make(-0.02, -0.02, 0.05 + 2e-3 - m * G0 / k), 0.01);
    film_set_velocity(w, web, u);
    out[0] = out[1] = 0.0;
    for (int s = 0; s < steps; s++) {
        ck_ok(w, ws_world_step(w));
        film_departure(w, web, u, m * G0, &out[0], &out[1]);
    }
    ws_world_destroy(w);
}

START_TEST(test_kinematic_face_galilean)
{
    /* A film resting on a world element's face by its weight: at rest, the face holds each
     * node with its weight, m g = 9.8e-5 N, and nothing moves. Moving together at a steady
     * 0.2 m/s along the face's normal (up or down) or across it, the same: the step is the
     * same in the box's frame. The contact's linear model over the step takes the node's motion
     * relative to the face's point (the face rises h u_n = 0.2 mm a step, 8000 times the
     * penetration); a face taken at rest over the step would lose k h u_n = 0.8 N a node from
     * the model's force and let the film fall off a rising face, or jam it into a falling one.
     * Bounds: the velocities to 1e-9 m/s and the forces to 1e-6 of the weight (the solve's
     * tolerance 1e-9 of each node's weight impulse, over 100 steps; round-off of positions
     * 0.05 m against a 25 nm penetration: 1e-17 m, 4e-14 N). */
    const double weight = 1e-5 * G0;
    const ws_vec3 us[4] = {{0, 0, 0}, {0, 0, 0.2}, {0, 0, -0.2}, {0.2, 0, 0}};
    const char *name[4] = {"at rest", "rising", "sinking", "across"};
    for (int k = 0; k < 4; k++) {
        double o[2];
        film_on_kinematic_box(us[k], 100, o);
        report("film resting on a moving kinematic face, %s: node velocity off by <= %.3g "
               "m/s, contact force off the weight by <= %.3g of it",
               name[k], o[0], o[1] / weight);
        ck_assert_msg(o[0] <= 1e-9, "%s: nodes' velocity changed by %g m/s", name[k], o[0]);
        ck_assert_msg(o[1] <= 1e-6 * weight, "%s: contact force off the weight by %g N",
                      name[k], o[1]);
    }
}
END_TEST

/* A drum of the real film (31 x 31 nodes 1 cm apart, 0.018 kg/m^2: 1.8 mg a node, pre-stretched
 * 40 % and 20 %, its edge pinned, the film's law of bench_implicit's drums) over a box whose
 * top face starts 0.5 mm under it, inside the nodes' 1 mm contact layer, and rises 5 mm into it
 * at 2 Hz (a kinematic drive), at dt 1 ms, block Jacobi, the solve's tolerance tol and its
 * stopping test (relative: the earlier one). The film tents over the box's edges as a wrap
 * over a load's corners, its pressed nodes held between the pretension and the contacts'
 * forces, 1e4 of their weight. After `steps` steps: the last solve's residual recomputed from
 * its matrix, b - A dv (not the CG's running residual), each row's over its own weight impulse
 * m g h: the largest over the nodes without contacts (worst[0]) and with (worst[1]). */
static void pressed_drum(double tol, int relative, int steps, double worst[2])
{
    const double dt = 1e-3;
    ws_world *w = world_g(dt, (ws_vec3){0, 0, -G0});
    ws_material_id film_mat;
    ws_body_def bd;
    cube_and_film(w, &film_mat, &bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.position = v3_make(0.0, 0.0, -0.05 - 0.5e-3);
    ws_body_id box;
    ck_ok(w, ws_body_create(w, &bd, &box));
    ws_drive_def dd; /* the box rises into the film: 5 mm at 2 Hz */
    ws_drive_def_init(&dd);
    dd.type = WS_DRIVE_SINE;
    dd.direction = v3_make(0.0, 0.0, 1.0);
    dd.amplitude = 5e-3;
    dd.frequency = 2.0;
    dd.ramp_time = 0.0;
    ck_ok(w, ws_body_set_drive(w, box, &dd));
    ws_law_id law = make_law(w, WS_LAW_TENSION_COMPRESSION, 2000.0 * 0.01 / 1.4,
                             0.01 * 2000.0 * 0.01 / 1.4, 0.1 * 0.01 / 1.4, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.areal_density = 0.018;
    wd.law = wd.law_shear = law;
    wd.material = film_mat;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = tol;
    wd.solver_max_iterations = 20000;
    wd.preconditioner = WS_WEB_PRECONDITIONER_BLOCK_JACOBI;
    enum { N = 31 };
    uint32_t pins[4 * N];
    const size_t np = edge_pins(N, N, pins);
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = sd.ny = N;
    sd.origin = v3_make(-0.15, -0.15, 0.0);
    sd.spacing_x = sd.spacing_y = 0.01;
    sd.prestretch_x = 0.4;
    sd.prestretch_y = 0.2;
    sd.shear = 1;
    sd.pinned = pins;
    sd.pinned_count = np;
    ws_web_id id;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &id));
    ws_web *web = web_of(w, id);
    ck_assert_int_eq(ws_implicit_reserve(&w->mem, web), 0);
    web->imp->stop_relative = relative;
    ck_ok(w, ws_world_step_n(w, steps));
    const ws_implicit *im = web->imp;
    double *y = malloc(3 * (size_t)web->n * sizeof *y);
    ck_assert(y);
    ws_implicit_apply(web, dt, im->dv, y);
    worst[0] = worst[1] = 0.0;
    for (uint32_t i = 0; i < web->n; i++) {
        int pressed = 0;
        for (int k = 0; k < WS_SYM; k++)
            pressed |= im->kc[WS_SYM * (size_t)i + k] != 0.0;
        double s = 0.0;
        for (int k = 0; k < 3; k++) {
            const double r = im->b[3 * i + k] - y[3 * i + k];
            s += r * r;
        }
        worst[pressed] = fmax(worst[pressed], sqrt(s) * web->inv_m[i] / (G0 * dt));
    }
    free(y);
    ws_world_destroy(w);
}

START_TEST(test_stop_on_rows)
{
    /* The solve stops when every row's residual is at most tol m g h, its own weight impulse
     * over the step, tol the default 1e-3: recomputed from the matrix, no row, a light
     * pressed node's as a free one's, is left above it. The bound is 1.5 tol, not tol: the
     * CG's running residual, which the solve reads, drifts from b - A dv by round-off, eps
     * times the rows' forces times the iterations (the pressed nodes' 1e4 of their weight,
     * a few hundred iterations: under 1e-9 of it), and 0.5 tol leaves room for that. The
     * earlier test, the residual's norm at most 1e-6 of the right-hand side's, whose norm is
     * the pretension's and contacts' forces (2e4 of the film's weight impulse here), leaves
     * the pressed rows above the new bound: 5 tol after 100 steps (asserted above 3 tol,
     * twice the bound the rows' test keeps), so that the case goes on telling the two tests
     * apart. (Before the film's static friction, its nodes creeping over the box's face by eq.
     * 13 alone, their friction put 15 tol there after 60 steps; sticking, 1.7 tol.) */
    double rows[2], old[2];
    ws_web_def wd;
    ws_web_def_init(&wd);
    const double tol = wd.solver_tolerance;
    ck_assert(tol == 1e-3);
    pressed_drum(tol, 0, 100, rows);
    pressed_drum(1e-6, 1, 100, old);
    report("real film over a rising box, dt 1 ms, after 100 steps: worst row residual over m g h: "
           "rows test at %g: free %.3g, pressed %.3g; relative test at 1e-6: free %.3g, "
           "pressed %.3g",
           tol, rows[0], rows[1], old[0], old[1]);
    ck_assert_msg(rows[1] > 0.0, "no node pressed the box");
    ck_assert_msg(rows[0] <= 1.5 * tol && rows[1] <= 1.5 * tol, "rows %g %g over %g", rows[0],
                  rows[1], tol);
    ck_assert_msg(old[1] > 3.0 * tol, "the relative test left %g: no longer shows the rows' need",
                  old[1]);
}
END_TEST

/* Phi^T A Phi column by column, as the coarse space's set-up computed it before it took the
 * columns of a body at once: Phi e_c into the film (each node once a body), the coupled
 * operator (ws_implicit_apply_op, ws_rigid_apply), Phi^T of the result; symmetrised by the
 * mean. Into A (nc x nc). */
static void coarse_by_columns(const ws_rigid *R, const ws_web *web, double *A)
{
    const size_t nc = 6 * (size_t)R->nb, m = 3 * (size_t)web->n;
    double *fa = malloc(m * sizeof(double)), *fb = malloc(m * sizeof(double));
    double *cb = malloc(nc * sizeof(double)), *cq = malloc(nc * sizeof(double));
    ck_assert(fa && fb && cb && cq);
    for (size_t c = 0; c < nc; c++) {
        memset(cb, 0, nc * sizeof(double));
        memset(fa, 0, m * sizeof(double));
        cb[c] = 1.0;
        for (size_t k = 0; k < R->nphi; k++) {
            const double *C = cb + 6 * (size_t)R->phi_body[k], *r = R->phi_lever + 3 * k;
            const v3 u = v3_add(v3_make(C[0], C[1], C[2]),
                                v3_cross(v3_make(C[3], C[4], C[5]), v3_make(r[0], r[1], r[2])));
            double *y = fa + 3 * (size_t)R->phi_node[k];
            y[0] += u.x, y[1] += u.y, y[2] += u.z;
        }
        (void)ws_implicit_apply_op(web, fa, fb);
        (void)ws_rigid_apply(R, web, fa, cb, fb, cq);
        for (size_t k = 0; k < R->nphi; k++) {
            const double *f = fb + 3 * (size_t)R->phi_node[k], *r = R->phi_lever + 3 * k;
            double *o = cq + 6 * (size_t)R->phi_body[k];
            const v3 mo = v3_cross(v3_make(r[0], r[1], r[2]), v3_make(f[0], f[1], f[2]));
            o[0] += f[0], o[1] += f[1], o[2] += f[2];
            o[3] += mo.x, o[4] += mo.y, o[5] += mo.z;
        }
        for (size_t d = 0; d < nc; d++)
            A[nc * d + c] = cq[d];
    }
    for (size_t c = 0; c < nc; c++)
        for (size_t d = c + 1; d < nc; d++)
            A[nc * d + c] = A[nc * c + d] = 0.5 * (A[nc * d + c] + A[nc * c + d]);
    free(fa);
    free(fb);
    free(cb);
    free(cq);
}

START_TEST(test_coarse_setup)
{
    /* The coarse space's Phi^T A Phi, set up a body's six columns at once over the rows and
     * springs they reach, equals the column-by-column product over the whole film to the bit
     * (compared as doubles, so a zero's sign aside): the same terms are summed in the same
     * order, only the zeros are left out. A sagging drum (pinned edge, shear springs) under
     * two bodies, with nodes on one, on both, on one body twice (two faces: one column entry)
     * and pinned nodes among the contacts, at three states of its run: the springs' blocks
     * and the contacts' change between them. */
    ws_web_id id;
    ws_status st;
    ws_world *w = choice_drum(14, 11, WS_WEB_PRECONDITIONER_BLOCK_JACOBI, 1e-3, &id, &st);
    ck_assert_ptr_nonnull(w);
    const double h = 2e-3;
    for (int state = 0; state < 3; state++) {
        ck_ok(w, ws_world_step_n(w, 4));
        ws_web *web = web_of(w, id);
        ws_implicit *im = web->imp;
        const uint32_t n = web->n;
        const ws_nodes3 x = web->x[w->cur], v = web->v[w->cur];
        ck_assert_int_eq(ws_implicit_begin(web, x, v, v3_make(0, 0, -G0), w->time, 0.0), 0);
        /* The contacts: sorted by node; a body's run broken by the other's. */
        const size_t cap = 3 * (size_t)n;
        ws_rigid_link *link = calloc(cap + 1, sizeof *link);
        ck_assert(link);
        size_t nl = 0;
        for (uint32_t i = 0; i < n; i++) {
            const v3 xi = nodes_get(x, i);
            const int on0 = i % 3 != 2, on1 = i % 4 == 0 || i % 5 == 1, twice = i % 7 == 0;
            for (int k = 0; k < 3; k++) {
                if ((k == 0 && !on0) || (k == 1 && !(on0 && twice)) || (k == 2 && !on1))
                    continue;
                ws_rigid_link *L = &link[nl++];
                L->node = i;
                L->body = k == 2;
                const v3 c0 = L->body ? v3_make(0.03, 0.02, -0.05) : v3_make(0.07, 0.05, 0.04);
                L->lever = v3_add(v3_sub(xi, c0), v3_make(0.001 * k, -0.002 * k, 0.0));
                const v3 g = v3_make(sin(0.3 * i + state), cos(0.7 * i), 1.0);
                const v3 nrm = v3_scale(g, 1.0 / v3_norm(g));
                double K[WS_SYM] = {0}, D[WS_SYM] = {0};
                ws_sym_add_outer(K, 4000.0 * (1 + i % 5), nrm);
                ws_sym_add_outer(D, 1.0, nrm);
                D[WS_SYM_XX] += 0.3, D[WS_SYM_YY] += 0.3, D[WS_SYM_ZZ] += 0.3;
                ws_implicit_add(im, i, v3_make(0, 0, 0), K, D);
                for (int q = 0; q < WS_SYM; q++)
                    L->C[q] = h * h * K[q] + h * D[q];
            }
        }
        ck_assert(nl > n / 2 && nl <= cap);
        ws_rigid R;
        memset(&R, 0, sizeof R);
        R.nb = 2;
        R.nl = nl;
        R.cap = cap;
        R.link = link;
        const size_t v6 = 12;
        double mass[2] = {1.0, 2.5};
        double inertia[2 * WS_SYM] = {0.01, 0.02, 0.015, 1e-3, 0, -2e-3,
                                      0.03, 0.02,  0.04,  0,    1e-3, 0};
        R.mass = mass;
        R.inertia = inertia;
        double *d = calloc(2 * v6 * v6 + 8 * v6 + v6 * v6 + 6 * v6 + 18 * (cap + 1),
                           sizeof(double));
        uint32_t env[24];
        R.phi_node = calloc(cap + 1, sizeof *R.phi_node);
        R.phi_body = calloc(cap + 1, sizeof *R.phi_body);
        R.phi_lever = calloc(3 * (cap + 1), sizeof *R.phi_lever);
        R.crow = calloc(n + 1, sizeof *R.crow);
        R.cphi = calloc(2 * (cap + 1), sizeof *R.cphi);
        R.cwork = calloc(ws_rigid_coarse_words(cap, 2), sizeof *R.cwork);
        ck_assert(d && R.phi_node && R.phi_body && R.phi_lever && R.crow && R.cphi && R.cwork);
        R.abb = d, R.fac = d + v6 * v6, R.env = env;
        R.b = d + 2 * v6 * v6, R.x = R.b + v6, R.r = R.x + v6, R.z = R.r + v6, R.p = R.z + v6;
        R.q = R.p + v6, R.cb = R.q + v6, R.cq = R.cb + v6, R.coarse = R.cq + v6;
        R.cyr = R.coarse + v6 * v6, R.cy = R.cyr + 6 * v6;
        /* The solve sets the operator up (and takes the coarse space it sets up). */
        im->rig = &R;
        im->warm = 0;
        (void)ws_implicit_solve(web, v, h);
        im->rig = NULL;
        double A[144], B[144];
        ws_rigid_coarse_matrix(&R, web);
        memcpy(A, R.coarse, sizeof A);
        coarse_by_columns(&R, web, B);
        size_t pinned = 0, both = 0;
        for (size_t k = 0; k < nl; k++)
            pinned += web->inv_m[link[k].node] == 0.0;
        for (size_t k = 1; k < R.nphi; k++)
            both += R.phi_node[k] == R.phi_node[k - 1];
        double worst = 0.0, scale = 0.0;
        int differ = 0;
        for (int k = 0; k < 144; k++) {
            differ += A[k] != B[k];
            worst = fmax(worst, fabs(A[k] - B[k]));
            scale = fmax(scale, fabs(B[k]));
        }
        report("coarse set-up, state %d: %zu contacts (%zu at pinned nodes), %zu of Phi's nodes "
               "(%zu on both bodies): %d of 144 entries differ, by at most %.3g of %.3g",
               state, nl, pinned, R.nphi, both, differ, worst, scale);
        ck_assert(pinned > 0 && both > 0);
        ck_assert_msg(differ == 0, "state %d: %d entries differ, by up to %g", state, differ,
                      worst);
        free(d);
        free(R.phi_node);
        free(R.phi_body);
        free(R.phi_lever);
        free(R.crow);
        free(R.cphi);
        free(R.cwork);
        free(link);
    }
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_bodies_block)
{
    /* The bodies' block of the coupled matrix as ws_rigid_factor assembles it (R->abb) is the
     * bodies' part of the operator: for a unit motion e_k of one body, ws_rigid_apply's yr is
     * column k of A_bb, to round-off (1e-12 of the column's largest entry: the two add the
     * same terms, in other orders). Four bodies on a drum, with film contacts on three, pairs
     * between bodies 0 and 1 (strong: h c 50 kg against 1 to 3 kg), between 2 and 0 (a later
     * body coupled to the first, which widens the factor's envelope over body 1's rows), of
     * bodies 1 and 2 with a world element (either side), and body 3 alone. Then the factor
     * solves A_bb z = r: the operator's A_bb z is r to 1e-12 of |r| (Cholesky is backward stable;
     * this block's condition number is about 1e3, so round-off leaves some 1e-13). */
    ws_web_id id;
    ws_status st;
    ws_world *w = choice_drum(8, 6, WS_WEB_PRECONDITIONER_BLOCK_JACOBI, 1e-3, &id, &st);
    ck_assert_ptr_nonnull(w);
    ws_web *web = web_of(w, id);
    const uint32_t n = web->n;
    const double h = 1e-3;
    enum { NB = 4, V6 = 24, NL = 6, NP = 4 };
    const uint32_t node[NL] = {9, 10, 18, 20, 27, 29}, body[NL] = {0, 0, 1, 2, 2, 0};
    ws_rigid_link link[NL];
    for (int l = 0; l < NL; l++) {
        ws_rigid_link *L = &link[l];
        ck_assert(web->inv_m[node[l]] > 0.0);
        L->node = node[l];
        L->body = body[l];
        L->lever = v3_make(0.05 * (l % 3) - 0.04, 0.03 * (l % 2) + 0.02, -0.06 + 0.01 * l);
        const v3 g = v3_make(sin(0.7 * l), cos(1.3 * l), 1.0);
        const v3 e = v3_scale(g, 1.0 / v3_norm(g));
        double K[WS_SYM] = {0}, D[WS_SYM] = {0};
        ws_sym_add_outer(K, 4000.0 * (1 + l), e);
        K[WS_SYM_XX] += 800.0, K[WS_SYM_YY] += 800.0, K[WS_SYM_ZZ] += 800.0;
        ws_sym_add_outer(D, 2.0, e);
        for (int q = 0; q < WS_SYM; q++)
            L->C[q] = h * h * K[q] + h * D[q];
    }
    const uint32_t pa[NP] = {0, 2, 1, UINT32_MAX}, pb[NP] = {1, 0, UINT32_MAX, 2};
    const double pc[NP] = {5e4, 2e4, 1e4, 3e4}; /* c, N s/m */
    ws_rigid_pair pair[NP];
    for (int q = 0; q < NP; q++) {
        ws_rigid_pair *P = &pair[q];
        memset(P, 0, sizeof *P);
        P->a = pa[q], P->b = pb[q], P->tag = (uint32_t)q;
        P->ra = v3_make(0.1, -0.05 * q, 0.08);
        P->rb = v3_make(-0.07, 0.04, -0.02 * q);
        const v3 g = v3_make(0.3 * q, 1.0 - 0.2 * q, 0.5);
        const v3 e = v3_scale(g, 1.0 / v3_norm(g));
        ws_sym_add_outer(P->C, -h * pc[q], e);
        P->C[WS_SYM_XX] += h * pc[q], P->C[WS_SYM_YY] += h * pc[q], P->C[WS_SYM_ZZ] += h * pc[q];
    }
    double mass[NB] = {1.0, 2.5, 3.0, 1.5};
    double inertia[NB * WS_SYM] = {0.01, 0.02, 0.015, 1e-3, 0,    -2e-3, 0.03, 0.02,
                                   0.04, 0,    1e-3,  0,    0.02, 0.02,  0.02, 0,
                                   0,    0,    0.01,  0.03, 0.02, 0,     0,    1e-3};
    double abb[V6 * V6], fac[V6 * V6];
    uint32_t env[2 * V6];
    ws_rigid R;
    memset(&R, 0, sizeof R);
    R.nb = NB;
    R.nl = R.cap = NL;
    R.link = link;
    R.pair = pair;
    R.npair = NP;
    R.mass = mass;
    R.inertia = inertia;
    R.abb = abb, R.fac = fac, R.env = env;
    ck_assert_int_eq(ws_rigid_factor(&R), 0);
    double *p = calloc(3 * (size_t)n, sizeof(double)), *y = calloc(3 * (size_t)n, sizeof(double));
    ck_assert(p && y);
    double worst = 0.0, coupled = 0.0;
    for (int k = 0; k < V6; k++) {
        double pr[V6] = {0}, yr[V6];
        pr[k] = 1.0;
        (void)ws_rigid_apply(&R, web, p, pr, y, yr);
        double scale = 0.0, diff = 0.0;
        for (int d = 0; d < V6; d++) {
            scale = fmax(scale, fabs(yr[d]));
            diff = fmax(diff, fabs(yr[d] - abb[V6 * d + k]));
        }
        worst = fmax(worst, diff / scale);
        for (int d = 6; d < 12 && k < 6; d++) /* body 1's rows of body 0's columns */
            coupled = fmax(coupled, fabs(abb[V6 * d + k]) / scale);
    }
    report("bodies' block: columns of the operator vs the assembled block, worst %.2g of the "
           "column; bodies 0-1 coupled at %.3g of the column",
           worst, coupled);
    double r[V6], z[V6], az[V6];
    for (int k = 0; k < V6; k++)
        r[k] = sin(1.7 * k + 0.3) * (k % 6 < 3 ? 1.0 : 0.1);
    ws_rigid_block_solve(&R, r, z);
    (void)ws_rigid_apply(&R, web, p, z, y, az);
    double res = 0.0, nr = 0.0;
    for (int k = 0; k < V6; k++)
        res += (az[k] - r[k]) * (az[k] - r[k]), nr += r[k] * r[k];
    report("bodies' block solved together: |A_bb z - r| %.2g of |r|", sqrt(res / nr));
    ck_assert_msg(coupled > 0.1, "the pair's coupling is not in the block: %g", coupled);
    ck_assert_msg(worst <= 1e-12, "the bodies' block differs from the operator by %g", worst);
    ck_assert_uint_eq(env[12], 0);  /* body 2 coupled to body 0 */
    ck_assert_uint_eq(env[18], 18); /* body 3 alone */
    ck_assert_msg(sqrt(res / nr) <= 1e-12, "A_bb z - r: %g of r", sqrt(res / nr));
    free(p), free(y);
    ws_world_destroy(w);
}
END_TEST

/* A 1 kg cube, 0.1 m, resting on a kinematic floor (2e5 N/m, 10 kg/s; eq. 13 friction mu 0.3,
 * v_lim 2 mm/s) and sliding along x at v0 below v_lim, under a light implicit sheet (7 x 7
 * nodes, its border pinned, frictionless on the box) that touches its top face, so that the
 * box is in the film's solve, at step dt for `steps` steps: the box's velocity along x at the
 * end, its largest over the last half of the steps and the steps that reverse it. */
typedef struct slip_run {
    double v_end, v_late;
    int reversals;
} slip_run;

/* What a step of box_slip_checked tells its check: the world after the step, the box and the
 * floor, the box's centre of mass before the step. */
typedef void (*slip_check)(ws_world *w, ws_body_id box, ws_body_id floor_id, ws_vec3 r0,
                           void *data);

static slip_run box_slip_checked(double dt, double v0, long steps, slip_check check, void *data)
{
    const double a = 0.1, layer = 1e-3, vlim = 2e-3;
    ws_world *w = world_g(dt, (ws_vec3){0, 0, -G0});
    ws_material_def md;
    ws_material_def_init(&md);
    ws_material_id box_mat, floor_mat, film_mat;
    ck_ok(w, ws_material_create(w, &md, &box_mat));
    ck_ok(w, ws_material_create(w, &md, &floor_mat));
    ck_ok(w, ws_material_create(w, &md, &film_mat));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 2e5;
    cd.damping = 10.0;
    cd.friction = 0.3;
    cd.friction_vlim = vlim;
    ck_ok(w, ws_world_set_contact(w, box_mat, floor_mat, &cd));
    cd.stiffness = 4000.0;
    cd.damping = 1.0;
    cd.friction = 0.0;
    ck_ok(w, ws_world_set_contact(w, film_mat, box_mat, &cd));
    ws_shape_id slab, cube;
    ck_ok(w, ws_shape_create_box(w, 1.0, 1.0, 0.05, &slab));
    ck_ok(w, ws_shape_create_box(w, a, a, a, &cube));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = slab;
    bd.material = floor_mat;
    bd.contact_layer = layer;
    bd.position = v3_make(0, 0, -0.025);
    ws_body_id floor_id, box;
    ck_ok(w, ws_body_create(w, &bd, &floor_id));
    ws_body_def_init(&bd);
    bd.shape = cube;
    bd.material = box_mat;
    bd.mass = 1.0;
    bd.contact_layer = layer;
    /* On its layers, pressed in by its weight over its four corners. */
    bd.position = v3_make(0, 0, 2 * layer + a / 2 - G0 / 2e5 / 4);
    bd.velocity = v3_make(v0, 0, 0);
    ck_ok(w, ws_body_create(w, &bd, &box));
    /* A light sheet over the box's top face, its border pinned, touching it. */
    enum { N = 7 };
    uint32_t pins[4 * N];
    const size_t np = edge_pins(N, N, pins);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-5;
    wd.law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, 20.0, 0.0, 0.01, 0.0);
    wd.material = film_mat;
    wd.contact_layer = layer;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.solver_tolerance = 1e-9;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = N;
    sd.ny = N;
    sd.origin = v3_make(-0.06, -0.06, 2 * layer + a + 2 * layer - 2e-4);
    sd.spacing_x = sd.spacing_y = 0.02;
    sd.pinned = pins;
    sd.pinned_count = np;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    slip_run o = {0.0, 0.0, 0};
    double last = v0;
    for (long n = 1; n <= steps; n++) {
        ws_vec3 r0;
        ck_ok(w, ws_body_get_position(w, box, &r0));
        ck_ok(w, ws_world_step(w));
        if (check)
            check(w, box, floor_id, r0, data);
        ws_vec3 v;
        ck_ok(w, ws_body_get_velocity(w, box, &v));
        if (v.x * last < 0.0)
            o.reversals++;
        if (2 * n > steps && fabs(v.x) > o.v_late)
            o.v_late = fabs(v.x);
        last = v.x;
        o.v_end = v.x;
    }
    ws_world_destroy(w);
    return o;
}

static slip_run box_slip(double dt, double v0, long steps)
{
    return box_slip_checked(dt, v0, steps, NULL, NULL);
}
/* Eq. 13 below v_lim is a damper of 2 mu N / v_lim on the slip: a box sliding on a floor at
 * less than v_lim slows as exp(-2 mu g t / v_lim) (a time constant of 0.34 ms here) and never
 * reverses, whatever the step, when the step takes the damper implicitly. Taken explicitly in
 * the bodies' step it multiplies the slip by 1 - 2 mu g h / v_lim = -1.9 a step at h = 1 ms,
 * beyond its limit (docs/theory.md section 8: 2 / (2 mu g / v_lim) = 0.68 ms here): the slip
 * flips every step and grows until the law's cap holds it at about v_lim (main gave 1.2-1.75
 * mm/s, reversed at every step). With the bodies in the implicit film's solve, the friction of
 * their contacts is in it too (section 8b), and the box stops: what is left after 100 steps is
 * its rocking on the stiff contacts (the friction acts 5 cm below its centre of mass), ringing
 * down under the contacts' damping (1.2e-6 m/s at most). Bound: 1e-5 m/s, v_lim / 200. */
START_TEST(test_body_friction_in_solve)
{
    const slip_run o = box_slip(1e-3, 1e-3, 200);
    ck_assert_msg(o.v_late < 1e-5, "the box still slips at %.3g mm/s (%d reversals)",
                  1e3 * o.v_late, o.reversals);
    ck_assert_msg(fabs(o.v_end) < 1e-5, "the box ends at %.3g mm/s", 1e3 * o.v_end);
}
END_TEST

/* The box-floor contacts of box_slip_checked's steps against the step's linear model of eq. 13
 * (docs/theory.md section 5, the same for every body contact in a solve): about the slip t0 at
 * the start, F(t1) = F(t0) - C (t1 - t0), F(t0) = -mu N p(s0) e (e = t0 / |t0|, s0 = |t0| /
 * v_lim), C = mu N [phi (P - e e^T) + (p'(s0) / v_lim) e e^T], phi = p(s0) / |t0| the secant
 * across the slip (2 / v_lim at rest), p'(s) = 2 - 2 s the law's slope along it (zero once it
 * slides), P the tangent plane's projection; t1 the tangential slip the box ends the step with
 * at the contact point (its end velocity and spin, the lever from its centre before the step).
 * worst: the largest |ft - F(t1)| / (mu N); for contacts sliding at the start (s0 >= 1), the
 * largest |ft . e + mu N| / (mu N) (Coulomb's force along the slip) and how many; the largest
 * power over mu N |t1|; the most friction over mu N. */
typedef struct damper_check {
    double dev, coulomb_dev, power, coulomb;
    long contacts, sliding, turned;
} damper_check;

static void check_damper(ws_world *w, ws_body_id box, ws_body_id floor_id, ws_vec3 r0,
                         void *data)
{
    damper_check *o = data;
    const double mu = 0.3, vlim = 2e-3; /* box_slip's box-floor contact */
    ws_contact_info buf[16];
    size_t n = 0;
    ck_ok(w, ws_world_copy_contacts_between(w, floor_id, box, buf, 16, &n));
    ws_vec3 v, om;
    ck_ok(w, ws_body_get_velocity(w, box, &v));
    ck_ok(w, ws_body_get_angular_velocity(w, box, &om));
    for (size_t k = 0; k < n; k++) {
        const ws_contact_info *c = &buf[k];
        if (!(c->normal_force > 0.0))
            continue;
        /* The face's owner is a; the slip is b's against a, the floor's or the box's. */
        const double sign = c->body_b.bits == box.bits ? 1.0 : -1.0;
        const v3 lever = v3_sub(c->point, r0);
        const v3 u = v3_scale(v3_add(v, v3_cross(om, lever)), sign);
        const v3 t1 = v3_sub(u, v3_scale(c->normal, v3_dot(u, c->normal)));
        const v3 t0 = c->slip_velocity;
        const double v0 = v3_norm(t0), s0 = v0 / vlim;
        const double cap = mu * c->normal_force;
        const double p0 = s0 < 1.0 ? s0 * (2.0 - s0) : 1.0;
        const double secant = v0 > 0.0 ? cap * p0 / v0 : 2.0 * cap / vlim;
        const double slope = cap * (s0 < 1.0 ? 2.0 - 2.0 * s0 : 0.0) / vlim;
        const v3 ft = c->friction_force;
        /* The slope's model and the secant's, -secant t1 (the pair turned: its slip reversed
         * in a solve of the step). */
        const double off_secant = v3_norm(v3_add(ft, v3_scale(t1, secant))) / cap;
        double off = off_secant;
        if (v0 > 0.0) {
            const v3 e = v3_scale(t0, 1.0 / v0);
            const double along = v3_dot(t1, e);
            const v3 across = v3_sub(t1, v3_scale(e, along));
            const v3 model = v3_add(v3_scale(e, -cap * p0 - slope * (along - v0)),
                                    v3_scale(across, -secant));
            const double off_slope = v3_norm(v3_sub(ft, model)) / cap;
            /* The slope's model holds only where the step does not reverse the slip. */
            if (along >= 0.0 && off_slope < off) {
                off = off_slope;
                if (s0 >= 1.0) {
                    o->coulomb_dev =
                        fmax(o->coulomb_dev, fabs(v3_dot(ft, e) + cap) / cap);
                    o->sliding++;
                }
            } else if (off_secant < 1e-6 && off_slope > 1e-6) {
                o->turned++;
            }
        }
        o->dev = fmax(o->dev, off);
        const double tl = v3_norm(t1);
        const double power = tl > 0.0 ? v3_dot(ft, t1) / (cap * tl) : 0.0;
        o->power = fmax(o->power, power);
        o->coulomb = fmax(o->coulomb, v3_norm(ft) / cap);
        o->contacts++;
    }
}

/* The bodies' friction in the film's solve (docs/theory.md sections 5 and 8b) is the step's
 * linear model of eq. 13 taken at the slip the step ends with: the box of
 * body_friction_in_solve starts sliding at 6 mm/s, above v_lim (Coulomb's force), and slows
 * through v_lim to rest, at 1 ms and at 0.25 ms. Each contact's friction at the end of a step
 * must be the model's F(t1) with the law's slope along the slip where the step does not
 * reverse the slip, or the secant's -phi t1 where a solve of the step reversed it
 * (check_damper). Bound: 1e-6 of mu N, far above what the solve leaves (its tolerance 1e-9 of
 * the box's weight impulse gives 1e-8 m/s of velocity, 1e-8 N against mu N = 0.74 N on each
 * of four contacts) and far below what an explicit law or the secant alone give (at 1 ms the
 * explicit law flipped the slip every step; the secant from 6 mm/s ends a step at 2.66 mm/s
 * with mu N 0.44 along the slip, where Coulomb's law gives mu N). A contact sliding at the
 * start of a step and not reversed feels Coulomb's force, mu N, to 1e-6 along the slip (the
 * law's slope is zero there); at 0.25 ms there are such steps. At 1 ms the box's pitch in the
 * first step (its friction 5 cm below its centre, the corners' normal springs taken at the
 * start) reverses the corners' slip within the step, and their pairs turn. Either way the
 * friction opposes the end slip (power <= 0) and here, the slip falling, is at most mu N, both
 * to 1e-6. */
START_TEST(test_body_friction_dissipates)
{
    const double dts[2] = {1e-3, 2.5e-4};
    for (int k = 0; k < 2; k++) {
        damper_check o = {0.0, 0.0, -INFINITY, 0.0, 0, 0, 0};
        const slip_run r = box_slip_checked(dts[k], 6e-3, lround(0.1 / dts[k]), check_damper, &o);
        ck_assert_msg(o.contacts > 100, "dt %g: only %ld pushing contacts", dts[k], o.contacts);
        /* At 1 ms the first step's pitch (the friction 5 cm below the centre, the corners'
         * normal springs taken at the start) reverses the corners' slip within the step:
         * they turn to the secant. At 0.25 ms the box slides at Coulomb's force. */
        ck_assert_msg(k == 0 || o.sliding >= 8, "dt %g: only %ld sliding contacts", dts[k],
                      o.sliding);
        ck_assert_msg(k == 1 || o.turned >= 4, "dt %g: only %ld turned contacts", dts[k],
                      o.turned);
        ck_assert_msg(o.dev < 1e-6,
                      "dt %g: a contact's friction is not the linear model's: off by %.3g of mu N",
                      dts[k], o.dev);
        ck_assert_msg(o.coulomb_dev < 1e-6,
                      "dt %g: a sliding contact's friction is off Coulomb's by %.3g of mu N",
                      dts[k], o.coulomb_dev);
        ck_assert_msg(o.power <= 1e-6,
                      "dt %g: a contact's friction pushes along the end slip: %.3g of mu N |t1|",
                      dts[k], o.power);
        ck_assert_msg(o.coulomb <= 1.0 + 1e-6, "dt %g: friction %.6g of mu N", dts[k],
                      o.coulomb);
        ck_assert_msg(fabs(r.v_end) < 1e-5, "dt %g: the box ends at %.3g mm/s", dts[k],
                      1e3 * r.v_end);
    }
}
END_TEST

/* ---- Coulomb's static friction on the implicit film -------------------------------------- */

/* A free 5 x 5 implicit sheet (free_film: 0.1 g a node, 20 mm apart) lying on a level slab
 * (film_and_box's pair: mu 0.5, v_lim 10 mm/s), under gravity first straight down for 0.2 s
 * (it settles into the contacts' window), then turned by theta about y, as if the slab were
 * tilted. Its mean x displacement from the turn to t1, and its mean x velocity at t0 and t1
 * (from the turn). */
typedef struct incline {
    ws_status status;
    double dx, v0, v1;
} incline;

static double sheet_mean(ws_world *w, ws_web_id web, int velocity)
{
    double xyz[3 * 25];
    size_t n;
    ck_ok(w, velocity ? ws_web_copy_velocities(w, web, xyz, 25, &n)
                      : ws_web_copy_positions(w, web, xyz, 25, &n));
    double s = 0.0;
    for (int i = 0; i < 25; i++)
        s += xyz[3 * i];
    return s / 25.0;
}

static incline film_on_incline(double theta, double t0, double t1)
{
    const double dt = 2.5e-4;
    ws_world *w = world_g(dt, (ws_vec3){0, 0, -G0});
    ws_material_id film, slab_mat;
    film_and_box(w, &film, &slab_mat);
    ws_shape_id slab;
    ck_ok(w, ws_shape_create_box(w, 2.0, 0.4, 0.1, &slab));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = slab;
    bd.material = slab_mat;
    bd.position = v3_make(0.0, 0.0, -0.05);
    ws_body_id body;
    ck_ok(w, ws_body_create(w, &bd, &body));
    /* 1.5 mm above the face: within the window of the two contact layers (2 mm). */
    const ws_web_id web = free_film(w, film, 1e-4, 1e-6, 5, v3_make(-0.9, -0.04, 1.5e-3), 0.02);
    incline o = {WS_OK, 0.0, 0.0, 0.0};
    o.status = ws_world_step_n(w, (long)(0.2 / dt + 0.5));
    const ws_vec3 g = {G0 * sin(theta), 0.0, -G0 * cos(theta)};
    ck_ok(w, ws_world_set_gravity(w, &g));
    const double x0 = sheet_mean(w, web, 0);
    if (o.status == WS_OK)
        o.status = ws_world_step_n(w, (long)(t0 / dt + 0.5));
    o.v0 = sheet_mean(w, web, 1);
    if (o.status == WS_OK)
        o.status = ws_world_step_n(w, (long)((t1 - t0) / dt + 0.5));
    o.v1 = sheet_mean(w, web, 1);
    o.dx = sheet_mean(w, web, 0) - x0;
    ws_world_destroy(w);
    return o;
}

/* Coulomb: a film lying on a face whose slope is below atan(mu) stays where it is, and above
 * it slides at g (sin theta - mu cos theta). At 20 deg (tan 0.364 < mu = 0.5) the sheet must
 * not move: eq. 13 alone, no force at rest, would let it creep at the slip where its force
 * meets the slope's pull, p(v / v_lim) = tan(theta) / mu, v = 4.8 mm/s, 4.8 mm in the second
 * (as it did before); the film's friction stops the slip within the step as the explicit
 * film's does (docs/theory.md 8c), so it moves less than 1 um (round-off). At 35 deg (tan 0.700) it slides: between 0.25 and 0.75 s
 * after the turn its speed grows at 9.81 (sin 35 - 0.5 cos 35) = 1.6088 m/s^2, within 1 %
 * (at a slip of 0.4 m/s and more, 40 times v_lim, eq. 13 is Coulomb's force; its secant taken
 * at the step's start slip lags the speed by a h / v, under 1e-3). */
START_TEST(test_film_static_friction)
{
    const double deg = 3.14159265358979323846 / 180.0, hold = 20.0 * deg, slide = 35.0 * deg;
    const incline a = film_on_incline(hold, 0.5, 1.0);
    report("implicit film on a slope of 20 deg (mu 0.5): moved %.3g m in 1 s (mean speed %.3g "
           "m/s at the end)",
           a.dx, a.v1);
    ck_assert_int_eq(a.status, WS_OK);
    ck_assert_msg(fabs(a.dx) < 1e-6, "the film crept %g m on a slope it holds to", a.dx);
    const incline b = film_on_incline(slide, 0.25, 0.75);
    const double acc = (b.v1 - b.v0) / 0.5, theory = G0 * (sin(slide) - 0.5 * cos(slide));
    report("implicit film on a slope of 35 deg (mu 0.5): accelerates at %.5f m/s^2 (theory "
           "%.5f, rel %.2g)",
           acc, theory, (acc - theory) / theory);
    ck_assert_int_eq(b.status, WS_OK);
    ck_assert_msg(fabs(acc - theory) < 0.01 * theory, "acceleration %g, theory %g", acc, theory);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("implicit");
    add_case(s, "spring_jacobian", test_spring_jacobian, 10);
    add_case(s, "contact_jacobian", test_contact_jacobian, 10);
    add_case(s, "push_past_edge_continuous", test_push_past_edge_continuous, 10);
    add_case(s, "push_continuous_onto_face", test_push_continuous_onto_face, 10);
    add_case(s, "band_corners_mirror", test_band_corners_mirror, 10);
    add_case(s, "blend_jacobian", test_blend_jacobian, 10);
    add_case(s, "coupled_jacobian", test_coupled_jacobian, 10);
    add_case(s, "body_on_film", test_body_on_film, 60);
    add_case(s, "film_body_momentum", test_film_body_momentum, 30);
    add_case(s, "moving_face_galilean", test_moving_face_galilean, 30);
    add_case(s, "kinematic_face_galilean", test_kinematic_face_galilean, 30);
    add_case(s, "string_mode_amplification", test_string_mode_amplification, 10);
    add_case(s, "row_tension", test_row_tension, 20);
    add_case(s, "converges_to_explicit", test_converges_to_explicit, 60);
    add_case(s, "band_pressure", test_band_pressure, 60);
    add_case(s, "same_on_workers", test_same_on_workers, 60);
    add_case(s, "scales_and_rupture", test_scales_and_rupture, 10);
    add_case(s, "failed_solve_leaves_world", test_failed_solve_leaves_world, 10);
    add_case(s, "failed_solve_with_body", test_failed_solve_with_body, 10);
    add_case(s, "bad_solver_defs", test_bad_solver_defs, 10);
    add_case(s, "multigrid", test_multigrid, 30);
    add_case(s, "preconditioner_choice", test_preconditioner_choice, 20);
    add_case(s, "preconditioners_agree", test_preconditioners_agree, 20);
    add_case(s, "refined_band_pressure", test_refined_band_pressure, 60);
    add_case(s, "band_multigrid_refined", test_band_multigrid_refined, 60);
    add_case(s, "band_rows_chosen", test_band_rows_chosen, 60);
    add_case(s, "rows_mixed", test_rows_mixed, 60);
    add_case(s, "band_bodies_nested", test_band_bodies_nested, 60);
    add_case(s, "bodies_solved_together", test_bodies_solved_together, 60);
    add_case(s, "bodies_warm_start", test_bodies_warm_start, 60);
    add_case(s, "stop_on_rows", test_stop_on_rows, 30);
    add_case(s, "coarse_setup", test_coarse_setup, 20);
    add_case(s, "bodies_block", test_bodies_block, 10);
    add_case(s, "body_friction_in_solve", test_body_friction_in_solve, 20);
    add_case(s, "body_friction_dissipates", test_body_friction_dissipates, 20);
    add_case(s, "film_static_friction", test_film_static_friction, 60);
    return run_suite(s);
}
