/* Public calls on shapes, bodies and contact reports: validation, id lookup, delegation. */
#include "world/world_internal.h"

#include <stddef.h>
#include <stdio.h>
#include <string.h>


/* ---- ids ---- */

ws_status ws_lookup_slot(const ws_world *w, uint64_t bits, unsigned kind, const ws_slot_table *t,
                         const char *what, uint32_t *slot)
{
    if (bits == 0)
        return ws_fail(w, WS_ERR_STALE_HANDLE, "%s id is null", what);
    if (ws_id_kind(bits) != kind)
        return ws_fail(w, WS_ERR_STALE_HANDLE, "%s id 0x%016llx is not a %s id", what,
                       (unsigned long long)bits, what);
    if (!ws_slots_is_live(t, bits, kind))
        return ws_fail(w, WS_ERR_STALE_HANDLE,
                       "%s id 0x%016llx names no live %s of this world (destroyed, or another "
                       "world's)",
                       what, (unsigned long long)bits, what);
    *slot = ws_id_slot(bits);
    return WS_OK;
}

ws_status ws_lookup_body(const ws_world *w, ws_body_id id, uint32_t *slot)
{
    return ws_lookup_slot(w, id.bits, WS_KIND_BODY, &w->body_slots, "body", slot);
}

ws_status ws_lookup_shape(const ws_world *w, ws_shape_id id, uint32_t *slot)
{
    return ws_lookup_slot(w, id.bits, WS_KIND_SHAPE, &w->shape_slots, "shape", slot);
}

ws_body_id ws_make_body_id(const ws_world *w, uint32_t slot)
{
    ws_body_id id = {ws_slots_id(&w->body_slots, WS_KIND_BODY, slot)};
    return id;
}

/* is_valid must not disturb the last error: it is a question, not a failure. */
static int quiet_valid(const ws_world *w, uint64_t bits, unsigned kind, const ws_slot_table *t)
{
    return w && ws_slots_is_live(t, bits, kind);
}

int ws_body_is_valid(const ws_world *w, ws_body_id id)
{
    return w ? quiet_valid(w, id.bits, WS_KIND_BODY, &w->body_slots) : 0;
}

int ws_shape_is_valid(const ws_world *w, ws_shape_id id)
{
    return w ? quiet_valid(w, id.bits, WS_KIND_SHAPE, &w->shape_slots) : 0;
}

/* ---- shapes ---- */

static void mesh_defaults(ws_mesh_def *def)
{
    ws_def_reset(def, sizeof *def);
}
WS_DEF_INITS(ws_mesh_def, mesh_defaults, triangle_count)

static ws_status add_shape(ws_world *w, const double *xyz, size_t nv, const uint32_t *tri,
                           size_t nt, const char *fn, ws_shape_id *out)
{
    char why[400] = ""; /* a refused mesh's reason and repair hint; fits the error text */
    ws_shape *s = ws_mem_alloc(&w->mem, sizeof *s);
    if (!s)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    ws_status st = ws_shape_build(&w->mem, xyz, nv, tri, nt, s, why, sizeof why);
    if (st != WS_OK) {
        ws_mem_free(&w->mem, s, sizeof *s);
        return ws_fail(w, st, "%s: %s", fn, why);
    }
    uint32_t slot;
    int taken = ws_slots_take(&w->mem, &w->shape_slots, &slot) == 0;
    if (!taken || ws_array_reserve(&w->mem, (void **)&w->shapes, &w->shape_cap, slot + 1,
                                   sizeof *w->shapes) != 0) {
        if (taken)
            ws_slots_release(&w->shape_slots, slot);
        ws_shape_free(&w->mem, s);
        ws_mem_free(&w->mem, s, sizeof *s);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    }
    w->shapes[slot] = s;
    w->shape_slots.dense[slot] = slot;
    out->bits = ws_slots_id(&w->shape_slots, WS_KIND_SHAPE, slot);
    return WS_OK;
}

ws_status ws_shape_create_box(ws_world *w, double lx, double ly, double lz, ws_shape_id *out)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_shape_create_box");
    NEED_OUT(w, out, "ws_shape_create_box");
    out->bits = 0;
    if (!(isfinite(lx) && isfinite(ly) && isfinite(lz) && lx > 0.0 && ly > 0.0 && lz > 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_shape_create_box: edge lengths must be > 0 m, got %g x %g x %g", lx, ly,
                       lz);
    if (lx > 2.0 * WS_MESH_MAX_COORD || ly > 2.0 * WS_MESH_MAX_COORD ||
        lz > 2.0 * WS_MESH_MAX_COORD)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_shape_create_box: edge lengths must be at most 2 WS_MESH_MAX_COORD "
                       "(%g m), got %g x %g x %g",
                       2.0 * WS_MESH_MAX_COORD, lx, ly, lz);
    double xyz[24];
    uint32_t tri[36];
    ws_shape_box_mesh(lx, ly, lz, xyz, tri);
    return add_shape(w, xyz, 8, tri, 12, "ws_shape_create_box", out);
}

