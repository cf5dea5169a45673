/* Validation of the rigid-body dynamics without contact: known analytical answers.
 *
 *  - free fall: the discrete solutions of both integrators in closed form, and the continuous one;
 *  - torque-free asymmetric body (Euler's equations, eq. 10 with M' = 0): the stable major and
 *    minor axes, the unstable intermediate axis, conservation of angular momentum and energy;
 *  - invariants of the Euler parameters and the kinematic relations eq. 2, 3, 6.
 *
 * Every tolerance is derived in the comment above the assertion. Measured values are printed
 * with a "[measured]" prefix so that the validation report can quote them. */
#include "helpers.h"

#include <stdarg.h>
#include <stdio.h>


static ws_world *world_with(double dt, ws_integrator integ, double g)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = dt;
    d.integrator = integ;
    d.gravity = (ws_vec3){0, 0, -g};
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    return w;
}

static ws_body_id add_body(ws_world *w, double lx, double ly, double lz, double m, ws_vec3 r,
                           ws_quat q, ws_vec3 v, ws_vec3 omega_global)
{
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, lx, ly, lz, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = s;
    bd.mass = m;
    bd.position = r;
    bd.orientation = q;
    bd.velocity = v;
    bd.angular_velocity = omega_global;
    bd.name = "body";
    ws_body_id id;
    ck_ok(w, ws_body_create(w, &bd, &id));
    return id;
}

static const ws_quat Q_ID = {1, 0, 0, 0};

/* ck_ok for loops: Check's assertions record their location through a system call each time they
 * pass, which costs more than a step; this one touches Check only when the call fails. */
