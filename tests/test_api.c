/* API contract tests: ids, Defs, argument validation, allocation failure, memory accounting,
 * determinism, failed steps, bulk copies, versions, the log hook, shape lifetime, tilt drives.
 * STYLE.md rule 12. */
#include "helpers.h"

#include <stdio.h>

/* ---- small helpers ---- */

static ws_body_id box_at(ws_world *w, double edge, double m, double x, double y, double z,
                         const char *name)
{
    ws_vec3 c = {x, y, z};
    return add_box(w, edge, edge, edge, m, c, no_material(), name);
}

static size_t body_count(ws_world *w)
{
    size_t n = 99;
    ck_ok(w, ws_world_copy_body_ids(w, NULL, 0, &n));
    return n;
}

static uint64_t hash_of(ws_world *w)
{
    uint64_t h = 0;
    ck_ok(w, ws_world_get_state_hash(w, &h));
    return h;
}

static double time_of(ws_world *w)
{
    double t = -1.0;
    ck_ok(w, ws_world_get_time(w, &t));
    return t;
}

/* The last error names the problem: a key word (and, for bodies, the body's name). */
#define ck_err_has(w, word)                                                                        \
    ck_assert_msg(strstr(ws_world_last_error(w), (word)) != NULL,                                  \
                  "last error '%s' does not mention '%s'", ws_world_last_error(w), (word))

/* Every id-taking body call must refuse `id` with WS_ERR_STALE_HANDLE and not crash. */
static void expect_stale_body(ws_world *w, ws_body_id id)
{
    ws_vec3 v = {0, 0, 0}, v2;
    ws_quat q;
    ws_mat3 m;
    double d;
    ws_body_type ty;
    ws_pose pose = {{0, 0, 0}, {1, 0, 0, 0}};
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    ck_assert_int_eq(ws_body_is_valid(w, id), 0);
    ck_assert_int_eq(ws_body_get_type(w, id, &ty), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_get_position(w, id, &v2), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_get_orientation(w, id, &q), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_get_rotation(w, id, &m), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_get_velocity(w, id, &v2), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_get_angular_velocity(w, id, &v2), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_get_angular_velocity_local(w, id, &v2), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_get_point_velocity(w, id, &v, &v2), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_get_world_point(w, id, &v, &v2), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_get_mass(w, id, &d), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_get_inertia(w, id, &m), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_get_contact_force(w, id, &v2, NULL), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_set_pose(w, id, &pose), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_set_velocity(w, id, &v, &v), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_set_drive(w, id, &dd), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_body_destroy(w, id), WS_ERR_STALE_HANDLE);
    ck_assert_str_eq(ws_body_get_name(w, id), "");
    ck_assert_ptr_null(ws_body_get_user_data(w, id));
    ck_assert_str_ne(ws_world_last_error(w), "");
}

static void expect_stale_shape(ws_world *w, ws_shape_id id)
{
    ws_shape_info info;
    size_t nv = 0, nt = 0;
    ck_assert_int_eq(ws_shape_is_valid(w, id), 0);
    ck_assert_int_eq(ws_shape_get_info(w, id, &info), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_shape_copy_mesh(w, id, NULL, 0, &nv, NULL, 0, &nt), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_shape_destroy(w, id), WS_ERR_STALE_HANDLE);
    /* A body on a stale shape is refused too. */
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = id;
    bd.name = "orphan";
    ws_body_id b;
    ck_assert_int_eq(ws_body_create(w, &bd, &b), WS_ERR_STALE_HANDLE);
    /* The message names the body and what is wrong with it. */
    const char *e = ws_world_last_error(w);
    ck_assert_msg(strstr(e, "orphan") && strstr(e, "shape"), "last error '%s'", e);
}

/* ---- stale, foreign and null ids ---- */

START_TEST(test_stale_destroyed_body)
{
    ws_world *w = new_world(2.5e-4);
    ws_body_id a = box_at(w, 0.1, 1.0, 0, 0, 1, "a");
    ck_assert_int_eq(ws_body_is_valid(w, a), 1);
    ck_ok(w, ws_body_destroy(w, a));
    expect_stale_body(w, a);
    /* The freed slot is reused with a new generation: the old id stays stale, the new one works. */
    ws_body_id b = box_at(w, 0.1, 1.0, 0, 0, 1, "b");
    ck_assert_int_eq(ws_body_is_valid(w, b), 1);
    ck_assert(a.bits != b.bits);
    expect_stale_body(w, a);
    ck_assert_str_eq(ws_body_get_name(w, b), "b");
    ck_assert_uint_eq(body_count(w), 1);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_stale_null_body)
{
    ws_world *w = new_world(2.5e-4);
    box_at(w, 0.1, 1.0, 0, 0, 1, "a"); /* a live body in slot 0 must not be reached by null */
    ws_body_id nul = {0};
    expect_stale_body(w, nul);
    ws_shape_id nuls = {0};
    expect_stale_shape(w, nuls);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_stale_foreign_world)
{
    ws_world *w = new_world(2.5e-4), *w2 = new_world(2.5e-4);
    /* Same construction order in both worlds: same slots and generations; only the world tag
     * differs. */
    ws_body_id mine = box_at(w, 0.1, 1.0, 0, 0, 1, "mine");
    ws_body_id other = box_at(w2, 0.1, 1.0, 0, 0, 1, "other");
    ck_assert(mine.bits != other.bits);
    expect_stale_body(w, other);
    ck_assert_int_eq(ws_body_is_valid(w, mine), 1);
    ck_assert_int_eq(ws_body_is_valid(w2, other), 1);
    ws_shape_id s2;
    ck_ok(w2, ws_shape_create_box(w2, 1, 1, 1, &s2));
    expect_stale_shape(w, s2);
    ck_assert_int_eq(ws_shape_is_valid(w2, s2), 1);
    /* A foreign material is refused as well. */
    ws_material_id m2;
    ck_ok(w2, ws_world_get_default_material(w2, &m2));
    ws_material_id m1;
    ck_ok(w, ws_world_get_default_material(w, &m1));
    ck_assert_int_eq(ws_material_is_valid(w, m2), 0);
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    ck_assert_int_eq(ws_world_set_contact(w, m1, m2, &cd), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_world_get_contact(w, m2, m1, &cd), WS_ERR_STALE_HANDLE);
    ws_shape_id s1;
    ck_ok(w, ws_shape_create_box(w, 1, 1, 1, &s1));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = s1;
    bd.material = m2;
    bd.name = "stranger";
    ws_body_id b;
    ck_assert_int_eq(ws_body_create(w, &bd, &b), WS_ERR_STALE_HANDLE);
    const char *e = ws_world_last_error(w);
    ck_assert_msg(strstr(e, "stranger") && strstr(e, "material"), "last error '%s'", e);
    /* A tag collision between two worlds (1 in 65536) would make these ids look local; the
     * construction above gives the same slots in both, so only the tag can tell them apart. */
    ws_world_destroy(w2);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_stale_wrong_kind)
{
    ws_world *w = new_world(2.5e-4);
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = s;
    ws_body_id b;
    ck_ok(w, ws_body_create(w, &bd, &b));
    /* A shape id in a body slot and a body id in a shape slot: both live objects of this world in
     * slot 0, so only the kind tells them apart. */
    ws_body_id as_body = {s.bits};
    ws_shape_id as_shape = {b.bits};
    expect_stale_body(w, as_body);
    ck_assert_int_eq(ws_shape_is_valid(w, as_shape), 0);
    ws_shape_info info;
    ck_assert_int_eq(ws_shape_get_info(w, as_shape, &info), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_shape_destroy(w, as_shape), WS_ERR_STALE_HANDLE);
    ws_material_id as_mat = {b.bits};
    ck_assert_int_eq(ws_material_is_valid(w, as_mat), 0);
    /* The real objects are untouched. */
    ck_assert_int_eq(ws_body_is_valid(w, b), 1);
    ck_assert_int_eq(ws_shape_is_valid(w, s), 1);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_is_valid_keeps_last_error)
{
    ws_world *w = new_world(2.5e-4);
    ws_body_id b = box_at(w, 0.1, 1.0, 0, 0, 1, "b");
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 1, 1, 1, &s));
    ck_assert_int_eq(ws_world_set_dt(w, -1.0), WS_ERR_INVALID_ARGUMENT);
    char keep[1024];
    snprintf(keep, sizeof keep, "%s", ws_world_last_error(w));
    ck_assert_str_ne(keep, "");
    ws_body_id nul = {0}, wrong = {s.bits}, junk = {0xFFFFFFFFFFFFFFFFull};
    ws_shape_id snul = {0}, swrong = {b.bits};
    ws_material_id mnul = {0}, mjunk = {0x0123456789ABCDEFull};
    ck_assert_int_eq(ws_body_is_valid(w, nul), 0);
    ck_assert_int_eq(ws_body_is_valid(w, wrong), 0);
    ck_assert_int_eq(ws_body_is_valid(w, junk), 0);
    ck_assert_int_eq(ws_body_is_valid(w, b), 1);
    ck_assert_int_eq(ws_shape_is_valid(w, snul), 0);
    ck_assert_int_eq(ws_shape_is_valid(w, swrong), 0);
    ck_assert_int_eq(ws_shape_is_valid(w, s), 1);
    ck_assert_int_eq(ws_material_is_valid(w, mnul), 0);
    ck_assert_int_eq(ws_material_is_valid(w, mjunk), 0);
    ck_assert_str_eq(ws_world_last_error(w), keep);
    /* A NULL world is a question with the answer 0, not a crash. */
    ck_assert_int_eq(ws_body_is_valid(NULL, b), 0);
    ck_assert_int_eq(ws_shape_is_valid(NULL, s), 0);
    ck_assert_int_eq(ws_material_is_valid(NULL, mnul), 0);
    ws_world_destroy(w);
}
END_TEST

/* ---- uninitialised Defs ---- */

START_TEST(test_uninit_world_def)
{
    ws_world_def d;
    ws_world *w = (ws_world *)&d; /* must be reset to NULL on error */
    memset(&d, 0xAB, sizeof d);
    ck_assert_int_eq(ws_world_create(&d, &w), WS_ERR_UNINITIALIZED_DEF);
    ck_assert_ptr_null(w);
    memset(&d, 0, sizeof d);
    w = (ws_world *)&d;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_ERR_UNINITIALIZED_DEF);
    ck_assert_ptr_null(w);
    w = (ws_world *)&d;
    ck_assert_int_eq(ws_world_create(NULL, &w), WS_ERR_INVALID_ARGUMENT);
    ck_assert_ptr_null(w);
    ws_world_def_init(&d);
    ck_assert_int_eq(ws_world_create(&d, NULL), WS_ERR_INVALID_ARGUMENT);
}
END_TEST

