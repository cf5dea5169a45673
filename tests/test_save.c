/* Save and restore (checkpoint/restart): a world restored from a save and stepped takes, bit for
 * bit, the steps of the world that was saved (the state hash compared at every later step, a
 * few hundred of them, in phases where much is going on: stick-slip, a film settling on a
 * stack, relaxing law histories, a restore between two full detections). A save that is
 * truncated, corrupted, of a newer format or of another structure is refused with the reason,
 * and the world is left as it was (its save before and after is the same, byte for byte).
 *
 * Why "bit for bit" is the test: the step is deterministic, so any piece of state a save
 * misses (a law history, an anchor, a cache that decides which pairs are evaluated in which
 * order) shows up as a different hash within a few steps of the restore. The restoring world is
 * not fresh: it has been stepped a different number of steps first, so whatever the restore
 * does not overwrite is stale and would show. */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

#include "helpers.h"

#include <stdint.h>
#include <unistd.h>

static int short_run(void)
{
    const char *e = getenv("WS_TEST_SHORT");
    return e && *e && strcmp(e, "0") != 0;
}

static uint64_t hash_of(ws_world *w)
{
    uint64_t h = 0;
    ck_ok(w, ws_world_get_state_hash(w, &h));
    return h;
}

/* The whole save of a world, in a malloc'd buffer. */
static unsigned char *save_of(ws_world *w, size_t *n)
{
    ck_assert_int_eq(ws_world_save(w, NULL, 0, n), WS_OK);
    unsigned char *b = malloc(*n);
    ck_assert_ptr_nonnull(b);
    size_t m = 0;
    ck_ok(w, ws_world_save(w, b, *n, &m));
    ck_assert_uint_eq(m, *n);
    return b;
}

/* ---- scenes ---- */

typedef struct scene {
    ws_world *world;
    ws_web_id web;
    ws_body_id box;
} scene;

typedef void (*builder)(scene *sc, int variant);

/* The reference case through the example's own builder. variant: bit 0 wrapped, bit 1 stick
 * friction, bit 2 two film sub-steps, bit 3 case R (else P). */
static void build_tilt(scene *sc, int variant)
{
    tilt_options o;
    tilt_default_options(&o);
    o.variant = variant & 8 ? 'R' : 'P';
    o.wrapped = variant & 1;
    o.stick = (variant & 2) != 0;
    o.substeps = variant & 4 ? 2 : 1;
    /* One sub-step (its own path through node detection) runs the 1 g film at 0.685 of its
     * stable sub-step: allowed only with the check at the bound itself. */
    o.stable_fraction = 1.0;
    o.quiet = 1;
    tilt_scene ts;
    ck_assert_int_eq(tilt_build(&o, &ts), WS_OK);
    sc->world = ts.world;
    sc->web = ts.film;
    sc->box = ts.box[1];
}

/* A box dropped on the ground with a sheet of film falling over it whose springs relax (a Prony
 * law: history in every spring), and a rod of a relaxing law from the box to a point above it
 * (history in an element). Full detection every third step. */
static void build_relax_with(scene *sc, int nx, test_alloc *ta)
{
    ws_world_def wd;
    ws_world_def_init(&wd);
    wd.dt = 2.5e-4;
    wd.detection_interval = 3;
    wd.stable_fraction = 1.0; /* one film sub-step at 0.6 of its bound: its own detection path */
    if (ta)
        test_alloc_install(&wd, ta);
    ck_assert_int_eq(ws_world_create(&wd, &sc->world), WS_OK);
    ws_world *w = sc->world;
    ws_material_id def;
    ck_ok(w, ws_world_get_default_material(w, &def));
    add_ground(w, 1.0, def);
    sc->box = add_box(w, 0.25, 0.25, 0.25, 5.0, (ws_vec3){0, 0, 0.126}, def, "box");
    double k1[2] = {300.0, 200.0}, tau[2] = {0.02, 0.2};
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_RELAXATION;
    ld.stiffness = 100.0;
    ld.prony_stiffness = k1;
    ld.prony_time = tau;
    ld.prony_count = 2;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_material_def md;
    ws_material_def_init(&md);
    md.name = "film";
    ws_material_id film;
    ck_ok(w, ws_material_create(w, &md, &film));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 4000.0;
    cd.damping = 1.0;
    cd.friction = 0.9;
    ck_ok(w, ws_world_set_contact(w, film, def, &cd));
    ws_web_def d;
    ws_web_def_init(&d);
    d.law = law;
    d.node_mass = 5e-3;
    d.material = film;
    d.node_damping = 1e-3;
    ws_sheet_def sh;
    ws_sheet_def_init(&sh);
    sh.nx = nx;
    sh.ny = nx;
    sh.spacing_x = sh.spacing_y = 0.36 / (nx - 1);
    sh.origin = (ws_vec3){-0.18, -0.17, 0.26};
    sh.prestretch_x = 0.1;
    ck_ok(w, ws_web_create_sheet(w, &d, &sh, &sc->web));
    ws_law_id rod_law;
    ld.stiffness = 2000.0;
    k1[0] = 3000.0;
    ck_ok(w, ws_law_create(w, &ld, &rod_law));
    ws_element_def ed;
    ws_element_def_init(&ed);
    ed.body1 = sc->box;
    ed.law = rod_law;
    ed.point1 = (ws_vec3){0.1, 0.1, 0.125};
    ed.point2 = (ws_vec3){0.3, 0.1, 0.6};
    ed.global_attachment = 0;
    ed.rest_length = 0.5;
    ws_element_id e;
    ck_ok(w, ws_element_create(w, &ed, &e));
}

