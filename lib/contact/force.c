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

/* The stick law's friction of a contact at xg (normal n, tangential slip vt, normal force fn)
 * from the anchors of *c, for its share of the pair's laws: the force on b into *ft, the
 * spring's deflection after the update into *dt (anchor a slides with the slip when the force
 * is capped), and whether it was capped and is sliding. */
static void stick_friction(const ws_contact_ctx *x, ws_cand *c, const ws_pair_params *pp, v3 xg,
                           v3 n, v3 vt, double fn, double share, v3 *ft_out, v3 *dt_out,
                           int *at_cap, int *slipping)
{
    const ws_body_store *b = x->b;
    const ws_body_state *st = &b->st[x->cur];
    const uint32_t ia = c->a, ib = c->b;
    const double kt = share * pp->kt;
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
    v3 ft = v3_add(v3_scale(dt, -kt), v3_scale(vt, -share * ws_stick_damping(pp, m_eff)));
    double cap = pp->mu * fn, fts = v3_norm(ft);
    *at_cap = *slipping = 0;
    if (fts > cap) {
        ft = fts > 0.0 ? v3_scale(ft, cap / fts) : ft;
        /* The anchor slides so the spring alone carries the capped force. */
        v3 dt_new = v3_scale(ft, -1.0 / kt);
        v3 xa_new = v3_sub(xb, dt_new);
        c->anchor_a = m3_tmul_v(&b->A[ia], v3_sub(xa_new, st->r[ia]));
        *at_cap = 1;
        /* Sliding, not a step held at the cap: the anchor moves with the slip, at v_lim or
         * faster (the regularised law's threshold). */
        *slipping = v3_norm(vt) >= pp->vlim;
        dt = dt_new;
    }
    *ft_out = ft;
    *dt_out = dt;
}

int ws_contact_eval(ws_contact_ctx *x, ws_cand *c, ws_contact_rec *rec)
{
    if (!ws_contact_measure(x, c, rec))
        return 0;
    ws_contact_apply(x, rec);
    return 1;
}

void ws_contact_apply(const ws_contact_ctx *x, const ws_contact_rec *rec)
{
    const v3 F = v3_add(v3_scale(rec->n, rec->fn), rec->ft);
    apply(x->b, x->cur, rec->b, rec->x, F);
    apply(x->b, x->cur, rec->a, rec->x, v3_neg(F));
}

int ws_contact_measure(ws_contact_ctx *x, ws_cand *c, ws_contact_rec *rec)
{
    v3 xg, n;
    double d, share;
    /* Most of a load's candidates are neighbours' features a gap apart, sideways: while they
     * have not moved that far they stay apart, unmeasured (WS_CLEAR_PAD). */
    if (ws_contact_apart(x, c))
        return 0;
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
     * share below 1 (a nearly parallel flat edge pair, WS_EDGE_PARALLEL_SIN; a twin corner,
     * WS_TWIN_REACH) has that share of every stiffness and damping of its laws, normal and
     * tangential, and so of its force. */
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
        stick_friction(x, c, pp, xg, n, vt, fn, share, &ft, &defl, &at_cap, &slipping);
        energy_t = 0.5 * kt * v3_norm2(defl);
    }
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

/* The contact of c[k] (fresh this step, its record rec) takes over the stick anchor of ended
 * contact e: the deflection e's anchors have now, its part along e's normal (ne) taken out,
 * scaled from e's share of the laws (se) to c's, with the sign of c's body order, and projected
 * on c's tangent plane; then c's friction again from that anchor, the difference from the
 * fresh anchor's applied to both bodies. */
static void inherit(ws_contact_ctx *x, ws_cand *c, const ws_cand *e, v3 ne, double se,
                    ws_contact_rec *rec)
{
    ws_body_store *b = x->b;
    const ws_body_state *st = &b->st[x->cur];
    v3 xg, n;
    double d, share;
    if (!ws_contact_geometry(x, c, &xg, &n, &d, &share))
        return; /* it evaluated in contact at this state: not reached */
    const uint32_t ia = c->a, ib = c->b;
    v3 xa = v3_add(st->r[e->a], m3_mul_v(&b->A[e->a], e->anchor_a));
    v3 xb = v3_add(st->r[e->b], m3_mul_v(&b->A[e->b], e->anchor_b));
    v3 dd = v3_sub(xb, xa);
    dd = v3_madd(dd, ne, -v3_dot(dd, ne));
    dd = v3_scale(dd, (e->a == ia ? se : -se) / share);
    v3 dt = v3_madd(dd, n, -v3_dot(dd, n));
    /* Anchors at the contact point on b and the deflection back from it on a. */
    c->anchor_b = m3_tmul_v(&b->A[ib], v3_sub(xg, st->r[ib]));
    c->anchor_a = m3_tmul_v(&b->A[ia], v3_sub(v3_sub(xg, dt), st->r[ia]));
    c->anchored = 1;
    const ws_pair_params *pp = ws_contact_params(x, ia, ib);
    v3 ft, defl;
    int at_cap, slipping;
    stick_friction(x, c, pp, xg, n, rec->vt, rec->fn, share, &ft, &defl, &at_cap, &slipping);
    const v3 dF = v3_sub(ft, rec->ft);
    apply(b, x->cur, ib, xg, dF);
    apply(b, x->cur, ia, xg, v3_neg(dF));
    rec->ft = ft;
    rec->defl = defl;
    rec->at_cap = (uint32_t)at_cap;
    rec->slipping = (uint32_t)slipping;
    rec->energy_t = 0.5 * share * pp->kt * v3_norm2(defl);
}

void ws_contact_handover(ws_contact_ctx *x, ws_cand *c, size_t n, ws_contact_rec *rec)
{
    for (size_t k = 0; k < n; k++) {
        if (!c[k].fresh)
            continue;
        ws_contact_rec *r = &rec[c[k].fresh - 1];
        /* The ended contacts between the same two bodies, in either order: two runs of the
         * sorted list. The nearest within reach, the first of equals. */
        size_t best = n;
        double best_d = WS_ANCHOR_REACH, best_share = 0.0;
        v3 best_n = v3_make(0, 0, 0);
        for (int o = 0; o < 2; o++) {
            const uint32_t a = o ? c[k].b : c[k].a, bb = o ? c[k].a : c[k].b;
            for (size_t e = ws_contact_pair_start(c, n, a, bb);
                 e < n && c[e].a == a && c[e].b == bb; e++) {
                v3 xe, ne;
                double se;
                if (c[e].ended != 1 || !ws_contact_place(x, &c[e], &xe, &ne, &se))
                    continue;
                const double de = v3_norm(v3_sub(xe, r->x));
                if (de <= best_d && (best == n || de < best_d || e < best)) {
                    best = e;
                    best_d = de;
                    best_n = ne;
                    best_share = se;
                }
            }
        }
        if (best == n)
            continue;
        c[best].ended = 2; /* given: one inheritor per ended contact */
        inherit(x, &c[k], &c[best], best_n, best_share, r);
    }
}
