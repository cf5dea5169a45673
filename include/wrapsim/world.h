/**
 * @file world.h
 * @brief The world: owner of every shape, body and material; its parameters; the step.
 */
#ifndef WRAPSIM_WORLD_H
#define WRAPSIM_WORLD_H

#include <wrapsim/common.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Opaque world. One world belongs to one thread at a time; different worlds are independent. */
typedef struct ws_world ws_world;

/** Time integrators. */
typedef enum ws_integrator {
    /** Symplectic Euler: the forces kick the momenta (v += a dt, H += M dt), then the bodies
     *  drift with the new momenta: x += v dt, and the free rigid rotor split symmetrically into
     *  exact rotations about the principal axes. Angular momentum is kept to round-off and the
     *  energy error stays bounded when no moment acts. The default. */
    WS_INTEGRATOR_SYMPLECTIC_EULER = 0,
    /** The paper's explicit scheme (eq. 8-11): x += v dt + a dt^2/2, v += a dt, omega' += dt J^-1
     *  (M' - omega' x J omega'), p += dt L^T omega' / 2, p renormalised. For reproducing it. */
    WS_INTEGRATOR_PAPER_EXPLICIT = 1
} ws_integrator;

/** How a step takes the bodies' regularised friction (WS_FRICTION_REGULARIZED contacts). */
typedef enum ws_friction_step {
    /** Linearly implicit (the default): the friction at the end of the step, linearised about
     *  its start (eq. 13 and its slopes), solved over all bodies at once, so it holds bodies
     *  still at any dt, however hard they are clamped together (docs/theory.md, section 5). */
    WS_FRICTION_STEP_IMPLICIT = 0,
    /** Explicit, as the paper: the friction at the start of the step. Stable only while dt
     *  lambda <= 2 (ws_world_stats.friction_step_use), beyond which clamped bodies slip back
     *  and forth every step and a load creeps faster than the law allows. */
    WS_FRICTION_STEP_EXPLICIT = 1
} ws_friction_step;

/** A piece of a step's work given to the host's scheduler: items [start, end) of it, on worker
 *  `worker` (< ws_world_def.worker_count, distinct among pieces that run at once), with the
 *  task's own context. */
typedef void ws_task_fn(int32_t start, int32_t end, uint32_t worker, void *task_context);
/** The host's scheduler takes a task of `item_count` items (0 .. item_count - 1), to be cut
 *  into ranges of at least `min_range` items and run, each range once, on its workers, in any
 *  order, at once or one after another. Returns a handle that ws_finish_task_fn receives, or
 *  NULL when it ran the whole task before returning (then it is not finished). `user_context`
 *  is ws_world_def.task_context. */
typedef void *ws_enqueue_task_fn(ws_task_fn *task, int32_t item_count, int32_t min_range,
                                 void *task_context, void *user_context);
/** Wait until every range of the task `user_task` (an ws_enqueue_task_fn's handle) has run. */
typedef void ws_finish_task_fn(void *user_task, void *user_context);

/** World parameters. Fill with ws_world_def_init(), then change what you need. */
typedef struct ws_world_def {
    uint32_t size;  /**< set by ws_world_def_init(); do not change */
    uint32_t magic; /**< set by ws_world_def_init(); do not change */
    ws_vec3 gravity;           /**< m/s^2; default (0, 0, -9.81) */
    double dt;                 /**< time step, s; default 2.5e-4 */
    ws_integrator integrator;  /**< default WS_INTEGRATOR_SYMPLECTIC_EULER */
    /** Full contact detection every step while t < this time (s); default 0. */
    double full_detection_until;
    /** Afterwards, full detection every Nth step (>= 1); the cached candidate pairs are
     *  re-checked on the steps between. Default 1 (every step). */
    int detection_interval;
    /** Extra distance (m) beyond the contact layers within which feature pairs are kept as
     *  candidates between full detections. Must exceed how far bodies move relative to each other
     *  in detection_interval steps. Default 2e-3. */
    double contact_margin;
    /** Runaway guard: a dynamic body faster than this (m/s) fails the step. Default 1000. */
    double max_speed;
    /** Runaway guard for angular speed (rad/s). Default 1e5. */
    double max_angular_speed;
    /** Use the libccd gate when built in (1, default) or not (0). Results are the same. */
    int use_ccd;
    /** 1: time the phases of each step (wall clock, see ws_world_stats); 0 (default): not. */
    int profile;
    ws_allocator allocator; /**< memory hooks; default malloc/realloc/free */
    ws_log_fn log;          /**< optional log hook; NULL for none */
    void *log_user;         /**< passed to log */
    void *user_data;        /**< yours; see ws_world_get_user_data() */
    /** Safety factor of the film's stable-step check: a web runs only while dt / substeps <=
     *  stable_fraction x its stable sub-step (ws_web_get_stable_dt), the bound's margin against
     *  what it does not see (a film crumpling, nodes sliding off edges, laws stiffer than they
     *  state). 0 < it <= 1; default 0.5 (docs/theory.md, section 8). */
    double stable_fraction;
    /** Workers a step may use, 1 (default) to WS_MAX_WORKERS. With more than one the film is
     *  stepped in parallel; the results are the same to the bit for any count. */
    uint32_t worker_count;
    /** The host's scheduler (both, or neither: NULL, the default). Without them and with
     *  worker_count > 1 the world runs its own worker_count - 1 threads, made with it and
     *  joined when it is destroyed. With them, the world makes no thread. */
    ws_enqueue_task_fn *enqueue_task;
    ws_finish_task_fn *finish_task; /**< see enqueue_task */
    void *task_context;             /**< passed to enqueue_task and finish_task */
    /** How the bodies' regularised friction is stepped; default WS_FRICTION_STEP_IMPLICIT. */
    ws_friction_step friction_step;
} ws_world_def;

