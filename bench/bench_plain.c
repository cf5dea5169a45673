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
 *
 * With `contacts`, the yardstick with the film's work on the boxes: each node against each of
 * the two boxes at rest where the case puts them (plain_contacts: penalty and regularised
 * friction, the case's film-box parameters, the box's load summed), stepped at the wrapped
 * case's sub-step (dt / its sub-steps, that many steps a step), so that its node-updates are
 * the wrapped case's; it prints the node contacts a node-update beside the time. The film
 * pulls onto the boxes and stays on them, where the wrapped case's lifts off as the stack tips:
 * compare its contacts a node-update with the case's (bench_wrapped prints them).
 * Usage: bench_plain [steps] (default 24000) [linear|law] [refine r] (default 1) [contacts] */
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
    const int contacts = argc > 4 && !strcmp(argv[4], "contacts");
    /* The case's boxes (a = 0.25 m cubes, contact layer 1 mm) and its film-box contact, per
     * node (tilt_table.c: 4000 N/m and 1 N s/m over r^2, mu 0.9, v_lim 10 mm/s). */
    plain_box bx[2];
    const double half[3] = {0.125, 0.125, 0.125};
    plain_contact pc = {4000.0 / ((double)r * r), 1.0 / ((double)r * r), 0.9, sc.vlim, 0};
    ws_web_info info;
    ws_web_get_info(sc.world, sc.film, &info);
    const int subs = contacts ? info.substeps : 1;
    for (int b = 0; b < 2; b++)
        plain_box_load(sc.world, sc.box[b], half, 1e-3, &bx[b]);
    const double dt = 0.25e-3 / r / subs;
    steps *= subs;
    struct timespec c0, c1;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    double t0 = now();
    for (long s = 0; s < steps; s++) {
        if (contacts)
            plain_step_contacts(pf.nd, n, pf.sp, ns, dt, -9.81, bx, 2, &pc);
        else
            plain_step(pf.nd, n, pf.sp, ns, dt, -9.81);
    }
    double el = now() - t0;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
    const double cpu = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
    if (!isfinite(plain_film_check(&pf))) {
        fprintf(stderr, "bench_plain: the loop ran away\n");
        return 1;
    }
    printf("plain scalar explicit loop: the film of reference case P%s, %zu nodes, %zu springs "
           "(%s), %s, dt %.4g ms\n",
           r > 1 ? " refined" : "", n, ns, plain_linear ? "linear, undamped" : "the case's law",
           contacts ? "each node against the two boxes at rest" : "no contacts", 1e3 * dt);
    if (contacts)
        printf("  %.3f node contacts a node-update; the film's load on the boxes now %.2f, "
               "%.2f N (x)\n",
               (double)pc.touching / ((double)n * (double)steps), bx[0].f[0], bx[1].f[0]);
    const long cs = steps / subs; /* the case's steps */
    printf("  %ld steps (%d sub-step(s) each) in %.3f s: %.0f steps/s, %.2f M node-updates/s, "
           "%.1f us/step (24000 steps: %.2f s)\n",
           cs, subs, el, cs / el, (double)n * steps / el / 1e6, 1e6 * el / cs, 24000.0 * el / cs);
    printf("  CPU %.3f s: %.2f M node-updates/s of CPU\n", cpu, (double)n * steps / cpu / 1e6);
    plain_film_free(&pf);
    ws_world_destroy(sc.world);
    return 0;
}
