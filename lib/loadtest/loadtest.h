/* The load-test module's own state: what a built load is and the reference its measurements are
 * taken from. The module works on the world through the public API only; it takes from world/
 * the one thing the public API cannot give, the last-error text (ws_fail). */
#ifndef WS_LOADTEST_INTERNAL_H
#define WS_LOADTEST_INTERNAL_H

#include <wrapsim/body.h>
#include <wrapsim/contact.h>
#include <wrapsim/loadtest.h>
#include <wrapsim/shape.h>

#include "base/base.h"

/* How much smaller (m, a side) the cartons of every second layer are than those of the first:
 * stacked faces are never equal (load.c, build_bodies). */
#define WS_LOAD_INSET 0.001

/* Levels of the load's bodies, bottom up: an interface joins two neighbouring levels. */
enum { WS_LEVEL_PLATFORM = 0, WS_LEVEL_PALLET = 1, WS_LEVEL_FIRST_LAYER = 2 };

/* Interface kinds, in the order of ws_load_get_point_stiffness(). */
enum { WS_IF_CARTON_CARTON = 0, WS_IF_CARTON_PALLET = 1, WS_IF_PALLET_PLATFORM = 2,
       WS_IF_FILM_CARTON = 3, WS_IF_KINDS = 4 };

/* A body id with where it sits in the load, sorted by id for lookups from contact reports. */
typedef struct ws_load_key {
    uint64_t bits;
    int level; /* WS_LEVEL_* or WS_LEVEL_FIRST_LAYER + layer */
    int body;  /* -2 platform, -1 pallet, else the carton's index */
} ws_load_key;

struct ws_load {
    ws_mem mem;
    const ws_world *world;
    ws_load_info info;
    ws_vec3 pallet_size;
    int layer_start[WS_LOAD_MAX_LAYERS + 1]; /* first carton of each layer; [layers] = count */
    int layer_nx[WS_LOAD_MAX_LAYERS];         /* cartons along x in each layer */
    ws_load_carton *carton;                   /* cartons, layer by layer */
    ws_vec3 *reference;                       /* each carton's CoG relative to the pallet, in
                                                 the platform's frame, at the reference */
    double *carton_bottom;                    /* height of its base above the deck, as built */
    ws_load_key *keys;                        /* platform, pallet, cartons; sorted by bits */
    size_t nkeys;
    double point_stiffness[WS_IF_KINDS];
    int points[WS_IF_KINDS];
    double friction[WS_IF_KINDS];
    double carton_mass;
    double contact_layer;
    ws_vec3 carton_shape; /* the carton's size in its own frame */
    double carton_cut;    /* its mesh is smaller by this along its own x and y (build_bodies),
                             and every second layer's by 2 WS_LOAD_INSET more */
    /* The film's rows when it is wrapped: nodes i + film_nx j, row j's around-springs
     * film_nx j .. film_nx j + film_nx - 1 (a closed band's numbering); 0 when unwrapped. */
    int film_nx, film_ny;
    int film_spiral; /* 1 when the film is ws_load_wrap_spiral's (a mesh web) */
};

/* ---- the measurements of a test run (record.c), shared by every test ---------------------- */

/* Where a run's figures go: the fields of the caller's result. */
typedef struct ws_lt_sink {
    double *peak_level;
    double *layer_max, *layer_tilt;                  /* [layers] */
    double *interface_slip_max, *interface_use_max;  /* [layers + 1] */
    int *cartons_lost, *event_count, *events_dropped;
    ws_loadtest_event *events;                       /* [WS_LOADTEST_MAX_EVENTS] */
    double *film_peak_strain;
} ws_lt_sink;

/* Four quarters of a base: a contact more than a quarter of the half-size off the centre along
 * x or y counts for that edge. */
enum { WS_LT_BIN_XP, WS_LT_BIN_XN, WS_LT_BIN_YP, WS_LT_BIN_YN, WS_LT_BINS };

