/* Film rupture: a spring strained past its web's rupture strain breaks at the end of the step
 * and carries no force from then on (include/wrapsim/web.h, ws_web_def.rupture_strain).
 *
 * The physics the tests hold it to: a row pulled by a slowly growing force breaks when the
 * force passes the law's force at the rupture strain, and its free part then falls freely
 * (its momentum grows by exactly the external force; the node next to the break feels only
 * its other spring); a band around two blocks pulled apart breaks and stops squeezing them; a
 * web with broken springs swept in blocks moves as the same web swept spring by spring, on
 * one worker or two; a save across a break restores bit for bit; bad limits are refused. */
#include "helpers.h"

#include <stdint.h>

/* WS_TEST_SHORT (sanitizer and valgrind runs): the same checks on shorter runs. */
static int short_run(void)
{
    const char *e = getenv("WS_TEST_SHORT");
    return e && *e && strcmp(e, "0") != 0;
}

/* ---- builders ---- */

static ws_world *world_dt(double dt, ws_vec3 g, uint32_t workers)
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

static ws_law_id linear_law(ws_world *w, double ea, double c)
{
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = WS_LAW_LINEAR_VISCOELASTIC;
    d.stiffness = ea;
    d.damping = c;
    ws_law_id id;
    ck_ok(w, ws_law_create(w, &d, &id));
    return id;
}

static double *copy_pos(ws_world *w, ws_web_id web, size_t *n)
{
    size_t cnt;
    ck_ok(w, ws_web_copy_positions(w, web, NULL, 0, &cnt));
    double *p = malloc(3 * cnt * sizeof *p);
    ck_assert(p);
    ck_ok(w, ws_web_copy_positions(w, web, p, cnt, &cnt));
    if (n)
        *n = cnt;
    return p;
}

static double *copy_vel(ws_world *w, ws_web_id web)
{
    size_t cnt;
    ck_ok(w, ws_web_copy_velocities(w, web, NULL, 0, &cnt));
    double *p = malloc(3 * cnt * sizeof *p);
    ck_assert(p);
    ck_ok(w, ws_web_copy_velocities(w, web, p, cnt, &cnt));
    return p;
}

static uint64_t hash_of(ws_world *w)
{
    uint64_t h = 0;
    ck_ok(w, ws_world_get_state_hash(w, &h));
    return h;
}

/* The row of the first test: 4 nodes along x, 0.1 m apart at rest, node 0 held; light inner
 * nodes (m), a heavy end (M); three springs of EA (no damping), rupture strain eps_r. */
#define ROW_N 4
static const double ROW_L0 = 0.1, ROW_EA = 1000.0, ROW_m = 0.01, ROW_M = 1.0;

static ws_web_id make_row(ws_world *w, double eps_r)
{
    double pos[3 * ROW_N] = {0}, mass[ROW_N] = {ROW_m, ROW_m, ROW_m, ROW_M};
    uint32_t spr[2 * (ROW_N - 1)], pin = 0;
    for (int i = 0; i < ROW_N; i++)
        pos[3 * i] = i * ROW_L0;
    for (int i = 0; i + 1 < ROW_N; i++) {
        spr[2 * i] = (uint32_t)i;
        spr[2 * i + 1] = (uint32_t)(i + 1);
    }
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.law = linear_law(w, ROW_EA, 0.0);
    wd.rupture_strain = eps_r;
    wd.name = "row";
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = pos;
    md.node_count = ROW_N;
    md.node_masses = mass;
    md.springs = spr;
    md.spring_count = ROW_N - 1;
    md.pinned = &pin;
    md.pinned_count = 1;
    ws_web_id id;
    ck_ok(w, ws_web_create_mesh(w, &wd, &md, &id));
    return id;
}

/* ---- 1. a row pulled apart ---- */

