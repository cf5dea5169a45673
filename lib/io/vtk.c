/* VTK XML output for ParaView: PolyData files of the bodies, each web's film surface, its springs
 * and the contacts, gathered per frame in a named multiblock (.vtm) and over time in a .pvd
 * collection. Reads the world, writes files only when asked.
 *
 * A file is composed in memory first: its XML text, and beside it the appended binary block whose
 * offsets the XML must name before the data follows. Every array is first laid out as raw values
 * in a scratch buffer, then written in the chosen form (ASCII text, raw binary, or zlib blocks), so
 * the code that gathers an array knows nothing of the format. */
#define _POSIX_C_SOURCE 200809L /* stat, to check the series' directory */
#include "world/world_internal.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#if !defined(S_ISDIR) && defined(S_IFDIR)
#define S_ISDIR(m) (((m) & S_IFMT) == S_IFDIR)
#endif

#ifdef WS_HAVE_ZLIB
#include <zlib.h>
#endif

/* Uncompressed size of a zlib block, as VTK's own writer cuts them. */
#define VTK_ZBLOCK 65536u

typedef enum vtk_type { T_F64, T_I32, T_U64, T_U8, T_STR, T_F32 } vtk_type;

static const char *const vtk_type_name[] = {"Float64", "Int32",  "UInt64",
                                            "UInt8",   "String", "Float32"};
static const size_t vtk_type_size[] = {8, 4, 8, 1, 1, 4};

typedef struct vtk_buf {
    unsigned char *p;
    size_t len, cap;
} vtk_buf;

/* One file being composed. The buffers grow and stay for the next file of a series. */
typedef struct vtk_file {
    ws_world *w;
    int format;    /* ws_vtk_format, WS_VTK_COMPRESSED only when zlib is in */
    int single;    /* 1: real values written as Float32 */
    vtk_buf xml;   /* the text */
    vtk_buf blob;  /* the appended data */
    vtk_buf raw;   /* the array being written, raw values */
    vtk_buf z;     /* compressed blocks of one array */
    vtk_buf index; /* body slot -> index in the bodies' field arrays (uint32) */
    int oom;       /* an allocation failed: the file is not written */
} vtk_file;

static int buf_reserve(vtk_file *f, vtk_buf *b, size_t need)
{
    if (f->oom)
        return -1;
    if (need <= b->cap)
        return 0;
    size_t cap = b->cap ? b->cap : 4096;
    while (cap < need)
        cap *= 2;
    unsigned char *p = ws_mem_realloc(&f->w->mem, b->p, b->cap, cap);
    if (!p) {
        f->oom = 1;
        return -1;
    }
    b->p = p;
    b->cap = cap;
    return 0;
}

static void buf_free(vtk_file *f, vtk_buf *b)
{
    ws_mem_free(&f->w->mem, b->p, b->cap);
    memset(b, 0, sizeof *b);
}

static void vtk_file_free(vtk_file *f)
{
    buf_free(f, &f->xml);
    buf_free(f, &f->blob);
    buf_free(f, &f->raw);
    buf_free(f, &f->z);
    buf_free(f, &f->index);
}

static void buf_put(vtk_file *f, vtk_buf *b, const void *data, size_t n)
{
    if (buf_reserve(f, b, b->len + n) != 0)
        return;
    memcpy(b->p + b->len, data, n);
    b->len += n;
}

static void
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    xml(vtk_file *f, const char *fmt, ...)
{
    for (;;) {
        if (f->oom)
            return;
        size_t room = f->xml.cap - f->xml.len;
        va_list ap;
        va_start(ap, fmt);
        int n = vsnprintf(room ? (char *)f->xml.p + f->xml.len : NULL, room, fmt, ap);
        va_end(ap);
        if (n < 0) {
            f->oom = 1;
            return;
        }
        if ((size_t)n < room) {
            f->xml.len += (size_t)n;
            return;
        }
        buf_reserve(f, &f->xml, f->xml.len + (size_t)n + 1);
    }
}

/* Room for n values of a type in the raw scratch; NULL when out of memory. */
static void *raw_take(vtk_file *f, vtk_type t, size_t n)
{
    f->raw.len = 0;
    if (buf_reserve(f, &f->raw, n * vtk_type_size[t] + 1) != 0)
        return NULL;
    f->raw.len = n * vtk_type_size[t];
    return f->raw.p;
}

static int little_endian(void)
{
    const uint16_t one = 1;
    unsigned char c;
    memcpy(&c, &one, 1);
    return c == 1;
}

/* The raw scratch as ASCII text inside the element. */
static void emit_ascii(vtk_file *f, vtk_type t)
{
    size_t n = f->raw.len / vtk_type_size[t];
    const unsigned char *p = f->raw.p;
    for (size_t i = 0; i < n && !f->oom; i++) {
        const char *sep = i + 1 == n || i % 6 == 5 ? "\n" : " ";
        if (t == T_F64) {
            double v;
            memcpy(&v, p + 8 * i, 8);
            xml(f, "%.9g%s", v, sep);
        } else if (t == T_F32) {
            float v;
            memcpy(&v, p + 4 * i, 4);
            xml(f, "%.9g%s", (double)v, sep); /* 9 digits: the float back exactly */
        } else if (t == T_I32) {
            int32_t v;
            memcpy(&v, p + 4 * i, 4);
            xml(f, "%ld%s", (long)v, sep);
        } else if (t == T_U64) {
            uint64_t v;
            memcpy(&v, p + 8 * i, 8);
            xml(f, "%llu%s", (unsigned long long)v, sep);
        } else {
            xml(f, "%u%s", (unsigned)p[i], sep);
        }
    }
}

/* The raw scratch as one array of the appended block: a UInt64 byte count and the bytes, or
 * VTK's compression header (blocks, block size, size of a partial last block, the compressed
 * size of each block) and the zlib blocks. */
