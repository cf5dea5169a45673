/* Workers: a step on several workers (the world's own threads, or a host's scheduler) must give
 * the state a step on one gives, to the bit. The film is swept in lanes of rows whose edges are
 * computed by both neighbours and whose loads on the bodies are added in node order, so the
 * sums are the same sums in the same order: the state hash (every double by its bits) is the
 * test, with no tolerance. A scheduler that runs the pieces in reverse order, or each on a
 * thread of its own, shows that the result does not depend on who runs them when. */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

#include <pthread.h>
#include <stdatomic.h>

#include "base/pool.h"
#include "web/forces.h"
#include "world/world_internal.h"
#include "helpers.h"

static int short_run(void)
{
    const char *e = getenv("WS_TEST_SHORT");
    return e && *e && strcmp(e, "0") != 0;
}

/* ---- schedulers of a host ---- */

/* Runs every item, the last first, before returning (no handle). */
static void *enqueue_reverse(ws_task_fn *task, int32_t count, int32_t min_range, void *ctx,
                             void *user)
{
    (void)min_range;
    int *calls = user;
    (*calls)++;
    for (int32_t i = count; i-- > 0;)
        task(i, i + 1, 0, ctx);
    return NULL;
}

static void finish_never(void *task, void *user)
{
    (void)task, (void)user;
    ck_abort_msg("finish called for a task run before enqueue returned");
}

/* Each item on a thread of its own, the threads started last first; finish joins them. */
#define MAX_ITEMS 64
typedef struct thread_task {
    pthread_t id[MAX_ITEMS];
    struct item {
        ws_task_fn *task;
        void *ctx;
        int32_t i;
    } item[MAX_ITEMS];
    int32_t count;
} thread_task;

static void *item_main(void *arg)
{
    struct item *it = arg;
    it->task(it->i, it->i + 1, (uint32_t)it->i, it->ctx);
    return NULL;
}

static void *enqueue_threads(ws_task_fn *task, int32_t count, int32_t min_range, void *ctx,
                             void *user)
{
    (void)min_range;
    thread_task *t = user;
    ck_assert_int_le(count, MAX_ITEMS);
    t->count = count;
    for (int32_t i = count; i-- > 0;) {
        t->item[i] = (struct item){task, ctx, i};
        ck_assert_int_eq(pthread_create(&t->id[i], NULL, item_main, &t->item[i]), 0);
    }
    return t;
}

static void finish_threads(void *task, void *user)
{
    thread_task *t = task;
    ck_assert_ptr_eq(task, user);
    for (int32_t i = 0; i < t->count; i++)
        pthread_join(t->id[i], NULL);
}

/* ---- the wrapped reference case ---- */

/* The wrapped case P (a closed band of 5856 nodes around the stack) for `steps` steps on
 * `workers` of the world's threads; its state hash. */
static uint64_t wrapped_hash(long steps, int workers)
{
    tilt_options o;
    tilt_default_options(&o);
    o.variant = 'P';
    o.wrapped = 1;
    o.quiet = 1;
    o.workers = workers;
    tilt_scene sc;
    ck_assert_int_eq(tilt_build(&o, &sc), WS_OK);
    ck_ok(sc.world, ws_world_step_n(sc.world, steps));
    uint64_t h = 0;
    ck_ok(sc.world, ws_world_get_state_hash(sc.world, &h));
    ws_world_destroy(sc.world);
    return h;
}

START_TEST(test_wrapped_same_for_any_workers)
{
    /* 0.1 s: the band falls onto the stack and its contacts (runs and one by one) form; 7.5 ms
     * and 2 workers under WS_TEST_SHORT (sanitizers, valgrind), past the first contacts. */
    const long steps = short_run() ? 30 : 400;
    const int most = short_run() ? 2 : 4;
    const uint64_t one = wrapped_hash(steps, 1);
    for (int k = 2; k <= most; k++) {
        uint64_t h = wrapped_hash(steps, k);
        report("workers: wrapped case, %ld steps, %d workers: 0x%016llx (1 worker 0x%016llx)",
               steps, k, (unsigned long long)h, (unsigned long long)one);
        ck_assert_msg(h == one, "%d workers: state hash 0x%016llx, 1 worker 0x%016llx", k,
                      (unsigned long long)h, (unsigned long long)one);
    }
}
END_TEST

/* ---- a sheet dropped onto a box ---- */

typedef struct sheet_run {
    int workers;
    int host; /* 0: the world's threads (or none), 1: reverse order, 2: a thread an item */
    int law_type;
    int tight; /* the pieces of a search start with little room, so that some run again */
    uint64_t *reruns; /* where to put how many did (may be NULL) */
    int interval;     /* the bodies' full detection every this many steps (0: the default) */
    int narrow_tight; /* the narrow phase beside the film has little room: it runs again */
    uint64_t *narrow_reruns, *full; /* how many did, and the full detections (may be NULL) */
    int implicit; /* the implicit film at the real film's areal density, on the multigrid */
    int one_lane; /* a sheet of one sweep block onto a second box on the first */
    int mesh;     /* the sheet made again as a mesh web, its springs scaled, its masses apart */
} sheet_run;

