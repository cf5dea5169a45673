/* Web nodes against body faces, evaluated: normal forces and friction on the nodes, their
 * opposite on the bodies (eq. 13, 14). The candidates come from node.c. */
#include "contact/contact.h"
#include "contact/node.h"
#include "contact/penalty.h"

#include <string.h>

/* Eq. 14 in the global frame for a prepared face: whether the point projects into it (its
 * distance to the plane is the caller's). Every triangle is tested (a face has few), without an
 * early way out: whether a node near the outline projects in is a coin toss. */
static inline int in_wface(const ws_node_geom *g, const ws_wface *F, v3 x)
{
    int in = 0;
    for (uint32_t t = F->first_tri; t < F->first_tri + F->tri_count; t++) {
        const ws_wtri *q = &g->tri[t];
        v3 r = v3_sub(x, q->p);
        in |= ws_bary_inside(v3_dot(r, q->w), v3_dot(r, q->v), q->g00, q->g01, q->g11);
    }
    return in;
}

/* A node against the rounded rim of a convex edge, closer than `hi` and only where the direction
 * from the edge to the node lies strictly between its faces' normals (elsewhere a face holds the
 * node): the unit normal from the edge to the node and the distance. `sure`: the faces' planes
 * have shown that direction already (corner_left). */
static inline int in_wedge(const ws_wedge *E, v3 x, double hi, int sure, v3 *nrm, double *dist)
{
    v3 rp = v3_sub(x, E->p);
    double t = v3_dot(rp, E->e) * E->inv_e2;
    if (!(t > 0.0 && t < 1.0))
        return 0;
    v3 r = v3_madd(rp, E->e, -t);
    double l2 = v3_dot(r, r);
    if (!(l2 < hi * hi) || !(l2 > 0.0))
        return 0;
    const double c = E->c;
    if (1.0 - c * c < 1e-12)
        return 0; /* faces about parallel: no wedge between them */
    /* Outside both faces' planes, and not over either face: r = a n1 + b n2 with a, b > 0. */
    if (!sure) {
        const double r1 = v3_dot(r, E->n1), r2 = v3_dot(r, E->n2);
        if (!(r1 > 0.0 && r2 > 0.0 && r1 - c * r2 > 0.0 && r2 - c * r1 > 0.0))
            return 0;
    }
    double l = sqrt(l2);
    *nrm = v3_scale(r, 1.0 / l);
    *dist = l;
    return 1;
}

/* A load on a body: force and moment about the CoG. */
typedef struct act_load {
    v3 f, m;
} act_load;

/* A contact's load on its body: the opposite of the contact force on the node (friction a plus
 * the normal force fn along n) times share, and its moment about the CoG at lever l; zero for
 * a contact that does not push (push: all bits or none). Adding that zero leaves every sum as it
 * was: the bodies' sums start at +0 and never reach -0, and the moment's zero, of either sign,
 * changes no sum. Both paths (act_friction, run_apply) take it from here, so their loads agree
 * to the bit. */
static inline act_load body_load(uint64_t push, v3 a, v3 n, double fn, double share, v3 l)
{
    const double Bx = ws_pick(push, (a.x + n.x * fn) * -share, 0.0),
                 By = ws_pick(push, (a.y + n.y * fn) * -share, 0.0),
                 Bz = ws_pick(push, (a.z + n.z * fn) * -share, 0.0);
    return (act_load){v3_make(Bx, By, Bz),
                      v3_make(l.y * Bz - l.z * By, l.z * Bx - l.x * Bz, l.x * By - l.y * Bx)};
}

/* A contact's friction a on its node where it pushes (push: all bits or none); -0 where it does
 * not, which leaves the node's force as it was to the bit when added, as the one-by-one pass
 * leaves the force of a contact it does not list (the body's load is then +0, body_load). */
static inline v3 pushed(uint64_t push, v3 a)
{
    return v3_make(ws_pick(push, a.x, -0.0), ws_pick(push, a.y, -0.0), ws_pick(push, a.z, -0.0));
}

/* Eq. 13's friction on a node (ws_friction_law) from the contact's normal n, the node's
 * tangential velocity t relative to the body, its force k with every normal force in, its
 * 1 / mass and mass, Coulomb's force cap and v_lim; none for a pinned node. Limited to the force
 * that stops the node's slip within the sub-step h, the slip predicted with every normal force
 * in and no friction, so that the result does not depend on the order of a corner's faces
 * (docs/theory.md, section 6). Straight-line code, for loops on vectors. */
static inline v3 friction_of(v3 n, v3 t, v3 k, double im, double mass, double cap, double vlim,
                             double h)
{
    /* The slip predicted at the end of the sub-step: t and the force across n, k's part o. */
    const double dot = k.x * n.x + k.y * n.y + k.z * n.z, hm = h * im;
    const double ox = k.x + n.x * (-dot), oy = k.y + n.y * (-dot), oz = k.z + n.z * (-dot);
    const v3 pred = v3_make(t.x + ox * hm, t.y + oy * hm, t.z + oz * hm);
    const ws_friction fr = ws_friction_law(pred, cap, vlim, mass, h);
    const uint64_t loose = ws_mask(im != 0.0); /* not pinned */
    return v3_make(ws_pick(loose, fr.f.x, 0.0), ws_pick(loose, fr.f.y, 0.0),
                   ws_pick(loose, fr.f.z, 0.0));
}

/* ---- the contacts of a sweep block gone one by one
 *
 * The one-by-one pass lists the contacts whose tests it passed, in node order, in groups of
 * four (nc->act), which act_apply evaluates at the block's end; runs apply theirs in batches
 * (run_flush). The loads on the bodies of both go to one list in node order, each into the
 * place its contact took, and are summed last: the bodies' totals are added in the same order
 * however the candidates are cut. */

/* Four contacts of the list side by side (wide.h), lane l of group g the list's contact
 * 4 g + l, so that a pass over the groups runs on vectors with one pointer. */
typedef struct act_group {
    ws_wide3 n;                    /* as contacts_general finds it: normal (body to node), */
    ws_wide d, hi;                 /* depth, window top */
    ws_wide3 x, u, r, v, w;        /* the node's position, velocity; the body's CoG, v, spin */
    ws_wide kp, cp, mu, vl, im, m; /* the contact's parameters; the node's 1 / mass, mass */
    ws_wide3 p, l, t;              /* normal_of's force vector, lever, tangential velocity */
    ws_wide fn;                    /* and normal force */
    ws_wide3 k, a, b, mm; /* the node's force with its normal forces in; friction; body's load */
} act_group;

/* The doubles of nc->act per contact of its room (act_cap): its group's share, then its load;
 * and its bytes, with its four ids (act_list). */
enum { ACT_GROUP = (int)(sizeof(act_group) / (4 * sizeof(double))), ACT_ARRAYS = ACT_GROUP + 6 };
enum { ACT_BYTES = ACT_ARRAYS * sizeof(double) + 4 * sizeof(uint32_t) };

/* The list's loads (act_load) come after its groups. */
_Static_assert(sizeof(act_load) == 6 * sizeof(double) && sizeof(act_group) % 32 == 0,
               "a list's loads take 6 doubles each, its groups whole vectors");

/* The list: n contacts (their groups, nodes, bodies' slots and places in the loads), and nl
 * loads on bodies (each body's slot in lbody). */
typedef struct act_list {
    act_group *grp;
    uint32_t *node, *body, *slot, *lbody;
    act_load *load;
    size_t n, nl;
} act_list;

