/* Public calls on constitutive laws: validation, id lookup, evaluation, history. */
#include "world/world_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static void law_defaults(ws_law_def *def)
{
    ws_def_reset(def, sizeof *def);
    def->type = WS_LAW_LINEAR_ELASTIC;
    def->transition = 1e-3;
    def->dim = 1;
    def->stop_low = -INFINITY;
    def->stop_high = INFINITY;
    def->scale = 1.0;
    def->user_flags = WS_LAW_FLAG_ELASTIC | WS_LAW_FLAG_VISCOUS;
}
WS_DEF_INITS(ws_law_def, law_defaults, user_flags)

ws_status ws_lookup_law(const ws_world *w, ws_law_id id, uint32_t *slot)
{
    return ws_lookup_slot(w, id.bits, WS_KIND_LAW, &w->law_slots, "law", slot);
}

int ws_law_is_valid(const ws_world *w, ws_law_id id)
{
    if (!w)
        return 0;
    return ws_slots_is_live(&w->law_slots, id.bits, WS_KIND_LAW);
}

/* The law of an id, or NULL with the error recorded (status in *s). */
static ws_law *find(const ws_world *w, ws_law_id id, ws_status *s)
{
    uint32_t slot;
    *s = ws_lookup_law(w, id, &slot);
    return *s == WS_OK ? w->laws[slot] : NULL;
}

ws_status ws_law_create(ws_world *w, const ws_law_def *def, ws_law_id *out)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_law_create");
    NEED_OUT(w, out, "ws_law_create");
    out->bits = 0;
    ws_law_def d;
    ws_law_def_init(&d);
    /* The first released layout ended at `name`; older callers keep working. */
    ws_status s =
        ws_def_take(w, &d, sizeof d, def, "law");
    if (s != WS_OK)
        return s;
    const char *label = d.name ? d.name : "(unnamed)";

    /* The laws it refers to. */
    ws_law *refs[WS_LAW_MAX_TERMS];
    size_t nrefs = 0;
    if (d.type == WS_LAW_SUM) {
        if (!d.terms)
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "law '%s': a sum needs terms (got NULL)",
                           label);
        if (d.term_count < 1 || d.term_count > WS_LAW_MAX_TERMS)
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                           "law '%s': term_count of a sum must be 1 to %d, got %zu", label,
                           WS_LAW_MAX_TERMS, d.term_count);
        for (size_t j = 0; j < d.term_count; j++) {
            if (!(refs[j] = find(w, d.terms[j], &s)))
                return ws_fail(w, s, "law '%s': terms[%zu]: %s", label, j, w->err);
        }
        nrefs = d.term_count;
    } else if (d.type == WS_LAW_SCALED) {
        if (!d.base.bits)
            return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "law '%s': a scaled law needs base", label);
        if (!(refs[0] = find(w, d.base, &s)))
            return ws_fail(w, s, "law '%s': base: %s", label, w->err);
        nrefs = 1;
    }
    /* A law can refer only to laws that exist before it, and laws never change, so the
     * references cannot form a cycle. */

    char why[256];
    ws_law *p = NULL;
    if ((s = ws_law_new(&w->mem, &d, refs, nrefs, &p, why, sizeof why)) != WS_OK) {
        if (s == WS_ERR_OUT_OF_MEMORY)
            return ws_fail(w, s, "ws_law_create: out of memory");
        /* why starts with "law: " */
        return ws_fail(w, s, "law '%s': %s", label, strncmp(why, "law: ", 5) ? why : why + 5);
    }
    if (d.name && !(p->name = ws_mem_strdup(&w->mem, d.name))) {
        ws_law_free(&w->mem, p, 1);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_law_create: out of memory");
    }
    uint32_t slot;
    if (ws_world_take_slot(w, &w->law_slots, (void ***)&w->laws, &w->law_cap, &slot) != 0) {
        ws_mem_free_str(&w->mem, p->name);
        ws_law_free(&w->mem, p, 1);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_law_create: out of memory");
    }
    w->laws[slot] = p;
    out->bits = ws_slots_id(&w->law_slots, WS_KIND_LAW, slot);
    return WS_OK;
}

