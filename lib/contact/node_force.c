/* Web nodes against body faces, evaluated: normal forces and friction on the nodes, their
 * opposite on the bodies (eq. 13, 14). The candidates come from node.c. */
#include "contact/contact.h"
#include "contact/node.h"

/* Eq. 14 in the global frame for a prepared face: 1 and the signed distance when the point
 * projects into the face and lies within (lo, hi) of its plane. */
static inline int in_wface(const ws_node_geom *g, const ws_wface *F, v3 x, double lo, double hi,
                           double *dist)
{
    double d = v3_dot(F->n, x) - F->off;
    if (!(d > lo && d < hi))
        return 0;
    for (uint32_t t = F->first_tri; t < F->first_tri + F->tri_count; t++) {
        const ws_wtri *q = &g->tri[t];
        v3 r = v3_sub(x, q->p);
        if (ws_bary_inside(v3_dot(r, q->w), v3_dot(r, q->v), q->g00, q->g01, q->g11)) {
            *dist = d;
            return 1;
        }
    }
    return 0;
}

/* A node against the rounded rim of a convex edge: only in the edge's own region, where the
 * direction from the edge to the node lies strictly between the normals of its two faces
 * (elsewhere a face holds the node), and closer than `hi`. Gives the unit normal from the edge
 * to the node and the distance. */
static inline int in_wedge(const ws_wedge *E, v3 x, double hi, v3 *nrm, double *dist)
{
    v3 rp = v3_sub(x, E->p);
    double t = v3_dot(rp, E->e) * E->inv_e2;
    if (!(t > 0.0 && t < 1.0))
        return 0;
    v3 r = v3_madd(rp, E->e, -t);
    double l2 = v3_dot(r, r);
    if (!(l2 < hi * hi) || !(l2 > 0.0))
        return 0;
    /* Outside both faces' planes: in the wedge between them. */
    if (!(v3_dot(r, E->n1) > 0.0 && v3_dot(r, E->n2) > 0.0))
        return 0;
    /* And not over either face: r = a n1 + b n2 with a, b > 0. */
    double c = v3_dot(E->n1, E->n2), r1 = v3_dot(r, E->n1), r2 = v3_dot(r, E->n2);
    double den = 1.0 - c * c;
    if (den < 1e-12 || !(r1 - c * r2 > 0.0 && r2 - c * r1 > 0.0))
        return 0;
    double l = sqrt(l2);
    *nrm = v3_scale(r, 1.0 / l);
    *dist = l;
    return 1;
}

/* Whether face f is the shallowest of a convex body for a point at distance d under it: no
 * other face's plane has the point farther out (the prepared faces, global). */
static int convex_shallowest(const ws_node_geom *g, uint32_t base, uint32_t count, uint32_t f,
                             v3 x, double d)
{
    for (uint32_t q = 0; q < count; q++)
        if (q != f && v3_dot(g->face[base + q].n, x) - g->face[base + q].off > d)
            return 0;
    return 1;
}

