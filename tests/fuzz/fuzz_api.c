/* A libFuzzer target: the input bytes decode into a sequence of calls of the public API on one
 * world (shapes, bodies, drives, materials, laws, elements, webs, steps, read-outs), with
 * bounded arguments that include bad ones: stale, null and random ids, NaN, infinities, huge
 * values, destroy-then-use, an allocator that fails on a chosen allocation. The library must refuse
 * bad input with a status; the target aborts (a finding) when
 *   - a step returns WS_OK while a body's or a film node's state is not finite;
 *   - a call that failed (a step, or any call that changes the world) changed the state hash;
 *   - a block is freed or resized with another size than it was allocated with;
 *   - the world's statistics count other bytes in use than the allocator has handed out, or
 *     bytes are still allocated after ws_world_destroy();
 * and AddressSanitizer and UBSan report everything else. tests/fuzz/README.md says how to build
 * and run it. */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <wrapsim/wrapsim.h>

/* ---- the input ---- */

typedef struct reader {
    const uint8_t *p;
    size_t n;
} reader;

static uint8_t byte(reader *r)
{
    if (r->n == 0)
        return 0;
    r->n--;
    return *r->p++;
}

static unsigned pick(reader *r, unsigned n)
{
    return byte(r) % n;
}

static const double special[] = {
    0.0,      1.0,       -1.0,   0.5,   2.0,    1e-3,    1e-2,     0.1,     10.0,
    100.0,    1e3,       1e4,    1e5,   1e6,    1e9,     1e12,     -0.5,    -1e3,
    1e-6,     1e-9,      1e-300, 1e300, -1e300, DBL_MAX, -DBL_MAX, DBL_MIN, 5e-324,
    INFINITY, -INFINITY, NAN,    -0.0,  0.25,   2.5e-4,  0.3,      1e20,    -1e20,
};
#define N_SPECIAL (sizeof special / sizeof special[0])

/* Any double: mostly the special values and small multiples, sometimes 8 raw bytes. */
static double num(reader *r)
{
    unsigned b = byte(r);
    if (b < N_SPECIAL)
        return special[b];
    if (b < 248)
        return ((double)b - 140.0) / 16.0;
    uint64_t bits = 0;
    for (int i = 0; i < 8; i++)
        bits = bits << 8 | byte(r);
    double d;
    memcpy(&d, &bits, sizeof d);
    return d;
}

/* A value that is mostly sane: a byte scaled into [-4, 4) or [0, 8) (positive), and through
 * the last code point any double of num(). */
static double sane(reader *r)
{
    unsigned b = byte(r);
    if (b == 255)
        return num(r);
    return ((double)b - 128.0) / 32.0;
}

static double positive(reader *r)
{
    unsigned b = byte(r);
    if (b == 255)
        return num(r);
    return ((double)b + 1.0) / 32.0;
}

static int integer(reader *r, int lo, int hi)
{
    static const int bad[] = {0, -1, INT_MIN, INT_MAX, 100001, 1025};
    unsigned b = byte(r);
    if (b >= 250)
        return bad[b - 250];
    return lo + (int)(b % (unsigned)(hi - lo + 1));
}

static ws_vec3 vec(reader *r)
{
    ws_vec3 v = {sane(r), sane(r), sane(r)};
    return v;
}

/* ---- the allocator: sized blocks, counted, failing on request ---- */

typedef struct fuzz_alloc {
    long fail_in; /* < 0: never; 0: the next allocation or growth fails */
    long blocks;
    size_t bytes;
} fuzz_alloc;

/* Each block carries its size in front, so a free or resize with another size is caught. */
#define HEADER 16
/* Blocks beyond this are refused as if memory ran out: a huge but valid size (a sheet of 100001
 * x 12 nodes) then tests the out-of-memory paths instead of the machine, and every input stays
 * quick (the webs the decoder makes otherwise, 12 x 12 at most, need far less). */
#define MOST_BYTES ((size_t)1 << 20)

static void finding(const char *what)
{
    fprintf(stderr, "fuzz_api finding: %s\n", what);
    abort();
}

static int fail_now(fuzz_alloc *a)
{
    if (a->fail_in < 0)
        return 0;
    return a->fail_in-- == 0;
}

static void *fa_alloc(void *u, size_t n)
{
    fuzz_alloc *a = u;
    if (fail_now(a) || n > MOST_BYTES)
        return NULL;
    unsigned char *p = malloc(n + HEADER);
    if (!p)
        return NULL;
    memcpy(p, &n, sizeof n);
    a->blocks++;
    a->bytes += n;
    return p + HEADER;
}

static void *fa_realloc(void *u, void *ptr, size_t old, size_t n)
{
    fuzz_alloc *a = u;
    if (!ptr)
        return fa_alloc(u, n);
    unsigned char *p = (unsigned char *)ptr - HEADER;
    size_t had;
    memcpy(&had, p, sizeof had);
    if (had != old)
        finding("realloc with another old size than the block has");
    if (fail_now(a) || n > MOST_BYTES)
        return NULL;
    unsigned char *q = realloc(p, n + HEADER);
    if (!q)
        return NULL;
    memcpy(q, &n, sizeof n);
    a->bytes = a->bytes - old + n;
    return q + HEADER;
}

static void fa_free(void *u, void *ptr, size_t n)
{
    fuzz_alloc *a = u;
    if (!ptr)
        return;
    unsigned char *p = (unsigned char *)ptr - HEADER;
    size_t had;
    memcpy(&had, p, sizeof had);
    if (had != n)
        finding("free with another size than the block has");
    a->blocks--;
    a->bytes -= n;
    free(p);
}

/* ---- callbacks: pure functions of their arguments, failing or non-finite on request ---- */

/* What a callback does, chosen by the input: 0 well, 1 reports failure, 2 a NaN result. The
 * callbacks never call the library: the guard against calls from inside a step
 * (WS_ERR_IN_STEP) is tested case by case in tests/test_api.c (reentry_from_drive,
 * reentry_from_law). */
static const int modes[3] = {0, 1, 2};

static int drive_cb(void *user, double t, ws_pose *pose, ws_vec3 *v, ws_vec3 *w)
{
    int mode = *(const int *)user;
    if (mode == 1)
        return 1;
    double z = mode == 2 ? NAN : 0.01 * sin(t);
    pose->position = (ws_vec3){0.0, 0.0, z};
    pose->orientation = (ws_quat){1.0, 0.0, 0.0, 0.0};
    *v = (ws_vec3){0.0, 0.0, 0.01 * cos(t)};
    *w = (ws_vec3){0.0, 0.0, 0.0};
    return 0;
}