START_TEST(test_uninit_body_def)
{
    ws_world *w = new_world(2.5e-4);
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &s));
    ws_body_def d;
    ws_body_id b;
    memset(&d, 0xAB, sizeof d);
    ck_assert_int_eq(ws_body_create(w, &d, &b), WS_ERR_UNINITIALIZED_DEF);
    ck_err_has(w, "body");
    memset(&d, 0, sizeof d);
    d.shape = s; /* everything valid except the header */
    d.mass = 1.0;
    d.orientation.e0 = 1.0;
    ck_assert_int_eq(ws_body_create(w, &d, &b), WS_ERR_UNINITIALIZED_DEF);
    ck_assert_int_eq(ws_body_create(w, NULL, &b), WS_ERR_INVALID_ARGUMENT);
    ck_assert_str_ne(ws_world_last_error(w), "");
    ck_assert_uint_eq(body_count(w), 0);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_uninit_mesh_def)
{
    ws_world *w = new_world(2.5e-4);
    static const double v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const uint32_t t[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    ws_mesh_def d;
    ws_shape_id s;
    memset(&d, 0xAB, sizeof d);
    ck_assert_int_eq(ws_shape_create_mesh(w, &d, &s), WS_ERR_UNINITIALIZED_DEF);
    ck_err_has(w, "mesh");
    memset(&d, 0, sizeof d);
    d.vertices = v;
    d.vertex_count = 4;
    d.triangles = t;
    d.triangle_count = 4;
    ck_assert_int_eq(ws_shape_create_mesh(w, &d, &s), WS_ERR_UNINITIALIZED_DEF);
    ck_assert_int_eq(ws_shape_create_mesh(w, NULL, &s), WS_ERR_INVALID_ARGUMENT);
    /* The same mesh through an initialised Def is fine: the header was the only fault. */
    ws_mesh_def_init(&d);
    d.vertices = v;
    d.vertex_count = 4;
    d.triangles = t;
    d.triangle_count = 4;
    ck_ok(w, ws_shape_create_mesh(w, &d, &s));
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_uninit_contact_def)
{
    ws_world *w = new_world(2.5e-4);
    ws_material_id m;
    ck_ok(w, ws_world_get_default_material(w, &m));
    ws_contact_def d;
    memset(&d, 0xAB, sizeof d);
    ck_assert_int_eq(ws_world_set_contact(w, m, m, &d), WS_ERR_UNINITIALIZED_DEF);
    ck_err_has(w, "contact");
    ck_assert_int_eq(ws_world_set_default_contact(w, &d), WS_ERR_UNINITIALIZED_DEF);
    memset(&d, 0, sizeof d);
    d.stiffness = 1e5;
    d.friction_vlim = 0.01;
    d.stick_stiffness = 1e5;
    ck_assert_int_eq(ws_world_set_contact(w, m, m, &d), WS_ERR_UNINITIALIZED_DEF);
    ck_assert_int_eq(ws_world_set_default_contact(w, &d), WS_ERR_UNINITIALIZED_DEF);
    ck_assert_int_eq(ws_world_set_contact(w, m, m, NULL), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_world_set_default_contact(w, NULL), WS_ERR_INVALID_ARGUMENT);
    /* Nothing was stored: the pair still has the ws_contact_def_init() values. */
    ws_contact_def got, ref;
    ws_contact_def_init(&ref);
    ck_ok(w, ws_world_get_contact(w, m, m, &got));
    ck_assert_double_eq(got.stiffness, ref.stiffness);
    ck_assert_double_eq(got.friction, ref.friction);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_uninit_material_def)
{
    ws_world *w = new_world(2.5e-4);
    ws_material_def d;
    ws_material_id m;
    memset(&d, 0xAB, sizeof d);
    ck_assert_int_eq(ws_material_create(w, &d, &m), WS_ERR_UNINITIALIZED_DEF);
    ck_err_has(w, "material");
    memset(&d, 0, sizeof d);
    ck_assert_int_eq(ws_material_create(w, &d, &m), WS_ERR_UNINITIALIZED_DEF);
    ck_assert_int_eq(ws_material_create(w, NULL, &m), WS_ERR_INVALID_ARGUMENT);
    ws_material_def_init(&d);
    d.name = "rubber";
    ck_ok(w, ws_material_create(w, &d, &m));
    ck_assert_int_eq(ws_material_is_valid(w, m), 1);
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_uninit_drive_def)
{
    ws_world *w = new_world(2.5e-4);
    ws_body_id table = add_ground(w, 1.0, no_material());
    ws_drive_def d;
    memset(&d, 0xAB, sizeof d);
    ck_assert_int_eq(ws_body_set_drive(w, table, &d), WS_ERR_UNINITIALIZED_DEF);
    ck_err_has(w, "drive");
    memset(&d, 0, sizeof d);
    d.type = WS_DRIVE_TILT;
    d.axis.y = 1.0;
    d.rate = 0.1;
    ck_assert_int_eq(ws_body_set_drive(w, table, &d), WS_ERR_UNINITIALIZED_DEF);
    ck_assert_int_eq(ws_body_set_drive(w, table, NULL), WS_ERR_INVALID_ARGUMENT);
    /* The body did not move: its drive was never installed. */
    ws_quat q;
    ck_ok(w, ws_body_get_orientation(w, table, &q));
    ck_assert_double_eq(q.e0, 1.0);
    ws_world_destroy(w);
}
END_TEST

/* ---- bad numbers ---- */

START_TEST(test_bad_world_numbers)
{
    ws_world_def d;
    ws_world *w;
    const double bad_dt[] = {0.0, -1e-3, NAN, INFINITY};
    for (size_t k = 0; k < sizeof bad_dt / sizeof bad_dt[0]; k++) {
        ws_world_def_init(&d);
        d.dt = bad_dt[k];
        w = (ws_world *)&d;
        ck_assert_int_eq(ws_world_create(&d, &w), WS_ERR_INVALID_ARGUMENT);
        ck_assert_ptr_null(w);
    }
    ws_world_def_init(&d);
    d.gravity.y = NAN;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_ERR_INVALID_ARGUMENT);
    ck_assert_ptr_null(w);
    ws_world_def_init(&d);
    d.gravity.z = -INFINITY;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_ERR_INVALID_ARGUMENT);
    /* Without a world the status is the report; the NULL-world text is still a string. */
    ck_assert_ptr_nonnull(ws_world_last_error(NULL));

    /* Between steps: ws_world_set_dt and ws_world_set_gravity. */
    w = new_world(1e-3);
    ck_assert_int_eq(ws_world_set_dt(w, 0.0), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "dt");
    ck_assert_int_eq(ws_world_set_dt(w, -1e-3), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_world_set_dt(w, NAN), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "dt");
    double dt = 0;
    ck_ok(w, ws_world_get_dt(w, &dt));
    ck_assert_double_eq(dt, 1e-3); /* unchanged, bit for bit */
    ws_vec3 g = {0, NAN, -9.81};
    ck_assert_int_eq(ws_world_set_gravity(w, &g), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "gravity");
    ck_assert_int_eq(ws_world_set_gravity(w, NULL), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_world_step_n(w, -1), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "steps");
    ws_world_destroy(w);
}
END_TEST

/* Create a body from `d` and expect WS_ERR_INVALID_ARGUMENT with `word` and the body's name in the
 * last error, and no body created. */
static void expect_bad_body(ws_world *w, const ws_body_def *d, const char *word)
{
    ws_body_id b = {12345};
    ws_status s = ws_body_create(w, d, &b);
    ck_assert_msg(s == WS_ERR_INVALID_ARGUMENT, "expected WS_ERR_INVALID_ARGUMENT for '%s', got %s",
                  word, ws_status_string(s));
    ck_err_has(w, word);
    ck_err_has(w, d->name);
    ck_assert_int_eq(ws_body_is_valid(w, b), 0);
    ck_assert_uint_eq(body_count(w), 0);
}

START_TEST(test_bad_body_numbers)
{
    ws_world *w = new_world(2.5e-4);
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 0.2, 0.2, 0.2, &s));
    ws_body_def base;
    ws_body_def_init(&base);
    base.shape = s;
    base.mass = 2.0;
    base.name = "crate";
    ws_body_def d;

    d = base;
    d.mass = -1.0;
    expect_bad_body(w, &d, "mass");
    d = base;
    d.mass = NAN;
    expect_bad_body(w, &d, "mass");
    d = base;
    d.mass = INFINITY;
    expect_bad_body(w, &d, "mass");
    d = base;
    d.mass = 0.0;
    d.density = 0.0;
    expect_bad_body(w, &d, "density");
    d = base;
    d.mass = 0.0;
    d.density = -5.0;
    expect_bad_body(w, &d, "density");

    /* Inertia: not symmetric (off-diagonal 0.5 vs 0, far above any round-off tolerance). */
    d = base;
    d.inertia.m[0] = d.inertia.m[4] = d.inertia.m[8] = 1.0;
    d.inertia.m[1] = 0.5;
    expect_bad_body(w, &d, "inertia");
    /* Symmetric but indefinite: eigenvalues 3, -1, 1. */
    d = base;
    d.inertia.m[0] = d.inertia.m[4] = d.inertia.m[8] = 1.0;
    d.inertia.m[1] = d.inertia.m[3] = 2.0;
    expect_bad_body(w, &d, "inertia");
    /* Negative diagonal. */
    d = base;
    d.inertia.m[0] = d.inertia.m[4] = 1.0;
    d.inertia.m[8] = -1.0;
    expect_bad_body(w, &d, "inertia");
    /* NaN entry. */
    d = base;
    d.inertia.m[0] = d.inertia.m[4] = d.inertia.m[8] = 1.0;
    d.inertia.m[5] = NAN;
    expect_bad_body(w, &d, "inertia");

    d = base;
    d.orientation.e0 = d.orientation.e1 = d.orientation.e2 = d.orientation.e3 = 0.0;
    expect_bad_body(w, &d, "orientation");
    d = base;
    d.orientation.e2 = NAN;
    expect_bad_body(w, &d, "orientation");
    d = base;
    d.position.x = NAN;
    expect_bad_body(w, &d, "position");
    d = base;
    d.velocity.z = INFINITY;
    expect_bad_body(w, &d, "velocit");
    d = base;
    d.contact_layer = -1e-3;
    expect_bad_body(w, &d, "contact_layer");
    d = base;
    d.contact_layer = NAN;
    expect_bad_body(w, &d, "contact_layer");
    d = base;
    d.type = (ws_body_type)7;
    expect_bad_body(w, &d, "type");

    /* The base Def itself is good: the single changed field was the fault each time. */
    ws_body_id b;
    ck_ok(w, ws_body_create(w, &base, &b));
    ws_world_destroy(w);
}
END_TEST

