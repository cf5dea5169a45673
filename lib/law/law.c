#include "law/law.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Nesting of sums and scalings; evaluation recurses this deep. */
#define MAX_DEPTH 32
/* Largest table; far beyond any measured curve, and keeps the block size from overflowing. */
#define MAX_TABLE 1000000u

/* ---- small dense helpers (n <= 6) ---- */

/* Eigenvalues of the symmetric part of A (n x n, row-major) by cyclic Jacobi rotations. */
static void sym_eigenvalues(int n, const double *A, double *ev)
{
    double a[WS_LAW_MAX_DIM * WS_LAW_MAX_DIM];
    double scale = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            a[i * n + j] = 0.5 * (A[i * n + j] + A[j * n + i]);
            scale += a[i * n + j] * a[i * n + j];
        }
    for (int sweep = 0; sweep < 64; sweep++) {
        double off = 0.0;
        for (int p = 0; p < n; p++)
            for (int q = p + 1; q < n; q++)
                off += a[p * n + q] * a[p * n + q];
        if (!(off > 1e-32 * scale))
            break;
        for (int p = 0; p < n; p++)
            for (int q = p + 1; q < n; q++) {
                double apq = a[p * n + q];
                if (apq == 0.0)
                    continue;
                /* tan of the angle that zeroes a_pq: the smaller root of t^2 + 2 theta t = 1 */
                double theta = (a[q * n + q] - a[p * n + p]) / (2.0 * apq);
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < n; k++) {
                    double g = a[k * n + p], h = a[k * n + q];
                    a[k * n + p] = c * g - s * h;
                    a[k * n + q] = s * g + c * h;
                }
                for (int k = 0; k < n; k++) {
                    double g = a[p * n + k], h = a[q * n + k];
                    a[p * n + k] = c * g - s * h;
                    a[q * n + k] = s * g + c * h;
                }
            }
    }
    for (int i = 0; i < n; i++)
        ev[i] = a[i * n + i];
}

/* An upper bound on the 2-norm: sqrt(|A|_1 |A|_inf), exact for a diagonal matrix. */
static double mat_norm_bound(int n, const double *A)
{
    double r = 0.0, c = 0.0;
    for (int i = 0; i < n; i++) {
        double ri = 0.0, ci = 0.0;
        for (int j = 0; j < n; j++) {
            ri += fabs(A[i * n + j]);
            ci += fabs(A[j * n + i]);
        }
        r = fmax(r, ri);
        c = fmax(c, ci);
    }
    return sqrt(r * c);
}

/* A matrix a law may use: finite, symmetric part positive semi-definite, not zero (unless
 * zero_ok). 0, or -1 with the reason in why. */
static int check_matrix(int n, const double *A, const char *field, int zero_ok, char *why,
                        size_t why_len)
{
    double big = 0.0;
    for (int i = 0; i < n * n; i++) {
        if (!isfinite(A[i])) {
            snprintf(why, why_len, "law: %s[%d] (row %d, column %d) must be finite, got %g", field,
                     i, i / n, i % n, A[i]);
            return -1;
        }
        big = fmax(big, fabs(A[i]));
    }
    if (big == 0.0) {
        if (zero_ok)
            return 0;
        snprintf(why, why_len, "law: %s is zero", field);
        return -1;
    }
    double ev[WS_LAW_MAX_DIM], lo = INFINITY, hi = 0.0;
    sym_eigenvalues(n, A, ev);
    for (int i = 0; i < n; i++) {
        lo = fmin(lo, ev[i]);
        hi = fmax(hi, fabs(ev[i]));
    }
    /* Round-off of the rotations is a few eps of the largest eigenvalue. */
    if (lo < -1e-12 * hi) {
        snprintf(why, why_len,
                 "law: %s must have a positive semi-definite symmetric part (it would make "
                 "energy), but an eigenvalue is %g",
                 field, lo);
        return -1;
    }
    return 0;
}

/* y += M x and J += M, M the matrix or s times the identity. */
static void lin_add(int n, const double *M, double s, const double *x, double *y, double *J)
{
    if (M) {
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                y[i] += M[i * n + j] * x[j];
                J[i * n + j] += M[i * n + j];
            }
    } else if (s != 0.0) {
        for (int i = 0; i < n; i++) {
            y[i] += s * x[i];
            J[i * n + i] += s;
        }
    }
}

/* 1/2 x^T M x */
static double lin_energy(int n, const double *M, double s, const double *x)
{
    double e = 0.0;
    if (M) {
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++)
                e += x[i] * M[i * n + j] * x[j];
    } else {
        for (int i = 0; i < n; i++)
            e += s * x[i] * x[i];
    }
    return 0.5 * e;
}

/* ---- one-component kernels ---- */

/* The stop's ramp: 0 for x <= 0, x^2/(4w) up to 2w, x - w beyond (C1); w = 0 is a corner. */
static double stop_ramp(double x, double w, double *rp, double *rpp)
{
    if (x <= 0.0) {
        *rp = *rpp = 0.0;
        return 0.0;
    }
    if (w > 0.0 && x < 2.0 * w) {
        *rp = x / (2.0 * w);
        *rpp = 1.0 / (2.0 * w);
        return x * x / (4.0 * w);
    }
    *rp = 1.0;
    *rpp = 0.0;
    return x - w;
}

/* Integral of the stop's ramp from 0 to x. */
static double stop_ramp_integral(double x, double w)
{
    if (x <= 0.0)
        return 0.0;
    if (w > 0.0 && x < 2.0 * w)
        return x * x * x / (12.0 * w);
    return 2.0 * w * w / 3.0 + 0.5 * ((x - w) * (x - w) - w * w);
}

