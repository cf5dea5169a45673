/* Unit tests of the internal math module (lib/math/wmath.h): Euler parameters against
 * independent formulas, and the small dense matrix routines.
 *
 * Tolerances: every quantity here is a handful of flops on numbers of size <= 1 (rotations) or
 * on well-conditioned matrices, so round-off is a few eps = 2.2e-16 each; the assertions use
 * 1e-14 (rotations) or cond x 1e-14 (inverses), i.e. ~10-50 eps. A wrong sign or a dropped term
 * in any of these formulas produces an O(1) error for random inputs. */
#include "helpers.h"

#include "math/wmath.h"

/* Deterministic pseudo-random numbers (xorshift64*), so a failure is reproducible. */
static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double urand(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}
static double srand1(void) { return 2.0 * urand() - 1.0; }
static v3 rand_unit(void)
{
    for (;;) {
        v3 a = v3_make(srand1(), srand1(), srand1());
        double n = v3_norm(a);
        if (n > 0.1 && n <= 1.0)
            return v3_scale(a, 1.0 / n);
    }
}

static double m3_maxdiff(const m3 *a, const m3 *b)
{
    double d = 0.0;
    for (int i = 0; i < 9; i++)
        d = fmax(d, fabs(a->m[i] - b->m[i]));
    return d;
}

/* Rodrigues' rotation formula, written out independently of eq. 6:
 *   R = cos(phi) I + sin(phi) u~ + (1 - cos(phi)) u u^T. */
static m3 rodrigues(v3 u, double phi)
{
    double c = cos(phi), s = sin(phi), k = 1.0 - c;
    m3 r = {{c + k * u.x * u.x, k * u.x * u.y - s * u.z, k * u.x * u.z + s * u.y,
             k * u.y * u.x + s * u.z, c + k * u.y * u.y, k * u.y * u.z - s * u.x,
             k * u.z * u.x - s * u.y, k * u.z * u.y + s * u.x, c + k * u.z * u.z}};
    return r;
}

/* Eq. 4-6: the matrix of qt_from_axis_angle(u, phi) is Rodrigues' matrix for 2000 random axes and
 * angles in (-2 pi, 2 pi); it is orthonormal with det +1 and rotates u onto itself. */
START_TEST(test_quat_matrix_vs_rodrigues)
{
    double worst = 0.0, worst_orth = 0.0, worst_det = 0.0, worst_axis = 0.0;
    for (int n = 0; n < 2000; n++) {
        v3 u = rand_unit();
        double phi = 2.0 * WS_PI * srand1();
        qt q = qt_from_axis_angle(u, phi);
        m3 a = qt_to_m3(q), r = rodrigues(u, phi);
        worst = fmax(worst, m3_maxdiff(&a, &r));
        m3 at = m3_transpose(&a), aat = m3_mul(&a, &at), id = m3_identity();
        worst_orth = fmax(worst_orth, m3_maxdiff(&aat, &id));
        worst_det = fmax(worst_det, fabs(m3_det(&a) - 1.0));
        worst_axis = fmax(worst_axis, v3_norm(v3_sub(m3_mul_v(&a, u), u)));
    }
    ck_assert_msg(worst < 1e-14, "eq. 6 differs from Rodrigues by %.3g", worst);
    ck_assert_msg(worst_orth < 1e-14, "A A^T - I = %.3g", worst_orth);
    ck_assert_msg(worst_det < 1e-14, "det A - 1 = %.3g", worst_det);
    ck_assert_msg(worst_axis < 1e-14, "the axis is not fixed: %.3g", worst_axis);
    /* A known case: 90 deg about z takes x to y. */
    m3 a = qt_to_m3(qt_from_axis_angle(v3_make(0, 0, 1), 0.5 * WS_PI));
    v3 y = m3_mul_v(&a, v3_make(1, 0, 0));
    ck_assert_msg(fabs(y.x) < 1e-15 && fabs(y.y - 1.0) < 1e-15 && fabs(y.z) < 1e-15,
                  "Rz(90) x = (%g, %g, %g)", y.x, y.y, y.z);
}
END_TEST

