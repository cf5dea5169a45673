/* Validation of the deformable elements (rod, linear spring, angular spring, bushing) through the
 * public API: known analytical answers, conservation laws, and the invariance the seed's slides
 * are about.
 *
 *  - rod mass-spring and torsional oscillators: periods 2 pi sqrt(m/k) and 2 pi sqrt(J/k);
 *  - elastic elements conserve energy (bounded error, no drift) with the symplectic integrator;
 *  - loads balance exactly: linear and angular momentum of two bodies joined by any element stay
 *    constant to round-off, and the reported loads sum to zero force and zero moment;
 *  - where a potential exists, the loads are minus its gradient (central differences);
 *  - swapping the two bodies of an invariant angular spring or bushing with an orthotropic law at
 *    large rotations gives the same motion, the attached one another;
 *  - viscous and Kelvin-Voigt bushings decay at the law's rate;
 *  - the API: stale ids, bad Defs, bodies and laws in use, failing allocator, bytes back to
 *    zero, failed steps leave the law history alone, determinism hash.
 *
 * Every tolerance is argued in the comment above its assertion. Measured figures are printed with
 * a "[measured]" prefix. */
#include "helpers.h"

/* ck_ok for loops: touches Check only when the call fails. */
#define OK(w, call)                                                                                \
    do {                                                                                           \
        ws_status s_ = (call);                                                                     \
        if (s_ != WS_OK)                                                                           \
            ck_abort_msg("%s -> %s (%s)", #call, ws_status_string(s_), ws_world_last_error(w));    \
    } while (0)

#define PI 3.14159265358979323846

/* ---- small vector algebra on the public types ---- */

static ws_vec3 v3(double x, double y, double z)
{
    return (ws_vec3){x, y, z};
}
static ws_vec3 add(ws_vec3 a, ws_vec3 b)
{
    return v3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static ws_vec3 sub(ws_vec3 a, ws_vec3 b)
{
    return v3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static ws_vec3 scale(ws_vec3 a, double s)
{
    return v3(a.x * s, a.y * s, a.z * s);
}
static double dot(ws_vec3 a, ws_vec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static double norm(ws_vec3 a)
{
    return sqrt(dot(a, a));
}
static ws_vec3 cross(ws_vec3 a, ws_vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static ws_vec3 mv(const ws_mat3 *a, ws_vec3 v)
{
    const double *m = a->m;
    return v3(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
              m[6] * v.x + m[7] * v.y + m[8] * v.z);
}
static double comp(ws_vec3 a, int k)
{
    return k == 0 ? a.x : k == 1 ? a.y : a.z;
}
static ws_vec3 unit(int k)
{
    return v3(k == 0, k == 1, k == 2);
}

static ws_quat qrot(ws_vec3 phi)
{
    double a = norm(phi);
    if (a == 0.0)
        return (ws_quat){1, 0, 0, 0};
    double s = sin(0.5 * a) / a;
    return (ws_quat){cos(0.5 * a), phi.x * s, phi.y * s, phi.z * s};
}

/* Deterministic pseudo-random numbers (xorshift64*), so a failure is reproducible. */
static uint64_t rng = 0x2545F4914F6CDD1Dull;
static double urand(void)
{
    rng ^= rng >> 12;
    rng ^= rng << 25;
    rng ^= rng >> 27;
    return (double)((rng * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}
static double srand1(void)
{
    return 2.0 * urand() - 1.0;
}
static ws_vec3 rvec(double s)
{
    return v3(s * srand1(), s * srand1(), s * srand1());
}

/* ---- scene builders ---- */

static ws_world *world0(double dt)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = dt;
    d.gravity = v3(0, 0, 0);
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    return w;
}

/* A dynamic box of edge lengths l (m) and mass m (kg) at r with orientation q. */
static ws_body_id box(ws_world *w, ws_vec3 l, double m, ws_vec3 r, ws_quat q, const char *name)
{
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, l.x, l.y, l.z, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = s;
    bd.mass = m;
    bd.position = r;
    bd.orientation = q;
    bd.name = name;
    ws_body_id id;
    ck_ok(w, ws_body_create(w, &bd, &id));
    return id;
}

static const ws_quat QI = {1, 0, 0, 0};
static const ws_body_id WORLD = {0};

/* A law of dim 1, 3 or 6: K (and C) as matrices when given, else k (and c) times I. */
static ws_law_id law(ws_world *w, int dim, ws_law_type type, double k, double c, const double *K,
                     const double *C)
{
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = type;
    d.dim = dim;
    d.stiffness = k;
    d.damping = c;
    d.stiffness_matrix = K;
    d.damping_matrix = C;
    ws_law_id id;
    ck_ok(w, ws_law_create(w, &d, &id));
    return id;
}

static ws_element_id element(ws_world *w, ws_element_type type, ws_element_formulation form,
                             ws_body_id b1, ws_body_id b2, ws_law_id lw, ws_vec3 p1, ws_vec3 p2)
{
    ws_element_def d;
    ws_element_def_init(&d);
    d.type = type;
    d.formulation = form;
    d.body1 = b1;
    d.body2 = b2;
    d.law = lw;
    d.point1 = p1;
    d.point2 = p2;
    d.name = "element";
    ws_element_id id;
    ck_ok(w, ws_element_create(w, &d, &id));
    return id;
}

static ws_element_output out_of(ws_world *w, ws_element_id e)
{
    ws_element_output o;
    OK(w, ws_element_get_output(w, e, &o));
    return o;
}

/* Mechanical energy: kinetic + elastic in the elements (no gravity in these scenes), J. */
static double energy(ws_world *w)
{
    ws_energy e;
    double el;
    OK(w, ws_world_get_energy(w, &e));
    OK(w, ws_world_get_element_energy(w, &el));
    return e.kinetic + el;
}

/* Linear momentum (kg m/s) and angular momentum about the origin (kg m^2/s) of the listed
 * bodies: sum of m v and r x m v + A J omega'. */
static void momenta(ws_world *w, const ws_body_id *b, int n, ws_vec3 *P, ws_vec3 *H)
{
    *P = *H = v3(0, 0, 0);
    for (int i = 0; i < n; i++) {
        double m;
        ws_vec3 r, v, wl;
        ws_mat3 A, J;
        OK(w, ws_body_get_mass(w, b[i], &m));
        OK(w, ws_body_get_position(w, b[i], &r));
        OK(w, ws_body_get_velocity(w, b[i], &v));
        OK(w, ws_body_get_angular_velocity_local(w, b[i], &wl));
        OK(w, ws_body_get_rotation(w, b[i], &A));
        OK(w, ws_body_get_inertia(w, b[i], &J));
        *P = add(*P, scale(v, m));
        *H = add(*H, add(cross(r, scale(v, m)), mv(&A, mv(&J, wl))));
    }
}

/* Period of a signal sampled every h from upward zero crossings, linearly interpolated. */
typedef struct crossing {
    double prev, t_first, t_last;
    int count, started;
} crossing;

static void crossing_add(crossing *c, double t, double h, double s)
{
    if (c->started && c->prev < 0.0 && s >= 0.0) {
        double tc = t - h + h * c->prev / (c->prev - s);
        if (c->count == 0)
            c->t_first = tc;
        c->t_last = tc;
        c->count++;
    }
    c->prev = s;
    c->started = 1;
}

static double crossing_period(const crossing *c)
{
    ck_assert_int_ge(c->count, 3);
    return (c->t_last - c->t_first) / (c->count - 1);
}

/* The period of symplectic Euler for x'' = -omega^2 x: the scheme maps x_k exactly onto a
 * sinusoid of frequency Omega with cos(Omega h) = 1 - (omega h)^2 / 2, so
 * T_h = 2 pi / Omega = pi h / asin(omega h / 2), shorter than 2 pi / omega by (omega h)^2 / 24. */
static double discrete_period(double omega, double h)
{
    return PI * h / asin(0.5 * omega * h);
}

/* ======================================================================================== */
/* Oscillators with known periods                                                           */
/* ======================================================================================== */

/* A 2 kg box hanging on a rod from a fixed point, along an oblique line n = (1, 2, 2)/3 (gravity
 * 9.81 m/s^2 along +n, away from the anchor), the rod attached at the box's CoG or 50 mm from it
 * on the line, on the anchor's side (the force then still passes through the CoG, so the box
 * translates along n only; gravity keeps the rod in tension, eps_eq = m g/EA = 0.078, so the
 * offset box hangs stably instead of balancing on a compressed rod). Law: EA = 250 N per unit
 * strain, l0 = 0.5 m, so k = EA/l0 = 500 N/m; pulled 20 mm beyond equilibrium and released:
 * T = 2 pi sqrt(m/k) = 0.397 s, gravity only shifting the centre. dt = 1e-4 s, 12 periods.
 * The rod's strain is linear in the stretch (eps = |l|/l0 - 1), so the oscillator is exactly
 * linear and symplectic Euler reproduces the discrete period T_h (discrete_period) to the
 * accuracy of the zero-crossing interpolation: for a sampled sinusoid the linear interpolation
 * of a crossing is off by O((Omega h)^3) h ~ 1e-12 s, so |T - T_h| <= 1e-9 T. The continuous
 * period differs from T_h by (omega h)^2/24 = 1.0e-7 relative: asserted within 3e-7. */
START_TEST(test_rod_period)
{
    const double m = 2.0, EA = 250.0, l0 = 0.5, k = EA / l0, h = 1e-4;
    const ws_vec3 n = v3(1.0 / 3, 2.0 / 3, 2.0 / 3), a = v3(0.1, -0.2, 0.3);
    const double eq = m * G0 / EA, s0 = eq * l0 + 0.02; /* stretch at release, m */
    for (int offset = 0; offset < 2; offset++) {
        ws_world *w = world0(h);
        ws_vec3 g = scale(n, G0);
        ck_ok(w, ws_world_set_gravity(w, &g));
        ws_vec3 o = scale(n, offset ? -0.05 : 0.0); /* the box point that faces the anchor */
        ws_vec3 r = sub(add(a, scale(n, l0 + s0)), o);
        ws_body_id b = box(w, v3(0.1, 0.1, 0.1), m, r, QI, "mass");
        ws_law_id L = law(w, 1, WS_LAW_LINEAR_ELASTIC, EA, 0, NULL, NULL);
        ws_element_def d;
        ws_element_def_init(&d);
        d.type = WS_ELEMENT_ROD;
        d.body1 = WORLD;
        d.body2 = b;
        d.law = L;
        d.point1 = a;
        d.point2 = o;
        d.rest_length = l0;
        ws_element_id e;
        ck_ok(w, ws_element_create(w, &d, &e));
        ws_element_output o0 = out_of(w, e);
        ck_assert_double_eq_tol(o0.strain[0], s0 / l0, 1e-14);
        /* Tension EA eps pulls the box back towards the anchor: -n on body 2 = +n on body 1. */
        ck_assert_double_eq_tol(dot(o0.force, n), EA * s0 / l0, 1e-11);
        ck_assert_double_eq_tol(norm(cross(o0.force, n)), 0.0, 1e-12);

        double omega = sqrt(k / m), T = 2 * PI / omega, Th = discrete_period(omega, h);
        crossing c = {0};
        int steps = (int)(12 * T / h);
        for (int s = 1; s <= steps; s++) {
            OK(w, ws_world_step(w));
            crossing_add(&c, s * h, h, out_of(w, e).strain[0] - eq);
        }
        double Tm = crossing_period(&c);
        ws_vec3 rn, vn;
        ck_ok(w, ws_body_get_position(w, b, &rn));
        ck_ok(w, ws_body_get_velocity(w, b, &vn));
        report("rod period (%s): %.9f s, 2 pi sqrt(m/k) = %.9f s (rel %.2e), symplectic %.9f s "
               "(rel %.2e)",
               offset ? "offset point" : "point at CoG", Tm, T, Tm / T - 1, Th, Tm / Th - 1);
        ck_assert_msg(fabs(Tm / Th - 1) <= 1e-9, "T = %.12g, T_h = %.12g", Tm, Th);
        ck_assert_msg(fabs(Tm / T - 1) <= 3e-7, "T = %.12g, 2 pi sqrt(m/k) = %.12g", Tm, T);
        /* The box moved along n only: no sideways velocity beyond round-off of |v| ~ 0.7 m/s. */
        ck_assert_msg(norm(cross(vn, n)) <= 1e-12, "sideways velocity %g", norm(cross(vn, n)));
        ws_world_destroy(w);
    }
}
END_TEST

/* A box 0.1 x 0.2 x 0.3 m, 3 kg (principal moments J = m/12 (b^2 + c^2): 0.0325, 0.025, 0.0125
 * kg m^2) on an angular spring to the world frame, k = 2 N m/rad isotropic, started unstrained
 * spinning at 6 rad/s about one principal axis: amplitude 6/omega = 0.5-0.8 rad. The spring's
 * moment stays on that axis and theta = the rotation angle there, so the motion is the linear
 * oscillator J theta'' = -k theta at any amplitude: T = 2 pi sqrt(J/k). Symplectic Euler's kick
 * and exact rotor rotation about a principal axis are the linear scheme, so as for the rod the
 * measured period is T_h to 1e-9, and T_h is shorter than T by (omega h)^2/24 (at most 1.7e-6:
 * omega <= 12.6 rad/s, h = 5e-4 s): asserted within 1.1 (omega h)^2/24. All three formulations
 * agree here (theta along the axis: mid frame and body frame share it, and H(theta) theta = theta).
 */
START_TEST(test_torsion_period)
{
    const double m = 3.0, k = 2.0, h = 5e-4, w0 = 6.0;
    const double J[3] = {m / 12 * (0.04 + 0.09), m / 12 * (0.01 + 0.09), m / 12 * (0.01 + 0.04)};
    const ws_element_formulation forms[3] = {WS_ELEMENT_INVARIANT, WS_ELEMENT_ATTACHED,
                                             WS_ELEMENT_POTENTIAL};
    for (int f = 0; f < 3; f++) {
        for (int ax = 0; ax < 3; ax++) {
            ws_world *w = world0(h);
            ws_body_id b = box(w, v3(0.1, 0.2, 0.3), m, v3(0, 0, 0), QI, "rotor");
            ws_vec3 v0 = v3(0, 0, 0), om = scale(unit(ax), w0);
            ck_ok(w, ws_body_set_velocity(w, b, &v0, &om));
            ws_law_id L = law(w, 3, WS_LAW_LINEAR_ELASTIC, k, 0, NULL, NULL);
            /* The rotor is body 1: theta is the world's rotation seen from the rotor. */
            ws_element_id e = element(w, WS_ELEMENT_ANGULAR_SPRING, forms[f], b, WORLD, L,
                                      v3(0, 0, 0), v3(0, 0, 0));
            double omega = sqrt(k / J[ax]), T = 2 * PI / omega, Th = discrete_period(omega, h);
            crossing c = {0};
            int steps = (int)(8 * T / h);
            double amp = 0.0;
            for (int s = 1; s <= steps; s++) {
                OK(w, ws_world_step(w));
                ws_element_output o = out_of(w, e);
                /* Body 1 is the rotor: theta = its rotation seen from body 2 (the world), negated.
                 */
                crossing_add(&c, s * h, h, -o.strain[ax]);
                amp = fmax(amp, fabs(o.strain[ax]));
            }
            double Tm = crossing_period(&c);
            report("torsion period, axis %c, %s: %.9f s, 2 pi sqrt(J/k) = %.9f s (rel %.2e), "
                   "symplectic (rel %.2e), amplitude %.3f rad",
                   "xyz"[ax],
                   f == 0   ? "invariant"
                   : f == 1 ? "attached"
                            : "potential",
                   Tm, T, Tm / T - 1, Tm / Th - 1, amp);
            ck_assert_msg(fabs(Tm / Th - 1) <= 1e-9, "axis %d: T = %.12g, T_h = %.12g", ax, Tm, Th);
            double dh = omega * h * omega * h / 24.0;
            ck_assert_msg(fabs(Tm / T - 1) <= 1.1 * dh,
                          "axis %d: T = %.12g, 2 pi sqrt(J/k) = %.12g", ax, Tm, T);
            ck_assert_double_eq_tol(amp, w0 / omega, 1e-3 * w0 / omega);
            ws_world_destroy(w);
        }
    }
}
END_TEST

/* ======================================================================================== */
/* Energy                                                                                   */
/* ======================================================================================== */

/* Two free boxes (2 kg 0.2 x 0.15 x 0.1 m and 3 kg 0.1 x 0.25 x 0.2 m) joined by one element,
 * with the attachment points off their CoGs, large initial rotations and velocities, no gravity.
 * What each case uses, and why its energy must be conserved:
 *  rod, linear spring (invariant, attached): strains whose loads are the exact gradient of the
 *    law energy, whatever the law (an orthotropic diag(800, 1200, 2000) N/m for the springs);
 *  angular spring invariant and attached, isotropic k = 4 N m/rad: M = k theta is along theta,
 *    where the tangent maps are the identity, so the seed's moments are the gradient too;
 *  angular spring potential, orthotropic diag(2, 4, 8) N m/rad: the gradient by construction;
 *  bushing potential, a coupled symmetric 6x6 law; bushing invariant with an isotropic rotation
 *    block (its displacement part is always potential-based).
 * Symplectic Euler keeps a modified energy exactly, which differs from the energy by O(omega h)
 * times the energy exchanged: the error stays bounded and does not drift. Bound asserted:
 * |E - E0| <= omega_max h E0 with omega_max the fastest relative mode of the pair (sqrt(k w),
 * k the largest stiffness entry, w the sum of the two bodies' compliances at the points,
 * 1/m + r^2/J_min, or 1/J_min in rotation; the harmonic oscillator's energy error under
 * symplectic Euler is (omega h / 2) of its energy at most); and the mean of E over the last
 * tenth of the run within 0.05 omega_max h E0 of the mean over the first tenth (no drift: a
 * non-conservative form shows up there, as the report of the orthotropic invariant angular
 * spring shows). 40000 steps of 1e-4 s = 4 s, tens of periods.
 * The invariant forms are defined for relative rotations below pi: at pi the principal rotation
 * vector, and with it the mid frame, turns over (docs/elements.md). A linear spring alone does
 * not hold the relative rotation back, so its cases are stirred gently (largest relative
 * rotation reported; asserted below 3 rad for every checked case but the rod). */
typedef struct energy_case {
    const char *name;
    ws_element_type type;
    ws_element_formulation form;
    int dim;
    const double *K; /* NULL: k I */
    double k;
    int check; /* 0: report only */
    int gentle;
} energy_case;

/* clang-format off */
static const double K3_ORTHO[9] = {800, 0, 0, 0, 1200, 0, 0, 0, 2000};
static const double K3_ROT[9] = {2, 0, 0, 0, 4, 0, 0, 0, 8};
/* Symmetric positive definite, coupled: displacement blocks N/m, rotation N m/rad, coupling N. */
static const double K6_COUPLED[36] = {
    2000, 0,    0,    0,  60,  0,  /**/
    0,    3000, 0,    -40, 0,  0,  /**/
    0,    0,    5000, 0,  0,   30, /**/
    0,    -40,  0,    6,  0,   0,  /**/
    60,   0,    0,    0,  8,   1,  /**/
    0,    0,    30,   0,  1,   10, /**/
};
static const double K6_ISO_ROT[36] = {
    2000, 0, 0, 0, 0, 0, /**/ 0, 3000, 0, 0, 0, 0, /**/ 0, 0, 5000, 0, 0, 0,
    0,    0, 0, 6, 0, 0, /**/ 0, 0,    0, 0, 6, 0, /**/ 0, 0, 0,    0, 0, 6,
};
/* clang-format on */

/* The two boxes of the energy, momentum and swap tests (A: 2 kg, 0.2 x 0.15 x 0.1 m at the
 * origin; B: 3 kg, 0.1 x 0.25 x 0.2 m at (0.8, 0.1, -0.05)) and their attachment points in the
 * bodies' frames: for a rod two points 0.66 m apart; for the others one shared point between
 * the boxes, 0.4 m from each CoG, so that a spring starts with the points together. Their
 * bounding spheres (radii 0.134 and 0.168 m) stay apart while the CoGs are 0.31 m apart or
 * more, so no contact takes part (checked: the contact count stays 0). */
typedef struct pair_scene {
    ws_world *w;
    ws_body_id a, b;
    ws_vec3 pa, pb; /* attachment points in the bodies' frames */
} pair_scene;

static const ws_vec3 XA = {0, 0, 0}, XB = {0.8, 0.1, -0.05};
static const ws_vec3 ROD_A = {0.1, 0.03, -0.02}, ROD_B = {-0.05, -0.04, 0.06};

static pair_scene make_pair(double h, int rod)
{
    pair_scene p;
    p.w = world0(h);
    p.a = box(p.w, v3(0.2, 0.15, 0.1), 2.0, XA, QI, "A");
    p.b = box(p.w, v3(0.1, 0.25, 0.2), 3.0, XB, QI, "B");
    ws_vec3 c = v3(0.4, 0.05, -0.02);
    p.pa = rod ? ROD_A : sub(c, XA);
    p.pb = rod ? ROD_B : sub(c, XB);
    return p;
}

/* Large rotations (0.37 rad of A, 2.1 rad of B) and velocities, set after the elements are made
 * (their frames then coincide); each body turned about its attachment point, which stays where
 * it was made: the strain starts from rotation alone and the motion does the rest. `gentle`
 * scales B's turn by 1/2 and the spins by 0.3. */
static void stir_by(pair_scene *p, int gentle)
{
    double sb = gentle ? 0.5 : 1.0, sw = gentle ? 0.3 : 1.0;
    ws_quat qa = qrot(v3(0.3, 0.2, -0.1)), qb = qrot(scale(v3(1.2, -0.8, 1.5), sb));
    ws_pose pa = {XA, qa}, pb = {XB, qb};
    ck_ok(p->w, ws_body_set_pose(p->w, p->a, &pa));
    ck_ok(p->w, ws_body_set_pose(p->w, p->b, &pb));
    ws_vec3 ga, gb; /* where the points went */
    ck_ok(p->w, ws_body_get_world_point(p->w, p->a, &p->pa, &ga));
    ck_ok(p->w, ws_body_get_world_point(p->w, p->b, &p->pb, &gb));
    pa.position = sub(XA, sub(ga, add(XA, p->pa)));
    pb.position = sub(XB, sub(gb, add(XB, p->pb)));
    ck_ok(p->w, ws_body_set_pose(p->w, p->a, &pa));
    ck_ok(p->w, ws_body_set_pose(p->w, p->b, &pb));
    ws_vec3 va = v3(0.1, -0.2, 0.05), wa = scale(v3(1.0, -2.0, 0.5), sw);
    ws_vec3 vb = v3(-0.05, 0.1, 0.2), wb = scale(v3(-1.5, 0.7, 2.5), sw);
    ck_ok(p->w, ws_body_set_velocity(p->w, p->a, &va, &wa));
    ck_ok(p->w, ws_body_set_velocity(p->w, p->b, &vb, &wb));
}

static void stir(pair_scene *p)
{
    stir_by(p, 0);
}

/* Relative rotation angle of the two boxes, rad (their element frames coincided at create). */
static double relative_angle(const pair_scene *p)
{
    ws_quat a, b;
    OK(p->w, ws_body_get_orientation(p->w, p->a, &a));
    OK(p->w, ws_body_get_orientation(p->w, p->b, &b));
    double c = fabs(a.e0 * b.e0 + a.e1 * b.e1 + a.e2 * b.e2 + a.e3 * b.e3);
    return 2.0 * acos(c < 1.0 ? c : 1.0);
}

START_TEST(test_energy_conservation)
{
    const energy_case cases[] = {
        {"rod", WS_ELEMENT_ROD, WS_ELEMENT_INVARIANT, 1, NULL, 300.0, 1, 0},
        {"linear spring invariant", WS_ELEMENT_LINEAR_SPRING, WS_ELEMENT_INVARIANT, 3, K3_ORTHO, 0,
         1, 1},
        {"linear spring attached", WS_ELEMENT_LINEAR_SPRING, WS_ELEMENT_ATTACHED, 3, K3_ORTHO, 0, 1,
         1},
        {"angular spring invariant, isotropic", WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_INVARIANT, 3,
         NULL, 4.0, 1, 0},
        {"angular spring attached, isotropic", WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_ATTACHED, 3,
         NULL, 4.0, 1, 0},
        {"angular spring potential, orthotropic", WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_POTENTIAL,
         3, K3_ROT, 0, 1, 0},
        {"bushing potential, coupled 6x6", WS_ELEMENT_BUSHING, WS_ELEMENT_POTENTIAL, 6, K6_COUPLED,
         0, 1, 0},
        {"bushing invariant, isotropic rotation", WS_ELEMENT_BUSHING, WS_ELEMENT_INVARIANT, 6,
         K6_ISO_ROT, 0, 1, 0},
        /* Not conservative at large rotations: reported, to show why the potential form is. */
        {"angular spring invariant, orthotropic", WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_INVARIANT,
         3, K3_ROT, 0, 0, 0},
        {"angular spring attached, orthotropic", WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_ATTACHED, 3,
         K3_ROT, 0, 0, 0},
    };
    const double h = 1e-4;
    const int steps = 40000, win = steps / 10;
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        const energy_case *ec = &cases[c];
        pair_scene p = make_pair(h, ec->type == WS_ELEMENT_ROD);
        ws_law_id L = law(p.w, ec->dim, WS_LAW_LINEAR_ELASTIC, ec->k, 0, ec->K, NULL);
        ws_element_id e = element(p.w, ec->type, ec->form, p.a, p.b, L, p.pa, p.pb);
        /* The fastest relative mode: the largest stiffness entry (for the rod EA/l0) times the
         * sum of the two bodies' compliances at the points, 1/m + r^2/J_min (translation) or
         * 1/J_min (rotation); J_min = 0.0054 kg m^2 (A) and 0.0125 kg m^2 (B). */
        double ja = 2.0 / 12 * (0.15 * 0.15 + 0.1 * 0.1), jb = 3.0 / 12 * (0.1 * 0.1 + 0.2 * 0.2);
        double wt = 1.0 / 2.0 + dot(p.pa, p.pa) / ja + 1.0 / 3.0 + dot(p.pb, p.pb) / jb;
        double jmin = 1.0 / (1.0 / ja + 1.0 / jb);
        double omega2 = 0.0;
        if (ec->type == WS_ELEMENT_ROD) {
            /* Made before stir(): unstrained, so l0 is the distance between the points now. */
            ws_element_output o0 = out_of(p.w, e);
            omega2 = ec->k / norm(sub(o0.point2, o0.point1)) * wt;
        } else {
            for (int i = 0; i < ec->dim * ec->dim; i++) {
                double kk = ec->K ? fabs(ec->K[i]) : (i % (ec->dim + 1) == 0 ? ec->k : 0.0);
                int rot =
                    ec->type == WS_ELEMENT_ANGULAR_SPRING || (i / ec->dim >= 3 && i % ec->dim >= 3);
                omega2 = fmax(omega2, kk * (rot ? 1.0 / jmin : wt));
            }
        }
        stir_by(&p, ec->gentle);
        double omh = sqrt(omega2) * h;
        double E0 = energy(p.w), worst = 0.0, first = 0.0, last = 0.0, turn = 0.0;
        for (int s = 1; s <= steps; s++) {
            OK(p.w, ws_world_step(p.w));
            double E = energy(p.w);
            turn = fmax(turn, relative_angle(&p));
            worst = fmax(worst, fabs(E - E0));
            if (s <= win)
                first += E / win;
            if (s > steps - win)
                last += E / win;
        }
        double drift = fabs(last - first);
        ws_world_stats wst;
        ck_ok(p.w, ws_world_get_stats(p.w, &wst));
        ck_assert_uint_eq(wst.candidates, 0); /* the boxes never came near each other */
        report("energy, %s: E0 = %.6f J, max |E - E0| = %.3e E0 (bound omega h = %.3e), drift of "
               "the mean %.3e E0; relative rotation up to %.2f rad",
               ec->name, E0, worst / E0, omh, drift / E0, turn);
        if (ec->check) {
            if (ec->type != WS_ELEMENT_ROD) /* a rod has no frame */
                ck_assert_msg(turn < 3.0, "%s: relative rotation %g reached pi", ec->name, turn);
            ck_assert_msg(worst <= omh * E0, "%s: |E - E0| = %g > %g", ec->name, worst, omh * E0);
            ck_assert_msg(drift <= 0.05 * omh * E0, "%s: drift %g > %g", ec->name, drift,
                          0.05 * omh * E0);
        }
        ws_world_destroy(p.w);
    }
}
END_TEST

/* ======================================================================================== */
/* Balance                                                                                  */
/* ======================================================================================== */

/* Every type and formulation, with an orthotropic (and for the bushing coupled, viscoelastic)
 * law, between two free boxes after stir(): no load acts but the element's, so symplectic Euler
 * keeps the total linear momentum exactly when the two forces cancel, and the angular momentum
 * about the origin when their moments cancel (the kick adds h (r x f + m) per body, the drift
 * keeps r x m v and the free rotor keeps A J omega'). 2000 steps; each step adds round-off of
 * the momenta (|P| ~ 0.7 kg m/s, |H| ~ 0.3 kg m^2/s) and of the loads times h: asserted
 * 1e-12 of the scale, ~ 2000 x a few eps. A load that misses its moment (the turning of an
 * invariant spring's mid frame, say) breaks this by the size of l x f h per step, 1e-4 or more.
 * Also at 20 random configurations per case (200 in all), from the reported loads: force on body 2
 * = -force on body 1 exactly, and p1 x f + m1 + p2 x (-f) + m2 = 0 to 1e-13 of |p| |f| + |m|. */
START_TEST(test_balance)
{
    /* clang-format off */
    static const double C6[36] = {
        3, 0, 0, 0, 0, 0, /**/ 0, 4, 0, 0, 0, 0, /**/ 0, 0, 5, 0, 0, 0,
        0, 0, 0, 0.02, 0, 0, /**/ 0, 0, 0, 0, 0.03, 0, /**/ 0, 0, 0, 0, 0, 0.04,
    };
    /* clang-format on */
    static const double C3[9] = {2, 0, 0, 0, 3, 0, 0, 0, 4};
    static const double C3R[9] = {0.02, 0, 0, 0, 0.03, 0, 0, 0, 0.04};
    const ws_element_type types[4] = {WS_ELEMENT_ROD, WS_ELEMENT_LINEAR_SPRING,
                                      WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_BUSHING};
    const char *tn[4] = {"rod", "linear spring", "angular spring", "bushing"};
    const char *fn[3] = {"invariant", "attached", "potential"};
    double worst_p = 0.0, worst_h = 0.0, worst_m = 0.0;
    for (int t = 0; t < 4; t++) {
        for (int f = 0; f < 3; f++) {
            if (t == 0 && f > 0)
                continue; /* a rod has no frame */
            pair_scene p = make_pair(2e-4, t == 0);
            ws_law_id L;
            if (t == 0)
                L = law(p.w, 1, WS_LAW_LINEAR_VISCOELASTIC, 300, 2, NULL, NULL);
            else if (t == 1)
                L = law(p.w, 3, WS_LAW_LINEAR_VISCOELASTIC, 0, 0, K3_ORTHO, C3);
            else if (t == 2)
                L = law(p.w, 3, WS_LAW_LINEAR_VISCOELASTIC, 0, 0, K3_ROT, C3R);
            else
                L = law(p.w, 6, WS_LAW_LINEAR_VISCOELASTIC, 0, 0, K6_COUPLED, C6);
            ws_element_id e =
                element(p.w, types[t], (ws_element_formulation)f, p.a, p.b, L, p.pa, p.pb);
            stir(&p);
            const ws_body_id bs[2] = {p.a, p.b};
            ws_vec3 P0, H0, P, H;
            momenta(p.w, bs, 2, &P0, &H0);
            OK(p.w, ws_world_step_n(p.w, 2000));
            momenta(p.w, bs, 2, &P, &H);
            double dp = norm(sub(P, P0)) / norm(P0), dh = norm(sub(H, H0)) / norm(H0);
            worst_p = fmax(worst_p, dp);
            worst_h = fmax(worst_h, dh);
            ck_assert_msg(dp <= 1e-12 && dh <= 1e-12,
                          "%s %s: momentum changed by %.3g, angular "
                          "momentum by %.3g (relative)",
                          tn[t], fn[f], dp, dh);
            /* The element did work: the test is not vacuous. */
            ck_assert(norm(out_of(p.w, e).force) + norm(out_of(p.w, e).moment) > 1e-3);

            for (int n = 0; n < 20; n++) {
                ws_pose pa = {rvec(0.3), qrot(rvec(3.0))},
                        pb = {add(v3(0.5, 0, 0), rvec(0.3)), qrot(rvec(3.0))};
                ck_ok(p.w, ws_body_set_pose(p.w, p.a, &pa));
                ck_ok(p.w, ws_body_set_pose(p.w, p.b, &pb));
                ws_vec3 va = rvec(1), wa = rvec(3), vb = rvec(1), wb = rvec(3);
                ck_ok(p.w, ws_body_set_velocity(p.w, p.a, &va, &wa));
                ck_ok(p.w, ws_body_set_velocity(p.w, p.b, &vb, &wb));
                ws_element_output o = out_of(p.w, e);
                ws_vec3 res = add(add(cross(o.point1, o.force), o.moment),
                                  add(cross(o.point2, scale(o.force, -1.0)), o.moment2));
                double sc = (norm(o.point1) + norm(o.point2)) * norm(o.force) + norm(o.moment) +
                            norm(o.moment2);
                worst_m = fmax(worst_m, norm(res) / sc);
                ck_assert_msg(norm(res) <= 1e-13 * sc, "%s %s: moment residual %g of %g", tn[t],
                              fn[f], norm(res), sc);
            }
            ws_world_destroy(p.w);
        }
    }
    report("balance: momentum drift %.2e, angular momentum drift %.2e (relative, 2000 steps); "
           "reported loads' moment residual %.2e",
           worst_p, worst_h, worst_m);
}
END_TEST

/* ======================================================================================== */
/* Loads are minus the energy gradient                                                      */
/* ======================================================================================== */

/* Body 1 the world frame (element axes turned from the world's), body B moved by +-delta along each
 * axis and turned by +-delta about each global axis; the elastic energy U from the output. Central
 * differences: -dU/dx = force on B, -dU/dphi = moment on B about its CoG (moment2 + (p2 - x) x f2).
 * delta = 1e-5 m or rad: truncation delta^2 U''' / 6 ~ 1e-10 of the load, round-off eps U / delta ~
 * 1e-11 of it: asserted 1e-6 of the largest load component. The seed's invariant moment with an
 * orthotropic law differs from the gradient by (H(theta) - I) F, about theta^2/24 of F: reported
 * (and asserted to be well above the tolerance, so the check can tell). */
static double gradient_mismatch(ws_element_type type, ws_element_formulation form, const double *K,
                                int dim, double k)
{
    ws_world *w = world0(1e-4);
    ws_body_id b = box(w, v3(0.1, 0.25, 0.2), 3.0, v3(0.5, 0.1, -0.05), QI, "B");
    ws_law_id L = law(w, dim, WS_LAW_LINEAR_ELASTIC, k, 0, K, NULL);
    ws_element_def d;
    ws_element_def_init(&d);
    d.type = type;
    d.formulation = form;
    d.body1 = WORLD;
    d.body2 = b;
    d.law = L;
    d.point1 = v3(0.1, 0.03, -0.02);
    d.point2 = v3(-0.05, -0.04, 0.06);
    d.frame1 = qrot(v3(0.2, -0.1, 0.3)); /* element axes not the world's */
    d.rest_length = 0.3;
    ws_element_id e;
    ck_ok(w, ws_element_create(w, &d, &e));
    ws_pose base = {v3(0.55, 0.02, 0.04), qrot(v3(1.1, -0.7, 1.3))};
    ck_ok(w, ws_body_set_pose(w, b, &base));
    ws_element_output o = out_of(w, e);
    ws_vec3 f2 = scale(o.force, -1.0);
    ws_vec3 m2 = add(o.moment2, cross(sub(o.point2, base.position), f2));
    const double dl = 1e-5;
    double worst = 0.0, sc = fmax(norm(f2) * 0.3, norm(m2));
    for (int k3 = 0; k3 < 3; k3++) {
        double U[2][2];
        for (int sg = 0; sg < 2; sg++) {
            double s = sg ? -dl : dl;
            ws_pose pp = {add(base.position, scale(unit(k3), s)), base.orientation};
            ck_ok(w, ws_body_set_pose(w, b, &pp));
            U[0][sg] = out_of(w, e).energy;
            ws_pose pr = {base.position, qmul(qrot(scale(unit(k3), s)), base.orientation)};
            ck_ok(w, ws_body_set_pose(w, b, &pr));
            U[1][sg] = out_of(w, e).energy;
        }
        double gf = -(U[0][0] - U[0][1]) / (2 * dl), gm = -(U[1][0] - U[1][1]) / (2 * dl);
        /* Forces in N, moments in N m: a moment is compared on a 0.3 m lever. */
        worst = fmax(worst, fabs(gf - comp(f2, k3)) * 0.3);
        worst = fmax(worst, fabs(gm - comp(m2, k3)));
    }
    ws_world_destroy(w);
    return worst / sc;
}

START_TEST(test_gradient)
{
    struct {
        const char *name;
        ws_element_type type;
        ws_element_formulation form;
        const double *K;
        int dim;
        double k;
        int potential;
    } cases[] = {
        {"rod", WS_ELEMENT_ROD, WS_ELEMENT_INVARIANT, NULL, 1, 300, 1},
        {"linear spring invariant", WS_ELEMENT_LINEAR_SPRING, WS_ELEMENT_INVARIANT, K3_ORTHO, 3, 0,
         1},
        {"linear spring attached", WS_ELEMENT_LINEAR_SPRING, WS_ELEMENT_ATTACHED, K3_ORTHO, 3, 0,
         1},
        {"angular spring potential", WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_POTENTIAL, K3_ROT, 3, 0,
         1},
        {"angular spring invariant, isotropic", WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_INVARIANT,
         NULL, 3, 4, 1},
        {"angular spring attached, isotropic", WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_ATTACHED, NULL,
         3, 4, 1},
        {"bushing potential, coupled", WS_ELEMENT_BUSHING, WS_ELEMENT_POTENTIAL, K6_COUPLED, 6, 0,
         1},
        {"angular spring invariant, orthotropic", WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_INVARIANT,
         K3_ROT, 3, 0, 0},
        {"angular spring attached, orthotropic", WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_ATTACHED,
         K3_ROT, 3, 0, 0},
    };
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        double r =
            gradient_mismatch(cases[c].type, cases[c].form, cases[c].K, cases[c].dim, cases[c].k);
        report("gradient, %s: |load + grad U| = %.2e of the load", cases[c].name, r);
        if (cases[c].potential)
            ck_assert_msg(r <= 1e-6, "%s: %g", cases[c].name, r);
        else
            ck_assert_msg(r >= 1e-3, "%s: %g (expected a visible mismatch)", cases[c].name, r);
    }
}
END_TEST

/* ======================================================================================== */
/* Swapping the bodies                                                                      */
/* ======================================================================================== */

/* The seed's point: the two bodies of pair_scene joined by an angular spring with the
 * orthotropic law diag(2, 4, 8) N m/rad, or a bushing with the coupled 6x6 law, started at a
 * relative rotation of 2.1 rad with spin; run 600 steps of 5e-4 s (0.3 s) with the bodies in
 * one order and in the other (points and frames swapped with them). Invariant and potential
 * forms compute every quantity so that the swap flips exact signs only (docs/elements.md), so
 * the trajectories must agree to the last bit: asserted 1e-12 relative all the same, the
 * brief's bound. The attached form refers the law to body 1's frame: swapping changes the
 * physics, and the states part by O(1) of their size (reported; asserted > 1e-3). */
static void swap_run(ws_element_type type, ws_element_formulation form, int swapped, double out[26])
{
    pair_scene p = make_pair(5e-4, 0);
    ws_law_id L = type == WS_ELEMENT_BUSHING
                      ? law(p.w, 6, WS_LAW_LINEAR_ELASTIC, 0, 0, K6_COUPLED, NULL)
                      : law(p.w, 3, WS_LAW_LINEAR_ELASTIC, 0, 0, K3_ROT, NULL);
    if (swapped)
        element(p.w, type, form, p.b, p.a, L, p.pb, p.pa);
    else
        element(p.w, type, form, p.a, p.b, L, p.pa, p.pb);
    stir(&p);
    OK(p.w, ws_world_step_n(p.w, 600));
    const ws_body_id bs[2] = {p.a, p.b};
    for (int i = 0; i < 2; i++) {
        ws_vec3 r, v, om;
        ws_quat q;
        ck_ok(p.w, ws_body_get_position(p.w, bs[i], &r));
        ck_ok(p.w, ws_body_get_velocity(p.w, bs[i], &v));
        ck_ok(p.w, ws_body_get_angular_velocity(p.w, bs[i], &om));
        ck_ok(p.w, ws_body_get_orientation(p.w, bs[i], &q));
        double *o = out + 13 * i;
        double vals[13] = {r.x, r.y, r.z, v.x, v.y, v.z, om.x, om.y, om.z, q.e0, q.e1, q.e2, q.e3};
        memcpy(o, vals, sizeof vals);
    }
    ws_world_destroy(p.w);
}

START_TEST(test_swap_invariance)
{
    const ws_element_type types[2] = {WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_BUSHING};
    const ws_element_formulation forms[3] = {WS_ELEMENT_INVARIANT, WS_ELEMENT_POTENTIAL,
                                             WS_ELEMENT_ATTACHED};
    const char *fnames[3] = {"invariant", "potential", "attached"};
    for (int t = 0; t < 2; t++) {
        for (int f = 0; f < 3; f++) {
            double a[26], b[26], diff = 0.0, size = 0.0;
            swap_run(types[t], forms[f], 0, a);
            swap_run(types[t], forms[f], 1, b);
            for (int i = 0; i < 26; i++) {
                diff = fmax(diff, fabs(a[i] - b[i]));
                size = fmax(size, fabs(a[i]));
            }
            report("swap, %s %s: largest state difference %.3e (states up to %.3f)",
                   t ? "bushing" : "angular spring", fnames[f], diff, size);
            if (forms[f] == WS_ELEMENT_ATTACHED)
                ck_assert_msg(diff > 1e-3 * size, "attached: the swap changed nothing (%g)", diff);
            else
                ck_assert_msg(diff <= 1e-12 * size, "%s: the swap changed the motion by %g",
                              fnames[f], diff);
        }
    }
}
END_TEST

/* ======================================================================================== */
/* Damping                                                                                  */
/* ======================================================================================== */

/* A viscous bushing (WS_LAW_LINEAR_VISCOUS, C = diag(4, 4, 4 N s/m, 0.025, 0.025, 0.025 N m s))
 * from the world to the 3 kg box of test_torsion_period, at its CoG: (a) moving at 0.3 m/s
 * along x without spin; (b) spinning at 2 rad/s about its z axis (J = 0.0125 kg m^2) in place.
 * The law's time constants are m/c = 0.75 s and J/c = 0.5 s. Symplectic Euler with the damping
 * force taken at the start of the step gives exactly v_n = v0 (1 - c h/m)^n (and the same for
 * the spin about a principal axis): asserted to 1e-12 relative (n multiplications). That is
 * exp(-n c h/m) to within n (c h/m)^2/2 = 1.3e-3 relative at n = 1000, h = 5e-4 s: asserted. */
START_TEST(test_viscous_decay)
{
    /* clang-format off */
    static const double C6[36] = {
        4, 0, 0, 0, 0, 0, /**/ 0, 4, 0, 0, 0, 0, /**/ 0, 0, 4, 0, 0, 0,
        0, 0, 0, 0.025, 0, 0, /**/ 0, 0, 0, 0, 0.025, 0, /**/ 0, 0, 0, 0, 0, 0.025,
    };
    /* clang-format on */
    const double m = 3.0, Jz = m / 12 * (0.01 + 0.04), h = 5e-4;
    const int n = 1000;
    for (int mode = 0; mode < 2; mode++) {
        ws_world *w = world0(h);
        ws_body_id b = box(w, v3(0.1, 0.2, 0.3), m, v3(0, 0, 0), QI, "box");
        ws_law_id L = law(w, 6, WS_LAW_LINEAR_VISCOUS, 0, 0, NULL, C6);
        ws_element_id e = element(w, WS_ELEMENT_BUSHING, WS_ELEMENT_INVARIANT, WORLD, b, L,
                                  v3(0, 0, 0), v3(0, 0, 0));
        ws_vec3 v = mode == 0 ? v3(0.3, 0, 0) : v3(0, 0, 0), om = mode ? v3(0, 0, 2) : v3(0, 0, 0);
        ck_ok(w, ws_body_set_velocity(w, b, &v, &om));
        ws_element_output o = out_of(w, e);
        /* The rate fed to the law: d_dot = 0.3 m/s, or the relative spin 2 rad/s. */
        ck_assert_double_eq_tol(o.strain_rate[mode ? 5 : 0], mode ? 2.0 : 0.3, 1e-15);
        OK(w, ws_world_step_n(w, n));
        double x0 = mode ? 2.0 : 0.3, rate = mode ? 0.025 / Jz : 4.0 / m, got;
        if (mode == 0) {
            ck_ok(w, ws_body_get_velocity(w, b, &v));
            got = v.x;
        } else {
            ck_ok(w, ws_body_get_angular_velocity(w, b, &om));
            got = om.z;
        }
        double disc = x0 * pow(1.0 - rate * h, n), cont = x0 * exp(-rate * n * h);
        report("viscous bushing, %s: %.12f after %.2f s; discrete %.12f (rel %.1e); exp(-t/tau) "
               "%.12f with tau = %.3f s (rel %.2e)",
               mode ? "spin" : "translation", got, n * h, disc, got / disc - 1, cont, 1 / rate,
               got / cont - 1);
        ck_assert_msg(fabs(got / disc - 1) <= 1e-12, "%.17g vs %.17g", got, disc);
        ck_assert_msg(fabs(got / cont - 1) <= 1.5e-3, "%.17g vs %.17g", got, cont);
        ws_world_destroy(w);
    }
}
END_TEST

/* A Kelvin-Voigt bushing (k = 800 N/m, c = 4 N s/m on every displacement axis; rotation
 * 20 N m/rad, 0.1 N m s) from the world to a 2 kg box, pulled 10 mm along y and released: the
 * amplitude decays as exp(-c t/(2m)), rate 1/s. Symplectic Euler multiplies the energy-norm
 * amplitude by sqrt(1 - c h/m) per step, a rate -ln(1 - c h/m)/(2h) = 1.0005/s at h = 5e-4 s.
 * Measured from the first and last positive peaks of the strain over 4 s (25 periods), the
 * peaks taken at samples: each off by at most (Omega h)^2/8 = 1.3e-5 relative, so the rate is
 * within 1e-5/4 s of the discrete one. Asserted: 1e-4/s of the discrete rate, 1e-3/s of the
 * law's 1/s. */
START_TEST(test_viscoelastic_decay)
{
    /* clang-format off */
    static const double K6[36] = {
        800, 0, 0, 0, 0, 0, /**/ 0, 800, 0, 0, 0, 0, /**/ 0, 0, 800, 0, 0, 0,
        0, 0, 0, 20, 0, 0, /**/ 0, 0, 0, 0, 20, 0, /**/ 0, 0, 0, 0, 0, 20,
    };
    /* clang-format on */
    /* clang-format off */
    static const double C6[36] = {
        4, 0, 0, 0, 0, 0, /**/ 0, 4, 0, 0, 0, 0, /**/ 0, 0, 4, 0, 0, 0,
        0, 0, 0, 0.1, 0, 0, /**/ 0, 0, 0, 0, 0.1, 0, /**/ 0, 0, 0, 0, 0, 0.1,
    };
    /* clang-format on */
    const double m = 2.0, h = 5e-4, c = 4.0;
    ws_world *w = world0(h);
    ws_body_id b = box(w, v3(0.1, 0.1, 0.1), m, v3(0, 0, 0), QI, "box");
    ws_law_id L = law(w, 6, WS_LAW_LINEAR_VISCOELASTIC, 0, 0, K6, C6);
    ws_element_id e =
        element(w, WS_ELEMENT_BUSHING, WS_ELEMENT_INVARIANT, WORLD, b, L, v3(0, 0, 0), v3(0, 0, 0));
    ws_pose p = {v3(0, 0.01, 0), QI};
    ck_ok(w, ws_body_set_pose(w, b, &p));
    double prev2 = 0, prev1 = 0, t_first = -1, a_first = 0, t_last = 0, a_last = 0;
    int steps = (int)(4.0 / h);
    for (int s = 1; s <= steps; s++) {
        OK(w, ws_world_step(w));
        double y = out_of(w, e).strain[1];
        if (s >= 3 && prev1 > prev2 && prev1 >= y && prev1 > 0) { /* a peak at step s - 1 */
            if (t_first < 0) {
                t_first = (s - 1) * h;
                a_first = prev1;
            }
            t_last = (s - 1) * h;
            a_last = prev1;
        }
        prev2 = prev1;
        prev1 = y;
    }
    double rate = log(a_first / a_last) / (t_last - t_first);
    double disc = -log(1.0 - c * h / m) / (2 * h), law_rate = c / (2 * m);
    report("Kelvin-Voigt bushing: amplitude decay rate %.6f /s; discrete %.6f /s, law c/(2m) = "
           "%.6f /s",
           rate, disc, law_rate);
    ck_assert_msg(fabs(rate - disc) <= 1e-4, "rate %.8f vs %.8f", rate, disc);
    ck_assert_msg(fabs(rate - law_rate) <= 1e-3, "rate %.8f vs %.8f", rate, law_rate);
    ws_world_destroy(w);
}
END_TEST

/* ======================================================================================== */
/* History, failed steps, determinism                                                       */
/* ======================================================================================== */

/* Fails the step while *fail is set (the drive of a kinematic body, evaluated after the
 * elements' loads: the failure comes after the elements computed their trial strain). */
static int drive_maybe_fail(void *user, double t, ws_pose *pose, ws_vec3 *v, ws_vec3 *om)
{
    (void)t;
    pose->position = v3(0, 0, 0);
    pose->orientation = QI;
    *v = *om = v3(0, 0, 0);
    return *(int *)user;
}

/* A rod with a relaxation law (k_inf = 100 N, one branch k1 = 400 N, tau = 0.05 s) between a
 * static kinematic anchor and a box held at a strain of 0.1 by... nothing: it is a kinematic
 * body too, so the strain is the step eps0 = 0.1 applied at create. The force must then follow
 * F(t) = (k_inf + k1 exp(-t/tau)) eps0, the law's relaxation, exactly at every step (each commit
 * advances the history by the step; evaluating dt after it gives the force at t): asserted to
 * 1e-12 relative. Then a step that fails after the elements' loads (a drive callback) must leave
 * the history untouched: the world after fail + retry equals the world that never failed
 * (same state hash, which covers the law histories, and the same force). */
START_TEST(test_history_and_failed_step)
{
    const double kinf = 100.0, k1 = 400.0, tau = 0.05, h = 1e-3, eps0 = 0.1;
    uint64_t hashes[2];
    double forces[2];
    for (int run = 0; run < 2; run++) {
        ws_world *w = world0(h);
        ws_shape_id s;
        ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &s));
        ws_body_def bd;
        ws_body_def_init(&bd);
        bd.type = WS_BODY_KINEMATIC;
        bd.shape = s;
        ws_body_id anchor, held;
        ck_ok(w, ws_body_create(w, &bd, &anchor));
        bd.position = v3(0.55, 0, 0);
        ck_ok(w, ws_body_create(w, &bd, &held));
        int fail = 0;
        ws_drive_def dd;
        ws_drive_def_init(&dd);
        dd.type = WS_DRIVE_CALLBACK;
        dd.callback = drive_maybe_fail;
        dd.callback_user = &fail;
        ck_ok(w, ws_body_set_drive(w, anchor, &dd));
        ws_law_def ld;
        ws_law_def_init(&ld);
        ld.type = WS_LAW_RELAXATION;
        ld.stiffness = kinf;
        ld.prony_stiffness = &k1;
        ld.prony_time = &tau;
        ld.prony_count = 1;
        ws_law_id L;
        ck_ok(w, ws_law_create(w, &ld, &L));
        size_t ns = 0;
        ck_ok(w, ws_law_get_state_size(w, L, &ns));
        ck_assert_uint_gt(ns, 0); /* a law with history: the test means something */
        ws_element_def d;
        ws_element_def_init(&d);
        d.body1 = anchor;
        d.body2 = held;
        d.law = L;
        d.rest_length = 0.5;
        ws_element_id e;
        ck_ok(w, ws_element_create(w, &d, &e));
        double worst = 0.0;
        for (int k = 1; k <= 200; k++) {
            if (run == 1 && k == 100) {
                uint64_t h0, h1;
                ck_ok(w, ws_world_get_state_hash(w, &h0));
                ws_element_output before = out_of(w, e);
                fail = 1;
                ck_assert_int_eq(ws_world_step(w), WS_ERR_CALLBACK);
                fail = 0;
                ck_ok(w, ws_world_get_state_hash(w, &h1));
                ck_assert(h0 == h1);
                ck_assert(out_of(w, e).law_force[0] == before.law_force[0]);
            }
            OK(w, ws_world_step(w));
            double t = k * h, F = out_of(w, e).law_force[0];
            double Fx = (kinf + k1 * exp(-t / tau)) * eps0;
            worst = fmax(worst, fabs(F / Fx - 1));
        }
        if (run == 0)
            report("relaxing rod: force follows (k_inf + k1 exp(-t/tau)) eps0 to %.2e", worst);
        ck_assert_msg(worst <= 1e-12, "relaxation off by %g", worst);
        ck_ok(w, ws_world_get_state_hash(w, &hashes[run]));
        forces[run] = out_of(w, e).law_force[0];
        ws_world_destroy(w);
    }
    ck_assert(hashes[0] == hashes[1]);
    ck_assert(forces[0] == forces[1]);
}
END_TEST

/* Two identical worlds with one element of each type give the same hash after 500 steps; a
 * world that differs by 1e-9 m at the start does not (so the hash sees the motion). */
static uint64_t mixed_hash(double nudge)
{
    pair_scene p = make_pair(2e-4, 0);
    ws_law_id L1 = law(p.w, 1, WS_LAW_LINEAR_VISCOELASTIC, 300, 1, NULL, NULL);
    ws_law_id L3 = law(p.w, 3, WS_LAW_LINEAR_ELASTIC, 0, 0, K3_ORTHO, NULL);
    ws_law_id L3r = law(p.w, 3, WS_LAW_LINEAR_ELASTIC, 0, 0, K3_ROT, NULL);
    ws_law_id L6 = law(p.w, 6, WS_LAW_LINEAR_ELASTIC, 0, 0, K6_COUPLED, NULL);
    element(p.w, WS_ELEMENT_ROD, WS_ELEMENT_INVARIANT, p.a, p.b, L1, ROD_A, ROD_B);
    element(p.w, WS_ELEMENT_LINEAR_SPRING, WS_ELEMENT_ATTACHED, p.a, p.b, L3, p.pa, p.pb);
    element(p.w, WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_POTENTIAL, p.b, p.a, L3r, p.pb, p.pa);
    element(p.w, WS_ELEMENT_BUSHING, WS_ELEMENT_INVARIANT, p.a, WORLD, L6, p.pa, v3(0.1, 0, 0));
    stir(&p);
    ws_pose pb;
    ck_ok(p.w, ws_body_get_position(p.w, p.b, &pb.position));
    ck_ok(p.w, ws_body_get_orientation(p.w, p.b, &pb.orientation));
    pb.position.x += nudge;
    ck_ok(p.w, ws_body_set_pose(p.w, p.b, &pb));
    OK(p.w, ws_world_step_n(p.w, 500));
    uint64_t hsh;
    ck_ok(p.w, ws_world_get_state_hash(p.w, &hsh));
    ws_world_destroy(p.w);
    return hsh;
}

START_TEST(test_determinism_hash)
{
    uint64_t a = mixed_hash(0.0), b = mixed_hash(0.0), c = mixed_hash(1e-9);
    ck_assert(a == b);
    ck_assert(a != c);
}
END_TEST

/* ======================================================================================== */
/* API                                                                                      */
/* ======================================================================================== */

static void expect_err(ws_world *w, ws_status got, ws_status want, const char *needle)
{
    ck_assert_msg(got == want, "got %s, want %s (%s)", ws_status_string(got),
                  ws_status_string(want), ws_world_last_error(w));
    if (needle)
        ck_assert_msg(strstr(ws_world_last_error(w), needle), "'%s' not in '%s'", needle,
                      ws_world_last_error(w));
}

START_TEST(test_bad_defs)
{
    ws_world *w = world0(1e-3);
    ws_body_id a = box(w, v3(0.1, 0.1, 0.1), 1, v3(0, 0, 0), QI, "a");
    ws_body_id b = box(w, v3(0.1, 0.1, 0.1), 1, v3(1, 0, 0), QI, "b");
    ws_law_id L1 = law(w, 1, WS_LAW_LINEAR_ELASTIC, 100, 0, NULL, NULL);
    ws_law_id L3 = law(w, 3, WS_LAW_LINEAR_ELASTIC, 100, 0, NULL, NULL);
    ws_law_id L6 = law(w, 6, WS_LAW_LINEAR_ELASTIC, 100, 0, NULL, NULL);
    ws_element_id e = {12345};
    ws_element_def d;

    /* An uninitialised Def, a NULL Def, a NULL output. */
    memset(&d, 0, sizeof d);
    expect_err(w, ws_element_create(w, &d, &e), WS_ERR_UNINITIALIZED_DEF, "ws_element_def_init");
    ck_assert(e.bits == 0);
    expect_err(w, ws_element_create(w, NULL, &e), WS_ERR_INVALID_ARGUMENT, NULL);
    ws_element_def_init(&d);
    d.body1 = a;
    d.body2 = b;
    d.law = L1;
    expect_err(w, ws_element_create(w, &d, NULL), WS_ERR_INVALID_ARGUMENT, NULL);
    ck_assert_int_eq(ws_element_create(NULL, &d, &e), WS_ERR_INVALID_ARGUMENT);
    ws_element_def_init_sized(NULL, sizeof(ws_element_def)); /* ignored */

    /* Law dims: each type against the wrong ones. */
    const ws_element_type types[4] = {WS_ELEMENT_ROD, WS_ELEMENT_LINEAR_SPRING,
                                      WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_BUSHING};
    const ws_law_id laws[3] = {L1, L3, L6};
    const int dims[3] = {1, 3, 6};
    for (int t = 0; t < 4; t++) {
        for (int l = 0; l < 3; l++) {
            ws_element_def_init(&d);
            d.type = types[t];
            d.body1 = a;
            d.body2 = b;
            d.law = laws[l];
            int need = t == 0 ? 1 : t == 3 ? 6 : 3;
            ws_status s = ws_element_create(w, &d, &e);
            if (dims[l] == need) {
                ck_ok(w, s);
                ck_ok(w, ws_element_destroy(w, e));
            } else {
                char msg[64];
                snprintf(msg, sizeof msg, "needs a law of dim %d", need);
                expect_err(w, s, WS_ERR_INVALID_ARGUMENT, msg);
            }
        }
    }

    /* Bodies: both the world, the same twice, stale ones; a missing or stale law. */
    ws_element_def_init(&d);
    d.law = L1;
    d.point2 = v3(1, 0, 0);
    expect_err(w, ws_element_create(w, &d, &e), WS_ERR_INVALID_ARGUMENT, "both the world");
    d.body1 = d.body2 = a;
    expect_err(w, ws_element_create(w, &d, &e), WS_ERR_INVALID_ARGUMENT, "same body");
    d.body2 = (ws_body_id){a.bits ^ 0x10000000ull};
    expect_err(w, ws_element_create(w, &d, &e), WS_ERR_STALE_HANDLE, "body2");
    d.body2 = b;
    d.law = (ws_law_id){0};
    expect_err(w, ws_element_create(w, &d, &e), WS_ERR_STALE_HANDLE, "law");
    d.law = L1;

    /* Numbers. */
    d.point1.y = NAN;
    expect_err(w, ws_element_create(w, &d, &e), WS_ERR_INVALID_ARGUMENT, "finite");
    d.point1.y = 0;
    d.frame1 = (ws_quat){INFINITY, 0, 0, 0};
    expect_err(w, ws_element_create(w, &d, &e), WS_ERR_INVALID_ARGUMENT, "frame1");
    d.frame1 = (ws_quat){0, 0, 0, 0};
    d.rest_length = NAN;
    expect_err(w, ws_element_create(w, &d, &e), WS_ERR_INVALID_ARGUMENT, "rest_length");
    d.rest_length = 0;
    d.type = (ws_element_type)9;
    expect_err(w, ws_element_create(w, &d, &e), WS_ERR_INVALID_ARGUMENT, "type");
    d.type = WS_ELEMENT_ROD;
    d.formulation = (ws_element_formulation)-1;
    expect_err(w, ws_element_create(w, &d, &e), WS_ERR_INVALID_ARGUMENT, "formulation");
    d.formulation = WS_ELEMENT_INVARIANT;
    /* A rod whose points coincide needs a rest length. */
    d.point1 = v3(0, 0, 0);
    d.point2 = v3(-1, 0, 0);
    expect_err(w, ws_element_create(w, &d, &e), WS_ERR_INVALID_ARGUMENT, "rest_length");
    d.rest_length = 0.2;
    ck_ok(w, ws_element_create(w, &d, &e));
    ck_assert_double_eq_tol(out_of(w, e).strain[0], -1.0, 1e-15);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_stale_and_in_use)
{
    ws_world *w = world0(1e-3), *other = world0(1e-3);
    ws_body_id a = box(w, v3(0.1, 0.1, 0.1), 1, v3(0, 0, 0), QI, "a");
    ws_body_id b = box(w, v3(0.1, 0.1, 0.1), 1, v3(1, 0, 0), QI, "b");
    ws_law_id L = law(w, 1, WS_LAW_LINEAR_ELASTIC, 100, 0, NULL, NULL);
    ws_element_def d;
    ws_element_def_init(&d);
    d.body1 = a;
    d.body2 = b;
    d.law = L;
    d.name = "strap";
    int mine = 7;
    d.user_data = &mine;
    ws_element_id e, e2;
    ck_ok(w, ws_element_create(w, &d, &e));
    ck_assert_int_eq(ws_element_is_valid(w, e), 1);
    ck_assert_str_eq(ws_element_get_name(w, e), "strap");
    ck_assert_ptr_eq(ws_element_get_user_data(w, e), &mine);

    /* In use: the bodies and the law stay while the element lives. */
    expect_err(w, ws_body_destroy(w, b), WS_ERR_IN_USE, "strap");
    expect_err(w, ws_law_destroy(w, L), WS_ERR_IN_USE, NULL);
    ck_assert_int_eq(ws_body_is_valid(w, b), 1);
    OK(w, ws_world_step_n(w, 10));

    /* Ids of the wrong kind, of another world, null, destroyed. */
    ws_element_output o;
    ws_element_id wrong_kind = {a.bits};
    expect_err(w, ws_element_get_output(w, wrong_kind, &o), WS_ERR_STALE_HANDLE, "element");
    ck_assert_int_eq(ws_element_is_valid(w, wrong_kind), 0);
    ws_body_id oa = box(other, v3(0.1, 0.1, 0.1), 1, v3(0, 0, 0), QI, "oa");
    ws_law_id oL = law(other, 1, WS_LAW_LINEAR_ELASTIC, 100, 0, NULL, NULL);
    ws_element_def od;
    ws_element_def_init(&od);
    od.body2 = oa;
    od.law = oL;
    od.point1 = v3(1, 0, 0);
    ws_element_id foreign;
    ck_ok(other, ws_element_create(other, &od, &foreign));
    expect_err(w, ws_element_get_output(w, foreign, &o), WS_ERR_STALE_HANDLE, "this world");
    expect_err(w, ws_element_destroy(w, foreign), WS_ERR_STALE_HANDLE, NULL);
    ck_assert_int_eq(ws_element_is_valid(w, foreign), 0);
    expect_err(w, ws_element_get_output(w, (ws_element_id){0}, &o), WS_ERR_STALE_HANDLE, "null");
    expect_err(w, ws_element_get_output(w, e, NULL), WS_ERR_INVALID_ARGUMENT, NULL);
    /* A body of another world in a Def. */
    d.body2 = oa;
    expect_err(w, ws_element_create(w, &d, &e2), WS_ERR_STALE_HANDLE, "body2");
    d.body2 = b;

    ck_ok(w, ws_element_destroy(w, e));
    ck_assert_int_eq(ws_element_is_valid(w, e), 0);
    expect_err(w, ws_element_get_output(w, e, &o), WS_ERR_STALE_HANDLE, "destroyed");
    expect_err(w, ws_element_destroy(w, e), WS_ERR_STALE_HANDLE, "destroyed");
    ck_assert_str_eq(ws_element_get_name(w, e), "");
    ck_assert_ptr_null(ws_element_get_user_data(w, e));
    /* The slot is reused with a new generation: the old id stays stale. */
    ck_ok(w, ws_element_create(w, &d, &e2));
    ck_assert(e2.bits != e.bits);
    ck_assert_int_eq(ws_element_is_valid(w, e), 0);
    ck_ok(w, ws_element_destroy(w, e2));
    /* Nothing uses them now. */
    ck_ok(w, ws_body_destroy(w, b));
    ck_ok(w, ws_law_destroy(w, L));
    ws_world_destroy(w);
    ws_world_destroy(other);
}
END_TEST

START_TEST(test_bulk_copies)
{
    pair_scene p = make_pair(1e-3, 0);
    ws_law_id L1 = law(p.w, 1, WS_LAW_LINEAR_ELASTIC, 300, 0, NULL, NULL);
    ws_law_id L6 = law(p.w, 6, WS_LAW_LINEAR_ELASTIC, 0, 0, K6_COUPLED, NULL);
    ws_element_id e[3];
    e[0] = element(p.w, WS_ELEMENT_ROD, WS_ELEMENT_INVARIANT, p.a, p.b, L1, ROD_A, ROD_B);
    e[1] = element(p.w, WS_ELEMENT_BUSHING, WS_ELEMENT_INVARIANT, p.a, p.b, L6, p.pa, p.pb);
    e[2] =
        element(p.w, WS_ELEMENT_BUSHING, WS_ELEMENT_ATTACHED, WORLD, p.b, L6, v3(0.4, 0, 0), p.pb);
    stir(&p);
    OK(p.w, ws_world_step_n(p.w, 20));
    size_t n = 99;
    ck_ok(p.w, ws_world_copy_element_ids(p.w, NULL, 0, &n));
    ck_assert_uint_eq(n, 3);
    ck_ok(p.w, ws_world_copy_element_outputs(p.w, NULL, 0, &n));
    ck_assert_uint_eq(n, 3);
    ws_element_id ids[3];
    ws_element_output outs[3], one;
    expect_err(p.w, ws_world_copy_element_ids(p.w, ids, 2, &n), WS_ERR_BUFFER_TOO_SMALL, NULL);
    ck_assert_uint_eq(n, 3);
    expect_err(p.w, ws_world_copy_element_outputs(p.w, outs, 1, &n), WS_ERR_BUFFER_TOO_SMALL, NULL);
    expect_err(p.w, ws_world_copy_element_ids(p.w, NULL, 2, &n), WS_ERR_INVALID_ARGUMENT, NULL);
    expect_err(p.w, ws_world_copy_element_outputs(p.w, outs, 3, NULL), WS_ERR_INVALID_ARGUMENT,
               NULL);
    ck_ok(p.w, ws_world_copy_element_ids(p.w, ids, 3, &n));
    ck_ok(p.w, ws_world_copy_element_outputs(p.w, outs, 3, &n));
    double sum = 0.0;
    for (int k = 0; k < 3; k++) {
        ck_assert(ids[k].bits == e[k].bits);
        one = out_of(p.w, ids[k]);
        ck_assert(memcmp(&one, &outs[k], sizeof one) == 0);
        sum += one.energy;
    }
    ck_assert_int_eq(outs[0].dim, 1);
    ck_assert_int_eq(outs[1].type, WS_ELEMENT_BUSHING);
    ck_assert(outs[0].strain[1] == 0.0 && outs[1].strain[5] != 0.0);
    double total;
    ck_ok(p.w, ws_world_get_element_energy(p.w, &total));
    ck_assert_double_eq_tol(total, sum, 1e-12 * fabs(sum));
    ws_world_destroy(p.w);
}
END_TEST

/* A user law has no known energy: the total is refused, the step still runs. */
static int user_law(void *user, int dim, const double *u, const double *ud, double t, double *F,
                    double *dFdu, double *dFdud)
{
    (void)user;
    (void)ud;
    (void)t;
    (void)dFdud;
    for (int i = 0; i < dim; i++) {
        F[i] = 50.0 * u[i];
        dFdu[i * dim + i] = 50.0;
    }
    return *(int *)user;
}

START_TEST(test_user_law)
{
    ws_world *w = world0(1e-3);
    ws_body_id b = box(w, v3(0.1, 0.1, 0.1), 1, v3(0, 0, 0), QI, "b");
    int fail = 0;
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_USER;
    ld.dim = 3;
    ld.stiffness = 50.0;
    ld.user_fn = user_law;
    ld.user_data = &fail;
    ws_law_id L;
    ck_ok(w, ws_law_create(w, &ld, &L));
    ws_element_id e = element(w, WS_ELEMENT_LINEAR_SPRING, WS_ELEMENT_INVARIANT, WORLD, b, L,
                              v3(0.01, 0, 0), v3(0, 0, 0));
    OK(w, ws_world_step_n(w, 10));
    ck_assert(out_of(w, e).law_force[0] != 0.0);
    double en;
    expect_err(w, ws_world_get_element_energy(w, &en), WS_ERR_UNSUPPORTED, "energy");
    ck_assert(isnan(out_of(w, e).energy));
    uint64_t h0, h1;
    ck_ok(w, ws_world_get_state_hash(w, &h0));
    fail = 1;
    expect_err(w, ws_world_step(w), WS_ERR_CALLBACK, "element");
    ws_element_output o;
    expect_err(w, ws_element_get_output(w, e, &o), WS_ERR_CALLBACK, NULL);
    ck_ok(w, ws_world_get_state_hash(w, &h1));
    ck_assert(h0 == h1);
    fail = 0;
    OK(w, ws_world_step(w));
    ws_world_destroy(w);
}
END_TEST

/* Element creation under every failure point of the allocator: WS_ERR_OUT_OF_MEMORY with
 * nothing changed (bytes in use as before, the world still steps), until it succeeds; every
 * byte back when the world goes. Then the bytes of an element (its block, its law history, its
 * name) come back when it is destroyed. */
START_TEST(test_out_of_memory_and_bytes)
{
    /* variant 0: the first element of the world (the pool and slot table grow: the growth may
     * stay after a failure, and is freed with the world); variant 1: a slot free for reuse, so a
     * failure must leave the bytes exactly as they were. */
    for (int variant = 0; variant < 2; variant++) {
        int done = 0;
        for (long n = 0; n < 200 && !done; n++) {
            test_alloc a = {.allocs_left = -1};
            ws_world_def wd;
            ws_world_def_init(&wd);
            test_alloc_install(&wd, &a);
            ws_world *w = NULL;
            ck_assert_int_eq(ws_world_create(&wd, &w), WS_OK);
            ws_body_id b = box(w, v3(0.1, 0.1, 0.1), 1, v3(0, 0, 0), QI, "b");
            double k1 = 10, tau = 0.1;
            ws_law_def ld;
            ws_law_def_init(&ld);
            ld.type = WS_LAW_RELAXATION;
            ld.dim = 6;
            ld.stiffness = 100;
            ld.prony_stiffness = &k1;
            ld.prony_time = &tau;
            ld.prony_count = 1;
            ws_law_id L;
            ck_ok(w, ws_law_create(w, &ld, &L));
            ws_element_def d;
            ws_element_def_init(&d);
            d.type = WS_ELEMENT_BUSHING;
            d.body2 = b;
            d.law = L;
            d.name = "mount";
            ws_element_id e = {777};
            if (variant == 1) {
                ck_ok(w, ws_element_create(w, &d, &e));
                ck_ok(w, ws_element_destroy(w, e));
            }
            ws_world_stats st0, st1;
            ck_ok(w, ws_world_get_stats(w, &st0));
            a.allocs_left = n;
            e.bits = 777;
            ws_status s = ws_element_create(w, &d, &e);
            a.allocs_left = -1;
            if (s == WS_OK) {
                done = 1;
                ck_assert_int_eq(ws_element_is_valid(w, e), 1);
                OK(w, ws_world_step_n(w, 5));
                /* Destroy and create again: the pool and slot table stay, the element's own bytes
                 * come back exactly. */
                ck_ok(w, ws_element_destroy(w, e));
                ck_ok(w, ws_world_get_stats(w, &st0));
                ck_ok(w, ws_element_create(w, &d, &e));
                ck_ok(w, ws_element_destroy(w, e));
                ck_ok(w, ws_world_get_stats(w, &st1));
                ck_assert_uint_eq(st1.bytes_in_use, st0.bytes_in_use);
            } else {
                expect_err(w, s, WS_ERR_OUT_OF_MEMORY, "memory");
                ck_assert(e.bits == 0);
                ck_ok(w, ws_world_get_stats(w, &st1));
                if (variant == 1)
                    ck_assert_uint_eq(st1.bytes_in_use, st0.bytes_in_use);
                OK(w, ws_world_step_n(w, 2));
                ck_ok(w, ws_law_destroy(w, L)); /* no user was counted */
            }
            ws_world_destroy(w);
            ck_assert_msg(a.live == 0 && a.bytes == 0, "N = %ld: %ld blocks, %lld bytes left", n,
                          a.live, a.bytes);
        }
        ck_assert(done);
    }
}
END_TEST

/* A warm step with elements allocates nothing. */
START_TEST(test_step_allocates_nothing)
{
    test_alloc a = {.allocs_left = -1};
    ws_world_def wd;
    ws_world_def_init(&wd);
    wd.gravity = v3(0, 0, 0);
    test_alloc_install(&wd, &a);
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&wd, &w), WS_OK);
    ws_body_id b = box(w, v3(0.1, 0.1, 0.1), 1, v3(0, 0, 0), QI, "b");
    ws_law_id L = law(w, 6, WS_LAW_LINEAR_VISCOELASTIC, 1000, 1, NULL, NULL);
    element(w, WS_ELEMENT_BUSHING, WS_ELEMENT_POTENTIAL, WORLD, b, L, v3(0.05, 0, 0), v3(0, 0, 0));
    OK(w, ws_world_step_n(w, 10));
    a.allocs_left = 0;
    OK(w, ws_world_step_n(w, 100));
    a.allocs_left = -1;
    ws_world_destroy(w);
    ck_assert(a.live == 0 && a.bytes == 0);
}
END_TEST

