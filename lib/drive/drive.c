#include "drive/drive.h"

#include <stdio.h>
#include <string.h>

/* Times a drive may be given, s: beyond this an angle or a phase keeps no digit of precision
 * after the point (1e9 s is 32 years), and products of a rate with a time are what overflow. */
#define TIME_LIMIT 1e9

/* Integral of the smoothstep 3x^2 - 2x^3 from 0 to x, for x in [0, 1]; equals 1/2 at x = 1. */
static double smooth_int(double x)
{
    return x * x * x - 0.5 * x * x * x * x;
}

static double smooth(double x)
{
    return x * x * (3.0 - 2.0 * x);
}

/* Angle gained by a rate that ramps 0 -> 1 smoothly over [c - T/2, c + T/2]: zero before, then
 * T * smooth_int, then (t - c) after the ramp. Centring the ramp on c makes the angle after it
 * exactly that of an instant start at c. ddg is the rate's derivative (1/s). */
static void ramp_centered(double t, double c, double T, double *g, double *dg, double *ddg)
{
    *ddg = 0.0;
    if (T <= 0.0) {
        *g = t > c ? t - c : 0.0;
        *dg = t > c ? 1.0 : 0.0;
        return;
    }
    double t0 = c - 0.5 * T;
    if (t <= t0) {
        *g = 0.0;
        *dg = 0.0;
    } else if (t >= t0 + T) {
        *g = t - c;
        *dg = 1.0;
    } else {
        double x = (t - t0) / T;
        *g = T * smooth_int(x);
        *dg = smooth(x);
        *ddg = 6.0 * x * (1.0 - x) / T;
    }
}

void ws_drive_tilt_angle(const ws_drive_def *def, double stop_ramp, double t, double *theta,
                         double *rate, double *angacc)
{
    double g, dg, ddg;
    ramp_centered(t, def->start_time, def->ramp_time, &g, &dg, &ddg);
    double th = def->rate * g, rt = def->rate * dg, ac = def->rate * ddg;
    if (def->max_angle > 0.0 && def->rate != 0.0) {
        /* The stop is a rate ramp down centred on the time the free angle would reach
         * max_angle, so the angle settles exactly on it. */
        double stop = def->start_time + def->max_angle / fabs(def->rate);
        double g2, dg2, ddg2;
        ramp_centered(t, stop, stop_ramp, &g2, &dg2, &ddg2);
        th -= def->rate * g2;
        rt -= def->rate * dg2;
        ac -= def->rate * ddg2;
    }
    *theta = th;
    *rate = rt;
    *angacc = ac;
}

/* WS_ERR_INVALID_ARGUMENT with the reason: `fmt` takes the offending value (%g). */
static ws_status bad(char *why, size_t n, const char *fmt, double value)
{
    if (why && n)
        snprintf(why, n, fmt, value);
    return WS_ERR_INVALID_ARGUMENT;
}

/* The same with a reason that names no value. */
static ws_status bad_text(char *why, size_t n, const char *text)
{
    if (why && n)
        snprintf(why, n, "%s", text);
    return WS_ERR_INVALID_ARGUMENT;
}

/* ---- profiles of phases (pulse, impact) ---- */

/* Velocity gained and displacement (from v0 = 0) over a whole phase, and within it. */
static void seg_at(const ws_seg *s, double tau, double *a, double *v, double *x)
{
    double T = s->T, A = s->A, k, c, sn;
    switch (s->kind) {
    case WS_SEG_RISE:
    case WS_SEG_FALL: {
        double sg = s->kind == WS_SEG_RISE ? -1.0 : 1.0;
        k = WS_PI / T;
        c = cos(k * tau);
        sn = sin(k * tau);
        *a = 0.5 * A * (1.0 + sg * c);
        *v = 0.5 * A * (tau + sg * sn / k);
        *x = 0.5 * A * (0.5 * tau * tau + sg * (1.0 - c) / (k * k));
        return;
    }
    case WS_SEG_HOLD:
        *a = A;
        *v = A * tau;
        *x = 0.5 * A * tau * tau;
        return;
    case WS_SEG_COAST:
        *a = *v = *x = 0.0;
        return;
    case WS_SEG_LOBE:
        k = 2.0 * WS_PI / T;
        c = cos(k * tau);
        sn = sin(k * tau);
        *a = 0.5 * A * (1.0 - c);
        *v = 0.5 * A * (tau - sn / k);
        *x = 0.5 * A * (0.5 * tau * tau - (1.0 - c) / (k * k));
        return;
    case WS_SEG_HALF_SINE:
        k = WS_PI / T;
        c = cos(k * tau);
        sn = sin(k * tau);
        *a = A * sn;
        *v = A * (1.0 - c) / k;
        *x = A * (tau - sn / k) / k;
        return;
    }
    *a = *v = *x = 0.0;
}

