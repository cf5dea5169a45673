/* The world: owner of all pools, and the one orchestrator of a step. Reaches every module. */
#ifndef WS_WORLD_INTERNAL_H
#define WS_WORLD_INTERNAL_H

#include <wrapsim/wrapsim.h>

#include "base/base.h"
#include "base/pool.h"
#include "body/body.h"
#include "contact/contact.h"
#include "contact/node.h"
#include "drive/drive.h"
#include "element/element.h"
#include "law/law.h"
#include "math/wmath.h"
#include "shape/shape.h"
#include "web/web.h"

#define WS_ERR_LEN 512

/* Lanes a web's sweep is cut into per worker, at most: more lanes than workers let a worker
 * that runs while another waits for its core take more of them. */
#define WS_LANES_PER_WORKER 2

/* A lane of a parallel sweep of a web (world_step.c): copies of the web and its contact that
 * share their state, with the lane's own scratch (lane 0: the web's); the rows [r0, r1) it
 * sweeps and what it found. Lanes 1.. take the spring chunk (tmp, WS_WEB_TMP doubles) and the
 * list of touched nodes (fct) from the world's arena for each web of a step, before the lanes
 * start; they keep the contact lists, run batch and run faces (own) from step to step. A
 * search of node candidates in pieces (world_step.c, search_lanes) uses the same jobs, before
 * the sweep: piece i searches with its scratch (geom, from the arena) into its list (found,
 * kept from step to step), marking the bodies near in its copy's cbody (from the arena). */
typedef struct ws_lane_job {
    ws_web view;
    ws_node_contact cview;
    uint32_t r0, r1;
    size_t fast; /* nodes too fast */
    uint64_t checks;
    double *tmp;
    uint32_t *fct;
    size_t *marks; /* where each row of a block starts in its loads (from the arena) */
    ws_node_contact own;
    ws_node_geom geom;
    ws_ncand_list found;
    uint64_t found_checks;
    int found_bad;  /* the piece ran out of room in found (or of memory) */
    int found_same; /* its nodes' candidates found are those the committed list holds */
} ws_lane_job;
/* Per material, the two lightest dynamic bodies (slots, UINT32_MAX for none) and a kinematic
 * body of it (scratch of ws_world_contact_limit). */
typedef struct ws_mat_mass {
    uint32_t light[2];
    uint32_t kinematic;
} ws_mat_mass;

/* The contact pair that sets the bodies' stable step: materials, bodies (b may be kinematic),
 * the pair's stiffness and damping as the bound counts them, the effective mass and the
 * stable step (INFINITY when no pair of bodies can touch). */
typedef struct ws_contact_limit {
    double dt, k, c, m_eff;
    uint32_t mat_a, mat_b, body_a, body_b;
} ws_contact_limit;

/* Simultaneous contacts the bodies' stable-step bound assumes on one body (docs/theory.md). */
#define WS_CONTACTS_PER_BODY 8.0
/* The contacts now acting are measured against dt (their highest mode, by this many power
 * iterations) once dt passes this fraction of the per-pair bound: below it a mode would need
 * omega^2 16 times the pair's, more than solid boxes touching on two faces can have
 * (docs/theory.md, section 8), and the measure is skipped. */
#define WS_CONTACT_CHECK_FRACTION 0.25
#define WS_CONTACT_RATE_ITERATIONS 40
/* The measured bound is kept this many steps (the contacts of a load change little in 16 ms
 * at dt 0.25 ms, and the energy guard stands behind every step), or until the contacts grow by
 * a quarter, the per-pair bound changes or the world is restored: measured every step, 80
 * power iterations over a 33-body load cost more than the step itself. */
#define WS_CONTACT_CHECK_EVERY 64

/* The regularised friction's explicit limit counts where it holds this many measures in a row
 * (WS_CONTACT_CHECK_EVERY steps apart: 0.26 s at dt 0.25 ms): a stack dropped onto a plane
 * passes it for single measures as it bounces, with no harm; the clamped wrapped stacks of
 * the reference cases stay past it (docs/theory.md, section 8). */
