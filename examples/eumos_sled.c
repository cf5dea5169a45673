/*
 * eumos_sled.c: a pallet load on the EUMOS 40509 acceleration sled, and its verdict.
 *
 * A EUR pallet (1200 x 800 x 144 mm, 25 kg) with 4 layers of 8 cartons (400 x 300 x 250 mm,
 * 10 kg each), unwrapped, or (--wrapped) spiral-wrapped as a machine lays 500 mm film of 20 um
 * at 200 % pre-stretch, or (--band) in a plain band of film, settles on a
 * level platform until it stands still (at most --settle S seconds, default 4, before and again
 * after the wrap); the platform then accelerates at k g
 * (reached in 40 ms, held 0.35 s) and stops gently. The program prints what the load did and
 * the verdict of each criterion: elastic displacement <= 10 % of the load's height, permanent
 * <= 5 %, lowest 20 cm <= 40 mm, layer shift < 2 %, no rupture.
 *
 * Build:  cc eumos_sled.c $(pkg-config --cflags --libs libwrapsim) -o eumos_sled
 * Run:    ./eumos_sled [--k G] [--wrapped | --band] [--brake] [--settle S] [--rest S] [--find-k]
 *
 * Copy it as the start of your own test: change the load Def, the EUMOS Def, read the result.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <wrapsim/wrapsim.h>

/* A number in [lo, hi], or an error: "--k abc" must not run the default. */
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

static const char *event_name(int type)
{
    switch (type) {
    case WS_LOADTEST_SLIP_ONSET: return "slip onset";
    case WS_LOADTEST_TIP_ONSET: return "tip onset";
    case WS_LOADTEST_CARTON_LOST: return "carton lost";
    default: return "rupture";
    }
}

static void print_criterion(const char *name, const ws_loadtest_criterion *c, double scale,
                            const char *unit)
{
    printf("  %-28s %9.1f %s  (limit %.1f %s)  %s\n", name, c->value * scale, unit,
           c->limit * scale, unit, c->pass ? "pass" : "FAIL");
}

static void print_result(const ws_eumos_result *r)
{
    printf("pulse: peak %.3f g, reached in %.1f ms, held within 1 %% for %.3f s\n", r->peak_level,
           r->rise_measured * 1e3, r->time_at_level);
    for (int l = 0; l < r->layers; l++)
        printf("layer %d: largest displacement %.1f mm, permanent %.1f mm, tilt %.2f deg\n", l,
               r->layer_max[l] * 1e3, r->layer_permanent[l] * 1e3,
               r->layer_tilt[l] * 57.29577951308232);
    for (int i = 0; i <= r->layers; i++)
        printf("interface %d: largest slip speed %.1f mm/s, friction use %.2f\n", i,
               r->interface_slip_max[i] * 1e3, r->interface_use_max[i]);
    int shown = r->event_count < 12 ? r->event_count : 12;
    for (int i = 0; i < shown; i++) {
        const ws_loadtest_event *e = &r->events[i];
        printf("event at %.3f s (%.3f g): %s, layer/interface %d, carton %d\n", e->time, e->level,
               event_name(e->type), e->layer, e->index);
    }
    if (r->event_count > shown)
        printf("... %d more events\n", r->event_count - shown + r->events_dropped);
    const ws_eumos_verdict *v = &r->verdict;
    printf("EUMOS 40509 at %.2f g, load height %.3f m:\n", r->k, v->load_height);
    print_criterion("elastic displacement", &v->elastic, 1e3, "mm");
    print_criterion("permanent displacement", &v->permanent, 1e3, "mm");
    print_criterion("lowest 20 cm", &v->bottom, 1e3, "mm");
    print_criterion("layer shift", &v->layer_shift, 1e3, "mm");
    print_criterion("film ruptures", &v->rupture, 1, "");
    printf("verdict: %s\n", v->pass ? "PASS" : "FAIL");
}