static void build_relax(scene *sc, int nx)
{
    build_relax_with(sc, nx, NULL);
}

static void build_relax_std(scene *sc, int variant)
{
    (void)variant;
    build_relax(sc, 16);
}

/* A box resting on the ground under a sheet held still (every node pinned) a little wider than
 * the box, 1 mm above its top: the nodes over the top face and its edges have candidates, and
 * as nothing moves no step finds them again. */
static void build_pinned(scene *sc, int variant)
{
    (void)variant;
    ws_world_def wd;
    ws_world_def_init(&wd);
    wd.dt = 2.5e-4;
    wd.stable_fraction = 1.0; /* one film sub-step near its bound: its own detection path */
    ck_assert_int_eq(ws_world_create(&wd, &sc->world), WS_OK);
    ws_world *w = sc->world;
    ws_material_id def;
    ck_ok(w, ws_world_get_default_material(w, &def));
    add_ground(w, 1.0, def);
    sc->box = add_box(w, 0.25, 0.25, 0.25, 5.0, (ws_vec3){0, 0, 0.126}, def, "box");
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.stiffness = 100.0;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_material_def md;
    ws_material_def_init(&md);
    md.name = "film";
    ws_material_id film;
    ck_ok(w, ws_material_create(w, &md, &film));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 4000.0;
    cd.damping = 1.0;
    ck_ok(w, ws_world_set_contact(w, film, def, &cd));
    enum { N = 9 };
    uint32_t pinned[N * N];
    for (uint32_t i = 0; i < N * N; i++)
        pinned[i] = i;
    ws_web_def d;
    ws_web_def_init(&d);
    d.law = law;
    d.node_mass = 5e-3;
    d.material = film;
    ws_sheet_def sh;
    ws_sheet_def_init(&sh);
    sh.nx = sh.ny = N;
    sh.spacing_x = sh.spacing_y = 0.04;
    sh.origin = (ws_vec3){-0.16, -0.16, 0.2525};
    sh.pinned = pinned;
    sh.pinned_count = N * N;
    ck_ok(w, ws_web_create_sheet(w, &d, &sh, &sc->web));
}

/* ---- continuation ---- */

/* Build, step `before` steps, save; step on `after` steps recording the hash of each. Build the
 * scene again, step it `other` steps (so its caches hold something else), restore, and check its
 * hash at the restore and after every step. */
