/* VTK XML PolyData frames (bodies; each web apart) and a ParaView .pvd collection. Reads the
 * world, writes files only when asked. */
#define _POSIX_C_SOURCE 200809L /* stat, to check the series' directory */
#include "world/world_internal.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#if !defined(S_ISDIR) && defined(S_IFDIR)
#define S_ISDIR(m) (((m) & S_IFMT) == S_IFDIR)
#endif

struct ws_vtk_series {
    ws_world *world;
    char *directory;
    char *basename;
    double *times;
    size_t count, cap;
    /* The webs written with each frame: their slots, frame after frame; web_end[k] is where the
     * run of frame k ends (the one of frame k - 1, or 0, is where it starts). */
    uint32_t *web_slot;
    size_t nweb, web_cap;
    size_t *web_end;
    size_t web_end_cap;
};

static ws_status write_vtp(ws_world *w, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return ws_fail(w, WS_ERR_IO, "cannot open '%s' for writing: %s", path, strerror(errno));
    const ws_body_store *b = &w->bodies;
    const ws_body_state *st = &b->st[w->cur];
    size_t np = 0, nt = 0;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        np += b->shape[i]->vertex_count;
        nt += b->shape[i]->triangle_count;
    }
    fprintf(f, "<?xml version=\"1.0\"?>\n"
               "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
               "<PolyData>\n<Piece NumberOfPoints=\"%zu\" NumberOfPolys=\"%zu\">\n",
            np, nt);
    fprintf(f, "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        m3 A = qt_to_m3(st->p[i]);
        const ws_shape *s = b->shape[i];
        for (uint32_t k = 0; k < s->vertex_count; k++) {
            v3 p = v3_add(st->r[i], m3_mul_v(&A, s->vertices[k]));
            fprintf(f, "%.9g %.9g %.9g\n", p.x, p.y, p.z);
        }
    }
    fprintf(f, "</DataArray>\n</Points>\n<PointData Vectors=\"velocity\">\n"
               "<DataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\" "
               "format=\"ascii\">\n");
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        m3 A = qt_to_m3(st->p[i]);
        v3 om = m3_mul_v(&A, st->w[i]);
        const ws_shape *s = b->shape[i];
        for (uint32_t k = 0; k < s->vertex_count; k++) {
            v3 v = v3_add(st->v[i], v3_cross(om, m3_mul_v(&A, s->vertices[k])));
            fprintf(f, "%.9g %.9g %.9g\n", v.x, v.y, v.z);
        }
    }
    fprintf(f, "</DataArray>\n</PointData>\n<CellData Scalars=\"body\">\n"
               "<DataArray type=\"Int32\" Name=\"body\" format=\"ascii\">\n");
    for (size_t i = 0; i < b->slots; i++)
        if (b->alive[i])
            for (uint32_t k = 0; k < b->shape[i]->triangle_count; k++)
                fprintf(f, "%zu\n", i);
    fprintf(f, "</DataArray>\n</CellData>\n<Polys>\n"
               "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    size_t base = 0;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        const ws_shape *s = b->shape[i];
        for (uint32_t k = 0; k < s->triangle_count; k++)
            fprintf(f, "%zu %zu %zu\n", base + s->triangles[3 * k], base + s->triangles[3 * k + 1],
                    base + s->triangles[3 * k + 2]);
        base += s->vertex_count;
    }
    fprintf(f, "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for (size_t k = 1; k <= nt; k++)
        fprintf(f, "%zu\n", 3 * k);
    fprintf(f, "</DataArray>\n</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return ws_fail(w, WS_ERR_IO, "error while writing '%s'", path);
    return WS_OK;
}

ws_status ws_world_write_vtp(ws_world *w, const char *path)
{
    if (!w)
        return WS_ERR_INVALID_ARGUMENT;
    if (!path || !*path)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_world_write_vtp: path is NULL or empty");
    return write_vtp(w, path);
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
static double web_spring_value(const ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s,
                               int what)
{
    return what == 0 ? ws_web_spring_tension(web, x, v, s) : ws_web_spring_strain(web, x, s);
}

static void write_web_array(FILE *f, ws_web *web, ws_nodes3 x, ws_nodes3 v, int what, int cells)
{
    static const char *const names[2] = {"tension", "strain"};
    fprintf(f, "<DataArray type=\"Float64\" Name=\"%s\" format=\"ascii\">\n", names[what]);
    if (!cells) {
        /* Node means from the force scratch: it holds nothing between steps (see node_bounds in
         * web.c), so the writer needs no allocation. .x: sum, .y: springs at the node. */
        ws_nodes3 acc = web->f;
        for (uint32_t i = 0; i < web->n; i++)
            acc.x[i] = acc.y[i] = 0.0;
        for (uint32_t s = 0; s < web->ns; s++) {
            double val = web_spring_value(web, x, v, s, what);
            acc.x[web->sa[s]] += val;
            acc.x[web->sb[s]] += val;
            acc.y[web->sa[s]] += 1.0;
            acc.y[web->sb[s]] += 1.0;
        }
        for (uint32_t i = 0; i < web->n; i++) {
            fprintf(f, "%.9g\n", acc.y[i] > 0.0 ? acc.x[i] / acc.y[i] : 0.0);
            acc.x[i] = acc.y[i] = 0.0;
        }
    } else {
        /* VTK orders the cells of a PolyData piece verts, lines, polys, strips: the springs
         * (lines) first, then the quads with the mean of their four edges. */
        for (uint32_t s = 0; s < web->ns; s++)
            fprintf(f, "%.9g\n", web_spring_value(web, x, v, s, what));
        size_t nq = web_quad_count(web);
        for (size_t q = 0; q < nq; q++) {
            uint32_t e[4];
            web_quad_edges(web, q, e);
            double sum = 0.0;
            for (int k = 0; k < 4; k++)
                sum += web_spring_value(web, x, v, e[k], what);
            fprintf(f, "%.9g\n", 0.25 * sum);
        }
    }
    fprintf(f, "</DataArray>\n");
}

static void write_v3_array(FILE *f, const char *name, const v3 *a, uint32_t n)
{
    fprintf(f, "<DataArray type=\"Float64\" Name=\"%s\" NumberOfComponents=\"3\" "
               "format=\"ascii\">\n",
            name);
    for (uint32_t i = 0; i < n; i++)
        fprintf(f, "%.9g %.9g %.9g\n", a[i].x, a[i].y, a[i].z);
    fprintf(f, "</DataArray>\n");
}

static void write_nodes_array(FILE *f, const char *name, ws_nodes3 a, uint32_t n)
{
    fprintf(f, "<DataArray type=\"Float64\" Name=\"%s\" NumberOfComponents=\"3\" "
               "format=\"ascii\">\n",
            name);
    for (uint32_t i = 0; i < n; i++)
        fprintf(f, "%.9g %.9g %.9g\n", a.x[i], a.y[i], a.z[i]);
    fprintf(f, "</DataArray>\n");
}

static ws_status write_web_vtp(ws_world *w, uint32_t slot, const char *path)
{
    ws_web *web = w->webs[slot];
    const char *label = web->name ? web->name : "(unnamed)";
    size_t nq = web_quad_count(web);
    if (nq && !web_grid_consistent(web))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "web '%s': its springs are not numbered as a grid; cannot write its quads",
                       label);
    FILE *f = fopen(path, "w");
    if (!f)
        return ws_fail(w, WS_ERR_IO, "cannot open '%s' for writing: %s", path, strerror(errno));
    const ws_nodes3 x = web->x[w->cur], v = web->v[w->cur];
    fprintf(f, "<?xml version=\"1.0\"?>\n"
               "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
               "<PolyData>\n<Piece NumberOfPoints=\"%u\" NumberOfVerts=\"0\" "
               "NumberOfLines=\"%u\" NumberOfStrips=\"0\" NumberOfPolys=\"%zu\">\n<Points>\n",
            web->n, web->ns, nq);
    write_nodes_array(f, "position", x, web->n);
    fprintf(f, "</Points>\n<PointData Scalars=\"tension\" Vectors=\"velocity\">\n");
    write_nodes_array(f, "velocity", v, web->n);
    write_v3_array(f, "contact_force", web->fc[w->cur], web->n);
    write_web_array(f, web, x, v, 0, 0);
    write_web_array(f, web, x, v, 1, 0);
    fprintf(f, "</PointData>\n<CellData Scalars=\"tension\">\n");
    write_web_array(f, web, x, v, 0, 1);
    write_web_array(f, web, x, v, 1, 1);
    fprintf(f, "</CellData>\n<Lines>\n"
               "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for (uint32_t s = 0; s < web->ns; s++)
        fprintf(f, "%u %u\n", web->sa[s], web->sb[s]);
    fprintf(f, "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for (size_t s = 1; s <= web->ns; s++)
        fprintf(f, "%zu\n", 2 * s);
    fprintf(f, "</DataArray>\n</Lines>\n");
    if (nq) {
        fprintf(f, "<Polys>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
        for (size_t q = 0; q < nq; q++) {
            uint32_t c[4];
            web_quad_nodes(web, q, c);
            fprintf(f, "%u %u %u %u\n", c[0], c[1], c[2], c[3]);
        }
        fprintf(f, "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
        for (size_t q = 1; q <= nq; q++)
            fprintf(f, "%zu\n", 4 * q);
        fprintf(f, "</DataArray>\n</Polys>\n");
    }
    fprintf(f, "</Piece>\n</PolyData>\n</VTKFile>\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return ws_fail(w, WS_ERR_IO, "error while writing '%s'", path);
    return WS_OK;
}

ws_status ws_web_write_vtp(ws_world *w, ws_web_id web, const char *path)
{
    NEED_WORLD(w);
    uint32_t slot;
    ws_status s = ws_lookup_web(w, web, &slot);
    if (s != WS_OK)
        return s;
    if (!path || !*path)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_web_write_vtp: path is NULL or empty");
    return write_web_vtp(w, slot, path);
}

/* ---- series ---- */

ws_status ws_vtk_series_create(ws_world *w, const char *directory, const char *basename,
                               ws_vtk_series **out)
{
    if (!w)
        return WS_ERR_INVALID_ARGUMENT;
    if (!out)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_vtk_series_create: out is NULL");
    *out = NULL;
    if (!directory || !basename || !*basename || strchr(basename, '/'))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_vtk_series_create: need a directory and a basename without '/'");
    /* Refused now rather than at the first frame, minutes into a run. */
    struct stat st;
    if (stat(directory, &st) != 0)
        return ws_fail(w, WS_ERR_IO, "ws_vtk_series_create: directory '%s': %s", directory,
                       strerror(errno));
    if (!S_ISDIR(st.st_mode))
        return ws_fail(w, WS_ERR_IO, "ws_vtk_series_create: '%s' is not a directory", directory);
    ws_vtk_series *s = ws_mem_calloc(&w->mem, 1, sizeof *s);
    if (!s)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_vtk_series_create: out of memory");
    s->world = w;
    s->directory = ws_mem_strdup(&w->mem, directory);
    s->basename = ws_mem_strdup(&w->mem, basename);
    if (!s->directory || !s->basename) {
        ws_vtk_series_destroy(s);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_vtk_series_create: out of memory");
    }
    *out = s;
    return WS_OK;
}

static ws_status write_pvd(ws_vtk_series *s)
{
    char path[4096];
    ws_world *w = s->world;
    if (snprintf(path, sizeof path, "%s/%s.pvd", s->directory, s->basename) >= (int)sizeof path)
        return ws_fail(w, WS_ERR_IO, "path too long for '%s'", s->basename);
    FILE *f = fopen(path, "w");
    if (!f)
        return ws_fail(w, WS_ERR_IO, "cannot open '%s' for writing: %s", path, strerror(errno));
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n"
               "<Collection>\n");
    /* Part 0: the bodies; part 1 + k: the web in slot k, so ParaView shows each as a block. */
    for (size_t k = 0; k < s->count; k++) {
        fprintf(f, "<DataSet timestep=\"%.9g\" part=\"0\" file=\"%s_%06zu.vtp\"/>\n", s->times[k],
                s->basename, k);
        for (size_t q = k ? s->web_end[k - 1] : 0; q < s->web_end[k]; q++)
            fprintf(f, "<DataSet timestep=\"%.9g\" part=\"%zu\" file=\"%s_web%u_%06zu.vtp\"/>\n",
                    s->times[k], 1 + (size_t)s->web_slot[q], s->basename, s->web_slot[q], k);
    }
    fprintf(f, "</Collection>\n</VTKFile>\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return ws_fail(w, WS_ERR_IO, "error while writing '%s'", path);
    return WS_OK;
}

ws_status ws_vtk_series_write_frame(ws_vtk_series *s)
{
    if (!s)
        return WS_ERR_INVALID_ARGUMENT;
    ws_world *w = s->world;
    char path[4096];
    if (snprintf(path, sizeof path, "%s/%s_%06zu.vtp", s->directory, s->basename, s->count) >=
        (int)sizeof path)
        return ws_fail(w, WS_ERR_IO, "path too long for '%s'", s->basename);
    size_t webs = 0;
    for (size_t k = 0; k < w->web_slots.slot_count; k++)
        webs += w->web_slots.dense[k] != UINT32_MAX;
    if (ws_array_reserve(&w->mem, (void **)&s->times, &s->cap, s->count + 1,
                         sizeof *s->times) != 0 ||
        ws_array_reserve(&w->mem, (void **)&s->web_end, &s->web_end_cap, s->count + 1,
                         sizeof *s->web_end) != 0 ||
        (webs && ws_array_reserve(&w->mem, (void **)&s->web_slot, &s->web_cap, s->nweb + webs,
                                  sizeof *s->web_slot) != 0))
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_vtk_series_write_frame: out of memory");
    ws_status st = write_vtp(w, path);
    if (st != WS_OK)
        return st;
    /* Each web in its own file, named by its slot, which stays the same while it lives. */
    size_t m = 0;
    for (size_t k = 0; k < w->web_slots.slot_count; k++) {
        if (w->web_slots.dense[k] == UINT32_MAX)
            continue;
        if (snprintf(path, sizeof path, "%s/%s_web%zu_%06zu.vtp", s->directory, s->basename, k,
                     s->count) >= (int)sizeof path)
            return ws_fail(w, WS_ERR_IO, "path too long for '%s'", s->basename);
        if ((st = write_web_vtp(w, (uint32_t)k, path)) != WS_OK)
            return st;
        s->web_slot[s->nweb + m++] = (uint32_t)k;
    }
    s->nweb += m;
    s->web_end[s->count] = s->nweb;
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
    ws_mem_free_str(m, s->directory);
    ws_mem_free_str(m, s->basename);
    ws_mem_free(m, s->times, s->cap * sizeof *s->times);
    ws_mem_free(m, s->web_slot, s->web_cap * sizeof *s->web_slot);
    ws_mem_free(m, s->web_end, s->web_end_cap * sizeof *s->web_end);
    ws_mem_free(m, s, sizeof *s);
}
