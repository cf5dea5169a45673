/**
 * @file law.h
 * @brief Constitutive laws: force as a function of strain and strain rate, with derivatives.
 *
 * A law knows nothing of what uses it (web springs, rods, springs and bushings). Its parameters
 * may be shared by many users; a law with history (WS_LAW_RELAXATION, or a sum or scaling of
 * one) keeps that history in a small array of doubles that belongs to each user, never to the
 * law (see ws_law_get_state_size()).
 *
 * **Strain and units.** 1D laws map strain u (dimensionless, l/l0 - 1 for a spring) and strain
 * rate u_dot (1/s) to a force F (N); their stiffness is per unit strain (N), e.g. E A for a bar,
 * and their damping per unit strain rate (N s). A spring of rest length l0 then has the
 * stiffness dF/du / l0 in N/m. 3D and 6D laws take a vector u of 3 or 6 components; the element
 * that uses the law says what they are (a 3D displacement in m gives forces in N and stiffness
 * in N/m; a 6D law orders u as [displacement x y z, rotation x y z] and F as [force x y z, moment
 * x y z]). The derivatives are dim x dim matrices, row-major: dF/du[i * dim + j] = dF_i/du_j.
 *
 * **Nonlinear laws in 3D and 6D** (tension/compression, cubic, table, stop, relaxation) act on
 * each component alone with the same parameters: F_i = f(u_i, u_dot_i). Their damping (and the
 * linear part of the cubic law) may be a full matrix.
 *
 * **History.** Evaluation is a pure function of the committed state: ws_law_evaluate_state()
 * never changes it, however often a solver calls it while it iterates. Once a step is accepted
 * the caller commits the strain it accepted with ws_law_commit_state(); only that changes the
 * state. Evaluating at the committed strain right after a commit (dt = 0) gives the force the
 * trial gave.
 */
#ifndef WRAPSIM_LAW_H
#define WRAPSIM_LAW_H

#include <wrapsim/world.h>