static void emit_binary(vtk_file *f)
{
    size_t n = f->raw.len;
#ifdef WS_HAVE_ZLIB
    if (f->format == WS_VTK_COMPRESSED) {
        size_t nb = (n + VTK_ZBLOCK - 1) / VTK_ZBLOCK;
        uint64_t head[3] = {nb, VTK_ZBLOCK, n % VTK_ZBLOCK};
        f->z.len = 0;
        if (buf_reserve(f, &f->z, nb * 8 + compressBound(VTK_ZBLOCK) * (nb ? nb : 1)) != 0)
            return;
        uint64_t *sizes = (uint64_t *)(void *)f->z.p; /* the start of a realloc'd block */
        unsigned char *out = f->z.p + nb * 8;
        size_t used = 0;
        for (size_t k = 0; k < nb; k++) {
            size_t len = k + 1 < nb || n % VTK_ZBLOCK == 0 ? VTK_ZBLOCK : n % VTK_ZBLOCK;
            uLongf zlen = compressBound(VTK_ZBLOCK);
            if (compress2(out + used, &zlen, f->raw.p + k * VTK_ZBLOCK, (uLong)len, 6) != Z_OK) {
                f->oom = 1;
                return;
            }
            sizes[k] = zlen;
            used += zlen;
        }
        buf_put(f, &f->blob, head, sizeof head);
        buf_put(f, &f->blob, f->z.p, nb * 8 + used);
        return;
    }
#endif
    uint64_t head = n;
    buf_put(f, &f->blob, &head, sizeof head);
    buf_put(f, &f->blob, f->raw.p, n);
}

/* Write the raw scratch as a DataArray of `tuples` tuples of `comps` components. */
static void emit(vtk_file *f, vtk_type t, const char *name, int comps, size_t tuples)
{
    if (f->oom)
        return;
    if (t == T_F64 && f->single) {
        /* In place, front to back: float k ends before double k + 1 starts. */
        size_t n = f->raw.len / 8;
        for (size_t k = 0; k < n; k++) {
            double d;
            memcpy(&d, f->raw.p + 8 * k, 8);
            float v = (float)d;
            memcpy(f->raw.p + 4 * k, &v, 4);
        }
        f->raw.len = 4 * n;
        t = T_F32;
    }
    xml(f, "<DataArray type=\"%s\" Name=\"%s\"", vtk_type_name[t], name);
    if (comps > 1)
        xml(f, " NumberOfComponents=\"%d\"", comps);
    xml(f, " NumberOfTuples=\"%zu\"", tuples);
    if (f->format == WS_VTK_ASCII) {
        xml(f, " format=\"ascii\">\n");
        emit_ascii(f, t);
        xml(f, "</DataArray>\n");
    } else {
        xml(f, " format=\"appended\" offset=\"%zu\"/>\n", f->blob.len);
        emit_binary(f);
    }
}

static void emit_v3(vtk_file *f, const char *name, const v3 *a, size_t n)
{
    double *d = raw_take(f, T_F64, 3 * n);
    if (!d)
        return;
    for (size_t i = 0; i < n; i++) {
        d[3 * i] = a[i].x;
        d[3 * i + 1] = a[i].y;
        d[3 * i + 2] = a[i].z;
    }
    emit(f, T_F64, name, 3, n);
}

static void emit_nodes(vtk_file *f, const char *name, ws_nodes3 a, size_t n)
{
    double *d = raw_take(f, T_F64, 3 * n);
    if (!d)
        return;
    for (size_t i = 0; i < n; i++) {
        d[3 * i] = a.x[i];
        d[3 * i + 1] = a.y[i];
        d[3 * i + 2] = a.z[i];
    }
    emit(f, T_F64, name, 3, n);
}

static void emit_scalar(vtk_file *f, const char *name, double value)
{
    double *d = raw_take(f, T_F64, 1);
    if (d) {
        d[0] = value;
        emit(f, T_F64, name, 1, 1);
    }
}

/* The offsets array of `n` cells of `per` points each. */
static void emit_offsets(vtk_file *f, size_t n, size_t per)
{
    int32_t *o = raw_take(f, T_I32, n);
    if (!o)
        return;
    for (size_t k = 0; k < n; k++)
        o[k] = (int32_t)(per * (k + 1));
    emit(f, T_I32, "offsets", 1, n);
}

static void file_begin(vtk_file *f, const char *type)
{
    f->xml.len = f->blob.len = 0;
    f->oom = 0;
    xml(f,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"%s\" version=\"1.0\" byte_order=\"%s\" "
        "header_type=\"UInt64\"%s>\n",
        type, little_endian() ? "LittleEndian" : "BigEndian",
        f->format == WS_VTK_COMPRESSED ? " compressor=\"vtkZLibDataCompressor\"" : "");
}

static ws_status file_write(vtk_file *f, const char *path)
{
    ws_world *w = f->w;
    if (f->oom)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "VTK output: out of memory composing '%s'", path);
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return ws_fail(w, WS_ERR_IO, "cannot open '%s' for writing: %s", path, strerror(errno));
    fwrite(f->xml.p, 1, f->xml.len, fp);
    if (f->format != WS_VTK_ASCII && f->blob.len) {
        fputs("<AppendedData encoding=\"raw\">\n_", fp);
        fwrite(f->blob.p, 1, f->blob.len, fp);
        fputs("\n</AppendedData>\n", fp);
    }
    fputs("</VTKFile>\n", fp);
    int bad = ferror(fp);
    if (fclose(fp) != 0 || bad)
        return ws_fail(w, WS_ERR_IO, "error while writing '%s'", path);
    return WS_OK;
}

/* ---- bodies ---- */

