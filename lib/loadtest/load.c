/* Unit loads: the Def, the builder and the measurements relative to the pallet.
 *
 * Everything here goes through the public API of the world; world_internal.h is included only
 * for the last-error text (ws_fail) and the Def intake (ws_def_take). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <wrapsim/law.h>

#include "loadtest/loadtest.h"
#include "math/wmath.h"
#include "world/world_internal.h"

static ws_load_interface interface_default(double k, double c, double mu)
{
    ws_load_interface f;
    f.stiffness = k;
    f.damping = c;
    f.friction = mu;
    f.friction_vlim = 0.01;
    f.friction_model = WS_FRICTION_STICK;
    f.stick_stiffness = k;
    f.stick_damping = c;
    return f;
}

static void load_defaults(ws_load_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->pallet_size = v3_make(1.2, 0.8, 0.144);
    def->pallet_mass = 25.0;
    def->carton_size = v3_make(0.3, 0.4, 0.25);
    def->carton_mass = 10.0;
    def->layers = 4;
    def->count_x = 4;
    def->count_y = 2;
    def->pattern = WS_LOAD_COLUMN;
    def->gap = 0.003;
    def->contact_layer = 0.001;
    def->stiffness_rule = WS_LOAD_STIFFNESS_PER_INTERFACE;
    /* A carton of 10 kg on 2e6 N/m bears 100 N per layer above it with 0.05 mm of compression;
     * its bounce (447 rad/s) is 22 % damped by 2000 kg/s and needs no step under 1 ms. */
    def->carton_carton = interface_default(2e6, 2000.0, 0.4);
    def->carton_pallet = interface_default(2e6, 2000.0, 0.45);
    /* The pallet carries the whole load (345 kg for the reference case): ten times stiffer keeps
     * its compression near 0.2 mm, inside the contact layers. */
    def->pallet_platform = interface_default(2e7, 2e4, 0.8);
    def->film_carton = interface_default(4000.0, 1.0, 0.9);
    def->film_carton.friction_model = WS_FRICTION_REGULARIZED;
}

WS_DEF_INITS(ws_load_def, load_defaults, allocator)

/* ---- validation --------------------------------------------------------------------------- */

static int finite3(ws_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }
static int positive3(ws_vec3 v) { return finite3(v) && v.x > 0 && v.y > 0 && v.z > 0; }

