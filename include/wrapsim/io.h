/**
 * @file io.h
 * @brief Output engineers open: VTK PolyData frames (.vtp) and a ParaView collection (.pvd).
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

/** Write the bodies of the world as one VTK PolyData file (XML, ASCII): every body's triangles
 *  in global coordinates, with cell data "body" (index) and point data "velocity" (m/s).
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT, WS_ERR_IO (the path in the last error). */
WS_API ws_status ws_world_write_vtp(ws_world *world, const char *path);

/** Write one web (film) as a VTK PolyData file (XML, ASCII), in its state now.
 *  Points: the nodes (m, global). Cells: every spring as a line (its two nodes), then, for a grid
 *  web (a sheet or a band), every grid cell as a quad (i, j), (i+1, j), (i+1, j+1), (i, j+1),
 *  wrapping around i for a closed band.
 *  Point data: "velocity" (m/s), "contact_force" (N, the force of the bodies on the node in the
 *  last step, as ws_web_copy_contact_forces), "tension" (N, the mean tension of the springs that
 *  end at the node; negative in compression) and "strain" (the mean strain l/l0 - 1 of those
 *  springs); 0 for a node without springs.
 *  Cell data, the same for both kinds of cell so a viewer can colour the surface by them:
 *  "tension" (N) and "strain" of the spring of a line, the mean of the four edge springs of a
 *  quad.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (world NULL, path NULL or empty),
 *  WS_ERR_STALE_HANDLE (web), WS_ERR_IO (the path in the last error). */
WS_API ws_status ws_web_write_vtp(ws_world *world, ws_web_id web, const char *path);

/** A time series of .vtp frames collected in a .pvd file for ParaView. The series calls report
 *  their details through ws_world_last_error() of the world the series was created on. */
typedef struct ws_vtk_series ws_vtk_series;

/** Start a series in `directory` (it must exist). Each frame writes `basename`_NNNNNN.vtp (the
 *  bodies, as ws_world_write_vtp) and `basename`_web<k>_NNNNNN.vtp for every web alive then (as
 *  ws_web_write_vtp; k is the web's slot in the world: 0, 1, ... in the order webs are created,
 *  a destroyed web's slot taken again by the next one). `basename`.pvd collects them: the bodies
 *  are its part 0 and the web of slot k its part 1 + k, so ParaView shows bodies and film
 *  together. Uses the world's allocator. */
WS_API ws_status ws_vtk_series_create(ws_world *world, const char *directory,
                                      const char *basename, ws_vtk_series **out);
/** Write the world now as the next frame (bodies and every web), stamped with the world time,
 *  and rewrite the .pvd so it is always complete and lists only whole frames.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (series NULL), WS_ERR_OUT_OF_MEMORY, WS_ERR_IO. */
WS_API ws_status ws_vtk_series_write_frame(ws_vtk_series *series);
/** Frames written so far. */
WS_API ws_status ws_vtk_series_get_frame_count(const ws_vtk_series *series, size_t *count);
/** Close the series (the files stay). NULL is allowed. Destroy it before its world. */
WS_API void ws_vtk_series_destroy(ws_vtk_series *series);

/** The save format this library writes; it reads this one and the older ones. */
#define WS_SAVE_FORMAT_VERSION 1

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
