/*
 * stl_shape.c: a body's shape from an STL file, in your own C program.
 *
 * The library reads no files: it takes vertices and triangles (ws_shape_create_mesh). This
 * example is the reading a program does first: an STL file, binary or ASCII, into those
 * arrays, with the copies of each vertex welded into one (STL repeats every vertex in each of
 * its triangles; unwelded, the mesh is a heap of loose triangles and the library calls it
 * open). It creates the shape, prints its volume, size and where its centroid was in the file
 * (ws_shape_get_centroid_offset: create the body there to put it where the file had it), and
 * for a mesh the library refuses, the error with the offending edge's vertex positions.
 *
 * Build:  cc stl_shape.c $(pkg-config --cflags --libs libwrapsim) -o stl_shape
 * Run:    ./stl_shape FILE.stl [--scale S]     (S: metres per file unit, 0.001 for mm)
 * Exit status: 0 the shape was made, 1 the file or the mesh was refused, 2 bad arguments.
 *
 * Welding here is exact: copies with the same coordinates become one vertex, which is what a
 * binary STL holds (each copy is the same float) and what one ASCII writer prints. Files whose
 * copies differ in the last digits need a tolerance (the Python binding's mesh_from_file has
 * one).
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <wrapsim/wrapsim.h>

/* One corner of a triangle as read, with its place in the file. */
typedef struct corner {
    double x, y, z;
    size_t at;
} corner;

typedef struct mesh {
    corner *corners; /* 3 per triangle, file order */
    size_t count, cap;
} mesh;

static int add_corner(mesh *m, double x, double y, double z)
{
    if (m->count == m->cap) {
        size_t cap = m->cap ? 2 * m->cap : 3 * 1024;
        corner *c = realloc(m->corners, cap * sizeof *c);
        if (!c)
            return -1;
        m->corners = c;
        m->cap = cap;
    }
    m->corners[m->count] = (corner){x, y, z, m->count};
    m->count++;
    return 0;
}