static void check_continuation(builder build, int variant, long before, long after, long other,
                               const char *what)
{
    scene a, b;
    build(&a, variant);
    ck_ok(a.world, ws_world_step_n(a.world, before));
    size_t n;
    unsigned char *buf = save_of(a.world, &n);
    uint64_t *want = malloc((size_t)(after + 1) * sizeof *want);
    want[0] = hash_of(a.world);
    for (long k = 1; k <= after; k++) {
        ck_ok(a.world, ws_world_step(a.world));
        want[k] = hash_of(a.world);
    }
    build(&b, variant);
    ck_ok(b.world, ws_world_step_n(b.world, other));
    ck_ok(b.world, ws_world_restore(b.world, buf, n));
    ck_assert_msg(hash_of(b.world) == want[0], "%s: hash differs right after the restore", what);
    for (long k = 1; k <= after; k++) {
        ck_ok(b.world, ws_world_step(b.world));
        uint64_t h = hash_of(b.world);
        ck_assert_msg(h == want[k],
                      "%s: restored at step %ld, the hash differs %ld steps later (%016llx, "
                      "uninterrupted %016llx)",
                      what, before, k, (unsigned long long)h, (unsigned long long)want[k]);
    }
    /* The two worlds' saves agree too: the bookkeeping the hash leaves out as well. */
    size_t na, nb;
    unsigned char *sa = save_of(a.world, &na), *sb = save_of(b.world, &nb);
    ck_assert_uint_eq(na, nb);
    ck_assert_msg(memcmp(sa, sb, na) == 0, "%s: the saves differ after %ld steps", what, after);
    report("%s: restored at step %ld (a %zu-byte save), %ld steps bit-identical", what, before,
           n, after);
    free(sa);
    free(sb);
    free(want);
    free(buf);
    ws_world_destroy(a.world);
    ws_world_destroy(b.world);
}

START_TEST(bodies_stick_slip_restore_between_full_detections)
{
    /* Case R unwrapped with stick friction, restored at t = 3.9005 s: the top box is at the
     * onset of slip (theta_c = 16.70 deg at 3.915 s), its stick anchors loaded, and the step is
     * the 2nd after a full detection (every 5th step from 0.5 s on: 15602 - 2000 = 13602 = 5 k
     * + 2). 800 steps take it through the break-away. Under WS_TEST_SHORT: at 0.6 s (the
     * boxes stand on their anchors), the 2nd step after a full detection too. */
    long at = short_run() ? 2402 : 15602;
    scene sc;
    build_tilt(&sc, 8 | 2);
    ck_ok(sc.world, ws_world_step_n(sc.world, at));
    size_t n;
    unsigned char *buf = save_of(sc.world, &n);
    /* The step count and the last full detection's follow the time and the 4 bodies. */
    size_t o = 32 + 8 + 8 + 4 * (8 + 8 + 3 * 8 + 13 * 8);
    uint64_t steps = 0, last = 0;
    for (int i = 7; i >= 0; i--) {
        steps = steps << 8 | buf[o + (size_t)i];
        last = last << 8 | buf[o + 8 + (size_t)i];
    }
    ck_assert_uint_eq(steps, (uint64_t)at);
    ck_assert_msg(steps - last >= 2 && steps - last < 5,
                  "saved %llu steps after the last full detection: not between two",
                  (unsigned long long)(steps - last));
    free(buf);
    ws_world_destroy(sc.world);
    if (short_run())
        check_continuation(build_tilt, 8 | 2, 2402, 200, 900, "case R unwrapped, stick");
    else
        check_continuation(build_tilt, 8 | 2, 15602, 800, 15000, "case R unwrapped, stick");
}
END_TEST

START_TEST(bodies_regularised_sliding)
{
    /* Case P unwrapped, regularised friction, restored as both boxes slide (4.5 s). */
    if (short_run())
        check_continuation(build_tilt, 0, 2403, 200, 900, "case P unwrapped, regularised");
    else
        check_continuation(build_tilt, 0, 18003, 600, 17000, "case P unwrapped, regularised");
}
END_TEST

START_TEST(wrapped_film_one_substep)
{
    /* Case P wrapped: the film settles on the stack in the first 0.1 s, so at step 300 the node
     * contacts and candidates come and go. */
    long before = short_run() ? 120 : 300, after = short_run() ? 100 : 300;
    check_continuation(build_tilt, 1, before, after, 77, "case P wrapped, 1 sub-step");
}
END_TEST

START_TEST(into_a_fresh_world)
{
    /* Restored into a world built and never stepped: nothing it has in room or caches comes
     * from a run of its own (its contacts' room for node candidates is empty). */
    long before = short_run() ? 120 : 300, after = short_run() ? 50 : 100;
    check_continuation(build_tilt, 1, before, after, 0, "case P wrapped, into a fresh world");
    /* A film held still over a box: no step after the restore finds its candidates again, so
     * the restore itself must make the contacts' room for them. */
    check_continuation(build_pinned, 0, 200, 50, 0, "pinned film, into a fresh world");
}
END_TEST

START_TEST(wrapped_film_substeps_stick)
{
    long before = short_run() ? 120 : 402, after = short_run() ? 100 : 300;
    check_continuation(build_tilt, 8 | 4 | 2 | 1, before, after, 51,
                       "case R wrapped, 2 sub-steps, stick");
}
END_TEST