/* Grid web g made again as a mesh web (the same nodes and springs, in the same order) whose
 * springs' stiffness scales run from 0.75 to 1.25 and whose node masses from 0.8 to 1.2 of the
 * sheet's: the mesh's own ways through the sweep (a law's force times its spring's scale, each
 * node its own mass). The sheet is destroyed; the mesh is returned. */
static ws_web_id sheet_as_mesh(ws_world *w, const ws_web_def *wd, ws_web_id g)
{
    uint32_t slot;
    ck_assert_int_eq(ws_lookup_web(w, g, &slot), WS_OK);
    const ws_web *s = w->webs[slot];
    const uint32_t n = s->n, ns = s->ns;
    double *pos = malloc(3 * n * sizeof *pos), *mass = malloc(n * sizeof *mass);
    double *rest = malloc(ns * sizeof *rest), *scale = malloc(ns * sizeof *scale);
    uint32_t *spr = malloc(2 * ns * sizeof *spr);
    uint8_t *kind = malloc(ns);
    ck_assert(pos && mass && rest && scale && spr && kind);
    for (uint32_t i = 0; i < n; i++) {
        pos[3 * i] = s->x[0].x[i];
        pos[3 * i + 1] = s->x[0].y[i];
        pos[3 * i + 2] = s->x[0].z[i];
        mass[i] = s->m[i] * (0.8 + 0.4 * (double)((i * 37u) % 101u) / 100.0);
    }
    for (uint32_t k = 0; k < ns; k++) {
        spr[2 * k] = s->sa[k];
        spr[2 * k + 1] = s->sb[k];
        rest[k] = 1.0 / s->inv_l0[k];
        kind[k] = s->kind[k];
        scale[k] = 0.75 + 0.5 * (double)((k * 53u) % 97u) / 96.0;
    }
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = pos;
    md.node_count = n;
    md.node_masses = mass;
    md.springs = spr;
    md.spring_count = ns;
    md.rest_lengths = rest;
    md.kinds = kind;
    md.stiffness_scales = scale;
    ws_web_def d = *wd;
    d.node_mass = 0.0;
    ws_web_id m;
    ck_ok(w, ws_web_create_mesh(w, &d, &md, &m));
    ck_ok(w, ws_web_destroy(w, g));
    free(pos);
    free(mass);
    free(rest);
    free(scale);
    free(spr);
    free(kind);
    return m;
}

/* A 48 x 40 sheet with shear springs (5 sweep blocks of 8 rows), pre-stretched, 3 mm above a
 * box on the ground, so that dropped it drapes over the edges: contacts on faces, edges and
 * corners, runs and one by one, with friction. The world is made with d (its workers and
 * scheduler set); the box and the web into *box and *web. */
static ws_world *sheet_world(const ws_world_def *d, const sheet_run *r, ws_body_id *box,
                             ws_web_id *web)
{
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(d, &w), WS_OK);
    w->search_tight = r->tight;
    w->narrow_tight = r->narrow_tight;
    add_ground(w, 2.0, no_material());
    *box = add_box(w, 0.4, 0.3, 0.3, 20.0, (ws_vec3){0.0, 0.0, 0.15}, no_material(), "box");
    if (r->one_lane) /* 1 mm above the first box, its twin in plan: it lands, and the two
                        press on each other, corner on corner (twin corners) */
        *box = add_box(w, 0.4, 0.3, 0.2, 8.0, (ws_vec3){0.0, 0.0, 0.401}, no_material(),
                       "top box");
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = (ws_law_type)r->law_type;
    ld.stiffness = 200.0;
    ld.damping = r->law_type == WS_LAW_LINEAR_VISCOELASTIC ? 0.05 : 0.0;
    if (r->law_type == WS_LAW_CUBIC_ELASTIC)
        ld.cubic_stiffness = 2e3;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-3;
    wd.law = wd.law_cross = wd.law_shear = law;
    wd.node_damping = 1e-3;
    if (r->implicit) {
        wd.node_mass = 0.0;
        wd.areal_density = 0.018;
        wd.integrator = WS_WEB_IMPLICIT;
        wd.preconditioner = WS_WEB_PRECONDITIONER_MULTIGRID;
    }
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = 48;
    sd.ny = 40;
    sd.spacing_x = sd.spacing_y = 0.0125;
    /* The implicit sheet 0.1 mm above the box: it lands after 4.5 ms (18 steps). */
    sd.origin = (ws_vec3){-0.2975, -0.24375, r->implicit ? 0.3001 : 0.303};
    if (r->one_lane) { /* 24 x 16 = 384 nodes: one block, so one lane */
        sd.nx = 24;
        sd.ny = 16;
        sd.origin = (ws_vec3){-0.14375, -0.09375, 0.504};
    }
    sd.prestretch_x = sd.prestretch_y = 0.02;
    sd.shear = 1;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, web));
    if (r->mesh)
        *web = sheet_as_mesh(w, &wd, *web);
    if (r->implicit)
        return w; /* one sub-step */
    double S;
    ck_ok(w, ws_web_get_stable_dt(w, *web, &S));
    /* Sub-steps for half the stable sub-step, with 5 % to spare (the world's default
     * stable_fraction is 0.5). */
    int n = (int)ceil(2.1 * d->dt / S);
    ck_ok(w, ws_web_set_substeps(w, *web, n < 1 ? 1 : n));
    return w;
}

