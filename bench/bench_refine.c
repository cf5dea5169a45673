/* Benchmark (not a test): the wrapped reference case (DESIGN.md, variant P) with its film band
 * refined r x r (r = 4: 16 times the nodes) beside the unrefined band, at the same dt and the
 * same film: node mass / r^2 (the same areal density), springs of the same stiffness per width
 * (tilt_table.c sets EA = k l0, and l0 falls as 1 / r), node contacts of 1 / r^2 the stiffness
 * and damping (the same pressure). The lighter nodes have a stable sub-step r times shorter, so
 * the refined film takes r times the sub-steps (2 r), which keeps the same fraction of its
 * stable sub-step (web_step_use, printed). Both are measured after the film has settled: the
 * band starts just touching and snaps onto the boxes; the timed windows start at `settle`
 * (default 0.5 s, the end of the every-step body detection) on the level platform.
 *
 * Cost is process CPU time (CLOCK_PROCESS_CPUTIME_ID: all threads, not the time a thread waits
 * for its core), in interleaved rounds: both worlds live side by side, each settled once, then
 * round after round a window of the unrefined one and a window of the refined one. Printed per
 * round: CPU per step, node-updates per second (nodes x sub-steps a second of CPU), the cost
 * ratio per step, and per node-update (the cost of 16 times the nodes at equal sub-steps, over
 * 16, is that per node-update ratio: the "16x the nodes at <= 16.5x the cost" reads
 * 16 x it <= 16.5); then the medians. Never fails on time.
 *
 * Usage:
 *   bench_refine [times] [rounds] [window] [workers] [settle] [r]
 *       window: steps of the unrefined window (default 400); the refined one takes window / r
 *       rounded to whole detection intervals (5 steps), default 100; r default 4.
 *   bench_refine save R FILE [settle] [workers]
 *       build the band refined R x R, settle it, save the world's state to FILE.
 *   bench_refine window R FILE STEPS [workers]
 *       build it again, restore FILE, step STEPS (0: none) and print the state hash: run under
 *       valgrind --tool=cachegrind, the difference of STEPS and 0 is the settled window's
 *       instructions and cache misses alone.
 */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

typedef struct bench_film {
    tilt_scene sc;
    int r;
    uint32_t nodes;
    int substeps;
    double use; /* fraction of the stable sub-step the film uses */
} bench_film;

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* CPU time of the calling thread alone: with workers, the world's thread runs the serial part
 * of a step and its own share of the lanes; the process's CPU less this is the workers'. */
static double thread_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The reference wrapped case P with the band refined r x r, the same film (see the top). */
static int film_build(bench_film *f, int r, int workers)
{
    tilt_options o;
    tilt_default_options(&o);
    o.variant = 'P';
    o.wrapped = 1;
    o.quiet = 1;
    o.profile = 1;
    o.workers = workers;
    o.refine = r;
    o.film_mass = 1e-3 / ((double)r * r);
    o.substeps = 2 * r;
    memset(f, 0, sizeof *f);
    f->r = r;
    if (tilt_build(&o, &f->sc) != WS_OK) {
        fprintf(stderr, "bench_refine: cannot build the band refined %d x %d\n", r, r);
        return -1;
    }
    ws_web_info info;
    ws_web_get_info(f->sc.world, f->sc.film, &info);
    f->nodes = info.node_count;
    f->substeps = info.substeps;
    return 0;
}

static int film_step(bench_film *f, long steps)
{
    if (steps <= 0)
        return 0;
    if (ws_world_step_n(f->sc.world, (uint64_t)steps) != WS_OK) {
        fprintf(stderr, "bench_refine: refine %d: %s\n", f->r, ws_world_last_error(f->sc.world));
        return -1;
    }
    ws_world_stats st;
    ws_world_get_stats(f->sc.world, &st);
    f->use = st.web_step_use;
    return 0;
}

static double median(double *a, int n)
{
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n; j++)
            if (a[j] < a[i]) {
                const double x = a[i];
                a[i] = a[j];
                a[j] = x;
            }
    return n % 2 ? a[n / 2] : 0.5 * (a[n / 2 - 1] + a[n / 2]);
}

/* One timed window: CPU seconds a step, and the library's own phase split (wall clock). */
typedef struct window {
    double cpu_step, main_step, wall_step, det, con, web;
} window;