static int law_cb(void *user, int dim, const double *u, const double *ud, double t, double *f,
                  double *dfdu, double *dfdud)
{
    int mode = *(const int *)user;
    if (mode == 1)
        return 1;
    for (int i = 0; i < dim; i++) {
        f[i] = mode == 2 ? NAN : 100.0 * u[i] + 0.1 * ud[i];
        dfdu[i * dim + i] = 100.0;
        dfdud[i * dim + i] = 0.1;
    }
    return 0;
}

static int scale_cb(void *user, double t, double *factor)
{
    int mode = *(const int *)user;
    if (mode == 1)
        return 1;
    *factor = mode == 2 ? NAN : 0.5 + 0.5 * cos(t);
    return 0;
}

/* ---- the world and what lives in it ---- */

#define POOL 8

typedef struct fuzz {
    reader in;
    ws_world *w;
    fuzz_alloc alloc;
    ws_shape_id shapes[POOL];
    ws_body_id bodies[POOL];
    ws_material_id materials[POOL];
    ws_law_id laws[POOL];
    ws_element_id elements[POOL];
    ws_web_id webs[POOL];
    unsigned n_shapes, n_bodies, n_materials, n_laws, n_elements, n_webs;
    long work;                 /* what steps may still cost, in node sub-steps / 64 */
    int trace;                 /* FUZZ_API_TRACE set: say each call's status on stderr */
    long long untracked;       /* bytes the hook holds that the world's stats do not count */
    ws_load *load;             /* op_load's load, or NULL */
    fuzz_alloc load_alloc;     /* the load's own allocator */
    ws_loadtest_result result; /* a run's result (large for the stack) */
} fuzz;

/* An id from a pool of n ids (each a struct of one uint64_t): one made earlier (maybe destroyed
 * since), null, or random bits. */
static uint64_t pick_bits(fuzz *f, const void *pool, unsigned n)
{
    unsigned b = byte(&f->in);
    if (b < 200 && n > 0) {
        uint64_t bits;
        memcpy(&bits, (const unsigned char *)pool + (b % n) * sizeof(ws_body_id), sizeof bits);
        return bits;
    }
    if (b < 240)
        return 0;
    uint64_t x = 0;
    for (int i = 0; i < 8; i++)
        x = x << 8 | byte(&f->in);
    return x;
}

#define PICK(f, pool, n, type) ((type){pick_bits(f, (pool), (n))})
_Static_assert(sizeof(ws_shape_id) == 8 && sizeof(ws_body_id) == 8 && sizeof(ws_material_id) == 8 &&
                   sizeof(ws_law_id) == 8 && sizeof(ws_element_id) == 8 && sizeof(ws_web_id) == 8,
               "pick_bits reads the pools as arrays of 64-bit ids");
#define PUT(pool, n, id)                                                                           \
    do {                                                                                           \
        (pool)[(n) % POOL] = (id);                                                                 \
        (n)++;                                                                                     \
    } while (0)
#define COUNT(n) ((n) < POOL ? (n) : POOL)

static ws_shape_id pick_shape(fuzz *f)
{
    return PICK(f, f->shapes, COUNT(f->n_shapes), ws_shape_id);
}
static ws_body_id pick_body(fuzz *f)
{
    return PICK(f, f->bodies, COUNT(f->n_bodies), ws_body_id);
}
static ws_material_id pick_material(fuzz *f)
{
    return PICK(f, f->materials, COUNT(f->n_materials), ws_material_id);
}
static ws_law_id pick_law(fuzz *f)
{
    return PICK(f, f->laws, COUNT(f->n_laws), ws_law_id);
}
static ws_element_id pick_element(fuzz *f)
{
    return PICK(f, f->elements, COUNT(f->n_elements), ws_element_id);
}
static ws_web_id pick_web(fuzz *f)
{
    return PICK(f, f->webs, COUNT(f->n_webs), ws_web_id);
}

static int finite3(ws_vec3 v)
{
    return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
}

/* Every body's pose and velocities and every film node's position and velocity are finite. */
static void check_finite(fuzz *f)
{
    ws_body_id ids[64];
    size_t n = 0;
    ws_status s = ws_world_copy_body_ids(f->w, ids, 64, &n);
    if (s != WS_OK && s != WS_ERR_BUFFER_TOO_SMALL)
        finding("ws_world_copy_body_ids failed after a step");
    for (size_t i = 0; i < n && i < 64; i++) {
        ws_vec3 p, v, om;
        ws_quat q;
        if (ws_body_get_position(f->w, ids[i], &p) != WS_OK ||
            ws_body_get_velocity(f->w, ids[i], &v) != WS_OK ||
            ws_body_get_angular_velocity(f->w, ids[i], &om) != WS_OK ||
            ws_body_get_orientation(f->w, ids[i], &q) != WS_OK)
            finding("a listed body cannot be read");
        if (!finite3(p) || !finite3(v) || !finite3(om) ||
            !(isfinite(q.e0) && isfinite(q.e1) && isfinite(q.e2) && isfinite(q.e3)))
            finding("a step returned WS_OK with a non-finite body state");
    }
    for (unsigned k = 0; k < COUNT(f->n_webs); k++) {
        if (!ws_web_is_valid(f->w, f->webs[k]))
            continue;
        size_t count = 0;
        ws_web_copy_positions(f->w, f->webs[k], NULL, 0, &count);
        double *xyz = malloc(3 * count * sizeof *xyz + 1);
        double *vel = malloc(3 * count * sizeof *vel + 1);
        if (!xyz || !vel)
            abort();
        size_t got = 0;
        if (ws_web_copy_positions(f->w, f->webs[k], xyz, count, &got) != WS_OK ||
            ws_web_copy_velocities(f->w, f->webs[k], vel, count, &got) != WS_OK)
            finding("a live web cannot be read");
        for (size_t i = 0; i < 3 * count; i++)
            if (!isfinite(xyz[i]) || !isfinite(vel[i]))
                finding("a step returned WS_OK with a non-finite film node");
        free(xyz);
        free(vel);
    }
}

/* The world's count of bytes in use moves with the allocator's: what the stats leave out (the
 * world itself) stays the same from creation to destruction. */
