/**
 * @file io.h
 * @brief Output engineers open: VTK PolyData files (.vtp), named multiblock frames (.vtm) and a
 *        ParaView time collection (.pvd).
 *
 * These calls write files only when asked; nothing else in the library touches the file system.
 *
 * And a world's state saved and restored (checkpoint/restart): ws_world_save() and
 * ws_world_restore() to and from memory, ws_world_save_file() and ws_world_restore_file() to and
 * from a file. A save holds the state, not the structure: restore into a world that the program
 * has built as it built the saved one (the same shapes, bodies, webs, elements and laws, created
 * in the same order), then stepping it gives, bit for bit, the steps the saved world would have
 * taken. Parameters (dt, gravity, materials and contact parameters, masses, drives, laws) are the
 * program's: a study may change them after a restore. The format: a 32-byte header (the magic
 * "WSSTATE" and a zero byte, the format version as a 32-bit number, the byte-order mark
 * 0x01020304, the state's length in bytes as a 64-bit number, the 64-bit FNV-1a hash of the
 * state), then the state; every number little-endian, doubles as their IEEE 754 bits.
 */
#ifndef WRAPSIM_IO_H
#define WRAPSIM_IO_H

#include <wrapsim/web.h>
#include <wrapsim/world.h>

#ifdef __cplusplus
extern "C" {
#endif

/** The form of the VTK XML files. */
typedef enum ws_vtk_format {
    /** Binary data appended after the XML, each array zlib-compressed (VTK's
     *  vtkZLibDataCompressor). A library built without zlib (ws_build_features() without
     *  WS_FEATURE_ZLIB) writes WS_VTK_BINARY instead. The default: about a tenth of ASCII. */
    WS_VTK_COMPRESSED = 0,
    /** Binary data appended after the XML, uncompressed. */
    WS_VTK_BINARY = 1,
    /** Every value as text inside its element: large, readable by eye and by simple scripts. */
    WS_VTK_ASCII = 2
} ws_vtk_format;

/** Height bands of the containment profile written with a film unless a series asks otherwise. */
#define WS_VTK_DEFAULT_BANDS 10
/** Most height bands a film file carries. */
#define WS_VTK_MAX_BANDS 256

/** Write the bodies of the world as one VTK PolyData file (XML, ASCII): every body's triangles
 *  in global coordinates (m).
 *  Point data: "velocity" (m/s).
 *  Cell data: "body" (the body's index among the bodies alive, in the order of the field data
 *  below), "body_id" (its ws_body_id bits) and "contact_force" (N, the body's total contact force
 *  of the last step, as ws_body_get_contact_force, on each of its triangles).
 *  Field data: "TimeValue" (s), "body_name" (a string per body, "" when it has none) and
 *  "body_id", one entry per body.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (world NULL, path NULL or empty), WS_ERR_OUT_OF_MEMORY,
 *  WS_ERR_IO (the path in the last error). */
WS_API ws_status ws_world_write_vtp(ws_world *world, const char *path);

/** Write one web (film) as a VTK PolyData surface file (XML, ASCII), in its state now.
 *  Points: the nodes (m, global). Cells: for a grid web (a sheet or a band) the grid's quads (i, j),
 *  (i+1, j), (i+1, j+1), (i, j+1), wrapping around i for a closed band; for a mesh web its springs
 *  as lines.
 *  Point data: "velocity" (m/s), "contact_force" (N, the force of the bodies on the node in the
 *  last step, as ws_web_copy_contact_forces), "tension_around" and "tension_up" (N, the mean
 *  tension of the springs of that direction that end at the node; 0 where none; negative in
 *  compression).
 *  Cell data of the quads: "tension_around", "tension_up" (N, the mean of the quad's two edge
 *  springs of that direction) and "strain_around", "strain_up" (l/l0 - 1, likewise). Cell data of
 *  a mesh web's lines: "tension" (N), "strain" and "kind" (ws_spring_kind) of the spring.
 *  Field data: "TimeValue" (s), "web_name", "web_id", and for a grid web the containment profile
 *  in WS_VTK_DEFAULT_BANDS height bands (fewer when it has fewer rows), bottom to top, as
 *  ws_web_get_containment: "band_z_low", "band_z_high" (m), "band_hoop_tension" (N),
 *  "band_line_load" (N/m), "band_contact_force" (N).
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (world NULL, path NULL or empty, a grid web whose
 *  springs are not numbered as a grid), WS_ERR_STALE_HANDLE (web), WS_ERR_OUT_OF_MEMORY,
 *  WS_ERR_IO (the path in the last error). */
WS_API ws_status ws_web_write_vtp(ws_world *world, ws_web_id web, const char *path);

/** A time series of frames collected in a .pvd file for ParaView. The series calls report
 *  their details through ws_world_last_error() of the world the series was created on. */
typedef struct ws_vtk_series ws_vtk_series;

/** What a series writes, and how often. */
typedef struct ws_vtk_series_def {
    uint32_t size;         /**< set by ws_vtk_series_def_init() */
    uint32_t magic;        /**< set by ws_vtk_series_def_init() */
    const char *directory; /**< where the files go (it must exist); required */
    const char *basename;  /**< start of every file name, without '/'; required */
    int format;            /**< ws_vtk_format; default WS_VTK_COMPRESSED */
    /** Write every frame_stride-th call of ws_vtk_series_write_frame (>= 1); default 1. */
    int frame_stride;
    /** s (>= 0): at most one frame per multiple of time_stride of world time, the first call
     *  always written; 0 (default): no time stride. With a step dt, a call every step and
     *  time_stride = 0.1 write the frames at t = 0, 0.1, 0.2, ... */
    double time_stride;
    int springs;           /**< 1: add the block "springs" (each web's springs as lines); default 0 */
    int contacts;          /**< 1 (default): add the block "contacts"; 0: leave it out */
    /** Height bands of each grid film's containment profile (0..WS_VTK_MAX_BANDS; capped at the
     *  film's rows; 0: none); default WS_VTK_DEFAULT_BANDS. */
    int containment_bands;
    /** 0 (default): real values as Float32 (7 significant digits: 0.1 um over a metre, half the
     *  size); 1: as Float64, every digit of the state. Integers and ids are exact either way. */
    int double_precision;
} ws_vtk_series_def;

/** Fill a series Def with its defaults (compressed, Float32, every call, contacts, no
 *  springs). ws_vtk_series_def_init(def) calls this with size = sizeof *def as the caller
 *  compiled it (see "Defs" in common.h). */
WS_API void ws_vtk_series_def_init_sized(ws_vtk_series_def *def, size_t size);
/** The plain form of the init (the whole Def of these headers). New code reaches the macro
 *  below. */
WS_API void(ws_vtk_series_def_init)(ws_vtk_series_def *def);
/** Fill a series Def with its defaults: ws_vtk_series_def_init_sized with the caller's sizeof. */
#define ws_vtk_series_def_init(def) ws_vtk_series_def_init_sized((def), sizeof *(def))

/** Start a series in def->directory, which must exist (else WS_ERR_IO naming it). Each frame
 *  written is `basename`_NNNNNN.vtm, a VTK multiblock whose named
 *  blocks are, in this order:
 *  - "bodies": `basename`_NNNNNN_bodies.vtp, as ws_world_write_vtp;
 *  - "film": a dataset per web alive then, named after the web ("web<k>" for an unnamed one, k its
 *    slot), `basename`_NNNNNN_film<k>.vtp, as ws_web_write_vtp with def->containment_bands bands;
 *  - "contacts" (when def->contacts): `basename`_NNNNNN_contacts.vtp, the active contacts of the
 *    last step as vertices at their points (m), with point data "normal" (unit, from body_a to
 *    body_b), "normal_force" (N, vector, the force on body_b), "normal_force_N" (N, its size),
 *    "friction_force" (N, on body_b), "slip_velocity" (m/s), "overlap" (m), "body_a", "body_b"
 *    (indices into the bodies' field data), "kind" (ws_contact_kind), "slipping" (0 or 1);
 *  - "springs" (when def->springs): a dataset per web, `basename`_NNNNNN_springs<k>.vtp, every
 *    spring a line with cell data "tension" (N), "strain" and "kind".
 *  `basename`.pvd lists the frames with their world times. Every file carries "TimeValue".
 *  Uses the world's allocator.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (world or out NULL, no directory or basename, '/' in
 *  the basename, a value out of its range: the last error names it),
 *  WS_ERR_UNINITIALIZED_DEF, WS_ERR_IO (the directory does not exist or is not one),
 *  WS_ERR_OUT_OF_MEMORY. */
WS_API ws_status ws_vtk_series_create_def(ws_world *world, const ws_vtk_series_def *def,
                                          ws_vtk_series **out);

/** Start a series with the defaults of ws_vtk_series_def_init() in `directory` with `basename`:
 *  as ws_vtk_series_create_def. */
WS_API ws_status ws_vtk_series_create(ws_world *world, const char *directory,
                                      const char *basename, ws_vtk_series **out);
/** Offer the world now as the next frame: written (all its blocks, stamped with the world time,
 *  and the .pvd rewritten so it always lists only whole frames) when the strides of the series
 *  allow it, skipped otherwise. Call it every step, or as often as you like: the strides decide.
 *  @return WS_OK (written or skipped: ws_vtk_series_get_frame_count tells),
 *  WS_ERR_INVALID_ARGUMENT (series NULL, a grid web whose springs are not numbered as a grid),
 *  WS_ERR_OUT_OF_MEMORY, WS_ERR_IO. */
WS_API ws_status ws_vtk_series_write_frame(ws_vtk_series *series);
/** Frames written so far. */
WS_API ws_status ws_vtk_series_get_frame_count(const ws_vtk_series *series, size_t *count);
/** Close the series (the files stay). NULL is allowed. Destroy it before its world. */
WS_API void ws_vtk_series_destroy(ws_vtk_series *series);

/** The save format this library writes; it reads this one and the older ones. Version 2 adds
 *  the webs' rupture (broken springs); a version 1 save restores with none broken. */
#define WS_SAVE_FORMAT_VERSION 2

/** Save the world's state into `buf` (`cap` bytes): the time and step count, every body's
 *  position, orientation and velocities, every web's node positions and velocities and its
 *  springs' law histories, every element's law history, the stick-friction anchors, the contact
 *  caches of bodies and webs with their detection bookkeeping (how many steps since the last
 *  full detection, how far the bodies may have moved since), and what the last step reported
 *  (contacts, the film's contact forces and loads on the bodies). Call it with `buf` NULL (and
 *  `cap` 0) to learn the size first.
 *  @param needed receives the bytes the save takes (always).
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (world or needed NULL, buf NULL with cap > 0),
 *  WS_ERR_BUFFER_TOO_SMALL (cap < *needed; nothing written). */
WS_API ws_status ws_world_save(const ws_world *world, void *buf, size_t cap, size_t *needed);

/** Restore a state saved by ws_world_save() into a world built as the saved one was. Everything
 *  in the buffer is checked before anything changes: on any error the world is as it was.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (world NULL, buf NULL), WS_ERR_FORMAT with the reason
 *  in the last error: truncated, not a saved state, "checksum mismatch", "version 3 is newer than
 *  this library's 1", or a structure that differs ("web 2 has 5856 nodes in the file, 100
 *  here"); WS_ERR_OUT_OF_MEMORY (room for the contact caches). */
WS_API ws_status ws_world_restore(ws_world *world, const void *buf, size_t len);

/** ws_world_save() into a file: written whole to `path`.tmp, then renamed over `path`, so a
 *  crash while saving leaves any older file at `path` as it was. Uses the world's allocator for
 *  one buffer of the save's size.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL or empty path), WS_ERR_OUT_OF_MEMORY, WS_ERR_IO
 *  (the path and the system's reason in the last error). */
WS_API ws_status ws_world_save_file(const ws_world *world, const char *path);

/** ws_world_restore() from a file written by ws_world_save_file(); on any error the world is as
 *  it was.
 *  @return as ws_world_restore(), and WS_ERR_IO (cannot open or read `path`). */
WS_API ws_status ws_world_restore_file(ws_world *world, const char *path);

#ifdef __cplusplus
}
#endif

#endif
