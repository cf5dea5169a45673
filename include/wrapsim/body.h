/**
 * @file body.h
 * @brief Rigid bodies (dynamic) and world elements (kinematic bodies whose pose follows a drive).
 *
 * A body's frame has its origin at the centre of gravity; its orientation is a set of Euler
 * parameters. Velocities cross the API in the global frame unless the name says "local".
 */
#ifndef WRAPSIM_BODY_H
#define WRAPSIM_BODY_H

#include <wrapsim/world.h>

#ifdef __cplusplus
extern "C" {
#endif

/** What moves a body. */
typedef enum ws_body_type {
    WS_BODY_DYNAMIC = 0,  /**< moved by forces (Newton-Euler) */
    WS_BODY_KINEMATIC = 1 /**< a world element: infinite mass, pose from its drive (static if none) */
} ws_body_type;

/** A body. Fill with ws_body_def_init(). */
typedef struct ws_body_def {
    uint32_t size;  /**< set by ws_body_def_init() */
    uint32_t magic; /**< set by ws_body_def_init() */
    ws_body_type type;       /**< default WS_BODY_DYNAMIC */
    ws_shape_id shape;       /**< required */
    ws_material_id material; /**< null id: the world's default material */
    double mass;             /**< kg (> 0); 0 = density x shape volume */
    double density;          /**< kg/m^3, used when mass is 0; default 1000 */
    /** Inertia tensor about the CoG in the body frame, kg m^2; all zero (default) = from the
     *  shape and the mass. Must be symmetric positive definite. */
    ws_mat3 inertia;
    double contact_layer;     /**< delta, m (>= 0); default 1e-3 */
    ws_vec3 position;         /**< CoG, m */
    ws_quat orientation;      /**< Euler parameters; normalised on create; default identity */
    ws_vec3 velocity;         /**< CoG velocity, m/s */
    ws_vec3 angular_velocity; /**< rad/s, global frame */
    const char *name;         /**< optional, copied; used in error messages */
    void *user_data;          /**< yours */
} ws_body_def;

/** Prescribed motions of kinematic bodies. */
typedef enum ws_drive_type {
    WS_DRIVE_STATIC = 0,   /**< stays where it is */
    /** Rotation about `axis` through `point` by theta(t) = rate (t - start_time) after a smooth
     *  rate ramp of length ramp_time centred on start_time (so the start is no impulse), stopping
     *  smoothly at max_angle when that is > 0. */
    WS_DRIVE_TILT = 1,
    /** Translation along `direction` by amplitude sin(2 pi frequency (t - start_time) + phase)
     *  from start_time, the amplitude ramped in smoothly over ramp_time. */
    WS_DRIVE_SINE = 2,
    /** The pose and velocities from a user function of time. */
    WS_DRIVE_CALLBACK = 3
} ws_drive_type;

/** User drive: write the pose and the global velocities at time t (s). Return 0, or non-zero to
 *  fail the step with WS_ERR_CALLBACK. */
typedef int (*ws_drive_fn)(void *user, double t, ws_pose *pose, ws_vec3 *velocity,
                           ws_vec3 *angular_velocity);

/** A drive. Fill with ws_drive_def_init(). Tilt and sine motions are relative to the body's pose
 *  when the drive is set; a callback gives the absolute (global) pose. */
typedef struct ws_drive_def {
    uint32_t size;  /**< set by ws_drive_def_init() */
    uint32_t magic; /**< set by ws_drive_def_init() */
    ws_drive_type type;  /**< default WS_DRIVE_STATIC */
    double start_time;   /**< s; tilt and sine */
    double ramp_time;    /**< s (>= 0); default 0.05 */
    ws_vec3 axis;        /**< tilt axis (normalised); default (0, 1, 0) */
    ws_vec3 point;       /**< a point on the tilt axis, m */
    double rate;         /**< tilt rate, rad/s */
    double max_angle;    /**< rad (>= 0); 0 = no limit */
    ws_vec3 direction;   /**< sine direction (normalised); default (1, 0, 0) */
    double amplitude;    /**< m */
    double frequency;    /**< Hz (>= 0) */
    double phase;        /**< rad */
    ws_drive_fn callback; /**< WS_DRIVE_CALLBACK */
    void *callback_user;  /**< passed to callback */
} ws_drive_def;

/** Fill a body Def with defaults (dynamic, density 1000 kg/m^3, layer 1 mm, identity
 *  orientation). `def` must not be NULL (NULL is ignored).
 *  ws_body_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_body_def_init_sized(ws_body_def *def, size_t size);
/** The plain form, for programs built against headers before ws_body_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_body_def_init)(ws_body_def *def);
#define ws_body_def_init(def) ws_body_def_init_sized((def), sizeof *(def))
/** Fill a drive Def with defaults (static, ramp 0.05 s, axis y, direction x). NULL is ignored.
 *  ws_drive_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_drive_def_init_sized(ws_drive_def *def, size_t size);
/** The plain form, for programs built against headers before ws_drive_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_drive_def_init)(ws_drive_def *def);
#define ws_drive_def_init(def) ws_drive_def_init_sized((def), sizeof *(def))

/** Smallest mass of a dynamic body, kg (a milligram): lighter ones are refused. */
#define WS_BODY_MIN_MASS 1e-6
/** Largest mass of a dynamic body, kg (a million tonnes): heavier ones are refused. Between the
 *  two, a body's inertia and its inverse stay far from overflow and underflow. */
#define WS_BODY_MAX_MASS 1e9

/** Create a body.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (mass <= 0 or outside [WS_BODY_MIN_MASS,
 *  WS_BODY_MAX_MASS], inertia not symmetric positive definite or its principal moments J1, J2,
 *  J3 not a rigid body's (each must be at most the sum of the other two), NaN, zero
 *  quaternion...), WS_ERR_UNINITIALIZED_DEF, WS_ERR_STALE_HANDLE (shape or material),
 *  WS_ERR_OUT_OF_MEMORY. */
WS_API ws_status ws_body_create(ws_world *world, const ws_body_def *def, ws_body_id *out);
/** Destroy a body; its contacts go with it. */
WS_API ws_status ws_body_destroy(ws_world *world, ws_body_id id);
/** 1 if the id names a live body of this world, else 0. */
WS_API int ws_body_is_valid(const ws_world *world, ws_body_id id);
/** Set the drive of a kinematic body (WS_ERR_INVALID_ARGUMENT for a dynamic one). A tilt or sine
 *  motion is relative to the pose the body has now; the body moves to the drive's pose at the current
 *  time at once (a callback is called then). On any error the previous drive stays and nothing
 *  of the new Def is kept; on success the library keeps the callback pointer and its user
 *  pointer until the drive is replaced or the body destroyed. */
WS_API ws_status ws_body_set_drive(ws_world *world, ws_body_id id, const ws_drive_def *def);

/** Dynamic or kinematic. @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (NULL). */
WS_API ws_status ws_body_get_type(const ws_world *world, ws_body_id id, ws_body_type *type);
/** CoG position, m. */
WS_API ws_status ws_body_get_position(const ws_world *world, ws_body_id id, ws_vec3 *position);
/** Euler parameters (unit). */
WS_API ws_status ws_body_get_orientation(const ws_world *world, ws_body_id id, ws_quat *q);
/** Rotation matrix A (body to global), row-major. */
WS_API ws_status ws_body_get_rotation(const ws_world *world, ws_body_id id, ws_mat3 *a);
/** CoG velocity, m/s. */
WS_API ws_status ws_body_get_velocity(const ws_world *world, ws_body_id id, ws_vec3 *v);
/** Angular velocity in the global frame, rad/s. */
WS_API ws_status ws_body_get_angular_velocity(const ws_world *world, ws_body_id id, ws_vec3 *w);
/** Angular velocity in the body frame (omega'), rad/s. */
WS_API ws_status ws_body_get_angular_velocity_local(const ws_world *world, ws_body_id id,
                                                    ws_vec3 *w);
/** Velocity (m/s) of the body point now at global position `point` (m) (eq. 3). */
WS_API ws_status ws_body_get_point_velocity(const ws_world *world, ws_body_id id,
                                            const ws_vec3 *point, ws_vec3 *v);
/** Global position (m) of a point given in the body frame (eq. 2). */
WS_API ws_status ws_body_get_world_point(const ws_world *world, ws_body_id id,
                                         const ws_vec3 *local, ws_vec3 *global);
/** Mass, kg (0 for kinematic bodies). */
WS_API ws_status ws_body_get_mass(const ws_world *world, ws_body_id id, double *mass);
/** Inertia about the CoG in the body frame, kg m^2. */
WS_API ws_status ws_body_get_inertia(const ws_world *world, ws_body_id id, ws_mat3 *j);
/** Total contact force (N, global) and moment about the CoG (N m, global) of the last step. */
WS_API ws_status ws_body_get_contact_force(const ws_world *world, ws_body_id id, ws_vec3 *force,
                                           ws_vec3 *moment);
/** Set pose (position m, orientation normalised) of a dynamic body between steps. */
WS_API ws_status ws_body_set_pose(ws_world *world, ws_body_id id, const ws_pose *pose);
/** Set velocities (m/s, rad/s global) of a dynamic body between steps. */
WS_API ws_status ws_body_set_velocity(ws_world *world, ws_body_id id, const ws_vec3 *velocity,
                                      const ws_vec3 *angular_velocity);
/** The name given in the Def ("" if none). Valid while the body lives. */
WS_API const char *ws_body_get_name(const ws_world *world, ws_body_id id);
/** The user pointer of the Def; NULL for a stale id (check ws_body_is_valid() to tell). */
WS_API void *ws_body_get_user_data(const ws_world *world, ws_body_id id);
/** Copy the ids of all live bodies, in creation order. buf may be NULL with capacity 0. */
WS_API ws_status ws_world_copy_body_ids(const ws_world *world, ws_body_id *buf, size_t capacity,
                                        size_t *count);

#ifdef __cplusplus
}
#endif

#endif
