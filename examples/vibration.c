/*
 * vibration.c: a pallet load on a vibration table: truck random vibration, or a sine sweep
 * that finds the load's resonance.
 *
 * The EUR pallet with 4 layers of 8 cartons (the load builder's defaults), unwrapped or
 * (--wrapped) in a band of film, settles on a level platform; the platform then shakes
 * vertically:
 *   random (default): the library's truck spectrum at an ASTM D4169 level (--level 1, 2, 3:
 *            0.40, 0.54, 0.70 Grms), synthesised from --seed (the same seed, the same history);
 *   --sweep: a sine of 0.25 g from 2 to 40 Hz, logarithmic, over the duration.
 * It prints the Grms the platform delivered, how far the cartons moved against the pallet (up:
 * they bounce; sideways: they walk; tilt), and for the sweep the frequency at which the top
 * layer answered most: the load's first vertical resonance.
 *
 * Build:  cc vibration.c $(pkg-config --cflags --libs libwrapsim) -o vibration
 * Run:    ./vibration [--sweep] [--level N] [--seed S] [--duration S] [--wrapped]
 *
 * Copy it as the start of your own test: change the load Def, the drive Def, what is measured.
 */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <wrapsim/wrapsim.h>

#define MAX_CARTONS 256
#define BINS 40 /* sweep: response by frequency, in bins of equal ratio from 2 to 40 Hz */

typedef struct options {
    int sweep, level, wrapped;
    unsigned long long seed;
    double duration;
} options;

/* A number, or an error: "--duration abc" must not run the default. */
static int number(const char *text, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (errno || end == text || *end || !(v >= lo && v <= hi))
        return -1;
    *out = v;
    return 0;
}

static int parse(int argc, char **argv, options *o)
{
    static const struct option longs[] = {
        {"sweep", no_argument, 0, 'w'},       {"level", required_argument, 0, 'l'},
        {"seed", required_argument, 0, 's'},  {"duration", required_argument, 0, 'd'},
        {"wrapped", no_argument, 0, 'p'},     {"help", no_argument, 0, 'h'},
        {0, 0, 0, 0}};
    double v;
    int c;
    while ((c = getopt_long(argc, argv, "", longs, NULL)) != -1) {
        if (c == 'w')
            o->sweep = 1;
        else if (c == 'p')
            o->wrapped = 1;
        else if (c == 'l' && number(optarg, 1, 3, &v) == 0 && v == floor(v))
            o->level = (int)v;
        else if (c == 's' && number(optarg, 0, 1e18, &v) == 0 && v == floor(v))
            o->seed = (unsigned long long)v;
        else if (c == 'd' && number(optarg, 0.1, 3600, &v) == 0)
            o->duration = v;
        else {
            fprintf(c == 'h' ? stdout : stderr,
                    "usage: %s [--sweep] [--level 1|2|3] [--seed N] [--duration S] [--wrapped]\n",
                    argv[0]);
            return c == 'h' ? 0 : 2;
        }
    }
    return optind == argc ? -1 : 2;
}

/* The platform's drive: the truck spectrum's random history, or the sweep. */
static ws_status shake(ws_world *w, ws_body_id platform, const options *o, double t0)
{
    double f[64], g2[64];
    size_t n = 0;
    ws_drive_def d;
    ws_drive_def_init(&d);
    d.direction = (ws_vec3){0.0, 0.0, 1.0};
    d.start_time = t0;
    d.duration = o->duration;
    d.ramp_time = fmin(0.5, 0.25 * o->duration); /* fade in and out, a quarter at most */
    if (o->sweep) {
        d.type = WS_DRIVE_SWEEP;
        d.acceleration = 0.25 * WS_STANDARD_GRAVITY;
        d.frequency = 2.0;
        d.frequency_end = 40.0;
        d.sweep_law = WS_SWEEP_LOG;
    } else {
        ws_status s = ws_vibration_truck_psd((ws_truck_level)o->level, f, g2, 64, &n);
        if (s != WS_OK)
            return s;
        d.type = WS_DRIVE_RANDOM;
        d.psd_frequency = f;
        d.psd_level = g2;
        d.psd_count = n;
        d.seed = o->seed;
    }
    return ws_body_set_drive(w, platform, &d);
}

