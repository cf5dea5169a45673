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
    def->settle_time = 1.0;
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

/* Four quarters of a base: a contact more than a quarter of the half-size off the centre along
 * x or y counts for that edge. */
enum { BIN_XP, BIN_XN, BIN_YP, BIN_YN, BINS };

typedef struct run_state {
    ws_load *ld;
    ws_eumos_def d;
    ws_eumos_result *res;
    ws_contact_info *contacts;
    size_t contacts_cap;
    ws_load_carton_state *cs;
    double (*bins)[BINS];     /* per body (pallet = 0, carton c = c + 1): support force by edge */
    double (*ref_bins)[BINS]; /* the same at the first sample */
    unsigned char *tipped, *lost;
    int have_ref_bins;
    int slipped[WS_LOAD_MAX_LAYERS + 1];
    double layer_disp[WS_LOAD_MAX_LAYERS];
    ws_loadtest_interface_state ifs[WS_LOAD_MAX_LAYERS + 1];
    double ifs_use[WS_LOAD_MAX_LAYERS + 1];
    double *strain; /* the film's spring strains (wrapped loads) */
    size_t springs;
} run_state;

static void add_event(ws_eumos_result *r, int type, int layer, int index, double t, double level,
                      double value)
{
    if (r->event_count >= WS_LOADTEST_MAX_EVENTS) {
        r->events_dropped++;
        return;
    }
    ws_loadtest_event *e = &r->events[r->event_count++];
    e->type = type;
    e->layer = layer;
    e->index = index;
    e->time = t;
    e->level = level;
    e->value = value;
}

static double interface_mu(const ws_load *ld, int i)
{
    return ld->friction[i == 0 ? WS_IF_PALLET_PLATFORM
                               : (i == 1 ? WS_IF_CARTON_PALLET : WS_IF_CARTON_CARTON)];
}

/* The support force under each edge of a body from a contact at `point`. */
static ws_status bin_contact(const ws_world *w, const ws_load *ld, const ws_load_key *upper,
                             ws_vec3 point, double fn, double (*bins)[BINS])
{
    ws_body_id id = upper->body < 0 ? ld->info.pallet : ld->carton[upper->body].body;
    ws_vec3 r;
    ws_mat3 a;
    ws_status s;
    if ((s = ws_body_get_position(w, id, &r)) != WS_OK ||
        (s = ws_body_get_rotation(w, id, &a)) != WS_OK)
        return s;
    v3 o = m3_tmul_v(&a, v3_sub(point, r));
    v3 half = upper->body < 0 ? v3_scale(ld->pallet_size, 0.5) : v3_scale(ld->carton_shape, 0.5);
    double *b = bins[upper->body + 1];
    if (o.x > 0.25 * half.x)
        b[BIN_XP] += fn;
    if (o.x < -0.25 * half.x)
        b[BIN_XN] += fn;
    if (o.y > 0.25 * half.y)
        b[BIN_YP] += fn;
    if (o.y < -0.25 * half.y)
        b[BIN_YN] += fn;
    return WS_OK;
}

/* Sort the contacts into interfaces (neighbouring levels) and the bases' edges. */
static ws_status read_contacts(ws_world *w, run_state *rs)
{
    ws_load *ld = rs->ld;
    size_t n;
    ws_status s = ws_world_get_contact_count(w, &n);
    if (s != WS_OK)
        return s;
    if (n > rs->contacts_cap) {
        size_t cap = n + n / 2 + 16;
        void *p = ws_mem_realloc(&ld->mem, rs->contacts, rs->contacts_cap * sizeof *rs->contacts,
                                 cap * sizeof *rs->contacts);
        if (!p)
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "EUMOS run: no room for %zu contacts", n);
        rs->contacts = p;
        rs->contacts_cap = cap;
    }
    if ((s = ws_world_copy_contacts(w, rs->contacts, rs->contacts_cap, &n)) != WS_OK)
        return s;
    int ni = ld->info.layers + 1;
    for (int i = 0; i < ni; i++) {
        memset(&rs->ifs[i], 0, sizeof rs->ifs[i]);
        rs->ifs_use[i] = 0;
    }
    memset(rs->bins, 0, (size_t)(ld->info.cartons + 1) * sizeof *rs->bins);
    for (size_t k = 0; k < n; k++) {
        const ws_contact_info *c = &rs->contacts[k];
        const ws_load_key *ka = ws_load_find(ld, c->body_a), *kb = ws_load_find(ld, c->body_b);
        if (!ka || !kb || abs(ka->level - kb->level) != 1)
            continue;
        const ws_load_key *lower = ka->level < kb->level ? ka : kb;
        const ws_load_key *upper = ka->level < kb->level ? kb : ka;
        ws_loadtest_interface_state *f = &rs->ifs[lower->level];
        double fn = c->normal_force;
        f->normal_force += fn;
        f->slip_speed += fn * v3_norm(c->slip_velocity);
        rs->ifs_use[lower->level] += v3_norm(c->friction_force);
        f->contacts++;
        if ((s = bin_contact(w, ld, upper, c->point, fn, rs->bins)) != WS_OK)
            return s;
    }
    for (int i = 0; i < ni; i++) {
        ws_loadtest_interface_state *f = &rs->ifs[i];
        double mu = interface_mu(ld, i);
        f->friction_use = f->normal_force > 0 && mu > 0 ? rs->ifs_use[i] / (mu * f->normal_force)
                                                        : 0;
        f->slip_speed = f->normal_force > 0 ? f->slip_speed / f->normal_force : 0;
    }
    return WS_OK;
}

