/* Validation of the stretch film (laws, webs, node-face contact) against analytical answers.
 *
 *  1. laws: derivatives against central differences, C1 join of the film law, energy as the
 *     integral of the elastic force, bad Defs refused;
 *  2. a pre-stretched row between fixed ends settles to the uniform tension EA p;
 *  3. sag of a tensioned chain under its weight: w L^2 / (8 H);
 *  4. longitudinal wave speed of a chain: c = spacing sqrt(k / m);
 *  5. a band around a cylinder presses with T / R per unit length (row sum 2 pi T);
 *  6. capstan: a chain over a rotating cylinder, tension ratio exp(+-mu pi);
 *  7. no energy gain without damping (symplectic Euler: bounded oscillation, no drift);
 *  8. the stable sub-step check (refusal, message, sub-steps, bound vs the chain's omega_max);
 *  9. sheet generator facts (counts, rest lengths, pinned nodes, areal masses);
 * 10. bulk read-out contracts (short buffers, counts, stale ids, laws in use).
 *
 * Every tolerance is argued in the comment above its assertion. Measured values are printed
 * with a "[measured]" prefix so that the validation report can quote them. */
#include "helpers.h"

#include <stdarg.h>
#include <stdio.h>

#define PI 3.14159265358979323846


/* ---- builders ---- */

static ws_world *world_g(double dt, ws_vec3 g)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = dt;
    d.gravity = g;
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    return w;
}

/* A world whose film check uses the fraction f of the stable step (1: the bound itself). */
static ws_world *world_f(double dt, ws_vec3 g, double f)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = dt;
    d.gravity = g;
    d.stable_fraction = f;
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    return w;
}

static const ws_vec3 NO_G = {0, 0, 0};
static const ws_vec3 DOWN_G = {0, 0, -G0};

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

/* A straight chain along x as a mesh web: n nodes at spacing s from x0 (z = z0), springs i-i+1
 * with rest length l0, optional displacement dx[i] added to x, masses m (or masses[]). */
static ws_web_id make_chain(ws_world *w, const ws_web_def *wd, int n, double s, double l0,
                            const double *dx, const double *masses, const uint32_t *pinned,
                            size_t npinned)
{
    double *pos = calloc((size_t)n * 3, sizeof *pos);
    uint32_t *spr = calloc((size_t)(n - 1) * 2, sizeof *spr);
    double *rest = calloc((size_t)(n - 1), sizeof *rest);
    ck_assert(pos && spr && rest);
    for (int i = 0; i < n; i++)
        pos[3 * i] = i * s + (dx ? dx[i] : 0.0);
    for (int i = 0; i + 1 < n; i++) {
        spr[2 * i] = (uint32_t)i;
        spr[2 * i + 1] = (uint32_t)(i + 1);
        rest[i] = l0;
    }
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = pos;
    md.node_count = (size_t)n;
    md.node_masses = masses;
    md.springs = spr;
    md.spring_count = (size_t)(n - 1);
    md.rest_lengths = rest;
    md.pinned = pinned;
    md.pinned_count = npinned;
    ws_web_id id;
    ws_status st = ws_web_create_mesh(w, wd, &md, &id);
    free(pos);
    free(spr);
    free(rest);
    ck_ok(w, st);
    return id;
}

/* The default safety factor of the stable-step check (world.h: stable_fraction). */
static double default_fraction(void)
{
    ws_world_def d;
    ws_world_def_init(&d);
    return d.stable_fraction;
}

/* Sub-steps that make the web run at the world's dt within the default safety factor of its
 * stable step (with a 5 % margin). */
