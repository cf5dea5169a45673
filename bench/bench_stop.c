/* Benchmark (not a test): where the implicit film's linear solve leaves its residual on the
 * wrapped reference case R (DESIGN.md) at the real film, the bodies in the solve. Reads the
 * library's internals (links the static archive), so it can switch the stopping test between
 * the solve's (every row against its own weight impulse m g h) and the earlier relative one
 * (the residual's norm against the right-hand side's) and read, at the end of every step's
 * last solve, the residual by kind of row: the film's nodes without contacts ("free"), its
 * nodes with contacts ("pressed") and the bodies' rows. Prints, for each half second of
 * simulated time: the platform's angle, CG iterations a step, the relative test's scale (the
 * right-hand side's norm |b| against the film's weight impulse h g |m|), each kind's share of
 * the residual's squared norm, and each kind's worst row's residual over its weight impulse
 * (mean over the steps and largest). Never fails on time.
 * Usage: bench_stop [duration s] [dt ms] [preconditioner] [tolerance] [test]: preconditioner
 * a ws_web_preconditioner (1 block Jacobi, 2 multigrid, 0 AUTO), tolerance 0 the default, test
 * 0 the solve's (rows), 1 the relative one.
 * `bench_stop window file r duration [every]`: the band refined r x r at the real areal density
 * restored from a checkpoint (bench_implicit's WS_BENCH_SAVE), each step's solves read through
 * the solve's probe (ws_implicit_probe), the boxes' velocity change, the film's load on them and
 * the bodies' contacts: see window_probe. Studies by environment: WS_PROBE_COLD=1 (the bodies
 * from rest), WS_PROBE_TOL=tol, WS_PROBE_HOLD=1 (the bodies held), WS_PROBE_DT=s (after the
 * restore), WS_PROBE_DAMP=f,T[,1] (the box contacts' damping, or with 1 the film-box one's,
 * times f for T s), WS_PROBE_CONTACTS=n (list the bodies' contacts of the first n steps),
 * WS_PROBE_STEPS=file (a line a step, ending with the boxes' |dV| and |dW| that step, bottom
 * then top, and the bodies' contact count), WS_PROBE_LOADS=file (a line a step: each box's pose
 * and the film's force and moment on it, the plane's and the box-box contacts, the film at the
 * boxes' vertical edges: see loads_line), WS_PROBE_MIRROR=n and WS_PROBE_NODE=column,row (the
 * band against its mirror image: see mirror_line), WS_PROBE_NODES=file (a line a node at the
 * end: column, row, its contact's comings and goings, steps in contact, rms of its dv and of
 * dv's change from step to step, its position), WS_PROBE_WATCH=column,row (that node's
 * contacts a step: active at the start, normal force at the start and at the end by the
 * linear model, the body's point's and the node's velocity along the normal; its springs'
 * strains). */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

#include "web/implicit.h"
#include "world/world_internal.h"

/* CPU seconds of this process (the runs are single-threaded). */
static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

typedef struct window {
    long steps;
    double it, b, wt;          /* sums: iterations, |b|, h g |m| */
    double rr[3], worst[3];    /* sums over the steps */
    double worst_max[3];
} window;

/* |b|^2 over n nodes' xyz. */
static double dot3_norm2(const double *b, uint32_t n)
{
    double s = 0.0;
    for (size_t j = 0; j < 3 * (size_t)n; j++)
        s += b[j] * b[j];
    return s;
}

static void window_print(const window *s, double t, double angle)
{
    const double n = s->steps > 0 ? (double)s->steps : 1.0;
    const double rr = s->rr[0] + s->rr[1] + s->rr[2];
    printf("%5.2f s %6.2f deg  CG %6.1f it/step  |b|/(h g |m|) %8.3g  |r|^2 share free %.3f "
           "pressed %.3f bodies %.3f  worst/(m g h): free %8.2g (max %8.2g) pressed %8.2g "
           "(max %8.2g) bodies %8.2g (max %8.2g)\n",
           t, angle, s->it / n, s->b / (s->wt > 0 ? s->wt : 1.0), rr > 0 ? s->rr[0] / rr : 0.0,
           rr > 0 ? s->rr[1] / rr : 0.0, rr > 0 ? s->rr[2] / rr : 0.0, s->worst[0] / n,
           s->worst_max[0], s->worst[1] / n, s->worst_max[1], s->worst[2] / n, s->worst_max[2]);
    fflush(stdout);
}