static long long untracked_bytes(fuzz *f)
{
    ws_world_stats st;
    if (ws_world_get_stats(f->w, &st) != WS_OK)
        finding("ws_world_get_stats failed on a live world");
    return (long long)f->alloc.bytes - (long long)st.bytes_in_use;
}

static uint64_t state_hash(fuzz *f)
{
    uint64_t h = 0;
    if (ws_world_get_state_hash(f->w, &h) != WS_OK)
        finding("ws_world_get_state_hash failed on a live world");
    return h;
}

/* What a step costs: one, plus the node sub-steps of the webs (a web may ask 100000). */
static long step_cost(fuzz *f)
{
    long cost = 1;
    for (unsigned k = 0; k < COUNT(f->n_webs); k++) {
        ws_web_info info;
        if (ws_web_get_info(f->w, f->webs[k], &info) == WS_OK)
            cost += (long)info.node_count * info.substeps / 64;
    }
    return cost;
}

static void step(fuzz *f)
{
    long cost = step_cost(f);
    if (cost > f->work)
        return;
    f->work -= cost;
    uint64_t before = state_hash(f);
    ws_status s = ws_world_step(f->w);
    if (f->trace)
        fprintf(stderr, "  step: %s %s\n", ws_status_string(s), ws_world_last_error(f->w));
    if (s == WS_OK)
        check_finite(f);
    else if (state_hash(f) != before)
        finding("a failed step changed the state hash");
}

/* ---- the calls ---- */

static ws_status op_shape(fuzz *f)
{
    ws_shape_id id = {0};
    ws_status s;
    switch (pick(&f->in, 3)) {
    case 0:
        s = ws_shape_create_box(f->w, positive(&f->in), positive(&f->in), positive(&f->in), &id);
        break;
    case 1:
        s = ws_shape_create_cylinder(f->w, positive(&f->in), positive(&f->in),
                                     integer(&f->in, 3, 40), &id);
        break;
    default: {
        /* A unit cube, maybe spoiled: an index out of range, a NaN or merged vertex, a flipped
         * or missing triangle, NULL arrays. */
        double v[24] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
        uint32_t t[36] = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                          2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
        ws_mesh_def d;
        ws_mesh_def_init(&d);
        d.vertices = v;
        d.vertex_count = 8;
        d.triangles = t;
        d.triangle_count = 12;
        for (unsigned k = 0, n = pick(&f->in, 4); k < n; k++) {
            switch (pick(&f->in, 7)) {
            case 0:
                t[pick(&f->in, 36)] = byte(&f->in) < 128 ? 8 : UINT32_MAX;
                break;
            case 1:
                v[pick(&f->in, 24)] = num(&f->in);
                break;
            case 2: {
                unsigned i = pick(&f->in, 12);
                uint32_t x = t[3 * i + 1];
                t[3 * i + 1] = t[3 * i + 2];
                t[3 * i + 2] = x;
                break;
            }
            case 3:
                d.triangle_count = pick(&f->in, 12);
                break;
            case 4:
                d.vertex_count = pick(&f->in, 8);
                break;
            case 5:
                memcpy(v + 3 * pick(&f->in, 8), v + 3 * pick(&f->in, 8), 3 * sizeof *v);
                break;
            default:
                if (byte(&f->in) & 1)
                    d.vertices = NULL;
                else
                    d.triangles = NULL;
                break;
            }
        }
        s = ws_shape_create_mesh(f->w, &d, &id);
        break;
    }
    }
    if (s == WS_OK)
        PUT(f->shapes, f->n_shapes, id);
    return s;
}

static ws_status op_body(fuzz *f)
{
    ws_body_def d;
    ws_body_def_init(&d);
    d.type = byte(&f->in) & 1 ? WS_BODY_KINEMATIC : WS_BODY_DYNAMIC;
    if (byte(&f->in) == 255)
        d.type = (ws_body_type)7;
    d.shape = pick_shape(f);
    if (byte(&f->in) & 1)
        d.material = pick_material(f);
    if (byte(&f->in) & 1)
        d.mass = num(&f->in);
    if (byte(&f->in) & 1)
        d.density = num(&f->in);
    switch (pick(&f->in, 4)) {
    case 1:
        d.inertia.m[0] = num(&f->in);
        d.inertia.m[4] = num(&f->in);
        d.inertia.m[8] = num(&f->in);
        break;
    case 2:
        for (int i = 0; i < 9; i++)
            d.inertia.m[i] = sane(&f->in);
        break;
    default:
        break;
    }
    if (byte(&f->in) & 1)
        d.contact_layer = num(&f->in);
    d.position = vec(&f->in);
    if (byte(&f->in) & 1)
        d.orientation = (ws_quat){sane(&f->in), sane(&f->in), sane(&f->in), sane(&f->in)};
    if (byte(&f->in) & 1)
        d.velocity = vec(&f->in);
    if (byte(&f->in) & 1)
        d.angular_velocity = vec(&f->in);
    d.name = byte(&f->in) & 1 ? "body" : NULL;
    ws_body_id id;
    ws_status s = ws_body_create(f->w, &d, &id);
    if (s == WS_OK)
        PUT(f->bodies, f->n_bodies, id);
    return s;
}

static ws_status op_drive(fuzz *f)
{
    ws_drive_def d;
    ws_drive_def_init(&d);
    d.type = (ws_drive_type)pick(&f->in, 9);
    /* Any values, overflowing products included (-1e308 start times, DBL_MAX rates and
     * frequencies): the drive's checks refuse them, or the step checks its result. */
    d.start_time = sane(&f->in);
    d.ramp_time = fabs(sane(&f->in));
    d.axis = (ws_vec3){sane(&f->in), sane(&f->in), sane(&f->in)};
    d.point = (ws_vec3){sane(&f->in), sane(&f->in), sane(&f->in)};
    d.rate = sane(&f->in);
    d.max_angle = fabs(sane(&f->in));
    d.direction = (ws_vec3){sane(&f->in), sane(&f->in), sane(&f->in)};
    d.amplitude = sane(&f->in);
    d.frequency = fabs(sane(&f->in));
    d.phase = sane(&f->in);
    /* The platform tests' drives (pulse, impact, sweep; a table and a random history need
     * arrays and are refused without them). */
    d.stop_ramp_time = fabs(sane(&f->in));
    d.acceleration = sane(&f->in);
    d.hold_time = fabs(sane(&f->in));
    d.speed = sane(&f->in);
    d.duration = sane(&f->in);
    d.frequency_end = sane(&f->in);
    if (!finite3(d.axis) || !finite3(d.point) || !finite3(d.direction))
        d.axis = d.point = d.direction = (ws_vec3){1.0, 0.0, 0.0};
    if (d.type == WS_DRIVE_CALLBACK && byte(&f->in) != 0) {
        d.callback = drive_cb;
        d.callback_user = (void *)&modes[pick(&f->in, 3)];
    }
    return ws_body_set_drive(f->w, pick_body(f), &d);
}

