/* VTK XML PolyData frames and a ParaView .pvd collection. Reads the world, writes files only when
 * asked. */
#include "world/world_internal.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

struct ws_vtk_series {
    ws_world *world;
    char *directory;
    char *basename;
    double *times;
    size_t count, cap;
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
    for (size_t k = 0; k < s->count; k++)
        fprintf(f, "<DataSet timestep=\"%.9g\" part=\"0\" file=\"%s_%06zu.vtp\"/>\n", s->times[k],
                s->basename, k);
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
    if (ws_array_reserve(&w->mem, (void **)&s->times, &s->cap, s->count + 1, sizeof *s->times) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_vtk_series_write_frame: out of memory");
    ws_status st = write_vtp(w, path);
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
    ws_mem_free_str(m, s->directory);
    ws_mem_free_str(m, s->basename);
    ws_mem_free(m, s->times, s->cap * sizeof *s->times);
    ws_mem_free(m, s, sizeof *s);
}