static void body_fields(vtk_file *f, const ws_body_store *b, double time)
{
    xml(f, "<FieldData>\n");
    emit_scalar(f, "TimeValue", time);
    size_t nb = 0, chars = 0;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        nb++;
        chars += (b->name[i] ? strlen(b->name[i]) : 0) + 1;
    }
    char *s = raw_take(f, T_STR, chars);
    if (s) {
        for (size_t i = 0; i < b->slots; i++) {
            if (!b->alive[i])
                continue;
            size_t len = b->name[i] ? strlen(b->name[i]) : 0;
            memcpy(s, b->name[i] ? b->name[i] : "", len + 1);
            s += len + 1;
        }
        emit(f, T_STR, "body_name", 1, nb);
    }
    uint64_t *id = raw_take(f, T_U64, nb);
    if (id) {
        size_t k = 0;
        for (size_t i = 0; i < b->slots; i++)
            if (b->alive[i])
                id[k++] = ws_make_body_id(f->w, (uint32_t)i).bits;
        emit(f, T_U64, "body_id", 1, nb);
    }
    xml(f, "</FieldData>\n");
}

/* The index of each alive body among the alive ones, by slot (UINT32_MAX for a dead slot). */
static const uint32_t *body_index(vtk_file *f)
{
    const ws_body_store *b = &f->w->bodies;
    f->index.len = 0;
    if (buf_reserve(f, &f->index, (b->slots + 1) * sizeof(uint32_t)) != 0)
        return NULL;
    uint32_t *ix = (uint32_t *)(void *)f->index.p, k = 0;
    for (size_t i = 0; i < b->slots; i++)
        ix[i] = b->alive[i] ? k++ : UINT32_MAX;
    return ix;
}

static void compose_bodies(vtk_file *f)
{
    ws_world *w = f->w;
    const ws_body_store *b = &w->bodies;
    const ws_body_state *st = &b->st[w->cur];
    size_t np = 0, nt = 0;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        np += b->shape[i]->vertex_count;
        nt += b->shape[i]->triangle_count;
    }
    file_begin(f, "PolyData");
    xml(f, "<PolyData>\n");
    body_fields(f, b, w->time);
    xml(f, "<Piece NumberOfPoints=\"%zu\" NumberOfPolys=\"%zu\">\n<Points>\n", np, nt);
    double *d = raw_take(f, T_F64, 3 * np);
    if (d) {
        for (size_t i = 0; i < b->slots; i++) {
            if (!b->alive[i])
                continue;
            m3 A = qt_to_m3(st->p[i]);
            const ws_shape *s = b->shape[i];
            for (uint32_t k = 0; k < s->vertex_count; k++, d += 3) {
                v3 p = v3_add(st->r[i], m3_mul_v(&A, s->vertices[k]));
                d[0] = p.x, d[1] = p.y, d[2] = p.z;
            }
        }
        emit(f, T_F64, "Points", 3, np);
    }
    xml(f, "</Points>\n<PointData Vectors=\"velocity\">\n");
    if ((d = raw_take(f, T_F64, 3 * np)) != NULL) {
        for (size_t i = 0; i < b->slots; i++) {
            if (!b->alive[i])
                continue;
            m3 A = qt_to_m3(st->p[i]);
            v3 om = m3_mul_v(&A, st->w[i]);
            const ws_shape *s = b->shape[i];
            for (uint32_t k = 0; k < s->vertex_count; k++, d += 3) {
                v3 v = v3_add(st->v[i], v3_cross(om, m3_mul_v(&A, s->vertices[k])));
                d[0] = v.x, d[1] = v.y, d[2] = v.z;
            }
        }
        emit(f, T_F64, "velocity", 3, np);
    }
    xml(f, "</PointData>\n<CellData Scalars=\"body\">\n");
    const uint32_t *ix = body_index(f);
    int32_t *c = raw_take(f, T_I32, nt);
    if (c && ix) {
        for (size_t i = 0; i < b->slots; i++)
            if (b->alive[i])
                for (uint32_t k = 0; k < b->shape[i]->triangle_count; k++)
                    *c++ = (int32_t)ix[i];
        emit(f, T_I32, "body", 1, nt);
    }
    uint64_t *id = raw_take(f, T_U64, nt);
    if (id) {
        for (size_t i = 0; i < b->slots; i++)
            if (b->alive[i])
                for (uint32_t k = 0; k < b->shape[i]->triangle_count; k++)
                    *id++ = ws_make_body_id(w, (uint32_t)i).bits;
        emit(f, T_U64, "body_id", 1, nt);
    }
    /* The body's total contact force, on each of its triangles, so a viewer colours a body by the
     * load it carries. */
    if ((d = raw_take(f, T_F64, 3 * nt)) != NULL) {
        for (size_t i = 0; i < b->slots; i++) {
            if (!b->alive[i])
                continue;
            ws_vec3 fc = {0, 0, 0};
            ws_body_get_contact_force(w, ws_make_body_id(w, (uint32_t)i), &fc, NULL);
            for (uint32_t k = 0; k < b->shape[i]->triangle_count; k++, d += 3)
                d[0] = fc.x, d[1] = fc.y, d[2] = fc.z;
        }
        emit(f, T_F64, "contact_force", 3, nt);
    }
    xml(f, "</CellData>\n<Polys>\n");
    if ((c = raw_take(f, T_I32, 3 * nt)) != NULL) {
        size_t base = 0;
        for (size_t i = 0; i < b->slots; i++) {
            if (!b->alive[i])
                continue;
            const ws_shape *s = b->shape[i];
            for (uint32_t k = 0; k < 3 * s->triangle_count; k++)
                *c++ = (int32_t)(base + s->triangles[k]);
            base += s->vertex_count;
        }
        emit(f, T_I32, "connectivity", 1, 3 * nt);
    }
    emit_offsets(f, nt, 3);
    xml(f, "</Polys>\n</Piece>\n</PolyData>\n");
}

