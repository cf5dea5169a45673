/* Small fixed-size linear algebra: vec3, mat3 (row-major), Euler parameters. Knows nothing else. */
#ifndef WS_WMATH_H
#define WS_WMATH_H

#include <math.h>

#include <wrapsim/common.h>

#define WS_PI 3.14159265358979323846

typedef ws_vec3 v3;
typedef ws_mat3 m3;
typedef ws_quat qt;

static inline v3 v3_make(double x, double y, double z)
{
    v3 r = {x, y, z};
    return r;
}
static inline v3 v3_add(v3 a, v3 b) { return v3_make(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline v3 v3_sub(v3 a, v3 b) { return v3_make(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline v3 v3_scale(v3 a, double s) { return v3_make(a.x * s, a.y * s, a.z * s); }
static inline v3 v3_madd(v3 a, v3 b, double s)
{
    return v3_make(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}
static inline double v3_dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline v3 v3_cross(v3 a, v3 b)
{
    return v3_make(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double v3_norm2(v3 a) { return v3_dot(a, a); }
static inline double v3_norm(v3 a) { return sqrt(v3_dot(a, a)); }
static inline v3 v3_neg(v3 a) { return v3_make(-a.x, -a.y, -a.z); }
static inline v3 v3_load(const double *p) { return v3_make(p[0], p[1], p[2]); }
static inline void v3_store(double *p, v3 a)
{
    p[0] = a.x;
    p[1] = a.y;
    p[2] = a.z;
}
/* Plain compares, not fmin/fmax: those are library calls on hot paths (NaN never reaches
 * here: inputs are checked). */
static inline v3 v3_min(v3 a, v3 b)
{
    return v3_make(a.x < b.x ? a.x : b.x, a.y < b.y ? a.y : b.y, a.z < b.z ? a.z : b.z);
}
static inline v3 v3_max(v3 a, v3 b)
{
    return v3_make(a.x > b.x ? a.x : b.x, a.y > b.y ? a.y : b.y, a.z > b.z ? a.z : b.z);
}

static inline v3 m3_mul_v(const m3 *a, v3 v)
{
    const double *m = a->m;
    return v3_make(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
                   m[6] * v.x + m[7] * v.y + m[8] * v.z);
}
/* A^T v */
static inline v3 m3_tmul_v(const m3 *a, v3 v)
{
    const double *m = a->m;
    return v3_make(m[0] * v.x + m[3] * v.y + m[6] * v.z, m[1] * v.x + m[4] * v.y + m[7] * v.z,
                   m[2] * v.x + m[5] * v.y + m[8] * v.z);
}

/* A B; inline, as the narrow phase takes one for every edge pair it places */
static inline m3 m3_mul(const m3 *a, const m3 *b)
{
    m3 r;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r.m[3 * i + j] = a->m[3 * i] * b->m[j] + a->m[3 * i + 1] * b->m[3 + j] +
                             a->m[3 * i + 2] * b->m[6 + j];
    return r;
}
/* A^T B, the products and sums of m3_mul of A's transpose */
static inline m3 m3_tmul(const m3 *a, const m3 *b)
{
    m3 r;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r.m[3 * i + j] =
                a->m[i] * b->m[j] + a->m[3 + i] * b->m[3 + j] + a->m[6 + i] * b->m[6 + j];
    return r;
}
static inline m3 m3_transpose(const m3 *a)
{
    m3 r;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r.m[3 * i + j] = a->m[3 * j + i];
    return r;
}

m3 m3_identity(void);
double m3_det(const m3 *a);
/* Inverse; returns 0 on success, -1 when |det| is tiny relative to the entries. */
int m3_inverse(const m3 *a, m3 *out);
/* 1 if symmetric (to relative 1e-9) and positive definite (Cholesky), else 0. */
int m3_is_spd(const m3 *a);

/* Euler parameters. */
static inline qt qt_identity(void)
{
    qt q = {1.0, 0.0, 0.0, 0.0};
    return q;
}
static inline double qt_norm(qt q) { return sqrt(q.e0 * q.e0 + q.e1 * q.e1 + q.e2 * q.e2 + q.e3 * q.e3); }
/* Normalise; a zero quaternion stays zero (callers check). Sign chosen with e0 >= 0 is NOT
 * enforced: the sign is kept so that the state stays continuous. */
static inline qt qt_normalize(qt q)
{
    double n = qt_norm(q);
    if (n > 0.0) {
        q.e0 /= n;
        q.e1 /= n;
        q.e2 /= n;
        q.e3 /= n;
    }
    return q;
}
/* Hamilton product a (x) b: the rotation b followed by a. */
static inline qt qt_mul(qt a, qt b)
{
    qt r;
    r.e0 = a.e0 * b.e0 - a.e1 * b.e1 - a.e2 * b.e2 - a.e3 * b.e3;
    r.e1 = a.e0 * b.e1 + a.e1 * b.e0 + a.e2 * b.e3 - a.e3 * b.e2;
    r.e2 = a.e0 * b.e2 - a.e1 * b.e3 + a.e2 * b.e0 + a.e3 * b.e1;
    r.e3 = a.e0 * b.e3 + a.e1 * b.e2 - a.e2 * b.e1 + a.e3 * b.e0;
    return r;
}
static inline qt qt_conj(qt q)
{
    qt r = {q.e0, -q.e1, -q.e2, -q.e3};
    return r;
}
/* Rotation by angle |phi| about phi/|phi| (eq. 4-5). */
qt qt_from_rotvec(v3 phi);
qt qt_from_axis_angle(v3 unit_axis, double angle);
/* Rotation matrix A = (2 e0^2 - 1) I + 2 (e e^T + e0 e~) (eq. 6). */
m3 qt_to_m3(qt q);
/* p_dot = 1/2 L^T omega' (eq. 11-12), omega' in the body frame. */
qt qt_rate_local(qt p, v3 omega_local);

/* Eigen-decomposition of a symmetric matrix: a = V diag(values) V^T, V a rotation (columns are
 * the unit eigenvectors, right-handed). */
void m3_sym_eigen(const m3 *a, m3 *vectors, v3 *values);

/* Skew form: a~ b = a x b. */
m3 m3_skew(v3 a);

/* ---- Rotation vectors (the deformable elements' strains) ---- */

/* The principal logarithm of a unit quaternion as a rotation vector: the angle in [0, pi] times
 * the unit axis; q and -q give the same vector. Odd to the last bit: the conjugate of q gives
 * exactly the negated vector. */
v3 qt_to_rotvec(qt q);
/* conj(a) (x) b: the rotation from frame a to frame b, in a's frame (A_a^T A_b). Written out so
 * that qt_relative(b, a) is exactly the conjugate of qt_relative(a, b) (same e0, the vector part
 * negated to the last bit), which the elements' invariance to the order of their bodies needs. */
qt qt_relative(qt a, qt b);
/* Right Jacobian (tangent map) of the rotation vector: exp(phi + d) = exp(phi) exp(J_r(phi) d)
 * to first order in d. J_r = I - (1 - cos a)/a^2 phi~ + (a - sin a)/a^3 phi~^2, a = |phi|. */
m3 rotvec_jacobian(v3 phi);
/* Its inverse, I + phi~/2 + (1/a^2 - (1 + cos a)/(2 a sin a)) phi~^2 (finite for a < 2 pi). */
m3 rotvec_jacobian_inv(v3 phi);
/* H(theta) x: how the relative rotation vector theta between two frames changes per small
 * rotation of one frame against the other measured in their mid frame (exp(theta/2) from the
 * first): d theta = H(theta) (d phi_2 - d phi_1)_mid. H = J_r^-1(theta) exp(-theta~/2), which is
 * symmetric and even in theta: the identity along theta and (a/2)/sin(a/2) across it. */
v3 rotvec_mid_map(v3 theta, v3 x);

#endif