/* One window's sums over its steps (window_probe). */
typedef struct probe_sums {
    long steps, onepass;
    double it, solves, first_it;
    double start[WS_PROBE_KINDS], start_max[WS_PROBE_KINDS];
    double above0[WS_PROBE_KINDS], above[WS_PROBE_MARKS];
    long bind[WS_PROBE_KINDS];
    double enter, leave, flip, ddv, ddu;
    long cold; /* steps whose warm start already met the test */
    double bc, bc_change; /* the bodies' contacts a step, and steps whose count changed */
    double dfilm[2][6]; /* sums of the squared step-to-step change of the film's load on
                           each box: force x y z (N), moment x y z (N m) */
    double du_axis[2][6]; /* the same by component: dV x y z, dW x y z */
    double du_lin[2], du_ang[2]; /* sums over the steps of |dV|^2, |dW|^2 of the boxes */
    long where_up[12], where_around[4]; /* contacts in or out by twelfth up the band, quarter
                                           around it */
} probe_sums;

static const char *const kind_name[WS_PROBE_KINDS] = {"free", "stick", "slip", "body"};

static void probe_print(const probe_sums *s, double t)
{
    const double n = s->steps > 0 ? (double)s->steps : 1.0;
    printf("%6.3f s  CG %5.2f it/step (first solve %5.2f) %4.2f solves/step, 1-pass %3.0f%%  "
           "start/goal free %7.3g stick %7.3g slip %7.3g body %7.3g (max %7.3g %7.3g %7.3g %7.3g)"
           "  rows>goal at start %6.1f %6.1f %6.1f %4.1f  after 1,2,4,8,16,32 it %6.1f %6.1f "
           "%6.1f %5.1f %5.1f %5.1f  binds free %ld stick %ld slip %ld body %ld  contacts in "
           "%5.2f out %5.2f stick<->slip %5.2f a step  |ddv|/|dv| %6.3f  |ddU|/|dU| %6.3f\n",
           t, s->it / n, s->first_it / n, s->solves / n, 100.0 * s->onepass / n,
           s->start[0] / n, s->start[1] / n, s->start[2] / n, s->start[3] / n, s->start_max[0],
           s->start_max[1], s->start_max[2], s->start_max[3], s->above0[0] / n, s->above0[1] / n,
           s->above0[2] / n, s->above0[3] / n, s->above[0] / n, s->above[1] / n, s->above[2] / n,
           s->above[3] / n, s->above[4] / n, s->above[5] / n, s->bind[0], s->bind[1], s->bind[2],
           s->bind[3], s->enter / n, s->leave / n, s->flip / n, s->ddv / n, s->ddu / n);
    printf("         boxes' velocity change a step, rms: bottom %.3g m/s %.3g rad/s, top %.3g m/s "
           "%.3g rad/s\n",
           sqrt(s->du_lin[0] / n), sqrt(s->du_ang[0] / n), sqrt(s->du_lin[1] / n),
           sqrt(s->du_ang[1] / n));
    for (int q = 0; q < 2; q++)
        printf("         %s box, rms by component: dV %.3g %.3g %.3g m/s, dW %.3g %.3g %.3g "
               "rad/s\n",
               q ? "top" : "bottom", sqrt(s->du_axis[q][0] / n), sqrt(s->du_axis[q][1] / n),
               sqrt(s->du_axis[q][2] / n), sqrt(s->du_axis[q][3] / n),
               sqrt(s->du_axis[q][4] / n), sqrt(s->du_axis[q][5] / n));
    for (int q = 0; q < 2; q++)
        printf("         %s box, the film's load, its change a step rms: force %.3g %.3g %.3g N, "
               "moment %.3g %.3g %.3g N m\n",
               q ? "top" : "bottom", sqrt(s->dfilm[q][0] / n), sqrt(s->dfilm[q][1] / n),
               sqrt(s->dfilm[q][2] / n), sqrt(s->dfilm[q][3] / n), sqrt(s->dfilm[q][4] / n),
               sqrt(s->dfilm[q][5] / n));
    printf("         the bodies' contacts: %.2f a step, their number changed in %.0f %% of the "
           "steps\n",
           s->bc / n, 100.0 * s->bc_change / n);
    printf("         contacts in or out by twelfth up the band:");
    for (int q = 0; q < 12; q++)
        printf(" %ld", s->where_up[q]);
    printf("; by quarter around:");
    for (int q = 0; q < 4; q++)
        printf(" %ld", s->where_around[q]);
    printf("\n");
    fflush(stdout);
}

/* Case R wrapped, its film implicit, the example's defaults otherwise, quiet. */
static void case_r_implicit(tilt_options *a)
{
    tilt_default_options(a);
    a->variant = 'R';
    a->quiet = 1;
    a->wrapped = 1;
    a->implicit = 1;
}