/* ---- contacts ---- */

static void compose_contacts(vtk_file *f, const ws_contact_info *ci, size_t n)
{
    file_begin(f, "PolyData");
    xml(f, "<PolyData>\n<FieldData>\n");
    emit_scalar(f, "TimeValue", f->w->time);
    xml(f, "</FieldData>\n<Piece NumberOfPoints=\"%zu\" NumberOfVerts=\"%zu\">\n<Points>\n", n, n);
    double *d;
    int32_t *c;
    /* One array of the contacts' vectors: what 0 point, 1 normal, 2 normal force, 3 friction
     * force, 4 slip velocity. */
    static const char *const vname[] = {"Points", "normal", "normal_force", "friction_force",
                                        "slip_velocity"};
    for (int what = 0; what < 5; what++) {
        if (what == 1)
            xml(f, "</Points>\n<PointData Vectors=\"normal_force\" Scalars=\"normal_force_N\">\n");
        if ((d = raw_take(f, T_F64, 3 * n)) == NULL)
            break;
        for (size_t k = 0; k < n; k++, d += 3) {
            ws_vec3 v = what == 0   ? ci[k].point
                        : what <= 2 ? ci[k].normal
                        : what == 3 ? ci[k].friction_force
                                    : ci[k].slip_velocity;
            double s = what == 2 ? ci[k].normal_force : 1.0; /* the normal force as a vector */
            d[0] = s * v.x, d[1] = s * v.y, d[2] = s * v.z;
        }
        emit(f, T_F64, vname[what], 3, n);
    }
    if ((d = raw_take(f, T_F64, n)) != NULL) {
        for (size_t k = 0; k < n; k++)
            d[k] = ci[k].normal_force;
        emit(f, T_F64, "normal_force_N", 1, n);
    }
    if ((d = raw_take(f, T_F64, n)) != NULL) {
        for (size_t k = 0; k < n; k++)
            d[k] = ci[k].overlap;
        emit(f, T_F64, "overlap", 1, n);
    }
    const uint32_t *ix = body_index(f);
    for (int which = 0; which < 4; which++) {
        if ((c = raw_take(f, T_I32, n)) == NULL || !ix)
            break;
        for (size_t k = 0; k < n; k++) {
            uint32_t slot = 0;
            ws_body_id id = which == 0 ? ci[k].body_a : ci[k].body_b;
            if (which < 2)
                c[k] = ws_lookup_body(f->w, id, &slot) == WS_OK ? (int32_t)ix[slot] : -1;
            else
                c[k] = which == 2 ? ci[k].kind : ci[k].slipping;
        }
        static const char *const iname[] = {"body_a", "body_b", "kind", "slipping"};
        emit(f, T_I32, iname[which], 1, n);
    }
    xml(f, "</PointData>\n<Verts>\n");
    if ((c = raw_take(f, T_I32, n)) != NULL) {
        for (size_t k = 0; k < n; k++)
            c[k] = (int32_t)k;
        emit(f, T_I32, "connectivity", 1, n);
    }
    emit_offsets(f, n, 1);
    xml(f, "</Verts>\n</Piece>\n</PolyData>\n");
}

/* ---- webs ---- */

/* The grid numbering of build.c (ws_web_build_grid): the around-springs of row j are
 * j cols + i, from (i, j) to (i + 1 mod nx, j); then the up-springs, cols ny + j nx + i, from
 * (i, j) to (i, j + 1). A quad (i, j) has the around-springs of rows j and j + 1 and the
 * up-springs of columns i and i + 1 (mod nx) as its edges. */
static int web_cols(const ws_web *web)
{
    return web->closed ? web->nx : web->nx - 1;
}

static size_t web_quad_count(const ws_web *web)
{
    return web->nx > 0 && web->ny > 1 ? (size_t)web_cols(web) * (size_t)(web->ny - 1) : 0;
}

static void web_quad_edges(const ws_web *web, size_t q, uint32_t e[4])
{
    uint32_t nx = (uint32_t)web->nx, cols = (uint32_t)web_cols(web), ny = (uint32_t)web->ny;
    uint32_t i = (uint32_t)(q % cols), j = (uint32_t)(q / cols);
    e[0] = j * cols + i;
    e[1] = (j + 1) * cols + i;
    e[2] = cols * ny + j * nx + i;
    e[3] = cols * ny + j * nx + (i + 1) % nx;
}

static void web_quad_nodes(const ws_web *web, size_t q, uint32_t c[4])
{
    uint32_t nx = (uint32_t)web->nx, cols = (uint32_t)web_cols(web);
    uint32_t i = (uint32_t)(q % cols), j = (uint32_t)(q / cols), i1 = (i + 1) % nx;
    c[0] = i + nx * j;
    c[1] = i1 + nx * j;
    c[2] = i1 + nx * (j + 1);
    c[3] = i + nx * (j + 1);
}

/* The quads need the springs to be numbered as build.c numbers them; check it rather than trust
 * it, so a change there cannot write cells over the wrong nodes. */
static int web_grid_consistent(const ws_web *web)
{
    size_t nq = web_quad_count(web);
    for (size_t q = 0; q < nq; q++) {
        uint32_t e[4], c[4];
        web_quad_edges(web, q, e);
        web_quad_nodes(web, q, c);
        if (e[3] >= web->ns || web->sa[e[0]] != c[0] || web->sb[e[0]] != c[1] ||
            web->sa[e[1]] != c[3] || web->sb[e[1]] != c[2] || web->sa[e[2]] != c[0] ||
            web->sb[e[2]] != c[3] || web->sa[e[3]] != c[1] || web->sb[e[3]] != c[2])
            return 0;
    }
    return 1;
}

