#include "math/wmath.h"

m3 m3_identity(void)
{
    m3 r = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
    return r;
}

double m3_det(const m3 *a)
{
    const double *m = a->m;
    return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
           m[2] * (m[3] * m[7] - m[4] * m[6]);
}

int m3_inverse(const m3 *a, m3 *out)
{
    const double *m = a->m;
    double scale = 0.0;
    for (int i = 0; i < 9; i++)
        scale = fmax(scale, fabs(m[i]));
    double det = m3_det(a);
    if (!(scale > 0.0) || !(fabs(det) > 1e-14 * scale * scale * scale))
        return -1;
    double inv = 1.0 / det;
    out->m[0] = (m[4] * m[8] - m[5] * m[7]) * inv;
    out->m[1] = (m[2] * m[7] - m[1] * m[8]) * inv;
    out->m[2] = (m[1] * m[5] - m[2] * m[4]) * inv;
    out->m[3] = (m[5] * m[6] - m[3] * m[8]) * inv;
    out->m[4] = (m[0] * m[8] - m[2] * m[6]) * inv;
    out->m[5] = (m[2] * m[3] - m[0] * m[5]) * inv;
    out->m[6] = (m[3] * m[7] - m[4] * m[6]) * inv;
    out->m[7] = (m[1] * m[6] - m[0] * m[7]) * inv;
    out->m[8] = (m[0] * m[4] - m[1] * m[3]) * inv;
    return 0;
}

int m3_is_spd(const m3 *a)
{
    const double *m = a->m;
    double scale = 0.0;
    for (int i = 0; i < 9; i++) {
        if (!isfinite(m[i]))
            return 0;
        scale = fmax(scale, fabs(m[i]));
    }
    if (!(scale > 0.0))
        return 0;
    double tol = 1e-9 * scale;
    if (fabs(m[1] - m[3]) > tol || fabs(m[2] - m[6]) > tol || fabs(m[5] - m[7]) > tol)
        return 0;
    /* Cholesky: every pivot must be positive (relative to the scale). */
    double l00 = m[0];
    if (!(l00 > 1e-12 * scale))
        return 0;
    double l10 = m[3] / sqrt(l00), l20 = m[6] / sqrt(l00);
    double d1 = m[4] - l10 * l10;
    if (!(d1 > 1e-12 * scale))
        return 0;
    double l21 = (m[7] - l20 * l10) / sqrt(d1);
    double d2 = m[8] - l20 * l20 - l21 * l21;
    return d2 > 1e-12 * scale;
}

qt qt_from_axis_angle(v3 u, double angle)
{
    double s = sin(0.5 * angle);
    qt q = {cos(0.5 * angle), u.x * s, u.y * s, u.z * s};
    return q;
}

qt qt_from_rotvec(v3 phi)
{
    double a = v3_norm(phi);
    if (a < 1e-8) {
        /* Series of sin(a/2)/a keeps the small-angle update exact to round-off. */
        double k = 0.5 - a * a / 48.0;
        qt q = {1.0 - a * a / 8.0, phi.x * k, phi.y * k, phi.z * k};
        return qt_normalize(q);
    }
    return qt_from_axis_angle(v3_scale(phi, 1.0 / a), a);
}

m3 qt_to_m3(qt q)
{
    double e0 = q.e0, e1 = q.e1, e2 = q.e2, e3 = q.e3;
    double d = 2.0 * e0 * e0 - 1.0;
    m3 a = {{d + 2.0 * e1 * e1, 2.0 * (e1 * e2 - e0 * e3), 2.0 * (e1 * e3 + e0 * e2),
             2.0 * (e2 * e1 + e0 * e3), d + 2.0 * e2 * e2, 2.0 * (e2 * e3 - e0 * e1),
             2.0 * (e3 * e1 - e0 * e2), 2.0 * (e3 * e2 + e0 * e1), d + 2.0 * e3 * e3}};
    return a;
}

qt qt_rate_local(qt p, v3 w)
{
    /* L (eq. 12) transposed times omega', halved. */
    qt r;
    r.e0 = 0.5 * (-p.e1 * w.x - p.e2 * w.y - p.e3 * w.z);
    r.e1 = 0.5 * (p.e0 * w.x - p.e3 * w.y + p.e2 * w.z);
    r.e2 = 0.5 * (p.e3 * w.x + p.e0 * w.y - p.e1 * w.z);
    r.e3 = 0.5 * (-p.e2 * w.x + p.e1 * w.y + p.e0 * w.z);
    return r;
}

m3 m3_skew(v3 a)
{
    m3 r = {{0, -a.z, a.y, a.z, 0, -a.x, -a.y, a.x, 0}};
    return r;
}