/* The sheet of sheet_world on r's workers and scheduler: its state hash after `steps` steps. */
static uint64_t sheet_hash(const sheet_run *r, long steps, int *enqueued)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = 2.5e-4;
    d.worker_count = (uint32_t)r->workers;
    if (r->interval)
        d.detection_interval = r->interval;
    int calls = 0;
    thread_task tt;
    if (r->host == 1) {
        d.enqueue_task = enqueue_reverse;
        d.finish_task = finish_never;
        d.task_context = &calls;
    } else if (r->host == 2) {
        d.enqueue_task = enqueue_threads;
        d.finish_task = finish_threads;
        d.task_context = &tt;
    }
    ws_body_id box;
    ws_web_id web;
    ws_world *w = sheet_world(&d, r, &box, &web);
    /* The film touches the box: a sheet in free fall would test no contact. */
    double press = 0.0;
    for (long k = 0; k < steps; k += 20) {
        ck_ok(w, ws_world_step_n(w, steps - k < 20 ? steps - k : 20));
        ws_vec3 f;
        ck_ok(w, ws_web_get_body_force(w, web, box, &f, NULL));
        press = fmax(press, -f.z);
    }
    ck_assert_msg(press > 0.0, "the sheet never pressed on the box");
    uint64_t h = 0;
    ck_ok(w, ws_world_get_state_hash(w, &h));
    if (r->reruns)
        *r->reruns = w->search_reruns;
    if (r->narrow_reruns)
        *r->narrow_reruns = w->narrow_reruns;
    if (r->full) {
        ws_world_stats st;
        ck_ok(w, ws_world_get_stats(w, &st));
        *r->full = st.full_detections;
    }
    ws_world_destroy(w);
    if (enqueued)
        *enqueued = calls;
    return h;
}

static long sheet_steps(void)
{
    /* The sheet lands after 25 ms (3 mm at g) and drapes for 0.18 s; under WS_TEST_SHORT
     * (sanitizers, valgrind) for 5 ms after it lands. */
    return short_run() ? 120 : 800;
}

/* The sheet r's state hash on one worker after `steps` steps, checked against that on 2 to
 * `most` workers (each the same to the bit; `what` names the case in a failure). */
static uint64_t workers_agree(sheet_run r, long steps, int most, const char *what)
{
    r.workers = 1;
    const uint64_t one = sheet_hash(&r, steps, NULL);
    for (int k = 2; k <= most; k++) {
        r.workers = k;
        const uint64_t h = sheet_hash(&r, steps, NULL);
        ck_assert_msg(h == one, "%s, %d workers: state hash 0x%016llx, 1 worker 0x%016llx", what, k,
                      (unsigned long long)h, (unsigned long long)one);
    }
    return one;
}

/* The sheet r on two host schedulers (the pieces last first on 3 workers, then each on a
 * thread of its own on 4): the state hash `one` both times, and the host called. Returns how
 * many tasks the first got. */
static int hosts_agree(sheet_run r, long steps, uint64_t one)
{
    int calls = 0;
    r.workers = 3;
    r.host = 1;
    uint64_t h = sheet_hash(&r, steps, &calls);
    ck_assert_msg(h == one, "reverse scheduler: 0x%016llx, 1 worker 0x%016llx",
                  (unsigned long long)h, (unsigned long long)one);
    ck_assert_msg(calls > 0, "the host's scheduler was never called");
    r.workers = 4;
    r.host = 2;
    h = sheet_hash(&r, steps, NULL);
    ck_assert_msg(h == one, "threaded scheduler: 0x%016llx, 1 worker 0x%016llx",
                  (unsigned long long)h, (unsigned long long)one);
    return calls;
}

START_TEST(test_sheet_same_for_any_workers)
{
    const long steps = sheet_steps();
    sheet_run r = {1, 0, WS_LAW_LINEAR_VISCOELASTIC, 0, NULL, 0, 0, NULL, NULL, 0, 0, 0};
    const uint64_t one = workers_agree(r, steps, short_run() ? 2 : 4, "sheet");
    hosts_agree(r, steps, one);
    /* The search of node candidates in pieces, each piece's list given little room: the
     * pieces that run out are searched again on the world's thread, and the list is the
     * same. */
    uint64_t reruns = 0;
    r = (sheet_run){2, 0, WS_LAW_LINEAR_VISCOELASTIC, 1, &reruns, 0, 0, NULL, NULL, 0, 0, 0};
    uint64_t h = sheet_hash(&r, steps, NULL);
    ck_assert_msg(h == one, "pieces searched again: 0x%016llx, 1 worker 0x%016llx",
                  (unsigned long long)h, (unsigned long long)one);
    ck_assert_msg(reruns > 0, "no piece of a search ran out of room");
    report("workers: sheet, %ld steps: 0x%016llx for 1-%d workers, both schedulers and %llu "
           "pieces of searches run again",
           steps, (unsigned long long)one, short_run() ? 2 : 4, (unsigned long long)reruns);
}
END_TEST