#define WS_FRICTION_HELD 16

/* The contacts' measured stable step (world_step.c, contacts_ready) and when it was taken. */
typedef struct ws_contact_check {
    int valid;
    uint64_t step;  /* w->steps when measured */
    size_t nrec;    /* contacts then */
    double pair_dt; /* the per-pair bound then */
    double stable;  /* s; 0: no bound (no contact pushed) */
    double omega, rate;
} ws_contact_check;
/* The energy guard's allowance: a step's kinetic energy may grow by the known loads' work plus
 * this multiple of the kinetic and contact energy at its start (docs/theory.md, section 8). */
#define WS_ENERGY_GROWTH_FACTOR 10.0

struct ws_world {
    ws_mem mem;
    ws_arena arena; /* a step's scratch, given back when the next step starts */
    ws_world_def def;
    double time;
    uint64_t steps;
    uint64_t last_full_step;
    int cand_valid; /* 0 forces a full detection on the next step */
    ws_contact_check contact_check; /* not state: measured again after a restore */
    /* The regularised friction's explicit limit (world_step.c, friction_check): when it was
     * last measured (steps + 1; 0 never), the last WS_FRICTION_HELD measures (a ring, `nuse`
     * of them taken), and whether the log hook has heard it is passed. */
    uint64_t friction_step;
    v3 *friction_scratch; /* its power iteration's vectors, 4 (slots + 1); kept, so that a
                             steady run's measures take nothing from the allocator */
    size_t friction_cap;
    double friction_uses[WS_FRICTION_HELD];
    uint64_t nuse;
    int friction_warned;
    double travel;  /* bound on how far any body point moved since the last full detection, m */
    int cur;        /* committed buffer: bodies, candidates, contact records */
    int in_step;    /* 1 while ws_world_step runs: its callbacks may only read */
    char err[WS_ERR_LEN];

    ws_body_store bodies;
    ws_slot_table body_slots;

    ws_shape **shapes;
    size_t shape_cap;
    ws_slot_table shape_slots;

    char **mat_name;
    size_t mat_cap;
    ws_slot_table mat_slots;
    ws_pair_params *params; /* [0] is the default */
    size_t nparams, params_cap;
    uint32_t *pair_index; /* dim x dim, indices into params */
    size_t pair_dim;
    ws_mat_mass *mat_mass; /* pair_dim entries: scratch of the contact stable step */

    ws_law **laws;
    size_t law_cap;
    ws_slot_table law_slots;

    ws_web **webs;
    size_t web_cap;
    ws_slot_table web_slots;
    int web_check; /* 1: re-check the webs' stable step before the next step */
    ws_node_params *node_par; /* node contact parameters by body material, scratch */
    ws_node_geom node_geom;   /* bodies' faces in the global frame, scratch */
    ws_pool *pool;            /* the world's own threads (worker_count > 1, no host scheduler) */
    struct ws_lane_job *lane_job; /* a parallel sweep's lanes, WS_LANES_PER_WORKER a worker */
    const struct ws_web *cut_web; /* the web whose lanes' cut lane_job holds, made at step */
    uint64_t cut_step;            /* cut_step (world_step.c, lanes_cut) */
    int search_tight;       /* tests: the pieces of a search start with room for 8 candidates */
    uint64_t search_reruns; /* pieces of a search searched again, their room run out */
    int narrow_tight;       /* tests: a narrow phase beside the film has room for 2 candidates */
    uint64_t narrow_reruns; /* narrow phases beside the film run again, their room run out */
    size_t node_par_cap;

    ws_element **elements; /* by id slot (world_element.c) */
    size_t element_cap;
    ws_slot_table element_slots;

    ws_cand *cand[2];
    size_t ncand[2], capcand[2];
    ws_contact_rec *rec[2];
    size_t nrec[2], caprec[2];

    ws_world_stats stats;
};

