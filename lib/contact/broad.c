/* Broad phase: sweep and prune of the bodies' inflated boxes along x. The alive slots are put in
 * order of their boxes' low x by insertion sort (stable, so the order is the same whatever the
 * bodies did before); the order and the pairs are scratch of the step (the world's arena). */
#include "contact/contact.h"

#include <string.h>

int ws_broad_pairs(ws_arena *a, const ws_body_store *b, uint32_t **pairs, size_t *npairs)
{
    size_t n = 0, room = b->slots + 1; /* pairs the room holds: grown by doubling */
    uint32_t *o = ws_arena_alloc(a, (b->slots + 1) * sizeof *o);
    uint32_t *pr = ws_arena_alloc(a, 2 * room * sizeof *pr);
    if (!o || !pr)
        return -1;
    for (size_t i = 0; i < b->slots; i++)
        if (b->alive[i])
            o[n++] = (uint32_t)i;
    for (size_t i = 1; i < n; i++) {
        uint32_t k = o[i];
        double key = b->lo[k].x;
        size_t j = i;
        while (j > 0 && b->lo[o[j - 1]].x > key) {
            o[j] = o[j - 1];
            j--;
        }
        o[j] = k;
    }
    *npairs = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t p = o[i];
        for (size_t j = i + 1; j < n; j++) {
            uint32_t q = o[j];
            if (b->lo[q].x > b->hi[p].x)
                break;
            if (b->type[p] == WS_BODY_KINEMATIC && b->type[q] == WS_BODY_KINEMATIC)
                continue;
            if (b->lo[q].y > b->hi[p].y || b->hi[q].y < b->lo[p].y || b->lo[q].z > b->hi[p].z ||
                b->hi[q].z < b->lo[p].z)
                continue;
            if (*npairs == room) { /* the old room stays in the arena until its reset */
                uint32_t *more = room <= SIZE_MAX / 8 / sizeof *pr
                                     ? ws_arena_alloc(a, 4 * room * sizeof *pr)
                                     : NULL;
                if (!more)
                    return -1;
                memcpy(more, pr, 2 * room * sizeof *pr);
                pr = more;
                room *= 2;
            }
            /* Lower slot first, so candidate keys do not depend on the sweep order. */
            pr[2 * *npairs] = p < q ? p : q;
            pr[2 * *npairs + 1] = p < q ? q : p;
            (*npairs)++;
        }
    }
    *pairs = pr;
    return 0;
}