static int fit_substeps(ws_world *w, ws_web_id web, double dt)
{
    double S;
    ck_ok(w, ws_web_get_stable_dt(w, web, &S));
    int n = (int)ceil(1.05 * dt / (default_fraction() * S));
    if (n < 1)
        n = 1;
    ck_ok(w, ws_web_set_substeps(w, web, n));
    return n;
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

/* A grid web's nodes, springs and rest lengths as a mesh web's Def (md, pointing into x, spr
 * and rest, which free_sheet_copy frees): the same film, which a mesh web sweeps as one block,
 * spring by spring. */
typedef struct sheet_copy {
    ws_web_mesh_def md;
    double *x, *rest;
    uint32_t *spr;
} sheet_copy;

static sheet_copy copy_sheet(ws_world *w, ws_web_id sheet)
{
    sheet_copy c;
    size_t nn, ns;
    c.x = copy_pos(w, sheet, &nn);
    ck_ok(w, ws_web_copy_springs(w, sheet, NULL, 0, &ns));
    c.spr = malloc(2 * ns * sizeof *c.spr);
    c.rest = malloc(ns * sizeof *c.rest);
    double *strain = malloc(ns * sizeof *strain);
    ck_assert(c.spr && strain && c.rest);
    ck_ok(w, ws_web_copy_springs(w, sheet, c.spr, ns, &ns));
    ck_ok(w, ws_web_copy_spring_strains(w, sheet, strain, ns, &ns));
    for (size_t k = 0; k < ns; k++) {
        const double *pa = c.x + 3 * c.spr[2 * k], *pb = c.x + 3 * c.spr[2 * k + 1];
        double l = sqrt((pb[0] - pa[0]) * (pb[0] - pa[0]) + (pb[1] - pa[1]) * (pb[1] - pa[1]) +
                        (pb[2] - pa[2]) * (pb[2] - pa[2]));
        c.rest[k] = l / (1.0 + strain[k]);
    }
    free(strain);
    ws_web_mesh_def_init(&c.md);
    c.md.positions = c.x;
    c.md.node_count = nn;
    c.md.springs = c.spr;
    c.md.spring_count = ns;
    c.md.rest_lengths = c.rest;
    return c;
}

static void free_sheet_copy(sheet_copy *c)
{
    free(c->x);
    free(c->spr);
    free(c->rest);
}

static double *copy_tensions(ws_world *w, ws_web_id web, size_t *n)
{
    size_t cnt;
    ck_ok(w, ws_web_copy_spring_tensions(w, web, NULL, 0, &cnt));
    double *t = malloc((cnt ? cnt : 1) * sizeof *t);
    ck_assert(t);
    ck_ok(w, ws_web_copy_spring_tensions(w, web, t, cnt, &cnt));
    if (n)
        *n = cnt;
    return t;
}

/* ======================================================================================
 * 1. Laws
 * ====================================================================================== */

/* Film law in closed form (the header's definition), for the value checks. */
static double film_force(double k, double kc, double c, double w, double e, double ed)
{
    double g = e >= w ? e : e <= -w ? 0.0 : (e + w) * (e + w) / (4.0 * w);
    return kc * e + (k - kc) * g + c * ed;
}

START_TEST(test_law_derivatives)
{
    ws_world *w = world_g(1e-4, NO_G);
    const double k = 1000.0, kc = 20.0, c = 5.0, tw = 1e-3;
    ws_law_id laws[3] = {
        make_law(w, WS_LAW_LINEAR_ELASTIC, k, 0.0, c, 0.0), /* damping ignored: elastic */
        make_law(w, WS_LAW_LINEAR_VISCOELASTIC, k, 0.0, c, 0.0),
        make_law(w, WS_LAW_TENSION_COMPRESSION, k, kc, c, tw),
    };
    const char *names[3] = {"linear", "kelvin-voigt", "film"};
    /* Strains: deep compression, the join's ends exactly, inside the join (both halves, 0),
     * just inside/outside the ends, tension. */
    const double eps[] = {-0.3,    -2e-3,  -1e-3, -9.99e-4, -7e-4, -1e-4, 0.0,   2e-4,
                          6.5e-4,  9.99e-4, 1e-3, 1.0001e-3, 1.5e-3, 0.05, 0.4};
    const double rates[] = {-2.0, 0.0, 0.7};
    /* Step h = 1e-7 = w/1e4. The film law is piecewise quadratic in eps, so a central
     * difference is exact inside each piece; a piece boundary within h of eps adds at most
     * |jump of F''| h / 4 = ((k - kc) / (2 w)) h / 4 = 0.0123 N (attained exactly at eps =
     * +-w, which are in the list). Roundoff: eps_mach |F| / h
     * <= 2.2e-16 * 410 N / 1e-7 = 9e-7 N. In the rate F is linear: exact up to roundoff
     * eps_mach |F| / hr (hr = 1e-3): 1e-10 N. Tolerances: 0.0123 N + 1e-5 N in eps (1.2e-5 of
     * k: an error of 1e-4 k in a slope fails), 1e-6 N s in the rate. */
    const double h = 1e-7, hr = 1e-3;
    double worst_d = 0.0, worst_r = 0.0;
    for (int L = 0; L < 3; L++) {
        for (size_t i = 0; i < sizeof eps / sizeof eps[0]; i++) {
            for (size_t j = 0; j < sizeof rates / sizeof rates[0]; j++) {
                double e = eps[i], r = rates[j], F, dF, dFr, Fp, Fm, Frp, Frm;
                ck_ok(w, ws_law_evaluate(w, laws[L], e, r, &F, &dF, &dFr));
                ck_ok(w, ws_law_evaluate(w, laws[L], e + h, r, &Fp, NULL, NULL));
                ck_ok(w, ws_law_evaluate(w, laws[L], e - h, r, &Fm, NULL, NULL));
                ck_ok(w, ws_law_evaluate(w, laws[L], e, r + hr, &Frp, NULL, NULL));
                ck_ok(w, ws_law_evaluate(w, laws[L], e, r - hr, &Frm, NULL, NULL));
                double fd = (Fp - Fm) / (2 * h), fr = (Frp - Frm) / (2 * hr);
                double tol_d = (L == 2 ? (k - kc) / (2 * tw) * h / 4 : 0.0) + 1e-5;
                ck_assert_msg(fabs(fd - dF) <= tol_d,
                              "%s: dF/deps at eps %g rate %g: analytic %.12g, FD %.12g", names[L],
                              e, r, dF, fd);
                ck_assert_msg(fabs(fr - dFr) <= 1e-6,
                              "%s: dF/deps_dot at eps %g: analytic %.12g, FD %.12g", names[L], e,
                              dFr, fr);
                worst_d = fmax(worst_d, fabs(fd - dF));
                worst_r = fmax(worst_r, fabs(fr - dFr));
                /* Values: the header's definitions, to roundoff (1e-12 relative of k). */
                double want = L == 0   ? k * e
                              : L == 1 ? k * e + c * r
                                       : film_force(k, kc, c, tw, e, r);
                ck_assert_msg(fabs(F - want) <= 1e-12 * k,
                              "%s: F(%g, %g) = %.15g, definition %.15g", names[L], e, r, F, want);
                ck_assert_msg(fabs(dFr - (L == 0 ? 0.0 : c)) <= 0.0, "%s: dF/deps_dot %g",
                              names[L], dFr);
            }
        }
    }
    report("laws: largest |FD - dF/deps| = %.3g N, |FD - dF/deps_dot| = %.3g N s", worst_d,
           worst_r);
    /* Outside the join the film law is exactly k (tension) and kc (compression). */
    double d1, d2;
    ck_ok(w, ws_law_evaluate(w, laws[2], 0.01, 0.0, NULL, &d1, NULL));
    ck_ok(w, ws_law_evaluate(w, laws[2], -0.01, 0.0, NULL, &d2, NULL));
    ck_assert_double_eq(d1, k);
    ck_assert_double_eq(d2, kc);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_law_film_c1)
{
    ws_world *w = world_g(1e-4, NO_G);
    const double k = 1000.0, kc = 20.0, tw = 1e-3;
    ws_law_id L = make_law(w, WS_LAW_TENSION_COMPRESSION, k, kc, 0.0, tw);
    /* C1 at eps = +-w: value and slope from both sides of the end, 1 ulp apart. Across 2 ulp
     * (4.4e-19) the value may change by k * 4.4e-19 plus roundoff 2 eps_mach |F| (F <= 1 N):
     * bound 1e-15 N. The slope is continuous: its change across 2 ulp is at most
     * F'' * 4.4e-19 = 2e-13 N (F'' = (k - kc) / (2 w) = 4.9e5) plus roundoff: bound 1e-12 N.
     * A kink of the ramp (slope 1/2 at the end, say) would jump by 490 N. */
    const double ends[2] = {tw, -tw};
    for (int s = 0; s < 2; s++) {
        double e = ends[s], lo = nextafter(e, -1.0), hi = nextafter(e, 1.0);
        double Fl, Fh, dl, dh;
        ck_ok(w, ws_law_evaluate(w, L, lo, 0.0, &Fl, &dl, NULL));
        ck_ok(w, ws_law_evaluate(w, L, hi, 0.0, &Fh, &dh, NULL));
        report("film law at eps = %+g: F %.15g | %.15g N, dF/deps %.15g | %.15g N", e, Fl, Fh,
               dl, dh);
        ck_assert_msg(fabs(Fh - Fl) <= 1e-15, "F jumps by %g at eps = %g", Fh - Fl, e);
        ck_assert_msg(fabs(dh - dl) <= 1e-12, "dF/deps jumps by %g at eps = %g", dh - dl, e);
    }
    /* The slopes at the ends are k and kc exactly (the join's ramp g' runs 0 -> 1). */
    double dw, dmw;
    ck_ok(w, ws_law_evaluate(w, L, tw, 0.0, NULL, &dw, NULL));
    ck_ok(w, ws_law_evaluate(w, L, -tw, 0.0, NULL, &dmw, NULL));
    ck_assert_msg(fabs(dw - k) <= 1e-12 * k && fabs(dmw - kc) <= 1e-12 * k,
                  "slopes at the ends: %g (k = %g), %g (kc = %g)", dw, k, dmw, kc);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_law_energy)
{
    ws_world *w = world_g(1e-4, NO_G);
    const double k = 1000.0, kc = 20.0, c = 5.0, tw = 1e-3;
    ws_law_id laws[3] = {
        make_law(w, WS_LAW_LINEAR_ELASTIC, k, 0.0, 0.0, 0.0),
        make_law(w, WS_LAW_LINEAR_VISCOELASTIC, k, 0.0, c, 0.0),
        make_law(w, WS_LAW_TENSION_COMPRESSION, k, kc, c, tw),
    };
    const double ends[] = {-0.2, -1.5e-3, -1e-3, -4e-4, 3e-4, 1e-3, 2.5e-3, 0.3};
    double worst = 0.0;
    for (int L = 0; L < 3; L++) {
        double e0;
        ck_ok(w, ws_law_energy(w, laws[L], 0.0, &e0));
        /* 0 at eps = 0 up to the roundoff of the film law's constant w^2/12 (k w^2 eps_mach). */
        ck_assert_msg(fabs(e0) <= 1e-15 * k * tw * tw, "law %d: energy at 0 = %g", L, e0);
        for (size_t i = 0; i < sizeof ends / sizeof ends[0]; i++) {
            double b = ends[i], E;
            ck_ok(w, ws_law_energy(w, laws[L], b, &E));
            /* Trapezoid sum of the elastic force F(eps, 0) from 0 to b, N = 40000 intervals
             * (h <= 5e-6): exact on linear pieces; on the quadratic join its error is
             * h^2/12 |F''| per unit length over at most 2w: h^2 (k - kc) / 12 <= 2e-9 J/m;
             * roundoff N eps_mach max|F h| <= 1e-13. Tolerance 5e-9 J/m (relative 1e-7 of
             * k b^2 / 2 at the largest b). */
            const int N = 40000;
            double hh = b / N, sum = 0.0, fprev;
            ck_ok(w, ws_law_evaluate(w, laws[L], 0.0, 0.0, &fprev, NULL, NULL));
            for (int j = 1; j <= N; j++) {
                double f;
                ck_ok(w, ws_law_evaluate(w, laws[L], j * hh, 0.0, &f, NULL, NULL));
                sum += 0.5 * (f + fprev) * hh;
                fprev = f;
            }
            ck_assert_msg(fabs(E - sum) <= 5e-9,
                          "law %d: energy(%g) = %.12g J/m, trapezoid %.12g", L, b, E, sum);
            worst = fmax(worst, fabs(E - sum));
        }
    }
    report("law energy: largest |energy - trapezoid integral| = %.3g J/m", worst);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_law_bad_defs)
{
    ws_world *w = world_g(1e-4, NO_G);
    ws_law_id id;
    ws_law_def d;
    /* NULL and uninitialised Defs. */
    ck_assert_int_ne(ws_law_create(w, NULL, &id), WS_OK);
    memset(&d, 0, sizeof d);
    d.stiffness = 1.0;
    ck_assert_int_eq(ws_law_create(w, &d, &id), WS_ERR_UNINITIALIZED_DEF);
    ck_assert_uint_eq(id.bits, 0);
    struct {
        ws_law_type type;
        double k, kc, c, tr;
    } bad[] = {
        {WS_LAW_LINEAR_ELASTIC, 0.0, 0, 0, 1e-3},
        {WS_LAW_LINEAR_ELASTIC, -5.0, 0, 0, 1e-3},
        {WS_LAW_LINEAR_ELASTIC, NAN, 0, 0, 1e-3},
        {WS_LAW_LINEAR_ELASTIC, INFINITY, 0, 0, 1e-3},
        {WS_LAW_LINEAR_VISCOELASTIC, 10.0, 0, -1.0, 1e-3},
        {WS_LAW_LINEAR_VISCOELASTIC, 10.0, 0, NAN, 1e-3},
        {WS_LAW_TENSION_COMPRESSION, 10.0, -1.0, 0, 1e-3},
        {WS_LAW_TENSION_COMPRESSION, 10.0, NAN, 0, 1e-3},
        {WS_LAW_TENSION_COMPRESSION, 10.0, 0.0, 0, 0.0},
        {WS_LAW_TENSION_COMPRESSION, 10.0, 0.0, 0, -1e-3},
        {WS_LAW_TENSION_COMPRESSION, 10.0, 0.0, 0, NAN},
        {(ws_law_type)7, 10.0, 0, 0, 1e-3},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ws_law_def_init(&d);
        d.type = bad[i].type;
        d.stiffness = bad[i].k;
        d.compression_stiffness = bad[i].kc;
        d.damping = bad[i].c;
        d.transition = bad[i].tr;
        id.bits = 12345;
        ws_status s = ws_law_create(w, &d, &id);
        ck_assert_msg(s == WS_ERR_INVALID_ARGUMENT, "bad law %zu accepted (%s)", i,
                      ws_status_string(s));
        ck_assert_uint_eq(id.bits, 0);
        ck_assert_msg(strlen(ws_world_last_error(w)) > 0, "bad law %zu: no message", i);
    }
    /* The same film law with a valid transition is accepted. */
    ws_law_id ok = make_law(w, WS_LAW_TENSION_COMPRESSION, 10.0, 0.0, 0.0, 1e-3);
    ck_assert(ws_law_is_valid(w, ok));
    /* Evaluation needs finite arguments and a live law. */
    double F;
    ck_assert_int_eq(ws_law_evaluate(w, ok, NAN, 0.0, &F, NULL, NULL), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_law_energy(w, ok, INFINITY, &F), WS_ERR_INVALID_ARGUMENT);
    ck_ok(w, ws_law_destroy(w, ok));
    ck_assert(!ws_law_is_valid(w, ok));
    ck_assert_int_eq(ws_law_evaluate(w, ok, 0.1, 0.0, &F, NULL, NULL), WS_ERR_STALE_HANDLE);
    ws_world_destroy(w);
}
END_TEST

/* ======================================================================================
 * 2. Pre-stretched row between fixed ends
 * ====================================================================================== */

START_TEST(test_row_prestretch_tension)
{
    /* 11 nodes, spacing 0.1 m, both ends pinned, pre-stretch 0.25: rest length 0.08 m. EA =
     * 100 N, node mass 0.01 kg, Kelvin-Voigt c = 0.5 N s. The row is disturbed by a gravity
     * along x for 0.1 s, which is then removed. The law's damping matrix is (c/EA) K, so
     * mode j decays at (c / EA) omega_j^2 / 2; the slowest, omega_1 = 2 sqrt(k/m) sin(pi/20)
     * = 111 rad/s (k = EA/l0 = 1250 N/m), at 31 /s: after 1.9 s the disturbance (strain
     * ~1e-3) is below 1e-25 of it. The equilibrium is then l = 0.1 m for every spring. */
    const double dt = 2e-4, EA = 100.0, p = 0.25, sp = 0.1, m = 0.01;
    ws_world *w = world_g(dt, NO_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, EA, 0.0, 0.5, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = m;
    wd.law = law;
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
    fit_substeps(w, web, dt);

    /* Disturb: the tensions must really differ (else the test could not fail). */
    ws_vec3 gx = {20.0, 0, 0};
    ck_ok(w, ws_world_set_gravity(w, &gx));
    ck_ok(w, ws_world_step_n(w, 500));
    size_t ns;
    double *T = copy_tensions(w, web, &ns);
    ck_assert_uint_eq(ns, 10);
    double spread = 0.0;
    for (size_t i = 0; i < ns; i++)
        spread = fmax(spread, fabs(T[i] - EA * p) / (EA * p));
    free(T);
    report("row: tension spread under the x-load: %.3g of EA p", spread);
    ck_assert_msg(spread > 1e-3, "the disturbance did nothing (%g)", spread);
    ck_ok(w, ws_world_set_gravity(w, &NO_G));
    ck_ok(w, ws_world_step_n(w, 9500));

    /* Tensions EA p, strains p: tolerance 1e-9 relative (the residual is ~1e-25; roundoff of
     * positions of 1 m at 1e-16 gives strain errors ~1e-15). */
    T = copy_tensions(w, web, &ns);
    double strains[10];
    size_t cnt;
    ck_ok(w, ws_web_copy_spring_strains(w, web, strains, 10, &cnt));
    double worst = 0.0, el_sum = 0.0;
    for (size_t i = 0; i < ns; i++) {
        worst = fmax(worst, fabs(T[i] - EA * p) / (EA * p));
        ck_assert_msg(fabs(T[i] - EA * p) <= 1e-9 * EA * p, "spring %zu: T = %.12g, EA p = %g",
                      i, T[i], EA * p);
        ck_assert_msg(fabs(strains[i] - p) <= 1e-9 * p, "spring %zu: strain %.12g", i,
                      strains[i]);
        double l0 = sp / (1 + p);
        el_sum += l0 * EA * strains[i] * strains[i] / 2;
    }
    free(T);
    double ke, el, gr;
    ck_ok(w, ws_web_get_energy(w, web, &ke, &el, &gr));
    const double el_exact = 10 * (sp / (1 + p)) * EA * p * p / 2; /* 2.5 J */
    report("row: largest |T - EA p| / EA p = %.3g; elastic energy %.15g J (analytic %.15g), "
           "kinetic %.3g J",
           worst, el, el_exact, ke);
    /* Energy: sum of l0 EA eps^2 / 2 of the read-back strains to roundoff (1e-12), and the
     * analytic 10 l0 EA p^2 / 2 to 1e-9 (strains to 1e-9 give 2e-9; in fact ~1e-15). */
    ck_assert_msg(fabs(el - el_sum) <= 1e-12 * el_exact, "energy %.15g vs sum %.15g", el,
                  el_sum);
    ck_assert_msg(fabs(el - el_exact) <= 2e-9 * el_exact, "energy %.15g vs %.15g", el,
                  el_exact);
    ck_assert_msg(ke <= 1e-20, "still moving: kinetic %g J", ke);
    ws_world_destroy(w);
}
END_TEST

/* ======================================================================================
 * 3. Sag of a tensioned chain
 * ====================================================================================== */

START_TEST(test_chain_sag)
{
    /* 101 nodes over L = 1 m (spacing 0.01 m), ends pinned, pre-stretch 0.05, EA = 245 N:
     * H ~ 12.3 N. Node mass 1 g: w = 99 * 1e-3 * 9.81 / (99 * 0.01) = 0.981 N/m, sag ~ 1 cm.
     * Settling: node drag 0.06 kg/s damps every mode at d / (2 m) = 30 /s (the transverse
     * fundamental, omega_1 = pi sqrt(H / mu) / L = 35 rad/s, is near critical); a small law
     * damping helps the longitudinal modes. 1.5 s: residual ~e^-40 of the 1 cm drop. */
    const int n = 101;
    const double L = 1.0, sp = L / (n - 1), p = 0.05, EA = 245.0, m = 1e-3, dt = 1e-4;
    ws_world *w = world_g(dt, DOWN_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, EA, 0.0, 0.005, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = m;
    wd.node_damping = 0.06;
    wd.law = law;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = n;
    sd.ny = 1;
    sd.spacing_x = sp;
    sd.spacing_y = sp;
    sd.prestretch_x = p;
    uint32_t pins[2] = {0, (uint32_t)(n - 1)};
    sd.pinned = pins;
    sd.pinned_count = 2;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    fit_substeps(w, web, dt);
    ck_ok(w, ws_world_step_n(w, 15000));

    size_t nn, ns;
    double *x = copy_pos(w, web, &nn);
    double *T = copy_tensions(w, web, &ns);
    const int mid = (n - 1) / 2;
    /* Horizontal tension from the two springs at midspan (spring j joins nodes j, j+1): read
     * back from the springs, so it includes the extra stretch of the sagged chain (its length
     * grows by 8 sag^2 / (3 L) = 2.6e-4 m, H by EA 2.6e-4 = 0.06 N over EA p = 12.25 N). */
    double H = 0.0;
    for (int j = mid - 1; j <= mid; j++) {
        double dx = x[3 * (j + 1)] - x[3 * j], dz = x[3 * (j + 1) + 2] - x[3 * j + 2];
        H += 0.5 * T[j] * dx / hypot(dx, dz);
    }
    /* Every spring carries the same horizontal component (static equilibrium): 1e-8. */
    double hspread = 0.0, th_max = 0.0;
    for (int j = 0; j < n - 1; j++) {
        double dx = x[3 * (j + 1)] - x[3 * j], dz = x[3 * (j + 1) + 2] - x[3 * j + 2];
        hspread = fmax(hspread, fabs(T[j] * dx / hypot(dx, dz) - H) / H);
        th_max = fmax(th_max, atan2(fabs(dz), dx));
    }
    const double wpm = (n - 2) * m * G0 / ((n - 2) * sp); /* interior weight per metre */
    double sag = -x[3 * mid + 2];
    double pred = wpm * L * L / (8 * H);
    /* The same funicular with the nodes where they really are: H sag = moment at midspan of
     * the left half's loads about the midspan node (exact statics of the discrete chain). */
    double Rl = 0.5 * (n - 2) * m * G0, mom = Rl * (x[3 * mid] - x[0]);
    for (int i = 1; i < mid; i++)
        mom -= m * G0 * (x[3 * mid] - x[3 * i]);
    double pred_exact = mom / H;
    report("sag: measured %.9g m, w L^2 / (8 H) = %.9g m (rel %.3g), funicular with the real "
           "node x %.9g m (rel %.3g); H = %.6g N, horizontal spread %.3g, max slope %.4g rad",
           sag, pred, (sag - pred) / pred, pred_exact, (sag - pred_exact) / pred_exact, H,
           hspread, th_max);
    ck_assert_msg(hspread <= 1e-8, "horizontal tension not uniform: %g", hspread);
    /* For equal loads at equal horizontal spacing the node polygon is inscribed in the
     * parabola and the midspan sag is exactly w L^2 / (8 H) (n even: the midspan moment is
     * P s n^2 / 8 = w L^2 / 8). The horizontal spacing is l0 (cos(theta) + H / EA): it is not
     * uniform by at most theta_max^2 / 2 (theta_max = wL/(2H) = 0.04: 8e-4), which is the
     * chain's departure from the parabola (a catenary's would be a^2/12 = 1.3e-4, a = wL/2H).
     * Tolerance theta_max^2 / 2 on the relative sag. */
    double tol = 0.5 * th_max * th_max;
    ck_assert_msg(fabs(sag - pred) <= tol * pred, "sag %.9g vs w L^2/(8H) %.9g (tol %.3g)", sag,
                  pred, tol);
    /* Exact statics with the measured node positions: settling residual only: 1e-7. */
    ck_assert_msg(fabs(sag - pred_exact) <= 1e-7 * pred_exact, "sag %.12g vs funicular %.12g",
                  sag, pred_exact);
    free(x);
    free(T);
    ws_world_destroy(w);
}
END_TEST

/* ======================================================================================
 * 4. Longitudinal wave speed
 * ====================================================================================== */

/* Parabolic refinement of a sampled peak at index i (samples y[i-1..i+1] at step dt). */
static double peak_time(const double *y, int i, double dt)
{
    double a = y[i - 1], b = y[i], c = y[i + 1];
    double den = a - 2 * b + c;
    double off = den != 0.0 ? 0.5 * (a - c) / den : 0.0;
    return (i + off) * dt;
}

START_TEST(test_wave_speed)
{
    /* 600 nodes along x, spacing s = 0.01 m, node mass 0.01 kg, EA = 100 N, no pre-stretch
     * (rest = spacing): k = EA / s = 1e4 N/m, omega0 = sqrt(k/m) = 1000 rad/s, c = s omega0 =
     * 10 m/s. Node 0 pinned, the far end free. A Gaussian displacement (sigma = 8 nodes,
     * amplitude 0.1 mm) centred on node 150, released at rest, splits into two half pulses;
     * the right one's peak is timed at nodes 300 and 450 (before any reflection can get
     * there: the left one reaches node 300 only after 450 node spacings of travel). */
    const int n = 600, i0 = 150, j1 = 300, j2 = 450;
    const double s = 0.01, m = 0.01, EA = 100.0, A = 1e-4, sig = 8.0, dt = 1e-4;
    ws_world *w = world_g(dt, NO_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, EA, 0.0, 0.0, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = m;
    wd.law = law;
    double *dx = calloc((size_t)n, sizeof *dx);
    ck_assert(dx);
    for (int i = 0; i < n; i++)
        dx[i] = A * exp(-0.5 * (i - i0) * (i - i0) / (sig * sig));
    uint32_t pin = 0;
    ws_web_id web = make_chain(w, &wd, n, s, s, dx, NULL, &pin, 1);
    free(dx);
    double S;
    ck_ok(w, ws_web_get_stable_dt(w, web, &S));
    ck_assert(dt < S);
    const int steps = 3600; /* 0.36 s: the right peak reaches 450 at 0.30 s */
    double *u1 = calloc(steps + 1, sizeof *u1), *u2 = calloc(steps + 1, sizeof *u2);
    double *pos = malloc(3 * (size_t)n * sizeof *pos);
    ck_assert(u1 && u2 && pos);
    for (int k = 0; k <= steps; k++) {
        size_t cnt;
        ck_ok(w, ws_web_copy_positions(w, web, pos, (size_t)n, &cnt));
        u1[k] = pos[3 * j1] - j1 * s;
        u2[k] = pos[3 * j2] - j2 * s;
        if (k < steps)
            ck_ok(w, ws_world_step(w));
    }
    int k1 = 1, k2 = 1;
    for (int k = 1; k < steps; k++) {
        if (u1[k] > u1[k1])
            k1 = k;
        if (u2[k] > u2[k2])
            k2 = k;
    }
    ck_assert(k1 > 1 && k1 < steps - 1 && k2 > 1 && k2 < steps - 1);
    double t1 = peak_time(u1, k1, dt), t2 = peak_time(u2, k2, dt);
    const double c = s * sqrt(EA / s / m);
    double cm = (j2 - j1) * s / (t2 - t1);
    double c1 = (j1 - i0) * s / t1;
    report("wave: peak at node %d after %.6f s, node %d after %.6f s (amplitudes %.4g, %.4g of "
           "A/2); speed %.6f m/s between them, %.6f m/s from the start; c = %.6f m/s (rel %.3g)",
           j1, t1, j2, t2, u1[k1] / (0.5 * A), u2[k2] / (0.5 * A), cm, c1, c, (cm - c) / c);
    /* Dispersion of the lattice: omega = 2 omega0 sin(kappa/2) = omega0 (kappa - kappa^3/24
     * + ...) (kappa in rad per node). In the frame moving at c the pulse is
     * int exp(-kappa^2 sigma^2 / 2) cos(kappa xi + beta kappa^3) dkappa, beta = D / 24 after D
     * nodes of travel; to first order in beta / sigma^3 its peak lags by
     * beta <kappa^4> / <kappa^2> = 3 beta / sigma^2 = D / (8 sigma^2): the peak moves
     * at c (1 - 1 / (8 sigma^2)) = c (1 - 1.95e-3) for sigma = 8.
     * (a) Against c: tolerance 2 x that slowdown, 1 / (4 sigma^2) = 3.9e-3, and the pulse must
     *     be slower than c (a lattice only slows it).
     * (b) Against the dispersion-corrected speed: what is left is second order in
     *     beta / sigma^3 (<= 12.5 / 512 = 2.4 %) of the 0.3-node lag (~1e-4 relative over the
     *     150 nodes), the kappa^5 term (3e-6), symplectic Euler's frequency error
     *     (omega dt)^2 / 24 (omega ~ omega0 / sigma: 7e-6) and the parabolic peak refinement
     *     of samples 0.1 node-time apart (< 1e-5): tolerance 2.5e-4.
     * From the start (t = 0) the time includes the split of the initial bump and the half-step
     * offset of symplectic Euler's velocities (dt/2 = 0.05 node-time): only (a) applies. */
    double tol = 1.0 / (4 * sig * sig), cdisp = c * (1 - 1.0 / (8 * sig * sig));
    report("wave: dispersion-corrected speed c (1 - 1/(8 sigma^2)) = %.6f m/s (measured rel "
           "%.3g)",
           cdisp, (cm - cdisp) / cdisp);
    ck_assert_msg(fabs(cm - c) <= tol * c, "speed %.6f vs %.6f (tol %.3g)", cm, c, tol);
    ck_assert_msg(cm <= c * (1 + 1e-6), "pulse faster than c: %.8f > %.8f", cm, c);
    ck_assert_msg(fabs(cm - cdisp) <= 2.5e-4 * cdisp, "speed %.6f vs dispersive %.6f", cm,
                  cdisp);
    ck_assert_msg(fabs(c1 - c) <= tol * c, "speed from the start %.6f vs %.6f", c1, c);
    /* The peak keeps about half the amplitude (the pulse split in two): 0.5 A within the
     * dispersive spreading (a few %): 10 %. */
    ck_assert_msg(fabs(u1[k1] - 0.5 * A) <= 0.1 * 0.5 * A, "peak amplitude %g", u1[k1]);
    free(u1);
    free(u2);
    free(pos);
    ws_world_destroy(w);
}
END_TEST

/* ======================================================================================
 * 5. Band around a cylinder
 * ====================================================================================== */

static ws_body_id add_cylinder(ws_world *w, double R, double h, int seg, ws_quat q,
                               const char *name)
{
    ws_shape_id s;
    ck_ok(w, ws_shape_create_cylinder(w, R, h, seg, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = s;
    bd.orientation = q;
    bd.name = name;
    ws_body_id id;
    ck_ok(w, ws_body_create(w, &bd, &id));
    return id;
}

static void band_case(double mu)
{
    /* Cylinder R = 0.1 m, 128 sides, axis z, kinematic at rest. A band of 64 x 3 nodes at z =
     * -0.05, 0, 0.05, pre-stretch 0.2 around, 0 up (the up-springs start at rest and stay so),
     * no gravity. EA = 100 N: T ~ 20 N. Node mass 1 g, node drag 0.5 kg/s: every mode decays
     * at 250 /s or faster (the contact and springs make them stiff): after 0.3 s the residual
     * is e^-75. Film-cylinder pair: k = 4000 N/m, c = 1 kg/s, mu as given. */
    const double R = 0.1, dt = 1e-4, EA = 100.0, kc = 4000.0, reach = 2e-3;
    const int seg = 128, na = 64, nu = 3;
    ws_world *w = world_g(dt, NO_G);
    ws_quat q = {1, 0, 0, 0};
    ws_body_id cyl = add_cylinder(w, R, 0.3, seg, q, "cylinder");
    ws_material_def md;
    ws_material_def_init(&md);
    md.name = "film";
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
    wd.name = "band";
    ws_band_def bdf;
    ws_band_def_init(&bdf);
    bdf.bodies = &cyl;
    bdf.body_count = 1;
    bdf.z_bottom = -0.05;
    bdf.z_top = 0.05;
    bdf.n_around = na;
    bdf.n_up = nu;
    bdf.prestretch_around = 0.2;
    bdf.prestretch_up = 0.0;
    ws_web_id web;
    ck_ok(w, ws_web_create_band(w, &wd, &bdf, &web));
    ws_web_info info;
    ck_ok(w, ws_web_get_info(w, web, &info));
    ck_assert_int_eq(info.closed, 1);
    ck_assert_uint_eq(info.spring_count, (uint32_t)(na * nu + na * (nu - 1)));
    int sub = fit_substeps(w, web, dt);
    ck_ok(w, ws_world_step_n(w, 3000));

    size_t nn, ns;
    double *x = copy_pos(w, web, &nn);
    double *T = copy_tensions(w, web, &ns);
    double *fc = malloc(3 * nn * sizeof *fc);
    ck_assert(fc);
    ck_ok(w, ws_web_copy_contact_forces(w, web, fc, nn, &nn));
    ws_containment_band cb[3];
    ck_ok(w, ws_web_get_containment(w, web, cb, 3));
    const double a = R * cos(PI / seg); /* apothem of the 128-gon */
    for (int j = 0; j < nu; j++) {
        double Tm = 0.0, Tmin = INFINITY, Tmax = -INFINITY, F = 0.0, Fr = 0.0, rm = 0.0;
        double worst_law = 0.0, worst_dir = 0.0;
        for (int i = 0; i < na; i++) {
            double t = T[j * na + i]; /* around-springs of row j */
            Tm += t / na;
            Tmin = fmin(Tmin, t);
            Tmax = fmax(Tmax, t);
            const double *p = x + 3 * (j * na + i), *f = fc + 3 * (j * na + i);
            double fn = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
            double r = hypot(p[0], p[1]);
            F += fn;
            Fr += (f[0] * p[0] + f[1] * p[1]) / r; /* radial part, outward on the film */
            rm += r / na;
            /* The face this node presses on: the one whose normal is closest to the force. */
            double ang = atan2(f[1], f[0]);
            double fidx = floor((ang < 0 ? ang + 2 * PI : ang) / (2 * PI / seg));
            double thf = (fidx + 0.5) * 2 * PI / seg; /* face normals sit between vertices */
            double c0 = cos(thf), s0 = sin(thf);
            double d = p[0] * c0 + p[1] * s0 - a;
            double want = kc * (reach - d);
            if (mu == 0.0) {
                /* Frictionless at rest: the force is k overlap along the face normal
                 * (damping times a zero rate): 1e-6 relative (settling residual). */
                worst_law = fmax(worst_law, fabs(fn - want) / want);
                worst_dir = fmax(worst_dir, fabs(f[0] * s0 - f[1] * c0) / fn);
            }
        }
        /* Equilibrium of a node: its contact force balances the two around-springs (turning
         * angle alpha_i); sum over a row = sum 2 T sin(alpha_i / 2) = 2 N T sin(pi / N) for a
         * regular polygon of N nodes: 2 pi T (1 - pi^2 / (6 N^2)) = 2 pi T (1 - 4.0e-4).
         * The 128-gon makes the turning angles and tensions vary around (the face normal is
         * not the bisector of a node's springs, offsets up to pi/128 = 0.025 rad): second
         * order, (pi/128)^2 = 6e-4 at most. Tolerance on the row sum against 2 pi T:
         * 4.0e-4 + 6e-4 + settling (1e-9): 1.5e-3. */
        double pred = 2 * PI * Tm;
        report("band mu %.1f row %d: sum |f_contact| %.6f N, 2 pi T %.6f N (rel %.3g), "
               "2 N T sin(pi/N) %.6f N; T %.6f N (spread %.2g), pressure per metre %.4f N/m vs "
               "T / r = %.4f N/m, r = %.6f m (R + layers %.6f); contact law %.2g, dir %.2g; "
               "substeps %d",
               mu, j, F, pred, (F - pred) / pred, 2 * na * Tm * sin(PI / na), Tm,
               (Tmax - Tmin) / Tm, F / (2 * PI * rm), Tm / rm, rm, R + reach, worst_law,
               worst_dir, sub);
        ck_assert_msg(fabs(F - pred) <= 1.5e-3 * pred, "row %d: sum %.6f vs 2 pi T %.6f", j, F,
                      pred);
        /* The discrete identity itself: 64 nodes on 128 faces sit alike, one on every other
         * face (the generator spaces them equally around the offset outline), so the node
         * polygon is regular and the sum is 2 N T sin(pi / N) up to settling (e^-75) and
         * roundoff: 1e-6. */
        double pred_d = 2 * na * Tm * sin(PI / na);
        ck_assert_msg(fabs(F - pred_d) <= 1e-6 * pred_d, "row %d: sum %.9f vs 2 N T sin %.9f", j,
                      F, pred_d);
        /* Frictionless, the forces are face normals, within pi/128 of radial: the radial part
         * is at least cos(pi/128) = 1 - 3e-4 of the total (and at most all of it). */
        if (mu == 0.0)
            ck_assert_msg(Fr <= F * (1 + 1e-12) && Fr >= F * cos(PI / seg) * (1 - 1e-12),
                          "row %d: radial part %.6f of %.6f", j, Fr, F);
        if (mu == 0.0) {
            ck_assert_msg(worst_law <= 1e-6, "row %d: |f| vs k overlap off by %g", j, worst_law);
            ck_assert_msg(worst_dir <= 1e-6, "row %d: force off the face normal by %g", j,
                          worst_dir);
        }
        /* The containment read-out says the same: its hoop tension is the row mean and its
         * contact force the row sum (same quantities: 1e-12). */
        ck_assert_msg(fabs(cb[j].hoop_tension - Tm) <= 1e-12 * Tm, "hoop %.12g vs %.12g",
                      cb[j].hoop_tension, Tm);
        ck_assert_msg(fabs(cb[j].contact_force - F) <= 1e-12 * F, "contact %.12g vs %.12g",
                      cb[j].contact_force, F);
        /* Line load: hoop tension over the row pitch, 0.05 m (rows stay where they were put:
         * the up-springs are at rest and nothing pushes along z): 1e-9. */
        ck_assert_msg(fabs(cb[j].line_load - Tm / 0.05) <= 1e-9 * Tm / 0.05,
                      "line load %.12g vs T / pitch %.12g", cb[j].line_load, Tm / 0.05);
        /* The band sits on the faces, pressed in by f / k: its radius lies between the
         * apothem + layers - max overlap and the vertex radius + layers (1 um slack). */
        ck_assert_msg(rm < R + reach + 1e-6 && rm > a + reach - 2 * Tm * sin(PI / na) / kc - 1e-4,
                      "row %d: radius %.6f", j, rm);
    }
    free(x);
    free(T);
    free(fc);
    ws_world_destroy(w);
}

START_TEST(test_band_pressure)
{
    band_case(0.0);
    band_case(0.3);
}
END_TEST

/* ======================================================================================
 * 6. Capstan over a rotating cylinder
 * ====================================================================================== */

/* Continuum capstan with the film's own weight, phi from 0 (hanging-mass side) to pi (pinned
 * side) over the top of a circle of radius r in the x-z plane: N = T / r + w sin(phi) per unit
 * length, dT/dphi = sg mu (T + w r sin(phi)) + w r cos(phi), sg = +1 when the friction on the
 * film points toward the hanging mass. RK4. */
static double capstan_ode(double T0, double sg, double mu, double wr)
{
    const int N = 2000;
    double h = PI / N, T = T0;
    for (int i = 0; i < N; i++) {
        double p = i * h;
#define CF(ph, t) (sg * mu * ((t) + wr * sin(ph)) + wr * cos(ph))
        double k1 = CF(p, T), k2 = CF(p + h / 2, T + h / 2 * k1);
        double k3 = CF(p + h / 2, T + h / 2 * k2), k4 = CF(p + h, T + h * k3);
#undef CF
        T += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    return T;
}

typedef struct capstan_out {
    double ratio;      /* time-averaged T_pinned-side / T_mass-side */
    double pred;       /* continuum with the film's weight */
    double pure;       /* exp(sg mu pi) */
    double Tm, Tp;     /* time-averaged tensions, N */
    double wobble;     /* rms of the ratio over the window / its mean */
    double contact_frac; /* arc nodes in contact (mean) */
    double below;      /* weight hanging under the measured mass-side spring, N */
    int substeps;
} capstan_out;

static void capstan_run(double rate, int implicit, capstan_out *o)
{
    /* Cylinder R = 0.1 m, 256 sides, axis y (the z-cylinder turned 90 deg about x), kinematic,
     * turning at `rate` rad/s about +y (a TILT drive through its centre; surface speed 0.2
     * m/s = 20 v_lim, so every touching node slides: full kinetic friction mu = 0.3). A chain
     * in the x-z plane: pinned at (-r, 0, -0.1), up, over the top, down to a free node of mass
     * M = 0.1 kg at (r, 0, -0.1). Spacing 5 mm (64 nodes on the half turn), EA = 100 N, light
     * nodes m = M / 5000 (the arc weighs 1.3 % of M; its effect is in the prediction), node
     * drag d = 0.25 kg/s: with the chain's own drag (~ N d / 3) the bounce of M on the chain
     * (sqrt(EA / (L M)) = 44 rad/s) is about critically damped. Film-cylinder pair: k = 2000
     * N/m (the node loads T dphi = 0.02-0.12 N sink the nodes 10-60 um into the layers),
     * c = 0.01 kg/s. The rest lengths are set so that the expected capstan tensions hold at the
     * start (small initial bounce). rate > 0 drags the film over the top toward +x, the mass
     * side. */
    const double R = 0.1, mu = 0.3, M = 0.1, s = 0.005, EA = 100.0, m = M / 5000.0, Lh = 0.1;
    const double dt = 1e-4, kc = 2000.0, reach = 2e-3;
    const int seg = 256;
    ws_world_def wdf;
    ws_world_def_init(&wdf);
    wdf.dt = dt;
    wdf.gravity = DOWN_G;
    wdf.detection_interval = 20;
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&wdf, &w), WS_OK);
    ws_quat q = {cos(PI / 4), sin(PI / 4), 0, 0};
    ws_body_id cyl = add_cylinder(w, R, 0.1, seg, q, "drum");
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    dd.type = WS_DRIVE_TILT;
    dd.axis = (ws_vec3){0, 1, 0};
    dd.point = (ws_vec3){0, 0, 0};
    dd.rate = rate;
    dd.ramp_time = 0.02;
    dd.start_time = 0.01;
    ck_ok(w, ws_body_set_drive(w, cyl, &dd));
    ws_material_def md;
    ws_material_def_init(&md);
    ws_material_id film, dflt;
    ck_ok(w, ws_material_create(w, &md, &film));
    ck_ok(w, ws_world_get_default_material(w, &dflt));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = kc;
    cd.damping = 0.01;
    cd.friction = mu;
    cd.friction_vlim = 0.01;
    ck_ok(w, ws_world_set_contact(w, film, dflt, &cd));

    /* Geometry. */
    const double sg = rate > 0 ? 1.0 : -1.0;
    const double a = R * cos(PI / seg);
    const int nL = (int)lround(Lh / s); /* segments of each strand */
    double r0 = a + reach;
    int narc = (int)lround(PI * r0 / s);
    double dphi = PI / narc;
    const double Tguess = M * G0 * (sg > 0 ? 1.6 : 0.8);
    double r = a + reach - Tguess * dphi / kc; /* pressed in by the mean node load */
    const int n = (nL + 1) + (narc - 1) + (nL + 1);
    double *pos = calloc(3 * (size_t)n, sizeof *pos), *mass = calloc((size_t)n, sizeof *mass);
    uint32_t *spr = calloc(2 * (size_t)(n - 1), sizeof *spr);
    double *rest = calloc((size_t)(n - 1), sizeof *rest), *Texp = calloc((size_t)n, sizeof *Texp);
    ck_assert(pos && mass && spr && rest && Texp);
    int k = 0;
    for (int i = 0; i <= nL; i++, k++) { /* left strand, pinned node 0 at the bottom */
        pos[3 * k] = -r;
        pos[3 * k + 2] = -Lh + i * s;
    }
    const int tanP = k - 1; /* left tangent node (z = 0, phi = pi) */
    for (int j = 1; j < narc; j++, k++) {
        double ph = PI - j * dphi;
        pos[3 * k] = r * cos(ph);
        pos[3 * k + 2] = r * sin(ph);
    }
    const int tanM = k; /* right tangent node (phi = 0) */
    for (int i = 0; i <= nL; i++, k++) {
        pos[3 * k] = r;
        pos[3 * k + 2] = -i * s;
    }
    ck_assert_int_eq(k, n);
    for (int i = 0; i < n; i++)
        mass[i] = m;
    mass[n - 1] = M;
    /* Expected tension of spring i (nodes i, i+1), walking from the mass up and over. */
    double t = M * G0;
    for (int i = n - 2; i >= 0; i--) {
        Texp[i] = t;
        if (i > tanM || i <= tanP)
            t += (i > tanM ? 1.0 : -1.0) * m * G0; /* strands: the weight below */
        else
            t *= exp(sg * mu * dphi);
    }
    for (int i = 0; i + 1 < n; i++) {
        spr[2 * i] = (uint32_t)i;
        spr[2 * i + 1] = (uint32_t)(i + 1);
        double l = hypot(pos[3 * (i + 1)] - pos[3 * i], pos[3 * (i + 1) + 2] - pos[3 * i + 2]);
        rest[i] = l / (1.0 + Texp[i] / EA);
    }
    ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, EA, 0.0, 0.0, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.law = law;
    wd.material = film;
    wd.node_damping = 0.25;
    wd.name = "capstan";
    wd.integrator = implicit ? WS_WEB_IMPLICIT : WS_WEB_EXPLICIT;
    /* node_masses win over node_mass, but take_common refuses node_mass = 0 without an areal
     * density even when node_masses are given (see test_mesh_node_masses): give both. */
    wd.node_mass = m;
    ws_web_mesh_def mdf;
    ws_web_mesh_def_init(&mdf);
    mdf.positions = pos;
    mdf.node_count = (size_t)n;
    mdf.node_masses = mass;
    mdf.springs = spr;
    mdf.spring_count = (size_t)(n - 1);
    mdf.rest_lengths = rest;
    uint32_t pin = 0;
    mdf.pinned = &pin;
    mdf.pinned_count = 1;
    ws_web_id web;
    ck_ok(w, ws_web_create_mesh(w, &wd, &mdf, &web));
    free(pos);
    free(spr);
    free(rest);
    o->substeps = implicit ? 1 : fit_substeps(w, web, dt);

    /* Measured springs: 3 nodes below each tangent node, well off the drum (a straight
     * strand leaves the circle: z^2 / (2 r) > overlap only below ~5 mm). */
    const int kP = tanP - 4; /* nodes tanP-4, tanP-3: z = -4s, -3s */
    const int kM = tanM + 3; /* nodes tanM+3, tanM+4: z = -3s, -4s */
    const int settle = 8000, window = 4000;
    ck_ok(w, ws_world_step_n(w, settle));
    double sp = 0, sm = 0, sr = 0, sr2 = 0, cf = 0;
    size_t ns;
    double *T = malloc((size_t)(n - 1) * sizeof *T), *fc = malloc(3 * (size_t)n * sizeof *fc);
    ck_assert(T && fc);
    for (int st = 0; st < window; st++) {
        ck_ok(w, ws_world_step(w));
        ck_ok(w, ws_web_copy_spring_tensions(w, web, T, (size_t)(n - 1), &ns));
        sp += T[kP];
        sm += T[kM];
        sr += T[kP] / T[kM];
        sr2 += (T[kP] / T[kM]) * (T[kP] / T[kM]);
        if (st % 50 == 0) {
            size_t c2;
            ck_ok(w, ws_web_copy_contact_forces(w, web, fc, (size_t)n, &c2));
            int in = 0;
            for (int i = tanP; i <= tanM; i++)
                in += (fc[3 * i] != 0.0 || fc[3 * i + 2] != 0.0);
            cf += (double)in / (tanM - tanP + 1) / (window / 50);
        }
    }
    free(T);
    free(fc);
    o->Tp = sp / window;
    o->Tm = sm / window;
    o->ratio = o->Tp / o->Tm;
    double mr = sr / window;
    o->wobble = sqrt(fmax(sr2 / window - mr * mr, 0.0)) / mr;
    o->contact_frac = cf;
    /* Prediction: up the mass strand by the 3 light nodes between kM and the tangent, the
     * capstan with the arc's own weight (w = m g per arc spacing), down the pinned strand by 3
     * nodes to kP. */
    double wr = m * G0 / (r * dphi) * r;
    double Ttop = capstan_ode(o->Tm + 3 * m * G0, sg, mu, wr);
    o->pred = (Ttop - 3 * m * G0) / o->Tm;
    o->pure = exp(sg * mu * PI);
    o->below = M * G0 + (n - 2 - (kM + 1) + 1) * m * G0; /* M and the light nodes under kM */
    free(Texp);
    free(mass);
    ws_world_destroy(w);
}

/* The capstan's run and checks, on the explicit film or (implicit) the implicit one at one
 * step a world step, far beyond its explicit stable step. */
static void capstan_check(int implicit)
{
    /* Which way: the drum drags the film the way its surface moves. Dragged toward the mass,
     * the friction on the film points toward the mass and the pinned end must hold M g plus
     * the friction: T_pinned = M g exp(+mu pi) (hoisting). Dragged toward the pinned end, the
     * friction helps the pinned end: T_pinned = M g exp(-mu pi) (lowering).
     *
     * Tolerance on the ratio against the continuum prediction with the film's weight:
     *  - contact compliance: the nodes sink delta = N / k into the layers, delta ~ T, so the
     *    film is not quite perpendicular to the radius where T changes and at the ends, and
     *    the normal force gets a share along the film: O(delta_max / r) = (T_max dphi / k) / r
     *    = (2.5 * 0.049 / 2000) / 0.1 = 6e-4 at most (checked with 256 sides: deviation
     *    2.7e-3 at k = 200 N/m, 1.0e-3 at 2000, 8.5e-4 at 5000: the 1/k share is 2e-4 here);
     *  - discrete nodes: per node T+/T- = (1 + mu tan(dphi/2)) / (1 - mu tan(dphi/2)), whose
     *    product over pi differs from exp(mu pi) by mu pi (1 + mu^2) dphi^2 / 12 = 2e-4;
     *  - the lumped weights: where the film leaves the drum is uncertain by +-1 node: m g / T
     *    = 2e-4 of the tension;
     *  - the 256-gon turning under the film: the nodes ride over its faces and the rounded
     *    rims of the layer at its edges (apothem vs vertex radius: 7.5 um, 15 mN of the
     *    0.02-0.12 N node loads), a 0.35-0.4 % rms wobble at ~80 Hz that the 0.4 s window
     *    averages out, and a small steady share: refining the drum moves the ratio toward the
     *    prediction (at k = 2000 N/m, relative deviations 2.2e-3 with 128 sides, 1.0e-3 with
     *    256, 6e-4 with 512, 5e-4 with 1024; the 1024-side rest is the compliance term): 8e-4;
     *  - the strands' lean (pinned node vs where the film leaves the drum): 1e-4 rad, mu 1e-4
     *    = 3e-5; the bounce of M decays by e^-30 in 0.8 s.
     * Shares as measured: 2e-4 + 2e-4 + 2e-4 + 8e-4 = 1.4e-3 (the whole deviation measured
     * here is 1.0e-3 in both directions): tolerance 1.5e-3 relative.
     * Without the weight correction the ratio differs from exp(+-mu pi) by 0.4 % and 0.9 %
     * (reported); a friction coefficient off by 1 % would move the ratio by 0.9 %. */
    const double mu = 0.3;
    const double rates[2] = {2.0, -2.0};
    const char *what[2] = {"drum drags the film toward the mass (hoisting)",
                           "drum drags the film toward the pinned end (lowering)"};
    for (int i = 0; i < 2; i++) {
        capstan_out o;
        capstan_run(rates[i], implicit, &o);
        report("capstan%s, %s: T_pinned %.6f N, T_mass %.6f N, ratio %.6f; predicted %.6f with "
               "the film's weight (rel %.3g), exp(%+.1f pi) = %.6f (rel %.3g); ratio wobble "
               "%.2g rms, arc nodes touching %.3f, substeps %d",
               implicit ? " (implicit film)" : "", what[i], o.Tp, o.Tm, o.ratio, o.pred, (o.ratio - o.pred) / o.pred,
               rates[i] > 0 ? mu : -mu, o.pure, (o.ratio - o.pure) / o.pure, o.wobble,
               o.contact_frac, o.substeps);
        ck_assert_msg(fabs(o.ratio - o.pred) <= 1.5e-3 * o.pred,
                      "%s: ratio %.6f vs capstan %.6f", what[i], o.ratio, o.pred);
        /* The ratio is on the right side of 1 (the direction of the friction). */
        ck_assert_msg((o.ratio - 1) * rates[i] > 0, "%s: ratio %.6f on the wrong side of 1",
                      what[i], o.ratio);
        /* The measured mass-side spring carries the weight hanging below it: M and the light
         * nodes. Time-averaged over a window of a bounded motion, the mean acceleration term
         * is (velocity change) / window, negligible: 1e-4 of M g. */
        ck_assert_msg(fabs(o.Tm - o.below) <= 1e-4 * o.below,
                      "mass-side tension %.6f vs the weight below %.6f", o.Tm, o.below);
    }
}

START_TEST(test_capstan)
{
    capstan_check(0);
}
END_TEST

START_TEST(test_capstan_implicit)
{
    /* The same answers on the implicit film in one step of 0.1 ms, where the explicit film
     * takes 8 sub-steps (the light nodes' stable step is 25 us): sliding friction taken as the damper mu N / |t| over the slip ends
     * each step with mu N |t1| / |t0|, which is mu N where the slip is steady (the drum turns
     * at a constant rate), and the same tolerance holds. */
    capstan_check(1);
}
END_TEST

/* ======================================================================================
 * 7. No energy gain without damping
 * ====================================================================================== */

/* A sheet of nx x ny nodes of 1 g with shear springs, one law for every spring, spacing sp and
 * pre-stretch pre both ways, nodes pins[0, npins) held; *wd its web Def, for a mesh web of the
 * same film (copy_sheet). */
static ws_web_id shear_sheet(ws_world *w, ws_law_id law, int nx, int ny, double sp, double pre,
                             const uint32_t *pins, size_t npins, ws_web_def *wd)
{
    ws_web_def_init(wd);
    wd->node_mass = 1e-3;
    wd->law = wd->law_cross = wd->law_shear = law;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = nx;
    sd.ny = ny;
    sd.spacing_x = sd.spacing_y = sp;
    sd.prestretch_x = sd.prestretch_y = pre;
    sd.shear = 1;
    sd.pinned = pins;
    sd.pinned_count = npins;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, wd, &sd, &web));
    return web;
}

static uint64_t lcg_state;
static double lcg(void) /* uniform in [-1, 1) */
{
    lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return ((double)(lcg_state >> 11) * (1.0 / 9007199254740992.0)) * 2.0 - 1.0;
}

START_TEST(test_energy_no_gain)
{
    /* A free 5 x 5 sheet with shear springs (spacing 0.05 m, rest lengths of a 10 % pre-stretch,
     * linear elastic EA = 50 N, node mass 1 g), no damping, no gravity, no bodies, every node
     * displaced at random by up to 5 mm in x, y, z (a mesh web with the sheet's springs). */
    const double EA = 50.0;
    ws_world *w = world_g(1e-4, NO_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, EA, 0.0, 0.0, 0.0);
    ws_web_def wd;
    ws_web_id sheet = shear_sheet(w, law, 5, 5, 0.05, 0.1, NULL, 0, &wd);
    sheet_copy c = copy_sheet(w, sheet);
    ck_ok(w, ws_web_destroy(w, sheet));
    lcg_state = 12345;
    for (size_t i = 0; i < 3 * c.md.node_count; i++)
        c.x[i] += 5e-3 * lcg();
    ws_web_id web;
    ck_ok(w, ws_web_create_mesh(w, &wd, &c.md, &web));
    free_sheet_copy(&c);
    /* dt = 0.1 S, S = 2 / omega_max the web's stable step (Gershgorin bound on omega_max). */
    double S;
    ck_ok(w, ws_web_get_stable_dt(w, web, &S));
    const double dt = 0.1 * S, wdt = 2.0 * 0.1; /* omega_max dt */
    ck_ok(w, ws_world_set_dt(w, dt));
    const int steps = 30000;
    double *E = malloc((steps + 1) * sizeof *E);
    ck_assert(E);
    double kmax = 0.0, ke, el;
    for (int k = 0; k <= steps; k++) {
        ck_ok(w, ws_web_get_energy(w, web, &ke, &el, NULL));
        E[k] = ke + el;
        kmax = fmax(kmax, ke);
        if (k < steps)
            ck_ok(w, ws_world_step(w));
    }
    double E0 = E[0], dev = 0.0, a1 = 0.0, a3 = 0.0;
    int third = (steps + 1) / 3;
    for (int k = 0; k <= steps; k++) {
        dev = fmax(dev, fabs(E[k] - E0) / E0);
        if (k < third)
            a1 += E[k] / third;
        if (k >= steps + 1 - third)
            a3 += E[k] / third;
    }
    report("energy: E0 = %.6g J, dt = %.3g s (omega_max dt = %.2f), largest |E - E0| / E0 = "
           "%.3g, first-third mean %.9g J, last-third mean %.9g J (drift %.3g), kinetic up to "
           "%.3g of E0, %d steps (%.3g s)",
           E0, dt, wdt, dev, a1, a3, (a3 - a1) / E0, kmax / E0, steps, steps * dt);
    /* Real motion: the kinetic energy takes a good part of E0 (else nothing is tested). */
    ck_assert_msg(kmax > 0.2 * E0, "hardly any motion: kinetic up to %g of E0", kmax / E0);
    /* Symplectic Euler keeps a modified energy exactly (linear) or to exponentially long times
     * (nonlinear); the true energy oscillates about it: for a mode omega the difference is
     * omega^2 dt x v / 2 <= (omega dt / 2) of the mode's energy (first order in dt, not
     * second). Bound: (omega_max dt) / 2 = 0.1 of E0 (all energy in the top mode). */
    ck_assert_msg(dev <= 0.5 * wdt, "energy deviates by %g of E0 (bound %g)", dev, 0.5 * wdt);
    /* No drift: the thirds' means differ only by the averaged oscillation. Over the ~100
     * slowest periods of a third that average is far below its amplitude: 1e-2 of the bound
     * (1e-3 of E0). An integrator that gains (explicit Euler: a factor 1 + (omega dt)^2 per
     * step) would be off by orders of magnitude. */
    ck_assert_msg(fabs(a3 - a1) <= 0.01 * 0.5 * wdt * E0, "drift %g of E0", (a3 - a1) / E0);
    free(E);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_sheet_in_blocks_moves_as_its_mesh)
{
    /* A sheet of 7 x 150 nodes with shear springs is swept in blocks of whole rows (55 rows of
     * 7, the first count past WS_WEB_BLOCK_NODES = 384: blocks of 55, 55 and 40 rows); the same
     * nodes, springs and rest lengths as a mesh web are swept as one block, spring by spring.
     * Both hang from their four corners under gravity (the film law, EA 50 N, 1 % in
     * compression, light damping; nodes of 1 g, spacing 20 mm, pre-stretch 10 %) for 0.1 s. The
     * two add each node's forces in another order, so they differ by round-off: some 1e-16 of a
     * force a step, in a damped motion that stays bounded (a few 1e-15 m after 2000 steps). A
     * row whose springs or integration a block left out or took twice would be off by more
     * than the sheet's first millimetre of sag. Tolerance 1e-9 m. */
    const int nx = 7, ny = 150;
    const double dt = 5e-5;
    ws_world *w = world_g(dt, DOWN_G);
    ws_law_id law = make_law(w, WS_LAW_TENSION_COMPRESSION, 50.0, 0.5, 0.02, 1e-3);
    const uint32_t pins[4] = {0, nx - 1, nx * (ny - 1), nx * ny - 1};
    ws_web_def wd;
    ws_web_id mesh, sheet = shear_sheet(w, law, nx, ny, 0.02, 0.1, pins, 4, &wd);
    sheet_copy c = copy_sheet(w, sheet);
    c.md.pinned = pins;
    c.md.pinned_count = 4;
    ck_ok(w, ws_web_create_mesh(w, &wd, &c.md, &mesh));
    double S;
    ck_ok(w, ws_web_get_stable_dt(w, sheet, &S));
    ck_assert_msg(S > dt, "the sheet's stable step %g s is below dt", S);
    const int steps = 2000;
    for (int k = 0; k < steps; k++)
        ck_ok(w, ws_world_step(w));
    size_t n;
    double *xs = copy_pos(w, sheet, &n), *xm = copy_pos(w, mesh, NULL);
    double diff = 0.0, sag = 0.0;
    for (size_t i = 0; i < 3 * n; i++) {
        diff = fmax(diff, fabs(xs[i] - xm[i]));
        sag = fmax(sag, fabs(xs[i] - c.x[i]));
    }
    report("sheet in blocks against its mesh: %zu nodes, %d steps, largest sag %.3g m, largest "
           "difference %.3g m",
           n, steps, sag, diff);
    ck_assert_msg(sag > 1e-3, "hardly any motion: the sheet sags %g m", sag);
    ck_assert_msg(diff <= 1e-9, "the sheet and its mesh differ by %g m", diff);
    free(xs);
    free(xm);
    free_sheet_copy(&c);
    ws_world_destroy(w);
}
END_TEST

/* ======================================================================================
 * 8. Stable sub-step
 * ====================================================================================== */

static ws_web_id pinned_row(ws_world *w, int n, double sp, double m, ws_law_id law,
                            const char *name)
{
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = m;
    wd.law = law;
    wd.name = name;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = n;
    sd.ny = 1;
    sd.spacing_x = sd.spacing_y = sp;
    sd.prestretch_x = 0.1;
    uint32_t pins[2] = {0, (uint32_t)(n - 1)};
    sd.pinned = pins;
    sd.pinned_count = 2;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    return web;
}

START_TEST(test_stable_dt)
{
    /* A pinned row of 21 nodes (19 free), spacing 0.01 m, pre-stretch 0.1, EA = 100 N, node
     * mass 2.5 g: k = EA / l0 = 11000 N/m. The estimate: omega^2 <= 2 sum(k) / m = 4 k / m,
     * S = 2 / omega = sqrt(m / k) (no damping, no contact: no bodies). */
    const int n = 21;
    const double sp = 0.01, EA = 100.0, m = 2.5e-3, l0 = sp / 1.1, kk = EA / l0;
    /* The check at the bound itself (stable_fraction 1); the default factor is tested below. */
    ws_world *w = world_f(1e-4, DOWN_G, 1.0);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, EA, 0.0, 0.0, 0.0);
    ws_web_id web = pinned_row(w, n, sp, m, law, "row");
    double S;
    ck_ok(w, ws_web_get_stable_dt(w, web, &S));
    double S_est = sqrt(m / kk);
    /* The exact top frequency of the pinned chain: 2 sqrt(k/m) sin(nf pi / (2 (nf + 1))). */
    const int nf = n - 2;
    double om_true = 2 * sqrt(kk / m) * sin(nf * PI / (2.0 * (nf + 1)));
    double S_true = 2 / om_true;
    report("stable dt: %.9g s; Gershgorin sqrt(m/k) = %.9g s; exact 2/omega_max = %.9g s "
           "(ratio %.5f)",
           S, S_est, S_true, S_true / S);
    ck_assert_msg(fabs(S - S_est) <= 1e-12 * S_est, "stable dt %.12g vs %.12g", S, S_est);
    /* Safe (S <= exact limit) and not absurdly conservative (within a factor 2). */
    ck_assert_msg(S <= S_true && S_true <= 2 * S, "S %.6g vs exact %.6g", S, S_true);

    /* With damping: symplectic Euler on m x'' + c x' + k x = 0 is stable for dt < 2/omega
     * (sqrt(1 + z^2) - z), z = c / (2 m omega); c = 2 * 2 c_law / l0 per interior node. */
    ws_law_id lawd = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, EA, 0.0, 0.05, 0.0);
    ws_web_id webd = pinned_row(w, n, sp, m, lawd, "damped");
    double Sd;
    ck_ok(w, ws_web_get_stable_dt(w, webd, &Sd));
    double om = 2 * sqrt(kk / m), z = (4 * 0.05 / l0) / (2 * m * om);
    double Sd_est = 2 / om * (sqrt(1 + z * z) - z);
    report("stable dt with damping: %.9g s, analytic %.9g s (z = %.3f)", Sd, Sd_est, z);
    ck_assert_msg(fabs(Sd - Sd_est) <= 1e-12 * Sd_est, "damped stable dt %.12g vs %.12g", Sd,
                  Sd_est);
    ck_ok(w, ws_web_destroy(w, webd));

    /* Refused before any step: dt = 1.01 S, substeps 1. Nothing changes. */
    ck_ok(w, ws_world_set_dt(w, 1.01 * S));
    uint64_t h0, h1;
    double t0, t1;
    ck_ok(w, ws_world_get_state_hash(w, &h0));
    ck_ok(w, ws_world_get_time(w, &t0));
    size_t nn;
    double *x0 = copy_pos(w, web, &nn);
    ws_status st = ws_world_step(w);
    ck_assert_int_eq(st, WS_ERR_NUMERICAL);
    const char *msg = ws_world_last_error(w);
    char mass_txt[32];
    snprintf(mass_txt, sizeof mass_txt, "%.3g kg", m);
    report("refusal: \"%s\"", msg);
    ck_assert_msg(strstr(msg, "substeps") != NULL, "message does not name substeps: %s", msg);
    ck_assert_msg(strstr(msg, mass_txt) != NULL, "message does not name the node mass %s: %s",
                  mass_txt, msg);
    ck_assert_msg(strstr(msg, "row") != NULL, "message does not name the web: %s", msg);
    ck_ok(w, ws_world_get_state_hash(w, &h1));
    ck_ok(w, ws_world_get_time(w, &t1));
    ck_assert(h0 == h1);
    ck_assert(t0 == t1);
    double *x1 = copy_pos(w, web, &nn);
    ck_assert(memcmp(x0, x1, 3 * nn * sizeof *x0) == 0);
    free(x1);
    /* Still refused on the next try (the check is not a one-shot). */
    ck_assert_int_eq(ws_world_step(w), WS_ERR_NUMERICAL);
    /* With ceil(dt / S) = 2 sub-steps it runs. */
    ck_ok(w, ws_web_set_substeps(w, web, (int)ceil(1.01 * S / S)));
    ck_ok(w, ws_world_step_n(w, 100));
    ck_ok(w, ws_web_set_substeps(w, web, 1));

    /* dt/substeps: dt = 3.5 S refused with 3 sub-steps, runs with ceil(3.5) = 4. */
    ck_ok(w, ws_world_set_dt(w, 3.5 * S));
    ck_ok(w, ws_web_set_substeps(w, web, 3));
    ck_assert_int_eq(ws_world_step(w), WS_ERR_NUMERICAL);
    ck_ok(w, ws_web_set_substeps(w, web, (int)ceil(3.5 * S / S)));
    ck_ok(w, ws_world_step_n(w, 200));
    ws_web_info info;
    ck_ok(w, ws_web_get_info(w, web, &info));
    ck_assert_int_eq(info.substeps, 4);
    free(x0);
    ws_world_destroy(w);

    /* A run at dt = 0.99 S (substeps 1), undamped, under gravity, 20000 steps: bounded. The
     * total energy (kinetic + elastic + gravity) is conserved up to the symplectic
     * oscillation, at most (omega dt / 2) ~ 1 of the energies in play; a blow-up grows without
     * bound (or fails the step). Bound: every node within 0.05 m of its start (the static sag
     * is ~0.3 mm). */
    w = world_f(0.99 * S, DOWN_G, 1.0);
    law = make_law(w, WS_LAW_LINEAR_ELASTIC, EA, 0.0, 0.0, 0.0);
    web = pinned_row(w, n, sp, m, law, "row");
    x0 = copy_pos(w, web, &nn);
    double far = 0.0;
    for (int k = 0; k < 20; k++) {
        ck_ok(w, ws_world_step_n(w, 1000));
        double *xx = copy_pos(w, web, &nn);
        for (size_t i = 0; i < 3 * nn; i++)
            far = fmax(far, fabs(xx[i] - x0[i]));
        free(xx);
    }
    report("run at 0.99 S: largest node excursion %.3g m over 20000 steps", far);
    ck_assert_msg(far < 0.05, "the web ran away at 0.99 S: excursion %g m", far);
    free(x0);
    ws_world_destroy(w);

    /* The default safety factor f (0.5): dt/substeps may use f S. Refused at 1.02 f S (saying
     * the fraction and the sub-steps that would do), runs at 0.98 f S; the world statistics
     * report the use, dt / S. */
    const double f = default_fraction();
    w = world_g(1.02 * f * S, DOWN_G);
    law = make_law(w, WS_LAW_LINEAR_ELASTIC, EA, 0.0, 0.0, 0.0);
    web = pinned_row(w, n, sp, m, law, "row");
    ck_assert_int_eq(ws_world_step(w), WS_ERR_NUMERICAL);
    msg = ws_world_last_error(w);
    report("refusal at 1.02 f S: \"%s\"", msg);
    ck_assert_msg(strstr(msg, "stable_fraction") && strstr(msg, "substeps >= 2"), "%s", msg);
    ws_world_stats stats;
    ck_ok(w, ws_world_get_stats(w, &stats));
    ck_assert_double_eq_tol(stats.web_step_use, 1.02 * f, 1e-12);
    ck_ok(w, ws_world_set_dt(w, 0.98 * f * S));
    ck_ok(w, ws_world_step_n(w, 100));
    ck_ok(w, ws_world_get_stats(w, &stats));
    ck_assert_double_eq_tol(stats.web_step_use, 0.98 * f, 1e-12);
    ck_assert(stats.body_step_use == 0.0); /* no bodies */
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_stable_dt_refusal_counted)
{
    /* world.h: stats.numerical_errors counts "steps refused with WS_ERR_NUMERICAL"; the web's
     * stable-step refusal is such a step. */
    ws_world *w = world_g(1e-4, DOWN_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, 100.0, 0.0, 0.0, 0.0);
    ws_web_id web = pinned_row(w, 11, 0.01, 1e-5, law, "light");
    double S;
    ck_ok(w, ws_web_get_stable_dt(w, web, &S));
    ck_assert(1e-4 > S); /* 1e-5 kg nodes: S = 3e-5 s */
    ws_world_stats st0, st1;
    ck_ok(w, ws_world_get_stats(w, &st0));
    ck_assert_int_eq(ws_world_step(w), WS_ERR_NUMERICAL);
    ck_ok(w, ws_world_get_stats(w, &st1));
    ws_world_destroy(w); /* before the verdict, so a failure leaks nothing (CK_FORK=no) */
    ck_assert(st1.steps == st0.steps);
    ck_assert_msg(st1.numerical_errors == st0.numerical_errors + 1,
                  "refused step not counted: numerical_errors %llu -> %llu",
                  (unsigned long long)st0.numerical_errors,
                  (unsigned long long)st1.numerical_errors);
}
END_TEST

START_TEST(test_step_leaves_no_scratch_in_state)
{
    /* A sweep keeps the nodes' forces where it writes their new velocities (web.h,
     * ws_web_sweep_begin); after the step the force scratch must be an array of its own again,
     * for what uses it between steps (the stable-step bound, the VTK writer) writes over it.
     * Asking the stable step after a step must leave the state as it was, with one sub-step
     * and with two (the scratch state between them). */
    for (int sub = 1; sub <= 2; sub++) {
        ws_world *w = world_g(1e-4, DOWN_G);
        ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, 100.0, 0.0, 0.0, 0.0);
        ws_web_id web = pinned_row(w, 11, 0.01, 1e-3, law, "row");
        ck_ok(w, ws_web_set_substeps(w, web, sub));
        ck_ok(w, ws_world_step_n(w, 20));
        size_t n;
        ck_ok(w, ws_web_copy_velocities(w, web, NULL, 0, &n));
        double *v0 = calloc(3 * n, sizeof *v0), *v1 = calloc(3 * n, sizeof *v1);
        ck_assert(v0 && v1);
        uint64_t h0, h1;
        ck_ok(w, ws_web_copy_velocities(w, web, v0, n, &n));
        ck_ok(w, ws_world_get_state_hash(w, &h0));
        double S;
        ck_ok(w, ws_web_get_stable_dt(w, web, &S));
        ck_ok(w, ws_web_copy_velocities(w, web, v1, n, &n));
        ck_ok(w, ws_world_get_state_hash(w, &h1));
        ws_world_destroy(w); /* before the verdict, so a failure leaks nothing (CK_FORK=no) */
        int same = memcmp(v0, v1, 3 * n * sizeof *v0) == 0;
        double vy = v0[3 * 5 + 2];
        free(v0);
        free(v1);
        ck_assert_msg(vy != 0.0, "the row does not move: the check would see nothing");
        ck_assert_msg(same && h0 == h1,
                      "%d sub-step(s): the stable-step bound changed the node velocities", sub);
    }
}
END_TEST