/* What the phases of one step share (world_step.c, world_implicit.c), in place of long lists
 * of arguments: the world and its bodies, the committed buffer cur and the one written (nxt),
 * the time at the start and the step, the contact evaluation's context (bodies, margin, the
 * pairs' parameters; it counts the narrow checks), the statistics, the arena every phase takes
 * its scratch from, and what the phases hand on: whether this is a full detection, the body
 * pairs it found, the contacts' loads on each body before the elements and the film (for the
 * energy guard), the contact records written. A web's sub-step is in the lanes' task
 * (world_step.c), whose node contacts' part (ws_node_pass) contact/ reads. */
typedef struct ws_step {
    ws_world *w;
    ws_body_store *b;
    int cur, nxt;
    double t, dt;
    ws_contact_ctx contact;
    ws_world_stats *stats;
    ws_arena *arena;
    int full;
    uint32_t *pairs; /* 2 npairs body slots (arena) */
    size_t npairs;
    v3 *guard_f, *guard_m; /* by body slot (arena) */
    size_t nrec;
    /* The body contacts measured in pieces beside a web's lanes (world_step.c,
     * contacts_piece): a record and a state a candidate, the checks of each piece (arena). */
    struct ws_contact_rec *mrec;
    uint8_t *mstate;
    uint64_t *mchecks;
    uint32_t mpieces;
    double pair_dt; /* the bodies' per-pair stable step (ws_world_contact_limit), s */
    /* The body contacts still to run (in the film's first sub-step in lanes, or after it),
     * and the webs' loads to add after the elements' (world_step.c, step_once). */
    int body_later, loads_later;
    /* A full detection's narrow phase still to run, before the body contacts and beside the
     * film like them (the broad phase's pairs found); and whether it ran out of the room
     * reserved for it there (then it runs again on the calling thread). */
    int narrow_later, narrow_bad;
    /* By contact record: its friction taken into a solve this step, WS_FRICTION_TAKEN, and
     * WS_FRICTION_TURNED once its slope along the slip turned to the secant (world_friction.c;
     * NULL before any is; 0: not taken). */
    uint8_t *friction_taken;
} ws_step;

/* Record an error (and log it) and return the status. The world may be const for callers that
 * only read: the error text is the one field such calls write. */