/* A web swept in one lane (a grid of one block, or a mesh web) leaves a worker free: with
 * workers the body contacts run beside it, a piece of them beside each sub-step, and a full
 * detection's narrow phase beside the first. A sheet of one block dropped onto a box that
 * lands on another (full detection every 5th step): on 1, 2 and 3 workers and both host
 * schedulers, the state hash is the same to the bit, and the host's scheduler gets the body
 * part (a law not of film form keeps its lane on the stepping thread: test_sheet_law_with_history). */
START_TEST(test_bodies_beside_one_lane)
{
    const long steps = sheet_steps();
    sheet_run r = {1, 0, WS_LAW_LINEAR_VISCOELASTIC, 0, NULL, 5, 0, NULL, NULL, 0, 1, 0};
    const uint64_t one = workers_agree(r, steps, 3, "one lane");
    const int calls = hosts_agree(r, steps, one);
    report("workers: one-lane sheet on two boxes, %ld steps: 0x%016llx for 1-3 workers and "
           "both schedulers (%d tasks to the host)",
           steps, (unsigned long long)one, calls);
}
END_TEST

/* The bodies' full detection: its narrow phase runs beside the film's first sub-step on
 * workers, with the body contacts. Every fifth step (as on the reference case after 0.5 s),
 * on 1, 2 and 3 workers, the state hash is the same to the bit; and with the room of the
 * narrow phase beside the film made tight, so that it runs out and runs again on the world's
 * thread, too. */
START_TEST(test_detection_beside_the_film)
{
    const long steps = sheet_steps();
    uint64_t full = 0, reruns = 0;
    sheet_run r = {1, 0, WS_LAW_LINEAR_VISCOELASTIC, 0, NULL, 5, 0, NULL, &full, 0, 0, 0};
    const uint64_t one = workers_agree(r, steps, 3, "a full detection every 5th step");
    /* ceil(steps / 5) full detections, the first of them at step 0. */
    ck_assert_msg(full == (uint64_t)(steps + 4) / 5, "%llu full detections in %ld steps",
                  (unsigned long long)full, steps);
    r = (sheet_run){2, 0, WS_LAW_LINEAR_VISCOELASTIC, 0, NULL, 5, 1, &reruns, NULL, 0, 0, 0};
    const uint64_t h = sheet_hash(&r, steps, NULL);
    ck_assert_msg(h == one, "narrow phases run again: 0x%016llx, 1 worker 0x%016llx",
                  (unsigned long long)h, (unsigned long long)one);
    ck_assert_msg(reruns > 0, "no narrow phase beside the film ran out of room");
    report("workers: sheet, full detection every 5th step (%llu), %ld steps: 0x%016llx for 1-3 "
           "workers, %llu narrow phases run again",
           (unsigned long long)full, steps, (unsigned long long)one, (unsigned long long)reruns);
}
END_TEST

/* A mesh web is swept in lanes of rows of WS_WEB_MESH_ROW nodes, its springs' forces computed
 * in pieces first and gathered node by node in spring order: the sheet made again as a mesh
 * (1920 nodes: 30 rows, 5 blocks) gives one state hash on 1 to 4 workers and both host
 * schedulers. */
START_TEST(test_mesh_same_for_any_workers)
{
    const long steps = sheet_steps();
    sheet_run r = {1, 0, WS_LAW_LINEAR_VISCOELASTIC, 0, NULL, 5, 0, NULL, NULL, 0, 0, 1};
    const uint64_t one = workers_agree(r, steps, 4, "mesh");
    const int calls = hosts_agree(r, steps, one);
    /* The mesh is swept in lanes at all: two blocks or more, laws of film form. */
    ws_world_def d;
    ws_world_def_init(&d);
    ws_body_id box;
    ws_web_id web;
    ws_world *w = sheet_world(&d, &r, &box, &web);
    uint32_t slot;
    ck_assert_int_eq(ws_lookup_web(w, web, &slot), WS_OK);
    ck_assert_uint_eq(ws_web_rows(w->webs[slot]), 30);
    ck_assert_uint_eq(ws_web_block_count(w->webs[slot]), 5);
    ck_assert(ws_web_sweep_parallel(w->webs[slot]));
    ws_world_destroy(w);
    report("workers: mesh sheet, %ld steps: 0x%016llx for 1-4 workers and both schedulers "
           "(%d tasks to the host)",
           steps, (unsigned long long)one, calls);
}
END_TEST

/* A mesh web's springs, computed in pieces on vectors (rows of springs on contiguous loads, the
 * rest gathered by index; a law not of the film form one by one) and gathered node by node,
 * give each node the force the springs scattered one by one in spring order give, to the bit
 * (memcmp): the same terms in the same order. 800 nodes at random, 40 rows of 19 springs end to
 * end, 600 springs between nodes at random, of three kinds (linear viscoelastic, the film's
 * tension and compression law, and a cubic law, which is not of the film form) with
 * stiffness scales; two springs broken and one whose ends coincide (neither pulls), random
 * velocities; the springs in three pieces. */