START_TEST(relaxing_film_and_element)
{
    /* The sheet lands on the box around step 150 (0.26 m - 0.25 m at rest, falling); the Prony
     * histories of its springs and of the rod change every step. */
    check_continuation(build_relax_std, 0, 400, 400, 123, "relaxing film and rod");
}
END_TEST

/* Restoring at step 0 into a world stepped on, and the same save twice: the world returns. */
START_TEST(restore_rewinds)
{
    scene a;
    build_relax(&a, 8);
    size_t n;
    unsigned char *buf = save_of(a.world, &n);
    uint64_t h0 = hash_of(a.world);
    ck_ok(a.world, ws_world_step_n(a.world, 200));
    uint64_t h200 = hash_of(a.world);
    ck_assert(h200 != h0);
    for (int k = 0; k < 2; k++) {
        ck_ok(a.world, ws_world_restore(a.world, buf, n));
        ck_assert(hash_of(a.world) == h0);
        double t;
        ck_ok(a.world, ws_world_get_time(a.world, &t));
        ck_assert(t == 0.0);
        ck_ok(a.world, ws_world_step_n(a.world, 200));
        ck_assert(hash_of(a.world) == h200);
    }
    free(buf);
    ws_world_destroy(a.world);
}
END_TEST

/* ---- the hash covers the film's law histories ---- */

/* Offset of the web's state in a save: its node x block starts with the x of nodes 0 and 1. */
static size_t find_bytes(const unsigned char *hay, size_t n, const unsigned char *needle,
                         size_t m)
{
    for (size_t i = 0; i + m <= n; i++)
        if (memcmp(hay + i, needle, m) == 0)
            return i;
    return SIZE_MAX;
}

static void put_le64(unsigned char *b, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
}

/* FNV-1a 64 over the payload, written into the header (bytes 24..31), as a save does. */
static void reseal(unsigned char *b, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 32; i < n; i++) {
        h ^= b[i];
        h *= 0x100000001b3ull;
    }
    put_le64(b + 24, h);
}

START_TEST(hash_covers_film_histories)
{
    /* Two worlds whose bodies and nodes are the same, bit for bit, and whose springs' law
     * histories differ in one double must have different state hashes. The second world is the
     * first's save with one history value changed (the save resealed). */
    scene a, b;
    build_relax(&a, 8);
    ck_ok(a.world, ws_world_step_n(a.world, 300));
    size_t n, cnt;
    unsigned char *buf = save_of(a.world, &n);
    ws_web_info info;
    ck_ok(a.world, ws_web_get_info(a.world, a.web, &info));
    double xyz[3 * 64], xyz_b[3 * 64];
    ck_assert_uint_eq(info.node_count, 64);
    ck_ok(a.world, ws_web_copy_positions(a.world, a.web, xyz, 64, &cnt));
    unsigned char key[16];
    uint64_t u;
    memcpy(&u, &xyz[0], 8);
    put_le64(key, u);
    memcpy(&u, &xyz[3], 8);
    put_le64(key + 8, u);
    size_t at = find_bytes(buf, n, key, sizeof key);
    ck_assert_uint_ne(at, SIZE_MAX);
    size_t hist = at + 6 * (size_t)info.node_count * 8; /* after x and v */
    ck_assert_uint_lt(hist + 8, n);
    buf[hist + 3] ^= 0x10; /* a low bit of the first spring's first history value */
    reseal(buf, n);
    build_relax(&b, 8);
    ck_ok(b.world, ws_world_restore(b.world, buf, n));
    ck_ok(b.world, ws_web_copy_positions(b.world, b.web, xyz_b, 64, &cnt));
    ck_assert(memcmp(xyz, xyz_b, sizeof xyz) == 0);
    ck_assert_msg(hash_of(a.world) != hash_of(b.world),
                  "the state hash does not see the springs' law histories");
    free(buf);
    ws_world_destroy(a.world);
    ws_world_destroy(b.world);
}
END_TEST

/* ---- refusals ---- */

/* Restore `buf` into w: refused with `status`, the last error containing `text`, and the world
 * as it was (its save the same, byte for byte). */
