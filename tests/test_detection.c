/* Contact detection schedule and gates must not change results.
 *
 * Between full detections only cached candidate pairs (within the layers + contact_margin) are
 * re-checked; a full detection is forced early whenever the bodies may have moved by half the
 * margin. So a schedule of "every 50th step" must give the same contacts, hence the same motion,
 * as "every step": the same trajectory to round-off (1e-9 m allows for the different summation
 * order of forces when candidate lists differ). The same holds for film nodes and their
 * candidates. This suite reaches into the world (world_internal.h) to force detection. */
#include "helpers.h"

#include "contact/node.h"
#include "world/world_internal.h"

/* Every film node of every web finds its candidates again before the next step. */
static void force_node_detection(ws_world *w)
{
    for (size_t k = 0; k < w->web_slots.slot_count; k++)
        if (w->web_slots.dense[k] != UINT32_MAX)
            w->webs[k]->contact->refresh = 1;
}

/* The one web of a world. */
static ws_web *only_web(ws_world *w)
{
    for (size_t k = 0; k < w->web_slots.slot_count; k++)
        if (w->web_slots.dense[k] != UINT32_MAX)
            return w->webs[k];
    return NULL;
}

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

/* A fixed 0.2 m block turned by qb and a free 1 kg cube of 0.1 m at pc turned by qc, moving at
 * vc; both of material mat (a null id: the world's default). */
static void block_and_cube(ws_world *w, ws_material_id mat, ws_quat qb, ws_vec3 pc, ws_quat qc,
                           ws_vec3 vc, ws_body_id *cube)
{
    ws_shape_id big, small;
    ck_ok(w, ws_shape_create_box(w, 0.2, 0.2, 0.2, &big));
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &small));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = big;
    bd.material = mat;
    bd.orientation = qb;
    bd.name = "block";
    ws_body_id block;
    ck_ok(w, ws_body_create(w, &bd, &block));
    ws_body_def_init(&bd);
    bd.shape = small;
    bd.material = mat;
    bd.mass = 1.0;
    bd.position = pc;
    bd.orientation = qc;
    bd.velocity = vc;
    bd.name = "cube";
    ck_ok(w, ws_body_create(w, &bd, cube));
}

/* Two edges nearly parallel: a cube's edge (the keel) passes 1.5 mm from the top front edge of
 * a fixed block, turned 0.01 rad from it about their common normal n. Moving across n at
 * 5 cm/s, the cube moves the lines' crossing along its keel a hundred times as fast, 1.25 mm a
 * step: it starts 20 mm past the keel's end and lies on the keel from the 17th step on, where
 * the two edges touch. No other features of the two can touch. No gravity. */
static ws_world *keel_world(int interval, ws_body_id *cube)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.gravity = (ws_vec3){0, 0, 0};
    d.detection_interval = interval;
    ws_world *w;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    /* n = (1, 0, 1) / sqrt 2 out of the block's edge (0.1, y, 0.1); m = n x y = (-1, 0, 1) /
     * sqrt 2. The keel, the cube's edge at (-h, y, -h) in its frame, lies along y turned by a
     * about n, so along cos a y + sin a m, at gap along n from the block's edge and mu along m
     * at its middle: the lines cross at -mu / sin a along the keel from its middle. */
    const double s2 = sqrt(0.5), h = 0.05, gap = 1.5e-3, a = 0.01, mu = (h + 0.02) * sin(a);
    const double c = gap + h * sqrt(2.0);
    block_and_cube(w, (ws_material_id){0}, (ws_quat){1, 0, 0, 0},
                   (ws_vec3){0.1 + s2 * (c - mu), 0.0, 0.1 + s2 * (c + mu)},
                   (ws_quat){cos(0.5 * a), s2 * sin(0.5 * a), 0.0, s2 * sin(0.5 * a)},
                   (ws_vec3){0.05 * s2, 0.0, -0.05 * s2} /* -m at 5 cm/s */, cube);
    return w;
}

START_TEST(schedule_keeps_nearly_parallel_edges)
{
    /* Every 50th step against every step: at the full detection of the first step the lines'
     * crossing lies 20 mm past the keel's end, yet the keel's end is 1.51 mm from the block's
     * edge, within the layers + margin. It must be a candidate then: the edges touch in the
     * 17th step, long before the cube's travel forces a full detection (80 steps). */
    ws_body_id ia, ib;
    ws_world *a = keel_world(1, &ia), *b = keel_world(50, &ib);
    double max_dev = 0.0;
    for (int k = 0; k < 200; k++) {
        ck_ok(a, ws_world_step(a));
        ck_ok(b, ws_world_step(b));
        ws_vec3 pa, pb;
        ws_body_get_position(a, ia, &pa);
        ws_body_get_position(b, ib, &pb);
        max_dev = fmax(max_dev, fabs(pa.x - pb.x) + fabs(pa.y - pb.y) + fabs(pa.z - pb.z));
    }
    ws_vec3 v;
    ws_body_get_velocity(a, ia, &v);
    double out = sqrt(0.5) * (v.x + v.z); /* along n: what the edges' contact gave */
    report("nearly parallel edges: the cube leaves the block at %.3f m/s along their normal; "
           "every 50th step and every step agree to %.1e m",
           out, max_dev);
    ck_assert_msg(out > 0.05, "the edges never touched (%.4f m/s): the case tests nothing", out);
    ck_assert_msg(max_dev < 1e-9, "trajectories differ by %.3e m", max_dev);
    ws_world_destroy(a);
    ws_world_destroy(b);
}
END_TEST

/* A cube turned 45 deg about x (its bottom edge, the keel, along x) resting across a fixed block
 * turned 45 deg about y (its top edge, the ridge, along y) on a soft contact: the crossed edges
 * carry the cube alone. interval: the detection interval. */
static ws_world *ridge_world(int interval, double k, ws_body_id *cube, double *ridge_top)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.detection_interval = interval;
    ws_world *w;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    ws_material_def md;
    ws_material_def_init(&md);
    ws_material_id mat;
    ck_ok(w, ws_material_create(w, &md, &mat));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = k;
    cd.damping = 40.0; /* 0.63 of critical for 1 kg on 1000 N/m */
    ck_ok(w, ws_world_set_contact(w, mat, mat, &cd));
    const double pi = 3.14159265358979323846;
    const double s2 = sqrt(0.5), c8 = cos(0.125 * pi), s8 = sin(0.125 * pi);
    *ridge_top = 0.1 / s2;
    /* The block turned 45 deg about y: an edge on top, along y; the cube 45 deg about x: an
     * edge below, along x, just touching: at the layers (1 mm each) above the ridge. */
    block_and_cube(w, mat, (ws_quat){c8, 0.0, s8, 0.0},
                   (ws_vec3){0.0, 0.0, *ridge_top + 2e-3 + 0.05 / s2}, (ws_quat){c8, s8, 0.0, 0.0},
                   (ws_vec3){0, 0, 0}, cube);
    return w;
}

START_TEST(crossed_edges_hold_below_the_margin)
{
    /* Penalty on the overlap of the layers: at rest k (2 delta - d) = m g, so the keel lies
     * d = 2 delta - m g / k = 2 - 9.81 = -7.81 mm from the ridge, deeper than the layers +
     * margin (4 mm) but well within the cube's inner depth (25 mm), where a contact is still
     * seen. Detected every step or every fifth, the edges must hold the cube there. Tolerance
     * 1e-5 m: the damped bounce (0.63 of critical, 31.6 rad/s) has decayed by e^-10 of its
     * 9.8 mm in 0.5 s. */
    const double k = 1000.0, g = 9.81, want = 2e-3 - g / k;
    for (int interval = 1; interval <= 5; interval += 4) {
        ws_body_id cube;
        double top;
        ws_world *w = ridge_world(interval, k, &cube, &top);
        ck_ok(w, ws_world_step_n(w, 2000));
        ws_vec3 p;
        ws_body_get_position(w, cube, &p);
        double d = p.z - 0.05 / sqrt(0.5) - top;
        report("crossed edges, detection every %d step(s): the keel rests %.4f mm from the ridge "
               "(theory %.4f mm)",
               interval, 1e3 * d, 1e3 * want);
        ck_assert_msg(fabs(d - want) < 1e-5, "keel at %.6f m from the ridge, theory %.6f m", d,
                      want);
        ws_world_destroy(w);
    }
}
END_TEST

/* Case 5's paddle: pressed on the band, it spins at 3 rad/s about its axis across the band
 * and jumps 4 cm along the band every 50 ms (a drive may jump). */
static int spin_and_jump(void *user, double t, ws_pose *pose, ws_vec3 *v, ws_vec3 *w)
{
    (void)user;
    const double rate = 3.0, phi = rate * t;
    pose->position = (ws_vec3){0.1535, (long)floor(t / 0.05) % 2 ? 0.02 : -0.02, 0.12};
    pose->orientation = (ws_quat){cos(0.5 * phi), sin(0.5 * phi), 0, 0};
    *v = (ws_vec3){0, 0, 0};
    *w = (ws_vec3){rate, 0, 0};
    return 0;
}

/* A 0.25 m cube wrapped in a band of film (24 x 6 nodes) on a platform that tilts at 1 rad/s
 * from the start: the film snaps on, the platform turns the stack, and from about 0.29 s
 * (tan 16.7 deg = 0.3) box and film slide down it together. */