static ws_status op_body_set(fuzz *f)
{
    ws_body_id b = pick_body(f);
    if (byte(&f->in) & 1) {
        ws_pose p = {vec(&f->in), {sane(&f->in), sane(&f->in), sane(&f->in), sane(&f->in)}};
        return ws_body_set_pose(f->w, b, byte(&f->in) ? &p : NULL);
    }
    ws_vec3 v = vec(&f->in), w = vec(&f->in);
    return ws_body_set_velocity(f->w, b, &v, byte(&f->in) ? &w : NULL);
}

static ws_status op_material(fuzz *f)
{
    if (byte(&f->in) & 1) {
        ws_material_def d;
        ws_material_def_init(&d);
        d.name = "material";
        ws_material_id id;
        ws_status s = ws_material_create(f->w, &d, &id);
        if (s == WS_OK)
            PUT(f->materials, f->n_materials, id);
        return s;
    }
    ws_contact_def c;
    ws_contact_def_init(&c);
    double *p[] = {&c.stiffness,     &c.damping,         &c.friction,
                   &c.friction_vlim, &c.stick_stiffness, &c.stick_damping};
    for (unsigned k = 0, n = pick(&f->in, 4); k < n; k++)
        *p[pick(&f->in, 6)] = num(&f->in);
    c.friction_model = (ws_friction_model)pick(&f->in, 3);
    if (byte(&f->in) & 1)
        return ws_world_set_default_contact(f->w, &c);
    return ws_world_set_contact(f->w, pick_material(f), pick_material(f), &c);
}

/* Law arrays live in the fuzz input's scratch: the largest is a 6 x 6 matrix. */
typedef struct law_arrays {
    double k[36], c[36], k3[6], strain[8], force[8], prony_k[17], prony_t[17], times[4], factors[4];
    ws_law_id terms[4];
} law_arrays;

static ws_status op_law(fuzz *f)
{
    static const int dims[] = {1, 3, 6, 1, 1, 3, 0, 2};
    law_arrays a;
    ws_law_def d;
    ws_law_def_init(&d);
    d.type = (ws_law_type)pick(&f->in, 12);
    d.dim = dims[pick(&f->in, 8)];
    int dim = d.dim >= 1 && d.dim <= 6 ? d.dim : 1;
    d.stiffness = positive(&f->in);
    if (byte(&f->in) & 1)
        d.compression_stiffness = num(&f->in);
    if (byte(&f->in) & 1)
        d.damping = num(&f->in);
    if (byte(&f->in) & 1)
        d.transition = num(&f->in);
    if (byte(&f->in) & 1)
        d.cubic_stiffness = num(&f->in);
    unsigned flags = byte(&f->in);
    if (flags & 1) {
        for (int i = 0; i < dim * dim; i++)
            a.k[i] = i % (dim + 1) == 0 ? positive(&f->in) : sane(&f->in) / 8.0;
        d.stiffness_matrix = a.k;
    }
    if (flags & 2) {
        for (int i = 0; i < dim * dim; i++)
            a.c[i] = i % (dim + 1) == 0 ? positive(&f->in) : sane(&f->in) / 8.0;
        d.damping_matrix = a.c;
    }
    if (flags & 4) {
        for (int i = 0; i < dim; i++)
            a.k3[i] = sane(&f->in);
        d.cubic_stiffnesses = a.k3;
    }
    if (d.type == WS_LAW_TABLE) {
        size_t n = pick(&f->in, 9);
        double x = -1.0, y = -10.0;
        for (size_t i = 0; i < n; i++) {
            x += byte(&f->in) == 0 ? 0.0 : positive(&f->in) / 8.0;
            y += sane(&f->in) + 2.0;
            a.strain[i] = x;
            a.force[i] = y;
        }
        d.table_strain = byte(&f->in) ? a.strain : NULL;
        d.table_force = a.force;
        d.table_count = n;
    }
    if (d.type == WS_LAW_STOP) {
        d.stop_low = byte(&f->in) & 1 ? sane(&f->in) / 4.0 : -INFINITY;
        d.stop_high = byte(&f->in) & 1 ? sane(&f->in) / 4.0 : INFINITY;
    }
    if (d.type == WS_LAW_RELAXATION) {
        size_t n = pick(&f->in, 18);
        for (size_t i = 0; i < n; i++) {
            a.prony_k[i] = positive(&f->in);
            a.prony_t[i] = positive(&f->in) / 16.0;
        }
        d.prony_stiffness = a.prony_k;
        d.prony_time = byte(&f->in) ? a.prony_t : NULL;
        d.prony_count = n;
    }
    if (d.type == WS_LAW_SUM || d.type == WS_LAW_SCALED) {
        /* Sums and scalings of any laws, sums and scalings included, nested as deep as the
         * input makes them: WS_LAW_MAX_HISTORY and WS_LAW_MAX_LEAVES refuse what is too big. */
        size_t n = pick(&f->in, 5);
        for (size_t i = 0; i < n; i++)
            a.terms[i] = pick_law(f);
        d.terms = a.terms;
        d.term_count = n;
        d.base = n > 0 ? a.terms[0] : pick_law(f);
        d.scale = byte(&f->in) & 1 ? num(&f->in) : 1.0;
        unsigned how = pick(&f->in, 3);
        if (how == 1) {
            size_t m = pick(&f->in, 5);
            for (size_t i = 0; i < m; i++) {
                a.times[i] = (double)i + (byte(&f->in) == 0 ? -2.0 : 0.0);
                a.factors[i] = sane(&f->in);
            }
            d.scale_times = a.times;
            d.scale_factors = a.factors;
            d.scale_count = m;
        } else if (how == 2) {
            d.scale_fn = scale_cb;
            d.scale_user = (void *)&modes[pick(&f->in, 3)];
        }
    }
    if (d.type == WS_LAW_USER && byte(&f->in) != 0) {
        d.user_fn = law_cb;
        d.user_data = (void *)&modes[pick(&f->in, 3)];
        d.user_flags = pick(&f->in, 4);
    }
    d.name = byte(&f->in) & 1 ? "law" : NULL;
    ws_law_id id;
    ws_status s = ws_law_create(f->w, &d, &id);
    if (s == WS_OK) {
        PUT(f->laws, f->n_laws, id);
    }
    return s;
}

