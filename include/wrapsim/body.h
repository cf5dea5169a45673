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

/** Prescribed motions of kinematic bodies.
 *
 *  The platform tests of packaging standards are drives of the platform: the tilt (ISO 10531),
 *  the EUMOS 40509 acceleration pulse (WS_DRIVE_PULSE), the horizontal impact of ASTM D4003 /
 *  D5414 and ISTA 3E (WS_DRIVE_IMPACT), random vibration (ASTM D4169 truck, ISTA:
 *  WS_DRIVE_RANDOM) and the resonance search by a sine sweep (WS_DRIVE_SWEEP). Every
 *  translating drive moves the body along `direction` from the pose it had when the drive was
 *  set, and reports what it delivered through ws_body_get_drive_state(). */
typedef enum ws_drive_type {
    WS_DRIVE_STATIC = 0,   /**< stays where it is */
    /** Rotation about `axis` through `point` by theta(t) = rate (t - start_time) after a smooth
     *  rate ramp of length ramp_time centred on start_time (so the start is no impulse), stopping
     *  smoothly at max_angle when that is > 0 over stop_ramp_time.
     *
     *  Which way is downhill: the rotation follows the right-hand rule about `axis`. With the
     *  default axis (0, 1, 0) and rate > 0, a point at +x of the axis goes down (the x axis
     *  turns towards -z), so the table's +x edge drops and downhill is +x; with rate < 0
     *  downhill is -x. In general downhill is axis x (0, 0, 1) for rate > 0 when the table is
     *  level and the axis horizontal. */
    WS_DRIVE_TILT = 1,
    /** Translation along `direction` by amplitude sin(2 pi frequency (t - start_time) + phase)
     *  from start_time, the amplitude ramped in smoothly over ramp_time. */
    WS_DRIVE_SINE = 2,
    /** The pose and velocities from a user function of time. */
    WS_DRIVE_CALLBACK = 3,
    /** EUMOS 40509 acceleration test along `direction`. WS_PULSE_ACCELERATE: from rest at
     *  start_time the acceleration rises as a half-cosine over rise_time to `acceleration`
     *  (k g), is held for hold_time, falls as a half-cosine over rise_time, then, after
     *  coast_time at the speed reached, a gentle stop brings the platform to rest (a
     *  raised-cosine deceleration whose peak is gentle_acceleration). WS_PULSE_BRAKE: the
     *  mirror image in time: a gentle run-up from rest at start_time to the same speed, coast_time
     *  at that speed, then braking at -acceleration along `direction` (rise, hold, fall as above)
     *  to rest: the load is thrown towards +direction. */
    WS_DRIVE_PULSE = 4,
    /** Horizontal impact (ASTM D4003 / D5414, ISTA 3E) along `direction`: a gentle run-up from
     *  rest at start_time to `speed` (raised-cosine acceleration, peak gentle_acceleration),
     *  coast_time at that speed, then the programmer stops it with a half-sine deceleration of
     *  duration pulse_duration: a(tau) = -(pi speed / (2 pulse_duration)) sin(pi tau /
     *  pulse_duration), whose velocity change equals `speed`. */
    WS_DRIVE_IMPACT = 5,
    /** A sampled acceleration history along `direction` (m/s^2): table[i] at start_time + i
     *  table_interval, linear between samples, zero outside; velocity and position are its exact
     *  integrals from rest. With table_end_at_rest (default) a smooth baseline correction (two
     *  shapes that vanish at both ends) is subtracted so that the platform ends at rest where it
     *  started. The table is copied. Useful for a measured sled pulse. */
    WS_DRIVE_TABLE = 6,
    /** Random vibration along `direction` (default: set it to (0, 0, 1) for vertical): the
     *  history of ws_vibration_synthesize() from the PSD breakpoints, seed and sample_rate,
     *  played from start_time for `duration` s, tapered over ramp_time at both ends (a
     *  half-cosine window) and baseline-corrected like a table so the platform does not
     *  wander. */
    WS_DRIVE_RANDOM = 7,
    /** Sine sweep along `direction`: acceleration amplitude `acceleration` (m/s^2), frequency
     *  rising from `frequency` (f1) to frequency_end (f2) over `duration` from start_time,
     *  logarithmically (f = f1 (f2/f1)^(tau/duration)) or linearly (sweep_law); the amplitude is
     *  ramped in and out over ramp_time. The displacement is x = -(acceleration / omega(t)^2)
     *  env(t) sin(phi(t)) with phi' = 2 pi f(t), so the platform ends at rest where it started;
     *  its acceleration (reported exactly by the drive state) equals acceleration sin(phi) up to
     *  terms of relative size f'/f^2 (below 1e-3 for sweeps slower than 1 octave per 0.1 s at
     *  f1 >= 1 Hz). */
    WS_DRIVE_SWEEP = 8
} ws_drive_type;