static ws_status check_interface(const ws_world *w, const ws_load_interface *f, const char *name)
{
    if (!(isfinite(f->stiffness) && f->stiffness > 0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load %s: stiffness must be > 0 N/m, got %g",
                       name, f->stiffness);
    if (!(isfinite(f->damping) && f->damping >= 0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load %s: damping must be >= 0 kg/s, got %g",
                       name, f->damping);
    if (!(isfinite(f->friction) && f->friction >= 0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load %s: friction must be >= 0, got %g", name,
                       f->friction);
    if (!(isfinite(f->friction_vlim) && f->friction_vlim > 0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "load %s: friction_vlim must be > 0 m/s, got %g", name, f->friction_vlim);
    if (f->friction_model != WS_FRICTION_REGULARIZED && f->friction_model != WS_FRICTION_STICK)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load %s: unknown friction_model %d", name,
                       (int)f->friction_model);
    if (!(isfinite(f->stick_stiffness) && f->stick_stiffness > 0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "load %s: stick_stiffness must be > 0 N/m, got %g", name,
                       f->stick_stiffness);
    if (!(isfinite(f->stick_damping) && f->stick_damping >= 0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "load %s: stick_damping must be >= 0 kg/s, got %g", name, f->stick_damping);
    return WS_OK;
}

/* The grid of one layer: cartons along x and y, their size along the platform's axes, the
 * pitch and the centre of the first carton relative to the pallet's centre. */
typedef struct layer_grid {
    int nx, ny, turned;
    ws_vec3 size;
    double px, py, x0, y0;
} layer_grid;

static layer_grid grid_of(const ws_load_def *d, int layer)
{
    layer_grid g;
    /* Cartons are placed at their nominal pitch; their meshes are smaller by the clearance. */
    double px = d->carton_size.x, py = d->carton_size.y;
    g.nx = d->count_x;
    g.ny = d->count_y;
    g.turned = 0;
    g.size = d->carton_size;
    g.px = px;
    g.py = py;
    if (layer % 2 == 1 && d->pattern == WS_LOAD_BRICK) {
        g.nx = d->count_x - 1;
    } else if (layer % 2 == 1 && d->pattern == WS_LOAD_TURNED) {
        /* As many turned cartons as fit in the first layer's extent. */
        double ex = d->count_x * px, ey = d->count_y * py;
        g.turned = 1;
        g.size = v3_make(d->carton_size.y, d->carton_size.x, d->carton_size.z);
        g.px = g.size.x;
        g.py = g.size.y;
        g.nx = (int)floor(ex / g.px + 1e-9);
        g.ny = (int)floor(ey / g.py + 1e-9);
    }
    g.x0 = -0.5 * (g.nx - 1) * g.px;
    g.y0 = -0.5 * (g.ny - 1) * g.py;
    return g;
}

static ws_status check_def(const ws_world *w, const ws_load_def *d)
{
    ws_status s;
    if (!positive3(d->pallet_size))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "load: pallet_size must be > 0 m in x, y and z, got (%g, %g, %g)",
                       d->pallet_size.x, d->pallet_size.y, d->pallet_size.z);
    if (!positive3(d->carton_size))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "load: carton_size must be > 0 m in x, y and z, got (%g, %g, %g)",
                       d->carton_size.x, d->carton_size.y, d->carton_size.z);
    if (!(isfinite(d->pallet_mass) && d->pallet_mass > 0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load: pallet_mass must be > 0 kg, got %g",
                       d->pallet_mass);
    if (!(isfinite(d->carton_mass) && d->carton_mass > 0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load: carton_mass must be > 0 kg, got %g",
                       d->carton_mass);
    if (d->layers < 1 || d->layers > WS_LOAD_MAX_LAYERS)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load: layers must be 1..%d, got %d",
                       WS_LOAD_MAX_LAYERS, d->layers);
    if (d->count_x < 1 || d->count_y < 1)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "load: count_x and count_y must be >= 1, got %d and %d", d->count_x,
                       d->count_y);
    if (d->pattern != WS_LOAD_COLUMN && d->pattern != WS_LOAD_BRICK &&
        d->pattern != WS_LOAD_TURNED)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load: unknown pattern %d", (int)d->pattern);
    if (d->pattern == WS_LOAD_BRICK && d->count_x < 2 && d->layers > 1)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "load: a brick pattern needs count_x >= 2 (its shifted rows hold one "
                       "carton fewer), got %d", d->count_x);
    if (!(isfinite(d->gap) && d->gap >= 0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load: gap must be >= 0 m, got %g", d->gap);
    if (!(isfinite(d->contact_layer) && d->contact_layer >= 0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load: contact_layer must be >= 0 m, got %g",
                       d->contact_layer);
    double cut = 2 * d->contact_layer + d->gap + 2 * WS_LOAD_INSET;
    if (cut >= 0.5 * fmin(d->carton_size.x, d->carton_size.y))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "load: the clearance 2 contact_layer + gap + 2 mm = %g m must be under half the "
                       "carton's least side (%g m)", cut, fmin(d->carton_size.x, d->carton_size.y));
    if (d->stiffness_rule != WS_LOAD_STIFFNESS_PER_INTERFACE &&
        d->stiffness_rule != WS_LOAD_STIFFNESS_PER_POINT)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load: unknown stiffness_rule %d",
                       (int)d->stiffness_rule);
    if (!finite3(d->origin))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "load: origin is not finite");
    if ((s = check_interface(w, &d->carton_carton, "carton_carton")) != WS_OK ||
        (s = check_interface(w, &d->carton_pallet, "carton_pallet")) != WS_OK ||
        (s = check_interface(w, &d->pallet_platform, "pallet_platform")) != WS_OK ||
        (s = check_interface(w, &d->film_carton, "film_carton")) != WS_OK)
        return s;
    for (int l = 0; l < d->layers; l++) {
        layer_grid g = grid_of(d, l);
        if (g.nx < 1 || g.ny < 1 || (long)g.nx * g.ny > WS_LOAD_MAX_PER_LAYER)
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "load: layer %d holds %d x %d cartons; it must hold 1..%d", l, g.nx,
                           g.ny, WS_LOAD_MAX_PER_LAYER);
    }
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL) ||
        (d->allocator.alloc == NULL) != (d->allocator.realloc == NULL))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "load: allocator hooks must be given all three or none");
    return WS_OK;
}

/* ---- building ----------------------------------------------------------------------------- */

static const ws_load_key *find_key(const ws_load_key *keys, size_t n, uint64_t bits)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (keys[mid].bits < bits)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < n && keys[lo].bits == bits ? &keys[lo] : NULL;
}

const ws_load_key *ws_load_find(const ws_load *load, ws_body_id id)
{
    return find_key(load->keys, load->nkeys, id.bits);
}

static int key_order(const void *a, const void *b)
{
    uint64_t x = ((const ws_load_key *)a)->bits, y = ((const ws_load_key *)b)->bits;
    return x < y ? -1 : x > y;
}

/* The contact parameters of an interface as the world takes them: per point. */
static ws_contact_def per_point(const ws_load_interface *f, int points)
{
    ws_contact_def c;
    ws_contact_def_init(&c);
    c.stiffness = f->stiffness / points;
    c.damping = f->damping / points;
    c.friction = f->friction;
    c.friction_vlim = f->friction_vlim;
    c.friction_model = f->friction_model;
    c.stick_stiffness = f->stick_stiffness / points;
    c.stick_damping = f->stick_damping / points;
    return c;
}

static ws_status new_material(ws_world *w, const char *name, ws_material_id *out)
{
    ws_material_def md;
    ws_material_def_init(&md);
    md.name = name;
    return ws_material_create(w, &md, out);
}