static float le_float(const unsigned char *b)
{
    uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* A binary STL: 80 bytes of header, a little-endian count, 50 bytes per triangle (normal,
 * three corners as float32, two attribute bytes). It is binary when its size says so: some
 * binary files also begin with "solid". */
static int read_binary(FILE *f, long size, mesh *m, const char *path)
{
    unsigned char head[84], rec[50];
    if (size < 84 || fread(head, 1, 84, f) != 84)
        return 1;
    uint32_t n = (uint32_t)head[80] | (uint32_t)head[81] << 8 | (uint32_t)head[82] << 16 |
                 (uint32_t)head[83] << 24;
    if ((unsigned long)size != 84ul + 50ul * n)
        return 1; /* not binary: try ASCII */
    for (uint32_t t = 0; t < n; t++) {
        if (fread(rec, 1, 50, f) != 50) {
            fprintf(stderr, "%s: ends inside triangle %lu\n", path, (unsigned long)t);
            return -1;
        }
        for (int k = 0; k < 3; k++) {
            const unsigned char *p = rec + 12 + 12 * k;
            if (add_corner(m, le_float(p), le_float(p + 4), le_float(p + 8)) != 0) {
                fprintf(stderr, "%s: out of memory\n", path);
                return -1;
            }
        }
    }
    return 0;
}

/* An ASCII STL: every "vertex x y z" line is a corner; three make a triangle. */
static int read_ascii(FILE *f, long size, mesh *m, const char *path)
{
    char line[512];
    long lineno = 0;
    rewind(f);
    while (fgets(line, sizeof line, f)) {
        lineno++;
        char *p = line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (strncmp(p, "vertex", 6) != 0)
            continue;
        double v[3];
        char *end = p + 6;
        for (int k = 0; k < 3; k++) {
            char *s = end;
            errno = 0;
            v[k] = strtod(s, &end);
            if (end == s || errno == ERANGE) {
                fprintf(stderr, "%s:%ld: a vertex needs three numbers\n", path, lineno);
                return -1;
            }
        }
        if (add_corner(m, v[0], v[1], v[2]) != 0) {
            fprintf(stderr, "%s: out of memory\n", path);
            return -1;
        }
    }
    if (m->count == 0) {
        fprintf(stderr,
                "%s: not an STL file: no 'vertex' lines, and %ld bytes is not the size of a "
                "binary STL (84 + 50 per triangle, as its count says)\n",
                path, size);
        return -1;
    }
    if (m->count % 3 != 0) {
        fprintf(stderr, "%s: %lu vertex lines: a triangle mesh needs a multiple of 3\n", path,
                (unsigned long)m->count);
        return -1;
    }
    return 0;
}

static int by_position(const void *pa, const void *pb)
{
    const corner *a = pa, *b = pb;
    if (a->x != b->x)
        return a->x < b->x ? -1 : 1;
    if (a->y != b->y)
        return a->y < b->y ? -1 : 1;
    if (a->z != b->z)
        return a->z < b->z ? -1 : 1;
    return a->at < b->at ? -1 : a->at > b->at;
}

/* Weld equal corners: sort by position, number each run of equal ones. Fills xyz (3 per
 * vertex, scaled) and tri (the vertex of each corner); returns the vertex count. */
static size_t weld(mesh *m, double scale, double *xyz, uint32_t *tri)
{
    qsort(m->corners, m->count, sizeof *m->corners, by_position);
    size_t nv = 0;
    for (size_t i = 0; i < m->count; i++) {
        const corner *c = &m->corners[i];
        const corner *prev = i ? &m->corners[i - 1] : NULL;
        if (!prev || c->x != prev->x || c->y != prev->y || c->z != prev->z) {
            xyz[3 * nv] = c->x * scale;
            xyz[3 * nv + 1] = c->y * scale;
            xyz[3 * nv + 2] = c->z * scale;
            nv++;
        }
        tri[c->at] = (uint32_t)(nv - 1);
    }
    return nv;
}

/* The library names a refused mesh's edge by its two vertex indices: show where they are. */
static void explain(ws_world *w, const double *xyz, size_t nv, double scale)
{
    const char *err = ws_world_last_error(w);
    fprintf(stderr, "%s\n", err);
    const char *e = strstr(err, "edge (");
    unsigned long a, b;
    if (e && sscanf(e, "edge (%lu, %lu)", &a, &b) == 2 && a < nv && b < nv)
        fprintf(stderr, "the edge runs from (%g, %g, %g) to (%g, %g, %g) in the file's units\n",
                xyz[3 * a] / scale, xyz[3 * a + 1] / scale, xyz[3 * a + 2] / scale,
                xyz[3 * b] / scale, xyz[3 * b + 1] / scale, xyz[3 * b + 2] / scale);
}

int main(int argc, char **argv)
{
    const char *path = NULL;
    double scale = 1.0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--scale") == 0 && i + 1 < argc) {
            char *end;
            scale = strtod(argv[++i], &end);
            if (*end || !(scale > 0.0) || scale > 1e6) {
                fprintf(stderr, "--scale must be a number > 0, got '%s'\n", argv[i]);
                return 2;
            }
        } else if (!path && argv[i][0] != '-') {
            path = argv[i];
        } else {
            fprintf(stderr, "usage: %s FILE.stl [--scale METRES_PER_UNIT]\n", argv[0]);
            return 2;
        }
    }
    if (!path) {
        fprintf(stderr, "usage: %s FILE.stl [--scale METRES_PER_UNIT]\n", argv[0]);
        return 2;
    }

    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "%s: %s\n", path, strerror(errno));
        return 1;
    }
    long size = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    rewind(f);
    mesh m = {0};
    int r = size < 0 ? -1 : read_binary(f, size, &m, path);
    if (r > 0)
        r = read_ascii(f, size, &m, path);
    fclose(f);
    for (size_t i = 0; r == 0 && i < m.count; i++) {
        const corner *c = &m.corners[i];
        if (!isfinite(c->x) || !isfinite(c->y) || !isfinite(c->z)) {
            fprintf(stderr, "%s: triangle %lu has a corner that is not a finite number\n", path,
                    (unsigned long)(i / 3));
            r = -1;
        }
    }
    if (r != 0 || m.count > UINT32_MAX) {
        free(m.corners);
        return 1;
    }

    size_t nt = m.count / 3;
    double *xyz = malloc(3 * m.count * sizeof *xyz);
    uint32_t *tri = malloc(m.count * sizeof *tri);
    ws_world_def wd;
    ws_world_def_init(&wd);
    ws_world *w = NULL;
    int status = 1;
    if (!xyz || !tri || ws_world_create(&wd, &w) != WS_OK) {
        fprintf(stderr, "out of memory\n");
        goto done;
    }
    size_t nv = weld(&m, scale, xyz, tri);

    ws_mesh_def md;
    ws_mesh_def_init(&md);
    md.vertices = xyz;
    md.vertex_count = nv;
    md.triangles = tri;
    md.triangle_count = nt;
    ws_shape_id shape;
    if (ws_shape_create_mesh(w, &md, &shape) != WS_OK) {
        fprintf(stderr, "%s: ", path);
        explain(w, xyz, nv, scale);
        goto done;
    }
    ws_shape_info info;
    ws_vec3 at;
    ws_shape_get_info(w, shape, &info);
    ws_shape_get_centroid_offset(w, shape, &at);
    printf("%s: %lu triangles, %lu corners welded into %lu vertices\n", path, (unsigned long)nt,
           (unsigned long)m.count, (unsigned long)nv);
    printf("volume %.10g m^3; size %.4g x %.4g x %.4g m; %s\n", info.volume,
           info.aabb_max.x - info.aabb_min.x, info.aabb_max.y - info.aabb_min.y,
           info.aabb_max.z - info.aabb_min.z, info.convex ? "convex" : "not convex");
    printf("centroid in the file's frame (create the body here): (%.6g, %.6g, %.6g) m\n", at.x,
           at.y, at.z);
    status = 0;
done:
    ws_world_destroy(w);
    free(xyz);
    free(tri);
    free(m.corners);
    return status;
}
