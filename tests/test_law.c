/* Constitutive laws (include/wrapsim/law.h, lib/law/) against analytical answers.
 *
 *  1. every law type and dim: dF/du and dF/du_dot against central differences;
 *  2. a matrix law reproduces K u + C u_dot (orthotropic and anisotropic, dims 3 and 6);
 *  3. Kelvin-Voigt creep under a constant force: u -> F/k with time constant c/k;
 *  4. relaxation: a held strain step decays as k_inf + sum k_i exp(-t/tau_i), exactly; a
 *     strain ramp follows its closed form for any step; Kelvin-Voigt cannot relax;
 *  5. table: reproduces its points exactly, monotone and C1 between them, energy exact;
 *  6. stop: no force in the gap, the contact force beyond, damping only in contact, never
 *     pulling (bumper) or pushing (strap);
 *  7. history: evaluation never changes the state, commit does; two users keep separate
 *     histories; a commit reproduces the trial's force;
 *  8. sum equals the sum; scaled follows its time function (table and callback);
 *  9. user law: the callback gets its pointer, its failure is an error;
 * 10. energies are the integral of the elastic force (1D) and 1/2 u^T K u (matrix);
 * 11. bad Defs name the field; stale and in-use ids; allocation failure without leaks; bytes
 *     back to zero; old-layout Defs; the internal interface (film form, compat calls).
 *
 * Every tolerance is argued above its assertion. Measured values are printed with a
 * "[measured]" prefix so that the validation report can quote them. */
#include "helpers.h"

#include "law/law.h"

#include <stddef.h>

#define N6 WS_LAW_MAX_DIM

/* A small deterministic generator (64-bit LCG), uniform in [lo, hi). */
static double rnd(uint64_t *s, double lo, double hi)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

/* A matrix with a positive definite symmetric part and a skew part: M = scale (A A^T / n + I/2
 * + 0.3 S), A random, S skew. Anisotropic, not symmetric. */
static void aniso_matrix(int n, double scale, uint64_t seed, int symmetric, double *M)
{
    double A[N6 * N6];
    for (int i = 0; i < n * n; i++)
        A[i] = rnd(&seed, -1.0, 1.0);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double s = 0.0;
            for (int k = 0; k < n; k++)
                s += A[i * n + k] * A[j * n + k];
            M[i * n + j] = scale * (s / n + (i == j ? 0.5 : 0.0));
        }
    if (!symmetric)
        for (int i = 0; i < n; i++)
            for (int j = i + 1; j < n; j++) {
                double s = 0.3 * scale * rnd(&seed, -1.0, 1.0);
                M[i * n + j] += s;
                M[j * n + i] -= s;
            }
}

static ws_law_id create(ws_world *w, const ws_law_def *d)
{
    ws_law_id id;
    ck_ok(w, ws_law_create(w, d, &id));
    return id;
}

/* A measured film tensile curve (force of a 20 mm strip, N, against engineering strain): stiff
 * start, a yield knee, a plateau, strain hardening. */
static const double FILM_X[] = {-0.05, 0.0, 0.01, 0.02, 0.04, 0.08, 0.15, 0.3, 0.6, 1.0, 2.0, 3.0};
static const double FILM_F[] = {-2.0, 0.0,  8.0,  14.0, 19.0, 21.0,
                                21.5, 22.0, 24.0, 30.0, 60.0, 110.0};
#define FILM_N (sizeof FILM_X / sizeof FILM_X[0])

/* A user law: F_i = k a tanh(u_i / a) + g u_j^2 + c (1 + u_i^2) ud_i with j = (i + 1) mod dim,
 * coupled and nonlinear in both arguments. */
typedef struct user_ctx {
    double k, a, g, c;
    long calls;
    int fail;   /* return non-zero */
    int nan;    /* write a NaN */
    void *seen; /* the user pointer the callback was given */
    int seen_dim;
} user_ctx;

static int user_law(void *user, int dim, const double *u, const double *ud, double t, double *F,
                    double *dFdu, double *dFdud)
{
    (void)t;
    user_ctx *c = user;
    c->calls++;
    c->seen = user;
    c->seen_dim = dim;
    if (c->fail)
        return 1;
    for (int i = 0; i < dim; i++) {
        int j = (i + 1) % dim;
        double th = tanh(u[i] / c->a);
        F[i] = c->k * c->a * th + c->g * u[j] * u[j] + c->c * (1.0 + u[i] * u[i]) * ud[i];
        dFdu[i * dim + i] += c->k * (1.0 - th * th) + 2.0 * c->c * u[i] * ud[i];
        dFdu[i * dim + j] += 2.0 * c->g * u[j];
        dFdud[i * dim + i] = c->c * (1.0 + u[i] * u[i]);
    }
    if (c->nan)
        F[0] = NAN;
    return 0;
}

/* A time function: 1 + 0.5 sin(2 pi t), counting calls; fails for t < 0. */
typedef struct time_ctx {
    long calls;
    void *seen;
} time_ctx;

static int time_fn(void *user, double t, double *factor)
{
    time_ctx *c = user;
    c->calls++;
    c->seen = user;
    if (t < 0.0)
        return 1;
    *factor = 0.5 + 0.25 * sin(2.0 * 3.14159265358979323846 * t);
    return 0;
}

/* ---- the laws under test ---- */

enum {
    L_ELASTIC,
    L_ELASTIC_MATRIX,
    L_VISCOUS,
    L_VISCOUS_MATRIX,
    L_KELVIN_VOIGT,
    L_KELVIN_VOIGT_MATRIX,
    L_FILM,
    L_CUBIC,
    L_CUBIC_MATRIX,
    L_TABLE,
    L_STOP,
    L_STOP_SHARP,
    L_RELAXATION,
    L_SUM,
    L_SCALED_TABLE,
    L_SCALED_FN,
    L_USER,
    L_COUNT
};

static const char *const LAW_LABEL[L_COUNT] = {"linear elastic",
                                               "linear elastic (matrix)",
                                               "viscous",
                                               "viscous (matrix)",
                                               "Kelvin-Voigt",
                                               "Kelvin-Voigt (matrix)",
                                               "film",
                                               "cubic",
                                               "cubic (matrices)",
                                               "table",
                                               "stop (smooth)",
                                               "stop (sharp)",
                                               "relaxation",
                                               "sum",
                                               "scaled (table)",
                                               "scaled (callback)",
                                               "user"};

/* Where a law's pieces join (strain, per component): central differences that straddle them
 * measure a one-sided mixture, so the test keeps its points away from them. */
typedef struct kinks {
    double at[32];
    int n;
} kinks;

static void add_kink(kinks *k, double x)
{
    if (k->n < 32)
        k->at[k->n++] = x;
}

static const double STOP_LO = -0.04, STOP_HI = 0.03, STOP_W = 0.005;
static const double PRONY_K[2] = {800.0, 300.0}, PRONY_TAU[2] = {0.05, 2.0};

/* Create law `which` of dimension dim without asserting (for the allocation-failure test).
 * parts: the laws a sum (3) or a scaled law (1) refers to; k: where its pieces join (may be
 * NULL). */
static ws_status law_create(ws_world *w, int which, int dim, const ws_law_id *parts, kinks *k,
                            user_ctx *uc, time_ctx *tc, ws_law_id *out)
{
    static const double T[] = {0.0, 1.0, 2.0}, S[] = {1.0, 0.25, 0.5};
    double K[N6 * N6], C[N6 * N6], k3[N6];
    ws_law_def d;
    ws_law_def_init(&d);
    d.dim = dim;
    d.name = LAW_LABEL[which];
    aniso_matrix(dim, 2000.0, 11u + (uint64_t)dim, 0, K);
    aniso_matrix(dim, 5.0, 23u + (uint64_t)dim, 0, C);
    switch (which) {
    case L_ELASTIC:
    case L_ELASTIC_MATRIX:
        d.type = WS_LAW_LINEAR_ELASTIC;
        d.stiffness = 2000.0;
        d.stiffness_matrix = which == L_ELASTIC_MATRIX ? K : NULL;
        break;
    case L_VISCOUS:
    case L_VISCOUS_MATRIX:
        d.type = WS_LAW_LINEAR_VISCOUS;
        d.damping = 5.0;
        d.damping_matrix = which == L_VISCOUS_MATRIX ? C : NULL;
        break;
    case L_KELVIN_VOIGT:
    case L_KELVIN_VOIGT_MATRIX:
        d.type = WS_LAW_LINEAR_VISCOELASTIC;
        d.stiffness = 2000.0;
        d.damping = 5.0;
        d.stiffness_matrix = which == L_KELVIN_VOIGT_MATRIX ? K : NULL;
        d.damping_matrix = which == L_KELVIN_VOIGT_MATRIX ? C : NULL;
        break;
    case L_FILM:
        d.type = WS_LAW_TENSION_COMPRESSION;
        d.stiffness = 2000.0;
        d.compression_stiffness = 20.0;
        d.damping = 0.1;
        d.transition = 0.01;
        if (k) {
            add_kink(k, -0.01);
            add_kink(k, 0.01);
        }
        break;
    case L_CUBIC:
    case L_CUBIC_MATRIX:
        d.type = WS_LAW_CUBIC_ELASTIC;
        d.stiffness = 500.0;
        d.cubic_stiffness = 4e5;
        d.damping = 2.0;
        if (which == L_CUBIC_MATRIX) {
            for (int i = 0; i < dim; i++)
                k3[i] = 1e5 * (i + 1);
            d.cubic_stiffnesses = k3;
            d.stiffness_matrix = K;
            d.damping_matrix = C;
        }
        break;
    case L_TABLE:
        d.type = WS_LAW_TABLE;
        d.table_strain = FILM_X;
        d.table_force = FILM_F;
        d.table_count = FILM_N;
        d.damping = 0.5;
        if (k)
            for (size_t i = 0; i < FILM_N; i++)
                add_kink(k, FILM_X[i]);
        break;
    case L_STOP:
    case L_STOP_SHARP:
        d.type = WS_LAW_STOP;
        d.stiffness = 3000.0;
        d.damping = 20.0;
        d.stop_low = STOP_LO;
        d.stop_high = STOP_HI;
        d.transition = which == L_STOP ? STOP_W : 0.0;
        if (k) {
            add_kink(k, STOP_LO);
            add_kink(k, STOP_HI);
            add_kink(k, STOP_LO - 2 * d.transition);
            add_kink(k, STOP_HI + 2 * d.transition);
        }
        break;
    case L_RELAXATION:
        d.type = WS_LAW_RELAXATION;
        d.stiffness = 500.0;
        d.damping = 1.0;
        d.prony_stiffness = PRONY_K;
        d.prony_time = PRONY_TAU;
        d.prony_count = 2;
        break;
    case L_SUM:
        d.type = WS_LAW_SUM;
        d.terms = parts;
        d.term_count = 3;
        break;
    case L_SCALED_TABLE:
        d.type = WS_LAW_SCALED;
        d.base = parts[0];
        d.scale = 2.0;
        d.scale_times = T;
        d.scale_factors = S;
        d.scale_count = 3;
        break;
    case L_SCALED_FN:
        d.type = WS_LAW_SCALED;
        d.base = parts[0];
        d.scale_fn = time_fn;
        d.scale_user = tc;
        break;
    case L_USER:
        d.type = WS_LAW_USER;
        d.user_fn = user_law;
        d.user_data = uc;
        d.stiffness = uc->k + 2 * uc->g;
        d.damping = 2 * uc->c;
        break;
    }
    return ws_law_create(w, &d, out);
}

/* The parts a composite law refers to: a sum of a cubic pad, a relaxation and a stop; a table-
 * scaled matrix Kelvin-Voigt law; a callback-scaled relaxation. 0 parts for the others. */