static int film_window(bench_film *f, long steps, window *out)
{
    ws_world_stats a, b;
    ws_world_get_stats(f->sc.world, &a);
    const double c0 = cpu_now(), m0 = thread_now(), t0 = now();
    if (film_step(f, steps) != 0)
        return -1;
    const double c1 = cpu_now(), m1 = thread_now(), t1 = now();
    ws_world_get_stats(f->sc.world, &b);
    const double tot = b.seconds_total - a.seconds_total;
    out->cpu_step = (c1 - c0) / (double)steps;
    out->main_step = (m1 - m0) / (double)steps;
    out->wall_step = (t1 - t0) / (double)steps;
    out->det = (b.seconds_detection - a.seconds_detection) / tot;
    out->con = (b.seconds_contacts - a.seconds_contacts) / tot;
    out->web = (b.seconds_web - a.seconds_web) / tot;
    return 0;
}

static int run_times(int rounds, long window1, int workers, double settle, int r)
{
    bench_film f[2];
    if (film_build(&f[0], 1, workers) != 0 || film_build(&f[1], r, workers) != 0)
        return 1;
    long windows[2] = {window1, 5 * lround((double)window1 / r / 5.0)};
    if (windows[1] < 5)
        windows[1] = 5;
    printf("libwrapsim %s: reference case P wrapped, dt 0.25 ms, %d worker(s); film refined "
           "%d x %d beside the band as it is, the same film (node mass / %d, sub-steps x %d)\n",
           ws_version_string(), workers, r, r, r * r, r);
    for (int k = 0; k < 2; k++) {
        const double c0 = cpu_now();
        if (film_step(&f[k], lround(settle / f[k].sc.dt)) != 0)
            return 1;
        ws_world_stats st;
        ws_world_get_stats(f[k].sc.world, &st);
        printf("  refine %d: %u nodes x %d sub-steps, %.3f of the stable sub-step; settled to "
               "t = %.3f s in %.2f s of CPU; world %.1f MB (%.0f B a node); windows of %ld "
               "steps\n",
               f[k].r, f[k].nodes, f[k].substeps, f[k].use, settle, cpu_now() - c0,
               (double)st.bytes_in_use / 1e6, (double)st.bytes_in_use / f[k].nodes, windows[k]);
        /* The same film holds the boxes alike: the hoop line load and the bodies' normal force
         * on it must agree between the two (within the discretisation's few per cent). */
        ws_containment_band band;
        ws_web_get_containment(f[k].sc.world, f[k].sc.film, &band, 1);
        printf("    containment: line load %.2f N/m, contact force %.2f N\n", band.line_load,
               band.contact_force);
    }
    fflush(stdout);
    double q_step[64], q_node[64], rate[2][64], q_film[64], main_share[2][64];
    if (rounds > 64)
        rounds = 64;
    for (int i = 0; i < rounds; i++) {
        window w[2];
        for (int k = 0; k < 2; k++)
            if (film_window(&f[k], windows[k], &w[k]) != 0)
                return 1;
        for (int k = 0; k < 2; k++)
            rate[k][i] = (double)f[k].nodes * f[k].substeps / w[k].cpu_step;
        q_step[i] = w[1].cpu_step / w[0].cpu_step;
        q_node[i] = rate[0][i] / rate[1][i];
        /* The film's phase per node-update, refined over unrefined: the library's wall-clock
         * split of each window applied to its CPU time (a rough figure on a busy machine). */
        q_film[i] = (w[1].cpu_step * w[1].web / ((double)f[1].nodes * f[1].substeps)) /
                    (w[0].cpu_step * w[0].web / ((double)f[0].nodes * f[0].substeps));
        printf("  round %d: refine 1 %.1f us/step (%.1f M node-updates/s; det %.0f %%, body "
               "contacts %.0f %%, film %.0f %%), refine %d %.1f us/step (%.1f M/s; det %.0f %%, "
               "body %.0f %%, film %.0f %%); per step %.2f x, per node-update %.3f x (x %d: "
               "%.1f); film per node-update %.3f x\n",
               i + 1, 1e6 * w[0].cpu_step, rate[0][i] / 1e6, 100 * w[0].det, 100 * w[0].con,
               100 * w[0].web, r, 1e6 * w[1].cpu_step, rate[1][i] / 1e6, 100 * w[1].det,
               100 * w[1].con, 100 * w[1].web, q_step[i], q_node[i], r * r, r * r * q_node[i],
               q_film[i]);
        for (int k = 0; k < 2 && workers > 1; k++) {
            main_share[k][i] = w[k].main_step / w[k].cpu_step;
            printf("    refine %d: the world's thread %.1f us/step of CPU, the workers %.1f "
                   "(%.0f %% on the world's thread), wall %.1f us/step\n",
                   f[k].r, 1e6 * w[k].main_step, 1e6 * (w[k].cpu_step - w[k].main_step),
                   100 * main_share[k][i], 1e6 * w[k].wall_step);
        }
        fflush(stdout);
    }
    const double qn = median(q_node, rounds);
    printf("  median: per step %.2f x, per node-update %.3f x (%d x the nodes at equal sub-steps "
           "would cost %.2f x); %.1f and %.1f M node-updates/s of CPU (%d rounds)\n",
           median(q_step, rounds), qn, r * r, (double)r * r * qn, median(rate[0], rounds) / 1e6,
           median(rate[1], rounds) / 1e6, rounds);
    printf("  median: the film's phase per node-update %.3f x\n", median(q_film, rounds));
    if (workers > 1)
        printf("  median share of the process's CPU on the world's thread: refine 1 %.3f, refine "
               "%d %.3f\n",
               median(main_share[0], rounds), r, median(main_share[1], rounds));
    for (int k = 0; k < 2; k++) {
        uint64_t h = 0;
        double t = 0;
        ws_world_get_state_hash(f[k].sc.world, &h);
        ws_world_get_time(f[k].sc.world, &t);
        printf("  refine %d: state hash %016llx at t = %.4f s\n", f[k].r, (unsigned long long)h, t);
        ws_world_destroy(f[k].sc.world);
    }
    return 0;
}

