/* Bad input to the calls of the platform tests, the spiral wrap and the film's rupture: every
 * refusal has its status, a last error naming the field (or the argument) at fault, and leaves
 * the world as it was (its state hash and its object counts unchanged).
 *
 *  1. the rupture calls and a mesh web's stiffness scales and rupture strain;
 *  2. the tilt, impact and vibration runs;
 *  3. the spiral wrap, its layers and the wrapped load's read-outs;
 *  4. the calls that change the world, from inside a step: WS_ERR_IN_STEP, nothing changed.
 *  5. a torn film's peak strain: of its intact springs, not of the broken ones' drifting ends.
 *
 * Nothing here runs a test to its end: every case but 5 is a refusal, and the whole suite takes
 * well under a second. */
#include "helpers.h"

#include <stdint.h>

static uint64_t state_hash(ws_world *w)
{
    uint64_t h = 0;
    ck_ok(w, ws_world_get_state_hash(w, &h));
    return h;
}

/* The world's bytes in use: a refused call allocates nothing it keeps. */
static uint64_t world_bytes(ws_world *w)
{
    ws_world_stats st;
    ck_ok(w, ws_world_get_stats(w, &st));
    return st.bytes_in_use;
}

/* The call returns `want`, its message holds `field`, and the world's state is unchanged. */
#define REFUSED(w, want, field, call)                                                              \
    do {                                                                                           \
        uint64_t h0_ = state_hash(w);                                                              \
        uint64_t n0_ = world_bytes(w);                                                             \
        ws_status s_ = (call);                                                                     \
        ck_assert_msg(s_ == (want), "%s: %s, want %s (%s)", #call, ws_status_string(s_),           \
                      ws_status_string(want), ws_world_last_error(w));                             \
        ck_assert_msg(strstr(ws_world_last_error(w), (field)) != NULL,                             \
                      "%s: the message does not name '%s': %s", #call, (field),                    \
                      ws_world_last_error(w));                                                     \
        ck_assert_msg(state_hash(w) == h0_, "%s changed the world's state", #call);                \
        ck_assert_msg(world_bytes(w) == n0_, "%s kept memory of the world", #call);                \
    } while (0)

static ws_world *abuse_world(void)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.detection_interval = 10;
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    return w;
}

/* One layer of 2 x 2 cartons on the pallet, not settled (nothing here runs it). */
static ws_load *small_load(ws_world *w)
{
    ws_load_def d;
    ws_load_def_init(&d);
    d.layers = 1;
    d.count_x = 2;
    d.count_y = 2;
    ws_load *ld = NULL;
    ck_ok(w, ws_load_build(w, &d, &ld));
    return ld;
}

/* Three nodes on x, two springs of a linear law; the ends pinned. */
static ws_status three_node_web(ws_world *w, const ws_web_def *d, const double *scales,
                                ws_web_id *out)
{
    static const double pos[9] = {0, 0, 5, 1, 0, 5, 2, 0, 5};
    static const uint32_t spr[4] = {0, 1, 1, 2}, pins[2] = {0, 2};
    static const double rest[2] = {0.9, 0.9};
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = pos;
    md.node_count = 3;
    md.springs = spr;
    md.spring_count = 2;
    md.rest_lengths = rest;
    md.pinned = pins;
    md.pinned_count = 2;
    md.stiffness_scales = scales;
    return ws_web_create_mesh(w, d, &md, out);
}

static ws_web_def web_def(ws_world *w)
{
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.stiffness = 100.0;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_web_def d;
    ws_web_def_init(&d);
    d.law = law;
    d.node_mass = 0.1;
    d.name = "strip";
    return d;
}

/* ---- 1. rupture ------------------------------------------------------------------------------ */

START_TEST(rupture_calls_refuse_bad_input)
{
    ws_world *w = abuse_world(), *other = abuse_world();
    ws_web_def d = web_def(w);
    ws_web_id web, gone, foreign;
    ck_ok(w, three_node_web(w, &d, NULL, &web));
    ck_ok(w, three_node_web(w, &d, NULL, &gone));
    ck_ok(w, ws_web_destroy(w, gone));
    ws_web_def od = web_def(other);
    ck_ok(other, three_node_web(other, &od, NULL, &foreign));
    ck_ok(other, three_node_web(other, &od, NULL, &foreign)); /* slot 1: no web of w there */
    ws_body_id body = add_ground(w, 1.0, no_material());
    const ws_web_id as_web = {body.bits}, null_web = {0};
    ck_ok(w, ws_world_step(w));

    /* The Def's rupture strain and the mesh's scales. */
    const double bad[] = {-1.0, NAN, INFINITY, -INFINITY, -1e-300};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        ws_web_def bd = d;
        bd.rupture_strain = bad[k];
        ws_web_id x;
        REFUSED(w, WS_ERR_INVALID_ARGUMENT, "rupture_strain", three_node_web(w, &bd, NULL, &x));
        REFUSED(w, WS_ERR_INVALID_ARGUMENT, "strain", ws_web_set_rupture_strain(w, web, bad[k]));
    }
    const double bad_scale[] = {0.0, -1.0, NAN, INFINITY, 1e300};
    for (size_t k = 0; k < sizeof bad_scale / sizeof bad_scale[0]; k++) {
        const double sc[2] = {1.0, bad_scale[k]};
        ws_web_id x;
        REFUSED(w, WS_ERR_INVALID_ARGUMENT, "stiffness scale", three_node_web(w, &d, sc, &x));
    }

    /* Ids: null, destroyed, of another world, a body's. */
    const ws_web_id ids[] = {null_web, gone, foreign, as_web};
    for (size_t k = 0; k < sizeof ids / sizeof ids[0]; k++) {
        ws_web_rupture r;
        ws_web_peak p;
        uint32_t sp[4];
        size_t n;
        ck_assert_int_eq(ws_web_set_rupture_strain(w, ids[k], 0.5), WS_ERR_STALE_HANDLE);
        ck_assert_int_eq(ws_web_get_rupture(w, ids[k], &r), WS_ERR_STALE_HANDLE);
        ck_assert_int_eq(ws_web_copy_broken_springs(w, ids[k], sp, 4, &n), WS_ERR_STALE_HANDLE);
        ck_assert_int_eq(ws_web_get_peak_strain(w, ids[k], &p), WS_ERR_STALE_HANDLE);
    }

    /* NULL world and outputs. */
    ws_web_rupture r;
    ws_web_peak p;
    size_t n = 99;
    uint32_t sp[1];
    ck_assert_int_eq(ws_web_set_rupture_strain(NULL, web, 0.5), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_web_get_rupture(NULL, web, &r), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_web_copy_broken_springs(NULL, web, sp, 1, &n), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_web_get_peak_strain(NULL, web, &p), WS_ERR_INVALID_ARGUMENT);
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "ws_web_get_rupture", ws_web_get_rupture(w, web, NULL));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "ws_web_get_peak_strain",
            ws_web_get_peak_strain(w, web, NULL));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "ws_web_copy_broken_springs",
            ws_web_copy_broken_springs(w, web, sp, 1, NULL));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "NULL", ws_web_copy_broken_springs(w, web, NULL, 4, &n));

    /* A web with no limit: nothing broken, zero counts; a NULL buffer of capacity 0 asks. */
    ck_ok(w, ws_web_copy_broken_springs(w, web, NULL, 0, &n));
    ck_assert_uint_eq(n, 0);
    ck_ok(w, ws_web_get_rupture(w, web, &r));
    ck_assert(r.ruptured == 0 && r.broken_count == 0 && r.first_spring == UINT32_MAX);

    /* Break both springs (laid at strain 1/0.9 - 1 = 0.111, a limit of 0.01): a buffer of 1 is
     * too small and says so, the count is 2. */
    ck_ok(w, ws_web_set_rupture_strain(w, web, 0.01));
    ck_ok(w, ws_world_step(w));
    ck_ok(w, ws_web_get_rupture(w, web, &r));
    ck_assert_uint_eq(r.broken_count, 2);
    REFUSED(w, WS_ERR_BUFFER_TOO_SMALL, "ws_web_copy_broken_springs",
            ws_web_copy_broken_springs(w, web, sp, 1, &n));
    ck_assert_uint_eq(n, 2);
    /* No intact spring: the peak says none found, not garbage. */
    ck_ok(w, ws_web_get_peak_strain(w, web, &p));
    ck_assert_int_eq(p.found, 0);
    ck_assert(p.strain == 0.0 && p.tension == 0.0);

    ws_world_destroy(other);
    ws_world_destroy(w);
}
END_TEST

