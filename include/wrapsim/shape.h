/**
 * @file shape.h
 * @brief Shapes: closed triangle meshes in their body frame, shared by bodies.
 *
 * A shape is re-centred on its volume centroid when it is created, so a body's position is its
 * centre of gravity (for uniform density). Points, feature edges (between faces that are not
 * coplanar) and faces (coplanar groups of triangles) are derived once and used by the contact
 * checks.
 */
#ifndef WRAPSIM_SHAPE_H
#define WRAPSIM_SHAPE_H

#include <wrapsim/world.h>

#ifdef __cplusplus
extern "C" {
#endif

/** A closed triangle mesh. Fill with ws_mesh_def_init(). */
typedef struct ws_mesh_def {
    uint32_t size;  /**< set by ws_mesh_def_init() */
    uint32_t magic; /**< set by ws_mesh_def_init() */
    const double *vertices;    /**< xyz triples, m, in any frame; copied */
    size_t vertex_count;       /**< number of vertices (>= 4) */
    const uint32_t *triangles; /**< index triples, counter-clockwise seen from outside; copied */
    size_t triangle_count;     /**< number of triangles (>= 4) */
} ws_mesh_def;

/** What a shape is made of, after creation. */
typedef struct ws_shape_info {
    double volume;        /**< m^3 */
    ws_vec3 centroid;     /**< the volume centroid in the frame the vertices were given in, m;
                               subtracted from every vertex */
    ws_vec3 aabb_min;     /**< bounding box in the body frame, low corner, m */
    ws_vec3 aabb_max;     /**< high corner, m */
    ws_mat3 inertia_unit; /**< inertia about the centroid for density 1 kg/m^3, kg m^2 */
    uint32_t point_count;    /**< vertices */
    uint32_t edge_count;     /**< feature edges (used by line-to-line contact) */
    uint32_t face_count;     /**< coplanar groups of triangles */
    uint32_t triangle_count; /**< triangles */
    int convex;              /**< 1 if the mesh is convex */
} ws_shape_info;

/** Fill a mesh Def with defaults (no vertices).
 *  ws_mesh_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_mesh_def_init_sized(ws_mesh_def *def, size_t size);
/** The plain form, for programs built against headers before ws_mesh_def_init_sized: fills
 *  the Def as those headers laid it out, never more. New code reaches the macro below. */
WS_API void(ws_mesh_def_init)(ws_mesh_def *def);
#define ws_mesh_def_init(def) ws_mesh_def_init_sized((def), sizeof *(def))

/** Largest magnitude of a mesh vertex coordinate, m. Beyond it a mesh's areas and volumes
 *  overflow, and no load is that large; such a vertex is refused (WS_ERR_INVALID_ARGUMENT). */
#define WS_MESH_MAX_COORD 1e6
/** Smallest extent (largest side of the bounding box) of a mesh, m; a smaller one is refused
 *  (WS_ERR_BAD_MESH). */
#define WS_MESH_MIN_EXTENT 1e-6

/** A box with full edge lengths lx, ly, lz (m, each > 0 and at most 2 WS_MESH_MAX_COORD),
 *  centred on the origin.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT, WS_ERR_OUT_OF_MEMORY, WS_ERR_STALE_HANDLE never. */
WS_API ws_status ws_shape_create_box(ws_world *world, double lx, double ly, double lz,
                                     ws_shape_id *out);
/** A right prism approximating a cylinder of radius r and height h (m) along z with `segments`
 *  sides (3..1024), centred on the origin. */
WS_API ws_status ws_shape_create_cylinder(ws_world *world, double radius, double height,
                                          int segments, ws_shape_id *out);
/** A closed mesh. Validated: indices in range, finite coordinates, no degenerate triangle, every
 *  edge shared by exactly two triangles wound oppositely, positive volume. The mesh is
 *  re-centred on its volume centroid, so a body's position is its centre of gravity: the body
 *  frame's origin is NOT the origin the vertices were given in. ws_shape_get_centroid_offset()
 *  says by how much it moved, to place a body where the mesh was.
 *  @return WS_OK, WS_ERR_BAD_MESH (with the reason in the last error), WS_ERR_INVALID_ARGUMENT,
 *          WS_ERR_UNINITIALIZED_DEF, WS_ERR_OUT_OF_MEMORY. */
WS_API ws_status ws_shape_create_mesh(ws_world *world, const ws_mesh_def *def,
                                      ws_shape_id *out);
/** Destroy a shape no body uses. @return WS_ERR_IN_USE while a body uses it. */
WS_API ws_status ws_shape_destroy(ws_world *world, ws_shape_id id);
/** 1 if the id names a live shape of this world, else 0. */
WS_API int ws_shape_is_valid(const ws_world *world, ws_shape_id id);
/** Volume, centroid, inertia and feature counts. */
WS_API ws_status ws_shape_get_info(const ws_world *world, ws_shape_id id, ws_shape_info *info);
/** How far a shape was moved when it was created: the volume centroid of the mesh in the frame
 *  its vertices were given in, m (zero for the box and cylinder builders). Every vertex was
 *  moved by -offset, so a body at `position` with orientation A puts a vertex v of the original
 *  mesh at position + A (v - offset): to place the body where the mesh was (vertices given in
 *  the global frame), create it at position = offset with the identity orientation. The same
 *  value as ws_shape_info.centroid.
 *  @return WS_OK, WS_ERR_STALE_HANDLE, WS_ERR_INVALID_ARGUMENT (offset NULL). */
WS_API ws_status ws_shape_get_centroid_offset(const ws_world *world, ws_shape_id shape,
                                              ws_vec3 *offset);
/** Copy the re-centred vertices (xyz, m) and triangles; either buffer may be NULL with capacity 0
 *  to ask for the counts. */
WS_API ws_status ws_shape_copy_mesh(const ws_world *world, ws_shape_id id, double *vertices,
                                    size_t vertex_capacity, size_t *vertex_count,
                                    uint32_t *triangles, size_t triangle_capacity,
                                    size_t *triangle_count);

#ifdef __cplusplus
}
#endif

#endif
