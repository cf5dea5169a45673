/**
 * @file io.h
 * @brief Output engineers open: VTK PolyData frames (.vtp) and a ParaView collection (.pvd).
 *
 * These calls write files only when asked; nothing else in the library touches the file system.
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

/** Start a series in `directory`, which must exist (else WS_ERR_IO naming it). Each frame writes `basename`_NNNNNN.vtp (the
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

#ifdef __cplusplus
}
#endif

#endif