/* ---- 2. the runs ----------------------------------------------------------------------------- */

static void bad_tilt(ws_world *w, ws_load *ld, const char *field, void (*set)(ws_tilt_test_def *))
{
    ws_tilt_test_def d;
    ws_tilt_test_def_init(&d);
    set(&d);
    ws_loadtest_result r;
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, field, ws_loadtest_run_tilt(w, ld, &d, &r));
}

static void bad_impact(ws_world *w, ws_load *ld, const char *field,
                       void (*set)(ws_impact_test_def *))
{
    ws_impact_test_def d;
    ws_impact_test_def_init(&d);
    set(&d);
    ws_loadtest_result r;
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, field, ws_loadtest_run_impact(w, ld, &d, &r));
}

static void bad_vibration(ws_world *w, ws_load *ld, const char *field,
                          void (*set)(ws_vibration_test_def *))
{
    ws_vibration_test_def d;
    ws_vibration_test_def_init(&d);
    set(&d);
    ws_loadtest_result r;
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, field, ws_loadtest_run_vibration(w, ld, &d, &r));
}

#define SETTER(name, type, ...)                                                                    \
    static void name(type *d)                                                                      \
    {                                                                                              \
        __VA_ARGS__;                                                                               \
    }

SETTER(t_rate_nan, ws_tilt_test_def, d->rate = NAN)
SETTER(t_rate_neg, ws_tilt_test_def, d->rate = -0.05)
SETTER(t_rate_tiny, ws_tilt_test_def, d->rate = 1e-300)
SETTER(t_rate_huge, ws_tilt_test_def, d->rate = 1e300)
SETTER(t_target_inf, ws_tilt_test_def, d->target_angle = INFINITY)
SETTER(t_target_big, ws_tilt_test_def, d->target_angle = 2.0)
SETTER(t_max_below, ws_tilt_test_def, d->max_angle = 0.1)
SETTER(t_ramp_nan, ws_tilt_test_def, d->ramp_time = NAN)
SETTER(t_hold_huge, ws_tilt_test_def, d->hold_time = 1e300)
SETTER(t_dir_zero, ws_tilt_test_def, d->direction = (ws_vec3){0, 0, 0})
SETTER(t_dir_nan, ws_tilt_test_def, d->direction = (ws_vec3){NAN, 0, 0})
SETTER(t_dir_up, ws_tilt_test_def, d->direction = (ws_vec3){1, 0, 1})
SETTER(t_slip_neg, ws_tilt_test_def, d->slip_speed = -1)
SETTER(t_tip_half, ws_tilt_test_def, d->tip_fraction = 0.5)
SETTER(t_interval0, ws_tilt_test_def, d->sample_interval = 0)
SETTER(i_speed_inf, ws_impact_test_def, d->speed = INFINITY)
SETTER(i_speed_0, ws_impact_test_def, d->speed = 0)
SETTER(i_pulse_nan, ws_impact_test_def, d->pulse_duration = NAN)
SETTER(i_gentle_tiny, ws_impact_test_def, d->gentle_acceleration = 1e-300)
SETTER(i_gentle_neg, ws_impact_test_def, d->gentle_acceleration = -2)
SETTER(i_coast_neg, ws_impact_test_def, d->coast_time = -1)
SETTER(i_dir_vertical, ws_impact_test_def, d->direction = (ws_vec3){0, 0, 1})
SETTER(i_interval_neg, ws_impact_test_def, d->sample_interval = -4)
SETTER(v_sweep_2, ws_vibration_test_def, d->sweep = 2)
SETTER(v_duration_0, ws_vibration_test_def, d->duration = 0)
SETTER(v_duration_nan, ws_vibration_test_def, d->duration = NAN)
SETTER(v_ramp_long, ws_vibration_test_def, d->ramp_time = 6)
SETTER(v_grms_neg, ws_vibration_test_def, d->grms = -0.5)
SETTER(v_grms_nan, ws_vibration_test_def, d->grms = NAN)
SETTER(v_rate_nan, ws_vibration_test_def, d->sample_rate = NAN)
SETTER(v_rate_low, ws_vibration_test_def, d->sample_rate = 10)
SETTER(v_rate_huge, ws_vibration_test_def, d->sample_rate = 1e300)
SETTER(v_dir_inf, ws_vibration_test_def, d->direction = (ws_vec3){0, 0, INFINITY})
SETTER(v_psd_half, ws_vibration_test_def, {
    static const double f[2] = {1, 100};
    d->psd_frequency = f;
})
SETTER(v_psd_count1, ws_vibration_test_def, {
    static const double f[2] = {1, 100}, l[2] = {0.01, 0.01};
    d->psd_frequency = f;
    d->psd_level = l;
    d->psd_count = 1;
})
SETTER(v_psd_count_huge, ws_vibration_test_def, {
    static const double f[2] = {1, 100}, l[2] = {0.01, 0.01};
    d->psd_frequency = f;
    d->psd_level = l;
    d->psd_count = SIZE_MAX / 4;
})
SETTER(v_psd_nan, ws_vibration_test_def, {
    static const double f[2] = {1, 100}, l[2] = {NAN, 0.01};
    d->psd_frequency = f;
    d->psd_level = l;
    d->psd_count = 2;
})
SETTER(v_psd_down, ws_vibration_test_def, {
    static const double f[2] = {100, 1}, l[2] = {0.01, 0.01};
    d->psd_frequency = f;
    d->psd_level = l;
    d->psd_count = 2;
})
SETTER(v_level_0, ws_vibration_test_def, {
    d->sweep = 1;
    d->sweep_level = 0;
})
SETTER(v_f_order, ws_vibration_test_def, {
    d->sweep = 1;
    d->frequency_start = 40;
    d->frequency_end = 2;
})
SETTER(v_law, ws_vibration_test_def, {
    d->sweep = 1;
    d->sweep_law = (ws_sweep_law)77;
})
SETTER(v_res_nan, ws_vibration_test_def, {
    d->sweep = 1;
    d->resonance_min = NAN;
})