START_TEST(row_breaks_at_the_law_force)
{
    /* The pull is gravity along +x, g = a t, on a row held at node 0: the spring at the hold
     * carries the weight of all below it, F = (M + 2 m) g, which grows at Fdot = 100 N/s. It
     * breaks when its strain passes eps_r = 0.5, i.e. when F passes the law's force there,
     * EA eps_r = 500 N. How well the break load can match: the row follows a ramp with the lag
     * of its slowest mode, whose force swings by about Fdot / omega_1 (omega_1^2 = k_series /
     * M, k_series = EA / (3 l0): 57.7 rad/s, 1.7 N), and the break is seen at the end of a step
     * (Fdot dt = 0.01 N): tolerance Fdot (1 / omega_1 + dt) = 1.74 N of 500. Short runs pull
     * ten times faster, with ten times the tolerance. */
    const double dt = 1e-4, eps_r = 0.5, Mtot = ROW_M + 2 * ROW_m;
    const double Fdot = short_run() ? 1000.0 : 100.0;
    const double a = Fdot / Mtot, Fr = ROW_EA * eps_r;
    const double om1 = sqrt(ROW_EA / (3 * ROW_L0) / ROW_M), tol = Fdot * (1.0 / om1 + dt);
    ws_world *w = world_dt(dt, (ws_vec3){0, 0, 0}, 1);
    ws_web_id web = make_row(w, eps_r);
    ws_web_rupture r;
    double t = 0.0, Fb = -1.0;
    for (int k = 0; k < 200000; k++) {
        ws_vec3 g = {a * t, 0, 0};
        ck_ok(w, ws_world_set_gravity(w, &g));
        ck_ok(w, ws_world_step(w));
        ck_ok(w, ws_world_get_time(w, &t));
        ck_ok(w, ws_web_get_rupture(w, web, &r));
        if (r.broken_count) {
            Fb = Mtot * g.x; /* the load the step that broke it ran with */
            break;
        }
        ck_assert_int_eq(r.ruptured, 0);
    }
    report("row pulled at %g N/s: broke at %.4f N, the law's force at the rupture strain %g N "
           "(tolerance %.3g N)",
           Fdot, Fb, Fr, tol);
    ck_assert_msg(Fb > 0.0, "never broke");
    ck_assert_msg(fabs(Fb - Fr) <= tol, "broke at %g N, expected %g +- %g N", Fb, Fr, tol);
    /* The spring at the hold broke (it carries the most), alone, and is reported as the first
     * with its time, strain and place (the midpoint of its nodes). */
    ck_assert_uint_eq(r.broken_count, 1);
    ck_assert_uint_eq(r.broken_last_step, 1);
    ck_assert_int_eq(r.ruptured, 1);
    ck_assert_uint_eq(r.first_spring, 0);
    ck_assert(r.first_time == t);
    ck_assert(r.first_strain > eps_r && r.first_strain < eps_r + 0.01);
    size_t n, nb;
    double *x = copy_pos(w, web, &n);
    ck_assert(fabs(r.first_position.x - 0.5 * (x[0] + x[3])) < 1e-15);
    uint32_t idx[3] = {99, 99, 99};
    ck_ok(w, ws_web_copy_broken_springs(w, web, NULL, 0, &nb));
    ck_assert_uint_eq(nb, 1);
    ck_ok(w, ws_web_copy_broken_springs(w, web, idx, 3, &nb));
    ck_assert_uint_eq(idx[0], 0);
    double T[3];
    ck_ok(w, ws_web_copy_spring_tensions(w, web, T, 3, &n));
    ck_assert(T[0] == 0.0 && T[1] > 0.9 * Fr);
    free(x);

    /* From now on the load is held at g_b. The spring at the hold carries nothing: in a step
     * (symplectic Euler), node 1's velocity changes by h (g + T1 u / m), T1 its other spring's
     * tension at the step's start along u, the unit vector to node 2 -- no pull of node 0 --
     * while the free part's momentum grows by exactly h (M + 2 m) g (its springs' forces cancel
     * in pairs): relative 1e-12, round-off over the sums. Node 1 moves away from node 0 for
     * good. */
    const double gb = a * (t - dt);
    ck_ok(w, ws_world_set_gravity(w, &(ws_vec3){gb, 0, 0}));
    double *x0 = copy_pos(w, web, NULL), *v0 = copy_vel(w, web);
    double *xs = copy_pos(w, web, NULL), pc0 = 0.0;
    for (int i = 1; i < ROW_N; i++)
        pc0 += (i == ROW_N - 1 ? ROW_M : ROW_m) * v0[3 * i];
    for (int k = 0; k < 300; k++) {
        double T1;
        ck_ok(w, ws_web_copy_spring_tensions(w, web, T, 3, &n));
        T1 = T[1];
        ck_ok(w, ws_world_step(w));
        double *x1 = copy_pos(w, web, NULL), *v1 = copy_vel(w, web);
        double dx = x0[6] - x0[3], dy = x0[7] - x0[4], dz = x0[8] - x0[5];
        double l = sqrt(dx * dx + dy * dy + dz * dz);
        double want = dt * (gb + T1 * dx / l / ROW_m), got = v1[3] - v0[3];
        ck_assert_msg(fabs(got - want) <= 1e-9 * (fabs(want) + dt * gb),
                      "step %d: node 1 gained %.17g m/s, its other spring and the load give "
                      "%.17g",
                      k, got, want);
        double p0 = 0.0, p1 = 0.0;
        for (int i = 1; i < ROW_N; i++) {
            double m = i == ROW_N - 1 ? ROW_M : ROW_m;
            p0 += m * v0[3 * i];
            p1 += m * v1[3 * i];
        }
        ck_assert_msg(fabs((p1 - p0) - dt * Mtot * gb) <= 1e-12 * (fabs(p1) + dt * Mtot * gb),
                      "step %d: the free part's momentum grew %.17g, the load gives %.17g", k,
                      p1 - p0, dt * Mtot * gb);
        free(x0);
        free(v0);
        x0 = x1;
        v0 = v1;
    }
    /* The free part's centre of mass then went as a free mass does under symplectic Euler:
     * x_N = x_0 + N h v_0 + h^2 g N (N + 1) / 2 (relative 1e-9: the sums' round-off). Its light
     * nodes meanwhile swing wildly: the energy the broken spring's neighbour held is let go. */
    double xc = 0.0, xc0 = 0.0;
    for (int i = 1; i < ROW_N; i++) {
        double m = i == ROW_N - 1 ? ROW_M : ROW_m;
        xc += m * x0[3 * i] / Mtot;
        xc0 += m * xs[3 * i] / Mtot;
    }
    const double want = xc0 + 300 * dt * pc0 / Mtot + dt * dt * gb * 300 * 301 / 2;
    ck_assert_msg(fabs(xc - want) <= 1e-9 * fabs(want - xc0),
                  "the free part's centre is at %.15g m, a free fall gives %.15g", xc, want);
    ck_ok(w, ws_web_get_rupture(w, web, &r));
    ck_assert_uint_eq(r.broken_last_step, 0);
    free(xs);
    free(x0);
    free(v0);
    ws_world_destroy(w);
}
END_TEST