static ws_status op_law_use(fuzz *f)
{
    ws_law_id id = pick_law(f);
    double u[6], ud[6], force[6], dfdu[36], dfdud[36], e;
    for (int i = 0; i < 6; i++) {
        u[i] = sane(&f->in);
        ud[i] = sane(&f->in);
    }
    switch (pick(&f->in, 4)) {
    case 0:
        ws_law_evaluate(f->w, id, u[0], ud[0], &force[0], &dfdu[0], NULL);
        ws_law_energy(f->w, id, u[1], &e);
        break;
    case 1: {
        ws_law_info info;
        ws_law_get_info(f->w, id, &info);
        size_t n = 0;
        if (ws_law_get_state_size(f->w, id, &n) != WS_OK || n > 4096)
            break;
        double *state = malloc((n + 1) * sizeof *state);
        if (!state)
            abort();
        if (ws_law_init_state(f->w, id, n ? state : NULL) == WS_OK) {
            double dt = byte(&f->in) & 1 ? num(&f->in) : 1e-3;
            ws_law_evaluate_state(f->w, id, state, u, ud, 0.5, dt, force, dfdu, dfdud);
            ws_law_commit_state(f->w, id, n ? state : NULL, u, ud, 0.5, dt);
            ws_law_energy_state(f->w, id, state, u, 0.5, &e);
        }
        free(state);
        break;
    }
    case 2:
        return ws_law_destroy(f->w, id);
    default:
        ws_law_evaluate_state(f->w, id, NULL, u, NULL, num(&f->in), num(&f->in), force, NULL,
                              dfdud);
        break;
    }
    return WS_OK;
}

static ws_status op_element(fuzz *f)
{
    if (byte(&f->in) < 64)
        return ws_element_destroy(f->w, pick_element(f));
    ws_element_def d;
    ws_element_def_init(&d);
    d.type = (ws_element_type)pick(&f->in, 5);
    d.formulation = (ws_element_formulation)pick(&f->in, 4);
    d.body1 = pick_body(f);
    d.body2 = pick_body(f);
    d.law = pick_law(f);
    d.point1 = vec(&f->in);
    d.point2 = vec(&f->in);
    if (byte(&f->in) & 1)
        d.frame1 = (ws_quat){sane(&f->in), sane(&f->in), sane(&f->in), sane(&f->in)};
    if (byte(&f->in) & 1)
        d.frame2 = (ws_quat){sane(&f->in), sane(&f->in), sane(&f->in), sane(&f->in)};
    d.global_attachment = byte(&f->in) & 1;
    if (byte(&f->in) & 1)
        d.rest_length = num(&f->in);
    ws_element_id id;
    ws_status s = ws_element_create(f->w, &d, &id);
    if (s == WS_OK)
        PUT(f->elements, f->n_elements, id);
    return s;
}

static void web_common(fuzz *f, ws_web_def *d)
{
    ws_web_def_init(d);
    d->node_mass = byte(&f->in) & 1 ? positive(&f->in) / 64.0 : 0.0;
    d->areal_density = byte(&f->in) & 1 ? positive(&f->in) / 64.0 : 0.0;
    if (byte(&f->in) & 1)
        d->contact_layer = num(&f->in);
    if (byte(&f->in) & 1)
        d->material = pick_material(f);
    if (byte(&f->in) & 1)
        d->node_damping = num(&f->in);
    d->law = pick_law(f);
    if (byte(&f->in) & 1)
        d->law_cross = pick_law(f);
    if (byte(&f->in) & 1)
        d->law_shear = pick_law(f);
    d->substeps = integer(&f->in, 1, 8);
    d->name = byte(&f->in) & 1 ? "film" : NULL;
}

static ws_status op_web(fuzz *f)
{
    ws_web_def d;
    ws_web_id id = {0};
    ws_status s = WS_ERR_INVALID_ARGUMENT;
    uint32_t pinned[8];
    switch (pick(&f->in, 3)) {
    case 0: {
        web_common(f, &d);
        ws_sheet_def sh;
        ws_sheet_def_init(&sh);
        sh.nx = integer(&f->in, 1, 12);
        sh.ny = integer(&f->in, 1, 12);
        sh.origin = vec(&f->in);
        if (byte(&f->in) & 1) {
            sh.axis_x = vec(&f->in);
            sh.axis_y = vec(&f->in);
        }
        sh.spacing_x = positive(&f->in) / 16.0;
        sh.spacing_y = positive(&f->in) / 16.0;
        sh.prestretch_x = sane(&f->in) / 8.0;
        sh.prestretch_y = sane(&f->in) / 8.0;
        sh.shear = byte(&f->in) & 1;
        sh.pinned_count = pick(&f->in, 9);
        for (size_t i = 0; i < sh.pinned_count; i++)
            pinned[i] = byte(&f->in) == 255 ? UINT32_MAX : byte(&f->in);
        sh.pinned = byte(&f->in) ? pinned : NULL;
        s = ws_web_create_sheet(f->w, &d, &sh, &id);
        break;
    }
    case 1: {
        web_common(f, &d);
        ws_body_id bodies[4];
        ws_band_def b;
        ws_band_def_init(&b);
        b.body_count = pick(&f->in, 5);
        for (size_t i = 0; i < b.body_count; i++)
            bodies[i] = pick_body(f);
        b.bodies = byte(&f->in) ? bodies : NULL;
        b.z_bottom = sane(&f->in);
        b.z_top = b.z_bottom + sane(&f->in);
        b.n_around = integer(&f->in, 3, 24);
        b.n_up = integer(&f->in, 1, 8);
        b.prestretch_around = sane(&f->in) / 8.0;
        b.prestretch_up = sane(&f->in) / 8.0;
        if (byte(&f->in) & 1)
            b.gap = num(&f->in);
        b.shear = byte(&f->in) & 1;
        s = ws_web_create_band(f->w, &d, &b, &id);
        break;
    }
    default: {
        web_common(f, &d);
        double pos[3 * 12], masses[12], rest[16], scales[16];
        uint32_t springs[2 * 16];
        uint8_t kinds[16];
        ws_web_mesh_def m;
        ws_web_mesh_def_init(&m);
        m.node_count = pick(&f->in, 13);
        for (size_t i = 0; i < 3 * m.node_count; i++)
            pos[i] = sane(&f->in);
        for (size_t i = 0; i < m.node_count; i++)
            masses[i] = positive(&f->in) / 64.0;
        m.spring_count = pick(&f->in, 17);
        for (size_t i = 0; i < 2 * m.spring_count; i++)
            springs[i] = byte(&f->in) == 255 ? UINT32_MAX : pick(&f->in, 13);
        for (size_t i = 0; i < m.spring_count; i++) {
            rest[i] = positive(&f->in) / 8.0;
            kinds[i] = (uint8_t)pick(&f->in, 4);
        }
        unsigned flags = byte(&f->in);
        if (flags & 64) {
            for (size_t i = 0; i < m.spring_count; i++)
                scales[i] = byte(&f->in) & 1 ? num(&f->in) : positive(&f->in);
            m.stiffness_scales = scales;
        }
        if (flags & 128)
            d.rupture_strain = byte(&f->in) & 1 ? num(&f->in) : positive(&f->in) / 16.0;
        m.positions = flags & 1 ? pos : NULL;
        m.node_masses = flags & 2 ? masses : NULL;
        m.springs = flags & 4 ? springs : NULL;
        m.rest_lengths = flags & 8 ? rest : NULL;
        m.kinds = flags & 16 ? kinds : NULL;
        m.pinned_count = pick(&f->in, 9);
        for (size_t i = 0; i < m.pinned_count; i++)
            pinned[i] = byte(&f->in) == 255 ? UINT32_MAX : pick(&f->in, 13);
        m.pinned = flags & 32 ? pinned : NULL;
        s = ws_web_create_mesh(f->w, &d, &m, &id);
        break;
    }
    }
    if (s == WS_OK)
        PUT(f->webs, f->n_webs, id);
    return s;
}