static int law_parts(int which, int *kinds)
{
    switch (which) {
    case L_SUM:
        kinds[0] = L_CUBIC;
        kinds[1] = L_RELAXATION;
        kinds[2] = L_STOP;
        return 3;
    case L_SCALED_TABLE:
        kinds[0] = L_KELVIN_VOIGT_MATRIX;
        return 1;
    case L_SCALED_FN:
        kinds[0] = L_RELAXATION;
        return 1;
    default:
        return 0;
    }
}

static ws_law_id make_law(ws_world *w, int which, int dim, kinks *k, user_ctx *uc, time_ctx *tc)
{
    int kinds[3];
    ws_law_id parts[3] = {{0}, {0}, {0}};
    int np = law_parts(which, kinds);
    for (int i = 0; i < np; i++)
        parts[i] = make_law(w, kinds[i], dim, k, uc, tc);
    ws_law_id id;
    ck_ok(w, law_create(w, which, dim, parts, k, uc, tc, &id));
    return id;
}

static ws_law_id make_stop(ws_world *w, int dim, double tr, kinks *k)
{
    return make_law(w, tr > 0.0 ? L_STOP : L_STOP_SHARP, dim, k, NULL, NULL);
}

static ws_law_id make_relaxation(ws_world *w, int dim, double damping)
{
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = WS_LAW_RELAXATION;
    d.dim = dim;
    d.stiffness = 500.0;
    d.damping = damping;
    d.prony_stiffness = PRONY_K;
    d.prony_time = PRONY_TAU;
    d.prony_count = 2;
    return create(w, &d);
}

static ws_law_id make_table(ws_world *w, int dim, kinks *k)
{
    return make_law(w, L_TABLE, dim, k, NULL, NULL);
}

static int near_kink(const kinks *k, double u, double gap)
{
    for (int i = 0; i < k->n; i++)
        if (fabs(u - k->at[i]) < gap)
            return 1;
    return 0;
}

/* ---- 1. derivatives against central differences ---- */

START_TEST(test_fd_derivatives)
{
    ws_world *w = new_world(1e-3);
    static const int dims[3] = {1, 3, 6};
    user_ctx uc = {800.0, 0.05, 300.0, 3.0, 0, 0, 0, NULL, 0};
    time_ctx tc = {0, NULL};
    /* Steps: h = 1e-6 in strain (the strains are ~0.1), hr = 1e-5 in rate (rates ~1/s). The
     * central difference errs by h^2 F'''/6 + eps |F| / h. The largest third derivative is the
     * table's: its pieces are 0.01 wide with slopes ~1e3 N, F''' ~ 6 (m0 + m1) / h_k^2 ~ 1e8 N,
     * so h^2 F''' / 6 ~ 2e-5 N; the round-off term is 2e-16 * 100 N / 1e-6 = 2e-8 N. Against
     * the law's stiffness scale (>= 100 N per unit strain) both stay below 1e-6 of it: the
     * tolerance is 1e-6 times the law's bound on the derivative (+1 for laws whose bound is
     * zero in one argument). A wrong derivative errs by its own size, 1e-2 to 1 of the scale. */
    const double h = 1e-6, hr = 1e-5;
    double worst_all = 0.0;
    for (int which = 0; which < L_COUNT; which++) {
        double worst = 0.0;
        int checked = 0;
        for (int di = 0; di < 3; di++) {
            const int n = dims[di];
            kinks kk = {{0}, 0};
            ws_law_id id = make_law(w, which, n, &kk, &uc, &tc);
            ws_law_info info;
            ck_ok(w, ws_law_get_info(w, id, &info));
            ck_assert_int_eq(info.dim, n);
            size_t ns = 0;
            ck_ok(w, ws_law_get_state_size(w, id, &ns));
            ck_assert_uint_eq(ns, info.state_size);
            double state[64];
            ck_assert_uint_le(ns, 64);
            ck_ok(w, ws_law_init_state(w, id, ns ? state : NULL));
            uint64_t seed = 1234u + (uint64_t)(which * 7 + n);
            /* A history: a few committed steps, so that the state is not the initial one. */
            for (int c = 0; c < 3 && ns; c++) {
                double u[N6], ud[N6];
                for (int i = 0; i < n; i++) {
                    u[i] = rnd(&seed, -0.05, 0.05);
                    ud[i] = rnd(&seed, -1.0, 1.0);
                }
                ck_ok(w, ws_law_commit_state(w, id, state, u, ud, 0.1 * c, 0.03));
            }
            double kscale = info.max_stiffness + 1.0, cscale = info.max_damping + 1.0;
            for (int trial = 0; trial < 30; trial++) {
                double u[N6], ud[N6];
                int ok = 1;
                for (int i = 0; i < n; i++) {
                    u[i] = rnd(&seed, -0.1, 0.12);
                    ud[i] = rnd(&seed, -1.0, 1.0);
                    ok &= !near_kink(&kk, u[i], 4 * h);
                    /* Where the stop's damping would cancel its spring it is clamped at zero, a
                     * corner of F: keep away from it by moving into contact on either side. */
                    if (u[i] > STOP_HI)
                        ud[i] = fabs(ud[i]);
                    if (u[i] < STOP_LO)
                        ud[i] = -fabs(ud[i]);
                }
                if (!ok)
                    continue;
                const double t = 0.7, dt = 0.01;
                double F[N6], K[N6 * N6], C[N6 * N6];
                ck_ok(w, ws_law_evaluate_state(w, id, ns ? state : NULL, u, ud, t, dt, F, K, C));
                for (int j = 0; j < n; j++) {
                    double up[N6], um[N6], Fp[N6], Fm[N6];
                    memcpy(up, u, sizeof up);
                    memcpy(um, u, sizeof um);
                    up[j] += h;
                    um[j] -= h;
                    ck_ok(w, ws_law_evaluate_state(w, id, ns ? state : NULL, up, ud, t, dt, Fp,
                                                   NULL, NULL));
                    ck_ok(w, ws_law_evaluate_state(w, id, ns ? state : NULL, um, ud, t, dt, Fm,
                                                   NULL, NULL));
                    for (int i = 0; i < n; i++) {
                        double fd = (Fp[i] - Fm[i]) / (2 * h), e = fabs(fd - K[i * n + j]);
                        ck_assert_msg(e <= 1e-6 * kscale,
                                      "%s dim %d: dF%d/du%d = %.12g, differences %.12g",
                                      LAW_LABEL[which], n, i, j, K[i * n + j], fd);
                        worst = fmax(worst, e / kscale);
                    }
                    memcpy(up, ud, sizeof up);
                    memcpy(um, ud, sizeof um);
                    up[j] += hr;
                    um[j] -= hr;
                    ck_ok(w, ws_law_evaluate_state(w, id, ns ? state : NULL, u, up, t, dt, Fp, NULL,
                                                   NULL));
                    ck_ok(w, ws_law_evaluate_state(w, id, ns ? state : NULL, u, um, t, dt, Fm, NULL,
                                                   NULL));
                    for (int i = 0; i < n; i++) {
                        double fd = (Fp[i] - Fm[i]) / (2 * hr), e = fabs(fd - C[i * n + j]);
                        ck_assert_msg(e <= 1e-6 * cscale,
                                      "%s dim %d: dF%d/dud%d = %.12g, differences %.12g",
                                      LAW_LABEL[which], n, i, j, C[i * n + j], fd);
                        worst = fmax(worst, e / cscale);
                    }
                }
                /* The bounds hold where the derivatives were checked (the stop's damping adds
                 * c r'' u_dot to dF/du, which its bound leaves out; the cubic's is at |u| <= 1). */
                if (which != L_STOP && which != L_SUM)
                    for (int i = 0; i < n * n; i++) {
                        ck_assert_msg(fabs(K[i]) <= info.max_stiffness * (1 + 1e-12) + 1e-9,
                                      "%s dim %d: |dF/du| %g above the bound %g", LAW_LABEL[which],
                                      n, K[i], info.max_stiffness);
                        ck_assert_msg(fabs(C[i]) <= info.max_damping * (1 + 1e-12) + 1e-9,
                                      "%s dim %d: |dF/dud| %g above the bound %g", LAW_LABEL[which],
                                      n, C[i], info.max_damping);
                    }
                checked++;
            }
        }
        ck_assert_msg(checked >= 60, "%s: only %d points checked", LAW_LABEL[which], checked);
        report("derivatives, %-18s: largest |difference - analytic| / scale = %.2e (%d points)",
               LAW_LABEL[which], worst, checked);
        worst_all = fmax(worst_all, worst);
    }
    report("derivatives of every law and dim: largest relative error %.2e (tolerance 1e-6)",
           worst_all);
    ck_assert_int_gt(uc.calls, 0);
    ck_assert_int_gt(tc.calls, 0);
    ws_world_destroy(w);
}
END_TEST

/* ---- 2. matrix laws ---- */

START_TEST(test_matrix_law)
{
    ws_world *w = new_world(1e-3);
    for (int n = 3; n <= 6; n += 3) {
        for (int sym = 0; sym < 2; sym++) {
            double K[N6 * N6], C[N6 * N6];
            aniso_matrix(n, 1e4, 5u + (uint64_t)n, sym, K);
            aniso_matrix(n, 30.0, 9u + (uint64_t)n, sym, C);
            ws_law_def d;
            ws_law_def_init(&d);
            d.type = WS_LAW_LINEAR_VISCOELASTIC;
            d.dim = n;
            d.stiffness_matrix = K;
            d.damping_matrix = C;
            ws_law_id id = create(w, &d);
            /* The Def's arrays are copies: changing them afterwards changes nothing. */
            double K0 = K[1];
            K[1] = 1e9;
            uint64_t seed = 77;
            double worst = 0.0;
            for (int trial = 0; trial < 20; trial++) {
                double u[N6], ud[N6], F[N6], dK[N6 * N6], dC[N6 * N6];
                for (int i = 0; i < n; i++) {
                    u[i] = rnd(&seed, -0.01, 0.01);
                    ud[i] = rnd(&seed, -0.5, 0.5);
                }
                ck_ok(w, ws_law_evaluate_state(w, id, NULL, u, ud, 0.0, 0.0, F, dK, dC));
                K[1] = K0;
                for (int i = 0; i < n; i++) {
                    double want = 0.0, mag = 0.0;
                    for (int j = 0; j < n; j++) {
                        want += K[i * n + j] * u[j] + C[i * n + j] * ud[j];
                        mag += fabs(K[i * n + j] * u[j]) + fabs(C[i * n + j] * ud[j]);
                    }
                    /* The same 2n products summed, maybe in another order: a few ulps of the
                     * sum of their magnitudes. */
                    ck_assert_msg(fabs(F[i] - want) <= 1e-14 * mag,
                                  "dim %d: F%d = %.17g, want %.17g", n, i, F[i], want);
                    worst = fmax(worst, fabs(F[i] - want) / mag);
                }
                for (int i = 0; i < n * n; i++) {
                    ck_assert(dK[i] == K[i]);
                    ck_assert(dC[i] == C[i]);
                }
                K[1] = 1e9;
            }
            K[1] = K0;
            ws_law_info info;
            ck_ok(w, ws_law_get_info(w, id, &info));
            ck_assert_uint_eq(info.flags, WS_LAW_FLAG_ELASTIC | WS_LAW_FLAG_VISCOUS);
            /* Energy 1/2 u^T K u (exact for symmetric K; for any K it is the quadratic form). */
            double u[N6], e, want = 0.0;
            for (int i = 0; i < n; i++)
                u[i] = 0.001 * (i + 1);
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++)
                    want += 0.5 * u[i] * K[i * n + j] * u[j];
            ck_ok(w, ws_law_energy_state(w, id, NULL, u, 0.0, &e));
            ck_assert_msg(fabs(e - want) <= 1e-13 * fabs(want), "energy %.17g, want %.17g", e,
                          want);
            report("matrix law dim %d (%s): F = K u + C u_dot to %.1e of the terms' magnitude", n,
                   sym ? "orthotropic/symmetric" : "anisotropic", worst);
        }
    }
    /* An orthotropic bushing: diagonal K, one direction free (zero stiffness is allowed). */
    double Kd[36] = {0};
    double diag[6] = {1e5, 1e5, 0.0, 50.0, 50.0, 10.0};
    for (int i = 0; i < 6; i++)
        Kd[i * 6 + i] = diag[i];
    ws_law_def d;
    ws_law_def_init(&d);
    d.dim = 6;
    d.stiffness_matrix = Kd;
    ws_law_id id = create(w, &d);
    ws_law_info info;
    ck_ok(w, ws_law_get_info(w, id, &info));
    /* The bound sqrt(|K|_1 |K|_inf) of a diagonal matrix is its largest entry. */
    ck_assert(info.max_stiffness == 1e5);
    ck_assert_uint_eq(info.flags, WS_LAW_FLAG_ELASTIC);
    ws_world_destroy(w);
}
END_TEST

