#include "shape/shape.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Two triangle normals closer than this (1 - cos) make one face: about 4.5e-5 rad. */
#define COPLANAR_TOL 1e-9

typedef struct half_edge {
    uint32_t lo, hi; /* undirected key */
    uint32_t tri;
    uint8_t forward; /* 1 when the triangle runs lo -> hi */
} half_edge;

static int cmp_half_edge(const void *pa, const void *pb)
{
    const half_edge *a = pa, *b = pb;
    if (a->lo != b->lo)
        return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi)
        return a->hi < b->hi ? -1 : 1;
    if (a->tri != b->tri)
        return a->tri < b->tri ? -1 : 1;
    return 0;
}

/* The reason a mesh is refused, with what to do about it: a mesh from a file is usually fixed
 * in a mesh tool, not in code. */
static void fail(char *why, size_t n, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void fail(char *why, size_t n, const char *fmt, ...)
{
    if (!why || !n)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, n, fmt, ap);
    va_end(ap);
}

void ws_shape_free(ws_mem *mem, ws_shape *s)
{
    ws_mem_free(mem, s->vertices, s->vertex_count * sizeof *s->vertices);
    ws_mem_free(mem, s->triangles, 3 * s->triangle_count * sizeof *s->triangles);
    ws_mem_free(mem, s->tris, s->triangle_count * sizeof *s->tris);
    ws_mem_free(mem, s->faces, s->face_count * sizeof *s->faces);
    ws_mem_free(mem, s->edges, s->edge_alloc * sizeof *s->edges);
    memset(s, 0, sizeof *s);
}

static v3 tri_normal_raw(const v3 *vx, const uint32_t *t)
{
    return v3_cross(v3_sub(vx[t[1]], vx[t[0]]), v3_sub(vx[t[2]], vx[t[0]]));
}

/* Mass properties by signed tetrahedra from the bounding-box centre (less cancellation than
 * from the origin): volume, centroid and the second moment C = int x x^T dV. */
static void mass_properties(const v3 *vx, const uint32_t *tri, size_t nt, v3 ref, double *vol,
                            v3 *centroid, m3 *inertia)
{
    double V = 0.0;
    v3 c = {0, 0, 0};
    double C[9] = {0};
    for (size_t t = 0; t < nt; t++) {
        v3 a = v3_sub(vx[tri[3 * t]], ref), b = v3_sub(vx[tri[3 * t + 1]], ref),
           d = v3_sub(vx[tri[3 * t + 2]], ref);
        double det6 = v3_dot(a, v3_cross(b, d)); /* 6 x signed volume */
        V += det6 / 6.0;
        v3 s = v3_add(v3_add(a, b), d);
        c = v3_madd(c, s, det6 / 24.0);
        const double *pa = &a.x, *pb = &b.x, *pd = &d.x, *ps = &s.x;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                C[3 * i + j] += det6 / 120.0 *
                                (pa[i] * pa[j] + pb[i] * pb[j] + pd[i] * pd[j] + ps[i] * ps[j]);
    }
    *vol = V;
    v3 cg = v3_scale(c, 1.0 / V); /* relative to ref */
    const double *g = &cg.x;
    double tr = 0.0;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            C[3 * i + j] -= V * g[i] * g[j];
        tr += C[4 * i];
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            inertia->m[3 * i + j] = (i == j ? tr : 0.0) - C[3 * i + j];
    *centroid = v3_add(cg, ref);
}

