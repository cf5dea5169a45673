/*
 * tilt_table.c: the reference case of the source paper, unwrapped.
 *
 * Two cubes (a = 0.25 m, 5 kg each) stacked on a plane. The plane is static for 1 s, then tilts
 * at 0.1 rad/s about a horizontal axis. Friction box-box and box-plane mu = 0.3, so theory says
 * the boxes start to slide at tan(theta) = 0.3, theta = 16.70 deg, t = 3.915 s.
 *   Variant P (paper): as above, 6 s.
 *   Variant R (reference): plus a stop bar (20 mm x 20 mm) on the plane along the downhill face
 *   of the bottom box, 7 s. The top box slides off at 16.70 deg; the bottom box rests on the stop.
 *   --wrapped: a band of stretch film around both boxes (96 x 61 nodes, pre-stretch 40 %
 *   around and 20 % up, springs of 2000 N/m, film-box contact 4000 N/m, mu 0.9). The film holds
 *   the top box; in R the stack then tips as one over the stop when its centre of mass passes
 *   the stop's edge: tan(theta) = (a/2) / (a - 0.02), theta = 28.52 deg, t = 5.978 s, without
 *   the layers; 28.61 deg with them (docs/theory.md 4.1); about 29.5-29.7 deg with Coulomb
 *   friction at the base. The example reports the angle where the load's CoG (boxes and film)
 *   passes over the stop's top edge, found in 10 ms samples and interpolated.
 *
 * Definitions it reports by (the same in examples/python/tilt_table.py):
 *   slide onset: every contact of a box with its support slips (|v_t| >= v_lim = 10 mm/s, or the
 *   stick anchor slides), the same way, without a break for 0.2 s; the onset is where that run
 *   began. A box turning on its support slips at every corner but not the same way.
 *   The run stops early when a box leaves the platform (its CoG below the platform's surface):
 *   the world has no floor, and a falling box says nothing more about the load.
 *
 * Build:  cc tilt_table.c $(pkg-config --cflags --libs libwrapsim) -o tilt_table
 * Run:    ./tilt_table [--variant P|R] [--stick] [--csv FILE] [--no-ccd]
 *                      [--vtk DIR [--vtk-every S] [--vtk-stride N] [--vtk-springs] [--vtk-ascii]]
 *                      [--paper-integrator] [--explicit-friction] [--duration S] [--quiet]
 *                      [--wrapped [--film-mass KG] [--substeps N]]
 *         ./tilt_table --help
 *         Exit status 0 when the run ends, 1 when it fails (the library or a file), 2 on a bad
 *         option.
 *
 * Copy this file as the start of your own load: build the scene in tilt_build(), read results
 * in tilt_run(). Compile with -DTILT_TABLE_NO_MAIN to use the two functions from another file.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include <wrapsim/wrapsim.h>

#define TILT_PI 3.14159265358979323846
#define DEG(x) ((x) * 180.0 / TILT_PI)
#define TILT_SLIDE_HOLD 0.2 /* s: gross slip must last this long to count as a slide */
#define TILT_START 1.0      /* s: the platform stands level until then, then tilts */

struct tilt_scene;

typedef struct tilt_options {
    char variant;         /* 'P' or 'R' */
    int stick;            /* 1: stick friction model instead of the paper's regularised law */
    int use_ccd;          /* 1: libccd gate (when built in) */
    int paper_integrator; /* 1: the paper's explicit scheme */
    int explicit_friction; /* 1: the bodies' friction taken at the step's start, as the paper */
    double duration;      /* s; 0 = 6 s for P, 7 s for R */
    const char *csv;      /* time series file, or NULL */
    const char *vtk_dir;  /* directory for VTK frames, or NULL */
    double vtk_every;     /* s between VTK frames (the series' time stride); default 0.1 s */
    int vtk_stride;       /* offer a frame every vtk_stride-th step (frame stride); default 1 */
    int vtk_springs;      /* 1: add the film's springs as their own block */
    int vtk_ascii;        /* 1: ASCII files instead of compressed binary */
    int quiet;            /* no progress, no summary */
    int wrapped;          /* 1: stretch film around the stack */
    double film_mass;     /* kg per node; 0 = 1 g */
    int substeps;         /* film sub-steps per step; 0 = 2 (1 g nodes then use 0.34 of their
                             stable sub-step, within the default safety factor 0.5) */
    double stable_fraction; /* the film check's safety factor (world.h); 0 = the default */
    int profile;          /* 1: the library times its phases (ws_world_stats) */
    int workers;          /* workers of a step; 0 = 1 (the results are the same for any) */
    int implicit;         /* 1: the film's implicit integrator (WS_WEB_IMPLICIT) */
    double areal_density; /* kg/m^2 of film, in place of film_mass when > 0 (0.018: real) */
    int refine;           /* film nodes refine x refine as many (each direction); 0 = 1 */
    double solver_tolerance; /* implicit film: the solve's tolerance; 0 = the default */
    int preconditioner;   /* implicit film: ws_web_preconditioner; 0 = AUTO */
    double dt;            /* s; 0 = 0.25 ms */
    int hold_bodies;      /* implicit film: 1 holds the boxes during its solve (ws_web_def) */
    const char *resume;   /* a state saved from this same scene (ws_world_save_file): the run
                             starts from it, and runs `duration` from its time; the slides are
                             then measured from the saved state's positions */
    void (*each_step)(const struct tilt_scene *sc, void *user); /* after every step, or NULL */
    void *user;
} tilt_options;

typedef struct tilt_scene {
    ws_world *world;
    ws_body_id plane, stop, box[2]; /* box[0] bottom, box[1] top; stop is null in variant P */
    ws_web_id film;                 /* null when unwrapped */
    double dt, duration, vlim;
} tilt_scene;