int main(int argc, char **argv)
{
    options o = {0, 2, 0, 1, 0.0};
    int rc = parse(argc, argv, &o);
    if (rc >= 0)
        return rc;
    if (o.duration == 0.0)
        o.duration = o.sweep ? 20.0 : 10.0;

    ws_world_def wd;
    ws_world_def_init(&wd);
    wd.detection_interval = 10;
    ws_world *w;
    if (ws_world_create(&wd, &w) != WS_OK)
        return 1;
    ws_load_def ld;
    ws_load_def_init(&ld); /* EUR pallet, 4 layers of 4 x 2 cartons of 10 kg */
    ws_wrap_def wr;
    ws_wrap_def_init(&wr); /* 3 layers of 20 um film, 10 % strain on the load */
    ws_load *load = NULL;
    ws_load_info info;
    ws_web_id film;
    int settled;
    double took, t0;
    ws_status s;
    if ((s = ws_load_build(w, &ld, &load)) != WS_OK ||
        (s = ws_load_settle(w, load, 0.2, 1.0, 1e-4, &settled, &took)) != WS_OK ||
        (o.wrapped && ((s = ws_load_wrap_band(w, load, &wr, &film)) != WS_OK ||
                       (s = ws_load_settle(w, load, 0.2, 1.0, 1e-4, &settled, &took)) != WS_OK)) ||
        (s = ws_load_get_info(load, &info)) != WS_OK ||
        (s = ws_load_set_reference(w, load)) != WS_OK || (s = ws_world_get_time(w, &t0)) != WS_OK ||
        (s = shake(w, info.platform, &o, t0)) != WS_OK) {
        fprintf(stderr, "%s: %s\n", ws_status_string(s), ws_world_last_error(w));
        ws_load_destroy(load);
        ws_world_destroy(w);
        return 1;
    }

    /* Every 1 ms: the platform's acceleration as delivered, and each carton against the
     * pallet. For the sweep, the top layer's largest vertical excursion in each frequency bin. */
    static ws_load_carton_state cs[MAX_CARTONS];
    double sum_a2 = 0, up = 0, side = 0, tilt = 0, answer[BINS] = {0};
    int top = info.layers - 1, samples = 0, steps = 4; /* 4 steps of 0.25 ms */
    for (double t = 0; t < o.duration; t += steps * 2.5e-4) {
        size_t n;
        ws_drive_state ds;
        if ((s = ws_world_step_n(w, steps)) != WS_OK ||
            (s = ws_body_get_drive_state(w, info.platform, &ds)) != WS_OK ||
            (s = ws_load_measure(w, load, cs, MAX_CARTONS, &n)) != WS_OK)
            break;
        sum_a2 += ds.acceleration.z * ds.acceleration.z;
        samples++;
        double top_up = 0; /* ws_load_measure lists the cartons layer by layer, bottom first */
        size_t first_top = n - (size_t)ws_load_get_layer_count(load, top);
        for (size_t i = 0; i < n; i++) {
            up = fmax(up, cs[i].displacement.z);
            side = fmax(side, cs[i].horizontal);
            tilt = fmax(tilt, cs[i].tilt);
            if (i >= first_top)
                top_up = fmax(top_up, fabs(cs[i].displacement.z));
        }
        if (o.sweep) { /* the sweep's frequency now: f1 (f2 / f1)^(t / T) */
            double f = 2.0 * pow(20.0, t / o.duration);
            int b = (int)(BINS * log(f / 2.0) / log(20.0));
            if (b >= 0 && b < BINS)
                answer[b] = fmax(answer[b], top_up);
        }
    }
    if (s != WS_OK) {
        fprintf(stderr, "%s: %s\n", ws_status_string(s), ws_world_last_error(w));
        ws_load_destroy(load);
        ws_world_destroy(w);
        return 1;
    }
    printf("%s, %s load, %.1f s: platform delivered %.3f Grms\n",
           o.sweep ? "sine sweep 2-40 Hz at 0.25 g" : "truck random vibration",
           o.wrapped ? "wrapped" : "unwrapped", o.duration,
           sqrt(sum_a2 / samples) / WS_STANDARD_GRAVITY);
    printf("cartons against the pallet: largest rise %.2f mm, sideways %.2f mm, tilt "
           "%.2f deg\n",
           up * 1e3, side * 1e3, tilt * 57.29577951308232);
    if (o.sweep) {
        int best = 0;
        for (int b = 1; b < BINS; b++)
            best = answer[b] > answer[best] ? b : best;
        printf("top layer answers most near %.1f Hz (%.3f mm against the pallet): the load's "
               "first vertical resonance in 2-40 Hz\n",
               2.0 * pow(20.0, (best + 0.5) / BINS), answer[best] * 1e3);
    }
    ws_load_destroy(load);
    ws_world_destroy(w);
    return 0;
}
