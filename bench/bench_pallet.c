/* Benchmark (not a test): the pallet load of the load-test guide (a EUR pallet, 4 layers of 8
 * cartons: 33 bodies on a platform), dt 0.25 ms, full detection every 10th step. Three phases,
 * each timed as the best of `repeats`: settling (1 s from the load as built), a EUMOS 40509 run
 * at 0.25 g (the pulse, the gentle stop, 0.5 s of rest) with its measurements every 4 steps,
 * and, with the load wrapped in the default band (ws_load_wrap_band), 1 s of stepping. Prints
 * steps/s, node-updates/s for the film, and the wall and CPU time; and, as a yardstick for the
 * machine's speed at the time (see bench_plain.c), the plain scalar explicit loop over the same
 * film (the same nodes, springs, laws and sub-steps, no contacts and no bodies) and the wrapped
 * load's CPU time as a ratio to it. Never fails on time.
 * Usage: bench_pallet [repeats] */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <wrapsim/wrapsim.h>

#include "plain_film.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The process's CPU time: on a machine shared with other work the wall clock counts their
 * time too; the two together say how much of the wall time was ours. */
static double cpu(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void die(ws_world *w, ws_status s)
{
    fprintf(stderr, "bench_pallet: %s (%s)\n", ws_status_string(s), ws_world_last_error(w));
    exit(1);
}

int main(int argc, char **argv)
{
    int repeats = argc > 1 ? atoi(argv[1]) : 3;
    if (repeats < 1)
        repeats = 1;
    double best_settle = INFINITY, best_run = INFINITY, run_time = 0;
    double cpu_settle = INFINITY, cpu_run = INFINITY, best_wrap = INFINITY, cpu_wrap = INFINITY;
    double cpu_plain = INFINITY;
    uint32_t nodes = 0;
    int substeps = 1;
    long settle_steps = 4000, run_steps = 0;
    ws_world_stats st = {0};
    uint64_t hash = 0;
    for (int k = 0; k < repeats; k++) {
        ws_world_def wd;
        ws_world_def_init(&wd);
        wd.detection_interval = 10;
        ws_world *w;
        ws_load *ld;
        ws_status s = ws_world_create(&wd, &w);
        if (s != WS_OK)
            die(NULL, s);
        ws_load_def d;
        ws_load_def_init(&d);
        if ((s = ws_load_build(w, &d, &ld)) != WS_OK)
            die(w, s);
        double t0 = now(), c0 = cpu();
        if ((s = ws_world_step_n(w, settle_steps)) != WS_OK)
            die(w, s);
        double el = now() - t0;
        best_settle = fmin(best_settle, el);
        cpu_settle = fmin(cpu_settle, cpu() - c0);
        ws_eumos_def e;
        ws_eumos_def_init(&e);
        e.k = 0.25;
        ws_eumos_result r;
        t0 = now();
        c0 = cpu();
        if ((s = ws_loadtest_run_eumos(w, ld, &e, &r)) != WS_OK)
            die(w, s);
        el = now() - t0;
        best_run = fmin(best_run, el);
        cpu_run = fmin(cpu_run, cpu() - c0);
        run_time = r.duration;
        ws_world_stats st1;
        ws_world_get_stats(w, &st1);
        run_steps = (long)st1.steps - settle_steps;
        st = st1;
        ws_world_get_state_hash(w, &hash);
        ws_wrap_def wr;
        ws_wrap_def_init(&wr);
        ws_web_id film;
        ws_web_info wi;
        if ((s = ws_load_wrap_band(w, ld, &wr, &film)) != WS_OK ||
            (s = ws_web_get_info(w, film, &wi)) != WS_OK)
            die(w, s);
        /* The plain loop over the film as it is laid on (every spring at its on-load strain), for
         * as many sub-steps as the wrapped load's phase takes. */
        plain_film pf;
        if (plain_film_load(w, film, 1e-5, &pf) != 0) {
            fprintf(stderr, "bench_pallet: cannot read the film\n");
            return 1;
        }
        double h = 2.5e-4 / wi.substeps;
        c0 = cpu();
        for (long i = 0; i < settle_steps * wi.substeps; i++)
            plain_step(pf.nd, pf.n, pf.sp, pf.ns, h, -9.81);
        cpu_plain = fmin(cpu_plain, cpu() - c0);
        if (!isfinite(plain_film_check(&pf))) {
            fprintf(stderr, "bench_pallet: the plain loop ran away\n");
            return 1;
        }
        plain_film_free(&pf);
        t0 = now();
        c0 = cpu();
        if ((s = ws_world_step_n(w, settle_steps)) != WS_OK)
            die(w, s);
        best_wrap = fmin(best_wrap, now() - t0);
        cpu_wrap = fmin(cpu_wrap, cpu() - c0);
        nodes = wi.node_count;
        substeps = wi.substeps;
        ws_load_destroy(ld);
        ws_world_destroy(w);
    }
    printf("libwrapsim %s: pallet load, 33 bodies unwrapped, dt 0.25 ms, detection every 10th "
           "step\n", ws_version_string());
    printf("settling   %8.0f steps/s  %6.1f us/step  %.3f s wall per simulated s  (%ld steps, "
           "best of %d: %.3f s; CPU %.3f s)\n", settle_steps / best_settle,
           1e6 * best_settle / settle_steps, best_settle / (settle_steps * 2.5e-4), settle_steps,
           repeats, best_settle, cpu_settle);
    printf("EUMOS run  %8.0f steps/s  %6.1f us/step  %.3f s wall per simulated s  (%ld steps, "
           "%.2f s simulated, best of %d: %.3f s; CPU %.3f s; measurements included)\n",
           run_steps / best_run, 1e6 * best_run / run_steps, best_run / run_time, run_steps,
           run_time, repeats, best_run, cpu_run);
    printf("wrapped    %8.0f steps/s  %6.1f us/step  %.1f M node-updates/s  (%u film nodes x %d "
           "sub-steps, %ld steps, best of %d: %.3f s; CPU %.3f s)\n", settle_steps / best_wrap,
           1e6 * best_wrap / settle_steps,
           (double)nodes * substeps * settle_steps / best_wrap / 1e6, nodes, substeps,
           settle_steps, repeats, best_wrap, cpu_wrap);
    printf("plain loop %8.0f steps/s  %6.1f us/step  %.1f M node-updates/s  (the same film, "
           "no contacts or bodies; figures of CPU time, %.3f s): wrapped / plain = %.2f (CPU)\n",
           settle_steps / cpu_plain, 1e6 * cpu_plain / settle_steps,
           (double)nodes * substeps * settle_steps / cpu_plain / 1e6, cpu_plain,
           cpu_wrap / cpu_plain);
    printf("  %llu contacts after the run, %llu full detections; state hash %016llx\n",
           (unsigned long long)st.contacts, (unsigned long long)st.full_detections,
           (unsigned long long)hash);
    return 0;
}
