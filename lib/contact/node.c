/* Web nodes against body faces: point-to-face only (eq. 14), one contact per node and face,
 * penalty normal force and friction, forces and moments on the body. */
#include "contact/contact.h"
#include "contact/node.h"

static int inside_box(v3 p, v3 lo, v3 hi, double e)
{
    return p.x > lo.x - e && p.x < hi.x + e && p.y > lo.y - e && p.y < hi.y + e &&
           p.z > lo.z - e && p.z < hi.z + e;
}

int ws_node_candidates(ws_mem *mem, const ws_body_store *b, int cur, const ws_node_geom *g,
                       ws_web *web, const v3 *x, double margin, ws_ncand **out, size_t *n,
                       size_t *cap, uint64_t *checks)
{
    *n = 0;
    if (web->n == 0)
        return 0;
    /* The web's box, to skip bodies far from it. */
    v3 lo = x[0], hi = x[0];
    for (uint32_t i = 1; i < web->n; i++) {
        lo = v3_min(lo, x[i]);
        hi = v3_max(hi, x[i]);
    }
    double pad = web->layer + 0.5 * margin;
    for (uint32_t k = 0; k < b->slots; k++) {
        if (!b->alive[k])
            continue;
        if (b->lo[k].x > hi.x + pad || b->hi[k].x < lo.x - pad || b->lo[k].y > hi.y + pad ||
            b->hi[k].y < lo.y - pad || b->lo[k].z > hi.z + pad || b->hi[k].z < lo.z - pad)
            continue;
        const ws_shape *sh = b->shape[k];
        const m3 *A = &b->A[k];
        v3 r = b->st[cur].r[k];
        double reach = b->layer[k] + web->layer + margin;
        double hi_k = b->layer[k] + web->layer, lo_k = -hi_k - sh->inner;
        for (uint32_t i = 0; i < web->n; i++) {
            v3 p = x[i];
            if (p.x < b->lo[k].x - pad || p.x > b->hi[k].x + pad || p.y < b->lo[k].y - pad ||
                p.y > b->hi[k].y + pad || p.z < b->lo[k].z - pad || p.z > b->hi[k].z + pad)
                continue;
            v3 s = m3_tmul_v(A, v3_sub(p, r));
            if (!inside_box(s, sh->lo, sh->hi, reach))
                continue;
            /* On a convex body a node touches face f only while f is the face whose plane it
             * is farthest out of (the largest signed distance D): over a face it projects into,
             * d_g <= d_f for every other face g, and inside the body the shallowest face is the
             * one of largest d. Until the next detection nodes and bodies move less than half
             * the margin each, which changes d_f - D by less than the margin: faces further
             * behind than that cannot come into contact and are not candidates. On a box this
             * drops the side faces next to the one a node lies on. */
            double D = -INFINITY;
            if (sh->convex)
                for (uint32_t f = 0; f < sh->face_count; f++)
                    D = fmax(D, v3_dot(sh->faces[f].normal, s) - sh->faces[f].offset);
            for (uint32_t f = 0; f < sh->face_count; f++) {
                const ws_face *fc = &sh->faces[f];
                (*checks)++;
                double d = v3_dot(fc->normal, s) - fc->offset;
                /* Depth counts along the normal only: the point's projection on the face's
                 * plane must lie within reach of the face. */
                if (d > -reach - sh->inner && d < reach && d >= D - margin &&
                    inside_box(v3_madd(s, fc->normal, -d), fc->lo, fc->hi, reach)) {
                    if (ws_array_reserve(mem, (void **)out, cap, *n + 1, sizeof **out) != 0)
                        return -1;
                    (*out)[(*n)++] = (ws_ncand){i, k, f, g->face_base[k] + f, 0, lo_k, hi_k};
                }
            }
            /* Convex edges within reach of the node: the rounded rim of the contact layer. */
            for (uint32_t e = 0; e < sh->edge_count; e++) {
                const ws_edge *E = &sh->edges[e];
                if (!inside_box(s, E->lo, E->hi, reach))
                    continue;
                (*checks)++;
                v3 a = sh->vertices[E->a], d = v3_sub(sh->vertices[E->b], a);
                double t = v3_dot(v3_sub(s, a), d) / v3_dot(d, d);
                if (t < 0.0 || t > 1.0)
                    continue;
                if (v3_norm2(v3_sub(s, v3_madd(a, d, t))) < reach * reach) {
                    if (ws_array_reserve(mem, (void **)out, cap, *n + 1, sizeof **out) != 0)
                        return -1;
                    (*out)[(*n)++] = (ws_ncand){i, k, e, g->edge_base[k] + e, 1, lo_k, hi_k};
                }
            }
        }
    }
    return 0;
}