static ws_status op_web_use(fuzz *f)
{
    ws_web_id id = pick_web(f);
    double buf[3 * 64];
    uint32_t pairs[2 * 64];
    size_t n = 0, cap = pick(&f->in, 65);
    ws_containment_band bands[4];
    ws_vec3 force, moment;
    double a, b, c;
    switch (pick(&f->in, 10)) {
    case 0:
        return ws_web_destroy(f->w, id);
    case 1:
        return ws_web_set_substeps(f->w, id, integer(&f->in, 1, 8));
    case 2:
        ws_web_copy_positions(f->w, id, cap ? buf : NULL, cap, &n);
        ws_web_copy_velocities(f->w, id, buf, cap, &n);
        break;
    case 3:
        ws_web_copy_contact_forces(f->w, id, buf, cap, &n);
        ws_web_copy_springs(f->w, id, pairs, cap, &n);
        break;
    case 4:
        ws_web_copy_spring_strains(f->w, id, buf, cap, &n);
        ws_web_copy_spring_tensions(f->w, id, buf, cap, &n);
        break;
    case 5:
        ws_web_get_body_force(f->w, id, pick_body(f), &force, byte(&f->in) ? &moment : NULL);
        break;
    case 6:
        ws_web_get_containment(f->w, id, bands, pick(&f->in, 5));
        break;
    case 7:
        ws_web_get_energy(f->w, id, &a, &b, &c);
        ws_web_get_stable_dt(f->w, id, &a);
        break;
    case 8: {
        ws_web_info info;
        ws_web_get_info(f->w, id, &info);
        break;
    }
    default:
        ws_web_write_vtp(f->w, id, "/dev/null");
        break;
    }
    return WS_OK;
}

static ws_status op_world(fuzz *f)
{
    switch (pick(&f->in, 4)) {
    case 0:
        return ws_world_set_dt(f->w, byte(&f->in) & 1 ? num(&f->in) : positive(&f->in) * 1e-4);
    case 1: {
        ws_vec3 g =
            byte(&f->in) & 1 ? vec(&f->in) : (ws_vec3){num(&f->in), num(&f->in), num(&f->in)};
        return ws_world_set_gravity(f->w, &g);
    }
    case 2:
        return ws_shape_destroy(f->w, pick_shape(f));
    default:
        return ws_body_destroy(f->w, pick_body(f));
    }
}

static void op_read(fuzz *f)
{
    ws_body_id b = pick_body(f);
    ws_vec3 v, m;
    ws_quat q;
    ws_mat3 a;
    double x;
    ws_body_type type;
    ws_contact_info contacts[8];
    ws_element_output out[4];
    ws_element_id elements[4];
    size_t n = 0, cap = pick(&f->in, 9);
    switch (pick(&f->in, 8)) {
    case 0:
        ws_body_get_type(f->w, b, &type);
        ws_body_get_position(f->w, b, &v);
        ws_body_get_orientation(f->w, b, &q);
        ws_body_get_rotation(f->w, b, &a);
        ws_body_get_mass(f->w, b, &x);
        ws_body_get_inertia(f->w, b, &a);
        ws_body_get_name(f->w, b);
        break;
    case 1: {
        ws_vec3 p = vec(&f->in);
        ws_body_get_point_velocity(f->w, b, &p, &v);
        ws_body_get_world_point(f->w, b, &p, &v);
        ws_body_get_angular_velocity_local(f->w, b, &v);
        ws_body_get_contact_force(f->w, b, &v, &m);
        break;
    }
    case 2:
        ws_world_copy_contacts(f->w, cap ? contacts : NULL, cap, &n);
        ws_world_get_contact_count(f->w, &n);
        break;
    case 3:
        ws_element_get_output(f->w, pick_element(f), &out[0]);
        ws_element_get_name(f->w, pick_element(f));
        break;
    case 4:
        ws_world_copy_element_ids(f->w, elements, cap < 4 ? cap : 4, &n);
        ws_world_copy_element_outputs(f->w, out, cap < 4 ? cap : 4, &n);
        ws_world_get_element_energy(f->w, &x);
        break;
    case 5: {
        ws_energy e;
        ws_world_stats st;
        ws_world_get_energy(f->w, &e);
        ws_world_get_stats(f->w, &st);
        ws_world_estimate_stable_dt(f->w, &x);
        break;
    }
    case 6: {
        ws_shape_info info;
        ws_shape_id s = pick_shape(f);
        size_t nv = 0, nt = 0;
        double v3[3 * 8];
        uint32_t t3[3 * 12];
        ws_shape_get_info(f->w, s, &info);
        ws_shape_copy_mesh(f->w, s, v3, cap, &nv, t3, cap, &nt);
        break;
    }
    default:
        ws_world_write_vtp(f->w, "/dev/null");
        break;
    }
}

