/* Public calls on deformable elements (Def intake, validation, id lookup, read-out) and the
 * elements' part of the step: loads into the bodies' accumulators, then the commit of the law
 * histories once the step is accepted. The formulas live in lib/element. */
#include "world/world_internal.h"

#include <string.h>

static const char *elabel(const ws_element *e)
{
    return e->name ? e->name : "(unnamed)";
}

static const char *type_name(ws_element_type t)
{
    switch (t) {
    case WS_ELEMENT_ROD:
        return "rod";
    case WS_ELEMENT_LINEAR_SPRING:
        return "linear spring";
    case WS_ELEMENT_ANGULAR_SPRING:
        return "angular spring";
    case WS_ELEMENT_BUSHING:
        return "bushing";
    }
    return "element";
}

/* The live element of slot i, or NULL. */
static ws_element *live(const ws_world *w, size_t i)
{
    if (i >= w->element_cap || i >= w->element_slots.slot_count ||
        w->element_slots.dense[i] == UINT32_MAX)
        return NULL;
    return w->elements[i];
}

static ws_status lookup_element(const ws_world *w, ws_element_id id, uint32_t *slot)
{
    return ws_lookup_slot(w, id.bits, WS_KIND_ELEMENT, &w->element_slots, "element", slot);
}

int ws_element_is_valid(const ws_world *w, ws_element_id id)
{
    if (!w)
        return 0;
    return ws_slots_is_live(&w->element_slots, id.bits, WS_KIND_ELEMENT);
}

static void element_defaults(ws_element_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->type = WS_ELEMENT_ROD;
    def->formulation = WS_ELEMENT_INVARIANT;
    /* frame1 = frame2 = 0: automatic (see the header). */
}
WS_DEF_INITS(ws_element_def, element_defaults, user_data)

/* The state of an end in body-state buffer k: a body's, or the world frame at rest. The global
 * angular velocity is formed as the step's prepare() forms it, so the read-out between steps
 * gives the loads the next step applies, to the last bit. */
static ws_element_end end_state(const ws_world *w, uint32_t body, int k)
{
    ws_element_end s = {{0, 0, 0}, {1, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    if (body == WS_ELEMENT_WORLD)
        return s;
    const ws_body_state *st = &w->bodies.st[k];
    m3 A = qt_to_m3(st->p[body]);
    s.x = st->r[body];
    s.p = st->p[body];
    s.v = st->v[body];
    s.w = m3_mul_v(&A, st->w[body]);
    return s;
}

static int quat_zero(qt q)
{
    return q.e0 == 0.0 && q.e1 == 0.0 && q.e2 == 0.0 && q.e3 == 0.0;
}

static int quat_usable(qt q)
{
    double n = qt_norm(q);
    return isfinite(n) && n > 1e-12;
}

/* Checks of a Def that need no allocation; the slots of the law and the bodies on success. */
static ws_status check_def(ws_world *w, const ws_element_def *d, const char *nm, uint32_t *law,
                           uint32_t body[2])
{
    int need = ws_element_type_dim(d->type);
    if (need == 0)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "element '%s': unknown type %d", nm,
                       (int)d->type);
    if (d->formulation != WS_ELEMENT_INVARIANT && d->formulation != WS_ELEMENT_ATTACHED &&
        d->formulation != WS_ELEMENT_POTENTIAL)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "element '%s': unknown formulation %d", nm,
                       (int)d->formulation);
    ws_status s = ws_lookup_law(w, d->law, law);
    if (s != WS_OK)
        return ws_fail(w, s, "element '%s': `law` is required: %s", nm, w->err);
    int dim = w->laws[*law]->dim;
    if (dim != need)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "element '%s': a %s needs a law of dim %d (%s), but the law has dim %d", nm,
                       type_name(d->type), need,
                       need == 1   ? "strain -> tension"
                       : need == 3 ? "3 components"
                                   : "[displacement xyz, rotation xyz]",
                       dim);
    const ws_body_id ids[2] = {d->body1, d->body2};
    for (int i = 0; i < 2; i++) {
        body[i] = WS_ELEMENT_WORLD;
        if (ids[i].bits != 0 && (s = ws_lookup_body(w, ids[i], &body[i])) != WS_OK)
            return ws_fail(w, s, "element '%s': body%d: %s", nm, i + 1, w->err);
    }
    if (body[0] == WS_ELEMENT_WORLD && body[1] == WS_ELEMENT_WORLD)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "element '%s': body1 and body2 are both the world frame (null ids); at "
                       "least one must be a body",
                       nm);
    if (body[0] == body[1])
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "element '%s': body1 and body2 are the same body", nm);
    if (!ws_is_finite3(&d->point1) || !ws_is_finite3(&d->point2))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "element '%s': point1 and point2 must be finite",
                       nm);
    const qt fr[2] = {d->frame1, d->frame2};
    for (int i = 0; i < 2; i++)
        if (!quat_zero(fr[i]) && !quat_usable(fr[i]))
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "element '%s': frame%d must be all zero (automatic) or a non-zero "
                           "finite quaternion, |q| = %g",
                           nm, i + 1, qt_norm(fr[i]));
    if (!isfinite(d->rest_length))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "element '%s': rest_length must be finite", nm);
    return WS_OK;
}

