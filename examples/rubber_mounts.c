/*
 * rubber_mounts.c: a box on four rubber mounts on a shaker table, and the loads in each mount.
 *
 * The packaging version of a suspension test rig: a carton of 15 kg (0.4 x 0.3 x 0.25 m) stands
 * on four rubber bushings, 30 mm high, under its corners; they sit on a platform that a drive
 * moves. The box starts at rest on the mounts, pressed down by its weight; for 0.5 s nothing
 * moves, then the platform heaves
 * (2 mm at 15 Hz) and rolls (1 deg at 6 Hz) for the rest of the run. Each mount is a 6D bushing
 * with a Kelvin-Voigt law: stiff in compression, softer in shear, with rotational stiffness,
 * referred to the mid frame between platform and box (WS_ELEMENT_INVARIANT), so the result
 * does not depend on which body is named first.
 *
 * It prints the static share of each mount (their sum is the weight m g) and the peak force and
 * moment in each during the shaking; with --csv it writes every mount's force (N) and moment
 * (N m, about the mount's point on the box) on the box, in the global frame, every millisecond.
 *
 * Build:  cc rubber_mounts.c $(pkg-config --cflags --libs libwrapsim) -o rubber_mounts
 * Run:    ./rubber_mounts [--duration S] [--csv FILE] [--quiet]
 *
 * Copy this file for your own load: the box, the mount law and their places are in build();
 * the motion of the table is table_motion().
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <wrapsim/wrapsim.h>

#define MOUNT_PI 3.14159265358979323846
#define MOUNTS 4

/* The shaker: heave and roll amplitudes (m, rad), frequencies (Hz), the start and a smooth
 * ramp-in (s). */
static const struct {
    double heave, heave_hz, roll, roll_hz, start, ramp;
} TABLE = {2e-3, 15.0, 1.0 * MOUNT_PI / 180.0, 6.0, 0.5, 0.1};

static const double PLATFORM_Z = -0.025; /* CoG of the 50 mm platform: its top face at z = 0 */

typedef struct scene {
    ws_world *world;
    ws_body_id platform, box;
    ws_element_id mount[MOUNTS];
} scene;

/* Ramp factor r(t) from 0 to 1 over TABLE.ramp after TABLE.start, with its rate. */
static double ramp(double t, double *rate)
{
    double u = (t - TABLE.start) / TABLE.ramp;
    *rate = 0.0;
    if (u <= 0.0)
        return 0.0;
    if (u >= 1.0)
        return 1.0;
    *rate = 0.5 * MOUNT_PI * sin(MOUNT_PI * u) / TABLE.ramp;
    return 0.5 * (1.0 - cos(MOUNT_PI * u));
}

/* The drive: the platform's pose and velocities at time t (global). */
static int table_motion(void *user, double t, ws_pose *pose, ws_vec3 *v, ws_vec3 *w)
{
    (void)user;
    double rr, r = ramp(t, &rr), tau = t - TABLE.start;
    double wh = 2 * MOUNT_PI * TABLE.heave_hz, wr = 2 * MOUNT_PI * TABLE.roll_hz;
    double z = TABLE.heave * r * sin(wh * tau);
    double zd = TABLE.heave * (rr * sin(wh * tau) + r * wh * cos(wh * tau));
    double phi = TABLE.roll * r * sin(wr * tau);
    double phid = TABLE.roll * (rr * sin(wr * tau) + r * wr * cos(wr * tau));
    pose->position = (ws_vec3){0.0, 0.0, PLATFORM_Z + z};
    pose->orientation = (ws_quat){cos(0.5 * phi), sin(0.5 * phi), 0.0, 0.0}; /* roll about x */
    *v = (ws_vec3){0.0, 0.0, zd};
    *w = (ws_vec3){phid, 0.0, 0.0};
    return 0;
}

#define TRY(call)                                                                                  \
    do {                                                                                           \
        if ((s = (call)) != WS_OK)                                                                 \
            return s;                                                                              \
    } while (0)