static act_list act_open(ws_node_contact *nc)
{
    const size_t cap = nc->act_cap; /* a multiple of 4 (ws_node_scratch) */
    uint32_t *id = nc->act_id;
    act_load *load = (act_load *)(nc->act + ACT_GROUP * cap);
    return (act_list){(act_group *)nc->act, id,   id + cap, id + 2 * cap,
                      id + 3 * cap,         load, 0,        nc->act_nl};
}

/* Contact `node` against body `body` as contacts_general finds it: along n, at depth d, in the
 * window of top hi, the node at x. Its place in the list of loads is taken now, in node order;
 * a contact that turns out not to push leaves a load of zero there. */
static inline void act_push(act_list *L, uint32_t node, uint32_t body, v3 n, double d, double hi,
                            v3 x)
{
    const size_t q = L->n++, l = q & 3;
    act_group *e = &L->grp[q >> 2];
    L->node[q] = node;
    L->body[q] = body;
    ws_lane_set(&e->n, l, n);
    e->d.v[l] = d;
    e->hi.v[l] = hi;
    ws_lane_set(&e->x, l, x);
    L->slot[q] = (uint32_t)L->nl++;
}

/* The contact laws' normal force (penalty.h) on a node at x (velocity u) against body b at depth
 * d along n (body to node), window top hi, stiffness k, damping c: its vector p, the lever l from
 * the CoG, the tangential velocity t relative to the body and fn (negative where it would pull).
 * Both passes (act_normal, run_normal) take it from here, on vectors. */
typedef struct node_normal {
    v3 p, l, t;
    double fn;
} node_normal;

static inline node_normal normal_of(v3 n, double d, double hi, v3 x, v3 u, ws_motion b, double k,
                                    double c)
{
    const ws_node_kin kin = ws_node_kinematics(n, d, x, u, b);
    const ws_normal nl = ws_normal_law(n, kin.vr, hi - d, k, c);
    return (node_normal){v3_scale(n, nl.fp), kin.lever, nl.t, nl.fn};
}

/* The normal forces of the contacts of groups [0, ng) (normal_of). */
WS_VECTOR_LOOP
static void act_normal(size_t ng, act_group *restrict G)
{
    for (size_t g = 0; g < ng; g++) {
        act_group *e = &G[g];
        for (size_t l = 0; l < WS_LANES; l++) {
            const ws_motion b = {ws_lane(&e->r, l), ws_lane(&e->v, l), ws_lane(&e->w, l)};
            const node_normal o =
                normal_of(ws_lane(&e->n, l), e->d.v[l], e->hi.v[l], ws_lane(&e->x, l),
                          ws_lane(&e->u, l), b, e->kp.v[l], e->cp.v[l]);
            ws_lane_set(&e->p, l, o.p);
            ws_lane_set(&e->l, l, o.l);
            ws_lane_set(&e->t, l, o.t);
            e->fn.v[l] = o.fn;
        }
    }
}

/* The frictions of the contacts of groups [0, ng) and their loads on the bodies (body_load). */
WS_VECTOR_LOOP
static void act_friction(size_t ng, double h, double share, act_group *restrict G)
{
    for (size_t g = 0; g < ng; g++) {
        act_group *e = &G[g];
        for (size_t l = 0; l < WS_LANES; l++) {
            const v3 n = ws_lane(&e->n, l);
            const double fn = e->fn.v[l];
            const v3 a = friction_of(n, ws_lane(&e->t, l), ws_lane(&e->k, l), e->im.v[l], e->m.v[l],
                                     e->mu.v[l] * fn, e->vl.v[l], h);
            const uint64_t push = ws_mask(fn > 0.0);
            ws_lane_set(&e->a, l, pushed(push, a));
            const act_load B = body_load(push, a, n, fn, share, ws_lane(&e->l, l));
            ws_lane_set(&e->b, l, B.f);
            ws_lane_set(&e->mm, l, B.m);
        }
    }
}

void ws_node_loads(ws_node_contact *nc, v3 *bforce, v3 *bmoment)
{
    const act_list L = act_open(nc);
    for (size_t q = 0; q < L.nl; q++) {
        bforce[L.lbody[q]] = v3_add(bforce[L.lbody[q]], L.load[q].f);
        bmoment[L.lbody[q]] = v3_add(bmoment[L.lbody[q]], L.load[q].m);
    }
    nc->act_nl = 0;
}

size_t ws_node_loads_fold(ws_node_contact *nc, size_t from, size_t to, size_t at)
{
    const act_list L = act_open(nc);
    for (size_t q = from; q < to; at++) {
        const uint32_t bi = L.lbody[q];
        act_load s = L.load[q++];
        for (; q < to && L.lbody[q] == bi; q++)
            s = (act_load){v3_add(s.f, L.load[q].f), v3_add(s.m, L.load[q].m)};
        L.load[at] = s;
        L.lbody[at] = bi;
    }
    return at;
}

/* The body part of corner_left's margin for the body met last in a sweep block (UINT32_MAX:
 * none): most corners in a row are of one body. */
typedef struct corner_memo {
    uint32_t body;
    double eps;
} corner_memo;

/* What the node contacts of a sweep block read (L: the list of the contacts gone one by one). */
typedef struct node_env {
    const ws_body_store *b;
    const ws_body_state *st;
    const ws_node_geom *g;
    ws_web *web;
    ws_nodes3 x, v;
    const ws_node_params *pp;
    act_list *L;
    corner_memo *memo;
} node_env;

/* Out of line where GCC would inline it: see shallowest. Inlined where GCC would not: touch_of
 * (as a call, contacts_general's values go through memory, 2 % of the step) and node_prefetch
 * (as a call of its own, GCC takes a function that only prefetches for one without effects,
 * and drops it). */
#if defined(__GNUC__)
#define NODE_OUT_OF_LINE __attribute__((noinline))
#define NODE_INLINE __attribute__((always_inline))
#define NODE_PREFETCH(p) __builtin_prefetch(p)
#else
#define NODE_OUT_OF_LINE
#define NODE_INLINE
#define NODE_PREFETCH(p) ((void)(p))
#endif

/* The list's contacts, each node's all in (its candidates lie in one stretch): gathered, their
 * normal forces into f in order, then, with every normal force in (order-free friction), their
 * frictions, each applied to its node, its share to fc and the opposite to its place in the
 * loads. The lanes past the last contact compute on what the list held, and are not read. */