static ws_status set_pair(ws_world *w, ws_load *ld, int kind, const ws_load_interface *f,
                          ws_material_id a, ws_material_id b, int per_interface_points)
{
    int n = per_interface_points;
    ld->points[kind] = n;
    ld->point_stiffness[kind] = f->stiffness / n;
    ld->friction[kind] = f->friction;
    ws_contact_def c = per_point(f, n);
    return ws_world_set_contact(w, a, b, &c);
}

static ws_status set_contacts(ws_world *w, const ws_load_def *d, ws_load *ld)
{
    ws_load_info *in = &ld->info;
    int per_if = d->stiffness_rule == WS_LOAD_STIFFNESS_PER_INTERFACE;
    ws_status s;
    /* Every face pair of the load touches at 4 points: the corners of the smaller face (the
     * cartons of alternate layers differ by WS_LOAD_INSET a side; the deck is larger than a
     * carton, the platform than the pallet). */
    if ((s = set_pair(w, ld, WS_IF_CARTON_CARTON, &d->carton_carton, in->carton_material,
                      in->carton_material, per_if ? 4 : 1)) != WS_OK ||
        (s = set_pair(w, ld, WS_IF_CARTON_PALLET, &d->carton_pallet, in->carton_material,
                      in->pallet_material, per_if ? 4 : 1)) != WS_OK ||
        (s = set_pair(w, ld, WS_IF_CARTON_PALLET, &d->carton_pallet, in->carton_material,
                      in->platform_material, per_if ? 4 : 1)) != WS_OK ||
        (s = set_pair(w, ld, WS_IF_PALLET_PLATFORM, &d->pallet_platform, in->pallet_material,
                      in->platform_material, per_if ? 4 : 1)) != WS_OK ||
        (s = set_pair(w, ld, WS_IF_FILM_CARTON, &d->film_carton, in->film_material,
                      in->pallet_material, 1)) != WS_OK ||
        (s = set_pair(w, ld, WS_IF_FILM_CARTON, &d->film_carton, in->film_material,
                      in->carton_material, 1)) != WS_OK)
        return s;
    return WS_OK;
}

/* A body of the load at `local` (platform frame, from the origin) turned by `turn` about the
 * platform's vertical. */
static ws_status place_body(ws_world *w, const ws_body_def *proto, const m3 *a_pf, qt q_pf,
                            ws_vec3 origin, ws_vec3 local, int turned, ws_body_id *out)
{
    ws_body_def bd = *proto;
    bd.position = v3_add(origin, m3_mul_v(a_pf, local));
    qt turn = turned ? qt_from_axis_angle(v3_make(0, 0, 1), 0.5 * WS_PI) : qt_identity();
    bd.orientation = qt_mul(q_pf, turn);
    return ws_body_create(w, &bd, out);
}

static ws_load *load_alloc(const ws_load_def *d, const ws_world *w, size_t cartons)
{
    ws_mem mem;
    ws_mem_init(&mem, &d->allocator);
    ws_load *ld = ws_mem_calloc(&mem, 1, sizeof *ld);
    if (!ld)
        return NULL;
    ld->mem = mem;
    ld->world = w;
    ld->carton = ws_mem_calloc(&ld->mem, cartons, sizeof *ld->carton);
    ld->reference = ws_mem_calloc(&ld->mem, cartons, sizeof *ld->reference);
    ld->carton_bottom = ws_mem_calloc(&ld->mem, cartons, sizeof *ld->carton_bottom);
    ld->keys = ws_mem_calloc(&ld->mem, cartons + 2, sizeof *ld->keys);
    if (!ld->carton || !ld->reference || !ld->carton_bottom || !ld->keys) {
        ld->info.cartons = (int)cartons;
        ws_load_destroy(ld);
        return NULL;
    }
    ld->info.cartons = (int)cartons;
    return ld;
}

void ws_load_destroy(ws_load *ld)
{
    if (!ld)
        return;
    size_t n = (size_t)ld->info.cartons;
    ws_mem mem = ld->mem;
    ws_mem_free(&mem, ld->carton, n * sizeof *ld->carton);
    ws_mem_free(&mem, ld->reference, n * sizeof *ld->reference);
    ws_mem_free(&mem, ld->carton_bottom, n * sizeof *ld->carton_bottom);
    ws_mem_free(&mem, ld->keys, (n + 2) * sizeof *ld->keys);
    ws_mem_free(&mem, ld, sizeof *ld);
}