/* A free sheet nx x ny with spacing 0.01 m and no pre-stretch (springs slack as placed), its
 * masses from node_mass (all alike) or from areal_density (edges and corners lighter), one
 * node pinned if pin >= 0. */
static ws_web_id free_sheet(ws_world *w, ws_law_id law, int nx, int ny, double node_mass,
                            double density, int pin)
{
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = node_mass;
    wd.areal_density = density;
    wd.law = law;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = nx;
    sd.ny = ny;
    sd.spacing_x = sd.spacing_y = 0.01;
    uint32_t p = (uint32_t)(pin >= 0 ? pin : 0);
    sd.pinned = pin >= 0 ? &p : NULL;
    sd.pinned_count = pin >= 0 ? 1 : 0;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    return web;
}

START_TEST(test_node_masses_each_their_own)
{
    /* A web whose nodes all weigh the same is swept with that one mass rather than the array
     * (web.h, same_m / same_inv_m); any other with each node's own. Under gravity alone a
     * slack web falls as one: every node's force m_i g over its own m_i, so after k steps of
     * dt every free node moves at g k dt (symplectic Euler is exact for a constant force up
     * to round-off, 1e-12 of it here) and the springs stay slack. A node swept with another
     * node's mass or inverse mass falls at g times their ratio (1/4 to 4 here), and a pinned
     * node must not move at all (the others of its sheet, held by it, must), nor a web pinned at
     * every node (its nodes are all alike, but with no inverse mass to sweep with). */
    const int steps = 100;
    const double dt = 1e-4, vz = -G0 * steps * dt;
    ws_world *w = world_g(dt, DOWN_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, 1.0, 0.0, 0.0, 0.0);
    ws_web_id webs[4];
    webs[0] = free_sheet(w, law, 4, 3, 1e-3, 0.0, -1); /* all alike */
    webs[1] = free_sheet(w, law, 4, 3, 0.0, 2.0, -1);  /* corners 1/4, edges 1/2 */
    webs[2] = free_sheet(w, law, 4, 3, 1e-3, 0.0, 5);  /* same masses, one pinned */
    double p[9] = {0, 0, 0, 0.01, 0, 0, 0.02, 0, 0}, ms[3] = {1e-3, 2e-3, 4e-3};
    uint32_t sp[4] = {0, 1, 1, 2};
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.law = law;
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = p;
    md.node_count = 3;
    md.node_masses = ms;
    md.springs = sp;
    md.spring_count = 2;
    ck_ok(w, ws_web_create_mesh(w, &wd, &md, &webs[3]));
    /* Every node pinned: all alike, with an inverse mass of 0. */
    uint32_t all[3] = {0, 1, 2};
    md.node_masses = NULL;
    md.pinned = all;
    md.pinned_count = 3;
    wd.node_mass = 1e-3;
    ws_web_id held;
    ck_ok(w, ws_web_create_mesh(w, &wd, &md, &held));
    ck_ok(w, ws_world_step_n(w, steps));
    double vh[9];
    size_t nh;
    ck_ok(w, ws_web_copy_velocities(w, held, vh, 3, &nh));
    double held_speed = 0.0;
    for (size_t i = 0; i < 3 * nh; i++)
        held_speed += fabs(vh[i]);
    double worst = 0.0, pinned_speed = -1.0, moving = INFINITY;
    for (int k = 0; k < 4; k++) {
        double v[3 * 12];
        size_t n;
        ck_ok(w, ws_web_copy_velocities(w, webs[k], v, 12, &n));
        for (size_t i = 0; i < n; i++) {
            if (k == 2) { /* held by its pinned node: not free fall */
                if (i == 5)
                    pinned_speed = fabs(v[3 * i]) + fabs(v[3 * i + 1]) + fabs(v[3 * i + 2]);
                else
                    moving = fmin(moving, fabs(v[3 * i + 2]));
                continue;
            }
            double e = fabs(v[3 * i]) + fabs(v[3 * i + 1]) + fabs(v[3 * i + 2] - vz);
            worst = fmax(worst, e / fabs(vz));
        }
    }
    ws_world_destroy(w); /* before the verdict, so a failure leaks nothing (CK_FORK=no) */
    report("free fall of slack webs: worst relative velocity error %.3g", worst);
    ck_assert_msg(worst < 1e-12, "a node did not fall at g: relative error %g", worst);
    ck_assert_msg(pinned_speed == 0.0, "the pinned node moves: |v| sum %g", pinned_speed);
    ck_assert_msg(moving > 0.0, "a free node of the pinned sheet does not move");
    ck_assert_msg(held_speed == 0.0, "a web pinned at every node moves: |v| sum %g", held_speed);
}
END_TEST