static void free_element(ws_world *w, uint32_t slot)
{
    ws_element *e = w->elements[slot];
    ws_mem_free(&w->mem, e->state, e->nstate * sizeof *e->state);
    ws_mem_free_str(&w->mem, e->name);
    ws_mem_free(&w->mem, e, sizeof *e);
    w->elements[slot] = NULL;
}

ws_status ws_element_create(ws_world *w, const ws_element_def *def, ws_element_id *out)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_element_create");
    NEED_OUT(w, out, "ws_element_create");
    out->bits = 0;
    ws_element_def d;
    ws_element_def_init(&d);
    ws_status s = ws_def_take(w, &d, sizeof d, def, "element");
    if (s != WS_OK)
        return s;
    const char *nm = d.name ? d.name : "(unnamed)";
    uint32_t law, body[2];
    if ((s = check_def(w, &d, nm, &law, body)) != WS_OK)
        return s;
    ws_law *L = w->laws[law];

    /* Points and frames into the bodies' frames, at the bodies' poses now. */
    ws_element e;
    memset(&e, 0, sizeof e);
    e.type = d.type;
    e.form = d.formulation;
    e.dim = L->dim;
    e.law = law;
    e.body[0] = body[0];
    e.body[1] = body[1];
    ws_element_end end[2] = {end_state(w, body[0], w->cur), end_state(w, body[1], w->cur)};
    const v3 pts[2] = {d.point1, d.point2};
    const qt frs[2] = {d.frame1, d.frame2};
    for (int i = 0; i < 2; i++) {
        m3 A = qt_to_m3(end[i].p);
        e.point[i] = d.global_attachment ? m3_tmul_v(&A, v3_sub(pts[i], end[i].x)) : pts[i];
        if (i == 1 && quat_zero(frs[1])) {
            /* Element frame 2 on element frame 1 as it is now: unstrained in rotation. */
            e.frame[1] = qt_normalize(qt_mul(qt_conj(end[1].p), qt_mul(end[0].p, e.frame[0])));
        } else if (quat_zero(frs[i])) {
            e.frame[i] = qt_identity();
        } else {
            qt f = qt_normalize(frs[i]);
            e.frame[i] = d.global_attachment ? qt_normalize(qt_mul(qt_conj(end[i].p), f)) : f;
        }
    }
    e.l0 = 1.0;
    if (e.type == WS_ELEMENT_ROD) {
        ws_element_kin k;
        ws_element_kinematics(&e, end, &k);
        double len = v3_norm(k.l);
        e.l0 = d.rest_length > 0.0 ? d.rest_length : len;
        if (!(e.l0 > 0.0))
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "element '%s': the rod's points coincide at create, so its rest "
                           "length cannot come from them: set rest_length > 0 m",
                           nm);
    }

    /* Everything the element will need, allocated now: a step allocates nothing. */
    e.nstate = L->nstate;
    ws_element *p = ws_mem_alloc(&w->mem, sizeof *p);
    double *state = e.nstate ? ws_mem_alloc(&w->mem, e.nstate * sizeof *state) : NULL;
    char *name = d.name ? ws_mem_strdup(&w->mem, d.name) : NULL;
    uint32_t slot = 0;
    if (!p || (e.nstate && !state) || (d.name && !name) ||
        ws_world_take_slot(w, &w->element_slots, (void ***)&w->elements, &w->element_cap, &slot) !=
            0) {
        ws_mem_free(&w->mem, p, p ? sizeof *p : 0);
        ws_mem_free(&w->mem, state, state ? e.nstate * sizeof *state : 0);
        ws_mem_free_str(&w->mem, name);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "element '%s': out of memory", nm);
    }
    e.state = state;
    e.name = name;
    e.user = d.user_data;
    ws_law_state_init(L, e.state);
    e.t_commit = w->time; /* the history starts relaxed now */
    *p = e;
    w->elements[slot] = p;
    L->users++;
    out->bits = ws_slots_id(&w->element_slots, WS_KIND_ELEMENT, slot);
    return WS_OK;
}