/* Tip onset: an edge that carried more than 5 % of the body's support at the first sample now
 * carries less than 1 % of it while the body still rests on something. */
static void find_tips(run_state *rs, double t, double level)
{
    ws_load *ld = rs->ld;
    int nb = ld->info.cartons + 1;
    if (!rs->have_ref_bins) {
        memcpy(rs->ref_bins, rs->bins, (size_t)nb * sizeof *rs->bins);
        rs->have_ref_bins = 1;
        return;
    }
    for (int b = 0; b < nb; b++) {
        if (rs->tipped[b])
            continue;
        const double *now = rs->bins[b], *ref = rs->ref_bins[b];
        double tot_now = now[BIN_XP] + now[BIN_XN], tot_ref = ref[BIN_XP] + ref[BIN_XN];
        double tot_y_now = now[BIN_YP] + now[BIN_YN], tot_y_ref = ref[BIN_YP] + ref[BIN_YN];
        int tip = 0;
        for (int e = 0; e < BINS; e++) {
            double tn = e < 2 ? tot_now : tot_y_now, tr = e < 2 ? tot_ref : tot_y_ref;
            if (tr > 0 && ref[e] > 0.05 * tr && tn > 0.25 * tr && now[e] < 0.01 * tn)
                tip = 1;
        }
        if (tip) {
            rs->tipped[b] = 1;
            int layer = b == 0 ? -1 : ld->carton[b - 1].layer;
            int index = b == 0 ? -1 : ld->carton[b - 1].index;
            add_event(rs->res, WS_LOADTEST_TIP_ONSET, layer, index, t, level, 0);
        }
    }
}

/* One measurement: cartons, layers, interfaces, events, running maxima. */
static ws_status sample(ws_world *w, run_state *rs, double t, double a, double v, double x)
{
    ws_load *ld = rs->ld;
    ws_eumos_result *r = rs->res;
    size_t n;
    ws_status s = ws_load_measure(w, ld, rs->cs, (size_t)ld->info.cartons, &n);
    if (s != WS_OK || (s = read_contacts(w, rs)) != WS_OK)
        return s;
    if (rs->strain) {
        size_t ns;
        if ((s = ws_web_copy_spring_strains(w, ld->info.film, rs->strain, rs->springs, &ns)) !=
            WS_OK)
            return s;
        for (size_t i = 0; i < ns; i++)
            r->film_peak_strain = fmax(r->film_peak_strain, rs->strain[i]);
    }
    double level = a / rs->d.g;
    if (fabs(level) > r->peak_level)
        r->peak_level = fabs(level);
    find_tips(rs, t, level);
    v3 dir = rs->d.direction;
    for (int l = 0; l < ld->info.layers; l++) {
        double sum = 0;
        int c0 = ld->layer_start[l], c1 = ld->layer_start[l + 1];
        for (int c = c0; c < c1; c++) {
            const ws_load_carton_state *cs = &rs->cs[c];
            sum += cs->displacement.x * dir.x + cs->displacement.y * dir.y;
            r->layer_max[l] = fmax(r->layer_max[l], cs->horizontal);
            r->layer_tilt[l] = fmax(r->layer_tilt[l], cs->tilt);
            v3 rel = v3_add(ld->reference[c], cs->displacement);
            int off = fabs(rel.x) > 0.5 * ld->pallet_size.x ||
                      fabs(rel.y) > 0.5 * ld->pallet_size.y ||
                      cs->displacement.z < -0.5 * ld->carton[c].size.z;
            if (off && !rs->lost[c]) {
                rs->lost[c] = 1;
                r->cartons_lost++;
                add_event(r, WS_LOADTEST_CARTON_LOST, l, ld->carton[c].index, t, level,
                          cs->horizontal);
            }
        }
        rs->layer_disp[l] = sum / (c1 - c0);
    }
    for (int i = 0; i <= ld->info.layers; i++) {
        const ws_loadtest_interface_state *f = &rs->ifs[i];
        r->interface_slip_max[i] = fmax(r->interface_slip_max[i], f->slip_speed);
        r->interface_use_max[i] = fmax(r->interface_use_max[i], f->friction_use);
        if (!rs->slipped[i] && f->slip_speed > rs->d.slip_speed) {
            rs->slipped[i] = 1;
            add_event(r, WS_LOADTEST_SLIP_ONSET, i, -1, t, level, f->slip_speed);
        }
    }
    if (rs->d.on_sample) {
        ws_loadtest_sample sm;
        sm.time = t;
        sm.level = level;
        sm.platform_velocity = v;
        sm.platform_position = x;
        sm.cartons = n;
        sm.carton = rs->cs;
        sm.layers = ld->info.layers;
        sm.layer_displacement = rs->layer_disp;
        sm.interfaces = ld->info.layers + 1;
        sm.interface = rs->ifs;
        if (rs->d.on_sample(rs->d.sample_user, &sm) != 0)
            return ws_fail(w, WS_ERR_CALLBACK, "EUMOS run: on_sample stopped the run at t = %g s",
                           t);
    }
    return WS_OK;
}