ws_status ws_shape_create_cylinder(ws_world *w, double r, double h, int segments,
                                   ws_shape_id *out)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_shape_create_cylinder");
    NEED_OUT(w, out, "ws_shape_create_cylinder");
    out->bits = 0;
    if (!(isfinite(r) && isfinite(h) && r > 0.0 && h > 0.0) || segments < 3 || segments > 1024 ||
        r > WS_MESH_MAX_COORD || h > 2.0 * WS_MESH_MAX_COORD)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_shape_create_cylinder: need 0 < radius <= WS_MESH_MAX_COORD (%g m), "
                       "0 < height <= 2 WS_MESH_MAX_COORD and 3..1024 segments, got %g, %g, %d",
                       WS_MESH_MAX_COORD, r, h, segments);
    size_t nv = 2 * (size_t)segments, nt = 4 * (size_t)segments - 4;
    double *xyz = ws_mem_alloc(&w->mem, 3 * nv * sizeof *xyz);
    uint32_t *tri = ws_mem_alloc(&w->mem, 3 * nt * sizeof *tri);
    ws_status st;
    if (!xyz || !tri) {
        st = ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_shape_create_cylinder: out of memory");
    } else {
        ws_shape_cylinder_mesh(r, h, segments, xyz, tri);
        st = add_shape(w, xyz, nv, tri, nt, "ws_shape_create_cylinder", out);
    }
    ws_mem_free(&w->mem, xyz, 3 * nv * sizeof *xyz);
    ws_mem_free(&w->mem, tri, 3 * nt * sizeof *tri);
    return st;
}

ws_status ws_shape_create_mesh(ws_world *w, const ws_mesh_def *def, ws_shape_id *out)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_shape_create_mesh");
    NEED_OUT(w, out, "ws_shape_create_mesh");
    out->bits = 0;
    ws_mesh_def d;
    ws_mesh_def_init(&d);
    ws_status s = ws_def_take(w, &d, sizeof d, def, "mesh");
    if (s != WS_OK)
        return s;
    return add_shape(w, d.vertices, d.vertex_count, d.triangles, d.triangle_count,
                     "ws_shape_create_mesh", out);
}

ws_status ws_shape_destroy(ws_world *w, ws_shape_id id)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_shape_destroy");
    uint32_t slot;
    ws_status s = ws_lookup_shape(w, id, &slot);
    if (s != WS_OK)
        return s;
    ws_shape *sh = w->shapes[slot];
    if (sh->users)
        return ws_fail(w, WS_ERR_IN_USE, "ws_shape_destroy: %u bodies still use this shape",
                       sh->users);
    ws_shape_free(&w->mem, sh);
    ws_mem_free(&w->mem, sh, sizeof *sh);
    w->shapes[slot] = NULL;
    ws_slots_release(&w->shape_slots, slot);
    return WS_OK;
}

ws_status ws_shape_get_info(const ws_world *w, ws_shape_id id, ws_shape_info *info)
{
    NEED_WORLD(w);
    NEED_OUT(w, info, "ws_shape_get_info");
    uint32_t slot;
    ws_status s = ws_lookup_shape(w, id, &slot);
    if (s != WS_OK)
        return s;
    const ws_shape *sh = w->shapes[slot];
    info->volume = sh->volume;
    info->centroid = sh->centroid;
    info->aabb_min = sh->lo;
    info->aabb_max = sh->hi;
    info->inertia_unit = sh->inertia_unit;
    info->point_count = sh->vertex_count;
    info->edge_count = sh->edge_count;
    info->face_count = sh->face_count;
    info->triangle_count = sh->triangle_count;
    info->convex = sh->convex;
    return WS_OK;
}

ws_status ws_shape_get_centroid_offset(const ws_world *w, ws_shape_id id, ws_vec3 *offset)
{
    NEED_WORLD(w);
    NEED_OUT(w, offset, "ws_shape_get_centroid_offset");
    uint32_t slot;
    ws_status s = ws_lookup_shape(w, id, &slot);
    if (s != WS_OK)
        return s;
    *offset = w->shapes[slot]->centroid;
    return WS_OK;
}

ws_status ws_shape_copy_mesh(const ws_world *w, ws_shape_id id, double *vertices, size_t vcap,
                             size_t *vcount, uint32_t *triangles, size_t tcap, size_t *tcount)
{
    NEED_WORLD(w);
    uint32_t slot;
    ws_status s = ws_lookup_shape(w, id, &slot);
    if (s != WS_OK)
        return s;
    const ws_shape *sh = w->shapes[slot];
    if (vcount)
        *vcount = sh->vertex_count;
    if (tcount)
        *tcount = sh->triangle_count;
    if ((vcap && !vertices) || (tcap && !triangles))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_shape_copy_mesh: a buffer is NULL but its capacity is not 0");
    size_t nv = vcap < sh->vertex_count ? vcap : sh->vertex_count;
    size_t nt = tcap < sh->triangle_count ? tcap : sh->triangle_count;
    for (size_t i = 0; i < nv; i++)
        v3_store(vertices + 3 * i, sh->vertices[i]);
    if (nt)
        memcpy(triangles, sh->triangles, 3 * nt * sizeof *triangles);
    if ((vertices && vcap < sh->vertex_count) || (triangles && tcap < sh->triangle_count))
        return ws_fail(w, WS_ERR_BUFFER_TOO_SMALL,
                       "ws_shape_copy_mesh: room for %zu vertices and %zu triangles, the shape "
                       "has %u and %u",
                       vcap, tcap, sh->vertex_count, sh->triangle_count);
    return WS_OK;
}

