/* Shared helpers of the Check suites: scene builders, a counting/failing allocator, runner. */
#ifndef WS_TEST_HELPERS_H
#define WS_TEST_HELPERS_H

#include <check.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <wrapsim/wrapsim.h>

#define G0 9.81

/* Assert a status with the world's last error in the message. */
#define ck_ok(w, call)                                                                            \
    do {                                                                                          \
        ws_status s_ = (call);                                                                    \
        ck_assert_msg(s_ == WS_OK, "%s -> %s (%s)", #call, ws_status_string(s_),                  \
                      ws_world_last_error(w));                                                    \
    } while (0)

/* A counting allocator that can be told to fail after N allocations. With `track` set it also
 * records every live block's size and checks the size the library passes to each free and each
 * realloc (as the old size) against it, as a sized or pool allocator would need: mismatches are
 * counted in size_errors, the first described in size_error. Call test_alloc_done() after the
 * world is gone to release the records. */
typedef struct ta_block {
    void *p;
    size_t n;
} ta_block;

typedef struct test_alloc {
    long allocs_left; /* < 0: never fail */
    long live;        /* blocks alive */
    long long bytes;  /* bytes alive by the sizes the library reports */
    int track;        /* 1: record sizes and check frees and reallocs */
    ta_block *blocks; /* live blocks (track) */
    size_t nblocks, capblocks;
    long size_errors;
    char size_error[160];
} test_alloc;

static inline ta_block *ta_find(test_alloc *a, void *p)
{
    for (size_t i = a->nblocks; i-- > 0;)
        if (a->blocks[i].p == p)
            return &a->blocks[i];
    return NULL;
}

static inline void ta_size_error(test_alloc *a, const char *what, void *p, size_t given,
                                 size_t real)
{
    if (a->size_errors++ == 0)
        snprintf(a->size_error, sizeof a->size_error, "%s of %p with %zu bytes, allocated %zu",
                 what, p, given, real);
}

static inline void ta_record(test_alloc *a, void *p, size_t n)
{
    if (a->nblocks == a->capblocks) {
        size_t cap = a->capblocks ? 2 * a->capblocks : 256;
        ta_block *b = realloc(a->blocks, cap * sizeof *b);
        if (!b)
            abort(); /* the test's own bookkeeping, not the library's */
        a->blocks = b;
        a->capblocks = cap;
    }
    a->blocks[a->nblocks].p = p;
    a->blocks[a->nblocks].n = n;
    a->nblocks++;
}

/* Check the size given for block p; with `drop`, forget the block. */
static inline void ta_check(test_alloc *a, const char *what, void *p, size_t given, int drop)
{
    ta_block *b = ta_find(a, p);
    if (!b) {
        ta_size_error(a, what, p, given, 0);
        return;
    }
    if (b->n != given)
        ta_size_error(a, what, p, given, b->n);
    if (drop)
        *b = a->blocks[--a->nblocks];
}

static inline void *ta_alloc(void *u, size_t n)
{
    test_alloc *a = u;
    if (a->allocs_left == 0)
        return NULL;
    if (a->allocs_left > 0)
        a->allocs_left--;
    void *p = malloc(n);
    if (p) {
        a->live++;
        a->bytes += (long long)n;
        if (a->track)
            ta_record(a, p, n);
    }
    return p;
}
static inline void *ta_realloc(void *u, void *p, size_t o, size_t n)
{
    test_alloc *a = u;
    if (a->track)
        ta_check(a, "realloc", p, o, 0);
    if (a->allocs_left == 0)
        return NULL;
    if (a->allocs_left > 0)
        a->allocs_left--;
    void *q = realloc(p, n);
    if (q) {
        a->bytes += (long long)n - (long long)o;
        if (a->track) {
            ta_block *b = ta_find(a, p);
            if (b) {
                b->p = q;
                b->n = n;
            } else {
                ta_record(a, q, n);
            }
        }
    }
    return q;
}
static inline void ta_free(void *u, void *p, size_t n)
{
    test_alloc *a = u;
    if (p) {
        a->live--;
        a->bytes -= (long long)n;
        if (a->track)
            ta_check(a, "free", p, n, 1);
    }
    free(p);
}
static inline void test_alloc_install(ws_world_def *d, test_alloc *a)
{
    d->allocator.alloc = ta_alloc;
    d->allocator.realloc = ta_realloc;
    d->allocator.free = ta_free;
    d->allocator.user = a;
}
static inline void test_alloc_done(test_alloc *a)
{
    free(a->blocks);
    a->blocks = NULL;
    a->nblocks = a->capblocks = 0;
}