START_TEST(runs_refuse_bad_input)
{
    ws_world *w = abuse_world(), *other = abuse_world();
    ws_load *ld = small_load(w), *foreign = small_load(other);
    ck_ok(w, ws_world_step(w));
    ws_tilt_test_def td;
    ws_impact_test_def id;
    ws_vibration_test_def vd;
    ws_tilt_test_def_init(&td);
    ws_impact_test_def_init(&id);
    ws_vibration_test_def_init(&vd);
    ws_loadtest_result r;

    /* NULL world, load, Def, result; a load of another world; an uninitialised Def. */
    ck_assert_int_eq(ws_loadtest_run_tilt(NULL, ld, &td, &r), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_loadtest_run_impact(NULL, ld, &id, &r), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_loadtest_run_vibration(NULL, ld, &vd, &r), WS_ERR_INVALID_ARGUMENT);
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "load", ws_loadtest_run_tilt(w, NULL, &td, &r));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "load", ws_loadtest_run_impact(w, NULL, &id, &r));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "load", ws_loadtest_run_vibration(w, NULL, &vd, &r));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "another world", ws_loadtest_run_tilt(w, foreign, &td, &r));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "another world",
            ws_loadtest_run_impact(w, foreign, &id, &r));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "another world",
            ws_loadtest_run_vibration(w, foreign, &vd, &r));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "output", ws_loadtest_run_tilt(w, ld, &td, NULL));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "output", ws_loadtest_run_impact(w, ld, &id, NULL));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "output", ws_loadtest_run_vibration(w, ld, &vd, NULL));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "tilt", ws_loadtest_run_tilt(w, ld, NULL, &r));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "impact", ws_loadtest_run_impact(w, ld, NULL, &r));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "vibration", ws_loadtest_run_vibration(w, ld, NULL, &r));
    memset(&td, 0, sizeof td);
    memset(&id, 0, sizeof id);
    memset(&vd, 0, sizeof vd);
    /* The message names the init to call, as it is spelt. */
    REFUSED(w, WS_ERR_UNINITIALIZED_DEF, "ws_tilt_test_def_init",
            ws_loadtest_run_tilt(w, ld, &td, &r));
    REFUSED(w, WS_ERR_UNINITIALIZED_DEF, "ws_impact_test_def_init",
            ws_loadtest_run_impact(w, ld, &id, &r));
    REFUSED(w, WS_ERR_UNINITIALIZED_DEF, "ws_vibration_test_def_init",
            ws_loadtest_run_vibration(w, ld, &vd, &r));

    /* Every numeric field: NaN, infinite, negative, out of its range. */
    bad_tilt(w, ld, "rate", t_rate_nan);
    bad_tilt(w, ld, "rate", t_rate_neg);
    bad_tilt(w, ld, "rate", t_rate_tiny); /* a run of 1e300 s */
    bad_tilt(w, ld, "rate", t_rate_huge);
    bad_tilt(w, ld, "target_angle", t_target_inf);
    bad_tilt(w, ld, "target_angle", t_target_big);
    bad_tilt(w, ld, "max_angle", t_max_below);
    bad_tilt(w, ld, "ramp_time", t_ramp_nan);
    bad_tilt(w, ld, "hold_time", t_hold_huge);
    bad_tilt(w, ld, "direction", t_dir_zero);
    bad_tilt(w, ld, "direction", t_dir_nan);
    bad_tilt(w, ld, "direction", t_dir_up);
    bad_tilt(w, ld, "slip_speed", t_slip_neg);
    bad_tilt(w, ld, "tip_fraction", t_tip_half);
    bad_tilt(w, ld, "sample_interval", t_interval0);
    bad_impact(w, ld, "speed", i_speed_inf);
    bad_impact(w, ld, "speed", i_speed_0);
    bad_impact(w, ld, "pulse_duration", i_pulse_nan);
    bad_impact(w, ld, "gentle_acceleration", i_gentle_tiny); /* a run-up of 1e301 s */
    bad_impact(w, ld, "gentle_acceleration", i_gentle_neg);
    bad_impact(w, ld, "coast_time", i_coast_neg);
    bad_impact(w, ld, "direction", i_dir_vertical);
    bad_impact(w, ld, "sample_interval", i_interval_neg);
    bad_vibration(w, ld, "sweep", v_sweep_2);
    bad_vibration(w, ld, "duration", v_duration_0);
    bad_vibration(w, ld, "duration", v_duration_nan);
    bad_vibration(w, ld, "ramp_time", v_ramp_long);
    bad_vibration(w, ld, "grms", v_grms_neg);
    bad_vibration(w, ld, "grms", v_grms_nan);
    bad_vibration(w, ld, "sample_rate", v_rate_nan);
    bad_vibration(w, ld, "sample_rate", v_rate_low);
    bad_vibration(w, ld, "sample_rate", v_rate_huge);
    bad_vibration(w, ld, "direction", v_dir_inf);
    bad_vibration(w, ld, "psd_level", v_psd_half);
    bad_vibration(w, ld, "psd_count", v_psd_count1);
    bad_vibration(w, ld, "psd_count", v_psd_count_huge);
    bad_vibration(w, ld, "PSD", v_psd_nan);
    bad_vibration(w, ld, "PSD", v_psd_down);
    bad_vibration(w, ld, "sweep_level", v_level_0);
    bad_vibration(w, ld, "frequency_start", v_f_order);
    bad_vibration(w, ld, "sweep_law", v_law);
    bad_vibration(w, ld, "resonance_min", v_res_nan);

    /* A platform with a drive of the caller's: the run would replace it (and its static drive at
     * the end would hold that drive's start, not the restored pose): refused, unchanged. */
    ws_tilt_test_def_init(&td);
    ws_impact_test_def_init(&id);
    ws_vibration_test_def_init(&vd);
    ws_load_info info;
    ck_ok(w, ws_load_get_info(ld, &info));
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    dd.type = WS_DRIVE_SINE;
    dd.amplitude = 0.01;
    dd.frequency = 2;
    dd.direction = (ws_vec3){1, 0, 0};
    ck_ok(w, ws_body_set_drive(w, info.platform, &dd));
    ck_ok(w, ws_world_step_n(w, 40));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "platform has a drive",
            ws_loadtest_run_tilt(w, ld, &td, &r));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "platform has a drive",
            ws_loadtest_run_impact(w, ld, &id, &r));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "platform has a drive",
            ws_loadtest_run_vibration(w, ld, &vd, &r));
    ws_eumos_def ed;
    ws_eumos_def_init(&ed);
    ws_eumos_result er;
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "platform has a drive",
            ws_loadtest_run_eumos(w, ld, &ed, &er));

    /* The criteria's names: every id has one, anything else is "unknown". */
    for (int k = WS_CHECK_STABLE_ANGLE; k <= WS_CHECK_RUPTURE; k++)
        ck_assert_str_ne(ws_loadtest_check_name(k), "unknown");
    ck_assert_str_eq(ws_loadtest_check_name(0), "unknown");
    ck_assert_str_eq(ws_loadtest_check_name(-1), "unknown");
    ck_assert_str_eq(ws_loadtest_check_name(INT32_MIN), "unknown");
    ck_assert_str_eq(ws_loadtest_check_name(WS_CHECK_RUPTURE + 1), "unknown");

    ws_load_destroy(foreign);
    ws_load_destroy(ld);
    ws_world_destroy(other);
    ws_world_destroy(w);
}
END_TEST