/* The scene's film web, its implicit part reserved (NULL when either fails). */
static ws_web *film_web(const tilt_scene *sc)
{
    uint32_t slot;
    if (ws_lookup_web(sc->world, sc->film, &slot) != WS_OK)
        return NULL;
    ws_web *web = sc->world->webs[slot];
    if (!web->imp && ws_implicit_reserve(&sc->world->mem, web) != 0)
        return NULL;
    return web;
}

/* WS_PROBE_LOADS=file: a line a step: t, then for each box (bottom, top) its centre (m), its
 * small rotation 2 (e1 e2 e3) (rad), the film's force (N) and moment about its centre (N m);
 * then the plane-bottom and the box-box contacts: count, edge-edge count, total normal force
 * (N) and the force-weighted mean point (x y, m); then the film at the boxes' vertical edges
 * (below). */
static void loads_line(FILE *f, const tilt_scene *sc, const ws_web *web, double t)
{
    fprintf(f, "%.5f", t);
    for (int q = 0; q < 2; q++) {
        ws_vec3 p;
        ws_quat e;
        uint32_t bslot = 0;
        ws_body_get_position(sc->world, sc->box[q], &p);
        ws_body_get_orientation(sc->world, sc->box[q], &e);
        ws_lookup_body(sc->world, sc->box[q], &bslot);
        const v3 F = web->bforce[sc->world->cur][bslot], M = web->bmoment[sc->world->cur][bslot];
        fprintf(f, "  %.6f %.6f %.6f %.3e %.3e %.3e  %.4f %.4f %.4f %.4f %.4f %.4f", p.x, p.y, p.z,
                2 * e.e1, 2 * e.e2, 2 * e.e3, F.x, F.y, F.z, M.x, M.y, M.z);
    }
    ws_contact_info ci[64];
    size_t nc = 0;
    ws_world_copy_contacts(sc->world, ci, 64, &nc);
    for (int g = 0; g < 2; g++) { /* 0: a box on the plane, 1: box on box */
        int cnt = 0, ee = 0;
        double N = 0.0, x = 0.0, y = 0.0;
        for (size_t q = 0; q < nc && q < 64; q++) {
            const int boxa = ci[q].body_a.bits == sc->box[0].bits || ci[q].body_a.bits == sc->box[1].bits;
            const int boxb = ci[q].body_b.bits == sc->box[0].bits || ci[q].body_b.bits == sc->box[1].bits;
            if ((boxa && boxb) != g)
                continue;
            cnt++;
            ee += ci[q].kind != 0;
            N += ci[q].normal_force;
            x += ci[q].normal_force * ci[q].point.x;
            y += ci[q].normal_force * ci[q].point.y;
        }
        fprintf(f, "  %d %d %.3f %.5f %.5f", cnt, ee, N, N > 0 ? x / N : 0.0, N > 0 ? y / N : 0.0);
    }
    /* The film at the boxes' vertical edges: the least distance of a node from an edge's line
     * (the footprint's corners, the boxes taken at the origin, unturned: they move microns) and
     * how many nodes lie inside the footprint (past the surface). */
    {
        const ws_nodes3 X = web->x[sc->world->cur];
        double dmin = INFINITY;
        int inside = 0;
        for (uint32_t i = 0; i < web->n; i++) {
            const double ax = fabs(X.x[i]), ay = fabs(X.y[i]);
            dmin = fmin(dmin, hypot(ax - 0.125, ay - 0.125));
            inside += ax < 0.125 && ay < 0.125 && X.z[i] > 0.002 && X.z[i] < 0.506;
        }
        fprintf(f, "  %.4e %d", dmin, inside);
    }
    fputc('\n', f);
}

/* WS_PROBE_MIRROR=n: for the first n steps, how far the band is from its mirror image in the
 * diagonal plane x = y (the case is symmetric in it: node column i maps to 3 nx / 4 - i): the
 * nodes whose contact state differs from their image's, the largest position difference and
 * where; with WS_PROBE_NODE=column,row that node's position, velocity and state. */
