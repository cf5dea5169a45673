/* Contact forces: penalty normal force on the layer overlap (never pulling) and Coulomb friction,
 * regularised (eq. 13) or with a stick anchor. Forces and their moments act on both bodies. The
 * laws are those of every contact (penalty.h), here for one contact at a time. */
#include "contact/contact.h"
#include "contact/penalty.h"

static v3 point_velocity(const ws_body_store *b, int cur, uint32_t i, v3 xg)
{
    const ws_body_state *st = &b->st[cur];
    return v3_add(st->v[i], v3_cross(b->wg[i], v3_sub(xg, st->r[i])));
}

static void apply(ws_body_store *b, int cur, uint32_t i, v3 xg, v3 F)
{
    b->f[i] = v3_add(b->f[i], F);
    b->m[i] = v3_add(b->m[i], v3_cross(v3_sub(xg, b->st[cur].r[i]), F));
}

int ws_contact_eval(ws_contact_ctx *x, ws_cand *c, ws_contact_rec *rec)
{
    v3 xg, n;
    double d, share;
    if (!ws_contact_geometry(x, c, &xg, &n, &d, &share)) {
        c->anchored = 0;
        return 0;
    }
    ws_body_store *b = x->b;
    uint32_t ia = c->a, ib = c->b;
    const ws_pair_params *pp = ws_contact_params(x, ia, ib);
    double overlap = b->layer[ia] + b->layer[ib] - d;
    v3 vrel = v3_sub(point_velocity(b, x->cur, ib, xg), point_velocity(b, x->cur, ia, xg));
    /* Spring on the overlap and damper on its rate; a contact never pulls. A contact with a
     * share below 1 (a nearly parallel flat edge pair, WS_EDGE_PARALLEL_SIN) has that share of
     * every stiffness and damping of its laws, normal and tangential, and so of its force. */
    const double k = share * pp->k, kt = share * pp->kt;
    const ws_normal law = ws_normal_law(n, vrel, overlap, k, share * pp->c);
    const double fn = law.fp;
    const v3 vt = law.t;
    v3 ft = v3_make(0, 0, 0);
    int slipping = 0, at_cap = 0;
    double energy_t = 0.0;
    v3 defl = v3_make(0, 0, 0);
    if (pp->model == WS_FRICTION_REGULARIZED) {
        /* eq. 13 itself, without the film's limit on the force (m = +inf) */
        const ws_friction fr = ws_friction_law(vt, pp->mu * fn, pp->vlim, INFINITY, 1.0);
        ft = fr.f;
        slipping = at_cap = !(fr.s < 1.0);
        c->anchored = 0;
    } else {
        const ws_body_state *st = &b->st[x->cur];
        if (!c->anchored) {
            c->anchor_a = m3_tmul_v(&b->A[ia], v3_sub(xg, st->r[ia]));
            c->anchor_b = m3_tmul_v(&b->A[ib], v3_sub(xg, st->r[ib]));
            c->anchored = 1;
        }
        v3 xa = v3_add(st->r[ia], m3_mul_v(&b->A[ia], c->anchor_a));
        v3 xb = v3_add(st->r[ib], m3_mul_v(&b->A[ib], c->anchor_b));
        v3 dd = v3_sub(xb, xa);
        v3 dt = v3_madd(dd, n, -v3_dot(dd, n));
        double m_eff = 1.0 / (b->inv_mass[ia] + b->inv_mass[ib]);
        ft = v3_add(v3_scale(dt, -kt), v3_scale(vt, -share * ws_stick_damping(pp, m_eff)));
        double cap = pp->mu * fn, fts = v3_norm(ft);
        if (fts > cap) {
            ft = fts > 0.0 ? v3_scale(ft, cap / fts) : ft;
            /* The anchor slides so the spring alone carries the capped force. */
            v3 dt_new = v3_scale(ft, -1.0 / kt);
            v3 xa_new = v3_sub(xb, dt_new);
            c->anchor_a = m3_tmul_v(&b->A[ia], v3_sub(xa_new, st->r[ia]));
            at_cap = 1;
            /* Sliding, not a step held at the cap: the anchor moves with the slip, at v_lim or
             * faster (the regularised law's threshold). */
            slipping = v3_norm(vt) >= pp->vlim;
            dt = dt_new;
        }
        defl = dt;
        energy_t = 0.5 * kt * v3_norm2(dt);
    }
    v3 F = v3_add(v3_scale(n, fn), ft);
    apply(b, x->cur, ib, xg, F);
    apply(b, x->cur, ia, xg, v3_neg(F));
    rec->a = ia;
    rec->b = ib;
    rec->kind = c->kind;
    rec->slipping = (uint32_t)slipping;
    rec->at_cap = (uint32_t)at_cap;
    rec->defl = defl;
    rec->x = xg;
    rec->n = n;
    rec->ft = ft;
    rec->vt = vt;
    rec->overlap = overlap;
    rec->fn = fn;
    rec->energy = 0.5 * k * overlap * overlap;
    rec->energy_t = energy_t;
    return 1;
}