START_TEST(test_mesh_gather_is_the_scatter)
{
    ws_world_def d;
    ws_world_def_init(&d);
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    ws_law_id law[3];
    for (int k = 0; k < 3; k++) {
        ws_law_def ld;
        ws_law_def_init(&ld);
        ld.type = k == 2   ? WS_LAW_CUBIC_ELASTIC
                  : k == 1 ? WS_LAW_TENSION_COMPRESSION
                           : WS_LAW_LINEAR_VISCOELASTIC;
        ld.stiffness = 200.0 + 50.0 * k;
        ld.damping = k == 2 ? 0.0 : 0.05;
        if (k == 1)
            ld.compression_stiffness = 10.0;
        if (k == 2)
            ld.cubic_stiffness = 2e3;
        ck_ok(w, ws_law_create(w, &ld, &law[k]));
    }
    enum { N = 800, ROWS = 40, RUN = 19, RANDOM = 600, NS = ROWS * RUN + RANDOM };
    static double pos[3 * N], mass[N], scale[NS];
    static uint32_t spr[2 * NS];
    static uint8_t kind[NS];
    srand(7);
    for (int i = 0; i < 3 * N; i++)
        pos[i] = (double)rand() / RAND_MAX;
    for (int i = 0; i < N; i++)
        mass[i] = 1e-3 * (0.5 + (double)rand() / RAND_MAX);
    for (int s = 0; s < NS; s++) {
        const int row = s / RUN, i = s % RUN;
        uint32_t a = (uint32_t)(row * (RUN + 1) + i), b = a + 1;
        if (s >= ROWS * RUN) {
            a = (uint32_t)(rand() % N);
            b = (uint32_t)((a + 1 + (uint32_t)(rand() % (N - 1))) % N);
        }
        spr[2 * s] = a;
        spr[2 * s + 1] = b;
        kind[s] = (uint8_t)(s < ROWS * RUN ? (row % 2) : (s % 3));
        scale[s] = 0.5 + (double)rand() / RAND_MAX;
    }
    /* Spring 5's ends coincide (its rest length set, as its ends give none). */
    for (int c = 0; c < 3; c++)
        pos[3 * spr[11] + c] = pos[3 * spr[10] + c];
    static double rest[NS];
    for (int s = 0; s < NS; s++) {
        const double *a = pos + 3 * spr[2 * s], *b = pos + 3 * spr[2 * s + 1];
        const double l = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                              (b[2] - a[2]) * (b[2] - a[2]));
        rest[s] = l > 0.0 ? 0.9 * l : 0.01;
    }
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.law = law[0];
    wd.law_cross = law[1];
    wd.law_shear = law[2];
    wd.node_damping = 1e-3;
    wd.rupture_strain = 10.0;
    ws_web_mesh_def md;
    ws_web_mesh_def_init(&md);
    md.positions = pos;
    md.node_count = N;
    md.node_masses = mass;
    md.springs = spr;
    md.spring_count = NS;
    md.kinds = kind;
    md.rest_lengths = rest;
    md.stiffness_scales = scale;
    ws_web_id id;
    ck_ok(w, ws_web_create_mesh(w, &wd, &md, &id));
    uint32_t slot;
    ck_assert_int_eq(ws_lookup_web(w, id, &slot), WS_OK);
    ws_web *web = w->webs[slot];
    web->broken[3] = web->broken[ROWS * RUN + 7] = 1;
    web->nbroken = 2;
    const ws_nodes3 x = web->x[0], v = web->v[0];
    for (uint32_t i = 0; i < N; i++) {
        v.x[i] = (double)rand() / RAND_MAX - 0.5;
        v.y[i] = (double)rand() / RAND_MAX - 0.5;
        v.z[i] = (double)rand() / RAND_MAX - 0.5;
    }
    ws_web_sweep_laws(web, (v3){0.0, 0.0, -9.81}, 0.0, 0.0);
    ck_assert_ptr_null(web->form[0].gen);
    ck_assert_ptr_null(web->form[1].gen);
    ck_assert_ptr_nonnull(web->form[2].gen);
    ws_web_mesh_springs(web, x, v, 0, 333);
    ws_web_mesh_springs(web, x, v, 333, 1000);
    ws_web_mesh_springs(web, x, v, 1000, NS);
    ws_web_mesh_gather(web, v, 0, N);
    static double got[3 * N], ref[3 * N];
    for (uint32_t i = 0; i < N; i++) {
        got[3 * i] = web->f.x[i];
        got[3 * i + 1] = web->f.y[i];
        got[3 * i + 2] = web->f.z[i];
        const v3 b = base_force(web, v, i);
        ref[3 * i] = b.x;
        ref[3 * i + 1] = b.y;
        ref[3 * i + 2] = b.z;
    }
    int pulls = 0;
    for (uint32_t s = 0; s < NS; s++) {
        v3 fu;
        if (!spring_force(web, x, v, s, &fu))
            continue;
        pulls++;
        const uint32_t a = web->sa[s], b = web->sb[s];
        ref[3 * a] += fu.x;
        ref[3 * a + 1] += fu.y;
        ref[3 * a + 2] += fu.z;
        ref[3 * b] += -fu.x;
        ref[3 * b + 1] += -fu.y;
        ref[3 * b + 2] += -fu.z;
    }
    ck_assert_int_eq(pulls, NS - 3);
    ck_assert_int_eq(web->law_failed, 0);
    int differ = 0;
    for (int i = 0; i < 3 * N; i++)
        differ += memcmp(&got[i], &ref[i], sizeof(double)) != 0;
    ck_assert_msg(differ == 0, "%d of %d force components differ from the scatter's", differ,
                  3 * N);
    ws_world_destroy(w);
    report("workers: mesh gather, %d nodes, %d springs (%d pulling): the scatter's forces to "
           "the bit",
           N, NS, pulls);
}
END_TEST

