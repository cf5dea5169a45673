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