static void act_apply(const node_env *E, double h, double share, v3 *fc)
{
    ws_web *web = E->web;
    act_list *L = E->L;
    const size_t m = L->n, ng = (m + 3) / 4;
    if (m == 0)
        return;
    const ws_body_store *b = E->b;
    const ws_body_state *st = E->st;
    const ws_node_params *pp = E->pp;
    const ws_nodes3 v = E->v, f = web->f;
    act_group *G = L->grp;
    /* The body's values kept from one contact to the next, as most are of the body before. */
    uint32_t body = UINT32_MAX;
    ws_motion mb = {v3_make(0, 0, 0), v3_make(0, 0, 0), v3_make(0, 0, 0)};
    ws_node_params p = {0.0, 0.0, 0.0, 0.0};
    for (size_t q = 0; q < m; q++) {
        const uint32_t i = L->node[q], bi = L->body[q];
        if (bi != body) {
            body = bi;
            mb = (ws_motion){st->r[bi], st->v[bi], b->wg[bi]};
            p = pp[b->material[bi]];
        }
        act_group *e = &G[q >> 2];
        const size_t l = q & 3;
        ws_lane_set(&e->u, l, nodes_get(v, i));
        ws_lane_set(&e->r, l, mb.r);
        ws_lane_set(&e->v, l, mb.v);
        ws_lane_set(&e->w, l, mb.w);
        e->kp.v[l] = p.k;
        e->cp.v[l] = p.c;
        e->mu.v[l] = p.mu;
        e->vl.v[l] = p.vlim;
        e->im.v[l] = web->inv_m[i];
        e->m.v[l] = web->m[i];
    }
    act_normal(ng, G);
    /* The normal forces into f in order, and each node's force with all its normal forces in
     * to each of its contacts (a node's contacts lie side by side in the list): the earlier
     * ones of a node with more than one take the later one's. */
    for (size_t q = 0; q < m; q++) {
        act_group *e = &G[q >> 2];
        const size_t l = q & 3;
        const uint32_t i = L->node[q];
        const v3 k = v3_add(nodes_get(f, i), ws_lane(&e->p, l));
        nodes_set(f, i, k);
        ws_lane_set(&e->k, l, k);
        for (size_t j = q; j > 0 && L->node[j - 1] == i; j--)
            ws_lane_set(&G[(j - 1) >> 2].k, (j - 1) & 3, k);
    }
    act_friction(ng, h, share, G);
    for (size_t q = 0; q < m; q++) {
        const act_group *e = &G[q >> 2];
        const size_t l = q & 3;
        const uint32_t i = L->node[q], at = L->slot[q];
        const v3 Fb = ws_lane(&e->b, l);
        nodes_add(f, i, ws_lane(&e->a, l));
        fc[i] = v3_sub(fc[i], Fb); /* the share of the contact force: -Fb, to the bit */
        L->load[at] = (act_load){Fb, ws_lane(&e->mm, l)};
        L->lbody[at] = L->body[q];
    }
    L->n = 0;
}

/* How far past a convex body's edge the push turns from one face's normal to the other's, for
 * both films (the one-by-one pass and ws_node_touch alike; bench/NOTES.md, sessions 18 and 19).
 * A node below face f of a convex body at depth d < 0, e the largest signed distance to the
 * body's other planes (the shallowest other depth, of face g), t = d - e, m = max(d, e) (its
 * signed distance to the body's surface): its push comes from one contact, f's where t > 0 (the
 * lower face's index of f, g on a tie), with the overlap hi - m along the unit normal
 *
 *     n = (s n_f + (1 - s) n_g) / |s n_f + (1 - s) n_g|,   s = min(1, 1/2 + t / (2 W)),
 *     W = min(NODE_BLEND_WIDTH, -m);
 *
 * for t >= W that is n_f and d, the shallowest face alone, to the bit. Continuous: across the
 * medial plane (t = 0) the contact passes from f to g with the same push, k (hi - m) along the
 * bisector, which the shallowest face alone would turn by the faces' angle on a difference of
 * round-off; on the edge line the push is the rounded rim's (in_wedge). One contact, as the
 * rim's: one normal force, one friction in its tangent plane (two faces' contacts would each
 * hold the node against the other's push by friction, and half shares each would let a corner
 * sink twice as deep). The width pinches to the depth (-m) near the surface, so that the push
 * is f's own by the time the node reaches g's plane (e = 0); a fixed width would turn it there
 * by up to half the faces' angle. So the blend fills the wedge about the edge inside the body
 * by angle, as the rim does outside it, turning as 1 / distance near the edge line.
 *
 * The width: far above round-off (1e-11 m, the medial plane's tie) and the noise that
 * mirror-symmetric nodes carry (1e-8 m in the settling bands), so that mirror images get mirror
 * pushes; within a film node's layer (~1 mm), which its push spans, and small beside a face. */
#define NODE_BLEND_WIDTH 1e-3

/* Whether the face of candidate c (of non-convex shape sh, body bi) is the shallowest for a
 * node at (xx, xy, xz) under it at depth d (ws_shallowest_face). Out of line: the few nodes
 * below a face need it, and inlined its values would crowd contacts_general's registers. */
NODE_OUT_OF_LINE static int shallowest(const node_env *E, const ws_shape *sh, uint32_t bi,
                                       const ws_ncand *c, double xx, double xy, double xz, double d)
{
    const uint32_t f = c->local & ~WS_NCAND_FLAGS;
    const v3 xi = v3_make(xx, xy, xz);
    return ws_shallowest_face(sh, f, m3_tmul_v(&E->b->A[bi], v3_sub(xi, E->st->r[bi])), d);
}

/* The push of face candidate c of a convex shape sh on a node at xi below it at depth d < 0
 * (NODE_BLEND_WIDTH's law), the window's top hi (the two layers): whether it pushes, and then
 * its normal and the distance it pushes over (hi less the overlap) and, with gr (zeroed by the
 * caller), their gradients in xi for the implicit film's exact derivatives (ws_node_touch_at:
 * g, and dn/dx = ta tb^T). The prepared faces (global). Out of line as shallowest. */
NODE_OUT_OF_LINE static int convex_push(const node_env *E, const ws_shape *sh, const ws_ncand *c,
                                        v3 xi, double d, double hi, v3 *nrm, double *dist,
                                        ws_node_touch_at *gr)
{
    const uint32_t f = c->local & ~WS_NCAND_FLAGS;
    const ws_wface *F = E->g->face + (c->feat - f);
    double e = -INFINITY;
    uint32_t qg = f;
    for (uint32_t q = 0; q < sh->face_count; q++) {
        const double dq = v3_dot(F[q].n, xi) - F[q].off;
        if (q != f && dq > e) {
            e = dq;
            qg = q;
        }
    }
    const double t = d - e, m = e > d ? e : d, W = fmin(NODE_BLEND_WIDTH, -m);
    if (!(W > 0.0) || !(t < W)) {
        /* The shallowest face alone, as far from an edge. */
        if (e > d)
            return 0;
        *nrm = F[f].n;
        *dist = d;
        if (gr)
            gr->g = F[f].n;
        return 1;
    }
    if (t < 0.0 || (t == 0.0 && qg < f))
        return 0; /* g's contact pushes */
    const double s = 0.5 + t / (2.0 * W);
    const v3 bl = v3_add(v3_scale(F[f].n, s), v3_scale(F[qg].n, 1.0 - s));
    const double bn = v3_norm(bl);
    const v3 n = v3_scale(bl, 1.0 / bn);
    *nrm = n;
    *dist = m;
    if (gr) {
        /* m's gradient is n_f (t >= 0 here); s's is (n_f - n_g) / (2 W) - t dW / (2 W^2) with
         * dW = -n_f where the width is pinched to the depth; n's is (I - n n^T) (n_f - n_g) /
         * |bl| ds^T. */
        const v3 u = v3_sub(F[f].n, F[qg].n);
        v3 ds = v3_scale(u, 1.0 / (2.0 * W));
        if (-m < NODE_BLEND_WIDTH)
            ds = v3_madd(ds, F[f].n, t / (2.0 * W * W));
        gr->g = F[f].n;
        gr->ta = v3_scale(v3_madd(u, n, -v3_dot(n, u)), 1.0 / bn);
        gr->tb = ds;
    }
    return 1;
}

/* Whether candidate c holds the node at xi in the window (lo, top), by the one-by-one pass's
 * and the implicit film's test alike (ws_node_touch): the normal from the body to the node, the
 * distance it pushes over (hi: the window's top without the caller's reach) and, with gr, a
 * blended push's gradients (convex_push). `sure` as in_wedge's. */