/* Sub-steps that let a web run at the world's dt within the default safety factor of its
 * stable step (world.h: stable_fraction). */
static void fit_substeps(ws_world *w, ws_web_id web)
{
    ws_world_def d;
    ws_world_def_init(&d);
    double S, dt;
    ck_ok(w, ws_web_get_stable_dt(w, web, &S));
    ck_ok(w, ws_world_get_dt(w, &dt));
    int n = (int)ceil(dt / (d.stable_fraction * S));
    ck_ok(w, ws_web_set_substeps(w, web, n < 1 ? 1 : n));
}

static ws_world *wrapped_world(int kind, ws_web_id *web, ws_body_id *box)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.detection_interval = 5;
    ws_world *w;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    ws_material_def md;
    ws_material_def_init(&md);
    ws_material_id plane_mat, box_mat, film_mat;
    md.name = "plane";
    ck_ok(w, ws_material_create(w, &md, &plane_mat));
    md.name = "box";
    ck_ok(w, ws_material_create(w, &md, &box_mat));
    md.name = "film";
    ck_ok(w, ws_material_create(w, &md, &film_mat));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 2e5;
    cd.damping = 10.0;
    cd.friction = 0.3;
    ck_ok(w, ws_world_set_contact(w, box_mat, plane_mat, &cd));
    cd.stiffness = 4000.0;
    cd.damping = 1.0;
    cd.friction = 0.9;
    ck_ok(w, ws_world_set_contact(w, film_mat, box_mat, &cd));
    ck_ok(w, ws_world_set_contact(w, film_mat, plane_mat, &cd));
    ws_shape_id slab, cube;
    ck_ok(w, ws_shape_create_box(w, 1.5, 1.5, 0.05, &slab));
    ck_ok(w, ws_shape_create_box(w, 0.25, 0.25, 0.25, &cube));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = slab;
    bd.material = plane_mat;
    bd.position = (ws_vec3){0, 0, -0.025};
    bd.name = "platform";
    ws_body_id plane;
    ck_ok(w, ws_body_create(w, &bd, &plane));
    ws_drive_def tilt;
    ws_drive_def_init(&tilt);
    tilt.type = WS_DRIVE_TILT;
    tilt.axis = (ws_vec3){0, 1, 0};
    tilt.rate = 1.0;
    if (kind < 2 || kind == 6)
        ck_ok(w, ws_body_set_drive(w, plane, &tilt));
    else {
        /* A paddle (2 Hz). Case 2: far from the film at first, it swings in, pokes 7 mm into
         * the film and the box and swings out: a body that comes near. Case 3: it touches the
         * film from the start and slides along it, over nodes that need not move to be met.
         * Case 5: it touches the film, spins and jumps (spin_and_jump): the film is found again
         * only near it and where it held the film, and only its turn tells that its corners
         * sweep over new nodes. */
        ws_shape_id pad;
        ck_ok(w, ws_shape_create_box(w, 0.05, kind == 2 ? 0.3 : 0.1, 0.1, &pad));
        bd.shape = pad;
        bd.position = kind == 2 ? (ws_vec3){0.21, 0, 0.12} : (ws_vec3){0.1535, 0, 0.12};
        bd.name = "paddle";
        ws_body_id paddle;
        ck_ok(w, ws_body_create(w, &bd, &paddle));
        ws_drive_def sine;
        ws_drive_def_init(&sine);
        sine.type = kind == 5 ? WS_DRIVE_CALLBACK : WS_DRIVE_SINE;
        sine.callback = spin_and_jump;
        sine.direction = kind == 2 ? (ws_vec3){-1, 0, 0} : (ws_vec3){0, 1, 0};
        sine.amplitude = kind == 2 ? 0.065 : 0.06;
        sine.frequency = 2.0;
        ck_ok(w, ws_body_set_drive(w, paddle, &sine));
    }
    ws_body_def_init(&bd);
    bd.shape = cube;
    bd.mass = 5.0;
    bd.material = box_mat;
    bd.position = (ws_vec3){0, 0, 0.127};
    bd.name = "box";
    ck_ok(w, ws_body_create(w, &bd, box));
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_TENSION_COMPRESSION;
    /* Scene 6: the band of scene 0 pulled 1.5 times as hard (45 N a row's spring at its
     * prestretch for 30 N): its turn at a vertical edge presses the corner column past the edge
     * by more, and the chords to it pull the next nodes over the faces behind the faces' planes
     * (runs with a node below their face, which go one by one). */
    ld.stiffness = kind == 6 ? 150.0 : 100.0;
    ld.compression_stiffness = 1.0;
    ld.damping = 0.01;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-3;
    wd.node_damping = 0.05;
    wd.law = law;
    wd.material = film_mat;
    wd.name = "band";
    if (kind == 1) {
        /* 14 x 14 nodes, 0.33 m square with shear springs, slack, 3 cm above the box: it falls
         * onto it, drapes over its edges and slides off with it. */
        ws_sheet_def sd;
        ws_sheet_def_init(&sd);
        sd.nx = sd.ny = 14;
        sd.spacing_x = sd.spacing_y = 0.025;
        sd.origin = (ws_vec3){-0.1625, -0.1625, 0.284};
        sd.shear = 1;
        wd.law_shear = law;
        ck_ok(w, ws_web_create_sheet(w, &wd, &sd, web));
        fit_substeps(w, *web); /* the shear springs need 2 */
        return w;
    }
    ws_band_def bdf;
    ws_band_def_init(&bdf);
    bdf.bodies = box;
    bdf.body_count = 1;
    bdf.z_bottom = 0.03;
    bdf.z_top = 0.22;
    bdf.n_around = 24;
    bdf.n_up = 6;
    bdf.prestretch_around = 0.3;
    bdf.prestretch_up = 0.1;
    ck_ok(w, ws_web_create_band(w, &wd, &bdf, web));
    fit_substeps(w, *web); /* 2 within the default safety factor */
    return w;
}

/* A light film against the world's default material (4000 N/m, 1 kg/s, mu 0.5), nodes of 1 g
 * joined by springs of 5 N: into wd. */
static void soft_film(ws_world *w, ws_web_def *wd)
{
    ws_material_def md;
    ws_material_def_init(&md);
    ws_material_id film_mat, dflt;
    md.name = "film";
    ck_ok(w, ws_material_create(w, &md, &film_mat));
    ck_ok(w, ws_world_get_default_material(w, &dflt));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 4000.0;
    cd.damping = 1.0;
    cd.friction = 0.5;
    ck_ok(w, ws_world_set_contact(w, film_mat, dflt, &cd));
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.stiffness = 5.0;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_web_def_init(wd);
    wd->node_mass = 1e-3;
    wd->law = law;
    wd->material = film_mat;
}

/* A kinematic box of sizes h (m) at `at` that rises by `amplitude` (a sine of 1 Hz from
 * `start`, at once). */
static void rising_box(ws_world *w, ws_vec3 h, ws_vec3 at, double amplitude, double start,
                       const char *name, ws_body_id *box)
{
    ws_shape_id cube;
    ck_ok(w, ws_shape_create_box(w, h.x, h.y, h.z, &cube));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = cube;
    bd.position = at;
    bd.name = name;
    ck_ok(w, ws_body_create(w, &bd, box));
    ws_drive_def up;
    ws_drive_def_init(&up);
    up.type = WS_DRIVE_SINE;
    up.direction = (ws_vec3){0, 0, 1};
    up.amplitude = amplitude;
    up.frequency = 1.0;
    up.start_time = start;
    up.ramp_time = 0.0;
    ck_ok(w, ws_body_set_drive(w, *box, &up));
}

/* Case 4: a square sheet pinned at its border sags under its weight (its nodes move and are
 * found again on the way down) to some mm above a kinematic block that was 16 mm below it at
 * the first search; then the block rises 15 mm and lifts the sheet. The sagged nodes stand
 * still while the block closes on them: only the gap the partial searches recorded tells that
 * it has come near. */
static ws_world *sag_world(ws_web_id *web, ws_body_id *block)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.detection_interval = 5;
    ws_world *w;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    /* Top at 0.184 m; a quarter period, 0.25 s, to rise 15 mm. */
    rising_box(w, (ws_vec3){0.1, 0.1, 0.05}, (ws_vec3){0, 0, 0.159}, 0.015, 0.3, "block", block);
    ws_web_def wd;
    soft_film(w, &wd);
    wd.node_damping = 0.2;
    wd.name = "sheet";
    enum { N = 12 };
    uint32_t pin[4 * N];
    size_t np = 0;
    for (uint32_t j = 0; j < N; j++)
        for (uint32_t i = 0; i < N; i++)
            if (i == 0 || j == 0 || i == N - 1 || j == N - 1)
                pin[np++] = i + N * j;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = sd.ny = N;
    sd.spacing_x = sd.spacing_y = 0.02;
    sd.origin = (ws_vec3){-0.11, -0.11, 0.2};
    sd.prestretch_x = sd.prestretch_y = 0.05;
    sd.pinned = pin;
    sd.pinned_count = np;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, web));
    return w;
}