/* Global attachment and automatic frames: a bushing between two boxes turned differently, made
 * at a global point with global axes, starts with zero strain, reports the frame it was given,
 * and its points where they were put. The stable-step estimate falls to the explicit limit of a
 * stiff rod on a 2 kg box, 2/omega, omega = sqrt(k/m) (the rod at the CoG: no lever). */
START_TEST(test_attachment_and_stable_dt)
{
    ws_world *w = world0(1e-4);
    ws_body_id a = box(w, v3(0.2, 0.2, 0.2), 2, v3(0, 0, 0), qrot(v3(0.3, 0, 0)), "a");
    ws_body_id b = box(w, v3(0.2, 0.2, 0.2), 2, v3(0, 0, 0.5), qrot(v3(0, 0.4, 0.2)), "b");
    ws_law_id L6 = law(w, 6, WS_LAW_LINEAR_ELASTIC, 1000, 0, NULL, NULL);
    ws_element_def d;
    ws_element_def_init(&d);
    d.type = WS_ELEMENT_BUSHING;
    d.body1 = a;
    d.body2 = b;
    d.law = L6;
    d.global_attachment = 1;
    d.point1 = d.point2 = v3(0.01, 0.02, 0.25);
    d.frame1 = qrot(v3(0, 0, 0.7));
    ws_element_id e;
    ck_ok(w, ws_element_create(w, &d, &e));
    ws_element_output o = out_of(w, e);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(o.strain[i], 0.0, 1e-15);
    ck_assert_double_eq_tol(norm(sub(o.point1, d.point1)), 0.0, 1e-15);
    ck_assert_double_eq_tol(norm(sub(o.point2, d.point2)), 0.0, 1e-15);
    ws_quat q = o.frame, f = d.frame1;
    double dq = fmin(fabs(q.e0 - f.e0) + fabs(q.e1 - f.e1) + fabs(q.e2 - f.e2) + fabs(q.e3 - f.e3),
                     fabs(q.e0 + f.e0) + fabs(q.e1 + f.e1) + fabs(q.e2 + f.e2) + fabs(q.e3 + f.e3));
    ck_assert_msg(dq <= 4e-15, "frame off by %g", dq);
    ck_ok(w, ws_element_destroy(w, e));

    double before, after;
    ck_ok(w, ws_world_estimate_stable_dt(w, &before));
    ws_law_id L1 = law(w, 1, WS_LAW_LINEAR_ELASTIC, 1e7, 0, NULL, NULL);
    ws_element_def_init(&d);
    d.body1 = WORLD;
    d.body2 = a;
    d.law = L1;
    d.point1 = v3(0, 0, -0.1);
    d.rest_length = 0.1; /* k = 1e8 N/m */
    ck_ok(w, ws_element_create(w, &d, &e));
    ck_ok(w, ws_world_estimate_stable_dt(w, &after));
    double expect = 2.0 / sqrt(1e8 / 2.0);
    report("stable dt: %.3e s without the rod, %.3e s with it (2/omega = %.3e s)", before, after,
           expect);
    ck_assert_double_eq_tol(after, expect, 1e-12 * expect);
    ws_world_destroy(w);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("element");
    /* Timeouts: several times the run time of a debugoptimized build; the sanitizer and valgrind
     * runs are slower by 10-50x, hence the margins. */
    add_case(s, "rod_period", test_rod_period, 120);
    add_case(s, "torsion_period", test_torsion_period, 300);
    add_case(s, "energy_conservation", test_energy_conservation, 600);
    add_case(s, "balance", test_balance, 300);
    add_case(s, "gradient", test_gradient, 60);
    add_case(s, "swap_invariance", test_swap_invariance, 120);
    add_case(s, "viscous_decay", test_viscous_decay, 60);
    add_case(s, "viscoelastic_decay", test_viscoelastic_decay, 120);
    add_case(s, "history_and_failed_step", test_history_and_failed_step, 60);
    add_case(s, "determinism_hash", test_determinism_hash, 60);
    add_case(s, "bad_defs", test_bad_defs, 30);
    add_case(s, "stale_and_in_use", test_stale_and_in_use, 30);
    add_case(s, "bulk_copies", test_bulk_copies, 30);
    add_case(s, "user_law", test_user_law, 30);
    add_case(s, "out_of_memory_and_bytes", test_out_of_memory_and_bytes, 120);
    add_case(s, "step_allocates_nothing", test_step_allocates_nothing, 30);
    add_case(s, "attachment_and_stable_dt", test_attachment_and_stable_dt, 30);
    return run_suite(s);
}
