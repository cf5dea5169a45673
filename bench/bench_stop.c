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
 * 0 the solve's (rows), 1 the relative one. */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

#include "web/implicit.h"
#include "world/world_internal.h"

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

int main(int argc, char **argv)
{
    (void)tilt_run; /* the example's driver: this bench steps the scene itself */
    tilt_options a;
    tilt_default_options(&a);
    a.variant = 'R';
    a.quiet = 1;
    a.wrapped = 1;
    a.implicit = 1;
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
    uint32_t slot;
    if (ws_lookup_web(sc.world, sc.film, &slot) != WS_OK)
        return 1;
    ws_web *web = sc.world->webs[slot];
    if (!web->imp && ws_implicit_reserve(&sc.world->mem, web) != 0)
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
