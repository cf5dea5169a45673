/**
 * @file element.h
 * @brief Deformable elements between two bodies, or a body and the fixed world frame: rods,
 *        linear springs, angular springs and 6D bushings, each with a constitutive law.
 *
 * An element computes a strain u (and its rate) from the states of its two bodies, asks its law
 * for the force F(u, u_dot), and applies F back to both bodies as forces and moments that
 * balance exactly (their sum and their moment about any point are zero to round-off). The law's
 * dimension must match the element: 1 for a rod, 3 for a linear or angular spring, 6 for a
 * bushing ([displacement x y z, rotation x y z]).
 *
 * Each end of an element has an attachment point and an element frame fixed in its body. The
 * strains:
 * - rod: eps = |p2 - p1| / l0 - 1 (dimensionless; the law's F is the tension, N);
 * - linear spring: d = E^T (p2 - p1), m, in the law frame E (forces in N);
 * - angular spring: theta = ax(log(E1^T E2)), rad, the relative rotation vector of the two
 *   element frames (moments in N m);
 * - bushing: [d, theta] together, one 6x6 law (coupled terms allowed).
 *
 * The law frame E is the element frame of body 1 (WS_ELEMENT_ATTACHED) or the mid frame
 * E1 exp(theta/2) halfway between the two (WS_ELEMENT_INVARIANT, WS_ELEMENT_POTENTIAL): with the
 * mid frame, swapping the two bodies gives the same motion for any law, orthotropic or not.
 * docs/elements.md has the formulas, the sign conventions and the invariance argument.
 *
 * Units are SI: m, rad, N, N m, s.
 */
#ifndef WRAPSIM_ELEMENT_H
#define WRAPSIM_ELEMENT_H

#include <wrapsim/body.h>
#include <wrapsim/law.h>

