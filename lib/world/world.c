/* World lifecycle, errors, materials and contact parameters, statistics. */
#include "world/world_internal.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

static void vlog(const ws_world *w, ws_log_level level, const char *fmt, va_list ap)
{
    char buf[WS_ERR_LEN];
    vsnprintf(buf, sizeof buf, fmt, ap);
    if (w->def.log)
        w->def.log(w->def.log_user, level, buf);
}

ws_status ws_fail(const ws_world *w, ws_status s, const char *fmt, ...)
{
    ws_world *mw = (ws_world *)w; /* the error text is the one thing a reading call writes */
    /* Format into a copy first: callers may pass the previous message as an argument. */
    char buf[WS_ERR_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    memcpy(mw->err, buf, sizeof buf);
    if (w->def.log)
        w->def.log(w->def.log_user, WS_LOG_ERROR, mw->err);
    return s;
}

void ws_log(const ws_world *w, ws_log_level level, const char *fmt, ...)
{
    if (!w->def.log)
        return;
    va_list ap;
    va_start(ap, fmt);
    vlog(w, level, fmt, ap);
    va_end(ap);
}

ws_status ws_def_take(const ws_world *w, void *dst, size_t full, const void *src, const char *what)
{
    if (!src)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: the Def pointer is NULL", what);
    if (ws_def_check(src) != 0)
        return ws_fail(w, WS_ERR_UNINITIALIZED_DEF,
                       "%s: the Def was not filled by ws_%s_def_init() (size/magic header wrong)",
                       what, what);
    ws_def_copy(dst, full, src);
    return WS_OK;
}

static void world_defaults(ws_world_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->gravity = v3_make(0.0, 0.0, -9.81);
    def->dt = 2.5e-4;
    def->integrator = WS_INTEGRATOR_SYMPLECTIC_EULER;
    def->full_detection_until = 0.0;
    def->detection_interval = 1;
    def->contact_margin = 2e-3;
    def->max_speed = 1000.0;
    def->max_angular_speed = 1e5;
    def->use_ccd = 1;
    def->stable_fraction = 0.5;
    def->worker_count = 1;
}
WS_DEF_INITS(ws_world_def, world_defaults, user_data)

static void contact_defaults(ws_contact_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->stiffness = 2e5;
    def->damping = 10.0;
    def->friction = 0.3;
    def->friction_vlim = 0.01;
    def->friction_model = WS_FRICTION_REGULARIZED;
    def->stick_stiffness = 2e5;
    def->stick_damping = 0.0; /* from the ratio */
    def->stick_damping_ratio = 1.0;
}
WS_DEF_INITS(ws_contact_def, contact_defaults, stick_damping)

static void material_defaults(ws_material_def *def)
{
    ws_def_reset(def, sizeof *def);
}
WS_DEF_INITS(ws_material_def, material_defaults, name)

static ws_status check_contact_def(const ws_world *w, const ws_contact_def *c)
{
    if (!(isfinite(c->stiffness) && c->stiffness > 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "contact: stiffness must be > 0 N/m, got %g",
                       c->stiffness);
    if (!(isfinite(c->damping) && c->damping >= 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "contact: damping must be >= 0 kg/s, got %g",
                       c->damping);
    if (!(isfinite(c->friction) && c->friction >= 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "contact: friction mu must be >= 0, got %g",
                       c->friction);
    if (!(isfinite(c->friction_vlim) && c->friction_vlim > 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "contact: friction_vlim must be > 0 m/s, got %g",
                       c->friction_vlim);
    if (c->friction_model != WS_FRICTION_REGULARIZED && c->friction_model != WS_FRICTION_STICK)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "contact: unknown friction_model %d",
                       (int)c->friction_model);
    if (!(isfinite(c->stick_stiffness) && c->stick_stiffness > 0.0) ||
        !(isfinite(c->stick_damping) && c->stick_damping >= 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "contact: stick_stiffness must be > 0 N/m and stick_damping >= 0 kg/s");
    if (!(c->stick_damping_ratio >= 0.0 && c->stick_damping_ratio <= 10.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "contact: stick_damping_ratio must be 0..10 (of critical), got %g",
                       c->stick_damping_ratio);
    return WS_OK;
}

static ws_pair_params to_params(const ws_contact_def *c)
{
    ws_pair_params p = {c->stiffness,       c->damping,       c->friction,
                        c->friction_vlim,   c->stick_stiffness, c->stick_damping,
                        (int)c->friction_model, c->stick_damping_ratio};
    return p;
}

static ws_contact_def from_params(const ws_pair_params *p)
{
    ws_contact_def c;
    ws_contact_def_init(&c);
    c.stiffness = p->k;
    c.damping = p->c;
    c.friction = p->mu;
    c.friction_vlim = p->vlim;
    c.stick_stiffness = p->kt;
    c.stick_damping = p->ct;
    c.stick_damping_ratio = p->zt;
    c.friction_model = (ws_friction_model)p->model;
    return c;
}

static ws_status create_material(ws_world *w, const char *name, ws_material_id *out);

ws_status ws_world_create(const ws_world_def *def, ws_world **out)
{
    if (!out)
        return WS_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if (!def)
        return WS_ERR_INVALID_ARGUMENT;
    if (ws_def_check(def) != 0)
        return WS_ERR_UNINITIALIZED_DEF;
    /* A caller built against an older, smaller Def has only its own fields: the rest default. */
    ws_world_def d;
    ws_world_def_init(&d);
    ws_def_copy(&d, sizeof d, def);
    if (!(isfinite(d.dt) && d.dt > 0.0) || !ws_is_finite3(&d.gravity) ||
        !(isfinite(d.full_detection_until)) || d.detection_interval < 1 ||
        !(isfinite(d.contact_margin) && d.contact_margin >= 0.0) ||
        !(d.max_speed > 0.0) || !(d.max_angular_speed > 0.0) ||
        !(d.stable_fraction > 0.0 && d.stable_fraction <= 1.0) ||
        (d.integrator != WS_INTEGRATOR_SYMPLECTIC_EULER &&
         d.integrator != WS_INTEGRATOR_PAPER_EXPLICIT) ||
        (d.friction_step != WS_FRICTION_STEP_IMPLICIT &&
         d.friction_step != WS_FRICTION_STEP_EXPLICIT))
        return WS_ERR_INVALID_ARGUMENT;
    int hooks = (d.allocator.alloc != NULL) + (d.allocator.realloc != NULL) +
                (d.allocator.free != NULL);
    if (hooks != 0 && hooks != 3)
        return WS_ERR_INVALID_ARGUMENT;
    /* Workers: 1 to WS_MAX_WORKERS; the host's scheduler is both of its calls or neither. */
    if (d.worker_count < 1 || d.worker_count > WS_MAX_WORKERS ||
        (d.enqueue_task == NULL) != (d.finish_task == NULL))
        return WS_ERR_INVALID_ARGUMENT;

    ws_mem mem;
    ws_mem_init(&mem, &d.allocator);
    ws_world *w = ws_mem_calloc(&mem, 1, sizeof *w);
    if (!w)
        return WS_ERR_OUT_OF_MEMORY;
    w->mem = mem;
    ws_arena_init(&w->arena, &w->mem);
    w->def = d;
    /* The salt of every slot's first generation, so an id of another world is refused but
     * with odds of about 2^-32 (base.h); no global counter is needed. */
    uint32_t salt = ws_id_salt(w);
    w->body_slots.salt = salt;
    w->shape_slots.salt = salt;
    w->mat_slots.salt = salt;
    w->law_slots.salt = salt;
    w->web_slots.salt = salt;
    w->element_slots.salt = salt;

    w->params = ws_mem_alloc(&w->mem, 4 * sizeof *w->params);
    if (!w->params) {
        ws_world_destroy(w);
        return WS_ERR_OUT_OF_MEMORY;
    }
    w->params_cap = 4;
    /* A task's items: the lanes, and the body part's items after them (as many at most:
     * world_step.c's body_plan). */
    if (d.worker_count > 1 && !d.enqueue_task &&
        !(w->pool = ws_pool_create(&w->mem, d.worker_count - 1,
                                   2 * WS_LANES_PER_WORKER * (int32_t)d.worker_count))) {
        ws_world_destroy(w);
        return WS_ERR_OUT_OF_MEMORY;
    }
    if (!(w->lane_job = ws_mem_calloc(&w->mem, (size_t)WS_LANES_PER_WORKER * d.worker_count,
                                      sizeof *w->lane_job))) {
        ws_world_destroy(w);
        return WS_ERR_OUT_OF_MEMORY;
    }
    ws_contact_def c;
    ws_contact_def_init(&c);
    w->params[0] = to_params(&c);
    w->nparams = 1;
    ws_material_id def_mat;
    if (create_material(w, "default", &def_mat) != WS_OK) {
        ws_world_destroy(w);
        return WS_ERR_OUT_OF_MEMORY;
    }
    w->stats.bytes_in_use = w->mem.in_use;
    *out = w;
    return WS_OK;
}

void ws_world_destroy(ws_world *w)
{
    if (!w)
        return;
    if (w->in_step) {
        /* The step still runs on this world: refuse, saying so (it has no status to return). */
        ws_fail(w, WS_ERR_IN_STEP, "ws_world_destroy called from inside ws_world_step (a "
                                   "callback); the world was not destroyed");
        return;
    }
    ws_mem *m = &w->mem;
    ws_pool_destroy(m, w->pool); /* no step runs: its threads wait for work */
    ws_world_lanes_free(w);
    ws_mem_free(
        m, w->lane_job,
        w->lane_job ? (size_t)WS_LANES_PER_WORKER * w->def.worker_count * sizeof *w->lane_job : 0);
    ws_world_free_elements(w); /* before the laws and bodies they use */
    ws_world_free_webs(w);
    ws_world_free_laws(w);
    ws_bodies_free(m, &w->bodies);
    ws_slots_destroy(m, &w->body_slots);
    /* A slot may have been taken while growing the array failed: walk the array, not slots. */
    for (size_t i = 0; i < w->shape_cap && i < w->shape_slots.slot_count; i++) {
        if (w->shape_slots.dense[i] != UINT32_MAX && w->shapes[i]) {
            ws_shape_free(m, w->shapes[i]);
            ws_mem_free(m, w->shapes[i], sizeof *w->shapes[i]);
        }
    }
    ws_mem_free(m, w->shapes, w->shape_cap * sizeof *w->shapes);
    ws_slots_destroy(m, &w->shape_slots);
    for (size_t i = 0; i < w->mat_cap && i < w->mat_slots.slot_count; i++)
        if (w->mat_slots.dense[i] != UINT32_MAX) /* only live slots have a name set */
            ws_mem_free_str(m, w->mat_name[i]);
    ws_mem_free(m, w->mat_name, w->mat_cap * sizeof *w->mat_name);
    ws_slots_destroy(m, &w->mat_slots);
    ws_mem_free(m, w->params, w->params_cap * sizeof *w->params);
    ws_mem_free(m, w->pair_index, w->pair_dim * w->pair_dim * sizeof *w->pair_index);
    ws_mem_free(m, w->mat_mass, w->pair_dim * sizeof *w->mat_mass);
    for (int k = 0; k < 2; k++) {
        ws_mem_free(m, w->cand[k], w->capcand[k] * sizeof *w->cand[k]);
        ws_mem_free(m, w->rec[k], w->caprec[k] * sizeof *w->rec[k]);
    }
    ws_mem_free(m, w->friction_scratch, w->friction_cap * sizeof *w->friction_scratch);
    ws_arena_free(&w->arena);
    ws_mem local = *m;
    ws_mem_free(&local, w, sizeof *w);
}

const char *ws_world_last_error(const ws_world *w)
{
    if (!w)
        return "no world (NULL)";
    return w->err;
}

void *ws_world_get_user_data(const ws_world *w)
{
    return w ? w->def.user_data : NULL;
}


ws_status ws_world_get_time(const ws_world *w, double *t)
{
    NEED_WORLD(w);
    NEED_OUT(w, t, "ws_world_get_time");
    *t = w->time;
    return WS_OK;
}

ws_status ws_world_get_dt(const ws_world *w, double *dt)
{
    NEED_WORLD(w);
    NEED_OUT(w, dt, "ws_world_get_dt");
    *dt = w->def.dt;
    return WS_OK;
}

ws_status ws_world_get_stable_fraction(const ws_world *w, double *fraction)
{
    NEED_WORLD(w);
    NEED_OUT(w, fraction, "ws_world_get_stable_fraction");
    *fraction = w->def.stable_fraction;
    return WS_OK;
}

ws_status ws_world_set_dt(ws_world *w, double dt)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_world_set_dt");
    if (!(isfinite(dt) && dt > 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_world_set_dt: dt must be > 0 s, got %g", dt);
    w->def.dt = dt;
    w->web_check = 1;
    return WS_OK;
}

ws_status ws_world_set_gravity(ws_world *w, const ws_vec3 *g)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_world_set_gravity");
    if (!g || !ws_is_finite3(g))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_world_set_gravity: gravity must be finite");
    w->def.gravity = *g;
    return WS_OK;
}

ws_status ws_world_get_stats(const ws_world *w, ws_world_stats *s)
{
    NEED_WORLD(w);
    NEED_OUT(w, s, "ws_world_get_stats");
    *s = w->stats;
    s->time = w->time;
    s->steps = w->steps;
    s->contacts = w->nrec[w->cur];
    s->candidates = w->ncand[w->cur];
    /* The margins now (the bounds are asked of scratch, not state: no step is running). */
    s->web_step_use = 0.0;
    for (size_t k = 0; k < w->web_slots.slot_count; k++) {
        if (w->web_slots.dense[k] == UINT32_MAX)
            continue;
        const ws_web *web = w->webs[k];
        if (web->integrator == WS_WEB_IMPLICIT)
            continue; /* no explicit limit to use */
        double use = w->def.dt / web->substeps / ws_world_web_stable_dt((ws_world *)w, web);
        s->web_step_use = use > s->web_step_use ? use : s->web_step_use;
    }
    ws_contact_limit lim;
    ws_world_contact_limit(w, &lim);
    s->body_step_use = w->def.dt / lim.dt;
    s->bytes_in_use = w->mem.in_use;
    s->bytes_peak = w->mem.peak;
    s->bodies = w->bodies.alive_count;
    return WS_OK;
}

ws_status ws_world_get_energy(const ws_world *w, ws_energy *e)
{
    NEED_WORLD(w);
    NEED_OUT(w, e, "ws_world_get_energy");
    const ws_body_store *b = &w->bodies;
    const ws_body_state *st = &b->st[w->cur];
    e->kinetic = e->potential = e->contact = 0.0;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i] || b->type[i] != WS_BODY_DYNAMIC)
            continue;
        v3 Jw = m3_mul_v(&b->J[i], st->w[i]);
        e->kinetic += 0.5 * b->mass[i] * v3_norm2(st->v[i]) + 0.5 * v3_dot(st->w[i], Jw);
        e->potential -= b->mass[i] * v3_dot(w->def.gravity, st->r[i]);
    }
    for (size_t k = 0; k < w->nrec[w->cur]; k++)
        e->contact += w->rec[w->cur][k].energy;
    return WS_OK;
}

ws_status ws_world_get_state_hash(const ws_world *w, uint64_t *hash)
{
    NEED_WORLD(w);
    NEED_OUT(w, hash, "ws_world_get_state_hash");
    /* The hashed part of the walk that save and restore make (world_state.c): every piece
     * of state that follows the physics, the detection bookkeeping left out (a failed step may
     * change that, and the hash is the same as long as the motion is). The walk only reads. */
    ws_walk k = {WS_WALK_HASH, WS_HASH_SEED, NULL, NULL, 0, 0, WS_OK, NULL, 0};
    ws_world_walk((ws_world *)w, &k);
    uint64_t h = k.hash;
    *hash = h;
    return WS_OK;
}

/* ---- materials and contact pairs ---- */

static ws_status create_material(ws_world *w, const char *name, ws_material_id *out)
{
    uint32_t slot;
    if (ws_slots_take(&w->mem, &w->mat_slots, &slot) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_material_create: out of memory");
    if (ws_array_reserve(&w->mem, (void **)&w->mat_name, &w->mat_cap, slot + 1,
                         sizeof *w->mat_name) != 0) {
        ws_slots_release(&w->mat_slots, slot);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_material_create: out of memory");
    }
    if (slot + 1 > w->pair_dim) {
        size_t dim = w->pair_dim ? 2 * w->pair_dim : 4;
        while (dim < slot + 1)
            dim *= 2;
        uint32_t *pi = ws_mem_calloc(&w->mem, dim * dim, sizeof *pi);
        ws_mat_mass *mm = pi ? ws_mem_realloc(&w->mem, w->mat_mass, w->pair_dim * sizeof *mm,
                                              dim * sizeof *mm)
                             : NULL;
        if (!mm) {
            ws_mem_free(&w->mem, pi, dim * dim * sizeof *pi);
            ws_slots_release(&w->mat_slots, slot);
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_material_create: out of memory");
        }
        w->mat_mass = mm;
        for (size_t a = 0; a < w->pair_dim; a++)
            for (size_t b = 0; b < w->pair_dim; b++)
                pi[a * dim + b] = w->pair_index[a * w->pair_dim + b];
        ws_mem_free(&w->mem, w->pair_index, w->pair_dim * w->pair_dim * sizeof *pi);
        w->pair_index = pi;
        w->pair_dim = dim;
    }
    char *nm = NULL;
    if (name && !(nm = ws_mem_strdup(&w->mem, name))) {
        ws_slots_release(&w->mat_slots, slot);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_material_create: out of memory");
    }
    w->mat_name[slot] = nm;
    w->mat_slots.dense[slot] = slot;
    for (size_t k = 0; k < w->pair_dim; k++)
        w->pair_index[slot * w->pair_dim + k] = w->pair_index[k * w->pair_dim + slot] = 0;
    out->bits = ws_slots_id(&w->mat_slots, WS_KIND_MATERIAL, slot);
    return WS_OK;
}

ws_status ws_material_create(ws_world *w, const ws_material_def *def, ws_material_id *out)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_material_create");
    NEED_OUT(w, out, "ws_material_create");
    out->bits = 0;
    ws_material_def d;
    ws_material_def_init(&d);
    ws_status s = ws_def_take(w, &d, sizeof d, def, "material");
    if (s != WS_OK)
        return s;
    return create_material(w, d.name, out);
}

ws_status ws_lookup_material(const ws_world *w, ws_material_id id, uint32_t *slot)
{
    uint32_t s = ws_id_slot(id.bits);
    if (id.bits == 0)
        return ws_fail(w, WS_ERR_STALE_HANDLE, "material id is null");
    if (ws_id_kind(id.bits) != WS_KIND_MATERIAL)
        return ws_fail(w, WS_ERR_STALE_HANDLE, "material id 0x%016llx is not a material id",
                       (unsigned long long)id.bits);
    if (!ws_slots_is_live(&w->mat_slots, id.bits, WS_KIND_MATERIAL))
        return ws_fail(w, WS_ERR_STALE_HANDLE,
                       "material id 0x%016llx names no live material of this world (destroyed, "
                       "or another world's)",
                       (unsigned long long)id.bits);
    *slot = s;
    return WS_OK;
}

int ws_material_is_valid(const ws_world *w, ws_material_id id)
{
    if (!w)
        return 0;
    char keep[WS_ERR_LEN];
    memcpy(keep, w->err, sizeof keep);
    uint32_t s;
    int ok = ws_lookup_material(w, id, &s) == WS_OK;
    memcpy(((ws_world *)w)->err, keep, sizeof keep);
    return ok;
}

ws_status ws_world_get_default_material(const ws_world *w, ws_material_id *out)
{
    NEED_WORLD(w);
    NEED_OUT(w, out, "ws_world_get_default_material");
    out->bits = ws_slots_id(&w->mat_slots, WS_KIND_MATERIAL, 0);
    return WS_OK;
}

ws_status ws_world_set_contact(ws_world *w, ws_material_id a, ws_material_id b,
                               const ws_contact_def *def)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_world_set_contact");
    uint32_t sa, sb;
    ws_status s;
    if ((s = ws_lookup_material(w, a, &sa)) != WS_OK || (s = ws_lookup_material(w, b, &sb)) != WS_OK)
        return s;
    ws_contact_def d;
    ws_contact_def_init(&d);
    if ((s = ws_def_take(w, &d, sizeof d, def, "contact")) != WS_OK)
        return s;
    if ((s = check_contact_def(w, &d)) != WS_OK)
        return s;
    uint32_t idx = w->pair_index[sa * w->pair_dim + sb];
    if (idx == 0) {
        if (ws_array_reserve(&w->mem, (void **)&w->params, &w->params_cap, w->nparams + 1,
                             sizeof *w->params) != 0)
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_world_set_contact: out of memory");
        idx = (uint32_t)w->nparams++;
    }
    w->params[idx] = to_params(&d);
    w->pair_index[sa * w->pair_dim + sb] = w->pair_index[sb * w->pair_dim + sa] = idx;
    w->web_check = 1;
    return WS_OK;
}

ws_status ws_world_get_contact(const ws_world *w, ws_material_id a, ws_material_id b,
                               ws_contact_def *def)
{
    NEED_WORLD(w);
    NEED_OUT(w, def, "ws_world_get_contact");
    uint32_t sa, sb;
    ws_status s;
    if ((s = ws_lookup_material(w, a, &sa)) != WS_OK || (s = ws_lookup_material(w, b, &sb)) != WS_OK)
        return s;
    *def = from_params(&w->params[w->pair_index[sa * w->pair_dim + sb]]);
    return WS_OK;
}

ws_status ws_world_set_default_contact(ws_world *w, const ws_contact_def *def)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_world_set_default_contact");
    ws_contact_def d;
    ws_contact_def_init(&d);
    ws_status s;
    if ((s = ws_def_take(w, &d, sizeof d, def, "contact")) != WS_OK)
        return s;
    if ((s = check_contact_def(w, &d)) != WS_OK)
        return s;
    w->params[0] = to_params(&d);
    w->web_check = 1;
    return WS_OK;
}

double ws_contact_stable_dt(double k, double c, double m_eff)
{
    /* Explicit limit 2/omega for a mass on several penalty springs: omega^2 = n k / m with n
     * simultaneous contacts, reduced by damping: dt < 2/omega (sqrt(1 + z^2) - z), z = n c /
     * (2 m omega); in closed form (sqrt(C^2 + 4 m K) - C) / K with K = n k, C = n c. */
    double K = WS_CONTACTS_PER_BODY * k, C = WS_CONTACTS_PER_BODY * c;
    if (!(K > 0.0))
        return INFINITY;
    return (sqrt(C * C + 4.0 * m_eff * K) - C) / K;
}

/* Effective mass of a pair of bodies (a kinematic or absent one counts as infinite). */
static double pair_mass(const ws_body_store *b, uint32_t i, uint32_t j)
{
    double inv_i = i == UINT32_MAX ? 0.0 : b->inv_mass[i];
    double inv_j = j == UINT32_MAX ? 0.0 : b->inv_mass[j];
    return 1.0 / (inv_i + inv_j);
}

void ws_world_contact_limit(const ws_world *w, ws_contact_limit *lim)
{
    /* Every pair of materials that two bodies now in the world have, at its lightest: the two
     * lightest dynamic bodies of each material, or a dynamic body against a kinematic one.
     * The stiffness is the larger of the normal and (stick model) tangential springs, the
     * damping likewise: either direction can run away. */
    const ws_body_store *b = &w->bodies;
    ws_mat_mass *mm = ((ws_world *)w)->mat_mass; /* scratch, not state */
    const uint32_t none = UINT32_MAX;
    for (size_t a = 0; a < w->pair_dim; a++)
        mm[a].light[0] = mm[a].light[1] = mm[a].kinematic = none;
    for (uint32_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        ws_mat_mass *e = &mm[b->material[i]];
        if (b->type[i] != WS_BODY_DYNAMIC) {
            e->kinematic = i;
        } else if (e->light[0] == none || b->mass[i] < b->mass[e->light[0]]) {
            e->light[1] = e->light[0];
            e->light[0] = i;
        } else if (e->light[1] == none || b->mass[i] < b->mass[e->light[1]]) {
            e->light[1] = i;
        }
    }
    *lim = (ws_contact_limit){INFINITY, 0, 0, 0, 0, 0, none, none};
    for (uint32_t ma = 0; ma < w->pair_dim; ma++) {
        uint32_t i = mm[ma].light[0];
        if (i == none)
            continue; /* a pair needs a dynamic body on one side */
        for (uint32_t mb = 0; mb < w->pair_dim; mb++) {
            /* The partner: the lightest dynamic body of mb (the second lightest when it is the
             * same material), else a kinematic one. */
            uint32_t j = mb == ma ? mm[mb].light[1] : mm[mb].light[0];
            if (j == none)
                j = mm[mb].kinematic;
            if (j == none)
                continue;
            const ws_pair_params *p = &w->params[w->pair_index[ma * w->pair_dim + mb]];
            int stick = p->model == WS_FRICTION_STICK;
            double k = stick ? fmax(p->k, p->kt) : p->k;
            double m = pair_mass(b, i, b->type[j] == WS_BODY_DYNAMIC ? j : none);
            double c = stick ? fmax(p->c, ws_stick_damping(p, m)) : p->c;
            double dt = ws_contact_stable_dt(k, c, m);
            if (dt < lim->dt)
                *lim = (ws_contact_limit){dt, k, c, m, ma, mb, i, j};
        }
    }
}

double ws_world_stable_dt(const ws_world *w)
{
    ws_contact_limit lim;
    ws_world_contact_limit(w, &lim);
    return fmin(lim.dt, ws_world_element_stable_dt(w)); /* the elements' springs too */
}

ws_status ws_world_estimate_stable_dt(const ws_world *w, double *dt)
{
    NEED_WORLD(w);
    NEED_OUT(w, dt, "ws_world_estimate_stable_dt");
    *dt = ws_world_stable_dt(w);
    return WS_OK;
}

/* Take a slot of a table whose objects live in a pointer array, growing the array. */
int ws_world_take_slot(ws_world *w, ws_slot_table *t, void ***arr, size_t *cap, uint32_t *slot)
{
    if (ws_slots_take(&w->mem, t, slot) != 0)
        return -1;
    if (ws_array_reserve(&w->mem, (void **)arr, cap, *slot + 1, sizeof(void *)) != 0) {
        ws_slots_release(t, *slot);
        return -1;
    }
    (*arr)[*slot] = NULL;
    t->dense[*slot] = *slot;
    return 0;
}