/* ---- 3. the spiral wrap ---------------------------------------------------------------------- */

typedef struct spiral_case {
    const char *field;
    size_t offset; /* of a double field, or SIZE_MAX for an int */
    double value;
} spiral_case;

/* clang-format off */
#define SD(f, v) {#f, offsetof(ws_spiral_wrap_def, f), (v)}
/* clang-format on */

START_TEST(spiral_refuses_bad_input)
{
    ws_world *w = abuse_world(), *other = abuse_world();
    ws_load *ld = small_load(w), *foreign = small_load(other);
    ck_ok(w, ws_world_step(w));
    ws_spiral_wrap_def sd;
    ws_web_id film;

    /* Every double field: NaN, infinite, negative, absurdly large or small. */
    /* clang-format off */
    const spiral_case cases[] = {
        SD(width, NAN), SD(width, -0.5), SD(width, INFINITY),
        SD(width, 1e-9), SD(width, 1e300), SD(gauge, 0),
        SD(gauge, NAN), SD(gauge, 1e300), SD(modulus, -1),
        SD(modulus, INFINITY), SD(modulus, 1e300), SD(density, 0),
        SD(density, 1e300), SD(prestretch, -0.1), SD(prestretch, 11),
        SD(neck_in, 0.95), SD(neck_in, NAN), SD(load_strain, 0),
        SD(load_strain, 1), SD(revolutions_bottom, -1), SD(revolutions_top, 1e9),
        SD(overlap, 0.99), SD(overlap, -0.1), SD(lock_height, NAN),
        SD(lock_height, 50), SD(top_margin, -1), SD(rope_revolutions, -1),
        SD(top_sheet_gauge, 0), SD(node_pitch, 0), SD(node_pitch, 1e-12),
        SD(node_pitch, NAN), SD(node_mass_min, -1), SD(node_mass_min, INFINITY),
        SD(elongation_at_break, -1), SD(elongation_at_break, 1.5), SD(rupture_strain, NAN),
        SD(rupture_strain, 0.05),
    };
    /* clang-format on */
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        ws_spiral_wrap_def_init(&sd);
        memcpy((char *)&sd + cases[k].offset, &cases[k].value, sizeof(double));
        const char *want = cases[k].field;
        /* A film whose rupture is too low or whose elongation is below the pre-stretch: the
         * message names the rupture strain or the pre-stretch. */
        if (strcmp(want, "elongation_at_break") == 0 && cases[k].value > 0)
            want = "prestretch";
        if (strcmp(want, "rupture_strain") == 0 && isfinite(cases[k].value))
            want = "load_strain";
        if (strcmp(want, "lock_height") == 0 && isfinite(cases[k].value))
            want = "lock_height and top_margin";
        REFUSED(w, WS_ERR_INVALID_ARGUMENT, want, ws_load_wrap_spiral(w, ld, &sd, &film));
        int layers = -1;
        ws_status s = ws_spiral_wrap_layers(&sd, 1.5, 0.15, 4.0, 0.0, 0.8, &layers);
        ck_assert_msg(s == WS_ERR_INVALID_ARGUMENT || s == WS_OK, "layers: %s",
                      ws_status_string(s));
    }
    /* The int fields. */
    int *ints[] = {&sd.passes, &sd.pallet_lock, &sd.top_sheet, &sd.substeps};
    const char *int_names[] = {"passes", "pallet_lock", "top_sheet", "substeps"};
    const int int_bad[] = {-1, 3, INT32_MIN, INT32_MAX};
    for (int k = 0; k < 4; k++)
        for (int v = 0; v < 4; v++) {
            ws_spiral_wrap_def_init(&sd);
            *ints[k] = k == 3 && int_bad[v] == 3 ? 100001 : int_bad[v];
            REFUSED(w, WS_ERR_INVALID_ARGUMENT, int_names[k],
                    ws_load_wrap_spiral(w, ld, &sd, &film));
        }
    ws_spiral_wrap_def_init(&sd);
    sd.rope_revolutions = 2;
    sd.rope_height = 50;
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "rope_height", ws_load_wrap_spiral(w, ld, &sd, &film));

    /* NULLs, an uninitialised Def, a load of another world. */
    ws_spiral_wrap_def_init(&sd);
    ck_assert_int_eq(ws_load_wrap_spiral(NULL, ld, &sd, &film), WS_ERR_INVALID_ARGUMENT);
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "load", ws_load_wrap_spiral(w, NULL, &sd, &film));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "output", ws_load_wrap_spiral(w, ld, &sd, NULL));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "another world",
            ws_load_wrap_spiral(w, foreign, &sd, &film));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "spiral", ws_load_wrap_spiral(w, ld, NULL, &film));
    memset(&sd, 0, sizeof sd);
    REFUSED(w, WS_ERR_UNINITIALIZED_DEF, "ws_spiral_wrap_def_init",
            ws_load_wrap_spiral(w, ld, &sd, &film));

    /* The layers call: no world, so the status alone. */
    int layers = -1;
    ws_spiral_wrap_def_init(&sd);
    ck_ok(w, ws_spiral_wrap_layers(&sd, 1.5, 0.15, 4.0, 0.0, 0.8, &layers));
    ck_assert_int_ge(layers, 1);
    ck_assert_int_eq(ws_spiral_wrap_layers(NULL, 1.5, 0.15, 4, 0, 0.8, &layers),
                     WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_spiral_wrap_layers(&sd, 1.5, 0.15, 4, 0, 0.8, NULL),
                     WS_ERR_INVALID_ARGUMENT);
    const double geo[][5] = {{NAN, 0.15, 4, 0, 0.8},        {1e300, 0.15, 4, 0, 0.8},
                             {1.5, -1, 4, 0, 0.8},          {1.5, 0.15, 0, 0, 0.8},
                             {1.5, 0.15, INFINITY, 0, 0.8}, {1.5, 0.15, 4, NAN, 0.8},
                             {1.5, 0.15, 4, 0, NAN},        {-1.5, 0.15, 4, 0, 0.8}};
    for (size_t k = 0; k < sizeof geo / sizeof geo[0]; k++)
        ck_assert_int_eq(ws_spiral_wrap_layers(&sd, geo[k][0], geo[k][1], geo[k][2], geo[k][3],
                                               geo[k][4], &layers),
                         WS_ERR_INVALID_ARGUMENT);
    /* A place far round the load, or far above it: a count, not a hang. */
    ck_ok(w, ws_spiral_wrap_layers(&sd, 1.5, 0.15, 4.0, 1e300, 0.8, &layers));
    ck_ok(w, ws_spiral_wrap_layers(&sd, 1.5, 0.15, 4.0, -1e300, 1e300, &layers));
    ck_assert_int_eq(layers, 0);
    memset(&sd, 0, sizeof sd);
    ck_assert_int_eq(ws_spiral_wrap_layers(&sd, 1.5, 0.15, 4, 0, 0.8, &layers),
                     WS_ERR_UNINITIALIZED_DEF);

    /* The read-outs: NULL, not wrapped, another world, bad counts. */
    ws_load_containment b[65];
    double strain;
    uint32_t spring;
    double height;
    ck_assert_int_eq(ws_load_get_containment(NULL, ld, b, 3), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_load_get_film_peak(NULL, ld, &strain, NULL, NULL), WS_ERR_INVALID_ARGUMENT);
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "load", ws_load_get_containment(w, NULL, b, 3));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "load",
            ws_load_get_film_peak(w, NULL, &strain, NULL, NULL));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "not wrapped", ws_load_get_containment(w, ld, b, 3));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "not wrapped",
            ws_load_get_film_peak(w, ld, &strain, &spring, &height));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "another world", ws_load_get_containment(w, foreign, b, 3));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "another world",
            ws_load_get_film_peak(w, foreign, &strain, NULL, NULL));

    /* Wrapped: the counts and the outputs; a refused second wrap; the film destroyed. */
    ws_spiral_wrap_def_init(&sd);
    sd.node_mass_min = 1e-3;
    ck_ok(w, ws_load_wrap_spiral(w, ld, &sd, &film));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "wrapped already", ws_load_wrap_spiral(w, ld, &sd, &film));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "count", ws_load_get_containment(w, ld, b, 0));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "count", ws_load_get_containment(w, ld, b, 65));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "count", ws_load_get_containment(w, ld, b, SIZE_MAX));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "ws_load_get_containment",
            ws_load_get_containment(w, ld, NULL, 3));
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "ws_load_get_film_peak",
            ws_load_get_film_peak(w, ld, NULL, &spring, &height));
    ck_ok(w, ws_load_get_containment(w, ld, b, 64));
    ck_ok(w, ws_load_get_film_peak(w, ld, &strain, NULL, NULL));
    ck_assert(isfinite(strain));
    ck_ok(w, ws_web_destroy(w, film));
    ck_assert_int_eq(ws_load_get_containment(w, ld, b, 3), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_load_get_film_peak(w, ld, &strain, NULL, NULL), WS_ERR_STALE_HANDLE);

    ws_load_destroy(foreign);
    ws_load_destroy(ld);
    ws_world_destroy(other);
    ws_world_destroy(w);
}
END_TEST