static ws_status build(scene *sc)
{
    ws_status s;
    ws_world_def wd;
    ws_world_def_init(&wd);
    wd.dt = 2.5e-4;
    TRY(ws_world_create(&wd, &sc->world));
    ws_world *w = sc->world;

    ws_shape_id plate, carton;
    TRY(ws_shape_create_box(w, 0.8, 0.6, 0.05, &plate));
    TRY(ws_shape_create_box(w, 0.4, 0.3, 0.25, &carton));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = plate;
    bd.position = (ws_vec3){0, 0, PLATFORM_Z};
    bd.name = "platform";
    TRY(ws_body_create(w, &bd, &sc->platform));
    ws_drive_def dd;
    ws_drive_def_init(&dd);
    dd.type = WS_DRIVE_CALLBACK;
    dd.callback = table_motion;
    TRY(ws_body_set_drive(w, sc->platform, &dd));

    const double h = 0.030; /* mount height: the box's bottom face at z = h */
    ws_body_def_init(&bd);
    bd.shape = carton;
    bd.mass = 15.0;
    bd.position = (ws_vec3){0, 0, h + 0.125};
    bd.name = "carton";
    TRY(ws_body_create(w, &bd, &sc->box));

    /* One rubber mount: u = [displacement x y z (m), rotation x y z (rad)] in its frame; 60 kN/m
     * in compression, 20 kN/m in shear, 30 N m/rad in rocking, 20 N m/rad in torsion; damping
     * 0.8 ms times each stiffness (a loss of about 6 % at the box's bounce near 20 Hz). */
    double K[36] = {0}, C[36] = {0};
    const double k[6] = {2e4, 2e4, 6e4, 30.0, 30.0, 20.0};
    for (int i = 0; i < 6; i++) {
        K[7 * i] = k[i];
        C[7 * i] = 8e-4 * k[i];
    }
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_LINEAR_VISCOELASTIC;
    ld.dim = 6;
    ld.stiffness_matrix = K;
    ld.damping_matrix = C;
    ld.name = "rubber mount";
    ws_law_id rubber;
    TRY(ws_law_create(w, &ld, &rubber));

    /* Each mount at mid-height under a corner, given in the global frame: the element keeps the
     * point in both bodies, so it starts unstrained; its axes are the global ones (default). */
    static const char *const names[MOUNTS] = {"mount -x-y", "mount +x-y", "mount -x+y",
                                              "mount +x+y"};
    ws_element_def ed;
    ws_element_def_init(&ed);
    ed.type = WS_ELEMENT_BUSHING;
    ed.formulation = WS_ELEMENT_INVARIANT;
    ed.body1 = sc->platform;
    ed.body2 = sc->box;
    ed.law = rubber;
    ed.global_attachment = 1;
    for (int m = 0; m < MOUNTS; m++) {
        ed.point1 = ed.point2 = (ws_vec3){(m & 1) ? 0.17 : -0.17, (m & 2) ? 0.12 : -0.12, h / 2};
        ed.name = names[m];
        TRY(ws_element_create(w, &ed, &sc->mount[m]));
    }
    /* Start the box at its static deflection, m g over the four mounts' compression stiffness,
     * so it rests from the first step rather than bouncing in. */
    ws_pose rest = {{0, 0, h + 0.125 - 15.0 * 9.81 / (MOUNTS * k[2])}, {1, 0, 0, 0}};
    return ws_body_set_pose(w, sc->box, &rest);
}

static double norm(ws_vec3 a)
{
    return sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
}