/* The platform: given (checked to be kinematic) or a kinematic slab with its top at origin. */
static ws_status make_platform(ws_world *w, const ws_load_def *d, ws_load *ld,
                               ws_shape_id *made_shape)
{
    ws_load_info *in = &ld->info;
    ws_status s;
    if (d->platform.bits) {
        ws_body_type type;
        if ((s = ws_body_get_type(w, d->platform, &type)) != WS_OK)
            return s;
        if (type != WS_BODY_KINEMATIC)
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "load: the platform must be a kinematic body (a world element)");
        in->platform = d->platform;
        if (d->platform_material.bits) {
            if (!ws_material_is_valid(w, d->platform_material))
                return ws_fail(w, WS_ERR_STALE_HANDLE, "load: platform_material is stale");
            in->platform_material = d->platform_material;
            return WS_OK;
        }
        return ws_world_get_default_material(w, &in->platform_material);
    }
    if ((s = new_material(w, "platform", &in->platform_material)) != WS_OK)
        return s;
    const double thick = 0.1;
    double lx = d->pallet_size.x + 2.8, ly = d->pallet_size.y + 1.2;
    if ((s = ws_shape_create_box(w, lx, ly, thick, made_shape)) != WS_OK)
        return s;
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = WS_BODY_KINEMATIC;
    bd.shape = *made_shape;
    bd.material = in->platform_material;
    bd.contact_layer = d->contact_layer;
    bd.position = v3_make(d->origin.x, d->origin.y, d->origin.z - 0.5 * thick);
    bd.name = "platform";
    return ws_body_create(w, &bd, &in->platform);
}

static ws_status build_bodies(ws_world *w, const ws_load_def *d, ws_load *ld, ws_shape_id *shapes)
{
    ws_load_info *in = &ld->info;
    ws_status s;
    ws_mat3 a_pf;
    ws_quat q_pf;
    if ((s = ws_body_get_rotation(w, in->platform, &a_pf)) != WS_OK ||
        (s = ws_body_get_orientation(w, in->platform, &q_pf)) != WS_OK)
        return s;
    const double dl = d->contact_layer, clear = 2 * dl;
    /* A carton's mesh is its nominal footprint less the clearance (its two contact layers and
     * the gap), so a layer of count x size fills that much of the pallet and no carton's edge
     * lies on the deck's edge, where coinciding edges would make contacts come and go. */
    double cut = clear + d->gap;
    ld->carton_cut = cut;
    /* Every second layer's cartons are smaller by WS_LOAD_INSET a side, so two stacked faces
     * are never equal: the smaller face's four corners lie inside the larger, and a shift of a
     * nanometre does not halve the contacts of a pair, as it does when equal faces put every
     * corner on the other face's edge. Each face pair touches at 4 points. */
    if ((s = ws_shape_create_box(w, d->pallet_size.x, d->pallet_size.y, d->pallet_size.z,
                                 &shapes[0])) != WS_OK ||
        (s = ws_shape_create_box(w, d->carton_size.x - cut, d->carton_size.y - cut,
                                 d->carton_size.z, &shapes[1])) != WS_OK ||
        (d->layers > 1 &&
         (s = ws_shape_create_box(w, d->carton_size.x - cut - 2 * WS_LOAD_INSET,
                                  d->carton_size.y - cut - 2 * WS_LOAD_INSET, d->carton_size.z,
                                  &shapes[3])) != WS_OK))
        return s;
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.contact_layer = dl;
    /* The pallet stands on the platform with the layers just touching. */
    bd.shape = shapes[0];
    bd.mass = d->pallet_mass;
    bd.material = in->pallet_material;
    bd.name = "pallet";
    if ((s = place_body(w, &bd, &a_pf, q_pf, d->origin,
                        v3_make(0, 0, clear + 0.5 * d->pallet_size.z), 0, &in->pallet)) != WS_OK)
        return s;
    in->pallet_top = clear + d->pallet_size.z;
    bd.mass = d->carton_mass;
    bd.material = in->carton_material;
    char name[48];
    bd.name = name;
    int c = 0;
    for (int l = 0; l < d->layers; l++) {
        layer_grid g = grid_of(d, l);
        double bottom = in->pallet_top + clear + l * (d->carton_size.z + clear);
        ld->layer_start[l] = c;
        ld->layer_nx[l] = g.nx;
        bd.shape = shapes[l % 2 ? 3 : 1];
        for (int iy = 0; iy < g.ny; iy++)
            for (int ix = 0; ix < g.nx; ix++, c++) {
                ws_load_carton *ct = &ld->carton[c];
                snprintf(name, sizeof name, "carton %d.%d", l, iy * g.nx + ix);
                ws_vec3 local = v3_make(g.x0 + ix * g.px, g.y0 + iy * g.py,
                                        bottom + 0.5 * d->carton_size.z);
                if ((s = place_body(w, &bd, &a_pf, q_pf, d->origin, local, g.turned,
                                    &ct->body)) != WS_OK)
                    return s;
                ct->layer = l;
                ct->index = iy * g.nx + ix;
                ct->ix = ix;
                ct->iy = iy;
                ct->turned = g.turned;
                ct->size = g.size;
                ld->carton_bottom[c] = bottom - in->pallet_top;
            }
    }
    ld->layer_start[d->layers] = c;
    in->load_height = in->pallet_top + d->layers * (d->carton_size.z + clear);
    return WS_OK;
}

static void fill_keys(ws_load *ld)
{
    size_t n = 0;
    ld->keys[n++] = (ws_load_key){ld->info.platform.bits, WS_LEVEL_PLATFORM, -2};
    ld->keys[n++] = (ws_load_key){ld->info.pallet.bits, WS_LEVEL_PALLET, -1};
    for (int c = 0; c < ld->info.cartons; c++)
        ld->keys[n++] = (ws_load_key){ld->carton[c].body.bits,
                                      WS_LEVEL_FIRST_LAYER + ld->carton[c].layer, c};
    qsort(ld->keys, n, sizeof *ld->keys, key_order);
    ld->nkeys = n;
}