/* ---- bodies ---- */

static void body_defaults(ws_body_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->type = WS_BODY_DYNAMIC;
    def->density = 1000.0;
    def->contact_layer = 1e-3;
    def->orientation = qt_identity();
}
WS_DEF_INITS(ws_body_def, body_defaults, user_data)

static void drive_defaults(ws_drive_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->type = WS_DRIVE_STATIC;
    def->ramp_time = 0.05;
    def->axis = v3_make(0, 1, 0);
    def->direction = v3_make(1, 0, 0);
    def->stop_ramp_time = 1.0;
    def->rise_time = 0.05;
    def->hold_time = 0.3;
    def->pulse_mode = WS_PULSE_ACCELERATE;
    def->gentle_acceleration = 1.0;
    def->coast_time = 0.5;
    def->pulse_duration = 0.01;
    def->table_end_at_rest = 1;
    def->sample_rate = 1024.0;
    def->sweep_law = WS_SWEEP_LOG;
}
WS_DEF_INITS(ws_drive_def, drive_defaults, callback_user)

static const char *label(const ws_body_def *d)
{
    return d->name ? d->name : "(unnamed)";
}

ws_status ws_body_create(ws_world *w, const ws_body_def *def, ws_body_id *out)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_body_create");
    NEED_OUT(w, out, "ws_body_create");
    out->bits = 0;
    ws_body_def d;
    ws_body_def_init(&d);
    ws_status s = ws_def_take(w, &d, sizeof d, def, "body");
    if (s != WS_OK)
        return s;
    const char *nm = label(&d);
    if (d.type != WS_BODY_DYNAMIC && d.type != WS_BODY_KINEMATIC)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "body '%s': unknown type %d", nm, (int)d.type);
    uint32_t shape_slot, mat_slot = 0;
    if ((s = ws_lookup_shape(w, d.shape, &shape_slot)) != WS_OK)
        return ws_fail(w, s, "body '%s': %s", nm, w->err);
    if (d.material.bits != 0 && (s = ws_lookup_material(w, d.material, &mat_slot)) != WS_OK)
        return ws_fail(w, s, "body '%s': %s", nm, w->err);
    const ws_shape *sh = w->shapes[shape_slot];
    if (!ws_is_finite3(&d.position) || !ws_is_finite3(&d.velocity) ||
        !ws_is_finite3(&d.angular_velocity))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "body '%s': position and velocities must be finite", nm);
    double qn = qt_norm(d.orientation);
    if (!(isfinite(qn) && qn > 1e-12))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "body '%s': orientation must be a non-zero finite quaternion, |q| = %g", nm,
                       qn);
    if (!(isfinite(d.contact_layer) && d.contact_layer >= 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "body '%s': contact_layer must be >= 0 m, got %g",
                       nm, d.contact_layer);
    double mass = 0.0;
    m3 J = m3_identity(), Jinv = m3_identity();
    if (d.type == WS_BODY_DYNAMIC) {
        if (!isfinite(d.mass) || d.mass < 0.0)
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "body '%s': mass must be > 0 kg (or 0 to use density), got %g", nm,
                           d.mass);
        if (d.mass == 0.0) {
            if (!(isfinite(d.density) && d.density > 0.0))
                return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                               "body '%s': mass is 0, so density must be > 0 kg/m^3, got %g", nm,
                               d.density);
            mass = d.density * sh->volume;
        } else {
            mass = d.mass;
        }
        if (!(mass >= WS_BODY_MIN_MASS && mass <= WS_BODY_MAX_MASS))
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "body '%s': mass %g kg%s is outside [WS_BODY_MIN_MASS, "
                           "WS_BODY_MAX_MASS] = [%g, %g] kg",
                           nm, mass, d.mass == 0.0 ? " (density x volume)" : "",
                           WS_BODY_MIN_MASS, WS_BODY_MAX_MASS);
        int zero = 1;
        for (int k = 0; k < 9; k++) {
            if (!isfinite(d.inertia.m[k]))
                return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "body '%s': inertia is not finite", nm);
            if (d.inertia.m[k] != 0.0)
                zero = 0;
        }
        J = zero ? ws_body_inertia_from_shape(sh, mass) : d.inertia;
        if (!m3_is_spd(&J))
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "body '%s': inertia must be symmetric positive definite "
                           "(diagonal %g, %g, %g kg m^2)",
                           nm, J.m[0], J.m[4], J.m[8]);
        /* The principal moments of a rigid body: J1 = integral of (y^2 + z^2) dm and so on,
         * so J1 + J2 = J3 + 2 integral of z^2 dm >= J3; a flat plate is the equality. */
        m3 axes;
        v3 pm;
        m3_sym_eigen(&J, &axes, &pm);
        double jmax = fmax(pm.x, fmax(pm.y, pm.z)), jsum = pm.x + pm.y + pm.z;
        if (jsum - jmax < jmax * (1.0 - 1e-9))
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "body '%s': principal moments of inertia %g, %g, %g kg m^2 are no "
                           "rigid body's: each must be at most the sum of the other two "
                           "(J1 + J2 >= J3)",
                           nm, pm.x, pm.y, pm.z);
        if (m3_inverse(&J, &Jinv) != 0)
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "body '%s': inertia (principal moments %g, %g, %g kg m^2) cannot be "
                           "inverted in double precision",
                           nm, pm.x, pm.y, pm.z);
    }

    uint32_t slot;
    if (ws_slots_take(&w->mem, &w->body_slots, &slot) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "body '%s': out of memory", nm);
    char *name_copy = NULL;
    if (ws_bodies_reserve(&w->mem, &w->bodies, slot + 1) != 0 ||
        (d.name && !(name_copy = ws_mem_strdup(&w->mem, d.name)))) {
        ws_slots_release(&w->body_slots, slot);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "body '%s': out of memory", nm);
    }
    ws_body_store *b = &w->bodies;
    if (slot >= b->slots)
        b->slots = slot + 1;
    b->alive[slot] = 1;
    b->alive_count++;
    b->type[slot] = (uint8_t)d.type;
    b->shape[slot] = w->shapes[shape_slot];
    w->shapes[shape_slot]->users++;
    b->material[slot] = mat_slot;
    b->layer[slot] = d.contact_layer;
    b->mass[slot] = mass;
    b->inv_mass[slot] = d.type == WS_BODY_DYNAMIC ? 1.0 / mass : 0.0;
    b->J[slot] = J;
    b->Jinv[slot] = Jinv;
    m3_sym_eigen(&J, &b->Q[slot], &b->Ip[slot]);
    b->has_drive[slot] = 0;
    b->name[slot] = name_copy;
    b->user[slot] = d.user_data;
    ws_body_state *st = &b->st[w->cur];
    qt p = qt_normalize(d.orientation);
    m3 A = qt_to_m3(p);
    st->r[slot] = d.position;
    st->p[slot] = p;
    if (d.type == WS_BODY_DYNAMIC) {
        st->v[slot] = d.velocity;
        st->w[slot] = m3_tmul_v(&A, d.angular_velocity);
    } else {
        st->v[slot] = v3_make(0, 0, 0);
        st->w[slot] = v3_make(0, 0, 0);
    }
    w->body_slots.dense[slot] = slot;
    w->cand_valid = 0;
    w->web_check = 1; /* a new material may meet the webs */
    *out = ws_make_body_id(w, slot);
    return WS_OK;
}

