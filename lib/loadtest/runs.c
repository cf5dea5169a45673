/* The tests beside EUMOS 40509, as drives of the platform: the ISO 10531 tilt, the horizontal
 * impact (ASTM D4003 / D5414, ISTA 3E), random vibration (ASTM D4169 truck, ISTA) and the sine
 * sweep that finds the load's resonance. Each measures through record.c, judges by its own
 * criteria and, unless asked to keep it, leaves the world as it found it (a saved state
 * restored). Through the public API of the world, as load.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <wrapsim/io.h>

#include "loadtest/loadtest.h"
#include "math/wmath.h"
#include "world/world_internal.h"

#define LT_PI 3.14159265358979323846

/* ---- the Defs ----------------------------------------------------------------------------- */

static void tilt_defaults(ws_tilt_test_def *d)
{
    ws_def_reset(d, sizeof *d);
    d->rate = 0.05;
    d->target_angle = atan(0.5);
    d->max_angle = 0;
    d->ramp_time = 0.5;
    d->stop_time = 1.0;
    d->hold_time = 0.5;
    d->stop_at_failure = 1;
    d->after_failure = 0.5;
    d->direction = v3_make(1, 0, 0);
    d->rest_before = 0.05;
    d->slip_speed = 0.0002;
    d->tip_fraction = 0.001;
    d->sample_interval = 4;
}

WS_DEF_INITS(ws_tilt_test_def, tilt_defaults, sample_user)

static void impact_defaults(ws_impact_test_def *d)
{
    ws_def_reset(d, sizeof *d);
    d->speed = 1.2;
    d->pulse_duration = 0.01;
    d->gentle_acceleration = 2.0;
    d->coast_time = 0.2;
    d->rest_before = 0.05;
    d->rest_after = 0.5;
    d->direction = v3_make(1, 0, 0);
    d->slip_speed = 0.005;
    d->tip_fraction = 0.01;
    d->sample_interval = 4;
}

WS_DEF_INITS(ws_impact_test_def, impact_defaults, sample_user)

static void vibration_defaults(ws_vibration_test_def *d)
{
    ws_def_reset(d, sizeof *d);
    d->grms = 0.54;
    d->seed = 1;
    d->sample_rate = 1024;
    d->sweep_level = 0.25;
    d->frequency_start = 2;
    d->frequency_end = 40;
    d->sweep_law = WS_SWEEP_LOG;
    d->duration = 10;
    d->ramp_time = 0.5;
    d->direction = v3_make(0, 0, 1);
    d->rest_before = 0.05;
    d->rest_after = 0.5;
    d->slip_speed = 0.005;
    d->tip_fraction = 0.01;
    d->sample_interval = 4;
}

WS_DEF_INITS(ws_vibration_test_def, vibration_defaults, sample_user)

const char *ws_loadtest_check_name(int id)
{
    switch (id) {
    case WS_CHECK_STABLE_ANGLE: return "stable_angle";
    case WS_CHECK_CARTONS_LOST: return "cartons_lost";
    case WS_CHECK_PERMANENT: return "permanent";
    case WS_CHECK_LAYER_SHIFT: return "layer_shift";
    case WS_CHECK_VELOCITY_CHANGE: return "velocity_change";
    case WS_CHECK_GRMS: return "grms";
    case WS_CHECK_RESONANCE: return "resonance";
    case WS_CHECK_RUPTURE: return "rupture";
    default: return "unknown";
    }
}

#define NEED(cond, ...)                                                                          \
    do {                                                                                          \
        if (!(cond)) {                                                                            \
            snprintf(why, len, __VA_ARGS__);                                                      \
            return -1;                                                                            \
        }                                                                                         \
    } while (0)

/* A time in s: finite, in [0, 1e4]. */
static int time_ok(double t) { return isfinite(t) && t >= 0 && t <= 1e4; }

static int common_check(double slip_speed, double tip_fraction, int sample_interval, char *why,
                        size_t len)
{
    NEED(isfinite(slip_speed) && slip_speed > 0 && slip_speed <= 10,
         "slip_speed must be in (0, 10] m/s, got %g", slip_speed);
    NEED(isfinite(tip_fraction) && tip_fraction > 0 && tip_fraction < 0.5,
         "tip_fraction must be in (0, 0.5), got %g", tip_fraction);
    NEED(sample_interval >= 1, "sample_interval must be >= 1, got %d", sample_interval);
    return 0;
}