static void mirror_line(const ws_web *web, int cur, const uint8_t *st, long k)
{
    const ws_nodes3 X = web->x[cur], V = web->v[cur];
    const int nx = web->nx;
    uint32_t bad = 0, imax = 0;
    double dmax = 0.0;
    for (uint32_t i = 0; i < web->n; i++) {
        const int col = (int)(i % (uint32_t)nx), row = (int)(i / (uint32_t)nx);
        const uint32_t m = (uint32_t)((3 * nx / 4 - col + nx) % nx + row * nx);
        bad += st[i] != st[m];
        const double d =
            fabs(X.x[i] - X.y[m]) + fabs(X.y[i] - X.x[m]) + fabs(X.z[i] - X.z[m]);
        if (d > dmax)
            dmax = d, imax = i;
    }
    printf("mirror step %ld: %u nodes in another contact state than their image, position "
           "off by up to %.3g m (column %u row %u)\n",
           k, bad, dmax, imax % (uint32_t)nx, imax / (uint32_t)nx);
    int qc = 0, qr = 0;
    if (getenv("WS_PROBE_NODE") && sscanf(getenv("WS_PROBE_NODE"), "%d,%d", &qc, &qr) == 2 &&
        qc >= 0 && qc < nx && qr >= 0 && qr < web->ny) {
        const uint32_t c = (uint32_t)(qc + qr * nx);
        printf("  node %d,%d: x %.7f %.7f %.7f (x - y %.3g) v %.4g %.4g %.4g state %d\n", qc, qr,
               X.x[c], X.y[c], X.z[c], X.x[c] - X.y[c], V.x[c], V.y[c], V.z[c], st[c]);
    }
}

/* `window file r duration [every]`: case R's band refined r x r at the real areal density on
 * the multigrid (bench_implicit's `phases`), restored from `file` (bench_implicit's
 * WS_BENCH_SAVE; "-" starts at t = 0), stepped `duration` s with the probe of the solve
 * (ws_implicit_probe): per window of `every` s (default 0.05), the warm start's residual by
 * kind of row over the goal, rows above the goal at the start and after some iterations, the
 * binding row's kind, contacts entering and leaving and stick-slip changes a step, how much dv
 * (the film's velocity change) and dU (the bodies') change from step to step, the boxes'
 * velocity change a step by component, the change of the film's load on them, and the bodies'
 * contacts a step. With WS_PROBE_STEPS=file, a line a step into it (the file's head comment
 * above lists the other knobs). */
