/* EUMOS 40509: the platform's pulse, the run with its measurements and events, the verdict, and
 * the k-value search. Through the public API of the world, as load.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "loadtest/loadtest.h"
#include "math/wmath.h"
#include "world/world_internal.h"

static void eumos_defaults(ws_eumos_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->k = 0.5;
    def->g = 9.81;
    def->rise_time = 0.04;
    def->hold_time = 0.35;
    def->mode = WS_PULSE_ACCELERATE;
    def->stop_level = 0.2;
    def->coast_time = 0.1;
    def->rest_before = 0.05;
    def->rest_after = 0.5;
    def->direction = v3_make(1, 0, 0);
    def->slip_speed = 0.005;
    def->sample_interval = 4;
}

WS_DEF_INITS(ws_eumos_def, eumos_defaults, sample_user)

static void kvalue_defaults(ws_kvalue_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->k_low = 0.05;
    def->k_high = 1.0;
    def->tolerance = 0.01;
    def->settle_time = 4.0;
}

WS_DEF_INITS(ws_kvalue_def, kvalue_defaults, wrap)

/* ---- the pulse ---------------------------------------------------------------------------- */

static int pulse_check(const ws_eumos_def *d, char *why, size_t len)
{
#define NEED(cond, ...)                                                                          \
    do {                                                                                          \
        if (!(cond)) {                                                                            \
            snprintf(why, len, __VA_ARGS__);                                                      \
            return -1;                                                                            \
        }                                                                                         \
    } while (0)
    NEED(isfinite(d->k) && d->k > 0 && d->k <= 10, "k must be in (0, 10] g, got %g", d->k);
    NEED(isfinite(d->g) && d->g > 0 && d->g <= 1e3, "g must be in (0, 1000] m/s^2, got %g",
         d->g);
    NEED(isfinite(d->rise_time) && d->rise_time > 0 && d->rise_time <= 1e3,
         "rise_time must be in (0, 1000] s, got %g", d->rise_time);
    NEED(isfinite(d->hold_time) && d->hold_time >= 0 && d->hold_time <= 1e3,
         "hold_time must be in [0, 1000] s, got %g", d->hold_time);
    NEED(d->mode == WS_PULSE_ACCELERATE || d->mode == WS_PULSE_BRAKE, "unknown mode %d",
         (int)d->mode);
    NEED(isfinite(d->stop_level) && d->stop_level > 0 && d->stop_level <= 10,
         "stop_level must be in (0, 10] g, got %g", d->stop_level);
    NEED(isfinite(d->coast_time) && d->coast_time >= 0 && d->coast_time <= 1e3,
         "coast_time must be in [0, 1000] s, got %g", d->coast_time);
    NEED(isfinite(d->rest_before) && d->rest_before >= 0 && d->rest_before <= 1e3,
         "rest_before must be in [0, 1000] s, got %g", d->rest_before);
    NEED(isfinite(d->rest_after) && d->rest_after >= 0 && d->rest_after <= 1e3,
         "rest_after must be in [0, 1000] s, got %g", d->rest_after);
    double n = hypot(d->direction.x, d->direction.y);
    NEED(isfinite(n) && n > 0 && isfinite(d->direction.z) && fabs(d->direction.z) <= 1e-12 * n,
         "direction must be horizontal in the platform's frame and not zero");
    NEED(isfinite(d->slip_speed) && d->slip_speed > 0, "slip_speed must be > 0 m/s, got %g",
         d->slip_speed);
    NEED(d->sample_interval >= 1, "sample_interval must be >= 1, got %d", d->sample_interval);
#undef NEED
    return 0;
}

/* The platform's drive, its direction in the platform's frame (the caller turns it into the
 * global frame), and the run's length: rest, the drive (two rises, the hold, the coast and the
 * gentle phase, a raised cosine of peak G whose mean is G / 2, so it takes 2 V / G to undo the
 * speed V = k g (rise + hold) the pulse gives), rest. */
static void pulse_drive(const ws_eumos_def *d, ws_drive_def *dd, double *duration)
{
    double A = d->k * d->g, G = fmin(d->stop_level, 0.5 * d->k) * d->g;
    ws_drive_def_init(dd);
    dd->type = WS_DRIVE_PULSE;
    dd->start_time = d->rest_before;
    dd->direction = d->direction;
    dd->acceleration = A;
    dd->rise_time = d->rise_time;
    dd->hold_time = d->hold_time;
    dd->pulse_mode = d->mode;
    dd->gentle_acceleration = G;
    dd->coast_time = d->coast_time;
    double v = A * (d->rise_time + d->hold_time);
    *duration = d->rest_before + 2 * d->rise_time + d->hold_time + d->coast_time + 2 * v / G +
                d->rest_after;
}