ws_status ws_element_destroy(ws_world *w, ws_element_id id)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_element_destroy");
    uint32_t slot;
    ws_status s = lookup_element(w, id, &slot);
    if (s != WS_OK)
        return s;
    w->laws[w->elements[slot]->law]->users--;
    free_element(w, slot);
    ws_slots_release(&w->element_slots, slot);
    return WS_OK;
}

void ws_world_free_elements(ws_world *w)
{
    for (size_t i = 0; i < w->element_cap && i < w->element_slots.slot_count; i++)
        if (live(w, i))
            free_element(w, (uint32_t)i);
    ws_mem_free(&w->mem, w->elements, w->element_cap * sizeof *w->elements);
    w->elements = NULL;
    w->element_cap = 0;
    ws_slots_destroy(&w->mem, &w->element_slots);
}

ws_status ws_world_body_free_of_elements(const ws_world *w, uint32_t slot)
{
    size_t n = 0;
    const ws_element *first = NULL;
    for (size_t i = 0; i < w->element_slots.slot_count; i++) {
        const ws_element *e = live(w, i);
        if (e && (e->body[0] == slot || e->body[1] == slot)) {
            if (!first)
                first = e;
            n++;
        }
    }
    if (n == 0)
        return WS_OK;
    const char *bn = w->bodies.name[slot] ? w->bodies.name[slot] : "(unnamed)";
    return ws_fail(w, WS_ERR_IN_USE,
                   "ws_body_destroy: body '%s' is joined by %zu element(s) (the first: '%s'); "
                   "destroy them first",
                   bn, n, elabel(first));
}

/* ---- the step ---- */

static ws_status law_failed(const ws_world *w, const ws_element *e, int rc, double t,
                            const char *when)
{
    const double *u = e->u;
    if (rc == WS_LAW_EVAL_CALLBACK)
        return ws_fail(w, WS_ERR_CALLBACK,
                       "%s at t = %.6g s: element '%s' (%s): a callback of its law failed%s", when,
                       t, elabel(e), type_name(e->type),
                       when[0] == 's' ? "; the step was undone" : "");
    return ws_fail(w, WS_ERR_NUMERICAL,
                   "%s at t = %.6g s: element '%s' (%s): its law gave a non-finite force at "
                   "strain (%.4g, %.4g, %.4g, %.4g, %.4g, %.4g)%s",
                   when, t, elabel(e), type_name(e->type), u[0], u[1], u[2], u[3], u[4], u[5],
                   when[0] == 's' ? "; the step was undone" : "");
}