static void criterion(ws_loadtest_criterion *c, double value, double limit, int strict)
{
    c->value = value;
    c->limit = limit;
    c->pass = strict ? value < limit : value <= limit;
}

/* The verdict from the permanent displacements (rs->cs after the rest) and the maxima. */
static void judge(run_state *rs)
{
    ws_load *ld = rs->ld;
    ws_eumos_result *r = rs->res;
    ws_eumos_verdict *vd = &r->verdict;
    double H = ld->info.load_height, elastic = 0, permanent = 0, bottom = 0, shift = 0;
    double prev_x = 0, prev_y = 0; /* the pallet's own displacement is zero by definition */
    for (int l = 0; l < ld->info.layers; l++) {
        double mx = 0, my = 0;
        int c0 = ld->layer_start[l], c1 = ld->layer_start[l + 1];
        for (int c = c0; c < c1; c++) {
            const ws_load_carton_state *cs = &rs->cs[c];
            r->layer_permanent[l] = fmax(r->layer_permanent[l], cs->horizontal);
            if (ld->carton_bottom[c] < 0.2)
                bottom = fmax(bottom, cs->horizontal);
            mx += cs->displacement.x;
            my += cs->displacement.y;
        }
        mx /= c1 - c0;
        my /= c1 - c0;
        shift = fmax(shift, hypot(mx - prev_x, my - prev_y));
        prev_x = mx;
        prev_y = my;
        elastic = fmax(elastic, r->layer_max[l]);
        permanent = fmax(permanent, r->layer_permanent[l]);
    }
    vd->load_height = H;
    criterion(&vd->elastic, elastic, 0.10 * H, 0);
    criterion(&vd->permanent, permanent, 0.05 * H, 0);
    criterion(&vd->bottom, bottom, 0.04, 0);
    criterion(&vd->layer_shift, shift, 0.02 * H, 1);
    criterion(&vd->rupture, 0, 0, 0);
    vd->pass = vd->elastic.pass && vd->permanent.pass && vd->bottom.pass &&
               vd->layer_shift.pass && vd->rupture.pass;
}

static void run_free(run_state *rs)
{
    ws_load *ld = rs->ld;
    size_t nb = (size_t)ld->info.cartons + 1;
    ws_mem_free(&ld->mem, rs->contacts, rs->contacts_cap * sizeof *rs->contacts);
    ws_mem_free(&ld->mem, rs->cs, (nb - 1) * sizeof *rs->cs);
    ws_mem_free(&ld->mem, rs->bins, nb * sizeof *rs->bins);
    ws_mem_free(&ld->mem, rs->ref_bins, nb * sizeof *rs->ref_bins);
    ws_mem_free(&ld->mem, rs->tipped, nb);
    ws_mem_free(&ld->mem, rs->lost, nb);
    ws_mem_free(&ld->mem, rs->strain, rs->springs * sizeof *rs->strain);
}