static void free_law(ws_world *w, uint32_t slot, int release_refs)
{
    ws_mem_free_str(&w->mem, w->laws[slot]->name);
    ws_law_free(&w->mem, w->laws[slot], release_refs);
    w->laws[slot] = NULL;
}

ws_status ws_law_destroy(ws_world *w, ws_law_id id)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_law_destroy");
    uint32_t slot;
    ws_status s = ws_lookup_law(w, id, &slot);
    if (s != WS_OK)
        return s;
    if (w->laws[slot]->users)
        return ws_fail(w, WS_ERR_IN_USE,
                       "ws_law_destroy: %u users (webs, elements or other laws) still use this law",
                       w->laws[slot]->users);
    free_law(w, slot, 1);
    ws_slots_release(&w->law_slots, slot);
    return WS_OK;
}

ws_status ws_law_get_info(const ws_world *w, ws_law_id id, ws_law_info *info)
{
    NEED_WORLD(w);
    NEED_OUT(w, info, "ws_law_get_info");
    ws_status s;
    const ws_law *L = find(w, id, &s);
    if (!L)
        return s;
    memset(info, 0, sizeof *info);
    info->type = L->type;
    info->dim = L->dim;
    info->flags = L->flags;
    info->state_size = L->nstate;
    info->users = L->users;
    info->max_stiffness = ws_law_max_stiffness(L);
    info->max_damping = ws_law_max_damping(L);
    return WS_OK;
}

/* Map an evaluation failure to a status and message. */
static ws_status eval_failed(const ws_world *w, const ws_law *L, int r, const char *fn)
{
    const char *label = L->name ? L->name : "(unnamed)";
    if (r == WS_LAW_EVAL_CALLBACK)
        return ws_fail(w, WS_ERR_CALLBACK, "%s: law '%s': a user or time callback failed", fn,
                       label);
    return ws_fail(w, WS_ERR_NUMERICAL, "%s: law '%s': the force or a derivative is not finite", fn,
                   label);
}

static int all_finite(const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

ws_status ws_law_evaluate(const ws_world *w, ws_law_id id, double eps, double epsd, double *F,
                          double *dF, double *dFd)
{
    NEED_WORLD(w);
    ws_status s;
    const ws_law *L = find(w, id, &s);
    if (!L)
        return s;
    if (L->dim != 1)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_law_evaluate: the law has dim %d: use ws_law_evaluate_state", L->dim);
    if (!isfinite(eps) || !isfinite(epsd))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_law_evaluate: strain and rate must be finite");
    int r = ws_law_eval(L, NULL, &eps, &epsd, 0.0, 0.0, F, dF, dFd);
    return r ? eval_failed(w, L, r, "ws_law_evaluate") : WS_OK;
}

/* Energy and its failures: NaN means a user law (unknown) or a failed time callback. */
static ws_status energy_of(const ws_world *w, const ws_law *L, const double *state, const double *u,
                           double t, double *energy, const char *fn)
{
    double e = ws_law_elastic_energy_at(L, state, u, t);
    if (isnan(e)) {
        /* Tell the two apart: a time callback that fails also fails evaluation. */
        double f[WS_LAW_MAX_DIM];
        if (ws_law_eval(L, state, u, NULL, t, 0.0, f, NULL, NULL) == WS_LAW_EVAL_CALLBACK &&
            L->type != WS_LAW_USER)
            return eval_failed(w, L, WS_LAW_EVAL_CALLBACK, fn);
        return ws_fail(w, WS_ERR_UNSUPPORTED,
                       "%s: the energy of a user law (or of a sum or scaling of one) is unknown",
                       fn);
    }
    if (!isfinite(e))
        return ws_fail(w, WS_ERR_NUMERICAL, "%s: the energy is not finite", fn);
    *energy = e;
    return WS_OK;
}

ws_status ws_law_energy(const ws_world *w, ws_law_id id, double eps, double *energy)
{
    NEED_WORLD(w);
    NEED_OUT(w, energy, "ws_law_energy");
    ws_status s;
    const ws_law *L = find(w, id, &s);
    if (!L)
        return s;
    if (L->dim != 1)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_law_energy: the law has dim %d: use ws_law_energy_state", L->dim);
    if (!isfinite(eps))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_law_energy: strain must be finite");
    return energy_of(w, L, NULL, &eps, 0.0, energy, "ws_law_energy");
}

ws_status ws_law_get_state_size(const ws_world *w, ws_law_id id, size_t *count)
{
    NEED_WORLD(w);
    NEED_OUT(w, count, "ws_law_get_state_size");
    ws_status s;
    const ws_law *L = find(w, id, &s);
    if (!L)
        return s;
    *count = L->nstate;
    return WS_OK;
}

ws_status ws_law_init_state(const ws_world *w, ws_law_id id, double *state)
{
    NEED_WORLD(w);
    ws_status s;
    const ws_law *L = find(w, id, &s);
    if (!L)
        return s;
    if (L->nstate && !state)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_law_init_state: state is NULL but the law keeps %u doubles", L->nstate);
    ws_law_state_init(L, state);
    return WS_OK;
}

/* The checks evaluation and commit share. */
static ws_status check_point(const ws_world *w, const ws_law *L, const double *state,
                             const double *u, const double *ud, double t, double dt, const char *fn)
{
    if (!u)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: u is NULL", fn);
    if (!all_finite(u, L->dim) || (ud && !all_finite(ud, L->dim)))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: strain and rate must be finite", fn);
    if (!isfinite(t) || !(isfinite(dt) && dt >= 0.0))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "%s: t must be finite and dt finite and >= 0 s, got %g and %g", fn, t, dt);
    if (state && !all_finite(state, (int)L->nstate))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: the state is not finite", fn);
    return WS_OK;
}

