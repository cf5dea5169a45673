/* Shapes: closed triangle meshes in the body frame, with the features contact detection uses.
 * Knows math only. */
#ifndef WS_SHAPE_H
#define WS_SHAPE_H

#include <stddef.h>
#include <stdint.h>

#include <wrapsim/shape.h>

#include "base/base.h"
#include "math/wmath.h"

/* A triangle prepared for eq. 14: origin p, edge vectors w = pq, v = pr, and the inverse Gram
 * matrix of (w, v) so that (k1, k2) come from two dot products. */
typedef struct ws_tri {
    v3 p, w, v;
    double g00, g01, g11;
    uint32_t face;
} ws_tri;

/* A face: a connected group of coplanar triangles, n . x = offset on its plane. */
typedef struct ws_face {
    v3 normal;
    double offset;
    uint32_t first_tri, tri_count;
    v3 lo, hi; /* bounding box of its vertices */
} ws_face;

/* A convex feature edge between two faces that are not coplanar. n1, n2: the outward normals of
 * the two faces, for the normal-cone test; f1, f2: the two faces (an edge lies in the box of
 * each). */
typedef struct ws_edge {
    uint32_t a, b;
    uint32_t f1, f2;
    v3 n1, n2;
    v3 lo, hi; /* bounding box of the edge */
} ws_edge;

typedef struct ws_shape {
    uint32_t vertex_count, triangle_count, face_count, edge_count;
    uint32_t edge_alloc; /* edges allocated (>= edge_count) */
    v3 *vertices;        /* re-centred on the centroid */
    uint32_t *triangles; /* 3 per triangle, as given (re-ordered by face) */
    ws_tri *tris;        /* sorted by face */
    ws_face *faces;
    ws_edge *edges;
    v3 lo, hi;       /* bounding box */
    double radius;   /* bounding sphere about the origin */
    double inner;    /* how deep inside the solid a contact is still seen: 1/4 of the smallest
                        extent of its box */
    double volume;
    m3 inertia_unit; /* about the centroid, density 1 */
    v3 centroid;     /* where the given vertices had their centroid */
    int convex;
    int flat; /* every face's triangles lie in its plane to round-off (1e-12) */
    uint32_t users;  /* bodies using it */
} ws_shape;

/* Build and validate. On failure returns WS_ERR_BAD_MESH / WS_ERR_INVALID_ARGUMENT /
 * WS_ERR_OUT_OF_MEMORY with a reason in `why`, and leaves *out empty. */
ws_status ws_shape_build(ws_mem *mem, const double *xyz, size_t nv, const uint32_t *tri,
                         size_t nt, ws_shape *out, char *why, size_t why_len);
void ws_shape_free(ws_mem *mem, ws_shape *s);

/* Vertices and triangles of a box with full edge lengths (8 vertices, 12 triangles). */
void ws_shape_box_mesh(double lx, double ly, double lz, double xyz[24], uint32_t tri[36]);
/* A prism of `segments` sides approximating a cylinder: 2*segments vertices, 4*segments - 4
 * triangles. Arrays sized by the caller. */
void ws_shape_cylinder_mesh(double r, double h, int segments, double *xyz, uint32_t *tri);

/* Support point of the shape (body frame) in direction d. */
v3 ws_shape_support(const ws_shape *s, v3 d);

#endif