/* One scalar of a spring: 0 tension (N), 1 strain. */
static double spring_value(const ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s, int what)
{
    return what == 0 ? ws_web_spring_tension(web, x, v, s) : ws_web_spring_strain(web, x, s);
}

static const char *web_label(const ws_web *web)
{
    return web->name ? web->name : "";
}

/* Node means of tension or strain over the springs of one kind at each node; 0 where none. The
 * sums go through the force scratch, which holds nothing between steps (ws_web_node_limits),
 * so the writer needs no room of its own for them. */
static void emit_node_means(vtk_file *f, ws_web *web, ws_nodes3 x, ws_nodes3 v, int what, int kind,
                            const char *name)
{
    ws_nodes3 acc = web->f;
    for (uint32_t i = 0; i < web->n; i++)
        acc.x[i] = acc.y[i] = 0.0;
    for (uint32_t s = 0; s < web->ns; s++) {
        if (web->kind[s] != kind)
            continue;
        double val = spring_value(web, x, v, s, what);
        acc.x[web->sa[s]] += val;
        acc.x[web->sb[s]] += val;
        acc.y[web->sa[s]] += 1.0;
        acc.y[web->sb[s]] += 1.0;
    }
    double *d = raw_take(f, T_F64, web->n);
    if (d) {
        for (uint32_t i = 0; i < web->n; i++)
            d[i] = acc.y[i] > 0.0 ? acc.x[i] / acc.y[i] : 0.0;
        emit(f, T_F64, name, 1, web->n);
    }
    for (uint32_t i = 0; i < web->n; i++)
        acc.x[i] = acc.y[i] = 0.0;
}

static void web_fields(vtk_file *f, ws_web *web, uint32_t slot, int bands)
{
    ws_world *w = f->w;
    xml(f, "<FieldData>\n");
    emit_scalar(f, "TimeValue", w->time);
    const char *name = web_label(web);
    char *s = raw_take(f, T_STR, strlen(name) + 1);
    if (s) {
        memcpy(s, name, strlen(name) + 1);
        emit(f, T_STR, "web_name", 1, 1);
    }
    uint64_t *id = raw_take(f, T_U64, 1);
    ws_web_id wid = {ws_slots_id(&w->web_slots, WS_KIND_WEB, slot)};
    if (id) {
        id[0] = wid.bits;
        emit(f, T_U64, "web_id", 1, 1);
    }
    /* The containment profile: hoop tension per height band, bottom to top. */
    if (web->nx > 0 && bands > 0) {
        size_t nb = (size_t)bands < (size_t)web->ny ? (size_t)bands : (size_t)web->ny;
        static const char *const bname[] = {"band_z_low", "band_z_high", "band_hoop_tension",
                                            "band_line_load", "band_contact_force"};
        ws_containment_band band[WS_VTK_MAX_BANDS];
        if (ws_web_get_containment(w, wid, band, nb) == WS_OK) {
            for (int what = 0; what < 5; what++) {
                double *d = raw_take(f, T_F64, nb);
                if (!d)
                    break;
                for (size_t k = 0; k < nb; k++)
                    d[k] = what == 0   ? band[k].z_low
                           : what == 1 ? band[k].z_high
                           : what == 2 ? band[k].hoop_tension
                           : what == 3 ? band[k].line_load
                                       : band[k].contact_force;
                emit(f, T_F64, bname[what], 1, nb);
            }
        }
    }
    xml(f, "</FieldData>\n");
}

/* The springs' tension, strain and kind as cell data of their lines. */
static void emit_spring_cells(vtk_file *f, ws_web *web, ws_nodes3 x, ws_nodes3 v)
{
    for (int what = 0; what < 2; what++) {
        double *d = raw_take(f, T_F64, web->ns);
        if (!d)
            return;
        for (uint32_t s = 0; s < web->ns; s++)
            d[s] = spring_value(web, x, v, s, what);
        emit(f, T_F64, what == 0 ? "tension" : "strain", 1, web->ns);
    }
    int32_t *c = raw_take(f, T_I32, web->ns);
    if (c) {
        for (uint32_t s = 0; s < web->ns; s++)
            c[s] = web->kind[s];
        emit(f, T_I32, "kind", 1, web->ns);
    }
}

static void emit_lines(vtk_file *f, const ws_web *web)
{
    int32_t *c = raw_take(f, T_I32, 2 * (size_t)web->ns);
    if (c) {
        for (uint32_t s = 0; s < web->ns; s++) {
            c[2 * s] = (int32_t)web->sa[s];
            c[2 * s + 1] = (int32_t)web->sb[s];
        }
        emit(f, T_I32, "connectivity", 1, 2 * (size_t)web->ns);
    }
    emit_offsets(f, web->ns, 2);
}

/* The film: nodes as points; for a grid web the quads of the grid, whose cells carry the around
 * and up tensions and strains apart (each the mean of the quad's two edges of that direction);
 * for a mesh web the springs as lines. `springs_only`: the springs block instead, every spring a
 * line with its own tension, strain and kind. */