START_TEST(test_state_hash_sees_web)
{
    /* ws_world_get_state_hash: "a hash of the whole dynamic state ... the determinism check".
     * Two worlds that differ only in where a web's nodes are must hash differently, and a
     * world whose web moved (bodies none) must hash differently from before at equal time is
     * not testable, so: equal time, equal bodies, different web state. */
    ws_world *a = world_g(1e-4, DOWN_G), *b = world_g(1e-4, DOWN_G);
    ws_law_id la = make_law(a, WS_LAW_LINEAR_ELASTIC, 100.0, 0.0, 0.0, 0.0);
    ws_law_id lb = make_law(b, WS_LAW_LINEAR_ELASTIC, 100.0, 0.0, 0.0, 0.0);
    ws_web_id wa = pinned_row(a, 11, 0.01, 1e-3, la, "a");
    ws_web_id wb = pinned_row(b, 11, 0.012, 1e-3, lb, "b");
    (void)wa;
    (void)wb;
    uint64_t ha, hb;
    ck_ok(a, ws_world_get_state_hash(a, &ha));
    ck_ok(b, ws_world_get_state_hash(b, &hb));
    ws_world_destroy(a); /* before the verdict, so a failure leaks nothing (CK_FORK=no) */
    ws_world_destroy(b);
    ck_assert_msg(ha != hb, "the state hash ignores the webs: two different films, same hash "
                            "%016llx",
                  (unsigned long long)ha);
}
END_TEST