int ws_node_geometry(ws_mem *mem, const ws_body_store *b, int cur, ws_node_geom *g)
{
    size_t nf = 0, nt = 0, ne = 0;
    for (size_t k = 0; k < b->slots; k++)
        if (b->alive[k]) {
            nf += b->shape[k]->face_count;
            nt += b->shape[k]->triangle_count;
            ne += b->shape[k]->edge_count;
        }
    if (ws_array_reserve(mem, (void **)&g->face, &g->face_cap, nf + 1, sizeof *g->face) != 0 ||
        ws_array_reserve(mem, (void **)&g->tri, &g->tri_cap, nt + 1, sizeof *g->tri) != 0 ||
        ws_array_reserve(mem, (void **)&g->edge, &g->edge_cap, ne + 1, sizeof *g->edge) != 0 ||
        ws_array_reserve(mem, (void **)&g->edge_base, &g->edge_base_cap, b->slots + 1,
                         sizeof(uint32_t)) != 0)
        return -1;
    if (ws_array_reserve(mem, (void **)&g->face_base, &g->face_base_cap, b->slots + 1,
                         sizeof(uint32_t)) != 0 ||
        ws_array_reserve(mem, (void **)&g->tri_base, &g->tri_base_cap, b->slots + 1,
                         sizeof(uint32_t)) != 0)
        return -1;
    uint32_t fo = 0, to = 0, eo = 0;
    for (size_t k = 0; k < b->slots; k++) {
        if (!b->alive[k])
            continue;
        const ws_shape *sh = b->shape[k];
        const m3 *A = &b->A[k];
        v3 r = b->st[cur].r[k];
        g->face_base[k] = fo;
        g->tri_base[k] = to;
        for (uint32_t f = 0; f < sh->face_count; f++) {
            const ws_face *F = &sh->faces[f];
            ws_wface *o = &g->face[fo + f];
            o->n = m3_mul_v(A, F->normal);
            o->off = F->offset + v3_dot(o->n, r); /* n . (r + A s) = n' . s + n . r */
            o->first_tri = to + F->first_tri;
            o->tri_count = F->tri_count;
        }
        for (uint32_t t = 0; t < sh->triangle_count; t++) {
            const ws_tri *T = &sh->tris[t];
            ws_wtri *o = &g->tri[to + t];
            o->p = v3_add(r, m3_mul_v(A, T->p));
            o->w = m3_mul_v(A, T->w);
            o->v = m3_mul_v(A, T->v);
            o->g00 = T->g00; /* the Gram matrix does not change under rotation */
            o->g01 = T->g01;
            o->g11 = T->g11;
        }
        g->edge_base[k] = eo;
        for (uint32_t e = 0; e < sh->edge_count; e++) {
            const ws_edge *E = &sh->edges[e];
            ws_wedge *o = &g->edge[eo + e];
            v3 a = sh->vertices[E->a], d = v3_sub(sh->vertices[E->b], a);
            o->p = v3_add(r, m3_mul_v(A, a));
            o->e = m3_mul_v(A, d);
            o->n1 = m3_mul_v(A, E->n1);
            o->n2 = m3_mul_v(A, E->n2);
            o->inv_e2 = 1.0 / v3_dot(d, d);
        }
        fo += sh->face_count;
        to += sh->triangle_count;
        eo += sh->edge_count;
    }
    return 0;
}

void ws_node_geometry_free(ws_mem *mem, ws_node_geom *g)
{
    ws_mem_free(mem, g->face, g->face_cap * sizeof *g->face);
    ws_mem_free(mem, g->tri, g->tri_cap * sizeof *g->tri);
    ws_mem_free(mem, g->face_base, g->face_base_cap * sizeof *g->face_base);
    ws_mem_free(mem, g->tri_base, g->tri_base_cap * sizeof *g->tri_base);
    ws_mem_free(mem, g->edge, g->edge_cap * sizeof *g->edge);
    ws_mem_free(mem, g->edge_base, g->edge_base_cap * sizeof *g->edge_base);
}

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