static void film_detection_case(int kind)
{
    /* Film nodes find their candidates again only when they (or the bodies near the film)
     * moved far enough relative to the stack since: every node and feature pair that can
     * touch is still in the list, so the motion must equal that of a run whose nodes are all
     * found again every step, to round-off of the force sums (1e-9 m, as above). */
    ws_web_id wa, wb;
    ws_body_id ba, bb;
    ws_world *a = kind == 4 ? sag_world(&wa, &ba) : wrapped_world(kind, &wa, &ba);
    ws_world *b = kind == 4 ? sag_world(&wb, &bb) : wrapped_world(kind, &wb, &bb);
    const int steps = 2400; /* 0.6 s: snap-on, the tilt, and 0.3 s of sliding */
    double max_dev = 0.0;
    size_t n;
    ws_web_info info;
    ck_ok(a, ws_web_get_info(a, wa, &info));
    double *xa = malloc(6 * info.node_count * sizeof *xa), *xb = xa + 3 * info.node_count;
    ck_assert(xa);
    for (int k = 0; k < steps; k++) {
        force_node_detection(a);
        ck_ok(a, ws_world_step(a));
        ck_ok(b, ws_world_step(b));
        if (k % 20 != 19 && k != steps - 1)
            continue;
        ck_ok(a, ws_web_copy_positions(a, wa, xa, info.node_count, &n));
        ck_ok(b, ws_web_copy_positions(b, wb, xb, info.node_count, &n));
        for (size_t i = 0; i < 3 * n; i++)
            max_dev = fmax(max_dev, fabs(xa[i] - xb[i]));
    }
    ws_vec3 pa, pb;
    ws_body_get_position(a, ba, &pa);
    ws_body_get_position(b, bb, &pb);
    double slid = kind == 4 ? pb.z - 0.159 : hypot(pb.x, pb.y);
    report("film detection (%s): nodes agree to %.2e m, box to %.2e m; the box %s %.3f m",
           kind == 1   ? "a sheet falls on the box"
           : kind == 2 ? "a paddle pokes the band"
           : kind == 3 ? "a paddle slides along the band"
           : kind == 4 ? "a block rises into a sagging sheet"
           : kind == 5 ? "a paddle spins and jumps on the band"
                       : "a band around the box",
           max_dev, fabs(pa.x - pb.x) + fabs(pa.y - pb.y) + fabs(pa.z - pb.z),
           kind == 4 ? "rose" : "slid", slid);
    ck_assert_msg(max_dev < 1e-9, "film nodes differ by %.3e m", max_dev);
    ck_assert_msg(fabs(pa.x - pb.x) + fabs(pa.y - pb.y) + fabs(pa.z - pb.z) < 1e-9,
                  "the box differs");
    if (kind == 4) { /* the block did lift the sheet: it carries the sheet's weight */
        ws_vec3 fw;
        ck_ok(b, ws_web_get_body_force(b, wb, bb, &fw, NULL));
        report("the block carries %.3f N of the sheet (weight of its free nodes 0.98 N)", -fw.z);
        ck_assert_msg(-fw.z > 0.1, "the sheet does not rest on the block: %g N", -fw.z);
    }
    if (kind != 3 && kind != 5) /* the paddle on the band leaves the box in place */
        ck_assert_msg(slid > 0.005, "the box did not move (%.4f m): the case tests too little",
                      slid);
    ws_world_stats sa, sb;
    ws_world_get_stats(a, &sa);
    ws_world_get_stats(b, &sb);
    report("feature checks: %llu finding every node every step, %llu as scheduled",
           (unsigned long long)sa.narrow_checks, (unsigned long long)sb.narrow_checks);
    ck_assert_msg(sb.narrow_checks < sa.narrow_checks / 2, "the schedule saved little");
    free(xa);
    ws_world_destroy(a);
    ws_world_destroy(b);
}

/* A world without gravity at dt = 0.25 ms, for film nodes placed by hand. */
static ws_world *weightless_world(void)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.gravity = (ws_vec3){0, 0, 0};
    d.dt = 2.5e-4;
    ws_world *w;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    return w;
}

/* A web of `probes` nodes placed by hand (pos, 3 each), each held by a spring to one more node
 * after them, pinned (pos holds probes + 1 points). */
static void probe_web(ws_world *w, const ws_web_def *wd, const double *pos, uint32_t probes,
                      ws_web_id *web)
{
    uint32_t spring[8], pin[1] = {probes};
    ck_assert_uint_le(probes, 4);
    for (uint32_t i = 0; i < probes; i++) {
        spring[2 * i] = i;
        spring[2 * i + 1] = probes;
    }
    ws_web_mesh_def mesh;
    ws_web_mesh_def_init(&mesh);
    mesh.positions = pos;
    mesh.node_count = probes + 1;
    mesh.springs = spring;
    mesh.spring_count = probes;
    mesh.pinned = pin;
    mesh.pinned_count = 1;
    ck_ok(w, ws_web_create_mesh(w, wd, &mesh, web));
}

/* A kinematic body of the shape, standing still at `at`. */
static ws_body_id still_body(ws_world *w, ws_shape_id shape, ws_vec3 at)
{
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = shape;
    bd.position = at;
    ws_body_id body;
    ck_ok(w, ws_body_create(w, &bd, &body));
    return body;
}

/* A film node just past the top end of a box's vertical edge, within the layers of the edge's
 * line, while the box rises: the edge's span comes to the node within a few steps, before the
 * node or the box has moved far enough to be found again. It must be an edge candidate from the
 * start (within reach of the segment, not only of its span). */
static ws_world *edge_end_world(ws_web_id *web, ws_body_id *box)
{
    ws_world *w = weightless_world();
    /* Rises at 63 mm/s: 16 um a step. */
    rising_box(w, (ws_vec3){0.1, 0.1, 0.1}, (ws_vec3){0, 0, 0}, 0.01, 0.0, "box", box);
    ws_web_def wd;
    soft_film(w, &wd);
    /* 1.5 mm from the edge's line (x = y = 0.05 m) on its diagonal, 50 um above its top end;
     * the other node is pinned far off. */
    const double o = 0.05 + 1.5e-3 / sqrt(2.0);
    const double pos[6] = {o, o, 0.05 + 5e-5, 0.3, 0.3, 0.05 + 5e-5};
    probe_web(w, &wd, pos, 1, web);
    return w;
}

START_TEST(film_node_past_an_edge_end)
{
    ws_web_id wa, wb;
    ws_body_id ba, bb;
    ws_world *a = edge_end_world(&wa, &ba), *b = edge_end_world(&wb, &bb);
    double xa[6], xb[6], max_dev = 0.0, pushed = 0.0;
    const double x0 = 0.05 + 1.5e-3 / sqrt(2.0);
    size_t n;
    for (int k = 0; k < 80; k++) {
        force_node_detection(a);
        ck_ok(a, ws_world_step(a));
        ck_ok(b, ws_world_step(b));
        ck_ok(a, ws_web_copy_positions(a, wa, xa, 2, &n));
        ck_ok(b, ws_web_copy_positions(b, wb, xb, 2, &n));
        for (int i = 0; i < 3; i++)
            max_dev = fmax(max_dev, fabs(xa[i] - xb[i]));
        pushed = fmax(pushed, xa[0] - x0);
    }
    report("film node past an edge's end: pushed out %.1f um by the edge; found every step and "
           "as scheduled agree to %.1e m",
           1e6 * pushed, max_dev);
    ck_assert_msg(pushed > 1e-6, "the edge never pushed the node: the case tests nothing");
    ck_assert_msg(max_dev < 1e-12, "the scheduled node differs by %.3e m", max_dev);
    ws_world_destroy(a);
    ws_world_destroy(b);
}
END_TEST

/* A node over a box's top face, near its edge with a side face, but with its projection on
 * the top a margin or more behind the side's plane (well inside the top), can be held by the top
 * alone until it is found again: the edge is no candidate of it, and it may join a run. A node
 * whose projection lies nearer the side's plane than the margin keeps the edge. Both are
 * within reach (layers + margin, 4 mm) of the edge. */
START_TEST(edges_of_faces_a_node_is_well_inside_of_are_dropped)
{
    ws_web_id web;
    ws_body_id box;
    ws_world *w = weightless_world();
    rising_box(w, (ws_vec3){0.1, 0.1, 0.1}, (ws_vec3){0, 0, 0}, 0.0, 0.0, "box", &box);
    ws_web_def wd;
    soft_film(w, &wd);
    /* 1 mm over the top (z = 0.05 m), 3 mm and 1.5 mm in from the +x side (x = 0.05 m), whose
     * plane the margin (2 mm) separates: 3.2 mm and 1.8 mm from the edge. The third node is
     * pinned far off. */
    const double top = 0.05 + 1e-3;
    const double pos[9] = {0.05 - 3e-3, 0.0, top, 0.05 - 1.5e-3, 0.0, top, 0.3, 0.3, top};
    probe_web(w, &wd, pos, 2, &web);
    ck_ok(w, ws_world_step(w));
    const ws_web *wb = only_web(w);
    const ws_ncand *c = wb->contact->cand[wb->contact->next_list].c;
    int faces[2] = {0, 0}, edges[2] = {0, 0}, inside[2] = {0, 0};
    for (size_t k = 0; k < wb->contact->cand[wb->contact->next_list].n; k++) {
        ck_assert_uint_lt(c[k].node, 2);
        if (c[k].local & WS_NCAND_EDGE) {
            edges[c[k].node]++;
        } else {
            faces[c[k].node]++;
            inside[c[k].node] += (c[k].local & WS_NCAND_INSIDE) != 0;
        }
    }
    report("node well inside the top: %d face(s), %d inside, %d edge(s); node near the side's "
           "plane: %d face(s), %d inside, %d edge(s)",
           faces[0], inside[0], edges[0], faces[1], inside[1], edges[1]);
    ck_assert_msg(faces[0] == 1 && inside[0] == 1 && edges[0] == 0,
                  "the node well inside the top has %d faces (%d inside) and %d edges", faces[0],
                  inside[0], edges[0]);
    ck_assert_msg(faces[1] == 1 && inside[1] == 0 && edges[1] == 1,
                  "the node near the side's plane has %d faces (%d inside) and %d edges", faces[1],
                  inside[1], edges[1]);
    ws_world_destroy(w);
}
END_TEST