static void expect_refused(ws_world *w, const void *buf, size_t len, ws_status status,
                           const char *text)
{
    size_t n0, n1;
    unsigned char *before = save_of(w, &n0);
    ws_status s = ws_world_restore(w, buf, len);
    ck_assert_msg(s == status, "restore gave %s (%s), expected %s", ws_status_string(s),
                  ws_world_last_error(w), ws_status_string(status));
    ck_assert_msg(strstr(ws_world_last_error(w), text), "last error '%s' does not say '%s'",
                  ws_world_last_error(w), text);
    unsigned char *after = save_of(w, &n1);
    ck_assert_uint_eq(n0, n1);
    size_t at = 32; /* the first byte of the state that differs, past the header */
    while (at < n0 && before[at] == after[at])
        at++;
    ck_assert_msg(memcmp(before, after, n0) == 0,
                  "a refused restore changed the world (its save at byte %zu of %zu)", at, n0);
    free(before);
    free(after);
}

START_TEST(refuses_bad_saves)
{
    scene a, b;
    build_relax(&a, 8);
    ck_ok(a.world, ws_world_step_n(a.world, 250));
    size_t n;
    unsigned char *buf = save_of(a.world, &n);
    build_relax(&b, 8);
    ck_ok(b.world, ws_world_step_n(b.world, 100));
    unsigned char *c = malloc(n + 8);
    ck_assert_ptr_nonnull(c);

    expect_refused(b.world, buf, 10, WS_ERR_FORMAT, "truncated");
    expect_refused(b.world, buf, n - 1, WS_ERR_FORMAT, "truncated");
    expect_refused(b.world, buf, 32, WS_ERR_FORMAT, "truncated");
    memcpy(c, buf, n);
    memset(c + n, 0, 8);
    expect_refused(b.world, c, n + 8, WS_ERR_FORMAT, "trailing");
    c[n / 2] ^= 1; /* one bit in the state */
    expect_refused(b.world, c, n, WS_ERR_FORMAT, "checksum mismatch");
    memcpy(c, buf, n);
    c[0] = 'X';
    expect_refused(b.world, c, n, WS_ERR_FORMAT, "not a saved");
    memcpy(c, buf, n);
    c[8] = 3; /* format version 3 */
    expect_refused(b.world, c, n, WS_ERR_FORMAT, "version 3 is newer than this library's 2");
    memcpy(c, buf, n);
    for (int i = 0; i < 4; i++) /* the byte-order mark written big-endian */
        c[12 + i] = (unsigned char)(i + 1);
    expect_refused(b.world, c, n, WS_ERR_FORMAT, "little-endian");
    /* A state whose checksum holds but whose contents name what this world does not have: the
     * first body candidate's body a (after time, 2 body slots of structure and state, steps,
     * last full step, valid flag, travel and the candidate count) set to body 7. */
    memcpy(c, buf, n);
    size_t body_bytes = 8 + 2 * (8 + 8 + 3 * 8 + 13 * 8);
    size_t cand = 32 + 8 + body_bytes + 8 + 8 + 4 + 8;
    uint64_t ncand = 0;
    for (int i = 7; i >= 0; i--)
        ncand = ncand << 8 | c[cand + (size_t)i];
    ck_assert_uint_gt(ncand, 0); /* the box stands on the ground: there are candidates */
    c[cand + 8] = 7;
    reseal(c, n);
    expect_refused(b.world, c, n, WS_ERR_FORMAT, "contact candidate 0 (bodies 7, 1");
    ck_assert_int_eq(ws_world_restore(b.world, NULL, 5), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_world_restore(NULL, buf, n), WS_ERR_INVALID_ARGUMENT);

    /* Another structure: a sheet of 10 x 10 nodes in place of 8 x 8. */
    scene d;
    build_relax(&d, 10);
    expect_refused(d.world, buf, n, WS_ERR_FORMAT, "web 0 has 64 nodes in the file, 100 here");
    ws_world_destroy(d.world);
    /* And a world with one body more. */
    build_relax(&d, 8);
    ws_material_id def;
    ck_ok(d.world, ws_world_get_default_material(d.world, &def));
    add_box(d.world, 0.1, 0.1, 0.1, 1.0, (ws_vec3){0.5, 0.5, 0.06}, def, "extra");
    expect_refused(d.world, buf, n, WS_ERR_FORMAT, "has 2 body slots in the file, 3 here");
    ws_world_destroy(d.world);

    /* After all that, the good save is taken. */
    ck_ok(b.world, ws_world_restore(b.world, buf, n));
    ck_assert(hash_of(b.world) == hash_of(a.world));
    free(c);
    free(buf);
    ws_world_destroy(a.world);
    ws_world_destroy(b.world);
}
END_TEST