START_TEST(no_limit_no_break_same_motion)
{
    /* The row under a load twice its breaking load: without a limit nothing breaks; with a
     * limit it never reaches (eps 10), the nodes move the same, bit for bit. */
    const double dt = 1e-4;
    ws_world *a = world_dt(dt, (ws_vec3){0, 0, 0}, 1), *b = world_dt(dt, (ws_vec3){0, 0, 0}, 1);
    ws_web_id wa = make_row(a, 0.0), wb = make_row(b, 10.0);
    ws_vec3 g = {1000.0 / (ROW_M + 2 * ROW_m), 0, 0};
    ck_ok(a, ws_world_set_gravity(a, &g));
    ck_ok(b, ws_world_set_gravity(b, &g));
    ck_ok(a, ws_world_step_n(a, 3000));
    ck_ok(b, ws_world_step_n(b, 3000));
    ws_web_rupture r;
    ck_ok(a, ws_web_get_rupture(a, wa, &r));
    ck_assert_uint_eq(r.broken_count, 0);
    ck_assert_int_eq(r.ruptured, 0);
    ck_assert_uint_eq(r.first_spring, UINT32_MAX);
    ck_assert(r.rupture_strain == 0.0);
    double *xa = copy_pos(a, wa, NULL), *xb = copy_pos(b, wb, NULL);
    ck_assert(memcmp(xa, xb, 3 * ROW_N * sizeof *xa) == 0);
    ck_assert(xa[9] > 3 * ROW_L0 * 1.5); /* stretched past eps 0.5 everywhere: 1000 N on EA 1000 */
    /* The peak: the spring at the hold, whose strain the positions give. */
    ws_web_peak pk;
    ck_ok(a, ws_web_get_peak_strain(a, wa, &pk));
    ck_assert_int_eq(pk.found, 1);
    ck_assert_uint_eq(pk.spring, 0);
    ck_assert_uint_eq(pk.node_a, 0);
    ck_assert_uint_eq(pk.node_b, 1);
    ck_assert(pk.position_b.x == xa[3]);
    ck_assert(fabs(pk.strain - ((xa[3] - xa[0]) / ROW_L0 - 1.0)) < 1e-12);
    ck_assert(fabs(pk.tension - ROW_EA * pk.strain) < 1e-9);
    free(xa);
    free(xb);
    ws_world_destroy(a);
    ws_world_destroy(b);
}
END_TEST

/* ---- 2. a band pulled past its limit ---- */

static ws_body_id add_block(ws_world *w, double x, ws_material_id mat, int driven)
{
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.2, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = s;
    bd.material = mat;
    bd.position.x = x;
    ws_body_id id;
    ck_ok(w, ws_body_create(w, &bd, &id));
    if (driven) {
        ws_drive_def dd;
        ws_drive_def_init(&dd);
        dd.type = WS_DRIVE_SINE;
        dd.direction = (ws_vec3){1, 0, 0};
        dd.amplitude = 0.04;
        dd.frequency = 0.5;
        dd.ramp_time = 0.0;
        dd.start_time = 0.1;
        ck_ok(w, ws_body_set_drive(w, id, &dd));
    }
    return id;
}