/* Film nodes side by side on one face are evaluated on vectors (runs), the others one by one,
 * where a node at a box's edge (a corner: two faces and their edge) is told apart by the faces'
 * planes before the full tests; the short cuts must give the same contacts with the same
 * arithmetic, operation by operation: the same motion to the bit as every candidate one by one
 * through its full tests. */
static void film_runs_case(int kind, uint64_t *run_nodes, uint64_t *run_deep, uint64_t *corners)
{
    ws_web_id wa, wb;
    ws_body_id ba, bb;
    ws_world *a = kind == 4 ? sag_world(&wa, &ba) : wrapped_world(kind, &wa, &ba);
    ws_world *b = kind == 4 ? sag_world(&wb, &bb) : wrapped_world(kind, &wb, &bb);
    ws_web *web_a = only_web(a), *web_b = only_web(b);
    ck_assert(web_a && web_b);
    web_a->contact->runs_off = 1;
    /* Runs take their groups of nodes in batches, each sweep block's at its end; in two of the
     * scenes a batch runs before every chunk of a run instead, as a block with more than a
     * batch holds does. */
    web_b->contact->run_batch = kind % 2 ? 1u : 0u;
    const int steps = 2400;
    ws_web_info wi;
    ck_ok(b, ws_web_get_info(b, wb, &wi));
    double *fa = malloc(6 * wi.node_count * sizeof *fa), *fb = fa + 3 * wi.node_count;
    ck_assert(fa);
    double worst = 0.0;
    for (int k = 0; k < steps; k++) {
        ck_ok(a, ws_world_step(a));
        ck_ok(b, ws_world_step(b));
        if (k % 50 != 49)
            continue;
        /* The nodes' contact forces: the same both ways, and they add up to minus the film's
         * load on the bodies (a node that stopped touching reads zero, not what it had). */
        size_t nc;
        ck_ok(a, ws_web_copy_contact_forces(a, wa, fa, wi.node_count, &nc));
        ck_ok(b, ws_web_copy_contact_forces(b, wb, fb, wi.node_count, &nc));
        double sum[3] = {0, 0, 0}, size = 0.0;
        for (size_t i = 0; i < 3 * nc; i++) {
            ck_assert_msg(fa[i] == fb[i], "contact forces differ at node %zu", i / 3);
            sum[i % 3] += fb[i];
            size += fabs(fb[i]);
        }
        const ws_body_store *bs = &b->bodies;
        for (size_t q = 0; q < bs->slots; q++)
            if (bs->alive[q]) {
                sum[0] += web_b->bforce[b->cur][q].x;
                sum[1] += web_b->bforce[b->cur][q].y;
                sum[2] += web_b->bforce[b->cur][q].z;
            }
        /* Round-off of two sums of the same terms in different orders. */
        double off = fabs(sum[0]) + fabs(sum[1]) + fabs(sum[2]);
        ck_assert_msg(off <= 1e-12 * size + 1e-300,
                      "contact forces sum to %.3e N off the loads "
                      "on the bodies (of %.3e N)",
                      off, size);
        worst = fmax(worst, size > 0.0 ? off / size : 0.0);
    }
    free(fa);
    report("film runs (scene %d): node contact forces add up to the loads on the bodies to "
           "%.1e of their size",
           kind, worst);
    uint64_t ha, hb;
    ck_ok(a, ws_world_get_state_hash(a, &ha));
    ck_ok(b, ws_world_get_state_hash(b, &hb));
    ws_web_info info;
    ck_ok(a, ws_web_get_info(a, wa, &info));
    size_t n;
    double *xa = malloc(6 * info.node_count * sizeof *xa), *xb = xa + 3 * info.node_count;
    ck_assert(xa);
    ck_ok(a, ws_web_copy_positions(a, wa, xa, info.node_count, &n));
    ck_ok(b, ws_web_copy_positions(b, wb, xb, info.node_count, &n));
    double max_dev = 0.0;
    for (size_t i = 0; i < 3 * n; i++)
        max_dev = fmax(max_dev, fabs(xa[i] - xb[i]));
    report("film runs (scene %d): %llu node evaluations in runs (%llu in runs gone one by one), "
           "nodes differ by %.1e m, state hashes %016llx %016llx",
           kind, (unsigned long long)web_b->contact->run_nodes,
           (unsigned long long)web_b->contact->run_deep, max_dev, (unsigned long long)ha,
           (unsigned long long)hb);
    ck_assert_msg(web_a->contact->run_nodes == 0 && web_a->contact->corners == 0,
                  "short cuts taken with runs off");
    ck_assert_msg(ha == hb && max_dev == 0.0, "runs differ from one by one: %.3e m", max_dev);
    *run_nodes += web_b->contact->run_nodes;
    *run_deep += web_b->contact->run_deep;
    *corners += web_b->contact->corners;
    free(xa);
    ws_world_destroy(a);
    ws_world_destroy(b);
}

START_TEST(film_runs_equal_one_by_one)
{
    uint64_t nodes = 0, deep = 0, corners = 0;
    /* Scenes 0-4, and 6: the tilted band pulled harder, whose nodes next to the corners go
     * behind their faces' planes (with the push past an edge turning continuously, scenes 0-3
     * no longer drive them there). */
    const int kinds[6] = {0, 1, 2, 3, 4, 6};
    for (int k = 0; k < 6; k++)
        film_runs_case(kinds[k], &nodes, &deep, &corners);
    /* The scenes exercise them all: most node evaluations in runs, runs with a node below the
     * face, which go one by one, and corners. */
    ck_assert_msg(nodes > 1000000, "few nodes in runs: %llu", (unsigned long long)nodes);
    ck_assert_msg(deep > 0, "no run had a node below its face");
    ck_assert_msg(corners > 1000, "few corners: %llu", (unsigned long long)corners);
    report("film runs: %llu corners told apart by their planes", (unsigned long long)corners);
}
END_TEST

/* The corner short cut of the node contacts (a node at a box's edge told apart by the two
 * faces' planes) holds on convex shapes whose faces are flat; a face merged from triangles that
 * bend within the merging tolerance is not, and its corners take the full tests. */
START_TEST(corners_need_flat_faces)
{
    ws_world *w = new_world(2.5e-4);
    double v[24];
    memcpy(v, cube_v, sizeof v);
    ws_shape_id box, mesh, bent;
    ck_ok(w, ws_shape_create_box(w, 0.5, 0.5, 0.5, &box));
    ck_ok(w, create_mesh(w, v, 8, cube_t, 12, &mesh));
    /* Vertex 5 lies on the +z, -y and +x faces; lowered along z it leaves only +z's plane, by
     * 1e-8 m (lowered, the top folds outward along its diagonal 4-7 and stays convex): its two
     * triangles' normals then differ by 1e-8 rad, well within the merging tolerance (1 - cos =
     * 5e-17 against 1e-9), and the vertex lies 1e-8 off the plane, far past round-off (1e-12
     * of the size). */
    v[3 * 5 + 2] -= 1e-8;
    ck_ok(w, create_mesh(w, v, 8, cube_t, 12, &bent));
    const ws_shape_id ids[3] = {box, mesh, bent};
    const int flat[3] = {1, 1, 0};
    for (int k = 0; k < 3; k++) {
        uint32_t slot;
        ck_assert_int_eq(ws_lookup_shape(w, ids[k], &slot), WS_OK);
        const ws_shape *sh = w->shapes[slot];
        ck_assert_uint_eq(sh->face_count, 6); /* the bent top is still one face */
        ck_assert_int_eq(sh->convex, 1);
        ck_assert_msg(sh->flat == flat[k], "shape %d: flat %d, expected %d", k, sh->flat, flat[k]);
    }
    ws_world_destroy(w);
}
END_TEST

/* The detection marks a node's candidates of a body as a corner (WS_NCAND_CORNER on the first)
 * when they are two faces and then the edge between them on a flat convex shape, and only then:
 * the node contacts take the planes' short cut for those alone. A node 0.5 mm out of the +x
 * and +z planes of a unit cube, midway along their edge, is a corner of the box and of the cube
 * mesh, not of the cube whose top bends 1e-8 m (corners_need_flat_faces); a node 0.5 mm out of
 * three planes at a vertex (three faces, three edges), or out of two and 3 mm behind the third
 * (two faces, three edges), is no corner of any. */