/* A linear spring's law that fails while *user is not 0. */
static int failing_law(void *user, int dim, const double *u, const double *ud, double t,
                       double *F, double *dFdu, double *dFdud)
{
    (void)ud, (void)t, (void)dFdud;
    for (int i = 0; i < dim; i++) {
        F[i] = 10.0 * u[i];
        dFdu[i * dim + i] = 10.0;
    }
    return *(int *)user;
}

/* On workers the body contacts run beside the film's first sub-step, and the elements and the
 * bodies' stable-step check after the film: a step that an element's law refuses there has
 * swept the film already, and must still leave the world as it was. The sheet on 2 workers
 * with a soft spring from the world to the box, whose law fails at steps 80 and 81 (the sheet
 * lands at step 65 and lifts off at 105: contacts, runs, searches): each refused step leaves the state hash as it
 * was, and the world then steps on to the hash of a twin that was never refused, to the bit
 * (the film's contact cache, lists and anchors undone too). */
START_TEST(test_refused_after_the_film)
{
    const long steps = short_run() ? 120 : 400, fail_at = 80;
    uint64_t h[2];
    long refused = 0;
    for (int twin = 0; twin < 2; twin++) {
        ws_world_def d;
        ws_world_def_init(&d);
        d.dt = 2.5e-4;
        d.worker_count = 2;
        const sheet_run r = {2, 0, WS_LAW_LINEAR_VISCOELASTIC, 0, NULL, 0, 0, NULL, NULL, 0, 0, 0};
        ws_body_id box;
        ws_web_id web;
        ws_world *w = sheet_world(&d, &r, &box, &web);
        int fail = 0;
        ws_law_def ld;
        ws_law_def_init(&ld);
        ld.type = WS_LAW_USER;
        ld.dim = 3;
        ld.stiffness = 10.0;
        ld.user_fn = failing_law;
        ld.user_data = &fail;
        ws_law_id law;
        ck_ok(w, ws_law_create(w, &ld, &law));
        ws_element_def ed;
        ws_element_def_init(&ed);
        ed.type = WS_ELEMENT_LINEAR_SPRING;
        ed.body2 = box;
        ed.law = law;
        ed.point1 = (ws_vec3){0.0, 0.0, 0.15};
        ws_element_id e;
        ck_ok(w, ws_element_create(w, &ed, &e));
        ck_ok(w, ws_world_step_n(w, fail_at));
        if (twin == 1) {
            uint64_t before, after;
            ck_ok(w, ws_world_get_state_hash(w, &before));
            fail = 1;
            for (int k = 0; k < 2; k++) {
                ck_assert_int_eq(ws_world_step(w), WS_ERR_CALLBACK);
                ck_ok(w, ws_world_get_state_hash(w, &after));
                ck_assert_msg(after == before, "refused step %d changed the state hash", k);
                refused++;
            }
            fail = 0;
        }
        /* The film touches the box after the refused steps. */
        double press = 0.0;
        for (long k = fail_at; k < steps; k++) {
            ck_ok(w, ws_world_step(w));
            ws_vec3 f;
            ck_ok(w, ws_web_get_body_force(w, web, box, &f, NULL));
            press = fmax(press, -f.z);
        }
        ck_assert_msg(press > 0.0, "the sheet never pressed on the box");
        ck_ok(w, ws_world_get_state_hash(w, &h[twin]));
        ws_world_destroy(w);
    }
    ck_assert_int_eq(refused, 2);
    ck_assert_msg(h[1] == h[0], "refused twice: 0x%016llx, never: 0x%016llx",
                  (unsigned long long)h[1], (unsigned long long)h[0]);
}
END_TEST

START_TEST(test_sheet_law_with_history)
{
    /* A law that is not of the film form (cubic: evaluated spring by spring, as a law with
     * history or a user's function would be) sweeps in one lane whatever the workers: the
     * same hash, and the host's scheduler never called. */
    const long steps = short_run() ? 120 : 500;
    sheet_run r = {1, 0, WS_LAW_CUBIC_ELASTIC, 0, NULL, 0, 0, NULL, NULL, 0, 0, 0};
    const uint64_t one = sheet_hash(&r, steps, NULL);
    int calls = 0;
    r = (sheet_run){2, 1, WS_LAW_CUBIC_ELASTIC, 0, NULL, 0, 0, NULL, NULL, 0, 0, 0};
    ck_assert(sheet_hash(&r, steps, &calls) == one);
    ck_assert_int_eq(calls, 0);
    if (!short_run()) {
        r = (sheet_run){2, 0, WS_LAW_CUBIC_ELASTIC, 0, NULL, 0, 0, NULL, NULL, 0, 0, 0};
        ck_assert(sheet_hash(&r, steps, NULL) == one);
    }
}
END_TEST

