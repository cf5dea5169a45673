/* Benchmark (not a test): the wrapped reference case R (DESIGN.md) with the film at its real
 * areal density, 1.6 mg nodes (1.6 mg a node), on the implicit film integrator, beside the
 * explicit film of 1 g nodes (the examples' choice) and the explicit film at the real mass with
 * the sub-steps its stability needs. Prints, for each run, the uphill edge's lift-off angle,
 * the tipping angle (the load's CoG over the stop's edge), the top box's largest slide on the
 * bottom one, wall time, CG iterations a step and node-updates a second per CG iteration.
 * Never fails on time.
 * Usage: bench_implicit [what] [duration s]: what = ref (the three films at dt 0.25 ms,
 * default; explicit: the two explicit films alone), dt (the implicit film at dt 0.25, 1, 1.6,
 * 2.4 and 2.5 ms; dt1 from 1 ms on; dt1sub: dt 1 ms with the film in 1 and in 4 sub-steps),
 * ratio (the three films' times
 * in interleaved rounds of a short run), refine (the implicit film's band refined 1, 2 and 4
 * times in each direction, short runs: cost per simulated second and containment; `refine
 * [duration] [r] [tolerance] [preconditioner]` runs refinement r alone, at that solve
 * tolerance, with that ws_web_preconditioner: 1 block Jacobi, 2 multigrid, 0 AUTO), rigid (the
 * unwrapped stack, no film, at dt 0.25 to 2.4 ms: the rigid contacts' own share of the limit),
 * crossing (drums of the real film from 10 x 10 to 96 x 96 nodes, block Jacobi and multigrid
 * in turn: CPU time a step and CG iterations, where the multigrid starts to pay; `crossing 0 1`
 * with a 1 kg box on each drum's middle, in the film's solve),
 * solve (`solve [duration] [dt ms] [preconditioner] [tolerance]`: one implicit run of case R),
 * phases (`phases [duration] [r] [dt ms]`: case R's band refined r x r on the multigrid, CG
 * iterations a step, mean and largest, and CPU s per simulated s, every 50 ms of the run;
 * WS_BENCH_SAVE=file with WS_BENCH_SAVE_AT=t saves the state at t, WS_BENCH_RESUME=file starts
 * from a saved one; WS_BENCH_WORKERS=n steps on n workers, the wall time printed beside the
 * CPU time), tilt (`tilt [duration] [r] [tolerance] [dt ms]`: as phases, at that solve
 * tolerance, and then the run's answers; WS_BENCH_RESUME and WS_BENCH_WORKERS as phases),
 * why (dt 1 ms: the boxes held during the film's solve or in it, box-box friction
 * regularised or stick; both at 0.25 and 0.125 ms; `why [duration] [case]` runs case 0..7
 * alone). */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

/* CPU seconds of this process: on a machine shared with other work the process's own time,
 * not the wall clock, is what a refinement costs (the runs are single-threaded). */
static double wall_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* `tilt`'s log of every 50 ms of a run: CG iterations a step, mean and largest, and CPU s per
 * simulated s, as `phases` prints them. */
typedef struct window_log {
    int r, known; /* known: `iterations` holds the run's count before the next step */
    long window, k, counted;
    double dt, cpu, wall;
    uint64_t iterations, sum, most;
} window_log;

static void window_step(const tilt_scene *sc, void *user)
{
    window_log *log = user;
    ws_web_solver_stats s;
    ws_web_get_solver_stats(sc->world, sc->film, &s);
    const uint64_t it = s.iterations - log->iterations;
    log->iterations = s.iterations;
    if (log->known) { /* a resumed run's first count is its history's */
        log->sum += it;
        log->most = it > log->most ? it : log->most;
        log->counted++;
    }
    log->known = 1;
    if (++log->k % log->window)
        return;
    double t, c = cpu_now(), wl = wall_now();
    ws_world_get_time(sc->world, &t);
    printf("  r %d  t %.2f s  CG %.2f it/step  most %llu  %.1f s CPU and %.1f s wall per "
           "simulated s\n",
           log->r, t, log->counted ? (double)log->sum / (double)log->counted : 0.0,
           (unsigned long long)log->most, (c - log->cpu) / (log->window * log->dt),
           (wl - log->wall) / (log->window * log->dt));
    fflush(stdout);
    log->sum = log->most = 0;
    log->counted = 0;
    log->cpu = c;
    log->wall = wl;
}