/** Which EUMOS 40509 variant a WS_DRIVE_PULSE runs. */
typedef enum ws_pulse_mode {
    WS_PULSE_ACCELERATE = 0, /**< from rest: acceleration pulse, then a gentle stop */
    WS_PULSE_BRAKE = 1       /**< a gentle run-up, then braking at k g to rest */
} ws_pulse_mode;

/** Frequency law of a WS_DRIVE_SWEEP. */
typedef enum ws_sweep_law {
    WS_SWEEP_LOG = 0,   /**< f = f1 (f2/f1)^(tau/T): equal time per octave */
    WS_SWEEP_LINEAR = 1 /**< f = f1 + (f2 - f1) tau / T */
} ws_sweep_law;

/** The ASTM D4169 truck levels (D4169-16 calls them low, medium, high). */
typedef enum ws_truck_level {
    WS_TRUCK_LOW = 1,    /**< 0.40 Grms */
    WS_TRUCK_MEDIUM = 2, /**< 0.54 Grms */
    WS_TRUCK_HIGH = 3    /**< 0.70 Grms */
} ws_truck_level;

/** Standard gravity, m/s^2: the "g" of the PSD levels (g^2/Hz) and of Grms. */
#define WS_STANDARD_GRAVITY 9.80665

/** User drive: write the pose and the global velocities at time t (s). Return 0, or non-zero to
 *  fail the step with WS_ERR_CALLBACK. */
typedef int (*ws_drive_fn)(void *user, double t, ws_pose *pose, ws_vec3 *velocity,
                           ws_vec3 *angular_velocity);

/** A drive. Fill with ws_drive_def_init(). Tilt and translating motions are relative to the
 *  body's pose when the drive is set; a callback gives the absolute (global) pose. Fields after
 *  `callback_user` were added in 0.2 (old callers, with a smaller Def, get their defaults). */