/* The implicit film's solve runs its passes over the film in blocks of rows, and its coarse
 * levels' sweeps in chunks of rows of two colours, on the workers; each node's sums are taken
 * in one order whoever runs them, and the blocks' and rows' sums (the dot products, the
 * bodies' loads) are added in block order: the same state to the bit for any number of
 * workers and either scheduler. The sheet at the real film's mass drapes over the box, which
 * is an unknown of the film's solve, nested in the multigrid. A law not of the film form
 * (cubic) keeps the springs' laws on the stepping thread and gives the same bits too. */
START_TEST(test_implicit_same_for_any_workers)
{
    /* 30 ms (120 steps): the sheet lands and drapes; under WS_TEST_SHORT 7.5 ms (30 steps),
     * past its landing, the film form's law on 2 workers and the reverse scheduler alone. */
    const int shorter = short_run();
    const long steps = shorter ? 30 : 120;
    for (int law = 0; law < 2; law++) {
        const int type = law ? WS_LAW_CUBIC_ELASTIC : WS_LAW_LINEAR_VISCOELASTIC;
        sheet_run r = {1, 0, type, 0, NULL, 0, 0, NULL, NULL, 1, 0, 0};
        const uint64_t one = workers_agree(r, steps, shorter ? 2 : 3, law ? "cubic" : "film");
        if (law && shorter)
            continue;
        int calls = 0;
        r = (sheet_run){3, 1, type, 0, NULL, 0, 0, NULL, NULL, 1, 0, 0};
        uint64_t h = sheet_hash(&r, steps, &calls);
        ck_assert_msg(h == one, "law %d, reverse scheduler: 0x%016llx, 1 worker 0x%016llx", type,
                      (unsigned long long)h, (unsigned long long)one);
        ck_assert_msg(calls > 0, "the host's scheduler was never called");
        if (!shorter) {
            r = (sheet_run){2, 2, type, 0, NULL, 0, 0, NULL, NULL, 1, 0, 0};
            h = sheet_hash(&r, steps, NULL);
            ck_assert_msg(h == one, "law %d, threaded scheduler: 0x%016llx, 1 worker 0x%016llx",
                          type, (unsigned long long)h, (unsigned long long)one);
        }
        report("workers: implicit sheet (law %d), %ld steps: 0x%016llx for 1-%d workers and "
               "the host's schedulers",
               type, steps, (unsigned long long)one, shorter ? 2 : 3);
    }
}
END_TEST

START_TEST(test_oom_in_a_parallel_step)
{
    /* Every allocation of the first steps of a sheet on 2 workers fails in turn (the lanes'
     * scratch among them): each failure is WS_ERR_OUT_OF_MEMORY and undoes the step, and
     * after the world is gone every block was freed with the size it was allocated with. */
    test_alloc a = {0};
    a.allocs_left = -1;
    a.track = 1;
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = 2.5e-4;
    d.worker_count = 2;
    test_alloc_install(&d, &a);
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    add_ground(w, 2.0, no_material());
    add_box(w, 0.4, 0.3, 0.3, 20.0, (ws_vec3){0.0, 0.0, 0.15}, no_material(), "box");
    ws_law_id law;
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_LINEAR_ELASTIC;
    ld.stiffness = 200.0;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = 1e-3;
    wd.law = wd.law_cross = law;
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = 48;
    sd.ny = 40;
    sd.spacing_x = sd.spacing_y = 0.0125;
    sd.origin = (ws_vec3){-0.2975, -0.24375, 0.30};
    ws_web_id web;
    ck_ok(w, ws_web_create_sheet(w, &wd, &sd, &web));
    ck_ok(w, ws_web_set_substeps(w, web, 8)); /* half the stable sub-step: 6 would do */
    long failures = 0, n = 0;
    for (; n < 2000; n++) {
        a.allocs_left = n;
        ws_status st = ws_world_step(w);
        if (st == WS_OK)
            break;
        ck_assert_msg(st == WS_ERR_OUT_OF_MEMORY, "allocation %ld failed: status %d, %s", n,
                      (int)st, ws_world_last_error(w));
        failures++;
    }
    a.allocs_left = -1;
    ck_assert_msg(n < 2000, "the step never had enough memory");
    ck_assert_msg(failures > 0, "no allocation failed: the test tested nothing");
    ck_ok(w, ws_world_step_n(w, 20)); /* and steps on */
    ws_world_destroy(w);
    ck_assert_msg(a.size_errors == 0, "%ld frees with the wrong size, first: %s", a.size_errors,
                  a.size_error);
    ck_assert_msg(a.live == 0 && a.bytes == 0, "%ld blocks and %lld bytes left", a.live, a.bytes);
    test_alloc_done(&a);
}
END_TEST