typedef struct tilt_result {
    ws_status status;
    char error[512];
    long steps;
    double wall_seconds;
    double slide_time[2], slide_angle[2]; /* s, deg: onset of gross slip that lasted 0.2 s
                                              (TILT_SLIDE_HOLD); NaN when it never slid */
    int slide_confirmed[2];
    double tip_time[2], tip_angle[2];     /* first time a box leans > 2 deg on its support */
    double lift_time, lift_angle;         /* the bottom box's uphill edge lifts off the
                                             platform: the stack starts to tip (NaN: never) */
    double final_slip[2];                 /* m along the platform, downhill positive */
    double off_time[2];                   /* when its CoG went below the platform's surface:
                                             it left the platform and the run stopped (NaN:
                                             never) */
    double over_time, over_angle;         /* wrapped R: the load's CoG (boxes and film) passes
                                             over the stop's top edge: the physical tip (NaN:
                                             never) */
    double over_theory;                   /* deg: where a rigid load would tip, from its CoG
                                             and the stop edge when the uphill edge lifts
                                             (layers included); NaN when not wrapped R */
    double stop_height, stop_share;       /* wrapped R, the last 10 ms sample before the
                                             uphill edge lifted: the height of the stop's push
                                             above the bottom box's bottom face (m, from its
                                             moment) and its share of the load's weight down
                                             the platform (NaN: not measured) */
    double lift_theory;                   /* deg: where a rigid stack with that push and its
                                             CoG of that sample unloads its uphill edge */
    double end_time;                      /* s, the run's last time (earlier than the duration
                                             when a box left the platform) */
    double cog_distance_start, cog_distance_end; /* m */
    double final_angle;                   /* plane angle at the end, deg */
    double max_relative_slip;             /* m, largest move of the top box on the bottom one */
    double peak_strain, peak_tension;     /* film, largest over the run (wrapped) */
    uint64_t hash;
    uint32_t film_nodes;                  /* wrapped: nodes of the film */
    ws_web_solver_stats solver;           /* wrapped, implicit film: its solves */
    double friction_use;                  /* dt over the regularised friction's explicit limit,
                                             the run's largest (ws_world_stats) */
} tilt_result;

static void tilt_default_options(tilt_options *o)
{
    memset(o, 0, sizeof *o);
    o->variant = 'R';
    o->use_ccd = 1;
    o->vtk_every = 0.1; /* 0.57 deg of tilt a frame: 71 frames of a 7 s run */
    o->vtk_stride = 1;
}

/* The film of the reference case: a band from 30 mm above the plane to 20 mm below the top,
 * 96 around x 61 up, pre-stretched 40 % around and 20 % up. The paper gives its springs as
 * 2000 N/m and 0.1 kg/s; a law is per unit strain, so EA = k l0 and eta = c l0 with the rest
 * lengths that follow from the outline and the pre-stretch. */
static ws_status tilt_wrap(const tilt_options *o, tilt_scene *sc, ws_material_id box_mat,
                           ws_material_id plane_mat)
{
    ws_world *w = sc->world;
    const double a = 0.25, layer = 1e-3, k = 2000.0, c = 0.1;
    const int r = o->refine > 1 ? o->refine : 1;
    const int n_around = 96 * r, n_up = 60 * r + 1;
    const double z0 = 0.030, z1 = 2 * a + 2 * 2 * layer - 0.020;
    /* Outline: the square footprint pushed out by the box and node layers. */
    double perimeter = 4 * a + 2 * TILT_PI * 2 * layer;
    double l0_around = perimeter / n_around / 1.4, l0_up = (z1 - z0) / (n_up - 1) / 1.2;
    ws_status s;
    ws_law_def ld;
    ws_law_id around, up;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_TENSION_COMPRESSION; /* film buckles: 1 % stiffness in compression */
    ld.stiffness = k * l0_around;
    ld.compression_stiffness = 0.01 * ld.stiffness;
    ld.damping = c * l0_around;
    ld.name = "film around";
    if ((s = ws_law_create(w, &ld, &around)) != WS_OK)
        return s;
    ld.stiffness = k * l0_up;
    ld.compression_stiffness = 0.01 * ld.stiffness;
    ld.damping = c * l0_up;
    ld.name = "film up";
    if ((s = ws_law_create(w, &ld, &up)) != WS_OK)
        return s;

    ws_material_def md;
    ws_material_id film_mat;
    ws_material_def_init(&md);
    md.name = "film";
    if ((s = ws_material_create(w, &md, &film_mat)) != WS_OK)
        return s;
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    /* N/m per node; a refined band's nodes each stand for 1 / refine^2 of the film, and so
     * take that share of the stiffness and damping: the same pressure at the same overlap. */
    cd.stiffness = 4000.0 / (r * r);
    cd.damping = 1.0 / (r * r);
    cd.friction = 0.9; /* film sticks to cardboard */
    cd.friction_vlim = sc->vlim;
    if ((s = ws_world_set_contact(w, film_mat, box_mat, &cd)) != WS_OK ||
        (s = ws_world_set_contact(w, film_mat, plane_mat, &cd)) != WS_OK)
        return s;

    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = o->areal_density > 0 ? 0.0 : o->film_mass > 0 ? o->film_mass : 1e-3;
    wd.areal_density = o->areal_density;
    if (o->implicit)
        wd.integrator = WS_WEB_IMPLICIT;
    if (o->solver_tolerance > 0)
        wd.solver_tolerance = o->solver_tolerance;
    wd.preconditioner = o->preconditioner;
    wd.hold_bodies = o->hold_bodies;
    wd.contact_layer = layer;
    wd.material = film_mat;
    wd.law = around;
    wd.law_cross = up;
    wd.substeps = o->substeps > 0 ? o->substeps : 2;
    wd.name = "film";
    ws_band_def bd;
    ws_band_def_init(&bd);
    bd.bodies = sc->box;
    bd.body_count = 2;
    bd.z_bottom = z0;
    bd.z_top = z1;
    bd.n_around = n_around;
    bd.n_up = n_up;
    bd.prestretch_around = 0.4;
    bd.prestretch_up = 0.2;
    return ws_web_create_band(w, &wd, &bd, &sc->film);
}