static int window_probe(int argc, char **argv)
{
    tilt_options a;
    case_r_implicit(&a);
    a.areal_density = 0.018;
    a.substeps = 1;
    a.refine = argc > 3 ? atoi(argv[3]) : 1;
    a.preconditioner = WS_WEB_PRECONDITIONER_MULTIGRID;
    const double T = argc > 4 ? atof(argv[4]) : 0.1;
    const double every = argc > 5 ? atof(argv[5]) : 0.05;
    tilt_scene sc;
    if (tilt_build(&a, &sc) != WS_OK)
        return 1;
    if (strcmp(argv[2], "-") && ws_world_restore_file(sc.world, argv[2]) != WS_OK) {
        printf("restore %s: %s\n", argv[2], ws_world_last_error(sc.world));
        return 1;
    }
    /* WS_PROBE_DAMP=f,T[,film]: the box-box and box-plane contacts' damping (film 1: the
     * film-box contact's) times f for the first T s, then as it was: whether a rattle is energy
     * left over (it stays gone) or fed each step (it comes back). */
    double damp_f = 1.0, damp_T = 0.0;
    int damp_film = 0, npair = 0;
    ws_material_id pa[2] = {{0}, {0}}, pb[2] = {{0}, {0}};
    ws_contact_def cd0[2];
    if (getenv("WS_PROBE_DAMP") &&
        sscanf(getenv("WS_PROBE_DAMP"), "%lf,%lf,%d", &damp_f, &damp_T, &damp_film) >= 2) {
        uint32_t bs[2], ws;
        ws_body_id who[2] = {sc.box[0], sc.plane};
        for (int q = 0; q < 2; q++)
            if (ws_lookup_body(sc.world, who[q], &bs[q]) != WS_OK)
                return 1;
        if (ws_lookup_web(sc.world, sc.film, &ws) != WS_OK)
            return 1;
        const ws_slot_table *mt = &sc.world->mat_slots;
        const uint64_t box = ws_slots_id(mt, WS_KIND_MATERIAL, sc.world->bodies.material[bs[0]]);
        const uint64_t plane = ws_slots_id(mt, WS_KIND_MATERIAL, sc.world->bodies.material[bs[1]]);
        const uint64_t film = ws_slots_id(mt, WS_KIND_MATERIAL, sc.world->webs[ws]->material);
        pa[0].bits = box;
        pb[0].bits = damp_film ? film : box;
        pa[1].bits = box;
        pb[1].bits = plane;
        npair = damp_film ? 1 : 2;
        for (int q = 0; q < npair; q++) {
            if (ws_world_get_contact(sc.world, pa[q], pb[q], &cd0[q]) != WS_OK)
                return 1;
            ws_contact_def cd = cd0[q];
            cd.damping *= damp_f;
            printf("contacts %s: damping %g -> %g kg/s for %g s\n",
                   damp_film ? "film-box" : q ? "box-plane" : "box-box", cd0[q].damping,
                   cd.damping, damp_T);
            if (ws_world_set_contact(sc.world, pa[q], pb[q], &cd) != WS_OK)
                return 1;
        }
    }
    if (getenv("WS_PROBE_DT")) { /* the step, s, after the restore */
        sc.dt = atof(getenv("WS_PROBE_DT"));
        if (ws_world_set_dt(sc.world, sc.dt) != WS_OK)
            return 1;
    }
    ws_web *web = film_web(&sc);
    if (!web)
        return 1;
    const uint32_t n = web->n;
    ws_implicit_probe pr;
    memset(&pr, 0, sizeof pr);
    uint8_t *st = calloc(n, 1), *st0 = calloc(n, 1);
    double *dv0 = calloc(3 * (size_t)n, sizeof(double));
    if (!st || !st0 || !dv0)
        return 1;
    pr.state = st;
    web->imp->probe = &pr;
    /* WS_PROBE_COLD=1: the bodies start each solve from rest, as before the film's warm
     * start was carried over to them (ws_implicit's cold_bodies). */
    web->imp->cold_bodies = getenv("WS_PROBE_COLD") && atoi(getenv("WS_PROBE_COLD"));
    /* Studies of the cause: WS_PROBE_TOL, the solve's tolerance; WS_PROBE_HOLD=1, the bodies
     * held during the film's solve. */
    if (getenv("WS_PROBE_TOL"))
        web->solver_tol = atof(getenv("WS_PROBE_TOL"));
    if (getenv("WS_PROBE_HOLD"))
        web->hold_bodies = atoi(getenv("WS_PROBE_HOLD"));
    FILE *steps_out = getenv("WS_PROBE_STEPS") ? fopen(getenv("WS_PROBE_STEPS"), "w") : NULL;
    FILE *loads_out = getenv("WS_PROBE_LOADS") ? fopen(getenv("WS_PROBE_LOADS"), "w") : NULL;
    /* WS_PROBE_NODES=file: per node over the run, its contact's comings and goings, the steps
     * it was in contact, and its dv's size and step-to-step change (rms), a line a node. */
    FILE *nodes_out = getenv("WS_PROBE_NODES") ? fopen(getenv("WS_PROBE_NODES"), "w") : NULL;
    double *nd_dv = calloc(n, sizeof(double)), *nd_ddv = calloc(n, sizeof(double));
    uint32_t *nd_flip = calloc(n, sizeof(uint32_t)), *nd_on = calloc(n, sizeof(uint32_t));
    if (!nd_dv || !nd_ddv || !nd_flip || !nd_on)
        return 1;
    double t0;
    ws_world_get_time(sc.world, &t0);
    printf("case R refined %d (%u nodes, %d x %d), bodies %s, from t %.4f s (%.2f deg), %.3f s\n",
           a.refine, n, web->nx, web->ny, web->imp->cold_bodies ? "cold" : "warm", t0, plane_angle(sc.world, sc.plane) * 180.0 / 3.14159265358979,
           T);
    const long steps = lround(T / sc.dt), per = lround(every / sc.dt);
    probe_sums s;
    memset(&s, 0, sizeof s);
    double u0[2][6], du0[2][6] = {{0}}, bf0[2][6] = {{0}};
    size_t nbc0 = 0;
    for (int q = 0; q < 2; q++) {
        ws_vec3 v, w;
        ws_body_get_velocity(sc.world, sc.box[q], &v);
        ws_body_get_angular_velocity(sc.world, sc.box[q], &w);
        const double u[6] = {v.x, v.y, v.z, w.x, w.y, w.z};
        memcpy(u0[q], u, sizeof u);
    }
    const double c0 = cpu_seconds();
    for (long k = 1; k <= steps; k++) {
        if (damp_T > 0.0 && k == lround(damp_T / sc.dt) + 1)
            for (int q = 0; q < npair; q++)
                if (ws_world_set_contact(sc.world, pa[q], pb[q], &cd0[q]) != WS_OK)
                    return 1;
        memcpy(st0, st, n);
        memset(st, 0, n);
        pr.solves = 0;
        pr.watch_count = 0;
        int wc = -1, wr = -1;
        if (getenv("WS_PROBE_WATCH") &&
            sscanf(getenv("WS_PROBE_WATCH"), "%d,%d", &wc, &wr) == 2) {
            pr.watch_on = 1;
            pr.watch = (uint32_t)(wc + wr * web->nx);
        }
        if (ws_world_step(sc.world) != WS_OK) {
            printf("step %ld failed: %s\n", k, ws_world_last_error(sc.world));
            return 1;
        }
        /* Step-to-step change of the film's dv and of the bodies' (dU, both boxes, their
         * velocity and spin as they are, metres and radians a second). */
        if (pr.watch_on) {
            /* WS_PROBE_WATCH=column,row: that node's contacts at the start and the normal force
             * their linear model ends with, its velocity, and its springs' strains. */
            const uint32_t i = pr.watch;
            const ws_nodes3 X = web->x[sc.world->cur], V = web->v[sc.world->cur];
            const double *D = web->imp->dv + 3 * (size_t)i;
            printf("watch %ld x %.7f %.7f %.7f v %.5f %.5f %.5f dv %.3g %.3g %.3g its %u\n", k,
                   X.x[i], X.y[i], X.z[i], V.x[i], V.y[i], V.z[i], D[0], D[1], D[2],
                   pr.it[0]);
            for (uint32_t q = 0; q < pr.watch_count; q++) {
                const double *nn = pr.watch_link[q].n;
                const double nv = nn[0] * V.x[i] + nn[1] * V.y[i] + nn[2] * V.z[i],
                             nd = nn[0] * D[0] + nn[1] * D[1] + nn[2] * D[2];
                printf("   link body %u active %d fn %.4g fe %.4g fin %.3g n %.3f %.3f %.3f slip "
                       "%.3g n.u_body %.4g n.v_node %.4g\n",
                       pr.watch_link[q].body, pr.watch_link[q].active, pr.watch_link[q].fn,
                       pr.watch_link[q].fn - pr.watch_link[q].k * sc.dt * nv -
                           pr.watch_link[q].c * nd,
                       pr.watch_link[q].fin, nn[0], nn[1], nn[2], pr.watch_link[q].slip,
                       pr.watch_link[q].nu, nv);
            }
            printf("   strains");
            for (uint32_t s2 = 0; s2 < web->ns; s2++)
                if (web->sa[s2] == i || web->sb[s2] == i) {
                    const uint32_t a2 = web->sa[s2], b2 = web->sb[s2];
                    const double l = sqrt((X.x[a2] - X.x[b2]) * (X.x[a2] - X.x[b2]) +
                                          (X.y[a2] - X.y[b2]) * (X.y[a2] - X.y[b2]) +
                                          (X.z[a2] - X.z[b2]) * (X.z[a2] - X.z[b2]));
                    printf(" k%d %.4f", web->kind[s2], l * web->inv_l0[s2] - 1.0);
                }
            printf("\n");
        }
        const double *dv = web->imp->dv;
        double dd = 0.0, d2 = 0.0, ud = 0.0, u2 = 0.0, dlin[2] = {0.0, 0.0}, dang[2] = {0.0, 0.0};
        for (size_t j = 0; j < 3 * (size_t)n; j++) {
            dd += (dv[j] - dv0[j]) * (dv[j] - dv0[j]);
            d2 += dv[j] * dv[j];
            if (k > 1) {
                nd_dv[j / 3] += dv[j] * dv[j];
                nd_ddv[j / 3] += (dv[j] - dv0[j]) * (dv[j] - dv0[j]);
            }
        }
        memcpy(dv0, dv, 3 * (size_t)n * sizeof(double));
        for (int q = 0; q < 2; q++) {
            ws_vec3 v, w;
            ws_body_get_velocity(sc.world, sc.box[q], &v);
            ws_body_get_angular_velocity(sc.world, sc.box[q], &w);
            const double u[6] = {v.x, v.y, v.z, w.x, w.y, w.z};
            for (int c = 0; c < 6; c++) {
                const double du = u[c] - u0[q][c];
                if (c < 3) {
                    s.du_lin[q] += du * du;
                    dlin[q] += du * du;
                } else {
                    s.du_ang[q] += du * du;
                    dang[q] += du * du;
                }
                s.du_axis[q][c] += du * du;
                ud += (du - du0[q][c]) * (du - du0[q][c]);
                u2 += du * du;
                du0[q][c] = du;
                u0[q][c] = u[c];
            }
        }
        /* The film's load on each box this step (its contacts' forces as the bodies take
         * them) and its change from the last step. */
        for (int q = 0; q < 2; q++) {
            uint32_t bslot;
            if (ws_lookup_body(sc.world, sc.box[q], &bslot) != WS_OK)
                return 1;
            const v3 F = web->bforce[sc.world->cur][bslot], M = web->bmoment[sc.world->cur][bslot];
            const double d[6] = {F.x - bf0[q][0], F.y - bf0[q][1], F.z - bf0[q][2],
                                 M.x - bf0[q][3], M.y - bf0[q][4], M.z - bf0[q][5]};
            if (k > 1)
                for (int c = 0; c < 6; c++)
                    s.dfilm[q][c] += d[c] * d[c];
            bf0[q][0] = F.x, bf0[q][1] = F.y, bf0[q][2] = F.z;
            bf0[q][3] = M.x, bf0[q][4] = M.y, bf0[q][5] = M.z;
        }
        size_t nbc = 0;
        ws_world_get_contact_count(sc.world, &nbc);
        if (getenv("WS_PROBE_MIRROR") && k <= atoi(getenv("WS_PROBE_MIRROR")))
            mirror_line(web, sc.world->cur, st, k);
        if (loads_out && k > 1)
            loads_line(loads_out, &sc, web, t0 + k * sc.dt);
        if (getenv("WS_PROBE_CONTACTS") && k <= atoi(getenv("WS_PROBE_CONTACTS"))) {
            ws_contact_info ci[64];
            size_t nc = 0;
            ws_world_copy_contacts(sc.world, ci, 64, &nc);
            printf("step %ld: %zu body contacts\n", k, nc);
            for (size_t q = 0; q < nc && q < 64; q++) {
                const char *nm[3] = {"bottom", "top", "plane/stop"};
                const int ia = ci[q].body_a.bits == sc.box[0].bits ? 0
                               : ci[q].body_a.bits == sc.box[1].bits ? 1 : 2;
                const int ib = ci[q].body_b.bits == sc.box[0].bits ? 0
                               : ci[q].body_b.bits == sc.box[1].bits ? 1 : 2;
                printf("  %-10s %-10s kind %d at (%.4f %.4f %.4f) overlap %.3g mm N %.3g\n",
                       nm[ia], nm[ib], ci[q].kind, ci[q].point.x, ci[q].point.y, ci[q].point.z,
                       1e3 * ci[q].overlap, ci[q].normal_force);
            }
        }
        if (k > 1) {
            s.bc += (double)nbc;
            s.bc_change += nbc != nbc0;
        }
        nbc0 = nbc;
        uint32_t enter = 0, leave = 0, flip = 0;
        for (uint32_t i = 0; i < n; i++) {
            const int was = st0[i] >= 2, is = st[i] >= 2;
            enter += !was && is;
            leave += was && !is;
            flip += was && is && st0[i] != st[i];
            if (k > 1) {
                nd_flip[i] += was != is;
                nd_on[i] += is;
            }
            if (k > 1 && was != is) { /* where on the band: twelfths up it, quarters around */
                s.where_up[12 * (i / (uint32_t)web->nx) / (uint32_t)web->ny]++;
                s.where_around[4 * (i % (uint32_t)web->nx) / (uint32_t)web->nx]++;
            }
        }
        uint32_t its = 0;
        for (uint32_t q = 0; q < pr.solves && q < WS_PROBE_PASSES; q++)
            its += pr.it[q];
        if (k > 1) { /* the first step after a restore starts cold */
            s.steps++;
            s.it += its;
            s.first_it += pr.it[0];
            s.solves += pr.solves;
            s.onepass += pr.solves == 1;
            s.cold += its == 0;
            for (int q = 0; q < WS_PROBE_KINDS; q++) {
                s.start[q] += pr.start[q];
                s.start_max[q] = fmax(s.start_max[q], pr.start[q]);
                s.above0[q] += pr.above0[q];
            }
            for (int m = 0; m < WS_PROBE_MARKS; m++)
                for (int q = 0; q < WS_PROBE_KINDS; q++)
                    s.above[m] += pr.above[m][q];
            if (its > 0)
                s.bind[pr.bind_kind]++;
            s.enter += enter;
            s.leave += leave;
            s.flip += flip;
            s.ddv += d2 > 0 ? sqrt(dd / d2) : 0.0;
            s.ddu += u2 > 0 ? sqrt(ud / u2) : 0.0;
        }
        if (steps_out && k > 1) {
            const uint32_t b = pr.bind_row;
            fprintf(steps_out,
                    "%.5f %u %u %u %.4g %.4g %.4g %.4g %u %u %u %u %u %u %u %u %u %u %s %d %d "
                    "%.4g %u %u %u %.4g %.4g %.3g %.3g %.3g %.3g %zu\n",
                    t0 + k * sc.dt, its, pr.solves, pr.it[0], pr.start[0], pr.start[1],
                    pr.start[2], pr.start[3], pr.above0[0], pr.above0[1], pr.above0[2],
                    pr.above0[3], pr.above[0][0] + pr.above[0][1] + pr.above[0][2] + pr.above[0][3],
                    pr.above[1][0] + pr.above[1][1] + pr.above[1][2] + pr.above[1][3],
                    pr.above[2][0] + pr.above[2][1] + pr.above[2][2] + pr.above[2][3],
                    pr.above[3][0] + pr.above[3][1] + pr.above[3][2] + pr.above[3][3],
                    pr.above[4][0] + pr.above[4][1] + pr.above[4][2] + pr.above[4][3], b,
                    kind_name[pr.bind_kind], b < n ? (int)(b % (uint32_t)web->nx) : -1,
                    b < n ? (int)(b / (uint32_t)web->nx) : -1, pr.bind_value, enter, leave, flip,
                    d2 > 0 ? sqrt(dd / d2) : 0.0, u2 > 0 ? sqrt(ud / u2) : 0.0, sqrt(dlin[0]),
                    sqrt(dang[0]), sqrt(dlin[1]), sqrt(dang[1]), nbc);
        }
        if (k % per == 0) {
            probe_print(&s, t0 + k * sc.dt);
            memset(&s, 0, sizeof s);
        }
    }
    printf("%.1f s CPU per simulated s (the probe's own passes included)\n",
           (cpu_seconds() - c0) / T);
    if (steps_out)
        fclose(steps_out);
    if (nodes_out) {
        const ws_nodes3 X = web->x[sc.world->cur];
        for (uint32_t i = 0; i < n; i++)
            fprintf(nodes_out, "%u %u %u %u %.4g %.4g %.5f %.5f %.5f\n", i % (uint32_t)web->nx,
                    i / (uint32_t)web->nx, nd_flip[i], nd_on[i], sqrt(nd_dv[i] / (steps - 1)),
                    sqrt(nd_ddv[i] / (steps - 1)), X.x[i], X.y[i], X.z[i]);
        fclose(nodes_out);
    }
    free(nd_dv);
    free(nd_ddv);
    free(nd_flip);
    free(nd_on);
    if (loads_out)
        fclose(loads_out);
    web->imp->probe = NULL;
    free(st);
    free(st0);
    free(dv0);
    ws_world_destroy(sc.world);
    return 0;
}