ws_status ws_eumos_get_drive(const ws_eumos_def *def, ws_drive_def *drive, double *duration)
{
    if (!def)
        return WS_ERR_INVALID_ARGUMENT;
    if (ws_def_check(def) != 0)
        return WS_ERR_UNINITIALIZED_DEF;
    ws_eumos_def d;
    ws_eumos_def_init(&d);
    ws_def_copy(&d, sizeof d, def);
    char why[160];
    if (pulse_check(&d, why, sizeof why) != 0)
        return WS_ERR_INVALID_ARGUMENT;
    double n = hypot(d.direction.x, d.direction.y);
    d.direction = v3_make(d.direction.x / n, d.direction.y / n, 0);
    ws_drive_def dd;
    double t;
    pulse_drive(&d, &dd, &t);
    if (drive)
        *drive = dd;
    if (duration)
        *duration = t;
    return WS_OK;
}

/* ---- the run ------------------------------------------------------------------------------ */

typedef struct run_state {
    ws_lt_run m; /* the measurements (record.c) */
    ws_eumos_def d;
    ws_eumos_result *res;
} run_state;

/* The verdict from the permanent displacements (the last sample, after the rest) and the
 * maxima. */
static void judge(run_state *rs)
{
    ws_load *ld = rs->m.ld;
    ws_eumos_result *r = rs->res;
    ws_eumos_verdict *vd = &r->verdict;
    double H = ld->info.load_height, elastic = 0, permanent = 0, bottom, shift;
    ws_lt_permanent(&rs->m, r->layer_permanent, &bottom, &shift);
    for (int l = 0; l < ld->info.layers; l++) {
        elastic = fmax(elastic, r->layer_max[l]);
        permanent = fmax(permanent, r->layer_permanent[l]);
    }
    vd->load_height = H;
    ws_lt_criterion(&vd->elastic, elastic, 0.10 * H, 0);
    ws_lt_criterion(&vd->permanent, permanent, 0.05 * H, 0);
    ws_lt_criterion(&vd->bottom, bottom, 0.04, 0);
    ws_lt_criterion(&vd->layer_shift, shift, 0.02 * H, 1);
    ws_lt_criterion(&vd->rupture, rs->m.broken, 0, 0);
    vd->pass = vd->elastic.pass && vd->permanent.pass && vd->bottom.pass &&
               vd->layer_shift.pass && vd->rupture.pass;
}

/* The platform's drive during a run and where the run stands. */
typedef struct sled {
    double t0, duration, rise_start;
    ws_vec3 r0, dir; /* where the platform started, the direction in global axes */
} sled;

/* Step the whole run, sampling every sample_interval steps; the level is what the platform's
 * drive delivered, read back from the world. */
static ws_status run_steps(ws_world *w, run_state *rs, const sled *sl, double dt)
{
    ws_eumos_result *r = rs->res;
    const double kg = rs->d.k * rs->d.g;
    int64_t total = (int64_t)ceil(sl->duration / dt - 1e-9);
    ws_status s;
    r->rise_measured = -1;
    for (int64_t done = 0; done < total;) {
        int64_t chunk = rs->d.sample_interval;
        if (chunk > total - done)
            chunk = total - done;
        if ((s = ws_world_step_n(w, chunk)) != WS_OK)
            return s;
        done += chunk;
        ws_drive_state ds;
        if ((s = ws_body_get_drive_state(w, rs->m.ld->info.platform, &ds)) != WS_OK)
            return s;
        double t = ds.time - sl->t0;
        double a = v3_dot(ds.acceleration, sl->dir), v = v3_dot(ds.velocity, sl->dir);
        double x = v3_dot(v3_sub(ds.position, sl->r0), sl->dir);
        if (fabs(fabs(a) - kg) <= 0.01 * kg)
            r->time_at_level += (double)chunk * dt;
        if (r->rise_measured < 0 && fabs(a) >= 0.99 * kg)
            r->rise_measured = t - sl->rise_start;
        if ((s = ws_lt_sample(w, &rs->m, t, a / rs->d.g, v, x, 0)) != WS_OK)
            return s;
        r->duration = t;
    }
    return WS_OK;
}