/** The most workers a world takes. */
#define WS_MAX_WORKERS 64

/** Friction laws for a pair of materials. */
typedef enum ws_friction_model {
    /** Coulomb with the paper's regularisation (eq. 13): F = mu N p(v/v_lim), p(s) = 2s - s^2
     *  below v_lim, 1 above. Creeps at a few mm/s under a static tangential load. */
    WS_FRICTION_REGULARIZED = 0,
    /** Stick model: a tangential spring anchored where the contact began, its force capped at
     *  mu N; the anchor slides when the cap is reached. No creep below tan(theta) = mu. */
    WS_FRICTION_STICK = 1
} ws_friction_model;

/** Contact parameters of a pair of materials. Fill with ws_contact_def_init(). */
typedef struct ws_contact_def {
    uint32_t size;  /**< set by ws_contact_def_init() */
    uint32_t magic; /**< set by ws_contact_def_init() */
    double stiffness;     /**< normal penalty stiffness, N/m per contact point; default 2e5 */
    double damping;       /**< normal damping, N s/m (kg/s) per contact point; default 10 */
    double friction;      /**< Coulomb coefficient mu (>= 0); default 0.3 */
    double friction_vlim; /**< regularisation speed v_lim, m/s (> 0); default 0.01 */
    ws_friction_model friction_model; /**< default WS_FRICTION_REGULARIZED */
    double stick_stiffness; /**< tangential spring of the stick model, N/m; default 2e5 */
    /** Tangential damping of the stick model, kg/s per contact point, when > 0 (releases
     *  up to 0.1.0 defaulted to 10, about 1 % of critical for 5 kg boxes: set 10 to reproduce
     *  them). Default 0: from stick_damping_ratio. */
    double stick_damping;
    /** With stick_damping 0: the tangential damping as a fraction of critical for the pair,
     *  c = ratio sqrt(stick_stiffness m), m = m_a m_b / (m_a + m_b) of the two bodies (the
     *  dynamic one's mass against a kinematic body): critical for one of the 4 corner contacts
     *  of a box face carrying a quarter of m is 2 sqrt(k m / 4). Default 1 (critical for a box
     *  swaying on its 4 corners); >= 0, <= 10. */
    double stick_damping_ratio;
} ws_contact_def;

/** A material: only a name for now; contact parameters belong to pairs of materials. */
typedef struct ws_material_def {
    uint32_t size;  /**< set by ws_material_def_init() */
    uint32_t magic; /**< set by ws_material_def_init() */
    const char *name; /**< optional, copied; NULL for none */
} ws_material_def;