int main(int argc, char **argv)
{
    double duration = 1.5;
    const char *csv_path = NULL;
    int quiet = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--duration") && i + 1 < argc) {
            duration = atof(argv[++i]);
        } else if (!strcmp(argv[i], "--csv") && i + 1 < argc) {
            csv_path = argv[++i];
        } else if (!strcmp(argv[i], "--quiet")) {
            quiet = 1;
        } else {
            fprintf(stderr, "usage: rubber_mounts [--duration S] [--csv FILE] [--quiet]\n");
            return 2;
        }
    }
    scene sc;
    memset(&sc, 0, sizeof sc);
    ws_status s = build(&sc);
    FILE *csv = NULL;
    if (s == WS_OK && csv_path && !(csv = fopen(csv_path, "w"))) {
        fprintf(stderr, "rubber_mounts: cannot write %s\n", csv_path);
        ws_world_destroy(sc.world);
        return 1;
    }
    if (csv) {
        /* Each column's unit at the end of its name: s, N, N m (Nm). */
        fprintf(csv, "t_s");
        for (int m = 0; m < MOUNTS; m++)
            for (int c = 0; c < 6; c++)
                fprintf(csv, ",m%d_%c%c_%s", m + 1, c < 3 ? 'F' : 'M', "xyz"[c % 3],
                        c < 3 ? "N" : "Nm");
        fprintf(csv, "\n");
    }

    double dt = 0.0, static_fz[MOUNTS] = {0}, peak_f[MOUNTS] = {0}, peak_m[MOUNTS] = {0};
    ws_element_output out[MOUNTS];
    size_t n = 0;
    if (s == WS_OK)
        s = ws_world_get_dt(sc.world, &dt);
    long steps = lround(duration / dt), every = lround(1e-3 / dt);
    long settled = lround(TABLE.start / dt);
    for (long k = 0; s == WS_OK && k <= steps; k++) {
        /* All four mounts in one call: the loads they put on the bodies now. */
        if ((s = ws_world_copy_element_outputs(sc.world, out, MOUNTS, &n)) != WS_OK)
            break;
        for (int m = 0; m < MOUNTS; m++) {
            /* On the box (body 2): the opposite of the force on the platform, and moment2. */
            ws_vec3 f = {0.0 - out[m].force.x, 0.0 - out[m].force.y, 0.0 - out[m].force.z};
            if (k == settled || (k == steps && steps < settled)) /* at rest, or the end */
                static_fz[m] = f.z;
            if (k > settled) {
                peak_f[m] = fmax(peak_f[m], norm(f));
                peak_m[m] = fmax(peak_m[m], norm(out[m].moment2));
            }
            if (csv && k % every == 0) {
                if (m == 0)
                    fprintf(csv, "%.6f", k * dt);
                fprintf(csv, ",%.6g,%.6g,%.6g,%.6g,%.6g,%.6g", f.x, f.y, f.z, out[m].moment2.x,
                        out[m].moment2.y, out[m].moment2.z);
            }
        }
        if (csv && k % every == 0)
            fprintf(csv, "\n");
        if (k < steps)
            s = ws_world_step(sc.world);
    }
    if (csv)
        fclose(csv);
    if (s != WS_OK) {
        fprintf(stderr, "rubber_mounts: %s\n  %s\n", ws_status_string(s),
                ws_world_last_error(sc.world));
        ws_world_destroy(sc.world);
        return 1;
    }
    if (!quiet) {
        double sum = 0.0;
        printf("rubber mounts: 15 kg carton on 4 bushings, table heave %.1f mm at %.0f Hz and roll "
               "%.1f deg at %.0f Hz from t = %.1f s, %.2f s in all\n",
               TABLE.heave * 1e3, TABLE.heave_hz, TABLE.roll * 180.0 / MOUNT_PI, TABLE.roll_hz,
               TABLE.start, duration);
        for (int m = 0; m < MOUNTS; m++) {
            printf("  %-11s static %6.2f N up; shaking: peak |force| %7.2f N, peak |moment| "
                   "%6.3f N m\n",
                   ws_element_get_name(sc.world, sc.mount[m]), static_fz[m], peak_f[m], peak_m[m]);
            sum += static_fz[m];
        }
        if (duration >= TABLE.start)
            printf("  static check: the mounts carry %.2f N, the weight is m g = %.2f N\n", sum,
                   15.0 * 9.81);
        if (csv_path)
            printf("  time series: %s\n", csv_path);
    }
    ws_world_destroy(sc.world);
    return 0;
}
