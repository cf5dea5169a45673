/* Contact detection schedule and gates must not change results.
 *
 * Between full detections only cached candidate pairs (within the layers + contact_margin) are
 * re-checked; a full detection is forced early whenever the bodies may have moved by half the
 * margin. So a schedule of "every 50th step" must give the same contacts, hence the same motion,
 * as "every step": the same trajectory to round-off (1e-9 m allows for the different summation
 * order of forces when candidate lists differ). */
#include "helpers.h"

#define WS_TEST_PI 3.14159265358979323846

static ws_world *drop_world(int interval, int use_ccd, double height)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.detection_interval = interval;
    d.use_ccd = use_ccd;
    ws_world *w;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    add_ground(w, 1.0, no_material());
    /* Tilted a little so that corners, edges and faces all come into play on impact. */
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 0.2, 0.3, 0.25, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = s;
    bd.mass = 4.0;
    bd.position = (ws_vec3){0.01, -0.02, height};
    double a = 0.3;
    bd.orientation = (ws_quat){cos(a / 2), 0.6 * sin(a / 2), 0.8 * sin(a / 2), 0.0};
    bd.angular_velocity = (ws_vec3){0.5, -1.0, 2.0};
    bd.name = "dropped";
    ws_body_id id;
    ck_ok(w, ws_body_create(w, &bd, &id));
    /* Two resting cubes yawed 45 deg, offset along the diagonal: their boxes overlap while the
     * hulls are 0.25 sqrt(2) - 0.25 = 10 cm apart, which is what the libccd gate is for. */
    ws_shape_id cube;
    ck_ok(w, ws_shape_create_box(w, 0.25, 0.25, 0.25, &cube));
    bd.shape = cube;
    bd.mass = 5.0;
    bd.orientation = (ws_quat){cos(WS_TEST_PI / 8), 0, 0, sin(WS_TEST_PI / 8)};
    bd.angular_velocity = (ws_vec3){0, 0, 0};
    bd.position = (ws_vec3){0.6, 0.0, 0.127};
    bd.name = "neighbour 1";
    ck_ok(w, ws_body_create(w, &bd, &id));
    bd.position = (ws_vec3){0.85, 0.25, 0.127};
    bd.name = "neighbour 2";
    ck_ok(w, ws_body_create(w, &bd, &id));
    return w;
}

static ws_body_id first_dynamic(ws_world *w)
{
    ws_body_id ids[8];
    size_t n;
    ck_ok(w, ws_world_copy_body_ids(w, ids, 8, &n));
    return ids[1];
}

START_TEST(schedule_does_not_change_the_motion)
{
    /* From 0.5 m the box hits at about 3 m/s: 3.75 mm in 5 steps, more than the 2 mm margin.
     * Without the forced detection the "every 50th" run would find its contacts late. */
    ws_world *a = drop_world(1, 0, 0.5), *b = drop_world(50, 0, 0.5);
    ws_body_id ia = first_dynamic(a), ib = first_dynamic(b);
    double max_dev = 0.0;
    for (int k = 0; k < 8000; k++) {
        ck_ok(a, ws_world_step(a));
        ck_ok(b, ws_world_step(b));
        ws_vec3 pa, pb;
        ws_body_get_position(a, ia, &pa);
        ws_body_get_position(b, ib, &pb);
        double d = fabs(pa.x - pb.x) + fabs(pa.y - pb.y) + fabs(pa.z - pb.z);
        if (d > max_dev)
            max_dev = d;
    }
    ck_assert_msg(max_dev < 1e-9, "trajectories differ by %.3e m", max_dev);
    ws_world_stats sa, sb;
    ws_world_get_stats(a, &sa);
    ws_world_get_stats(b, &sb);
    /* And the cache did save work once the box came to rest. */
    ck_assert_msg(sb.full_detections < sa.full_detections / 2, "%llu vs %llu full detections",
                  (unsigned long long)sb.full_detections, (unsigned long long)sa.full_detections);
    ws_world_destroy(a);
    ws_world_destroy(b);
}
END_TEST

START_TEST(ccd_gate_does_not_change_the_motion)
{
    if (!(ws_build_features() & WS_FEATURE_CCD))
        return;
    ws_world *a = drop_world(5, 0, 0.5), *b = drop_world(5, 1, 0.5);
    ck_ok(a, ws_world_step_n(a, 8000));
    ck_ok(b, ws_world_step_n(b, 8000));
    uint64_t ha, hb;
    ws_world_get_state_hash(a, &ha);
    ws_world_get_state_hash(b, &hb);
    ck_assert_msg(ha == hb, "state differs with the libccd gate");
    ws_world_stats sb;
    ws_world_get_stats(b, &sb);
    ck_assert_msg(sb.body_pairs_gated > 0, "the gate never skipped the two yawed neighbours");
    ws_world_destroy(a);
    ws_world_destroy(b);
}
END_TEST

START_TEST(impact_stays_within_the_layers)
{
    /* A 4 kg box on k = 2e5 N/m corners at 3 m/s: the peak overlap of one contact is bounded by
     * energy, m v^2/2 = n k x^2/2 with n >= 1 contacts: x <= v sqrt(m/k) = 13 mm for one corner.
     * The real impact shares it among corners and loses some to damping: assert < 13 mm and
     * that the box never passes through the 50 mm slab (its CoG stays above the plane). */
    ws_world *w = drop_world(5, 1, 0.5);
    ws_body_id id = first_dynamic(w);
    double worst = 0.0, lowest = 1.0;
    for (int k = 0; k < 8000; k++) {
        ck_ok(w, ws_world_step(w));
        ws_contact_info c[32];
        size_t n;
        ws_world_copy_contacts(w, c, 32, &n);
        for (size_t i = 0; i < n && i < 32; i++)
            if (c[i].overlap > worst)
                worst = c[i].overlap;
        ws_vec3 p;
        ws_body_get_position(w, id, &p);
        if (p.z < lowest)
            lowest = p.z;
    }
    ck_assert_msg(worst < 0.013, "peak overlap %.4f m", worst);
    ck_assert_msg(lowest > 0.05, "CoG went down to %.4f m", lowest);
    ws_world_destroy(w);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("detection");
    TCase *tc = tcase_create("schedule");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, schedule_does_not_change_the_motion);
    tcase_add_test(tc, ccd_gate_does_not_change_the_motion);
    tcase_add_test(tc, impact_stays_within_the_layers);
    suite_add_tcase(s, tc);
    return run_suite(s);
}