/* A torn film's peak: the check at the end of every step breaks each spring past the limit,
 * so after a step no intact spring is above it, and the film's peak (ws_load_get_film_peak)
 * is the web's intact peak (ws_web_get_peak_strain), to the bit. The broken springs' ends
 * drift apart (strains of 10 and more a second later); they are no peak of the film. */
START_TEST(a_torn_film_peaks_in_its_intact_springs)
{
    ws_world *w = abuse_world();
    ws_load *ld = small_load(w);
    ws_spiral_wrap_def sd;
    ws_spiral_wrap_def_init(&sd);
    sd.node_mass_min = 1e-3;
    ws_web_id film;
    ck_ok(w, ws_load_wrap_spiral(w, ld, &sd, &film));
    ck_ok(w, ws_web_set_rupture_strain(w, film, 0.105)); /* about the laid film's 0.1 */
    ck_ok(w, ws_world_step_n(w, 200));
    ws_web_rupture r;
    ck_ok(w, ws_web_get_rupture(w, film, &r));
    ck_assert_uint_gt(r.broken_count, 0);
    double strain, height;
    uint32_t spring;
    ws_web_peak pk;
    ck_ok(w, ws_load_get_film_peak(w, ld, &strain, &spring, &height));
    ck_ok(w, ws_web_get_peak_strain(w, film, &pk));
    report("torn spiral film: %u springs broken, film peak %.4f at spring %u, %.3f m up",
           r.broken_count, strain, spring, height);
    ck_assert(pk.found);
    ck_assert_double_eq(strain, pk.strain);
    ck_assert_uint_eq(spring, pk.spring);
    ck_assert_double_le(strain, 0.105);
    ck_assert(height > 0.0 && height < 0.5);
    ws_load_destroy(ld);
    ws_world_destroy(w);
}
END_TEST