static void expect_bad_contact(ws_world *w, const ws_contact_def *d, const char *word)
{
    ws_material_id m;
    ck_ok(w, ws_world_get_default_material(w, &m));
    ck_assert_int_eq(ws_world_set_contact(w, m, m, d), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, word);
    ck_assert_int_eq(ws_world_set_default_contact(w, d), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, word);
    /* Nothing stored. */
    ws_contact_def got, ref;
    ws_contact_def_init(&ref);
    ck_ok(w, ws_world_get_contact(w, m, m, &got));
    ck_assert_double_eq(got.stiffness, ref.stiffness);
    ck_assert_double_eq(got.friction, ref.friction);
    ck_assert_double_eq(got.friction_vlim, ref.friction_vlim);
}

START_TEST(test_bad_contact_numbers)
{
    ws_world *w = new_world(2.5e-4);
    ws_contact_def d;
    ws_contact_def_init(&d);
    d.stiffness = 0.0;
    expect_bad_contact(w, &d, "stiffness");
    ws_contact_def_init(&d);
    d.stiffness = -1e5;
    expect_bad_contact(w, &d, "stiffness");
    ws_contact_def_init(&d);
    d.stiffness = NAN;
    expect_bad_contact(w, &d, "stiffness");
    ws_contact_def_init(&d);
    d.friction_vlim = 0.0;
    expect_bad_contact(w, &d, "vlim");
    ws_contact_def_init(&d);
    d.friction_vlim = -0.01;
    expect_bad_contact(w, &d, "vlim");
    ws_contact_def_init(&d);
    d.friction = -0.1;
    expect_bad_contact(w, &d, "friction");
    ws_contact_def_init(&d);
    d.damping = -1.0;
    expect_bad_contact(w, &d, "damping");
    ws_world_destroy(w);
}
END_TEST

static int never_called(void *user, double t, ws_pose *pose, ws_vec3 *v, ws_vec3 *om)
{
    (void)user, (void)t, (void)pose, (void)v, (void)om;
    return 0;
}

START_TEST(test_bad_drive_numbers)
{
    ws_world *w = new_world(2.5e-4);
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 1, 1, 0.05, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = s;
    bd.name = "table";
    ws_body_id table;
    ck_ok(w, ws_body_create(w, &bd, &table));
    ws_body_id crate = box_at(w, 0.2, 1.0, 0, 0, 1, "crate");

    ws_drive_def d;
    ws_drive_def_init(&d);
    d.type = WS_DRIVE_TILT;
    d.rate = 0.1;
    d.axis.x = d.axis.y = d.axis.z = 0.0;
    ck_assert_int_eq(ws_body_set_drive(w, table, &d), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "axis");
    ck_err_has(w, "table");
    ws_drive_def_init(&d);
    d.type = WS_DRIVE_TILT;
    d.axis.y = NAN;
    ck_assert_int_eq(ws_body_set_drive(w, table, &d), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "axis");
    ws_drive_def_init(&d);
    d.type = (ws_drive_type)42;
    ck_assert_int_eq(ws_body_set_drive(w, table, &d), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "type");
    ck_err_has(w, "table");
    ws_drive_def_init(&d);
    d.type = WS_DRIVE_TILT;
    d.ramp_time = -0.1;
    ck_assert_int_eq(ws_body_set_drive(w, table, &d), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "ramp_time");
    ws_drive_def_init(&d);
    d.type = WS_DRIVE_CALLBACK; /* no callback */
    ck_assert_int_eq(ws_body_set_drive(w, table, &d), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "callback");
    ws_drive_def_init(&d);
    d.type = WS_DRIVE_SINE;
    d.frequency = -1.0;
    ck_assert_int_eq(ws_body_set_drive(w, table, &d), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "frequency");

    /* A tilt drive on a dynamic body. */
    ws_drive_def_init(&d);
    d.type = WS_DRIVE_TILT;
    d.rate = 0.1;
    ck_assert_int_eq(ws_body_set_drive(w, crate, &d), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "kinematic");
    ck_err_has(w, "crate");
    d.type = WS_DRIVE_CALLBACK;
    d.callback = never_called;
    ck_assert_int_eq(ws_body_set_drive(w, crate, &d), WS_ERR_INVALID_ARGUMENT);

    /* None of it moved the table; a good drive is accepted. */
    ws_quat q;
    ck_ok(w, ws_body_get_orientation(w, table, &q));
    ck_assert_double_eq(q.e0, 1.0);
    ws_drive_def_init(&d);
    d.type = WS_DRIVE_TILT;
    d.rate = 0.1;
    ck_ok(w, ws_body_set_drive(w, table, &d));
    ws_world_destroy(w);
}
END_TEST

/* ---- allocation failure ---- */

/* Upper bound on the allocations any single call below makes: the loops must reach success well
 * before it, or the library allocates without bound. */
#define MAX_ALLOCS 2000

static ws_world *counted_world(test_alloc *a)
{
    ws_world_def d;
    ws_world_def_init(&d);
    test_alloc_install(&d, a);
    ws_world *w = NULL;
    a->allocs_left = -1;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    return w;
}

static void expect_all_freed(const test_alloc *a, const char *what, long n)
{
    ck_assert_msg(a->live == 0 && a->bytes == 0, "%s, N = %ld: %ld blocks and %lld bytes left",
                  what, n, a->live, a->bytes);
}

START_TEST(test_oom_world_create)
{
    long n;
    int done = 0;
    for (n = 0; n < MAX_ALLOCS && !done; n++) {
        test_alloc a = {.allocs_left = n};
        ws_world_def d;
        ws_world_def_init(&d);
        test_alloc_install(&d, &a);
        ws_world *w = (ws_world *)&d;
        ws_status s = ws_world_create(&d, &w);
        if (s == WS_OK) {
            ck_assert_ptr_nonnull(w);
            ws_world_destroy(w);
            done = 1;
        } else {
            ck_assert_msg(s == WS_ERR_OUT_OF_MEMORY, "N = %ld: %s", n, ws_status_string(s));
            ck_assert_ptr_null(w);
        }
        expect_all_freed(&a, "ws_world_create", n);
    }
    ck_assert_msg(done, "ws_world_create never succeeded");
    ck_assert_int_gt(n, 1); /* at least one allocation failed on the way */
}
END_TEST

static ws_status make_mesh_shape(ws_world *w, ws_shape_id *out)
{
    /* A unit cube given as a mesh. */
    static const double v[24] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0,
                                 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
    static const uint32_t t[36] = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                                   2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
    ws_mesh_def d;
    ws_mesh_def_init(&d);
    d.vertices = v;
    d.vertex_count = 8;
    d.triangles = t;
    d.triangle_count = 12;
    return ws_shape_create_mesh(w, &d, out);
}

/* Shape creation of each kind under every failure point. */
START_TEST(test_oom_shape_create)
{
    for (int kind = 0; kind < 3; kind++) {
        int done = 0;
        for (long n = 0; n < MAX_ALLOCS && !done; n++) {
            test_alloc a = {.allocs_left = -1};
            ws_world *w = counted_world(&a);
            a.allocs_left = n;
            ws_shape_id s = {777};
            ws_status st = kind == 0   ? ws_shape_create_box(w, 1, 2, 3, &s)
                           : kind == 1 ? ws_shape_create_cylinder(w, 0.5, 1, 32, &s)
                                       : make_mesh_shape(w, &s);
            a.allocs_left = -1;
            if (st == WS_OK) {
                ck_assert_int_eq(ws_shape_is_valid(w, s), 1);
                done = 1;
            } else {
                ck_assert_msg(st == WS_ERR_OUT_OF_MEMORY, "kind %d, N = %ld: %s (%s)", kind, n,
                              ws_status_string(st), ws_world_last_error(w));
                ck_assert_int_eq(ws_shape_is_valid(w, s), 0);
                /* The world still works and can still make (and use) a shape. */
                ws_shape_id s2;
                ck_ok(w, ws_shape_create_box(w, 1, 1, 1, &s2));
                ws_body_def bd;
                ws_body_def_init(&bd);
                bd.shape = s2;
                ws_body_id b;
                ck_ok(w, ws_body_create(w, &bd, &b));
                ck_ok(w, ws_world_step(w));
            }
            ws_world_destroy(w);
            expect_all_freed(&a, kind == 0 ? "box" : kind == 1 ? "cylinder" : "mesh", n);
        }
        ck_assert_msg(done, "shape kind %d never succeeded", kind);
    }
}
END_TEST

START_TEST(test_oom_body_create)
{
    /* With and without a name (the name is copied: one more allocation), and a second body into a
     * store that already holds one. */
    for (int variant = 0; variant < 3; variant++) {
        int done = 0;
        for (long n = 0; n < MAX_ALLOCS && !done; n++) {
            test_alloc a = {.allocs_left = -1};
            ws_world *w = counted_world(&a);
            ws_shape_id s;
            ck_ok(w, ws_shape_create_box(w, 0.2, 0.2, 0.2, &s));
            ws_body_def bd;
            ws_body_def_init(&bd);
            bd.shape = s;
            bd.name = variant == 1 ? "a body with a name" : NULL;
            size_t before = 0;
            if (variant == 2) {
                for (int k = 0; k < 4; k++) { /* fill the first block of the store */
                    ws_body_id first;
                    bd.position.x = 1.0 + k;
                    ck_ok(w, ws_body_create(w, &bd, &first));
                }
                bd.position.x = 0.0;
                before = 4;
            }
            uint64_t h0 = hash_of(w);
            a.allocs_left = n;
            ws_body_id b = {777};
            ws_status st = ws_body_create(w, &bd, &b);
            a.allocs_left = -1;
            if (st == WS_OK) {
                ck_assert_int_eq(ws_body_is_valid(w, b), 1);
                ck_assert_uint_eq(body_count(w), before + 1);
                done = 1;
            } else {
                ck_assert_msg(st == WS_ERR_OUT_OF_MEMORY, "variant %d, N = %ld: %s (%s)", variant,
                              n, ws_status_string(st), ws_world_last_error(w));
                ck_assert_int_eq(ws_body_is_valid(w, b), 0);
                ck_assert_uint_eq(body_count(w), before);
                ck_assert(hash_of(w) == h0);
                /* Still usable. */
                ck_ok(w, ws_body_create(w, &bd, &b));
                ck_assert_uint_eq(body_count(w), before + 1);
                ck_ok(w, ws_world_step(w));
            }
            ws_world_destroy(w);
            expect_all_freed(&a, "ws_body_create", n);
        }
        ck_assert_msg(done, "body variant %d never succeeded", variant);
    }
}
END_TEST