#define OK(w, call)                                                                               \
    do {                                                                                          \
        ws_status s_ = (call);                                                                    \
        if (s_ != WS_OK)                                                                          \
            ck_abort_msg("%s -> %s (%s)", #call, ws_status_string(s_), ws_world_last_error(w));   \
    } while (0)

/* ---- small linear algebra on the public types (independent of lib/math) ---- */

static ws_vec3 mv(const ws_mat3 *a, ws_vec3 v)
{
    const double *m = a->m;
    return (ws_vec3){m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
                     m[6] * v.x + m[7] * v.y + m[8] * v.z};
}
static ws_vec3 cross(ws_vec3 a, ws_vec3 b)
{
    return (ws_vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static double dot(ws_vec3 a, ws_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static double norm(ws_vec3 a) { return sqrt(dot(a, a)); }
static ws_vec3 sub(ws_vec3 a, ws_vec3 b) { return (ws_vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static ws_vec3 add(ws_vec3 a, ws_vec3 b) { return (ws_vec3){a.x + b.x, a.y + b.y, a.z + b.z}; }

/* Rotation matrix of a unit quaternion by Rodrigues' formula from its axis and angle:
 * A = cos(phi) I + sin(phi) u~ + (1 - cos(phi)) u u^T. Written independently of eq. 6 so that
 * the library's matrix is checked against a second derivation. */
static ws_mat3 rodrigues_from_quat(ws_quat q)
{
    double s = sqrt(q.e1 * q.e1 + q.e2 * q.e2 + q.e3 * q.e3);
    double phi = 2.0 * atan2(s, q.e0);
    ws_vec3 u = s > 0 ? (ws_vec3){q.e1 / s, q.e2 / s, q.e3 / s} : (ws_vec3){1, 0, 0};
    double c = cos(phi), sn = sin(phi), k = 1.0 - c;
    ws_mat3 a = {{c + k * u.x * u.x, k * u.x * u.y - sn * u.z, k * u.x * u.z + sn * u.y,
                  k * u.y * u.x + sn * u.z, c + k * u.y * u.y, k * u.y * u.z - sn * u.x,
                  k * u.z * u.x - sn * u.y, k * u.z * u.y + sn * u.x, c + k * u.z * u.z}};
    return a;
}

/* Global angular momentum H = A J omega' (kg m^2/s) and kinetic energy of rotation
 * T = omega' . J omega' / 2 (J), from the public getters only. */
static ws_vec3 momentum(ws_world *w, ws_body_id b)
{
    ws_mat3 A, J;
    ws_vec3 wl;
    OK(w, ws_body_get_rotation(w, b, &A));
    OK(w, ws_body_get_inertia(w, b, &J));
    OK(w, ws_body_get_angular_velocity_local(w, b, &wl));
    return mv(&A, mv(&J, wl));
}
static double rot_energy(ws_world *w, ws_body_id b)
{
    ws_mat3 J;
    ws_vec3 wl;
    OK(w, ws_body_get_inertia(w, b, &J));
    OK(w, ws_body_get_angular_velocity_local(w, b, &wl));
    return 0.5 * dot(wl, mv(&J, wl));
}

/* ======================================================================================== */
/* Free fall                                                                                 */
/* ======================================================================================== */

/* Symplectic Euler under constant g: v_k = v0 - g k dt, z_k = z_{k-1} + v_k dt, so
 *   z_n = z0 + v0 n dt - g dt^2 (1 + 2 + ... + n) = z0 + v0 n dt - g dt^2 n (n + 1) / 2.
 * Tolerance: n additions of numbers of size |z| <= 10 m each round by <= eps |z|, so the sum is
 * off by at most n eps |z| ~ 2000 * 1.1e-16 * 10 = 2e-12 m; the assertion allows 1e-12 of
 * max(|z0|, |z_n - z0|) = 1.6e-11 m (the body falls 15.6 m in the 2 s).
 * The continuous answer z0 + v0 t - g t^2/2 differs from the discrete one by exactly
 * g dt^2 n/2 = g dt t/2: the scheme's first-order error, with the body below the true
 * parabola (it takes the end-of-step velocity). Asserted: |error| <= g dt t/2 + round-off and
 * the error equals g dt t/2 to round-off (so the bound is tight, and a second-order scheme
 * would be noticed as a change). The horizontal motion x = x0 + vx t is exact in both. */
START_TEST(test_free_fall_symplectic)
{
    const double dt = 1e-3, z0 = 10.0, vz0 = 2.0, vx0 = 1.5;
    const int n = 2000;
    ws_world *w = world_with(dt, WS_INTEGRATOR_SYMPLECTIC_EULER, G0);
    ws_body_id b = add_body(w, 0.1, 0.1, 0.1, 1.0, (ws_vec3){0, 0, z0}, Q_ID,
                            (ws_vec3){vx0, 0, vz0}, (ws_vec3){0, 0, 0});
    ck_ok(w, ws_world_step_n(w, n));
    ws_vec3 r, v;
    ck_ok(w, ws_body_get_position(w, b, &r));
    ck_ok(w, ws_body_get_velocity(w, b, &v));
    double t = n * dt;
    double z_disc = z0 + vz0 * n * dt - G0 * dt * dt * n * (n + 1.0) / 2.0;
    double z_cont = z0 + vz0 * t - 0.5 * G0 * t * t;
    double scale = fmax(fabs(z0), fabs(z_disc - z0));
    report("free fall (symplectic): z = %.15g, discrete %.15g (diff %.3g), continuous %.15g "
           "(diff %.6g, bound g dt t/2 = %.6g)",
           r.z, z_disc, r.z - z_disc, z_cont, r.z - z_cont, 0.5 * G0 * dt * t);
    ck_assert_msg(fabs(r.z - z_disc) <= 1e-12 * scale, "z = %.17g, discrete solution %.17g", r.z,
                  z_disc);
    ck_assert_msg(fabs(v.z - (vz0 - G0 * t)) <= 1e-12 * fabs(G0 * t), "vz = %.17g", v.z);
    ck_assert_msg(fabs(r.z - z_cont) <= 0.5 * G0 * dt * t + 1e-12 * scale,
                  "first-order bound broken: %.3g > %.3g", fabs(r.z - z_cont),
                  0.5 * G0 * dt * t);
    ck_assert_msg(fabs((z_cont - r.z) - 0.5 * G0 * dt * t) <= 1e-12 * scale,
                  "error %.17g is not g dt t/2 = %.17g", z_cont - r.z, 0.5 * G0 * dt * t);
    ck_assert_msg(fabs(r.x - vx0 * t) <= 1e-12 * vx0 * t, "x = %.17g, expected %.17g", r.x,
                  vx0 * t);
    ck_assert_msg(r.y == 0.0, "y = %g", r.y);
    ws_world_destroy(w);
}
END_TEST

/* The paper's scheme (eq. 8-9): z_{k+1} = z_k + v_k dt - g dt^2/2, v_{k+1} = v_k - g dt. For a
 * constant acceleration this is Taylor's series cut after the exact last term, so
 *   z_n = z0 + v0 t - g t^2/2 with t = n dt, exactly.
 * Tolerance: round-off only, as above 1e-12 relative. */
START_TEST(test_free_fall_paper_exact)
{
    const double dt = 1e-3, z0 = 10.0, vz0 = 2.0, vx0 = 1.5;
    const int n = 2000;
    ws_world *w = world_with(dt, WS_INTEGRATOR_PAPER_EXPLICIT, G0);
    ws_body_id b = add_body(w, 0.1, 0.1, 0.1, 1.0, (ws_vec3){0, 0, z0}, Q_ID,
                            (ws_vec3){vx0, 0, vz0}, (ws_vec3){0, 0, 0});
    ck_ok(w, ws_world_step_n(w, n));
    ws_vec3 r, v;
    ck_ok(w, ws_body_get_position(w, b, &r));
    ck_ok(w, ws_body_get_velocity(w, b, &v));
    double t = n * dt;
    double z_cont = z0 + vz0 * t - 0.5 * G0 * t * t;
    double scale = fmax(fabs(z0), fabs(z_cont - z0));
    report("free fall (paper): z = %.15g, exact %.15g, diff %.3g", r.z, z_cont, r.z - z_cont);
    ck_assert_msg(fabs(r.z - z_cont) <= 1e-12 * scale, "z = %.17g, exact %.17g", r.z, z_cont);
    ck_assert_msg(fabs(v.z - (vz0 - G0 * t)) <= 1e-12 * fabs(G0 * t), "vz = %.17g", v.z);
    ck_assert_msg(fabs(r.x - vx0 * t) <= 1e-12 * vx0 * t, "x = %.17g", r.x);
    ws_world_destroy(w);
}
END_TEST

/* ======================================================================================== */
/* Torque-free asymmetric body                                                               */
/* ======================================================================================== */

/* Box 0.1 x 0.2 x 0.3 m, 2 kg: J = m/12 diag(ly^2+lz^2, lx^2+lz^2, lx^2+ly^2)
 *   = diag(0.021667, 0.016667, 0.008333) kg m^2: x is the major axis (largest J), y the
 * intermediate, z the minor. Spin Omega = 10 rad/s, dt = 1e-4 s, 10 s, no gravity, no ground. */
#define TF_LX 0.1
#define TF_LY 0.2
#define TF_LZ 0.3
#define TF_M 2.0
#define TF_OMEGA 10.0
#define TF_DT 1e-4
#define TF_T 10.0
#define TF_EPS 1e-3

static const double TF_J[3] = {TF_M / 12 * (TF_LY * TF_LY + TF_LZ * TF_LZ),
                               TF_M / 12 * (TF_LX * TF_LX + TF_LZ * TF_LZ),
                               TF_M / 12 * (TF_LX * TF_LX + TF_LY * TF_LY)};

static double comp(ws_vec3 v, int i) { return i == 0 ? v.x : i == 1 ? v.y : v.z; }

typedef struct tf_result {
    double max_perp[3];  /* max |omega'_i| over the run, per component (rad/s) */
    double first_flip_t; /* first time omega'_axis changes sign (s), or -1 */
    double max_dH_rel;   /* max |H - H0| / |H0| */
    double dHn_rel_end;  /* (|H_end| - |H0|) / |H0| */
    double dT_rel_end;   /* (T_end - T0) / T0 */
    double max_dT_rel;   /* max |T - T0| / T0 */
    double pred_dT_rel;  /* sum over steps of dt^2/2 |w x L'|^2_{J^-1} / T0 (see energy test) */
    double pred_dHn_rel; /* sum over steps of dt^2/2 |w x L'|^2 / |L0|^2 (paper scheme's |H|) */
    double T0, L0sq;     /* initial 2T/2 (J) and |L|^2 */
} tf_result;

/* Run a torque-free body with omega'(0) = w0 (identity orientation, so omega global = omega')
 * and read the state after every step (1e5 steps of one body: well under a second). */
static tf_result run_torque_free_w(ws_integrator integ, const double w0[3], int axis, double dt,
                                   double T)
{
    ws_world *w = world_with(dt, integ, 0.0);
    ws_body_id b = add_body(w, TF_LX, TF_LY, TF_LZ, TF_M, (ws_vec3){0, 0, 0}, Q_ID,
                            (ws_vec3){0, 0, 0}, (ws_vec3){w0[0], w0[1], w0[2]});
    ws_mat3 J;
    ck_ok(w, ws_body_get_inertia(w, b, &J));
    for (int i = 0; i < 3; i++)
        ck_assert_msg(fabs(J.m[4 * i] - TF_J[i]) <= 1e-12 * TF_J[i],
                      "J[%d] = %.17g, m/12 (..) = %.17g", i, J.m[4 * i], TF_J[i]);
    tf_result res = {{0, 0, 0}, -1, 0, 0, 0, 0, 0, 0, 0, 0};
    ws_vec3 H0 = momentum(w, b);
    double T0 = rot_energy(w, b);
    res.T0 = T0;
    res.L0sq = dot(H0, H0);
    long n = lround(T / dt);
    for (long k = 0; k < n; k++) {
        ws_vec3 wl;
        OK(w, ws_body_get_angular_velocity_local(w, b, &wl));
        /* Leading term of what one step adds to T and to |L'| (see test_torque_free_energy). */
        ws_vec3 L = {TF_J[0] * wl.x, TF_J[1] * wl.y, TF_J[2] * wl.z};
        ws_vec3 c = cross(wl, L);
        res.pred_dT_rel += 0.5 * dt * dt *
                           (c.x * c.x / TF_J[0] + c.y * c.y / TF_J[1] + c.z * c.z / TF_J[2]) / T0;
        res.pred_dHn_rel += 0.5 * dt * dt * dot(c, c) / res.L0sq;
        OK(w, ws_world_step(w));
        OK(w, ws_body_get_angular_velocity_local(w, b, &wl));
        for (int i = 0; i < 3; i++)
            res.max_perp[i] = fmax(res.max_perp[i], fabs(comp(wl, i)));
        if (res.first_flip_t < 0 && comp(wl, axis) < 0)
            res.first_flip_t = (k + 1) * dt;
        ws_vec3 H = momentum(w, b);
        res.max_dH_rel = fmax(res.max_dH_rel, norm(sub(H, H0)) / norm(H0));
        res.dHn_rel_end = (norm(H) - norm(H0)) / norm(H0);
        double Tk = rot_energy(w, b);
        res.max_dT_rel = fmax(res.max_dT_rel, fabs(Tk - T0) / T0);
        res.dT_rel_end = (Tk - T0) / T0;
    }
    ws_world_destroy(w);
    return res;
}

/* Spin Omega about body axis `axis`, eps Omega on the two others. */
static tf_result run_torque_free(ws_integrator integ, int axis, double dt, double T)
{
    double o[3] = {TF_EPS * TF_OMEGA, TF_EPS * TF_OMEGA, TF_EPS * TF_OMEGA};
    o[axis] = TF_OMEGA;
    return run_torque_free_w(integ, o, axis, dt, T);
}

/* Stable axes. For M' = 0 both 2T = sum J_i w_i^2 and |L|^2 = sum J_i^2 w_i^2 are invariants,
 * hence exactly (not only linearised):
 *   major axis 1:  J1 2T - |L|^2 = J2 (J1 - J2) w2^2 + J3 (J1 - J3) w3^2 = C   (both terms >= 0)
 *   minor axis 3:  |L|^2 - J3 2T = J1 (J1 - J3) w1^2 + J2 (J2 - J3) w2^2 = C
 * so each perturbation component is bounded by sqrt(C / its coefficient) with C from the
 * initial perturbation eps Omega: it stays O(eps Omega) for ever and the spin never reverses.
 * The default integrator keeps |L| to round-off and its energy error is bounded with no drift
 * (test_torque_free_energy); near an axis that error scales with the same eps^2 as C, so the
 * exact invariant bound must hold to 1 % (measured: to 1e-6). A first-order rotation would gain
 * energy steadily and break it: ~7 % above the bound on the major axis after 10 s. The
 * intermediate axis reaches O(Omega), 1000 times these bounds, so the test separates the cases
 * widely. */
static void check_stable_axis(int axis)
{
    tf_result r = run_torque_free(WS_INTEGRATOR_SYMPLECTIC_EULER, axis, TF_DT, TF_T);
    double e = TF_EPS * TF_OMEGA, C = 0.0, coef[3];
    for (int i = 0; i < 3; i++) {
        coef[i] = TF_J[i] * fabs(TF_J[axis] - TF_J[i]);
        if (i != axis)
            C += coef[i] * e * e;
    }
    for (int i = 0; i < 3; i++) {
        if (i == axis)
            continue;
        double exact = sqrt(C / coef[i]);
        report("%s axis: max |w%d| = %.6g rad/s, invariant bound %.6g (initial %.3g)",
               axis == 0 ? "major" : "minor", i + 1, r.max_perp[i], exact, e);
        ck_assert_msg(r.max_perp[i] <= 1.01 * exact,
                      "axis %d: perturbation w%d grew to %.4g rad/s > 1.01 x bound %.4g", axis,
                      i + 1, r.max_perp[i], exact);
    }
    ck_assert_msg(r.first_flip_t < 0, "spin about stable axis %d reversed at t = %g s", axis,
                  r.first_flip_t);
}

START_TEST(test_spin_major_axis_stable) { check_stable_axis(0); }
END_TEST

START_TEST(test_spin_minor_axis_stable) { check_stable_axis(2); }
END_TEST

/* Intermediate axis (2): linearised, the perturbation grows like exp(lambda t) with
 *   lambda = Omega sqrt((J1 - J2)(J2 - J3) / (J1 J3)) = 4.80 1/s,
 * so from eps = 1e-3 it is O(1) after tg = ln(1/eps)/lambda = 1.44 s, and the body turns over
 * (Dzhanibekov): w2 passes through zero and reverses, periodically. Asserted: the reversal
 * happens within [tg/2, 3 tg] (the linear growth time sets the scale; the nonlinear turn-over
 * adds O(1/lambda)). At the reversal (w2 = 0) the two invariants fix the other components:
 *   J1 w1^2 + J3 w3^2 = 2T,  J1^2 w1^2 + J3^2 w3^2 = |L|^2
 *   => w1^2 = (|L|^2 - J3 2T) / (J1 (J1 - J3)),  w3^2 = (J1 2T - |L|^2) / (J3 (J1 - J3)),
 * and these are the largest values over the orbit (both decrease as w2^2 grows). Asserted
 * within 2 %: the energy drift by then is < 0.5 % (it moves w1^2, w3^2 by about as much). */
START_TEST(test_spin_intermediate_axis_flips)
{
    tf_result r = run_torque_free(WS_INTEGRATOR_SYMPLECTIC_EULER, 1, TF_DT, 5.0);
    double lam = TF_OMEGA * sqrt((TF_J[0] - TF_J[1]) * (TF_J[1] - TF_J[2]) / (TF_J[0] * TF_J[2]));
    double tg = log(1.0 / TF_EPS) / lam;
    double T2 = 2.0 * r.T0, L2 = r.L0sq;
    double w1 = sqrt((L2 - TF_J[2] * T2) / (TF_J[0] * (TF_J[0] - TF_J[2])));
    double w3 = sqrt((TF_J[0] * T2 - L2) / (TF_J[2] * (TF_J[0] - TF_J[2])));
    report("intermediate axis: lambda = %.4g 1/s, growth time %.4g s, first reversal at %.4g s; "
           "max |w1| = %.5g (invariants: %.5g), max |w3| = %.5g (invariants: %.5g) rad/s",
           lam, tg, r.first_flip_t, r.max_perp[0], w1, r.max_perp[2], w3);
    ck_assert_msg(r.first_flip_t > 0, "no reversal of w2 within 5 s");
    ck_assert_msg(r.first_flip_t > 0.5 * tg && r.first_flip_t < 3.0 * tg,
                  "reversal at %g s, expected within [%g, %g] s", r.first_flip_t, 0.5 * tg,
                  3.0 * tg);
    ck_assert_msg(fabs(r.max_perp[0] - w1) <= 0.02 * w1, "max |w1| = %g, invariants give %g",
                  r.max_perp[0], w1);
    ck_assert_msg(fabs(r.max_perp[2] - w3) <= 0.02 * w3, "max |w3| = %g, invariants give %g",
                  r.max_perp[2], w3);
}
END_TEST

/* Angular momentum in the global frame H = A J omega' is an invariant of torque-free motion.
 * The default integrator carries H itself (adds M dt, here 0) and derives omega' from it, so H
 * is conserved to round-off: each step re-derives H from A(p) and omega' with O(10) flops of
 * relative error eps ~ 1.1e-16; even if these add up in one direction over 1e5 steps that is
 * ~ 1e5 x 3 eps = 3e-11 (measured: 3e-11, so they do add up). The asserted 1e-9 relative
 * leaves a factor 30 and still catches any O(dt) scheme, whose error here is ~ Omega dt = 1e-3
 * (the paper's scheme: 1.4e-3).
 * Run on the intermediate axis, the most violent of the three motions. */
START_TEST(test_torque_free_momentum_conserved)
{
    tf_result r = run_torque_free(WS_INTEGRATOR_SYMPLECTIC_EULER, 1, TF_DT, TF_T);
    report("torque-free, default integrator: max |H - H0|/|H0| = %.3g over %g s", r.max_dH_rel,
           TF_T);
    ck_assert_msg(r.max_dH_rel < 1e-9, "angular momentum drifted by %.3g (relative)",
                  r.max_dH_rel);
}
END_TEST

/* Energy. The default scheme's rotational drift is the free rotor split symmetrically into exact
 * rotations about the principal axes (R1(dt/2) R2(dt/2) R3(dt) R2(dt/2) R1(dt/2)). Each factor
 * is the exact flow of a part of the Hamiltonian, so the step is symplectic and time-reversible:
 * it conserves a modified energy T~ = T + O((Omega dt)^2) T exactly, hence |T - T0|/T0 stays
 * bounded by C (Omega dt)^2 for all time, with C of order one set by the inertia ratios -- no
 * secular drift. A first-order explicit rotation (exp(-dt w~) on L' with w frozen) would instead
 * gain dt^2/2 |w x L'|^2_{J^-1} every step, always upward; summed along the run that is
 * pred_dT_rel (about 3e-3 here). Asserted, on the intermediate-axis flip (the most violent
 * motion) for 10 s at dt = 1e-4 s, Omega dt = 1e-3:
 *  - max |T - T0|/T0 <= (Omega dt)^2 = 1e-6 (C <= 1);
 *  - and below 1e-3 of the explicit drift pred_dT_rel, which shows there is no secular term. */
START_TEST(test_torque_free_energy)
{
    tf_result d = run_torque_free(WS_INTEGRATOR_SYMPLECTIC_EULER, 1, TF_DT, TF_T);
    double bound = (TF_OMEGA * TF_DT) * (TF_OMEGA * TF_DT);
    report("torque-free energy, default: dT/T0 = %.4g at %g s (max %.4g), bound (Omega dt)^2 = "
           "%.3g; a first-order explicit rotation would drift by %.4g",
           d.dT_rel_end, TF_T, d.max_dT_rel, bound, d.pred_dT_rel);
    ck_assert_msg(d.max_dT_rel <= bound, "default energy error %.4g above (Omega dt)^2 = %.4g",
                  d.max_dT_rel, bound);
    ck_assert_msg(d.max_dT_rel <= 1e-3 * d.pred_dT_rel,
                  "default energy error %.4g not far below the explicit drift %.4g", d.max_dT_rel,
                  d.pred_dT_rel);
}
END_TEST

/* The paper's scheme (eq. 10-12, explicit Euler on omega', p += dt p_dot, p renormalised).
 * Its omega' step is L' <- L' - dt w x L', so per step
 *   T gains dt^2/2 |w x L'|^2_{J^-1}: the SAME leading term as the default scheme, and
 *   |L'|^2 gains dt^2 |w x L'|^2 (the cross term L'.(w x L') vanishes): |H| = |L'| drifts up
 *   by dt^2/2 |w x L'|^2 / |L| per step, where the default keeps H to round-off.
 * The default scheme's energy error is bounded (test_torque_free_energy), so the paper's scheme
 * drifts far more in energy, and in |H|, which the default keeps to round-off. Asserted:
 *  - p stays unit (renormalised) -- checked in test_euler_parameter_invariants_paper;
 *  - energy drift within 20 % of its own leading-term sum (the O(dt^3) terms are a relative
 *    O(Omega dt) = 1e-3 of it);
 *  - |H| drift within 20 % of its leading-term sum, and > 1e4 times the default's;
 *  - energy drift > 1e3 times the default's energy error, on the flip and on a generic tumble
 *    w0 = (3, -7, 5) rad/s. */
START_TEST(test_torque_free_paper_scheme)
{
    tf_result p = run_torque_free(WS_INTEGRATOR_PAPER_EXPLICIT, 1, TF_DT, TF_T);
    tf_result d = run_torque_free(WS_INTEGRATOR_SYMPLECTIC_EULER, 1, TF_DT, TF_T);
    report("torque-free, paper scheme (intermediate axis): dT/T0 = %.4g (predicted %.4g; default "
           "%.4g), d|H|/|H0| = %.4g (predicted %.4g; default max |dH| %.3g)",
           p.dT_rel_end, p.pred_dT_rel, d.dT_rel_end, p.dHn_rel_end, p.pred_dHn_rel,
           d.max_dH_rel);
    ck_assert_msg(fabs(p.dT_rel_end) <= 1.2 * p.pred_dT_rel, "paper energy drift %.4g, predicted %.4g",
                  p.dT_rel_end, p.pred_dT_rel);
    ck_assert_msg(fabs(p.dHn_rel_end - p.pred_dHn_rel) <= 0.2 * p.pred_dHn_rel,
                  "paper |H| drift %.4g, predicted %.4g", p.dHn_rel_end, p.pred_dHn_rel);
    ck_assert_msg(p.max_dH_rel > 1e4 * d.max_dH_rel, "paper |H| drift %.3g vs default %.3g",
                  p.max_dH_rel, d.max_dH_rel);

    ck_assert_msg(fabs(p.dT_rel_end) > 1e3 * d.max_dT_rel,
                  "paper energy drift %.4g not above 1e3 x the default's %.4g", p.dT_rel_end,
                  d.max_dT_rel);

    const double w0[3] = {3.0, -7.0, 5.0};
    tf_result pg = run_torque_free_w(WS_INTEGRATOR_PAPER_EXPLICIT, w0, 1, TF_DT, TF_T);
    tf_result dg = run_torque_free_w(WS_INTEGRATOR_SYMPLECTIC_EULER, w0, 1, TF_DT, TF_T);
    report("torque-free, generic tumble: dT/T0 paper %.5g, default %.5g (max %.3g)",
           pg.dT_rel_end, dg.dT_rel_end, dg.max_dT_rel);
    ck_assert_msg(fabs(pg.dT_rel_end) > 1e3 * dg.max_dT_rel,
                  "generic tumble: paper drift %.5g not above 1e3 x the default's %.5g",
                  pg.dT_rel_end, dg.max_dT_rel);
}
END_TEST

/* ======================================================================================== */
/* Euler parameters and kinematics                                                            */
/* ======================================================================================== */

/* A tumbling body (general omega, general initial orientation, moving CoG), 1e5 steps:
 *  - |p| = 1 to 1e-12: both integrators renormalise p each step (round-off 1e-16 per step);
 *  - A = ws_body_get_rotation orthonormal, A A^T = I, det A = +1 to 1e-12 (eq. 6 of a unit p
 *    is exactly orthogonal; only round-off of |p| and of the products, ~1e-15);
 *  - A equals Rodrigues' matrix of the same rotation (axis, angle from p) to 1e-12;
 *  - ws_body_get_angular_velocity = A omega' (1e-12 relative);
 *  - ws_body_get_world_point(s) = r + A s (eq. 2) with A from Rodrigues, 1e-12 m;
 *  - ws_body_get_point_velocity(x) = v + omega x (x - r) (eq. 3), 1e-12 relative;
 *  - and eq. 3 is the actual rate of the material point: over the next step the point moves by
 *    the eq. 3 velocity times dt up to O(dt^2 Omega^2 |s|) (the step is first order). */
static void check_kinematics(ws_integrator integ)
{
    const double dt = 1e-4;
    ws_world *w = world_with(dt, integ, 0.0);
    double a = 0.7, n0 = sqrt(1.0 + 4.0 + 9.0);
    ws_quat q0 = {cos(a / 2), sin(a / 2) / n0, 2 * sin(a / 2) / n0, 3 * sin(a / 2) / n0};
    ws_body_id b = add_body(w, TF_LX, TF_LY, TF_LZ, TF_M, (ws_vec3){0.3, -0.2, 0.1}, q0,
                            (ws_vec3){0.5, 0.25, -0.125}, (ws_vec3){3.0, -7.0, 5.0});
    ck_ok(w, ws_world_step_n(w, 100000));

    ws_quat q;
    ws_mat3 A;
    ck_ok(w, ws_body_get_orientation(w, b, &q));
    ck_ok(w, ws_body_get_rotation(w, b, &A));
    double qn = sqrt(q.e0 * q.e0 + q.e1 * q.e1 + q.e2 * q.e2 + q.e3 * q.e3);
    double orth = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double s = 0.0;
            for (int k = 0; k < 3; k++)
                s += A.m[3 * i + k] * A.m[3 * j + k];
            orth = fmax(orth, fabs(s - (i == j)));
        }
    const double *m = A.m;
    double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                 m[2] * (m[3] * m[7] - m[4] * m[6]);
    ws_mat3 R = rodrigues_from_quat(q);
    double dR = 0.0;
    for (int i = 0; i < 9; i++)
        dR = fmax(dR, fabs(R.m[i] - A.m[i]));
    report("%s after 1e5 steps: ||p|-1| = %.3g, |A A^T - I| = %.3g, |det-1| = %.3g, "
           "|A - Rodrigues| = %.3g",
           integ == WS_INTEGRATOR_PAPER_EXPLICIT ? "paper" : "default", fabs(qn - 1.0), orth,
           fabs(det - 1.0), dR);
    ck_assert_msg(fabs(qn - 1.0) < 1e-12, "|p| = %.17g", qn);
    ck_assert_msg(orth < 1e-12, "A A^T - I = %.3g", orth);
    ck_assert_msg(fabs(det - 1.0) < 1e-12, "det A = %.17g", det);
    ck_assert_msg(dR < 1e-12, "A differs from Rodrigues by %.3g", dR);

    ws_vec3 wl, wg, r, v;
    ck_ok(w, ws_body_get_angular_velocity_local(w, b, &wl));
    ck_ok(w, ws_body_get_angular_velocity(w, b, &wg));
    ck_ok(w, ws_body_get_position(w, b, &r));
    ck_ok(w, ws_body_get_velocity(w, b, &v));
    ws_vec3 Awl = mv(&R, wl);
    ck_assert_msg(norm(sub(wg, Awl)) <= 1e-12 * norm(wl), "omega global != A omega': %.3g",
                  norm(sub(wg, Awl)));

    /* eq. 2 and eq. 3 at a corner and at an off-body point. */
    ws_vec3 pts[2] = {{0.05, -0.1, 0.15}, {0.4, 0.3, -0.8}};
    for (int k = 0; k < 2; k++) {
        ws_vec3 xg, xe = add(r, mv(&R, pts[k]));
        ck_ok(w, ws_body_get_world_point(w, b, &pts[k], &xg));
        ck_assert_msg(norm(sub(xg, xe)) < 1e-12, "world point off by %.3g m",
                      norm(sub(xg, xe)));
        ws_vec3 vp, ve = add(v, cross(Awl, sub(xg, r)));
        ck_ok(w, ws_body_get_point_velocity(w, b, &xg, &vp));
        ck_assert_msg(norm(sub(vp, ve)) <= 1e-12 * norm(ve), "point velocity off by %.3g",
                      norm(sub(vp, ve)));
        /* The material point's displacement over one more step. */
        ck_ok(w, ws_world_step(w));
        ws_vec3 xg1;
        ck_ok(w, ws_body_get_world_point(w, b, &pts[k], &xg1));
        ws_vec3 fd = {(xg1.x - xg.x) / dt, (xg1.y - xg.y) / dt, (xg1.z - xg.z) / dt};
        double om = norm(wl), sl = norm(pts[k]);
        double tol = 2.0 * dt * om * om * sl + 1e-9; /* O(dt Omega^2 |s|) + round-off / dt */
        ck_assert_msg(norm(sub(fd, vp)) <= tol,
                      "eq. 3 velocity %.6g differs from the step's %.6g by %.3g > %.3g",
                      norm(vp), norm(fd), norm(sub(fd, vp)), tol);
        ck_ok(w, ws_body_get_position(w, b, &r));
        ck_ok(w, ws_body_get_velocity(w, b, &v));
        ck_ok(w, ws_body_get_orientation(w, b, &q));
        ck_ok(w, ws_body_get_angular_velocity_local(w, b, &wl));
        R = rodrigues_from_quat(q);
        Awl = mv(&R, wl);
    }
    ws_world_destroy(w);
}

START_TEST(test_euler_parameter_invariants) { check_kinematics(WS_INTEGRATOR_SYMPLECTIC_EULER); }
END_TEST

START_TEST(test_euler_parameter_invariants_paper) { check_kinematics(WS_INTEGRATOR_PAPER_EXPLICIT); }
END_TEST

static Suite *dynamics_suite(void)
{
    Suite *s = suite_create("dynamics");
    TCase *tc = tcase_create("free_fall");
    tcase_set_timeout(tc, 10);
    tcase_add_test(tc, test_free_fall_symplectic);
    tcase_add_test(tc, test_free_fall_paper_exact);
    suite_add_tcase(s, tc);

    tc = tcase_create("torque_free");
    tcase_set_timeout(tc, 30);
    tcase_add_test(tc, test_spin_major_axis_stable);
    tcase_add_test(tc, test_spin_minor_axis_stable);
    tcase_add_test(tc, test_spin_intermediate_axis_flips);
    tcase_add_test(tc, test_torque_free_momentum_conserved);
    tcase_add_test(tc, test_torque_free_energy);
    tcase_add_test(tc, test_torque_free_paper_scheme);
    suite_add_tcase(s, tc);

    tc = tcase_create("euler_parameters");
    tcase_set_timeout(tc, 20);
    tcase_add_test(tc, test_euler_parameter_invariants);
    tcase_add_test(tc, test_euler_parameter_invariants_paper);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return run_suite(dynamics_suite());
}
