/* Benchmark (not a test): the unwrapped reference case, variant R, 28000 steps, stepping only (no
 * read-back), with and without the libccd gate. Prints steps/s, microseconds per step and narrow
 * feature checks per second. Never fails on time.
 * Usage: bench_tilt [repeats] */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

static void bench(int use_ccd, int repeats)
{
    double best = INFINITY;
    ws_world_stats st = {0};
    long steps = 0;
    for (int k = 0; k < repeats; k++) {
        tilt_options o;
        tilt_default_options(&o);
        o.use_ccd = use_ccd;
        tilt_scene sc;
        if (tilt_build(&o, &sc) != WS_OK) {
            fprintf(stderr, "bench_tilt: cannot build the scene\n");
            exit(1);
        }
        steps = lround(sc.duration / sc.dt);
        double t0 = now();
        ws_status s = ws_world_step_n(sc.world, steps);
        double el = now() - t0;
        if (s != WS_OK) {
            fprintf(stderr, "bench_tilt: %s\n", ws_world_last_error(sc.world));
            exit(1);
        }
        if (el < best)
            best = el;
        ws_world_get_stats(sc.world, &st);
        ws_world_destroy(sc.world);
    }
    printf("%-14s %9.0f steps/s  %6.2f us/step  %6.2f M checks/s  (%ld steps, best of %d: %.3f s; "
           "%llu full detections, %llu pairs tested, %llu gated)\n",
           use_ccd ? "with libccd" : "without libccd", steps / best, 1e6 * best / steps,
           st.narrow_checks / best / 1e6, steps, repeats, best,
           (unsigned long long)st.full_detections, (unsigned long long)st.body_pairs_tested,
           (unsigned long long)st.body_pairs_gated);
}

int main(int argc, char **argv)
{
    (void)tilt_run; /* the example's runner is not used here */
    int repeats = argc > 1 ? atoi(argv[1]) : 5;
    if (repeats < 1)
        repeats = 1;
    printf("libwrapsim %s: reference case R unwrapped (4 bodies, dt 0.25 ms, 7 s)\n",
           ws_version_string());
    if (ws_build_features() & WS_FEATURE_CCD)
        bench(1, repeats);
    bench(0, repeats);
    return 0;
}