static inline NODE_INLINE int touch_of(const node_env *E, const ws_ncand *c, v3 xi, double lo,
                                       double top, double hi, int sure, v3 *nrm, double *dist,
                                       ws_node_touch_at *gr)
{
    const ws_node_geom *g = E->g;
    if (c->local & WS_NCAND_EDGE)
        return in_wedge(&g->edge[c->feat], xi, top, sure, nrm, dist);
    const ws_wface *F = &g->face[c->feat];
    const double d = F->n.x * xi.x + F->n.y * xi.y + F->n.z * xi.z - F->off;
    if (!(d < top) || !(d > lo))
        return 0;
    /* A node found well inside the face's outline stays over the face while the candidates
     * are valid: no need to find its triangle. */
    if (!(c->local & WS_NCAND_INSIDE) && !in_wface(g, F, xi))
        return 0;
    if (d < 0.0) {
        const ws_shape *sh = E->b->shape[c->body];
        if (sh->convex)
            return convex_push(E, sh, c, xi, d, hi, nrm, dist, gr);
        if (!shallowest(E, sh, c->body, c, xi.x, xi.y, xi.z, d))
            return 0;
    }
    *nrm = F->n;
    *dist = d;
    return 1;
}

/* ---- a node at a convex body's edge: faces A, B and the edge between them, of which at most
 * one holds the node, told apart by the two planes' distances dA, dB, by a margin eps that the
 * full tests cannot disagree with (docs/theory.md, section 6, "Corners"). */

/* Of a corner c[0, 3) of node xi (the shape sh at r, the window's top hi), those the planes
 * leave to their full tests, one bit each: a face within the window's top and not turned down,
 * the edge unless turned down. *sure: the node lies out of both planes and each face's
 * projection of it out of the other's plane, by eps, so that in_wedge's tests of the direction
 * (r . n1, r . n2 and r = a n1 + b n2 with a, b > 0, which are dA, dB, qA and qB to round-off,
 * as for turning the edge down) hold and need not be taken. */
static inline uint32_t corner_left(const ws_node_geom *g, const ws_shape *sh, const ws_ncand *c,
                                   v3 xi, v3 r, double hi, corner_memo *memo, int *sure)
{
    const ws_wface *A = &g->face[c[0].feat], *B = &g->face[c[1].feat];
    /* The planes' distances as the one-by-one pass takes them. */
    const double dA = A->n.x * xi.x + A->n.y * xi.y + A->n.z * xi.z - A->off,
                 dB = B->n.x * xi.x + B->n.y * xi.y + B->n.z * xi.z - B->off;
    const double cn = v3_dot(A->n, B->n), qA = dA - cn * dB, qB = dB - cn * dA;
    /* The margin: the faces' outlines stand out of the other faces' planes by the shape's
     * convexity tolerance (1e-9 of its size) and eq. 14's (1e-9 of a triangle) at most, a few
     * 1e-9 of its radius; round-off and the flatness of its faces (1e-12) come at the size of
     * the coordinates and distances. Both with room to spare: a node that close to a boundary
     * takes the full test. (On the reference case the closest calls stand 2.4e-10 m out of the
     * other plane, where eq. 14's tolerance still takes them; eps is 2.2e-8 m there.) */
    if (memo->body != c[0].body) {
        memo->body = c[0].body;
        memo->eps = 1e-7 * sh->radius +
                    1e-10 * (fabs(r.x) + fabs(r.y) + fabs(r.z) + sh->radius + sh->inner + hi);
    }
    const double eps = memo->eps + 1e-10 * (fabs(xi.x) + fabs(xi.y) + fabs(xi.z));
    /* A's projection of the node stands out of B's plane by qB, B's out of A's by qA. */
    const uint32_t a = (dA < hi) & !(qB > eps);
    const uint32_t z = (dB < hi) & !(qA > eps);
    const double dmax = dA > dB ? dA : dB;
    const uint32_t e = (qA > -eps) & (qB > -eps) & (dmax < hi + eps);
    *sure = (qA > eps) & (qB > eps) & (dA > eps) & (dB > eps);
    return a | z << 1 | e << 2;
}

/* Candidates one by one, in node order: any feature, any body. The contacts that pass their
 * tests go into the list, which act_apply evaluates at the block's end. A corner (marked
 * WS_NCAND_CORNER by the detection, which looks at a node's candidates once where this pass
 * would every sub-step) is told apart by its faces' planes first, and only what they leave
 * takes the tests. */
static void contacts_general(const node_env *E, const ws_ncand *cand, size_t n)
{
    /* E's members are read where used, not copied first: shallowest may change what E points
     * to as far as the compiler knows, so they are loaded again after it either way, and
     * copies would be kept on the stack at every call. */
    for (size_t k = 0; k < n;) {
        const ws_body_store *b = E->b;
        const ws_body_state *st = E->st;
        const ws_node_geom *g = E->g;
        const ws_ncand *c0 = &cand[k];
        const uint32_t i = c0->node, bi = c0->body;
        const ws_shape *sh = b->shape[bi];
        const v3 xi = nodes_get(E->x, i);
        /* The contact window of the pair: the two layers outside, the body's inner depth in. */
        const double hi = b->layer[bi] + E->web->layer, lo = -hi - sh->inner;
        /* The node's candidates of this body (at most 32 at a time) left to their tests. */
        uint32_t left;
        int sure = 0;
        if ((c0->local & WS_NCAND_CORNER) && !E->web->contact->runs_off) {
            left = corner_left(g, sh, c0, xi, st->r[bi], hi, E->memo, &sure);
            E->web->contact->corners++;
            k += 3;
        } else {
            size_t e = k + 1;
            while (e < n && e < k + 32 && cand[e].node == i && cand[e].body == bi)
                e++;
            left = (uint32_t)(((uint64_t)1 << (e - k)) - 1u);
            k = e;
        }
        for (; left; left &= left - 1) {
            const ws_ncand *c = c0 + ws_lowest_bit(left);
            v3 nrm;
            double d;
            if (touch_of(E, c, xi, lo, hi, hi, sure, &nrm, &d, NULL))
                act_push(E->L, i, bi, nrm, d, hi, xi);
        }
    }
}

/* ---- runs: nodes side by side on one face */

#define RUN_MIN 4    /* shorter stretches go one by one */
#define RUN_CHUNK 64 /* nodes of a run whose depths are taken at once: a bit each in a word */
_Static_assert(RUN_CHUNK == 64, "run_depth answers with a bit a node, run_bit has 64");
/* Groups of four nodes a sweep block's batch holds (run_batch): at least a chunk's. */
#define RUN_GROUPS 32
_Static_assert(RUN_GROUPS >= RUN_CHUNK / 4, "a chunk's groups fit in an empty batch");
/* The length of the batch's scratch arrays (run_tmp): not a power of two, so that their first
 * lines, the ones a short batch uses, fall in different sets of the first-level cache (at a
 * power of two apart they crowd into a few sets and evict each other). */
#define RUN_OSTRIDE (4 * RUN_GROUPS + 8)

/* What a run needs of its face and body, the same for every run on the face in a sub-step:
 * filled by the first of them (run_face_of). */
typedef struct ws_run_face {
    v3 n;                  /* the face's plane, global: d = n . x - off */
    double off, hi, lo;    /* and the contact window of d */
    ws_motion b;           /* the body's CoG, velocity and spin */
    double k, c, mu, vlim; /* the contact's parameters */
    uint32_t body;         /* the body's slot */
    uint64_t gen;          /* the sub-step filled in, nc->rface_gen */
} run_face;