/* ---- 3. Kelvin-Voigt creep ---- */

START_TEST(test_kelvin_voigt_creep)
{
    ws_world *w = new_world(1e-3);
    const double k = 2000.0, c = 40.0, F0 = 30.0, tau = c / k; /* 20 ms, u_inf = 15 mm/m */
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = WS_LAW_LINEAR_VISCOELASTIC;
    d.stiffness = k;
    d.damping = c;
    ws_law_id id = create(w, &d);
    /* Integrate F(u, u_dot) = F0 with the trapezoidal rule, solving each step by Newton with
     * the law's derivatives, as an implicit integrator would: u1 = u0 + dt/2 (v0 + v1), so
     * v1 = 2 (u1 - u0)/dt - v0 and dR/du1 = dF/du + dF/du_dot 2/dt. */
    const double dt = tau / 100.0;
    double u = 0.0, v = F0 / c; /* at t = 0+ the damper takes the whole force */
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int np = 0;
    for (int step = 1; step <= 2000; step++) {
        double u1 = u;
        for (int it = 0; it < 3; it++) {
            double v1 = 2.0 * (u1 - u) / dt - v, F, dFu, dFv;
            ck_ok(w, ws_law_evaluate(w, id, u1, v1, &F, &dFu, &dFv));
            u1 -= (F - F0) / (dFu + dFv * 2.0 / dt);
        }
        v = 2.0 * (u1 - u) / dt - v;
        u = u1;
        double t = step * dt;
        if (t <= 5 * tau) { /* fit ln(1 - u/u_inf) = -t/tau_measured */
            double y = log(1.0 - u / (F0 / k));
            sx += t;
            sy += y;
            sxx += t * t;
            sxy += t * y;
            np++;
        }
    }
    double slope = (np * sxy - sx * sy) / (np * sxx - sx * sx);
    double tau_m = -1.0 / slope;
    report("Kelvin-Voigt creep: tau measured %.9g s, c/k = %.9g s (relative %.2e); u(20 tau) = "
           "%.12g, F0/k = %.12g",
           tau_m, tau, fabs(tau_m / tau - 1), u, F0 / k);
    /* The trapezoidal rule multiplies the deficit by (1 - a/2)/(1 + a/2) per step, a = dt/tau
     * = 0.01, which is exp(-a (1 + a^2/12 + ...)): the measured tau is short by a^2/12 = 8e-6
     * of itself. Allow 2e-5. */
    ck_assert_msg(fabs(tau_m / tau - 1) < 2e-5, "tau %g, want %g", tau_m, tau);
    /* After 20 tau the deficit is exp(-20) = 2e-9 of u_inf. */
    ck_assert_msg(fabs(u - F0 / k) < 1e-8 * F0 / k, "u = %.12g, want %.12g", u, F0 / k);
    ws_world_destroy(w);
}
END_TEST

/* ---- 4. relaxation ---- */

START_TEST(test_relaxation_step)
{
    ws_world *w = new_world(1e-3);
    for (int n = 1; n <= 3; n += 2) {
        ws_law_id id = make_relaxation(w, n, 0.0);
        size_t ns;
        ck_ok(w, ws_law_get_state_size(w, id, &ns));
        ck_assert_uint_eq(ns, (size_t)n * 3); /* the committed strain and two branch forces */
        double state[9], u[3] = {0.02, -0.01, 0.05}, F[3];
        ck_ok(w, ws_law_init_state(w, id, state));
        /* The step: applied within one step of zero length, then held. */
        ck_ok(w, ws_law_commit_state(w, id, state, u, NULL, 0.0, 0.0));
        const double dt = 1e-3, kinf = 500.0;
        double worst = 0.0, sx = 0, sy = 0, sxx = 0, sxy = 0;
        int np = 0;
        for (int step = 1; step <= 4000; step++) {
            double t = step * dt;
            /* A trial first (never changes the state), then the commit. */
            ck_ok(w, ws_law_evaluate_state(w, id, state, u, NULL, t, dt, F, NULL, NULL));
            ck_ok(w, ws_law_commit_state(w, id, state, u, NULL, t, dt));
            for (int i = 0; i < n; i++) {
                double want = (kinf + PRONY_K[0] * exp(-t / PRONY_TAU[0]) +
                               PRONY_K[1] * exp(-t / PRONY_TAU[1])) *
                              u[i];
                /* The update multiplies each branch force by exp(-dt/tau) every step: after N
                 * steps the force carries N roundings, N eps = 4000 * 1.1e-16 = 4.4e-13 of it;
                 * allow 1e-12. */
                ck_assert_msg(fabs(F[i] - want) <= 1e-12 * fabs(want), "t %g: F %.17g want %.17g",
                              t, F[i], want);
                worst = fmax(worst, fabs(F[i] - want) / fabs(want));
            }
            /* The fast branch, measured: once the slow one is subtracted analytically. */
            if (n == 1 && t <= 5 * PRONY_TAU[0]) {
                double y =
                    log((F[0] / u[0] - kinf - PRONY_K[1] * exp(-t / PRONY_TAU[1])) / PRONY_K[0]);
                sx += t;
                sy += y;
                sxx += t * t;
                sxy += t * y;
                np++;
            }
        }
        if (n == 1) {
            double tau_m = -(np * sxx - sx * sx) / (np * sxy - sx * sy);
            report("relaxation (Prony, 2 branches): F(t) = (k_inf + sum k_i exp(-t/tau_i)) u0 "
                   "to %.1e over 4000 steps; fast tau measured %.12g s (%.12g s)",
                   worst, tau_m, PRONY_TAU[0]);
            /* The subtraction of the slow branch leaves the fast one to round-off of F (1e-12
             * relative) divided by what is left of it at 5 tau (exp(-5) k_0 / F ~ 5e-3): the
             * log errs by ~2e-10, the fitted tau by less. */
            ck_assert_msg(fabs(tau_m / PRONY_TAU[0] - 1) < 1e-8, "tau %g", tau_m);
        }
    }
    /* A standard linear solid (one branch): the relaxation time from the history alone. */
    const double ks = 100.0, k1 = 400.0, tau1 = 0.3;
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = WS_LAW_RELAXATION;
    d.stiffness = ks;
    d.prony_stiffness = &k1;
    d.prony_time = &tau1;
    d.prony_count = 1;
    ws_law_id sls = create(w, &d);
    double st[2], u0 = 0.1, F = 0.0, F0 = 0.0, Fe = 0.0;
    ck_ok(w, ws_law_init_state(w, sls, st));
    ck_ok(w, ws_law_commit_state(w, sls, st, &u0, NULL, 0.0, 0.0));
    ck_ok(w, ws_law_evaluate_state(w, sls, st, &u0, NULL, 0.0, 0.0, &F0, NULL, NULL));
    double t_e = NAN, prev = F0, dt = 1e-3;
    for (int step = 1; step <= 3000; step++) {
        ck_ok(w, ws_law_commit_state(w, sls, st, &u0, NULL, step * dt, dt));
        ck_ok(w, ws_law_evaluate_state(w, sls, st, &u0, NULL, step * dt, 0.0, &F, NULL, NULL));
        /* When the excess force over the relaxed one falls to 1/e of its start. */
        double target = ks * u0 + k1 * u0 / exp(1.0);
        if (isnan(t_e) && F <= target)
            t_e = (step - 1) * dt + dt * (prev - target) / (prev - F);
        prev = F;
    }
    Fe = F;
    report("standard linear solid: F(0) = %.6g N (instantaneous (k_inf + k_1) u0 = %.6g), "
           "F(3 s) = %.6g N (relaxed k_inf u0 = %.6g), 1/e time %.6g s (tau %.6g s)",
           F0, (ks + k1) * u0, Fe, ks * u0, t_e, tau1);
    ck_assert(fabs(F0 - (ks + k1) * u0) <= 1e-13 * F0);
    /* exp(-10) of k_1 u0 is left after 10 tau. */
    ck_assert(fabs(Fe - ks * u0) <= 1e-4 * k1 * u0);
    /* Linear interpolation within a 1 ms step of an exponential with tau = 0.3 s errs by
     * dt^2 / (8 tau) = 4e-7 s. */
    ck_assert_msg(fabs(t_e - tau1) < 1e-6, "1/e time %g", t_e);

    /* Kelvin-Voigt at a held strain keeps its force: it cannot show the film's tension loss. */
    ws_law_def kv;
    ws_law_def_init(&kv);
    kv.type = WS_LAW_LINEAR_VISCOELASTIC;
    kv.stiffness = ks + k1;
    kv.damping = k1 * tau1;
    ws_law_id kvid = create(w, &kv);
    double Fkv;
    ck_ok(w, ws_law_evaluate(w, kvid, u0, 0.0, &Fkv, NULL, NULL));
    ck_assert(Fkv == (ks + k1) * u0);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_relaxation_ramp)
{
    /* A strain ramp u = r t: dq/dt = k r - q/tau gives q = k r tau (1 - exp(-t/tau)). The
     * update assumes a linear strain within each step, so it is exact for any step: a step of
     * tau/2 still follows the closed form to round-off. */
    ws_world *w = new_world(1e-3);
    ws_law_id id = make_relaxation(w, 1, 0.0);
    double st[3];
    ck_ok(w, ws_law_init_state(w, id, st));
    const double r = 0.4, dt = 0.025, kinf = 500.0;
    double worst = 0.0;
    for (int step = 1; step <= 200; step++) {
        double t = step * dt, u = r * t, F;
        ck_ok(w, ws_law_evaluate_state(w, id, st, &u, &r, t, dt, &F, NULL, NULL));
        ck_ok(w, ws_law_commit_state(w, id, st, &u, &r, t, dt));
        double want = kinf * u;
        for (int j = 0; j < 2; j++)
            want += PRONY_K[j] * r * PRONY_TAU[j] * -expm1(-t / PRONY_TAU[j]);
        worst = fmax(worst, fabs(F - want) / want);
        /* 200 steps of a few roundings each: 1e-13. */
        ck_assert_msg(fabs(F - want) <= 1e-13 * want, "t %g: F %.17g want %.17g", t, F, want);
    }
    report("relaxation under a strain ramp, dt = tau_fast / 2: closed form to %.1e", worst);
    ws_world_destroy(w);
}
END_TEST

/* ---- 5. table ---- */

/* A sharp yield knee: tangents from the neighbouring secants alone (Catmull-Rom) overshoot
 * it badly. */
static const double KNEE_X[] = {0.0, 0.01, 0.02, 0.03, 0.1};
static const double KNEE_F[] = {0.0, 10.0, 10.1, 10.2, 10.3};
#define KNEE_N (sizeof KNEE_X / sizeof KNEE_X[0])