/* Build the reference case. Returns WS_OK or the first error (the world is then destroyed). */
static ws_status tilt_build(const tilt_options *o, tilt_scene *sc)
{
    const double a = 0.25, m = 5.0, layer = 1e-3, gap = 2 * layer;
    memset(sc, 0, sizeof *sc);
    sc->dt = o->dt > 0 ? o->dt : 2.5e-4;
    sc->duration = o->duration > 0 ? o->duration : (o->variant == 'P' ? 6.0 : 7.0);
    sc->vlim = 0.01;

    ws_world_def wd;
    ws_world_def_init(&wd);
    wd.dt = sc->dt;
    wd.full_detection_until = 0.5; /* full detection every step for 0.5 s ... */
    wd.detection_interval = 5;     /* ... then every 5th step */
    wd.use_ccd = o->use_ccd;
    wd.profile = o->profile;
    if (o->stable_fraction > 0)
        wd.stable_fraction = o->stable_fraction;
    wd.worker_count = o->workers > 0 ? (uint32_t)o->workers : 1u;
    wd.integrator = o->paper_integrator ? WS_INTEGRATOR_PAPER_EXPLICIT
                                        : WS_INTEGRATOR_SYMPLECTIC_EULER;
    wd.friction_step =
        o->explicit_friction ? WS_FRICTION_STEP_EXPLICIT : WS_FRICTION_STEP_IMPLICIT;
    ws_status s = ws_world_create(&wd, &sc->world);
    if (s != WS_OK)
        return s;
    ws_world *w = sc->world;

    /* Materials and the contact parameters of each pair. */
    ws_material_def md;
    ws_material_id box_mat, plane_mat;
    ws_material_def_init(&md);
    md.name = "cardboard";
    if ((s = ws_material_create(w, &md, &box_mat)) != WS_OK)
        goto fail;
    md.name = "platform";
    if ((s = ws_material_create(w, &md, &plane_mat)) != WS_OK)
        goto fail;
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 2e5;  /* N/m */
    cd.damping = 10.0;   /* kg/s */
    cd.friction = 0.3;
    cd.friction_vlim = sc->vlim;
    cd.friction_model = o->stick ? WS_FRICTION_STICK : WS_FRICTION_REGULARIZED;
    /* Stick model: the anchor spring is a numerical device; damp it near critically for a 5 kg
     * box on 4 corners (c_t ~ sqrt(k_t m) / 4) so it does not ring when contacts come and go. */
    cd.stick_stiffness = 2e5;
    cd.stick_damping = 250.0;
    if ((s = ws_world_set_contact(w, box_mat, box_mat, &cd)) != WS_OK ||
        (s = ws_world_set_contact(w, box_mat, plane_mat, &cd)) != WS_OK)
        goto fail;

    /* The platform: a kinematic slab whose top face is z = 0, tilting about the y axis through
     * the origin. A positive rate lowers +x: downhill is +x. */
    ws_shape_id slab, cube, bar;
    if ((s = ws_shape_create_box(w, 1.5, 1.5, 0.05, &slab)) != WS_OK ||
        (s = ws_shape_create_box(w, a, a, a, &cube)) != WS_OK ||
        (s = ws_shape_create_box(w, 0.02, 0.5, 0.02, &bar)) != WS_OK)
        goto fail;
    ws_drive_def tilt;
    ws_drive_def_init(&tilt);
    tilt.type = WS_DRIVE_TILT;
    tilt.axis = (ws_vec3){0, 1, 0};
    tilt.point = (ws_vec3){0, 0, 0};
    tilt.start_time = TILT_START;
    tilt.rate = 0.1; /* rad/s */

    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = slab;
    bd.material = plane_mat;
    bd.contact_layer = layer;
    bd.position = (ws_vec3){0, 0, -0.025};
    bd.name = "platform";
    if ((s = ws_body_create(w, &bd, &sc->plane)) != WS_OK ||
        (s = ws_body_set_drive(w, sc->plane, &tilt)) != WS_OK)
        goto fail;
    if (o->variant == 'R') {
        /* The stop: 20 mm high, 20 mm thick, its uphill face one layer gap from the box. */
        bd.shape = bar;
        bd.position = (ws_vec3){a / 2 + gap + 0.01, 0, 0.01};
        bd.name = "stop";
        if ((s = ws_body_create(w, &bd, &sc->stop)) != WS_OK ||
            (s = ws_body_set_drive(w, sc->stop, &tilt)) != WS_OK)
            goto fail;
    }

    /* The boxes, placed with their layers just touching; they settle in the first second. */
    ws_body_def_init(&bd);
    bd.shape = cube;
    bd.material = box_mat;
    bd.mass = m; /* inertia from the shape: m a^2 / 6 */
    bd.contact_layer = layer;
    bd.position = (ws_vec3){0, 0, gap + a / 2};
    bd.name = "bottom";
    if ((s = ws_body_create(w, &bd, &sc->box[0])) != WS_OK)
        goto fail;
    bd.position = (ws_vec3){0, 0, gap + a + gap + a / 2};
    bd.name = "top";
    if ((s = ws_body_create(w, &bd, &sc->box[1])) != WS_OK)
        goto fail;
    if (o->wrapped && (s = tilt_wrap(o, sc, box_mat, plane_mat)) != WS_OK)
        goto fail;
    return WS_OK;
fail:
    ws_world_destroy(w);
    sc->world = NULL;
    return s;
}

/* Plane angle about y from its Euler parameters. */
static double plane_angle(ws_world *w, ws_body_id plane)
{
    ws_quat q;
    ws_body_get_orientation(w, plane, &q);
    return 2.0 * atan2(q.e2, q.e0);
}

/* Position of a point in the plane's frame (x downhill along the platform). */
static ws_vec3 in_plane_frame(ws_world *w, ws_body_id plane, ws_vec3 p)
{
    ws_vec3 r;
    ws_mat3 A;
    ws_body_get_position(w, plane, &r);
    ws_body_get_rotation(w, plane, &A);
    ws_vec3 d = {p.x - r.x, p.y - r.y, p.z - r.z};
    ws_vec3 s = {A.m[0] * d.x + A.m[3] * d.y + A.m[6] * d.z,
                 A.m[1] * d.x + A.m[4] * d.y + A.m[7] * d.z,
                 A.m[2] * d.x + A.m[5] * d.y + A.m[8] * d.z};
    return s;
}

/* Lean (rad) of body b on body a: the angle between their z axes. A twist about the vertical
 * is not a lean. */
static double relative_tilt(ws_world *w, ws_body_id a, ws_body_id b)
{
    ws_mat3 A, B;
    ws_body_get_rotation(w, a, &A);
    ws_body_get_rotation(w, b, &B);
    double dot = A.m[2] * B.m[2] + A.m[5] * B.m[5] + A.m[8] * B.m[8]; /* third columns */
    return acos(fmax(-1.0, fmin(1.0, dot)));
}

/* Gross slip of body b on its support: every contact between them slips (tangential speed at
 * or above v_lim under the regularised law, the anchor at its cap under the stick law), and
 * they slip the same way (|sum of slip velocities| >= half the sum of their sizes): a box
 * turning on its support, as when the platform starts to tilt, slips at every corner but is not
 * sliding. The pair's report gives every slip velocity as b's on its support, whichever owns
 * the face. */