/* qt_from_rotvec(phi) is the rotation by |phi| about phi/|phi|: equal to qt_from_axis_angle
 * above its small-angle switch (1e-8 rad), continuous across it (the series sin(a/2)/a =
 * 1/2 - a^2/48 is exact to 1e-33 there), the identity at 0, and unit. */
START_TEST(test_quat_from_rotvec)
{
    for (int n = 0; n < 500; n++) {
        v3 u = rand_unit();
        double a = 3.0 * urand() + 1e-6;
        qt p = qt_from_rotvec(v3_scale(u, a)), q = qt_from_axis_angle(u, a);
        ck_assert_msg(fabs(p.e0 - q.e0) + fabs(p.e1 - q.e1) + fabs(p.e2 - q.e2) +
                              fabs(p.e3 - q.e3) < 1e-15 * 4,
                      "rotvec != axis-angle at angle %g", a);
    }
    v3 u = rand_unit();
    const double a_lo = 1e-8 * (1 - 1e-12), a_hi = 1e-8 * (1 + 1e-12);
    qt below = qt_from_rotvec(v3_scale(u, a_lo)), above = qt_from_rotvec(v3_scale(u, a_hi));
    qt ex_lo = qt_from_axis_angle(u, a_lo), ex_hi = qt_from_axis_angle(u, a_hi);
    /* Each side equals the exact rotation to relative round-off (|e| ~ 5e-9). */
    double d_lo = fabs(below.e1 - ex_lo.e1) + fabs(below.e2 - ex_lo.e2) + fabs(below.e3 - ex_lo.e3);
    double d_hi = fabs(above.e1 - ex_hi.e1) + fabs(above.e2 - ex_hi.e2) + fabs(above.e3 - ex_hi.e3);
    ck_assert_msg(d_lo < 1e-15 * 5e-9 * 3 && d_hi < 1e-15 * 5e-9 * 3,
                  "wrong at the small-angle switch: %.3g below, %.3g above", d_lo, d_hi);
    ck_assert_msg(fabs(below.e0 - ex_lo.e0) < 2.3e-16, "e0 below the switch: %.3g",
                  below.e0 - ex_lo.e0);
    ck_assert_msg(fabs(qt_norm(below) - 1.0) < 1e-15, "small-angle quaternion not unit");
    qt z = qt_from_rotvec(v3_make(0, 0, 0));
    ck_assert(z.e0 == 1.0 && z.e1 == 0.0 && z.e2 == 0.0 && z.e3 == 0.0);
}
END_TEST

/* qt_mul composes rotations: A(a (x) b) = A(a) A(b) (b first, then a), to round-off; q (x) q* is
 * the identity; the product is associative and keeps |q| = 1. */
START_TEST(test_quat_mul_composition)
{
    double worst = 0.0, worst_assoc = 0.0, worst_norm = 0.0;
    for (int n = 0; n < 1000; n++) {
        qt a = qt_from_axis_angle(rand_unit(), 2 * WS_PI * srand1());
        qt b = qt_from_axis_angle(rand_unit(), 2 * WS_PI * srand1());
        qt c = qt_from_axis_angle(rand_unit(), 2 * WS_PI * srand1());
        m3 ma = qt_to_m3(a), mb = qt_to_m3(b);
        m3 mab = qt_to_m3(qt_mul(a, b)), prod = m3_mul(&ma, &mb);
        worst = fmax(worst, m3_maxdiff(&mab, &prod));
        qt l = qt_mul(qt_mul(a, b), c), r = qt_mul(a, qt_mul(b, c));
        worst_assoc = fmax(worst_assoc, fabs(l.e0 - r.e0) + fabs(l.e1 - r.e1) +
                                            fabs(l.e2 - r.e2) + fabs(l.e3 - r.e3));
        worst_norm = fmax(worst_norm, fabs(qt_norm(l) - 1.0));
        qt i = qt_mul(a, qt_conj(a));
        ck_assert_msg(fabs(i.e0 - 1.0) < 1e-15 && fabs(i.e1) + fabs(i.e2) + fabs(i.e3) < 1e-15,
                      "q q* != 1");
    }
    ck_assert_msg(worst < 1e-14, "A(a b) != A(a) A(b) by %.3g", worst);
    ck_assert_msg(worst_assoc < 1e-14, "not associative: %.3g", worst_assoc);
    ck_assert_msg(worst_norm < 1e-14, "product not unit: %.3g", worst_norm);
}
END_TEST