/* The table law through (X, F): its points exactly, monotone and within each interval's end
 * values over `per` samples per interval, C1 at the inner points. Returns the least tangent. */
static double check_table(ws_world *w, ws_law_id id, const double *X, const double *Fv, size_t n,
                          int per)
{
    /* Its points, exactly: a Hermite piece at s = 0 is its left value times 1. */
    for (size_t i = 0; i < n; i++) {
        double F;
        ck_ok(w, ws_law_evaluate(w, id, X[i], 0.0, &F, NULL, NULL));
        ck_assert_msg(F == Fv[i], "point %zu: %.17g, want %.17g", i, F, Fv[i]);
    }
    double least = INFINITY, prevF = -INFINITY;
    for (size_t k = 0; k + 1 < n; k++) {
        for (int j = 0; j <= per; j++) {
            double u = X[k] + (X[k + 1] - X[k]) * j / per, F, dF;
            ck_ok(w, ws_law_evaluate(w, id, u, 0.0, &F, &dF, NULL));
            ck_assert_msg(F >= prevF, "decreases at %.9g: %.17g after %.17g", u, F, prevF);
            ck_assert_msg(F >= Fv[k] && F <= Fv[k + 1], "overshoot at %g: %.17g", u, F);
            ck_assert_msg(dF >= 0.0, "negative tangent %g at %g", dF, u);
            least = fmin(least, dF);
            prevF = F;
        }
        /* C1: the tangents on both sides of an inner point agree (to the change of the tangent
         * over one ulp of u, far below 1e-9). */
        if (k + 2 < n) {
            double dl, dr, x = X[k + 1];
            ck_ok(w, ws_law_evaluate(w, id, nextafter(x, -INFINITY), 0.0, NULL, &dl, NULL));
            ck_ok(w, ws_law_evaluate(w, id, x, 0.0, NULL, &dr, NULL));
            ck_assert_msg(fabs(dl - dr) <= 1e-9 * fmax(1.0, fabs(dr)), "kink at %g: %g | %g", x, dl,
                          dr);
        }
    }
    return least;
}

START_TEST(test_table)
{
    ws_world *w = new_world(1e-3);
    ws_law_id id = make_table(w, 1, NULL);
    const int per = 2000;
    double least = check_table(w, id, FILM_X, FILM_F, FILM_N, per);
    /* Beyond the ends, straight lines with the end tangents (continuing monotone). */
    double Fa, Fb, da, db;
    ck_ok(w, ws_law_evaluate(w, id, 4.0, 0.0, &Fa, &da, NULL));
    ck_ok(w, ws_law_evaluate(w, id, 5.0, 0.0, &Fb, &db, NULL));
    ck_assert(da == db && da > 0.0 && fabs(Fb - Fa - da) <= 1e-12 * Fb);

    ws_law_def d;
    ws_law_def_init(&d);
    d.type = WS_LAW_TABLE;
    d.table_strain = KNEE_X;
    d.table_force = KNEE_F;
    d.table_count = KNEE_N;
    ws_law_id knee = create(w, &d);
    double least_knee = check_table(w, knee, KNEE_X, KNEE_F, KNEE_N, per);
    /* What the unlimited tangents would do on [0.01, 0.02]. */
    double cr_max = -INFINITY;
    {
        const size_t k = 1;
        double h = KNEE_X[k + 1] - KNEE_X[k];
        double m0 = (KNEE_F[k + 1] - KNEE_F[k - 1]) / (KNEE_X[k + 1] - KNEE_X[k - 1]);
        double m1 = (KNEE_F[k + 2] - KNEE_F[k]) / (KNEE_X[k + 2] - KNEE_X[k]);
        for (int j = 0; j <= per; j++) {
            double s = (double)j / per, s1 = 1 - s;
            double F = KNEE_F[k] * (1 + 2 * s) * s1 * s1 + h * m0 * s * s1 * s1 +
                       KNEE_F[k + 1] * s * s * (3 - 2 * s) - h * m1 * s * s * s1;
            cr_max = fmax(cr_max, F);
        }
    }
    report("table: points exact, monotone and within the end values over %d samples per "
           "interval (film curve, %zu points: least tangent %.3g N; yield knee: %.3g N); at the "
           "knee [0.01, 0.02] (10 to 10.1 N) unlimited Catmull-Rom tangents would reach %.4g N",
           per, FILM_N, least, least_knee, cr_max);
    ck_assert(cr_max > 10.5); /* the knee is sharp enough to show it */

    /* Energy: the integral of the interpolant from 0, exact (cubic pieces integrated), against
     * Simpson's rule on a fine grid (exact for cubics up to round-off on each piece). */
    double worst = 0.0;
    for (double b = -0.2; b <= 3.5; b += 0.37) {
        double E;
        ck_ok(w, ws_law_energy(w, id, b, &E));
        /* Simpson on the knots and the limits: every piece is a cubic, so each sub-interval
         * rule is exact; the sum is exact to round-off. */
        double pts[64];
        int np = 0;
        double lo = fmin(0.0, b), hi = fmax(0.0, b);
        pts[np++] = lo;
        for (size_t i = 0; i < FILM_N; i++)
            if (FILM_X[i] > lo && FILM_X[i] < hi)
                pts[np++] = FILM_X[i];
        pts[np++] = hi;
        double sum = 0.0;
        for (int i = 0; i + 1 < np; i++) {
            double a = pts[i], c = pts[i + 1], m = 0.5 * (a + c), fa, fm, fc;
            ck_ok(w, ws_law_evaluate(w, id, a, 0.0, &fa, NULL, NULL));
            ck_ok(w, ws_law_evaluate(w, id, m, 0.0, &fm, NULL, NULL));
            ck_ok(w, ws_law_evaluate(w, id, c, 0.0, &fc, NULL, NULL));
            sum += (c - a) / 6.0 * (fa + 4 * fm + fc);
        }
        if (b < 0)
            sum = -sum;
        worst = fmax(worst, fabs(E - sum));
        ck_assert_msg(fabs(E - sum) <= 1e-12 * (1.0 + fabs(sum)), "energy(%g) = %.17g, %.17g", b, E,
                      sum);
    }
    report("table energy: exact integral vs Simpson on the pieces, largest difference %.2e J/m",
           worst);

    /* Bad tables are refused with the field named. */
    ws_law_def_init(&d);
    d.type = WS_LAW_TABLE;
    ws_law_id bad;
    double x[4] = {0.0, 0.1, 0.2, 0.3}, f[4] = {0.0, 5.0, 4.0, 9.0};
    d.table_strain = x;
    d.table_force = f;
    d.table_count = 4;
    ck_assert_int_eq(ws_law_create(w, &d, &bad), WS_ERR_INVALID_ARGUMENT);
    ck_assert_msg(strstr(ws_world_last_error(w), "table_force"), "%s", ws_world_last_error(w));
    report("non-monotone table refused: \"%s\"", ws_world_last_error(w));
    f[2] = 6.0;
    x[2] = 0.05; /* unsorted */
    ck_assert_int_eq(ws_law_create(w, &d, &bad), WS_ERR_INVALID_ARGUMENT);
    ck_assert_msg(strstr(ws_world_last_error(w), "table_strain"), "%s", ws_world_last_error(w));
    report("unsorted table refused: \"%s\"", ws_world_last_error(w));
    x[2] = 0.1; /* repeated */
    ck_assert_int_eq(ws_law_create(w, &d, &bad), WS_ERR_INVALID_ARGUMENT);
    x[2] = 0.2;
    ck_ok(w, ws_law_create(w, &d, &bad));
    /* A flat stretch is allowed (zero stiffness there), and stays flat. */
    double xf[4] = {0.0, 0.1, 0.2, 0.3}, ff[4] = {0.0, 5.0, 5.0, 9.0};
    d.table_strain = xf;
    d.table_force = ff;
    ws_law_id flat = create(w, &d);
    for (int j = 0; j <= 100; j++) {
        double F, dF;
        ck_ok(w, ws_law_evaluate(w, flat, 0.1 + 0.001 * j, 0.0, &F, &dF, NULL));
        /* h00 + h01 = 1 up to the rounding of four products. */
        ck_assert_msg(fabs(F - 5.0) <= 4 * 5.0 * 2.3e-16 && dF == 0.0, "%.17g %g", F, dF);
    }
    ws_world_destroy(w);
}
END_TEST

/* ---- 6. stop ---- */

START_TEST(test_stop)
{
    ws_world *w = new_world(1e-3);
    ws_law_id id = make_stop(w, 1, STOP_W, NULL);
    const double k = 3000.0, c = 20.0;
    /* In the gap: exactly nothing, whatever the rate; no damping either. */
    for (double u = STOP_LO; u <= STOP_HI; u += 0.001) {
        double F, dF, dFd;
        ck_ok(w, ws_law_evaluate(w, id, u, 3.0, &F, &dF, &dFd));
        ck_assert_msg(F == 0.0 && dF == 0.0 && dFd == 0.0, "u %g: %g %g %g", u, F, dF, dFd);
    }
    /* Beyond the ramp: the contact spring from the closed gap, k (u - gap - w), and the damper. */
    double F, dF, dFd;
    double u = STOP_HI + 0.02;
    ck_ok(w, ws_law_evaluate(w, id, u, 0.5, &F, &dF, &dFd));
    ck_assert(fabs(F - (k * (u - STOP_HI - STOP_W) + c * 0.5)) <= 1e-12 * F);
    ck_assert(dF == k && dFd == c);
    u = STOP_LO - 0.02;
    ck_ok(w, ws_law_evaluate(w, id, u, -0.5, &F, &dF, &dFd));
    ck_assert(fabs(F - (k * (u - STOP_LO + STOP_W) - c * 0.5)) <= 1e-12 * fabs(F));
    ck_assert(dF == k && dFd == c);
    /* Smooth closing: force and tangent start from zero at the gap. */
    double eps = 1e-9;
    ck_ok(w, ws_law_evaluate(w, id, STOP_HI + eps, 0.0, &F, &dF, NULL));
    ck_assert(F > 0.0 && F < k * eps && dF < k * 1e-6);
    /* Never pulling: a bumper leaving fast gives zero, not a tension. */
    ck_ok(w, ws_law_evaluate(w, id, STOP_LO - 0.001, 100.0, &F, &dF, &dFd));
    ck_assert(F == 0.0 && dF == 0.0 && dFd == 0.0);
    ck_ok(w, ws_law_evaluate(w, id, STOP_HI + 0.001, -100.0, &F, &dF, &dFd));
    ck_assert(F == 0.0 && dF == 0.0 && dFd == 0.0);
    /* The sharp stop: k (u - gap) right from the gap. */
    ws_law_id sharp = make_stop(w, 1, 0.0, NULL);
    ck_ok(w, ws_law_evaluate(w, sharp, STOP_HI + 0.001, 0.0, &F, &dF, NULL));
    ck_assert(fabs(F - k * 0.001) <= 1e-12 * F && dF == k);
    /* A one-sided slack strap (no compression side). */
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = WS_LAW_STOP;
    d.stiffness = k;
    d.stop_high = 0.01;
    d.transition = 0.0;
    ws_law_id strap = create(w, &d);
    ck_ok(w, ws_law_evaluate(w, strap, -5.0, 0.0, &F, NULL, NULL));
    ck_assert(F == 0.0);
    ck_ok(w, ws_law_evaluate(w, strap, 0.02, 0.0, &F, NULL, NULL));
    ck_assert(fabs(F - k * 0.01) < 1e-12 * F);
    ws_law_info info;
    ck_ok(w, ws_law_get_info(w, strap, &info));
    ck_assert_uint_eq(info.flags, WS_LAW_FLAG_ELASTIC);
    ck_assert_uint_eq(info.state_size, 0);
    report("stop: zero in the gap [%g, %g], k (u - gap - w) beyond the %g ramp, damped only in "
           "contact, clamped so it never pulls",
           STOP_LO, STOP_HI, 2 * STOP_W);
    ws_world_destroy(w);
}
END_TEST