START_TEST(test_mesh_node_masses)
{
    /* web.h: node_masses "kg per node; NULL: the web Def's node_mass", so per-node masses with
     * node_mass left at 0 (and no areal density, which a mesh web cannot use) must be
     * accepted, and the masses must be those given. */
    ws_world *w = world_g(1e-4, NO_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, 100.0, 0.0, 0.0, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.law = law;
    double p[9] = {0, 0, 0, 0.01, 0, 0, 0.02, 0, 0}, ms[3] = {1e-3, 2e-3, 4e-3};
    uint32_t sp[4] = {0, 1, 1, 2};
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = p;
    md.node_count = 3;
    md.node_masses = ms;
    md.springs = sp;
    md.spring_count = 2;
    ws_web_id web;
    ws_web_info info;
    memset(&info, 0, sizeof info);
    ws_status st = ws_web_create_mesh(w, &wd, &md, &web);
    char err[256];
    snprintf(err, sizeof err, "%s", ws_world_last_error(w));
    if (st == WS_OK)
        st = ws_web_get_info(w, web, &info);
    ws_world_destroy(w); /* before the verdict, so a failure leaks nothing (CK_FORK=no) */
    ck_assert_msg(st == WS_OK, "mesh web with node_masses and node_mass 0: %s (%s)",
                  ws_status_string(st), err);
    ck_assert_msg(fabs(info.mass - 7e-3) <= 1e-15 && info.min_node_mass == 1e-3,
                  "masses: total %g, smallest %g", info.mass, info.min_node_mass);
}
END_TEST

/* ======================================================================================
 * 9. Sheet generator facts
 * ====================================================================================== */

START_TEST(test_sheet_generator)
{
    ws_world *w = world_g(1e-4, DOWN_G);
    ws_law_id lx = make_law(w, WS_LAW_LINEAR_ELASTIC, 100.0, 0.0, 0.0, 0.0);
    ws_law_id ly = make_law(w, WS_LAW_LINEAR_ELASTIC, 40.0, 0.0, 0.0, 0.0);
    ws_law_id lsh = make_law(w, WS_LAW_LINEAR_ELASTIC, 10.0, 0.0, 0.0, 0.0);
    const int nx = 7, ny = 4;
    const double hx = 0.02, hy = 0.03, px = 0.3, py = 0.1, rho = 0.018;
    for (int shear = 0; shear <= 1; shear++) {
        ws_web_def wd;
        ws_web_def_init(&wd);
        wd.areal_density = rho;
        wd.law = lx;
        wd.law_cross = ly;
        wd.law_shear = lsh;
        ws_sheet_def sd;
        ws_sheet_def_init(&sd);
        sd.nx = nx;
        sd.ny = ny;
        sd.spacing_x = hx;
        sd.spacing_y = hy;
        sd.prestretch_x = px;
        sd.prestretch_y = py;
        sd.shear = shear;
        sd.origin = (ws_vec3){0.1, -0.2, 0.5};
        sd.axis_x = (ws_vec3){2, 0, 0}; /* normalised by the generator */
        sd.axis_y = (ws_vec3){0, 0, 1};
        uint32_t pins[3] = {(uint32_t)(nx * (ny - 1)), (uint32_t)(nx * ny - 1),
                            (uint32_t)(nx * (ny - 1) + 3)}; /* on the top row */
        sd.pinned = pins;
        sd.pinned_count = 3;
        ws_web_id web;
        ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
        ws_web_info info;
        ck_ok(w, ws_web_get_info(w, web, &info));
        uint32_t want_s = (uint32_t)((nx - 1) * ny + nx * (ny - 1) +
                                     (shear ? 2 * (nx - 1) * (ny - 1) : 0));
        ck_assert_uint_eq(info.node_count, (uint32_t)(nx * ny));
        ck_assert_uint_eq(info.spring_count, want_s);
        ck_assert_int_eq(info.nx, nx);
        ck_assert_int_eq(info.ny, ny);
        ck_assert_int_eq(info.closed, 0);
        /* Masses: rho times the rest area (nx-1) hx/(1+px) (ny-1) hy/(1+py); the corner node
         * has a quarter cell. Sums of 28 products: 1e-12. */
        double l0x = hx / (1 + px), l0y = hy / (1 + py);
        double area = (nx - 1) * l0x * (ny - 1) * l0y;
        ck_assert_msg(fabs(info.mass - rho * area) <= 1e-12 * rho * area, "mass %.15g vs %.15g",
                      info.mass, rho * area);
        ck_assert_msg(fabs(info.min_node_mass - rho * l0x * l0y / 4) <= 1e-12 * rho * l0x * l0y,
                      "corner mass %.15g vs %.15g", info.min_node_mass, rho * l0x * l0y / 4);
        /* Positions: origin + i hx x + j hy z. */
        size_t nn;
        double *x0 = copy_pos(w, web, &nn);
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                const double *p = x0 + 3 * (i + nx * j);
                ck_assert(fabs(p[0] - (0.1 + i * hx)) < 1e-15 && fabs(p[1] + 0.2) < 1e-15 &&
                          fabs(p[2] - (0.5 + j * hy)) < 1e-15);
            }
        /* Strains read back = pre-stretch; a diagonal's rest length is that of its rest cell:
         * strain sqrt(hx^2 + hy^2) / sqrt(l0x^2 + l0y^2) - 1. Tensions follow each kind's
         * law. Roundoff: 1e-14. */
        size_t ns;
        uint32_t *spr = malloc(2 * info.spring_count * sizeof *spr);
        double *eps = malloc(info.spring_count * sizeof *eps);
        ck_assert(spr && eps);
        ck_ok(w, ws_web_copy_springs(w, web, spr, info.spring_count, &ns));
        ck_ok(w, ws_web_copy_spring_strains(w, web, eps, ns, &ns));
        double *T = copy_tensions(w, web, &ns);
        double pd = sqrt(hx * hx + hy * hy) / sqrt(l0x * l0x + l0y * l0y) - 1;
        int counts[3] = {0, 0, 0};
        for (size_t k = 0; k < ns; k++) {
            uint32_t a = spr[2 * k], b = spr[2 * k + 1];
            uint32_t dd = a > b ? a - b : b - a;
            int kind = dd == 1 && (a / nx == b / nx) ? 0 : dd == (uint32_t)nx ? 1 : 2;
            double want = kind == 0 ? px : kind == 1 ? py : pd;
            double kl = kind == 0 ? 100.0 : kind == 1 ? 40.0 : 10.0;
            counts[kind]++;
            ck_assert_msg(fabs(eps[k] - want) <= 1e-14, "spring %zu (kind %d): strain %.15g vs "
                                                        "%.15g",
                          k, kind, eps[k], want);
            ck_assert_msg(fabs(T[k] - kl * want) <= 1e-12 * kl, "spring %zu: T %.15g vs %.15g",
                          k, T[k], kl * want);
        }
        ck_assert_int_eq(counts[0], (nx - 1) * ny);
        ck_assert_int_eq(counts[1], nx * (ny - 1));
        ck_assert_int_eq(counts[2], shear ? 2 * (nx - 1) * (ny - 1) : 0);
        free(spr);
        free(eps);
        free(T);
        /* Pinned nodes do not move under gravity (bitwise); the free ones fall. */
        fit_substeps(w, web, 1e-4);
        ck_ok(w, ws_world_step_n(w, 300));
        double *x1 = copy_pos(w, web, &nn);
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++)
                ck_assert_msg(x1[3 * pins[k] + c] == x0[3 * pins[k] + c], "pinned node %u moved",
                              pins[k]);
        /* (The pre-stretch pulls the free rows up toward the pinned one faster than the tiny
         * areal masses fall, so just: the free corner moved.) */
        ck_assert_msg(fabs(x1[2] - x0[2]) > 1e-3, "free node did not move: %g -> %g", x0[2],
                      x1[2]);
        double vel[3 * 28];
        ck_ok(w, ws_web_copy_velocities(w, web, vel, nn, &nn));
        for (int k = 0; k < 3; k++)
            ck_assert(vel[3 * pins[k]] == 0 && vel[3 * pins[k] + 1] == 0 &&
                      vel[3 * pins[k] + 2] == 0);
        free(x0);
        free(x1);
        ck_ok(w, ws_web_destroy(w, web));
    }
    /* Areal density needs a 2-D grid: a single row has no area and is refused. */
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.areal_density = rho;
    wd.law = lx;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = 5;
    sd.ny = 1;
    sd.spacing_x = sd.spacing_y = 0.01;
    ws_web_id bad;
    ck_assert_int_eq(ws_web_create_sheet(w, &wd, &sd, &bad), WS_ERR_INVALID_ARGUMENT);
    /* Shear without law_shear is refused. */
    ws_web_def_init(&wd);
    wd.node_mass = 1e-3;
    wd.law = lx;
    sd.ny = 3;
    sd.shear = 1;
    ck_assert_int_eq(ws_web_create_sheet(w, &wd, &sd, &bad), WS_ERR_INVALID_ARGUMENT);
    ws_world_destroy(w);
}
END_TEST