#ifdef __cplusplus
extern "C" {
#endif

/** A constitutive law. */
typedef struct ws_law_id {
    uint64_t bits; /**< opaque; 0 = null */
} ws_law_id;

/** Largest dimension of a law (6: force and moment). */
#define WS_LAW_MAX_DIM 6
/** Largest number of terms of a WS_LAW_SUM. */
#define WS_LAW_MAX_TERMS 16
/** Largest number of Prony branches of a WS_LAW_RELAXATION. */
#define WS_LAW_MAX_PRONY 16
/** Most doubles of history a law may need per user (ws_law_get_state_size), with everything its
 *  sums and scalings contain: a sum of 16 dim-6 relaxation laws of 16 branches needs 1632. A
 *  law that would need more is refused at create. */
#define WS_LAW_MAX_HISTORY 4096
/** Most leaf laws (laws that are neither sums nor scalings) one evaluation may visit, counting
 *  a law each time it appears: a sum of 16 sums of 16 laws has 256. Sums of sums that would
 *  visit more are refused at create, so the cost of an evaluation stays bounded. */
#define WS_LAW_MAX_LEAVES 256

/** Kinds of laws. In the formulas u is the strain, u_dot its rate, K the stiffness
 *  (`stiffness` times the identity, or `stiffness_matrix`) and C the damping (`damping` times
 *  the identity, or `damping_matrix`). */
typedef enum ws_law_type {
    /** F = K u (any damping is ignored). dim 1, 3, 6. */
    WS_LAW_LINEAR_ELASTIC = 0,
    /** Kelvin-Voigt: F = K u + C u_dot. A constant force F0 applied at u = 0 gives the creep
     *  u(t) = F0/k (1 - exp(-t k / c)). dim 1, 3, 6. */
    WS_LAW_LINEAR_VISCOELASTIC = 1,
    /** Film: F = k_c u + (k - k_c) g(u) + c u_dot, where g is a smooth (C1) ramp from 0
     *  for u <= -w to u for u >= w, quadratic between (w = transition): stiffness k in
     *  tension, k_c in compression, joined smoothly. A film buckles rather than pushes: k_c << k.
     *  The join is centred on u = 0, so F(0) = (k - k_c) w / 4: keep w small. */
    WS_LAW_TENSION_COMPRESSION = 2,
    /** F = C u_dot: a dashpot, no stiffness. dim 1, 3, 6. */
    WS_LAW_LINEAR_VISCOUS = 3,
    /** F = K u + k3 u^3 + C u_dot, the cube per component (k3 = `cubic_stiffness`, or one value
     *  per component in `cubic_stiffnesses`): a hardening pad. dim 1, 3, 6. */
    WS_LAW_CUBIC_ELASTIC = 4,
    /** F = T(u) + C u_dot, T the monotone cubic Hermite interpolant (Fritsch-Carlson) of measured
     *  points (`table_strain`, `table_force`), as from a film's tensile test: it passes through
     *  every point, never overshoots between them and is C1; beyond the ends it continues as a
     *  straight line with the end slope. dim 1, 3, 6. */
    WS_LAW_TABLE = 5,
    /** A stop: no force while stop_low <= u <= stop_high; beyond, F = k r(u - stop_high) for the
     *  tension side (a slack strap) or -k r(stop_low - u) for the compression side (a bumper),
     *  r a C1 ramp that is 0 up to 0, x^2/(4w) up to 2w and x - w beyond (w = `transition`; w = 0
     *  gives a sharp corner). The damping acts only in contact, faded in with r', and the stop
     *  never pulls (a bumper) or pushes (a strap): the force is clamped at 0 on its side. A
     *  stop needs no history: its state is decided from u at each evaluation. dim 1, 3, 6. */
    WS_LAW_STOP = 6,
    /** Stress relaxation, a Prony series (one branch: the standard linear solid):
     *  F = k_inf u + sum_i q_i + C u_dot, each q_i the force of a spring k_i in series with a
     *  damper k_i tau_i: dq_i/dt = k_i du/dt - q_i / tau_i. A strain step u0 held from t = 0
     *  gives F(t) = (k_inf + sum_i k_i exp(-t / tau_i)) u0. History: the q_i and the committed
     *  strain. The update over a step assumes u moves linearly from the committed strain to the
     *  new one and is exact for that, so a held strain decays exactly. dim 1, 3, 6. */
    WS_LAW_RELAXATION = 7,
    /** F = the sum of other laws (`terms`) of the same dim; their histories side by side. */
    WS_LAW_SUM = 8,
    /** F = s(t) F_base(u, u_dot): another law (`base`) scaled by a function of time, s(t) =
     *  `scale` times the callback `scale_fn`, or times the piecewise linear table
     *  (`scale_times`, `scale_factors`), or times 1 when neither is given. */
    WS_LAW_SCALED = 9,
    /** A law computed by a user callback (`user_fn`, `user_data`), e.g. from Python. */
    WS_LAW_USER = 10
} ws_law_type;

/** Kind flags of a law (ws_law_info.flags): which of u and u_dot it depends on, so that users
 *  may skip the rate work of a purely elastic law. */
enum ws_law_flag {
    WS_LAW_FLAG_ELASTIC = 1, /**< F depends on u (or on its history) */
    WS_LAW_FLAG_VISCOUS = 2  /**< F depends on u_dot */
};

/** A time function s(t) of a WS_LAW_SCALED law: write the factor (dimensionless) at time t (s)
 *  to *factor and return 0; non-zero (or a non-finite factor) is a failure that the
 *  evaluation reports as WS_ERR_CALLBACK. Called during evaluation: keep it pure. */
typedef int (*ws_law_time_fn)(void *user, double t, double *factor);

/** A user law: from the dim components of u and u_dot (ud) at time t (s), write F (dim values)
 *  and the derivatives dFdu and dFdud (dim x dim, row-major), and return 0; non-zero is a
 *  failure reported as WS_ERR_CALLBACK, a non-finite result as WS_ERR_NUMERICAL (both with the
 *  law's name in the last error). The outputs are never NULL
 *  and are zero on entry, so a law without a rate term may leave dFdud alone. It must be a pure
 *  function of its arguments (it may be called many times per step, also at trial strains). */
typedef int (*ws_law_user_fn)(void *user, int dim, const double *u, const double *ud, double t,
                              double *F, double *dFdu, double *dFdud);

/** A law. Fill with ws_law_def_init(). Arrays are copied at create, so they need only live
 *  through the call. */
typedef struct ws_law_def {
    uint32_t size;    /**< set by ws_law_def_init() */
    uint32_t magic;   /**< set by ws_law_def_init() */
    ws_law_type type; /**< default WS_LAW_LINEAR_ELASTIC */
    /** k, N per unit strain: > 0 for the linear elastic, Kelvin-Voigt, film, cubic (its linear
     *  part, >= 0) and stop laws; k_inf (>= 0) for relaxation; for a user law an upper bound on
     *  its tangent stiffness (>= 0, used for stable-step estimates). In tension for the film
     *  law. Ignored when `stiffness_matrix` is given. */
    double stiffness;
    double compression_stiffness; /**< k_c, N per unit strain (>= 0), film law only; default 0 */
    /** c, N s per unit strain rate (>= 0); > 0 for WS_LAW_LINEAR_VISCOUS; ignored by
     *  WS_LAW_LINEAR_ELASTIC; for a user law an upper bound on its tangent damping. Ignored when
     *  `damping_matrix` is given. */
    double damping;
    /** w, strain: half-width of the film law's smooth join (> 0), or the stop's ramp (>= 0);
     *  default 1e-3 */
    double transition;
    const char *name; /**< optional, copied */
    /** 1 (default), 3 or 6: the number of components of u and F. */
    int dim;
    /** Optional dim x dim stiffness matrix, row-major, N per unit strain: for the linear elastic,
     *  Kelvin-Voigt and cubic laws (orthotropic or anisotropic). Its symmetric part must be
     *  positive semi-definite and it must not be zero. NULL: `stiffness` times the identity. */
    const double *stiffness_matrix;
    /** Optional dim x dim damping matrix, row-major, N s: for every law with damping except the
     *  stop; symmetric part positive semi-definite. NULL: `damping` times the identity. */
    const double *damping_matrix;
    /** k3 of WS_LAW_CUBIC_ELASTIC, N per unit strain cubed (>= 0: hardening). */
    double cubic_stiffness;
    /** Optional k3 per component (dim values, each >= 0); NULL: `cubic_stiffness` for all. */
    const double *cubic_stiffnesses;
    /** WS_LAW_TABLE: `table_count` strains, strictly increasing. */
    const double *table_strain;
    /** WS_LAW_TABLE: `table_count` forces (N), non-decreasing (the law's stiffness is >= 0). */
    const double *table_force;
    size_t table_count; /**< WS_LAW_TABLE: number of points, >= 2 */
    /** WS_LAW_STOP: the strain below which the stop pushes back (a bumper closes); default
     *  -INFINITY (no compression side). */
    double stop_low;
    /** WS_LAW_STOP: the strain above which it pulls back (a slack strap tightens); default
     *  +INFINITY (no tension side). stop_low < stop_high, at least one finite. */
    double stop_high;
    /** WS_LAW_RELAXATION: `prony_count` branch stiffnesses k_i (N per unit strain, > 0). */
    const double *prony_stiffness;
    /** WS_LAW_RELAXATION: `prony_count` relaxation times tau_i (s, > 0). */
    const double *prony_time;
    size_t prony_count; /**< WS_LAW_RELAXATION: 1 to WS_LAW_MAX_PRONY branches */
    /** WS_LAW_SUM: `term_count` laws of this world (live, of the same dim). They count this law
     *  as a user: they cannot be destroyed before it. */
    const ws_law_id *terms;
    size_t term_count; /**< WS_LAW_SUM: 1 to WS_LAW_MAX_TERMS */
    ws_law_id base;    /**< WS_LAW_SCALED: the law scaled (live, same dim; counted as used) */
    double scale;      /**< WS_LAW_SCALED: constant factor (>= 0); default 1 */
    /** WS_LAW_SCALED: optional table of times (s, strictly increasing), `scale_count` values;
     *  the factor is interpolated linearly between them and held beyond the ends. */
    const double *scale_times;
    const double *scale_factors; /**< WS_LAW_SCALED: the factors at `scale_times` (>= 0) */
    size_t scale_count;          /**< WS_LAW_SCALED: points of the table (0: none) */
    /** WS_LAW_SCALED: optional time function; it takes precedence over the table. Its factors
     *  should lie in [0, 1]: the stiffness bound of the law assumes so. */
    ws_law_time_fn scale_fn;
    void *scale_user;       /**< passed to scale_fn */
    ws_law_user_fn user_fn; /**< WS_LAW_USER: the callback (required) */
    void *user_data;        /**< WS_LAW_USER: passed to user_fn */
    /** WS_LAW_USER: WS_LAW_FLAG_* the law has; default elastic and viscous. */
    unsigned user_flags;
} ws_law_def;

/** What a law is (ws_law_get_info()). */
typedef struct ws_law_info {
    ws_law_type type;     /**< the law's type */
    int dim;              /**< 1, 3 or 6 */
    unsigned flags;       /**< WS_LAW_FLAG_* */
    uint32_t state_size;  /**< doubles of history each user keeps (0: none) */
    uint32_t users;       /**< webs, elements and laws that use it */
    double max_stiffness; /**< upper bound on the norm of dF/du (N per unit strain); for the
                               cubic law taken at |u| <= 1 */
    double max_damping;   /**< upper bound on the norm of dF/du_dot (N s) */
} ws_law_info;

/** Fill a law Def with defaults (linear elastic, dim 1, no damping, transition 1e-3, scale 1,
 *  stop_low -INFINITY, stop_high +INFINITY, user_flags elastic and viscous; the stiffness must
 *  be set). NULL is ignored.
 *  ws_law_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_law_def_init_sized(ws_law_def *def, size_t size);
/** The plain form, for programs built against headers before ws_law_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_law_def_init)(ws_law_def *def);
#define ws_law_def_init(def) ws_law_def_init_sized((def), sizeof *(def))
/** Create a law. Arrays of the Def are copied; laws named by `terms` or `base` count the new
 *  law as a user. @return WS_OK, WS_ERR_INVALID_ARGUMENT (a bad field: the last error names
 *  it), WS_ERR_STALE_HANDLE (a term or base that is not a live law of this world),
 *  WS_ERR_UNINITIALIZED_DEF, WS_ERR_OUT_OF_MEMORY. */
WS_API ws_status ws_law_create(ws_world *world, const ws_law_def *def, ws_law_id *out);
/** Destroy a law nothing uses (WS_ERR_IN_USE while a web, an element or another law uses it). */
WS_API ws_status ws_law_destroy(ws_world *world, ws_law_id id);
/** 1 if the id names a live law of this world, else 0. */
WS_API int ws_law_is_valid(const ws_world *world, ws_law_id id);
/** What a law is: its type, dim, kind flags, state size and bounds. @return WS_OK,
 *  WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (NULL info). */
WS_API ws_status ws_law_get_info(const ws_world *world, ws_law_id id, ws_law_info *info);
/** Evaluate a 1D law at its initial state and t = 0: force F (N) at strain eps and strain rate
 *  eps_dot (1/s), with dF/deps (N) and dF/deps_dot (N s). Any output pointer may be NULL.
 *  @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (non-finite arguments, a law of
 *  dim 3 or 6), WS_ERR_CALLBACK (a user or time callback failed), WS_ERR_NUMERICAL (a
 *  non-finite result). */
WS_API ws_status ws_law_evaluate(const ws_world *world, ws_law_id id, double eps, double eps_dot,
                                 double *force, double *dforce_dstrain, double *dforce_drate);
/** Elastic energy of a 1D law per unit rest length (J/m) stored at strain eps from the initial
 *  state at t = 0: the integral of the elastic part of F from 0 to eps (a spring of rest length
 *  l0 stores l0 times this). For a relaxation law, the instantaneous (unrelaxed) energy.
 *  @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (non-finite eps, dim != 1,
 *  NULL energy), WS_ERR_UNSUPPORTED (a user law: its energy is unknown), WS_ERR_CALLBACK. */
WS_API ws_status ws_law_energy(const ws_world *world, ws_law_id id, double eps, double *energy);

/** Doubles of history each user of the law keeps (0 for a law without history). @return WS_OK,
 *  WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (NULL count). */
WS_API ws_status ws_law_get_state_size(const ws_world *world, ws_law_id id, size_t *count);
/** Write the initial state (unstrained and relaxed) into state, which holds
 *  ws_law_get_state_size() doubles (NULL when that is 0). @return WS_OK, WS_ERR_STALE_HANDLE,
 *  WS_ERR_INVALID_ARGUMENT. */
WS_API ws_status ws_law_init_state(const ws_world *world, ws_law_id id, double *state);
/** Evaluate a law of any dim from a committed state, without changing it.
 *  @param world the world that owns the law.
 *  @param id the law.
 *  @param state the user's history (ws_law_get_state_size() doubles); NULL means the initial
 *         state.
 *  @param u strain, dim values (not NULL).
 *  @param ud strain rate, dim values in 1/s; NULL means zero.
 *  @param t time of the evaluation, s.
 *  @param dt time since the committed state, s (>= 0; used by relaxation).
 *  @param force F, dim values (N); may be NULL.
 *  @param dforce_dstrain dF/du, dim x dim, row-major (N per unit strain); may be NULL.
 *  @param dforce_drate dF/du_dot, dim x dim, row-major (N s per unit strain); may be NULL.
 *  @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (NULL u, non-finite input,
 *  dt < 0), WS_ERR_CALLBACK (a user or time callback failed), WS_ERR_NUMERICAL (non-finite
 *  result). Outputs are unspecified on error. */
WS_API ws_status ws_law_evaluate_state(const ws_world *world, ws_law_id id, const double *state,
                                       const double *u, const double *ud, double t, double dt,
                                       double *force, double *dforce_dstrain, double *dforce_drate);
/** Commit a step accepted at strain u and rate ud (NULL: zero) at time t, dt after the
 *  previously committed state: state becomes the history after that step. Nothing else
 *  changes it. Does nothing for a law without history (state may then be NULL).
 *  @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (NULL state or u, non-finite
 *  input, dt < 0); on error the state is unchanged. */
WS_API ws_status ws_law_commit_state(const ws_world *world, ws_law_id id, double *state,
                                     const double *u, const double *ud, double t, double dt);
/** Elastic energy (J per unit of the strain's scale: J/m of rest length for a 1D film strain)
 *  stored at strain u (dim values) from a committed state (NULL: the initial one) at time t
 *  (s; it matters for a scaled law). For a matrix law 1/2 u^T K u, exact for a symmetric K.
 *  @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT, WS_ERR_UNSUPPORTED (a user law
 *  or a sum or scaling of one), WS_ERR_CALLBACK (a time callback failed). */
WS_API ws_status ws_law_energy_state(const ws_world *world, ws_law_id id, const double *state,
                                     const double *u, double t, double *energy);

#ifdef __cplusplus
}
#endif

#endif