START_TEST(corners_are_marked_by_the_detection)
{
    double v[24];
    memcpy(v, cube_v, sizeof v);
    v[3 * 5 + 2] -= 1e-8;
    for (int k = 0; k < 3; k++) {
        ws_world *w = weightless_world();
        ws_shape_id shape;
        if (k == 0)
            ck_ok(w, ws_shape_create_box(w, 1.0, 1.0, 1.0, &shape));
        else
            ck_ok(w, create_mesh(w, k == 1 ? cube_v : v, 8, cube_t, 12, &shape));
        still_body(w, shape, (ws_vec3){0, 0, 0});
        ws_web_def wd;
        soft_film(w, &wd);
        const double o = 0.5 + 0.5e-3;
        const double pos[12] = {o, 0.0, o, o, o, o, o, 0.497, o, 3.0, 3.0, 3.0};
        ws_web_id web;
        probe_web(w, &wd, pos, 3, &web);
        ck_ok(w, ws_world_step(w));
        const ws_web *wb = only_web(w);
        const ws_ncand *c = wb->contact->cand[wb->contact->next_list].c;
        int count[3] = {0, 0, 0}, marked[3] = {0, 0, 0}, edges[3] = {0, 0, 0};
        for (size_t q = 0; q < wb->contact->cand[wb->contact->next_list].n; q++) {
            ck_assert_uint_lt(c[q].node, 3);
            count[c[q].node]++;
            marked[c[q].node] += (c[q].local & WS_NCAND_CORNER) != 0;
            edges[c[q].node] += (c[q].local & WS_NCAND_EDGE) != 0;
        }
        report("shape %d: node at an edge: %d candidates (%d edges), %d marked; node at a vertex: "
               "%d candidates (%d edges), %d marked; node near a vertex: %d candidates (%d edges), "
               "%d marked",
               k, count[0], edges[0], marked[0], count[1], edges[1], marked[1], count[2], edges[2],
               marked[2]);
        ck_assert_msg(count[0] == 3 && edges[0] == 1,
                      "shape %d: the node at the edge has %d candidates (%d edges)", k, count[0],
                      edges[0]);
        ck_assert_msg(count[1] == 6 && edges[1] == 3,
                      "shape %d: the node at the vertex has %d candidates (%d edges)", k, count[1],
                      edges[1]);
        ck_assert_msg(count[2] == 5 && edges[2] == 3,
                      "shape %d: the node near the vertex has %d candidates (%d edges)", k,
                      count[2], edges[2]);
        ck_assert_msg(marked[0] == (k < 2) && marked[1] == 0 && marked[2] == 0,
                      "shape %d: %d marked at the edge, %d and %d at the vertex", k, marked[0],
                      marked[1], marked[2]);
        if (k < 2)
            ck_assert(c[0].local & WS_NCAND_CORNER); /* on the first of the three */
        ws_world_destroy(w);
    }
}
END_TEST

/* The prism on an equilateral triangle of side 1 m in the xz plane, 1 m long along y: its
 * edges' faces stand 60 degrees apart, their normals' dot product is -0.5. */
static const double prism_h = 0.86602540378443864676; /* sqrt(3) / 2 */
static const double prism_v[18] = {0, -0.5, 0, 1, -0.5, 0, 0.5, -0.5, 0.86602540378443864676,
                                   0, 0.5,  0, 1, 0.5,  0, 0.5, 0.5,  0.86602540378443864676};
static const uint32_t prism_t[24] = {0, 4, 1, 0, 3, 4, /* bottom */ 0, 1, 2, 3, 5, 4, /* ends */
                                     1, 4, 5, 1, 5, 2, /* right */ 0,  2, 5, 0, 5, 3 /* left */};

/* From the prism's top edge, at y: out of its left face's plane (normal (-h, 0, 1/2)) by dl
 * and of its right one's ((h, 0, 1/2)) by dr, into o: a dl-plane distance a - b / 2 and a
 * dr one b - a / 2 for a and b along the two normals. */
static void prism_offset(double dl, double dr, double y, double *o)
{
    const double a = (dl + 0.5 * dr) / 0.75, b = (dr + 0.5 * dl) / 0.75;
    o[0] = prism_h * (b - a);
    o[1] = y;
    o[2] = 0.5 * (a + b);
}

/* A film of three free nodes, tied to a fourth pinned far off, at offsets off (9 values) from
 * an edge of a kinematic body at the origin, with the short cuts off when runs_off: the unit
 * box's +x/+z edge, or the prism's top edge. */
static ws_world *edge_film_world(int prism, const double *off, int runs_off, ws_web_id *web)
{
    ws_world *w = weightless_world();
    ws_shape_id shape;
    if (prism)
        ck_ok(w, create_mesh(w, prism_v, 6, prism_t, 8, &shape));
    else
        ck_ok(w, ws_shape_create_box(w, 1.0, 1.0, 1.0, &shape));
    ws_shape_info si;
    ck_ok(w, ws_shape_get_info(w, shape, &si));
    still_body(w, shape, (ws_vec3){0, 0, 0});
    ws_web_def wd;
    soft_film(w, &wd);
    /* The edge in the body's frame, which the shape's centroid is the origin of. */
    const double ex = prism ? 0.5 - si.centroid.x : 0.5, ez = prism ? prism_h - si.centroid.z : 0.5;
    double pos[12];
    for (int i = 0; i < 3; i++) {
        pos[3 * i] = ex + off[3 * i];
        pos[3 * i + 1] = off[3 * i + 1];
        pos[3 * i + 2] = ez + off[3 * i + 2];
    }
    pos[9] = pos[10] = pos[11] = 3.0;
    probe_web(w, &wd, pos, 3, web);
    only_web(w)->contact->runs_off = runs_off;
    return w;
}

/* At a corner the planes may spare the edge its tests of direction (in_wedge), but only where
 * they show the node in the edge's region by their margin. By the box's edge: nodes 0.5 mm out
 * of one plane and 1e-9 m under the other are not (the other face holds them, not the edge),
 * one 0.3 mm out of both is. By the prism's sharp edge: nodes 0.5 mm out of one plane and 1e-9
 * m under the other, where the planes' test alone would take them (each face's projection of
 * them stands a quarter millimetre out of the other's plane), are held by nothing; one 0.3 mm
 * out of both is the edge's. The first step's contact forces are those of every candidate
 * through its full tests, to the bit. */
START_TEST(corner_edge_tests_spared_only_in_its_region)
{
    for (int prism = 0; prism < 2; prism++) {
        double off[9] = {0.5e-3, 0.0, -1e-9, -1e-9, 0.1, 0.5e-3, 0.3e-3, -0.1, 0.3e-3};
        if (prism) {
            prism_offset(-1e-9, 0.5e-3, -0.1, off);
            prism_offset(0.5e-3, -1e-9, 0.0, off + 3);
            prism_offset(0.3e-3, 0.3e-3, 0.1, off + 6);
        }
        ws_web_id wa, wb;
        ws_world *a = edge_film_world(prism, off, 1, &wa), *b = edge_film_world(prism, off, 0, &wb);
        ck_ok(a, ws_world_step(a));
        ck_ok(b, ws_world_step(b));
        ck_assert_uint_eq(only_web(a)->contact->corners, 0);
        ck_assert_uint_eq(only_web(b)->contact->corners, 3);
        double fa[12], fb[12];
        size_t n;
        ck_ok(a, ws_web_copy_contact_forces(a, wa, fa, 4, &n));
        ck_ok(b, ws_web_copy_contact_forces(b, wb, fb, 4, &n));
        report("node contact forces at the edge of %s: (%.3g %.3g %.3g), (%.3g %.3g %.3g), "
               "(%.3g %.3g %.3g) N",
               prism ? "the prism" : "the box", fb[0], fb[1], fb[2], fb[3], fb[4], fb[5], fb[6],
               fb[7], fb[8]);
        for (int i = 0; i < 12; i++)
            ck_assert_msg(fa[i] == fb[i],
                          "node %d: contact force %.17g with the short cuts, "
                          "%.17g without",
                          i / 3, fb[i], fa[i]);
        if (prism) {
            /* The first two are over no face and behind a plane: no contact; the third is the
             * edge's. */
            for (int i = 0; i < 6; i++)
                ck_assert(fb[i] == 0.0);
            ck_assert(fabs(fb[6]) < 1e-9 && fb[8] > 0.0);
        } else {
            /* The first two are held by one face, along its normal; the third by the edge. */
            ck_assert(fb[0] > 0.0 && fb[1] == 0.0 && fb[2] == 0.0);
            ck_assert(fb[3] == 0.0 && fb[4] == 0.0 && fb[5] > 0.0);
            ck_assert(fb[6] > 0.0 && fb[8] > 0.0);
        }
        ws_world_destroy(a);
        ws_world_destroy(b);
    }
}
END_TEST

/* ---- the explicit film's push past a convex body's edge (contact/node_force.c, convex_push)
 *
 * A kinematic 0.2 m box at the origin turned by 0.3 rad about z, and n film nodes, all pinned
 * (no friction, no velocity: a contact force is its push alone), at the body-frame places p,
 * with soft_film's contact (k 4000 N/m, c 1 N s/m; layers 1 mm each, a 2 mm window). One step
 * finds the candidates and evaluates them at the places, through the explicit film's one-by-one
 * pass and its corner short cut; the nodes' contact forces go to f, their places to x (both 3
 * n values, global). */
