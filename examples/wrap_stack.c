/*
 * wrap_stack.c: wrap your own load in stretch film and read what the film does.
 *
 * A pallet (a kinematic slab, top face at z = 0) carries a stack of boxes: 2 x 2 boxes of
 * 0.4 x 0.3 x 0.25 m and 12 kg a layer, two layers high. A band of film goes around the whole
 * stack, pre-stretched 40 % around and 20 % up, and settles for 1 s. Then the example prints the
 * film's stable sub-step, the containment profile (bottom, middle, top), the force the film puts
 * on each box and the peak spring tension.
 *
 * Build:  cc wrap_stack.c $(pkg-config --cflags --libs libwrapsim) -o wrap_stack
 * Run:    ./wrap_stack [--duration S] [--vtk DIR [--vtk-every S] [--vtk-springs]]
 *                      [--film-mass KG] [--substeps N] [--quiet]
 *
 * Copy this file for your own load: change LOAD (or the loop in build_stack() for boxes of
 * different sizes), the film in wrap_film(), and what main() reads at the end.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <wrapsim/wrapsim.h>

#define WRAP_PI 3.14159265358979323846
#define MAX_BOXES 64

/* The load: boxes along x, along y, layers; box size (m) and mass (kg). */
static const struct {
    int columns, rows, layers;
    double lx, ly, lz, mass;
} LOAD = {2, 2, 2, 0.4, 0.3, 0.25, 12.0};

static const double LAYER = 1e-3; /* contact layer of every body and film node, m */

typedef struct scene {
    ws_world *world;
    ws_body_id pallet, box[MAX_BOXES];
    int boxes;
    ws_web_id film;
    double node_mass; /* kg per film node */
} scene;

#define TRY(call)                                                                                  \
    do {                                                                                           \
        if ((s = (call)) != WS_OK)                                                                 \
            return s;                                                                              \
    } while (0)

/* World, materials, contact pairs, pallet and boxes, placed with their layers just touching so
 * they settle in the first milliseconds. */
static ws_status build_stack(scene *sc, ws_material_id *box_mat, ws_material_id *pallet_mat)
{
    ws_status s;
    ws_world_def wd;
    ws_world_def_init(&wd);
    wd.dt = 2.5e-4;
    wd.full_detection_until = 0.5; /* full contact detection every step while things move ... */
    wd.detection_interval = 5;     /* ... then every 5th step */
    TRY(ws_world_create(&wd, &sc->world));
    ws_world *w = sc->world;

    ws_material_def md;
    ws_material_def_init(&md);
    md.name = "cardboard";
    TRY(ws_material_create(w, &md, box_mat));
    md.name = "pallet";
    TRY(ws_material_create(w, &md, pallet_mat));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 2e5; /* N/m per contact point */
    cd.damping = 10.0;  /* kg/s */
    cd.friction = 0.5;  /* cardboard on cardboard */
    TRY(ws_world_set_contact(w, *box_mat, *box_mat, &cd));
    cd.friction = 0.4; /* cardboard on wood */
    TRY(ws_world_set_contact(w, *box_mat, *pallet_mat, &cd));

    ws_shape_id slab, carton;
    TRY(ws_shape_create_box(w, 1.2, 0.8, 0.144, &slab)); /* a EUR pallet's outline */
    TRY(ws_shape_create_box(w, LOAD.lx, LOAD.ly, LOAD.lz, &carton));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC; /* static: no drive */
    bd.shape = slab;
    bd.material = *pallet_mat;
    bd.contact_layer = LAYER;
    bd.position = (ws_vec3){0, 0, -0.072};
    bd.name = "pallet";
    TRY(ws_body_create(w, &bd, &sc->pallet));

    const double gap = 2 * LAYER; /* two layers between neighbours: just touching */
    ws_body_def_init(&bd);
    bd.shape = carton;
    bd.material = *box_mat;
    bd.mass = LOAD.mass;
    bd.contact_layer = LAYER;
    for (int l = 0; l < LOAD.layers; l++)
        for (int r = 0; r < LOAD.rows; r++)
            for (int c = 0; c < LOAD.columns && sc->boxes < MAX_BOXES; c++) {
                bd.position = (ws_vec3){(c - 0.5 * (LOAD.columns - 1)) * (LOAD.lx + gap),
                                        (r - 0.5 * (LOAD.rows - 1)) * (LOAD.ly + gap),
                                        gap + LOAD.lz / 2 + l * (LOAD.lz + gap)};
                char name[48]; /* the library keeps a copy: ParaView shows it */
                snprintf(name, sizeof name, "box layer %d row %d column %d", l + 1, r + 1, c + 1);
                bd.name = name;
                TRY(ws_body_create(w, &bd, &sc->box[sc->boxes++]));
            }
    return WS_OK;
}

