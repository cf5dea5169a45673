/**
 * @file law.h
 * @brief Constitutive laws: force as a function of strain and strain rate, with derivatives.
 *
 * A law knows nothing of what uses it (web springs now; rods and bushings later). One law may be
 * shared by many springs. 1D laws map strain eps (dimensionless, l/l0 - 1) and strain rate
 * eps_dot (1/s) to a force F (N); their stiffness is per unit strain (N), e.g. E A for a bar, and
 * their damping per unit strain rate (N s). A spring of rest length l0 then has the stiffness
 * dF/deps / l0 in N/m.
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

/** Kinds of 1D laws. */
typedef enum ws_law_type {
    /** F = k eps. */
    WS_LAW_LINEAR_ELASTIC = 0,
    /** Kelvin-Voigt: F = k eps + c eps_dot. */
    WS_LAW_LINEAR_VISCOELASTIC = 1,
    /** Film: F = k_c eps + (k - k_c) g(eps) + c eps_dot, where g is a smooth (C1) ramp from 0
     *  for eps <= -w to eps for eps >= w, quadratic between (w = transition): stiffness k in
     *  tension, k_c in compression, joined smoothly. A film buckles rather than pushes: k_c << k.
     *  The join is centred on eps = 0, so F(0) = (k - k_c) w / 4: keep w small. */
    WS_LAW_TENSION_COMPRESSION = 2
} ws_law_type;

/** A law. Fill with ws_law_def_init(). */
typedef struct ws_law_def {
    uint32_t size;  /**< set by ws_law_def_init() */
    uint32_t magic; /**< set by ws_law_def_init() */
    ws_law_type type;             /**< default WS_LAW_LINEAR_ELASTIC */
    double stiffness;             /**< k, N per unit strain (> 0); in tension for the film law */
    double compression_stiffness; /**< k_c, N per unit strain (>= 0), film law only; default 0 */
    double damping;               /**< c, N s per unit strain rate (>= 0) */
    double transition;            /**< w, strain half-width of the smooth join (> 0); 1e-3 */
    const char *name;             /**< optional, copied */
} ws_law_def;

/** Fill a law Def with defaults (linear elastic, no damping, transition 1e-3; the stiffness
 *  must be set). NULL is ignored. */
WS_API void ws_law_def_init(ws_law_def *def);
/** Create a law. @return WS_OK, WS_ERR_INVALID_ARGUMENT, WS_ERR_UNINITIALIZED_DEF,
 *  WS_ERR_OUT_OF_MEMORY. */
WS_API ws_status ws_law_create(ws_world *world, const ws_law_def *def, ws_law_id *out);
/** Destroy a law nothing uses (WS_ERR_IN_USE while a web uses it). */
WS_API ws_status ws_law_destroy(ws_world *world, ws_law_id id);
/** 1 if the id names a live law of this world, else 0. */
WS_API int ws_law_is_valid(const ws_world *world, ws_law_id id);
/** Evaluate a law: force F (N) at strain eps and strain rate eps_dot (1/s), with dF/deps (N) and
 *  dF/deps_dot (N s). Any output pointer may be NULL. */
WS_API ws_status ws_law_evaluate(const ws_world *world, ws_law_id id, double eps, double eps_dot,
                                 double *force, double *dforce_dstrain, double *dforce_drate);
/** Elastic energy per unit rest length (J/m) stored at strain eps: the integral of the elastic
 *  part of F from 0 to eps (a spring of rest length l0 stores l0 times this). */
WS_API ws_status ws_law_energy(const ws_world *world, ws_law_id id, double eps, double *energy);

#ifdef __cplusplus
}
#endif

#endif