static void yawed_box_pushes(size_t n, const double *p, double *x, double *f)
{
    ws_world *w = weightless_world();
    ws_shape_id cube;
    ck_ok(w, ws_shape_create_box(w, 0.2, 0.2, 0.2, &cube));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = cube;
    bd.orientation = (ws_quat){cos(0.15), 0.0, 0.0, sin(0.15)};
    ws_body_id body;
    ck_ok(w, ws_body_create(w, &bd, &body));
    ws_web_def wd;
    soft_film(w, &wd);
    const double c = cos(0.3), s = sin(0.3);
    uint32_t spring[8], pin[5];
    ck_assert_uint_le(n, 5);
    for (size_t i = 0; i < n; i++) {
        x[3 * i] = c * p[3 * i] - s * p[3 * i + 1];
        x[3 * i + 1] = s * p[3 * i] + c * p[3 * i + 1];
        x[3 * i + 2] = p[3 * i + 2];
        pin[i] = (uint32_t)i;
        if (i + 1 < n)
            spring[2 * i] = (uint32_t)i, spring[2 * i + 1] = (uint32_t)(i + 1);
    }
    ws_web_mesh_def mesh;
    ws_web_mesh_def_init(&mesh);
    mesh.positions = x;
    mesh.node_count = n;
    mesh.springs = spring;
    mesh.spring_count = n - 1;
    mesh.pinned = pin;
    mesh.pinned_count = n;
    ws_web_id web;
    ck_ok(w, ws_web_create_mesh(w, &wd, &mesh, &web));
    ck_ok(w, ws_world_step(w));
    size_t got;
    ck_ok(w, ws_web_copy_contact_forces(w, web, f, n, &got));
    ck_assert_uint_eq(got, n);
    ws_world_destroy(w);
}

START_TEST(explicit_push_past_edge_continuous)
{
    /* A node pressed past the box's vertical edge (+x, +y) at depth delta below both side
     * faces, on the bisector and 1e-12 m to either side of it, in the explicit film. What the
     * push must be: continuous across the bisector (the blend's gradient is at most k (hi +
     * delta) |n_A - n_B| / (2 W) ~ 2.5e4 N/m, W = min(1 mm, delta), so 1e-12 m moves it by
     * 2.5e-8 N at most: bound 1e-7 N); on the bisector k (hi + delta), the overlap below the
     * surface (to 1e-9 of it), along the bisector (to 1e-10: round-off of the turned planes
     * turns it by 1e-14), so with no moment about the box's vertical axis. The shallowest face
     * alone (the explicit film's law before) turned it by 45 degrees across the bisector, a
     * jump of 0.77 k (hi + delta): 11 N at 1.5 mm. Two depths: 1.5 mm (W = 1 mm) and 0.4 mm
     * (W pinched to the depth). */
    const double depths[2] = {1.5e-3, 0.4e-3}, k = 4000.0, hi = 2e-3, r2 = sqrt(0.5);
    for (int dc = 0; dc < 2; dc++) {
        const double de = depths[dc];
        double p[9], x[9], f[9];
        for (int j = 0; j < 3; j++) {
            const double o = (j - 1) * 1e-12 * r2; /* across the bisector, 1e-12 m */
            p[3 * j] = 0.1 - de + o, p[3 * j + 1] = 0.1 - de - o, p[3 * j + 2] = 0.0;
        }
        yawed_box_pushes(3, p, x, f);
        const double c = cos(0.3), s = sin(0.3);
        const double bis[3] = {r2 * (c - s), r2 * (s + c), 0.0}; /* the turned bisector */
        double jm = 0, jp = 0, size = 0, along = 0;
        for (int q = 0; q < 3; q++) {
            jm += (f[q] - f[3 + q]) * (f[q] - f[3 + q]);
            jp += (f[6 + q] - f[3 + q]) * (f[6 + q] - f[3 + q]);
            size += f[3 + q] * f[3 + q];
            along += f[3 + q] * bis[q];
        }
        jm = sqrt(jm), jp = sqrt(jp), size = sqrt(size);
        double across = 0.0;
        for (int q = 0; q < 3; q++)
            across += (f[3 + q] - along * bis[q]) * (f[3 + q] - along * bis[q]);
        across = sqrt(across);
        const double mz = x[3] * f[4] - x[4] * f[3], want = k * (hi + de);
        report("explicit film, push past the edge %.1f mm deep: %.4f N (want %.4f); jumps %.2g, "
               "%.2g N across the bisector; off it %.2g of the push; moment about z %.2g N m",
               de * 1e3, size, want, jm, jp, across / size, mz);
        ck_assert_msg(jm <= 1e-7 && jp <= 1e-7, "the push jumps by %g, %g N across the bisector",
                      jm, jp);
        ck_assert_msg(fabs(size - want) <= 1e-9 * want, "push %.12g N, want %.12g", size, want);
        ck_assert_msg(across <= 1e-10 * size, "push off the bisector by %g N", across);
        ck_assert_msg(fabs(mz) <= 1e-10 * size * hypot(x[3], x[4]), "moment about z %g N m", mz);
    }
}
END_TEST

START_TEST(explicit_band_corners_mirror)
{
    /* Four nodes past the box's four vertical edges, on the bisectors, 0.8 mm deep (a refined
     * band's corner columns), in the explicit film: the set is its own mirror image in the
     * box's x-z and y-z planes, so the pushes' moment about the box's vertical axis must
     * vanish. Each push k (hi + 0.8 mm) = 11.2 N along its bisector has none; round-off of the
     * turned planes (1e-17 m of depth) turns it by 1e-12 N at most (see above), a moment of
     * 1e-13 N m; bound 1e-9 N m, against 0.8 N m of one corner pushed by a single face
     * (the shallowest face alone, picked by round-off on the bisector). Again with mirrored
     * noise: each node moved 1e-8 m across its bisector, mirror images mirror-wise, where each
     * node's moment (3e-5 N m) cancels its image's. */
    for (int noisy = 0; noisy < 2; noisy++) {
        const double de = 0.8e-3, eta = noisy ? 1e-8 * sqrt(0.5) : 0.0;
        double p[12], x[12], f[12], mz = 0.0, one = 0.0, off = 0.0;
        for (int c = 0; c < 4; c++) {
            const double sx = (c & 1) ? -1.0 : 1.0, sy = (c & 2) ? -1.0 : 1.0;
            p[3 * c] = sx * (0.1 - de + eta), p[3 * c + 1] = sy * (0.1 - de - eta);
            p[3 * c + 2] = 0.0;
        }
        yawed_box_pushes(4, p, x, f);
        for (int c = 0; c < 4; c++) {
            const double m = x[3 * c] * f[3 * c + 1] - x[3 * c + 1] * f[3 * c];
            const double size = sqrt(f[3 * c] * f[3 * c] + f[3 * c + 1] * f[3 * c + 1] +
                                     f[3 * c + 2] * f[3 * c + 2]);
            /* k (hi - m), m the shallower depth: -(de - eta) */
            off = fmax(off, fabs(size / (4000.0 * (2e-3 + de - eta)) - 1.0));
            mz += m;
            one = fmax(one, fabs(m));
        }
        report("explicit film, band corners%s: moment about z %.2g N m (largest one's %.2g); "
               "pushes off k (hi - m) by %.2g of it",
               noisy ? ", 1e-8 m mirrored noise" : " on the bisectors", mz, one, off);
        ck_assert_msg(fabs(mz) <= 1e-9, "the corners twist the box: %g N m", mz);
        ck_assert_msg(off <= 1e-9, "a corner's push is off k (hi - m) by %g of it", off);
    }
}
END_TEST

/* A film node in the inner corner of two kinematic unit cubes, A's top face and B's -x face
 * standing at right angles, 0.5 mm out of both (held by a spring to a node pinned 3 m off), in
 * a gravity that presses it into both faces and drags it along the corner's line: both faces
 * push it and it slides. The friction of each face's contact is found from the node's force
 * with every normal force in, so the motion does not depend on which body was made first (which
 * puts its contact first): the two orders agree to round-off. A friction taken before the other
 * face's normal force is in would tilt the node's predicted slip by that force. */
static ws_world *inner_corner_world(int b_first, ws_web_id *web)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.gravity = (ws_vec3){1.0, 8.0, -3.0};
    d.dt = 2.5e-4;
    ws_world *w;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    ws_shape_id cube;
    ck_ok(w, ws_shape_create_box(w, 1.0, 1.0, 1.0, &cube));
    const ws_vec3 at[2] = {{0.0, 0.0, 0.0}, {1.0, 0.0, 1.0}};
    for (int k = 0; k < 2; k++)
        still_body(w, cube, at[b_first ? 1 - k : k]);
    ws_web_def wd;
    soft_film(w, &wd);
    const double pos[6] = {0.5 - 1.99e-3, 0.0, 0.5 + 1.99e-3, 0.5, 3.0, 0.5};
    probe_web(w, &wd, pos, 1, web);
    return w;
}