/* Bit i, for i below RUN_CHUNK: a table, so that a loop sets bit i of a word with an AND
 * rather than a shift by its own index, which takes more work on vectors. */
#define RUN_BIT4(k)                                                                                \
    (uint64_t)1 << (k), (uint64_t)1 << ((k) + 1), (uint64_t)1 << ((k) + 2), (uint64_t)1 << ((k) + 3)
#define RUN_BIT16(k) RUN_BIT4(k), RUN_BIT4((k) + 4), RUN_BIT4((k) + 8), RUN_BIT4((k) + 12)
static const uint64_t run_bit[RUN_CHUNK] = {RUN_BIT16(0), RUN_BIT16(16), RUN_BIT16(32),
                                            RUN_BIT16(48)};

/* Depth d of nodes [0, 4 nv) (4 nv <= RUN_CHUNK) under the face's plane: bit i of the answer
 * says whether node i lies in the window, bit i of *below whether it lies below the plane.
 * Whole vectors of four, so that no loop is left over; straight-line code. */
WS_VECTOR_LOOP
static uint64_t run_depth(size_t nv, const run_face *restrict q, const double *restrict x,
                          const double *restrict y, const double *restrict z, double *restrict d,
                          uint64_t *restrict below)
{
    const double nx = q->n.x, ny = q->n.y, nz = q->n.z, off = q->off, hi = q->hi, lo = q->lo;
    uint64_t in = 0, neg = 0;
    for (size_t i = 0; i < 4 * nv; i++) {
        double e = nx * x[i] + ny * y[i] + nz * z[i] - off;
        const uint64_t bit = run_bit[i];
        d[i] = e;
        in |= bit & (0 - (uint64_t)((e < hi) & (e > lo)));
        neg |= bit & (0 - (uint64_t)(e < 0.0));
    }
    *below = neg;
    return in;
}

/* Four consecutive nodes from a node of a run in the window on, within the nodes its chunk's
 * depths were taken of: the unit of the run passes. */
typedef struct run_group {
    const run_face *rf; /* the run's face and body */
    uint32_t node;      /* the first of the four */
    uint32_t slot;      /* the place of the first of them in the list of loads */
    uint64_t bits;      /* those in the window: bit l for node + l (none past the run) */
} run_group;

/* The groups of a sweep block's runs waiting for the run passes (their places in the list of
 * loads kept, they may wait until the block's end), and the passes' scratch (run_tmp). */
typedef struct run_batch {
    run_group *grp;
    struct run_tmp *tmp;
    double *depth; /* by node: the depths run_depth took, under the face of the run it took
                      them for (past a run's end, the next run's take the place of its) */
    size_t n, max; /* max: how many groups it holds, at most RUN_GROUPS: it runs before a
                      chunk that could take it past them (a chunk's groups go in whole) */
} run_batch;

/* The contacts of the run nodes in the window, a group of four nodes at a time, straight from
 * the nodes' arrays, with act_apply's arithmetic operation by operation (the test
 * film_runs_equal_one_by_one holds them to it, to the bit). A run's node has no other contact,
 * so its force with every normal force in is its force with this one. Lanes of a group not in
 * the window, or not the run's, keep their forces.
 *
 * In three passes over all the groups (run_normal, run_friction, run_apply), their values in
 * between in run_tmp, so that the long chains of several groups' arithmetic overlap
 * (docs/design.md, deviation (i)). Values a later pass takes only under a condition are read
 * there as masks (as a select, the compiler would read them under the condition: slow loads).
 *
 * run_tmp: each array a value of every lane (4 g + l for lane l of group g). */
typedef struct run_tmp {
    double k[3][RUN_OSTRIDE];                    /* normal force, then the node's force with it */
    double t[3][RUN_OSTRIDE];                    /* tangential velocity */
    double fn[RUN_OSTRIDE], keep[RUN_OSTRIDE];   /* normal force; in the window */
    double l[3][RUN_OSTRIDE];                    /* lever */
    double a[3][RUN_OSTRIDE];                    /* friction, if it pushes */
    double b[3][RUN_OSTRIDE], m[3][RUN_OSTRIDE]; /* the body's share: force, moment about the CoG */
} run_tmp;

/* Lane e of a vector of run_tmp, and back. */
static inline v3 tmp_get(double (*a)[RUN_OSTRIDE], size_t e)
{
    return v3_make(a[0][e], a[1][e], a[2][e]);
}

static inline void tmp_set(double (*a)[RUN_OSTRIDE], size_t e, v3 p)
{
    a[0][e] = p.x;
    a[1][e] = p.y;
    a[2][e] = p.z;
}

/* The passes' arrays are restrict pointers, parameters or the function's first locals: read
 * through a struct, GCC 12 no longer takes them as apart, and runs the passes with many more
 * instructions. An array a pass writes stays a parameter (as a local, GCC 12 checks it against
 * the others at run time: twice the instructions). Each pass takes only those it uses.
 *
 * normal_of for the groups [0, ng) of the batch: the nodes' positions p, velocities u and
 * depths, into T (the normal force's vector into T->k). */
WS_VECTOR_LOOP
static void run_normal(size_t ng, const run_group *restrict grp, ws_nodes3 p, ws_nodes3 u,
                       const double *restrict depth, run_tmp *restrict T)
{
    const double *restrict px = p.x, *restrict py = p.y, *restrict pz = p.z;
    const double *restrict ux = u.x, *restrict uy = u.y, *restrict uz = u.z;
    for (size_t g = 0; g < ng; g++) {
        const run_face *q = grp[g].rf;
        const size_t o = grp[g].node;
        const uint64_t bits = grp[g].bits;
        /* Into locals: loads in the loop, some under a select, would keep it off vectors (the
         * motion member by member: GCC copies it whole through the stack, a step slower). */
        const v3 n = q->n;
        const ws_motion b = {q->b.r, q->b.v, q->b.w};
        const double hi = q->hi, k = q->k, c = q->c;
        for (size_t l = 0; l < WS_LANES; l++) {
            const size_t t = o + l, e = 4 * g + l;
            T->keep[e] = ws_double_of(0 - ((bits >> l) & 1u));
            const node_normal nf = normal_of(n, depth[t], hi, v3_make(px[t], py[t], pz[t]),
                                             v3_make(ux[t], uy[t], uz[t]), b, k, c);
            tmp_set(T->k, e, nf.p);
            tmp_set(T->t, e, nf.t);
            T->fn[e] = nf.fn;
            tmp_set(T->l, e, nf.l);
        }
    }
}

/* act_apply's friction over sub-step h, from the nodes' forces g (T->k becomes the node's force
 * with its normal force in), 1 / mass im and mass. */
WS_VECTOR_LOOP
static void run_friction(size_t ng, const run_group *restrict grp, ws_nodes3 f,
                         const double *restrict im, const double *restrict mass, double h,
                         run_tmp *restrict T)
{
    const double *restrict gx = f.x, *restrict gy = f.y, *restrict gz = f.z;
    for (size_t g = 0; g < ng; g++) {
        const run_face *q = grp[g].rf;
        const size_t o = grp[g].node;
        const v3 n = q->n;
        const double mu = q->mu, vlim = q->vlim;
        for (size_t l = 0; l < WS_LANES; l++) {
            const size_t t = o + l, e = 4 * g + l;
            const v3 k = v3_make(gx[t] + T->k[0][e], gy[t] + T->k[1][e], gz[t] + T->k[2][e]);
            tmp_set(T->k, e, k);
            tmp_set(T->a, e,
                    friction_of(n, tmp_get(T->t, e), k, im[t], mass[t], mu * T->fn[e], vlim, h));
        }
    }
}