#ifdef __cplusplus
extern "C" {
#endif

/** A deformable element. */
typedef struct ws_element_id {
    uint64_t bits; /**< opaque; 0 = null */
} ws_element_id;

/** What an element measures. */
typedef enum ws_element_type {
    /** Distance between two points: a 1D law of the strain |p2 - p1|/l0 - 1 gives the tension. */
    WS_ELEMENT_ROD = 0,
    /** Displacement p2 - p1 in the law frame: a 3D law gives the force (N). */
    WS_ELEMENT_LINEAR_SPRING = 1,
    /** Relative rotation of the two element frames: a 3D law gives the moment (N m). */
    WS_ELEMENT_ANGULAR_SPRING = 2,
    /** Displacement and relative rotation in one mid frame: a 6D law gives force and moment. */
    WS_ELEMENT_BUSHING = 3
} ws_element_type;

/** Which frame the law is referred to (ignored by rods). */
typedef enum ws_element_formulation {
    /** The mid frame halfway between the two element frames, as in the seed's "invariant"
     *  angular spring: the same motion whichever body is body 1. The angular law's rate is the
     *  relative angular velocity in the mid frame, and its moment is applied as it comes. The
     *  default. */
    WS_ELEMENT_INVARIANT = 0,
    /** Body 1's element frame, as in the seed's "attached" angular spring: simple, but biased
     *  towards body 1 (an orthotropic law gives another motion when the bodies are swapped). */
    WS_ELEMENT_ATTACHED = 1,
    /** As WS_ELEMENT_INVARIANT, but the angular moment is the derivative of the law's elastic
     *  energy with respect to the rotation, so an elastic law conserves energy exactly at any
     *  rotation, orthotropic or coupled. Angular springs and bushings; a linear spring is already
     *  potential-based as WS_ELEMENT_INVARIANT and takes either name. */
    WS_ELEMENT_POTENTIAL = 2
} ws_element_formulation;

/** An element. Fill with ws_element_def_init(). */
typedef struct ws_element_def {
    uint32_t size;                      /**< set by ws_element_def_init() */
    uint32_t magic;                     /**< set by ws_element_def_init() */
    ws_element_type type;               /**< default WS_ELEMENT_ROD */
    ws_element_formulation formulation; /**< default WS_ELEMENT_INVARIANT */
    ws_body_id body1;                   /**< first body; null id = the fixed world frame */
    ws_body_id body2; /**< second body; null id = the fixed world frame (not both null) */
    /** The law: dim 1 for a rod, 3 for a spring, 6 for a bushing (required). */
    ws_law_id law;
    /** Attachment point on body 1, m, in body 1's frame (the global frame for the world). */
    ws_vec3 point1;
    /** Attachment point on body 2, m, in body 2's frame (the global frame for the world). */
    ws_vec3 point2;
    /** Orientation of the element frame in body 1's frame. All zero (default): identity. */
    ws_quat frame1;
    /** Orientation of the element frame in body 2's frame. All zero (default): the one that
     *  makes the two element frames coincide at create, so that an angular spring or bushing
     *  starts unstrained in rotation. */
    ws_quat frame2;
    /** 1: point1, point2 are global positions (m) and frame1, frame2 global orientations, all
     *  taken at the bodies' poses at create and kept in the bodies' frames from then on. 0
     *  (default): in the bodies' frames as above. */
    int global_attachment;
    /** Rod rest length l0, m; <= 0 (default 0): the distance between the points at create. */
    double rest_length;
    const char *name; /**< optional, copied; used in error messages */
    void *user_data;  /**< yours */
} ws_element_def;

/** What an element does now, at the world's current state (from the committed law history). */
typedef struct ws_element_output {
    int32_t type; /**< ws_element_type */
    int32_t dim;  /**< components used in strain, strain_rate and law_force: 1, 3 or 6 */
    /** The strain u fed to the law: rod eps; linear spring d (m); angular spring theta (rad);
     *  bushing [d, theta]. Components beyond dim are zero. */
    double strain[6];
    /** Its rate as fed to the law: rod eps_dot (1/s); linear spring d_dot (m/s) in the law
     *  frame; angular: the relative angular velocity in the law frame (rad/s) for ATTACHED and
     *  INVARIANT, theta_dot for POTENTIAL. */
    double strain_rate[6];
    /** The law's F in the law frame: rod tension (N); force (N) and/or moment (N m). */
    double law_force[6];
    ws_vec3 force;   /**< force on body 1, N, global; body 2 gets exactly -force */
    ws_vec3 moment;  /**< moment on body 1 about point 1, N m, global */
    ws_vec3 moment2; /**< moment on body 2 about point 2, N m, global (balances the rest) */
    ws_vec3 point1;  /**< attachment point 1 now, m, global */
    ws_vec3 point2;  /**< attachment point 2 now, m, global */
    ws_quat frame;   /**< orientation of the law frame, global (the rod's: identity) */
    double energy;   /**< elastic energy stored in the law at this strain, J; NaN if unknown */
} ws_element_output;

/** Fill an element Def with defaults (a rod, invariant formulation, points at the bodies'
 *  origins, frames automatic, rest length from the geometry). NULL is ignored.
 *  ws_element_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_element_def_init_sized(ws_element_def *def, size_t size);
/** The plain form, for programs built against headers before ws_element_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_element_def_init)(ws_element_def *def);
#define ws_element_def_init(def) ws_element_def_init_sized((def), sizeof *(def))
/** Create an element. The law's history (if any) starts relaxed at the world's time; the
 *  element counts as a user of its law and of its bodies, which cannot be destroyed before it.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (a law of the wrong dim, both ends the world, the
 *  same body twice, a non-finite point, a zero rest length ...: the last error says which),
 *  WS_ERR_UNINITIALIZED_DEF, WS_ERR_STALE_HANDLE (a body or the law), WS_ERR_OUT_OF_MEMORY. */
WS_API ws_status ws_element_create(ws_world *world, const ws_element_def *def, ws_element_id *out);
/** Destroy an element (its law and bodies stay). @return WS_OK, WS_ERR_STALE_HANDLE. */
WS_API ws_status ws_element_destroy(ws_world *world, ws_element_id id);
/** 1 if the id names a live element of this world, else 0. */
WS_API int ws_element_is_valid(const ws_world *world, ws_element_id id);
/** Strain, law force, loads on both bodies and stored energy at the world's current state: the
 *  loads the next step will apply.
 *  @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (NULL out), WS_ERR_CALLBACK (a
 *  user law or time callback failed), WS_ERR_NUMERICAL (a non-finite result). */
WS_API ws_status ws_element_get_output(const ws_world *world, ws_element_id id,
                                       ws_element_output *out);
/** The name given in the Def ("" if none or for a stale id). Valid while the element lives. */
WS_API const char *ws_element_get_name(const ws_world *world, ws_element_id id);
/** The user pointer of the Def; NULL for a stale id. */
WS_API void *ws_element_get_user_data(const ws_world *world, ws_element_id id);
/** Copy the ids of all live elements. The order is the one of ws_world_copy_element_outputs();
 *  destroying an element may change it. buf may be NULL with capacity 0 to ask the count.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL count, NULL buf with capacity > 0),
 *  WS_ERR_BUFFER_TOO_SMALL (the first `capacity` were copied, *count says how many exist). */
WS_API ws_status ws_world_copy_element_ids(const ws_world *world, ws_element_id *buf,
                                           size_t capacity, size_t *count);
/** The output of every live element, as ws_element_get_output(), in the order of
 *  ws_world_copy_element_ids(): one call for a whole load (numpy reads the array directly).
 *  @return as ws_world_copy_element_ids(), and WS_ERR_CALLBACK or WS_ERR_NUMERICAL. */
WS_API ws_status ws_world_copy_element_outputs(const ws_world *world, ws_element_output *buf,
                                               size_t capacity, size_t *count);
/** Elastic energy stored in all elements now, J (add it to ws_world_get_energy()'s terms for
 *  the mechanical energy). @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL), WS_ERR_UNSUPPORTED
 *  (a law whose energy is unknown: a user law, or a time callback that failed). */
WS_API ws_status ws_world_get_element_energy(const ws_world *world, double *energy);

#ifdef __cplusplus
}
#endif

#endif