START_TEST(band_breaks_and_lets_go)
{
    /* Two blocks 0.1 x 0.1 m side by side, a band of 40 x 3 nodes around them laid at 10 %
     * strain (EA 100 N: T = 10 N a row), no friction so the strain is the same all round. The
     * right block moves out by 0.04 sin(pi (t - 0.1)) from t = 0.1 s: the band's length grows by
     * up to 0.08 of its 0.6 m, its strain towards 1.1 x 1.133 - 1 = 0.247: it passes the
     * rupture strain 0.2 when the block has moved by some 0.027 m, about 0.24 s into the
     * motion (earlier where the film bends round a corner). Before: the band squeezes the
     * right block with 2 T = 20 N a row (the two sides pulling round its far face). After: every
     * row is a broken ring, which holds no tension: the pull on the block falls to the inertia
     * and drag of loose film (node mass 1 g, drag 0.2 kg/s), under 2 % of before. */
    const double dt = 1e-4;
    ws_world *w = world_dt(dt, (ws_vec3){0, 0, 0}, 1);
    ws_material_def md;
    ws_material_def_init(&md);
    md.name = "film";
    ws_material_id film, dflt;
    ck_ok(w, ws_material_create(w, &md, &film));
    ck_ok(w, ws_world_get_default_material(w, &dflt));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 4000.0;
    cd.damping = 1.0;
    cd.friction = 0.0;
    ck_ok(w, ws_world_set_contact(w, film, dflt, &cd));
    ws_body_id blocks[2] = {add_block(w, -0.05, dflt, 0), add_block(w, 0.05, dflt, 1)};
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-3;
    wd.node_damping = 0.2;
    wd.law = linear_law(w, 100.0, 0.005);
    wd.material = film;
    wd.rupture_strain = 0.2;
    wd.name = "band";
    ws_band_def bd;
    ws_band_def_init(&bd);
    bd.bodies = blocks;
    bd.body_count = 2;
    bd.z_bottom = -0.05;
    bd.z_top = 0.05;
    bd.n_around = 40;
    bd.n_up = 3;
    bd.prestretch_around = 0.1;
    ws_web_id web;
    ck_ok(w, ws_web_create_band(w, &wd, &bd, &web));
    ck_ok(w, ws_world_step_n(w, 1000)); /* settled, the drive starts at 0.1 s */
    ws_vec3 f0, f1;
    ck_ok(w, ws_web_get_body_force(w, web, blocks[1], &f0, NULL));
    ws_containment_band c0[3], c1[3];
    ck_ok(w, ws_web_get_containment(w, web, c0, 3));
    ws_web_rupture r;
    ck_ok(w, ws_web_get_rupture(w, web, &r));
    ck_assert_uint_eq(r.broken_count, 0);
    ws_web_peak pk;
    ck_ok(w, ws_web_get_peak_strain(w, web, &pk));
    ck_assert_msg(pk.strain > 0.09 && pk.strain < 0.2, "peak strain %g at rest", pk.strain);
    ck_assert_msg(f0.x < -0.8 * 3 * 2 * 10.0, "the band pulls the block by %g N", f0.x);
    ck_ok(w, ws_world_step_n(w, 4000)); /* to t = 0.5 s */
    ck_ok(w, ws_web_get_rupture(w, web, &r));
    ck_ok(w, ws_web_get_body_force(w, web, blocks[1], &f1, NULL));
    ck_ok(w, ws_web_get_containment(w, web, c1, 3));
    report("band pulled past its rupture strain 0.2: first break at t = %.4f s (spring %u, "
           "strain %.4f), %u springs broken; pull on the block %.3g N before, %.3g N after",
           r.first_time, r.first_spring, r.first_strain, r.broken_count, f0.x, f1.x);
    ck_assert_int_eq(r.ruptured, 1);
    ck_assert_msg(r.first_time > 0.1 && r.first_time < 0.4, "first break at %g s", r.first_time);
    ck_assert(r.first_strain > 0.2);
    /* Every row cut at least once: its around-springs are numbered 40 a row. */
    size_t nb;
    ck_ok(w, ws_web_copy_broken_springs(w, web, NULL, 0, &nb));
    uint32_t *idx = malloc(nb * sizeof *idx);
    ck_assert(idx);
    ck_ok(w, ws_web_copy_broken_springs(w, web, idx, nb, &nb));
    int cut[3] = {0, 0, 0};
    for (size_t i = 0; i < nb; i++) {
        if (i)
            ck_assert_uint_gt(idx[i], idx[i - 1]);
        if (idx[i] < 120)
            cut[idx[i] / 40] = 1;
    }
    ck_assert_msg(cut[0] && cut[1] && cut[2], "rows cut: %d %d %d", cut[0], cut[1], cut[2]);
    ck_assert_msg(fabs(f1.x) < 0.02 * fabs(f0.x) && fabs(f1.y) < 0.02 * fabs(f0.x),
                  "the broken band still pulls the block by (%g, %g) N", f1.x, f1.y);
    for (int j = 0; j < 3; j++)
        ck_assert_msg(fabs(c1[j].hoop_tension) < 0.02 * c0[j].hoop_tension,
                      "row band %d: hoop tension %g N after, %g before", j, c1[j].hoop_tension,
                      c0[j].hoop_tension);
    free(idx);
    ws_world_destroy(w);
}
END_TEST

/* ---- 3. the sweep with broken springs ---- */