/* A direction: finite, not zero; horizontal when asked. Normalised into *out. */
static int direction_ok(ws_vec3 d, int horizontal, ws_vec3 *out, char *why, size_t len)
{
    double n = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    NEED(isfinite(n) && n > 0, "direction must be finite and not zero");
    NEED(!horizontal || fabs(d.z) <= 1e-12 * n,
         "direction must be horizontal in the platform's frame");
    *out = v3_scale(d, 1 / n);
    return 0;
}

static int tilt_check(ws_tilt_test_def *d, char *why, size_t len)
{
    NEED(isfinite(d->rate) && d->rate > 0 && d->rate <= 1, "rate must be in (0, 1] rad/s, got %g",
         d->rate);
    NEED(isfinite(d->target_angle) && d->target_angle > 0 && d->target_angle < 0.5 * LT_PI,
         "target_angle must be in (0, pi/2) rad, got %g", d->target_angle);
    NEED(isfinite(d->max_angle) && (d->max_angle == 0 || (d->max_angle >= d->target_angle &&
                                                          d->max_angle < 0.5 * LT_PI)),
         "max_angle must be 0 or in [target_angle, pi/2) rad, got %g", d->max_angle);
    NEED(time_ok(d->ramp_time) && time_ok(d->stop_time) && time_ok(d->hold_time) &&
             time_ok(d->after_failure) && time_ok(d->rest_before),
         "ramp_time, stop_time, hold_time, after_failure and rest_before must be in [0, 1e4] s");
    if (direction_ok(d->direction, 1, &d->direction, why, len) != 0)
        return -1;
    return common_check(d->slip_speed, d->tip_fraction, d->sample_interval, why, len);
}

static int impact_check(ws_impact_test_def *d, char *why, size_t len)
{
    NEED(isfinite(d->speed) && d->speed > 0 && d->speed <= 20,
         "speed must be in (0, 20] m/s, got %g", d->speed);
    NEED(isfinite(d->pulse_duration) && d->pulse_duration > 0 && d->pulse_duration <= 1,
         "pulse_duration must be in (0, 1] s, got %g", d->pulse_duration);
    NEED(isfinite(d->gentle_acceleration) && d->gentle_acceleration > 0 &&
             d->gentle_acceleration <= 100,
         "gentle_acceleration must be in (0, 100] m/s^2, got %g", d->gentle_acceleration);
    NEED(time_ok(d->coast_time) && time_ok(d->rest_before) && time_ok(d->rest_after),
         "coast_time, rest_before and rest_after must be in [0, 1e4] s");
    if (direction_ok(d->direction, 1, &d->direction, why, len) != 0)
        return -1;
    return common_check(d->slip_speed, d->tip_fraction, d->sample_interval, why, len);
}

static int vibration_check(ws_vibration_test_def *d, char *why, size_t len)
{
    NEED(d->sweep == 0 || d->sweep == 1, "sweep must be 0 or 1, got %d", d->sweep);
    NEED(isfinite(d->duration) && d->duration > 0 && d->duration <= 1e4,
         "duration must be in (0, 1e4] s, got %g", d->duration);
    NEED(time_ok(d->ramp_time) && 2 * d->ramp_time < d->duration,
         "ramp_time must be >= 0 and less than half the duration, got %g", d->ramp_time);
    NEED(time_ok(d->rest_before) && time_ok(d->rest_after),
         "rest_before and rest_after must be in [0, 1e4] s");
    if (d->sweep) {
        NEED(isfinite(d->sweep_level) && d->sweep_level > 0 && d->sweep_level <= 10,
             "sweep_level must be in (0, 10] g, got %g", d->sweep_level);
        NEED(isfinite(d->frequency_start) && d->frequency_start > 0 &&
                 isfinite(d->frequency_end) && d->frequency_end > d->frequency_start &&
                 d->frequency_end <= 1e4,
             "need 0 < frequency_start < frequency_end <= 1e4 Hz, got %g, %g",
             d->frequency_start, d->frequency_end);
        NEED(d->sweep_law == WS_SWEEP_LOG || d->sweep_law == WS_SWEEP_LINEAR,
             "unknown sweep_law %d", (int)d->sweep_law);
        NEED(isfinite(d->resonance_min) && d->resonance_min >= 0,
             "resonance_min must be >= 0 Hz, got %g", d->resonance_min);
    } else {
        NEED(isfinite(d->grms) && d->grms >= 0 && d->grms <= 20,
             "grms must be in [0, 20] g, got %g", d->grms);
        NEED(!d->psd_frequency == !d->psd_level,
             "psd_frequency and psd_level must be given together");
        NEED(!d->psd_frequency || d->psd_count >= 2,
             "psd_count must be >= 2 with breakpoints, got %zu", d->psd_count);
    }
    if (direction_ok(d->direction, 0, &d->direction, why, len) != 0)
        return -1;
    return common_check(d->slip_speed, d->tip_fraction, d->sample_interval, why, len);
}