/* A 1 kg box of 0.2 m resting on the ground (bottom face inside the contact layers). */
static ws_body_id box_on_ground(ws_world *w)
{
    add_ground(w, 1.0, no_material());
    return box_at(w, 0.2, 1.0, 0.0, 0.0, 0.1 + 1.99e-3, "box");
}

START_TEST(test_oom_step)
{
    int done = 0;
    for (long n = 0; n < MAX_ALLOCS && !done; n++) {
        test_alloc a = {.allocs_left = -1};
        ws_world *w = counted_world(&a);
        box_on_ground(w);
        uint64_t h0 = hash_of(w);
        a.allocs_left = n;
        ws_status st = ws_world_step(w);
        a.allocs_left = -1;
        if (st == WS_OK) {
            ck_assert(time_of(w) > 0.0);
            done = 1;
        } else {
            ck_assert_msg(st == WS_ERR_OUT_OF_MEMORY, "N = %ld: %s (%s)", n, ws_status_string(st),
                          ws_world_last_error(w));
            ck_assert(hash_of(w) == h0);
            ck_assert_double_eq(time_of(w), 0.0);
            ck_err_has(w, "memory");
            /* Nothing lost: the step works once memory is back. */
            ck_ok(w, ws_world_step_n(w, 10));
            size_t nc = 0;
            ck_ok(w, ws_world_get_contact_count(w, &nc));
            ck_assert_uint_eq(nc, 4);
        }
        ws_world_destroy(w);
        expect_all_freed(&a, "ws_world_step", n);
    }
    ck_assert_msg(done, "ws_world_step never succeeded");
}
END_TEST

/* STYLE rule 9: once warm, a step allocates nothing. */
START_TEST(test_warm_step_allocates_nothing)
{
    test_alloc a = {.allocs_left = -1};
    ws_world *w = counted_world(&a);
    box_on_ground(w);
    box_at(w, 0.1, 0.5, 0.0, 0.0, 0.2 + 0.05 + 2 * 1.99e-3, "top");
    ck_ok(w, ws_world_step_n(w, 100));
    a.allocs_left = 0;
    long live = a.live;
    ck_ok(w, ws_world_step_n(w, 1000));
    ck_assert_int_eq(a.live, live);
    a.allocs_left = -1;
    ws_world_destroy(w);
    expect_all_freed(&a, "warm steps", 0);
}
END_TEST

/* ---- bytes back to zero ---- */

START_TEST(test_bytes_back_to_zero)
{
    test_alloc a = {.allocs_left = -1};
    ws_world *w = counted_world(&a);
    ws_world_stats st;
    ck_ok(w, ws_world_get_stats(w, &st));
    ck_assert_uint_gt(st.bytes_in_use, 0);
    ck_assert(st.bytes_in_use == (uint64_t)a.bytes); /* the world counts what the hook saw */

    add_ground(w, 3.0, no_material());
    box_at(w, 0.2, 1.0, 0.0, 0.0, 0.1 + 1.99e-3, "low");
    box_at(w, 0.1, 0.5, 0.0, 0.0, 0.2 + 0.05 + 2 * 1.99e-3, "high");
    ws_shape_id m;
    ck_ok(w, make_mesh_shape(w, &m));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = m;
    bd.mass = 2.0;
    bd.position.x = 1.5; /* the unit cube is re-centred on its centroid */
    bd.position.z = 0.5 + 1.99e-3;
    bd.name = "mesh cube";
    ws_body_id mb;
    ck_ok(w, ws_body_create(w, &bd, &mb));
    ck_ok(w, ws_world_step_n(w, 2000));

    ck_ok(w, ws_world_get_stats(w, &st));
    ck_assert_uint_gt(st.bytes_in_use, 0);
    ck_assert(st.bytes_in_use == (uint64_t)a.bytes);
    ck_assert_uint_ge(st.bytes_peak, st.bytes_in_use);
    ck_assert_uint_eq(st.bodies, 4);
    ck_assert_uint_gt(st.contacts, 0); /* the scene touched: contact arrays were in use */

    ws_body_id ids[8];
    size_t n = 0;
    ck_ok(w, ws_world_copy_body_ids(w, ids, 8, &n));
    ck_assert_uint_eq(n, 4);
    for (size_t k = 0; k < n; k++)
        ck_ok(w, ws_body_destroy(w, ids[k]));
    ck_ok(w, ws_world_get_stats(w, &st));
    ck_assert_uint_eq(st.bodies, 0);
    ck_assert_uint_eq(st.contacts, 0);
    ck_ok(w, ws_shape_destroy(w, m));
    ck_assert(st.bytes_in_use > 0);
    ws_world_destroy(w);
    expect_all_freed(&a, "scene", 0);
}
END_TEST

/* ---- determinism ---- */

/* Ground, a 1 kg 0.2 m box sliding at vx and a 0.5 kg 0.1 m box on top of it: three contact
 * pairs, friction active from the first step. Returns the hash after `steps`. */
static uint64_t stacked_hash(double vx, int use_ccd, int steps, double *vx_end)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.use_ccd = use_ccd;
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    add_ground(w, 2.0, no_material());
    ws_shape_id s1, s2;
    ck_ok(w, ws_shape_create_box(w, 0.2, 0.2, 0.2, &s1));
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &s2));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = s1;
    bd.mass = 1.0;
    bd.position.z = 0.1 + 1.99e-3;
    bd.velocity.x = vx;
    bd.name = "bottom";
    ws_body_id low, high;
    ck_ok(w, ws_body_create(w, &bd, &low));
    bd.shape = s2;
    bd.mass = 0.5;
    bd.position.x = 0.03; /* off-centre: the top box also tips the bottom one a little */
    bd.position.z = 0.2 + 0.05 + 2 * 1.99e-3;
    bd.velocity.x = 0.0;
    bd.name = "top";
    ck_ok(w, ws_body_create(w, &bd, &high));
    ck_ok(w, ws_world_step_n(w, steps));
    ws_vec3 v;
    ck_ok(w, ws_body_get_velocity(w, low, &v));
    if (vx_end)
        *vx_end = v.x;
    uint64_t h = hash_of(w);
    ws_world_destroy(w);
    return h;
}

START_TEST(test_determinism_hash)
{
    const double vx = 0.3;
    double vend = 0;
    uint64_t h1 = stacked_hash(vx, 1, 3000, &vend);
    uint64_t h2 = stacked_hash(vx, 1, 3000, NULL);
    ck_assert_msg(h1 == h2, "identical worlds: %016llx vs %016llx", (unsigned long long)h1,
                  (unsigned long long)h2);
    /* Friction really acted: mu g = 2.9 m/s^2 stops 0.3 m/s within about 0.1 s of the 0.75 s. */
    ck_assert_msg(fabs(vend) < 0.5 * vx, "bottom box still at %g m/s", vend);
    /* A change of 1e-12 m/s (about 1e4 ulp of 0.3) must show in the hash. */
    uint64_t h3 = stacked_hash(vx + 1e-12, 1, 3000, NULL);
    ck_assert(h3 != h1);
    if (ws_build_features() & WS_FEATURE_CCD) {
        /* The libccd gate only skips pairs that cannot touch: the result is bit-identical. */
        uint64_t h0 = stacked_hash(vx, 0, 3000, NULL);
        ck_assert_msg(h0 == h1, "use_ccd 0 vs 1: %016llx vs %016llx", (unsigned long long)h0,
                      (unsigned long long)h1);
    }
}
END_TEST

/* ---- a failed step changes nothing ---- */

START_TEST(test_failed_step_numerical)
{
    ws_world *w = new_world(1e-5);
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 1e7;
    ck_ok(w, ws_world_set_default_contact(w, &cd));
    add_ground(w, 1.0, no_material());
    /* 0.01 kg on 4 springs of 1e7 N/m: omega = sqrt(4e7 / 0.01) = 6.3e4 rad/s, so dt = 1e-5 is
     * stable (omega dt = 0.63 < 2) and dt = 0.05 is 1600 times past the limit. */
    /* Bottom face 1.9e-3 above the ground: overlap 1e-4 m, 4000 N on 0.01 kg. One small step
     * (a fifth of a quarter period) keeps it pressed in, so the big step gives v ~ 4e5 * 0.05 m/s,
     * far above max_speed = 1000 m/s. */
    ws_body_id light = box_at(w, 0.05, 0.01, 0.0, 0.0, 0.025 + 1.9e-3, "light");
    ck_ok(w, ws_world_step(w));
    size_t nc = 0;
    ck_ok(w, ws_world_get_contact_count(w, &nc));
    ck_assert_uint_eq(nc, 4); /* still in contact */
    ck_ok(w, ws_world_set_dt(w, 0.05));
    ws_world_stats before, after;
    ck_ok(w, ws_world_get_stats(w, &before));
    uint64_t h0 = hash_of(w);
    double t0 = time_of(w);
    ws_vec3 p0, p1;
    ck_ok(w, ws_body_get_position(w, light, &p0));
    ws_status s = ws_world_step(w);
    ck_assert_msg(s == WS_ERR_NUMERICAL, "got %s", ws_status_string(s));
    ck_assert(hash_of(w) == h0);
    ck_assert_double_eq(time_of(w), t0);
    ck_ok(w, ws_body_get_position(w, light, &p1));
    ck_assert(memcmp(&p0, &p1, sizeof p0) == 0);
    ck_ok(w, ws_world_get_stats(w, &after));
    ck_assert_uint_eq(after.numerical_errors, before.numerical_errors + 1);
    ck_assert_uint_eq(after.steps, before.steps);
    ck_assert_uint_eq(after.contacts, before.contacts);
    ck_err_has(w, "light");
    ck_err_has(w, "dt");
    /* Same failure again, same unchanged world; then a small dt goes on from where it was. */
    ck_assert_int_eq(ws_world_step(w), WS_ERR_NUMERICAL);
    ck_assert(hash_of(w) == h0);
    ck_ok(w, ws_world_get_stats(w, &after));
    ck_assert_uint_eq(after.numerical_errors, before.numerical_errors + 2);
    ck_ok(w, ws_world_set_dt(w, 1e-5));
    ck_ok(w, ws_world_step(w));
    ck_assert_double_eq_tol(time_of(w), t0 + 1e-5, 1e-15); /* one addition: a few ulp of t0 */
    ws_world_destroy(w);
}
END_TEST