static int slides_on(ws_world *w, ws_body_id b, ws_body_id support)
{
    ws_contact_info buf[64];
    size_t n = 0;
    ws_world_copy_contacts_between(w, support, b, buf, 64, &n); /* 64 are plenty here */
    if (n > 64)
        n = 64;
    size_t slipping = 0;
    double sx = 0, sy = 0, sz = 0, size = 0;
    for (size_t k = 0; k < n; k++) {
        const ws_vec3 *v = &buf[k].slip_velocity;
        sx += v->x;
        sy += v->y;
        sz += v->z;
        size += sqrt(v->x * v->x + v->y * v->y + v->z * v->z);
        slipping += buf[k].slipping != 0 || buf[k].at_cap != 0; /* stick: saturated */
    }
    return n > 0 && slipping == n && sqrt(sx * sx + sy * sy + sz * sz) >= 0.5 * size;
}

/* 1 when body b touches the platform only on the downhill half of its bottom (x in the
 * platform's frame greater than its CoG's) or not at all: its uphill edge has lifted. */
static int uphill_lifted(ws_world *w, ws_body_id plane, ws_body_id b)
{
    ws_contact_info buf[64];
    size_t n = 0;
    ws_world_copy_contacts_between(w, plane, b, buf, 64, &n);
    if (n > 64)
        n = 64;
    ws_vec3 r;
    ws_body_get_position(w, b, &r);
    double xc = in_plane_frame(w, plane, r).x;
    for (size_t k = 0; k < n; k++)
        if (in_plane_frame(w, plane, buf[k].point).x < xc)
            return 0;
    return 1;
}

/* The load's centre of mass: the boxes and, when wrapped, the film's nodes (xyz: room for them). */
static ws_vec3 load_cog(ws_world *w, const tilt_scene *sc, double *xyz, size_t nodes,
                        double node_mass)
{
    double m = 0, x = 0, y = 0, z = 0;
    for (int k = 0; k < 2; k++) {
        ws_vec3 r;
        double mk;
        ws_body_get_position(w, sc->box[k], &r);
        ws_body_get_mass(w, sc->box[k], &mk);
        x += mk * r.x, y += mk * r.y, z += mk * r.z, m += mk;
    }
    if (nodes && ws_web_copy_positions(w, sc->film, xyz, nodes, &nodes) == WS_OK) {
        for (size_t q = 0; q < nodes; q++) {
            x += node_mass * xyz[3 * q];
            y += node_mass * xyz[3 * q + 1];
            z += node_mass * xyz[3 * q + 2];
        }
        m += node_mass * (double)nodes;
    }
    return (ws_vec3){x / m, y / m, z / m};
}

/* How far the load's CoG is past the stop's top uphill edge, horizontally and downhill (m): it
 * passes over the edge, and gravity tips a rigid load, when this turns positive. */
static double past_stop_edge(ws_world *w, const tilt_scene *sc, ws_vec3 cog)
{
    const ws_vec3 edge_local = {-0.01, 0, 0.01}; /* in the 20 x 20 mm bar's frame */
    ws_vec3 e;
    ws_mat3 A;
    ws_body_get_world_point(w, sc->stop, &edge_local, &e);
    ws_body_get_rotation(w, sc->plane, &A);
    /* Downhill along the level: the platform's x axis with its vertical part removed. */
    double hx = A.m[0], hy = A.m[3], hn = sqrt(hx * hx + hy * hy);
    return ((cog.x - e.x) * hx + (cog.y - e.y) * hy) / hn;
}

/* Where the stop pushes on the bottom box: the stack rests on the platform (its friction acts
 * in the bottom face, at no lever about the downhill bottom edge) and against the stop. The
 * stop's push S up the platform and its moment about that edge give its height h_s above the
 * bottom face; with S a share s of the load's weight down the platform, m g sin(theta), the
 * uphill edge unloads when the moments about the downhill edge balance with the platform's
 * push all at that edge: m g sin(theta) h = m g cos(theta) x_e + s m g sin(theta) h_s, i.e.
 * tan(theta) = x_e / (h - s h_s), with h the CoG's height above the bottom face and x_e its
 * distance up the platform from the edge. A push at the stop's foot (h_s = 0) gives the
 * textbook (a/2)/h; at its top edge, h_s = 18 mm above the box's bottom face, later. Where
 * between the two it pushes is not fixed by rigid bodies (the box bears on the stop's whole
 * face); the contacts' compliance decides it. Returns the rigid angle (deg), NaN without a
 * push. */
static double stop_push(ws_world *w, const tilt_scene *sc, ws_vec3 cog, double mass, double theta,
                        double *height, double *share)
{
    ws_contact_info buf[64];
    size_t n = 0;
    ws_world_copy_contacts_between(w, sc->stop, sc->box[0], buf, 64, &n);
    if (n > 64)
        n = 64;
    ws_vec3 r, o = {0, 0, 0};
    ws_body_get_position(w, sc->box[0], &r);
    ws_vec3 c = in_plane_frame(w, sc->plane, r), origin = in_plane_frame(w, sc->plane, o);
    double zb = c.z - 0.125, xe = c.x + 0.125; /* bottom face; downhill bottom edge */
    double push = 0, moment = 0;
    for (size_t k = 0; k < n; k++) {
        /* The force on the box (body_b), turned into the platform's frame. */
        ws_vec3 f = {buf[k].normal_force * buf[k].normal.x + buf[k].friction_force.x,
                     buf[k].normal_force * buf[k].normal.y + buf[k].friction_force.y,
                     buf[k].normal_force * buf[k].normal.z + buf[k].friction_force.z};
        ws_vec3 fp = in_plane_frame(w, sc->plane, f), p = in_plane_frame(w, sc->plane, buf[k].point);
        fp.x -= origin.x, fp.y -= origin.y, fp.z -= origin.z;
        push -= fp.x;
        moment += (p.z - zb) * fp.x + (xe - p.x) * fp.z;
    }
    ws_vec3 g = in_plane_frame(w, sc->plane, cog);
    double down = mass * 9.81 * sin(theta);
    if (!(push > 0) || !(down > 0))
        return *height = *share = NAN;
    *height = -moment / push;
    *share = push / down;
    return DEG(atan((xe - g.x) / ((g.z - zb) - *share * *height)));
}