/* The film: a band from 30 mm above the pallet to 20 mm below the top of the stack, nodes about
 * 20 mm apart around and 15 mm up as placed. */
static ws_status wrap_film(scene *sc, ws_material_id box_mat, ws_material_id pallet_mat,
                           double film_mass, int substeps)
{
    ws_status s;
    ws_world *w = sc->world;
    const double pre_around = 0.4, pre_up = 0.2;
    const double z0 = 0.030, z1 = LOAD.layers * (LOAD.lz + 2 * LAYER) - 0.020;
    /* Length of the band as placed: the footprint's outline pushed out by the box and film
     * layers (what ws_web_create_band does). */
    double X = LOAD.columns * LOAD.lx + (LOAD.columns - 1) * 2 * LAYER;
    double Y = LOAD.rows * LOAD.ly + (LOAD.rows - 1) * 2 * LAYER;
    double perimeter = 2 * (X + Y) + 2 * WRAP_PI * 2 * LAYER;
    int n_around = (int)ceil(perimeter / 0.020), n_up = (int)ceil((z1 - z0) / 0.015) + 1;
    double l0_around = perimeter / n_around / (1 + pre_around);
    double l0_up = (z1 - z0) / (n_up - 1) / (1 + pre_up);

    /* Film stiffness as in the source paper: every spring k = 2000 N/m, damping 0.1 kg/s. A law
     * is per unit strain, so EA = k l0 and eta = c l0 with each direction's rest length. (For a
     * film of membrane stiffness E t in N/m, e.g. 150 MPa x 20 um = 3000 N/m, a spring standing
     * for a strip of width b has EA = E t b; with b about l0 that is k about E t.) The film
     * buckles rather than pushes: 1 % of the stiffness in compression. */
    const double k = 2000.0, c = 0.1;
    ws_law_def ld;
    ws_law_id around, up;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_TENSION_COMPRESSION;
    ld.stiffness = k * l0_around;
    ld.compression_stiffness = 0.01 * ld.stiffness;
    ld.damping = c * l0_around;
    ld.name = "film around";
    TRY(ws_law_create(w, &ld, &around));
    ld.stiffness = k * l0_up;
    ld.compression_stiffness = 0.01 * ld.stiffness;
    ld.damping = c * l0_up;
    ld.name = "film up";
    TRY(ws_law_create(w, &ld, &up));

    /* Film on cardboard: 4000 N/m per node, sticky. Give the film a pair with every material in
     * the world, the pallet too: the film's stable step counts the stiffest pair it could meet,
     * and the default pair (2e5 N/m) would need a far heavier node. */
    ws_material_def md;
    ws_material_id film_mat;
    ws_material_def_init(&md);
    md.name = "film";
    TRY(ws_material_create(w, &md, &film_mat));
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 4000.0;
    cd.damping = 1.0;
    cd.friction = 0.9;
    TRY(ws_world_set_contact(w, film_mat, box_mat, &cd));
    TRY(ws_world_set_contact(w, film_mat, pallet_mat, &cd));

    /* Node mass: a real 20 um film (0.018 kg/m^2) puts ~5 mg on a node of this grid, which
     * would need ~15 sub-steps of the 0.25 ms step. 1 g keeps the step stable without any
     * (0.5 g does not: the stable step is printed); the film then weighs a few kg, which
     * friction on the boxes carries. */
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = film_mass;
    wd.contact_layer = LAYER;
    wd.material = film_mat;
    wd.law = around;
    wd.law_cross = up;
    wd.substeps = substeps;
    wd.name = "film";
    ws_band_def bd;
    ws_band_def_init(&bd);
    bd.bodies = sc->box;
    bd.body_count = (size_t)sc->boxes;
    bd.z_bottom = z0;
    bd.z_top = z1;
    bd.n_around = n_around;
    bd.n_up = n_up;
    bd.prestretch_around = pre_around;
    bd.prestretch_up = pre_up;
    sc->node_mass = film_mass;
    return ws_web_create_band(w, &wd, &bd, &sc->film);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* The largest spring tension now, N. */
static double peak_tension(ws_world *w, ws_web_id film, double *buf, size_t n)
{
    size_t m;
    double peak = -INFINITY;
    if (ws_web_copy_spring_tensions(w, film, buf, n, &m) == WS_OK)
        for (size_t k = 0; k < m; k++)
            peak = fmax(peak, buf[k]);
    return peak;
}

/* What to write for ParaView: a directory (NULL: nothing), seconds between frames, springs. */
typedef struct vtk_options {
    const char *dir;
    double every;
    int springs;
} vtk_options;

/* Step for `duration` s with progress on stderr and VTK frames every vo->every s. */
static ws_status settle(scene *sc, double duration, const vtk_options *vo, int quiet,
                        double *peak_run)
{
    ws_world *w = sc->world;
    ws_vtk_series *vtk = NULL;
    ws_status s = WS_OK;
    ws_vtk_series_def vd;
    ws_vtk_series_def_init(&vd);
    vd.directory = vo->dir;
    vd.basename = "wrap_stack";
    vd.time_stride = vo->every;
    vd.springs = vo->springs;
    if (vo->dir && (s = ws_vtk_series_create_def(w, &vd, &vtk)) != WS_OK)
        return s;
    size_t ns = 0;
    ws_web_copy_springs(w, sc->film, NULL, 0, &ns);
    double *tension = malloc(ns * sizeof *tension);
    if (!tension) {
        ws_vtk_series_destroy(vtk);
        return WS_ERR_OUT_OF_MEMORY;
    }
    double dt, t0 = now(), next_report = t0 + 1.0;
    ws_world_get_dt(w, &dt);
    long steps = lround(duration / dt), every = lround(0.05 / dt);
    *peak_run = -INFINITY;
    for (long n = 0;; n++) {
        if (n % every == 0 || n == steps)
            *peak_run = fmax(*peak_run, peak_tension(w, sc->film, tension, ns));
        /* Offered every step: the series' time stride chooses the frames. */
        if (vtk && (s = ws_vtk_series_write_frame(vtk)) != WS_OK)
            break;
        if (n == steps || (s = ws_world_step(w)) != WS_OK)
            break;
        if (!quiet && now() > next_report) {
            fprintf(stderr, "\r  t = %.2f s of %.2f s", (n + 1) * dt, duration);
            next_report = now() + 0.5;
        }
    }
    if (!quiet && now() - t0 > 1.0)
        fprintf(stderr, "\r  t = %.2f s of %.2f s: done in %.1f s\n", duration, duration,
                now() - t0);
    free(tension);
    ws_vtk_series_destroy(vtk);
    return s;
}

static void report(scene *sc, double peak_run)
{
    ws_world *w = sc->world;
    ws_containment_band band[3];
    if (ws_web_get_containment(w, sc->film, band, 3) == WS_OK) {
        static const char *const name[3] = {"bottom", "middle", "top"};
        printf("  containment (hoop tension of the around-springs, line load per height):\n");
        for (int k = 0; k < 3; k++)
            printf("    %-6s z = %.3f..%.3f m: hoop tension %7.2f N, line load %8.1f N/m, "
                   "contact force %7.1f N\n",
                   name[k], band[k].z_low, band[k].z_high, band[k].hoop_tension, band[k].line_load,
                   band[k].contact_force);
    }
    printf("  force of the film on each box (N, global; |horizontal|):\n");
    double sum = 0.0;
    for (int b = 0; b < sc->boxes; b++) {
        ws_vec3 f, r;
        ws_web_get_body_force(w, sc->film, sc->box[b], &f, NULL);
        ws_body_get_position(w, sc->box[b], &r);
        printf("    box %2d at (%+.3f, %+.3f, %.3f) m: (%+8.2f, %+8.2f, %+8.2f), %7.2f\n", b, r.x,
               r.y, r.z, f.x, f.y, f.z, hypot(f.x, f.y));
        sum += hypot(f.x, f.y);
    }
    /* Check: the film is straight along the faces and turns 90 deg at the stack's 4 vertical
     * edges, where each row of hoop tension T presses with sqrt(2) T. */
    ws_containment_band all;
    ws_web_info info;
    if (ws_web_get_containment(w, sc->film, &all, 1) == WS_OK &&
        ws_web_get_info(w, sc->film, &info) == WS_OK)
        printf("    sum %.1f N; check: 4 edges x sqrt(2) x %.2f N x %d rows = %.1f N\n", sum,
               all.hoop_tension, info.ny, 4 * sqrt(2.0) * all.hoop_tension * info.ny);
    size_t ns = 0;
    ws_web_copy_springs(w, sc->film, NULL, 0, &ns);
    double *buf = malloc(ns * sizeof *buf);
    if (buf) {
        size_t m;
        double strain = -INFINITY;
        ws_web_copy_spring_strains(w, sc->film, buf, ns, &m);
        for (size_t k = 0; k < m; k++)
            strain = fmax(strain, buf[k]);
        printf("  peak spring tension: %.2f N now (strain %.3f), %.2f N during the run\n",
               peak_tension(w, sc->film, buf, ns), strain, peak_run);
        free(buf);
    }
}

int main(int argc, char **argv)
{
    double duration = 1.0, film_mass = 1e-3;
    int substeps = 2, quiet = 0; /* 1 g nodes: 0.35 of the stable sub-step (factor 0.5) */
    vtk_options vo = {NULL, 0.05, 0}; /* 21 frames of a 1 s settling */
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--duration") && i + 1 < argc) {
            duration = atof(argv[++i]);
        } else if (!strcmp(argv[i], "--vtk") && i + 1 < argc) {
            vo.dir = argv[++i];
        } else if (!strcmp(argv[i], "--vtk-every") && i + 1 < argc) {
            vo.every = atof(argv[++i]);
        } else if (!strcmp(argv[i], "--vtk-springs")) {
            vo.springs = 1;
        } else if (!strcmp(argv[i], "--film-mass") && i + 1 < argc) {
            film_mass = atof(argv[++i]);
        } else if (!strcmp(argv[i], "--substeps") && i + 1 < argc) {
            substeps = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--quiet")) {
            quiet = 1;
        } else {
            fprintf(stderr, "usage: wrap_stack [--duration S] [--vtk DIR [--vtk-every S] "
                            "[--vtk-springs]]\n"
                            "                  [--film-mass KG] [--substeps N] [--quiet]\n");
            return 2;
        }
    }
    scene sc;
    memset(&sc, 0, sizeof sc);
    ws_material_id box_mat, pallet_mat;
    ws_status s = build_stack(&sc, &box_mat, &pallet_mat);
    if (s == WS_OK)
        s = wrap_film(&sc, box_mat, pallet_mat, film_mass, substeps);
    if (s != WS_OK) {
        fprintf(stderr, "wrap_stack: building the scene: %s\n  %s\n", ws_status_string(s),
                ws_world_last_error(sc.world));
        ws_world_destroy(sc.world);
        return 1;
    }
    ws_web_info info;
    double dt, stable;
    ws_web_get_info(sc.world, sc.film, &info);
    ws_world_get_dt(sc.world, &dt);
    ws_web_get_stable_dt(sc.world, sc.film, &stable);
    if (!quiet) {
        printf("libwrapsim %s - %d boxes (%d x %d x %d layers, %.2f x %.2f x %.2f m, %.1f kg) "
               "on a pallet, one band of film\n",
               ws_version_string(), sc.boxes, LOAD.columns, LOAD.rows, LOAD.layers, LOAD.lx,
               LOAD.ly, LOAD.lz, LOAD.mass);
        printf("  film: %d x %d nodes, %u springs, node mass %.2f g (film %.2f kg)\n", info.nx,
               info.ny, info.spring_count, 1e3 * sc.node_mass, info.mass);
        printf("  stable film sub-step %.3f ms; world step %.3f ms in %d sub-step(s) of %.3f ms\n",
               1e3 * stable, 1e3 * dt, info.substeps, 1e3 * dt / info.substeps);
    }
    double peak_run;
    s = settle(&sc, duration, &vo, quiet, &peak_run);
    if (s != WS_OK) {
        fprintf(stderr, "wrap_stack: %s\n  %s\n", ws_status_string(s),
                ws_world_last_error(sc.world));
        ws_world_destroy(sc.world);
        return 1;
    }
    if (!quiet) {
        printf("after %.2f s of settling:\n", duration);
        report(&sc, peak_run);
        if (vo.dir)
            printf("  VTK frames: %s/wrap_stack.pvd (open in ParaView)\n", vo.dir);
    }
    ws_world_destroy(sc.world);
    return 0;
}