#undef NEED

/* ---- a run: open, step, close ------------------------------------------------------------- */

typedef struct lt_test {
    ws_lt_run m;
    ws_loadtest_result *res;
    const char *name;
    int keep;
    void *saved; /* the world's state before the run (unless keep) */
    size_t saved_len;
    double t0, dt;
    ws_vec3 r0, dir; /* the platform's CoG at the start; the drive's direction, global */
    ws_mat3 a_pf;    /* the platform's rotation at the start */
    int sample_interval;
} lt_test;

/* Check the arguments, save the world (unless keep), take the reference, set up the
 * measurements. On error nothing is held. */
static ws_status test_open(ws_world *w, ws_load *ld, ws_loadtest_result *res, lt_test *lt,
                           const char *name)
{
    ws_status s;
    lt->res = res;
    lt->name = name;
    memset(res, 0, sizeof *res);
    res->layers = ld->info.layers;
    res->failure_angle = -1;
    res->failure_event = -1;
    res->verdict.load_height = ld->info.load_height;
    if ((s = ws_world_get_dt(w, &lt->dt)) != WS_OK ||
        (s = ws_world_get_time(w, &lt->t0)) != WS_OK ||
        (s = ws_body_get_position(w, ld->info.platform, &lt->r0)) != WS_OK ||
        (s = ws_body_get_rotation(w, ld->info.platform, &lt->a_pf)) != WS_OK)
        return s;
    lt->dir = m3_mul_v(&lt->a_pf, lt->m.dir);
    if (!lt->keep) {
        if ((s = ws_world_save(w, NULL, 0, &lt->saved_len)) != WS_OK)
            return s;
        lt->saved = ws_mem_alloc(&ld->mem, lt->saved_len);
        if (!lt->saved)
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY,
                           "%s run: no room to save the world's state (%zu bytes)", name,
                           lt->saved_len);
        if ((s = ws_world_save(w, lt->saved, lt->saved_len, &lt->saved_len)) != WS_OK) {
            ws_mem_free(&ld->mem, lt->saved, lt->saved_len);
            lt->saved = NULL;
            return s;
        }
    }
    ws_lt_sink sink = {&res->peak_level, res->layer_max, res->layer_tilt,
                       res->interface_slip_max, res->interface_use_max, &res->cartons_lost,
                       &res->event_count, &res->events_dropped, res->events,
                       &res->film_peak_strain};
    if ((s = ws_load_set_reference(w, ld)) != WS_OK ||
        (s = ws_lt_begin(w, &lt->m, ld, &sink, name)) != WS_OK) {
        ws_mem_free(&ld->mem, lt->saved, lt->saved_len);
        lt->saved = NULL;
        return s;
    }
    return WS_OK;
}

/* The platform static where it stands; the world restored (unless keep): restore first, so the
 * static drive holds the restored pose. Returns the run's status, or the first error here. */
static ws_status test_close(ws_world *w, lt_test *lt, ws_status s)
{
    ws_load *ld = lt->m.ld;
    ws_status s2 = WS_OK;
    if (lt->saved) {
        s2 = ws_world_restore(w, lt->saved, lt->saved_len);
        ws_mem_free(&ld->mem, lt->saved, lt->saved_len);
        lt->saved = NULL;
    }
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    ws_status s3 = ws_body_set_drive(w, ld->info.platform, &dd);
    ws_lt_end(&lt->m);
    if (s != WS_OK)
        return s;
    return s2 != WS_OK ? s2 : s3;
}

/* What a test does at each step: read what the drive delivered (ds, at run time t), give the
 * level and angle of a sample, and say when to end (1). */
typedef int (*step_fn)(void *ctx, lt_test *lt, const ws_drive_state *ds, double t, double *level,
                       double *angle);