/* Undo a failed build: the bodies and shapes it made go (materials cannot be destroyed). */
static void unbuild(ws_world *w, ws_load *ld, const ws_shape_id *shapes, int made_platform)
{
    for (int c = 0; c < ld->info.cartons; c++)
        if (ld->carton[c].body.bits)
            ws_body_destroy(w, ld->carton[c].body);
    if (ld->info.pallet.bits)
        ws_body_destroy(w, ld->info.pallet);
    if (made_platform && ld->info.platform.bits)
        ws_body_destroy(w, ld->info.platform);
    for (int i = 0; i < 4; i++)
        if (shapes[i].bits)
            ws_shape_destroy(w, shapes[i]);
}

ws_status ws_load_build(ws_world *w, const ws_load_def *def, ws_load **out)
{
    NEED_WORLD(w);
    NEED_OUT(w, out, "ws_load_build");
    *out = NULL;
    ws_load_def d;
    ws_load_def_init(&d);
    ws_status s = ws_def_take(w, &d, sizeof d, def, "load");
    if (s != WS_OK || (s = check_def(w, &d)) != WS_OK)
        return s;
    size_t cartons = 0;
    for (int l = 0; l < d.layers; l++) {
        layer_grid g = grid_of(&d, l);
        cartons += (size_t)g.nx * (size_t)g.ny;
    }
    ws_load *ld = load_alloc(&d, w, cartons);
    if (!ld)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_load_build: out of memory for %zu cartons",
                       cartons);
    ld->pallet_size = d.pallet_size;
    ld->info.layers = d.layers;
    ld->carton_mass = d.carton_mass;
    ld->contact_layer = d.contact_layer;
    ld->carton_shape = d.carton_size;
    ld->info.total_mass = d.pallet_mass + (double)cartons * d.carton_mass;
    ws_shape_id shapes[4] = {{0}, {0}, {0}, {0}};
    ws_load_info *in = &ld->info;
    if ((s = new_material(w, "carton", &in->carton_material)) != WS_OK ||
        (s = new_material(w, "pallet", &in->pallet_material)) != WS_OK ||
        (s = new_material(w, "film", &in->film_material)) != WS_OK ||
        (s = make_platform(w, &d, ld, &shapes[2])) != WS_OK ||
        (s = set_contacts(w, &d, ld)) != WS_OK || (s = build_bodies(w, &d, ld, shapes)) != WS_OK)
        goto fail;
    fill_keys(ld);
    if ((s = ws_load_set_reference(w, ld)) != WS_OK)
        goto fail;
    *out = ld;
    return WS_OK;
fail:
    unbuild(w, ld, shapes, d.platform.bits == 0);
    ws_load_destroy(ld);
    return s;
}

/* ---- reading ------------------------------------------------------------------------------ */

ws_status ws_load_get_info(const ws_load *ld, ws_load_info *info)
{
    if (!ld || !info)
        return WS_ERR_INVALID_ARGUMENT;
    *info = ld->info;
    return WS_OK;
}

int ws_load_get_layer_count(const ws_load *ld, int layer)
{
    if (!ld || layer < 0 || layer >= ld->info.layers)
        return 0;
    return ld->layer_start[layer + 1] - ld->layer_start[layer];
}

ws_status ws_load_get_carton(const ws_load *ld, int layer, int index, ws_load_carton *carton)
{
    if (!ld || !carton || index < 0 || index >= ws_load_get_layer_count(ld, layer))
        return WS_ERR_INVALID_ARGUMENT;
    *carton = ld->carton[ld->layer_start[layer] + index];
    return WS_OK;
}

ws_status ws_load_copy_cartons(const ws_load *ld, ws_load_carton *buf, size_t capacity,
                               size_t *count)
{
    if (!ld || !count || (!buf && capacity))
        return WS_ERR_INVALID_ARGUMENT;
    size_t n = (size_t)ld->info.cartons;
    *count = n;
    size_t k = capacity < n ? capacity : n;
    if (k)
        memcpy(buf, ld->carton, k * sizeof *buf);
    return capacity < n && (buf || capacity) ? WS_ERR_BUFFER_TOO_SMALL : WS_OK;
}

ws_status ws_load_get_point_stiffness(const ws_load *ld, int kind, double *stiffness,
                                      int *points)
{
    if (!ld || !stiffness || kind < 0 || kind >= WS_IF_KINDS)
        return WS_ERR_INVALID_ARGUMENT;
    *stiffness = ld->point_stiffness[kind];
    if (points)
        *points = ld->points[kind];
    return WS_OK;
}