typedef struct cb_state {
    double fail_after; /* s */
    int calls;
} cb_state;

static int failing_drive(void *user, double t, ws_pose *pose, ws_vec3 *v, ws_vec3 *om)
{
    cb_state *c = user;
    c->calls++;
    (void)v, (void)om;
    pose->position.z = -0.025; /* stays put */
    return t > c->fail_after ? 1 : 0;
}

START_TEST(test_failed_step_callback)
{
    ws_world *w = new_world(2.5e-4);
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 2, 2, 0.05, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = s;
    bd.position.z = -0.025;
    bd.name = "shaker";
    ws_body_id shaker;
    ck_ok(w, ws_body_create(w, &bd, &shaker));
    box_at(w, 0.2, 1.0, 0.0, 0.0, 0.1 + 1.99e-3, "box");
    cb_state cs = {0.01, 0};
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    dd.type = WS_DRIVE_CALLBACK;
    dd.callback = failing_drive;
    dd.callback_user = &cs;
    ck_ok(w, ws_body_set_drive(w, shaker, &dd));
    /* 40 steps reach t = 0.01 exactly or just below; the callback fails for t > 0.01. */
    ws_status s1 = WS_OK;
    int k;
    for (k = 0; k < 100 && s1 == WS_OK; k++) {
        uint64_t h0 = hash_of(w);
        double t0 = time_of(w);
        ws_world_stats before, after;
        ck_ok(w, ws_world_get_stats(w, &before));
        s1 = ws_world_step(w);
        if (s1 != WS_OK) {
            ck_assert_msg(s1 == WS_ERR_CALLBACK, "got %s", ws_status_string(s1));
            ck_assert(t0 + 2.5e-4 > 0.01); /* it failed when it should, not before */
            ck_assert(hash_of(w) == h0);
            ck_assert_double_eq(time_of(w), t0);
            ck_ok(w, ws_world_get_stats(w, &after));
            ck_assert_uint_eq(after.steps, before.steps);
            ck_assert_uint_eq(after.numerical_errors, before.numerical_errors);
            ck_err_has(w, "shaker");
            ck_err_has(w, "drive");
            ck_err_has(w, "callback");
        }
    }
    ck_assert_int_eq(s1, WS_ERR_CALLBACK);
    ck_assert_int_ge(k, 40);
    ws_world_destroy(w);
}
END_TEST

/* ---- bulk copies ---- */

START_TEST(test_copy_contacts)
{
    ws_world *w = new_world(2.5e-4);
    ws_body_id ground = add_ground(w, 1.0, no_material());
    const double m = 1.0;
    ws_body_id box = box_at(w, 0.2, m, 0.0, 0.0, 0.1 + 1.99e-3, "box");
    /* 4 springs of 2e5 N/m with 10 kg/s each on 1 kg: the bounce decays at zeta omega = 20 /s
     * (the slowest mode seen decays at about 12 /s), so after 2 s the force sum equals m g to
     * ~1e-12. 1e-6 relative leaves wide margin yet catches a lost contact (25 %) or a force
     * that is not balanced. */
    ck_ok(w, ws_world_step_n(w, 8000));
    size_t n = 99;
    ck_assert_int_eq(ws_world_copy_contacts(w, NULL, 0, &n), WS_OK);
    ck_assert_uint_eq(n, 4); /* the 4 bottom corners in the ground's top face */
    size_t nc = 0;
    ck_ok(w, ws_world_get_contact_count(w, &nc));
    ck_assert_uint_eq(nc, n);

    ws_contact_info c[8];
    memset(c, 0, sizeof c);
    size_t got = 0;
    ck_assert_int_eq(ws_world_copy_contacts(w, c, 2, &got), WS_ERR_BUFFER_TOO_SMALL);
    ck_assert_uint_eq(got, 4);
    ck_err_has(w, "4");
    ck_assert(c[0].body_b.bits == box.bits && c[1].body_b.bits == box.bits);
    ck_assert_uint_eq(c[2].body_b.bits, 0); /* nothing written past the capacity */
    ck_assert_int_eq(ws_world_copy_contacts(w, c, 8, &got), WS_OK);
    ck_assert_uint_eq(got, 4);
    ck_assert_int_eq(ws_world_copy_contacts(w, NULL, 3, &got), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_world_copy_contacts(w, c, 8, NULL), WS_ERR_INVALID_ARGUMENT);

    double fsum = 0.0;
    for (size_t k = 0; k < 4; k++) {
        ck_assert(c[k].body_a.bits == ground.bits);
        ck_assert(c[k].body_b.bits == box.bits);
        /* The ground's top face normal is computed from exact +-1 coordinates: round-off only. */
        ck_assert_double_eq_tol(c[k].normal.x, 0.0, 1e-12);
        ck_assert_double_eq_tol(c[k].normal.y, 0.0, 1e-12);
        ck_assert_double_eq_tol(c[k].normal.z, 1.0, 1e-12);
        ck_assert(c[k].overlap > 0.0);
        ck_assert(c[k].normal_force > 0.0);
        ck_assert_int_eq(c[k].kind, WS_CONTACT_POINT_FACE);
        /* Each contact sits under a bottom corner (+-0.1, +-0.1) of the box; it may creep by much
         * less than a millimetre. */
        ck_assert_double_eq_tol(fabs(c[k].point.x), 0.1, 1e-3);
        ck_assert_double_eq_tol(fabs(c[k].point.y), 0.1, 1e-3);
        fsum += c[k].normal_force;
    }
    ck_assert_msg(fabs(fsum - m * G0) <= 1e-6 * m * G0, "sum of normal forces %.12g vs m g %.12g",
                  fsum, m * G0);
    /* The body's total contact force agrees with the records. */
    ws_vec3 F, M;
    ck_ok(w, ws_body_get_contact_force(w, box, &F, &M));
    ck_assert_double_eq_tol(F.z, fsum, 1e-9 * fsum); /* same 4 forces, another order of sum */
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_copy_body_ids)
{
    ws_world *w = new_world(2.5e-4);
    ws_body_id b[5];
    for (int k = 0; k < 5; k++)
        b[k] = box_at(w, 0.1, 1.0, k, 0, 1, NULL);
    ck_ok(w, ws_body_destroy(w, b[1]));
    size_t n = 99;
    ck_assert_int_eq(ws_world_copy_body_ids(w, NULL, 0, &n), WS_OK);
    ck_assert_uint_eq(n, 4);
    ws_body_id buf[8];
    memset(buf, 0, sizeof buf);
    ck_assert_int_eq(ws_world_copy_body_ids(w, buf, 2, &n), WS_ERR_BUFFER_TOO_SMALL);
    ck_assert_uint_eq(n, 4);
    ck_assert_uint_eq(buf[2].bits, 0); /* nothing past the capacity */
    ck_assert(buf[0].bits == b[0].bits);
    ck_assert(buf[1].bits == b[2].bits); /* creation order, the destroyed one skipped */
    ck_assert_int_eq(ws_world_copy_body_ids(w, buf, 8, &n), WS_OK);
    ck_assert_uint_eq(n, 4);
    ck_assert(buf[0].bits == b[0].bits && buf[1].bits == b[2].bits && buf[2].bits == b[3].bits &&
              buf[3].bits == b[4].bits);
    ck_assert_int_eq(ws_world_copy_body_ids(w, NULL, 4, &n), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_world_copy_body_ids(w, buf, 8, NULL), WS_ERR_INVALID_ARGUMENT);
    ws_world_destroy(w);
}
END_TEST

/* ---- version and features ---- */

START_TEST(test_version_and_status_strings)
{
    ck_assert_int_eq(ws_version_number(), WS_VERSION_NUMBER);
    ck_assert_ptr_nonnull(ws_version_string());
    ck_assert_str_eq(ws_version_string(), WS_VERSION_STRING);
    /* The number is major*10000 + minor*100 + patch of the string. */
    int ma = -1, mi = -1, pa = -1;
    ck_assert_int_eq(sscanf(ws_version_string(), "%d.%d.%d", &ma, &mi, &pa), 3);
    ck_assert_int_eq(ws_version_number(), ma * 10000 + mi * 100 + pa);
    ck_assert_uint_eq(ws_build_features() & ~(unsigned)(WS_FEATURE_CCD | WS_FEATURE_ZLIB), 0);

    const ws_status all[] = {WS_OK,
                             WS_ERR_INVALID_ARGUMENT,
                             WS_ERR_UNINITIALIZED_DEF,
                             WS_ERR_STALE_HANDLE,
                             WS_ERR_OUT_OF_MEMORY,
                             WS_ERR_NUMERICAL,
                             WS_ERR_BAD_MESH,
                             WS_ERR_IN_USE,
                             WS_ERR_CALLBACK,
                             WS_ERR_BUFFER_TOO_SMALL,
                             WS_ERR_IO,
                             WS_ERR_UNSUPPORTED,
                             WS_ERR_IN_STEP,
                             WS_ERR_FORMAT};
    const size_t n = sizeof all / sizeof all[0];
    for (size_t i = 0; i < n; i++) {
        const char *si = ws_status_string(all[i]);
        ck_assert_ptr_nonnull(si);
        ck_assert_uint_gt(strlen(si), 0);
        for (size_t j = 0; j < i; j++)
            ck_assert_str_ne(si, ws_status_string(all[j]));
    }
    ck_assert_ptr_nonnull(ws_status_string((ws_status)1000));
    ck_assert_ptr_nonnull(ws_status_string((ws_status)-1));
}
END_TEST

/* ---- log hook ---- */

typedef struct log_rec {
    int errors, others;
    ws_log_level last_level;
    char last[1024];
    void *self;
} log_rec;

