#include "body/body.h"

#include <string.h>

#define BODY_ARRAYS(X)                                                                            \
    X(alive) X(type) X(shape) X(material) X(layer) X(mass) X(inv_mass) X(J) X(Jinv) X(A) X(wg)  \
    X(f) X(m) X(lo) X(hi) X(has_drive) X(drive) X(name) X(user)

/* Every pool array of the store with its element size, in one list. */
static int list_arrays(ws_body_store *b, void ***arrs, size_t *elems)
{
    int k = 0;
#define X(name) arrs[k] = (void **)&b->name; elems[k] = sizeof *b->name; k++;
    BODY_ARRAYS(X)
#undef X
    for (int s = 0; s < 2; s++) {
        arrs[k] = (void **)&b->st[s].r; elems[k++] = sizeof(v3);
        arrs[k] = (void **)&b->st[s].p; elems[k++] = sizeof(qt);
        arrs[k] = (void **)&b->st[s].v; elems[k++] = sizeof(v3);
        arrs[k] = (void **)&b->st[s].w; elems[k++] = sizeof(v3);
    }
    return k;
}

/* All arrays are allocated anew first and swapped in only when every one succeeded, so running
 * out of memory changes nothing. */
int ws_bodies_reserve(ws_mem *mem, ws_body_store *b, size_t n)
{
    if (n <= b->capacity)
        return 0;
    size_t cap = b->capacity ? b->capacity : 4;
    while (cap < n)
        cap *= 2;
    void **arrs[32];
    size_t elems[32];
    void *fresh[32];
    int k = list_arrays(b, arrs, elems);
    for (int i = 0; i < k; i++) {
        fresh[i] = ws_mem_calloc(mem, cap, elems[i]);
        if (!fresh[i]) {
            for (int j = 0; j < i; j++)
                ws_mem_free(mem, fresh[j], cap * elems[j]);
            return -1;
        }
    }
    for (int i = 0; i < k; i++) {
        if (*arrs[i])
            memcpy(fresh[i], *arrs[i], b->capacity * elems[i]);
        ws_mem_free(mem, *arrs[i], b->capacity * elems[i]);
        *arrs[i] = fresh[i];
    }
    b->capacity = cap;
    return 0;
}

void ws_bodies_free(ws_mem *mem, ws_body_store *b)
{
    for (size_t i = 0; i < b->slots; i++)
        if (b->name && b->name[i])
            ws_mem_free_str(mem, b->name[i]);
    void **arrs[32];
    size_t elems[32];
    int k = list_arrays(b, arrs, elems);
    for (int i = 0; i < k; i++)
        ws_mem_free(mem, *arrs[i], b->capacity * elems[i]);
    memset(b, 0, sizeof *b);
}

m3 ws_body_inertia_from_shape(const ws_shape *s, double mass)
{
    m3 j;
    double k = mass / s->volume;
    for (int i = 0; i < 9; i++)
        j.m[i] = s->inertia_unit.m[i] * k;
    return j;
}

/* Symplectic Euler: velocities first, positions with the new velocities. The rotation goes
 * through the angular momentum in the global frame, H = A J omega': without a moment H is kept
 * to round-off, and the orientation advances by the exact exponential of omega dt. */
void ws_body_integrate_symplectic(ws_body_store *b, size_t i, int cur, int nxt, double dt)
{
    const ws_body_state *c = &b->st[cur];
    ws_body_state *n = &b->st[nxt];
    v3 v = v3_madd(c->v[i], b->f[i], dt * b->inv_mass[i]);
    n->v[i] = v;
    n->r[i] = v3_madd(c->r[i], v, dt);

    const m3 *A = &b->A[i];
    v3 H = m3_mul_v(A, m3_mul_v(&b->J[i], c->w[i]));
    H = v3_madd(H, b->m[i], dt);
    /* omega' at the old orientation with the new momentum, then rotate in the body frame. */
    v3 w_local = m3_mul_v(&b->Jinv[i], m3_tmul_v(A, H));
    qt p = qt_normalize(qt_mul(c->p[i], qt_from_rotvec(v3_scale(w_local, dt))));
    n->p[i] = p;
    m3 An = qt_to_m3(p);
    n->w[i] = m3_mul_v(&b->Jinv[i], m3_tmul_v(&An, H));
}

/* The paper's explicit scheme (eq. 8-11). */
void ws_body_integrate_paper(ws_body_store *b, size_t i, int cur, int nxt, double dt)
{
    const ws_body_state *c = &b->st[cur];
    ws_body_state *n = &b->st[nxt];
    v3 a = v3_scale(b->f[i], b->inv_mass[i]);
    n->r[i] = v3_madd(v3_madd(c->r[i], c->v[i], dt), a, 0.5 * dt * dt); /* eq. 9 */
    n->v[i] = v3_madd(c->v[i], a, dt);                                /* eq. 8 */
    v3 w = c->w[i];
    v3 M = m3_tmul_v(&b->A[i], b->m[i]); /* moment in the body frame */
    v3 Jw = m3_mul_v(&b->J[i], w);
    v3 wdot = m3_mul_v(&b->Jinv[i], v3_sub(M, v3_cross(w, Jw))); /* eq. 10 */
    n->w[i] = v3_madd(w, wdot, dt);
    qt pd = qt_rate_local(c->p[i], w); /* eq. 11-12 */
    qt p = c->p[i];
    p.e0 += dt * pd.e0;
    p.e1 += dt * pd.e1;
    p.e2 += dt * pd.e2;
    p.e3 += dt * pd.e3;
    n->p[i] = qt_normalize(p);
}