static inline ws_world *new_world(double dt)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = dt;
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    return w;
}

/* A shape from a triangle mesh (v: nv points, t: nt triangles). */
static inline ws_status create_mesh(ws_world *w, const double *v, size_t nv, const uint32_t *t,
                                    size_t nt, ws_shape_id *out)
{
    ws_mesh_def d;
    ws_mesh_def_init(&d);
    d.vertices = v;
    d.vertex_count = nv;
    d.triangles = t;
    d.triangle_count = nt;
    return ws_shape_create_mesh(w, &d, out);
}

/* The unit cube [0,1]^3, wound counter-clockwise seen from outside. */
static const double cube_v[24] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0,
                                  0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
static const uint32_t cube_t[36] = {0, 2, 3, 0, 3, 1, /* -z */
                                    4, 5, 7, 4, 7, 6, /* +z */
                                    0, 1, 5, 0, 5, 4, /* -y */
                                    2, 6, 7, 2, 7, 3, /* +y */
                                    0, 4, 6, 0, 6, 2, /* -x */
                                    1, 3, 7, 1, 7, 5 /* +x */};

/* A static (kinematic) box whose top face is the plane z = 0, large in x and y. */
static inline ws_body_id add_ground(ws_world *w, double half, ws_material_id mat)
{
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 2 * half, 2 * half, 0.05, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = s;
    bd.material = mat;
    bd.position.z = -0.025;
    bd.name = "ground";
    ws_body_id id;
    ck_ok(w, ws_body_create(w, &bd, &id));
    return id;
}

/* A dynamic box of edge lengths lx, ly, lz and mass m with its bottom face at height z0. */
static inline ws_body_id add_box(ws_world *w, double lx, double ly, double lz, double m,
                                 ws_vec3 centre, ws_material_id mat, const char *name)
{
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, lx, ly, lz, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = s;
    bd.mass = m;
    bd.position = centre;
    bd.material = mat;
    bd.name = name;
    ws_body_id id;
    ck_ok(w, ws_body_create(w, &bd, &id));
    return id;
}

/* Hamilton product of Euler parameters: rotation b, then a. */
static inline ws_quat qmul(ws_quat a, ws_quat b)
{
    return (ws_quat){a.e0 * b.e0 - a.e1 * b.e1 - a.e2 * b.e2 - a.e3 * b.e3,
                     a.e0 * b.e1 + a.e1 * b.e0 + a.e2 * b.e3 - a.e3 * b.e2,
                     a.e0 * b.e2 - a.e1 * b.e3 + a.e2 * b.e0 + a.e3 * b.e1,
                     a.e0 * b.e3 + a.e1 * b.e2 - a.e2 * b.e1 + a.e3 * b.e0};
}

static inline ws_material_id no_material(void)
{
    ws_material_id m = {0};
    return m;
}

/* A measured value, printed as "[measured] ..." for tools/validation_report.py. */
static inline void report(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;
static inline void report(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    printf("[measured] ");
    vprintf(fmt, ap);
    printf("\n");
    fflush(stdout);
    va_end(ap);
}

/* Run the suite; CK_FORK=no is honoured (valgrind). Returns the process exit code. */
/* A test case of its own, with its own timeout (s), in suite s. */
static inline void add_case(Suite *s, const char *name, const TTest *t, double timeout)
{
    TCase *tc = tcase_create(name);
    tcase_set_timeout(tc, timeout);
    tcase_add_test(tc, t);
    suite_add_tcase(s, tc);
}

static inline int run_suite(Suite *s)
{
    SRunner *r = srunner_create(s);
    srunner_run_all(r, CK_NORMAL);
    int failed = srunner_ntests_failed(r);
    srunner_free(r);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}

#endif