/* Eq. 11-12: p_dot = 1/2 L^T omega' equals the quaternion form 1/2 p (x) (0, omega') to
 * round-off, and it is the true rate of A: with p(h) = p + h p_dot, the central difference
 * (A(p(h)) - A(p(-h)))/2h equals A omega'~ (body-frame angular velocity: A_dot = A omega'~) up
 * to O(h^2) = 1e-10 at h = 1e-5 (A is quadratic in p, so the difference quotient is exact up to
 * round-off ~ eps/h = 2e-11: asserted 1e-9). Also p . p_dot = 0: the rate keeps |p| = 1. */
START_TEST(test_quat_rate_local)
{
    double worst = 0.0, worst_adot = 0.0, worst_dot = 0.0;
    const double h = 1e-5;
    for (int n = 0; n < 1000; n++) {
        qt p = qt_from_axis_angle(rand_unit(), 2 * WS_PI * srand1());
        v3 w = v3_scale(rand_unit(), 10.0 * urand());
        qt r = qt_rate_local(p, w);
        qt o = {0.0, w.x, w.y, w.z};
        qt k = qt_mul(p, o);
        worst = fmax(worst, fabs(r.e0 - 0.5 * k.e0) + fabs(r.e1 - 0.5 * k.e1) +
                                fabs(r.e2 - 0.5 * k.e2) + fabs(r.e3 - 0.5 * k.e3));
        worst_dot = fmax(worst_dot, fabs(p.e0 * r.e0 + p.e1 * r.e1 + p.e2 * r.e2 + p.e3 * r.e3));
        qt pp = {p.e0 + h * r.e0, p.e1 + h * r.e1, p.e2 + h * r.e2, p.e3 + h * r.e3};
        qt pm = {p.e0 - h * r.e0, p.e1 - h * r.e1, p.e2 - h * r.e2, p.e3 - h * r.e3};
        m3 ap = qt_to_m3(pp), am = qt_to_m3(pm), a = qt_to_m3(p), sk = m3_skew(w);
        m3 expect = m3_mul(&a, &sk);
        for (int i = 0; i < 9; i++)
            worst_adot = fmax(worst_adot, fabs((ap.m[i] - am.m[i]) / (2 * h) - expect.m[i]) /
                                              fmax(1.0, v3_norm(w)));
    }
    ck_assert_msg(worst < 1e-14, "1/2 L^T w != 1/2 p (x) (0, w) by %.3g", worst);
    ck_assert_msg(worst_dot < 1e-14, "p . p_dot = %.3g", worst_dot);
    ck_assert_msg(worst_adot < 1e-9, "A_dot != A w~ by %.3g", worst_adot);
}
END_TEST

/* The skew matrix: a~ b = a x b. */
START_TEST(test_skew_is_cross)
{
    for (int n = 0; n < 100; n++) {
        v3 a = v3_make(srand1(), srand1(), srand1()), b = v3_make(srand1(), srand1(), srand1());
        m3 s = m3_skew(a);
        v3 c = v3_cross(a, b), d = m3_mul_v(&s, b);
        ck_assert_msg(v3_norm(v3_sub(c, d)) < 1e-15, "a~ b != a x b");
    }
}
END_TEST

