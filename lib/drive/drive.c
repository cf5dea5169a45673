#include "drive/drive.h"

#include "base/base.h"

#include <stdio.h>
#include <string.h>

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
 * exactly that of an instant start at c. */
static void ramp_centered(double t, double c, double T, double *g, double *dg)
{
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
    }
}

void ws_drive_tilt_angle(const ws_drive_def *def, double t, double *theta, double *rate)
{
    double g, dg;
    ramp_centered(t, def->start_time, def->ramp_time, &g, &dg);
    double th = def->rate * g, rt = def->rate * dg;
    if (def->max_angle > 0.0 && def->rate != 0.0) {
        /* The stop mirrors the start: the rate ramps down centred on the time the free angle
         * would reach max_angle, so the angle settles exactly on it. */
        double stop = def->start_time + def->max_angle / fabs(def->rate);
        double g2, dg2;
        ramp_centered(t, stop, def->ramp_time, &g2, &dg2);
        th -= def->rate * g2;
        rt -= def->rate * dg2;
    }
    *theta = th;
    *rate = rt;
}

static int bad(char *why, size_t n, const char *msg)
{
    if (why && n)
        snprintf(why, n, "%s", msg);
    return 1;
}

ws_status ws_drive_setup(ws_drive *d, const ws_drive_def *def, const ws_pose *base, char *why,
                         size_t why_len)
{
    ws_drive_def c = *def;
    if (!(isfinite(c.start_time) && isfinite(c.ramp_time) && c.ramp_time >= 0.0))
        return bad(why, why_len, "drive: start_time must be finite and ramp_time >= 0"),
               WS_ERR_INVALID_ARGUMENT;
    switch (c.type) {
    case WS_DRIVE_STATIC:
        break;
    case WS_DRIVE_TILT: {
        double n = v3_norm(c.axis);
        if (!(n > 0.0) || !isfinite(n) || !ws_is_finite3(&c.point) || !isfinite(c.rate))
            return bad(why, why_len, "drive: tilt needs a non-zero finite axis, a finite point and rate"),
                   WS_ERR_INVALID_ARGUMENT;
        if (!(isfinite(c.max_angle) && c.max_angle >= 0.0))
            return bad(why, why_len, "drive: max_angle must be >= 0 (0 = no limit)"),
                   WS_ERR_INVALID_ARGUMENT;
        if (c.max_angle > 0.0 && c.max_angle < fabs(c.rate) * c.ramp_time)
            return bad(why, why_len,
                       "drive: max_angle is reached before the start ramp ends; lower ramp_time"),
                   WS_ERR_INVALID_ARGUMENT;
        c.axis = v3_scale(c.axis, 1.0 / n);
        break;
    }
    case WS_DRIVE_SINE: {
        double n = v3_norm(c.direction);
        if (!(n > 0.0) || !isfinite(n) || !isfinite(c.amplitude) || !isfinite(c.phase) ||
            !(isfinite(c.frequency) && c.frequency >= 0.0))
            return bad(why, why_len,
                       "drive: sine needs a non-zero direction, finite amplitude and phase, frequency >= 0"),
                   WS_ERR_INVALID_ARGUMENT;
        c.direction = v3_scale(c.direction, 1.0 / n);
        break;
    }
    case WS_DRIVE_CALLBACK:
        if (!c.callback)
            return bad(why, why_len, "drive: WS_DRIVE_CALLBACK needs a callback"),
                   WS_ERR_INVALID_ARGUMENT;
        break;
    default:
        return bad(why, why_len, "drive: unknown type"), WS_ERR_INVALID_ARGUMENT;
    }
    d->def = c;
    d->base = *base;
    return WS_OK;
}

int ws_drive_eval(const ws_drive *d, double t, ws_pose *pose, v3 *v, v3 *w)
{
    const ws_drive_def *c = &d->def;
    *pose = d->base;
    *v = v3_make(0, 0, 0);
    *w = v3_make(0, 0, 0);
    switch (c->type) {
    case WS_DRIVE_STATIC:
        return 0;
    case WS_DRIVE_TILT: {
        double th, rate;
        ws_drive_tilt_angle(c, t, &th, &rate);
        qt q = qt_from_axis_angle(c->axis, th);
        m3 R = qt_to_m3(q);
        v3 arm = m3_mul_v(&R, v3_sub(d->base.position, c->point));
        pose->position = v3_add(c->point, arm);
        pose->orientation = qt_normalize(qt_mul(q, d->base.orientation));
        *w = v3_scale(c->axis, rate);
        *v = v3_cross(*w, arm);
        return 0;
    }
    case WS_DRIVE_SINE: {
        double tau = t - c->start_time;
        if (tau <= 0.0)
            return 0;
        double env = 1.0, denv = 0.0;
        if (c->ramp_time > 0.0 && tau < c->ramp_time) {
            double x = tau / c->ramp_time;
            env = smooth(x);
            denv = 6.0 * x * (1.0 - x) / c->ramp_time;
        }
        double om = 2.0 * WS_PI * c->frequency;
        double s = sin(om * tau + c->phase), co = cos(om * tau + c->phase);
        double x = c->amplitude * env * s;
        double xd = c->amplitude * (denv * s + env * om * co);
        pose->position = v3_madd(d->base.position, c->direction, x);
        *v = v3_scale(c->direction, xd);
        return 0;
    }
    case WS_DRIVE_CALLBACK: {
        int rc = c->callback(c->callback_user, t, pose, v, w);
        if (rc != 0)
            return rc;
        if (!ws_is_finite3(&pose->position) || !ws_is_finite3(v) || !ws_is_finite3(w) ||
            !(qt_norm(pose->orientation) > 0.0) || !isfinite(qt_norm(pose->orientation)))
            return -1;
        pose->orientation = qt_normalize(pose->orientation);
        return 0;
    }
    }
    return 0;
}