/** Counters and figures of a world. Filled by ws_world_get_stats(). */
typedef struct ws_world_stats {
    double time;               /**< simulated time, s */
    uint64_t steps;            /**< steps taken */
    uint64_t full_detections;  /**< steps with full contact detection */
    uint64_t narrow_checks;    /**< feature-pair tests (point-face, edge-edge), in all; a
                                    candidate still apart by its clearance is not tested */
    uint64_t body_pairs_tested; /**< body pairs that reached the narrow phase, in all */
    uint64_t body_pairs_gated; /**< body pairs the libccd gate skipped, in all */
    uint64_t contacts;         /**< contacts active after the last step */
    uint64_t candidates;       /**< cached candidate feature pairs after the last step */
    uint64_t numerical_errors; /**< steps refused with WS_ERR_NUMERICAL */
    uint64_t bytes_in_use;     /**< bytes allocated through the allocator, now */
    uint64_t bytes_peak;       /**< most bytes in use at once */
    uint64_t bodies;           /**< bodies alive */
    /* With ws_world_def.profile = 1, wall-clock seconds spent in, over all steps: */
    double seconds_detection;  /**< finding candidate pairs (bodies and film nodes) */
    /** evaluating body-body contacts (with worker_count > 1 and only explicit webs they are
     *  evaluated beside the film's first sub-step, and that part counts in seconds_web) */
    double seconds_contacts;
    double seconds_web;        /**< film: springs, node contacts, node integration */
    double seconds_total;      /**< whole steps */
    /** The largest fraction of an explicit web's stable sub-step that dt / substeps uses (0
     *  without explicit webs); such a web runs while it is <= ws_world_def.stable_fraction.
     *  Implicit webs have no such limit and are not counted. */
    double web_step_use;
    /** dt as a fraction of the bodies' contact stable step (ws_world_estimate_stable_dt without
     *  the elements; 0 when no two bodies can touch); refused above 1. */
    double body_step_use;
    /** With ws_world_def.friction_step = WS_FRICTION_STEP_EXPLICIT (0 otherwise: taken at the
     *  end of the step the friction has no such limit), dt as a fraction of the regularised
     *  friction's explicit limit 2 / lambda, held: the
     *  largest value that 16 measures in a row all passed since the world was made (lambda:
     *  the highest rate of the bodies' contacts' friction below v_lim as dampers, slope
     *  2 mu F_n / v_lim, on the bodies' masses; measured every 64 steps while contacts act;
     *  0 before 16 measures). Above 1 the bodies' contacts slip back and forth every step and
     *  a load creeps faster than the law allows (docs/theory.md, section 8); the step is not
     *  refused, the log hook hears it once (WS_LOG_WARNING). Use a smaller dt,
     *  WS_FRICTION_STEP_IMPLICIT or WS_FRICTION_STICK. */
    double friction_step_use;
    uint64_t reserved[1];      /**< zero; room to grow */
} ws_world_stats;

/** Mechanical energy of the dynamic bodies, J. */
typedef struct ws_energy {
    double kinetic;       /**< translational + rotational */
    double potential;     /**< gravity, -m g . r summed (zero at the origin) */
    double contact;       /**< elastic energy stored in the penalty springs, k overlap^2 / 2 */
} ws_energy;

/** Fill a world Def with defaults. `def` must not be NULL.
 *  ws_world_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_world_def_init_sized(ws_world_def *def, size_t size);
/** The plain form, for programs built against headers before ws_world_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_world_def_init)(ws_world_def *def);
#define ws_world_def_init(def) ws_world_def_init_sized((def), sizeof *(def))
/** Fill a contact Def with defaults.
 *  ws_contact_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_contact_def_init_sized(ws_contact_def *def, size_t size);
/** The plain form, for programs built against headers before ws_contact_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_contact_def_init)(ws_contact_def *def);
#define ws_contact_def_init(def) ws_contact_def_init_sized((def), sizeof *(def))
/** Fill a material Def with defaults.
 *  ws_material_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_material_def_init_sized(ws_material_def *def, size_t size);
/** The plain form, for programs built against headers before ws_material_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_material_def_init)(ws_material_def *def);
#define ws_material_def_init(def) ws_material_def_init_sized((def), sizeof *(def))

/** Create a world. On error *out is NULL.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, dt <= 0, NaN...), WS_ERR_UNINITIALIZED_DEF,
 *          WS_ERR_OUT_OF_MEMORY. Without a world there is no last error: see the status. */
WS_API ws_status ws_world_create(const ws_world_def *def, ws_world **out);
/** Destroy a world and everything in it. NULL is allowed and does nothing. Called from a
 *  callback inside ws_world_step it does nothing but set the last error (WS_ERR_IN_STEP). */
WS_API void ws_world_destroy(ws_world *world);