/* m3_inverse: A A^-1 = A^-1 A = I for random diagonally dominant matrices (condition number
 * <= ~10, so the error is <= cond x a few eps: asserted 1e-13) at scales 1e-6 .. 1e6 (the
 * singularity test is relative to the entries' scale, so a small inertia is invertible);
 * -1 for an exactly singular matrix (rank 2) and for one singular to 1e-16 relative. */
START_TEST(test_m3_inverse)
{
    const double scales[3] = {1e-6, 1.0, 1e6};
    for (int n = 0; n < 300; n++) {
        double sc = scales[n % 3];
        m3 a;
        for (int i = 0; i < 9; i++)
            a.m[i] = srand1() * sc;
        for (int i = 0; i < 3; i++)
            a.m[4 * i] += 3.0 * sc * (srand1() < 0 ? -1 : 1);
        m3 inv;
        ck_assert_int_eq(m3_inverse(&a, &inv), 0);
        m3 p = m3_mul(&a, &inv), q = m3_mul(&inv, &a), id = m3_identity();
        ck_assert_msg(m3_maxdiff(&p, &id) < 1e-13 && m3_maxdiff(&q, &id) < 1e-13,
                      "A A^-1 - I = %.3g, A^-1 A - I = %.3g (scale %g)", m3_maxdiff(&p, &id),
                      m3_maxdiff(&q, &id), sc);
    }
    m3 sing = {{1, 2, 3, 4, 5, 6, 7, 8, 9}}; /* row3 = 2 row2 - row1 */
    m3 out;
    ck_assert_int_eq(m3_inverse(&sing, &out), -1);
    m3 near = {{1, 0, 0, 0, 1, 0, 0, 0, 1e-17}};
    ck_assert_int_eq(m3_inverse(&near, &out), -1);
    m3 zero = {{0}};
    ck_assert_int_eq(m3_inverse(&zero, &out), -1);
    /* A known inverse. */
    m3 d = {{2, 0, 0, 0, 4, 0, 0, 0, 8}};
    ck_assert_int_eq(m3_inverse(&d, &out), 0);
    ck_assert(out.m[0] == 0.5 && out.m[4] == 0.25 && out.m[8] == 0.125 && out.m[1] == 0.0);
}
END_TEST

/* m3_is_spd: 1 for symmetric positive definite matrices (B^T B + a I, a box's inertia, the
 * identity at any positive scale, a matrix symmetric to 1e-12 relative, i.e. within its 1e-9
 * tolerance), 0 for indefinite ones (eigenvalue -1, or all diagonal entries positive but
 * det < 0), for semi-definite (rank 2), for asymmetric ones (1e-6 relative off), zero, NaN,
 * negative definite. */