/* The workers of `phases` and `tilt` (WS_BENCH_WORKERS, default 1): the state is the same for
 * any count, the wall time is not. */
static int bench_workers(void)
{
    const char *e = getenv("WS_BENCH_WORKERS");
    return e && atoi(e) > 0 ? atoi(e) : 1;
}

static void line(const char *name, const tilt_options *o)
{
    tilt_result r;
    tilt_run(o, &r);
    if (r.status != WS_OK) {
        printf("  %-34s failed: %s\n", name, r.error);
        return;
    }
    const double steps = (double)r.steps;
    printf("  %-34s lift %7.3f deg  tip %7.3f deg  slide %6.3f mm  %8.2f s wall", name,
           r.lift_angle, r.over_angle, 1e3 * r.max_relative_slip, r.wall_seconds);
    if (r.solver.solves)
        printf("  CG %.1f it/step, %.2f M node-updates/s per CG iteration",
               (double)r.solver.iterations / steps,
               (double)r.film_nodes * (double)r.solver.iterations / r.wall_seconds / 1e6);
    printf("\n");
    fflush(stdout);
}

/* The unwrapped stack of case R on the level platform for its first second at step dt: the
 * bodies' largest kinetic energy (J) and the bottom box's highest rise above its start (m). A
 * stack that settles keeps both small (millijoules, tenths of a millimetre); a runaway does not. */
static void settle_motion(double dt, double *kmax, double *rise, char *why, size_t why_size)
{
    why[0] = 0;
    tilt_options a;
    tilt_default_options(&a);
    a.variant = 'R';
    a.quiet = 1;
    a.dt = dt;
    tilt_scene sc;
    *kmax = *rise = NAN;
    if (tilt_build(&a, &sc) != WS_OK)
        return;
    ws_vec3 r0;
    ws_body_get_position(sc.world, sc.box[0], &r0);
    *kmax = *rise = 0.0;
    for (long n = lround(1.0 / dt); n > 0; n--) {
        if (ws_world_step(sc.world) != WS_OK) {
            snprintf(why, why_size, "%s", ws_world_last_error(sc.world));
            *kmax = *rise = NAN;
            break;
        }
        ws_energy e;
        ws_vec3 r;
        ws_world_get_energy(sc.world, &e);
        ws_body_get_position(sc.world, sc.box[0], &r);
        *kmax = fmax(*kmax, e.kinetic);
        *rise = fmax(*rise, r.z - r0.z);
    }
    ws_world_destroy(sc.world);
}

/* A drum of the real film, n x n nodes 1 cm apart pinned along the edge, pre-stretched 40 % and
 * 20 % as the reference band, its laws (2000 N/m a spring, 1 % in compression) and areal
 * density, sagging under gravity at dt 0.25 ms from flat: after 40 steps untimed, CPU seconds
 * a step and CG iterations a step over 200 more, with preconditioner pre. */
/* A box resting on the drum's middle (half its side each way, 1 kg, in the film's solve):
 * the crossing with a body in the solve. */
static ws_status drum_box(ws_world *w, int n, ws_web_def *wd)
{
    ws_material_def md;
    ws_material_def_init(&md);
    ws_material_id film_mat, box_mat;
    ws_status s;
    if ((s = ws_material_create(w, &md, &film_mat)) != WS_OK ||
        (s = ws_material_create(w, &md, &box_mat)) != WS_OK)
        return s;
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 4000.0;
    cd.damping = 1.0;
    cd.friction = 0.5;
    if ((s = ws_world_set_contact(w, film_mat, box_mat, &cd)) != WS_OK)
        return s;
    const double a = 0.005 * n; /* the box's side: half the drum's */
    ws_shape_id cube;
    if ((s = ws_shape_create_box(w, a, a, a, &cube)) != WS_OK)
        return s;
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = cube;
    bd.mass = 1.0;
    bd.material = box_mat;
    bd.position = (ws_vec3){0.0, 0.0, a / 2 + 1.9e-3}; /* its layer just on the film's */
    ws_body_id body;
    wd->material = film_mat;
    return ws_body_create(w, &bd, &body);
}

