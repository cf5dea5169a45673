/**
 * @file io.h
 * @brief Output engineers open: VTK PolyData frames (.vtp) and a ParaView collection (.pvd).
 *
 * These calls write files only when asked; nothing else in the library touches the file system.
 */
#ifndef WRAPSIM_IO_H
#define WRAPSIM_IO_H

#include <wrapsim/world.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Write the bodies of the world as one VTK PolyData file (XML, ASCII): every body's triangles
 *  in global coordinates, with cell data "body" (index) and point data "velocity" (m/s).
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT, WS_ERR_IO (the path in the last error). */
WS_API ws_status ws_world_write_vtp(ws_world *world, const char *path);

/** A time series of .vtp frames collected in a .pvd file for ParaView. */
typedef struct ws_vtk_series ws_vtk_series;

/** Start a series: frames go to `directory`/`basename`_NNNNNN.vtp and the collection to
 *  `directory`/`basename`.pvd (the directory must exist). Uses the world's allocator. */
WS_API ws_status ws_vtk_series_create(ws_world *world, const char *directory,
                                      const char *basename, ws_vtk_series **out);
/** Write the world now as the next frame, stamped with the world time, and rewrite the .pvd so
 *  it is always complete. */
WS_API ws_status ws_vtk_series_write_frame(ws_vtk_series *series);
/** Frames written so far. */
WS_API ws_status ws_vtk_series_get_frame_count(const ws_vtk_series *series, size_t *count);
/** Close the series (the files stay). NULL is allowed. Destroy it before its world. */
WS_API void ws_vtk_series_destroy(ws_vtk_series *series);

#ifdef __cplusplus
}
#endif

#endif