ws_status ws_law_evaluate_state(const ws_world *w, ws_law_id id, const double *state,
                                const double *u, const double *ud, double t, double dt, double *F,
                                double *dFdu, double *dFdud)
{
    NEED_WORLD(w);
    ws_status s;
    const ws_law *L = find(w, id, &s);
    if (!L)
        return s;
    if ((s = check_point(w, L, state, u, ud, t, dt, "ws_law_evaluate_state")) != WS_OK)
        return s;
    int r = ws_law_eval(L, state, u, ud, t, dt, F, dFdu, dFdud);
    return r ? eval_failed(w, L, r, "ws_law_evaluate_state") : WS_OK;
}

ws_status ws_law_commit_state(const ws_world *w, ws_law_id id, double *state, const double *u,
                              const double *ud, double t, double dt)
{
    NEED_WORLD(w);
    ws_status s;
    const ws_law *L = find(w, id, &s);
    if (!L)
        return s;
    if (!L->nstate)
        return WS_OK;
    if (!state)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_law_commit_state: state is NULL but the law keeps %u doubles",
                       L->nstate);
    if ((s = check_point(w, L, state, u, ud, t, dt, "ws_law_commit_state")) != WS_OK)
        return s;
    ws_law_commit(L, state, u, ud, t, dt);
    return WS_OK;
}

ws_status ws_law_energy_state(const ws_world *w, ws_law_id id, const double *state, const double *u,
                              double t, double *energy)
{
    NEED_WORLD(w);
    NEED_OUT(w, energy, "ws_law_energy_state");
    ws_status s;
    const ws_law *L = find(w, id, &s);
    if (!L)
        return s;
    if ((s = check_point(w, L, state, u, NULL, t, 0.0, "ws_law_energy_state")) != WS_OK)
        return s;
    return energy_of(w, L, state, u, t, energy, "ws_law_energy_state");
}

void ws_world_free_laws(ws_world *w)
{
    /* Every law goes, so none needs its users counted down (the laws a sum refers to may be
     * freed before it). */
    for (size_t i = 0; i < w->law_cap && i < w->law_slots.slot_count; i++)
        if (w->law_slots.dense[i] != UINT32_MAX && w->laws[i])
            free_law(w, (uint32_t)i, 0);
    ws_mem_free(&w->mem, w->laws, w->law_cap * sizeof *w->laws);
    ws_slots_destroy(&w->mem, &w->law_slots);
}
