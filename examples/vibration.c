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
 * The run (ws_loadtest_run_vibration) prints the Grms the platform delivered, how far each
 * layer's cartons moved against the pallet (sideways: they walk; tilt), and for the sweep the
 * frequency at which the top layer answered most: the load's first vertical resonance; then
 * the verdict, criterion by criterion.
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
    double took;
    ws_status s;
    if ((s = ws_load_build(w, &ld, &load)) != WS_OK ||
        (s = ws_load_settle(w, load, 0.2, 1.0, 1e-4, &settled, &took)) != WS_OK ||
        (o.wrapped && ((s = ws_load_wrap_band(w, load, &wr, &film)) != WS_OK ||
                       (s = ws_load_settle(w, load, 0.2, 1.0, 1e-4, &settled, &took)) != WS_OK)) ||
        (s = ws_load_get_info(load, &info)) != WS_OK) {
        fprintf(stderr, "%s: %s\n", ws_status_string(s), ws_world_last_error(w));
        ws_load_destroy(load);
        ws_world_destroy(w);
        return 1;
    }

    /* The test: vertical, faded in and out; the truck spectrum of the level as it is, or the
     * sweep's defaults (0.25 g, 2 to 40 Hz, logarithmic). The run measures every 1 ms, judges,
     * and leaves the world as it found it. */
    ws_vibration_test_def vd;
    ws_vibration_test_def_init(&vd);
    vd.duration = o.duration;
    vd.ramp_time = fmin(0.5, 0.25 * o.duration);
    double f[64], g2[64];
    size_t n = 0;
    if (o.sweep) {
        vd.sweep = 1;
    } else if ((s = ws_vibration_truck_psd((ws_truck_level)o.level, f, g2, 64, &n)) == WS_OK) {
        vd.psd_frequency = f;
        vd.psd_level = g2;
        vd.psd_count = n;
        vd.grms = 0; /* as given: the level's spectrum */
        vd.seed = o.seed;
    }
    ws_loadtest_result r;
    if (s != WS_OK || (s = ws_loadtest_run_vibration(w, load, &vd, &r)) != WS_OK) {
        fprintf(stderr, "%s: %s\n", ws_status_string(s), ws_world_last_error(w));
        ws_load_destroy(load);
        ws_world_destroy(w);
        return 1;
    }
    if (o.sweep)
        printf("sine sweep 2-40 Hz at 0.25 g, %s load, %.1f s: the top layer answers most at "
               "%.2f Hz (transmissibility %.2f): the load's first vertical resonance\n",
               o.wrapped ? "wrapped" : "unwrapped", o.duration, r.resonance_frequency,
               r.resonance_transmissibility);
    else
        printf("truck random vibration, %s load, %.1f s: platform delivered %.3f Grms of %.3f\n",
               o.wrapped ? "wrapped" : "unwrapped", o.duration, r.grms_delivered, r.grms_target);
    for (int l = 0; l < r.layers; l++)
        printf("layer %d: largest sideways displacement %.2f mm, tilt %.2f deg\n", l + 1,
               r.layer_max[l] * 1e3, r.layer_tilt[l] * 57.29577951308232);
    printf("%d events, %d cartons lost; verdict %s\n", r.event_count, r.cartons_lost,
           r.verdict.pass ? "PASS" : "FAIL");
    for (int i = 0; i < r.verdict.count; i++) {
        const ws_loadtest_check *c = &r.verdict.check[i];
        const char *op = c->at_least ? ">=" : (c->id == WS_CHECK_LAYER_SHIFT ? "<" : "<=");
        printf("  %-12s %10.4g (limit %s %.4g) %s\n", ws_loadtest_check_name(c->id), c->value,
               op, c->limit, c->pass ? "pass" : "FAIL");
    }
    ws_load_destroy(load);
    ws_world_destroy(w);
    return 0;
}