static void add_seg(ws_drive *d, ws_seg_kind kind, double T, double A)
{
    ws_seg *s = &d->seg[d->nseg];
    s->kind = kind;
    s->T = T;
    s->A = A;
    if (d->nseg == 0) {
        s->t0 = 0.0;
        s->v0 = s->x0 = 0.0;
    } else {
        const ws_seg *p = &d->seg[d->nseg - 1];
        double a, v, x;
        seg_at(p, p->T, &a, &v, &x);
        s->t0 = p->t0 + p->T;
        s->v0 = p->v0 + v;
        s->x0 = p->x0 + p->v0 * p->T + x;
    }
    d->nseg++;
    double a, v, x;
    seg_at(s, T, &a, &v, &x);
    d->end_v = s->v0 + v;
    d->end_x = s->x0 + s->v0 * T + x;
}

static void profile_at(const ws_drive *d, double tau, double *a, double *v, double *x)
{
    if (tau <= 0.0) {
        *a = *v = *x = 0.0;
        return;
    }
    for (int i = 0; i < d->nseg; i++) {
        const ws_seg *s = &d->seg[i];
        if (tau < s->t0 + s->T) {
            double u = tau - s->t0, sa, sv, sx;
            seg_at(s, u, &sa, &sv, &sx);
            *a = sa;
            *v = s->v0 + sv;
            *x = s->x0 + s->v0 * u + sx;
            return;
        }
    }
    const ws_seg *l = &d->seg[d->nseg - 1];
    *a = 0.0;
    *v = d->end_v;
    *x = d->end_x + d->end_v * (tau - l->t0 - l->T);
}

/* ---- tables (table, random) ---- */

/* Exact integrals of the piecewise-linear acceleration a[0..n) at interval h from rest. */
static void integrate_table(const double *a, size_t n, double h, double *v, double *x)
{
    v[0] = 0.0;
    x[0] = 0.0;
    for (size_t i = 0; i + 1 < n; i++) {
        v[i + 1] = v[i] + 0.5 * h * (a[i] + a[i + 1]);
        x[i + 1] = x[i] + h * v[i] + h * h * (a[i] / 3.0 + a[i + 1] / 6.0);
    }
}

/* Subtract c1 sin(pi t/T) + c2 sin(2 pi t/T) from the samples so that the integrals end at
 * zero velocity and displacement. The two shapes vanish at both ends, so a history that starts
 * and ends at rest keeps doing so; their end integrals are found by the same integration, so
 * the correction is exact for the played (piecewise-linear) history. v and x are scratch. */
static void end_at_rest(double *a, size_t n, double h, double *v, double *x)
{
    double T = (double)(n - 1) * h, e[2][2], ve, xe;
    integrate_table(a, n, h, v, x);
    ve = v[n - 1];
    xe = x[n - 1];
    for (int k = 0; k < 2; k++) {
        /* The shape's end velocity and displacement, by the same integration as the table. */
        for (size_t i = 0; i < n; i++)
            v[i] = sin((double)(k + 1) * WS_PI * ((double)i * h) / T);
        double vv = 0.0, xx = 0.0;
        for (size_t i = 0; i + 1 < n; i++) {
            xx += h * vv + h * h * (v[i] / 3.0 + v[i + 1] / 6.0);
            vv += 0.5 * h * (v[i] + v[i + 1]);
        }
        e[0][k] = vv;
        e[1][k] = xx;
    }
    double det = e[0][0] * e[1][1] - e[0][1] * e[1][0];
    double c1 = (ve * e[1][1] - e[0][1] * xe) / det;
    double c2 = (e[0][0] * xe - e[1][0] * ve) / det;
    for (size_t i = 0; i < n; i++) {
        double s = (double)i * h / T;
        a[i] -= c1 * sin(WS_PI * s) + c2 * sin(2.0 * WS_PI * s);
    }
}

static void table_at(const ws_drive *d, double tau, double *a, double *v, double *x)
{
    const double *A = d->tab, *V = d->tab + d->tab_n, *X = d->tab + 2 * d->tab_n;
    double h = d->tab_h;
    size_t n = d->tab_n;
    if (tau <= 0.0) {
        *a = *v = *x = 0.0;
        return;
    }
    double span = (double)(n - 1) * h;
    if (tau >= span) {
        *a = 0.0;
        *v = V[n - 1];
        *x = X[n - 1] + V[n - 1] * (tau - span);
        return;
    }
    size_t i = (size_t)(tau / h);
    if (i > n - 2)
        i = n - 2;
    double u = tau - (double)i * h, s = (A[i + 1] - A[i]) / h;
    *a = A[i] + s * u;
    *v = V[i] + A[i] * u + 0.5 * s * u * u;
    *x = X[i] + V[i] * u + 0.5 * A[i] * u * u + s * u * u * u / 6.0;
}

/* ---- random vibration ---- */

