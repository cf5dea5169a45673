/* The reference case (DESIGN.md), unwrapped, run through the example program's own code so the
 * template users copy is what is validated.
 *
 * Theory: a block on a plane tilting slowly starts to slide when tan(theta) = mu = 0.3, i.e.
 * theta_c = 16.699 deg (t = 1 + 0.2915/0.1 = 3.915 s). Tolerance 0.3 deg (the issue's): the
 * regularised law creeps and reaches v_lim exactly at theta_c in the quasi-static limit; what
 * remains is the dynamic lag of a 5 kg box starting to slip while the plane turns at 0.1 rad/s
 * (measured ~0.15 deg). The example reports where a gross slip that lasts 0.2 s began, so the
 * persistence it asks for does not delay the angle. */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

#include "helpers.h"

static const double theta_c = 16.699244233993621; /* atan(0.3) in degrees */

static void run(char variant, int stick, int use_ccd, tilt_result *r)
{
    tilt_options o;
    tilt_default_options(&o);
    o.variant = variant;
    o.stick = stick;
    o.use_ccd = use_ccd;
    o.quiet = 1;
    ws_status s = tilt_run(&o, r);
    ck_assert_msg(s == WS_OK, "tilt_run: %s: %s", ws_status_string(s), r->error);
}

START_TEST(variant_r_unwrapped_regularised)
{
    tilt_result r;
    run('R', 0, 1, &r);
    ck_assert_msg(fabs(r.slide_angle[1] - theta_c) < 0.3, "top box slid at %.3f deg, theory %.3f",
                  r.slide_angle[1], theta_c);
    /* The bottom box rests on the stop: no gross slip, and it moves less than a layer (2 mm). */
    ck_assert_msg(isnan(r.slide_angle[0]), "bottom box slid at %.3f deg", r.slide_angle[0]);
    ck_assert_msg(fabs(r.final_slip[0]) < 2e-3, "bottom slip %.4f m", r.final_slip[0]);
    /* The top box leaves the bottom one: it slid off by more than its own width. */
    ck_assert_msg(r.final_slip[1] > 0.25, "top slip %.4f m", r.final_slip[1]);
    /* The record of its move on the bottom box goes on through the slide: it slid past half its
     * width (0.125 m) before it tipped off the edge. (A record that stopped when the slide was
     * confirmed, 0.2 s after its onset, would read a few mm and hide the slide.) */
    ck_assert_msg(r.max_relative_slip > 0.1, "top box on the bottom one: %.4f m",
                  r.max_relative_slip);
    /* It then leaves the platform (the world has no floor) and the run stops there, before the
     * 7 s, with the box's CoG just below the platform's surface, not 19 m below. */
    ck_assert_msg(!isnan(r.off_time[1]) && r.end_time == r.off_time[1] && r.end_time < 7.0,
                  "top box off at %.3f s, run ended at %.3f s", r.off_time[1], r.end_time);
}
END_TEST

START_TEST(variant_r_unwrapped_stick)
{
    tilt_result r;
    run('R', 1, 1, &r);
    ck_assert_msg(fabs(r.slide_angle[1] - theta_c) < 0.3, "top box slid at %.3f deg, theory %.3f",
                  r.slide_angle[1], theta_c);
    ck_assert_msg(isnan(r.slide_angle[0]), "bottom box slid at %.3f deg", r.slide_angle[0]);
}
END_TEST

START_TEST(variant_p_unwrapped)
{
    /* Same mu on both interfaces: both boxes start to slide at theta_c (P says little about film:
     * the stack slides as one, see DESIGN.md). */
    tilt_result r;
    run('P', 0, 1, &r);
    for (int k = 0; k < 2; k++)
        ck_assert_msg(fabs(r.slide_angle[k] - theta_c) < 0.3, "box %d slid at %.3f deg", k,
                      r.slide_angle[k]);
}
END_TEST