/** Advance one step dt. On WS_ERR_NUMERICAL (or a callback error) the world is left exactly as it
 *  was before the call and ws_world_last_error() says which body and what to change.
 *  WS_ERR_NUMERICAL: a dt above the bodies' contact stable step (refused before the step), or
 *  above the stable step of the contacts acting in this step (bodies stacked on several
 *  partners rock faster than any one pair: measured once dt passes a quarter of the pair
 *  bound, docs/theory.md section 8; refused before the bodies move), a web's sub-step above its stable step, NaN or inf, a speed above max_speed, or runaway energy
 *  (the bodies' kinetic energy growing in a step by more than the loads' work plus ten times
 *  the kinetic and contact energy at its start).
 *  Callbacks run inside a step (drives, laws, the log hook) may read the world with any getter;
 *  every call that changes it (create, destroy, set, step) returns WS_ERR_IN_STEP there. */
WS_API ws_status ws_world_step(ws_world *world);
/** Take up to `steps` steps, stopping at the first error. */
WS_API ws_status ws_world_step_n(ws_world *world, int64_t steps);

/** Simulated time, s. */
WS_API ws_status ws_world_get_time(const ws_world *world, double *time);
/** Time step, s. */
WS_API ws_status ws_world_get_dt(const ws_world *world, double *dt);
/** The film's stable-step safety factor (ws_world_def.stable_fraction): a web runs while
 *  dt / substeps <= it x ws_web_get_stable_dt. */
WS_API ws_status ws_world_get_stable_fraction(const ws_world *world, double *fraction);
/** Change the time step (s, > 0) between steps. */
WS_API ws_status ws_world_set_dt(ws_world *world, double dt);
/** Gravity, m/s^2. */
WS_API ws_status ws_world_set_gravity(ws_world *world, const ws_vec3 *gravity);
/** Counters and figures. */
WS_API ws_status ws_world_get_stats(const ws_world *world, ws_world_stats *stats);
/** Energy of the dynamic bodies (contact energy from the last step's contacts). */
WS_API ws_status ws_world_get_energy(const ws_world *world, ws_energy *energy);
/** A 64-bit hash of the whole dynamic state (time, every body's pose and velocities, friction
 *  anchors, every film node's position and velocity, the law histories of the film's springs and
 *  of the elements): FNV-1a over the little-endian bytes of the state a save holds
 *  (ws_world_save), less the contact caches' bookkeeping, which a failed step may change. Equal
 *  hashes after equal inputs, on every machine: the determinism check. */
WS_API ws_status ws_world_get_state_hash(const ws_world *world, uint64_t *hash);
/** The detail of the last error in this world ("body 'top': mass must be > 0, got -1"); ""
 *  when there was none. Valid until the next call on the world. NULL world gives a static text. */
WS_API const char *ws_world_last_error(const ws_world *world);
/** The user pointer of the Def. */
WS_API void *ws_world_get_user_data(const ws_world *world);

/** Estimate the largest stable dt (s) for the bodies and contact pairs now in the world: the
 *  explicit limit 2/omega of each pair of materials that bodies have, on the lightest such
 *  pair's effective mass, counting 8 simultaneous contacts (see docs/theory.md), and of the
 *  deformable elements on the bodies they join (docs/elements.md). ws_world_step refuses a dt
 *  above the contact part of it (WS_ERR_NUMERICAL, naming the pair and the fix). It is an
 *  upper bound for stacks: bodies resting on one partner and carrying another rock faster
 *  (two stacked 5 kg cubes on a plane: 1.86 ms where this gives 2.45 ms), which ws_world_step
 *  measures from its contacts and refuses. Films are not counted here: each web has its own
 *  sub-step limit, ws_web_get_stable_dt(). */
WS_API ws_status ws_world_estimate_stable_dt(const ws_world *world, double *dt);

/** The material every body has unless its Def names another. */
WS_API ws_status ws_world_get_default_material(const ws_world *world, ws_material_id *out);
/** Create a material. */
WS_API ws_status ws_material_create(ws_world *world, const ws_material_def *def,
                                    ws_material_id *out);
/** 1 if the id names a live material of this world, else 0. */
WS_API int ws_material_is_valid(const ws_world *world, ws_material_id id);

/** Contact parameters between two materials (in either order). Pairs never set use the
 *  default set by ws_world_set_default_contact() (ws_contact_def_init() values at first). */
WS_API ws_status ws_world_set_contact(ws_world *world, ws_material_id a, ws_material_id b,
                                      const ws_contact_def *def);
/** Read the parameters that apply between two materials. `def` is filled whole. */
WS_API ws_status ws_world_get_contact(const ws_world *world, ws_material_id a, ws_material_id b,
                                      ws_contact_def *def);
/** Parameters for every pair not set explicitly. */
WS_API ws_status ws_world_set_default_contact(ws_world *world, const ws_contact_def *def);

#ifdef __cplusplus
}
#endif

#endif