ws_status ws_load_frame(const ws_world *w, const ws_load *ld, ws_mat3 *a_pf, ws_vec3 *r_pal,
                        ws_vec3 *v_pal)
{
    ws_status s;
    if ((s = ws_body_get_rotation(w, ld->info.platform, a_pf)) != WS_OK ||
        (s = ws_body_get_position(w, ld->info.pallet, r_pal)) != WS_OK)
        return s;
    return v_pal ? ws_body_get_velocity(w, ld->info.pallet, v_pal) : WS_OK;
}

ws_status ws_load_check_world(const ws_world *w, const ws_load *ld, const char *fn)
{
    if (!w)
        return WS_ERR_INVALID_ARGUMENT;
    if (!ld)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: load is NULL", fn);
    if (ld->world != w)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: the load was built in another world", fn);
    return WS_OK;
}

ws_status ws_load_set_reference(ws_world *w, ws_load *ld)
{
    ws_status s = ws_load_check_world(w, ld, "ws_load_set_reference");
    if (s != WS_OK)
        return s;
    ws_mat3 a_pf;
    ws_vec3 r_pal;
    if ((s = ws_load_frame(w, ld, &a_pf, &r_pal, NULL)) != WS_OK)
        return s;
    for (int c = 0; c < ld->info.cartons; c++) {
        ws_vec3 r;
        if ((s = ws_body_get_position(w, ld->carton[c].body, &r)) != WS_OK)
            return s;
        ld->reference[c] = m3_tmul_v(&a_pf, v3_sub(r, r_pal));
    }
    return WS_OK;
}

ws_status ws_load_measure(const ws_world *w, const ws_load *ld, ws_load_carton_state *buf,
                          size_t capacity, size_t *count)
{
    ws_status s = ws_load_check_world(w, ld, "ws_load_measure");
    if (s != WS_OK)
        return s;
    NEED_OUT(w, count, "ws_load_measure");
    if (!buf && capacity)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_load_measure: buf is NULL");
    size_t n = (size_t)ld->info.cartons;
    *count = n;
    ws_mat3 a_pf;
    ws_vec3 r_pal, v_pal;
    if ((s = ws_load_frame(w, ld, &a_pf, &r_pal, &v_pal)) != WS_OK)
        return s;
    v3 up_pf = v3_make(a_pf.m[2], a_pf.m[5], a_pf.m[8]);
    size_t k = capacity < n ? capacity : n;
    for (size_t c = 0; c < k; c++) {
        ws_vec3 r, v;
        ws_mat3 a;
        ws_body_id id = ld->carton[c].body;
        if ((s = ws_body_get_position(w, id, &r)) != WS_OK ||
            (s = ws_body_get_velocity(w, id, &v)) != WS_OK ||
            (s = ws_body_get_rotation(w, id, &a)) != WS_OK)
            return s;
        ws_load_carton_state *st = &buf[c];
        st->displacement = v3_sub(m3_tmul_v(&a_pf, v3_sub(r, r_pal)), ld->reference[c]);
        st->horizontal = hypot(st->displacement.x, st->displacement.y);
        st->velocity = m3_tmul_v(&a_pf, v3_sub(v, v_pal));
        /* atan2 of |cross| and dot keeps small angles accurate, where acos loses them. */
        v3 up = v3_make(a.m[2], a.m[5], a.m[8]);
        st->tilt = atan2(v3_norm(v3_cross(up, up_pf)), v3_dot(up, up_pf));
    }
    if (capacity < n && capacity)
        return ws_fail(w, WS_ERR_BUFFER_TOO_SMALL,
                       "ws_load_measure: room for %zu cartons, the load has %zu", capacity, n);
    return WS_OK;
}

static ws_status body_drift(const ws_world *w, ws_body_id platform, ws_body_id id, double *out)
{
    ws_vec3 r, v, vp;
    ws_status s;
    if ((s = ws_body_get_position(w, id, &r)) != WS_OK ||
        (s = ws_body_get_velocity(w, id, &v)) != WS_OK ||
        (s = ws_body_get_point_velocity(w, platform, &r, &vp)) != WS_OK)
        return s;
    double d = v3_norm(v3_sub(v, vp));
    if (d > *out)
        *out = d;
    return WS_OK;
}

ws_status ws_load_get_drift(const ws_world *w, const ws_load *ld, double *speed)
{
    ws_status s = ws_load_check_world(w, ld, "ws_load_get_drift");
    if (s != WS_OK)
        return s;
    NEED_OUT(w, speed, "ws_load_get_drift");
    double m = 0;
    if ((s = body_drift(w, ld->info.platform, ld->info.pallet, &m)) != WS_OK)
        return s;
    for (int c = 0; c < ld->info.cartons; c++)
        if ((s = body_drift(w, ld->info.platform, ld->carton[c].body, &m)) != WS_OK)
            return s;
    *speed = m;
    return WS_OK;
}