START_TEST(test_bad_worker_defs)
{
    ws_world_def d;
    ws_world *w = NULL;
    ws_world_def_init(&d);
    ck_assert_uint_eq(d.worker_count, 1);
    d.worker_count = 0;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_ERR_INVALID_ARGUMENT);
    d.worker_count = WS_MAX_WORKERS + 1;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_ERR_INVALID_ARGUMENT);
    d.worker_count = 2;
    d.enqueue_task = enqueue_reverse; /* without its finish */
    ck_assert_int_eq(ws_world_create(&d, &w), WS_ERR_INVALID_ARGUMENT);
    ck_assert_ptr_null(w);
    d.enqueue_task = NULL;
    d.worker_count = WS_MAX_WORKERS;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    ws_world_destroy(w); /* its threads joined */
}
END_TEST

/* ---- the world's own threads, directly ---- */

/* What a task's items recorded: how often each ran, and on which worker. */
typedef struct pool_probe {
    atomic_int runs[64];
    atomic_uint worker[64];
    atomic_int bad_range;
    uint32_t workers;
} pool_probe;

static void probe_items(int32_t start, int32_t end, uint32_t worker, void *ctx)
{
    pool_probe *P = ctx;
    if (end != start + 1 || worker >= P->workers)
        atomic_fetch_add(&P->bad_range, 1);
    for (int32_t i = start; i < end; i++) {
        atomic_fetch_add(&P->runs[i], 1);
        atomic_store(&P->worker[i], worker);
    }
}

/* Every item of every task runs exactly once, on a worker below the pool's count, one item a
 * call, whatever the task's size: 20000 tasks back to back (a thread that wakes late for one
 * must not take an item of the next), of 1 to 48 items (more than the pool was made for: then
 * all on the caller), 0 to 3 of them shared (no worker's own share, up to all of them). The bookkeeping of each task is exact, so any miss is a failure. And the
 * pool is made and joined with its bytes back to zero. */
START_TEST(test_pool_runs_each_item_once)
{
    ws_mem mem;
    ws_mem_init(&mem, NULL);
    const uint32_t threads = 3, cap = 32;
    ws_pool *pool = ws_pool_create(&mem, threads, (int32_t)cap);
    ck_assert_ptr_nonnull(pool);
    pool_probe *P = calloc(1, sizeof *P);
    ck_assert_ptr_nonnull(P);
    P->workers = threads + 1;
    const int tasks = short_run() ? 2000 : 20000;
    long on_threads = 0;
    for (int t = 0; t < tasks; t++) {
        const int32_t count = 1 + (int32_t)((t * 7919u) % 48u);
        for (int32_t i = 0; i < count; i++)
            atomic_store(&P->runs[i], 0);
        const int32_t shared = (int32_t)((t * 31u) % 4u) < count ? (int32_t)((t * 31u) % 4u)
                                                                  : count;
        ws_pool_run(pool, probe_items, count, shared, P);
        for (int32_t i = 0; i < count; i++) {
            if (atomic_load(&P->runs[i]) != 1)
                ck_abort_msg("task %d of %d items: item %d ran %d times", t, count, i,
                             atomic_load(&P->runs[i]));
            on_threads += atomic_load(&P->worker[i]) != 0;
            if (count > (int32_t)cap && atomic_load(&P->worker[i]) != 0)
                ck_abort_msg("task %d of %d items, more than %u: item %d on worker %u", t, count,
                             cap, i, atomic_load(&P->worker[i]));
        }
    }
    ck_assert_int_eq(atomic_load(&P->bad_range), 0);
    report("pool: %d tasks, %ld items on the threads", tasks, on_threads);
    ws_pool_destroy(&mem, pool);
    ck_assert_uint_eq(mem.in_use, 0);
    free(P);
}
END_TEST

int main(void)
{
    (void)tilt_run;
    Suite *s = suite_create("workers");
    add_case(s, "wrapped_same_for_any_workers", test_wrapped_same_for_any_workers, 300);
    add_case(s, "sheet_same_for_any_workers", test_sheet_same_for_any_workers, 300);
    add_case(s, "detection_beside_the_film", test_detection_beside_the_film, 300);
    add_case(s, "bodies_beside_one_lane", test_bodies_beside_one_lane, 300);
    add_case(s, "mesh_same_for_any_workers", test_mesh_same_for_any_workers, 300);
    add_case(s, "mesh_gather_is_the_scatter", test_mesh_gather_is_the_scatter, 60);
    add_case(s, "refused_after_the_film", test_refused_after_the_film, 300);
    add_case(s, "sheet_law_with_history", test_sheet_law_with_history, 300);
    add_case(s, "implicit_same_for_any_workers", test_implicit_same_for_any_workers, 300);
    add_case(s, "oom_in_a_parallel_step", test_oom_in_a_parallel_step, 300);
    add_case(s, "bad_worker_defs", test_bad_worker_defs, 60);
    add_case(s, "pool_runs_each_item_once", test_pool_runs_each_item_once, 120);
    return run_suite(s);
}