static void compose_web(vtk_file *f, uint32_t slot, int springs_only, int bands)
{
    ws_world *w = f->w;
    ws_web *web = w->webs[slot];
    const ws_nodes3 x = web->x[w->cur], v = web->v[w->cur];
    size_t nq = springs_only ? 0 : web_quad_count(web);
    size_t nl = nq ? 0 : web->ns;
    file_begin(f, "PolyData");
    xml(f, "<PolyData>\n");
    web_fields(f, web, slot, springs_only ? 0 : bands);
    xml(f, "<Piece NumberOfPoints=\"%u\" NumberOfLines=\"%zu\" NumberOfPolys=\"%zu\">\n<Points>\n",
        web->n, nl, nq);
    emit_nodes(f, "Points", x, web->n);
    xml(f, "</Points>\n<PointData Vectors=\"velocity\" Scalars=\"tension_around\">\n");
    emit_nodes(f, "velocity", v, web->n);
    emit_v3(f, "contact_force", web->fc[w->cur], web->n);
    emit_node_means(f, web, x, v, 0, WS_SPRING_AROUND, "tension_around");
    emit_node_means(f, web, x, v, 0, WS_SPRING_UP, "tension_up");
    xml(f, "</PointData>\n");
    if (nq) {
        xml(f, "<CellData Scalars=\"tension_around\">\n");
        static const char *const qname[4] = {"tension_around", "tension_up", "strain_around",
                                             "strain_up"};
        for (int a = 0; a < 4; a++) {
            double *d = raw_take(f, T_F64, nq);
            if (!d)
                break;
            for (size_t q = 0; q < nq; q++) {
                uint32_t e[4];
                web_quad_edges(web, q, e);
                int k = (a & 1) ? 2 : 0; /* e[0], e[1] around; e[2], e[3] up */
                d[q] = 0.5 * (spring_value(web, x, v, e[k], a >> 1) +
                              spring_value(web, x, v, e[k + 1], a >> 1));
            }
            emit(f, T_F64, qname[a], 1, nq);
        }
        xml(f, "</CellData>\n<Polys>\n");
        int32_t *c = raw_take(f, T_I32, 4 * nq);
        if (c) {
            for (size_t q = 0; q < nq; q++) {
                uint32_t n4[4];
                web_quad_nodes(web, q, n4);
                for (int k = 0; k < 4; k++)
                    c[4 * q + (size_t)k] = (int32_t)n4[k];
            }
            emit(f, T_I32, "connectivity", 1, 4 * nq);
        }
        emit_offsets(f, nq, 4);
        xml(f, "</Polys>\n");
    } else {
        xml(f, "<CellData Scalars=\"tension\">\n");
        emit_spring_cells(f, web, x, v);
        xml(f, "</CellData>\n<Lines>\n");
        emit_lines(f, web);
        xml(f, "</Lines>\n");
    }
    xml(f, "</Piece>\n</PolyData>\n");
}

/* ---- single files ---- */

static ws_status check_path(ws_world *w, const char *path, const char *fn)
{
    if (!path || !*path)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: path is NULL or empty", fn);
    return WS_OK;
}

ws_status ws_world_write_vtp(ws_world *w, const char *path)
{
    NEED_WORLD(w);
    ws_status s = check_path(w, path, "ws_world_write_vtp");
    if (s != WS_OK)
        return s;
    vtk_file f = {.w = w, .format = WS_VTK_ASCII};
    compose_bodies(&f);
    s = file_write(&f, path);
    vtk_file_free(&f);
    return s;
}

static ws_status check_grid(ws_world *w, uint32_t slot)
{
    const ws_web *web = w->webs[slot];
    if (web_quad_count(web) && !web_grid_consistent(web))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': its springs are not numbered as a grid; cannot write its quads",
                       web->name ? web->name : "(unnamed)");
    return WS_OK;
}

ws_status ws_web_write_vtp(ws_world *w, ws_web_id web, const char *path)
{
    NEED_WORLD(w);
    uint32_t slot;
    ws_status s = ws_lookup_web(w, web, &slot);
    if (s != WS_OK || (s = check_path(w, path, "ws_web_write_vtp")) != WS_OK ||
        (s = check_grid(w, slot)) != WS_OK)
        return s;
    vtk_file f = {.w = w, .format = WS_VTK_ASCII};
    compose_web(&f, slot, 0, WS_VTK_DEFAULT_BANDS);
    s = file_write(&f, path);
    vtk_file_free(&f);
    return s;
}

/* ---- series ---- */

struct ws_vtk_series {
    ws_world *world;
    ws_vtk_series_def def;
    char *directory;
    char *basename;
    double *times;     /* of the frames written */
    size_t count, cap; /* frames written; room in times */
    uint64_t calls;    /* ws_vtk_series_write_frame calls */
    double last_slot;  /* time-stride slot of the last frame written */
    ws_contact_info *contacts;
    size_t contact_cap;
    vtk_file file;
};

static void vtk_series_defaults(ws_vtk_series_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->format = WS_VTK_COMPRESSED;
    def->frame_stride = 1;
    def->time_stride = 0.0;
    def->springs = 0;
    def->contacts = 1;
    def->containment_bands = WS_VTK_DEFAULT_BANDS;
    def->double_precision = 0;
}
WS_DEF_INITS(ws_vtk_series_def, vtk_series_defaults, double_precision)

ws_status ws_vtk_series_create_def(ws_world *w, const ws_vtk_series_def *def, ws_vtk_series **out)
{
    NEED_WORLD(w);
    NEED_OUT(w, out, "ws_vtk_series_create_def");
    *out = NULL;
    ws_vtk_series_def d;
    ws_vtk_series_def_init(&d);
    ws_status st = ws_def_take(w, &d, sizeof d, def, "vtk_series");
    if (st != WS_OK)
        return st;
    if (!d.directory || !d.basename || !*d.basename || strchr(d.basename, '/'))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_vtk_series_create: need a directory and a basename without '/'");
    if (d.format < WS_VTK_COMPRESSED || d.format > WS_VTK_ASCII)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "vtk_series: format must be 0..2 (ws_vtk_format), got %d", d.format);
    if (d.frame_stride < 1)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "vtk_series: frame_stride must be >= 1, got %d",
                       d.frame_stride);
    if (!(isfinite(d.time_stride) && d.time_stride >= 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "vtk_series: time_stride must be finite and >= 0 s, got %g", d.time_stride);
    if (d.containment_bands < 0 || d.containment_bands > WS_VTK_MAX_BANDS)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "vtk_series: containment_bands must be 0..%d, got %d", WS_VTK_MAX_BANDS,
                       d.containment_bands);
    /* Refused now rather than at the first frame, minutes into a run. */
    struct stat dir;
    if (stat(d.directory, &dir) != 0)
        return ws_fail(w, WS_ERR_IO, "ws_vtk_series_create: directory '%s': %s", d.directory,
                       strerror(errno));
    if (!S_ISDIR(dir.st_mode))
        return ws_fail(w, WS_ERR_IO, "ws_vtk_series_create: '%s' is not a directory",
                       d.directory);