/* CoG of body b in the frame of body a. */
static ws_vec3 box_local(ws_world *w, ws_body_id a, ws_body_id b)
{
    ws_vec3 p;
    ws_body_get_position(w, b, &p);
    ws_vec3 ra;
    ws_mat3 A;
    ws_body_get_position(w, a, &ra);
    ws_body_get_rotation(w, a, &A);
    ws_vec3 d = {p.x - ra.x, p.y - ra.y, p.z - ra.z};
    ws_vec3 s = {A.m[0] * d.x + A.m[3] * d.y + A.m[6] * d.z,
                 A.m[1] * d.x + A.m[4] * d.y + A.m[7] * d.z,
                 A.m[2] * d.x + A.m[5] * d.y + A.m[8] * d.z};
    return s;
}

static double distance(ws_world *w, ws_body_id a, ws_body_id b)
{
    ws_vec3 p, q;
    ws_body_get_position(w, a, &p);
    ws_body_get_position(w, b, &q);
    return sqrt((p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y) + (p.z - q.z) * (p.z - q.z));
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* mkdir -p: create the directory and its missing parents. Returns 0, or -1 with errno. */
static int make_dirs(const char *path)
{
    char buf[4096];
    size_t n = strlen(path);
    if (n == 0 || n >= sizeof buf) {
        errno = ENAMETOOLONG;
        return -1;
    }
    memcpy(buf, path, n + 1);
    for (size_t k = 1; k <= n; k++) {
        if (buf[k] != '/' && buf[k] != '\0')
            continue;
        char c = buf[k];
        buf[k] = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST)
            return -1;
        buf[k] = c;
    }
    struct stat st;
    if (stat(path, &st) != 0)
        return -1;
    if (!S_ISDIR(st.st_mode)) {
        errno = ENOTDIR;
        return -1;
    }
    return 0;
}

/* Run the case and fill the result. Returns the last status (WS_OK when it ran to the end or
 * stopped because a box left the platform). */
