#include "body/body.h"

#include <string.h>

#define BODY_ARRAYS(X)                                                                            \
    X(alive) X(type) X(shape) X(material) X(layer) X(mass) X(inv_mass) X(J) X(Jinv) X(Q) X(Ip) X(A) X(wg)  \
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
    for (size_t i = 0; i < b->slots; i++) {
        if (b->name && b->name[i])
            ws_mem_free_str(mem, b->name[i]);
        if (b->has_drive && b->has_drive[i] && b->alive[i])
            ws_drive_release(&b->drive[i], mem);
    }
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

/* Exact rotation of the free rotor about principal axis k for a time tau: the body turns by
 * phi = L_k / I_k tau about that axis, and the principal components of the angular momentum turn
 * the other way, so the global momentum A Q Lp does not change. */
static void rotor_axis(qt *p, v3 *Lp, const m3 *Q, v3 I, int k, double tau)
{
    double *L = &Lp->x;
    double phi = L[k] / (&I.x)[k] * tau;
    v3 axis = v3_make(Q->m[k], Q->m[3 + k], Q->m[6 + k]); /* column k */
    *p = qt_mul(*p, qt_from_axis_angle(axis, phi));
    int i = (k + 1) % 3, j = (k + 2) % 3;
    double c = cos(phi), sn = sin(phi);
    double li = L[i], lj = L[j];
    L[i] = c * li + sn * lj;
    L[j] = -sn * li + c * lj;
}

/* Symplectic Euler: the forces at t kick the momenta, then the positions drift with the new
 * momenta. The rotational drift is the free rigid rotor, split symmetrically into exact rotations
 * about the principal axes, R1(dt/2) R2(dt/2) R3(dt) R2(dt/2) R1(dt/2): symplectic and
 * time-reversible, it keeps the global angular momentum to round-off and the energy error bounded
 * (no drift) when no moment acts. */
void ws_body_integrate_symplectic(ws_body_store *b, size_t i, int cur, int nxt, double dt)
{
    const ws_body_state *c = &b->st[cur];
    ws_body_state *n = &b->st[nxt];
    v3 v = v3_madd(c->v[i], b->f[i], dt * b->inv_mass[i]);
    n->v[i] = v;
    n->r[i] = v3_madd(c->r[i], v, dt);

    const m3 *A = &b->A[i], *Q = &b->Q[i];
    v3 H = m3_mul_v(A, m3_mul_v(&b->J[i], c->w[i])); /* global angular momentum */
    H = v3_madd(H, b->m[i], dt);                    /* kick */
    v3 Lp = m3_tmul_v(Q, m3_tmul_v(A, H));          /* principal components */
    qt p = c->p[i];
    v3 I = b->Ip[i];
    rotor_axis(&p, &Lp, Q, I, 0, 0.5 * dt);
    rotor_axis(&p, &Lp, Q, I, 1, 0.5 * dt);
    rotor_axis(&p, &Lp, Q, I, 2, dt);
    rotor_axis(&p, &Lp, Q, I, 1, 0.5 * dt);
    rotor_axis(&p, &Lp, Q, I, 0, 0.5 * dt);
    n->p[i] = qt_normalize(p);
    n->w[i] = m3_mul_v(&b->Jinv[i], m3_mul_v(Q, Lp));
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