ws_status ws_world_element_forces(ws_world *w, int cur, double t)
{
    ws_body_store *b = &w->bodies;
    for (size_t i = 0; i < w->element_slots.slot_count; i++) {
        ws_element *e = live(w, i);
        if (!e)
            continue;
        ws_element_end end[2] = {end_state(w, e->body[0], cur), end_state(w, e->body[1], cur)};
        ws_element_kin k;
        ws_element_loads ld;
        double F[6];
        int rc = ws_element_eval(e, w->laws[e->law], end, t, &k, F, &ld);
        /* The trial strain is scratch until the commit: a failed step never reaches it. */
        memcpy(e->u, k.u, sizeof e->u);
        memcpy(e->ud, k.ud, sizeof e->ud);
        if (rc != 0) {
            if (rc != WS_LAW_EVAL_CALLBACK)
                w->stats.numerical_errors++;
            return law_failed(w, e, rc, t, "step");
        }
        for (int j = 0; j < 2; j++) {
            uint32_t s = e->body[j];
            if (s == WS_ELEMENT_WORLD)
                continue;
            b->f[s] = v3_add(b->f[s], ld.f[j]);
            b->m[s] = v3_add(b->m[s], ld.m[j]);
        }
    }
    return WS_OK;
}

void ws_world_commit_elements(ws_world *w, double t)
{
    for (size_t i = 0; i < w->element_slots.slot_count; i++) {
        ws_element *e = live(w, i);
        if (!e)
            continue;
        if (e->nstate)
            ws_law_commit(w->laws[e->law], e->state, e->u, e->ud, t,
                          t > e->t_commit ? t - e->t_commit : 0.0);
        e->t_commit = t;
    }
}

/* ---- stable step ---- */

/* Frobenius norm of the 3x3 block (r, c) of a 6x6 row-major matrix. */
static double block_norm(const double *a, int r, int c)
{
    double s = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            s += a[6 * (3 * r + i) + 3 * c + j] * a[6 * (3 * r + i) + 3 * c + j];
    return sqrt(s);
}

/* Bounds on an element's stiffness and damping: translational (N/m, N s/m), rotational (N m/rad,
 * N m s/rad) and their coupling (N/rad). */
typedef struct elem_bounds {
    double kt, kr, ktr, ct, cr, ctr;
} elem_bounds;

static elem_bounds bounds_of(const ws_world *w, const ws_element *e)
{
    const ws_law *L = w->laws[e->law];
    elem_bounds bd = {0, 0, 0, 0, 0, 0};
    double k = ws_law_max_stiffness(L), c = ws_law_max_damping(L);
    switch (e->type) {
    case WS_ELEMENT_ROD: /* dF/d|l| = (dF/d eps) / l0 */
        bd.kt = k / e->l0;
        bd.ct = c / e->l0;
        break;
    case WS_ELEMENT_LINEAR_SPRING:
        bd.kt = k;
        bd.ct = c;
        break;
    case WS_ELEMENT_ANGULAR_SPRING:
        bd.kr = k;
        bd.cr = c;
        break;
    case WS_ELEMENT_BUSHING: {
        /* The law's bounds mix N/m with N m/rad; a linear law's blocks are exact. */
        double u[6] = {0}, F[6], K[36], C[36];
        int linear = L->type == WS_LAW_LINEAR_ELASTIC || L->type == WS_LAW_LINEAR_VISCOELASTIC ||
                     L->type == WS_LAW_LINEAR_VISCOUS;
        if (linear && ws_law_eval(L, e->state, u, u, w->time, 0.0, F, K, C) == 0) {
            bd.kt = block_norm(K, 0, 0);
            bd.kr = block_norm(K, 1, 1);
            bd.ktr = fmax(block_norm(K, 0, 1), block_norm(K, 1, 0));
            bd.ct = block_norm(C, 0, 0);
            bd.cr = block_norm(C, 1, 1);
            bd.ctr = fmax(block_norm(C, 0, 1), block_norm(C, 1, 0));
        } else {
            bd.kt = bd.kr = bd.ktr = k;
            bd.ct = bd.cr = bd.ctr = c;
        }
        break;
    }
    }
    return bd;
}

