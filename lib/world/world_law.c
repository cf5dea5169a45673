/* Public calls on constitutive laws: validation, id lookup, evaluation. */
#include "world/world_internal.h"

#include <stdio.h>
#include <string.h>

void ws_law_def_init(ws_law_def *def)
{
    if (!ws_def_reset(def, sizeof *def))
        return;
    def->type = WS_LAW_LINEAR_ELASTIC;
    def->transition = 1e-3;
}

ws_status ws_lookup_law(const ws_world *w, ws_law_id id, uint32_t *slot)
{
    return ws_lookup_slot(w, id.bits, WS_KIND_LAW, &w->law_slots, "law", slot);
}

int ws_law_is_valid(const ws_world *w, ws_law_id id)
{
    if (!w)
        return 0;
    uint32_t s = ws_id_slot(id.bits);
    return id.bits != 0 && ws_id_tag(id.bits) == w->tag && ws_id_kind(id.bits) == WS_KIND_LAW &&
           s < w->law_slots.slot_count && w->law_slots.dense[s] != UINT32_MAX &&
           w->law_slots.generation[s] == ws_id_gen(id.bits);
}

ws_status ws_law_create(ws_world *w, const ws_law_def *def, ws_law_id *out)
{
    NEED_WORLD(w);
    NEED_OUT(w, out, "ws_law_create");
    out->bits = 0;
    ws_law_def d;
    ws_law_def_init(&d);
    ws_status s = ws_def_take(w, &d, sizeof d, def, sizeof d, "law");
    if (s != WS_OK)
        return s;
    char why[256];
    ws_law1d L;
    if ((s = ws_law1d_setup(&L, &d, why, sizeof why)) != WS_OK)
        return ws_fail(w, s, "%s", why);
    ws_law1d *p = ws_mem_alloc(&w->mem, sizeof *p);
    if (p) {
        *p = L;
        p->name = NULL;
    }
    if (!p || (d.name && !(p->name = ws_mem_strdup(&w->mem, d.name)))) {
        ws_mem_free(&w->mem, p, p ? sizeof *p : 0);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_law_create: out of memory");
    }
    uint32_t slot;
    if (ws_world_take_slot(w, &w->law_slots, (void ***)&w->laws, &w->law_cap, &slot) != 0) {
        ws_mem_free_str(&w->mem, p->name);
        ws_mem_free(&w->mem, p, sizeof *p);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_law_create: out of memory");
    }
    w->laws[slot] = p;
    out->bits = ws_id_pack(w->tag, WS_KIND_LAW, w->law_slots.generation[slot], slot);
    return WS_OK;
}

static void free_law(ws_world *w, uint32_t slot)
{
    ws_mem_free_str(&w->mem, w->laws[slot]->name);
    ws_mem_free(&w->mem, w->laws[slot], sizeof *w->laws[slot]);
    w->laws[slot] = NULL;
}

ws_status ws_law_destroy(ws_world *w, ws_law_id id)
{
    NEED_WORLD(w);
    uint32_t slot;
    ws_status s = ws_lookup_law(w, id, &slot);
    if (s != WS_OK)
        return s;
    if (w->laws[slot]->users)
        return ws_fail(w, WS_ERR_IN_USE, "ws_law_destroy: %u webs still use this law",
                       w->laws[slot]->users);
    free_law(w, slot);
    ws_slots_release(&w->law_slots, slot);
    return WS_OK;
}

ws_status ws_law_evaluate(const ws_world *w, ws_law_id id, double eps, double epsd, double *F,
                          double *dF, double *dFd)
{
    NEED_WORLD(w);
    uint32_t slot;
    ws_status s = ws_lookup_law(w, id, &slot);
    if (s != WS_OK)
        return s;
    if (!isfinite(eps) || !isfinite(epsd))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_law_evaluate: strain and rate must be finite");
    double f = ws_law1d_eval(w->laws[slot], eps, epsd, dF, dFd);
    if (F)
        *F = f;
    return WS_OK;
}

ws_status ws_law_energy(const ws_world *w, ws_law_id id, double eps, double *energy)
{
    NEED_WORLD(w);
    NEED_OUT(w, energy, "ws_law_energy");
    uint32_t slot;
    ws_status s = ws_lookup_law(w, id, &slot);
    if (s != WS_OK)
        return s;
    if (!isfinite(eps))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_law_energy: strain must be finite");
    *energy = ws_law1d_energy(w->laws[slot], eps);
    return WS_OK;
}

void ws_world_free_laws(ws_world *w)
{
    for (size_t i = 0; i < w->law_cap && i < w->law_slots.slot_count; i++)
        if (w->law_slots.dense[i] != UINT32_MAX && w->laws[i])
            free_law(w, (uint32_t)i);
    ws_mem_free(&w->mem, w->laws, w->law_cap * sizeof *w->laws);
    ws_slots_destroy(&w->mem, &w->law_slots);
}