ws_status ws_load_settle(ws_world *w, const ws_load *ld, double min_time, double max_time,
                         double speed, int *settled, double *time_taken)
{
    ws_status s = ws_load_check_world(w, ld, "ws_load_settle");
    if (s != WS_OK)
        return s;
    if (!(isfinite(min_time) && min_time >= 0 && isfinite(max_time) && max_time >= min_time))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_load_settle: need 0 <= min_time <= max_time, got %g and %g s",
                       min_time, max_time);
    if (!(isfinite(speed) && speed > 0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_load_settle: speed must be > 0 m/s, got %g",
                       speed);
    double dt, t0, t;
    if ((s = ws_world_get_dt(w, &dt)) != WS_OK || (s = ws_world_get_time(w, &t0)) != WS_OK)
        return s;
    /* The drift is read every 5 ms; standing still means below `speed` for 0.1 s. */
    int64_t chunk = (int64_t)ceil(0.005 / dt);
    double still_since = -1;
    int done = 0;
    for (t = t0; t - t0 < max_time - 0.5 * dt;) {
        if ((s = ws_world_step_n(w, chunk)) != WS_OK || (s = ws_world_get_time(w, &t)) != WS_OK)
            return s;
        double drift;
        if ((s = ws_load_get_drift(w, ld, &drift)) != WS_OK)
            return s;
        if (drift >= speed)
            still_since = -1;
        else if (still_since < 0)
            still_since = t;
        if (t - t0 >= min_time && still_since >= 0 && t - still_since >= 0.1) {
            done = 1;
            break;
        }
    }
    if (settled)
        *settled = done;
    if (time_taken)
        *time_taken = t - t0;
    return WS_OK;
}

/* ---- wrapping ----------------------------------------------------------------------------- */

static void wrap_defaults(ws_wrap_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->gauge = 20e-6;
    def->modulus = 150e6;
    def->density = 920.0;
    def->layers = 3;
    def->strain_around = 0.1;
    def->strain_up = 0.02;
    def->z_bottom = 0.03;
    def->top_margin = 0.03;
    def->node_pitch = 0.05;
    def->node_mass = 2e-3;
    def->substeps = 0;
    def->elongation_at_break = 4.0;
    def->powered_prestretch = 2.5;
}

/* The film's rupture strain from a wrap Def (0: none): the given one, or the elongation at break
 * turned from the unstretched film to the rest length the powered pre-stretch left. */
static double wrap_rupture(const ws_wrap_def *d)
{
    if (d->rupture_strain > 0)
        return d->rupture_strain;
    if (d->elongation_at_break == 0)
        return 0;
    return (1 + d->elongation_at_break) / (1 + d->powered_prestretch) - 1;
}

WS_DEF_INITS(ws_wrap_def, wrap_defaults, substeps)

static ws_status check_wrap(const ws_world *w, const ws_wrap_def *d, const ws_load *ld)
{
    const char *bad = NULL;
    if (!(isfinite(d->gauge) && d->gauge > 0))
        bad = "gauge must be > 0 m";
    else if (!(isfinite(d->modulus) && d->modulus > 0))
        bad = "modulus must be > 0 Pa";
    else if (!(isfinite(d->density) && d->density > 0))
        bad = "density must be > 0 kg/m^3";
    else if (d->layers < 1)
        bad = "layers must be >= 1";
    else if (!(isfinite(d->strain_around) && d->strain_around > -1 && d->strain_around < 10) ||
             !(isfinite(d->strain_up) && d->strain_up > -1 && d->strain_up < 10))
        bad = "strain_around and strain_up must be in (-1, 10)";
    else if (!(isfinite(d->z_bottom) && d->z_bottom >= 0 && isfinite(d->top_margin) &&
               d->top_margin >= 0 &&
               d->z_bottom + d->top_margin < ld->info.load_height - 1e-3))
        bad = "z_bottom and top_margin must be >= 0 m and leave room on the load";
    else if (!(isfinite(d->node_pitch) && d->node_pitch > 0 &&
               d->node_pitch < 0.25 * ld->info.load_height))
        bad = "node_pitch must be > 0 m and under a quarter of the load's height";
    else if (!(isfinite(d->node_mass) && d->node_mass >= 0))
        bad = "node_mass must be >= 0 kg";
    else if (d->substeps < 0)
        bad = "substeps must be >= 1, or 0 for the fewest the stable-step check accepts";
    else if (d->integrator != WS_WEB_EXPLICIT && d->integrator != WS_WEB_IMPLICIT)
        bad = "integrator must be WS_WEB_EXPLICIT (0) or WS_WEB_IMPLICIT (1)";
    else if (!(isfinite(d->elongation_at_break) && d->elongation_at_break >= 0) ||
             !(isfinite(d->powered_prestretch) && d->powered_prestretch >= 0) ||
             !(isfinite(d->rupture_strain) && d->rupture_strain >= 0))
        bad = "elongation_at_break, powered_prestretch and rupture_strain must be >= 0";
    else if (d->rupture_strain == 0 && d->elongation_at_break > 0 &&
             !(d->powered_prestretch < d->elongation_at_break))
        bad = "powered_prestretch must be below elongation_at_break: a film stretched that far "
              "has no elongation left";
    if (!bad && wrap_rupture(d) != 0 &&
        !(wrap_rupture(d) > d->strain_around && wrap_rupture(d) > d->strain_up))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "wrap: the film would break as it is laid: its rupture strain %g (%s) is "
                       "not above strain_around %g and strain_up %g",
                       wrap_rupture(d),
                       d->rupture_strain > 0 ? "rupture_strain"
                                             : "from elongation_at_break and powered_prestretch",
                       d->strain_around, d->strain_up);
    if (bad)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "wrap: %s", bad);
    if (ld->info.film.bits)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "wrap: the load is wrapped already");
    return WS_OK;
}