ws_status ws_shape_build(ws_mem *mem, const double *xyz, size_t nv, const uint32_t *tri,
                         size_t nt, ws_shape *out, char *why, size_t why_len)
{
    memset(out, 0, sizeof *out);
    if (!xyz || !tri) {
        fail(why, why_len, "mesh: vertices and triangles must not be NULL");
        return WS_ERR_INVALID_ARGUMENT;
    }
    if (nv < 4 || nt < 4) {
        fail(why, why_len, "mesh: a closed mesh needs >= 4 vertices and >= 4 triangles, got %ld and %ld",
             (long)nv, (long)nt);
        return WS_ERR_BAD_MESH;
    }
    if (nv > WS_MESH_MAX_ITEMS || nt > WS_MESH_MAX_ITEMS) {
        fail(why, why_len, "mesh: too large (%ld vertices, %ld triangles)", (long)nv, (long)nt);
        return WS_ERR_BAD_MESH;
    }
    for (size_t i = 0; i < 3 * nv; i++) {
        if (!isfinite(xyz[i])) {
            fail(why, why_len, "mesh: vertex %ld has a coordinate that is not finite",
                 (long)(i / 3));
            return WS_ERR_INVALID_ARGUMENT;
        }
        /* Beyond this the areas and volumes of the checks below overflow. */
        if (fabs(xyz[i]) > WS_MESH_MAX_COORD) {
            fail(why, why_len,
                 "mesh: vertex %ld has coordinate %g m, beyond WS_MESH_MAX_COORD (%g m)",
                 (long)(i / 3), xyz[i], WS_MESH_MAX_COORD);
            return WS_ERR_INVALID_ARGUMENT;
        }
    }
    for (size_t t = 0; t < nt; t++) {
        for (int k = 0; k < 3; k++) {
            if (tri[3 * t + k] >= nv) {
                fail(why, why_len, "mesh: triangle %ld refers to vertex %ld, which does not exist",
                     (long)t, (long)tri[3 * t + k]);
                return WS_ERR_BAD_MESH;
            }
        }
    }

    ws_status st = WS_ERR_OUT_OF_MEMORY;
    half_edge *he = NULL;
    uint32_t *face_of = NULL, *stack = NULL, *order = NULL;
    size_t nhe = 3 * nt;

    out->vertices = ws_mem_alloc(mem, nv * sizeof *out->vertices);
    out->triangles = ws_mem_alloc(mem, 3 * nt * sizeof *out->triangles);
    out->tris = ws_mem_alloc(mem, nt * sizeof *out->tris);
    /* Counts only for what was allocated, so ws_shape_free releases exactly that. */
    out->vertex_count = out->vertices ? (uint32_t)nv : 0;
    if (!out->triangles || !out->tris) {
        ws_mem_free(mem, out->triangles, out->triangles ? 3 * nt * sizeof *out->triangles : 0);
        ws_mem_free(mem, out->tris, out->tris ? nt * sizeof *out->tris : 0);
        out->triangles = NULL;
        out->tris = NULL;
    } else {
        out->triangle_count = (uint32_t)nt;
    }
    he = ws_mem_alloc(mem, nhe * sizeof *he);
    face_of = ws_mem_alloc(mem, nt * sizeof *face_of);
    stack = ws_mem_alloc(mem, nt * sizeof *stack);
    order = ws_mem_alloc(mem, nt * sizeof *order);
    if (!out->vertices || !out->triangles || !out->tris || !he || !face_of || !stack || !order)
        goto done;

    v3 lo = v3_load(xyz), hi = lo;
    for (size_t i = 0; i < nv; i++) {
        out->vertices[i] = v3_load(xyz + 3 * i);
        lo = v3_min(lo, out->vertices[i]);
        hi = v3_max(hi, out->vertices[i]);
    }
    /* The extent by the largest side of the bounding box: its diagonal would underflow to 0
     * for a mesh of 1e-200 m and call it a point. */
    double ext = fmax(hi.x - lo.x, fmax(hi.y - lo.y, hi.z - lo.z));
    if (!(ext > 0.0)) {
        fail(why, why_len, "mesh: all vertices coincide");
        st = WS_ERR_BAD_MESH;
        goto done;
    }
    if (ext < WS_MESH_MIN_EXTENT) {
        fail(why, why_len,
             "mesh: its extent (largest side of its bounding box) is %g m, below "
             "WS_MESH_MIN_EXTENT (%g m)",
             ext, WS_MESH_MIN_EXTENT);
        st = WS_ERR_BAD_MESH;
        goto done;
    }
    double diag = v3_norm(v3_sub(hi, lo));

    /* Degenerate triangles: area below 1e-12 of the squared size. */
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *tt = tri + 3 * t;
        v3 n = tri_normal_raw(out->vertices, tt);
        if (tt[0] == tt[1] || tt[1] == tt[2] || tt[0] == tt[2] ||
            !(v3_norm(n) > 1e-12 * diag * diag)) {
            fail(why, why_len,
                 "mesh: triangle %ld is degenerate (zero area): remove it, or repair the mesh "
                 "in a mesh tool (merge duplicate vertices, remove degenerate faces)",
                 (long)t);
            st = WS_ERR_BAD_MESH;
            goto done;
        }
    }

    /* Closed and consistently wound: every undirected edge used by exactly two triangles, once
     * in each direction. */
    for (size_t t = 0; t < nt; t++) {
        for (int k = 0; k < 3; k++) {
            uint32_t a = tri[3 * t + k], b = tri[3 * t + (k + 1) % 3];
            half_edge *h = &he[3 * t + k];
            h->lo = a < b ? a : b;
            h->hi = a < b ? b : a;
            h->tri = (uint32_t)t;
            h->forward = a < b;
        }
    }
    qsort(he, nhe, sizeof *he, cmp_half_edge);
    for (size_t i = 0; i < nhe;) {
        size_t j = i;
        while (j < nhe && he[j].lo == he[i].lo && he[j].hi == he[i].hi)
            j++;
        if (j - i == 1) {
            fail(why, why_len,
                 "mesh: not closed: edge (%ld, %ld) belongs to one triangle only: close the mesh, "
                 "or repair it in a mesh tool (merge duplicate vertices, fill holes)",
                 (long)he[i].lo, (long)he[i].hi);
            st = WS_ERR_BAD_MESH;
            goto done;
        }
        if (j - i > 2) {
            fail(why, why_len,
                 "mesh: not manifold: edge (%ld, %ld) belongs to %ld triangles, not two: give each "
                 "solid its own shape, or repair it in a mesh tool (remove duplicate faces, split "
                 "non-manifold edges)",
                 (long)he[i].lo, (long)he[i].hi, (long)(j - i));
            st = WS_ERR_BAD_MESH;
            goto done;
        }
        if (he[i].forward == he[i + 1].forward) {
            fail(why, why_len,
                 "mesh: inconsistent winding: the two triangles at edge (%ld, %ld) run the same "
                 "way: turn one of them, or repair the mesh in a mesh tool (unify or recalculate "
                 "the normals)",
                 (long)he[i].lo, (long)he[i].hi);
            st = WS_ERR_BAD_MESH;
            goto done;
        }
        i = j;
    }

    double vol;
    v3 cg;
    mass_properties(out->vertices, tri, nt, v3_scale(v3_add(lo, hi), 0.5), &vol, &cg,
                    &out->inertia_unit);
    if (!(vol > 1e-12 * diag * diag * diag)) {
        fail(why, why_len,
             "mesh: volume is not positive: triangles must run counter-clockwise seen from outside "
             "(the mesh is inside out): reverse every triangle, or repair it in a mesh tool "
             "(flip the normals)");
        st = WS_ERR_BAD_MESH;
        goto done;
    }
    out->volume = vol;
    out->centroid = cg;
    out->lo = v3_sub(lo, cg);
    out->hi = v3_sub(hi, cg);
    out->radius = 0.0;
    out->inner = 0.25 * fmin(hi.x - lo.x, fmin(hi.y - lo.y, hi.z - lo.z));
    for (size_t i = 0; i < nv; i++) {
        out->vertices[i] = v3_sub(out->vertices[i], cg);
        out->radius = fmax(out->radius, v3_norm(out->vertices[i]));
    }

    /* Faces: flood-fill over edges between coplanar triangles. Neighbours come from the sorted
     * half-edges: the two entries of an edge are adjacent. */
    uint32_t *nbr = ws_mem_alloc(mem, 3 * nt * sizeof *nbr);
    if (!nbr)
        goto done;
    for (size_t i = 0; i < nhe; i += 2) {
        uint32_t t0 = he[i].tri, t1 = he[i + 1].tri;
        /* Record t1 as neighbour of t0 at the edge slot that matches. */
        for (int k = 0; k < 3; k++) {
            uint32_t a = tri[3 * t0 + k], b = tri[3 * t0 + (k + 1) % 3];
            if ((a == he[i].lo && b == he[i].hi) || (b == he[i].lo && a == he[i].hi))
                nbr[3 * t0 + k] = t1;
            a = tri[3 * t1 + k];
            b = tri[3 * t1 + (k + 1) % 3];
            if ((a == he[i].lo && b == he[i].hi) || (b == he[i].lo && a == he[i].hi))
                nbr[3 * t1 + k] = t0;
        }
    }
    v3 *tn = ws_mem_alloc(mem, nt * sizeof *tn);
    if (!tn) {
        ws_mem_free(mem, nbr, 3 * nt * sizeof *nbr);
        goto done;
    }
    for (size_t t = 0; t < nt; t++) {
        v3 n = tri_normal_raw(out->vertices, tri + 3 * t);
        tn[t] = v3_scale(n, 1.0 / v3_norm(n));
        face_of[t] = UINT32_MAX;
    }
    uint32_t nf = 0;
    for (size_t t0 = 0; t0 < nt; t0++) {
        if (face_of[t0] != UINT32_MAX)
            continue;
        size_t sp = 0;
        stack[sp++] = (uint32_t)t0;
        face_of[t0] = nf;
        while (sp) {
            uint32_t t = stack[--sp];
            for (int k = 0; k < 3; k++) {
                uint32_t u = nbr[3 * t + k];
                if (face_of[u] == UINT32_MAX && 1.0 - v3_dot(tn[u], tn[t0]) < COPLANAR_TOL) {
                    face_of[u] = nf;
                    stack[sp++] = u;
                }
            }
        }
        nf++;
    }

    /* Feature edges: between triangles of different faces, convex only (the far vertex of the
     * neighbour lies behind the face). Reflex edges are left to point-face contacts. */
    uint32_t ne = 0;
    for (size_t i = 0; i < nhe; i += 2)
        if (face_of[he[i].tri] != face_of[he[i + 1].tri])
            ne++;
    out->faces = ws_mem_calloc(mem, nf, sizeof *out->faces);
    out->edges = ws_mem_calloc(mem, ne ? ne : 1, sizeof *out->edges);
    out->face_count = out->faces ? nf : 0;
    out->edge_alloc = out->edges ? (ne ? ne : 1) : 0;
    if (!out->faces || !out->edges) {
        ws_mem_free(mem, tn, nt * sizeof *tn);
        ws_mem_free(mem, nbr, 3 * nt * sizeof *nbr);
        goto done;
    }
    out->face_count = nf;
    out->edge_count = 0;
    for (size_t i = 0; i < nhe; i += 2) {
        uint32_t t0 = he[i].tri, t1 = he[i + 1].tri;
        if (face_of[t0] == face_of[t1])
            continue;
        /* Convex if the neighbour's vertices are all on or behind t0's plane. */
        v3 p0 = out->vertices[tri[3 * t0]];
        int convex = 1;
        for (int k = 0; k < 3; k++)
            if (v3_dot(tn[t0], v3_sub(out->vertices[tri[3 * t1 + k]], p0)) > 1e-9 * diag)
                convex = 0;
        if (!convex)
            continue;
        ws_edge *e = &out->edges[out->edge_count++];
        e->a = he[i].lo;
        e->b = he[i].hi;
        e->f1 = face_of[t0];
        e->f2 = face_of[t1];
        e->n1 = tn[t0];
        e->n2 = tn[t1];
        e->lo = v3_min(out->vertices[e->a], out->vertices[e->b]);
        e->hi = v3_max(out->vertices[e->a], out->vertices[e->b]);
    }

    /* Triangles sorted by face, faces with their plane and box. */
    uint32_t pos = 0;
    for (uint32_t f = 0; f < nf; f++) {
        ws_face *fc = &out->faces[f];
        fc->first_tri = pos;
        for (size_t t = 0; t < nt; t++)
            if (face_of[t] == f)
                order[pos++] = (uint32_t)t;
        fc->tri_count = pos - fc->first_tri;
    }
    for (uint32_t f = 0; f < nf; f++) {
        ws_face *fc = &out->faces[f];
        v3 nsum = {0, 0, 0};
        fc->lo = fc->hi = out->vertices[tri[3 * order[fc->first_tri]]];
        for (uint32_t k = fc->first_tri; k < fc->first_tri + fc->tri_count; k++) {
            uint32_t t = order[k];
            nsum = v3_add(nsum, tri_normal_raw(out->vertices, tri + 3 * t));
            for (int c = 0; c < 3; c++) {
                fc->lo = v3_min(fc->lo, out->vertices[tri[3 * t + c]]);
                fc->hi = v3_max(fc->hi, out->vertices[tri[3 * t + c]]);
            }
        }
        fc->normal = v3_scale(nsum, 1.0 / v3_norm(nsum));
        /* Offset as the mean over the face's vertices keeps the plane centred in round-off. */
        double off = 0.0;
        for (uint32_t k = fc->first_tri; k < fc->first_tri + fc->tri_count; k++)
            for (int c = 0; c < 3; c++)
                off += v3_dot(fc->normal, out->vertices[tri[3 * order[k] + c]]);
        fc->offset = off / (3.0 * fc->tri_count);
    }
    for (uint32_t k = 0; k < nt; k++) {
        uint32_t t = order[k];
        const uint32_t *tt = tri + 3 * t;
        memcpy(out->triangles + 3 * k, tt, 3 * sizeof *tt);
        ws_tri *q = &out->tris[k];
        q->p = out->vertices[tt[0]];
        q->w = v3_sub(out->vertices[tt[1]], q->p);
        q->v = v3_sub(out->vertices[tt[2]], q->p);
        double a = v3_dot(q->w, q->w), b = v3_dot(q->w, q->v), c = v3_dot(q->v, q->v);
        double det = a * c - b * b;
        q->g00 = c / det;
        q->g01 = -b / det;
        q->g11 = a / det;
        q->face = face_of[t];
    }

    out->convex = 1;
    for (uint32_t f = 0; f < nf && out->convex; f++)
        for (size_t i = 0; i < nv; i++)
            if (v3_dot(out->faces[f].normal, out->vertices[i]) - out->faces[f].offset >
                1e-9 * diag) {
                out->convex = 0;
                break;
            }
    /* Faces merged within COPLANAR_TOL may bend a little; flat ones are planar to round-off.
     * On a flat convex shape a face's outline lies behind every other face's plane as closely
     * as eq. 14's test sees it, so node contacts may turn a face down by those planes. */
    out->flat = 1;
    for (uint32_t k = 0; k < nt; k++) {
        uint32_t t = order[k];
        const ws_face *fc = &out->faces[face_of[t]];
        int on = v3_norm(v3_sub(tn[t], fc->normal)) <= 1e-12;
        for (int c = 0; c < 3; c++)
            on &= fabs(v3_dot(fc->normal, out->vertices[tri[3 * t + c]]) - fc->offset) <=
                  1e-12 * diag;
        out->flat &= on;
    }
    ws_mem_free(mem, tn, nt * sizeof *tn);
    ws_mem_free(mem, nbr, 3 * nt * sizeof *nbr);
    st = WS_OK;