static void log_fn(void *user, ws_log_level level, const char *msg)
{
    log_rec *r = user;
    r->self = user;
    if (level == WS_LOG_ERROR)
        r->errors++;
    else
        r->others++;
    r->last_level = level;
    snprintf(r->last, sizeof r->last, "%s", msg ? msg : "(null)");
}

START_TEST(test_log_hook)
{
    log_rec r;
    memset(&r, 0, sizeof r);
    ws_world_def d;
    ws_world_def_init(&d);
    d.log = log_fn;
    d.log_user = &r;
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    ck_assert_int_eq(r.errors, 0);
    ck_assert_int_eq(ws_world_set_dt(w, 0.0), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(r.errors, 1);
    ck_assert_int_eq(r.last_level, WS_LOG_ERROR);
    ck_assert_ptr_eq(r.self, &r);
    ck_assert_str_eq(r.last, ws_world_last_error(w));
    ck_assert_ptr_nonnull(strstr(r.last, "dt"));

    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = s;
    bd.mass = -3.0;
    bd.name = "heavy";
    ws_body_id b;
    ck_assert_int_eq(ws_body_create(w, &bd, &b), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_ge(r.errors, 2);
    ck_assert_int_eq(r.last_level, WS_LOG_ERROR);
    ck_assert_ptr_nonnull(strstr(r.last, "heavy"));
    ck_assert_ptr_nonnull(strstr(r.last, "mass"));
    ws_world_destroy(w);
}
END_TEST

/* ---- shape lifetime ---- */

START_TEST(test_shape_in_use)
{
    ws_world *w = new_world(2.5e-4);
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = s;
    ws_body_id b1, b2;
    ck_ok(w, ws_body_create(w, &bd, &b1));
    bd.position.x = 1.0;
    ck_ok(w, ws_body_create(w, &bd, &b2));
    ck_assert_int_eq(ws_shape_destroy(w, s), WS_ERR_IN_USE);
    ck_assert_str_ne(ws_world_last_error(w), "");
    ck_assert_int_eq(ws_shape_is_valid(w, s), 1);
    ck_ok(w, ws_body_destroy(w, b1));
    ck_assert_int_eq(ws_shape_destroy(w, s), WS_ERR_IN_USE); /* b2 still uses it */
    ck_ok(w, ws_world_step(w));
    ck_ok(w, ws_body_destroy(w, b2));
    ck_ok(w, ws_shape_destroy(w, s));
    ck_assert_int_eq(ws_shape_is_valid(w, s), 0);
    ck_assert_int_eq(ws_shape_destroy(w, s), WS_ERR_STALE_HANDLE);
    ws_world_destroy(w);
}
END_TEST

/* ---- tilt drive ---- */

START_TEST(test_tilt_drive_kinematics)
{
    ws_world *w = new_world(1e-3);
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 1.0, 1.0, 0.05, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = s;
    bd.position.x = 0.3;
    bd.position.z = 0.2;
    bd.name = "table";
    ws_body_id table;
    ck_ok(w, ws_body_create(w, &bd, &table));
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    dd.type = WS_DRIVE_TILT;
    const double rate = 0.4, start = 0.1, ramp = 0.05;
    const ws_vec3 u = {0.0, 0.6, 0.8}; /* unit */
    const ws_vec3 p = {-0.5, 0.0, 0.0};
    dd.axis.x = 0.0, dd.axis.y = 3.0, dd.axis.z = 4.0; /* normalised by the library */
    dd.point = p;
    dd.rate = rate;
    dd.start_time = start;
    dd.ramp_time = ramp;
    ck_ok(w, ws_body_set_drive(w, table, &dd));
    /* t = 0.5 s: the ramp (centred on start, +-ramp/2) is long over. */
    ck_ok(w, ws_world_step_n(w, 500));
    double t = time_of(w);
    ck_assert_double_eq_tol(t, 0.5, 1e-12); /* 500 additions of 1e-3: ~1e-14 of round-off */
    double th = rate * (t - start);
    ws_quat q;
    ck_ok(w, ws_body_get_orientation(w, table, &q));
    /* The pose is a closed-form function of t, not an integral: round-off only, hence 1e-12. */
    ck_assert_double_eq_tol(q.e0, cos(0.5 * th), 1e-12);
    ck_assert_double_eq_tol(q.e1, u.x * sin(0.5 * th), 1e-12);
    ck_assert_double_eq_tol(q.e2, u.y * sin(0.5 * th), 1e-12);
    ck_assert_double_eq_tol(q.e3, u.z * sin(0.5 * th), 1e-12);
    ws_vec3 om;
    ck_ok(w, ws_body_get_angular_velocity(w, table, &om));
    ck_assert_double_eq_tol(om.x, rate * u.x, 1e-12);
    ck_assert_double_eq_tol(om.y, rate * u.y, 1e-12);
    ck_assert_double_eq_tol(om.z, rate * u.z, 1e-12);
    /* The CoG turns about the axis through p (Rodrigues). */
    ws_vec3 r0 = {0.3 - p.x, 0.0 - p.y, 0.2 - p.z};
    double c = cos(th), sn = sin(th), ud = u.x * r0.x + u.y * r0.y + u.z * r0.z;
    ws_vec3 uxr = {u.y * r0.z - u.z * r0.y, u.z * r0.x - u.x * r0.z, u.x * r0.y - u.y * r0.x};
    ws_vec3 want = {p.x + r0.x * c + uxr.x * sn + u.x * ud * (1 - c),
                    p.y + r0.y * c + uxr.y * sn + u.y * ud * (1 - c),
                    p.z + r0.z * c + uxr.z * sn + u.z * ud * (1 - c)};
    ws_vec3 pos;
    ck_ok(w, ws_body_get_position(w, table, &pos));
    ck_assert_double_eq_tol(pos.x, want.x, 1e-12);
    ck_assert_double_eq_tol(pos.y, want.y, 1e-12);
    ck_assert_double_eq_tol(pos.z, want.z, 1e-12);
    ws_world_destroy(w);

    /* Before the ramp the table has not moved at all. */
    w = new_world(1e-3);
    ck_ok(w, ws_shape_create_box(w, 1.0, 1.0, 0.05, &s));
    bd.shape = s;
    ck_ok(w, ws_body_create(w, &bd, &table));
    ck_ok(w, ws_body_set_drive(w, table, &dd));
    ck_ok(w, ws_world_step_n(w, 50)); /* t = 0.05 < start - ramp/2 */
    ck_ok(w, ws_body_get_orientation(w, table, &q));
    ck_assert_double_eq(q.e0, 1.0);
    ck_ok(w, ws_body_get_angular_velocity(w, table, &om));
    ck_assert_double_eq(om.x * om.x + om.y * om.y + om.z * om.z, 0.0);
    ws_world_destroy(w);
}
END_TEST

/* ---- the Def ABI: a program built against an older, smaller Def ---- */

/* ws_body_def as an older header might have laid it out: today's fields up to `velocity`, none
 * after (angular_velocity, name, user_data came later). */
typedef struct old_body_def {
    uint32_t size, magic;
    ws_body_type type;
    ws_shape_id shape;
    ws_material_id material;
    double mass, density;
    ws_mat3 inertia;
    double contact_layer;
    ws_vec3 position;
    ws_quat orientation;
    ws_vec3 velocity;
} old_body_def;

/* The same for ws_world_def, cut before its last field (user_data). */
typedef struct old_world_def {
    uint32_t size, magic;
    ws_vec3 gravity;
    double dt;
    ws_integrator integrator;
    double full_detection_until;
    int detection_interval;
    double contact_margin, max_speed, max_angular_speed;
    int use_ccd, profile;
    ws_allocator allocator;
    ws_log_fn log;
    void *log_user;
} old_world_def;

#define CANARY 0xA5

static int canary_intact(const unsigned char *c, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (c[i] != CANARY)
            return 0;
    return 1;
}

START_TEST(test_old_size_defs)
{
    /* The old layouts are prefixes of today's Defs, field for field. */
    ck_assert_uint_eq(offsetof(old_body_def, velocity), offsetof(ws_body_def, velocity));
    ck_assert_uint_eq(offsetof(old_world_def, log_user), offsetof(ws_world_def, log_user));
    ck_assert_uint_lt(sizeof(old_body_def), sizeof(ws_body_def));
    ck_assert_uint_lt(sizeof(old_world_def), sizeof(ws_world_def));

    /* A guard after each old Def, filled with a pattern that the library must neither write nor
     * read: read as user_data or angular_velocity it would show (0xA5A5... is not zero). */
    struct {
        old_world_def d;
        unsigned char canary[sizeof(ws_world_def)];
    } wf;
    struct {
        old_body_def d;
        unsigned char canary[sizeof(ws_body_def)];
    } bf;
    memset(&wf, CANARY, sizeof wf);
    memset(&bf, CANARY, sizeof bf);

    ws_world_def_init_sized((ws_world_def *)&wf.d, sizeof wf.d);
    ck_assert_msg(canary_intact(wf.canary, sizeof wf.canary), "world init wrote past the Def");
    ck_assert_uint_eq(wf.d.size, sizeof wf.d);
    ck_assert(wf.d.dt == 2.5e-4 && wf.d.gravity.z == -9.81 && wf.d.use_ccd == 1);
    ck_assert(wf.d.log == NULL);
    wf.d.dt = 1e-4;
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create((const ws_world_def *)&wf.d, &w), WS_OK);
    ck_assert_msg(canary_intact(wf.canary, sizeof wf.canary), "world create wrote the guard");
    ck_assert_ptr_null(ws_world_get_user_data(w)); /* the missing field: its default */
    double dt = 0.0;
    ck_ok(w, ws_world_get_dt(w, &dt));
    ck_assert(dt == 1e-4);

    ws_body_def_init_sized((ws_body_def *)&bf.d, sizeof bf.d);
    ck_assert_msg(canary_intact(bf.canary, sizeof bf.canary), "body init wrote past the Def");
    ck_assert_uint_eq(bf.d.size, sizeof bf.d);
    ck_assert(bf.d.density == 1000.0 && bf.d.contact_layer == 1e-3 && bf.d.orientation.e0 == 1.0);
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &bf.d.shape));
    bf.d.mass = 2.0;
    bf.d.velocity = (ws_vec3){1.0, 2.0, 3.0};
    ws_body_id b;
    ck_ok(w, ws_body_create(w, (const ws_body_def *)&bf.d, &b));
    ck_assert_msg(canary_intact(bf.canary, sizeof bf.canary), "body create wrote the guard");
    ws_vec3 v, om;
    ck_ok(w, ws_body_get_velocity(w, b, &v));
    ck_ok(w, ws_body_get_angular_velocity(w, b, &om));
    ck_assert(v.x == 1.0 && v.y == 2.0 && v.z == 3.0);
    ck_assert(om.x == 0.0 && om.y == 0.0 && om.z == 0.0); /* the missing fields: defaults */
    ck_assert_ptr_null(ws_body_get_user_data(w, b));

    /* A newer, larger caller Def: the library fills its own fields, zeros the rest and records
     * the size both know, which tells the caller which fields the library reads. */
    struct newer_frame {
        ws_body_def d;
        double newer_field;
        unsigned char canary[16];
    } nf;
    memset(&nf, CANARY, sizeof nf);
    ws_body_def_init_sized(&nf.d, offsetof(struct newer_frame, canary));
    ck_assert_uint_eq(nf.d.size, sizeof nf.d);
    ck_assert(nf.newer_field == 0.0);
    ck_assert(canary_intact(nf.canary, sizeof nf.canary));

    /* The plain function, for programs built against headers before the sized form, fills
     * today's layout and not a byte more; a Def smaller than its header is left alone. */
    struct {
        ws_body_def d;
        unsigned char canary[16];
    } pf;
    memset(&pf, CANARY, sizeof pf);
    (ws_body_def_init)(&pf.d);
    ck_assert(canary_intact(pf.canary, sizeof pf.canary));
    ck_assert_uint_le(pf.d.size, sizeof pf.d);
    ck_assert_uint_ge(pf.d.size, offsetof(ws_body_def, user_data) + sizeof(void *));
    unsigned char tiny[4];
    memset(tiny, CANARY, sizeof tiny);
    ws_body_def_init_sized((ws_body_def *)(void *)tiny, sizeof tiny);
    ck_assert(canary_intact(tiny, sizeof tiny));
    ws_world_destroy(w);
}
END_TEST