static ws_status tilt_run(const tilt_options *o, tilt_result *res)
{
    memset(res, 0, sizeof *res);
    for (int k = 0; k < 2; k++)
        res->slide_time[k] = res->slide_angle[k] = res->tip_time[k] = res->tip_angle[k] =
            res->off_time[k] = NAN;
    res->lift_time = res->lift_angle = NAN;
    res->over_time = res->over_angle = res->over_theory = NAN;
    tilt_scene sc;
    ws_status s = tilt_build(o, &sc);
    if (s != WS_OK) {
        snprintf(res->error, sizeof res->error, "building the scene: %s", ws_status_string(s));
        return res->status = s;
    }
    ws_world *w = sc.world;
    if (o->resume && (s = ws_world_restore_file(w, o->resume)) != WS_OK) {
        snprintf(res->error, sizeof res->error, "%s", ws_world_last_error(w));
        ws_world_destroy(w);
        return res->status = s;
    }
    FILE *csv = NULL;
    ws_vtk_series *vtk = NULL;
    if (o->csv && !(csv = fopen(o->csv, "w"))) {
        snprintf(res->error, sizeof res->error, "cannot write %s: %s", o->csv, strerror(errno));
        ws_world_destroy(w);
        return res->status = WS_ERR_IO;
    }
    if (csv)
        /* Each column's unit at the end of its name: s, deg, m, m/s (m_s). */
        fprintf(csv, "t_s,plane_angle_deg,"
                     "bottom_x_m,bottom_y_m,bottom_z_m,bottom_vx_m_s,bottom_vy_m_s,bottom_vz_m_s,"
                     "bottom_tilt_deg,bottom_slip_m,"
                     "top_x_m,top_y_m,top_z_m,top_vx_m_s,top_vy_m_s,top_vz_m_s,top_tilt_deg,"
                     "top_slip_m,cog_distance_m\n");
    ws_vtk_series_def vd;
    ws_vtk_series_def_init(&vd);
    vd.directory = o->vtk_dir;
    vd.basename = "tilt_table";
    vd.time_stride = o->vtk_every;
    vd.frame_stride = o->vtk_stride;
    vd.springs = o->vtk_springs;
    vd.format = o->vtk_ascii ? WS_VTK_ASCII : WS_VTK_COMPRESSED;
    if (o->vtk_dir && make_dirs(o->vtk_dir) != 0) {
        snprintf(res->error, sizeof res->error, "cannot create the directory %s: %s",
                 o->vtk_dir, strerror(errno));
        s = WS_ERR_IO;
    } else if (o->vtk_dir && (s = ws_vtk_series_create_def(w, &vd, &vtk)) != WS_OK) {
        snprintf(res->error, sizeof res->error, "%s", ws_world_last_error(w));
    }
    if (s != WS_OK) {
        if (csv)
            fclose(csv);
        ws_world_destroy(w);
        return res->status = s;
    }

    long steps = lround(sc.duration / sc.dt);
    long csv_every = lround(0.01 / sc.dt);
    ws_vec3 start[2];
    for (int k = 0; k < 2; k++) {
        ws_vec3 r;
        ws_body_get_position(w, sc.box[k], &r);
        start[k] = in_plane_frame(w, sc.plane, r);
    }
    res->cog_distance_start = distance(w, sc.box[0], sc.box[1]);
    ws_vec3 top_on_bottom0 = box_local(w, sc.box[0], sc.box[1]);
    size_t nspr = 0, nodes = 0;
    double *tension = NULL, *strain = NULL, *xyz = NULL, node_mass = 0;
    if (sc.film.bits) {
        ws_web_info wi;
        ws_web_get_info(w, sc.film, &wi);
        nodes = wi.node_count;
        node_mass = wi.mass / (double)nodes; /* the band's nodes are all alike */
        ws_web_copy_springs(w, sc.film, NULL, 0, &nspr);
        tension = malloc(nspr * sizeof *tension);
        strain = malloc(nspr * sizeof *strain);
        xyz = malloc(3 * nodes * sizeof *xyz);
        if (!tension || !strain || !xyz) {
            free(tension);
            free(strain);
            free(xyz);
            ws_world_destroy(w);
            snprintf(res->error, sizeof res->error, "out of memory");
            return res->status = WS_ERR_OUT_OF_MEMORY;
        }
    }
    /* The physical tip is watched in the wrapped R case, where the stack pivots on the stop. */
    int watch_tip = sc.film.bits && sc.stop.bits;
    double past_prev = NAN, theta_prev = 0, t_prev = 0, rigid_now = NAN, rigid_at_lift = NAN;
    double push_height = NAN, push_share = NAN, push_rigid = NAN;
    res->stop_height = res->stop_share = res->lift_theory = NAN;
    double t0 = now(), next_report = t0 + 1.0;
    ws_body_id support[2] = {sc.plane, sc.box[0]};
    long slipping_steps[2] = {0, 0};
    /* Gross slip must last 0.2 s: the stack rocking as the platform starts to turn slips its
     * bottom face for a while (longer when wrapped, the film adding inertia); a slide goes on. */
    const long sustained = lround(TILT_SLIDE_HOLD / sc.dt);
    long lifted_steps = 0;
    int lift_confirmed = 0;
    for (long n = 0; n <= steps; n++) {
        double t, theta = plane_angle(w, sc.plane);
        ws_world_get_time(w, &t);
        double slip[2], tilt[2];
        ws_vec3 r[2], v[2];
        int off = 0;
        for (int k = 0; k < 2; k++) {
            ws_body_get_position(w, sc.box[k], &r[k]);
            ws_body_get_velocity(w, sc.box[k], &v[k]);
            ws_vec3 local = in_plane_frame(w, sc.plane, r[k]);
            slip[k] = local.x - start[k].x;
            if (isnan(res->off_time[k]) && local.z < 0.0)
                res->off_time[k] = t;
            off |= !isnan(res->off_time[k]);
            tilt[k] = relative_tilt(w, sc.box[k], support[k]);
            /* Sliding: every contact with its support slips the same way, for 0.2 s in a row. */
            /* Slides are of a standing stack on the tilting platform: not while the film
             * settles on the level platform (its jostle is no slide, and a slide confirmed
             * then would stop the relative slip's record below), not once the stack has
             * tipped or the box left. */
            int standing = t > TILT_START && !lift_confirmed && isnan(res->off_time[k]);
            slipping_steps[k] =
                standing && slides_on(w, sc.box[k], support[k]) ? slipping_steps[k] + 1 : 0;
            if (isnan(res->slide_time[k]) && slipping_steps[k] == 1)
                res->slide_time[k] = t, res->slide_angle[k] = DEG(theta); /* candidate onset */
            if (isnan(res->slide_angle[k]) == 0 && slipping_steps[k] == 0 &&
                !res->slide_confirmed[k])
                res->slide_time[k] = res->slide_angle[k] = NAN; /* it did not last */
            if (slipping_steps[k] >= sustained)
                res->slide_confirmed[k] = 1;
            if (isnan(res->tip_time[k]) && tilt[k] > 2.0 * TILT_PI / 180) {
                res->tip_time[k] = t;
                res->tip_angle[k] = DEG(theta);
            }
        }
        /* Tipping: the uphill edge stays off for 50 ms (a knock lifts it for less). */
        if (!lift_confirmed) {
            if (t > TILT_START && uphill_lifted(w, sc.plane, sc.box[0])) {
                if (lifted_steps++ == 0) {
                    res->lift_time = t;
                    res->lift_angle = DEG(theta);
                    rigid_at_lift = rigid_now;
                    res->stop_height = push_height, res->stop_share = push_share;
                    res->lift_theory = push_rigid;
                }
                lift_confirmed = lifted_steps >= lround(0.05 / sc.dt);
                if (lift_confirmed && watch_tip)
                    res->over_theory = rigid_at_lift;
            } else {
                lifted_steps = 0;
                res->lift_time = res->lift_angle = NAN;
                res->stop_height = res->stop_share = res->lift_theory = NAN;
            }
        }
        ws_vec3 rel = box_local(w, sc.box[0], sc.box[1]);
        double dx = rel.x - top_on_bottom0.x, dy = rel.y - top_on_bottom0.y;
        /* While the boxes stand stacked, until the stack tips. A slide of the top box does not
         * end the record: a top box sliding off is what this figure is to show. */
        if (!lift_confirmed)
            res->max_relative_slip = fmax(res->max_relative_slip, sqrt(dx * dx + dy * dy));
        if (sc.film.bits && n % csv_every == 0) {
            size_t m;
            ws_web_copy_spring_tensions(w, sc.film, tension, nspr, &m);
            ws_web_copy_spring_strains(w, sc.film, strain, nspr, &m);
            for (size_t q = 0; q < m; q++) {
                res->peak_tension = fmax(res->peak_tension, tension[q]);
                res->peak_strain = fmax(res->peak_strain, strain[q]);
            }
        }
        /* The physical tip, in 10 ms samples: the load's CoG crosses the vertical through the
         * stop's edge; the angle is interpolated between the two samples around the crossing.
         * rigid_now is where a rigid load would tip with the geometry of this sample (CoG and
         * stop edge in the platform's frame); it is kept from the last sample before the
         * uphill edge lifted, when the stack rests against the stop, layers and film included
         * (at rest on the flat platform the film holds the stack a few mm off the stop). */
        if (watch_tip && n % csv_every == 0) {
            ws_vec3 cog = load_cog(w, &sc, xyz, nodes, node_mass);
            double past = past_stop_edge(w, &sc, cog);
            const ws_vec3 edge_local = {-0.01, 0, 0.01};
            ws_vec3 e;
            ws_body_get_world_point(w, sc.stop, &edge_local, &e);
            ws_vec3 ce = in_plane_frame(w, sc.plane, cog), ee = in_plane_frame(w, sc.plane, e);
            rigid_now = DEG(atan((ee.x - ce.x) / (ce.z - ee.z)));
            if (!lift_confirmed && lifted_steps == 0) {
                double mass = node_mass * (double)nodes, mk;
                for (int k = 0; k < 2; k++)
                    ws_body_get_mass(w, sc.box[k], &mk), mass += mk;
                push_rigid = stop_push(w, &sc, cog, mass, theta, &push_height, &push_share);
            }
            if (isnan(res->over_time) && past >= 0.0 && !isnan(past_prev) && past_prev < 0.0) {
                double f = -past_prev / (past - past_prev);
                res->over_time = t_prev + f * (t - t_prev);
                res->over_angle = DEG(theta_prev + f * (theta - theta_prev));
            }
            past_prev = past, theta_prev = theta, t_prev = t;
        }
        if (csv && n % csv_every == 0)
            fprintf(csv, "%.4f,%.5f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f,%.6f,"
                         "%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f,%.6f,%.6f\n",
                    t, DEG(theta), r[0].x, r[0].y, r[0].z, v[0].x, v[0].y, v[0].z, DEG(tilt[0]),
                    slip[0], r[1].x, r[1].y, r[1].z, v[1].x, v[1].y, v[1].z, DEG(tilt[1]),
                    slip[1], distance(w, sc.box[0], sc.box[1]));
        /* Offered every step: the series' strides choose the frames. */
        if (vtk && (s = ws_vtk_series_write_frame(vtk)) != WS_OK)
            break;
        /* The end, or a box left the platform: the world has no floor, so it would only fall. */
        if (n == steps || off) {
            res->final_slip[0] = slip[0];
            res->final_slip[1] = slip[1];
            res->final_angle = DEG(theta);
            res->end_time = t;
            break;
        }
        if ((s = ws_world_step(w)) != WS_OK)
            break;
        res->steps++;
        if (o->each_step)
            o->each_step(&sc, o->user);
        if (!o->quiet && now() > next_report) {
            fprintf(stderr, "\r  t = %.2f s of %.2f s", t, sc.duration);
            next_report = now() + 0.5;
        }
    }
    /* A gross slip still short of 0.2 s when the run ended is not a slide. */
    for (int k = 0; k < 2; k++)
        if (!res->slide_confirmed[k])
            res->slide_time[k] = res->slide_angle[k] = NAN;
    res->wall_seconds = now() - t0;
    if (!o->quiet && res->wall_seconds > 1.0)
        fprintf(stderr, "\r  t = %.2f s of %.2f s: done\n", res->end_time, sc.duration);
    res->cog_distance_end = distance(w, sc.box[0], sc.box[1]);
    ws_world_get_state_hash(w, &res->hash);
    ws_world_stats stats;
    if (ws_world_get_stats(w, &stats) == WS_OK)
        res->friction_use = stats.friction_step_use;
    if (sc.film.bits) {
        res->film_nodes = (uint32_t)nodes;
        ws_web_get_solver_stats(w, sc.film, &res->solver);
    }
    if (s != WS_OK)
        snprintf(res->error, sizeof res->error, "%s", ws_world_last_error(w));
    res->status = s;
    free(tension);
    free(strain);
    free(xyz);
    ws_vtk_series_destroy(vtk);
    if (csv)
        fclose(csv);
    ws_world_destroy(w);
    return s;
}