START_TEST(creep_before_slip_is_small)
{
    /* The regularised law creeps below v_lim: the top box moves a few mm before theta_c; before
     * the tilt ramp begins (flat, t < 0.975 s) it must not slide: only settling moves it, by far
     * less than 1e-5 m along the plane (a 10 um tolerance, 100x the settling overlap change). */
    tilt_options o;
    tilt_default_options(&o);
    o.quiet = 1;
    o.duration = 3.9; /* theta = 16.6 deg, just before theta_c */
    tilt_result r;
    ck_assert_int_eq(tilt_run(&o, &r), WS_OK);
    ck_assert_msg(r.final_slip[1] > 1e-3 && r.final_slip[1] < 2e-2,
                  "creep of the top box before theta_c: %.4f m", r.final_slip[1]);
    o.duration = 0.9;
    ck_assert_int_eq(tilt_run(&o, &r), WS_OK);
    ck_assert_msg(fabs(r.final_slip[1]) < 1e-5, "drift on the flat plane %.2e m", r.final_slip[1]);
}
END_TEST

START_TEST(same_result_with_and_without_ccd)
{
    if (!(ws_build_features() & WS_FEATURE_CCD))
        return; /* nothing to compare in a build without libccd */
    tilt_result a, b;
    run('R', 0, 1, &a);
    run('R', 0, 0, &b);
    ck_assert_msg(a.hash == b.hash, "state hash differs with and without the libccd gate");
}
END_TEST

/* Variant R wrapped (DESIGN.md). The film must keep the top box on the bottom one (relative
 * slip of a few mm at most while the stack stands) and the stack tips as one over the stop.
 * Rigid-body answers: the uphill edge unloads when the platform's push reaches the downhill
 * bottom edge. With the stop pushing a share s of the load's weight down the platform at a
 * height h_s above the bottom face, tan(theta) = x_e / (h - s h_s), x_e and h the CoG's lever
 * arms (0.125 m and 0.252 m with the 2 mm layer gap): 26.39 deg for a push at the stop's foot,
 * 28.3 deg at its top edge (h_s = 20 mm); where between the two it pushes, rigid bodies do not
 * say (the box bears on the stop's whole face), so the run measures it (the stop's contacts'
 * force and moment, 10 ms before the lift) and the lift must come where a rigid stack with that
 * push and that CoG lifts; the stack tips over the stop's edge when its CoG passes it,
 * tan(theta) = 0.125 / 0.23: 28.52 deg. Tolerances: 0.5 deg for the lift-off (layer offsets of
 * 1-2 mm on 0.25 m lever arms move it by ~0.3 deg); for the tip the example reports a lean of
 * 2 deg, which the inverted pendulum reaches about half a degree of plane tilt after it starts,
 * and the film lets the stack shear a little (earlier): -1 to +1.5 deg.
 * Set WS_TEST_SHORT to run only the first 1.2 s (the wrap settling), as the sanitizer and
 * valgrind runs do: then only the film's hold is checked. */