/* ---- 7. history ---- */

START_TEST(test_history_pure_and_per_user)
{
    ws_world *w = new_world(1e-3);
    user_ctx uc = {800.0, 0.05, 300.0, 3.0, 0, 0, 0, NULL, 0};
    time_ctx tc = {0, NULL};
    const int n = 3;
    ws_law_id ids[3] = {make_relaxation(w, n, 1.0), make_law(w, L_SUM, n, NULL, &uc, &tc),
                        make_law(w, L_SCALED_FN, n, NULL, &uc, &tc)};
    for (int L = 0; L < 3; L++) {
        ws_law_id id = ids[L];
        size_t ns;
        ck_ok(w, ws_law_get_state_size(w, id, &ns));
        ck_assert_uint_eq(ns, 9); /* 3 components x (strain + 2 branches) */
        double a[9], b[9], a0[9], b0[9];
        ck_ok(w, ws_law_init_state(w, id, a));
        ck_ok(w, ws_law_init_state(w, id, b));
        /* Two users, two histories: a stretched and held, b untouched. */
        double ua[3] = {0.03, 0.02, -0.01}, zero[3] = {0, 0, 0};
        ck_ok(w, ws_law_commit_state(w, id, a, ua, NULL, 0.0, 0.0));
        ck_ok(w, ws_law_commit_state(w, id, a, ua, NULL, 0.1, 0.1));
        ck_ok(w, ws_law_commit_state(w, id, b, zero, NULL, 0.1, 0.1));
        memcpy(a0, a, sizeof a);
        memcpy(b0, b, sizeof b);
        /* The same strain, different forces; evaluating either twice changes nothing. */
        double u[3] = {0.01, 0.01, 0.01}, ud[3] = {0.2, -0.1, 0.0};
        double Fa1[3], Fa2[3], Fb[3], Ka1[9], Ka2[9];
        ck_ok(w, ws_law_evaluate_state(w, id, a, u, ud, 0.2, 0.1, Fa1, Ka1, NULL));
        ck_ok(w, ws_law_evaluate_state(w, id, b, u, ud, 0.2, 0.1, Fb, NULL, NULL));
        ck_ok(w, ws_law_evaluate_state(w, id, a, u, ud, 0.2, 0.1, Fa2, Ka2, NULL));
        ck_assert(memcmp(Fa1, Fa2, sizeof Fa1) == 0 && memcmp(Ka1, Ka2, sizeof Ka1) == 0);
        ck_assert(memcmp(a, a0, sizeof a) == 0 && memcmp(b, b0, sizeof b) == 0);
        ck_assert(Fa1[0] != Fb[0]);
        /* A commit changes the state, and the force at the committed strain right after it
         * (dt = 0) is the trial's, bit for bit. */
        ck_ok(w, ws_law_commit_state(w, id, a, u, ud, 0.2, 0.1));
        ck_assert(memcmp(a, a0, sizeof a) != 0);
        ck_assert(memcmp(b, b0, sizeof b) == 0);
        double Fc[3];
        ck_ok(w, ws_law_evaluate_state(w, id, a, u, ud, 0.2, 0.0, Fc, NULL, NULL));
        for (int i = 0; i < 3; i++)
            ck_assert_msg(Fc[i] == Fa1[i], "law %d: after commit %.17g, trial %.17g", L, Fc[i],
                          Fa1[i]);
        /* A NULL state is the initial one. */
        double s0[9], Fi[3], Fn[3];
        ck_ok(w, ws_law_init_state(w, id, s0));
        ck_ok(w, ws_law_evaluate_state(w, id, s0, u, ud, 0.2, 0.1, Fi, NULL, NULL));
        ck_ok(w, ws_law_evaluate_state(w, id, NULL, u, ud, 0.2, 0.1, Fn, NULL, NULL));
        ck_assert(memcmp(Fi, Fn, sizeof Fi) == 0);
        /* Commit refuses a NULL state and bad numbers, and then leaves the state alone. */
        memcpy(a0, a, sizeof a);
        ck_assert_int_eq(ws_law_commit_state(w, id, NULL, u, ud, 0.3, 0.1),
                         WS_ERR_INVALID_ARGUMENT);
        ck_assert_int_eq(ws_law_commit_state(w, id, a, u, ud, 0.3, -0.1), WS_ERR_INVALID_ARGUMENT);
        double bad[3] = {NAN, 0, 0};
        ck_assert_int_eq(ws_law_commit_state(w, id, a, bad, ud, 0.3, 0.1), WS_ERR_INVALID_ARGUMENT);
        ck_assert_int_eq(ws_law_evaluate_state(w, id, a, u, bad, 0.3, 0.1, Fc, NULL, NULL),
                         WS_ERR_INVALID_ARGUMENT);
        ck_assert_int_eq(ws_law_evaluate_state(w, id, a, NULL, ud, 0.3, 0.1, Fc, NULL, NULL),
                         WS_ERR_INVALID_ARGUMENT);
        ck_assert(memcmp(a, a0, sizeof a) == 0);
    }
    /* A law without history: size 0, NULL states are fine, commit does nothing. */
    ws_law_id plain = make_law(w, L_CUBIC, 1, NULL, &uc, &tc);
    size_t ns;
    ck_ok(w, ws_law_get_state_size(w, plain, &ns));
    ck_assert_uint_eq(ns, 0);
    double u = 0.1;
    ck_ok(w, ws_law_init_state(w, plain, NULL));
    ck_ok(w, ws_law_commit_state(w, plain, NULL, &u, NULL, 0.0, 0.1));
    ws_world_destroy(w);
}
END_TEST

/* ---- 8. sum and scaled ---- */

START_TEST(test_sum_and_scaled)
{
    ws_world *w = new_world(1e-3);
    user_ctx uc = {800.0, 0.05, 300.0, 3.0, 0, 0, 0, NULL, 0};
    const int n = 3;
    ws_law_id parts[3] = {make_law(w, L_CUBIC_MATRIX, n, NULL, &uc, NULL),
                          make_relaxation(w, n, 0.5), make_stop(w, n, STOP_W, NULL)};
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = WS_LAW_SUM;
    d.dim = n;
    d.terms = parts;
    d.term_count = 3;
    ws_law_id sum = create(w, &d);
    ws_law_info info;
    ck_ok(w, ws_law_get_info(w, sum, &info));
    ck_assert_uint_eq(info.state_size, 9);
    ck_assert_uint_eq(info.flags, WS_LAW_FLAG_ELASTIC | WS_LAW_FLAG_VISCOUS);
    /* Its history is the relaxation's, at offset 0 (the cubic has none). */
    double ss[9], sr[9];
    ck_ok(w, ws_law_init_state(w, sum, ss));
    ck_ok(w, ws_law_init_state(w, parts[1], sr));
    uint64_t seed = 5;
    double worst = 0.0;
    for (int step = 0; step < 50; step++) {
        double u[3], ud[3], Fs[3], Ks[9], Cs[9];
        for (int i = 0; i < n; i++) {
            u[i] = rnd(&seed, -0.08, 0.08);
            ud[i] = rnd(&seed, -1, 1);
        }
        ck_ok(w, ws_law_evaluate_state(w, sum, ss, u, ud, 0.0, 0.01, Fs, Ks, Cs));
        double F[3] = {0}, K[9] = {0}, C[9] = {0}, mag = 0.0;
        for (int j = 0; j < 3; j++) {
            double f[3], k[9], c[9];
            ck_ok(w, ws_law_evaluate_state(w, parts[j], j == 1 ? sr : NULL, u, ud, 0.0, 0.01, f, k,
                                           c));
            for (int i = 0; i < n; i++) {
                F[i] += f[i];
                mag += fabs(f[i]);
            }
            for (int i = 0; i < 9; i++) {
                K[i] += k[i];
                C[i] += c[i];
            }
        }
        /* The same terms added in the same order. */
        for (int i = 0; i < n; i++)
            worst = fmax(worst, fabs(Fs[i] - F[i]));
        ck_assert(memcmp(Fs, F, sizeof F) == 0);
        ck_assert(memcmp(Ks, K, sizeof K) == 0 && memcmp(Cs, C, sizeof C) == 0);
        ck_ok(w, ws_law_commit_state(w, sum, ss, u, ud, 0.0, 0.01));
        ck_ok(w, ws_law_commit_state(w, parts[1], sr, u, ud, 0.0, 0.01));
        (void)mag;
    }
    ck_assert(memcmp(ss, sr, sizeof ss) == 0);
    /* The parts are in use while the sum lives. */
    ck_ok(w, ws_law_get_info(w, parts[0], &info));
    ck_assert_uint_eq(info.users, 1);
    ck_assert_int_eq(ws_law_destroy(w, parts[0]), WS_ERR_IN_USE);
    ck_assert(strstr(ws_world_last_error(w), "use"));

    /* Scaled by a table: 2 x (1 at t <= 0, 0.25 at 1 s, 0.5 beyond 2 s), linear between. */
    time_ctx tc = {0, NULL};
    ws_law_id sc = make_law(w, L_SCALED_TABLE, n, NULL, &uc, &tc);
    ws_law_def bd;
    ws_law_def_init(&bd);
    ws_law_id base;
    {
        /* The base of L_SCALED_TABLE is the matrix Kelvin-Voigt law; make its twin. */
        double K[N6 * N6], C[N6 * N6];
        aniso_matrix(n, 2000.0, 11u + (uint64_t)n, 0, K);
        aniso_matrix(n, 5.0, 23u + (uint64_t)n, 0, C);
        bd.type = WS_LAW_LINEAR_VISCOELASTIC;
        bd.dim = n;
        bd.stiffness_matrix = K;
        bd.damping_matrix = C;
        base = create(w, &bd);
    }
    static const double ts[] = {-1.0, 0.0, 0.5, 1.0, 1.5, 2.0, 7.0};
    static const double want_s[] = {2.0, 2.0, 1.25, 0.5, 0.75, 1.0, 1.0};
    for (size_t i = 0; i < sizeof ts / sizeof ts[0]; i++) {
        double u[3] = {0.01, -0.02, 0.03}, ud[3] = {0.1, 0.2, 0.3}, Fs[3], Fb[3];
        ck_ok(w, ws_law_evaluate_state(w, sc, NULL, u, ud, ts[i], 0.0, Fs, NULL, NULL));
        ck_ok(w, ws_law_evaluate_state(w, base, NULL, u, ud, ts[i], 0.0, Fb, NULL, NULL));
        for (int j = 0; j < n; j++)
            ck_assert_msg(fabs(Fs[j] - want_s[i] * Fb[j]) <= 1e-15 * fabs(Fb[j]) * want_s[i],
                          "t %g: %g vs %g x %g", ts[i], Fs[j], want_s[i], Fb[j]);
    }
    /* Its bounds: the base's times the largest factor, 2 x 1. */
    ws_law_info bi;
    ck_ok(w, ws_law_get_info(w, sc, &info));
    ck_ok(w, ws_law_get_info(w, base, &bi));
    ck_assert(info.max_stiffness == 2.0 * bi.max_stiffness);
    ck_assert(info.max_damping == 2.0 * bi.max_damping);
    /* Scaled by a callback that gets its pointer; its failure (t < 0 here) is an error. */
    ws_law_id scf = make_law(w, L_SCALED_FN, 1, NULL, &uc, &tc);
    double F, st[3] = {0, 0, 0}, u1 = 0.01;
    ck_ok(w, ws_law_evaluate_state(w, scf, st, &u1, NULL, 0.25, 0.0, &F, NULL, NULL));
    ck_assert(tc.seen == &tc);
    /* 0.75 x the instantaneous (k_inf + sum k_i) u. */
    ck_assert(fabs(F - 0.75 * (500.0 + 800.0 + 300.0) * u1) <= 1e-13 * F);
    double t_bad = -1.0;
    ck_assert_int_eq(ws_law_evaluate_state(w, scf, st, &u1, NULL, t_bad, 0.0, &F, NULL, NULL),
                     WS_ERR_CALLBACK);
    ck_assert_int_eq(ws_law_energy_state(w, scf, st, &u1, t_bad, &F), WS_ERR_CALLBACK);
    report("sum = the sum of its terms bit for bit (largest difference %.1e N); scaled follows "
           "its table (held beyond the ends) and its callback",
           worst);
    ws_world_destroy(w);
}
END_TEST

