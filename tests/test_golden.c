/* Golden state hashes: the reference cases (DESIGN.md) stepped a stored number of steps must end
 * in the stored state hash, so a change of any result, on any machine or compiler, is seen here
 * and not only run against run. The scenes are built by the example program's own builder
 * (examples/tilt_table.c), the one the benchmarks use.
 *
 * When a change of results is intended (a new physics option as default, a fix), run this suite,
 * take the measured hashes it prints and update the one table below, saying why in the
 * CHANGELOG. A hash is the FNV-1a of the state as ws_world_get_state_hash walks it, every double
 * by its bits: there is no tolerance, the step is deterministic (-ffp-contract=off, no
 * reassociation), with libccd or without (its gate only skips pairs that cannot touch). */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

#include "helpers.h"

typedef struct golden {
    char variant; /* 'P' or 'R' */
    int wrapped;
    int use_ccd;      /* the libccd gate asked for (it skips only pairs that cannot touch) */
    int explicit_friction; /* the bodies' friction taken at the step's start (the paper's) */
    long steps;       /* stored run */
    uint64_t hash;    /* its state hash */
    long short_steps; /* the run under WS_TEST_SHORT=1 (sanitizer and valgrind stages) */
    uint64_t short_hash;
} golden;

/* THE TABLE. Unwrapped: the whole reference run (6 s of P, 7 s of R: both boxes slide in P,
 * the top one slides off in R). Wrapped: the first second (the film settles, the stack stands
 * while the platform waits), 0.1 s under WS_TEST_SHORT. All six since a corner within
 * WS_OUTLINE_TOL of a face's rim counts on the face (equal boxes keep their corners,
 * CHANGELOG), and since twin corners share one spring (WS_TWIN_REACH: two equal boxes' flush
 * interface is 4 springs, not 8; CHANGELOG), and since the bodies' regularised friction is
 * taken at the end of the step (world_friction.c, CHANGELOG), and since a contact whose slip
 * that step reverses takes the secant along the slip (ws_world_friction_turned, CHANGELOG). */
static const golden table[] = {
    {'P', 0, 1, 0, 24000, 0xd62ff5354efb769full, 4000, 0x9096ce4cea51c440ull},
    {'R', 0, 1, 0, 28000, 0x0bc4e9062a47a890ull, 4000, 0x9362f41b9491c25aull},
    /* Wrapped: 2 film sub-steps since the film's safety factor (CHANGELOG). All six since the
     * body contacts' friction takes the film's law (contact/penalty.h, CHANGELOG); the wrapped
     * ones also since an edge pair's normal cone has its tolerance (side-by-side corners), and
     * since the film's loads on the bodies are summed row by row (CHANGELOG), and since nearly
     * parallel edge pairs on faces lying on each other take the faces' normal
     * (WS_EDGE_FLAT_SIN: the stacked boxes' seam, CHANGELOG), and since such pairs within
     * 1e-3 of parallel fade out to the corners (WS_EDGE_PARALLEL_SIN, CHANGELOG), and since
     * an edge pair ending at a corner that counts on the other body's face is left to it
     * (WS_EDGE_END_REACH, CHANGELOG), and since the explicit film's push past a box's edge
     * turns continuously, the implicit film's law (contact/node_force.c, convex_push;
     * CHANGELOG). */
    {'P', 1, 1, 0, 4000, 0xcf64b996f90c89c3ull, 400, 0xb34972e84b2278a2ull},
    {'R', 1, 1, 0, 4000, 0x74a511fa68ebdeb4ull, 400, 0xb13d96fa37b1be25ull},
    /* The same without the gate: the same hashes. */
    {'P', 0, 0, 0, 24000, 0xd62ff5354efb769full, 4000, 0x9096ce4cea51c440ull},
    {'R', 0, 0, 0, 28000, 0x0bc4e9062a47a890ull, 4000, 0x9362f41b9491c25aull},
    /* The bodies' friction taken at the step's start (WS_FRICTION_STEP_EXPLICIT): the hashes
     * the library had before it was taken at the end of the step, kept to the bit. */
    {'P', 0, 1, 1, 24000, 0x32226e8a4a28cabeull, 4000, 0x8c8bd1890e9964e7ull},
    {'R', 1, 1, 1, 4000, 0x85ef85957f0fda35ull, 400, 0xfd8f75733ea37d94ull},
};
#define NGOLDEN (sizeof table / sizeof table[0])

static int short_run(void)
{
    const char *e = getenv("WS_TEST_SHORT");
    return e && *e && strcmp(e, "0") != 0;
}

START_TEST(reference_case_hash)
{
    const golden *g = &table[_i];
    long steps = short_run() ? g->short_steps : g->steps;
    uint64_t want = short_run() ? g->short_hash : g->hash;
    tilt_options o;
    tilt_default_options(&o);
    o.variant = g->variant;
    o.wrapped = g->wrapped;
    o.use_ccd = g->use_ccd;
    o.explicit_friction = g->explicit_friction;
    o.quiet = 1;
    tilt_scene sc;
    ck_assert_int_eq(tilt_build(&o, &sc), WS_OK);
    ck_ok(sc.world, ws_world_step_n(sc.world, steps));
    uint64_t h = 0;
    ck_ok(sc.world, ws_world_get_state_hash(sc.world, &h));
    ws_world_destroy(sc.world);
    report("golden: case %c %s%s%s, %ld steps: state hash 0x%016llxull", g->variant,
           g->wrapped ? "wrapped" : "unwrapped", g->use_ccd ? "" : " (no libccd gate)",
           g->explicit_friction ? " (explicit friction)" : "", steps, (unsigned long long)h);
    ck_assert_msg(h == want,
                  "case %c %s after %ld steps: state hash 0x%016llxull, the table in "
                  "tests/test_golden.c stores 0x%016llxull (update it if the change of results "
                  "is intended, and say why in the CHANGELOG)",
                  g->variant, g->wrapped ? "wrapped" : "unwrapped", steps,
                  (unsigned long long)h, (unsigned long long)want);
}
END_TEST

int main(void)
{
    (void)tilt_run; /* the example's runner is not used here */
    Suite *s = suite_create("golden");
    TCase *tc = tcase_create("reference_case_hash");
    tcase_set_timeout(tc, 300);
    tcase_add_loop_test(tc, reference_case_hash, 0, (int)NGOLDEN);
    suite_add_tcase(s, tc);
    return run_suite(s);
}