START_TEST(variant_r_wrapped)
{
    tilt_options o;
    tilt_default_options(&o);
    o.wrapped = 1;
    o.quiet = 1;
    int short_run = getenv("WS_TEST_SHORT") != NULL;
    if (short_run)
        o.duration = 1.2;
    tilt_result r;
    ws_status s = tilt_run(&o, &r);
    ck_assert_msg(s == WS_OK, "tilt_run: %s: %s", ws_status_string(s), r.error);
    ck_assert_msg(r.max_relative_slip < 5e-3, "top box moved %.2f mm on the bottom one",
                  1e3 * r.max_relative_slip);
    if (short_run)
        return;
    /* The film prevents the slip: the top box does not slide on the bottom one before the
     * stack tips (unwrapped it slides at 16.70 deg). */
    ck_assert_msg(isnan(r.slide_angle[1]) || r.slide_angle[1] > r.lift_angle,
                  "top box slid at %.2f deg", r.slide_angle[1]);
    double unload = atan(0.125 / 0.252) * 180.0 / 3.14159265358979323846;
    double unload_top = atan(0.125 / (0.252 - 0.02)) * 180.0 / 3.14159265358979323846;
    double tip = atan(0.125 / 0.23) * 180.0 / 3.14159265358979323846;
    report("reference R wrapped: uphill edge lifted at %.2f deg; the stop pushed %.2f mm above "
           "the box's bottom face with %.1f %% of the weight down the platform: a rigid stack "
           "lifts at %.2f deg (%.2f at the stop's foot, %.2f at its top edge)",
           r.lift_angle, 1e3 * r.stop_height, 100 * r.stop_share, r.lift_theory, unload,
           unload_top);
    ck_assert_msg(r.stop_height > -1e-3 && r.stop_height < 0.02 + 1e-3,
                  "the stop pushed %.2f mm above the box's bottom face", 1e3 * r.stop_height);
    ck_assert_msg(fabs(r.lift_angle - r.lift_theory) < 0.5,
                  "uphill edge lifted at %.2f deg, a rigid stack with the stop's push at %.2f",
                  r.lift_angle, r.lift_theory);
    ck_assert_msg(r.lift_angle > unload - 0.5 && r.lift_angle < unload_top + 0.5,
                  "uphill edge lifted at %.2f deg, rigid bounds %.2f-%.2f", r.lift_angle, unload,
                  unload_top);
    ck_assert_msg(r.tip_angle[0] > tip - 1.0 && r.tip_angle[0] < tip + 1.5,
                  "the stack tipped (lean > 2 deg) at %.2f deg, rigid-body theory %.2f",
                  r.tip_angle[0], tip);
    /* The physical tip: the load's CoG passes over the stop's edge. A rigid load would at
     * 28.61 deg with the layers (docs/theory.md 4.1) or, from its own geometry when the uphill
     * edge lifts, at over_theory; the film lets the stack shear, which tips it earlier (by
     * 0.3 deg measured against over_theory); never later than the rigid load by more than the
     * 10 ms sampling (0.06 deg). The 2 deg lean lags it: the pendulum needs time to fall. */
    ck_assert_msg(!isnan(r.over_angle) && !isnan(r.over_theory), "no physical tip reported");
    ck_assert_msg(r.over_angle > tip - 1.0 && r.over_angle < r.over_theory + 0.1 &&
                      r.over_theory < 28.61 + 0.1,
                  "CoG over the stop edge at %.2f deg, rigid from the lift geometry %.2f deg",
                  r.over_angle, r.over_theory);
    ck_assert_msg(r.over_time < r.tip_time[0], "CoG over the edge at %.3f s, lean 2 deg at %.3f s",
                  r.over_time, r.tip_time[0]);
    /* It tipped as one: the top box leans on the bottom one only after the stack has tipped. */
    ck_assert_msg(isnan(r.tip_angle[1]) || r.tip_angle[1] > r.tip_angle[0],
                  "top box leaned at %.2f deg, before the stack tipped at %.2f", r.tip_angle[1],
                  r.tip_angle[0]);
}
END_TEST

START_TEST(steady_state_steps_allocate_nothing)
{
    /* Buffers grow while the contact set grows, then stay: after warm-up a step must make no
     * call to the allocator (STYLE.md: no heap allocation inside a step). */
    test_alloc ta = {.allocs_left = 1000000000L};
    ws_world_def d;
    ws_world_def_init(&d);
    d.full_detection_until = 0.1;
    d.detection_interval = 5;
    test_alloc_install(&d, &ta);
    ws_world *w;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    add_ground(w, 1.0, no_material());
    ws_vec3 c = {0, 0, 0.127};
    add_box(w, 0.25, 0.25, 0.25, 5.0, c, no_material(), "bottom");
    c.z = 0.381;
    add_box(w, 0.25, 0.25, 0.25, 5.0, c, no_material(), "top");
    ck_ok(w, ws_world_step_n(w, 2000));
    long before = ta.allocs_left;
    ck_ok(w, ws_world_step_n(w, 10000));
    ck_assert_msg(ta.allocs_left == before, "%ld allocator calls in 10000 steady steps",
                  before - ta.allocs_left);
    ws_world_destroy(w);
    ck_assert_int_eq(ta.live, 0);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("tilt_table");
    TCase *tc = tcase_create("reference_case");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, variant_r_unwrapped_regularised);
    tcase_add_test(tc, variant_r_unwrapped_stick);
    tcase_add_test(tc, variant_p_unwrapped);
    tcase_add_test(tc, creep_before_slip_is_small);
    tcase_add_test(tc, same_result_with_and_without_ccd);
    tcase_add_test(tc, steady_state_steps_allocate_nothing);
    tcase_add_test(tc, variant_r_wrapped);
    suite_add_tcase(s, tc);
    return run_suite(s);
}