typedef struct ws_drive_def {
    uint32_t size;  /**< set by ws_drive_def_init() */
    uint32_t magic; /**< set by ws_drive_def_init() */
    ws_drive_type type;  /**< default WS_DRIVE_STATIC */
    double start_time;   /**< s, |start_time| <= 1e9; every drive but static and callback */
    /** s (>= 0); default 0.05. Tilt: the start's rate ramp. Sine: the amplitude's fade-in.
     *  Sweep: fade-in and fade-out. Random: the half-cosine taper at both ends. */
    double ramp_time;
    ws_vec3 axis;        /**< tilt axis (normalised); default (0, 1, 0) */
    ws_vec3 point;       /**< a point on the tilt axis, m */
    double rate;         /**< tilt rate, rad/s (> 0 turns by the right-hand rule about axis) */
    double max_angle;    /**< rad (>= 0); 0 = no limit */
    /** Direction of a translating drive (sine, pulse, impact, table, random, sweep),
     *  normalised; default (1, 0, 0) */
    ws_vec3 direction;
    double amplitude;    /**< sine, m */
    double frequency;    /**< sine: Hz (>= 0); sweep: start frequency f1, Hz (> 0) */
    double phase;        /**< sine, rad */
    ws_drive_fn callback; /**< WS_DRIVE_CALLBACK */
    void *callback_user;  /**< passed to callback */

    /* ---- added in 0.2 ---- */
    /** Tilt: s (>= 0), the rate ramp that stops the table at max_angle, centred on the time the
     *  free angle would reach it, so the angle settles exactly on max_angle. Default 1.0 s: the
     *  stop's angular deceleration then peaks at 1.5 |rate| / stop_ramp_time (0.15 rad/s^2 at
     *  0.1 rad/s), gentle enough that a block 1 deg short of tipping at max_angle does not tip
     *  when the table stops (a 50 ms stop, 3 rad/s^2, can topple it). Shortened to fit when
     *  max_angle is too small for it (the stop ramp then starts where the start ramp ends). */
    double stop_ramp_time;
    /** Pulse: the plateau acceleration k g, m/s^2 (> 0). Sweep: acceleration amplitude, m/s^2
     *  (> 0). */
    double acceleration;
    double rise_time;  /**< pulse: s (> 0), half-cosine rise and fall; default 0.05 (EUMOS) */
    double hold_time;  /**< pulse: s (>= 0), the plateau; default 0.3 (EUMOS: at least 0.3 s) */
    ws_pulse_mode pulse_mode; /**< pulse: default WS_PULSE_ACCELERATE */
    /** Pulse and impact: peak acceleration of the gentle run-up or stop, m/s^2 (> 0); default
     *  1.0 (about 0.1 g). Such a phase lasts 2 v / gentle_acceleration for a speed v. */
    double gentle_acceleration;
    /** Pulse and impact: s (>= 0) at constant speed between the gentle phase and the pulse (so
     *  the load settles after the run-up, or before the stop); default 0.5 */
    double coast_time;
    double speed;          /**< impact: speed at impact, m/s (> 0), e.g. 1.2 or 1.75 */
    double pulse_duration; /**< impact: half-sine duration, s (> 0); default 0.01 */
    /** Table: accelerations along direction, m/s^2, sampled every table_interval; copied when
     *  the drive is set (may be freed after). */
    const double *table;
    size_t table_count;     /**< table: number of samples (>= 2) */
    double table_interval;  /**< table: s (> 0) */
    int table_end_at_rest;  /**< table: 1 (default) = baseline-corrected to end at rest */
    /** Random: PSD breakpoints, frequencies in Hz (> 0, strictly increasing); copied */
    const double *psd_frequency;
    const double *psd_level; /**< random: one-sided PSD, g^2/Hz (> 0); log-log between */
    size_t psd_count;        /**< random: number of breakpoints (>= 2) */
    uint64_t seed;           /**< random: the seed of the phases; the same seed, the same history */
    double duration;         /**< random, sweep: s (> 0) */
    /** Random: samples per second, Hz (> 2 x the highest breakpoint); default 1024 */
    double sample_rate;
    double frequency_end;    /**< sweep: end frequency f2, Hz (> 0) */
    ws_sweep_law sweep_law;  /**< sweep: default WS_SWEEP_LOG */
} ws_drive_def;

/** What a drive delivers, at the world's current time (see ws_body_get_drive_state()). Vectors
 *  are global; position, velocity and acceleration are those of the body's CoG. */
typedef struct ws_drive_state {
    double time;           /**< s, the world's time */
    ws_drive_type type;    /**< the drive's type (WS_DRIVE_STATIC for a body without drive) */
    ws_vec3 position;      /**< CoG, m */
    /** m: CoG position minus its position when the drive was set (for a callback: zero) */
    ws_vec3 displacement;
    ws_vec3 velocity;      /**< CoG velocity, m/s */
    /** CoG acceleration, m/s^2 (exact, from the drive's law; for a callback: zero, see
     *  has_acceleration) */
    ws_vec3 acceleration;
    ws_vec3 angular_velocity; /**< rad/s */
    /** Tilt: the angle turned about the axis, rad (right-hand rule); others: 0 */
    double angle;
    double angular_rate;         /**< tilt: d angle / dt, rad/s */
    double angular_acceleration; /**< tilt: rad/s^2 */
    /** 1 when acceleration (and angular_acceleration) come from the drive's law; 0 for a
     *  callback, which gives pose and velocities only */
    int has_acceleration;
} ws_drive_state;