done:
    ws_mem_free(mem, he, he ? nhe * sizeof *he : 0);
    ws_mem_free(mem, face_of, face_of ? nt * sizeof *face_of : 0);
    ws_mem_free(mem, stack, stack ? nt * sizeof *stack : 0);
    ws_mem_free(mem, order, order ? nt * sizeof *order : 0);
    if (st != WS_OK) {
        if (st == WS_ERR_OUT_OF_MEMORY)
            fail(why, why_len, "mesh: out of memory");
        ws_shape_free(mem, out);
    }
    return st;
}

void ws_shape_box_mesh(double lx, double ly, double lz, double xyz[24], uint32_t tri[36])
{
    double hx = 0.5 * lx, hy = 0.5 * ly, hz = 0.5 * lz;
    for (int i = 0; i < 8; i++) {
        xyz[3 * i + 0] = (i & 1) ? hx : -hx;
        xyz[3 * i + 1] = (i & 2) ? hy : -hy;
        xyz[3 * i + 2] = (i & 4) ? hz : -hz;
    }
    static const uint32_t t[36] = {
        0, 2, 3, 0, 3, 1, /* -z */
        4, 5, 7, 4, 7, 6, /* +z */
        0, 1, 5, 0, 5, 4, /* -y */
        2, 6, 7, 2, 7, 3, /* +y */
        0, 4, 6, 0, 6, 2, /* -x */
        1, 3, 7, 1, 7, 5, /* +x */
    };
    memcpy(tri, t, sizeof t);
}