static ws_status run_alloc(ws_world *w, run_state *rs)
{
    ws_load *ld = rs->ld;
    size_t nb = (size_t)ld->info.cartons + 1;
    rs->cs = ws_mem_calloc(&ld->mem, nb - 1, sizeof *rs->cs);
    rs->bins = ws_mem_calloc(&ld->mem, nb, sizeof *rs->bins);
    rs->ref_bins = ws_mem_calloc(&ld->mem, nb, sizeof *rs->ref_bins);
    rs->tipped = ws_mem_calloc(&ld->mem, nb, 1);
    rs->lost = ws_mem_calloc(&ld->mem, nb, 1);
    ws_web_info wi;
    if (ld->info.film.bits && ws_web_get_info(w, ld->info.film, &wi) == WS_OK) {
        rs->springs = wi.spring_count;
        rs->strain = ws_mem_calloc(&ld->mem, rs->springs, sizeof *rs->strain);
    }
    if (!rs->cs || !rs->bins || !rs->ref_bins || !rs->tipped || !rs->lost ||
        (rs->springs && !rs->strain)) {
        run_free(rs);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "EUMOS run: out of memory for %zu bodies", nb);
    }
    return WS_OK;
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
        if ((s = ws_body_get_drive_state(w, rs->ld->info.platform, &ds)) != WS_OK)
            return s;
        double t = ds.time - sl->t0;
        double a = v3_dot(ds.acceleration, sl->dir), v = v3_dot(ds.velocity, sl->dir);
        double x = v3_dot(v3_sub(ds.position, sl->r0), sl->dir);
        if (fabs(fabs(a) - kg) <= 0.01 * kg)
            r->time_at_level += (double)chunk * dt;
        if (r->rise_measured < 0 && fabs(a) >= 0.99 * kg)
            r->rise_measured = t - sl->rise_start;
        if ((s = sample(w, rs, t, a, v, x)) != WS_OK)
            return s;
        r->duration = t;
    }
    return WS_OK;
}

ws_status ws_loadtest_run_eumos(ws_world *w, ws_load *ld, const ws_eumos_def *def,
                                ws_eumos_result *result)
{
    NEED_WORLD(w);
    NEED_OUT(w, result, "ws_loadtest_run_eumos");
    if (!ld)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_loadtest_run_eumos: load is NULL");
    if (ld->world != w)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_loadtest_run_eumos: the load was built in another world");
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
    rs.ld = ld;
    rs.res = result;

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
    if ((s = run_alloc(w, &rs)) != WS_OK)
        return s;
    if (ld->info.film.bits &&
        (s = ws_load_film_containment(w, ld, result->containment)) != WS_OK) {
        run_free(&rs);
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
    run_free(&rs);
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

static ws_status kworld_make(kworld *kw, const ws_world_def *wd, const ws_load_def *ldef,
                             const ws_kvalue_def *kd)
{
    double settle = kd->settle_time;
    memset(kw, 0, sizeof *kw);
    ws_status s = ws_world_create(wd, &kw->w);
    if (s != WS_OK)
        return s;
    double dt;
    if ((s = ws_load_build(kw->w, ldef, &kw->ld)) != WS_OK ||
        (s = ws_world_get_dt(kw->w, &dt)) != WS_OK ||
        (s = ws_world_step_n(kw->w, (int64_t)ceil(settle / dt - 1e-9))) != WS_OK)
        return s;
    ws_web_id film;
    if (kd->wrap && ((s = ws_load_wrap_band(kw->w, kw->ld, kd->wrap, &film)) != WS_OK ||
                     (s = ws_world_step_n(kw->w, (int64_t)ceil(settle / dt - 1e-9))) != WS_OK))
        return s;
    if (!kd->wrap && kd->spiral &&
        ((s = ws_load_wrap_spiral(kw->w, kw->ld, kd->spiral, &film)) != WS_OK ||
         (s = ws_world_step_n(kw->w, (int64_t)ceil(settle / dt - 1e-9))) != WS_OK))
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
    ws_status s = kworld_make(&kw, world_def, load_def, &kd);
    if (s == WS_OK)
        s = search(&kw, &ed, &kd, result);
    if (s != WS_OK)
        snprintf(result->error, sizeof result->error, "%s",
                 kw.w ? ws_world_last_error(kw.w) : ws_status_string(s));
    kworld_free(&kw);
    return s;
}