/* A run's measuring state: buffers, the events found so far, the latest sample. */
typedef struct ws_lt_run {
    ws_load *ld;
    ws_lt_sink sink;
    const char *name;     /* of the test, for error messages */
    ws_vec3 dir;          /* the drive's direction in the platform's frame (layer means) */
    double slip_speed;    /* m/s: slip onset */
    double tip_fraction;  /* an edge below this share of its body's support has unloaded */
    int (*on_sample)(void *user, const ws_loadtest_sample *sample);
    void *sample_user;
    ws_contact_info *contacts;
    size_t contacts_cap;
    ws_load_carton_state *cs;
    double (*bins)[WS_LT_BINS];     /* per body (pallet = 0, carton c = c + 1): support by edge */
    double (*ref_bins)[WS_LT_BINS]; /* the same at the first sample */
    unsigned char *tipped, *lost;
    int have_ref_bins;
    int slipped[WS_LOAD_MAX_LAYERS + 1];
    double layer_disp[WS_LOAD_MAX_LAYERS];
    ws_loadtest_interface_state ifs[WS_LOAD_MAX_LAYERS + 1];
    double ifs_use[WS_LOAD_MAX_LAYERS + 1];
    ws_loadtest_interface_state *base; /* per carton: the contacts under it */
    double *base_use;
    /* The film (wrapped loads): its broken springs at the last sample, and whether the event
     * of its first break in the run is out; a film broken before the run (broken at the start)
     * reports the next break at the sample that sees it. */
    uint32_t broken, broken_at_start;
    int ruptured;
} ws_lt_run;

/* Set up a run's measurements (buffers from the load's allocator); `sink` says where the maxima
 * and events go (zeroed by the caller). WS_ERR_OUT_OF_MEMORY with the message set. */
ws_status ws_lt_begin(ws_world *w, ws_lt_run *run, ws_load *ld, const ws_lt_sink *sink,
                      const char *name);
/* Free what ws_lt_begin took. */
void ws_lt_end(ws_lt_run *run);
/* One measurement at run time t (s): cartons, layers, interfaces, events, running maxima, the
 * sample callback. `level` is the drive's level (a / g, or tan theta on a tilt), v and x the
 * platform's velocity and position along the drive, angle the tilt's (0 for the others). */
ws_status ws_lt_sample(ws_world *w, ws_lt_run *run, double t, double level, double v, double x,
                       double angle);
/* Append an event (counted as dropped past WS_LOADTEST_MAX_EVENTS). */
void ws_lt_event(const ws_lt_sink *sink, int type, int layer, int index, double t, double level,
                 double value);
/* A criterion: pass when value <= limit (value < limit when strict). */
void ws_lt_criterion(ws_loadtest_criterion *c, double value, double limit, int strict);
/* From the latest sample (the permanent state after a rest): per layer the largest horizontal
 * carton displacement (fmax into layer_permanent[], may be NULL), the largest of a carton whose
 * base is within 0.2 m above the deck (*bottom) and the largest shift of a layer's mean relative
 * to the layer under it (*shift). */
void ws_lt_permanent(const ws_lt_run *run, double *layer_permanent, double *bottom,
                     double *shift);

/* The key of a body id, or NULL when it is not part of the load. */
const ws_load_key *ws_load_find(const ws_load *load, ws_body_id id);
/* Platform rotation (body to global) and the pallet's CoG and velocity. */
ws_status ws_load_frame(const ws_world *w, const ws_load *load, ws_mat3 *a_platform,
                        ws_vec3 *r_pallet, ws_vec3 *v_pallet);

/* WS_OK, or WS_ERR_INVALID_ARGUMENT (no world, no load, a load of another world) naming fn. */
ws_status ws_load_check_world(const ws_world *w, const ws_load *ld, const char *fn);
/* The film's spring law: tension-compression, EA `ea` N per unit strain in tension, 1 % of it
 * in compression (film buckles), a trace of internal damping. */
ws_status ws_load_film_law(ws_world *w, double ea, const char *name, ws_law_id *out);
/* The fewest sub-steps with which the world's stable-step check accepts the web: dt / n within
 * stable_fraction of its stable sub-step; fn names the caller in the error. */
ws_status ws_load_fit_substeps(ws_world *w, ws_web_id web, const char *fn);
/* The containment a EUMOS result reports, three bands bottom up: the band generator's grid
 * read-out (ws_web_get_containment) for ws_load_wrap_band's film, the load's read-out
 * (ws_load_get_containment: hoop tension a row, force a metre of height) for a spiral's. */
ws_status ws_load_film_containment(const ws_world *w, const ws_load *ld, ws_containment_band *b);

#endif