/* ---- 9. user law ---- */

static ws_law_id sum_of(ws_world *w, int dim, const ws_law_id *terms, size_t n, ws_status *st)
{
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = WS_LAW_SUM;
    d.dim = dim;
    d.terms = terms;
    d.term_count = n;
    ws_law_id id = {0};
    *st = ws_law_create(w, &d, &id);
    return id;
}

/* Nested sums are bounded in the history they keep and in the laws one evaluation visits.
 * Unbounded, ten nested sums reported 16 doubles of history but used 2^32 + 16 (the 32-bit
 * count wrapped) and a sum of 16 copies nested 8 deep visited 16^8 leaves. */
START_TEST(test_nested_sum_bounds)
{
    ws_world *w = new_world(1e-3);
    ws_status st;
    size_t n = 0;

    /* History. A dim-6 relaxation law of 16 branches keeps 6 (16 + 1) = 102 doubles. */
    double pk[WS_LAW_MAX_PRONY], pt[WS_LAW_MAX_PRONY];
    for (int j = 0; j < WS_LAW_MAX_PRONY; j++) {
        pk[j] = 10.0 * (j + 1);
        pt[j] = 0.01 * (j + 1);
    }
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = WS_LAW_RELAXATION;
    d.dim = 6;
    d.stiffness = 100.0;
    d.prony_stiffness = pk;
    d.prony_time = pt;
    d.prony_count = WS_LAW_MAX_PRONY;
    ws_law_id relax = create(w, &d);
    ck_ok(w, ws_law_get_state_size(w, relax, &n));
    ck_assert_uint_eq(n, 102);
    ws_law_id t16[WS_LAW_MAX_TERMS];
    for (int j = 0; j < WS_LAW_MAX_TERMS; j++)
        t16[j] = relax;
    ws_law_id s1 = sum_of(w, 6, t16, 16, &st);
    ck_ok(w, st);
    ck_ok(w, ws_law_get_state_size(w, s1, &n));
    ck_assert_uint_eq(n, 1632);
    /* 2 x 1632 + 8 x 102 = 4080 <= 4096 is taken; one term more (4182) is refused. */
    ws_law_id mix[11] = {s1, s1, relax, relax, relax, relax, relax, relax, relax, relax, relax};
    ws_law_id full = sum_of(w, 6, mix, 10, &st);
    ck_ok(w, st);
    ck_ok(w, ws_law_get_state_size(w, full, &n));
    ck_assert_uint_eq(n, 4080);
    sum_of(w, 6, mix, 11, &st);
    ck_assert_int_eq(st, WS_ERR_INVALID_ARGUMENT);
    ck_assert_ptr_nonnull(strstr(ws_world_last_error(w), "4182 doubles"));
    ck_assert_ptr_nonnull(strstr(ws_world_last_error(w), "WS_LAW_MAX_HISTORY (4096)"));
    for (int j = 0; j < WS_LAW_MAX_TERMS; j++)
        t16[j] = s1;
    sum_of(w, 6, t16, 16, &st); /* 26112 doubles */
    ck_assert_int_eq(st, WS_ERR_INVALID_ARGUMENT);
    ck_assert_ptr_nonnull(strstr(ws_world_last_error(w), "WS_LAW_MAX_HISTORY"));

    /* The largest law keeps exactly what it reports: evaluated and committed from a buffer of
     * that size with a guard after it, the guard stays intact and the force is the elastic
     * sum, (2 x 16 + 8)(100 + sum of the branches) u at dt = 0 (no relaxation yet). */
    double *state = malloc((n + 8) * sizeof *state);
    ck_assert_ptr_nonnull(state);
    for (size_t i = n; i < n + 8; i++)
        state[i] = 12345.0;
    ck_ok(w, ws_law_init_state(w, full, state));
    double u[6] = {1e-3, -2e-3, 0, 0, 0, 4e-3}, F[6];
    ck_ok(w, ws_law_commit_state(w, full, state, u, NULL, 0.01, 0.01));
    ck_ok(w, ws_law_evaluate_state(w, full, NULL, u, NULL, 0.0, 0.0, F, NULL, NULL));
    for (size_t i = n; i < n + 8; i++)
        ck_assert(state[i] == 12345.0);
    double k_one = 100.0;
    for (int j = 0; j < WS_LAW_MAX_PRONY; j++)
        k_one += pk[j];
    /* Forty relaxation laws each give k_one u; a sum of 40 terms rounds within 40 ulp. */
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(F[i], 40.0 * k_one * u[i], 1e-12 * 40.0 * k_one);
    free(state);

    /* Leaves. 16 copies of a spring, summed 16 times over: 256 leaves, the bound, is taken and
     * gives 256 k; one level more (4096) is refused. */
    ws_law_def_init(&d);
    d.stiffness = 3.0;
    ws_law_id lin = create(w, &d);
    for (int j = 0; j < WS_LAW_MAX_TERMS; j++)
        t16[j] = lin;
    ws_law_id l1 = sum_of(w, 1, t16, 16, &st);
    ck_ok(w, st);
    for (int j = 0; j < WS_LAW_MAX_TERMS; j++)
        t16[j] = l1;
    ws_law_id l2 = sum_of(w, 1, t16, 16, &st);
    ck_ok(w, st);
    double f, k;
    ck_ok(w, ws_law_evaluate(w, l2, 0.5, 0.0, &f, &k, NULL));
    ck_assert(k == 256.0 * 3.0 && f == 256.0 * 3.0 * 0.5); /* exact: small integers and halves */
    for (int j = 0; j < WS_LAW_MAX_TERMS; j++)
        t16[j] = l2;
    sum_of(w, 1, t16, 16, &st);
    ck_assert_int_eq(st, WS_ERR_INVALID_ARGUMENT);
    ck_assert_ptr_nonnull(strstr(ws_world_last_error(w), "4096 leaf laws"));
    ck_assert_ptr_nonnull(strstr(ws_world_last_error(w), "WS_LAW_MAX_LEAVES (256)"));
    /* A scaling adds no leaves: a scaled l2 is taken, a sum of it and the spring is not. */
    ws_law_def_init(&d);
    d.type = WS_LAW_SCALED;
    d.base = l2;
    d.scale = 2.0;
    ws_law_id sc = create(w, &d);
    ws_law_id two[2] = {sc, lin};
    sum_of(w, 1, two, 2, &st);
    ck_assert_int_eq(st, WS_ERR_INVALID_ARGUMENT);
    ck_assert_ptr_nonnull(strstr(ws_world_last_error(w), "257 leaf laws"));
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_user_law)
{
    ws_world *w = new_world(1e-3);
    user_ctx uc = {800.0, 0.05, 300.0, 3.0, 0, 0, 0, NULL, 0};
    ws_law_id id = make_law(w, L_USER, 6, NULL, &uc, NULL);
    double u[6] = {0.01, 0.02, 0.03, -0.01, -0.02, 0.0}, ud[6] = {1, 0, 0, 0, 0, 0}, F[6];
    ck_ok(w, ws_law_evaluate_state(w, id, NULL, u, ud, 0.0, 0.0, F, NULL, NULL));
    ck_assert(uc.seen == &uc && uc.seen_dim == 6 && uc.calls == 1);
    ck_assert(fabs(F[0] - (800.0 * 0.05 * tanh(0.2) + 300.0 * 0.02 * 0.02 + 3.0 * 1.0001)) < 1e-12);
    ws_law_info info;
    ck_ok(w, ws_law_get_info(w, id, &info));
    ck_assert_uint_eq(info.flags, WS_LAW_FLAG_ELASTIC | WS_LAW_FLAG_VISCOUS);
    ck_assert(info.max_stiffness == 800.0 + 600.0);
    uc.fail = 1;
    ck_assert_int_eq(ws_law_evaluate_state(w, id, NULL, u, ud, 0.0, 0.0, F, NULL, NULL),
                     WS_ERR_CALLBACK);
    ck_assert(strstr(ws_world_last_error(w), "callback"));
    uc.fail = 0;
    uc.nan = 1;
    ck_assert_int_eq(ws_law_evaluate_state(w, id, NULL, u, ud, 0.0, 0.0, F, NULL, NULL),
                     WS_ERR_NUMERICAL);
    uc.nan = 0;
    /* Its energy is not known. */
    double e;
    ck_assert_int_eq(ws_law_energy_state(w, id, NULL, u, 0.0, &e), WS_ERR_UNSUPPORTED);
    /* A 1D user law through the 1D call. */
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = WS_LAW_USER;
    d.user_fn = user_law;
    d.user_data = &uc;
    d.user_flags = WS_LAW_FLAG_ELASTIC;
    ws_law_id one = create(w, &d);
    double f, df;
    ck_ok(w, ws_law_evaluate(w, one, 0.02, 0.0, &f, &df, NULL));
    ck_assert(uc.seen_dim == 1);
    ck_ok(w, ws_law_get_info(w, one, &info));
    ck_assert_uint_eq(info.flags, WS_LAW_FLAG_ELASTIC);
    ws_world_destroy(w);
}
END_TEST

/* ---- 10. energies ---- */

START_TEST(test_energy_1d)
{
    ws_world *w = new_world(1e-3);
    user_ctx uc = {800.0, 0.05, 300.0, 3.0, 0, 0, 0, NULL, 0};
    time_ctx tc = {0, NULL};
    static const int which[] = {L_ELASTIC, L_KELVIN_VOIGT, L_FILM,       L_CUBIC,
                                L_TABLE,   L_STOP,         L_STOP_SHARP, L_RELAXATION,
                                L_SUM,     L_SCALED_TABLE, L_VISCOUS};
    double worst = 0.0;
    for (size_t L = 0; L < sizeof which / sizeof which[0]; L++) {
        kinks kk = {{0}, 0};
        ws_law_id id = make_law(w, which[L], 1, &kk, &uc, &tc);
        double e0;
        ck_ok(w, ws_law_energy(w, id, 0.0, &e0));
        ck_assert_msg(fabs(e0) <= 1e-12, "%s: energy at 0 = %g", LAW_LABEL[which[L]], e0);
        for (double b = -0.09; b <= 0.1; b += 0.0237) {
            /* Simpson's rule on the pieces between the law's joins: every piece of every law
             * here is a polynomial of degree <= 3 in u (linear, the quadratic ramps, the cubic,
             * the Hermite cubics), for which Simpson is exact; the sum is exact to round-off,
             * a few eps of the energy. */
            double pts[40], lo = fmin(0.0, b), hi = fmax(0.0, b);
            int np = 0;
            pts[np++] = lo;
            for (int i = 0; i < kk.n; i++)
                if (kk.at[i] > lo && kk.at[i] < hi)
                    pts[np++] = kk.at[i];
            pts[np++] = hi;
            for (int i = 1; i < np; i++) /* insertion sort */
                for (int j = i; j > 0 && pts[j] < pts[j - 1]; j--) {
                    double t = pts[j];
                    pts[j] = pts[j - 1];
                    pts[j - 1] = t;
                }
            double E, sum = 0.0;
            ck_ok(w, ws_law_energy(w, id, b, &E));
            for (int i = 0; i + 1 < np; i++) {
                double a = pts[i], c = pts[i + 1], m = 0.5 * (a + c), fa, fm, fc;
                ck_ok(w, ws_law_evaluate(w, id, a, 0.0, &fa, NULL, NULL));
                ck_ok(w, ws_law_evaluate(w, id, m, 0.0, &fm, NULL, NULL));
                ck_ok(w, ws_law_evaluate(w, id, c, 0.0, &fc, NULL, NULL));
                sum += (c - a) / 6.0 * (fa + 4.0 * fm + fc);
            }
            if (b < 0.0)
                sum = -sum;
            worst = fmax(worst, fabs(E - sum) / (1.0 + fabs(sum)));
            ck_assert_msg(fabs(E - sum) <= 1e-12 * (1.0 + fabs(sum)),
                          "%s: energy(%g) = %.15g J/m, Simpson %.15g", LAW_LABEL[which[L]], b, E,
                          sum);
        }
    }
    report("1D energies (elastic, KV, film, cubic, table, stops, relaxation, sum, scaled): "
           "largest |energy - integral of F| / (1 + |energy|) = %.2e",
           worst);
    /* A 3D cubic: 1/2 k |u|^2 + k3/4 sum u_i^4. */
    ws_law_id c3 = make_law(w, L_CUBIC, 3, NULL, &uc, &tc);
    double u[3] = {0.01, -0.02, 0.03}, e;
    ck_ok(w, ws_law_energy_state(w, c3, NULL, u, 0.0, &e));
    double want = 0.5 * 500.0 * (1e-4 + 4e-4 + 9e-4) + 0.25 * 4e5 * (1e-8 + 16e-8 + 81e-8);
    ck_assert(fabs(e - want) <= 1e-14 * want);
    ws_world_destroy(w);
}
END_TEST

