/* Broad phase: sweep and prune of the bodies' inflated boxes along x. The sweep order is kept
 * between calls and repaired by insertion sort, which is linear when little has moved. */
#include "contact/contact.h"

int ws_broad_pairs(ws_mem *mem, const ws_body_store *b, uint32_t **order, size_t *order_cap,
                   uint32_t **pairs, size_t *npairs, size_t *pairs_cap)
{
    size_t n = 0;
    if (ws_array_reserve(mem, (void **)order, order_cap, b->slots + 1, sizeof **order) != 0)
        return -1;
    uint32_t *o = *order;
    /* Rebuild the list of alive slots, keeping the previous relative order where possible is not
     * needed for correctness; insertion sort below makes it ordered. */
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
            if (ws_array_reserve(mem, (void **)pairs, pairs_cap, 2 * (*npairs + 1),
                                 sizeof **pairs) != 0)
                return -1;
            /* Lower slot first, so candidate keys do not depend on the sweep order. */
            (*pairs)[2 * *npairs] = p < q ? p : q;
            (*pairs)[2 * *npairs + 1] = p < q ? q : p;
            (*npairs)++;
        }
    }
    return 0;
}