int main(int argc, char **argv)
{
    double k = 0.3, settle = 4.0, rest = 0.5;
    int brake = 0, find_k = 0, wrapped = 0, band = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--k") && i + 1 < argc && number(argv[i + 1], 1e-3, 10, &k) == 0)
            i++;
        else if (!strcmp(argv[i], "--settle") && i + 1 < argc &&
                 number(argv[i + 1], 0.2, 100, &settle) == 0)
            i++;
        else if (!strcmp(argv[i], "--rest") && i + 1 < argc &&
                 number(argv[i + 1], 0, 100, &rest) == 0)
            i++;
        else if (!strcmp(argv[i], "--brake"))
            brake = 1;
        else if (!strcmp(argv[i], "--find-k"))
            find_k = 1;
        else if (!strcmp(argv[i], "--wrapped"))
            wrapped = 1;
        else if (!strcmp(argv[i], "--band"))
            band = 1;
        else {
            fprintf(stderr, "usage: %s [--k G] [--wrapped | --band] [--brake] [--settle S] "
                            "[--rest S] "
                            "[--find-k]\n",
                    argv[0]);
            return 2;
        }
    }

    /* The world: dt 0.25 ms; full contact detection every 10th step (the world detects sooner
     * when bodies close the contact margin). */
    ws_world_def wd;
    ws_world_def_init(&wd);
    wd.detection_interval = 10;
    /* The load: the defaults are the EUR pallet with 4 layers of 4 x 2 cartons. */
    ws_load_def ld;
    ws_load_def_init(&ld);
    /* The test. */
    ws_eumos_def ed;
    ws_eumos_def_init(&ed);
    ed.k = k;
    ed.rest_after = rest;
    ed.mode = brake ? WS_PULSE_BRAKE : WS_PULSE_ACCELERATE;
    /* The spiral: the defaults are 500 mm film of 20 um, 150 MPa, 200 % powered pre-stretch,
     * 10 % strain on the load, 2 revolutions at the bottom and top, 50 % overlap, up and down,
     * locked to the pallet. Nodes of at least 1 g (the film's own 0.1-0.4 g need 19 film
     * sub-steps a step rather than 3; the 1.8 kg of film is small beside 345 kg of load). */
    ws_spiral_wrap_def sp;
    ws_spiral_wrap_def_init(&sp);
    sp.node_mass_min = 1e-3;
    /* The band: 3 layers of 20 um, 150 MPa, 10 % strain on the load, from the pallet up. */
    ws_wrap_def wr;
    ws_wrap_def_init(&wr);
    if (wrapped && band) {
        fprintf(stderr, "%s: --wrapped or --band, not both\n", argv[0]);
        return 2;
    }

    if (find_k) {
        ws_kvalue_def kd;
        ws_kvalue_def_init(&kd);
        kd.settle_time = settle;
        kd.wrap = band ? &wr : NULL;
        kd.spiral = wrapped ? &sp : NULL;
        ws_kvalue_result kr;
        ws_status s = ws_loadtest_find_k(&wd, &ld, &ed, &kd, &kr);
        if (s != WS_OK) {
            fprintf(stderr, "k-value search: %s (%s)\n", ws_status_string(s), kr.error);
            return 1;
        }
        printf("k-value: %.3f g (fails at %.3f g) after %d runs\n", kr.k_value, kr.k_fail,
               kr.runs);
        return 0;
    }

    ws_world *w;
    ws_load *load = NULL;
    ws_status s = ws_world_create(&wd, &w);
    if (s != WS_OK) {
        fprintf(stderr, "world: %s\n", ws_status_string(s));
        return 1;
    }
    int settled = 0;
    double took = 0, took_wrap = 0;
    ws_eumos_result r;
    ws_web_id film;
    if ((s = ws_load_build(w, &ld, &load)) != WS_OK ||
        (s = ws_load_settle(w, load, 0.2, settle, 1e-4, &settled, &took)) != WS_OK ||
        (wrapped && (s = ws_load_wrap_spiral(w, load, &sp, &film)) != WS_OK) ||
        (band && (s = ws_load_wrap_band(w, load, &wr, &film)) != WS_OK) ||
        ((wrapped || band) &&
         (s = ws_load_settle(w, load, 0.2, settle, 1e-4, &settled, &took_wrap)) != WS_OK) ||
        (s = ws_loadtest_run_eumos(w, load, &ed, &r)) != WS_OK) {
        fprintf(stderr, "%s: %s\n", ws_status_string(s), ws_world_last_error(w));
        ws_load_destroy(load);
        ws_world_destroy(w);
        return 1;
    }
    printf("load settled in %.2f s%s (%s)\n", took + took_wrap,
           wrapped ? " with its spiral wrap" : band ? " with its band" : "",
           settled ? "standing still" : "still moving");
    print_result(&r);
    ws_load_destroy(load);
    ws_world_destroy(w);
    return 0;
}