/* A sheet of 7 x 150 nodes with shear springs hanging from its four corners, the film law;
 * *wd its web Def. */
static ws_web_id hanging_sheet(ws_world *w, ws_web_def *wd, const uint32_t *pins)
{
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_TENSION_COMPRESSION;
    ld.stiffness = 50.0;
    ld.compression_stiffness = 0.5;
    ld.damping = 0.02;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_web_def_init(wd);
    wd->node_mass = 1e-3;
    wd->law = wd->law_cross = wd->law_shear = law;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = 7;
    sd.ny = 150;
    sd.spacing_x = sd.spacing_y = 0.02;
    sd.prestretch_x = sd.prestretch_y = 0.1;
    sd.shear = 1;
    sd.pinned = pins;
    sd.pinned_count = 4;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, wd, &sd, &web));
    return web;
}

/* The same film as a mesh web (swept as one block, spring by spring). */
static ws_web_id mesh_of(ws_world *w, ws_web_id sheet, const ws_web_def *wd, const uint32_t *pins)
{
    size_t nn, ns;
    double *x = copy_pos(w, sheet, &nn);
    ck_ok(w, ws_web_copy_springs(w, sheet, NULL, 0, &ns));
    uint32_t *spr = malloc(2 * ns * sizeof *spr);
    double *rest = malloc(ns * sizeof *rest), *strain = malloc(ns * sizeof *strain);
    uint8_t *kind = malloc(ns);
    ck_assert(spr && rest && strain && kind);
    ck_ok(w, ws_web_copy_springs(w, sheet, spr, ns, &ns));
    ck_ok(w, ws_web_copy_spring_strains(w, sheet, strain, ns, &ns));
    for (size_t k = 0; k < ns; k++) {
        const double *pa = x + 3 * spr[2 * k], *pb = x + 3 * spr[2 * k + 1];
        rest[k] = sqrt((pb[0] - pa[0]) * (pb[0] - pa[0]) + (pb[1] - pa[1]) * (pb[1] - pa[1]) +
                       (pb[2] - pa[2]) * (pb[2] - pa[2])) /
                  (1.0 + strain[k]);
        kind[k] = WS_SPRING_AROUND; /* one law for all */
    }
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = x;
    md.node_count = nn;
    md.springs = spr;
    md.spring_count = ns;
    md.rest_lengths = rest;
    md.kinds = kind;
    md.pinned = pins;
    md.pinned_count = 4;
    ws_web_id id;
    ck_ok(w, ws_web_create_mesh(w, wd, &md, &id));
    free(x);
    free(spr);
    free(rest);
    free(strain);
    free(kind);
    return id;
}

static uint32_t *broken_list(ws_world *w, ws_web_id web, size_t *n)
{
    ck_ok(w, ws_web_copy_broken_springs(w, web, NULL, 0, n));
    uint32_t *idx = malloc((*n + 1) * sizeof *idx);
    ck_assert(idx);
    ck_ok(w, ws_web_copy_broken_springs(w, web, idx, *n, n));
    return idx;
}