/* The band wrap's rupture fields: NaN, infinite, negative; a pre-stretch that leaves no
 * elongation; a rupture strain the film passes as it is laid. */
START_TEST(band_rupture_fields_are_checked)
{
    ws_world *w = abuse_world();
    ws_load *ld = small_load(w);
    ck_ok(w, ws_world_step(w));
    ws_wrap_def d;
    ws_web_id film;
    const double bad[] = {NAN, INFINITY, -1.0};
    for (int k = 0; k < 3; k++) {
        ws_wrap_def_init(&d);
        d.elongation_at_break = bad[k];
        REFUSED(w, WS_ERR_INVALID_ARGUMENT, "elongation_at_break",
                ws_load_wrap_band(w, ld, &d, &film));
        ws_wrap_def_init(&d);
        d.powered_prestretch = bad[k];
        REFUSED(w, WS_ERR_INVALID_ARGUMENT, "powered_prestretch",
                ws_load_wrap_band(w, ld, &d, &film));
        ws_wrap_def_init(&d);
        d.rupture_strain = bad[k];
        REFUSED(w, WS_ERR_INVALID_ARGUMENT, "rupture_strain", ws_load_wrap_band(w, ld, &d, &film));
    }
    ws_wrap_def_init(&d);
    d.powered_prestretch = 4.0; /* = elongation_at_break */
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "powered_prestretch must be below elongation_at_break",
            ws_load_wrap_band(w, ld, &d, &film));
    ws_wrap_def_init(&d);
    d.rupture_strain = 0.05; /* the band is laid at strain_around 0.1 */
    REFUSED(w, WS_ERR_INVALID_ARGUMENT, "would break as it is laid",
            ws_load_wrap_band(w, ld, &d, &film));
    ws_load_destroy(ld);
    ws_world_destroy(w);
}
END_TEST