/* Step `duration` s, one step at a time (the tests integrate what the drive delivered at every
 * step), measuring every sample_interval steps and at the last step. */
static ws_status test_steps(ws_world *w, lt_test *lt, double duration, step_fn fn, void *ctx)
{
    int64_t total = (int64_t)ceil(duration / lt->dt - 1e-9);
    ws_status s;
    for (int64_t k = 1; k <= total; k++) {
        if ((s = ws_world_step(w)) != WS_OK)
            return s;
        ws_drive_state ds;
        if ((s = ws_body_get_drive_state(w, lt->m.ld->info.platform, &ds)) != WS_OK)
            return s;
        double t = ds.time - lt->t0, level = 0, angle = 0;
        int end = fn(ctx, lt, &ds, t, &level, &angle);
        if (k % lt->sample_interval == 0 || k == total || end) {
            double v = v3_dot(ds.velocity, lt->dir);
            double x = v3_dot(v3_sub(ds.position, lt->r0), lt->dir);
            if ((s = ws_lt_sample(w, &lt->m, t, level, v, x, angle)) != WS_OK)
                return s;
        }
        lt->res->duration = t;
        if (end)
            break;
    }
    return WS_OK;
}

static void check(ws_loadtest_verdict *vd, int id, double value, double limit, int at_least,
                  int strict)
{
    if (vd->count >= WS_LOADTEST_MAX_CHECKS)
        return;
    ws_loadtest_check *c = &vd->check[vd->count++];
    c->id = id;
    c->at_least = at_least;
    c->value = value;
    c->limit = limit;
    c->pass = at_least ? value >= limit : (strict ? value < limit : value <= limit);
}

/* A wrapped load's film: no spring of it broken by the end of the run. */
static void judge_rupture(lt_test *lt)
{
    if (lt->m.ld->info.film.bits)
        check(&lt->res->verdict, WS_CHECK_RUPTURE, lt->m.broken, 0, 0, 0);
}

static void verdict_pass(ws_loadtest_verdict *vd)
{
    vd->pass = 1;
    for (int i = 0; i < vd->count; i++)
        vd->pass = vd->pass && vd->check[i].pass;
}

/* The permanent state from the last sample: per layer, the largest carton displacement and
 * the largest layer shift; the criteria of EUMOS 40509's permanent and layer limits. */
static void judge_permanent(lt_test *lt, int with_permanent)
{
    ws_loadtest_result *r = lt->res;
    double shift, permanent = 0, H = lt->m.ld->info.load_height;
    ws_lt_permanent(&lt->m, r->layer_permanent, NULL, &shift);
    for (int l = 0; l < r->layers; l++)
        permanent = fmax(permanent, r->layer_permanent[l]);
    if (with_permanent)
        check(&r->verdict, WS_CHECK_PERMANENT, permanent, 0.05 * H, 0, 0);
    check(&r->verdict, WS_CHECK_LAYER_SHIFT, shift, 0.02 * H, 0, 1);
}

static ws_status load_check(ws_world *w, ws_load *ld, const void *result, const char *fn)
{
    NEED_OUT(w, result, fn);
    if (!ld)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: load is NULL", fn);
    if (ld->world != w)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: the load was built in another world", fn);
    return WS_OK;
}

/* ---- tilt ---------------------------------------------------------------------------------- */

typedef struct tilt_ctx {
    ws_tilt_test_def d;
    int seen_events;
    double end_at; /* run time to end at (after a failure), or INFINITY */
} tilt_ctx;

static int tilt_step(void *ctx, lt_test *lt, const ws_drive_state *ds, double t, double *level,
                     double *angle)
{
    tilt_ctx *c = ctx;
    ws_loadtest_result *r = lt->res;
    *angle = ds->angle;
    *level = tan(ds->angle);
    r->angle_reached = fmax(r->angle_reached, ds->angle);
    /* Events of the samples so far: the first of them is the failure (any slip, tip or lost
     * carton ends the load's stability on the tilt). */
    if (r->failure_event < 0 && r->event_count > c->seen_events) {
        const ws_loadtest_event *e = &r->events[c->seen_events];
        r->failure_event = c->seen_events;
        r->failure_angle = atan(e->level);
        if (c->d.stop_at_failure)
            c->end_at = e->time + c->d.after_failure;
    }
    c->seen_events = r->event_count;
    return t >= c->end_at - 0.5 * lt->dt;
}