START_TEST(broken_sheet_moves_as_its_mesh)
{
    /* The sheet sags for 0.05 s, then gets a rupture strain between its largest and smallest
     * strain near the top of the range: the most strained springs (at the corners it hangs
     * from) break, the film tears from its corners and falls on. The grid sweep zeroes broken
     * springs chunk by chunk and row by row; the mesh sweep skips them one at a time: the two
     * must break the same springs and move alike. They add each node's forces in another
     * order, so they differ by round-off, some 1e-16 a step, grown by the motion (the
     * sheet in blocks against its mesh, test_web.c, stays within a few 1e-15 m): tolerance
     * 1e-9 m, where a broken spring still pulling in one of them would differ by millimetres.
     * The same sheet on two workers (lanes, cut at blocks) must be the same to the bit. */
    const double dt = 5e-5;
    const uint32_t pins[4] = {0, 6, 7 * 149, 7 * 150 - 1};
    ws_world *w = world_dt(dt, (ws_vec3){0, 0, -G0}, 1), *w2 = world_dt(dt, (ws_vec3){0, 0, -G0}, 2);
    ws_web_def wd, wd2;
    ws_web_id sheet = hanging_sheet(w, &wd, pins), sheet2 = hanging_sheet(w2, &wd2, pins);
    ws_web_id mesh = mesh_of(w, sheet, &wd, pins);
    const int steps = short_run() ? 300 : 1000;
    ck_ok(w, ws_world_step_n(w, steps));
    ck_ok(w2, ws_world_step_n(w2, steps));
    size_t ns;
    ck_ok(w, ws_web_copy_spring_strains(w, sheet, NULL, 0, &ns));
    double *eps = malloc(ns * sizeof *eps);
    ck_assert(eps);
    ck_ok(w, ws_web_copy_spring_strains(w, sheet, eps, ns, &ns));
    double lo = INFINITY, hi = -INFINITY;
    for (size_t k = 0; k < ns; k++) {
        lo = fmin(lo, eps[k]);
        hi = fmax(hi, eps[k]);
    }
    const double lim = hi - 0.1 * (hi - lo);
    ck_ok(w, ws_web_set_rupture_strain(w, sheet, lim));
    ck_ok(w, ws_web_set_rupture_strain(w, mesh, lim));
    ck_ok(w2, ws_web_set_rupture_strain(w2, sheet2, lim));
    ck_ok(w, ws_world_step_n(w, steps));
    ck_ok(w2, ws_world_step_n(w2, steps));
    size_t na, nm, n2;
    uint32_t *ba = broken_list(w, sheet, &na), *bm = broken_list(w, mesh, &nm),
             *b2 = broken_list(w2, sheet2, &n2);
    ck_assert_uint_gt(na, 0);
    ck_assert_uint_eq(na, nm);
    ck_assert(memcmp(ba, bm, na * sizeof *ba) == 0);
    ck_assert_uint_eq(na, n2);
    ck_assert(memcmp(ba, b2, na * sizeof *ba) == 0);
    size_t n;
    double *xs = copy_pos(w, sheet, &n), *xm = copy_pos(w, mesh, NULL), *x2 = copy_pos(w2, sheet2, NULL);
    double diff = 0.0;
    for (size_t i = 0; i < 3 * n; i++)
        diff = fmax(diff, fabs(xs[i] - xm[i]));
    ws_web_rupture r;
    ck_ok(w, ws_web_get_rupture(w, sheet, &r));
    report("torn sheet against its mesh: %zu of %zu springs broken (limit %.4f, first at t = "
           "%.4f s), largest difference %.3g m",
           na, ns, lim, r.first_time, diff);
    ck_assert_msg(diff <= 1e-9, "the torn sheet and its mesh differ by %g m", diff);
    ck_assert_msg(memcmp(xs, x2, 3 * n * sizeof *xs) == 0, "two workers moved the sheet otherwise");
    free(ba);
    free(bm);
    free(b2);
    free(xs);
    free(xm);
    free(x2);
    free(eps);
    ws_world_destroy(w);
    ws_world_destroy(w2);
}
END_TEST

/* ---- 4. save and restore ---- */

static unsigned char *save_of(ws_world *w, size_t *n)
{
    ck_ok(w, ws_world_save(w, NULL, 0, n));
    unsigned char *b = malloc(*n);
    ck_assert(b);
    ck_ok(w, ws_world_save(w, b, *n, n));
    return b;
}

/* FNV-1a 64 over the payload into the header's checksum (bytes 24..31), as a save does. */
static void reseal(unsigned char *b, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 32; i < n; i++) {
        h ^= b[i];
        h *= 0x100000001b3ull;
    }
    for (int i = 0; i < 8; i++)
        b[24 + i] = (unsigned char)(h >> (8 * i));
    uint64_t len = n - 32;
    for (int i = 0; i < 8; i++)
        b[16 + i] = (unsigned char)(len >> (8 * i));
}

static void pull_row(ws_world *w, double g)
{
    ck_ok(w, ws_world_set_gravity(w, &(ws_vec3){g, 0, 0}));
}