void ws_node_contacts(ws_body_store *b, int cur, const ws_node_geom *g, ws_web *web, const v3 *x,
                      const v3 *v, const ws_ncand *cand, size_t n, const ws_node_params *pp,
                      double h, double share, v3 *fc, v3 *bforce, v3 *bmoment, uint64_t *checks)
{
    const ws_body_state *st = &b->st[cur];
    ws_nact *act = web->act; /* room for n: reserved with the candidates */
    size_t na = 0;
    *checks += n;
    /* Pass 1: normal forces. A node at a corner touches two faces; doing every normal force
     * before any friction makes the result independent of the order of the faces (which
     * differs from corner to corner and would twist a symmetric load). */
    for (size_t k = 0; k < n; k++) {
        const ws_ncand *c = &cand[k];
        uint32_t i = c->node, bi = c->body;
        v3 nrm;
        double d;
        if (c->edge) {
            if (!in_wedge(&g->edge[c->wface], x[i], c->hi, &nrm, &d))
                continue;
        } else {
            /* Most candidates lie flat beside a face without pressing it: reject them on the
             * plane distance alone before anything else is loaded. */
            const ws_wface *F = &g->face[c->wface];
            d = v3_dot(F->n, x[i]) - F->off;
            if (!(d > c->lo && d < c->hi))
                continue;
            if (!in_wface(g, F, x[i], c->lo, c->hi, &d))
                continue;
            if (d < 0.0 && !ws_shallowest_face(b->shape[bi], c->face,
                                               m3_tmul_v(&b->A[bi], v3_sub(x[i], st->r[bi])), d))
                continue;
            nrm = F->n; /* from the body to the node */
        }
        const ws_node_params *p = &pp[b->material[bi]];
        v3 r = st->r[bi];
        v3 xc = v3_madd(x[i], nrm, -0.5 * d);
        v3 vb = v3_add(st->v[bi], v3_cross(b->wg[bi], v3_sub(xc, r)));
        v3 vrel = v3_sub(v[i], vb);
        double vn = v3_dot(vrel, nrm);
        double fn = p->k * (c->hi - d) - p->c * vn;
        if (!(fn > 0.0))
            continue; /* a contact never pulls */
        web->f[i] = v3_madd(web->f[i], nrm, fn);
        act[na++] = (ws_nact){i, bi, nrm, xc, v3_madd(vrel, nrm, -vn), v3_make(0, 0, 0), fn,
                              p->mu, p->vlim};
    }
    /* Pass 2: friction: eq. 13, limited to the force that stops the node's slip within this
     * sub-step. Below v_lim eq. 13 is a damper of slope 2 mu N / v_lim, far too stiff for an
     * explicit step of a light node (it would reverse the slip and chatter), so the slip is
     * predicted at the end of the sub-step with the other forces on the node (springs, gravity
     * and every normal force, none of the frictions: again order-free), and the friction is the
     * smaller of what stops that slip (m |v_pred| / h) and what eq. 13 gives for it, against it.
     * Sticking nodes hold their tangential load; sliding ones get mu N; for heavy masses this is
     * eq. 13 itself. */
    for (size_t k = 0; k < na; k++) {
        ws_nact *a = &act[k];
        uint32_t i = a->node;
        if (web->inv_m[i] == 0.0)
            continue;
        v3 fo = web->f[i];
        fo = v3_madd(fo, a->n, -v3_dot(fo, a->n)); /* tangential part of the other forces */
        v3 vp = v3_madd(a->vt, fo, h * web->inv_m[i]);
        double vps = v3_norm(vp);
        if (vps > 0.0) {
            double sr = vps / a->vlim;
            double law = a->mu * a->fn * (sr < 1.0 ? sr * (2.0 - sr) : 1.0);
            double stop = web->m[i] * vps / h;
            a->ft = v3_scale(vp, -(law < stop ? law : stop) / vps);
        }
    }
    /* Pass 3: apply; the bodies get the opposite, averaged over the sub-steps. */
    for (size_t k = 0; k < na; k++) {
        const ws_nact *a = &act[k];
        uint32_t i = a->node, bi = a->body;
        web->f[i] = v3_add(web->f[i], a->ft);
        v3 Fnode = v3_madd(a->ft, a->n, a->fn);
        fc[i] = v3_madd(fc[i], Fnode, share);
        v3 Fb = v3_scale(Fnode, -share);
        b->f[bi] = v3_add(b->f[bi], Fb);
        v3 mb = v3_cross(v3_sub(a->xc, st->r[bi]), Fb);
        b->m[bi] = v3_add(b->m[bi], mb);
        bforce[bi] = v3_add(bforce[bi], Fb);
        bmoment[bi] = v3_add(bmoment[bi], mb);
    }
}