ws_status ws_loadtest_run_tilt(ws_world *w, ws_load *ld, const ws_tilt_test_def *def,
                               ws_loadtest_result *result)
{
    NEED_WORLD(w);
    ws_status s = load_check(w, ld, result, "ws_loadtest_run_tilt");
    if (s != WS_OK)
        return s;
    tilt_ctx c;
    memset(&c, 0, sizeof c);
    ws_tilt_test_def_init(&c.d);
    if ((s = ws_def_take(w, &c.d, sizeof c.d, def, "tilt test")) != WS_OK)
        return s;
    char why[160];
    if (tilt_check(&c.d, why, sizeof why) != 0)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "tilt test: %s", why);
    const ws_tilt_test_def *d = &c.d;
    double max_angle = d->max_angle > 0 ? d->max_angle : d->target_angle;
    lt_test lt;
    memset(&lt, 0, sizeof lt);
    lt.m.dir = d->direction;
    lt.m.slip_speed = d->slip_speed;
    lt.m.tip_fraction = d->tip_fraction;
    lt.m.on_sample = d->on_sample;
    lt.m.sample_user = d->sample_user;
    lt.keep = d->keep_state;
    lt.sample_interval = d->sample_interval;
    if ((s = test_open(w, ld, result, &lt, "tilt")) != WS_OK)
        return s;
    result->kind = WS_LOADTEST_TILT;
    /* The axis lies in the platform's top face under the pallet's centre, across the downhill
     * direction: about (0, 0, 1) x downhill a positive rate turns downhill down. */
    ws_vec3 r_pal, n = m3_mul_v(&lt.a_pf, v3_make(0, 0, 1));
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    if ((s = ws_body_get_position(w, ld->info.pallet, &r_pal)) == WS_OK) {
        dd.type = WS_DRIVE_TILT;
        dd.axis = m3_mul_v(&lt.a_pf, v3_cross(v3_make(0, 0, 1), d->direction));
        dd.point = v3_madd(r_pal, n, -0.5 * ld->pallet_size.z - ld->contact_layer);
        dd.rate = d->rate;
        dd.max_angle = max_angle;
        dd.ramp_time = d->ramp_time;
        dd.stop_ramp_time = d->stop_time;
        /* The rate ramp is centred on start_time: it begins rest_before from now. */
        dd.start_time = lt.t0 + d->rest_before + 0.5 * d->ramp_time;
        s = ws_body_set_drive(w, ld->info.platform, &dd);
    }
    double duration = d->rest_before + 0.5 * d->ramp_time + max_angle / d->rate +
                      0.5 * d->stop_time + d->hold_time;
    c.end_at = INFINITY;
    if (s == WS_OK)
        s = test_steps(w, &lt, duration, tilt_step, &c);
    if (s == WS_OK) {
        ws_loadtest_verdict *vd = &result->verdict;
        double stable = result->failure_event >= 0 ? result->failure_angle
                                                   : result->angle_reached;
        /* Cartons lost up to the target angle (one lost beyond it, after the load stood to the
         * target, is the failure the stable angle already reports). */
        int lost = 0;
        for (int i = 0; i < result->event_count; i++)
            lost += result->events[i].type == WS_LOADTEST_CARTON_LOST &&
                    result->events[i].level <= tan(d->target_angle);
        check(vd, WS_CHECK_STABLE_ANGLE, stable, d->target_angle, 1, 0);
        check(vd, WS_CHECK_CARTONS_LOST, lost, 0, 0, 0);
        judge_rupture(&lt);
        ws_lt_permanent(&lt.m, result->layer_permanent, NULL, NULL);
        verdict_pass(vd);
    }
    return test_close(w, &lt, s);
}

/* ---- impact -------------------------------------------------------------------------------- */

typedef struct impact_ctx {
    double t_impact, g;
    double a_prev, t_prev;
    int started;
} impact_ctx;