START_TEST(friction_sees_every_normal_force)
{
    ws_web_id wa, wb;
    ws_world *a = inner_corner_world(0, &wa), *b = inner_corner_world(1, &wb);
    double xa[6], xb[6], fc[6], dev = 0.0;
    size_t n;
    for (int k = 0; k < 400; k++) {
        ck_ok(a, ws_world_step(a));
        ck_ok(b, ws_world_step(b));
        ck_ok(a, ws_web_copy_positions(a, wa, xa, 2, &n));
        ck_ok(b, ws_web_copy_positions(b, wb, xb, 2, &n));
        for (int i = 0; i < 3; i++)
            dev = fmax(dev, fabs(xa[i] - xb[i]));
    }
    ck_ok(a, ws_web_copy_contact_forces(a, wa, fc, 2, &n));
    report("node in an inner corner: at (%.6f %.6f %.6f) m, contact force (%.3g %.3g %.3g) N; "
           "the two orders of the bodies differ by %.1e m",
           xa[0], xa[1], xa[2], fc[0], fc[1], fc[2], dev);
    /* Both faces push (B's along -x, A's along +z), and the node slides along y. */
    ck_assert(fc[0] < 0.0 && fc[2] > 0.0 && fc[1] != 0.0);
    ck_assert(xa[1] > 1e-3);
    ck_assert_msg(dev < 1e-12, "the order of the bodies moves the node by %.3e m", dev);
    ws_world_destroy(a);
    ws_world_destroy(b);
}
END_TEST

/* Whether a node lies well inside a face (a margin or more behind every other face's plane
 * where it projects on the face's plane) takes the projection: out of the face's plane by df,
 * it lies dg - df c out of face g's plane, c the dot product of their normals. By the prism's
 * top edge (c = -0.5), 1.5 mm out of one face's plane: 2.25 mm behind the other's plane the
 * projection lies 1.5 mm behind it, within the margin (2 mm): not well inside, and the edge is
 * a candidate; 3.25 mm behind the plane, 2.5 mm: well inside, the face alone. */
START_TEST(well_inside_takes_the_projection)
{
    double off[9];
    prism_offset(-2.25e-3, 1.5e-3, -0.1, off);
    prism_offset(1.5e-3, -2.25e-3, 0.0, off + 3);
    prism_offset(-3.25e-3, 1.5e-3, 0.1, off + 6);
    ws_web_id id;
    ws_world *w = edge_film_world(1, off, 0, &id);
    ck_ok(w, ws_world_step(w));
    const ws_web *wb = only_web(w);
    const ws_ncand *c = wb->contact->cand[wb->contact->next_list].c;
    int faces[3] = {0, 0, 0}, inside[3] = {0, 0, 0}, edges[3] = {0, 0, 0};
    for (size_t q = 0; q < wb->contact->cand[wb->contact->next_list].n; q++) {
        ck_assert_uint_lt(c[q].node, 3);
        if (c[q].local & WS_NCAND_EDGE) {
            edges[c[q].node]++;
        } else {
            faces[c[q].node]++;
            inside[c[q].node] += (c[q].local & WS_NCAND_INSIDE) != 0;
        }
    }
    for (int i = 0; i < 3; i++)
        report("prism, node %d: %d face(s), %d inside, %d edge(s)", i, faces[i], inside[i],
               edges[i]);
    for (int i = 0; i < 2; i++)
        ck_assert_msg(faces[i] == 1 && inside[i] == 0 && edges[i] == 1,
                      "node %d: %d faces (%d inside), %d edges", i, faces[i], inside[i], edges[i]);
    ck_assert_msg(faces[2] == 1 && inside[2] == 1 && edges[2] == 0,
                  "node 2: %d faces (%d inside), %d edges", faces[2], inside[2], edges[2]);
    ws_world_destroy(w);
}
END_TEST

START_TEST(film_detection_does_not_change_the_motion)
{
    film_detection_case(0);
    film_detection_case(1);
    film_detection_case(2);
    film_detection_case(3);
    film_detection_case(4);
    film_detection_case(5);
}
END_TEST

/* The reference body of a film (a free box) and a sheet of 400 nodes over its top walk at
 * random, a step of some um in turn and position for the box and of some tenths of a mm for a
 * few nodes: ws_node_moved must flag every node whose move relative to the box since it was
 * found reaches a quarter of the margin (one sub-step), however it tests that move. A test of
 * the nodes' global moves against where they were found, as the box stood at some earlier step,
 * must allow for how far the box moved and turned since; and as that allowance stays under 1/8
 * of the bound, no node that moved less than 3/4 of it may be flagged (nor one whose flag of an
 * earlier step was left set). */
START_TEST(nodes_moved_relative_to_the_reference_are_flagged)
{
    ws_world *w = weightless_world();
    ws_shape_id cube;
    ck_ok(w, ws_shape_create_box(w, 0.2, 0.2, 0.2, &cube));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = cube;
    bd.mass = 5.0;
    bd.name = "box";
    ws_body_id box;
    ck_ok(w, ws_body_create(w, &bd, &box));
    ws_web_def wd;
    soft_film(w, &wd);
    /* 20 x 20 nodes 2 cm apart, 1 mm over the top (z = 0.1 m), at levers up to 0.27 m. */
    enum { N = 400 };
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = sd.ny = 20;
    sd.spacing_x = sd.spacing_y = 0.02;
    sd.origin = (ws_vec3){-0.19, -0.19, 0.1 + 1e-3};
    ws_web_id id;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &id));
    ck_ok(w, ws_world_step(w));
    ws_web *web = only_web(w);
    ck_assert_uint_eq(web->n, N);
    ws_body_store *b = &w->bodies;
    const int cur = w->cur;
    const uint32_t k = web->contact->ref;
    ck_assert_uint_ne(k, UINT32_MAX);
    const double margin = w->def.contact_margin, lim = 0.25 * margin;
    uint64_t seed = 12345;
    long flagged = 0, due = 0, epochs = 0;
    double *s0 = malloc(3 * N * sizeof *s0);
    uint8_t *hit = malloc(N);
    ck_assert(s0 && hit);
    for (int step = 0; step < 10000; step++) {
        /* The box turns by up to 0.17 mrad (46 um at the far corner) and moves up to 17 um;
         * four nodes move up to 0.7 mm each, so that many reach the bound while the box
         * drifts. */
        double rnd[18];
        for (int j = 0; j < 18; j++) {
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
            rnd[j] = (double)(seed >> 11) / 9007199254740992.0 - 0.5;
        }
        qt dq = qt_from_rotvec(v3_make(2e-4 * rnd[0], 2e-4 * rnd[1], 2e-4 * rnd[2]));
        b->st[cur].p[k] = qt_normalize(qt_mul(dq, b->st[cur].p[k]));
        b->A[k] = qt_to_m3(b->st[cur].p[k]);
        b->st[cur].r[k] =
            v3_add(b->st[cur].r[k], v3_make(2e-5 * rnd[3], 2e-5 * rnd[4], 2e-5 * rnd[5]));
        ws_nodes3 x = web->x[cur];
        for (int j = 0; j < 4; j++) {
            const uint32_t i = (uint32_t)((rnd[6 + 3 * j] + 0.5) * N) % N;
            x.x[i] += 8e-4 * rnd[7 + 3 * j];
            x.y[i] += 8e-4 * rnd[8 + 3 * j];
            x.z[i] += 8e-4 * rnd[6 + 3 * j];
        }
        for (uint32_t q = 0; q < N; q++) {
            s0[3 * q] = web->contact->xdet.x[q];
            s0[3 * q + 1] = web->contact->xdet.y[q];
            s0[3 * q + 2] = web->contact->xdet.z[q];
        }
        const v3 e0 = web->contact->epoch_r;
        double least[16]; /* a double a tracked body */
        ck_assert_uint_le(web->contact->ntrack, 16);
        long moved = ws_node_moved(b, cur, web, x, web->v[cur], w->def.dt, margin, least);
        if (moved < 0)
            ck_abort_msg("step %d: every node to be found again", step);
        epochs += e0.x != web->contact->epoch_r.x || e0.y != web->contact->epoch_r.y ||
                  e0.z != web->contact->epoch_r.z;
        memset(hit, 0, N);
        for (long m = 0; m < moved; m++)
            hit[web->contact->moved[m]] = 1;
        for (uint32_t q = 0; q < N; q++) {
            /* Asserted only when it fails: the checks are many. */
            v3 u = v3_sub(m3_tmul_v(&b->A[k], v3_sub(nodes_get(x, q), b->st[cur].r[k])),
                          v3_make(s0[3 * q], s0[3 * q + 1], s0[3 * q + 2]));
            if (hit[q] && v3_norm(u) < 0.75 * lim)
                ck_abort_msg("step %d: node %u flagged, moved only %.4g mm relative to the box",
                             step, q, 1e3 * v3_norm(u));
            if (v3_norm(u) < lim)
                continue;
            due++;
            if (!hit[q])
                ck_abort_msg("step %d: node %u moved %.4g mm relative to the box, unflagged",
                             step, q, 1e3 * v3_norm(u));
        }
        flagged += moved;
    }
    report("nodes walking on a drifting box: %ld flagged, %ld due; %ld new epochs", flagged, due,
           epochs);
    ck_assert_msg(due > 1000 && epochs > 100, "the walk tests too little");
    free(s0);
    free(hit);
    ws_world_destroy(w);
}
END_TEST

/* Candidate lists merged at random: nodes found again keep their candidates, lose them, gain
 * some or change one's feature. ws_node_same must tell whether any changed; the merge, planned
 * (ws_node_merge_plan) and carried out in pieces of nodes cut at random
 * (ws_node_merge_range), must give the list a search of every node would (the old candidates
 * of the other nodes, the fresh ones of those found again) with the nodes that changed, and the
 * index of the merged list, the old one's left as it was. */