int main(int argc, char **argv)
{
    (void)tilt_run; /* the example's driver: this bench steps the scene itself */
    if (argc > 2 && !strcmp(argv[1], "window"))
        return window_probe(argc, argv);
    tilt_options a;
    case_r_implicit(&a);
    a.film_mass = 1.6e-6; /* as bench_implicit's solve: 1.6 mg nodes, one solve a step */
    a.substeps = 1;
    a.duration = argc > 1 ? atof(argv[1]) : 0.0;
    a.dt = (argc > 2 ? atof(argv[2]) : 1.0) * 1e-3;
    a.preconditioner = argc > 3 ? atoi(argv[3]) : 0;
    a.solver_tolerance = argc > 4 ? atof(argv[4]) : 0.0;
    const int relative = argc > 5 ? atoi(argv[5]) : 0;
    tilt_scene sc;
    ws_status st = tilt_build(&a, &sc);
    if (st != WS_OK) {
        fprintf(stderr, "bench_stop: %s\n", ws_status_string(st));
        return 1;
    }
    ws_web *web = film_web(&sc);
    if (!web)
        return 1;
    ws_implicit *im = web->imp;
    im->stop_relative = relative;
    double weight2 = 0.0;
    for (uint32_t i = 0; i < web->n; i++)
        weight2 += web->m[i] * web->m[i];
    const double wt = sc.dt * 9.81 * sqrt(weight2);
    printf("case R, dt %.3g ms, preconditioner %d, tolerance %g, test %s, %u film nodes\n",
           1e3 * sc.dt, a.preconditioner, a.solver_tolerance, relative ? "relative" : "rows",
           web->n);
    const long steps = lround(sc.duration / sc.dt), per = lround(0.5 / sc.dt);
    window s = {0};
    uint64_t it0 = im->iterations;
    for (long k = 1; k <= steps; k++) {
        if ((st = ws_world_step(sc.world)) != WS_OK) {
            printf("step %ld failed: %s\n", k, ws_world_last_error(sc.world));
            break;
        }
        s.steps++;
        s.it += (double)(im->iterations - it0);
        it0 = im->iterations;
        s.b += sqrt(dot3_norm2(im->b, web->n));
        s.wt += wt;
        for (int q = 0; q < 3; q++) {
            s.rr[q] += im->last_rr[q];
            s.worst[q] += im->last_worst[q];
            s.worst_max[q] = fmax(s.worst_max[q], im->last_worst[q]);
        }
        if (k % per == 0) {
            window_print(&s, k * sc.dt, plane_angle(sc.world, sc.plane) * 180.0 / 3.14159265358979);
            memset(&s, 0, sizeof s);
        }
    }
    ws_world_destroy(sc.world);
    return st == WS_OK ? 0 : 1;
}