/* Compliances of a body end: translational at the attachment point (1/m + r^2/J_min) and
 * rotational (1/J_min); zero for the world and kinematic bodies. */
static void compliance(const ws_world *w, const ws_element *e, int j, double *wt, double *wr)
{
    const ws_body_store *b = &w->bodies;
    uint32_t s = e->body[j];
    *wt = *wr = 0.0;
    if (s == WS_ELEMENT_WORLD || b->type[s] != WS_BODY_DYNAMIC)
        return;
    v3 I = b->Ip[s];
    double jmin = fmin(I.x, fmin(I.y, I.z));
    *wr = 1.0 / jmin;
    *wt = b->inv_mass[s] + v3_norm2(e->point[j]) * *wr;
}

double ws_world_element_stable_dt(const ws_world *w)
{
    /* Gershgorin on the mass-scaled stiffness: for each dynamic body, the sum over its elements
     * of k (its compliance) (1 + sqrt(other's compliance / its own)), which is exact for a mass
     * on a spring to the world (k/m) and for two equal masses (2k/m). Damping lowers the limit
     * as for contacts: dt < 2/omega (sqrt(1 + z^2) - z), z = gamma / (2 omega). */
    const ws_body_store *b = &w->bodies;
    double best = INFINITY;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i] || b->type[i] != WS_BODY_DYNAMIC)
            continue;
        double om2 = 0.0, gam = 0.0;
        for (size_t n = 0; n < w->element_slots.slot_count; n++) {
            const ws_element *e = live(w, n);
            if (!e || (e->body[0] != i && e->body[1] != i))
                continue;
            int j = e->body[0] == i ? 0 : 1;
            double wt, wr, ot, orr;
            compliance(w, e, j, &wt, &wr);
            compliance(w, e, 1 - j, &ot, &orr);
            double rt = 1.0 + sqrt(ot / wt), rr = 1.0 + sqrt(orr / wr), rx = fmax(rt, rr);
            double cross = 2.0 * sqrt(wt * wr);
            elem_bounds bd = bounds_of(w, e);
            om2 += bd.kt * wt * rt + bd.kr * wr * rr + bd.ktr * cross * rx;
            gam += bd.ct * wt * rt + bd.cr * wr * rr + bd.ctr * cross * rx;
        }
        if (!(om2 > 0.0))
            continue;
        double om = sqrt(om2), z = gam / (2.0 * om);
        double dt = 2.0 / om * (sqrt(1.0 + z * z) - z);
        if (dt < best)
            best = dt;
    }
    return best;
}

/* ---- read-out ---- */

static ws_status output_of(const ws_world *w, const ws_element *e, ws_element_output *o)
{
    ws_element_end end[2] = {end_state(w, e->body[0], w->cur), end_state(w, e->body[1], w->cur)};
    ws_element_kin k;
    ws_element_loads ld;
    double F[6] = {0, 0, 0, 0, 0, 0};
    const ws_law *L = w->laws[e->law];
    int rc = ws_element_eval(e, L, end, w->time, &k, F, &ld);
    if (rc != 0) {
        /* Name the strain that failed without touching the element (a reading call). */
        ws_element probe = *e;
        memcpy(probe.u, k.u, sizeof probe.u);
        return law_failed(w, &probe, rc, w->time, "read-out");
    }
    memset(o, 0, sizeof *o);
    o->type = (int32_t)e->type;
    o->dim = (int32_t)e->dim;
    for (int i = 0; i < e->dim; i++) {
        o->strain[i] = k.u[i];
        o->strain_rate[i] = k.ud[i];
        o->law_force[i] = F[i];
    }
    o->force = ld.f[0];
    o->moment = ld.mp[0];
    o->moment2 = ld.mp[1];
    o->point1 = k.pt[0];
    o->point2 = k.pt[1];
    o->frame = k.q;
    o->energy = ws_element_energy(e, L, &k, w->time);
    return WS_OK;
}