static ws_status drum_run(int n, int pre, int box, double *cpu_per_step, double *iterations)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = 2.5e-4;
    ws_world *w = NULL;
    ws_status s = ws_world_create(&d, &w);
    if (s != WS_OK)
        return s;
    ws_law_def ld;
    ws_law_id law;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_TENSION_COMPRESSION;
    ld.stiffness = 2000.0 * 0.01 / 1.4;
    ld.compression_stiffness = 0.01 * ld.stiffness;
    ld.damping = 0.1 * 0.01 / 1.4;
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.areal_density = 0.018;
    wd.integrator = WS_WEB_IMPLICIT;
    wd.preconditioner = pre;
    if (box && (s = drum_box(w, n, &wd)) != WS_OK) {
        ws_world_destroy(w);
        return s;
    }
    ws_sheet_def sd;
    ws_sheet_def_init(&sd);
    sd.nx = sd.ny = n;
    sd.origin = (ws_vec3){-0.005 * (n - 1), -0.005 * (n - 1), 0.0}; /* centred */
    sd.spacing_x = sd.spacing_y = 0.01;
    sd.prestretch_x = 0.4;
    sd.prestretch_y = 0.2;
    sd.shear = 1;
    uint32_t pins[4 * 96];
    size_t np = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
            if (i == 0 || j == 0 || i == n - 1 || j == n - 1)
                pins[np++] = (uint32_t)(i + n * j);
    sd.pinned = pins;
    sd.pinned_count = np;
    ws_web_id id;
    if ((s = ws_law_create(w, &ld, &law)) == WS_OK) {
        wd.law = wd.law_shear = law;
        s = ws_web_create_sheet(w, &wd, &sd, &id);
    }
    if (s == WS_OK)
        s = ws_world_step_n(w, 40);
    ws_web_solver_stats s0, s1;
    const int steps = 200;
    double c0 = cpu_now();
    if (s == WS_OK && (s = ws_web_get_solver_stats(w, id, &s0)) == WS_OK)
        s = ws_world_step_n(w, steps);
    *cpu_per_step = (cpu_now() - c0) / steps;
    if (s == WS_OK && (s = ws_web_get_solver_stats(w, id, &s1)) == WS_OK)
        *iterations = (double)(s1.iterations - s0.iterations) / steps;
    ws_world_destroy(w);
    return s;
}