/** Fill a body Def with defaults (dynamic, density 1000 kg/m^3, layer 1 mm, identity
 *  orientation). `def` must not be NULL (NULL is ignored).
 *  ws_body_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_body_def_init_sized(ws_body_def *def, size_t size);
/** The plain form, for programs built against headers before ws_body_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_body_def_init)(ws_body_def *def);
#define ws_body_def_init(def) ws_body_def_init_sized((def), sizeof *(def))
/** Fill a drive Def with defaults (static, ramp 0.05 s, axis y, direction x, stop ramp 1 s, rise
 *  0.05 s, hold 0.3 s, gentle acceleration 1 m/s^2, coast 0.5 s, impact pulse 0.01 s, table
 *  ending at rest, sample rate 1024 Hz, log sweep). NULL is ignored.
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
/** What the drive of a kinematic body delivers now (at the world's time): CoG position,
 *  displacement since the drive was set, velocity and acceleration, angular velocity, and for a
 *  tilt its angle, rate and angular acceleration. Valid for every drive type; a kinematic body
 *  without a drive reports a static one. A callback drive reports the committed pose and
 *  velocities with zero acceleration and has_acceleration = 0.
 *  @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (a dynamic body, NULL out). */
WS_API ws_status ws_body_get_drive_state(const ws_world *world, ws_body_id id,
                                         ws_drive_state *out);

/** Synthesise a random vibration history (the WS_DRIVE_RANDOM drive's) into `accel`, m/s^2:
 *  `count` samples at def->sample_rate of a periodic Gaussian-like history whose one-sided PSD
 *  follows def's breakpoints (psd_frequency, psd_level in g^2/Hz, log-log between them, zero
 *  outside), by the inverse FFT: each frequency bin k (k sample_rate / count) inside the band
 *  gets the amplitude sqrt(2 G(f_k) df) g and a phase uniform in [0, 2 pi) drawn from
 *  def->seed (a generator of the library, no global state), so the same Def gives the same
 *  history to the bit on every machine. The history's mean is zero and its mean square is the
 *  sum of G(f_k) df g^2 (the PSD's integral within the bins' resolution). `count` must be a
 *  power of two >= 16. def->type is not looked at. `world` may be NULL: it only receives the
 *  error text.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, count not a power of two, bad breakpoints,
 *  sample_rate not above twice the highest breakpoint), WS_ERR_UNINITIALIZED_DEF. */
WS_API ws_status ws_vibration_synthesize(ws_world *world, const ws_drive_def *def, double *accel,
                                         size_t count);
/** The Grms (in g) of a PSD given by breakpoints (Hz, g^2/Hz, log-log interpolation): the
 *  square root of its exact integral between the first and the last breakpoint.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, count < 2, frequencies not > 0 and increasing,
 *  levels not > 0). */
WS_API ws_status ws_vibration_grms(const double *frequency, const double *level, size_t count,
                                   double *grms);
/** The library's truck spectrum for random vibration at an ASTM D4169 truck level (0.40,
 *  0.54 or 0.70 Grms): breakpoints (Hz, g^2/Hz) written into the caller's arrays, scaled so
 *  their Grms is the level's exactly. The shape (see docs/guide.md) is the library's rendering
 *  of a steel-spring truck spectrum, 1-200 Hz; check it against the edition of the standard
 *  you test to. Either array may be NULL with capacity 0 to ask the count.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (unknown level, NULL count),
 *  WS_ERR_BUFFER_TOO_SMALL (count says how many). */
WS_API ws_status ws_vibration_truck_psd(ws_truck_level level, double *frequency, double *level_g2hz,
                                        size_t capacity, size_t *count);

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
