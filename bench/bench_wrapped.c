/* Benchmark (not a test): the wrapped reference case (DESIGN.md), 5856 film nodes, dt 0.25 ms.
 * Prints wall time, steps/s, node-updates/s and where the time goes (contact detection, body
 * contacts, film). Never fails on time.
 * Usage: bench_wrapped [steps] (default 24000: the paper's 6 s, variant P) [P|R] [workers]
 * [rupture] (workers: of the step, default 1; the state hash is the same for any count;
 * rupture: the film's rupture strain, default 0: none, as in the reference case; with one the
 * peak strain and the springs broken are printed too). */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

int main(int argc, char **argv)
{
    (void)tilt_run; /* the example's runner is not used here */
    long steps = argc > 1 ? atol(argv[1]) : 24000;
    tilt_options o;
    tilt_default_options(&o);
    o.variant = argc > 2 ? argv[2][0] : 'P';
    o.wrapped = 1;
    o.profile = 1;
    o.workers = argc > 3 ? atoi(argv[3]) : 1;
    tilt_scene sc;
    if (tilt_build(&o, &sc) != WS_OK) {
        fprintf(stderr, "bench_wrapped: cannot build the scene\n");
        return 1;
    }
    const double rupture = argc > 4 ? atof(argv[4]) : 0.0;
    if (rupture != 0.0 && ws_web_set_rupture_strain(sc.world, sc.film, rupture) != WS_OK) {
        fprintf(stderr, "bench_wrapped: %s\n", ws_world_last_error(sc.world));
        return 1;
    }
    ws_web_info info;
    ws_web_get_info(sc.world, sc.film, &info);
    double t0 = now();
    ws_status s = ws_world_step_n(sc.world, steps);
    double el = now() - t0;
    if (s != WS_OK) {
        fprintf(stderr, "bench_wrapped: %s\n", ws_world_last_error(sc.world));
        return 1;
    }
    ws_world_stats st;
    ws_world_get_stats(sc.world, &st);
    double updates = (double)info.node_count * (double)info.substeps * (double)steps;
    printf("libwrapsim %s: reference case %c wrapped, %u film nodes x %d sub-step(s), dt 0.25 ms, "
           "%d worker(s)\n",
           ws_version_string(), o.variant, info.node_count, info.substeps, o.workers);
    printf("  %ld steps in %.3f s: %.0f steps/s, %.2f M node-updates/s, %.1f us/step\n", steps,
           el, steps / el, updates / el / 1e6, 1e6 * el / steps);
    double tot = st.seconds_total;
    printf("  time in the library %.3f s: contact detection %.1f %%, body contacts %.1f %%, "
           "film (springs, node contacts, integration) %.1f %%\n",
           tot, 100 * st.seconds_detection / tot, 100 * st.seconds_contacts / tot,
           100 * st.seconds_web / tot);
    printf("  %llu full body detections, %llu feature checks\n",
           (unsigned long long)st.full_detections, (unsigned long long)st.narrow_checks);
    if (rupture != 0.0) {
        ws_web_rupture r;
        ws_web_peak pk;
        ws_web_get_rupture(sc.world, sc.film, &r);
        ws_web_get_peak_strain(sc.world, sc.film, &pk);
        printf("  rupture strain %g: %u of %u springs broken", rupture, r.broken_count,
               info.spring_count);
        if (r.ruptured)
            printf(", the first at t = %.4f s (spring %u, z = %.3f m)", r.first_time,
                   r.first_spring, r.first_position.z);
        printf("; peak strain now %.4f (spring %u)\n", pk.strain, pk.spring);
    }
    uint64_t hash = 0;
    ws_world_get_state_hash(sc.world, &hash);
    ws_vec3 p0, p1;
    ws_body_get_position(sc.world, sc.box[0], &p0);
    ws_body_get_position(sc.world, sc.box[1], &p1);
    /* Where the boxes ended and the state hash: an optimisation that should not change the
     * results must leave them alone. */
    printf("  boxes at x = %.6f, %.6f m; state hash %016llx\n", p0.x, p1.x,
           (unsigned long long)hash);
    ws_world_destroy(sc.world);
    return 0;
}