/* ======================================================================================
 * 10. Bulk read-out
 * ====================================================================================== */

START_TEST(test_bulk_copies)
{
    ws_world *w = world_g(1e-4, DOWN_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, 100.0, 0.0, 0.0, 0.0);
    ws_web_id web = pinned_row(w, 6, 0.01, 1e-3, law, "six"); /* 6 nodes, 5 springs */
    ck_ok(w, ws_world_step_n(w, 10));
    double buf[3 * 6];
    uint32_t pairs[2 * 5];
    size_t cnt;
    typedef ws_status (*vfn)(const ws_world *, ws_web_id, double *, size_t, size_t *);
    vfn nodes[3] = {ws_web_copy_positions, ws_web_copy_velocities, ws_web_copy_contact_forces};
    vfn springs[2] = {ws_web_copy_spring_strains, ws_web_copy_spring_tensions};
    for (int f = 0; f < 3; f++) {
        cnt = 99;
        ck_ok(w, nodes[f](w, web, NULL, 0, &cnt));
        ck_assert_uint_eq(cnt, 6);
        double full[3 * 6];
        ck_ok(w, nodes[f](w, web, full, 6, &cnt));
        for (int i = 0; i < 18; i++)
            buf[i] = -777.0;
        cnt = 0;
        ck_assert_int_eq(nodes[f](w, web, buf, 4, &cnt), WS_ERR_BUFFER_TOO_SMALL);
        ck_assert_uint_eq(cnt, 6);
        ck_assert(memcmp(buf, full, 12 * sizeof(double)) == 0); /* the first 4 copied */
        ck_assert(buf[12] == -777.0);                            /* nothing beyond */
        ck_assert_int_eq(nodes[f](w, web, NULL, 3, &cnt), WS_ERR_INVALID_ARGUMENT);
    }
    for (int f = 0; f < 2; f++) {
        ck_ok(w, springs[f](w, web, NULL, 0, &cnt));
        ck_assert_uint_eq(cnt, 5);
        buf[2] = -777.0;
        ck_assert_int_eq(springs[f](w, web, buf, 2, &cnt), WS_ERR_BUFFER_TOO_SMALL);
        ck_assert_uint_eq(cnt, 5);
        ck_assert(buf[2] == -777.0);
    }
    ck_ok(w, ws_web_copy_springs(w, web, NULL, 0, &cnt));
    ck_assert_uint_eq(cnt, 5);
    ck_assert_int_eq(ws_web_copy_springs(w, web, pairs, 3, &cnt), WS_ERR_BUFFER_TOO_SMALL);
    ck_assert_uint_eq(cnt, 5);
    ck_assert(pairs[0] == 0 && pairs[1] == 1 && pairs[4] == 2 && pairs[5] == 3);

    /* A law in use cannot go; after its web is gone it can. */
    ck_assert_int_eq(ws_law_destroy(w, law), WS_ERR_IN_USE);
    ck_assert(ws_law_is_valid(w, law));
    /* The containment of a mesh web is refused. */
    double p[6] = {0, 0, 0, 0.01, 0, 0};
    uint32_t sp2[2] = {0, 1};
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-3;
    wd.law = law;
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = p;
    md.node_count = 2;
    md.springs = sp2;
    md.spring_count = 1;
    ws_web_id mesh;
    ck_ok(w, ws_web_create_mesh(w, &wd, &md, &mesh));
    ws_containment_band cb;
    ck_assert_int_eq(ws_web_get_containment(w, mesh, &cb, 1), WS_ERR_INVALID_ARGUMENT);

    ck_ok(w, ws_web_destroy(w, web));
    ck_assert(!ws_web_is_valid(w, web));
    ck_assert_int_eq(ws_web_copy_positions(w, web, buf, 6, &cnt), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_web_copy_spring_tensions(w, web, buf, 5, &cnt), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_web_copy_springs(w, web, pairs, 5, &cnt), WS_ERR_STALE_HANDLE);
    double d;
    ck_assert_int_eq(ws_web_get_stable_dt(w, web, &d), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_web_get_energy(w, web, &d, NULL, NULL), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_web_destroy(w, web), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_law_destroy(w, law), WS_ERR_IN_USE); /* the mesh still uses it */
    ck_ok(w, ws_web_destroy(w, mesh));
    ck_ok(w, ws_law_destroy(w, law));
    /* A web id from another world is stale here. */
    ws_world *w2 = world_g(1e-4, DOWN_G);
    ws_law_id l2 = make_law(w2, WS_LAW_LINEAR_ELASTIC, 100.0, 0.0, 0.0, 0.0);
    ws_web_id other = pinned_row(w2, 4, 0.01, 1e-3, l2, "other");
    ck_assert_int_eq(ws_web_copy_positions(w, other, buf, 6, &cnt), WS_ERR_STALE_HANDLE);
    ws_world_destroy(w2);
    ws_world_destroy(w);
}
END_TEST