ws_status ws_loadtest_run_eumos(ws_world *w, ws_load *ld, const ws_eumos_def *def,
                                ws_eumos_result *result)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_loadtest_run_eumos");
    NEED_OUT(w, result, "ws_loadtest_run_eumos");
    if (!ld)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_loadtest_run_eumos: load is NULL");
    if (ld->world != w)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_loadtest_run_eumos: the load was built in another world");
    /* The run drives the platform and leaves it static where it stopped: a drive of the
     * caller's would be lost, so the platform must stand on its own. */
    ws_drive_state ds0;
    ws_status s0 = ws_body_get_drive_state(w, ld->info.platform, &ds0);
    if (s0 != WS_OK)
        return s0;
    if (ds0.type != WS_DRIVE_STATIC)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_loadtest_run_eumos: the platform has a drive (type %d); the run "
                       "drives it itself: give it a static drive first",
                       (int)ds0.type);
    run_state rs;
    memset(&rs, 0, sizeof rs);
    ws_eumos_def_init(&rs.d);
    ws_status s = ws_def_take(w, &rs.d, sizeof rs.d, def, "eumos");
    if (s != WS_OK)
        return s;
    char why[160];
    if (pulse_check(&rs.d, why, sizeof why) != 0)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "eumos: %s", why);
    double nd = hypot(rs.d.direction.x, rs.d.direction.y);
    rs.d.direction = v3_make(rs.d.direction.x / nd, rs.d.direction.y / nd, 0);
    memset(result, 0, sizeof *result);
    result->k = rs.d.k;
    result->layers = ld->info.layers;
    rs.res = result;
    rs.m.dir = rs.d.direction;
    rs.m.slip_speed = rs.d.slip_speed;
    rs.m.tip_fraction = 0.01;
    rs.m.on_sample = rs.d.on_sample;
    rs.m.sample_user = rs.d.sample_user;
    ws_lt_sink sink = {&result->peak_level, result->layer_max, result->layer_tilt,
                       result->interface_slip_max, result->interface_use_max,
                       &result->cartons_lost, &result->event_count, &result->events_dropped,
                       result->events, &result->film_peak_strain};

    sled sl;
    double dt;
    ws_mat3 a_pf;
    ws_drive_def dd;
    if ((s = ws_world_get_dt(w, &dt)) != WS_OK ||
        (s = ws_world_get_time(w, &sl.t0)) != WS_OK ||
        (s = ws_body_get_position(w, ld->info.platform, &sl.r0)) != WS_OK ||
        (s = ws_body_get_rotation(w, ld->info.platform, &a_pf)) != WS_OK ||
        (s = ws_load_set_reference(w, ld)) != WS_OK)
        return s;
    pulse_drive(&rs.d, &dd, &sl.duration);
    sl.dir = m3_mul_v(&a_pf, rs.d.direction);
    dd.direction = sl.dir;
    dd.start_time += sl.t0;
    /* The pulse's rise starts after the gentle run-up in the braking variant. */
    sl.rise_start = rs.d.rest_before;
    if (rs.d.mode == WS_PULSE_BRAKE)
        sl.rise_start += rs.d.coast_time + 2 * dd.acceleration *
                                               (rs.d.rise_time + rs.d.hold_time) /
                                               dd.gentle_acceleration;
    if ((s = ws_lt_begin(w, &rs.m, ld, &sink, "EUMOS")) != WS_OK)
        return s;
    if (ld->info.film.bits &&
        (s = ws_load_film_containment(w, ld, result->containment)) != WS_OK) {
        ws_lt_end(&rs.m);
        return s;
    }
    if ((s = ws_body_set_drive(w, ld->info.platform, &dd)) == WS_OK) {
        s = run_steps(w, &rs, &sl, dt);
        /* The platform stays where it stopped. */
        ws_drive_def_init(&dd);
        ws_status s2 = ws_body_set_drive(w, ld->info.platform, &dd);
        if (s == WS_OK)
            s = s2;
    }
    if (s == WS_OK)
        judge(&rs);
    ws_lt_end(&rs.m);
    return s;
}

/* ---- the k-value -------------------------------------------------------------------------- */

/* The k-value search's world: the load built and settled once, its state saved; every run
 * restores that state first, so each starts from the same settled load to the bit. */
typedef struct kworld {
    ws_world *w;
    ws_load *ld;
    void *state;
    size_t len;
} kworld;

/* Let the load come to rest: until its drift stays under 0.1 mm/s (ws_load_settle), at most
 * the Def's settle time; *still and *taken add up over the stages (unwrapped, wrapped). */
static ws_status kworld_settle(kworld *kw, double most, int *still, double *taken)
{
    int st = 0;
    double t = 0;
    ws_status s = ws_load_settle(kw->w, kw->ld, fmin(0.2, most), most, 1e-4, &st, &t);
    *still &= st;
    *taken += t;
    return s;
}