/* The nodes' new forces into g, and the body's share of each load into T. */
WS_VECTOR_LOOP
static void run_apply(size_t ng, const run_group *restrict grp, double *restrict gx,
                      double *restrict gy, double *restrict gz, double share, run_tmp *restrict T)
{
    for (size_t g = 0; g < ng; g++) {
        const run_face *q = grp[g].rf;
        const size_t o = grp[g].node;
        const v3 n = q->n;
        for (size_t l = 0; l < WS_LANES; l++) {
            const size_t t = o + l, e = 4 * g + l;
            const double fn = T->fn[e];
            const uint64_t keep = ws_bits(T->keep[e]), push = ws_mask(fn > 0.0);
            const v3 a = pushed(push, tmp_get(T->a, e));
            gx[t] = ws_pick(keep, T->k[0][e] + a.x, gx[t]);
            gy[t] = ws_pick(keep, T->k[1][e] + a.y, gy[t]);
            gz[t] = ws_pick(keep, T->k[2][e] + a.z, gz[t]);
            const act_load B = body_load(push, a, n, fn, share, tmp_get(T->l, e));
            tmp_set(T->b, e, B.f);
            tmp_set(T->m, e, B.m);
        }
    }
}

/* A run contact's share of its force into fc and its body's load into its place (run_flush). */
static inline void flush_one(run_tmp *T, size_t e, v3 *fc, act_load *load, uint32_t *lbody,
                             uint32_t body)
{
    const v3 Fb = tmp_get(T->b, e);
    *fc = v3_sub(*fc, Fb); /* the share: -Fb, to the bit */
    *load = (act_load){Fb, tmp_get(T->m, e)};
    *lbody = body;
}

/* The batch's contacts: the run passes, then, in node order, each node's share of its contact
 * force and its body's load into their places in the list of loads. A contact that does not
 * push has a share of zero, and is listed as touched and loaded all the same (a branch would
 * be a coin toss). */
static void run_flush(const node_env *E, run_batch *B, double h, double share, v3 *fc)
{
    if (B->n == 0)
        return;
    ws_web *web = E->web;
    const ws_nodes3 x = E->x, v = E->v, f = web->f;
    run_tmp *T = B->tmp;
    run_normal(B->n, B->grp, x, v, B->depth, T);
    run_friction(B->n, B->grp, f, web->inv_m, web->m, h, T);
    run_apply(B->n, B->grp, f.x, f.y, f.z, share, T);
    act_list *L = E->L;
    act_load *load = L->load;
    uint32_t *lbody = L->lbody;
    for (size_t g = 0; g < B->n; g++) {
        const run_group *G = &B->grp[g];
        /* Read here: as far as the compiler knows, the stores below could change them. */
        const uint32_t body = G->rf->body, node = G->node;
        size_t s = G->slot;
        if (G->bits == 15u) {
            /* All four in the window (most groups of a film lying on a face): the same
             * stores, without the walk over the bits. */
            flush_one(T, 4 * g, fc + node, load + s, lbody + s, body);
            flush_one(T, 4 * g + 1, fc + node + 1, load + s + 1, lbody + s + 1, body);
            flush_one(T, 4 * g + 2, fc + node + 2, load + s + 2, lbody + s + 2, body);
            flush_one(T, 4 * g + 3, fc + node + 3, load + s + 3, lbody + s + 3, body);
            continue;
        }
        for (uint32_t bits = G->bits; bits; bits &= bits - 1, s++) {
            const uint32_t l = ws_lowest_bit(bits);
            flush_one(T, 4 * g + l, fc + node + l, load + s, lbody + s, body);
        }
    }
    B->n = 0;
}

/* The face of candidate c, which a run lies on, as the run needs it in this sub-step: taken
 * from the face, its body and their materials by the first run on it. */
static const run_face *run_face_of(const node_env *E, const ws_ncand *c)
{
    ws_web *web = E->web;
    ws_node_contact *nc = web->contact;
    run_face *e = &nc->rface[c->feat];
    if (e->gen == nc->rface_gen)
        return e;
    const ws_body_store *b = E->b;
    const ws_body_state *st = E->st;
    const uint32_t bi = c->body;
    const ws_wface *F = &E->g->face[c->feat];
    const ws_node_params *p = &E->pp[b->material[bi]];
    const double hi = b->layer[bi] + web->layer, lo = -hi - b->shape[bi]->inner;
    const ws_motion mb = {st->r[bi], st->v[bi], b->wg[bi]};
    *e = (run_face){F->n, F->off, hi, lo, mb, p->k, p->c, p->mu, p->vlim, bi, nc->rface_gen};
    return e;
}

/* Nodes in the window of each group of four: their count. */
static const uint8_t run_count4[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};

/* A run: its nodes' depths first, on vectors; most lie just outside the window and are done.
 * The groups of four nodes with one in the window join the block's batch (B), with their
 * places in the list of loads, in node order: the run passes take them with the arithmetic of
 * contacts_general for a node whose only candidate is a face it lies well inside of, without
 * its look-ups (the face, body and contact are the run's). A chunk with a node below the face's
 * plane (d < 0), where another face may lie shallower, goes to contacts_general. */
static void contacts_run(const node_env *E, run_batch *B, const ws_ncand *cand, const ws_nseg *sg,
                         double h, double share, v3 *fc)
{
    ws_web *web = E->web;
    ws_node_contact *nc = web->contact;
    const ws_nodes3 x = E->x;
    act_list *L = E->L;
    const ws_ncand *c = &cand[sg->c0];
    const run_face *rf = run_face_of(E, c);
    for (uint32_t o = sg->n0; o < sg->n1; o += RUN_CHUNK) {
        size_t m = sg->n1 - o < RUN_CHUNK ? sg->n1 - o : RUN_CHUNK;
        /* Depths on whole vectors, past the run (its row goes on), the bits of the nodes past
         * it dropped; a chunk whose vectors would end past the last node goes one by one. */
        const size_t nv = (m + 3) / 4;
        uint64_t below = 0, in = 0;
        int whole = o + 4 * nv <= web->n;
        if (whole) {
            in = run_depth(nv, rf, x.x + o, x.y + o, x.z + o, B->depth + o, &below);
            in &= m < RUN_CHUNK ? ((uint64_t)1 << m) - 1 : ~(uint64_t)0;
        }
        nc->run_nodes += m;
        if (!whole || (in & below)) { /* one by one */
            nc->run_deep += whole ? m : 0;
            contacts_general(E, c + (o - sg->n0), m);
            continue;
        }
        /* The batch runs first if the chunk's groups (nv at most) could overfill it. */
        if (B->n + nv > B->max)
            run_flush(E, B, h, share, fc);
        /* The groups: each from the first node in the window not yet in one, so that nodes in
         * the window side by side share few groups; the last no further than the depths
         * reach (it may then hold nodes of the one before, not as its own). */
        uint32_t slot = (uint32_t)L->nl;
        /* No group reaches past the lane's nodes (lane_end), whose forces another lane may be
         * writing: one that would starts earlier, its first nodes not its own (a lane holds
         * at least a block of WS_WEB_BLOCK_NODES nodes, so it stays within the lane). */
        const uint32_t last = (uint32_t)(4 * nv - 4);
        const uint32_t cap = o + 4 * nv > nc->lane_end ? nc->lane_end - 4 : UINT32_MAX;
        while (in) {
            uint32_t e = ws_lowest_bit(in);
            e = e < last ? e : last;
            const uint32_t start = o + e < cap ? o + e : cap;
            const uint32_t bits = (uint32_t)(in >> e) & 15u;
            in &= ~((uint64_t)15u << e);
            B->grp[B->n++] = (run_group){rf, start, slot, bits << (o + e - start)};
            slot += run_count4[bits];
        }
        L->nl = slot;
    }
}