/* A platform test's sample callback: stops the run at its first sample (WS_ERR_CALLBACK), so
 * a run costs a few steps, and the world must be restored after it. */
static int stop_run(void *user, const ws_loadtest_sample *sample)
{
    (void)user;
    (void)sample;
    return 1;
}

/* The load: built small (one layer of one or two cartons), wrapped in a spiral of fuzzed
 * figures, read, run for a few steps, destroyed. Its own allocator is the fuzz allocator too
 * (its own counts: the world's statistics leave the load's object out). */
static ws_status op_load(fuzz *f, unsigned what)
{
    ws_load *ld = f->load;
    if (!ld || what == 0) {
        if (ld) {
            ws_load_destroy(ld);
            f->load = NULL;
            return WS_OK;
        }
        ws_load_def d;
        ws_load_def_init(&d);
        d.layers = integer(&f->in, 1, 2);
        d.count_x = 1 + (int)pick(&f->in, 2);
        d.count_y = 1;
        if (byte(&f->in) & 1)
            d.carton_size =
                (ws_vec3){positive(&f->in) / 8, positive(&f->in) / 8, positive(&f->in) / 8};
        if (byte(&f->in) & 1)
            d.carton_mass = num(&f->in);
        d.allocator = (ws_allocator){fa_alloc, fa_realloc, fa_free, &f->load_alloc};
        ws_status s = ws_load_build(f->w, &d, &ld);
        if (s == WS_OK) {
            ws_load_info info;
            f->load = ld;
            if (ws_load_get_info(ld, &info) == WS_OK) {
                PUT(f->bodies, f->n_bodies, info.pallet);
                PUT(f->bodies, f->n_bodies, info.platform);
            }
        }
        return s;
    }
    ws_loadtest_result *res = &f->result;
    switch (what) {
    case 1: {
        ws_spiral_wrap_def d;
        ws_spiral_wrap_def_init(&d);
        unsigned flags = byte(&f->in);
        if (flags & 1) {
            d.width = positive(&f->in) / 8;
            d.gauge = positive(&f->in) * 1e-5;
            d.modulus = positive(&f->in) * 1e8;
        }
        if (flags & 2) {
            d.prestretch = sane(&f->in);
            d.neck_in = sane(&f->in) / 8;
            d.load_strain = sane(&f->in) / 8;
            d.overlap = sane(&f->in) / 4;
        }
        if (flags & 4) {
            d.revolutions_bottom = sane(&f->in);
            d.revolutions_top = sane(&f->in);
            d.passes = integer(&f->in, 1, 2);
            d.pallet_lock = integer(&f->in, 0, 1);
            d.lock_height = sane(&f->in) / 16;
            d.top_margin = sane(&f->in) / 16;
        }
        if (flags & 8) {
            d.rope_revolutions = sane(&f->in);
            d.rope_height = sane(&f->in) / 4;
        }
        if (flags & 16) {
            d.top_sheet = integer(&f->in, 0, 1);
            d.top_sheet_gauge = positive(&f->in) * 1e-5;
        }
        if (flags & 32) {
            d.elongation_at_break = sane(&f->in);
            d.rupture_strain = sane(&f->in) / 4;
        }
        d.node_pitch = flags & 64 ? positive(&f->in) / 32 : 0.1;
        d.node_mass_min = flags & 128 ? num(&f->in) : 1e-3;
        d.substeps = integer(&f->in, 0, 8);
        ws_web_id film;
        ws_status s = ws_load_wrap_spiral(f->w, ld, byte(&f->in) ? &d : NULL, &film);
        if (s == WS_OK)
            PUT(f->webs, f->n_webs, film);
        return s;
    }
    case 2: {
        ws_load_containment b[8];
        double strain, height;
        uint32_t spring;
        ws_load_get_containment(f->w, ld, byte(&f->in) ? b : NULL, pick(&f->in, 9));
        ws_load_get_film_peak(f->w, ld, &strain, byte(&f->in) ? &spring : NULL,
                              byte(&f->in) ? &height : NULL);
        return WS_OK;
    }
    case 3: {
        ws_tilt_test_def d;
        ws_tilt_test_def_init(&d);
        d.rate = byte(&f->in) & 1 ? num(&f->in) : positive(&f->in) / 8;
        d.target_angle = sane(&f->in) / 4;
        d.direction = vec(&f->in);
        d.sample_interval = 1 + (int)pick(&f->in, 8); /* the callback stops the run there */
        d.on_sample = stop_run;
        return ws_loadtest_run_tilt(f->w, ld, &d, res);
    }
    case 4: {
        ws_impact_test_def d;
        ws_impact_test_def_init(&d);
        d.speed = byte(&f->in) & 1 ? num(&f->in) : positive(&f->in);
        d.gentle_acceleration = byte(&f->in) & 1 ? num(&f->in) : positive(&f->in);
        d.pulse_duration = positive(&f->in) / 64;
        d.direction = vec(&f->in);
        d.sample_interval = 1 + (int)pick(&f->in, 8); /* the callback stops the run there */
        d.on_sample = stop_run;
        return ws_loadtest_run_impact(f->w, ld, &d, res);
    }
    case 5: {
        ws_vibration_test_def d;
        ws_vibration_test_def_init(&d);
        double fr[4], lv[4];
        d.sweep = integer(&f->in, 0, 1);
        if (byte(&f->in) & 1) {
            d.psd_count = pick(&f->in, 5);
            for (size_t i = 0; i < d.psd_count; i++) {
                fr[i] = (double)(i + 1) * positive(&f->in) * 10;
                lv[i] = positive(&f->in) / 256;
            }
            d.psd_frequency = fr;
            d.psd_level = lv;
        }
        d.grms = sane(&f->in);
        d.sample_rate = byte(&f->in) & 1 ? num(&f->in) : 1024;
        d.frequency_start = positive(&f->in);
        d.frequency_end = d.frequency_start + sane(&f->in) * 10;
        d.duration = positive(&f->in);
        d.ramp_time = positive(&f->in) / 16;
        d.direction = vec(&f->in);
        d.sample_interval = 1 + (int)pick(&f->in, 8); /* the callback stops the run there */
        d.on_sample = stop_run;
        return ws_loadtest_run_vibration(f->w, ld, &d, res);
    }
    default: {
        /* An uninitialised Def, a NULL result. */
        ws_tilt_test_def d;
        memset(&d, 0, sizeof d);
        if (byte(&f->in) & 1)
            return ws_loadtest_run_tilt(f->w, ld, &d, res);
        ws_tilt_test_def_init(&d);
        return ws_loadtest_run_tilt(f->w, ld, &d, NULL);
    }
    }
}