void ws_world_forget_body(ws_world *w, uint32_t slot)
{
    for (int k = 0; k < 2; k++) {
        size_t m = 0;
        for (size_t i = 0; i < w->ncand[k]; i++)
            if (w->cand[k][i].a != slot && w->cand[k][i].b != slot)
                w->cand[k][m++] = w->cand[k][i];
        w->ncand[k] = m;
        m = 0;
        for (size_t i = 0; i < w->nrec[k]; i++)
            if (w->rec[k][i].a != slot && w->rec[k][i].b != slot)
                w->rec[k][m++] = w->rec[k][i];
        w->nrec[k] = m;
    }
    w->cand_valid = 0;
}

ws_status ws_body_destroy(ws_world *w, ws_body_id id)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_body_destroy");
    uint32_t slot;
    ws_status s = ws_lookup_body(w, id, &slot);
    if (s != WS_OK)
        return s;
    if ((s = ws_world_body_free_of_elements(w, slot)) != WS_OK)
        return s; /* an element still joins it: WS_ERR_IN_USE */
    ws_body_store *b = &w->bodies;
    ws_world_forget_body(w, slot);
    b->shape[slot]->users--;
    b->shape[slot] = NULL;
    if (b->has_drive[slot])
        ws_drive_release(&b->drive[slot], &w->mem);
    b->has_drive[slot] = 0;
    ws_mem_free_str(&w->mem, b->name[slot]);
    b->name[slot] = NULL;
    b->alive[slot] = 0;
    b->alive_count--;
    ws_slots_release(&w->body_slots, slot);
    return WS_OK;
}