void ws_node_contacts(ws_body_store *b, int cur, const ws_node_geom *g, ws_web *web, ws_nodes3 x,
                      ws_nodes3 v, const ws_ncand *cand, size_t n, const ws_node_params *pp,
                      double h, double share, v3 *fc, v3 *bforce, v3 *bmoment, uint64_t *checks)
{
    const ws_body_state *st = &b->st[cur];
    ws_nact *act = web->act; /* room for n: reserved with the candidates */
    uint32_t *sel = web->sel;
    *checks += n;
    /* Most face candidates lie flat beside their face, at about the layers' distance, pressing
     * it now and then: which ones do is a coin toss from step to step. So the plane distance
     * sorts them first without a branch (the ones within the window are listed), and the rest
     * of the work runs on that shorter list. Edges go to the list as they are. */
    const double wl = web->layer;
    size_t m = 0;
    for (size_t k = 0; k < n; k++) {
        const ws_ncand *c = &cand[k];
        const ws_wface *F = &g->face[c->local & WS_NCAND_EDGE ? 0 : c->feat];
        uint32_t i = c->node;
        double d = F->n.x * x.x[i] + F->n.y * x.y[i] + F->n.z * x.z[i] - F->off;
        sel[m] = (uint32_t)k;
        m += (size_t)((d < b->layer[c->body] + wl) | ((c->local & WS_NCAND_EDGE) != 0));
    }
    /* Normal forces, in node order. */
    size_t na = 0;
    for (size_t q = 0; q < m; q++) {
        const ws_ncand *c = &cand[sel[q]];
        uint32_t i = c->node, bi = c->body;
        v3 xi = nodes_get(x, i), nrm;
        double d;
        /* The contact window of the pair: the two layers outside, the body's inner depth in. */
        double hi = b->layer[bi] + wl;
        if (c->local & WS_NCAND_EDGE) {
            if (!in_wedge(&g->edge[c->feat], xi, hi, &nrm, &d))
                continue;
        } else {
            const ws_wface *F = &g->face[c->feat];
            d = v3_dot(F->n, xi) - F->off;
            const ws_shape *sh = b->shape[bi];
            double lo = -hi - sh->inner;
            if (!(d > lo))
                continue;
            /* A node found well inside the face's outline stays over the face while the
             * candidates are valid: no need to find its triangle. */
            if (!(c->local & WS_NCAND_INSIDE) && !in_wface(g, F, xi, lo, hi, &d))
                continue;
            uint32_t f = c->local & ~WS_NCAND_FLAGS;
            if (d < 0.0 &&
                !(sh->convex ? convex_shallowest(g, c->feat - f, sh->face_count, f, xi, d)
                             : ws_shallowest_face(sh, f,
                                                  m3_tmul_v(&b->A[bi], v3_sub(xi, st->r[bi])),
                                                  d)))
                continue;
            nrm = F->n; /* from the body to the node */
        }
        const ws_node_params *p = &pp[b->material[bi]];
        v3 r = st->r[bi];
        v3 xc = v3_madd(xi, nrm, -0.5 * d);
        v3 vb = v3_add(st->v[bi], v3_cross(b->wg[bi], v3_sub(xc, r)));
        v3 vrel = v3_sub(nodes_get(v, i), vb);
        double vn = v3_dot(vrel, nrm);
        double fn = p->k * (hi - d) - p->c * vn;
        /* A contact never pulls: listed only when it pushes (no branch), and its force is
         * added times that (0 or 1). */
        double push = fn > 0.0;
        nodes_add(web->f, i, v3_scale(nrm, fn * push));
        act[na] = (ws_nact){i, bi, nrm, xc, v3_madd(vrel, nrm, -vn), v3_make(0, 0, 0), fn,
                            p->mu, p->vlim};
        na += (size_t)push;
    }
    /* Node by node, once every normal force of the node is in: its frictions, then all of them
     * applied. A node at a corner touches two faces; doing every normal force before any
     * friction makes the result independent of the order of the faces (which differs from
     * corner to corner and would twist a symmetric load).
     *
     * Friction: eq. 13, limited to the force that stops the node's slip within this sub-step.
     * Below v_lim eq. 13 is a damper of slope 2 mu N / v_lim, far too stiff for an explicit
     * step of a light node (it would reverse the slip and chatter), so the slip is predicted at
     * the end of the sub-step with the other forces on the node (springs, gravity and every
     * normal force, none of the frictions: again order-free), and the friction is the smaller of
     * what stops that slip (m |v_pred| / h) and what eq. 13 gives for it, against it. Sticking
     * nodes hold their tangential load; sliding ones get mu N; for heavy masses this is eq. 13
     * itself. */
    size_t k = 0;
    while (k < na) {
        const uint32_t i = act[k].node;
        size_t e = k + 1;
        while (e < na && act[e].node == i)
            e++;
        if (web->inv_m[i] != 0.0) {
            const v3 f0 = nodes_get(web->f, i);
            for (size_t q = k; q < e; q++) {
                ws_nact *a = &act[q];
                v3 fo = v3_madd(f0, a->n, -v3_dot(f0, a->n)); /* tangential, other forces */
                v3 vp = v3_madd(a->vt, fo, h * web->inv_m[i]);
                double vps = v3_norm(vp);
                double sr = vps / a->vlim;
                double law = a->mu * a->fn * (sr < 1.0 ? sr * (2.0 - sr) : 1.0);
                double stop = web->m[i] * vps / h;
                /* vps = 0: no slip, no friction (the division is not taken). */
                a->ft = vps > 0.0 ? v3_scale(vp, -(law < stop ? law : stop) / vps) : a->ft;
            }
        }
        /* Apply; the bodies get the opposite, averaged over the sub-steps (into the web's
         * per-body totals, which the step adds to the bodies once). */
        for (size_t q = k; q < e; q++) {
            const ws_nact *a = &act[q];
            uint32_t bi = a->body;
            nodes_add(web->f, i, a->ft);
            v3 Fnode = v3_madd(a->ft, a->n, a->fn);
            fc[i] = v3_madd(fc[i], Fnode, share);
            v3 Fb = v3_scale(Fnode, -share);
            bforce[bi] = v3_add(bforce[bi], Fb);
            bmoment[bi] = v3_add(bmoment[bi], v3_cross(v3_sub(a->xc, st->r[bi]), Fb));
        }
        k = e;
    }
}