/* ---- re-entrancy: callbacks inside a step may read the world, never change it ---- */

enum { REENTRY_CALLS = 24 };

typedef struct reentry {
    ws_world *w;
    ws_body_id body, kin;
    ws_shape_id shape;
    ws_law_id law;
    ws_element_id element;
    ws_material_id mat;
    int calls;                    /* callback calls */
    ws_status got[REENTRY_CALLS]; /* what each mutating call returned, the first time */
    int named[REENTRY_CALLS];     /* 1 when its last error named it and the step */
    int read_ok;                  /* a getter worked inside the step */
} reentry;

/* Try every kind of call that changes the world; record what each returned. */
static void try_mutations(reentry *r)
{
    ws_world *w = r->w;
    static const char *const names[REENTRY_CALLS] = {
        "ws_body_destroy", "ws_body_create", "ws_world_step", "ws_world_step_n",
        "ws_shape_create_box", "ws_shape_create_cylinder", "ws_shape_create_mesh",
        "ws_shape_destroy", "ws_law_create", "ws_law_destroy", "ws_element_create",
        "ws_element_destroy", "ws_body_set_pose", "ws_body_set_velocity", "ws_body_set_drive",
        "ws_world_set_dt", "ws_world_set_gravity", "ws_material_create", "ws_world_set_contact",
        "ws_world_set_default_contact", "ws_web_create_sheet", "ws_web_create_band",
        "ws_web_create_mesh", "ws_world_destroy"};
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = r->shape;
    bd.mass = 1.0;
    ws_mesh_def md;
    ws_mesh_def_init(&md);
    md.vertices = cube_v;
    md.vertex_count = 8;
    md.triangles = cube_t;
    md.triangle_count = 12;
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.stiffness = 1.0;
    ws_element_def ed;
    ws_element_def_init(&ed);
    ed.body2 = r->body;
    ed.law = r->law;
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    ws_material_def mtd;
    ws_material_def_init(&mtd);
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 0.01;
    wd.law = r->law;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = sd.ny = 2;
    sd.spacing_x = sd.spacing_y = 0.01;
    ws_band_def bnd;
    ws_band_def_init(&bnd);
    ws_web_mesh_def wm;
    ws_web_mesh_def_init(&wm);
    ws_pose pose = {{0, 0, 1}, {1, 0, 0, 0}};
    ws_vec3 v = {0, 0, 0}, g = {0, 0, -1};
    ws_body_id b;
    ws_shape_id sh;
    ws_law_id l;
    ws_element_id e;
    ws_material_id m;
    ws_web_id web;
    int k = 0;
#define TRY(call)                                                                                 \
    do {                                                                                          \
        r->got[k] = (call);                                                                       \
        const char *e_ = ws_world_last_error(w);                                                  \
        r->named[k] = strstr(e_, names[k]) == e_ &&                                               \
                      strstr(e_, " called from inside ws_world_step (a callback)") != NULL;       \
        k++;                                                                                      \
    } while (0)
    TRY(ws_body_destroy(w, r->body));
    TRY(ws_body_create(w, &bd, &b));
    TRY(ws_world_step(w));
    TRY(ws_world_step_n(w, 3));
    TRY(ws_shape_create_box(w, 1, 1, 1, &sh));
    TRY(ws_shape_create_cylinder(w, 1, 1, 8, &sh));
    TRY(ws_shape_create_mesh(w, &md, &sh));
    TRY(ws_shape_destroy(w, r->shape));
    TRY(ws_law_create(w, &ld, &l));
    TRY(ws_law_destroy(w, r->law));
    TRY(ws_element_create(w, &ed, &e));
    TRY(ws_element_destroy(w, r->element));
    TRY(ws_body_set_pose(w, r->body, &pose));
    TRY(ws_body_set_velocity(w, r->body, &v, &v));
    TRY(ws_body_set_drive(w, r->kin, &dd));
    TRY(ws_world_set_dt(w, 1e-4));
    TRY(ws_world_set_gravity(w, &g));
    TRY(ws_material_create(w, &mtd, &m));
    TRY(ws_world_set_contact(w, r->mat, r->mat, &cd));
    TRY(ws_world_set_default_contact(w, &cd));
    TRY(ws_web_create_sheet(w, &wd, &sd, &web));
    TRY(ws_web_create_band(w, &wd, &bnd, &web));
    TRY(ws_web_create_mesh(w, &wd, &wm, &web));
    /* ws_world_destroy returns nothing: it must leave the world alone and say why. */
    TRY((ws_world_destroy(w), WS_ERR_IN_STEP));
#undef TRY
    ck_assert_int_eq(k, REENTRY_CALLS);
    ws_vec3 p;
    r->read_ok = ws_body_get_position(w, r->body, &p) == WS_OK && p.z > 0.0;
}

static int reentry_drive(void *user, double t, ws_pose *pose, ws_vec3 *v, ws_vec3 *om)
{
    reentry *r = user;
    if (r->calls++ == 1) /* the first call is ws_body_set_drive's own, outside a step */
        try_mutations(r);
    *pose = (ws_pose){{0, 0, -1}, {1, 0, 0, 0}};
    (void)t;
    *v = *om = (ws_vec3){0, 0, 0};
    return 0;
}

static int reentry_law(void *user, int dim, const double *u, const double *ud, double t,
                       double *F, double *dFdu, double *dFdud)
{
    reentry *r = user;
    if (r->calls++ == 0)
        try_mutations(r);
    (void)dim;
    (void)ud;
    (void)t;
    F[0] = 10.0 * u[0];
    if (dFdu)
        dFdu[0] = 10.0;
    if (dFdud)
        dFdud[0] = 0.0;
    return 0;
}

/* A world with a dynamic box, a kinematic slab and a rod from the world to the box; `law_cb`
 * puts the re-entering callback in the rod's law, else in the slab's drive. */
static ws_world *reentry_world(reentry *r, int law_cb)
{
    memset(r, 0, sizeof *r);
    ws_world *w = new_world(2.5e-4);
    r->w = w;
    ck_ok(w, ws_world_get_default_material(w, &r->mat));
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &r->shape));
    r->body = box_at(w, 0.1, 1.0, 0.0, 0.0, 1.0, "box");
    r->kin = add_ground(w, 1.0, no_material());
    ws_law_def ld;
    ws_law_def_init(&ld);
    if (law_cb) {
        ld.type = WS_LAW_USER;
        ld.user_fn = reentry_law;
        ld.user_data = r;
        ld.stiffness = 10.0;
    } else {
        ld.stiffness = 10.0;
    }
    ck_ok(w, ws_law_create(w, &ld, &r->law));
    ws_element_def ed;
    ws_element_def_init(&ed);
    ed.body2 = r->body;
    ed.law = r->law;
    ed.point1 = (ws_vec3){0, 0, 2.0};
    ed.global_attachment = 1;
    ed.point2 = (ws_vec3){0, 0, 1.05};
    ck_ok(w, ws_element_create(w, &ed, &r->element));
    if (!law_cb) {
        ws_drive_def dd;
        ws_drive_def_init(&dd);
        dd.type = WS_DRIVE_CALLBACK;
        dd.callback = reentry_drive;
        dd.callback_user = r;
        ck_ok(w, ws_body_set_drive(w, r->kin, &dd));
    }
    return w;
}

static void check_reentry(reentry *r, const char *where)
{
    ws_world *w = r->w;
    ws_world_stats st;
    ck_ok(w, ws_world_step(w));
    ck_assert_msg(r->calls >= 1, "%s: the callback was not called", where);
    for (int k = 0; k < REENTRY_CALLS; k++) {
        ck_assert_msg(r->got[k] == WS_ERR_IN_STEP, "%s: call %d returned %s", where, k,
                      ws_status_string(r->got[k]));
        ck_assert_msg(r->named[k], "%s: call %d's last error does not name it", where, k);
    }
    ck_assert_msg(r->read_ok, "%s: a getter failed inside the step", where);
    /* Nothing changed: the same objects and parameters, and the world steps on; outside a
     * step the same calls work. */
    ck_assert(ws_body_is_valid(w, r->body) && ws_element_is_valid(w, r->element));
    ck_assert(ws_law_is_valid(w, r->law) && ws_shape_is_valid(w, r->shape));
    ck_ok(w, ws_world_get_stats(w, &st));
    ck_assert_uint_eq(st.bodies, 2);
    double dt;
    ck_ok(w, ws_world_get_dt(w, &dt));
    ck_assert(dt == 2.5e-4);
    ck_ok(w, ws_world_step_n(w, 10));
    ck_ok(w, ws_element_destroy(w, r->element));
    ck_ok(w, ws_body_destroy(w, r->body));
    ws_world_destroy(w);
}