ws_status ws_body_set_drive(ws_world *w, ws_body_id id, const ws_drive_def *def)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_body_set_drive");
    uint32_t slot;
    ws_status s = ws_lookup_body(w, id, &slot);
    if (s != WS_OK)
        return s;
    ws_body_store *b = &w->bodies;
    const char *nm = b->name[slot] ? b->name[slot] : "(unnamed)";
    if (b->type[slot] != WS_BODY_KINEMATIC)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "body '%s': only kinematic bodies (world elements) take a drive", nm);
    ws_drive_def d;
    ws_drive_def_init(&d);
    if ((s = ws_def_take(w, &d, sizeof d, def, "drive")) != WS_OK)
        return s;
    ws_body_state *st = &b->st[w->cur];
    ws_pose base = {st->r[slot], st->p[slot]};
    if (b->has_drive[slot]) /* the motion is relative to where the old drive started */
        base = b->drive[slot].base;
    char why[256] = "";
    ws_drive drv;
    if ((s = ws_drive_setup(&drv, &w->mem, &d, &base, why, sizeof why)) != WS_OK)
        return ws_fail(w, s, "body '%s': %s", nm, why);
    ws_pose pose;
    v3 v, om;
    int rc = ws_drive_eval(&drv, w->time, &pose, &v, &om);
    if (rc != 0) {
        ws_drive_release(&drv, &w->mem);
        if (d.type == WS_DRIVE_CALLBACK)
            return ws_fail(w, WS_ERR_CALLBACK,
                           "body '%s': the drive callback failed at t = %g s (it returned "
                           "non-zero or gave a non-finite pose)", nm, w->time);
        return ws_fail(w, WS_ERR_NUMERICAL,
                       "body '%s': the drive gives a non-finite pose or velocity at t = %g s", nm,
                       w->time);
    }
    if (b->has_drive[slot])
        ws_drive_release(&b->drive[slot], &w->mem);
    b->drive[slot] = drv;
    b->has_drive[slot] = 1;
    st->r[slot] = pose.position;
    st->p[slot] = pose.orientation;
    st->v[slot] = v;
    m3 A = qt_to_m3(pose.orientation);
    st->w[slot] = m3_tmul_v(&A, om);
    w->cand_valid = 0;
    return WS_OK;
}

ws_status ws_body_get_drive_state(const ws_world *w, ws_body_id id, ws_drive_state *out)
{
    NEED_WORLD(w);
    NEED_OUT(w, out, "ws_body_get_drive_state");
    uint32_t slot;
    ws_status s = ws_lookup_body(w, id, &slot);
    if (s != WS_OK)
        return s;
    const ws_body_store *b = &w->bodies;
    if (b->type[slot] != WS_BODY_KINEMATIC)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "body '%s': a dynamic body has no drive state",
                       b->name[slot] ? b->name[slot] : "(unnamed)");
    const ws_body_state *st = &b->st[w->cur];
    memset(out, 0, sizeof *out);
    out->time = w->time;
    out->type = WS_DRIVE_STATIC;
    out->position = st->r[slot];
    out->has_acceleration = 1;
    if (!b->has_drive[slot])
        return WS_OK;
    const ws_drive *d = &b->drive[slot];
    out->type = d->def.type;
    m3 A = qt_to_m3(st->p[slot]);
    if (d->def.type == WS_DRIVE_CALLBACK) {
        /* The committed state is what the callback gave; no second call from a getter. */
        out->velocity = st->v[slot];
        out->angular_velocity = m3_mul_v(&A, st->w[slot]);
        out->has_acceleration = 0;
        return WS_OK;
    }
    ws_drive_motion m;
    if (ws_drive_motion_at(d, w->time, &m) != 0) /* a committed state was finite */
        return ws_fail(w, WS_ERR_NUMERICAL, "body '%s': the drive is not finite at t = %g s",
                       b->name[slot] ? b->name[slot] : "(unnamed)", w->time);
    out->position = m.pose.position;
    out->displacement = v3_sub(m.pose.position, d->base.position);
    out->velocity = m.v;
    out->acceleration = m.a;
    out->angular_velocity = m.w;
    out->angle = m.angle;
    out->angular_rate = m.rate;
    out->angular_acceleration = m.angacc;
    return WS_OK;
}

ws_status ws_vibration_synthesize(ws_world *w, const ws_drive_def *def, double *accel,
                                  size_t count)
{
    char why[256] = "";
    ws_status s;
    if (!def) {
        s = WS_ERR_INVALID_ARGUMENT;
        snprintf(why, sizeof why, "ws_vibration_synthesize: def is NULL");
    } else if (ws_def_check(def) != 0) {
        s = WS_ERR_UNINITIALIZED_DEF;
        snprintf(why, sizeof why, "ws_vibration_synthesize: the Def was not filled by "
                                  "ws_drive_def_init()");
    } else if (def->size < sizeof *def) {
        s = WS_ERR_INVALID_ARGUMENT;
        snprintf(why, sizeof why, "ws_vibration_synthesize: the Def is too old to hold a PSD");
    } else {
        s = ws_drive_synthesize(def, accel, count, why, sizeof why);
    }
    if (s != WS_OK && w)
        return ws_fail(w, s, "ws_vibration_synthesize: %s", why);
    return s;
}

ws_status ws_vibration_grms(const double *frequency, const double *level, size_t count,
                            double *grms)
{
    if (!grms)
        return WS_ERR_INVALID_ARGUMENT;
    return ws_drive_psd_grms(frequency, level, count, grms, NULL, 0);
}