START_TEST(test_m3_is_spd)
{
    for (int n = 0; n < 200; n++) {
        m3 b;
        for (int i = 0; i < 9; i++)
            b.m[i] = srand1();
        m3 bt = m3_transpose(&b), s = m3_mul(&bt, &b);
        for (int i = 0; i < 3; i++)
            s.m[4 * i] += 0.1;
        ck_assert_msg(m3_is_spd(&s), "B^T B + 0.1 I not SPD");
        /* Asymmetric by 1e-6 of the scale: refused. */
        m3 asym = s;
        asym.m[1] += 1e-6 * 3.0;
        ck_assert_msg(!m3_is_spd(&asym), "asymmetric matrix accepted");
    }
    m3 box = {{0.021667, 0, 0, 0, 0.016667, 0, 0, 0, 0.008333}};
    ck_assert(m3_is_spd(&box));
    m3 tiny = {{1e-9, 0, 0, 0, 1e-9, 0, 0, 0, 1e-9}};
    ck_assert(m3_is_spd(&tiny));
    m3 nearly_sym = {{2, 1, 0, 1 + 1e-12, 2, 1, 0, 1, 2}};
    ck_assert(m3_is_spd(&nearly_sym));
    m3 indef = {{1, 0, 0, 0, -1, 0, 0, 0, 1}};
    ck_assert(!m3_is_spd(&indef));
    /* Positive diagonal, but eigenvalues 1 + 2 cos(...): [[1,2,0],[2,1,0],[0,0,1]] has -1. */
    m3 indef2 = {{1, 2, 0, 2, 1, 0, 0, 0, 1}};
    ck_assert(!m3_is_spd(&indef2));
    m3 semi = {{1, 1, 0, 1, 1, 0, 0, 0, 1}}; /* eigenvalues 2, 0, 1 */
    ck_assert(!m3_is_spd(&semi));
    m3 neg = {{-1, 0, 0, 0, -2, 0, 0, 0, -3}};
    ck_assert(!m3_is_spd(&neg));
    m3 zero = {{0}};
    ck_assert(!m3_is_spd(&zero));
    m3 nan_ = {{1, 0, 0, 0, NAN, 0, 0, 0, 1}};
    ck_assert(!m3_is_spd(&nan_));
    m3 asym = {{2, 1, 0, 0, 2, 0, 0, 0, 2}};
    ck_assert(!m3_is_spd(&asym));
}
END_TEST

/* ---- rotation vectors (the deformable elements' strains) ---- */

static double qt_maxdiff_sign(qt a, qt b)
{
    /* q and -q are one rotation. */
    double d1 = fmax(fmax(fabs(a.e0 - b.e0), fabs(a.e1 - b.e1)),
                     fmax(fabs(a.e2 - b.e2), fabs(a.e3 - b.e3)));
    double d2 = fmax(fmax(fabs(a.e0 + b.e0), fabs(a.e1 + b.e1)),
                     fmax(fabs(a.e2 + b.e2), fabs(a.e3 + b.e3)));
    return fmin(d1, d2);
}

/* qt_to_rotvec inverts qt_from_rotvec for angles in [0, pi), including 1e-12 rad and pi - 1e-9
 * (where e0 ~ 5e-10: atan2 stays well conditioned there), to 1e-14 (1 + |phi|): a few flops on
 * numbers of size 1. q and -q give the same vector; the conjugate gives exactly (bit for bit)
 * the negated vector, which the elements' swap invariance needs. An angle beyond pi comes back
 * as the shorter rotation the other way: phi (1 - 2 pi / |phi|). */
START_TEST(test_rotvec_log)
{
    double worst = 0.0;
    const double special[4] = {1e-12, 1e-6, WS_PI - 1e-9, 0.05};
    for (int n = 0; n < 2004; n++) {
        double a = n < 4 ? special[n] : WS_PI * urand() * 0.999999;
        v3 phi = v3_scale(rand_unit(), a);
        qt q = qt_from_rotvec(phi), mq = {-q.e0, -q.e1, -q.e2, -q.e3};
        v3 back = qt_to_rotvec(q), back2 = qt_to_rotvec(mq), neg = qt_to_rotvec(qt_conj(q));
        worst = fmax(worst, v3_norm(v3_sub(back, phi)) / (1.0 + a));
        ck_assert(back.x == back2.x && back.y == back2.y && back.z == back2.z);
        ck_assert(neg.x == -back.x && neg.y == -back.y && neg.z == -back.z);
    }
    ck_assert_msg(worst < 1e-14, "log(exp(phi)) != phi by %.3g", worst);
    v3 big = v3_make(0, 0, 1.5 * WS_PI), got = qt_to_rotvec(qt_from_rotvec(big));
    ck_assert_msg(fabs(got.z + 0.5 * WS_PI) < 1e-14 && fabs(got.x) + fabs(got.y) == 0.0,
                  "3 pi / 2 about z came back as %g %g %g", got.x, got.y, got.z);
    v3 z = qt_to_rotvec(qt_identity());
    ck_assert(z.x == 0.0 && z.y == 0.0 && z.z == 0.0);
}
END_TEST