#ifndef TILT_TABLE_NO_MAIN
static void usage(FILE *f)
{
    fprintf(f,
            "usage: tilt_table [options]\n"
            "  --variant P|R      P: the paper's case (6 s); R: with the stop bar (7 s). Default R\n"
            "  --stick            stick friction instead of the paper's regularised law\n"
            "  --wrapped          a band of stretch film around the stack\n"
            "  --film-mass KG     kg per film node (> 0; default 0.001)\n"
            "  --substeps N       film sub-steps per step (1..1000; default 1)\n"
            "  --duration S       simulated time, s (> 0; default 6 for P, 7 for R)\n"
            "  --csv FILE         time series every 10 ms\n"
            "  --vtk DIR          VTK frames for ParaView (DIR is created)\n"
            "  --vtk-every S      s between frames (>= 0; default 0.1; 0: every --vtk-stride)\n"
            "  --vtk-stride N     offer a frame every Nth step (>= 1; default 1)\n"
            "  --vtk-springs      the film's springs as a block of their own\n"
            "  --vtk-ascii        ASCII files instead of compressed binary\n"
            "  --no-ccd           without the libccd gate\n"
            "  --paper-integrator the paper's explicit scheme\n"
            "  --explicit-friction the bodies' friction at the step's start, as the paper\n"
            "  --quiet            no progress, no summary\n"
            "  --help             this text\n"
            "Exit status: 0 done, 1 the run failed (the library or a file), 2 a bad option.\n");
}

/* A number > 0 from the whole of `text`, or an error message and 0. */
static int positive(const char *name, const char *text, double *out)
{
    char *end;
    errno = 0;
    double x = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || !isfinite(x) || x <= 0) {
        fprintf(stderr, "tilt_table: %s must be a number > 0, got '%s'\n", name, text);
        return 0;
    }
    *out = x;
    return 1;
}

static void print_box(const char *name, const tilt_result *r, int k)
{
    if (isnan(r->slide_time[k]))
        printf("  %-6s box: did not slide on its support\n", name);
    else
        printf("  %-6s box: starts to slide at %.2f deg (t = %.3f s)\n", name, r->slide_angle[k],
               r->slide_time[k]);
    if (!isnan(r->tip_time[k]))
        printf("  %-6s box: leans > 2 deg on its support from %.2f deg (t = %.3f s)\n", name,
               r->tip_angle[k], r->tip_time[k]);
    if (!isnan(r->off_time[k]))
        printf("  %-6s box: left the platform at t = %.3f s (slip %.0f mm); the run stops there\n",
               name, r->off_time[k], 1e3 * r->final_slip[k]);
    else
        printf("  %-6s box: slip along the platform at the end %.1f mm\n", name,
               1e3 * r->final_slip[k]);
}