/* ---- 11. contracts ---- */

typedef struct bad_case {
    const char *what; /* the field the message must name */
    ws_law_def d;
} bad_case;

START_TEST(test_bad_defs)
{
    ws_world *w = new_world(1e-3);
    ws_law_id good = make_law(w, L_ELASTIC, 1, NULL, NULL, NULL);
    ws_law_id good3 = make_law(w, L_ELASTIC, 3, NULL, NULL, NULL);
    double negK[9] = {1, 0, 0, 0, -1, 0, 0, 0, 1}, nanK[9] = {1, 0, 0, 0, NAN, 0, 0, 0, 1};
    double zero9[9] = {0};
    double x2[2] = {0.0, 0.1}, f2[2] = {0.0, 1.0}, tk = 1.0, tneg = -1.0;
    double ts[2] = {1.0, 0.5}, sf[2] = {1.0, 1.0}, k3neg[3] = {1, -1, 1};
    bad_case cases[40];
    int nc = 0;
#define CASE(field, ...)                                                                           \
    do {                                                                                           \
        bad_case *c_ = &cases[nc++];                                                               \
        c_->what = field;                                                                          \
        ws_law_def_init(&c_->d);                                                                   \
        ws_law_def *d = &c_->d;                                                                    \
        __VA_ARGS__;                                                                               \
    } while (0)
    CASE("type", d->type = (ws_law_type)99; d->stiffness = 1);
    CASE("dim", d->dim = 2; d->stiffness = 1);
    CASE("dim", d->dim = 0; d->stiffness = 1);
    CASE("stiffness", d->stiffness = -1);
    CASE("stiffness", d->stiffness = NAN);
    CASE("stiffness", d->stiffness = 0);
    CASE("damping", d->type = WS_LAW_LINEAR_VISCOELASTIC; d->stiffness = 1; d->damping = NAN);
    CASE("damping", d->type = WS_LAW_LINEAR_VISCOUS; d->damping = 0);
    CASE("stiffness_matrix", d->dim = 3; d->stiffness_matrix = negK);
    CASE("stiffness_matrix", d->dim = 3; d->stiffness_matrix = nanK);
    CASE("stiffness_matrix", d->dim = 3; d->stiffness_matrix = zero9);
    CASE("damping_matrix", d->dim = 3; d->stiffness = 1; d->damping_matrix = zero9);
    CASE("damping_matrix", d->type = WS_LAW_LINEAR_VISCOELASTIC; d->dim = 3; d->stiffness = 1;
         d->damping_matrix = negK);
    CASE("stiffness_matrix", d->type = WS_LAW_STOP; d->dim = 3; d->stiffness = 1; d->stop_high = 0;
         d->stiffness_matrix = zero9);
    CASE("compression_stiffness", d->type = WS_LAW_TENSION_COMPRESSION; d->stiffness = 1;
         d->compression_stiffness = -1);
    CASE("transition", d->type = WS_LAW_TENSION_COMPRESSION; d->stiffness = 1; d->transition = 0);
    CASE("cubic_stiffness", d->type = WS_LAW_CUBIC_ELASTIC; d->stiffness = 1;
         d->cubic_stiffness = -1);
    CASE("cubic_stiffnesses", d->type = WS_LAW_CUBIC_ELASTIC; d->dim = 3; d->stiffness = 1;
         d->cubic_stiffnesses = k3neg);
    CASE("cubic_stiffness", d->type = WS_LAW_CUBIC_ELASTIC);
    CASE("table_strain", d->type = WS_LAW_TABLE; d->table_force = f2; d->table_count = 2);
    CASE("table_force", d->type = WS_LAW_TABLE; d->table_strain = x2; d->table_count = 2);
    CASE("table_count", d->type = WS_LAW_TABLE; d->table_strain = x2; d->table_force = f2;
         d->table_count = 1);
    CASE("stop_low", d->type = WS_LAW_STOP; d->stiffness = 1; d->stop_low = 0.1;
         d->stop_high = 0.0);
    CASE("stop_low or stop_high", d->type = WS_LAW_STOP; d->stiffness = 1);
    CASE("transition", d->type = WS_LAW_STOP; d->stiffness = 1; d->stop_high = 0;
         d->transition = -1);
    CASE("prony_stiffness", d->type = WS_LAW_RELAXATION; d->prony_time = &tk; d->prony_count = 1);
    CASE("prony_count", d->type = WS_LAW_RELAXATION; d->prony_time = &tk; d->prony_stiffness = &tk;
         d->prony_count = 0);
    CASE("prony_time", d->type = WS_LAW_RELAXATION; d->prony_time = &tneg; d->prony_stiffness = &tk;
         d->prony_count = 1);
    CASE("terms", d->type = WS_LAW_SUM);
    CASE("term_count", d->type = WS_LAW_SUM; d->terms = &good; d->term_count = 0);
    CASE("dim", d->type = WS_LAW_SUM; d->terms = &good3; d->term_count = 1);
    CASE("base", d->type = WS_LAW_SCALED);
    CASE("dim", d->type = WS_LAW_SCALED; d->base = good; d->dim = 3);
    CASE("scale", d->type = WS_LAW_SCALED; d->base = good; d->scale = -1);
    CASE("scale_times", d->type = WS_LAW_SCALED; d->base = good; d->scale_times = ts;
         d->scale_factors = sf; d->scale_count = 2);
    CASE("scale_factors", d->type = WS_LAW_SCALED; d->base = good; d->scale_times = x2;
         d->scale_count = 2);
    CASE("user_fn", d->type = WS_LAW_USER);
    CASE("user_flags", d->type = WS_LAW_USER; d->user_fn = user_law; d->user_flags = 0);
    CASE("user_flags", d->type = WS_LAW_USER; d->user_fn = user_law; d->user_flags = 4);
#undef CASE
    ck_assert_int_le(nc, 40);
    for (int i = 0; i < nc; i++) {
        ws_law_id id = {12345};
        ws_status s = ws_law_create(w, &cases[i].d, &id);
        ck_assert_msg(s == WS_ERR_INVALID_ARGUMENT, "case %d (%s): %s (%s)", i, cases[i].what,
                      ws_status_string(s), ws_world_last_error(w));
        ck_assert_msg(strstr(ws_world_last_error(w), cases[i].what),
                      "case %d: the message \"%s\" does not name %s", i, ws_world_last_error(w),
                      cases[i].what);
        ck_assert(id.bits == 0);
    }
    report("bad law Defs: %d refused with the field named, e.g. \"%s\"", nc,
           ws_world_last_error(w));
    /* An uninitialised Def, a NULL Def, a NULL out. */
    ws_law_def d;
    memset(&d, 0, sizeof d);
    ws_law_id id;
    ck_assert_int_eq(ws_law_create(w, &d, &id), WS_ERR_UNINITIALIZED_DEF);
    ck_assert_int_eq(ws_law_create(w, NULL, &id), WS_ERR_INVALID_ARGUMENT);
    ws_law_def_init(&d);
    d.stiffness = 1;
    ck_assert_int_eq(ws_law_create(w, &d, NULL), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_law_create(NULL, &d, &id), WS_ERR_INVALID_ARGUMENT);
    /* Stale terms and bases. */
    ws_law_id dead = create(w, &d);
    ck_ok(w, ws_law_destroy(w, dead));
    ws_law_def_init(&d);
    d.type = WS_LAW_SUM;
    ws_law_id two[2] = {good, dead};
    d.terms = two;
    d.term_count = 2;
    ck_assert_int_eq(ws_law_create(w, &d, &id), WS_ERR_STALE_HANDLE);
    ck_assert(strstr(ws_world_last_error(w), "terms[1]"));
    ws_law_def_init(&d);
    d.type = WS_LAW_SCALED;
    d.base = dead;
    ck_assert_int_eq(ws_law_create(w, &d, &id), WS_ERR_STALE_HANDLE);
    /* Every call refuses a stale id. */
    double u = 0.0, st = 0.0, e;
    size_t ns;
    ws_law_info info;
    ck_assert_int_eq(ws_law_evaluate(w, dead, 0, 0, NULL, NULL, NULL), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_law_energy(w, dead, 0, &e), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_law_get_info(w, dead, &info), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_law_get_state_size(w, dead, &ns), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_law_init_state(w, dead, &st), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_law_evaluate_state(w, dead, NULL, &u, NULL, 0, 0, NULL, NULL, NULL),
                     WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_law_commit_state(w, dead, &st, &u, NULL, 0, 0), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_law_energy_state(w, dead, NULL, &u, 0, &e), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_law_destroy(w, dead), WS_ERR_STALE_HANDLE);
    /* The 1D calls refuse a 3D law. */
    ck_assert_int_eq(ws_law_evaluate(w, good3, 0, 0, NULL, NULL, NULL), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_law_energy(w, good3, 0, &e), WS_ERR_INVALID_ARGUMENT);
    ck_assert(strstr(ws_world_last_error(w), "dim 3"));
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_in_use_and_old_def)
{
    ws_world *w = new_world(1e-3);
    ws_law_id a = make_law(w, L_CUBIC, 1, NULL, NULL, NULL);
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = WS_LAW_SUM;
    ws_law_id t2[2] = {a, a};
    d.terms = t2;
    d.term_count = 2;
    ws_law_id s = create(w, &d);
    ws_law_def_init(&d);
    d.type = WS_LAW_SCALED;
    d.base = s;
    ws_law_id sc = create(w, &d);
    ws_law_info info;
    ck_ok(w, ws_law_get_info(w, a, &info));
    ck_assert_uint_eq(info.users, 2); /* named twice by the sum */
    ck_assert_int_eq(ws_law_destroy(w, a), WS_ERR_IN_USE);
    ck_assert_int_eq(ws_law_destroy(w, s), WS_ERR_IN_USE);
    ck_ok(w, ws_law_destroy(w, sc));
    ck_ok(w, ws_law_destroy(w, s));
    ck_ok(w, ws_law_get_info(w, a, &info));
    ck_assert_uint_eq(info.users, 0);
    ck_ok(w, ws_law_destroy(w, a));
    /* A Def of an older, smaller layout (ending at `name`) still works: dim 1, defaults. */
    ws_law_def_init(&d);
    d.type = WS_LAW_LINEAR_VISCOELASTIC;
    d.stiffness = 10.0;
    d.damping = 1.0;
    d.dim = 77; /* beyond the old size: must not be read */
    d.size = (uint32_t)(offsetof(ws_law_def, name) + sizeof d.name);
    ws_law_id old = create(w, &d);
    ck_ok(w, ws_law_get_info(w, old, &info));
    ck_assert_int_eq(info.dim, 1);
    /* Any size from the header up reads only that much; one below the header is refused. */
    d.size = (uint32_t)offsetof(ws_law_def, name);
    ws_law_id older = create(w, &d);
    ck_ok(w, ws_law_get_info(w, older, &info));
    ck_assert_int_eq(info.dim, 1);
    d.size = 4;
    ck_assert_int_eq(ws_law_create(w, &d, &old), WS_ERR_UNINITIALIZED_DEF);
    /* Laws referring to laws that go away with the world: destroy frees them in any order. */
    ws_law_id b = make_law(w, L_SUM, 3, NULL, NULL, NULL);
    (void)b;
    ws_world_destroy(w);
}
END_TEST

