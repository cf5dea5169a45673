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
};

/* The key of a body id, or NULL when it is not part of the load. */
const ws_load_key *ws_load_find(const ws_load *load, ws_body_id id);
/* Platform rotation (body to global) and the pallet's CoG and velocity. */
ws_status ws_load_frame(const ws_world *w, const ws_load *load, ws_mat3 *a_platform,
                        ws_vec3 *r_pallet, ws_vec3 *v_pallet);

#endif