/* The truck spectrum's shape (see docs/guide.md, "Random vibration"): the suspension's hump at
 * 3-4 Hz, a plateau to 12 Hz, the axles' hump at 16-25 Hz, a fall to 200 Hz. Scaled to the
 * level's Grms by ws_vibration_truck_psd. */
static const double truck_f[] = {1.0, 3.0, 4.0, 6.0, 12.0, 16.0, 25.0, 30.0, 40.0, 80.0, 200.0};
static const double truck_g[] = {0.0001, 0.005, 0.005, 0.001, 0.001, 0.003, 0.003, 0.001,
                                 0.001, 0.0003, 0.00003};

ws_status ws_vibration_truck_psd(ws_truck_level level, double *frequency, double *level_g2hz,
                                 size_t capacity, size_t *count)
{
    static const double grms_of[] = {0.0, 0.40, 0.54, 0.70};
    const size_t n = sizeof truck_f / sizeof truck_f[0];
    if (!count || level < WS_TRUCK_LOW || level > WS_TRUCK_HIGH)
        return WS_ERR_INVALID_ARGUMENT;
    *count = n;
    if (capacity < n || !frequency || !level_g2hz)
        return WS_ERR_BUFFER_TOO_SMALL;
    double shape;
    ws_drive_psd_grms(truck_f, truck_g, n, &shape, NULL, 0);
    double k = grms_of[level] / shape;
    for (size_t i = 0; i < n; i++) {
        frequency[i] = truck_f[i];
        level_g2hz[i] = truck_g[i] * k * k;
    }
    return WS_OK;
}

#define BODY_GETTER(fn, T, what, expr)                                                            \
    ws_status fn(const ws_world *w, ws_body_id id, T *out)                                        \
    {                                                                                             \
        NEED_WORLD(w);                                                                            \
        NEED_OUT(w, out, #fn);                                                                    \
        uint32_t i;                                                                               \
        ws_status s = ws_lookup_body(w, id, &i);                                                  \
        if (s != WS_OK)                                                                           \
            return s;                                                                             \
        const ws_body_store *b = &w->bodies;                                                      \
        const ws_body_state *st = &b->st[w->cur];                                                 \
        (void)st;                                                                                 \
        *out = (expr);                                                                            \
        return WS_OK;                                                                             \
    }

BODY_GETTER(ws_body_get_type, ws_body_type, "type", (ws_body_type)b->type[i])
BODY_GETTER(ws_body_get_position, ws_vec3, "position", st->r[i])
BODY_GETTER(ws_body_get_orientation, ws_quat, "orientation", st->p[i])
BODY_GETTER(ws_body_get_rotation, ws_mat3, "rotation", qt_to_m3(st->p[i]))
BODY_GETTER(ws_body_get_velocity, ws_vec3, "velocity", st->v[i])
BODY_GETTER(ws_body_get_angular_velocity_local, ws_vec3, "angular velocity", st->w[i])
BODY_GETTER(ws_body_get_mass, double, "mass", b->mass[i])
BODY_GETTER(ws_body_get_inertia, ws_mat3, "inertia", b->J[i])

ws_status ws_body_get_angular_velocity(const ws_world *w, ws_body_id id, ws_vec3 *out)
{
    ws_status s = ws_body_get_angular_velocity_local(w, id, out);
    if (s != WS_OK)
        return s;
    uint32_t i;
    ws_lookup_body(w, id, &i);
    m3 A = qt_to_m3(w->bodies.st[w->cur].p[i]);
    *out = m3_mul_v(&A, *out);
    return WS_OK;
}

/* Common part of the calls that take a point: checks, then the body's slot and rotation. */
static ws_status point_call(const ws_world *w, ws_body_id id, const ws_vec3 *point, void *out,
                            const char *fn, uint32_t *slot, m3 *A)
{
    NEED_WORLD(w);
    NEED_OUT(w, out, fn);
    if (!point || !ws_is_finite3(point))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: point must be finite", fn);
    ws_status s = ws_lookup_body(w, id, slot);
    if (s == WS_OK)
        *A = qt_to_m3(w->bodies.st[w->cur].p[*slot]);
    return s;
}

ws_status ws_body_get_point_velocity(const ws_world *w, ws_body_id id, const ws_vec3 *point,
                                     ws_vec3 *v)
{
    uint32_t i;
    m3 A;
    ws_status s = point_call(w, id, point, v, "ws_body_get_point_velocity", &i, &A);
    if (s != WS_OK)
        return s;
    const ws_body_state *st = &w->bodies.st[w->cur];
    v3 om = m3_mul_v(&A, st->w[i]);
    *v = v3_add(st->v[i], v3_cross(om, v3_sub(*point, st->r[i]))); /* eq. 3 */
    return WS_OK;
}

ws_status ws_body_get_world_point(const ws_world *w, ws_body_id id, const ws_vec3 *local,
                                  ws_vec3 *global)
{
    uint32_t i;
    m3 A;
    ws_status s = point_call(w, id, local, global, "ws_body_get_world_point", &i, &A);
    if (s != WS_OK)
        return s;
    *global = v3_add(w->bodies.st[w->cur].r[i], m3_mul_v(&A, *local)); /* eq. 2 */
    return WS_OK;
}

ws_status ws_body_get_contact_force(const ws_world *w, ws_body_id id, ws_vec3 *force,
                                    ws_vec3 *moment)
{
    NEED_WORLD(w);
    NEED_OUT(w, force, "ws_body_get_contact_force");
    uint32_t i;
    ws_status s = ws_lookup_body(w, id, &i);
    if (s != WS_OK)
        return s;
    v3 F = {0, 0, 0}, M = {0, 0, 0};
    v3 r = w->bodies.st[w->cur].r[i];
    for (size_t k = 0; k < w->nrec[w->cur]; k++) {
        const ws_contact_rec *c = &w->rec[w->cur][k];
        v3 f = v3_add(v3_scale(c->n, c->fn), c->ft);
        if (c->a == i)
            f = v3_neg(f);
        else if (c->b != i)
            continue;
        F = v3_add(F, f);
        M = v3_add(M, v3_cross(v3_sub(c->x, r), f));
    }
    *force = F;
    if (moment)
        *moment = M;
    return WS_OK;
}

ws_status ws_body_set_pose(ws_world *w, ws_body_id id, const ws_pose *pose)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_body_set_pose");
    uint32_t i;
    ws_status s = ws_lookup_body(w, id, &i);
    if (s != WS_OK)
        return s;
    double qn = pose ? qt_norm(pose->orientation) : 0.0;
    if (!pose || !ws_is_finite3(&pose->position) || !(isfinite(qn) && qn > 1e-12))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_body_set_pose: position must be finite and orientation non-zero");
    if (w->bodies.type[i] != WS_BODY_DYNAMIC)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_body_set_pose: a kinematic body is placed by its drive");
    ws_body_state *st = &w->bodies.st[w->cur];
    /* Keep the global angular velocity: omega' is re-expressed in the new orientation. */
    m3 A = qt_to_m3(st->p[i]);
    v3 om = m3_mul_v(&A, st->w[i]);
    st->r[i] = pose->position;
    st->p[i] = qt_normalize(pose->orientation);
    A = qt_to_m3(st->p[i]);
    st->w[i] = m3_tmul_v(&A, om);
    w->cand_valid = 0;
    return WS_OK;
}

