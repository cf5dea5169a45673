/* Benchmark (not a test): a yardstick for the machine's speed at the time of a run. A plain
 * scalar explicit loop over the film of the wrapped reference case: the same 5856 nodes, their
 * places and masses, the same springs with their rest lengths and the same tension-compression
 * law, gravity and symplectic Euler at dt 0.25 ms, but no contacts and no bodies. Written as a
 * C programmer would write it first: nodes as structures, a list of springs, one loop over the
 * springs and one over the nodes, and compiled without vectors (bench/meson.build).
 *
 * Its figure, taken next to bench_wrapped's on the same core, turns a wall time that drifts
 * with the machine (a shared or virtual one varies by a third from hour to hour) into a ratio
 * that does not (bench/compare.sh runs the two side by side: see README). With `linear`, the
 * leanest loop of all: each spring linear, EA eps, without damping or the compression branch.
 * With a refinement r > 1 the film is the reference band refined r x r as bench_refine builds
 * it (node mass / r^2, the same stiffness per width), stepped at dt / r, as stable as the
 * unrefined loop at dt. Never fails on time.
 * Usage: bench_plain [steps] (default 24000) [linear|law] [refine r] (default 1) */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

#include <stdint.h>

#include "plain_film.h"

int main(int argc, char **argv)
{
    (void)tilt_run; /* the example's runner is not used here */
    long steps = argc > 1 ? atol(argv[1]) : 24000;
    plain_linear = argc > 2 && !strcmp(argv[2], "linear");
    const int r = argc > 3 ? atoi(argv[3]) : 1;
    tilt_options o;
    tilt_default_options(&o);
    o.wrapped = 1;
    o.refine = r;
    o.film_mass = 1e-3 / ((double)r * r);
    tilt_scene sc;
    if (steps <= 0 || r < 1 || tilt_build(&o, &sc) != WS_OK) {
        fprintf(stderr, "bench_plain: cannot build the scene\n");
        return 1;
    }
    /* The film as the reference case puts it on, with the example's laws (tilt_wrap): damping EA
     * times 0.1 / 2000 s (the paper's 0.1 kg/s over 2000 N/m). */
    plain_film pf;
    if (plain_film_load(sc.world, sc.film, 0.1 / 2000.0, &pf) != 0) {
        fprintf(stderr, "bench_plain: cannot read the film\n");
        return 1;
    }
    size_t n = pf.n, ns = pf.ns;
    const double dt = 0.25e-3 / r;
    struct timespec c0, c1;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    double t0 = now();
    for (long s = 0; s < steps; s++)
        plain_step(pf.nd, n, pf.sp, ns, dt, -9.81);
    double el = now() - t0;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
    const double cpu = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
    if (!isfinite(plain_film_check(&pf))) {
        fprintf(stderr, "bench_plain: the loop ran away\n");
        return 1;
    }
    printf("plain scalar explicit loop: the film of reference case P%s, %zu nodes, %zu springs "
           "(%s), no contacts, dt %.4g ms\n",
           r > 1 ? " refined" : "", n, ns, plain_linear ? "linear, undamped" : "the case's law",
           1e3 * dt);
    printf("  %ld steps in %.3f s: %.0f steps/s, %.2f M node-updates/s, %.1f us/step "
           "(24000 steps: %.2f s)\n",
           steps, el, steps / el, (double)n * steps / el / 1e6, 1e6 * el / steps,
           24000.0 * el / steps);
    printf("  CPU %.3f s: %.2f M node-updates/s of CPU\n", cpu, (double)n * steps / cpu / 1e6);
    plain_film_free(&pf);
    ws_world_destroy(sc.world);
    return 0;
}