/* splitmix64: a small generator whose state is one integer the caller holds. */
static uint64_t next_u64(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double uniform01(uint64_t *state)
{
    return (double)(next_u64(state) >> 11) * 0x1.0p-53;
}

/* One-sided PSD at f by log-log interpolation of the breakpoints; zero outside them. */
static double psd_at(const double *f, const double *g, size_t n, double x)
{
    if (!(x >= f[0] && x <= f[n - 1]))
        return 0.0;
    size_t i = 0;
    while (i + 2 < n && x > f[i + 1])
        i++;
    double b = log(g[i + 1] / g[i]) / log(f[i + 1] / f[i]);
    return g[i] * pow(x / f[i], b);
}

ws_status ws_drive_psd_grms(const double *f, const double *g, size_t n, double *grms, char *why,
                            size_t why_len)
{
    if (!f || !g || n < 2)
        return bad(why, why_len, "PSD: needs at least 2 breakpoints (got %g)", (double)n);
    for (size_t i = 0; i < n; i++) {
        if (!(isfinite(f[i]) && f[i] > 0.0 && f[i] < 1e9))
            return bad(why, why_len, "PSD: frequencies must be in (0, 1e9) Hz, got %g", f[i]);
        if (!(isfinite(g[i]) && g[i] > 0.0 && g[i] < 1e12))
            return bad(why, why_len, "PSD: levels must be in (0, 1e12) g^2/Hz, got %g", g[i]);
        if (i && !(f[i] > f[i - 1]))
            return bad(
                why, why_len,
                "PSD: frequencies must increase strictly, got %g after a larger or equal one",
                f[i]);
    }
    /* The exact integral of G1 (f/f1)^b over each segment. */
    double sum = 0.0;
    for (size_t i = 0; i + 1 < n; i++) {
        double r = f[i + 1] / f[i], b = log(g[i + 1] / g[i]) / log(r);
        if (fabs(b + 1.0) < 1e-12)
            sum += g[i] * f[i] * log(r);
        else
            sum += g[i] * f[i] / (b + 1.0) * (pow(r, b + 1.0) - 1.0);
    }
    if (grms)
        *grms = sqrt(sum);
    return WS_OK;
}

/* In-place inverse complex FFT of m (a power of two) interleaved values, without the 1/m:
 * z_l = sum_k Z_k exp(2 pi i l k / m). */
static void ifft_inplace(double *z, size_t m)
{
    for (size_t i = 1, j = 0; i < m; i++) {
        size_t bit = m >> 1;
        for (; j & bit; bit >>= 1)
            j ^= bit;
        j ^= bit;
        if (i < j) {
            double tr = z[2 * i], ti = z[2 * i + 1];
            z[2 * i] = z[2 * j];
            z[2 * i + 1] = z[2 * j + 1];
            z[2 * j] = tr;
            z[2 * j + 1] = ti;
        }
    }
    for (size_t len = 2; len <= m; len <<= 1) {
        double ang = 2.0 * WS_PI / (double)len;
        for (size_t k = 0; k < len / 2; k++) {
            /* Twiddles from sin and cos directly, not by recurrence, so their error does not
             * grow with the length. */
            double wr = cos(ang * (double)k), wi = sin(ang * (double)k);
            for (size_t s = 0; s < m; s += len) {
                size_t p = s + k, q = p + len / 2;
                double xr = z[2 * q] * wr - z[2 * q + 1] * wi;
                double xi = z[2 * q] * wi + z[2 * q + 1] * wr;
                z[2 * q] = z[2 * p] - xr;
                z[2 * q + 1] = z[2 * p + 1] - xi;
                z[2 * p] += xr;
                z[2 * p + 1] += xi;
            }
        }
    }
}

/* Z_k = X + conj Y + i W^k (X - conj Y) for X = X_k, Y = X_{m-k}, W = exp(2 pi i / n). */
static void pack_bin(const double x[2], const double y[2], size_t k, size_t n, double z[2])
{
    double e = 2.0 * WS_PI * (double)k / (double)n, wr = cos(e), wi = sin(e);
    double sr = x[0] + y[0], si = x[1] - y[1];              /* X + conj Y */
    double dr = x[0] - y[0], di = x[1] + y[1];              /* X - conj Y */
    double pr = wr * dr - wi * di, pim = wr * di + wi * dr; /* W^k (X - conj Y) */
    z[0] = sr - pim;                                        /* i (pr + i pim) = -pim + i pr */
    z[1] = si + pr;
}

static ws_status check_random(const ws_drive_def *c, char *why, size_t why_len)
{
    ws_status s =
        ws_drive_psd_grms(c->psd_frequency, c->psd_level, c->psd_count, NULL, why, why_len);
    if (s != WS_OK)
        return s;
    double fmax = c->psd_frequency[c->psd_count - 1];
    if (!(isfinite(c->sample_rate) && c->sample_rate > 2.0 * fmax && c->sample_rate <= 1e7))
        return bad(why, why_len,
                   "random: sample_rate must exceed twice the highest breakpoint (%g Hz) and be "
                   "<= 1e7 Hz",
                   fmax);
    return WS_OK;
}

ws_status ws_drive_synthesize(const ws_drive_def *c, double *accel, size_t count, char *why,
                              size_t why_len)
{
    if (!accel)
        return bad_text(why, why_len, "random: the output buffer is NULL");
    if (count < 16 || (count & (count - 1)) != 0)
        return bad(why, why_len, "random: count must be a power of two >= 16, got %g",
                   (double)count);
    ws_status s = check_random(c, why, why_len);
    if (s != WS_OK)
        return s;
    size_t n = count, m = n / 2;
    double df = c->sample_rate / (double)n, g0 = WS_STANDARD_GRAVITY;
    uint64_t state = c->seed;
    /* X_k for k in [1, m): half the amplitude sqrt(2 G df) g of the bin's cosine (the other half
     * is its mirror X_{n-k}), a phase drawn in the order of k; X_0 = X_m = 0 (no mean, no
     * Nyquist term). Stored as complex values at slot k. */
    accel[0] = accel[1] = 0.0;
    for (size_t k = 1; k < m; k++) {
        double amp =
            0.5 * g0 *
            sqrt(2.0 * psd_at(c->psd_frequency, c->psd_level, c->psd_count, (double)k * df) * df);
        double ph = 2.0 * WS_PI * uniform01(&state);
        accel[2 * k] = amp * cos(ph);
        accel[2 * k + 1] = amp * sin(ph);
    }
    /* A real inverse FFT of n points as a complex one of m points on the even and odd samples:
     * z_l = x_{2l} + i x_{2l+1} = sum_k Z_k exp(2 pi i l k / m) with
     * Z_k = X_k + conj X_{m-k} + i W^k (X_k - conj X_{m-k}), W = exp(2 pi i / n), X_m = 0.
     * Z_k and Z_{m-k} need the same two inputs, so each pair is rewritten together in place. */
    for (size_t k = 0; k <= m / 2; k++) {
        size_t j = k == 0 ? 0 : m - k;
        double xk[2] = {accel[2 * k], accel[2 * k + 1]};
        double xj[2] = {k == 0 ? 0.0 : accel[2 * j], k == 0 ? 0.0 : accel[2 * j + 1]};
        double zk[2], zj[2];
        pack_bin(xk, xj, k, n, zk);
        pack_bin(xj, xk, j, n, zj);
        accel[2 * k] = zk[0];
        accel[2 * k + 1] = zk[1];
        if (k != 0 && j != k) {
            accel[2 * j] = zj[0];
            accel[2 * j + 1] = zj[1];
        }
    }
    ifft_inplace(accel, m);
    return WS_OK;
}

/* ---- setup ---- */

static int finite_prod(double a, double b)
{
    return isfinite(a * b);
}

static ws_status setup_pulse(ws_drive *d, char *why, size_t n)
{
    ws_drive_def *c = &d->def;
    double A = c->acceleration, Tr = c->rise_time, Th = c->hold_time;
    double G = c->gentle_acceleration, Tc = c->coast_time;
    if (!(isfinite(A) && A > 0.0 && A <= 1e6))
        return bad(why, n, "pulse: acceleration must be in (0, 1e6] m/s^2, got %g", A);
    if (!(isfinite(Tr) && Tr > 0.0 && Tr <= TIME_LIMIT))
        return bad(why, n, "pulse: rise_time must be in (0, 1e9] s, got %g", Tr);
    if (!(isfinite(Th) && Th >= 0.0 && Th <= TIME_LIMIT))
        return bad(why, n, "pulse: hold_time must be in [0, 1e9] s, got %g", Th);
    if (!(isfinite(G) && G > 0.0 && G <= 1e6))
        return bad(why, n, "pulse: gentle_acceleration must be in (0, 1e6] m/s^2, got %g", G);
    if (!(isfinite(Tc) && Tc >= 0.0 && Tc <= TIME_LIMIT))
        return bad(why, n, "pulse: coast_time must be in [0, 1e9] s, got %g", Tc);
    if (c->pulse_mode != WS_PULSE_ACCELERATE && c->pulse_mode != WS_PULSE_BRAKE)
        return bad(why, n, "pulse: unknown pulse_mode %g", (double)c->pulse_mode);
    double V = A * (Tr + Th), Tg = 2.0 * V / G;
    if (!isfinite(Tg) || Tg > TIME_LIMIT)
        return bad(why, n,
                   "pulse: the gentle phase would last %g s (> 1e9 s); raise "
                   "gentle_acceleration",
                   Tg);
    d->nseg = 0;
    if (c->pulse_mode == WS_PULSE_ACCELERATE) {
        add_seg(d, WS_SEG_RISE, Tr, A);
        if (Th > 0.0)
            add_seg(d, WS_SEG_HOLD, Th, A);
        add_seg(d, WS_SEG_FALL, Tr, A);
        if (Tc > 0.0)
            add_seg(d, WS_SEG_COAST, Tc, 0.0);
        add_seg(d, WS_SEG_LOBE, Tg, -G);
    } else {
        add_seg(d, WS_SEG_LOBE, Tg, G);
        if (Tc > 0.0)
            add_seg(d, WS_SEG_COAST, Tc, 0.0);
        add_seg(d, WS_SEG_RISE, Tr, -A);
        if (Th > 0.0)
            add_seg(d, WS_SEG_HOLD, Th, -A);
        add_seg(d, WS_SEG_FALL, Tr, -A);
    }
    return WS_OK;
}

static ws_status setup_impact(ws_drive *d, char *why, size_t n)
{
    ws_drive_def *c = &d->def;
    double V = c->speed, T = c->pulse_duration, G = c->gentle_acceleration, Tc = c->coast_time;
    if (!(isfinite(V) && V > 0.0 && V <= 1e4))
        return bad(why, n, "impact: speed must be in (0, 1e4] m/s, got %g", V);
    if (!(isfinite(T) && T >= 1e-6 && T <= TIME_LIMIT))
        return bad(why, n, "impact: pulse_duration must be in [1e-6, 1e9] s, got %g", T);
    if (!(isfinite(G) && G > 0.0 && G <= 1e6))
        return bad(why, n, "impact: gentle_acceleration must be in (0, 1e6] m/s^2, got %g", G);
    if (!(isfinite(Tc) && Tc >= 0.0 && Tc <= TIME_LIMIT))
        return bad(why, n, "impact: coast_time must be in [0, 1e9] s, got %g", Tc);
    double Tg = 2.0 * V / G;
    if (Tg > TIME_LIMIT)
        return bad(why, n,
                   "impact: the run-up would last %g s (> 1e9 s); raise "
                   "gentle_acceleration",
                   Tg);
    d->nseg = 0;
    add_seg(d, WS_SEG_LOBE, Tg, G);
    if (Tc > 0.0)
        add_seg(d, WS_SEG_COAST, Tc, 0.0);
    add_seg(d, WS_SEG_HALF_SINE, T, -WS_PI * V / (2.0 * T));
    return WS_OK;
}

static ws_status take_table(ws_drive *d, ws_mem *mem, size_t count)
{
    d->tab = ws_mem_alloc(mem, 3 * count * sizeof(double));
    if (!d->tab)
        return WS_ERR_OUT_OF_MEMORY;
    d->tab_n = count;
    return WS_OK;
}

static ws_status setup_table(ws_drive *d, ws_mem *mem, const ws_drive_def *def, char *why, size_t n)
{
    ws_drive_def *c = &d->def;
    if (!def->table || def->table_count < 2 || def->table_count > ((size_t)1 << 28))
        return bad(why, n, "table: needs a table of 2 to 2^28 samples, got %g",
                   def->table ? (double)def->table_count : 0.0);
    if (!(isfinite(c->table_interval) && c->table_interval >= 1e-9 &&
          c->table_interval * (double)def->table_count <= TIME_LIMIT))
        return bad(why, n,
                   "table: table_interval must be >= 1e-9 s with the table no longer "
                   "than 1e9 s, got %g s",
                   c->table_interval);
    for (size_t i = 0; i < def->table_count; i++)
        if (!(isfinite(def->table[i]) && fabs(def->table[i]) <= 1e6))
            return bad(why, n,
                       "table: accelerations must be finite and within 1e6 m/s^2 "
                       "(sample %g is not)",
                       (double)i);
    ws_status s = take_table(d, mem, def->table_count);
    if (s != WS_OK)
        return s;
    memcpy(d->tab, def->table, def->table_count * sizeof(double));
    d->tab_h = c->table_interval;
    return WS_OK;
}

static ws_status setup_random(ws_drive *d, ws_mem *mem, const ws_drive_def *def, char *why,
                              size_t n)
{
    ws_drive_def *c = &d->def;
    ws_status s = check_random(def, why, n);
    if (s != WS_OK)
        return s;
    double samples = c->duration * c->sample_rate;
    if (!(isfinite(c->duration) && c->duration > 0.0 && samples >= 16.0 && samples <= 0x1p26))
        return bad(why, n,
                   "random: duration x sample_rate must give 16 to 2^26 samples, got "
                   "duration %g s",
                   c->duration);
    if (!(2.0 * c->ramp_time <= c->duration))
        return bad(why, n, "random: the taper ramp_time (%g s) must be at most half the duration",
                   c->ramp_time);
    size_t played = (size_t)samples + 1, full = 16;
    while (full < played)
        full <<= 1;
    double *hist = ws_mem_alloc(mem, full * sizeof(double));
    if (!hist)
        return WS_ERR_OUT_OF_MEMORY;
    s = ws_drive_synthesize(def, hist, full, why, n);
    if (s == WS_OK)
        s = take_table(d, mem, played);
    if (s != WS_OK) {
        ws_mem_free(mem, hist, full * sizeof(double));
        return s;
    }
    memcpy(d->tab, hist, played * sizeof(double));
    ws_mem_free(mem, hist, full * sizeof(double));
    d->tab_h = 1.0 / c->sample_rate;
    double R = c->ramp_time, span = (double)(played - 1) * d->tab_h;
    if (R > 0.0) {
        for (size_t i = 0; i < played; i++) {
            double t = (double)i * d->tab_h, e = t < span - t ? t : span - t;
            if (e < R)
                d->tab[i] *= 0.5 * (1.0 - cos(WS_PI * e / R));
        }
    }
    return WS_OK;
}

static ws_status setup_sweep(ws_drive_def *c, char *why, size_t n)
{
    double A = c->acceleration, f1 = c->frequency, f2 = c->frequency_end, T = c->duration;
    if (!(isfinite(A) && A > 0.0 && A <= 1e6))
        return bad(why, n, "sweep: acceleration must be in (0, 1e6] m/s^2, got %g", A);
    if (!(isfinite(f1) && f1 >= 1e-3 && f1 <= 1e6))
        return bad(why, n, "sweep: frequency (f1) must be in [1e-3, 1e6] Hz, got %g", f1);
    if (!(isfinite(f2) && f2 >= 1e-3 && f2 <= 1e6))
        return bad(why, n, "sweep: frequency_end (f2) must be in [1e-3, 1e6] Hz, got %g", f2);
    if (!(isfinite(T) && T > 0.0 && T <= TIME_LIMIT))
        return bad(why, n, "sweep: duration must be in (0, 1e9] s, got %g", T);
    if (!(2.0 * c->ramp_time <= T))
        return bad(why, n, "sweep: ramp_time (%g s) must be at most half the duration",
                   c->ramp_time);
    if (c->sweep_law != WS_SWEEP_LOG && c->sweep_law != WS_SWEEP_LINEAR)
        return bad(why, n, "sweep: unknown sweep_law %g", (double)c->sweep_law);
    if (!finite_prod(f1 > f2 ? f1 : f2, T) || (f1 > f2 ? f1 : f2) * T > 1e12)
        return bad(why, n, "sweep: frequency x duration must be <= 1e12 cycles, got duration %g s",
                   T);
    return WS_OK;
}

ws_status ws_drive_setup(ws_drive *d, ws_mem *mem, const ws_drive_def *def, const ws_pose *base,
                         char *why, size_t why_len)
{
    memset(d, 0, sizeof *d);
    d->def = *def;
    ws_drive_def *c = &d->def;
    c->table = NULL; /* the drive keeps copies, never the caller's pointers */
    c->psd_frequency = NULL;
    c->psd_level = NULL;
    d->base = *base;
    ws_status s = WS_OK;
    if (!(isfinite(c->start_time) && fabs(c->start_time) <= TIME_LIMIT))
        return bad(why, why_len, "drive: start_time must be within +-1e9 s, got %g", c->start_time);
    if (!(isfinite(c->ramp_time) && c->ramp_time >= 0.0 && c->ramp_time <= TIME_LIMIT))
        return bad(why, why_len, "drive: ramp_time must be in [0, 1e9] s, got %g", c->ramp_time);
    if (c->type != WS_DRIVE_TILT && c->type != WS_DRIVE_STATIC && c->type != WS_DRIVE_CALLBACK) {
        double n = v3_norm(c->direction);
        if (!(n > 0.0) || !isfinite(n))
            return bad_text(why, why_len, "drive: direction must be a non-zero finite vector");
        c->direction = v3_scale(c->direction, 1.0 / n);
    }
    switch (c->type) {
    case WS_DRIVE_STATIC:
        break;
    case WS_DRIVE_TILT: {
        double n = v3_norm(c->axis);
        if (!(n > 0.0) || !isfinite(n) || !ws_is_finite3(&c->point))
            return bad_text(why, why_len,
                            "drive: tilt needs a non-zero finite axis and a finite point");
        if (!(isfinite(c->rate) && fabs(c->rate) <= 1e6))
            return bad(why, why_len, "drive: tilt rate must be within +-1e6 rad/s, got %g",
                       c->rate);
        if (!(isfinite(c->max_angle) && c->max_angle >= 0.0 && c->max_angle <= 1e6))
            return bad(why, why_len,
                       "drive: max_angle must be in [0, 1e6] rad (0 = no limit), "
                       "got %g",
                       c->max_angle);
        if (!(isfinite(c->stop_ramp_time) && c->stop_ramp_time >= 0.0 &&
              c->stop_ramp_time <= TIME_LIMIT))
            return bad(why, why_len, "drive: stop_ramp_time must be in [0, 1e9] s, got %g",
                       c->stop_ramp_time);
        if (c->max_angle > 0.0 && c->max_angle < fabs(c->rate) * c->ramp_time)
            return bad(why, why_len,
                       "drive: max_angle (%g rad) is reached before the start "
                       "ramp ends; lower ramp_time",
                       c->max_angle);
        d->stop_ramp = c->stop_ramp_time;
        if (c->max_angle > 0.0 && c->rate != 0.0) {
            /* The stop ramp may not begin before the start ramp has ended. */
            double room = 2.0 * c->max_angle / fabs(c->rate) - c->ramp_time;
            if (d->stop_ramp > room)
                d->stop_ramp = room;
        }
        c->axis = v3_scale(c->axis, 1.0 / n);
        break;
    }
    case WS_DRIVE_SINE: {
        double om = 2.0 * WS_PI * c->frequency;
        if (!(isfinite(c->amplitude) && fabs(c->amplitude) <= 1e6))
            return bad(why, why_len, "drive: sine amplitude must be within +-1e6 m, got %g",
                       c->amplitude);
        if (!isfinite(c->phase) || fabs(c->phase) > 1e6 ||
            !(isfinite(c->frequency) && c->frequency >= 0.0 && c->frequency <= 1e6))
            return bad(why, why_len,
                       "drive: sine needs a finite amplitude, a phase within "
                       "+-1e6 rad and a frequency in [0, 1e6] Hz, got frequency %g",
                       c->frequency);
        /* The acceleration amplitude omega^2 A and its product with the ramp's slopes must
         * stay finite. */
        if (!(fabs(c->amplitude) * om * om < 1e12))
            return bad(why, why_len,
                       "drive: sine acceleration amplitude (2 pi f)^2 amplitude "
                       "must be < 1e12 m/s^2, got amplitude %g m",
                       c->amplitude);
        break;
    }
    case WS_DRIVE_CALLBACK:
        if (!c->callback)
            return bad_text(why, why_len, "drive: WS_DRIVE_CALLBACK needs a callback");
        break;
    case WS_DRIVE_PULSE:
        s = setup_pulse(d, why, why_len);
        break;
    case WS_DRIVE_IMPACT:
        s = setup_impact(d, why, why_len);
        break;
    case WS_DRIVE_TABLE:
        s = setup_table(d, mem, def, why, why_len);
        break;
    case WS_DRIVE_RANDOM:
        s = setup_random(d, mem, def, why, why_len);
        break;
    case WS_DRIVE_SWEEP:
        s = setup_sweep(c, why, why_len);
        break;
    default:
        return bad(why, why_len, "drive: unknown type %g", (double)c->type);
    }
    if (s != WS_OK) {
        ws_drive_release(d, mem);
        if (s == WS_ERR_OUT_OF_MEMORY && why && why_len)
            snprintf(why, why_len, "drive: out of memory for its table");
        return s;
    }
    if (d->tab) {
        double *A = d->tab, *V = d->tab + d->tab_n, *X = d->tab + 2 * d->tab_n;
        if (c->type == WS_DRIVE_RANDOM || c->table_end_at_rest)
            end_at_rest(A, d->tab_n, d->tab_h, V, X);
        integrate_table(A, d->tab_n, d->tab_h, V, X);
    }
    return WS_OK;
}

void ws_drive_release(ws_drive *d, ws_mem *mem)
{
    if (d->tab)
        ws_mem_free(mem, d->tab, 3 * d->tab_n * sizeof(double));
    d->tab = NULL;
    d->tab_n = 0;
}

/* ---- evaluation ---- */

/* Sweep: displacement, velocity and acceleration along the direction at tau. */
static void sweep_at(const ws_drive_def *c, double tau, double *x, double *v, double *a)
{
    double T = c->duration, R = c->ramp_time, f1 = c->frequency, f2 = c->frequency_end;
    *x = *v = *a = 0.0;
    if (tau <= 0.0 || tau >= T)
        return;
    /* Envelope: smoothstep in over R and out over R. */
    double e = 1.0, de = 0.0, dde = 0.0;
    if (R > 0.0) {
        double s1 = 1.0, d1 = 0.0, dd1 = 0.0, s2 = 1.0, d2 = 0.0, dd2 = 0.0;
        if (tau < R) {
            double u = tau / R;
            s1 = smooth(u);
            d1 = 6.0 * u * (1.0 - u) / R;
            dd1 = 6.0 * (1.0 - 2.0 * u) / (R * R);
        }
        if (T - tau < R) {
            double u = (T - tau) / R;
            s2 = smooth(u);
            d2 = -6.0 * u * (1.0 - u) / R;
            dd2 = 6.0 * (1.0 - 2.0 * u) / (R * R);
        }
        e = s1 * s2;
        de = d1 * s2 + s1 * d2;
        dde = dd1 * s2 + 2.0 * d1 * d2 + s1 * dd2;
    }
    double f, df, ddf, phi;
    if (c->sweep_law == WS_SWEEP_LOG && f1 != f2) {
        double L = log(f2 / f1) / T;
        f = f1 * exp(L * tau);
        df = f * L;
        ddf = df * L;
        phi = 2.0 * WS_PI * f1 * (exp(L * tau) - 1.0) / L;
    } else {
        double k = (f2 - f1) / T;
        f = f1 + k * tau;
        df = k;
        ddf = 0.0;
        phi = 2.0 * WS_PI * (f1 * tau + 0.5 * k * tau * tau);
    }
    double w = 2.0 * WS_PI * f, dw = 2.0 * WS_PI * df, ddw = 2.0 * WS_PI * ddf;
    double A = c->acceleration;
    /* x = u sin(phi), u = -A e / w^2. */
    double iw2 = 1.0 / (w * w);
    double u = -A * e * iw2;
    double du = -A * (de * iw2 - 2.0 * e * dw * iw2 / w);
    double ddu = -A * (dde * iw2 - 4.0 * de * dw * iw2 / w - 2.0 * e * ddw * iw2 / w +
                       6.0 * e * dw * dw * iw2 * iw2);
    double sn = sin(phi), cs = cos(phi);
    *x = u * sn;
    *v = du * sn + u * w * cs;
    *a = ddu * sn + 2.0 * du * w * cs + u * dw * cs - u * w * w * sn;
}

/* Sine: displacement, velocity, acceleration along the direction at tau. */
static void sine_at(const ws_drive_def *c, double tau, double *x, double *v, double *a)
{
    *x = *v = *a = 0.0;
    if (tau <= 0.0)
        return;
    double env = 1.0, denv = 0.0, ddenv = 0.0;
    if (c->ramp_time > 0.0 && tau < c->ramp_time) {
        double u = tau / c->ramp_time;
        env = smooth(u);
        denv = 6.0 * u * (1.0 - u) / c->ramp_time;
        ddenv = 6.0 * (1.0 - 2.0 * u) / (c->ramp_time * c->ramp_time);
    }
    double om = 2.0 * WS_PI * c->frequency;
    double s = sin(om * tau + c->phase), co = cos(om * tau + c->phase);
    *x = c->amplitude * env * s;
    *v = c->amplitude * (denv * s + env * om * co);
    *a = c->amplitude * (ddenv * s + 2.0 * denv * om * co - env * om * om * s);
}

static int motion_finite(const ws_drive_motion *m)
{
    return ws_is_finite3(&m->pose.position) && ws_is_finite3(&m->v) && ws_is_finite3(&m->w) &&
           ws_is_finite3(&m->a) && ws_is_finite3(&m->alpha) && isfinite(m->pose.orientation.e0) &&
           isfinite(m->pose.orientation.e1) && isfinite(m->pose.orientation.e2) &&
           isfinite(m->pose.orientation.e3) && isfinite(m->angle) && isfinite(m->rate) &&
           isfinite(m->angacc);
}

int ws_drive_motion_at(const ws_drive *d, double t, ws_drive_motion *m)
{
    const ws_drive_def *c = &d->def;
    memset(m, 0, sizeof *m);
    m->pose = d->base;
    m->has_acc = 1;
    double tau = t - c->start_time, x = 0.0, v = 0.0, a = 0.0;
    switch (c->type) {
    case WS_DRIVE_STATIC:
        return 0;
    case WS_DRIVE_TILT: {
        double th, rate, acc;
        ws_drive_tilt_angle(c, d->stop_ramp, t, &th, &rate, &acc);
        qt q = qt_from_axis_angle(c->axis, th);
        m3 R = qt_to_m3(q);
        v3 arm = m3_mul_v(&R, v3_sub(d->base.position, c->point));
        m->pose.position = v3_add(c->point, arm);
        m->pose.orientation = qt_normalize(qt_mul(q, d->base.orientation));
        m->w = v3_scale(c->axis, rate);
        m->v = v3_cross(m->w, arm);
        m->alpha = v3_scale(c->axis, acc);
        m->a = v3_add(v3_cross(m->alpha, arm), v3_cross(m->w, m->v));
        m->angle = th;
        m->rate = rate;
        m->angacc = acc;
        return motion_finite(m) ? 0 : 1;
    }
    case WS_DRIVE_CALLBACK: {
        m->has_acc = 0;
        int rc = c->callback(c->callback_user, t, &m->pose, &m->v, &m->w);
        if (rc != 0)
            return rc;
        if (!motion_finite(m) || !(qt_norm(m->pose.orientation) > 0.0))
            return -1;
        m->pose.orientation = qt_normalize(m->pose.orientation);
        return 0;
    }
    case WS_DRIVE_SINE:
        sine_at(c, tau, &x, &v, &a);
        break;
    case WS_DRIVE_PULSE:
    case WS_DRIVE_IMPACT:
        profile_at(d, tau, &a, &v, &x);
        break;
    case WS_DRIVE_TABLE:
    case WS_DRIVE_RANDOM:
        table_at(d, tau, &a, &v, &x);
        break;
    case WS_DRIVE_SWEEP:
        sweep_at(c, tau, &x, &v, &a);
        break;
    }
    m->pose.position = v3_madd(d->base.position, c->direction, x);
    m->v = v3_scale(c->direction, v);
    m->a = v3_scale(c->direction, a);
    return motion_finite(m) ? 0 : 1;
}

int ws_drive_eval(const ws_drive *d, double t, ws_pose *pose, v3 *v, v3 *w)
{
    ws_drive_motion m;
    int rc = ws_drive_motion_at(d, t, &m);
    *pose = m.pose;
    *v = m.v;
    *w = m.w;
    return rc;
}