/* A k-value search with a bad spiral Def is refused before it runs anything. */
START_TEST(kvalue_refuses_a_bad_spiral)
{
    ws_world_def wd;
    ws_world_def_init(&wd);
    ws_load_def ld;
    ws_load_def_init(&ld);
    ld.layers = 1;
    ws_eumos_def ed;
    ws_eumos_def_init(&ed);
    ws_kvalue_def kd;
    ws_kvalue_def_init(&kd);
    ws_spiral_wrap_def sd;
    ws_spiral_wrap_def_init(&sd);
    sd.overlap = NAN;
    kd.spiral = &sd;
    ws_kvalue_result kr;
    ck_assert_int_eq(ws_loadtest_find_k(&wd, &ld, &ed, &kd, &kr), WS_ERR_INVALID_ARGUMENT);
    memset(&sd, 0, sizeof sd);
    ck_assert_int_eq(ws_loadtest_find_k(&wd, &ld, &ed, &kd, &kr), WS_ERR_UNINITIALIZED_DEF);
}
END_TEST

/* ---- 4. from inside a step ---------------------------------------------------------------------
 */

typedef struct in_step {
    ws_world *w;
    ws_load *ld;
    ws_web_id web;
    int calls;
    ws_status got[7];
    int named[7];
    int reads_ok;
} in_step;