/* The film's rupture: set a web's limit, read its rupture, its broken springs, its peak. */
static ws_status op_rupture(fuzz *f, unsigned what)
{
    ws_web_id id = pick_web(f);
    uint32_t springs[64];
    size_t n = 0, cap = pick(&f->in, 65);
    ws_web_rupture r;
    ws_web_peak p;
    switch (what) {
    case 0:
        return ws_web_set_rupture_strain(f->w, id,
                                         byte(&f->in) & 1 ? num(&f->in) : positive(&f->in) / 16.0);
    case 1:
        ws_web_get_rupture(f->w, id, byte(&f->in) ? &r : NULL);
        ws_web_get_peak_strain(f->w, id, byte(&f->in) ? &p : NULL);
        break;
    default:
        ws_web_copy_broken_springs(f->w, id, byte(&f->in) ? springs : NULL, cap,
                                   byte(&f->in) ? &n : NULL);
        break;
    }
    return WS_OK;
}

/* The op codes 0xE0 .. 0xEF, added after the corpus was made (the others decode as before):
 * the load (0 .. 7) and the rupture calls (8 ..). */
static ws_status op_extra(fuzz *f, unsigned code)
{
    return code < 8 ? op_load(f, code) : op_rupture(f, (code - 8) % 3);
}

/* Calls that change the world; a failure among them must leave the dynamic state as it was. */
static ws_status (*const mutators[])(fuzz *) = {op_shape,    op_body,    op_drive,   op_body_set,
                                                op_material, op_law,     op_element, op_web,
                                                op_world,    op_law_use, op_web_use};
#define N_MUTATORS (sizeof mutators / sizeof mutators[0])

static void run(fuzz *f)
{
    for (int ops = 0; ops < 96 && f->in.n > 0; ops++) {
        unsigned op = byte(&f->in);
        if (op >= 0xF0) {
            /* Fail the allocation `k` allocations from now, during the next call. */
            f->alloc.fail_in = byte(&f->in) % 32;
            f->load_alloc.fail_in = f->alloc.fail_in;
            op = byte(&f->in);
        }
        unsigned kind = op % (N_MUTATORS + 3);
        uint64_t before = state_hash(f);
        ws_status s = WS_OK;
        if (op >= 0xE0 && op < 0xF0) {
            kind = N_MUTATORS + 3; /* a mutator: failures are checked as theirs */
            s = op_extra(f, op - 0xE0);
        } else if (kind < N_MUTATORS) {
            s = mutators[kind](f);
        } else if (kind == N_MUTATORS) {
            for (int i = 0, n = 1 + (int)(byte(&f->in) % 16); i < n; i++)
                step(f);
        } else if (kind == N_MUTATORS + 1) {
            op_read(f);
        } else {
            /* step_n may fail after steps that succeeded: only its successes are checked. */
            int64_t n = (int64_t)(byte(&f->in) % 8) - 1;
            long cost = n > 0 ? n * step_cost(f) : 0;
            if (cost <= f->work) {
                f->work -= cost;
                if (ws_world_step_n(f->w, n) == WS_OK && n > 0)
                    check_finite(f);
            }
        }
        f->alloc.fail_in = -1;
        f->load_alloc.fail_in = -1;
        if (f->trace)
            fprintf(stderr, "op %u: %s %s\n", kind, ws_status_string(s),
                    s != WS_OK ? ws_world_last_error(f->w) : "");
        if (s != WS_OK && state_hash(f) != before)
            finding("a call that failed changed the state hash");
        if (kind == N_MUTATORS + 1 && state_hash(f) != before)
            finding("a read-out changed the state hash");
        if (untracked_bytes(f) != f->untracked)
            finding("the world's bytes in use disagree with the allocator's");
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz f;
    memset(&f, 0, sizeof f);
    f.in = (reader){data, size};
    f.alloc.fail_in = -1;
    f.load_alloc.fail_in = -1;
    f.work = 4000;
    f.trace = getenv("FUZZ_API_TRACE") != NULL;
    ws_world_def d;
    ws_world_def_init(&d);
    d.allocator = (ws_allocator){fa_alloc, fa_realloc, fa_free, &f.alloc};
    unsigned flags = byte(&f.in);
    if (flags & 1)
        d.dt = byte(&f.in) & 1 ? num(&f.in) : positive(&f.in) * 1e-4;
    if (flags & 2)
        d.integrator = (ws_integrator)pick(&f.in, 3);
    if (flags & 4) {
        d.full_detection_until = sane(&f.in);
        d.detection_interval = integer(&f.in, 1, 8);
        d.contact_margin = byte(&f.in) & 1 ? num(&f.in) : positive(&f.in) * 1e-3;
    }
    if (flags & 8) {
        d.max_speed = num(&f.in);
        d.max_angular_speed = num(&f.in);
    }
    d.use_ccd = byte(&f.in) & 1;
    if (flags & 16)
        d.gravity = (ws_vec3){num(&f.in), num(&f.in), num(&f.in)};
    if (flags & 32)
        f.alloc.fail_in = byte(&f.in) % 16;
    ws_status s = ws_world_create(&d, &f.w);
    f.alloc.fail_in = -1;
    if (s == WS_OK) {
        f.untracked = untracked_bytes(&f);
        run(&f);
        ws_load_destroy(f.load);
        ws_world_destroy(f.w);
    } else if (f.w) {
        finding("ws_world_create failed but gave a world");
    }
    if (f.alloc.blocks != 0 || f.alloc.bytes != 0)
        finding("bytes still allocated after ws_world_destroy");
    if (f.load_alloc.blocks != 0 || f.load_alloc.bytes != 0)
        finding("bytes of the load still allocated after ws_load_destroy");
    return 0;
}
