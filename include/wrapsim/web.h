/**
 * @file web.h
 * @brief The film: a web of point masses joined by springs, pre-stretched, touching the bodies.
 *
 * Nodes carry position and velocity only. Springs join grid neighbours (and optionally the
 * diagonals); each spring's force comes from a 1D law (law.h) of its strain eps = l/l0 - 1 and
 * strain rate, so a measured film curve can replace the linear one. Pre-stretch is set by the
 * rest lengths. Nodes touch bodies point-to-face (eq. 14) in their contact layer, with the
 * penalty and friction of the pair (web material, body material). A web may take several
 * sub-steps inside one world step so a film of its real mass runs stable.
 */
#ifndef WRAPSIM_WEB_H
#define WRAPSIM_WEB_H

#include <wrapsim/law.h>
#include <wrapsim/world.h>

#ifdef __cplusplus
extern "C" {
#endif

/** A web (film). */
typedef struct ws_web_id {
    uint64_t bits; /**< opaque; 0 = null */
} ws_web_id;

/** Which law a spring follows. */
typedef enum ws_spring_kind {
    WS_SPRING_AROUND = 0, /**< first grid direction (around a band, x of a sheet): `law` */
    WS_SPRING_UP = 1,     /**< second grid direction (up a band, y of a sheet): `law_cross` */
    WS_SPRING_SHEAR = 2   /**< diagonals: `law_shear` */
} ws_spring_kind;

/** How a web's nodes advance over a (sub-)step. */
typedef enum ws_web_integrator {
    /** Symplectic Euler: cheap per step, stable only below the web's stable step
     *  (ws_web_get_stable_dt), so a light or finely meshed film needs sub-steps. */
    WS_WEB_EXPLICIT = 0,
    /** Linearly implicit backward Euler (one Newton step, Baraff & Witkin 1998): the springs'
     *  and the node contacts' stiffness and damping in a linear system solved by conjugate
     *  gradients each step; stable at any step for the film's stiffness and mass
     *  (docs/theory.md, "The implicit film"). */
    WS_WEB_IMPLICIT = 1
} ws_web_integrator;

/** How an implicit web's linear solve is preconditioned (docs/theory.md, "The implicit film";
 *  the answers are the same to the solve's tolerance, only the cost differs). */
typedef enum ws_web_preconditioner {
    /** The cheaper of the two for the web: multigrid on a grid web (sheet or band, springs
     *  between grid neighbours) of at least WS_WEB_MULTIGRID_AUTO_NODES nodes, block Jacobi
     *  otherwise. */
    WS_WEB_PRECONDITIONER_AUTO = 0,
    /** Each node's 3x3 diagonal block: cheap an iteration, but the iterations grow with the
     *  nodes across the film and its stiffness over its mass (h^2 k / m). */
    WS_WEB_PRECONDITIONER_BLOCK_JACOBI = 1,
    /** A geometric multigrid V-cycle on the web's grid: dearer an iteration, iterations
     *  nearly independent of the refinement. Grid webs only (ws_web_create_* refuses it on
     *  another web with WS_ERR_INVALID_ARGUMENT). */
    WS_WEB_PRECONDITIONER_MULTIGRID = 2
} ws_web_preconditioner;

/** WS_WEB_PRECONDITIONER_AUTO takes multigrid from this many nodes of a grid web on: below it,
 *  block Jacobi's cheaper iterations win (bench/NOTES.md, "the crossing"). */
#define WS_WEB_MULTIGRID_AUTO_NODES 15000

/** What every web has. Fill with ws_web_def_init(). */
typedef struct ws_web_def {
    uint32_t size;  /**< set by ws_web_def_init() */
    uint32_t magic; /**< set by ws_web_def_init() */
    double node_mass;       /**< kg per node (> 0); 0 = from areal_density (grid webs) */
    double areal_density;   /**< kg/m^2 of unstretched film, used when node_mass is 0: a node
                                 gets the rest area it stands for; 0.018 for 20 um LLDPE */
    double contact_layer;   /**< delta of every node, m (>= 0); default 1e-3 */
    ws_material_id material; /**< node-body contact pairs; null id: the default material */
    double node_damping;    /**< drag on each node's absolute velocity, kg/s (>= 0); default 0 */
    ws_law_id law;          /**< law of WS_SPRING_AROUND springs; required */
    ws_law_id law_cross;    /**< law of WS_SPRING_UP springs; null id: `law` */
    ws_law_id law_shear;    /**< law of WS_SPRING_SHEAR springs; required when there are any */
    int substeps;           /**< web sub-steps per world step (>= 1); default 1 */
    const char *name;       /**< optional, copied; used in error messages */
    /** Rupture: the strain l/l0 - 1 past which a spring breaks (>= 0, finite; 0, the default:
     *  none), checked at the end of every step. A broken spring carries no force (neither
     *  spring nor damper) from then on, for good (ws_web_get_rupture). From a film's
     *  elongation at break e_b, measured from its unstretched length (LLDPE stretch film: 3 to
     *  5, i.e. 300-500 %), and the powered pre-stretch P that made the film the rest length l0
     *  is (l0 = (1 + P) x its unstretched length): (1 + e_b) / (1 + P) - 1, e.g. 0.43 for
     *  e_b = 4, P = 2.5; e_b itself when l0 is the unstretched film (P = 0). The strain the film
     *  is laid with on the load (a generator's pre-stretch) counts from l0 and so uses part
     *  of it. A trailing field: older callers get 0. */
    double rupture_strain;
    int integrator;         /**< ws_web_integrator; default WS_WEB_EXPLICIT */
    double solver_tolerance; /**< implicit webs: the linear solve stops when every row's
                                  residual (a momentum, N s) is at most this fraction of its
                                  own weight over the step, m g h (g = 9.81 m/s^2 whatever
                                  the world's gravity): each node's with its mass m_i, each
                                  body in the solve's with its mass m_j, a body's turning
                                  rows as the speed, rms over its mass, of the spin change
                                  they would give it. Equivalently, the velocity change each
                                  row's residual would give its own mass is at most this
                                  times g h; the solve's velocities are then within this
                                  times g h of the exact ones, rms over the film's and the
                                  bodies' mass (docs/theory.md, section 8). (0, 0.1];
                                  default 1e-3. Earlier versions bounded the residual's
                                  norm by the right-hand side's (default 1e-6) */
    int solver_max_iterations; /**< implicit webs: conjugate-gradient iterations at most per
                                    solve (1..100000); default 1000. A solve that does not
                                    converge fails the step with WS_ERR_NUMERICAL */
    int preconditioner;     /**< implicit webs: ws_web_preconditioner; default
                                 WS_WEB_PRECONDITIONER_AUTO. A trailing field: older callers
                                 get AUTO */
    /** Implicit webs: how the dynamic bodies the film touches take part in its solve. 0, the
     *  default: their velocities are unknowns of the film's linear system beside the nodes',
     *  so the film's loads on them are those of the end of the step (docs/theory.md, section
     *  8b). 1: they are held at their state at t during the solve and take its loads as
     *  given forces (an explicit coupling, as for an explicit web; the scheme of earlier
     *  versions). Explicit webs ignore it. A trailing field: older callers get 0. */
    int hold_bodies;
} ws_web_def;

/** A rectangular sheet: nx x ny nodes at origin + i spacing_x axis_x + j spacing_y axis_y. */
typedef struct ws_sheet_def {
    uint32_t size;  /**< set by ws_sheet_def_init() */
    uint32_t magic; /**< set by ws_sheet_def_init() */
    int nx;                  /**< nodes along x (>= 1; nx * ny >= 2) */
    int ny;                  /**< nodes along y (>= 1) */
    ws_vec3 origin;          /**< m, node (0, 0) */
    ws_vec3 axis_x;          /**< direction of the grid's x (normalised); default x */
    ws_vec3 axis_y;          /**< direction of the grid's y (normalised); default y */
    double spacing_x;        /**< node spacing along x as placed, m (> 0) */
    double spacing_y;        /**< node spacing along y as placed, m (> 0) */
    double prestretch_x;     /**< rest length = spacing / (1 + prestretch), along x; > -1 and
                                  <= 10 (1000 %) */
    double prestretch_y;     /**< the same along y */
    int shear;               /**< 1: add both diagonals of every cell */
    const uint32_t *pinned;  /**< node indices (i + nx j) held fixed; may be NULL */
    size_t pinned_count;     /**< entries in pinned */
} ws_sheet_def;

/** A band wrapped around a stack: around the convex outline of the bodies' footprint (their
 *  vertices projected along z), pushed out by the layers so the film just touches, from
 *  z_bottom to z_top (m, global), n_around x n_up nodes, closed around. */
typedef struct ws_band_def {
    uint32_t size;  /**< set by ws_band_def_init() */
    uint32_t magic; /**< set by ws_band_def_init() */
    const ws_body_id *bodies; /**< the stack */
    size_t body_count;        /**< entries in bodies */
    double z_bottom;          /**< lowest row, global z, m */
    double z_top;             /**< highest row, global z, m */
    int n_around;             /**< nodes around (>= 3) */
    int n_up;                 /**< rows (>= 1) */
    double prestretch_around; /**< e.g. 0.4: rest length = spacing / (1 + it); > -1, <= 10 */
    double prestretch_up;     /**< e.g. 0.2; > -1, <= 10 */
    double gap;               /**< extra distance beyond the touching layers, m; default 0 */
    int shear;                /**< 1: add the diagonals */
} ws_band_def;

/** Anything else: nodes and springs as given. */
typedef struct ws_web_mesh_def {
    uint32_t size;  /**< set by ws_web_mesh_def_init() */
    uint32_t magic; /**< set by ws_web_mesh_def_init() */
    const double *positions;     /**< xyz per node, m */
    size_t node_count;           /**< nodes */
    const double *node_masses;   /**< kg per node; NULL: the web Def's node_mass */
    const uint32_t *springs;     /**< node index pairs */
    size_t spring_count;         /**< pairs in springs */
    const double *rest_lengths;  /**< m per spring (> 0); NULL: the lengths as placed */
    const uint8_t *kinds;        /**< ws_spring_kind per spring; NULL: all WS_SPRING_AROUND */
    const uint32_t *pinned;      /**< node indices held fixed; may be NULL */
    size_t pinned_count;         /**< entries in pinned */
    /** Per spring, its force as a multiple of its law's (finite, > 0): e.g. the number of film
     *  layers the spring stands for, so one law serves a film whose layers vary from place to
     *  place. Tensions, energy and the stable step read it too. NULL (default): 1 for every
     *  spring. */
    const double *stiffness_scales;
} ws_web_mesh_def;

/** Facts of a web. */
typedef struct ws_web_info {
    uint32_t node_count;   /**< nodes */
    uint32_t spring_count; /**< springs */
    int nx;           /**< grid nodes around / along x (0 for a mesh web) */
    int ny;           /**< grid rows (0 for a mesh web) */
    int closed;       /**< 1 for a band (closed around) */
    int substeps;     /**< sub-steps per world step */
    double mass;      /**< kg, all nodes */
    double min_node_mass; /**< kg */
} ws_web_info;

/** One height band of a containment profile. */
typedef struct ws_containment_band {
    double z_low;          /**< m, mean height of its lowest row (global z) */
    double z_high;         /**< m, mean height of its highest row */
    double hoop_tension;   /**< mean tension of the around-springs of its rows, N */
    double line_load;      /**< hoop tension per unit height, N/m */
    double contact_force;  /**< total normal force of the bodies on its nodes, N */
} ws_containment_band;

/** Rupture of a web (ws_web_get_rupture). */
typedef struct ws_web_rupture {
    double rupture_strain;     /**< the limit now; 0: none */
    uint32_t broken_count;     /**< springs broken so far */
    uint32_t broken_last_step; /**< of them, broken by the last step: an event when > 0 */
    int ruptured;              /**< 1 once a spring has broken; the first_ fields are then set */
    uint32_t first_spring;     /**< the first break: the most strained spring of the first step
                                    that broke any (UINT32_MAX before) */
    double first_time;         /**< s, world time at the end of that step */
    double first_strain;       /**< its strain then */
    ws_vec3 first_position;    /**< m, the midpoint of its two nodes then */
} ws_web_rupture;

/** The most strained intact spring of a web now (ws_web_get_peak_strain). */
typedef struct ws_web_peak {
    int found;         /**< 0 when the web has no intact spring (then the rest is zero) */
    uint32_t spring;   /**< its index (as ws_web_copy_springs numbers them) */
    double strain;     /**< l/l0 - 1 */
    double tension;    /**< N, the law's force now */
    uint32_t node_a;   /**< its first node */
    uint32_t node_b;   /**< its second node */
    ws_vec3 position_a; /**< m, node_a now */
    ws_vec3 position_b; /**< m, node_b now */
} ws_web_peak;

/** Fill a web Def with defaults (layer 1 mm, 1 sub-step; the law and a mass must be set).
 *  ws_web_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_web_def_init_sized(ws_web_def *def, size_t size);
/** The plain form, for programs built against headers before ws_web_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_web_def_init)(ws_web_def *def);
#define ws_web_def_init(def) ws_web_def_init_sized((def), sizeof *(def))
/** Fill a sheet Def with defaults (axes x and y; sizes and spacings must be set).
 *  ws_sheet_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_sheet_def_init_sized(ws_sheet_def *def, size_t size);
/** The plain form, for programs built against headers before ws_sheet_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_sheet_def_init)(ws_sheet_def *def);
#define ws_sheet_def_init(def) ws_sheet_def_init_sized((def), sizeof *(def))
/** Fill a band Def with defaults (no pre-stretch, no gap; bodies, heights, counts must be set).
 *  ws_band_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_band_def_init_sized(ws_band_def *def, size_t size);
/** The plain form, for programs built against headers before ws_band_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_band_def_init)(ws_band_def *def);
#define ws_band_def_init(def) ws_band_def_init_sized((def), sizeof *(def))
/** Fill a mesh-web Def with defaults (empty).
 *  ws_web_mesh_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_web_mesh_def_init_sized(ws_web_mesh_def *def, size_t size);
/** The plain form, for programs built against headers before ws_web_mesh_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_web_mesh_def_init)(ws_web_mesh_def *def);
#define ws_web_mesh_def_init(def) ws_web_mesh_def_init_sized((def), sizeof *(def))

/** Create a sheet. @return WS_OK, WS_ERR_INVALID_ARGUMENT, WS_ERR_UNINITIALIZED_DEF,
 *  WS_ERR_STALE_HANDLE (a law or material), WS_ERR_OUT_OF_MEMORY. */
WS_API ws_status ws_web_create_sheet(ws_world *world, const ws_web_def *def,
                                     const ws_sheet_def *sheet, ws_web_id *out);
/** Wrap a band around bodies (as they are now). */
WS_API ws_status ws_web_create_band(ws_world *world, const ws_web_def *def,
                                    const ws_band_def *band, ws_web_id *out);
/** A web from raw nodes and springs. */
WS_API ws_status ws_web_create_mesh(ws_world *world, const ws_web_def *def,
                                    const ws_web_mesh_def *mesh, ws_web_id *out);
/** Destroy a web; its laws stay. @return WS_OK, WS_ERR_STALE_HANDLE. */
WS_API ws_status ws_web_destroy(ws_world *world, ws_web_id id);
/** 1 if the id names a live web of this world, else 0. */
WS_API int ws_web_is_valid(const ws_world *world, ws_web_id id);
/** Node and spring counts, grid size, sub-steps, masses. */
WS_API ws_status ws_web_get_info(const ws_world *world, ws_web_id id, ws_web_info *info);

/** The largest stable sub-step of the web, s: the explicit limit 2/omega_max with omega_max^2
 *  bounded by (2 sum of spring stiffnesses + contact stiffness) / node mass over the nodes.
 *  ws_world_step refuses to run an explicit web (WS_ERR_NUMERICAL, saying the node mass or the
 *  sub-steps that would do) when dt / substeps exceeds it; an implicit web is never refused
 *  for it (the figure then says how far beyond the explicit limit it runs). */
WS_API ws_status ws_web_get_stable_dt(const ws_world *world, ws_web_id id, double *dt);
/** What the implicit solves of a web did (an explicit web reports zeros). */
typedef struct ws_web_solver_stats {
    uint64_t solves;          /**< linear solves since the web was made (one per sub-step) */
    uint64_t iterations;      /**< conjugate-gradient iterations of all of them */
    int last_iterations;      /**< iterations of the last solve */
    double last_residual;     /**< its worst row's residual over that row's weight over
                                   the step, m g h (<= solver_tolerance when it converged) */
} ws_web_solver_stats;

/** The implicit solver's counts of a web. @return WS_OK, WS_ERR_STALE_HANDLE,
 *  WS_ERR_INVALID_ARGUMENT (stats NULL). */
WS_API ws_status ws_web_get_solver_stats(const ws_world *world, ws_web_id id,
                                         ws_web_solver_stats *stats);

/** Sub-steps per world step (>= 1). */
WS_API ws_status ws_web_set_substeps(ws_world *world, ws_web_id id, int substeps);

/* Bulk read-out: each copies min(capacity, count) items and writes count; buf NULL with
 * capacity 0 asks for the count; a short buffer gives WS_ERR_BUFFER_TOO_SMALL. Capacities count
 * items (nodes or springs), not doubles. */
/** Node positions, xyz, m. */
WS_API ws_status ws_web_copy_positions(const ws_world *world, ws_web_id id, double *xyz,
                                       size_t capacity, size_t *count);
/** Node velocities, xyz, m/s. */
WS_API ws_status ws_web_copy_velocities(const ws_world *world, ws_web_id id, double *xyz,
                                        size_t capacity, size_t *count);
/** Force of the bodies on each node in the last step (normal + friction), xyz, N. */
WS_API ws_status ws_web_copy_contact_forces(const ws_world *world, ws_web_id id, double *xyz,
                                            size_t capacity, size_t *count);
/** Spring end nodes, pairs. */
WS_API ws_status ws_web_copy_springs(const ws_world *world, ws_web_id id, uint32_t *pairs,
                                     size_t capacity, size_t *count);
/** Spring strains l/l0 - 1 now. */
WS_API ws_status ws_web_copy_spring_strains(const ws_world *world, ws_web_id id, double *strain,
                                            size_t capacity, size_t *count);
/** Spring tensions now (the law's force, N; negative in compression; 0 when broken). */
WS_API ws_status ws_web_copy_spring_tensions(const ws_world *world, ws_web_id id,
                                             double *tension, size_t capacity, size_t *count);
/** Total force (N, global) and moment about the CoG (N m) the web put on a body in the last
 *  step. `moment` may be NULL. */
WS_API ws_status ws_web_get_body_force(const ws_world *world, ws_web_id web, ws_body_id body,
                                       ws_vec3 *force, ws_vec3 *moment);
/** Containment profile of a grid web: its rows split into `count` equal bands from bottom to
 *  top. WS_ERR_INVALID_ARGUMENT for a mesh web or count outside 1..rows. */
WS_API ws_status ws_web_get_containment(const ws_world *world, ws_web_id id,
                                        ws_containment_band *bands, size_t count);
/** Set the rupture strain of a web (see ws_web_def.rupture_strain; >= 0, 0: no more breaks).
 *  Springs broken stay broken. A web given a limit (here or in its Def) has its springs'
 *  broken flags in its saved state and state hash from then on.
 *  @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (negative, NaN or infinite),
 *  WS_ERR_OUT_OF_MEMORY, WS_ERR_IN_STEP. */
WS_API ws_status ws_web_set_rupture_strain(ws_world *world, ws_web_id id, double strain);
/** The web's rupture: its limit, how many springs broke (in all and in the last step: poll
 *  this after each step for the event) and the first break (time, spring, strain, place).
 *  @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (out NULL). */
WS_API ws_status ws_web_get_rupture(const ws_world *world, ws_web_id id, ws_web_rupture *out);
/** Indices of the broken springs, ascending (a bulk copy, as above; count = broken_count). */
WS_API ws_status ws_web_copy_broken_springs(const ws_world *world, ws_web_id id,
                                            uint32_t *springs, size_t capacity, size_t *count);
/** The most strained intact spring now (peak film strain and where): its index, strain,
 *  tension and its nodes' positions. Ties go to the lower index.
 *  @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (out NULL). */
WS_API ws_status ws_web_get_peak_strain(const ws_world *world, ws_web_id id, ws_web_peak *out);
/** Energy of the web, J: kinetic, elastic (springs), and gravitational (-m g . x summed). */
WS_API ws_status ws_web_get_energy(const ws_world *world, ws_web_id id, double *kinetic,
                                   double *elastic, double *gravity);

#ifdef __cplusplus
}
#endif

#endif