int main(int argc, char **argv)
{
    const char *what = argc > 1 ? argv[1] : "ref";
    const double duration = argc > 2 ? atof(argv[2]) : 0.0;
    tilt_options o;
    tilt_default_options(&o);
    o.variant = 'R';
    o.wrapped = 1;
    o.quiet = 1;
    o.duration = duration;
    printf("libwrapsim %s: reference case R wrapped%s\n", ws_version_string(),
           duration > 0 ? " (shortened)" : "");
    if (!strcmp(what, "ref") || !strcmp(what, "explicit")) {
        const int implicit = !strcmp(what, "ref"); /* explicit: the two explicit films alone */
        tilt_options a = o;
        line("explicit, 1 g nodes, 2 sub-steps", &a);
        a.film_mass = 1.6e-6;
        a.substeps = 1;
        if (implicit) {
            a.implicit = 1;
            line("implicit, 1.6 mg nodes, dt 0.25 ms", &a);
            a.implicit = 0;
        }
        /* The fewest sub-steps the film check accepts for 1.6 mg nodes at the default
         * stable_fraction 0.5 (its refusal says so). */
        a.substeps = 285;
        line("explicit, 1.6 mg nodes, 285 sub-steps", &a);
    } else if (!strcmp(what, "dt") || !strcmp(what, "dt1")) {
        const int first_dt = !strcmp(what, "dt1"); /* dt1: from 1 ms on */
        /* 2.5 ms is refused by the box-box pair's bound (2.45 ms: 2e5 N/m on an effective 2.5
         * kg over 8 contacts) and 2.4 ms by the stack's own highest mode (1.86 ms: the boxes
         * rocking against each other, docs/theory.md section 8): both print the refusal. 1.6
         * ms is below both. */
        const double dts[5] = {2.5e-4, 1e-3, 1.6e-3, 2.4e-3, 2.5e-3};
        for (int k = first_dt; k < 5; k++) {
            tilt_options a = o;
            a.film_mass = 1.6e-6;
            a.implicit = 1;
            a.substeps = 1;
            a.dt = dts[k];
            char name[64];
            snprintf(name, sizeof name, "implicit, 1.6 mg nodes, dt %.2f ms", 1e3 * dts[k]);
            line(name, &a);
        }
    } else if (!strcmp(what, "solve")) {
        /* `solve [duration] [dt ms] [preconditioner] [tolerance]`: the implicit film at one
         * dt with one ws_web_preconditioner (0 AUTO, 1 block Jacobi, 2 multigrid) and solve
         * tolerance (0: the default): whether the answers are the solve's and not its
         * preconditioner's, which a tighter tolerance must leave where they are. */
        tilt_options a = o;
        a.film_mass = 1.6e-6;
        a.implicit = 1;
        a.substeps = 1;
        a.dt = 1e-3 * (argc > 3 ? atof(argv[3]) : 1.0);
        a.preconditioner = argc > 4 ? atoi(argv[4]) : 0;
        a.solver_tolerance = argc > 5 ? atof(argv[5]) : 0.0;
        ws_web_def dw;
        ws_web_def_init(&dw);
        char name[96];
        snprintf(name, sizeof name, "implicit, dt %.2f ms, preconditioner %d, tolerance %g",
                 1e3 * a.dt, a.preconditioner,
                 a.solver_tolerance > 0 ? a.solver_tolerance : dw.solver_tolerance);
        line(name, &a);
    } else if (!strcmp(what, "dt1sub")) {
        /* What limits dt 1 ms: the world (bodies and their contacts) at 1 ms with the film at
         * 4 sub-steps of 0.25 ms each, beside both at 1 ms (dt1's first line). When the film's
         * sub-steps bring the slide back to the 0.25 ms run's, the film's own step (its
         * contacts' and friction's linearisation over h) is what limits; when not, the
         * bodies' step and their coupling to the film are. */
        for (int k = 0; k < 2; k++) {
            tilt_options a = o;
            a.film_mass = 1.6e-6;
            a.implicit = 1;
            a.substeps = k ? 4 : 1;
            a.dt = 1e-3;
            line(k ? "implicit, dt 1 ms, 4 film sub-steps" : "implicit, dt 1 ms, 1 film step",
                 &a);
        }
    } else if (!strcmp(what, "ratio")) {
        /* Time ratios from interleaved rounds of the first `duration` s (default 0.5 s: the
         * wrapped stack settling, the same work a step as later): the three films of `ref`,
         * round after round, each round's ratios to the explicit 1 g film, and their medians. */
        const double T = duration > 0 ? duration : 0.5;
        enum { ROUNDS = 3 };
        double t[ROUNDS][3];
        for (int k = 0; k < ROUNDS; k++) {
            for (int f = 0; f < 3; f++) {
                tilt_options a = o;
                a.duration = T;
                if (f > 0)
                    a.film_mass = 1.6e-6;
                a.implicit = f == 1;
                a.substeps = f == 0 ? 0 : f == 1 ? 1 : 285;
                tilt_result r;
                tilt_run(&a, &r);
                t[k][f] = r.status == WS_OK ? r.wall_seconds : NAN;
            }
            printf("  round %d: explicit 1 g %.2f s, implicit 1.6 mg %.2f s (%.1f x), explicit "
                   "1.6 mg x 285 %.2f s (%.1f x); implicit / explicit at 1.6 mg %.3f\n",
                   k + 1, t[k][0], t[k][1], t[k][1] / t[k][0], t[k][2], t[k][2] / t[k][0],
                   t[k][1] / t[k][2]);
            fflush(stdout);
        }
        double q[ROUNDS];
        for (int k = 0; k < ROUNDS; k++)
            q[k] = t[k][1] / t[k][2];
        for (int i = 0; i < ROUNDS; i++) /* sort the three */
            for (int j = i + 1; j < ROUNDS; j++)
                if (q[j] < q[i]) {
                    const double x = q[i];
                    q[i] = q[j];
                    q[j] = x;
                }
        printf("  median implicit / explicit at the real mass: %.3f\n", q[ROUNDS / 2]);
    } else if (!strcmp(what, "refine")) {
        /* The wrapped stack on the level platform (the tilt starts at 1 s), its band at the
         * real areal density refined r x r: after the film's first pull-in (`duration`, default
         * 0.05 s, not timed: the band starts just touching and its light nodes snap onto the
         * boxes), CPU time per simulated second over as long again, and the containment then
         * (the line load of the hoop tension, N/m, and the bodies' total normal force on the
         * film, N), which refinement must leave alone. */
        const double T = duration > 0 ? duration : 0.05;
        const int only = argc > 3 ? atoi(argv[3]) : 0; /* one refinement alone */
        const double tol = argc > 4 ? atof(argv[4]) : 0.0; /* the solve's tolerance; 0: the default */
        const int pre = argc > 5 ? atoi(argv[5]) : 0; /* ws_web_preconditioner; 0: AUTO */
        double base = 0;
        for (int r = 1; r <= 4; r *= 2) {
            if (only > 0 && r != only)
                continue;
            tilt_options a = o;
            a.areal_density = 0.018;
            a.implicit = 1;
            a.substeps = 1;
            a.refine = r;
            a.solver_tolerance = tol;
            a.preconditioner = pre;
            tilt_scene sc;
            if (tilt_build(&a, &sc) != WS_OK) {
                printf("  refine %d: cannot build\n", r);
                continue;
            }
            const long steps = lround(T / sc.dt);
            ws_status st = ws_world_step_n(sc.world, (uint64_t)steps);
            ws_web_solver_stats s0;
            ws_web_get_solver_stats(sc.world, sc.film, &s0);
            const double t0 = now(), c0 = cpu_now();
            if (st == WS_OK)
                st = ws_world_step_n(sc.world, (uint64_t)steps);
            const double wall = now() - t0, el = cpu_now() - c0;
            if (st != WS_OK) {
                printf("  refine %d: %s\n", r, ws_world_last_error(sc.world));
                ws_world_destroy(sc.world);
                continue;
            }
            ws_containment_band band;
            ws_web_get_containment(sc.world, sc.film, &band, 1);
            ws_web_info info;
            ws_web_get_info(sc.world, sc.film, &info);
            ws_web_solver_stats ss;
            ws_web_get_solver_stats(sc.world, sc.film, &ss);
            uint64_t hash = 0;
            ws_world_get_state_hash(sc.world, &hash);
            if (r == 1)
                base = el / T;
            printf("  refine %d (%u nodes): %.1f s CPU (%.1f s wall) per simulated s (%.2f x "
                   "unrefined), CG %.1f it/step (%.2f solves/step); line load %.2f N/m, contact force "
                   "%.2f N; state %016llx\n",
                   r, info.node_count, el / T, wall / T, el / T / base,
                   (double)(ss.iterations - s0.iterations) / steps,
                   (double)(ss.solves - s0.solves) / steps,
                   band.line_load, band.contact_force, (unsigned long long)hash);
            fflush(stdout);
            ws_world_destroy(sc.world);
        }
    } else if (!strcmp(what, "phases")) {
        /* Case R's band at the real areal density refined r x r (`phases [duration] [r] [dt
         * ms]`, default 1.5 s, 1 and 0.25 ms): CG iterations a step, mean and largest, and the
         * CPU time per simulated second over every 50 ms of the run, to see where in the run
         * (the pull-in, the settling, the tilt from 1 s) the iterations are taken; the
         * multigrid at every r, as `refine` with preconditioner 2. */
        const double T = duration > 0 ? duration : 1.5;
        const int r = argc > 3 ? atoi(argv[3]) : 1;
        tilt_options a = o;
        a.areal_density = 0.018;
        a.implicit = 1;
        a.substeps = 1;
        a.refine = r;
        a.preconditioner = WS_WEB_PRECONDITIONER_MULTIGRID;
        a.dt = 1e-3 * (argc > 4 ? atof(argv[4]) : 0.25);
        a.workers = bench_workers();
        tilt_scene sc;
        if (tilt_build(&a, &sc) != WS_OK) {
            printf("  refine %d: cannot build\n", r);
            return 1;
        }
        /* Checkpoints of the later tilt (the environment, so the arguments stay as they are):
         * WS_BENCH_RESUME=file restores a state saved by this same scene before the first
         * step (the run then covers `duration` from the saved time), WS_BENCH_SAVE=file with
         * WS_BENCH_SAVE_AT=t (s) saves the state once the run reaches t. */
        const char *resume = getenv("WS_BENCH_RESUME"), *save = getenv("WS_BENCH_SAVE");
        const double save_at = getenv("WS_BENCH_SAVE_AT") ? atof(getenv("WS_BENCH_SAVE_AT")) : -1;
        if (resume && ws_world_restore_file(sc.world, resume) != WS_OK) {
            printf("  resume %s: %s\n", resume, ws_world_last_error(sc.world));
            return 1;
        }
        double t_start = 0;
        ws_world_get_time(sc.world, &t_start);
        const long steps = lround(T / sc.dt), window = lround(0.05 / sc.dt);
        int saved = 0;
        ws_web_solver_stats prev;
        ws_web_get_solver_stats(sc.world, sc.film, &prev);
        window_log log = {.r = r, .known = 1, .iterations = prev.iterations, .window = window,
                          .dt = sc.dt, .cpu = cpu_now(), .wall = wall_now()};
        for (long k = 1; k <= steps; k++) {
            if (ws_world_step(sc.world) != WS_OK) {
                printf("  refine %d: %s\n", r, ws_world_last_error(sc.world));
                break;
            }
            if (save && !saved && t_start + k * sc.dt >= save_at - 0.5 * sc.dt && save_at >= 0) {
                saved = 1;
                if (ws_world_save_file(sc.world, save) != WS_OK)
                    printf("  save %s: %s\n", save, ws_world_last_error(sc.world));
                else
                    printf("  saved %s at t %.4f s\n", save, t_start + k * sc.dt);
            }
            window_step(&sc, &log);
        }
        uint64_t hash = 0;
        ws_world_get_state_hash(sc.world, &hash);
        printf("  state hash %016llx (%d workers)\n", (unsigned long long)hash, a.workers);
        ws_world_destroy(sc.world);
    } else if (!strcmp(what, "tilt")) {
        /* `tilt [duration] [r] [tolerance] [dt ms]`: case R's run with its band refined r x r
         * on the multigrid at that solve tolerance (0: the default), as `phases` every 50 ms,
         * and then its answers (lift-off, tipping, slide) and CPU time; WS_BENCH_RESUME=file
         * starts from a state `phases` saved (the slide then counts from it): whether a
         * tolerance moves the answers, and what it costs. */
        tilt_options a = o;
        a.areal_density = 0.018;
        a.implicit = 1;
        a.substeps = 1;
        a.refine = argc > 3 ? atoi(argv[3]) : 1;
        a.solver_tolerance = argc > 4 ? atof(argv[4]) : 0.0;
        a.preconditioner = WS_WEB_PRECONDITIONER_MULTIGRID;
        a.dt = 1e-3 * (argc > 5 ? atof(argv[5]) : 0.25);
        a.resume = getenv("WS_BENCH_RESUME");
        a.workers = bench_workers();
        window_log log = {.r = a.refine, .window = lround(0.05 / a.dt), .dt = a.dt,
                          .cpu = cpu_now(), .wall = wall_now()};
        a.each_step = window_step;
        a.user = &log;
        const double c0 = log.cpu;
        tilt_result res;
        tilt_run(&a, &res);
        if (res.status != WS_OK) {
            printf("  refine %d: %s\n", a.refine, res.error);
            return 1;
        }
        printf("  refine %d, tolerance %g: lift %.3f deg  tip %.3f deg  slide %.3f mm (from "
               "%s)  to t %.3f s: %.1f s CPU, CG %.2f it/step; state %016llx\n",
               a.refine, a.solver_tolerance, res.lift_angle, res.over_angle,
               1e3 * res.max_relative_slip, a.resume ? "the saved state" : "t = 0",
               res.end_time, cpu_now() - c0,
               (double)res.solver.iterations / (double)res.steps, (unsigned long long)res.hash);
    } else if (!strcmp(what, "crossing")) {
        const int sides[] = {10, 12, 16, 24, 32, 40, 48, 64, 96};
        const int box = argc > 3 ? atoi(argv[3]) : 0; /* a box on the drum, in its solve */
        for (size_t k = 0; k < sizeof sides / sizeof sides[0]; k++) {
            double cpu[2], its[2];
            for (int round = 0; round < 3; round++) /* interleaved; the least of 3 kept */
                for (int m = 0; m < 2; m++) {
                    double c, it;
                    if (drum_run(sides[k], m ? WS_WEB_PRECONDITIONER_MULTIGRID
                                             : WS_WEB_PRECONDITIONER_BLOCK_JACOBI,
                                 box, &c, &it) != WS_OK) {
                        printf("  drum %d: failed\n", sides[k]);
                        return 1;
                    }
                    if (round == 0 || c < cpu[m])
                        cpu[m] = c;
                    its[m] = it;
                }
            printf("  drum %2d x %2d (%4d nodes): block Jacobi %7.1f us a step (CG %5.1f it), "
                   "multigrid %7.1f us (CG %4.1f it): multigrid / block Jacobi %.2f\n",
                   sides[k], sides[k], sides[k] * sides[k], 1e6 * cpu[0], its[0], 1e6 * cpu[1],
                   its[1], cpu[1] / cpu[0]);
            fflush(stdout);
        }
    } else if (!strcmp(what, "why")) {
        /* What limits dt 1 ms, one cause at a time (`why [duration] [case]`, case alone or
         * all): the implicit film at 1 ms with the boxes held during its solve (the explicit
         * coupling) or in it (the default), each with the box-box friction regularised (the
         * paper's law) and with the stick model; then both couplings at 0.25 and 0.125 ms
         * (which answer the step converges to). */
        static const struct {
            const char *name;
            double dt;
            int hold, stick;
        } cases[8] = {{"1 ms, held, regularised", 1e-3, 1, 0},
                      {"1 ms, held, stick", 1e-3, 1, 1},
                      {"1 ms, in the solve, regularised", 1e-3, 0, 0},
                      {"1 ms, in the solve, stick", 1e-3, 0, 1},
                      {"0.25 ms, in the solve, regularised", 2.5e-4, 0, 0},
                      {"0.25 ms, held, regularised", 2.5e-4, 1, 0},
                      {"0.125 ms, held, regularised", 1.25e-4, 1, 0},
                      {"0.125 ms, in the solve, regularised", 1.25e-4, 0, 0}};
        const int only = argc > 3 ? atoi(argv[3]) : -1;
        for (int k = 0; k < 8; k++) {
            if (only >= 0 && k != only)
                continue;
            tilt_options a = o;
            a.film_mass = 1.6e-6;
            a.implicit = 1;
            a.substeps = 1;
            a.dt = cases[k].dt;
            a.hold_bodies = cases[k].hold;
            a.stick = cases[k].stick;
            line(cases[k].name, &a);
        }
    } else if (!strcmp(what, "rigid")) {
        /* The rigid contacts' share of the step limit, without the film: the top box's slide
         * onset on the bottom one (Coulomb: atan 0.3 = 16.70 deg) with the regularised law and
         * the stick model, and the first second's motion (bounce) of the settling stack. */
        const double dts[6] = {2.5e-4, 4e-4, 5e-4, 7.5e-4, 1e-3, 2.4e-3};
        for (int k = 0; k < 6; k++) {
            double slide[2];
            for (int stick = 0; stick < 2; stick++) {
                tilt_options a = o;
                a.wrapped = 0;
                a.dt = dts[k];
                a.stick = stick;
                tilt_result r;
                tilt_run(&a, &r);
                slide[stick] = r.status == WS_OK ? r.slide_angle[1] : NAN;
            }
            double kmax, rise;
            char why[512];
            settle_motion(dts[k], &kmax, &rise, why, sizeof why);
            if (why[0]) {
                printf("  unwrapped, dt %.2f ms: failed: %s\n", 1e3 * dts[k], why);
                continue;
            }
            printf("  unwrapped, dt %.2f ms: top box slides at %6.2f deg (regularised), %6.2f deg "
                   "(stick); first second: kinetic energy <= %.3g J, bottom box rises <= %.3g mm\n",
                   1e3 * dts[k], slide[0], slide[1], kmax, 1e3 * rise);
            fflush(stdout);
        }
    } else {
        return 2;
    }
    return 0;
}