void ws_shape_cylinder_mesh(double r, double h, int n, double *xyz, uint32_t *tri)
{
    for (int i = 0; i < n; i++) {
        double a = 2.0 * WS_PI * i / n;
        for (int k = 0; k < 2; k++) {
            double *p = xyz + 3 * (2 * i + k);
            p[0] = r * cos(a);
            p[1] = r * sin(a);
            p[2] = k ? 0.5 * h : -0.5 * h;
        }
    }
    uint32_t *t = tri;
    for (int i = 0; i < n; i++) {
        uint32_t b0 = 2 * i, t0 = 2 * i + 1, b1 = 2 * ((i + 1) % n), t1 = b1 + 1;
        *t++ = b0; *t++ = b1; *t++ = t1;
        *t++ = b0; *t++ = t1; *t++ = t0;
    }
    for (int i = 1; i + 1 < n; i++) { /* caps as fans */
        *t++ = 0; *t++ = 2 * (i + 1); *t++ = 2 * i;
        *t++ = 1; *t++ = 2 * i + 1; *t++ = 2 * (i + 1) + 1;
    }
}

v3 ws_shape_support(const ws_shape *s, v3 d)
{
    uint32_t best = 0;
    double bd = -INFINITY;
    for (uint32_t i = 0; i < s->vertex_count; i++) {
        double x = v3_dot(s->vertices[i], d);
        if (x > bd) {
            bd = x;
            best = i;
        }
    }
    return s->vertices[best];
}
