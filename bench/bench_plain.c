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
 * Never fails on time.
 * Usage: bench_plain [steps] (default 24000) [linear] */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

#include <stdint.h>

#include "plain_film.h"

int main(int argc, char **argv)
{
    (void)tilt_run; /* the example's runner is not used here */
    long steps = argc > 1 ? atol(argv[1]) : 24000;
    plain_linear = argc > 2 && !strcmp(argv[2], "linear");
    tilt_options o;
    tilt_default_options(&o);
    o.wrapped = 1;
    tilt_scene sc;
    if (steps <= 0 || tilt_build(&o, &sc) != WS_OK) {
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
    const double dt = 0.25e-3;
    double t0 = now();
    for (long s = 0; s < steps; s++)
        plain_step(pf.nd, n, pf.sp, ns, dt, -9.81);
    double el = now() - t0;
    if (!isfinite(plain_film_check(&pf))) {
        fprintf(stderr, "bench_plain: the loop ran away\n");
        return 1;
    }
    printf("plain scalar explicit loop: the film of reference case P, %zu nodes, %zu springs "
           "(%s), no contacts, dt 0.25 ms\n",
           n, ns, plain_linear ? "linear, undamped" : "the case's law");
    printf("  %ld steps in %.3f s: %.0f steps/s, %.2f M node-updates/s, %.1f us/step "
           "(24000 steps: %.2f s)\n",
           steps, el, steps / el, (double)n * steps / el / 1e6, 1e6 * el / steps,
           24000.0 * el / steps);
    plain_film_free(&pf);
    ws_world_destroy(sc.world);
    return 0;
}