START_TEST(test_reentry_from_drive)
{
    reentry r;
    reentry_world(&r, 0);
    check_reentry(&r, "drive callback");
}
END_TEST

START_TEST(test_reentry_from_law)
{
    reentry r;
    reentry_world(&r, 1);
    check_reentry(&r, "law callback");
}
END_TEST

/* ---- small refusals: each says what is really wrong ---- */

static int ends_with(const char *s, const char *tail)
{
    size_t n = strlen(s), m = strlen(tail);
    return n >= m && strcmp(s + n - m, tail) == 0;
}

#define ck_err_ends(w, tail)                                                                      \
    ck_assert_msg(ends_with(ws_world_last_error(w), tail), "last error '%s' does not end in '%s'", \
                  ws_world_last_error(w), tail)

START_TEST(test_mesh_messages)
{
    ws_world *w = new_world(2.5e-4);
    ws_shape_id s;
    static const uint32_t tet[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    static const uint32_t tet_in[12] = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};
    static const uint32_t tet_deg[12] = {0, 2, 2, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    double v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    /* Every message ends in its own words, not in stray numbers. */
    ck_assert_int_eq(create_mesh(w, NULL, 4, tet, 4, &s), WS_ERR_INVALID_ARGUMENT);
    ck_err_ends(w, "vertices and triangles must not be NULL");
    ck_assert_int_eq(create_mesh(w, v, 4, tet_deg, 4, &s), WS_ERR_BAD_MESH);
    ck_err_ends(w, "triangle 0 is degenerate (zero area): remove it, or repair the mesh in a mesh "
                   "tool (merge duplicate vertices, remove degenerate faces)");
    ck_assert_int_eq(create_mesh(w, v, 4, tet_in, 4, &s), WS_ERR_BAD_MESH);
    ck_err_ends(w, "counter-clockwise seen from outside (the mesh is inside out): reverse every "
                   "triangle, or repair it in a mesh tool (flip the normals)");
    double same[12] = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
    ck_assert_int_eq(create_mesh(w, same, 4, tet, 4, &s), WS_ERR_BAD_MESH);
    ck_err_ends(w, "all vertices coincide");
    v[4] = NAN;
    ck_assert_int_eq(create_mesh(w, v, 4, tet, 4, &s), WS_ERR_INVALID_ARGUMENT);
    ck_err_ends(w, "vertex 1 has a coordinate that is not finite");
    /* Sizes: a 1e200 box is too large, not "degenerate"; a 1e-200 one too small. */
    ck_assert_int_eq(ws_shape_create_box(w, 1e200, 1e200, 1e200, &s), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "WS_MESH_MAX_COORD");
    ck_assert_int_eq(ws_shape_create_cylinder(w, 1e200, 1.0, 8, &s), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "WS_MESH_MAX_COORD");
    double big[12] = {0, 0, 0, 1e200, 0, 0, 0, 1e200, 0, 0, 0, 1e200};
    ck_assert_int_eq(create_mesh(w, big, 4, tet, 4, &s), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "beyond WS_MESH_MAX_COORD (1e+06 m)");
    double tiny[12] = {0, 0, 0, 1e-200, 0, 0, 0, 1e-200, 0, 0, 0, 1e-200};
    ck_assert_int_eq(create_mesh(w, tiny, 4, tet, 4, &s), WS_ERR_BAD_MESH);
    ck_err_has(w, "below WS_MESH_MIN_EXTENT (1e-06 m)");
    /* At the bounds they are taken: a 2e6 m box, a 1 mm one. */
    ck_ok(w, ws_shape_create_box(w, 2e6, 2e6, 2e6, &s));
    ck_ok(w, ws_shape_create_box(w, 1e-3, 1e-3, 1e-3, &s));
    ws_world_destroy(w);
}
END_TEST

static ws_status body_with(ws_world *w, ws_shape_id s, double mass, const double *jdiag)
{
    ws_body_def d;
    ws_body_def_init(&d);
    d.shape = s;
    d.mass = mass;
    if (jdiag) {
        d.inertia.m[0] = jdiag[0];
        d.inertia.m[4] = jdiag[1];
        d.inertia.m[8] = jdiag[2];
    }
    ws_body_id b;
    return ws_body_create(w, &d, &b);
}

START_TEST(test_body_mass_and_inertia)
{
    ws_world *w = new_world(2.5e-4);
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &s));
    /* Masses outside the sane range are named as such, not as an inertia problem. */
    const double bad_mass[] = {1e300, 1e-300, 2e9, 1e-7};
    for (size_t k = 0; k < sizeof bad_mass / sizeof *bad_mass; k++) {
        ck_assert_int_eq(body_with(w, s, bad_mass[k], NULL), WS_ERR_INVALID_ARGUMENT);
        ck_err_has(w, "is outside [WS_BODY_MIN_MASS, WS_BODY_MAX_MASS] = [1e-06, 1e+09] kg");
        ck_assert_ptr_null(strstr(ws_world_last_error(w), "positive definite"));
    }
    ck_ok(w, body_with(w, s, WS_BODY_MAX_MASS, NULL));
    ck_ok(w, body_with(w, s, WS_BODY_MIN_MASS, NULL));
    /* Density x volume out of range says so. */
    ws_body_def d;
    ws_body_def_init(&d);
    d.shape = s;
    d.density = 1e300;
    ws_body_id b;
    ck_assert_int_eq(ws_body_create(w, &d, &b), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "(density x volume)");
    /* Principal moments: J1 + J2 >= J3 for any rigid body (a flat plate is the equality). */
    const double no_body[3] = {1, 1, 5}, no_body2[3] = {5, 1, 1}, plate[3] = {1, 1, 2},
                 solid[3] = {1, 2, 2.9};
    ck_assert_int_eq(body_with(w, s, 1.0, no_body), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "each must be at most the sum of the other two (J1 + J2 >= J3)");
    ck_assert_int_eq(body_with(w, s, 1.0, no_body2), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "J1 + J2 >= J3");
    ck_ok(w, body_with(w, s, 1.0, plate));
    ck_ok(w, body_with(w, s, 1.0, solid));
    ws_world_destroy(w);
}
END_TEST

START_TEST(test_vtk_series_directory)
{
    ws_world *w = new_world(2.5e-4);
    ws_vtk_series *series = (ws_vtk_series *)w;
    const char *missing = "/nonexistent-wrapsim-test-dir/frames";
    ck_assert_int_eq(ws_vtk_series_create(w, missing, "run", &series), WS_ERR_IO);
    ck_assert_ptr_null(series);
    ck_err_has(w, missing);
    /* Something that is not a directory where the directory should be. */
    FILE *f = fopen("/dev/null", "r");
    if (f) {
        fclose(f);
        ck_assert_int_eq(ws_vtk_series_create(w, "/dev/null", "run", &series), WS_ERR_IO);
        ck_err_has(w, "'/dev/null' is not a directory");
    }
    ck_ok(w, ws_vtk_series_create(w, ".", "run", &series));
    ws_vtk_series_destroy(series);
    ws_world_destroy(w);
}
END_TEST

/* ---- suite ---- */

static void add(Suite *s, const char *name, const TTest *t, double timeout)
{
    TCase *tc = tcase_create(name);
    tcase_set_timeout(tc, timeout);
    tcase_add_test(tc, t);
    suite_add_tcase(s, tc);
}

static Suite *api_suite(void)
{
    Suite *s = suite_create("api");
    /* Timeouts: a few times the measured run time under valgrind-free builds; the heavy ones
     * (thousands of steps, or a world per failure point) get more. */
    add(s, "stale_destroyed_body", test_stale_destroyed_body, 10);
    add(s, "stale_null_body", test_stale_null_body, 10);
    add(s, "stale_foreign_world", test_stale_foreign_world, 10);
    add(s, "stale_wrong_kind", test_stale_wrong_kind, 10);
    add(s, "is_valid_keeps_last_error", test_is_valid_keeps_last_error, 10);
    add(s, "uninit_world_def", test_uninit_world_def, 10);
    add(s, "uninit_body_def", test_uninit_body_def, 10);
    add(s, "uninit_mesh_def", test_uninit_mesh_def, 10);
    add(s, "uninit_contact_def", test_uninit_contact_def, 10);
    add(s, "uninit_material_def", test_uninit_material_def, 10);
    add(s, "uninit_drive_def", test_uninit_drive_def, 10);
    add(s, "old_size_defs", test_old_size_defs, 10);
    add(s, "reentry_from_drive", test_reentry_from_drive, 10);
    add(s, "mesh_messages", test_mesh_messages, 10);
    add(s, "body_mass_and_inertia", test_body_mass_and_inertia, 10);
    add(s, "vtk_series_directory", test_vtk_series_directory, 10);
    add(s, "reentry_from_law", test_reentry_from_law, 10);
    add(s, "bad_world_numbers", test_bad_world_numbers, 10);
    add(s, "bad_body_numbers", test_bad_body_numbers, 10);
    add(s, "bad_contact_numbers", test_bad_contact_numbers, 10);
    add(s, "bad_drive_numbers", test_bad_drive_numbers, 10);
    add(s, "oom_world_create", test_oom_world_create, 30);
    add(s, "oom_shape_create", test_oom_shape_create, 60);
    add(s, "oom_body_create", test_oom_body_create, 60);
    add(s, "oom_step", test_oom_step, 60);
    add(s, "warm_step_allocates_nothing", test_warm_step_allocates_nothing, 30);
    add(s, "bytes_back_to_zero", test_bytes_back_to_zero, 60);
    add(s, "determinism_hash", test_determinism_hash, 120);
    add(s, "failed_step_numerical", test_failed_step_numerical, 10);
    add(s, "failed_step_callback", test_failed_step_callback, 10);
    add(s, "copy_contacts", test_copy_contacts, 60);
    add(s, "copy_body_ids", test_copy_body_ids, 10);
    add(s, "version_and_status_strings", test_version_and_status_strings, 10);
    add(s, "log_hook", test_log_hook, 10);
    add(s, "shape_in_use", test_shape_in_use, 10);
    add(s, "tilt_drive_kinematics", test_tilt_drive_kinematics, 10);
    return s;
}

int main(void)
{
    return run_suite(api_suite());
}