static int impact_step(void *ctx, lt_test *lt, const ws_drive_state *ds, double t,
                       double *level, double *angle)
{
    impact_ctx *c = ctx;
    ws_loadtest_result *r = lt->res;
    double a = v3_dot(ds->acceleration, lt->dir), v = v3_dot(ds->velocity, lt->dir);
    *level = a / c->g;
    *angle = 0;
    /* The programmer's pulse from two steps before its start: the acceleration is zero while
     * the platform coasts, so the trapezoids outside the pulse add nothing. */
    if (t >= c->t_impact - 2 * lt->dt) {
        if (!c->started) {
            c->started = 1;
            r->impact_speed = v;
        } else {
            r->velocity_change -= 0.5 * (a + c->a_prev) * (t - c->t_prev);
        }
        r->peak_deceleration = fmax(r->peak_deceleration, -a / c->g);
    }
    c->a_prev = a;
    c->t_prev = t;
    return 0;
}

ws_status ws_loadtest_run_impact(ws_world *w, ws_load *ld, const ws_impact_test_def *def,
                                 ws_loadtest_result *result)
{
    NEED_WORLD(w);
    ws_status s = load_check(w, ld, result, "ws_loadtest_run_impact");
    if (s != WS_OK)
        return s;
    ws_impact_test_def d;
    ws_impact_test_def_init(&d);
    if ((s = ws_def_take(w, &d, sizeof d, def, "impact test")) != WS_OK)
        return s;
    char why[160];
    if (impact_check(&d, why, sizeof why) != 0)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "impact test: %s", why);
    lt_test lt;
    memset(&lt, 0, sizeof lt);
    lt.m.dir = d.direction;
    lt.m.slip_speed = d.slip_speed;
    lt.m.tip_fraction = d.tip_fraction;
    lt.m.on_sample = d.on_sample;
    lt.m.sample_user = d.sample_user;
    lt.keep = d.keep_state;
    lt.sample_interval = d.sample_interval;
    if ((s = test_open(w, ld, result, &lt, "impact")) != WS_OK)
        return s;
    result->kind = WS_LOADTEST_IMPACT;
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    dd.type = WS_DRIVE_IMPACT;
    dd.start_time = lt.t0 + d.rest_before;
    dd.direction = lt.dir;
    dd.speed = d.speed;
    dd.pulse_duration = d.pulse_duration;
    dd.gentle_acceleration = d.gentle_acceleration;
    dd.coast_time = d.coast_time;
    impact_ctx c;
    memset(&c, 0, sizeof c);
    c.g = WS_STANDARD_GRAVITY;
    /* The run-up is a raised cosine of peak G, mean G / 2: it takes 2 v / G. */
    c.t_impact = d.rest_before + 2 * d.speed / d.gentle_acceleration + d.coast_time;
    double duration = c.t_impact + d.pulse_duration + d.rest_after;
    s = ws_body_set_drive(w, ld->info.platform, &dd);
    if (s == WS_OK)
        s = test_steps(w, &lt, duration, impact_step, &c);
    if (s == WS_OK) {
        ws_loadtest_verdict *vd = &result->verdict;
        check(vd, WS_CHECK_VELOCITY_CHANGE, fabs(result->velocity_change - d.speed) / d.speed,
              0.01, 0, 0);
        judge_permanent(&lt, 1);
        check(vd, WS_CHECK_CARTONS_LOST, result->cartons_lost, 0, 0, 0);
        judge_rupture(&lt);
        verdict_pass(vd);
    }
    return test_close(w, &lt, s);
}

/* ---- vibration: random and sweep ----------------------------------------------------------- */

typedef struct vib_ctx {
    ws_vibration_test_def d;
    double g;
    double sum_a2;   /* random: delivered a^2 over the untapered part */
    long n_a2;
    /* Sweep: per bin, the top layer's and the platform's squared velocity along the drive. */
    double top2[WS_LOADTEST_RESPONSE_BINS], plat2[WS_LOADTEST_RESPONSE_BINS];
    ws_world *w;
    ws_status err;
} vib_ctx;

/* The sweep's frequency at run time tau from its start (the drive's law). */
static double sweep_frequency(const ws_vibration_test_def *d, double tau)
{
    double x = tau / d->duration;
    return d->sweep_law == WS_SWEEP_LINEAR
               ? d->frequency_start + (d->frequency_end - d->frequency_start) * x
               : d->frequency_start * pow(d->frequency_end / d->frequency_start, x);
}

/* The top layer's mean absolute velocity along the drive, m/s. */
static ws_status top_velocity(ws_world *w, const lt_test *lt, double *out)
{
    const ws_load *ld = lt->m.ld;
    int top = ld->info.layers - 1, c0 = ld->layer_start[top], c1 = ld->layer_start[top + 1];
    double sum = 0;
    for (int c = c0; c < c1; c++) {
        ws_vec3 v;
        ws_status s = ws_body_get_velocity(w, ld->carton[c].body, &v);
        if (s != WS_OK)
            return s;
        sum += v3_dot(v, lt->dir);
    }
    *out = sum / (c1 - c0);
    return WS_OK;
}