/* qt_relative(a, b) = conj(a) (x) b to round-off (1e-15), its matrix is A_a^T A_b, and
 * qt_relative(b, a) is exactly its conjugate (bit for bit). */
START_TEST(test_quat_relative)
{
    double worst = 0.0, worst_m = 0.0;
    for (int n = 0; n < 1000; n++) {
        qt a = qt_from_axis_angle(rand_unit(), 2 * WS_PI * srand1());
        qt b = qt_from_axis_angle(rand_unit(), 2 * WS_PI * srand1());
        qt r = qt_relative(a, b), ref = qt_mul(qt_conj(a), b), s = qt_relative(b, a);
        worst = fmax(worst, qt_maxdiff_sign(r, ref));
        ck_assert(s.e0 == r.e0 && s.e1 == -r.e1 && s.e2 == -r.e2 && s.e3 == -r.e3);
        m3 ma = qt_to_m3(a), mb = qt_to_m3(b), mat = m3_transpose(&ma), prod = m3_mul(&mat, &mb);
        m3 mr = qt_to_m3(r);
        worst_m = fmax(worst_m, m3_maxdiff(&mr, &prod));
    }
    ck_assert_msg(worst < 1e-15, "qt_relative != conj(a) b by %.3g", worst);
    ck_assert_msg(worst_m < 1e-14, "matrix != A_a^T A_b by %.3g", worst_m);
}
END_TEST

/* The right Jacobian: log(exp(phi)^-1 exp(phi + d e_k)) = J_r(phi) e_k d + O(d^2). Central
 * differences with d = 1e-6 cancel the d^2 term: truncation ~ d^2 = 1e-12, round-off ~ eps/d =
 * 2e-10: asserted 1e-8, at angles from 1e-3 (the series branch) to 3 rad. J_r^-1 is its inverse
 * to 1e-13 (the condition of J_r stays below 5 for |phi| < 3), and both agree across the switch
 * at 0.05 rad: the series and the closed forms meet to 1e-14 (the closed forms lose ~eps/a^2
 * relative to cancellation there, times entries of size a). */
START_TEST(test_rotvec_jacobian)
{
    double worst_fd = 0.0, worst_inv = 0.0;
    const double d = 1e-6;
    for (int n = 0; n < 300; n++) {
        double a = n < 100 ? 0.05 * urand() : 3.0 * urand();
        v3 phi = v3_scale(rand_unit(), a);
        m3 J = rotvec_jacobian(phi), Ji = rotvec_jacobian_inv(phi), I = m3_mul(&J, &Ji);
        m3 id = m3_identity();
        worst_inv = fmax(worst_inv, m3_maxdiff(&I, &id));
        qt q0 = qt_conj(qt_from_rotvec(phi));
        for (int k = 0; k < 3; k++) {
            v3 e = v3_make(k == 0, k == 1, k == 2);
            v3 lp = qt_to_rotvec(qt_mul(q0, qt_from_rotvec(v3_madd(phi, e, d))));
            v3 lm = qt_to_rotvec(qt_mul(q0, qt_from_rotvec(v3_madd(phi, e, -d))));
            v3 fd = v3_scale(v3_sub(lp, lm), 0.5 / d);
            v3 col = v3_make(J.m[k], J.m[3 + k], J.m[6 + k]);
            worst_fd = fmax(worst_fd, v3_norm(v3_sub(fd, col)));
        }
    }
    ck_assert_msg(worst_fd < 1e-8, "J_r differs from finite differences by %.3g", worst_fd);
    ck_assert_msg(worst_inv < 1e-13, "J_r J_r^-1 != I by %.3g", worst_inv);
    v3 u = rand_unit();
    /* 1e-15 rad apart: the functions themselves change by less than that. */
    m3 lo = rotvec_jacobian(v3_scale(u, 0.05 - 1e-15)), hi = rotvec_jacobian(v3_scale(u, 0.05));
    m3 lo_i = rotvec_jacobian_inv(v3_scale(u, 0.05 - 1e-15));
    m3 hi_i = rotvec_jacobian_inv(v3_scale(u, 0.05));
    ck_assert_msg(m3_maxdiff(&lo, &hi) < 1e-14 && m3_maxdiff(&lo_i, &hi_i) < 1e-14,
                  "the series and the closed form part at 0.05 rad");
}
END_TEST