void m3_sym_eigen(const m3 *a, m3 *vectors, v3 *values)
{
    /* Cyclic Jacobi: rotate away the largest off-diagonal entries until they vanish. For 3x3
     * it converges in a handful of sweeps to round-off. */
    double s[9];
    for (int i = 0; i < 9; i++)
        s[i] = a->m[i];
    m3 v = m3_identity();
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = fabs(s[1]) + fabs(s[2]) + fabs(s[5]);
        double scale = fabs(s[0]) + fabs(s[4]) + fabs(s[8]);
        if (off <= 1e-300 || off < 1e-17 * scale)
            break;
        for (int p = 0; p < 2; p++) {
            for (int q = p + 1; q < 3; q++) {
                double apq = s[3 * p + q];
                if (apq == 0.0)
                    continue;
                double app = s[4 * p], aqq = s[4 * q];
                double theta = 0.5 * (aqq - app) / apq;
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), sn = t * c;
                /* s <- J^T s J with J the rotation in the (p, q) plane. */
                for (int k = 0; k < 3; k++) {
                    double skp = s[3 * k + p], skq = s[3 * k + q];
                    s[3 * k + p] = c * skp - sn * skq;
                    s[3 * k + q] = sn * skp + c * skq;
                }
                for (int k = 0; k < 3; k++) {
                    double spk = s[3 * p + k], sqk = s[3 * q + k];
                    s[3 * p + k] = c * spk - sn * sqk;
                    s[3 * q + k] = sn * spk + c * sqk;
                }
                for (int k = 0; k < 3; k++) {
                    double vkp = v.m[3 * k + p], vkq = v.m[3 * k + q];
                    v.m[3 * k + p] = c * vkp - sn * vkq;
                    v.m[3 * k + q] = sn * vkp + c * vkq;
                }
            }
        }
    }
    /* A right-handed frame, so the columns can serve as a rotation. */
    if (m3_det(&v) < 0.0)
        for (int k = 0; k < 3; k++)
            v.m[3 * k + 2] = -v.m[3 * k + 2];
    *vectors = v;
    *values = v3_make(s[0], s[4], s[8]);
}

v3 qt_to_rotvec(qt q)
{
    /* The shorter of the two rotations q and -q stand for: e0 >= 0. */
    double c = q.e0 < 0.0 ? -q.e0 : q.e0, sg = q.e0 < 0.0 ? -1.0 : 1.0;
    v3 e = v3_make(sg * q.e1, sg * q.e2, sg * q.e3);
    double s = v3_norm(e);
    if (s == 0.0)
        return v3_make(0.0, 0.0, 0.0);
    /* atan2(s, c)/s has no cancellation at small angles (it tends to 1/c) nor near pi. */
    return v3_scale(e, 2.0 * atan2(s, c) / s);
}

qt qt_relative(qt a, qt b)
{
    /* e0 = a . b and e = a0 b_v - b0 a_v - a_v x b_v: each term changes sign exactly when a and
     * b trade places, and the sum keeps its order, so the result is the exact conjugate. */
    v3 av = v3_make(a.e1, a.e2, a.e3), bv = v3_make(b.e1, b.e2, b.e3);
    v3 e = v3_sub(v3_sub(v3_scale(bv, a.e0), v3_scale(av, b.e0)), v3_cross(av, bv));
    qt r = {a.e0 * b.e0 + v3_dot(av, bv), e.x, e.y, e.z};
    return r;
}

/* phi~^2 x = phi x (phi x x) = phi (phi . x) - |phi|^2 x. */
static m3 poly_skew(v3 phi, double c1, double c2)
{
    m3 k = m3_skew(phi), k2 = m3_mul(&k, &k), r = m3_identity();
    for (int i = 0; i < 9; i++)
        r.m[i] += c1 * k.m[i] + c2 * k2.m[i];
    return r;
}

m3 rotvec_jacobian(v3 phi)
{
    double a2 = v3_norm2(phi), a = sqrt(a2), c1, c2;
    if (a < 0.05) {
        /* Taylor series; the next terms are below 1e-15 of the leading ones at a = 0.05. */
        c1 = -(0.5 - a2 / 24.0 + a2 * a2 / 720.0 - a2 * a2 * a2 / 40320.0);
        c2 = 1.0 / 6.0 - a2 / 120.0 + a2 * a2 / 5040.0 - a2 * a2 * a2 / 362880.0;
    } else {
        c1 = -(1.0 - cos(a)) / a2;
        c2 = (a - sin(a)) / (a2 * a);
    }
    return poly_skew(phi, c1, c2);
}

m3 rotvec_jacobian_inv(v3 phi)
{
    double a2 = v3_norm2(phi), a = sqrt(a2), c2;
    if (a < 0.05)
        c2 = 1.0 / 12.0 + a2 / 720.0 + a2 * a2 / 30240.0 + a2 * a2 * a2 / 1209600.0;
    else
        c2 = 1.0 / a2 - (1.0 + cos(a)) / (2.0 * a * sin(a));
    return poly_skew(phi, 0.5, c2);
}

v3 rotvec_mid_map(v3 theta, v3 x)
{
    /* H x = h x + (1 - h)/a^2 theta (theta . x), h = (a/2)/sin(a/2). (1 - h)/a^2 cancels at
     * small a: its series to a^4 there (the next term adds below 1e-16 of |x| at a = 0.05). */
    double a2 = v3_norm2(theta), a = sqrt(a2);
    double h = a > 0.0 ? 0.5 * a / sin(0.5 * a) : 1.0;
    double c = a < 0.05 ? -(1.0 / 24.0 + 7.0 * a2 / 5760.0 + 31.0 * a2 * a2 / 967680.0)
                        : (1.0 - h) / a2;
    return v3_madd(v3_scale(x, h), theta, c * v3_dot(theta, x));
}