static void try_in_step(in_step *c)
{
    ws_world *w = c->w;
    ws_tilt_test_def td;
    ws_impact_test_def id;
    ws_vibration_test_def vd;
    ws_spiral_wrap_def sd;
    ws_tilt_test_def_init(&td);
    ws_impact_test_def_init(&id);
    ws_vibration_test_def_init(&vd);
    ws_spiral_wrap_def_init(&sd);
    ws_loadtest_result r;
    ws_web_id film;
    static const char *names[7] = {"ws_web_set_rupture_strain", "ws_loadtest_run_tilt",
                                   "ws_loadtest_run_impact",    "ws_loadtest_run_vibration",
                                   "ws_load_wrap_spiral",       "ws_web_set_rupture_strain",
                                   "ws_loadtest_run_eumos"};
    c->got[0] = ws_web_set_rupture_strain(w, c->web, 0.5);
    c->named[0] = strstr(ws_world_last_error(w), names[0]) != NULL;
    c->got[1] = ws_loadtest_run_tilt(w, c->ld, &td, &r);
    c->named[1] = strstr(ws_world_last_error(w), names[1]) != NULL;
    c->got[2] = ws_loadtest_run_impact(w, c->ld, &id, &r);
    c->named[2] = strstr(ws_world_last_error(w), names[2]) != NULL;
    c->got[3] = ws_loadtest_run_vibration(w, c->ld, &vd, &r);
    c->named[3] = strstr(ws_world_last_error(w), names[3]) != NULL;
    c->got[4] = ws_load_wrap_spiral(w, c->ld, &sd, &film);
    c->named[4] = strstr(ws_world_last_error(w), names[4]) != NULL;
    c->got[5] = ws_web_set_rupture_strain(w, c->web, 0.0);
    c->named[5] = strstr(ws_world_last_error(w), names[5]) != NULL;
    ws_eumos_def ed;
    ws_eumos_def_init(&ed);
    ws_eumos_result er;
    c->got[6] = ws_loadtest_run_eumos(w, c->ld, &ed, &er);
    c->named[6] = strstr(ws_world_last_error(w), names[6]) != NULL;
    /* The readers work inside a step. */
    ws_web_rupture ru;
    ws_web_peak pk;
    size_t n;
    c->reads_ok = ws_web_get_rupture(w, c->web, &ru) == WS_OK &&
                  ws_web_get_peak_strain(w, c->web, &pk) == WS_OK &&
                  ws_web_copy_broken_springs(w, c->web, NULL, 0, &n) == WS_OK;
}

static int in_step_drive(void *user, double t, ws_pose *pose, ws_vec3 *v, ws_vec3 *om)
{
    in_step *c = user;
    if (c->calls++ == 1) /* the first call is ws_body_set_drive's own, outside a step */
        try_in_step(c);
    *pose = (ws_pose){{50, 50, 50}, {1, 0, 0, 0}};
    (void)t;
    *v = *om = (ws_vec3){0, 0, 0};
    return 0;
}

START_TEST(calls_inside_a_step_are_refused)
{
    in_step c;
    memset(&c, 0, sizeof c);
    ws_world *w = abuse_world();
    c.w = w;
    c.ld = small_load(w);
    ws_web_def d = web_def(w);
    d.rupture_strain = 0.3;
    ck_ok(w, three_node_web(w, &d, NULL, &c.web));
    /* A kinematic box far from the load, moved by the callback. */
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = s;
    bd.position = (ws_vec3){50, 50, 50};
    ws_body_id kin;
    ck_ok(w, ws_body_create(w, &bd, &kin));
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    dd.type = WS_DRIVE_CALLBACK;
    dd.callback = in_step_drive;
    dd.callback_user = &c;
    ck_ok(w, ws_body_set_drive(w, kin, &dd));
    ck_ok(w, ws_world_step(w));
    ck_assert_int_ge(c.calls, 2);
    for (int k = 0; k < 7; k++) {
        ck_assert_msg(c.got[k] == WS_ERR_IN_STEP, "call %d returned %s", k,
                      ws_status_string(c.got[k]));
        ck_assert_msg(c.named[k], "call %d: the message does not name the call", k);
    }
    ck_assert(c.reads_ok);
    /* Nothing changed: the limit is the Def's, the load unwrapped, no web added. */
    ws_web_rupture ru;
    ck_ok(w, ws_web_get_rupture(w, c.web, &ru));
    ck_assert_double_eq(ru.rupture_strain, 0.3);
    ws_load_info info;
    ck_ok(w, ws_load_get_info(c.ld, &info));
    ck_assert_uint_eq(info.film.bits, 0);
    ck_ok(w, ws_world_step(w));
    ws_load_destroy(c.ld);
    ws_world_destroy(w);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("loadtest_abuse");
    add_case(s, "rupture", rupture_calls_refuse_bad_input, 30);
    add_case(s, "runs", runs_refuse_bad_input, 30);
    add_case(s, "spiral", spiral_refuses_bad_input, 30);
    add_case(s, "band_rupture", band_rupture_fields_are_checked, 30);
    add_case(s, "kvalue_spiral", kvalue_refuses_a_bad_spiral, 30);
    add_case(s, "torn_film_peak", a_torn_film_peaks_in_its_intact_springs, 60);
    add_case(s, "in_step", calls_inside_a_step_are_refused, 30);
    return run_suite(s);
}