ws_status ws_element_get_output(const ws_world *w, ws_element_id id, ws_element_output *out)
{
    NEED_WORLD(w);
    NEED_OUT(w, out, "ws_element_get_output");
    uint32_t slot;
    ws_status s = lookup_element(w, id, &slot);
    if (s != WS_OK)
        return s;
    return output_of(w, w->elements[slot], out);
}

const char *ws_element_get_name(const ws_world *w, ws_element_id id)
{
    if (!ws_element_is_valid(w, id))
        return "";
    const char *n = w->elements[ws_id_slot(id.bits)]->name;
    return n ? n : "";
}

void *ws_element_get_user_data(const ws_world *w, ws_element_id id)
{
    if (!ws_element_is_valid(w, id))
        return NULL;
    return w->elements[ws_id_slot(id.bits)]->user;
}

/* Common checks of the bulk copies. */
static ws_status bulk_args(const ws_world *w, const void *buf, size_t cap, size_t *count,
                           const char *fn)
{
    NEED_OUT(w, count, fn);
    if (cap && !buf)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: buffer is NULL but capacity is not 0", fn);
    return WS_OK;
}

ws_status ws_world_copy_element_ids(const ws_world *w, ws_element_id *buf, size_t cap,
                                    size_t *count)
{
    NEED_WORLD(w);
    ws_status s = bulk_args(w, buf, cap, count, "ws_world_copy_element_ids");
    if (s != WS_OK)
        return s;
    size_t n = 0;
    for (size_t i = 0; i < w->element_slots.slot_count; i++) {
        if (!live(w, i))
            continue;
        if (n < cap)
            buf[n].bits =
                ws_slots_id(&w->element_slots, WS_KIND_ELEMENT, (uint32_t)i);
        n++;
    }
    *count = n;
    if (buf && cap < n)
        return ws_fail(w, WS_ERR_BUFFER_TOO_SMALL,
                       "ws_world_copy_element_ids: room for %zu ids, there are %zu", cap, n);
    return WS_OK;
}

ws_status ws_world_copy_element_outputs(const ws_world *w, ws_element_output *buf, size_t cap,
                                        size_t *count)
{
    NEED_WORLD(w);
    ws_status s = bulk_args(w, buf, cap, count, "ws_world_copy_element_outputs");
    if (s != WS_OK)
        return s;
    size_t n = 0;
    for (size_t i = 0; i < w->element_slots.slot_count; i++) {
        const ws_element *e = live(w, i);
        if (!e)
            continue;
        if (n < cap && (s = output_of(w, e, &buf[n])) != WS_OK)
            return s;
        n++;
    }
    *count = n;
    if (buf && cap < n)
        return ws_fail(w, WS_ERR_BUFFER_TOO_SMALL,
                       "ws_world_copy_element_outputs: room for %zu elements, there are %zu", cap,
                       n);
    return WS_OK;
}

ws_status ws_world_get_element_energy(const ws_world *w, double *energy)
{
    NEED_WORLD(w);
    NEED_OUT(w, energy, "ws_world_get_element_energy");
    double sum = 0.0;
    for (size_t i = 0; i < w->element_slots.slot_count; i++) {
        const ws_element *e = live(w, i);
        if (!e)
            continue;
        ws_element_end end[2] = {end_state(w, e->body[0], w->cur),
                                 end_state(w, e->body[1], w->cur)};
        ws_element_kin k;
        ws_element_kinematics(e, end, &k);
        double u = ws_element_energy(e, w->laws[e->law], &k, w->time);
        if (!isfinite(u))
            return ws_fail(w, WS_ERR_UNSUPPORTED,
                           "ws_world_get_element_energy: element '%s': its law cannot give its "
                           "elastic energy (a user law, or a time callback that failed)",
                           elabel(e));
        sum += u;
    }
    *energy = sum;
    return WS_OK;
}