/* H(theta) x = J_r^-1(theta) exp(-theta/2) x (the mid-frame map), checked against that product
 * to 1e-13 for |theta| up to 3 rad and down to the series branch; H is symmetric (x . H y =
 * y . H x), even (H(-theta) = H(theta)), the identity along theta, and scales the plane across
 * theta by (a/2)/sin(a/2). */
START_TEST(test_rotvec_mid_map)
{
    double worst = 0.0, worst_sym = 0.0;
    for (int n = 0; n < 1000; n++) {
        double a = n < 300 ? 0.05 * urand() : 3.0 * urand();
        v3 th = v3_scale(rand_unit(), a), x = rand_unit(), y = rand_unit();
        m3 Ji = rotvec_jacobian_inv(th), R = qt_to_m3(qt_from_rotvec(v3_scale(th, -0.5)));
        m3 P = m3_mul(&Ji, &R);
        v3 ref = m3_mul_v(&P, x), got = rotvec_mid_map(th, x), neg = rotvec_mid_map(v3_neg(th), x);
        worst = fmax(worst, v3_norm(v3_sub(ref, got)));
        ck_assert(got.x == neg.x && got.y == neg.y && got.z == neg.z);
        worst_sym = fmax(worst_sym, fabs(v3_dot(y, got) - v3_dot(x, rotvec_mid_map(th, y))));
        if (a > 1e-3) {
            v3 u = v3_scale(th, 1.0 / a), along = rotvec_mid_map(th, u);
            v3 across = v3_cross(u, x);
            double h = 0.5 * a / sin(0.5 * a);
            ck_assert(v3_norm(v3_sub(along, u)) < 1e-14);
            ck_assert(v3_norm(v3_sub(rotvec_mid_map(th, across), v3_scale(across, h))) < 1e-14);
        }
    }
    ck_assert_msg(worst < 1e-13, "H != J_r^-1 exp(-theta/2) by %.3g", worst);
    ck_assert_msg(worst_sym < 1e-14, "H not symmetric: %.3g", worst_sym);
}
END_TEST

static Suite *math_suite(void)
{
    Suite *s = suite_create("math");
    TCase *tc = tcase_create("quaternion");
    tcase_set_timeout(tc, 5);
    tcase_add_test(tc, test_quat_matrix_vs_rodrigues);
    tcase_add_test(tc, test_quat_from_rotvec);
    tcase_add_test(tc, test_quat_mul_composition);
    tcase_add_test(tc, test_quat_rate_local);
    suite_add_tcase(s, tc);
    tc = tcase_create("matrix");
    tcase_set_timeout(tc, 5);
    tcase_add_test(tc, test_skew_is_cross);
    tcase_add_test(tc, test_m3_inverse);
    tcase_add_test(tc, test_m3_is_spd);
    suite_add_tcase(s, tc);
    tc = tcase_create("rotation vectors");
    tcase_set_timeout(tc, 5);
    tcase_add_test(tc, test_rotvec_log);
    tcase_add_test(tc, test_quat_relative);
    tcase_add_test(tc, test_rotvec_jacobian);
    tcase_add_test(tc, test_rotvec_mid_map);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return run_suite(math_suite());
}