ws_status ws_fail(const ws_world *w, ws_status s, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
void ws_log(const ws_world *w, ws_log_level level, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Argument guards of the public calls: a NULL world has no last error, a NULL output does. */
#define NEED_WORLD(w)                                                                             \
    do {                                                                                          \
        if (!(w))                                                                                 \
            return WS_ERR_INVALID_ARGUMENT;                                                       \
    } while (0)
#define NEED_OUT(w, p, fn)                                                                        \
    do {                                                                                          \
        if (!(p))                                                                                 \
            return ws_fail((w), WS_ERR_INVALID_ARGUMENT, "%s: output pointer is NULL", fn);       \
    } while (0)

/* Calls that change the world are refused from inside a step (from a drive, law or log
 * callback); getters stay allowed, they read the committed state, which a step leaves alone. */
#define NOT_IN_STEP(w, fn)                                                                        \
    do {                                                                                          \
        if ((w)->in_step)                                                                         \
            return ws_fail((w), WS_ERR_IN_STEP,                                                   \
                           "%s called from inside ws_world_step (a callback); a callback may "    \
                           "only read the world",                                                 \
                           fn);                                                                   \
    } while (0)

ws_status ws_lookup_body(const ws_world *w, ws_body_id id, uint32_t *slot);
ws_status ws_lookup_shape(const ws_world *w, ws_shape_id id, uint32_t *slot);
ws_status ws_lookup_material(const ws_world *w, ws_material_id id, uint32_t *slot);
ws_status ws_lookup_law(const ws_world *w, ws_law_id id, uint32_t *slot);
ws_status ws_lookup_web(const ws_world *w, ws_web_id id, uint32_t *slot);
/* Generic id lookup for a slot table (kind: WS_KIND_*). */
ws_status ws_lookup_slot(const ws_world *w, uint64_t bits, unsigned kind, const ws_slot_table *t,
                         const char *what, uint32_t *slot);
/* Free the webs and then the laws of a world (world destroy; webs first, they use laws). */
void ws_world_free_webs(ws_world *w);
void ws_world_free_laws(ws_world *w);
/* Take a slot of a table whose objects live in a pointer array, growing the array; the entry is
 * NULL. 0, or -1 when out of memory. */
int ws_world_take_slot(ws_world *w, ws_slot_table *t, void ***arr, size_t *cap, uint32_t *slot);
/* Free the scratch of the lanes of parallel sweeps (world_step.c). */
void ws_world_lanes_free(ws_world *w);
/* Node contact parameters of a web's material against every body material (into w->nparams). */
int ws_world_node_params(ws_world *w, uint32_t web_material);
/* An implicit web's step (world_implicit.c): its sub-steps from state S->cur into S->nxt, the node
 * contacts of candidate list `list` in the matrix, the loads on the bodies into web->bforce[nxt]
 * and web->bmoment[nxt] and the bodies' accumulators. WS_ERR_NUMERICAL when a solve does not
 * converge or a node runs away, WS_ERR_CALLBACK when a law fails, WS_ERR_OUT_OF_MEMORY; the
 * committed state is not written. */
ws_status ws_world_web_implicit(ws_step *S, ws_web *web, int list);

/* The step's workers as a module below the world runs a task on them (base/pool.h): the
 * world's threads or the host's scheduler; one worker, the caller, when worker_count is 1. */
ws_runner ws_world_runner(ws_world *w);
/* The bodies' regularised friction at the end of the step (world_friction.c): every contact of
 * it no web's solve took, solved over the bodies at once, its change over the step added to
 * the bodies' loads and the records. Before the integration, all loads known. */
ws_status ws_world_friction_step(ws_step *S);
/* The body contacts whose friction goes into a solve with the bodies slot (UINT32_MAX: not in
 * it; a contact with a dynamic body outside stays out) for step h: each its eq. 13 linearised
 * about the slip at the start, h C with C = mu N phi across the slip (the secant) and
 * mu N p'(s) / v_lim along it (the law's slope, ws_friction_slope), into R->pair (from the
 * step's arena), and marked taken. 0, or -1 when out of memory. */
enum { WS_FRICTION_TAKEN = 1, WS_FRICTION_TURNED = 2 };
struct ws_rigid;
int ws_world_friction_pairs(ws_step *S, struct ws_rigid *R, const uint32_t *slot, double h);
/* After a solve R->x: the pairs whose slip the step reverses (its end slip against its start),
 * their slope along the slip turned to the secant (the law's line through zero: the friction
 * at most stops the slip), for the next solve. How many turned. */
size_t ws_world_friction_turned(ws_step *S, struct ws_rigid *R, double h);
/* The pairs' friction over the solved step R->x, -C (J_b dU_b - J_a dU_a) / h on body b and the
 * opposite on a, added to their loads (and the guard's record of contact loads) and to the
 * contact's record: its friction at the end of the step, as the bodies take it. */
void ws_world_friction_loads(ws_step *S, const struct ws_rigid *R, double h);
/* The mass and global inertia A J A^T (symmetric, WS_SYM doubles) of each body of a solve
 * (slot: its index in R, UINT32_MAX for the others) into R->mass and R->inertia. */
void ws_world_rigid_bodies(struct ws_rigid *R, const ws_body_store *b, const uint32_t *slot);
/* The stable sub-step of a web with the stiffest contact its material can have. */
double ws_world_web_stable_dt(ws_world *w, const ws_web *web);
/* The smallest node mass (kg) that makes the web stable at sub-step h by the same bound. */
double ws_world_web_mass_for(ws_world *w, const ws_web *web, double h);
ws_body_id ws_make_body_id(const ws_world *w, uint32_t slot);

/* The two exported inits of a Def type `type` (ws_x_def) whose defaults `defaults` writes:
 * ws_x_def_init_sized(def, size), which the header's ws_x_def_init(def) macro calls with the
 * caller's sizeof, and the plain function ws_x_def_init(def) for programs built against headers
 * before the sized form. Those headers' Defs ended at `v0_last`, so the plain one fills up to
 * there and never past the end of such a caller's Def. */
#define WS_DEF_INITS(type, defaults, v0_last)                                                    \
    void type##_init_sized(type *def, size_t size)                                                \
    {                                                                                             \
        type full;                                                                                \
        defaults(&full);                                                                          \
        ws_def_fill(def, size, &full, sizeof full);                                               \
    }                                                                                             \
    void(type##_init)(type * def) { type##_init_sized(def, WS_DEF_END(type, v0_last)); }

/* Copy a caller's Def (of the size it says) over a default one; WS_ERR_UNINITIALIZED_DEF or
 * WS_ERR_INVALID_ARGUMENT (NULL) with the message set. */
ws_status ws_def_take(const ws_world *w, void *dst, size_t full, const void *src, const char *what);

/* Body bookkeeping after a change of the committed state outside a step. */
void ws_world_refresh_body(ws_world *w, uint32_t slot);
/* Drop cached candidates that refer to a body slot (before the slot is reused). */
void ws_world_forget_body(ws_world *w, uint32_t slot);
/* Largest stable dt for the current bodies and parameters (see ws_world_estimate_stable_dt). */
double ws_world_stable_dt(const ws_world *w);
/* The bodies' contact pair with the smallest stable step (world.c). */
void ws_world_contact_limit(const ws_world *w, ws_contact_limit *lim);
/* The stable step of a mass m_eff on WS_CONTACTS_PER_BODY contacts of stiffness k, damping c. */
double ws_contact_stable_dt(double k, double c, double m_eff);

/* Elements (world_element.c). In a step: the loads of every element at state `cur` and time t
 * into the bodies' accumulators, each element's strain kept for the commit (nothing committed
 * changes; WS_ERR_CALLBACK or WS_ERR_NUMERICAL when a law fails); after an accepted step, their
 * law histories committed at t. */
ws_status ws_world_element_forces(ws_world *w, int cur, double t);
void ws_world_commit_elements(ws_world *w, double t);
/* Free every element (world destroy; before the laws and bodies they use). */
void ws_world_free_elements(ws_world *w);
/* WS_OK when no element uses body `slot`, else WS_ERR_IN_USE with the message set. */
ws_status ws_world_body_free_of_elements(const ws_world *w, uint32_t slot);
/* The elements' explicit step limit on the bodies they join (INFINITY without elements). */
double ws_world_element_stable_dt(const ws_world *w);

/* One walk over every piece of the world's state that its future depends on
 * (world_state.c): HASH feeds the hashed part of it to an FNV-1a hash (ws_world_get_state_hash);
 * WRITE puts it into `out` as little-endian bytes (only counts them, in pos, when out is NULL);
 * CHECK reads `in` (len bytes) and checks every count and index against the world, changing no
 * state (it only grows arrays for READ, WS_ERR_OUT_OF_MEMORY when it cannot); READ, after a
 * CHECK that passed, writes it into the world. WS_ERR_FORMAT (or WS_ERR_OUT_OF_MEMORY) with
 * the last error set when a CHECK fails. */
typedef enum ws_walk_mode { WS_WALK_HASH, WS_WALK_WRITE, WS_WALK_CHECK, WS_WALK_READ } ws_walk_mode;
typedef struct ws_walk {
    ws_walk_mode mode;
    uint64_t hash;           /* HASH: start with WS_HASH_SEED */
    unsigned char *out;      /* WRITE */
    const unsigned char *in; /* CHECK, READ */
    size_t pos, len;         /* bytes walked; bytes in `in` */
    ws_status status;
    ws_world *w;
    uint32_t version; /* CHECK, READ: the save format of `in`; 0: WS_SAVE_FORMAT_VERSION */
} ws_walk;
ws_status ws_world_walk(ws_world *w, ws_walk *k);

#endif