ws_status ws_load_film_law(ws_world *w, double ea, const char *name, ws_law_id *out)
{
    ws_law_def l;
    ws_law_def_init(&l);
    l.type = WS_LAW_TENSION_COMPRESSION;
    l.stiffness = ea;
    l.compression_stiffness = 0.01 * ea; /* film buckles */
    l.damping = 1e-5 * ea; /* a trace of internal damping: its period's worth at 10 us */
    l.name = name;
    return ws_law_create(w, &l, out);
}

ws_status ws_load_fit_substeps(ws_world *w, ws_web_id web, const char *fn)
{
    double dt, stable, f;
    ws_status s;
    if ((s = ws_world_get_dt(w, &dt)) != WS_OK || (s = ws_web_get_stable_dt(w, web, &stable)) != WS_OK ||
        (s = ws_world_get_stable_fraction(w, &f)) != WS_OK)
        return s;
    double n = ceil(dt / (f * stable));
    if (!(n <= 100000.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "%s: the film's stable sub-step is %.3g s, so dt %.3g s "
                       "would need %.3g sub-steps: raise node_mass",
                       fn, stable, dt, n);
    return ws_web_set_substeps(w, web, n < 1.0 ? 1 : (int)n);
}

ws_status ws_load_wrap_band(ws_world *w, ws_load *ld, const ws_wrap_def *def, ws_web_id *out)
{
    ws_status s = ws_load_check_world(w, ld, "ws_load_wrap_band");
    if (s != WS_OK)
        return s;
    NEED_OUT(w, out, "ws_load_wrap_band");
    ws_wrap_def d;
    ws_wrap_def_init(&d);
    if ((s = ws_def_take(w, &d, sizeof d, def, "wrap")) != WS_OK ||
        (s = check_wrap(w, &d, ld)) != WS_OK)
        return s;
    size_t n = (size_t)ld->info.cartons + 1;
    ws_body_id *bodies = ws_mem_calloc(&ld->mem, n, sizeof *bodies);
    if (!bodies)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "wrap: out of memory");
    bodies[0] = ld->info.pallet;
    for (size_t c = 1; c < n; c++)
        bodies[c] = ld->carton[c - 1].body;
    /* Rows at global heights over the platform's top under the pallet. */
    ws_vec3 top;
    double zp = 0;
    if ((s = ws_body_get_position(w, ld->info.pallet, &top)) == WS_OK)
        zp = top.z - 0.5 * ld->pallet_size.z - 2 * ld->contact_layer;
    double z0 = zp + d.z_bottom, z1 = zp + ld->info.load_height - d.top_margin;
    double perimeter = 2 * (ld->pallet_size.x + ld->pallet_size.y);
    int n_around = (int)ceil(perimeter / d.node_pitch);
    int n_up = (int)ceil((z1 - z0) / d.node_pitch) + 1;
    double strip_up = (z1 - z0) / (n_up - 1), strip_around = perimeter / n_around;
    double eh = d.modulus * d.gauge * d.layers;
    ws_law_id around, up;
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.node_mass = d.node_mass;
    wd.areal_density = d.density * d.gauge * d.layers;
    wd.contact_layer = ld->contact_layer;
    wd.material = ld->info.film_material;
    wd.substeps = d.substeps > 0 ? d.substeps : 1;
    wd.integrator = d.integrator;
    wd.name = "film";
    wd.rupture_strain = wrap_rupture(&d);
    ws_band_def bd;
    ws_band_def_init(&bd);
    bd.bodies = bodies;
    bd.body_count = n;
    bd.z_bottom = z0;
    bd.z_top = z1;
    bd.n_around = n_around;
    bd.n_up = n_up;
    bd.prestretch_around = d.strain_around;
    bd.prestretch_up = d.strain_up;
    if (s == WS_OK && (s = ws_load_film_law(w, eh * strip_up, "film around", &around)) == WS_OK &&
        (s = ws_load_film_law(w, eh * strip_around, "film up", &up)) == WS_OK) {
        wd.law = around;
        wd.law_cross = up;
        s = ws_web_create_band(w, &wd, &bd, &ld->info.film);
    }
    if (s == WS_OK && d.substeps == 0 && d.integrator == WS_WEB_EXPLICIT &&
        (s = ws_load_fit_substeps(w, ld->info.film, "ws_load_wrap_band")) != WS_OK) {
        ws_web_destroy(w, ld->info.film);
        ld->info.film = (ws_web_id){0};
    }
    ws_mem_free(&ld->mem, bodies, n * sizeof *bodies);
    if (s == WS_OK) {
        ld->film_nx = n_around;
        ld->film_ny = n_up;
        *out = ld->info.film;
    }
    return s;
}