START_TEST(save_restore_across_a_break)
{
    /* The row under a constant 600 N breaks in its first few hundred steps. World a is saved
     * before the break and after it; world b, stepped otherwise first, restores each and must
     * then take a's steps to the bit (hashes compared every step), the break included. */
    const double dt = 1e-4, g = 600.0 / (ROW_M + 2 * ROW_m);
    ws_world *a = world_dt(dt, (ws_vec3){0, 0, 0}, 1), *b = world_dt(dt, (ws_vec3){0, 0, 0}, 1);
    ws_web_id wa = make_row(a, 0.5);
    make_row(b, 0.5);
    pull_row(a, g);
    pull_row(b, g);
    ck_ok(b, ws_world_step_n(b, 777)); /* stale */
    size_t n1, n2;
    unsigned char *before = save_of(a, &n1);
    uint64_t h[1000];
    int broke_at = -1;
    for (int k = 0; k < 1000; k++) {
        ck_ok(a, ws_world_step(a));
        h[k] = hash_of(a);
        ws_web_rupture r;
        ck_ok(a, ws_web_get_rupture(a, wa, &r));
        if (r.broken_count && broke_at < 0)
            broke_at = k;
    }
    ck_assert_msg(broke_at > 0 && broke_at < 900, "broke at step %d", broke_at);
    ck_ok(b, ws_world_restore(b, before, n1));
    for (int k = 0; k < 1000; k++) {
        ck_ok(b, ws_world_step(b));
        ck_assert_msg(hash_of(b) == h[k], "restored before the break: step %d differs", k);
    }
    /* After the break: the broken flags and the report come back. */
    unsigned char *after = save_of(a, &n2);
    ws_world *c = world_dt(dt, (ws_vec3){0, 0, 0}, 1);
    ws_web_id wc = make_row(c, 0.5);
    pull_row(c, g);
    ck_ok(c, ws_world_restore(c, after, n2));
    ck_assert(hash_of(c) == hash_of(a));
    ws_web_rupture ra, rc;
    ck_ok(a, ws_web_get_rupture(a, wa, &ra));
    ck_ok(c, ws_web_get_rupture(c, wc, &rc));
    ck_assert(memcmp(&ra, &rc, sizeof ra) == 0);
    ck_assert_uint_ge(rc.broken_count, 1);
    ck_ok(a, ws_world_step_n(a, 200));
    ck_ok(c, ws_world_step_n(c, 200));
    ck_assert(hash_of(c) == hash_of(a));
    /* A flag that is not 0 or 1 is refused, naming it, and the world is left as it was; the
     * flag cleared (the same save but spring 0 intact) is taken and hashes otherwise: the
     * flags are in the hash. */
    free(after);
    after = save_of(a, &n2);
    const uint64_t ha = hash_of(a);
    unsigned char *bad = malloc(n2);
    ck_assert(bad);
    int refused = 0;
    size_t flag_at = 0;
    for (size_t i = 32; i < n2; i++) {
        if (after[i] != 1)
            continue;
        memcpy(bad, after, n2);
        bad[i] = 2;
        reseal(bad, n2);
        ws_status s = ws_world_restore(c, bad, n2);
        if (s == WS_ERR_FORMAT && strstr(ws_world_last_error(c), "broken flag")) {
            refused++;
            flag_at = i;
            ck_assert(hash_of(c) == ha);
        }
    }
    ck_ok(a, ws_web_get_rupture(a, wa, &ra));
    ck_assert_int_eq(refused, (int)ra.broken_count); /* one a broken spring */
    memcpy(bad, after, n2);
    bad[flag_at] = 0;
    reseal(bad, n2);
    ck_ok(c, ws_world_restore(c, bad, n2));
    ck_assert(hash_of(c) != ha);
    ck_ok(c, ws_web_get_rupture(c, wc, &rc));
    ck_assert_uint_eq(rc.broken_count, ra.broken_count - 1);
    free(bad);
    free(before);
    free(after);
    ws_world_destroy(a);
    ws_world_destroy(b);
    ws_world_destroy(c);
}
END_TEST

START_TEST(save_format_1_restores_unbroken)
{
    /* A save of format 1 (before rupture) has no rupture record. Made here from a format 2
     * save of a web without a limit by taking out the 8 bytes of its rupture flag (found as
     * the first byte where it differs from the save of the same world with a limit) and
     * writing version 1: it restores into both worlds, the one with a limit with no spring
     * broken, and the state is the same as the save's. */
    const double dt = 1e-4;
    ws_world *a = world_dt(dt, (ws_vec3){0, 0, 0}, 1), *b = world_dt(dt, (ws_vec3){0, 0, 0}, 1);
    ws_web_id wa = make_row(a, 0.0), wb = make_row(b, 0.5);
    pull_row(a, 100.0);
    pull_row(b, 100.0);
    ck_ok(a, ws_world_step_n(a, 50));
    ck_ok(b, ws_world_step_n(b, 50));
    size_t na, nb;
    unsigned char *sa = save_of(a, &na), *sb = save_of(b, &nb);
    ck_assert_uint_gt(nb, na);
    size_t at = 32;
    while (at < na && sa[at] == sb[at])
        at++;
    ck_assert_uint_lt(at, na);
    ck_assert(sa[at] == 0 && sb[at] == 1);
    unsigned char *v1 = malloc(na - 8);
    ck_assert(v1);
    memcpy(v1, sa, at);
    memcpy(v1 + at, sa + at + 8, na - at - 8);
    v1[8] = 1;
    reseal(v1, na - 8);
    /* b runs into a break, then takes the old save: none broken, as a's state. */
    pull_row(b, 1000.0);
    ck_ok(b, ws_world_step_n(b, 300));
    ws_web_rupture r;
    ck_ok(b, ws_web_get_rupture(b, wb, &r));
    ck_assert_uint_gt(r.broken_count, 0);
    ck_ok(b, ws_world_restore(b, v1, na - 8));
    ck_ok(b, ws_web_get_rupture(b, wb, &r));
    ck_assert_uint_eq(r.broken_count, 0);
    ck_assert_int_eq(r.ruptured, 0);
    double *xa = copy_pos(a, wa, NULL), *xb = copy_pos(b, wb, NULL);
    ck_assert(memcmp(xa, xb, 3 * ROW_N * sizeof *xa) == 0);
    ck_ok(a, ws_world_restore(a, v1, na - 8));
    /* A format 2 save of the world with a limit does not fit the world without one. */
    ck_assert_int_eq(ws_world_restore(a, sb, nb), WS_ERR_FORMAT);
    ck_assert(strstr(ws_world_last_error(a), "rupture"));
    free(xa);
    free(xb);
    free(sa);
    free(sb);
    free(v1);
    ws_world_destroy(a);
    ws_world_destroy(b);
}
END_TEST