int main(int argc, char **argv)
{
    (void)tilt_run; /* the example's runner is not used here */
    const char *what = argc > 1 ? argv[1] : "times";
    if (!strcmp(what, "times")) {
        const int rounds = argc > 2 ? atoi(argv[2]) : 5;
        const long window1 = argc > 3 ? atol(argv[3]) : 400;
        const int workers = argc > 4 ? atoi(argv[4]) : 1;
        const double settle = argc > 5 ? atof(argv[5]) : 0.5;
        const int r = argc > 6 ? atoi(argv[6]) : 4;
        if (rounds < 1 || window1 < 5 || workers < 1 || settle < 0 || r < 2) {
            fprintf(stderr, "bench_refine: bad arguments\n");
            return 2;
        }
        return run_times(rounds, window1, workers, settle, r);
    }
    if (!strcmp(what, "save") && argc > 3) {
        const int r = atoi(argv[2]);
        const double settle = argc > 4 ? atof(argv[4]) : 0.5;
        const int workers = argc > 5 ? atoi(argv[5]) : 1;
        bench_film f;
        if (r < 1 || film_build(&f, r, workers) != 0 ||
            film_step(&f, lround(settle / f.sc.dt)) != 0)
            return 1;
        if (ws_world_save_file(f.sc.world, argv[3]) != WS_OK) {
            fprintf(stderr, "bench_refine: %s\n", ws_world_last_error(f.sc.world));
            ws_world_destroy(f.sc.world);
            return 1;
        }
        printf("refine %d: %u nodes x %d sub-steps settled to t = %.3f s, saved to %s\n", r,
               f.nodes, f.substeps, settle, argv[3]);
        ws_world_destroy(f.sc.world);
        return 0;
    }
    if (!strcmp(what, "window") && argc > 4) {
        const int r = atoi(argv[2]);
        const long steps = atol(argv[4]);
        const int workers = argc > 5 ? atoi(argv[5]) : 1;
        bench_film f;
        if (r < 1 || steps < 0 || film_build(&f, r, workers) != 0)
            return 1;
        if (ws_world_restore_file(f.sc.world, argv[3]) != WS_OK) {
            fprintf(stderr, "bench_refine: %s\n", ws_world_last_error(f.sc.world));
            ws_world_destroy(f.sc.world);
            return 1;
        }
        const double c0 = cpu_now();
        if (film_step(&f, steps) != 0)
            return 1;
        const double el = cpu_now() - c0;
        uint64_t h = 0;
        double t = 0;
        ws_world_get_state_hash(f.sc.world, &h);
        ws_world_get_time(f.sc.world, &t);
        printf("refine %d: %u nodes x %d sub-steps, %ld steps from t = %.3f s in %.3f s of CPU "
               "(%.1f M node-updates/s); state hash %016llx\n",
               r, f.nodes, f.substeps, steps, t - (double)steps * f.sc.dt, el,
               steps > 0 ? (double)f.nodes * f.substeps * steps / el / 1e6 : 0.0,
               (unsigned long long)h);
        ws_world_destroy(f.sc.world);
        return 0;
    }
    fprintf(stderr, "usage: bench_refine [times [rounds] [window] [workers] [settle] [r]] | save R "
                    "FILE [settle] [workers] | window R FILE STEPS [workers]\n");
    return 2;
}