static double stop_eval(const ws_law *L, double u, double ud, double *dk, double *dc)
{
    double rp, rpp;
    *dk = *dc = 0.0;
    if (u > L->hi) {
        double r = stop_ramp(u - L->hi, L->rw, &rp, &rpp);
        double p = L->ks * r + L->cs * rp * ud; /* the strap's pull, never negative */
        if (!(p > 0.0))
            return 0.0;
        *dk = L->ks * rp + L->cs * rpp * ud;
        *dc = L->cs * rp;
        return p;
    }
    if (u < L->lo) {
        double r = stop_ramp(L->lo - u, L->rw, &rp, &rpp);
        double p = L->ks * r - L->cs * rp * ud; /* the bumper's push, never negative */
        if (!(p > 0.0))
            return 0.0;
        *dk = L->ks * rp - L->cs * rpp * ud;
        *dc = L->cs * rp;
        return -p;
    }
    return 0.0;
}

static double stop_energy(const ws_law *L, double u)
{
    if (u > L->hi)
        return L->ks * stop_ramp_integral(u - L->hi, L->rw);
    if (u < L->lo)
        return L->ks * stop_ramp_integral(L->lo - u, L->rw);
    return 0.0;
}

/* Interval k of the table with x[k] <= u < x[k+1] (0 <= k <= n - 2), u inside the table. */
static uint32_t table_find(const ws_law *L, double u)
{
    uint32_t lo = 0, hi = L->n - 1;
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (L->x[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

static double table_eval(const ws_law *L, double u, double *dk)
{
    const uint32_t last = L->n - 1;
    if (u < L->x[0]) {
        *dk = L->m[0];
        return L->f[0] + L->m[0] * (u - L->x[0]);
    }
    if (u >= L->x[last]) {
        *dk = L->m[last];
        return L->f[last] + L->m[last] * (u - L->x[last]);
    }
    uint32_t k = table_find(L, u);
    double h = L->x[k + 1] - L->x[k], s = (u - L->x[k]) / h;
    double f0 = L->f[k], f1 = L->f[k + 1], m0 = L->m[k], m1 = L->m[k + 1];
    double s1 = 1.0 - s;
    *dk = 6.0 * s * s1 * (f1 - f0) / h + m0 * s1 * (1.0 - 3.0 * s) + m1 * s * (3.0 * s - 2.0);
    return f0 * (1.0 + 2.0 * s) * s1 * s1 + h * m0 * s * s1 * s1 + f1 * s * s * (3.0 - 2.0 * s) -
           h * m1 * s * s * s1;
}

/* Integral of the interpolant from x[0] to u (exact: the Hermite cubics integrated). */
static double table_primitive(const ws_law *L, double u)
{
    const uint32_t last = L->n - 1;
    if (u < L->x[0]) {
        double d = u - L->x[0];
        return L->f[0] * d + 0.5 * L->m[0] * d * d;
    }
    if (u >= L->x[last]) {
        double d = u - L->x[last];
        return L->e[last] + L->f[last] * d + 0.5 * L->m[last] * d * d;
    }
    uint32_t k = table_find(L, u);
    double h = L->x[k + 1] - L->x[k], s = (u - L->x[k]) / h;
    double s2 = s * s, s3 = s2 * s, s4 = s3 * s;
    return L->e[k] + h * (L->f[k] * (0.5 * s4 - s3 + s) +
                          h * L->m[k] * (0.25 * s4 - 2.0 * s3 / 3.0 + 0.5 * s2) +
                          L->f[k + 1] * (s3 - 0.5 * s4) + h * L->m[k + 1] * (0.25 * s4 - s3 / 3.0));
}

/* Monotone slopes (Fritsch and Carlson 1980): the mean of the neighbouring secants, zero at a
 * flat interval, then shrunk onto the circle alpha^2 + beta^2 <= 9 where the cubic cannot
 * overshoot. Forces are non-decreasing, so the secants are >= 0. */
static void table_slopes(ws_law *L)
{
    const uint32_t n = L->n;
    double *d = L->e; /* the secants, in the integral's array until it is filled */
    for (uint32_t k = 0; k + 1 < n; k++)
        d[k] = (L->f[k + 1] - L->f[k]) / (L->x[k + 1] - L->x[k]);
    L->m[0] = d[0];
    L->m[n - 1] = d[n - 2];
    for (uint32_t k = 1; k + 1 < n; k++)
        L->m[k] = d[k - 1] == 0.0 || d[k] == 0.0 ? 0.0 : 0.5 * (d[k - 1] + d[k]);
    for (uint32_t k = 0; k + 1 < n; k++) {
        if (d[k] == 0.0) {
            L->m[k] = L->m[k + 1] = 0.0;
            continue;
        }
        double a = L->m[k] / d[k], b = L->m[k + 1] / d[k], r2 = a * a + b * b;
        if (r2 > 9.0) {
            double tau = 3.0 / sqrt(r2);
            L->m[k] = tau * a * d[k];
            L->m[k + 1] = tau * b * d[k];
        }
    }
    /* Now the integral at every point: Simpson's rule is exact for the cubic pieces, or in
     * closed form h (f0 + f1) / 2 + h^2 (m0 - m1) / 12. */
    double acc = 0.0;
    for (uint32_t k = 0; k + 1 < n; k++) {
        double h = L->x[k + 1] - L->x[k];
        double piece = 0.5 * h * (L->f[k] + L->f[k + 1]) + h * h * (L->m[k] - L->m[k + 1]) / 12.0;
        L->e[k] = acc;
        acc += piece;
    }
    L->e[n - 1] = acc;
    L->e0 = 0.0;
    L->e0 = table_primitive(L, 0.0);
}

/* Relaxation over a step dt of a branch with time tau: the decay of its force and the share of
 * a strain increment (applied at a constant rate over the step) that the branch still holds. */
static void relax_factors(double dt, double tau, double *decay, double *share)
{
    double x = dt / tau;
    *decay = exp(-x);
    *share = x > 0.0 ? -expm1(-x) / x : 1.0;
}

/* ---- the time function of a scaled law ---- */

static int scale_at(const ws_law *L, double t, double *s)
{
    double v = 1.0;
    if (L->scale_fn) {
        if (L->scale_fn(L->scale_user, t, &v) != 0 || !isfinite(v))
            return WS_LAW_EVAL_CALLBACK;
    } else if (L->n > 0) {
        const double *T = L->st, *S = L->sf;
        uint32_t n = L->n;
        if (t <= T[0]) {
            v = S[0];
        } else if (t >= T[n - 1]) {
            v = S[n - 1];
        } else {
            uint32_t lo = 0, hi = n - 1;
            while (hi - lo > 1) {
                uint32_t mid = lo + (hi - lo) / 2;
                if (T[mid] <= t)
                    lo = mid;
                else
                    hi = mid;
            }
            double a = (t - T[lo]) / (T[lo + 1] - T[lo]);
            v = S[lo] + a * (S[lo + 1] - S[lo]);
        }
    }
    *s = L->scale * v;
    return 0;
}

/* ---- evaluation ---- */

/* F, K = dF/du and C = dF/dud, all written in full; ud not NULL. */
static int eval_into(const ws_law *L, const double *state, const double *u, const double *ud,
                     double t, double dt, double *F, double *K, double *C)
{
    const int n = L->dim;
    memset(F, 0, (size_t)n * sizeof *F);
    memset(K, 0, (size_t)(n * n) * sizeof *K);
    memset(C, 0, (size_t)(n * n) * sizeof *C);
    switch (L->type) {
    case WS_LAW_LINEAR_ELASTIC:
        lin_add(n, L->K, L->ks, u, F, K);
        return 0;
    case WS_LAW_LINEAR_VISCOELASTIC:
        lin_add(n, L->K, L->ks, u, F, K);
        lin_add(n, L->C, L->cs, ud, F, C);
        return 0;
    case WS_LAW_LINEAR_VISCOUS:
        lin_add(n, L->C, L->cs, ud, F, C);
        return 0;
    case WS_LAW_TENSION_COMPRESSION:
        for (int i = 0; i < n; i++) {
            double gp, g = ws_law_film_ramp(u[i], L->w, &gp);
            F[i] = L->kc * u[i] + (L->k - L->kc) * g;
            K[i * n + i] = L->kc + (L->k - L->kc) * gp;
        }
        lin_add(n, L->C, L->cs, ud, F, C);
        return 0;
    case WS_LAW_CUBIC_ELASTIC:
        lin_add(n, L->K, L->ks, u, F, K);
        for (int i = 0; i < n; i++) {
            F[i] += L->k3[i] * u[i] * u[i] * u[i];
            K[i * n + i] += 3.0 * L->k3[i] * u[i] * u[i];
        }
        lin_add(n, L->C, L->cs, ud, F, C);
        return 0;
    case WS_LAW_TABLE:
        for (int i = 0; i < n; i++)
            F[i] = table_eval(L, u[i], &K[i * n + i]);
        lin_add(n, L->C, L->cs, ud, F, C);
        return 0;
    case WS_LAW_STOP:
        for (int i = 0; i < n; i++)
            F[i] = stop_eval(L, u[i], ud[i], &K[i * n + i], &C[i * n + i]);
        return 0;
    case WS_LAW_RELAXATION: {
        const uint32_t nb = L->n, per = nb + 1;
        for (int i = 0; i < n; i++) {
            const double *s = state ? state + (size_t)i * per : NULL;
            double du = u[i] - (s ? s[0] : 0.0), f = L->ks * u[i], k = L->ks;
            for (uint32_t j = 0; j < nb; j++) {
                double decay, share;
                relax_factors(dt, L->ptau[j], &decay, &share);
                f += (s ? decay * s[1 + j] : 0.0) + L->pk[j] * share * du;
                k += L->pk[j] * share;
            }
            F[i] = f;
            K[i * n + i] = k;
        }
        lin_add(n, L->C, L->cs, ud, F, C);
        return 0;
    }
    case WS_LAW_SUM: {
        double f[WS_LAW_MAX_DIM], k[WS_LAW_MAX_DIM * WS_LAW_MAX_DIM],
            c[WS_LAW_MAX_DIM * WS_LAW_MAX_DIM];
        for (uint32_t j = 0; j < L->n; j++) {
            const ws_law *T = L->terms[j];
            int r =
                eval_into(T, state && T->nstate ? state + L->off[j] : NULL, u, ud, t, dt, f, k, c);
            if (r)
                return r;
            for (int i = 0; i < n; i++)
                F[i] += f[i];
            for (int i = 0; i < n * n; i++) {
                K[i] += k[i];
                C[i] += c[i];
            }
        }
        return 0;
    }
    case WS_LAW_SCALED: {
        double s;
        int r = scale_at(L, t, &s);
        if (!r)
            r = eval_into(L->base, state, u, ud, t, dt, F, K, C);
        if (r)
            return r;
        for (int i = 0; i < n; i++)
            F[i] *= s;
        for (int i = 0; i < n * n; i++) {
            K[i] *= s;
            C[i] *= s;
        }
        return 0;
    }
    case WS_LAW_USER:
        return L->user_fn(L->user, n, u, ud, t, F, K, C) != 0 ? WS_LAW_EVAL_CALLBACK : 0;
    }
    return WS_LAW_EVAL_CALLBACK; /* not reached: types are checked at create */
}

int ws_law_eval(const ws_law *L, const double *state, const double *u, const double *ud, double t,
                double dt, double *F, double *dFdu, double *dFdud)
{
    static const double zero[WS_LAW_MAX_DIM] = {0};
    double f[WS_LAW_MAX_DIM], k[WS_LAW_MAX_DIM * WS_LAW_MAX_DIM],
        c[WS_LAW_MAX_DIM * WS_LAW_MAX_DIM];
    const int n = L->dim;
    int r = eval_into(L, L->nstate ? state : NULL, u, ud ? ud : zero, t, dt, f, k, c);
    if (r)
        return r;
    int bad = 0;
    for (int i = 0; i < n; i++)
        bad |= !isfinite(f[i]);
    for (int i = 0; i < n * n; i++)
        bad |= !isfinite(k[i]) || !isfinite(c[i]);
    if (bad)
        return WS_LAW_EVAL_NONFINITE;
    if (F)
        memcpy(F, f, (size_t)n * sizeof *F);
    if (dFdu)
        memcpy(dFdu, k, (size_t)(n * n) * sizeof *dFdu);
    if (dFdud)
        memcpy(dFdud, c, (size_t)(n * n) * sizeof *dFdud);
    return 0;
}

void ws_law_state_init(const ws_law *L, double *state)
{
    if (L->nstate)
        memset(state, 0, L->nstate * sizeof *state);
}

void ws_law_commit(const ws_law *L, double *state, const double *u, const double *ud, double t,
                   double dt)
{
    if (!L->nstate)
        return;
    switch (L->type) {
    case WS_LAW_RELAXATION: {
        const uint32_t nb = L->n, per = nb + 1;
        for (int i = 0; i < L->dim; i++) {
            double *s = state + (size_t)i * per;
            double du = u[i] - s[0];
            for (uint32_t j = 0; j < nb; j++) {
                double decay, share;
                relax_factors(dt, L->ptau[j], &decay, &share);
                s[1 + j] = decay * s[1 + j] + L->pk[j] * share * du;
            }
            s[0] = u[i];
        }
        break;
    }
    case WS_LAW_SUM:
        for (uint32_t j = 0; j < L->n; j++)
            ws_law_commit(L->terms[j], state + L->off[j], u, ud, t, dt);
        break;
    case WS_LAW_SCALED:
        ws_law_commit(L->base, state, u, ud, t, dt);
        break;
    default:
        break;
    }
}

double ws_law_elastic_energy_at(const ws_law *L, const double *state, const double *u, double t)
{
    const int n = L->dim;
    if (!L->nstate)
        state = NULL;
    double e = 0.0;
    switch (L->type) {
    case WS_LAW_LINEAR_ELASTIC:
    case WS_LAW_LINEAR_VISCOELASTIC:
        return lin_energy(n, L->K, L->ks, u);
    case WS_LAW_LINEAR_VISCOUS:
        return 0.0;
    case WS_LAW_TENSION_COMPRESSION:
        for (int i = 0; i < n; i++) {
            /* kc u^2 / 2 + (k - kc) G(u), G the integral of the ramp from 0: the ramp integrated
             * from -w gives w^2/12 at 0, subtracted so that G(0) = 0. */
            double w = L->w, x = u[i], G, g0 = w * w / 12.0;
            if (x <= -w) {
                G = -g0;
            } else if (x < w) {
                double a = x + w;
                G = a * a * a / (12.0 * w) - g0;
            } else {
                G = 2.0 * w * w / 3.0 + 0.5 * (x * x - w * w) - g0;
            }
            e += 0.5 * L->kc * x * x + (L->k - L->kc) * G;
        }
        return e;
    case WS_LAW_CUBIC_ELASTIC:
        e = lin_energy(n, L->K, L->ks, u);
        for (int i = 0; i < n; i++)
            e += 0.25 * L->k3[i] * u[i] * u[i] * u[i] * u[i];
        return e;
    case WS_LAW_TABLE:
        for (int i = 0; i < n; i++)
            e += table_primitive(L, u[i]) - L->e0;
        return e;
    case WS_LAW_STOP:
        for (int i = 0; i < n; i++)
            e += stop_energy(L, u[i]);
        return e;
    case WS_LAW_RELAXATION: {
        /* The springs of the branches hold q_j / k_j each, q_j as evaluated with dt = 0. */
        const uint32_t nb = L->n, per = nb + 1;
        for (int i = 0; i < n; i++) {
            const double *s = state ? state + (size_t)i * per : NULL;
            double du = u[i] - (s ? s[0] : 0.0);
            e += 0.5 * L->ks * u[i] * u[i];
            for (uint32_t j = 0; j < nb; j++) {
                double q = (s ? s[1 + j] : 0.0) + L->pk[j] * du;
                e += 0.5 * q * q / L->pk[j];
            }
        }
        return e;
    }
    case WS_LAW_SUM:
        for (uint32_t j = 0; j < L->n; j++) {
            const ws_law *T = L->terms[j];
            e += ws_law_elastic_energy_at(T, state && T->nstate ? state + L->off[j] : NULL, u, t);
        }
        return e;
    case WS_LAW_SCALED: {
        double s;
        if (scale_at(L, t, &s) != 0)
            return NAN;
        return s * ws_law_elastic_energy_at(L->base, state, u, t);
    }
    case WS_LAW_USER:
        return NAN;
    }
    return NAN;
}

double ws_law_elastic_energy(const ws_law *L, const double *state, const double *u)
{
    return ws_law_elastic_energy_at(L, state, u, 0.0);
}

double ws_law_max_stiffness(const ws_law *L)
{
    return L->kmax;
}

double ws_law_max_damping(const ws_law *L)
{
    return L->cmax;
}

int ws_law_film_form(const ws_law *L, double *kc, double *dk, double *w, double *c)
{
    if (!L->film)
        return 0;
    *kc = L->kc;
    *dk = L->k - L->kc;
    *w = L->w;
    *c = L->c;
    return 1;
}

/* ---- creation ---- */

#define FAIL(...)                                                                                  \
    do {                                                                                           \
        snprintf(why, why_len, __VA_ARGS__);                                                       \
        return WS_ERR_INVALID_ARGUMENT;                                                            \
    } while (0)

static const char *type_name(ws_law_type t)
{
    switch (t) {
    case WS_LAW_LINEAR_ELASTIC:
        return "linear elastic";
    case WS_LAW_LINEAR_VISCOELASTIC:
        return "Kelvin-Voigt";
    case WS_LAW_TENSION_COMPRESSION:
        return "film (tension/compression)";
    case WS_LAW_LINEAR_VISCOUS:
        return "linear viscous";
    case WS_LAW_CUBIC_ELASTIC:
        return "cubic";
    case WS_LAW_TABLE:
        return "table";
    case WS_LAW_STOP:
        return "stop";
    case WS_LAW_RELAXATION:
        return "relaxation";
    case WS_LAW_SUM:
        return "sum";
    case WS_LAW_SCALED:
        return "scaled";
    case WS_LAW_USER:
        return "user";
    }
    return "unknown";
}

/* What a law of the Def's type takes: a stiffness matrix, damping (scalar or matrix). */
static int takes_stiffness_matrix(ws_law_type t)
{
    return t == WS_LAW_LINEAR_ELASTIC || t == WS_LAW_LINEAR_VISCOELASTIC ||
           t == WS_LAW_CUBIC_ELASTIC;
}
static int takes_damping_matrix(ws_law_type t)
{
    return t == WS_LAW_LINEAR_VISCOELASTIC || t == WS_LAW_LINEAR_VISCOUS ||
           t == WS_LAW_TENSION_COMPRESSION || t == WS_LAW_CUBIC_ELASTIC || t == WS_LAW_TABLE ||
           t == WS_LAW_RELAXATION;
}

/* Every check that needs no allocation; the array counts it finds go to *count. */
static ws_status check_def(const ws_law_def *d, ws_law *const *refs, size_t nrefs, size_t *count,
                           char *why, size_t why_len)
{
    const int n = d->dim;
    const char *tn = type_name(d->type);
    *count = 0;
    if ((int)d->type < (int)WS_LAW_LINEAR_ELASTIC || (int)d->type > (int)WS_LAW_USER)
        FAIL("law: unknown type %d", (int)d->type);
    if (n != 1 && n != 3 && n != 6)
        FAIL("law: dim must be 1, 3 or 6, got %d", n);
    if (d->stiffness_matrix && !takes_stiffness_matrix(d->type))
        FAIL("law: stiffness_matrix is for the linear elastic, Kelvin-Voigt and cubic laws, not "
             "the %s law",
             tn);
    if (d->damping_matrix && !takes_damping_matrix(d->type))
        FAIL("law: damping_matrix is not taken by the %s law%s", tn,
             d->type == WS_LAW_LINEAR_ELASTIC ? " (use WS_LAW_LINEAR_VISCOELASTIC)" : "");

    /* stiffness */
    switch (d->type) {
    case WS_LAW_LINEAR_ELASTIC:
    case WS_LAW_LINEAR_VISCOELASTIC:
    case WS_LAW_CUBIC_ELASTIC:
        if (d->stiffness_matrix) {
            if (check_matrix(n, d->stiffness_matrix, "stiffness_matrix",
                             d->type == WS_LAW_CUBIC_ELASTIC, why, why_len))
                return WS_ERR_INVALID_ARGUMENT;
            break;
        }
        if (d->type == WS_LAW_CUBIC_ELASTIC) {
            if (!(isfinite(d->stiffness) && d->stiffness >= 0.0))
                FAIL("law: stiffness of the cubic law must be >= 0 N (per unit strain), got %g",
                     d->stiffness);
            break;
        }
        /* fall through */
    case WS_LAW_TENSION_COMPRESSION:
    case WS_LAW_STOP:
        if (!(isfinite(d->stiffness) && d->stiffness > 0.0))
            FAIL("law: stiffness must be > 0 N (per unit strain), got %g", d->stiffness);
        break;
    case WS_LAW_RELAXATION:
        if (!(isfinite(d->stiffness) && d->stiffness >= 0.0))
            FAIL("law: stiffness (the relaxed, long-term k_inf) must be >= 0 N, got %g",
                 d->stiffness);
        break;
    case WS_LAW_USER:
        if (!(isfinite(d->stiffness) && d->stiffness >= 0.0))
            FAIL("law: stiffness of a user law (a bound on its tangent stiffness) must be >= 0 "
                 "N, got %g",
                 d->stiffness);
        break;
    default:
        break;
    }

    /* damping */
    if (d->damping_matrix) {
        if (check_matrix(n, d->damping_matrix, "damping_matrix", d->type != WS_LAW_LINEAR_VISCOUS,
                         why, why_len))
            return WS_ERR_INVALID_ARGUMENT;
    } else if (d->type == WS_LAW_LINEAR_VISCOUS) {
        if (!(isfinite(d->damping) && d->damping > 0.0))
            FAIL("law: damping of the linear viscous law must be > 0 N s, got %g", d->damping);
    } else if (d->type != WS_LAW_LINEAR_ELASTIC && d->type != WS_LAW_SUM &&
               d->type != WS_LAW_SCALED) {
        if (!(isfinite(d->damping) && d->damping >= 0.0))
            FAIL("law: damping must be >= 0 N s, got %g", d->damping);
    }

    switch (d->type) {
    case WS_LAW_TENSION_COMPRESSION:
        if (!(isfinite(d->compression_stiffness) && d->compression_stiffness >= 0.0))
            FAIL("law: compression_stiffness of the film law must be >= 0 N, got %g",
                 d->compression_stiffness);
        if (!(isfinite(d->transition) && d->transition > 0.0))
            FAIL("law: transition of the film law must be > 0 (strain), got %g", d->transition);
        break;
    case WS_LAW_CUBIC_ELASTIC: {
        int any = !d->stiffness_matrix && d->stiffness > 0.0;
        if (d->stiffness_matrix)
            for (int i = 0; i < n * n; i++)
                any |= d->stiffness_matrix[i] != 0.0;
        for (int i = 0; i < n; i++) {
            double k3 = d->cubic_stiffnesses ? d->cubic_stiffnesses[i] : d->cubic_stiffness;
            if (!(isfinite(k3) && k3 >= 0.0)) {
                if (d->cubic_stiffnesses)
                    FAIL("law: cubic_stiffnesses[%d] must be >= 0 N (hardening), got %g", i, k3);
                FAIL("law: cubic_stiffness must be >= 0 N (hardening), got %g", k3);
            }
            any |= k3 > 0.0;
        }
        if (!any)
            FAIL("law: the cubic law has neither stiffness nor cubic_stiffness");
        break;
    }
    case WS_LAW_TABLE: {
        if (!d->table_strain || !d->table_force)
            FAIL("law: the table law needs table_strain and table_force (got %s NULL)",
                 !d->table_strain ? "table_strain" : "table_force");
        if (d->table_count < 2 || d->table_count > MAX_TABLE)
            FAIL("law: table_count must be 2 to %u, got %zu", MAX_TABLE, d->table_count);
        const double *x = d->table_strain, *f = d->table_force;
        for (size_t i = 0; i < d->table_count; i++) {
            if (!isfinite(x[i]) || !isfinite(f[i]))
                FAIL("law: table point %zu is not finite (strain %g, force %g)", i, x[i], f[i]);
            if (i > 0 && !(x[i] > x[i - 1]))
                FAIL("law: table_strain must increase strictly, but point %zu (%g) follows %g", i,
                     x[i], x[i - 1]);
            if (i > 0 && f[i] < f[i - 1])
                FAIL("law: table_force must not decrease (a negative stiffness), but point %zu "
                     "(strain %g) has %g N after %g N",
                     i, x[i], f[i], f[i - 1]);
        }
        *count = d->table_count;
        break;
    }
    case WS_LAW_STOP:
        if (isnan(d->stop_low) || isnan(d->stop_high) || d->stop_low == INFINITY ||
            d->stop_high == -INFINITY || !(d->stop_low < d->stop_high))
            FAIL("law: the stop needs stop_low < stop_high (strains; -INFINITY / +INFINITY for "
                 "no side), got %g and %g",
                 d->stop_low, d->stop_high);
        if (!isfinite(d->stop_low) && !isfinite(d->stop_high))
            FAIL("law: the stop needs stop_low or stop_high finite (both are infinite)");
        if (!(isfinite(d->transition) && d->transition >= 0.0))
            FAIL("law: transition of the stop must be >= 0 (strain), got %g", d->transition);
        break;
    case WS_LAW_RELAXATION:
        if (!d->prony_stiffness || !d->prony_time)
            FAIL("law: the relaxation law needs prony_stiffness and prony_time (got %s NULL)",
                 !d->prony_stiffness ? "prony_stiffness" : "prony_time");
        if (d->prony_count < 1 || d->prony_count > WS_LAW_MAX_PRONY)
            FAIL("law: prony_count must be 1 to %d, got %zu", WS_LAW_MAX_PRONY, d->prony_count);
        for (size_t i = 0; i < d->prony_count; i++) {
            if (!(isfinite(d->prony_stiffness[i]) && d->prony_stiffness[i] > 0.0))
                FAIL("law: prony_stiffness[%zu] must be > 0 N, got %g", i, d->prony_stiffness[i]);
            if (!(isfinite(d->prony_time[i]) && d->prony_time[i] > 0.0))
                FAIL("law: prony_time[%zu] must be > 0 s, got %g", i, d->prony_time[i]);
        }
        *count = d->prony_count;
        break;
    case WS_LAW_SUM:
        if (nrefs < 1 || nrefs > WS_LAW_MAX_TERMS)
            FAIL("law: term_count of a sum must be 1 to %d, got %zu", WS_LAW_MAX_TERMS, nrefs);
        for (size_t j = 0; j < nrefs; j++)
            if (refs[j]->dim != n)
                FAIL("law: terms[%zu] has dim %d but the sum has dim %d (set dim)", j, refs[j]->dim,
                     n);
        *count = nrefs;
        break;
    case WS_LAW_SCALED:
        if (nrefs != 1)
            FAIL("law: a scaled law needs its base law");
        if (refs[0]->dim != n)
            FAIL("law: base has dim %d but the scaled law has dim %d (set dim)", refs[0]->dim, n);
        if (!(isfinite(d->scale) && d->scale >= 0.0))
            FAIL("law: scale must be >= 0, got %g", d->scale);
        if (!d->scale_fn && d->scale_count > 0) {
            if (!d->scale_times || !d->scale_factors)
                FAIL("law: scale_count is %zu but %s is NULL", d->scale_count,
                     !d->scale_times ? "scale_times" : "scale_factors");
            if (d->scale_count > MAX_TABLE)
                FAIL("law: scale_count must be at most %u, got %zu", MAX_TABLE, d->scale_count);
            for (size_t i = 0; i < d->scale_count; i++) {
                if (!isfinite(d->scale_times[i]) ||
                    (i > 0 && !(d->scale_times[i] > d->scale_times[i - 1])))
                    FAIL("law: scale_times must be finite and increase strictly (point %zu: %g)", i,
                         d->scale_times[i]);
                if (!(isfinite(d->scale_factors[i]) && d->scale_factors[i] >= 0.0))
                    FAIL("law: scale_factors[%zu] must be >= 0, got %g", i, d->scale_factors[i]);
            }
            *count = d->scale_count;
        }
        break;
    case WS_LAW_USER:
        if (!d->user_fn)
            FAIL("law: a user law needs user_fn");
        if (d->user_flags == 0 || (d->user_flags & ~3u))
            FAIL("law: user_flags must be WS_LAW_FLAG_ELASTIC, WS_LAW_FLAG_VISCOUS or both, got "
                 "%u",
                 d->user_flags);
        break;
    default:
        break;
    }
    if (d->type != WS_LAW_SUM && d->type != WS_LAW_SCALED && nrefs != 0)
        FAIL("law: only sums and scaled laws refer to other laws");
    int depth = 0;
    for (size_t j = 0; j < nrefs; j++)
        depth = refs[j]->depth > depth ? refs[j]->depth : depth;
    if (depth >= MAX_DEPTH)
        FAIL("law: sums and scalings nested deeper than %d", MAX_DEPTH);
    /* Every part's history and leaves are within the bounds, so these sums cannot overflow. */
    uint64_t history = d->type == WS_LAW_RELAXATION ? (uint64_t)n * (d->prony_count + 1) : 0;
    uint64_t leaves = nrefs ? 0 : 1;
    for (size_t j = 0; j < nrefs; j++) {
        history += refs[j]->nstate;
        leaves += refs[j]->leaves;
    }
    if (history > WS_LAW_MAX_HISTORY)
        FAIL("law: it would need %llu doubles of history per user, more than "
             "WS_LAW_MAX_HISTORY (%d)",
             (unsigned long long)history, WS_LAW_MAX_HISTORY);
    if (leaves > WS_LAW_MAX_LEAVES)
        FAIL("law: one evaluation would visit %llu leaf laws through its sums, more than "
             "WS_LAW_MAX_LEAVES (%d)",
             (unsigned long long)leaves, WS_LAW_MAX_LEAVES);
    return WS_OK;
}

/* Carve an aligned piece of `bytes` from the block at *at. */
static void *carve(unsigned char **at, size_t bytes)
{
    void *p = *at;
    *at += (bytes + 7u) & ~(size_t)7u;
    return p;
}

ws_status ws_law_new(ws_mem *mem, const ws_law_def *d, ws_law *const *refs, size_t nrefs,
                     ws_law **out, char *why, size_t why_len)
{
    size_t count;
    *out = NULL;
    ws_status s = check_def(d, refs, nrefs, &count, why, why_len);
    if (s != WS_OK)
        return s;
    const int n = d->dim;
    const size_t nn = (size_t)(n * n) * sizeof(double), cd = count * sizeof(double);
    const int kmat = d->stiffness_matrix && n > 1, cmat = d->damping_matrix && n > 1;
    size_t bytes = (sizeof(ws_law) + 7u) & ~(size_t)7u;
    bytes += kmat ? nn : 0;
    bytes += cmat ? nn : 0;
    switch (d->type) {
    case WS_LAW_TABLE:
        bytes += 4 * ((cd + 7u) & ~(size_t)7u);
        break;
    case WS_LAW_RELAXATION:
    case WS_LAW_SCALED:
        bytes += 2 * ((cd + 7u) & ~(size_t)7u);
        break;
    case WS_LAW_SUM:
        bytes += count * sizeof(ws_law *) + ((count * sizeof(uint32_t) + 7u) & ~(size_t)7u);
        break;
    default:
        break;
    }
    unsigned char *block = ws_mem_alloc(mem, bytes);
    if (!block) {
        snprintf(why, why_len, "law: out of memory");
        return WS_ERR_OUT_OF_MEMORY;
    }
    memset(block, 0, bytes);
    unsigned char *at = block;
    ws_law *L = carve(&at, sizeof *L);
    L->bytes = bytes;
    L->type = d->type;
    L->dim = n;
    L->depth = 1;
    L->leaves = nrefs ? 0 : 1;
    for (size_t j = 0; j < nrefs; j++) {
        L->depth = refs[j]->depth + 1 > L->depth ? refs[j]->depth + 1 : L->depth;
        L->leaves += refs[j]->leaves;
    }

    /* The linear parts; a 1 x 1 matrix is a scalar. */
    if (kmat) {
        L->K = carve(&at, nn);
        memcpy(L->K, d->stiffness_matrix, nn);
        L->kmax = mat_norm_bound(n, L->K);
    } else if (takes_stiffness_matrix(d->type) || d->type == WS_LAW_STOP ||
               d->type == WS_LAW_RELAXATION || d->type == WS_LAW_TENSION_COMPRESSION) {
        L->ks = d->stiffness_matrix ? d->stiffness_matrix[0] : d->stiffness;
        L->kmax = L->ks;
    }
    if (cmat) {
        L->C = carve(&at, nn);
        memcpy(L->C, d->damping_matrix, nn);
        L->cmax = mat_norm_bound(n, L->C);
    } else if (takes_damping_matrix(d->type) || d->type == WS_LAW_STOP) {
        L->cs = d->damping_matrix ? d->damping_matrix[0] : d->damping;
        L->cmax = L->cs;
    }
    int damped = L->C != NULL || L->cs != 0.0;

    switch (d->type) {
    case WS_LAW_LINEAR_ELASTIC:
        L->flags = WS_LAWF_ELASTIC;
        break;
    case WS_LAW_LINEAR_VISCOELASTIC:
        L->flags = WS_LAWF_ELASTIC | (damped ? WS_LAWF_VISCOUS : 0u);
        break;
    case WS_LAW_LINEAR_VISCOUS:
        L->flags = WS_LAWF_VISCOUS;
        break;
    case WS_LAW_TENSION_COMPRESSION:
        L->flags = WS_LAWF_ELASTIC | (damped ? WS_LAWF_VISCOUS : 0u);
        L->k = L->ks;
        L->kc = d->compression_stiffness;
        L->kmax = fmax(L->k, L->kc);
        break;
    case WS_LAW_CUBIC_ELASTIC: {
        double big = 0.0;
        for (int i = 0; i < n; i++) {
            L->k3[i] = d->cubic_stiffnesses ? d->cubic_stiffnesses[i] : d->cubic_stiffness;
            big = fmax(big, L->k3[i]);
        }
        L->kmax += 3.0 * big; /* the tangent at |u| = 1 */
        L->flags = WS_LAWF_ELASTIC | (damped ? WS_LAWF_VISCOUS : 0u);
        break;
    }
    case WS_LAW_TABLE: {
        L->n = (uint32_t)count;
        L->x = carve(&at, cd);
        L->f = carve(&at, cd);
        L->m = carve(&at, cd);
        L->e = carve(&at, cd);
        memcpy(L->x, d->table_strain, cd);
        memcpy(L->f, d->table_force, cd);
        table_slopes(L);
        /* The largest tangent: a piece's tangent is a quadratic in s, so it peaks at a point
         * (its slope there) or at its one stationary point inside the piece. */
        double big = 0.0;
        for (uint32_t k = 0; k < L->n; k++)
            big = fmax(big, L->m[k]);
        for (uint32_t k = 0; k + 1 < L->n; k++) {
            double h = L->x[k + 1] - L->x[k], d0 = (L->f[k + 1] - L->f[k]) / h;
            /* dT/du = 6 s (1 - s) d0 + m0 (1 - 4s + 3s^2) + m1 (3s^2 - 2s): a quadratic in s;
             * its stationary point, when inside (0, 1). */
            double a = -6.0 * d0 + 3.0 * L->m[k] + 3.0 * L->m[k + 1];
            double b = 6.0 * d0 - 4.0 * L->m[k] - 2.0 * L->m[k + 1];
            if (a != 0.0) {
                double sc = -b / (2.0 * a);
                if (sc > 0.0 && sc < 1.0)
                    big = fmax(big, fabs(L->m[k] + b * sc + a * sc * sc));
            }
        }
        L->kmax = big;
        L->flags = WS_LAWF_ELASTIC | (damped ? WS_LAWF_VISCOUS : 0u);
        break;
    }
    case WS_LAW_STOP:
        L->lo = d->stop_low;
        L->hi = d->stop_high;
        L->rw = d->transition;
        L->flags = WS_LAWF_ELASTIC | (damped ? WS_LAWF_VISCOUS : 0u);
        break;
    case WS_LAW_RELAXATION:
        L->n = (uint32_t)count;
        L->pk = carve(&at, cd);
        L->ptau = carve(&at, cd);
        memcpy(L->pk, d->prony_stiffness, cd);
        memcpy(L->ptau, d->prony_time, cd);
        for (uint32_t j = 0; j < L->n; j++)
            L->kmax += L->pk[j];
        L->nstate = (uint32_t)n * (L->n + 1);
        L->flags = WS_LAWF_ELASTIC | (damped ? WS_LAWF_VISCOUS : 0u);
        break;
    case WS_LAW_SUM:
        L->n = (uint32_t)count;
        L->terms = carve(&at, count * sizeof(ws_law *));
        L->off = carve(&at, count * sizeof(uint32_t));
        for (uint32_t j = 0; j < L->n; j++) {
            L->terms[j] = refs[j];
            L->off[j] = L->nstate;
            L->nstate += refs[j]->nstate;
            L->flags |= refs[j]->flags;
            L->kmax += refs[j]->kmax;
            L->cmax += refs[j]->cmax;
        }
        break;
    case WS_LAW_SCALED: {
        L->base = refs[0];
        L->scale = d->scale;
        L->scale_fn = d->scale_fn;
        L->scale_user = d->scale_user;
        double most = 1.0;
        if (!d->scale_fn && count > 0) {
            L->n = (uint32_t)count;
            L->st = carve(&at, cd);
            L->sf = carve(&at, cd);
            memcpy(L->st, d->scale_times, cd);
            memcpy(L->sf, d->scale_factors, cd);
            most = 0.0;
            for (uint32_t j = 0; j < L->n; j++)
                most = fmax(most, L->sf[j]);
        }
        L->nstate = refs[0]->nstate;
        L->flags = refs[0]->flags;
        L->kmax = d->scale * most * refs[0]->kmax;
        L->cmax = d->scale * most * refs[0]->cmax;
        break;
    }
    case WS_LAW_USER:
        L->user_fn = d->user_fn;
        L->user = d->user_data;
        L->flags = d->user_flags;
        L->kmax = d->stiffness;
        L->cmax = d->damping;
        break;
    default:
        break;
    }

    /* The old fields: the film form of stateless 1D laws (the web's fast path reads them). */
    L->w = d->type == WS_LAW_TENSION_COMPRESSION ? d->transition : 1.0;
    if (n == 1 && (d->type == WS_LAW_LINEAR_ELASTIC || d->type == WS_LAW_LINEAR_VISCOELASTIC ||
                   d->type == WS_LAW_LINEAR_VISCOUS || d->type == WS_LAW_TENSION_COMPRESSION)) {
        L->film = 1;
        if (d->type != WS_LAW_TENSION_COMPRESSION)
            L->k = L->kc = L->ks;
        L->c = L->cs;
    }
    for (size_t j = 0; j < nrefs; j++)
        refs[j]->users++;
    *out = L;
    return WS_OK;
}

void ws_law_free(ws_mem *mem, ws_law *L, int release_refs)
{
    if (!L)
        return;
    if (release_refs) {
        if (L->type == WS_LAW_SUM)
            for (uint32_t j = 0; j < L->n; j++)
                L->terms[j]->users--;
        if (L->type == WS_LAW_SCALED)
            L->base->users--;
    }
    ws_mem_free(mem, L, L->bytes);
}