/* ---- 5. bad input ---- */

START_TEST(bad_limits_refused)
{
    ws_world *w = world_dt(1e-4, (ws_vec3){0, 0, 0}, 1);
    ws_web_id web = make_row(w, 0.0);
    const double bad[3] = {-0.1, NAN, INFINITY};
    for (int i = 0; i < 3; i++) {
        ck_assert_int_eq(ws_web_set_rupture_strain(w, web, bad[i]), WS_ERR_INVALID_ARGUMENT);
        ck_assert_msg(strstr(ws_world_last_error(w), "finite and >= 0"), "%s",
                      ws_world_last_error(w));
        ws_web_rupture r;
        ck_ok(w, ws_web_get_rupture(w, web, &r));
        ck_assert(r.rupture_strain == 0.0);
    }
    /* In the Def: refused at creation, naming the field and the value. */
    double pos[6] = {0, 0, 0, 0.1, 0, 0};
    uint32_t spr[2] = {0, 1};
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.law = linear_law(w, 10.0, 0.0);
    wd.node_mass = 1e-3;
    wd.rupture_strain = -1.0;
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = pos;
    md.node_count = 2;
    md.springs = spr;
    md.spring_count = 1;
    ws_web_id id;
    ck_assert_int_eq(ws_web_create_mesh(w, &wd, &md, &id), WS_ERR_INVALID_ARGUMENT);
    ck_assert(strstr(ws_world_last_error(w), "rupture_strain"));
    ck_assert(strstr(ws_world_last_error(w), "-1"));
    wd.rupture_strain = NAN;
    ck_assert_int_eq(ws_web_create_mesh(w, &wd, &md, &id), WS_ERR_INVALID_ARGUMENT);
    ck_assert(strstr(ws_world_last_error(w), "rupture_strain"));
    /* Stale ids and NULL outputs. */
    ws_web_id stale = {0};
    ws_web_rupture r;
    ws_web_peak pk;
    size_t n;
    ck_assert_int_eq(ws_web_set_rupture_strain(w, stale, 0.5), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_web_get_rupture(w, stale, &r), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_web_get_peak_strain(w, stale, &pk), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_web_copy_broken_springs(w, stale, NULL, 0, &n), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_web_get_rupture(w, web, NULL), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_web_get_peak_strain(w, web, NULL), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_web_copy_broken_springs(w, web, NULL, 3, &n), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_web_copy_broken_springs(w, web, NULL, 0, NULL), WS_ERR_INVALID_ARGUMENT);
    ws_world_destroy(w);
}
END_TEST

START_TEST(limit_out_of_memory)
{
    /* Setting a first limit takes memory for the broken flags: refused when there is none,
     * the web as it was; every byte back after destroy. */
    test_alloc a = {-1, 0, 0, 1, NULL, 0, 0, 0, ""};
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = 1e-4;
    test_alloc_install(&d, &a);
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    ws_web_id web = make_row(w, 0.0);
    uint64_t h = hash_of(w);
    a.allocs_left = 0;
    ck_assert_int_eq(ws_web_set_rupture_strain(w, web, 0.3), WS_ERR_OUT_OF_MEMORY);
    a.allocs_left = -1;
    ws_web_rupture r;
    ck_ok(w, ws_web_get_rupture(w, web, &r));
    ck_assert(r.rupture_strain == 0.0);
    ck_assert(hash_of(w) == h);
    ck_ok(w, ws_web_set_rupture_strain(w, web, 0.3));
    ck_ok(w, ws_world_step_n(w, 10));
    ws_world_destroy(w);
    ck_assert_msg(a.size_errors == 0, "%s", a.size_error);
    ck_assert_msg(a.live == 0 && a.bytes == 0, "%ld blocks, %lld bytes left", a.live, a.bytes);
    test_alloc_done(&a);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("rupture");
    add_case(s, "row_breaks_at_the_law_force", row_breaks_at_the_law_force, 60);
    add_case(s, "no_limit_no_break_same_motion", no_limit_no_break_same_motion, 20);
    add_case(s, "band_breaks_and_lets_go", band_breaks_and_lets_go, 60);
    add_case(s, "broken_sheet_moves_as_its_mesh", broken_sheet_moves_as_its_mesh, 60);
    add_case(s, "save_restore_across_a_break", save_restore_across_a_break, 30);
    add_case(s, "save_format_1_restores_unbroken", save_format_1_restores_unbroken, 20);
    add_case(s, "bad_limits_refused", bad_limits_refused, 10);
    add_case(s, "limit_out_of_memory", limit_out_of_memory, 10);
    return run_suite(s);
}
