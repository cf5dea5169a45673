/**
 * @file common.h
 * @brief Basic types shared by every part of the libwrapsim API: status codes, vectors, ids,
 *        allocator and log hooks, versions.
 *
 * Units are SI throughout: metre, kilogram, second, newton, radian.
 */
#ifndef WRAPSIM_COMMON_H
#define WRAPSIM_COMMON_H

#include <stddef.h>
#include <stdint.h>

#include <wrapsim/version.h>

#if defined(_WIN32) && defined(WS_BUILDING_LIBRARY)
#define WS_API __declspec(dllexport)
#elif defined(_WIN32) && !defined(WS_STATIC)
#define WS_API __declspec(dllimport)
#elif defined(__GNUC__) && defined(WS_BUILDING_LIBRARY)
#define WS_API __attribute__((visibility("default")))
#else
#define WS_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** Result of every call that can fail. WS_OK is zero; every error is positive. */
typedef enum ws_status {
    WS_OK = 0,
    WS_ERR_INVALID_ARGUMENT = 1, /**< a value out of range, NaN/inf, a NULL pointer */
    WS_ERR_UNINITIALIZED_DEF = 2, /**< a Def not filled by its ws_*_def_init() */
    WS_ERR_STALE_HANDLE = 3,      /**< an id that was destroyed, is null, or is from another world */
    WS_ERR_OUT_OF_MEMORY = 4,     /**< the allocator hook returned NULL; nothing was changed */
    WS_ERR_NUMERICAL = 5,         /**< NaN, inf or runaway energy in a step; the step was undone */
    WS_ERR_BAD_MESH = 6,          /**< a mesh that is open, degenerate or inconsistently wound */
    WS_ERR_IN_USE = 7,            /**< an object still referenced (a shape used by a body) */
    WS_ERR_CALLBACK = 8,          /**< a user callback reported failure */
    WS_ERR_BUFFER_TOO_SMALL = 9,  /**< a bulk copy got less room than it needs; count says how much */
    WS_ERR_IO = 10,               /**< a file could not be read or written */
    WS_ERR_UNSUPPORTED = 11,      /**< a feature this build does not have (e.g. libccd) */
    /** a call that changes the world (create, destroy, set, step) made from a callback inside
     *  ws_world_step; getters are allowed there */
    WS_ERR_IN_STEP = 12,
    WS_ERR_FORMAT = 13            /**< a saved state that is truncated, corrupted, of a newer
                                       format or of a world built otherwise; nothing changed */
} ws_status;

/** A vector in metres, m/s, newtons ... as the call says. */
typedef struct ws_vec3 {
    double x; /**< first component */
    double y; /**< second component */
    double z; /**< third component (up in the examples) */
} ws_vec3;

/** Euler parameters (a unit quaternion), e0 = cos(phi/2), (e1, e2, e3) = u sin(phi/2) (eq. 4-5). */
typedef struct ws_quat {
    double e0; /**< cos(phi/2) */
    double e1; /**< u_x sin(phi/2) */
    double e2; /**< u_y sin(phi/2) */
    double e3; /**< u_z sin(phi/2) */
} ws_quat;

/** A 3x3 matrix, row-major: m[3*row + col]. */
typedef struct ws_mat3 {
    double m[9]; /**< entries, row-major */
} ws_mat3;

/** Position (m) and orientation of a body frame in the global frame. */
typedef struct ws_pose {
    ws_vec3 position;    /**< origin of the body frame (the CoG), m */
    ws_quat orientation; /**< Euler parameters, unit */
} ws_pose;

/* Defs. Every ws_x_def starts with its size and a magic number. ws_x_def_init(def) is a macro
 * calling the exported ws_x_def_init_sized(def, sizeof *def): it fills the caller's Def with
 * defaults, min(size, the library's sizeof) bytes of it and zeros past them, and records that
 * size in def->size. ws_x_create reads only def->size bytes and gives every later field its
 * default, so a program built against an older, smaller Def keeps working with a newer library
 * and its stack is never written past its Def. The plain function ws_x_def_init, reached by
 * programs built against headers before the sized form, fills the layout of those headers. */

/* Ids: opaque 64-bit values, [kind:4][generation:32][slot+1:28]; zero is the null id. Every call
 * that takes an id refuses a destroyed one (WS_ERR_STALE_HANDLE) in any lifetime: a slot whose
 * 32-bit generation would repeat is retired, never reused. An id of another world is refused
 * except with odds of about 2^-32 per call (generations start from a per-world random salt).
 * Each kind
 * has its own type so that a body id cannot be passed where a shape id is expected. */
/** A rigid body or world element. */
typedef struct ws_body_id {
    uint64_t bits; /**< opaque; 0 = null */
} ws_body_id;
/** A shape (a closed triangle mesh in its body frame), shareable by many bodies. */
typedef struct ws_shape_id {
    uint64_t bits; /**< opaque; 0 = null */
} ws_shape_id;
/** A contact material; contact parameters are set per pair of materials. */
typedef struct ws_material_id {
    uint64_t bits; /**< opaque; 0 = null */
} ws_material_id;

/** Memory hooks; all NULL means malloc/realloc/free. Either all three are given or none. */
typedef struct ws_allocator {
    void *(*alloc)(void *user, size_t bytes); /**< new block, or NULL */
    /** grow or shrink a block (sizes as allocated), or NULL leaving it as it was */
    void *(*realloc)(void *user, void *ptr, size_t old_bytes, size_t new_bytes);
    void (*free)(void *user, void *ptr, size_t bytes); /**< release a block of that size */
    void *user; /**< passed to the three hooks */
} ws_allocator;

/** Severity of a log message. */
typedef enum ws_log_level {
    WS_LOG_DEBUG = 0,
    WS_LOG_INFO = 1,
    WS_LOG_WARNING = 2,
    WS_LOG_ERROR = 3
} ws_log_level;

/** Log hook: the library never prints; it calls this when given one. `message` is valid only
 *  during the call. */
typedef void (*ws_log_fn)(void *user, ws_log_level level, const char *message);

/** Static text naming a status ("WS_ERR_STALE_HANDLE: ..."); never NULL. */
WS_API const char *ws_status_string(ws_status status);

/** Runtime version as major*10000 + minor*100 + patch; compare with WS_VERSION_NUMBER. */
WS_API int ws_version_number(void);
/** Runtime version as text, e.g. "0.1.0". */
WS_API const char *ws_version_string(void);

/** Optional features built in. */
enum {
    WS_FEATURE_CCD = 1, /**< libccd narrow-phase gate available */
    WS_FEATURE_ZLIB = 2 /**< zlib-compressed VTK output (WS_VTK_COMPRESSED) available */
};
/** Bit set of WS_FEATURE_* compiled into this library. */
WS_API unsigned ws_build_features(void);

#ifdef __cplusplus
}
#endif

#endif