static int vib_step(void *ctx, lt_test *lt, const ws_drive_state *ds, double t, double *level,
                    double *angle)
{
    vib_ctx *c = ctx;
    const ws_vibration_test_def *d = &c->d;
    double a = v3_dot(ds->acceleration, lt->dir);
    *level = a / c->g;
    *angle = 0;
    double tau = t - d->rest_before;
    if (tau < d->ramp_time || tau > d->duration - d->ramp_time)
        return 0;
    if (!d->sweep) {
        c->sum_a2 += a * a;
        c->n_a2++;
        return 0;
    }
    double f = sweep_frequency(d, tau);
    int nb = WS_LOADTEST_RESPONSE_BINS;
    int b = (int)floor(nb * log(f / d->frequency_start) /
                       log(d->frequency_end / d->frequency_start));
    if (b < 0 || b >= nb)
        return 0;
    double vt;
    ws_status s = top_velocity(c->w, lt, &vt);
    if (s != WS_OK) {
        c->err = s;
        return 1;
    }
    double vp = v3_dot(ds->velocity, lt->dir);
    c->top2[b] += vt * vt;
    c->plat2[b] += vp * vp;
    return 0;
}

/* The response by bin and its peak: the bin of the largest transmissibility, refined by a
 * parabola through it and its neighbours in log f; 0 when the peak is at an end of the band. */
static void sweep_response(vib_ctx *c, ws_loadtest_result *r)
{
    const ws_vibration_test_def *d = &c->d;
    int nb = WS_LOADTEST_RESPONSE_BINS, best = -1;
    double lr = log(d->frequency_end / d->frequency_start) / nb;
    r->response_bins = nb;
    for (int b = 0; b < nb; b++) {
        r->response_frequency[b] = d->frequency_start * exp((b + 0.5) * lr);
        r->response_transmissibility[b] = c->plat2[b] > 0 ? sqrt(c->top2[b] / c->plat2[b]) : 0;
        if (best < 0 || r->response_transmissibility[b] > r->response_transmissibility[best])
            best = b;
    }
    const double *T = r->response_transmissibility;
    if (best <= 0 || best >= nb - 1 || T[best - 1] <= 0 || T[best + 1] <= 0) {
        r->resonance_frequency = 0;
        r->resonance_transmissibility = best >= 0 ? T[best] : 0;
        return;
    }
    double y0 = T[best - 1], y1 = T[best], y2 = T[best + 1], den = y0 - 2 * y1 + y2;
    double off = den < 0 ? 0.5 * (y0 - y2) / den : 0;
    r->resonance_frequency = d->frequency_start * exp((best + 0.5 + off) * lr);
    r->resonance_transmissibility = y1 - 0.25 * (y0 - y2) * off;
}

/* The random drive's PSD: the given breakpoints or the truck's, scaled to grms when asked. The
 * caller frees *f (2 n doubles) from the load's allocator. */
static ws_status random_psd(ws_world *w, ws_load *ld, const ws_vibration_test_def *d, double **f,
                            size_t *n, double *grms)
{
    size_t count = d->psd_frequency ? d->psd_count : 0;
    ws_status s;
    if (!d->psd_frequency && (s = ws_vibration_truck_psd(WS_TRUCK_MEDIUM, NULL, NULL, 0,
                                                         &count)) != WS_OK &&
        s != WS_ERR_BUFFER_TOO_SMALL)
        return ws_fail(w, s, "vibration test: the truck spectrum is not available");
    double *buf = ws_mem_alloc(&ld->mem, 2 * count * sizeof *buf);
    if (!buf)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "vibration test: no room for %zu breakpoints",
                       count);
    if (d->psd_frequency) {
        memcpy(buf, d->psd_frequency, count * sizeof *buf);
        memcpy(buf + count, d->psd_level, count * sizeof *buf);
    } else if ((s = ws_vibration_truck_psd(WS_TRUCK_MEDIUM, buf, buf + count, count, &count)) !=
               WS_OK) {
        ws_mem_free(&ld->mem, buf, 2 * count * sizeof *buf);
        return ws_fail(w, s, "vibration test: the truck spectrum is not available");
    }
    double have;
    if ((s = ws_vibration_grms(buf, buf + count, count, &have)) != WS_OK) {
        ws_mem_free(&ld->mem, buf, 2 * count * sizeof *buf);
        return ws_fail(w, s, "vibration test: bad PSD breakpoints (frequencies > 0 and "
                             "increasing, levels > 0)");
    }
    if (d->grms > 0)
        for (size_t i = 0; i < count; i++)
            buf[count + i] *= (d->grms / have) * (d->grms / have);
    *grms = d->grms > 0 ? d->grms : have;
    *f = buf;
    *n = count;
    return WS_OK;
}