START_TEST(merged_candidates_equal_the_list_they_stand_for)
{
    enum { N = 40 };
    uint64_t seed = 777;
    ws_ncand *old = malloc(4 * N * sizeof *old), *fresh = malloc(4 * N * sizeof *fresh),
             *want = malloc(4 * N * sizeof *want), *out = NULL;
    size_t *start = malloc((N + 1) * sizeof *start), *index = malloc((N + 1) * sizeof *index);
    size_t *nstart = malloc((N + 1) * sizeof *nstart),
           *kept_start = malloc((N + 1) * sizeof *start);
    ws_nplace place[N + 1];
    ck_assert(old && fresh && want && start && index && nstart && kept_start);
    ws_mem mem;
    ws_mem_init(&mem, NULL);
    size_t cap = 0, merges = 0, kept = 0;
    for (int round = 0; round < 2000; round++) {
        /* Each node holds 0 to 3 candidates; a quarter of the nodes are found again. */
        size_t nold = 0, nfresh = 0, nwant = 0, count = 0, expect = 0;
        uint32_t nodes[N], changed[N], expected[N];
        int mode = round % 4; /* 0: all found again as they were */
        for (uint32_t i = 0; i < N; i++) {
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
            const uint32_t r = (uint32_t)(seed >> 33);
            const uint32_t had = r % 4, again = (r >> 2) % 4 == 0;
            for (uint32_t j = 0; j < had; j++)
                old[nold++] = (ws_ncand){i, j, 10 * i + j, j};
            if (!again) {
                for (uint32_t j = 0; j < had; j++)
                    want[nwant++] = (ws_ncand){i, j, 10 * i + j, j};
                continue;
            }
            nodes[count++] = i;
            /* Found again: the same, one more, one fewer, or one feature changed. */
            const uint32_t how = mode == 0 ? 0 : (r >> 4) % 4;
            const uint32_t has = how == 1 ? had + 1 : how == 2 && had ? had - 1 : had;
            for (uint32_t j = 0; j < has; j++) {
                ws_ncand c = {i, j, 10 * i + j, j};
                if (how == 3 && j + 1 == has)
                    c.local |= WS_NCAND_INSIDE;
                fresh[nfresh++] = c;
                want[nwant++] = c;
            }
            if (has != had || (how == 3 && had))
                expected[expect++] = i;
        }
        ws_node_index(old, nold, N, start);
        const ws_ncand_list lold = {old, nold, nold}, lfresh = {fresh, nfresh, nfresh};
        const ws_node_found found = {nodes, count, &lfresh};
        const int same = ws_node_same(&found, start, old);
        ck_assert_int_eq(same, expect == 0);
        if (same) {
            kept++;
            continue;
        }
        ws_ncand_list lout = {out, 0, cap};
        ws_nmerge M = {.ostart = start, .nstart = nstart, .place = place, .nn = N};
        memcpy(kept_start, start, (N + 1) * sizeof *start);
        const long nchanged = ws_node_merge_plan(&mem, &found, &lold, &M, &lout, changed);
        ck_assert_int_ge(nchanged, 0);
        out = lout.c;
        cap = lout.cap;
        /* In pieces of 1 to 16 nodes, in an order of their own: the last first. */
        uint32_t cut[N + 1], ncut = 0;
        for (uint32_t i = 0; i < N; i += 1 + (uint32_t)(seed >> 60)) {
            cut[ncut++] = i;
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        }
        cut[ncut] = N;
        for (uint32_t p = ncut; p-- > 0;)
            ws_node_merge_range(&M, cut[p], cut[p + 1]);
        ck_assert(!memcmp(start, kept_start, (N + 1) * sizeof *start));
        const size_t n = lout.n;
        merges++;
        ck_assert_uint_eq(n, nwant);
        ck_assert(n == 0 || !memcmp(out, want, n * sizeof *out));
        ck_assert_uint_eq((size_t)nchanged, expect);
        ck_assert(!expect || !memcmp(changed, expected, expect * sizeof *changed));
        ws_node_index(out, n, N, index);
        ck_assert(!memcmp(nstart, index, (N + 1) * sizeof *nstart));
    }
    report("candidate lists: %zu merged, %zu kept as they were", merges, kept);
    ck_assert(merges > 100 && kept > 100);
    ws_mem_free(&mem, out, cap * sizeof *out);
    free(old);
    free(fresh);
    free(want);
    free(start);
    free(index);
    free(nstart);
    free(kept_start);
}
END_TEST

/* The report of the node contact forces holds the last step's contacts alone: a sheet pressed
 * on a box, the box then taken away (10 m aside, between steps), and the sheet's nodes in free
 * fall for two steps, which write each of the report's two buffers once: every node's
 * contact force must then be zero exactly (a force left from the steps on the box, in either
 * buffer, is up to some N). On 1 and 2 workers (one sweep lane, or four). */
START_TEST(contact_forces_end_with_the_contacts)
{
    for (int workers = 1; workers <= 2; workers++) {
        ws_world_def d;
        ws_world_def_init(&d);
        d.dt = 2.5e-4;
        d.worker_count = (uint32_t)workers;
        ws_world *w = NULL;
        ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
        const ws_body_id box =
            add_box(w, 0.4, 0.3, 0.3, 20.0, (ws_vec3){0.0, 0.0, 0.5}, no_material(), "box");
        ws_pose held = {{0.0, 0.0, 0.5}, {1.0, 0.0, 0.0, 0.0}};
        ws_web_def wd;
        soft_film(w, &wd);
        ws_sheet_def sd;
        ws_sheet_def_init(&sd);
        sd.nx = 48;
        sd.ny = 40; /* 5 sweep blocks of 8 rows */
        sd.spacing_x = sd.spacing_y = 0.0125;
        sd.origin = (ws_vec3){-0.2975, -0.24375, 0.653};
        ws_web_id web;
        ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
        double S;
        ck_ok(w, ws_web_get_stable_dt(w, web, &S));
        const int n = (int)ceil(2.1 * d.dt / S);
        ck_ok(w, ws_web_set_substeps(w, web, n < 1 ? 1 : n));
        const size_t nn = 48 * 40;
        double *fc = malloc(3 * nn * sizeof *fc);
        ck_assert(fc);
        size_t got;
        double most = 0.0;
        for (int k = 0; k < 200; k++) { /* the box held still, the sheet dropped on it */
            ck_ok(w, ws_body_set_pose(w, box, &held));
            ck_ok(w, ws_body_set_velocity(w, box, &(ws_vec3){0, 0, 0}, &(ws_vec3){0, 0, 0}));
            ck_ok(w, ws_world_step(w));
        }
        ck_ok(w, ws_web_copy_contact_forces(w, web, fc, nn, &got));
        for (size_t i = 0; i < 3 * nn; i++)
            most = fmax(most, fabs(fc[i]));
        ck_assert_msg(most > 1e-3, "the sheet never pressed on the box (%g N)", most);
        const ws_pose away = {{10.0, 0.0, 0.5}, {1.0, 0.0, 0.0, 0.0}};
        ck_ok(w, ws_body_set_pose(w, box, &away));
        for (int k = 0; k < 2; k++) {
            ck_ok(w, ws_world_step(w));
            ck_ok(w, ws_web_copy_contact_forces(w, web, fc, nn, &got));
            size_t left = 0;
            for (size_t i = 0; i < 3 * nn; i++)
                left += fc[i] != 0.0;
            ck_assert_msg(left == 0,
                          "%d workers, step %d after the box left: %zu components of the "
                          "node contact forces not zero (before: up to %g N)",
                          workers, k + 1, left, most);
        }
        report("contact forces end with the contacts (%d workers): up to %.3g N on the box, "
               "all zero after it left",
               workers, most);
        free(fc);
        ws_world_destroy(w);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("detection");
    TCase *tc = tcase_create("schedule");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, schedule_does_not_change_the_motion);
    tcase_add_test(tc, ccd_gate_does_not_change_the_motion);
    tcase_add_test(tc, schedule_keeps_nearly_parallel_edges);
    tcase_add_test(tc, crossed_edges_hold_below_the_margin);
    tcase_add_test(tc, impact_stays_within_the_layers);
    tcase_add_test(tc, film_detection_does_not_change_the_motion);
    tcase_add_test(tc, film_runs_equal_one_by_one);
    tcase_add_test(tc, film_node_past_an_edge_end);
    tcase_add_test(tc, edges_of_faces_a_node_is_well_inside_of_are_dropped);
    tcase_add_test(tc, corners_need_flat_faces);
    tcase_add_test(tc, corners_are_marked_by_the_detection);
    tcase_add_test(tc, corner_edge_tests_spared_only_in_its_region);
    tcase_add_test(tc, explicit_push_past_edge_continuous);
    tcase_add_test(tc, explicit_band_corners_mirror);
    tcase_add_test(tc, friction_sees_every_normal_force);
    tcase_add_test(tc, well_inside_takes_the_projection);
    tcase_add_test(tc, nodes_moved_relative_to_the_reference_are_flagged);
    tcase_add_test(tc, merged_candidates_equal_the_list_they_stand_for);
    tcase_add_test(tc, contact_forces_end_with_the_contacts);
    suite_add_tcase(s, tc);
    return run_suite(s);
}