/* ======================================================================================
 * 10. Springs with any 1D law: history committed after each step, a failing law reported
 * ====================================================================================== */

/* Two nodes of 1 g on the x axis, `length` apart, joined by one spring of the law (rest
 * length *rest, or the length when rest is NULL); the first `pins` of them pinned. */
static ws_web_id spring_pair(ws_world *w, ws_law_id law, double length, const double *rest,
                             uint32_t pins)
{
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.law = law;
    wd.node_mass = 1e-3;
    double p[6] = {0, 0, 0, length, 0, 0};
    uint32_t sp[2] = {0, 1}, pin[2] = {0, 1};
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = p;
    md.node_count = 2;
    md.springs = sp;
    md.spring_count = 1;
    md.rest_lengths = rest;
    md.pinned = pin;
    md.pinned_count = pins;
    ws_web_id web;
    ck_ok(w, ws_web_create_mesh(w, &wd, &md, &web));
    return web;
}

/* Two pinned nodes 0.11 m apart joined by one spring of rest length 0.1 m (strain 0.1 held). */
static ws_web_id held_spring(ws_world *w, ws_law_id law)
{
    const double l0 = 0.1;
    return spring_pair(w, law, 0.11, &l0, 2);
}

/* A standard linear solid, the film's relaxing law: k_inf = 50 N, k1 = 100 N, tau = 0.05 s
 * (the law copies its Prony terms). */
static ws_law_id solid_law(ws_world *w)
{
    double k1 = 100.0, tau = 0.05;
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_RELAXATION;
    ld.stiffness = 50.0;
    ld.prony_stiffness = &k1;
    ld.prony_time = &tau;
    ld.prony_count = 1;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    return law;
}

START_TEST(test_spring_relaxation)
{
    /* Film loses tension after wrapping. A spring of a standard linear solid (k_inf = 50 N,
     * k1 = 100 N, tau = 0.05 s) stretched by 0.1 and held: T(t) = (k_inf + k1 e^(-t/tau)) 0.1,
     * from 15 N at once down to 5 N. The history is committed once per step with an update
     * exact for a held strain, so the only error is round-off: 1e-12 relative. */
    ws_world *w = world_g(1e-3, NO_G);
    const double k1 = 100.0, tau = 0.05; /* solid_law's */
    ws_law_id law = solid_law(w);
    ws_web_id web = held_spring(w, law);
    double worst = 0.0, T = 0.0;
    size_t n;
    for (int k = 0; k <= 200; k++) {
        ck_ok(w, ws_web_copy_spring_tensions(w, web, &T, 1, &n));
        double t = k * 1e-3, want = (50.0 + k1 * exp(-t / tau)) * 0.1;
        worst = fmax(worst, fabs(T - want) / want);
        ck_ok(w, ws_world_step(w));
    }
    report("relaxing spring: tension follows (k_inf + k1 e^(-t/tau)) eps to %.1e relative over "
           "4 tau",
           worst);
    ck_assert_msg(worst < 1e-12, "relaxation off by %.3e", worst);
    /* The law is in use: it cannot be destroyed under the web. */
    ck_assert_int_eq(ws_law_destroy(w, law), WS_ERR_IN_USE);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_springs_checked_before_law_histories)
{
    /* A film law with history (relaxation) sets up each spring's history from the spring's law,
     * found by its kind. Shear springs without law_shear, and a mesh spring of an unknown kind,
     * must be refused before that: they once dereferenced a NULL law (and read past the web's
     * three laws). Found by the fuzz target. */
    ws_world *w = world_g(1e-3, NO_G);
    double k1 = 100.0, tau = 0.05;
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_RELAXATION;
    ld.stiffness = 50.0;
    ld.prony_stiffness = &k1;
    ld.prony_time = &tau;
    ld.prony_count = 1;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.law = law;
    wd.node_mass = 1e-3;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = 3;
    sd.ny = 3;
    sd.spacing_x = sd.spacing_y = 0.1;
    sd.shear = 1;
    ws_world_stats before, after;
    ck_ok(w, ws_world_get_stats(w, &before));
    ws_web_id web;
    ck_assert_int_eq(ws_web_create_sheet(w, &wd, &sd, &web), WS_ERR_INVALID_ARGUMENT);
    ck_assert_msg(strstr(ws_world_last_error(w), "law_shear"), "%s", ws_world_last_error(w));
    double xyz[6] = {0, 0, 0, 0.1, 0, 0};
    uint32_t pair[2] = {0, 1};
    uint8_t kind = 7;
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = xyz;
    md.node_count = 2;
    md.springs = pair;
    md.spring_count = 1;
    md.kinds = &kind;
    ck_assert_int_eq(ws_web_create_mesh(w, &wd, &md, &web), WS_ERR_INVALID_ARGUMENT);
    ck_assert_msg(strstr(ws_world_last_error(w), "unknown kind"), "%s", ws_world_last_error(w));
    /* Nothing of either web is left behind. */
    ck_ok(w, ws_world_get_stats(w, &after));
    ck_assert_uint_eq(after.bytes_in_use, before.bytes_in_use);
    kind = WS_SPRING_UP;
    ck_ok(w, ws_web_create_mesh(w, &wd, &md, &web));
    ws_world_destroy(w);
}
END_TEST

static int failing_law(void *user, int dim, const double *u, const double *ud, double t,
                       double *F, double *dFdu, double *dFdud)
{
    (void)dim;
    (void)ud;
    int *calls = user;
    ++*calls;
    if (t > 0.0105)
        return 1; /* gives up after 10 ms */
    F[0] = 1000.0 * u[0];
    if (dFdu)
        dFdu[0] = 1000.0;
    if (dFdud)
        dFdud[0] = 0.0;
    return 0;
}

/* A user law that kicks: 1e306 N whatever the strain (its stated stiffness, 1 N, is what the
 * stable step believes). */
static int kicking_law(void *user, int dim, const double *u, const double *ud, double t, double *F,
                       double *dFdu, double *dFdud)
{
    (void)user;
    (void)dim;
    (void)u;
    (void)ud;
    (void)t;
    (void)dFdud;
    F[0] = 1e306;
    dFdu[0] = 1.0;
    return 0;
}

START_TEST(test_runaway_without_a_speed_limit)
{
    /* max_speed infinite turns the runaway guard's limit off, but a node's state must still
     * never go infinite unnoticed. A spring that pulls with 1e306 N on a free node of 1 g at
     * dt = 1 ms gives it 1e306 m/s in one step (finite, but its square overflows) and an
     * infinite speed in the next: the first step must fail as a runaway, name the speed, and
     * leave the node where it was, finite. */
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = 1e-3;
    d.gravity = NO_G;
    d.max_speed = INFINITY;
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_USER;
    ld.stiffness = 1.0;
    ld.user_fn = kicking_law;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_web_id web = spring_pair(w, law, 0.1, NULL, 1);
    ws_status s = ws_world_step(w);
    char msg[512];
    snprintf(msg, sizeof msg, "%s", ws_world_last_error(w));
    double x[6];
    size_t n;
    ck_ok(w, ws_web_copy_positions(w, web, x, 2, &n));
    ws_world_destroy(w);
    report("kicked node without a speed limit: status %d, '%s'", (int)s, msg);
    ck_assert_int_eq(s, WS_ERR_NUMERICAL);
    /* The web is stable as its law states it: the message must not ask for sub-steps. */
    ck_assert_msg(strstr(msg, "ran away") && strstr(msg, "1e+306") &&
                      strstr(msg, "of its stable step") && !strstr(msg, "substeps >="),
                  "message: %s", msg);
    ck_assert_msg(x[3] == 0.1 && x[4] == 0.0 && x[5] == 0.0, "the node moved to (%g, %g, %g)", x[3],
                  x[4], x[5]);
}
END_TEST

/* A film-like sheet for the advice tests: 6 x 6 nodes at 10 mm, pre-stretch 0.4 / 0.2, Kelvin-
 * Voigt springs (EA, c_law), node mass m, its material against the ground's (4000 N/m, 1 kg/s
 * as the reference case's node-body pair), 10 cm above a static ground so nothing touches. */
static ws_web_id advice_sheet(ws_world *w, ws_law_id law, ws_material_id film, double m,
                              int substeps)
{
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = m;
    wd.material = film;
    wd.law = law;
    wd.substeps = substeps;
    wd.name = "advice";
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = sd.ny = 6;
    sd.origin = (ws_vec3){0, 0, 0.1};
    sd.spacing_x = sd.spacing_y = 0.01;
    sd.prestretch_x = 0.4;
    sd.prestretch_y = 0.2;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    return web;
}

/* Step once with a web of node mass m and `substeps`; the status, the web destroyed again. */
static ws_status advice_try(ws_world *w, ws_law_id law, ws_material_id film, double m,
                            int substeps, char *msg, size_t cap)
{
    ws_web_id web = advice_sheet(w, law, film, m, substeps);
    ws_status s = ws_world_step(w);
    if (msg)
        snprintf(msg, cap, "%s", ws_world_last_error(w));
    ck_ok(w, ws_web_destroy(w, web));
    return s;
}