/* The stretches being cut into seg (room for one a candidate; none is empty), and pending: a run
 * of single inside candidates [r0, r1) and, before it, candidates to go one by one [g0, r0). */
typedef struct seg_cut {
    const ws_ncand *cand;
    ws_nseg *seg;
    size_t nseg, g0, r0, r1;
    uint32_t faces; /* one past the highest face a run lies on */
} seg_cut;

/* The stretch of candidates [c0, c1), unless empty. */
static void seg_emit(seg_cut *sc, size_t c0, size_t c1, int run)
{
    if (c0 == c1)
        return;
    sc->seg[sc->nseg++] =
        (ws_nseg){sc->cand[c0].node, sc->cand[c1 - 1].node + 1, (uint32_t)c0, (uint32_t)c1, run};
    if (run && sc->cand[c0].feat >= sc->faces)
        sc->faces = sc->cand[c0].feat + 1;
}

/* The pending run ends: a run if long enough (after the pending one-by-one ones), else its
 * candidates join those. */
static void seg_close_run(seg_cut *sc)
{
    if (sc->r1 - sc->r0 >= RUN_MIN) {
        seg_emit(sc, sc->g0, sc->r0, 0);
        seg_emit(sc, sc->r0, sc->r1, 1);
        sc->g0 = sc->r1;
    }
    sc->r0 = sc->r1;
}

/* Cut the candidates from k on (of n) whose nodes lie below stop, a block's start (blocks of bl
 * nodes, seg_block); the index past them. A block's stretches depend on its candidates alone. */
static size_t seg_cut_range(seg_cut *sc, const ws_web *web, uint32_t bl, size_t k, size_t n,
                            uint64_t stop)
{
    ws_node_contact *nc = web->contact;
    const ws_ncand *cand = sc->cand;
    uint64_t end = 0; /* the end of the block of the current node, at most stop */
    sc->g0 = sc->r0 = sc->r1 = k;
    while (k < n && cand[k].node < stop) {
        const uint32_t node = cand[k].node;
        size_t e = k + 1;
        while (e < n && cand[e].node == node)
            e++;
        /* Whatever ran before ends here: the loop below took every node that carries it on. */
        seg_close_run(sc);
        if (node >= end) { /* a new block: nothing pending crosses into it */
            seg_emit(sc, sc->g0, k, 0);
            sc->g0 = k;
            end = (uint64_t)(node / bl + 1) * bl;
            end = end < stop ? end : stop;
        }
        if (nc->runs_off || e != k + 1 || (cand[k].local & WS_NCAND_FLAGS) != WS_NCAND_INSIDE) {
            sc->r0 = sc->r1 = e; /* one by one: pending from g0 */
        } else {
            /* A run starts, and goes on over the next nodes of the block, each with one inside
             * candidate of its face. */
            const uint32_t feat = cand[k].feat;
            uint32_t prev = node;
            sc->r0 = k;
            while (e < n && cand[e].node == prev + 1 && cand[e].node < end &&
                   cand[e].feat == feat && (cand[e].local & WS_NCAND_FLAGS) == WS_NCAND_INSIDE &&
                   (e + 1 == n || cand[e + 1].node != cand[e].node)) {
                prev = cand[e].node;
                e++;
            }
            sc->r1 = e;
        }
        k = e;
    }
    seg_close_run(sc);
    seg_emit(sc, sc->g0, k, 0);
    return k;
}

/* The length of the blocks stretches are cut in: a web's rows (a sweep block holds whole rows,
 * ws_web_block_count; a mesh web's last row is cut as the others, past its rows' count). */
static uint32_t seg_block(const ws_web *web)
{
    return ws_web_row_len(web);
}

/* Room for the run batch of a web of n nodes: its groups, the run passes' scratch, the nodes'
 * depths. */
static int rtmp_reserve(ws_mem *mem, ws_node_contact *nc, size_t n)
{
    const size_t need = (RUN_GROUPS * sizeof(run_group) + sizeof(run_tmp)) / sizeof(double) + n;
    return ws_array_reserve(mem, (void **)&nc->rtmp, &nc->rtmp_cap, need, sizeof(double));
}

/* Room for the faces [0, faces) that runs lie on. */
static int rface_reserve(ws_mem *mem, ws_node_contact *nc, size_t faces)
{
    const size_t had = nc->rface_cap;
    if (ws_array_reserve(mem, (void **)&nc->rface, &nc->rface_cap, faces, sizeof *nc->rface) != 0)
        return -1;
    for (size_t f = had; f < nc->rface_cap; f++)
        nc->rface[f].gen = 0; /* filled in no sub-step: rface_gen is 1 from the first on */
    return 0;
}

/* The stretches cut (sc) are list `list`'s. */
static int seg_done(ws_mem *mem, ws_web *web, const seg_cut *sc, int list)
{
    ws_node_contact *nc = web->contact;
    nc->nseg = sc->nseg;
    if (rface_reserve(mem, nc, sc->faces) != 0)
        return -1;
    nc->seg_list = list;
    return 0;
}

int ws_node_segments(ws_mem *mem, ws_web *web, const ws_ncand *cand, size_t n, int list)
{
    ws_node_contact *nc = web->contact;
    nc->seg_list = -1;
    nc->nseg = 0;
    if (rtmp_reserve(mem, nc, web->n) != 0 ||
        ws_array_reserve(mem, (void **)&nc->seg, &nc->seg_cap, n + 1, sizeof *nc->seg) != 0)
        return -1;
    seg_cut sc = {cand, nc->seg, 0, 0, 0, 0, 0};
    seg_cut_range(&sc, web, seg_block(web), 0, n, UINT64_MAX);
    return seg_done(mem, web, &sc, list);
}

int ws_node_segments_merged(ws_mem *mem, ws_web *web, const ws_nmerge *M, int list, int from)
{
    ws_node_contact *nc = web->contact;
    const uint32_t bl = seg_block(web), nn = M->nn;
    const size_t nold = nc->nseg, count = M->count, n = M->out->n;
    if (nc->seg_list != from) /* cut whole, from the whole list merged here */
        return ws_node_merge_range(M, 0, nn), ws_node_segments(mem, web, M->out->c, n, list);
    nc->seg_list = -1;
    /* The new stretches go after the old ones, then down in their place. */
    if (ws_array_reserve(mem, (void **)&nc->seg, &nc->seg_cap, nold + n + 1, sizeof *nc->seg) != 0)
        return -1;
    const ws_nseg *old = nc->seg;
    seg_cut sc = {M->out->c, nc->seg + nold, 0, 0, 0, 0, 0};
    size_t p = 0, k = 0; /* the next old stretch; where the next candidates lie in the list */
    for (size_t q = 0; q <= count;) {
        const uint64_t b0 = q < count ? (uint64_t)(M->nodes[q] / bl) * bl : UINT64_MAX,
                       b1 = q < count ? b0 + bl : UINT64_MAX;
        /* The blocks before the next one that changed keep their stretches, which now start at
         * k: the candidates before them are those of the blocks before (runs' faces have room). */
        for (; p < nold && old[p].n0 < b0; p++) {
            ws_nseg sg = old[p];
            sg.c1 = (uint32_t)k + (sg.c1 - sg.c0);
            sg.c0 = (uint32_t)k;
            k = sg.c1;
            sc.seg[sc.nseg++] = sg;
        }
        if (q == count)
            break;
        /* That block is cut again from its candidates, merged here up to the next node's. */
        for (; p < nold && old[p].n0 < b1; p++)
            ;
        const uint32_t e = b1 < nn ? (uint32_t)b1 : nn;
        ws_node_merge_range(M, (uint32_t)b0, e < nn ? e + 1 : nn);
        k = seg_cut_range(&sc, web, bl, k, M->nstart[e], b1);
        while (q < count && M->nodes[q] < b1)
            q++;
    }
    memmove(nc->seg, sc.seg, sc.nseg * sizeof *nc->seg);
    return seg_done(mem, web, &sc, list);
}