ws_status ws_body_set_velocity(ws_world *w, ws_body_id id, const ws_vec3 *v, const ws_vec3 *om)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_body_set_velocity");
    uint32_t i;
    ws_status s = ws_lookup_body(w, id, &i);
    if (s != WS_OK)
        return s;
    if (!v || !om || !ws_is_finite3(v) || !ws_is_finite3(om))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_body_set_velocity: velocities must be finite");
    if (w->bodies.type[i] != WS_BODY_DYNAMIC)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_body_set_velocity: a kinematic body moves by its drive");
    ws_body_state *st = &w->bodies.st[w->cur];
    m3 A = qt_to_m3(st->p[i]);
    st->v[i] = *v;
    st->w[i] = m3_tmul_v(&A, *om);
    return WS_OK;
}

const char *ws_body_get_name(const ws_world *w, ws_body_id id)
{
    if (!ws_body_is_valid(w, id))
        return "";
    const char *n = w->bodies.name[ws_id_slot(id.bits)];
    return n ? n : "";
}

void *ws_body_get_user_data(const ws_world *w, ws_body_id id)
{
    if (!ws_body_is_valid(w, id))
        return NULL;
    return w->bodies.user[ws_id_slot(id.bits)];
}

ws_status ws_world_copy_body_ids(const ws_world *w, ws_body_id *buf, size_t cap, size_t *count)
{
    NEED_WORLD(w);
    NEED_OUT(w, count, "ws_world_copy_body_ids");
    if (cap && !buf)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_world_copy_body_ids: buffer is NULL but capacity is not 0");
    size_t n = 0;
    for (size_t i = 0; i < w->bodies.slots; i++) {
        if (!w->bodies.alive[i])
            continue;
        if (n < cap)
            buf[n] = ws_make_body_id(w, (uint32_t)i);
        n++;
    }
    *count = n;
    if (buf && cap < n)
        return ws_fail(w, WS_ERR_BUFFER_TOO_SMALL,
                       "ws_world_copy_body_ids: room for %zu ids, there are %zu", cap, n);
    return WS_OK;
}

/* ---- contact reports ---- */

ws_status ws_world_get_contact_count(const ws_world *w, size_t *count)
{
    NEED_WORLD(w);
    NEED_OUT(w, count, "ws_world_get_contact_count");
    *count = w->nrec[w->cur];
    return WS_OK;
}