ws_status ws_loadtest_run_vibration(ws_world *w, ws_load *ld, const ws_vibration_test_def *def,
                                    ws_loadtest_result *result)
{
    NEED_WORLD(w);
    ws_status s = load_check(w, ld, result, "ws_loadtest_run_vibration");
    if (s != WS_OK)
        return s;
    vib_ctx c;
    memset(&c, 0, sizeof c);
    ws_vibration_test_def_init(&c.d);
    if ((s = ws_def_take(w, &c.d, sizeof c.d, def, "vibration test")) != WS_OK)
        return s;
    char why[160];
    if (vibration_check(&c.d, why, sizeof why) != 0)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "vibration test: %s", why);
    const ws_vibration_test_def *d = &c.d;
    c.g = WS_STANDARD_GRAVITY;
    c.w = w;
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    double *psd = NULL, grms = 0;
    size_t np = 0;
    if (!d->sweep && (s = random_psd(w, ld, d, &psd, &np, &grms)) != WS_OK)
        return s;
    lt_test lt;
    memset(&lt, 0, sizeof lt);
    lt.m.dir = d->direction;
    lt.m.slip_speed = d->slip_speed;
    lt.m.tip_fraction = d->tip_fraction;
    lt.m.on_sample = d->on_sample;
    lt.m.sample_user = d->sample_user;
    lt.keep = d->keep_state;
    lt.sample_interval = d->sample_interval;
    if ((s = test_open(w, ld, result, &lt, d->sweep ? "sweep" : "vibration")) != WS_OK) {
        ws_mem_free(&ld->mem, psd, 2 * np * sizeof *psd);
        return s;
    }
    result->kind = d->sweep ? WS_LOADTEST_SWEEP : WS_LOADTEST_RANDOM;
    dd.start_time = lt.t0 + d->rest_before;
    dd.direction = lt.dir;
    dd.duration = d->duration;
    dd.ramp_time = d->ramp_time;
    if (d->sweep) {
        dd.type = WS_DRIVE_SWEEP;
        dd.acceleration = d->sweep_level * c.g;
        dd.frequency = d->frequency_start;
        dd.frequency_end = d->frequency_end;
        dd.sweep_law = d->sweep_law;
    } else {
        dd.type = WS_DRIVE_RANDOM;
        dd.psd_frequency = psd;
        dd.psd_level = psd + np;
        dd.psd_count = np;
        dd.seed = d->seed;
        dd.sample_rate = d->sample_rate;
        result->grms_target = grms;
    }
    s = ws_body_set_drive(w, ld->info.platform, &dd); /* the drive copies the PSD */
    ws_mem_free(&ld->mem, psd, 2 * np * sizeof *psd);
    if (s == WS_OK)
        s = test_steps(w, &lt, d->rest_before + d->duration + d->rest_after, vib_step, &c);
    if (s == WS_OK && c.err != WS_OK)
        s = c.err;
    if (s == WS_OK) {
        ws_loadtest_verdict *vd = &result->verdict;
        if (d->sweep) {
            sweep_response(&c, result);
            check(vd, WS_CHECK_RESONANCE, result->resonance_frequency, d->resonance_min, 1, 0);
        } else {
            result->grms_delivered = c.n_a2 ? sqrt(c.sum_a2 / (double)c.n_a2) / c.g : 0;
            check(vd, WS_CHECK_GRMS, fabs(result->grms_delivered - grms) / grms, 0.10, 0, 0);
        }
        judge_permanent(&lt, 0);
        check(vd, WS_CHECK_CARTONS_LOST, result->cartons_lost, 0, 0, 0);
        judge_rupture(&lt);
        verdict_pass(vd);
    }
    return test_close(w, &lt, s);
}