/* The stretches of the next row, from seg[k] on (the first row of the sweep block after the one
 * ending at n1), and the first and last of their candidates, asked of the memory now so that
 * they arrive while the block's springs are evaluated: from one step to the next they leave
 * the caches, and a block reads them in a few places (the first candidate of a run, a
 * one-by-one stretch), each a wait for the memory otherwise. */
static inline NODE_INLINE void node_prefetch(const ws_web *web, const ws_ncand *cand, size_t k,
                                             uint32_t n1)
{
    ws_node_contact *nc = web->contact;
    const uint64_t end = (uint64_t)n1 + seg_block(web);
    const ws_nseg *seg = nc->seg;
    const size_t nseg = nc->nseg;
    size_t s = k;
    for (; s < nseg && seg[s].n0 < end; s++) {
        NODE_PREFETCH(cand + seg[s].c0);
        if (!seg[s].run) /* a run reads its first candidate only */
            NODE_PREFETCH(cand + seg[s].c1 - 1);
    }
    /* And the first stretches of the block after, whose places the next call reads (a dozen
     * stretches, 20 bytes each). */
    for (size_t q = s; q < s + 12 && q < nseg; q += 3)
        NODE_PREFETCH(seg + q);
}

void ws_node_contacts(const ws_node_pass *P, ws_web *web, uint32_t n1, size_t *next,
                      uint64_t *checks)
{
    ws_node_contact *nc = web->contact;
    const ws_ncand *cand = P->cand;
    const double h = P->h, share = P->share;
    v3 *fc = P->fc;
    act_list L = act_open(web->contact);
    corner_memo memo = {UINT32_MAX, 0.0};
    const node_env E = {P->b, &P->b->st[P->cur], P->g, web, P->x, P->v, P->pp, &L, &memo};
    double *tmp = nc->rtmp + RUN_GROUPS * sizeof(run_group) / sizeof(double);
    run_batch B = {(run_group *)nc->rtmp, (struct run_tmp *)tmp,
                   tmp + sizeof(run_tmp) / sizeof(double), 0,
                   nc->run_batch > 0 && nc->run_batch < RUN_GROUPS ? nc->run_batch : RUN_GROUPS};
    size_t k = *next;
    /* In locals: the stores of the passes would make the compiler load them again. */
    const ws_nseg *seg = nc->seg;
    const size_t nseg = nc->nseg;
    uint64_t tried = 0;
    /* The end of the row of the stretch before (0: none yet); stretches come in node order. */
    for (uint64_t row_end = 0; k < nseg && seg[k].n0 < n1; k++) {
        const ws_nseg *sg = &seg[k];
        tried += sg->c1 - sg->c0;
        if (nc->row_mark && sg->n0 >= row_end) { /* a row's first stretch */
            nc->row_mark[nc->nrow_mark++] = L.nl;
            row_end = (uint64_t)(sg->n0 / seg_block(web) + 1) * seg_block(web);
        }
        if (sg->run)
            contacts_run(&E, &B, cand, sg, h, share, fc);
        else
            contacts_general(&E, cand + sg->c0, sg->c1 - sg->c0);
    }
    *checks += tried;
    *next = k;
    run_flush(&E, &B, h, share, fc);
    act_apply(&E, h, share, fc);
    nc->act_nl = L.nl; /* the loads wait for ws_node_loads */
    node_prefetch(web, cand, k, n1);
}

void ws_node_substep(ws_node_contact *nc)
{
    nc->rface_gen++; /* the runs' faces are taken afresh */
    nc->act_nl = 0;
}

size_t ws_node_first_segment(const ws_node_contact *nc, uint32_t n0)
{
    size_t lo = 0, hi = nc->nseg;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (nc->seg[mid].n0 < n0)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

int ws_node_lane_scratch(ws_mem *mem, ws_node_contact *lane, const ws_node_contact *nc, uint32_t n,
                         size_t ncand)
{
    if (ws_node_scratch(mem, lane, ncand) != 0 || rtmp_reserve(mem, lane, n) != 0)
        return -1;
    return rface_reserve(mem, lane, nc->rface_cap);
}

int ws_node_scratch(ws_mem *mem, ws_node_contact *nc, size_t ncand)
{
    /* Four more than every candidate, a multiple of four (act_apply's passes run on whole
     * groups of four); an odd number of cache lines, so that the id arrays' starts fall in
     * different sets of the first-level cache. Grown by half at least: the candidates of a
     * web being wrapped grow step by step, and each new room is cleared. */
    if (ncand + 4 <= nc->act_cap)
        return 0;
    const size_t grown = nc->act_cap + nc->act_cap / 2,
                 least = ncand + 4 > grown ? ncand + 4 : grown;
    const size_t need = (((least + 7) / 8) | 1) * 8;
    /* The new room is taken before the old is let go: out of memory, the web keeps the room it
     * had, of the size it had (a restore that fails leaves the world as it was). The ids' four
     * arrays follow the doubles' in one block. */
    double *act = ws_mem_calloc(mem, need, ACT_BYTES);
    if (!act)
        return -1;
    ws_mem_free(mem, nc->act, nc->act_cap * ACT_BYTES);
    nc->act = act;
    nc->act_id = (uint32_t *)(act + need * ACT_ARRAYS);
    nc->act_cap = need;
    return 0;
}

void ws_node_scratch_free(ws_mem *mem, ws_node_contact *nc)
{
    ws_mem_free(mem, nc->act, nc->act_cap * ACT_BYTES);
    ws_mem_free(mem, nc->rtmp, nc->rtmp_cap * sizeof(double));
    ws_mem_free(mem, nc->rface, nc->rface_cap * sizeof *nc->rface);
    nc->rface = NULL;
    nc->act = nc->rtmp = NULL;
    nc->act_id = NULL;
    nc->act_cap = nc->rtmp_cap = nc->rface_cap = 0;
}

/* ---- one candidate through its full tests, for the implicit film (contact/node_jacobian.c) */

int ws_node_touch(const ws_node_pass *P, const ws_web *web, const ws_ncand *c, v3 x, double reach,
                  ws_node_touch_at *at)
{
    const ws_body_store *b = P->b;
    const node_env E = {.b = b, .st = &b->st[P->cur], .g = P->g};
    at->hi = b->layer[c->body] + web->layer;
    const double lo = -at->hi - b->shape[c->body]->inner;
    at->g = at->ta = at->tb = v3_make(0, 0, 0);
    if (!touch_of(&E, c, x, lo, at->hi + reach, at->hi, 0, &at->n, &at->d, at))
        return 0;
    /* A face's or rim's distance changes along its normal (g is left zero); a blended push's
     * as convex_push gives. */
    if (!(v3_dot(at->g, at->g) > 0.0))
        at->g = at->n;
    return 1;
}