#ifndef WS_HAVE_ZLIB
    /* Without zlib the binary form is the raw one: the same files, uncompressed. */
    if (d.format == WS_VTK_COMPRESSED)
        d.format = WS_VTK_BINARY;
#endif
    ws_vtk_series *s = ws_mem_calloc(&w->mem, 1, sizeof *s);
    if (!s)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_vtk_series_create: out of memory");
    s->world = w;
    s->file.w = w;
    s->file.format = d.format;
    s->file.single = !d.double_precision;
    s->directory = ws_mem_strdup(&w->mem, d.directory);
    s->basename = ws_mem_strdup(&w->mem, d.basename);
    d.directory = d.basename = NULL; /* the copies above are the series' own */
    s->def = d;
    if (!s->directory || !s->basename) {
        ws_vtk_series_destroy(s);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_vtk_series_create: out of memory");
    }
    *out = s;
    return WS_OK;
}

ws_status ws_vtk_series_create(ws_world *w, const char *directory, const char *basename,
                               ws_vtk_series **out)
{
    ws_vtk_series_def def;
    ws_vtk_series_def_init(&def);
    def.directory = directory;
    def.basename = basename;
    return ws_vtk_series_create_def(w, &def, out);
}

/* Text into an XML attribute value: the five characters XML reserves as entities. */
static void put_attr(FILE *f, const char *text)
{
    for (const char *c = text; *c; c++) {
        switch (*c) {
        case '&':
            fputs("&amp;", f);
            break;
        case '<':
            fputs("&lt;", f);
            break;
        case '>':
            fputs("&gt;", f);
            break;
        case '"':
            fputs("&quot;", f);
            break;
        case '\'':
            fputs("&apos;", f);
            break;
        default:
            fputc(*c, f);
        }
    }
}

/* One frame's line of the .pvd. */
static void put_pvd_entry(FILE *f, const ws_vtk_series *s, size_t k)
{
    char file[64];
    fprintf(f, "<DataSet timestep=\"%.9g\" part=\"0\" file=\"", s->times[k]);
    put_attr(f, s->basename);
    snprintf(file, sizeof file, "_%06zu.vtm", k);
    fprintf(f, "%s\"/>\n", file);
}

static const char pvd_tail[] = "</Collection>\n</VTKFile>\n";

/* Add the newest frame to the .pvd in place: over its closing tags, the new entry and the tags
 * again, so a long series costs the same per frame as a short one. 0 when done; -1 when the file
 * does not end as this series left it (or cannot be read), and it must be written whole. */
static int append_pvd(const ws_vtk_series *s, const char *path)
{
    size_t k = s->count - 1, tail = sizeof pvd_tail - 1;
    char end[sizeof pvd_tail];
    FILE *f = fopen(path, "r+b");
    if (!f)
        return -1;
    int ok = fseek(f, -(long)tail, SEEK_END) == 0 && fread(end, 1, tail, f) == tail &&
             memcmp(end, pvd_tail, tail) == 0 && fseek(f, -(long)tail, SEEK_END) == 0;
    if (ok) {
        put_pvd_entry(f, s, k);
        fputs(pvd_tail, f);
        ok = !ferror(f);
    }
    return fclose(f) == 0 && ok ? 0 : -1;
}

static ws_status write_pvd(ws_vtk_series *s)
{
    char path[4096];
    ws_world *w = s->world;
    if (snprintf(path, sizeof path, "%s/%s.pvd", s->directory, s->basename) >= (int)sizeof path)
        return ws_fail(w, WS_ERR_IO, "path too long for '%s'", s->basename);
    if (s->count > 1 && append_pvd(s, path) == 0)
        return WS_OK;
    FILE *f = fopen(path, "w");
    if (!f)
        return ws_fail(w, WS_ERR_IO, "cannot open '%s' for writing: %s", path, strerror(errno));
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\">\n"
               "<Collection>\n");
    for (size_t k = 0; k < s->count; k++)
        put_pvd_entry(f, s, k);
    fputs(pvd_tail, f);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return ws_fail(w, WS_ERR_IO, "error while writing '%s'", path);
    return WS_OK;
}

/* The path of a block file of the frame being written: `what` names the block, `slot` the web
 * (SIZE_MAX: none). */
static ws_status frame_path(ws_vtk_series *s, char *path, size_t cap, const char *what, size_t slot)
{
    int n = slot == SIZE_MAX ? snprintf(path, cap, "%s/%s_%06zu_%s.vtp", s->directory, s->basename,
                                        s->count, what)
                             : snprintf(path, cap, "%s/%s_%06zu_%s%zu.vtp", s->directory,
                                        s->basename, s->count, what, slot);
    if (n < 0 || (size_t)n >= cap)
        return ws_fail(s->world, WS_ERR_IO, "path too long for '%s'", s->basename);
    return WS_OK;
}

/* The file name without its directory, as the .vtm refers to it. */
static const char *leaf(const ws_vtk_series *s, const char *path)
{
    return path + strlen(s->directory) + 1;
}