START_TEST(test_advice_at_both_limits)
{
    /* The real film's node mass, 1.6 mg, at the default dt h = 0.25 ms. The stable step of
     * symplectic Euler on m x'' + c x' + k x = 0 is (sqrt(c^2 + 4 m k) - c) / k, so the smallest
     * stable mass is m* = h^2 k / 4 + h c / 2. The stiffest node is an interior one: Gershgorin
     * k = 2 (2 EA / l0x + 2 EA / l0y) + k_contact, c = 2 (2 c_law / l0x + 2 c_law / l0y) +
     * c_contact. With EA = 20 N, c_law = 1e-3 N s, l0x = 0.01 / 1.4, l0y = 0.01 / 1.2, the
     * contact 4000 N/m and 1 kg/s: k = 23600 N/m, c = 2.04 kg/s; at the bound itself m* =
     * 0.3688 + 0.255 g, the damping term 40 % of it, which an advice scaled as for an undamped
     * node misses; with the default safety factor 0.5, h / 0.5 in place of h. */
    const double h = 2.5e-4, EA = 20.0, cl = 1e-3, m_film = 1.6e-6;
    const double l0x = 0.01 / 1.4, l0y = 0.01 / 1.2;
    const double k = 2 * (2 * EA / l0x + 2 * EA / l0y) + 4000.0;
    const double c = 2 * (2 * cl / l0x + 2 * cl / l0y) + 1.0;
    /* The check lets h use the fraction f of the stable step: the mass must make it h / f. */
    const double H = h / default_fraction();
    const double m_star = H * H * k / 4 + H * c / 2;
    ws_world *w = world_g(h, DOWN_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_VISCOELASTIC, EA, 0.0, cl, 0.0);
    ws_material_def md;
    ws_material_def_init(&md);
    ws_material_id film, ground;
    ck_ok(w, ws_material_create(w, &md, &film));
    ck_ok(w, ws_material_create(w, &md, &ground));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 4000.0;
    cd.damping = 1.0;
    ck_ok(w, ws_world_set_contact(w, film, ground, &cd));
    add_ground(w, 1.0, ground);

    char msg[512];
    ck_assert_int_eq(advice_try(w, law, film, m_film, 1, msg, sizeof msg), WS_ERR_NUMERICAL);
    report("refusal at 1.6 mg: \"%s\"", msg);
    const char *pm = strstr(msg, "node mass >= "), *ps = strstr(msg, "substeps >= ");
    ck_assert_msg(pm && ps, "no advice in: %s", msg);
    double m_adv = strtod(pm + strlen("node mass >= "), NULL);
    int n_adv = atoi(ps + strlen("substeps >= "));
    report("advice: node mass %.6g kg (closed form %.6g kg), substeps %d", m_adv, m_star, n_adv);
    /* The advice is the closed form rounded up in its 4th digit: within 0.1 % above it. */
    ck_assert_msg(m_adv >= m_star && m_adv <= 1.001 * m_star, "advised %g kg, bound %g kg", m_adv,
                  m_star);
    /* Both limits: the named mass runs, 1 % less is refused (the rounding is below 0.1 %). */
    ck_assert_int_eq(advice_try(w, law, film, m_adv, 1, NULL, 0), WS_OK);
    ck_assert_int_eq(advice_try(w, law, film, 0.99 * m_adv, 1, NULL, 0), WS_ERR_NUMERICAL);
    /* Sub-steps: the named count runs at 1.6 mg, one fewer is refused. */
    ck_assert_int_ge(n_adv, 2);
    ck_assert_int_eq(advice_try(w, law, film, m_film, n_adv, NULL, 0), WS_OK);
    ck_assert_int_eq(advice_try(w, law, film, m_film, n_adv - 1, msg, sizeof msg),
                     WS_ERR_NUMERICAL);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_advice_bounded)
{
    /* A pre-stretch beyond WS_WEB_MAX_PRESTRETCH (10) is refused, naming the limit. */
    ws_world *w = world_g(2.5e-4, DOWN_G);
    ws_law_id law = make_law(w, WS_LAW_LINEAR_ELASTIC, 100.0, 0.0, 0.0, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-3;
    wd.law = law;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = sd.ny = 3;
    sd.spacing_x = sd.spacing_y = 0.01;
    sd.prestretch_x = 1e12;
    ws_web_id web;
    ck_assert_int_eq(ws_web_create_sheet(w, &wd, &sd, &web), WS_ERR_INVALID_ARGUMENT);
    ck_assert_msg(strstr(ws_world_last_error(w), "<= 10"), "%s", ws_world_last_error(w));
    sd.prestretch_x = 10.0; /* the limit itself is allowed */
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    ck_ok(w, ws_web_destroy(w, web));
    /* A mesh web can still have rest lengths that make the stable step about 0: 1e-200 m gives
     * k = 2 EA / l0 = 2e202 N/m on 1 g, a stable step of 4.5e-103 s. The advice must say that
     * no number of sub-steps within the limit helps, with no overflowed count, and no mass. */
    ws_web_id chain = make_chain(w, &wd, 2, 0.01, 1e-200, NULL, NULL, NULL, 0);
    ck_assert_int_eq(ws_world_step(w), WS_ERR_NUMERICAL);
    const char *msg = ws_world_last_error(w);
    report("rest length 1e-200 m: \"%s\"", msg);
    ck_assert_msg(strstr(msg, "more than the limit of 100000") &&
                      !strstr(msg, "substeps >=") && !strstr(msg, "-2147483648"),
                  "%s", msg);
    ck_ok(w, ws_web_destroy(w, chain));
    ws_world_destroy(w);
}
END_TEST

/* A free 20 x 20 sheet (10 mm spacing, pre-stretch 0.4 / 0.2, linear springs of 2000 N/m,
 * no damping, no gravity, no bodies) at the default dt and safety factor, its node mass chosen
 * so that the step uses `use` of the stable sub-step; released for `steps` steps. Out: E0, the
 * largest |E - E0| / E0, and the means of E / E0 - 1 over the first and the last third. */
static void released_sheet(double use, int steps, double *E0, double *dev, double *first,
                           double *last)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.gravity = NO_G;
    d.stable_fraction = 1.0; /* `use` may be above the default factor (not in this test) */
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    const double sp = 0.01, k = 2000.0, h = d.dt;
    ws_law_id around = make_law(w, WS_LAW_LINEAR_ELASTIC, k * sp / 1.4, 0.0, 0.0, 0.0);
    ws_law_id up = make_law(w, WS_LAW_LINEAR_ELASTIC, k * sp / 1.2, 0.0, 0.0, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.law = around;
    wd.law_cross = up;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = sd.ny = 20;
    sd.spacing_x = sd.spacing_y = sp;
    sd.prestretch_x = 0.4;
    sd.prestretch_y = 0.2;
    /* Undamped, the stable step grows as sqrt(m): scale a trial mass to the wanted use. */
    wd.node_mass = 1e-3;
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    double S;
    ck_ok(w, ws_web_get_stable_dt(w, web, &S));
    ck_ok(w, ws_web_destroy(w, web));
    wd.node_mass = 1e-3 * pow(h / (use * S), 2);
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    double ke, el;
    ck_ok(w, ws_web_get_energy(w, web, &ke, &el, NULL));
    *E0 = ke + el;
    *dev = *first = *last = 0.0;
    const int third = steps / 3;
    for (int i = 1; i <= steps; i++) {
        ck_ok(w, ws_world_step(w));
        ck_ok(w, ws_web_get_energy(w, web, &ke, &el, NULL));
        double e = (ke + el) / *E0 - 1.0;
        *dev = fmax(*dev, fabs(e));
        if (i <= third)
            *first += e / third;
        if (i > steps - third)
            *last += e / third;
    }
    ws_world_destroy(w);
}

START_TEST(test_released_sheet_energy)
{
    /* Undamped and free, a sheet released from pre-stretch keeps its energy E0 (4.16 J: it
     * contracts and rings). At the default dt with the node mass at the limit of the default
     * safety factor f (the step using 0.999 f of its stable sub-step S), 8000 steps (2 s):
     * - symplectic Euler's energy oscillates about a conserved modified energy by at most
     *   omega h / 2 of each mode's share, and omega_max h / 2 <= h / S <= f: |E - E0| <= f E0
     *   (measured 4 %; the top modes hold little of the energy);
     * - no drift: the means of the first and last thirds differ by the averaged oscillation
     *   only, 1e-3 of E0 (as in energy_no_gain); a gaining integrator is off by orders more.
     * The same sheet at 0.685 of S (where the wrapped reference case ran before the factor)
     * oscillates by 6 %: the error grows with the step, first order. The film law's crumpling
     * sheet, which gains energy near the bound, is another matter (CHANGELOG, Known limits). */
    const double f = default_fraction();
    double E0, dev, first, last;
    released_sheet(0.999 * f, 8000, &E0, &dev, &first, &last);
    report("released sheet at %.3g of S: E0 %.4g J, largest |E - E0| %.3g of E0, thirds' "
           "means %+.2e, %+.2e",
           0.999 * f, E0, dev, first, last);
    ck_assert_msg(dev <= f && dev > 0.0, "energy off by %g of E0", dev);
    ck_assert_msg(fabs(last - first) <= 1e-3, "drift %g of E0", last - first);
    double E0b, devb, firstb, lastb;
    released_sheet(0.685, 8000, &E0b, &devb, &firstb, &lastb);
    report("released sheet at 0.685 of S: largest |E - E0| %.3g of E0, thirds' means %+.2e, "
           "%+.2e",
           devb, firstb, lastb);
    ck_assert_msg(devb > dev, "the error did not grow with the step: %g vs %g", devb, dev);
}
END_TEST

START_TEST(test_spring_user_law_and_failure)
{
    /* A spring of a user law gives the user's force; when the callback fails the step fails
     * with WS_ERR_CALLBACK, names the web, and leaves the world as it was. And a 3D law is
     * refused for springs. */
    ws_world *w = world_g(1e-3, NO_G);
    int calls = 0;
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_USER;
    ld.stiffness = 1000.0; /* the bound the stable step uses */
    ld.user_fn = failing_law;
    ld.user_data = &calls;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_web_id web = held_spring(w, law);
    double T;
    size_t n;
    ck_ok(w, ws_web_copy_spring_tensions(w, web, &T, 1, &n));
    ck_assert_msg(fabs(T - 100.0) < 1e-9, "user law tension %g, want 100 N", T);
    ws_status s = WS_OK;
    int k;
    for (k = 0; k < 20 && s == WS_OK; k++)
        s = ws_world_step(w);
    ck_assert_int_eq(s, WS_ERR_CALLBACK);
    ck_assert_msg(strstr(ws_world_last_error(w), "web 'springs'") ||
                      strstr(ws_world_last_error(w), "web '(unnamed)'"),
                  "message: %s", ws_world_last_error(w));
    double t;
    ck_ok(w, ws_world_get_time(w, &t));
    ck_assert_msg(fabs(t - 0.011) < 1e-12, "the failed step moved time to %g", t);
    ck_assert_msg(calls > 0, "the callback was never called");
    ws_law_def_init(&ld);
    ld.dim = 3;
    ld.stiffness = 10.0;
    ws_law_id l3;
    ck_ok(w, ws_law_create(w, &ld, &l3));
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.law = l3;
    wd.node_mass = 1e-3;
    double p[6] = {0, 0, 0, 0.1, 0, 0};
    uint32_t sp[2] = {0, 1};
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = p;
    md.node_count = 2;
    md.springs = sp;
    md.spring_count = 1;
    ws_web_id bad;
    ck_assert_int_eq(ws_web_create_mesh(w, &wd, &md, &bad), WS_ERR_INVALID_ARGUMENT);
    ck_assert_msg(strstr(ws_world_last_error(w), "1D law"), "%s", ws_world_last_error(w));
    ws_world_destroy(w);
}
END_TEST

/* A sheet lying on a box on the ground, in a world whose allocator records every block's size
 * and checks the size of each free and realloc against it. */
/* A box on the ground with a sheet of nx by ny nodes 2 cm apart draped over it, centred, on a
 * world of `workers` workers. */
static ws_world *draped_world_of(test_alloc *a, int nx, int ny, int workers)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = 1e-4;
    d.worker_count = workers;
    a->track = 1;
    a->allocs_left = -1;
    test_alloc_install(&d, a);
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    add_ground(w, 1.0, no_material());
    add_box(w, 0.2, 0.2, 0.2, 5.0, (ws_vec3){0, 0, 0.1 + 2e-3}, no_material(), "box");
    ws_law_id law = make_law(w, WS_LAW_TENSION_COMPRESSION, 100.0, 1.0, 0.01, 0.0);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 0.01;
    wd.law = law;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = nx;
    sd.ny = ny;
    sd.spacing_x = sd.spacing_y = 0.02;
    /* Centred over the box, its nodes 0.5 mm above the touching layers. */
    sd.origin = (ws_vec3){-0.01 * (nx - 1), -0.01 * (ny - 1), 0.2 + 2e-3 + 2e-3 + 0.5e-3};
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    return w;
}

/* Out of memory at each allocation of a film step in turn: the step fails with
 * WS_ERR_OUT_OF_MEMORY and changes nothing, the world steps on once memory is back, and every
 * free and realloc is given the size its block was allocated with (before the fix, the node
 * contact scratch kept one array while its capacity read zero, and the web's per-body force
 * arrays kept the old capacity when only some of them had grown). */
/* Out of memory at each allocation of a film step in turn (nx by ny nodes, `workers`): see
 * oom_film_step_sizes. Returns how many of the step's allocations failed in turn. */
static long oom_film_step(int nx, int ny, int workers)
{
    int done = 0;
    long n, failures = 0;
    for (n = 0; n < 400 && !done; n++) {
        test_alloc a = {.allocs_left = -1};
        ws_world *w = draped_world_of(&a, nx, ny, workers);
        uint64_t h0;
        ck_ok(w, ws_world_get_state_hash(w, &h0));
        a.allocs_left = n;
        ws_status st = ws_world_step(w);
        a.allocs_left = -1;
        if (st == WS_OK) {
            done = 1;
        } else {
            failures++;
            ck_assert_msg(st == WS_ERR_OUT_OF_MEMORY, "N = %ld: %s (%s)", n, ws_status_string(st),
                          ws_world_last_error(w));
            uint64_t h1;
            ck_ok(w, ws_world_get_state_hash(w, &h1));
            ck_assert_msg(h1 == h0, "N = %ld: a failed step changed the state", n);
        }
        ck_ok(w, ws_world_step_n(w, 20));
        ws_world_destroy(w);
        ck_assert_msg(a.size_errors == 0, "N = %ld: %ld wrong sizes, first: %s", n, a.size_errors,
                      a.size_error);
        ck_assert_msg(a.live == 0 && a.bytes == 0, "N = %ld: %ld blocks, %lld bytes left", n,
                      a.live, a.bytes);
        test_alloc_done(&a);
    }
    ck_assert_msg(done, "the film step never succeeded");
    return failures;
}

START_TEST(test_oom_film_step_sizes)
{
    report("film step: out of memory at each of its %ld allocations in turn, every free and "
           "realloc given its block's size",
           oom_film_step(12, 12, 1));
}
END_TEST

/* The same with the film swept in lanes: a 24 x 34 sheet is three sweep blocks of 16 rows
 * (WS_WEB_BLOCK_NODES), cut into lanes on two workers, whose scratch the step takes from the
 * world's arena; a failing allocation anywhere in the step, the arena's blocks included,
 * leaves the world as it was and every byte goes back to the free hook with its size. */
START_TEST(test_oom_film_step_lanes)
{
    report("film step in lanes: out of memory at each of its %ld allocations in turn, every "
           "free given its block's size, nothing left at destroy",
           oom_film_step(24, 34, 2));
}
END_TEST

/* A step of a running film takes its scratch from the world's arena and allocates nothing
 * from the user's hooks once the arena and the lists carried from step to step hold what a
 * step needs (STYLE: the step allocates nothing): a sheet draped on a box, on one worker and
 * swept in lanes on two, calls the hooks in its first 400 steps (0.04 s) only, while it
 * settles and its contact lists grow (each array a few doublings: at most 60 calls), and not
 * once in the 100 steps after. An arena given back to the allocator each step, or one that
 * never kept the size a step took, would call them every step. */
static void steady_film(int nx, int ny, int workers, long *first, long *last)
{
    test_alloc a = {0};
    ws_world *w = draped_world_of(&a, nx, ny, workers);
    a.allocs_left = 1000000000L; /* never fails; counts the hooks' calls down */
    ck_ok(w, ws_world_step_n(w, 400));
    *first = 1000000000L - a.allocs_left;
    const long mid = a.allocs_left;
    ck_ok(w, ws_world_step_n(w, 100));
    *last = mid - a.allocs_left;
    ws_world_destroy(w);
    ck_assert_msg(a.live == 0 && a.bytes == 0 && a.size_errors == 0, "%ld blocks, %lld bytes, %s",
                  a.live, a.bytes, a.size_error);
    test_alloc_done(&a);
}

START_TEST(test_steady_step_allocates_nothing)
{
    long first1, last1, first2, last2;
    steady_film(12, 12, 1, &first1, &last1);
    steady_film(24, 34, 2, &first2, &last2);
    report("allocations from the hooks: one worker %ld in steps 1-400, %ld in steps 401-500; "
           "lanes on two workers %ld, %ld",
           first1, last1, first2, last2);
    ck_assert_int_eq(last1, 0);
    ck_assert_int_eq(last2, 0);
    ck_assert_int_le(first1, 60);
    ck_assert_int_le(first2, 60);
}
END_TEST

/* The bytes a world holds (its allocator's count) after 40 steps of an nx by ny sheet on
 * `workers`, lying flat on the ground (every node a candidate: its nodes 0.5 mm above the
 * touching layers) or, `lifted`, 1 m above it (no candidate at all). */
static long long sheet_world_bytes(int nx, int ny, int workers, int lifted)
{
    test_alloc a = {0};
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = 1e-4;
    d.worker_count = workers;
    a.track = 1;
    a.allocs_left = -1;
    test_alloc_install(&d, &a);
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    add_ground(w, 1.0, no_material());
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 0.01;
    wd.law = make_law(w, WS_LAW_TENSION_COMPRESSION, 100.0, 1.0, 0.01, 0.0);
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = nx;
    sd.ny = ny;
    sd.spacing_x = sd.spacing_y = 0.02;
    sd.origin = (ws_vec3){-0.01 * (nx - 1), -0.01 * (ny - 1), (lifted ? 1.0 : 0.0) + 2.5e-3};
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    ck_ok(w, ws_world_step_n(w, 40));
    const long long bytes = a.bytes;
    ws_world_destroy(w);
    test_alloc_done(&a);
    return bytes;
}

/* The node-contact memory of a film swept in lanes is that of one lane plus a margin: each
 * lane keeps room for the candidates of its own rows, not for every candidate of the web (which
 * tripled the world at two workers). A 48 x 64 sheet flat on the ground (3072 candidates, eight
 * sweep blocks of 8 rows, so four lanes on two workers) against the same sheet 1 m up (none): the
 * difference is what the candidates cost. At two workers it must stay within 1.3 times that of
 * one: the lanes' rooms sum to the candidates, each grown by half at most past its own, and
 * rooms sized for the whole web would make it about 1 + lanes - 1 = 4 times. */
START_TEST(test_lanes_contact_memory)
{
    const long long one = sheet_world_bytes(48, 64, 1, 0) - sheet_world_bytes(48, 64, 1, 1);
    const long long two = sheet_world_bytes(48, 64, 2, 0) - sheet_world_bytes(48, 64, 2, 1);
    report("node-contact memory of a 48 x 64 sheet on the ground: %lld B on one worker, %lld B "
           "on two (%.2f times)",
           one, two, (double)two / (double)one);
    ck_assert_int_gt(one, 3072 * 100); /* the candidates' room is there to measure */
    ck_assert_msg((double)two <= 1.3 * (double)one, "two workers take %lld B, one %lld B", two,
                  one);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("web");
    add_case(s, "law_derivatives", test_law_derivatives, 10);
    add_case(s, "law_film_c1", test_law_film_c1, 10);
    add_case(s, "law_energy", test_law_energy, 20);
    add_case(s, "law_bad_defs", test_law_bad_defs, 10);
    add_case(s, "row_prestretch_tension", test_row_prestretch_tension, 20);
    add_case(s, "chain_sag", test_chain_sag, 30);
    add_case(s, "wave_speed", test_wave_speed, 30);
    add_case(s, "band_pressure", test_band_pressure, 60);
    add_case(s, "capstan", test_capstan, 120);
    add_case(s, "capstan_implicit", test_capstan_implicit, 120);
    add_case(s, "energy_no_gain", test_energy_no_gain, 30);
    add_case(s, "sheet_in_blocks_moves_as_its_mesh", test_sheet_in_blocks_moves_as_its_mesh, 10);
    add_case(s, "stable_dt", test_stable_dt, 30);
    add_case(s, "stable_dt_refusal_counted", test_stable_dt_refusal_counted, 10);
    add_case(s, "step_leaves_no_scratch_in_state", test_step_leaves_no_scratch_in_state, 10);
    add_case(s, "node_masses_each_their_own", test_node_masses_each_their_own, 10);
    add_case(s, "runaway_without_a_speed_limit", test_runaway_without_a_speed_limit, 10);
    add_case(s, "state_hash_sees_web", test_state_hash_sees_web, 10);
    add_case(s, "sheet_generator", test_sheet_generator, 20);
    add_case(s, "mesh_node_masses", test_mesh_node_masses, 10);
    add_case(s, "bulk_copies", test_bulk_copies, 10);
    add_case(s, "spring_relaxation", test_spring_relaxation, 10);
    add_case(s, "spring_user_law_and_failure", test_spring_user_law_and_failure, 10);
    add_case(s, "advice_at_both_limits", test_advice_at_both_limits, 10);
    add_case(s, "advice_bounded", test_advice_bounded, 10);
    add_case(s, "released_sheet_energy", test_released_sheet_energy, 20);
    add_case(s, "oom_film_step_sizes", test_oom_film_step_sizes, 60);
    add_case(s, "oom_film_step_lanes", test_oom_film_step_lanes, 120);
    add_case(s, "steady_step_allocates_nothing", test_steady_step_allocates_nothing, 30);
    add_case(s, "lanes_contact_memory", test_lanes_contact_memory, 60);
    add_case(s, "springs_checked_before_law_histories", test_springs_checked_before_law_histories,
             10);
    return run_suite(s);
}