START_TEST(every_byte_changed_is_refused_or_safe)
{
    /* A save whose checksum holds (made so, as a crafted file would be) with any one byte
     * changed: the restore either refuses it, leaving the world as it was, or takes it, and
     * then stepping never crashes (it may fail with WS_ERR_NUMERICAL on a value gone wild).
     * Every byte of the state (every 29th under WS_TEST_SHORT). */
    scene a, b;
    build_relax(&a, 8);
    ck_ok(a.world, ws_world_step_n(a.world, 250));
    size_t n;
    unsigned char *buf = save_of(a.world, &n), *c = malloc(n);
    build_relax(&b, 8);
    ck_ok(b.world, ws_world_restore(b.world, buf, n));
    size_t stride = short_run() ? 29 : 1, refused = 0, taken = 0;
    for (size_t i = 32; i < n; i += stride) {
        memcpy(c, buf, n);
        c[i] ^= (unsigned char)(0x5a ^ (i & 0xff));
        reseal(c, n);
        ws_status s = ws_world_restore(b.world, c, n);
        if (s != WS_OK) {
            ck_assert_int_eq(s, WS_ERR_FORMAT);
            ck_assert(hash_of(b.world) == hash_of(a.world));
            refused++;
            continue;
        }
        taken++;
        for (int k = 0; k < 3; k++) {
            s = ws_world_step(b.world);
            ck_assert_msg(s == WS_OK || s == WS_ERR_NUMERICAL,
                          "byte %zu changed: a step gave %s (%s)", i, ws_status_string(s),
                          ws_world_last_error(b.world));
        }
        ck_ok(b.world, ws_world_restore(b.world, buf, n));
    }
    report("one byte changed in a %zu-byte save (resealed): %zu refused, %zu taken and stepped",
           n, refused, taken);
    ck_assert_uint_gt(refused, 0);
    free(c);
    free(buf);
    ws_world_destroy(a.world);
    ws_world_destroy(b.world);
}
END_TEST

START_TEST(save_sizes)
{
    scene a;
    build_relax(&a, 8);
    size_t n = 0, m = 0;
    ck_assert_int_eq(ws_world_save(a.world, NULL, 0, &n), WS_OK);
    ck_assert_uint_gt(n, 32);
    unsigned char *b = malloc(n);
    ck_assert_int_eq(ws_world_save(a.world, b, n - 1, &m), WS_ERR_BUFFER_TOO_SMALL);
    ck_assert_uint_eq(m, n);
    ck_assert_int_eq(ws_world_save(a.world, NULL, 5, &m), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_world_save(a.world, b, n, NULL), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_world_save(NULL, b, n, &m), WS_ERR_INVALID_ARGUMENT);
    ck_ok(a.world, ws_world_save(a.world, b, n, &m));
    /* The header as documented: magic, version 2, the byte-order mark, the state's length. */
    ck_assert(memcmp(b, "WSSTATE", 8) == 0);
    ck_assert(b[8] == 2 && b[9] == 0 && b[10] == 0 && b[11] == 0);
    ck_assert(b[12] == 4 && b[13] == 3 && b[14] == 2 && b[15] == 1);
    uint64_t len = 0;
    for (int i = 7; i >= 0; i--)
        len = len << 8 | b[16 + i];
    ck_assert_uint_eq(len, n - 32);
    free(b);
    ws_world_destroy(a.world);
}
END_TEST