/* One dataset of the .vtm: <DataSet index="index" name="name" file="leaf of path"/>. */
static void put_dataset(FILE *vtm, const ws_vtk_series *s, unsigned index, const char *name,
                        const char *path)
{
    fprintf(vtm, "<DataSet index=\"%u\" name=\"", index);
    put_attr(vtm, name);
    fputs("\" file=\"", vtm);
    put_attr(vtm, leaf(s, path));
    fputs("\"/>\n", vtm);
}

/* Write the block files of the frame and the .vtm that names them: bodies, film, contacts
 * (when asked), springs (when asked), numbered in that order. */
static ws_status write_vtm(ws_vtk_series *s)
{
    ws_world *w = s->world;
    char path[4096], name[64];
    FILE *vtm = NULL;
    ws_status st = WS_OK;
    int n = snprintf(path, sizeof path, "%s/%s_%06zu.vtm", s->directory, s->basename, s->count);
    if (n < 0 || (size_t)n >= sizeof path)
        return ws_fail(w, WS_ERR_IO, "path too long for '%s'", s->basename);
    if (!(vtm = fopen(path, "w")))
        return ws_fail(w, WS_ERR_IO, "cannot open '%s' for writing: %s", path, strerror(errno));
    fprintf(vtm, "<?xml version=\"1.0\"?>\n<VTKFile type=\"vtkMultiBlockDataSet\" version=\"1.0\" "
                 "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<vtkMultiBlockDataSet>\n");
    vtk_file *f = &s->file;
    /* bodies */
    if ((st = frame_path(s, path, sizeof path, "bodies", SIZE_MAX)) != WS_OK)
        goto done;
    compose_bodies(f);
    if ((st = file_write(f, path)) != WS_OK)
        goto done;
    unsigned block = 0;
    put_dataset(vtm, s, block++, "bodies", path);
    /* film and springs: one block each, a dataset per web alive; contacts between them */
    for (int springs = 0; springs < 1 + (s->def.springs != 0); springs++) {
        fprintf(vtm, "<Block index=\"%u\" name=\"%s\">\n", block++, springs ? "springs" : "film");
        unsigned m = 0;
        for (size_t k = 0; k < w->web_slots.slot_count; k++) {
            if (w->web_slots.dense[k] == UINT32_MAX)
                continue;
            if ((st = check_grid(w, (uint32_t)k)) != WS_OK ||
                (st = frame_path(s, path, sizeof path, springs ? "springs" : "film", k)) != WS_OK)
                goto done;
            compose_web(f, (uint32_t)k, springs, s->def.containment_bands);
            if ((st = file_write(f, path)) != WS_OK)
                goto done;
            const ws_web *web = w->webs[k];
            if (!web->name)
                snprintf(name, sizeof name, "web%zu", k);
            put_dataset(vtm, s, m++, web->name ? web->name : name, path);
        }
        fprintf(vtm, "</Block>\n");
        if (!springs && s->def.contacts) {
            size_t nc = 0;
            ws_world_get_contact_count(w, &nc);
            if (ws_array_reserve(&w->mem, (void **)&s->contacts, &s->contact_cap, nc + 1,
                                 sizeof *s->contacts) != 0) {
                st = ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_vtk_series_write_frame: out of memory");
                goto done;
            }
            ws_world_copy_contacts(w, s->contacts, s->contact_cap, &nc);
            if ((st = frame_path(s, path, sizeof path, "contacts", SIZE_MAX)) != WS_OK)
                goto done;
            compose_contacts(f, s->contacts, nc);
            if ((st = file_write(f, path)) != WS_OK)
                goto done;
            put_dataset(vtm, s, block++, "contacts", path);
        }
    }
    fprintf(vtm, "</vtkMultiBlockDataSet>\n</VTKFile>\n");
done:;
    int bad = ferror(vtm);
    if (fclose(vtm) != 0 || bad) {
        if (st == WS_OK)
            st =
                ws_fail(w, WS_ERR_IO, "error while writing the frame's .vtm in '%s'", s->directory);
    }
    return st;
}

ws_status ws_vtk_series_write_frame(ws_vtk_series *s)
{
    if (!s)
        return WS_ERR_INVALID_ARGUMENT;
    ws_world *w = s->world;
    /* The strides: every frame_stride-th call, and at most one frame per time_stride, the first
     * call always. The time slot takes a millionth of a stride as slack so that a time a step
     * short of a multiple through rounding still counts as that multiple. */
    uint64_t call = s->calls++;
    if (call % (uint64_t)s->def.frame_stride != 0)
        return WS_OK;
    if (s->def.time_stride > 0.0) {
        double slot = floor(w->time / s->def.time_stride + 1e-6);
        if (s->count > 0 && slot <= s->last_slot)
            return WS_OK;
        s->last_slot = slot;
    }
    if (ws_array_reserve(&w->mem, (void **)&s->times, &s->cap, s->count + 1, sizeof *s->times) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_vtk_series_write_frame: out of memory");
    ws_status st = write_vtm(s);
    if (st != WS_OK)
        return st;
    s->times[s->count++] = w->time;
    return write_pvd(s);
}

ws_status ws_vtk_series_get_frame_count(const ws_vtk_series *s, size_t *count)
{
    if (!s || !count)
        return WS_ERR_INVALID_ARGUMENT;
    *count = s->count;
    return WS_OK;
}

void ws_vtk_series_destroy(ws_vtk_series *s)
{
    if (!s)
        return;
    ws_mem *m = &s->world->mem;
    vtk_file_free(&s->file);
    ws_mem_free_str(m, s->directory);
    ws_mem_free_str(m, s->basename);
    ws_mem_free(m, s->times, s->cap * sizeof *s->times);
    ws_mem_free(m, s->contacts, s->contact_cap * sizeof *s->contacts);
    ws_mem_free(m, s, sizeof *s);
}