static ws_world *counted_world(test_alloc *a)
{
    ws_world_def d;
    ws_world_def_init(&d);
    test_alloc_install(&d, a);
    ws_world *w = NULL;
    a->allocs_left = -1;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    return w;
}

START_TEST(test_oom_and_bytes)
{
    user_ctx uc = {800.0, 0.05, 300.0, 3.0, 0, 0, 0, NULL, 0};
    time_ctx tc = {0, NULL};
    for (int which = 0; which < L_COUNT; which++) {
        /* A world with a warm law table and the parts the law needs; then the law itself with
         * the n-th allocation failing, until it succeeds. */
        int done = 0;
        for (long n = 0; n < 200 && !done; n++) {
            test_alloc a = {.allocs_left = -1};
            ws_world *w = counted_world(&a);
            ws_law_id warm = make_law(w, L_ELASTIC, 1, NULL, NULL, NULL);
            ck_ok(w, ws_law_destroy(w, warm));
            int kinds[3];
            ws_law_id parts[3] = {{0}, {0}, {0}}, id = {0};
            int np = law_parts(which, kinds);
            for (int i = 0; i < np; i++)
                parts[i] = make_law(w, kinds[i], 6, NULL, &uc, &tc);
            ws_world_stats st0, st1;
            ck_ok(w, ws_world_get_stats(w, &st0));
            a.allocs_left = n;
            ws_status s = law_create(w, which, 6, parts, NULL, &uc, &tc, &id);
            a.allocs_left = -1;
            if (s == WS_OK) {
                done = 1;
                ck_ok(w, ws_law_destroy(w, id));
            } else {
                ck_assert_msg(s == WS_ERR_OUT_OF_MEMORY, "%s, N = %ld: %s (%s)", LAW_LABEL[which],
                              n, ws_status_string(s), ws_world_last_error(w));
                ck_assert(id.bits == 0);
            }
            /* Either way: the parts are free again, and the bytes are back where they were. */
            for (int i = 0; i < np; i++) {
                ws_law_info info;
                ck_ok(w, ws_law_get_info(w, parts[i], &info));
                ck_assert_uint_eq(info.users, 0);
            }
            ck_ok(w, ws_world_get_stats(w, &st1));
            ck_assert_msg(st1.bytes_in_use == st0.bytes_in_use, "%s, N = %ld: %llu bytes, was %llu",
                          LAW_LABEL[which], n, (unsigned long long)st1.bytes_in_use,
                          (unsigned long long)st0.bytes_in_use);
            if (s != WS_OK) {
                /* The world still makes that law. */
                ws_law_id again = make_law(w, which, 3, NULL, &uc, &tc);
                ck_assert(ws_law_is_valid(w, again));
            }
            ws_world_destroy(w);
            ck_assert_msg(a.live == 0 && a.bytes == 0, "%s, N = %ld: %ld blocks, %lld bytes left",
                          LAW_LABEL[which], n, a.live, a.bytes);
        }
        ck_assert_msg(done, "%s never succeeded", LAW_LABEL[which]);
    }
    /* Every law of every dim made and destroyed, twice: the second round ends where the
     * first did (the pool arrays keep their capacity), and the world's destroy returns every
     * byte. */
    test_alloc a = {.allocs_left = -1};
    ws_world *w = counted_world(&a);
    uint64_t after[2] = {0, 0}, peak = 0;
    int nm = 0;
    for (int round = 0; round < 2; round++) {
        ws_law_id made[L_COUNT * 3 * 4];
        ck_assert_int_le(L_COUNT * 3 + 3 * 5 * 3, L_COUNT * 3 * 4);
        nm = 0;
        ws_world_stats st;
        ck_ok(w, ws_world_get_stats(w, &st));
        uint64_t start = st.bytes_in_use;
        for (int which = 0; which < L_COUNT; which++)
            for (int dim = 1; dim <= 6; dim += (dim == 1 ? 2 : 3)) {
                int kinds[3];
                ws_law_id parts[3] = {{0}, {0}, {0}};
                int np = law_parts(which, kinds);
                for (int i = 0; i < np; i++)
                    made[nm++] = parts[i] = make_law(w, kinds[i], dim, NULL, &uc, &tc);
                ck_ok(w, law_create(w, which, dim, parts, NULL, &uc, &tc, &made[nm++]));
            }
        ck_ok(w, ws_world_get_stats(w, &st));
        peak = st.bytes_in_use - start;
        /* Destroy until nothing is left: laws in use refuse and wait for the next pass. */
        int left = 1;
        for (int pass = 0; pass < 8 && left; pass++) {
            left = 0;
            for (int i = 0; i < nm; i++)
                if (ws_law_is_valid(w, made[i])) {
                    ws_status s = ws_law_destroy(w, made[i]);
                    ck_assert(s == WS_OK || s == WS_ERR_IN_USE);
                    left |= s != WS_OK;
                }
        }
        ck_assert(!left);
        ck_ok(w, ws_world_get_stats(w, &st));
        after[round] = st.bytes_in_use;
    }
    report("laws: %d made (every type, dims 1/3/6, with their parts) took %llu bytes; after "
           "destroying them %llu bytes in use, after a second round %llu",
           nm, (unsigned long long)peak, (unsigned long long)after[0],
           (unsigned long long)after[1]);
    ck_assert(after[1] == after[0]);
    ws_world_destroy(w);
    ck_assert(a.live == 0 && a.bytes == 0);
}
END_TEST

/* The internal interface the web and the elements use. */
START_TEST(test_internal_interface)
{
    ws_mem mem;
    ws_mem_init(&mem, NULL);
    char why[256];
    ws_law_def d;
    ws_law *L = NULL;
    double kc, dk, tw, c;

    /* Film form: the four 1D stateless laws of that shape, with their numbers. */
    struct {
        ws_law_type type;
        double k, kc, c, want_kc, want_dk, want_c;
    } film[] = {
        {WS_LAW_LINEAR_ELASTIC, 100, 0, 3, 100, 0, 0},
        {WS_LAW_LINEAR_VISCOELASTIC, 100, 0, 3, 100, 0, 3},
        {WS_LAW_LINEAR_VISCOUS, 100, 0, 3, 0, 0, 3},
        {WS_LAW_TENSION_COMPRESSION, 100, 2, 3, 2, 98, 3},
    };
    for (size_t i = 0; i < sizeof film / sizeof film[0]; i++) {
        ws_law_def_init(&d);
        d.type = film[i].type;
        d.stiffness = film[i].k;
        d.compression_stiffness = film[i].kc;
        d.damping = film[i].c;
        ck_assert_int_eq(ws_law_new(&mem, &d, NULL, 0, &L, why, sizeof why), WS_OK);
        ck_assert_int_eq(ws_law_film_form(L, &kc, &dk, &tw, &c), 1);
        ck_assert(kc == film[i].want_kc && dk == film[i].want_dk && c == film[i].want_c);
        ck_assert(tw > 0.0);
        /* The film form is the law: F = kc eps + dk g(eps) + c eps_dot, as ws_law_eval says. */
        for (double e = -0.01; e <= 0.01; e += 0.0007) {
            double gp, G, g = ws_law_film_ramp(e, tw, &gp);
            ck_assert_int_eq(ws_law_eval(L, NULL, &e, &(double){0.3}, 0, 0, &G, NULL, NULL), 0);
            ck_assert(fabs(kc * e + dk * g + c * 0.3 - G) <= 1e-15 * fmax(1, fabs(G)));
        }
        ck_assert(L->flags != 0 && L->nstate == 0 && L->dim == 1);
        ws_law_free(&mem, L, 1);
    }
    /* Not film form: 3D, history, nonlinear. */
    ws_law_def_init(&d);
    d.dim = 3;
    d.stiffness = 5;
    ck_assert_int_eq(ws_law_new(&mem, &d, NULL, 0, &L, why, sizeof why), WS_OK);
    ck_assert_int_eq(ws_law_film_form(L, &kc, &dk, &tw, &c), 0);
    ck_assert_uint_eq(L->flags, WS_LAWF_ELASTIC);
    /* Derivative outputs may be NULL; F may be NULL. */
    double u[3] = {1, 2, 3}, F[3];
    ck_assert_int_eq(ws_law_eval(L, NULL, u, NULL, 0, 0, F, NULL, NULL), 0);
    ck_assert(F[2] == 15.0);
    ck_assert_int_eq(ws_law_eval(L, NULL, u, NULL, 0, 0, NULL, NULL, NULL), 0);
    ws_law_free(&mem, L, 1);
    ws_law_def_init(&d);
    d.type = WS_LAW_TABLE;
    d.table_strain = FILM_X;
    d.table_force = FILM_F;
    d.table_count = FILM_N;
    ck_assert_int_eq(ws_law_new(&mem, &d, NULL, 0, &L, why, sizeof why), WS_OK);
    ck_assert_int_eq(ws_law_film_form(L, &kc, &dk, &tw, &c), 0);
    ws_law_free(&mem, L, 1);
    ck_assert_uint_eq(mem.in_use, 0);
    report("internal interface: film form recognised for the 4 stateless 1D linear/film laws, "
           "and it gives ws_law_eval's force");
}
END_TEST

int main(void)
{
    Suite *s = suite_create("law");
    /* Timeouts: a few times the run time under valgrind; each case takes well under a second
     * natively. */
    add_case(s, "fd_derivatives", test_fd_derivatives, 120);
    add_case(s, "matrix_law", test_matrix_law, 30);
    add_case(s, "kelvin_voigt_creep", test_kelvin_voigt_creep, 30);
    add_case(s, "relaxation_step", test_relaxation_step, 60);
    add_case(s, "relaxation_ramp", test_relaxation_ramp, 30);
    add_case(s, "table", test_table, 60);
    add_case(s, "stop", test_stop, 30);
    add_case(s, "history_pure_and_per_user", test_history_pure_and_per_user, 30);
    add_case(s, "sum_and_scaled", test_sum_and_scaled, 30);
    add_case(s, "nested_sum_bounds", test_nested_sum_bounds, 30);
    add_case(s, "user_law", test_user_law, 30);
    add_case(s, "energy_1d", test_energy_1d, 120);
    add_case(s, "bad_defs", test_bad_defs, 30);
    add_case(s, "in_use_and_old_def", test_in_use_and_old_def, 30);
    add_case(s, "oom_and_bytes", test_oom_and_bytes, 120);
    add_case(s, "internal_interface", test_internal_interface, 30);
    return run_suite(s);
}