START_TEST(files)
{
    scene a, b;
    build_relax(&a, 8);
    ck_ok(a.world, ws_world_step_n(a.world, 150));
    char path[64];
    snprintf(path, sizeof path, "test_save_%ld.wss", (long)getpid());
    ck_ok(a.world, ws_world_save_file(a.world, path));
    build_relax(&b, 8);
    ck_ok(b.world, ws_world_restore_file(b.world, path));
    ck_assert(hash_of(a.world) == hash_of(b.world));
    ck_ok(a.world, ws_world_step_n(a.world, 50));
    ck_ok(b.world, ws_world_step_n(b.world, 50));
    ck_assert(hash_of(a.world) == hash_of(b.world));
    /* A file cut short: refused, naming the file, the world unchanged. */
    FILE *f = fopen(path, "rb+");
    ck_assert_ptr_nonnull(f);
    ck_assert_int_eq(fseek(f, 0, SEEK_END), 0);
    long size = ftell(f);
    fclose(f);
    ck_assert_int_eq(truncate(path, size - 100), 0);
    uint64_t h = hash_of(b.world);
    ck_assert_int_eq(ws_world_restore_file(b.world, path), WS_ERR_FORMAT);
    ck_assert(strstr(ws_world_last_error(b.world), path));
    ck_assert(strstr(ws_world_last_error(b.world), "truncated"));
    ck_assert(hash_of(b.world) == h);
    remove(path);
    ck_assert_int_eq(ws_world_restore_file(b.world, path), WS_ERR_IO);
    ck_assert(strstr(ws_world_last_error(b.world), path));
    ck_assert_int_eq(ws_world_save_file(b.world, "no-such-dir/x.wss"), WS_ERR_IO);
    ck_assert_int_eq(ws_world_save_file(b.world, ""), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_world_restore_file(b.world, NULL), WS_ERR_INVALID_ARGUMENT);
    ck_assert(hash_of(b.world) == h);
    ws_world_destroy(a.world);
    ws_world_destroy(b.world);
}
END_TEST

START_TEST(out_of_memory_leaves_world)
{
    /* A restore that needs room for the caches (a fresh world has none for candidates yet)
     * and does not get it fails with WS_ERR_OUT_OF_MEMORY and leaves the world as it was;
     * given room, it is taken. The allocator fails after k more allocations, k = 0, 1, ... */
    scene a;
    build_relax(&a, 8);
    ck_ok(a.world, ws_world_step_n(a.world, 250));
    size_t n;
    unsigned char *buf = save_of(a.world, &n);
    long k = 0;
    for (;; k++) {
        test_alloc ta = {.allocs_left = -1};
        scene b;
        build_relax_with(&b, 8, &ta);
        ta.allocs_left = k;
        ws_status s = ws_world_restore(b.world, buf, n);
        ta.allocs_left = -1;
        if (s == WS_OK) {
            ck_assert(hash_of(b.world) == hash_of(a.world));
            ws_world_destroy(b.world);
            ck_assert_int_eq(ta.live, 0);
            break;
        }
        ck_assert_int_eq(s, WS_ERR_OUT_OF_MEMORY);
        /* Unchanged: as a fresh world of the scene. */
        scene c;
        build_relax(&c, 8);
        size_t nb, nc;
        unsigned char *sb = save_of(b.world, &nb), *scc = save_of(c.world, &nc);
        ck_assert_uint_eq(nb, nc);
        ck_assert_msg(memcmp(sb, scc, nb) == 0, "a restore out of memory changed the world");
        free(sb);
        free(scc);
        ws_world_destroy(c.world);
        ws_world_destroy(b.world);
        ck_assert_int_eq(ta.live, 0);
        ck_assert_int_eq(ta.bytes, 0);
        ck_assert_int_lt(k, 100);
    }
    ck_assert_int_gt(k, 0); /* the restore did allocate, so the failures were exercised */
    free(buf);
    ws_world_destroy(a.world);
}
END_TEST

int main(void)
{
    (void)tilt_run; /* the example's runner is not used here */
    Suite *s = suite_create("save");
    add_case(s, "bodies_stick_slip_restore_between_full_detections",
             bodies_stick_slip_restore_between_full_detections, 120);
    add_case(s, "bodies_regularised_sliding", bodies_regularised_sliding, 120);
    add_case(s, "wrapped_film_one_substep", wrapped_film_one_substep, 300);
    add_case(s, "into_a_fresh_world", into_a_fresh_world, 300);
    add_case(s, "wrapped_film_substeps_stick", wrapped_film_substeps_stick, 300);
    add_case(s, "relaxing_film_and_element", relaxing_film_and_element, 120);
    add_case(s, "restore_rewinds", restore_rewinds, 60);
    add_case(s, "hash_covers_film_histories", hash_covers_film_histories, 60);
    add_case(s, "refuses_bad_saves", refuses_bad_saves, 60);
    add_case(s, "every_byte_changed_is_refused_or_safe", every_byte_changed_is_refused_or_safe,
             300);
    add_case(s, "save_sizes", save_sizes, 30);
    add_case(s, "files", files, 60);
    add_case(s, "out_of_memory_leaves_world", out_of_memory_leaves_world, 60);
    return run_suite(s);
}