int main(int argc, char **argv)
{
    tilt_options o;
    tilt_default_options(&o);
    enum { O_VARIANT = 1, O_STICK, O_NO_CCD, O_PAPER, O_CSV, O_VTK, O_DURATION, O_QUIET,
           O_WRAPPED, O_FILM_MASS, O_SUBSTEPS, O_HELP, O_VTK_EVERY, O_VTK_STRIDE, O_VTK_SPRINGS,
           O_VTK_ASCII, O_EXPLICIT_FRICTION };
    static const struct option longopts[] = {
        {"variant", required_argument, NULL, O_VARIANT},
        {"stick", no_argument, NULL, O_STICK},
        {"no-ccd", no_argument, NULL, O_NO_CCD},
        {"paper-integrator", no_argument, NULL, O_PAPER},
        {"explicit-friction", no_argument, NULL, O_EXPLICIT_FRICTION},
        {"csv", required_argument, NULL, O_CSV},
        {"vtk", required_argument, NULL, O_VTK},
        {"vtk-every", required_argument, NULL, O_VTK_EVERY},
        {"vtk-stride", required_argument, NULL, O_VTK_STRIDE},
        {"vtk-springs", no_argument, NULL, O_VTK_SPRINGS},
        {"vtk-ascii", no_argument, NULL, O_VTK_ASCII},
        {"duration", required_argument, NULL, O_DURATION},
        {"quiet", no_argument, NULL, O_QUIET},
        {"wrapped", no_argument, NULL, O_WRAPPED},
        {"film-mass", required_argument, NULL, O_FILM_MASS},
        {"substeps", required_argument, NULL, O_SUBSTEPS},
        {"help", no_argument, NULL, O_HELP},
        {NULL, 0, NULL, 0}};
    int c;
    double x;
    while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
        switch (c) {
        case O_VARIANT:
            o.variant = (char)(optarg[0] & ~0x20); /* upper case */
            if ((o.variant != 'P' && o.variant != 'R') || optarg[1] != '\0') {
                fprintf(stderr, "tilt_table: --variant must be P or R, got '%s'\n", optarg);
                return 2;
            }
            break;
        case O_STICK: o.stick = 1; break;
        case O_NO_CCD: o.use_ccd = 0; break;
        case O_PAPER: o.paper_integrator = 1; break;
        case O_EXPLICIT_FRICTION: o.explicit_friction = 1; break;
        case O_CSV: o.csv = optarg; break;
        case O_VTK: o.vtk_dir = optarg; break;
        case O_VTK_SPRINGS: o.vtk_springs = 1; break;
        case O_VTK_ASCII: o.vtk_ascii = 1; break;
        case O_VTK_EVERY: {
            char *end;
            errno = 0;
            o.vtk_every = strtod(optarg, &end);
            if (end == optarg || *end != '\0' || errno == ERANGE || !isfinite(o.vtk_every) ||
                o.vtk_every < 0) {
                fprintf(stderr, "tilt_table: --vtk-every must be a number >= 0, got '%s'\n",
                        optarg);
                return 2;
            }
            break;
        }
        case O_VTK_STRIDE:
            if (!positive("--vtk-stride", optarg, &x) || x != floor(x) || x > 1e9) {
                fprintf(stderr, "tilt_table: --vtk-stride must be a whole number >= 1\n");
                return 2;
            }
            o.vtk_stride = (int)x;
            break;
        case O_QUIET: o.quiet = 1; break;
        case O_WRAPPED: o.wrapped = 1; break;
        case O_DURATION:
            if (!positive("--duration", optarg, &o.duration))
                return 2;
            break;
        case O_FILM_MASS:
            if (!positive("--film-mass", optarg, &o.film_mass))
                return 2;
            break;
        case O_SUBSTEPS:
            if (!positive("--substeps", optarg, &x) || x != floor(x) || x > 1000) {
                fprintf(stderr, "tilt_table: --substeps must be a whole number 1..1000\n");
                return 2;
            }
            o.substeps = (int)x;
            break;
        case 'h':
        case O_HELP: usage(stdout); return 0;
        default: usage(stderr); return 2; /* getopt_long said what was wrong */
        }
    }
    if (optind < argc) {
        fprintf(stderr, "tilt_table: unexpected argument '%s'\n", argv[optind]);
        usage(stderr);
        return 2;
    }
    double theory = DEG(atan(0.3));
    if (!o.quiet)
        printf("libwrapsim %s - tilt table, variant %c, %s, %s friction\n"
               "  theory: sliding starts at tan(theta) = mu = 0.3, theta = %.2f deg, t = %.3f s\n"
               "  slide onset: every contact with its support slips (|v_t| >= v_lim = %.0f mm/s)"
               " the same way, for %.1f s\n",
               ws_version_string(), o.variant, o.wrapped ? "wrapped" : "unwrapped",
               o.stick ? "stick" : "regularised (paper)", theory, TILT_START + atan(0.3) / 0.1,
               1e3 * 0.01, TILT_SLIDE_HOLD);
    if (!o.quiet && o.wrapped && o.variant == 'R')
        printf("  theory, wrapped: the stack tips as one when its CoG passes over the stop's "
               "edge, tan(theta) = 0.125/0.23, theta = %.2f deg, t = %.3f s, without the layers; "
               "28.61 deg with them (docs/theory.md 4.1); about 29.5-29.7 deg with Coulomb "
               "friction at the base\n",
               DEG(atan(0.125 / 0.23)), TILT_START + atan(0.125 / 0.23) / 0.1);
    tilt_result r;
    ws_status s = tilt_run(&o, &r);
    if (s != WS_OK) {
        fprintf(stderr, "tilt_table: %s\n  %s\n", ws_status_string(s), r.error);
        return 1;
    }
    if (!o.quiet) {
        print_box("bottom", &r, 0);
        print_box("top", &r, 1);
        printf("  distance between the CoGs: %.1f mm at the start, %.1f mm at the end\n",
               1e3 * r.cog_distance_start, 1e3 * r.cog_distance_end);
        if (!isnan(r.lift_time))
            printf("  the bottom box's uphill edge lifts off the platform at %.2f deg (t = %.3f s);\n"
                   "    a rigid stack unloads it at tan(theta) = (a/2) / CoG height = 0.125/0.252, "
                   "%.2f deg\n",
                   r.lift_angle, r.lift_time, DEG(atan(0.125 / 0.252)));
        if (!isnan(r.lift_time) && !isnan(r.lift_theory))
            printf("    when pushed at its foot; the stop pushed %.1f mm above the box's bottom "
                   "face (%.0f %% of the load's weight down the platform), where a rigid stack "
                   "unloads it at %.2f deg\n",
                   1e3 * r.stop_height, 100 * r.stop_share, r.lift_theory);
        if (!isnan(r.over_theory))
            printf("  the load's CoG (boxes and film) passes over the stop's edge at %.2f deg "
                   "(t = %.3f s);\n"
                   "    a rigid load with the geometry it had when its uphill edge lifted "
                   "would at %.2f deg\n",
                   r.over_angle, r.over_time, r.over_theory);
        printf("  top box on the bottom one: largest move %.1f mm while the stack stands\n",
               1e3 * r.max_relative_slip);
        if (o.wrapped)
            printf("  film: peak strain %.3f, peak spring tension %.2f N\n", r.peak_strain,
                   r.peak_tension);
        printf("  plane angle at the end %.2f deg (t = %.3f s); %ld steps in %.3f s "
               "(%.0f steps/s)\n",
               r.final_angle, r.end_time, r.steps, r.wall_seconds, r.steps / r.wall_seconds);
        if (r.friction_use > 1.0)
            printf("  note: dt is %.2f times the regularised friction's explicit limit between "
                   "the bodies: their contacts slip back and forth every step and the load creeps "
                   "too fast (docs/theory.md 5, 8); leave out --explicit-friction, use --stick, "
                   "or a smaller dt\n",
                   r.friction_use);
        if (o.csv)
            printf("  time series: %s\n", o.csv);
        if (o.vtk_dir)
            printf("  VTK frames: %s/tilt_table.pvd (open in ParaView)\n", o.vtk_dir);
    }
    return 0;
}
#endif