ws_status ws_world_copy_contacts(const ws_world *w, ws_contact_info *buf, size_t cap,
                                 size_t *count)
{
    NEED_WORLD(w);
    NEED_OUT(w, count, "ws_world_copy_contacts");
    if (cap && !buf)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_world_copy_contacts: buffer is NULL but capacity is not 0");
    size_t n = w->nrec[w->cur];
    *count = n;
    size_t m = cap < n ? cap : n;
    for (size_t k = 0; k < m; k++) {
        const ws_contact_rec *c = &w->rec[w->cur][k];
        ws_contact_info *o = &buf[k];
        o->body_a = ws_make_body_id(w, c->a);
        o->body_b = ws_make_body_id(w, c->b);
        o->point = c->x;
        o->normal = c->n;
        o->overlap = c->overlap;
        o->normal_force = c->fn;
        o->friction_force = c->ft;
        o->slip_velocity = c->vt;
        o->kind = (int32_t)c->kind;
        o->slipping = (int32_t)c->slipping;
        o->at_cap = (int32_t)c->at_cap;
        o->reserved_ = 0;
        o->anchor_deflection = c->defl;
    }
    if (buf && cap < n)
        return ws_fail(w, WS_ERR_BUFFER_TOO_SMALL,
                       "ws_world_copy_contacts: room for %zu contacts, there are %zu", cap, n);
    return WS_OK;
}

/* Both ids live, distinct; the slots out. */
static ws_status pair_call(const ws_world *w, ws_body_id a, ws_body_id b, const char *fn,
                           uint32_t *ia, uint32_t *ib)
{
    ws_status s = ws_lookup_body(w, a, ia);
    if (s == WS_OK)
        s = ws_lookup_body(w, b, ib);
    if (s != WS_OK)
        return s;
    if (*ia == *ib)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: body_a and body_b are the same body", fn);
    return WS_OK;
}

ws_status ws_world_copy_contacts_between(const ws_world *w, ws_body_id a, ws_body_id b,
                                         ws_contact_info *buf, size_t cap, size_t *count)
{
    NEED_WORLD(w);
    NEED_OUT(w, count, "ws_world_copy_contacts_between");
    if (cap && !buf)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_world_copy_contacts_between: buffer is NULL but capacity is not 0");
    uint32_t ia, ib;
    ws_status s = pair_call(w, a, b, "ws_world_copy_contacts_between", &ia, &ib);
    if (s != WS_OK)
        return s;
    size_t n = 0;
    for (size_t k = 0; k < w->nrec[w->cur]; k++) {
        const ws_contact_rec *c = &w->rec[w->cur][k];
        int same = c->a == ia && c->b == ib, swapped = c->a == ib && c->b == ia;
        if (!same && !swapped)
            continue;
        if (n < cap) {
            /* Seen from the caller's order: the record's b is the caller's a when swapped, so
             * the normal, the force on b and b's slip all change sign. */
            double sg = swapped ? -1.0 : 1.0;
            ws_contact_info *o = &buf[n];
            o->body_a = a;
            o->body_b = b;
            o->point = c->x;
            o->normal = v3_scale(c->n, sg);
            o->overlap = c->overlap;
            o->normal_force = c->fn;
            o->friction_force = v3_scale(c->ft, sg);
            o->slip_velocity = v3_scale(c->vt, sg);
            o->kind = (int32_t)c->kind;
            if (swapped && c->kind == WS_CONTACT_POINT_FACE)
                o->kind = WS_CONTACT_FACE_POINT;
            o->slipping = (int32_t)c->slipping;
            o->at_cap = (int32_t)c->at_cap;
            o->reserved_ = 0;
            /* The deflection is b's point less its anchor on a: swapped, a's less b's. */
            o->anchor_deflection = v3_scale(c->defl, sg);
        }
        n++;
    }
    *count = n;
    if (buf && cap < n)
        return ws_fail(w, WS_ERR_BUFFER_TOO_SMALL,
                       "ws_world_copy_contacts_between: room for %zu contacts, there are %zu",
                       cap, n);
    return WS_OK;
}

ws_status ws_world_get_interface_stiffness(const ws_world *w, ws_body_id a, ws_body_id b,
                                           double *stiffness, size_t *points)
{
    NEED_WORLD(w);
    NEED_OUT(w, stiffness, "ws_world_get_interface_stiffness");
    uint32_t ia, ib;
    ws_status s = pair_call(w, a, b, "ws_world_get_interface_stiffness", &ia, &ib);
    if (s != WS_OK)
        return s;
    /* Every active contact point is a spring of the pair in parallel with the others: k times
     * its share of the laws (a twin corner's, a fading edge pair's), which its record's energy
     * 0.5 share k overlap^2 holds (the records saved with the state keep it). */
    const uint32_t *mat = w->bodies.material;
    double k = w->params[w->pair_index[mat[ia] * w->pair_dim + mat[ib]]].k, sum = 0.0;
    size_t n = 0;
    for (size_t q = 0; q < w->nrec[w->cur]; q++) {
        const ws_contact_rec *c = &w->rec[w->cur][q];
        if ((c->a == ia && c->b == ib) || (c->a == ib && c->b == ia)) {
            const double ov2 = c->overlap * c->overlap;
            sum += ov2 > 0.0 ? 2.0 * c->energy / ov2 : k;
            n++;
        }
    }
    *stiffness = sum;
    if (points)
        *points = n;
    return WS_OK;
}