static ws_status kworld_make(kworld *kw, const ws_world_def *wd, const ws_load_def *ldef,
                             const ws_kvalue_def *kd, ws_kvalue_result *result)
{
    double settle = kd->settle_time;
    memset(kw, 0, sizeof *kw);
    ws_status s = ws_world_create(wd, &kw->w);
    if (s != WS_OK)
        return s;
    result->settled = 1;
    if ((s = ws_load_build(kw->w, ldef, &kw->ld)) != WS_OK ||
        (s = kworld_settle(kw, settle, &result->settled, &result->settle_taken)) != WS_OK)
        return s;
    ws_web_id film;
    if (kd->wrap && ((s = ws_load_wrap_band(kw->w, kw->ld, kd->wrap, &film)) != WS_OK ||
                     (s = kworld_settle(kw, settle, &result->settled, &result->settle_taken)) !=
                         WS_OK))
        return s;
    if (!kd->wrap && kd->spiral &&
        ((s = ws_load_wrap_spiral(kw->w, kw->ld, kd->spiral, &film)) != WS_OK ||
         (s = kworld_settle(kw, settle, &result->settled, &result->settle_taken)) != WS_OK))
        return s;
    if ((s = ws_world_save(kw->w, NULL, 0, &kw->len)) != WS_OK)
        return s;
    kw->state = ws_mem_alloc(&kw->ld->mem, kw->len);
    if (!kw->state)
        return ws_fail(kw->w, WS_ERR_OUT_OF_MEMORY, "k-value: no room for a saved state of %zu "
                                                    "bytes", kw->len);
    return ws_world_save(kw->w, kw->state, kw->len, &kw->len);
}

static void kworld_free(kworld *kw)
{
    if (kw->ld)
        ws_mem_free(&kw->ld->mem, kw->state, kw->len);
    ws_load_destroy(kw->ld);
    ws_world_destroy(kw->w);
}

static ws_status run_at(kworld *kw, const ws_eumos_def *ed, double k, ws_eumos_result *res)
{
    ws_eumos_def d = *ed;
    d.k = k;
    ws_status s = ws_world_restore(kw->w, kw->state, kw->len);
    return s != WS_OK ? s : ws_loadtest_run_eumos(kw->w, kw->ld, &d, res);
}

static ws_status search(kworld *kw, const ws_eumos_def *ed, const ws_kvalue_def *kd,
                        ws_kvalue_result *result)
{
    ws_eumos_result *res = &result->last_pass, trial;
    ws_status s;
    double lo = kd->k_low, hi = kd->k_high;
    result->runs++;
    if ((s = run_at(kw, ed, lo, &trial)) != WS_OK)
        return s;
    if (!trial.verdict.pass) {
        result->k_fail = lo;
        return WS_OK;
    }
    *res = trial;
    result->runs++;
    if ((s = run_at(kw, ed, hi, &trial)) != WS_OK)
        return s;
    if (trial.verdict.pass) {
        result->k_value = hi;
        *res = trial;
        return WS_OK;
    }
    while (hi - lo > kd->tolerance) {
        double mid = 0.5 * (lo + hi);
        result->runs++;
        if ((s = run_at(kw, ed, mid, &trial)) != WS_OK)
            return s;
        if (trial.verdict.pass) {
            lo = mid;
            *res = trial;
        } else {
            hi = mid;
        }
    }
    result->k_value = lo;
    result->k_fail = hi;
    return WS_OK;
}

ws_status ws_loadtest_find_k(const ws_world_def *world_def, const ws_load_def *load_def,
                             const ws_eumos_def *eumos_def, const ws_kvalue_def *def,
                             ws_kvalue_result *result)
{
    if (!world_def || !load_def || !eumos_def || !def || !result)
        return WS_ERR_INVALID_ARGUMENT;
    memset(result, 0, sizeof *result);
    if (ws_def_check(def) != 0 || ws_def_check(eumos_def) != 0) {
        snprintf(result->error, sizeof result->error,
                 "ws_loadtest_find_k: a Def was not filled by its ws_*_def_init()");
        return WS_ERR_UNINITIALIZED_DEF;
    }
    ws_kvalue_def kd;
    ws_kvalue_def_init(&kd);
    ws_def_copy(&kd, sizeof kd, def);
    ws_eumos_def ed;
    ws_eumos_def_init(&ed);
    ws_def_copy(&ed, sizeof ed, eumos_def);
    if (!(isfinite(kd.k_low) && kd.k_low > 0 && isfinite(kd.k_high) && kd.k_high > kd.k_low &&
          isfinite(kd.tolerance) && kd.tolerance > 0 && isfinite(kd.settle_time) &&
          kd.settle_time > 0)) {
        snprintf(result->error, sizeof result->error,
                 "ws_loadtest_find_k: need 0 < k_low < k_high, tolerance > 0, settle_time > 0; "
                 "got %g, %g, %g, %g", kd.k_low, kd.k_high, kd.tolerance, kd.settle_time);
        return WS_ERR_INVALID_ARGUMENT;
    }
    kworld kw;
    ws_status s = kworld_make(&kw, world_def, load_def, &kd, result);
    if (s == WS_OK)
        s = search(&kw, &ed, &kd, result);
    if (s != WS_OK)
        snprintf(result->error, sizeof result->error, "%s",
                 kw.w ? ws_world_last_error(kw.w) : ws_status_string(s));
    kworld_free(&kw);
    return s;
}
