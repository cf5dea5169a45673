/* Web nodes near body faces: which node-face and node-edge pairs can touch (the candidates),
 * and when they must be found again. Their forces are evaluated in node_force.c. */
#include "contact/contact.h"
#include "contact/node.h"

#include <string.h>

/* The move test's budget (track_bodies, ws_node_moved), in sixteenths of the contact margin.
 * A full detection lists every node-feature pair within the layers and the margin; the list
 * holds while no node has come half the margin (COVER) closer to any near body, since that is
 * what it covers on either side. The half is spent as: a node's own move from where it was
 * found, in the reference body's frame (NODE); what its sub-steps' forces may add beyond the
 * state the test measures (SUBSTEP: with one sub-step the contacts see only that state, and
 * the node takes it too); and the deviations of two near bodies from their records at the
 * lever of their points (BODY each: the reference body's turn carries the node's frame, the
 * other body's its points), past which a body is re-based. A far body must not close the gap
 * it had by a node's whole move (NODE + SUBSTEP, a quarter): it is near when it is within it. */
enum { MOVE_PARTS = 16, MOVE_NODE = 3, MOVE_SUBSTEP = 1, MOVE_BODY = 2, MOVE_COVER = 8 };
_Static_assert(MOVE_NODE + MOVE_SUBSTEP + 2 * MOVE_BODY == MOVE_COVER,
               "the move test's parts must add up to the half margin the candidates cover");
/* Each part as a fraction of the margin (exact: sixteenths are binary fractions). */
#define MOVE_PART(k) ((double)(k) / MOVE_PARTS)

ws_node_contact *ws_node_contact_new(ws_mem *mem, uint32_t n)
{
    ws_node_contact *nc = ws_mem_calloc(mem, 1, sizeof *nc);
    if (!nc)
        return NULL;
    nc->seg_list = -1;
    int ok = ws_nodes_alloc(mem, &nc->xdet, n) & ws_nodes_alloc(mem, &nc->xep, n);
    ok &= (nc->moved = ws_mem_calloc(mem, n ? n : 1, sizeof(uint32_t))) != NULL;
    ok &= (nc->redo = ws_mem_calloc(mem, n ? n : 1, sizeof(uint8_t))) != NULL;
    ok &= (nc->cstart[0] = ws_mem_calloc(mem, 2 * ((size_t)n + 1), sizeof(size_t))) != NULL;
    nc->cstart[1] = nc->cstart[0] ? nc->cstart[0] + n + 1 : NULL; /* one block for both */
    if (ok)
        return nc;
    ws_node_contact_free(mem, nc, n);
    return NULL;
}

void ws_node_contact_free(ws_mem *mem, ws_node_contact *nc, uint32_t n)
{
    if (!nc)
        return;
    for (int k = 0; k < 2; k++)
        ws_mem_free(mem, nc->cand[k].c, nc->cand[k].cap * sizeof(ws_ncand));
    ws_mem_free(mem, nc->cstart[0], 2 * ((size_t)n + 1) * sizeof(size_t));
    ws_nodes_free(mem, &nc->xdet, n);
    ws_nodes_free(mem, &nc->xep, n);
    ws_mem_free(mem, nc->moved, (n ? n : 1) * sizeof(uint32_t));
    ws_mem_free(mem, nc->redo, (n ? n : 1) * sizeof(uint8_t));
    ws_mem_free(mem, nc->cbody, nc->cbody_cap);
    ws_mem_free(mem, nc->track, nc->track_cap * sizeof(ws_track));
    ws_mem_free(mem, nc->fresh.c, nc->fresh.cap * sizeof(ws_ncand));
    ws_mem_free(mem, nc->seg, nc->seg_cap * sizeof(ws_nseg));
    ws_node_scratch_free(mem, nc);
    ws_mem_free(mem, nc, sizeof *nc);
}

/* 1 when p lies in the open box (lo, hi) grown by e on every side, else 0; without branches,
 * so that the loops over nodes run on vectors. */
static inline uint64_t inside_box(v3 p, v3 lo, v3 hi, double e)
{
    return (uint64_t)((p.x > lo.x - e) & (p.x < hi.x + e) & (p.y > lo.y - e) & (p.y < hi.y + e) &
                      (p.z > lo.z - e) & (p.z < hi.z + e));
}

/* The box of the web's nodes x. */
static void web_box(const ws_web *web, ws_nodes3 x, v3 *lo, v3 *hi)
{
    *lo = *hi = nodes_get(x, 0);
    for (uint32_t i = 1; i < web->n; i++) {
        *lo = v3_min(*lo, nodes_get(x, i));
        *hi = v3_max(*hi, nodes_get(x, i));
    }
}

/* Largest distance from p to a corner of the box (lo, hi). */
static double far_corner(v3 p, v3 lo, v3 hi)
{
    double dx = fmax(fabs(p.x - lo.x), fabs(p.x - hi.x));
    double dy = fmax(fabs(p.y - lo.y), fabs(p.y - hi.y));
    double dz = fmax(fabs(p.z - lo.z), fabs(p.z - hi.z));
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* How far from its CoG a point of body k can touch a node, whatever the web's shape: its
 * bounding sphere grown by the layers and the margin. */
static double sphere_lever(const ws_body_store *b, uint32_t k, const ws_web *web, double margin)
{
    return b->shape[k]->radius + b->layer[k] + web->layer + margin;
}

/* Body k's own axis j at state cur (global, a), its box along it grown by its layer and the
 * web's (lo, hi), and the CoG's coordinate on it (o): a point x lies a . x - o along it. */
typedef struct axis_span {
    v3 a;
    double lo, hi, o;
} axis_span;

static double v3_at(v3 v, int j)
{
    return j == 0 ? v.x : j == 1 ? v.y : v.z;
}

static axis_span body_span(const ws_body_store *b, int cur, uint32_t k, const ws_web *web, int j)
{
    const ws_shape *sh = b->shape[k];
    const double *A = b->A[k].m, grow = b->layer[k] + web->layer;
    const v3 a = v3_make(A[j], A[3 + j], A[6 + j]);
    return (axis_span){a, v3_at(sh->lo, j) - grow, v3_at(sh->hi, j) + grow,
                       v3_dot(a, b->st[cur].r[k])};
}

/* How far body k is from every node: the largest gap between the nodes and the body's box
 * (grown by the layers) along one of the body's three axes, with that axis. A tilted
 * platform's global box swells over a film it is far from; its own axes tell them apart. */
static double body_gap(const ws_body_store *b, int cur, uint32_t k, const ws_web *web, ws_nodes3 x,
                       ws_track *t)
{
    double best = -INFINITY;
    for (int j = 0; j < 3; j++) {
        const axis_span S = body_span(b, cur, k, web, j);
        double lo = INFINITY, hi = -INFINITY;
        for (uint32_t i = 0; i < web->n; i++) {
            double c = v3_dot(S.a, nodes_get(x, i)) - S.o;
            lo = c < lo ? c : lo;
            hi = c > hi ? c : hi;
        }
        double gap = fmax(lo - S.hi, S.lo - hi);
        if (gap > best) {
            best = gap;
            t->axis = j;
            t->lo = S.lo;
            t->hi = S.hi;
        }
    }
    return best;
}

/* The reference frame of a web's moves as the move test holds it (A, r, vr, wr, the conjugate
 * orientation pc; the rest zero): its reference body's at state cur, or the global frame. */
static ws_move_test ref_frame(const ws_body_store *b, int cur, const ws_web *web)
{
    const uint32_t k = web->contact->ref;
    if (k == UINT32_MAX)
        return (ws_move_test){.A = m3_identity(), .pc = qt_conj(qt_identity())};
    return (ws_move_test){.A = b->A[k],
                          .r = b->st[cur].r[k],
                          .vr = b->st[cur].v[k],
                          .wr = b->wg[k],
                          .pc = qt_conj(b->st[cur].p[k])};
}

/* Body t->body's record (rho, q) in the reference frame M, from its pose at state st. */
static void record_body(ws_track *t, const ws_body_state *st, const ws_move_test *M)
{
    t->rho = m3_tmul_v(&M->A, v3_sub(st->r[t->body], M->r));
    t->q = qt_mul(M->pc, st->p[t->body]);
}

/* How far a point of body t->body at `lever` + `far` from its CoG has come since its record,
 * relative to the reference frame M: its CoG's move plus its turn at that lever. */
static double body_move(const ws_track *t, const ws_body_state *st, const ws_move_test *M,
                        double far)
{
    const uint32_t k = t->body;
    v3 rho = m3_tmul_v(&M->A, v3_sub(st->r[k], M->r));
    double turn = v3_norm(qt_to_rotvec(qt_mul(qt_conj(t->q), qt_mul(M->pc, st->p[k]))));
    return v3_norm(v3_sub(rho, t->rho)) + turn * (t->lever + far);
}

/* Whether a far body that came d closer may reach a node within its gap: the node itself may
 * go a quarter of the margin (MOVE_NODE + MOVE_SUBSTEP) before it is found again. */
static int may_reach(double d, double gap, double margin)
{
    return d + MOVE_PART(MOVE_NODE + MOVE_SUBSTEP) * margin >= gap;
}

/* Nodes are turned to the reference frame REF_CHUNK at a time (ws_node_ref_nodes). Flags are
 * found FLAG_CHUNK nodes at a time as 64-bit values, as wide as the doubles they come from, then
 * narrowed to bytes: a loop that writes the bytes at once takes 32 nodes a vector iteration and
 * runs out of registers. */
enum { REF_CHUNK = 64, FLAG_CHUNK = 256 };

/* The rows of ws_node_ref_nodes' scratch: the nodes' global x, y, z; in the reference frame,
 * s; at the epoch, g; |s|^2. */
enum { T_X, T_S = 3, T_G = 6, T_L2 = 9, T_ROWS };

/* m nodes (rows T_X of t) to the reference frame M: s = A^T (x - r) into rows T_S, and their
 * place at nc's epoch, epoch_r + epoch_A s, into rows T_G, |s|^2 into row T_L2. On vectors. */
WS_VECTOR_LOOP
static void ref_chunk(size_t m, const ws_move_test *M, const ws_node_contact *nc,
                      double (*restrict t)[REF_CHUNK])
{
    const m3 A = M->A, E = nc->epoch_A;
    const v3 r = M->r, e = nc->epoch_r;
    for (size_t i = 0; i < m; i++) {
        v3 u = m3_tmul_v(&A, v3_sub(v3_make(t[T_X][i], t[T_X + 1][i], t[T_X + 2][i]), r));
        v3 g = v3_add(e, m3_mul_v(&E, u));
        t[T_S][i] = u.x;
        t[T_S + 1][i] = u.y;
        t[T_S + 2][i] = u.z;
        t[T_G][i] = g.x;
        t[T_G + 1][i] = g.y;
        t[T_G + 2][i] = g.z;
        t[T_L2][i] = v3_norm2(u);
    }
}

/* Gathered REF_CHUNK at a time, turned on vectors (ref_chunk), put back: the gather costs
 * little beside the search that follows every call. */
void ws_node_ref_nodes(ws_web *web, ws_nodes3 x, const ws_move_test *M, const uint32_t *only,
                       size_t count)
{
    ws_node_contact *nc = web->contact;
    double t[T_ROWS][REF_CHUNK], lever2 = nc->lever2;
    const size_t n = only ? count : web->n;
    for (size_t q0 = 0; q0 < n; q0 += REF_CHUNK) {
        const size_t m = n - q0 < REF_CHUNK ? n - q0 : (size_t)REF_CHUNK;
        for (size_t j = 0; j < m; j++) {
            const size_t i = only ? only[q0 + j] : q0 + j;
            t[T_X][j] = x.x[i];
            t[T_X + 1][j] = x.y[i];
            t[T_X + 2][j] = x.z[i];
        }
        ref_chunk(m, M, nc, t);
        for (size_t j = 0; j < m; j++) {
            const uint32_t i = only ? only[q0 + j] : (uint32_t)(q0 + j);
            nodes_set(nc->xdet, i, v3_make(t[T_S][j], t[T_S + 1][j], t[T_S + 2][j]));
            nodes_set(nc->xep, i, v3_make(t[T_G][j], t[T_G + 1][j], t[T_G + 2][j]));
            lever2 = t[T_L2][j] > lever2 ? t[T_L2][j] : lever2;
        }
    }
    nc->lever2 = lever2;
}

/* A full detection's record (ws_node_contact): the web's box and xdet from its nodes at state
 * cur, every body near the web or how far from it, with its pose then. 0, or -1 out of memory. */
static int track_bodies(const ws_node_step *S, ws_web *web)
{
    const ws_body_store *b = S->b;
    const ws_nodes3 x = web->x[S->cur];
    ws_node_contact *nc = web->contact;
    nc->ntrack = 0;
    nc->ref = UINT32_MAX;
    if (web->n == 0)
        return 0;
    if (ws_array_reserve(S->mem, (void **)&nc->track, &nc->track_cap, b->slots + 1,
                         sizeof *nc->track) != 0)
        return -1;
    web_box(web, x, &nc->box_lo, &nc->box_hi);
    /* Near: a body that comes within the distance a node may still go before it is found
     * again (a quarter of the margin, ws_node_moved) with the layers. */
    double heaviest = -1.0;
    for (uint32_t k = 0; k < b->slots; k++) {
        if (!b->alive[k])
            continue;
        ws_track *t = &nc->track[nc->ntrack++];
        t->body = k;
        t->gap = body_gap(b, S->cur, k, web, x, t);
        t->near = t->gap <= MOVE_PART(MOVE_NODE + MOVE_SUBSTEP) * S->margin;
        /* A point of the body touches a node only within its bounding sphere grown by the
         * layers and the margin, and only in the web's box. */
        t->lever = fmin(sphere_lever(b, k, web, S->margin),
                        far_corner(b->st[S->cur].r[k], nc->box_lo, nc->box_hi));
        /* The reference: the heaviest dynamic body near the web (the load the film rides
         * on), else a kinematic one. */
        double m = b->type[k] == WS_BODY_DYNAMIC ? b->mass[k] : 0.0;
        if (t->near && m > heaviest) {
            heaviest = m;
            nc->ref = k;
        }
    }
    const ws_move_test M = ref_frame(b, S->cur, web);
    for (size_t q = 0; q < nc->ntrack; q++)
        record_body(&nc->track[q], &b->st[S->cur], &M);
    nc->epoch_A = M.A;
    nc->epoch_r = M.r;
    nc->epoch_q = qt_conj(M.pc);
    nc->lever2 = 0.0;
    ws_node_ref_nodes(web, x, &M, NULL, 0);
    return 0;
}

/* The flags of a group of e nodes (0 or 1, as 64-bit values) narrowed into their bytes of redo;
 * a group with none (any = 0) is cleared, not narrowed. */
static inline void put_flags(uint8_t *restrict redo, const uint64_t *restrict flag, size_t e,
                             int any)
{
    if (!any) {
        memset(redo, 0, e);
        return;
    }
    for (size_t i = 0; i < e; i++)
        redo[i] = (uint8_t)flag[i];
}

/* The per-node test of ws_node_moved on nodes [n0, n1): 1 in nc->redo for a node whose
 * measure reaches the bound (or is NaN), else 0; how many are flagged. With sub-steps (c > 0)
 * the measure is |u| + c |w|, u the node's move in the reference frame since it was found, w
 * its velocity relative to the reference body's point where it is. With one, it is the node's
 * distance from its place at the epoch (xep), a new epoch started first when renew asks (the
 * reference body's pose (A, r) now, each node's xep from its xdet): only a new epoch turns the
 * nodes. Straight-line code, on vectors. */
WS_VECTOR_LOOP
static size_t flag_nodes(ws_node_contact *nc, ws_nodes3 x, ws_nodes3 v, size_t n0, size_t n1)
{
    const ws_move_test M = nc->move;
    const double lim2 = M.lim * M.lim;
    uint64_t flag[FLAG_CHUNK];
    size_t count = 0;
    for (size_t i0 = n0; i0 < n1; i0 += FLAG_CHUNK) {
        const size_t e = n1 - i0 < FLAG_CHUNK ? n1 - i0 : (size_t)FLAG_CHUNK, before = count;
        const double *restrict qx = x.x + i0, *restrict qy = x.y + i0, *restrict qz = x.z + i0;
        const double *restrict vx = v.x + i0, *restrict vy = v.y + i0, *restrict vz = v.z + i0;
        const double *restrict sx = nc->xdet.x + i0, *restrict sy = nc->xdet.y + i0,
                               *restrict sz = nc->xdet.z + i0;
        double *restrict ox = nc->xep.x + i0, *restrict oy = nc->xep.y + i0,
                         *restrict oz = nc->xep.z + i0;
        if (M.c > 0.0) {
            for (size_t i = 0; i < e; i++) {
                v3 p = v3_sub(v3_make(qx[i], qy[i], qz[i]), M.r);
                v3 u = v3_sub(m3_tmul_v(&M.A, p), v3_make(sx[i], sy[i], sz[i]));
                v3 w = v3_sub(v3_sub(v3_make(vx[i], vy[i], vz[i]), M.vr), v3_cross(M.wr, p));
                uint64_t f = !(v3_norm(u) + M.c * v3_norm(w) < M.lim);
                flag[i] = f;
                count += f;
            }
        } else {
            if (M.renew)
                for (size_t i = 0; i < e; i++) {
                    v3 g = v3_add(M.r, m3_mul_v(&M.A, v3_make(sx[i], sy[i], sz[i])));
                    ox[i] = g.x;
                    oy[i] = g.y;
                    oz[i] = g.z;
                }
            for (size_t i = 0; i < e; i++) {
                uint64_t f = !(v3_norm2(v3_sub(v3_make(qx[i], qy[i], qz[i]),
                                               v3_make(ox[i], oy[i], oz[i]))) < lim2);
                flag[i] = f;
                count += f;
            }
        }
        put_flags(nc->redo + i0, flag, e, count != before);
    }
    return count;
}

/* The flagged nodes of [n0, n1) (flags 0 or 1) into `moved`, in order; how many. On a
 * little-endian machine thirty-two flags at a time, by the set bits of the words that hold
 * any: most steps flag few nodes, and those in runs. Elsewhere (and for the rest) one by one. */
static size_t collect_flagged(const uint8_t *flag, size_t n0, size_t n1, uint32_t *moved)
{
    size_t count = 0, i = n0;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    for (; i + 32 <= n1; i += 32) {
        uint64_t word[4];
        memcpy(word, flag + i, sizeof word);
        if (!(word[0] | word[1] | word[2] | word[3]))
            continue;
        /* Flag j is byte j - i - 8 w of word w: its lowest bit is set when it is 1. */
        for (size_t w = 0; w < 4; w++)
            for (uint64_t b = word[w]; b; b &= b - 1)
                moved[count++] = (uint32_t)(i + 8 * w + ws_lowest_bit(b) / 8);
    }
#endif
    for (; i < n1; i++) {
        moved[count] = (uint32_t)i;
        count += flag[i];
    }
    return count;
}

/* Flag (1 in `flag`) the nodes whose coordinates in body k's frame at state cur, A^T (x - r),
 * lie in its box grown by e. Straight-line code, on vectors, FLAG_CHUNK nodes at a time (those
 * of a group with none in the box are left as they are). */
WS_VECTOR_LOOP
static void flag_in_box(uint8_t *flag, ws_nodes3 x, size_t n, const ws_body_store *b, int cur,
                        uint32_t k, double e)
{
    const m3 A = b->A[k];
    const v3 r = b->st[cur].r[k], lo = b->shape[k]->lo, hi = b->shape[k]->hi;
    uint64_t in[FLAG_CHUNK];
    for (size_t i0 = 0; i0 < n; i0 += FLAG_CHUNK) {
        const size_t m = n - i0 < FLAG_CHUNK ? n - i0 : (size_t)FLAG_CHUNK;
        const double *restrict qx = x.x + i0, *restrict qy = x.y + i0, *restrict qz = x.z + i0;
        uint64_t any = 0;
        for (size_t i = 0; i < m; i++) {
            in[i] = inside_box(m3_tmul_v(&A, v3_sub(v3_make(qx[i], qy[i], qz[i]), r)), lo, hi, e);
            any |= in[i];
        }
        if (!any)
            continue;
        uint8_t *restrict f = flag + i0;
        for (size_t i = 0; i < m; i++)
            f[i] |= (uint8_t)in[i];
    }
}

/* Flag in nc->redo the nodes [n0, n1) (whole rows: a stretch lies in a row) that re-based body
 * t->body may meet: in its box grown by layers + margin now, or holding a candidate of it. */
static void rebase_flags(const ws_body_store *b, int cur, const ws_track *t, ws_web *web,
                         ws_nodes3 x, double margin, uint32_t n0, uint32_t n1)
{
    ws_node_contact *nc = web->contact;
    const uint32_t k = t->body;
    const ws_ncand *c = nc->cand[nc->list].c;
    flag_in_box(nc->redo + n0, (ws_nodes3){x.x + n0, x.y + n0, x.z + n0}, n1 - n0, b, cur, k,
                b->layer[k] + web->layer + margin);
    if (nc->seg_list != nc->list) {
        for (size_t q = nc->cstart[nc->list][n0]; q < nc->cstart[nc->list][n1]; q++)
            nc->redo[c[q].node] |= (uint8_t)(c[q].body == k);
        return;
    }
    /* By stretches: a run's candidates are of one body, its nodes flagged at once (a pass over
     * every candidate cost the reference case about 2 % of its step). */
    for (size_t s = ws_node_first_segment(nc, n0); s < nc->nseg && nc->seg[s].n0 < n1; s++) {
        const ws_nseg *sg = &nc->seg[s];
        if (sg->run && c[sg->c0].body == k)
            memset(nc->redo + sg->n0, 1, sg->n1 - sg->n0);
        else if (!sg->run)
            for (size_t q = sg->c0; q < sg->c1; q++)
                nc->redo[c[q].node] |= (uint8_t)(c[q].body == k);
    }
}

int ws_node_moved_begin(const ws_body_store *b, int cur, ws_web *web, double dt, double margin)
{
    ws_node_contact *nc = web->contact;
    const ws_body_state *st = &b->st[cur];
    /* A body made since the full detection: find every node again. */
    for (uint32_t k = 0, q = 0; k < b->slots; k++) {
        if (q < nc->ntrack && nc->track[q].body == k)
            q++;
        else if (b->alive[k])
            return -1;
    }
    ws_move_test *M = &nc->move;
    *M = ref_frame(b, cur, web);
    M->reach = far_corner(M->r, nc->box_lo, nc->box_hi) + margin;
    /* The contacts of this step see the bodies as they are now (state cur) and the nodes now
     * or, with sub-steps, where they go within the step; so a body's move relative to the
     * reference counts as it stands, its CoG's move plus its turn times its lever since its
     * record. A near one must stay within margin / 8 of its record. A far one closes on a node
     * by at most its own move twice (when the node was last found, in `gap`, and now) and the
     * node's (under a quarter margin): it must not reach the node.
     *
     * A near body past its bound is re-based rather than every node found again: its record
     * becomes its pose now, and the nodes in its box grown by the reach (layers + margin) are
     * found again now, like any node found. Any other node is farther than the reach from
     * every point of the body now; until it is found again the contacts see it within half the
     * margin of where it is now (a quarter of where it was found), and the body's points within
     * margin / 8 of theirs (at its bounding sphere's lever, wherever the nodes go): under 5/8
     * of the margin together, so the node cannot touch the body and needs no candidate of it.
     * The holders of its candidates are found again too: the body may have jumped, leaving
     * them outside its grown box with a candidate that no longer holds (a flag INSIDE). */
    for (size_t q = 0; q < nc->ntrack; q++) {
        ws_track *t = &nc->track[q];
        const double d = body_move(t, st, M, t->near ? 0.0 : M->reach);
        t->rebase = t->near && d >= MOVE_PART(MOVE_BODY) * margin;
        M->rebase |= t->rebase;
        if (t->rebase) { /* its record and lever from now (the lanes flag its nodes) */
            record_body(t, st, M);
            t->lever = sphere_lever(b, t->body, web, margin);
        }
        if (!t->near && may_reach(d, t->gap, margin))
            return -1;
    }
    /* Per node (flag_nodes): flagged when |u| + 1.5 |w| h_more reaches 3/16 of the margin,
     * h_more the time its sub-steps go beyond this state; with one sub-step the contacts see the
     * nodes only where the test measures them, and the bound is 1/4 (MOVE_SUBSTEP joins the
     * node's part). Either way a node stays within a quarter margin of where it was found
     * wherever the contacts see it. */
    const double lim = MOVE_PART(web->substeps > 1 ? MOVE_NODE : MOVE_NODE + MOVE_SUBSTEP) * margin;
    M->c = 1.5 * dt * (web->substeps - 1) / web->substeps;
    M->lim = lim;
    if (M->c <= 0.0) {
        /* Without a turn per node: the measure |u| = |A^T (x - r) - s|, s the node's xdet, is
         * |x - (r + A s)| (A is a rotation), and every node's xep holds g = epoch_r + epoch_A s
         * with the epoch's pose (ws_node_ref_nodes writes both for a node found since). g lies
         * within drift = |r - epoch_r| + turn sqrt(lever2) of r + A s, turn the angle between the
         * two orientations: |(epoch_A - A) s| = |(epoch_A A^T - I) A s| <= 2 sin(turn / 2) |s| <=
         * turn |s|, and lever2 bounds |s|^2 of every node found since the full detection. So
         * |u| <= |x - g| + drift, and a node is flagged when |x - g| reaches lim - drift: it stays
         * within lim of where it was found. A new epoch (the pose now, every g from its s, drift
         * 0) starts when the drift reaches lim / 8, so no node is flagged before it has moved 7/8
         * of the bound; it costs about what turning every node costs, and a load that rocks on its
         * film needs one every few steps. */
        const qt p = qt_conj(M->pc);
        const double turn = v3_norm(qt_to_rotvec(qt_mul(qt_conj(nc->epoch_q), p)));
        double drift = v3_norm(v3_sub(M->r, nc->epoch_r)) + turn * sqrt(nc->lever2);
        M->renew = !(drift < 0.125 * lim);
        if (M->renew) {
            nc->epoch_A = M->A;
            nc->epoch_r = M->r;
            nc->epoch_q = p;
            drift = 0.0;
        }
        M->lim = lim - drift;
    }
    return 0;
}

void ws_node_flag_lane(const ws_body_store *b, int cur, ws_web *web, ws_nodes3 x, ws_nodes3 v,
                       ws_node_lane *L)
{
    ws_node_contact *nc = web->contact;
    const size_t flagged = flag_nodes(nc, x, v, L->n0, L->n1);
    for (size_t q = 0; nc->move.rebase && q < nc->ntrack; q++)
        if (nc->track[q].rebase)
            rebase_flags(b, cur, &nc->track[q], web, x, L->margin, L->n0, L->n1);
    const int any = flagged || nc->move.rebase; /* a re-based body's nodes are not counted */
    L->count = any ? collect_flagged(nc->redo, L->n0, L->n1, nc->moved + L->n0) : 0;
    /* Each far body's least distance to them beyond its grown box, on its axis (body_gap). */
    for (size_t q = 0; q < nc->ntrack; q++) {
        const ws_track *t = &nc->track[q];
        const axis_span S = body_span(b, cur, t->body, web, t->axis);
        L->least[q] = INFINITY;
        for (size_t m = L->n0; !t->near && m < L->n0 + L->count; m++) {
            const double c = v3_dot(S.a, nodes_get(x, nc->moved[m])) - S.o;
            const double g = fmax(c - S.hi, S.lo - c);
            L->least[q] = g < L->least[q] ? g : L->least[q];
        }
    }
}

long ws_node_moved_end(const ws_body_store *b, int cur, ws_web *web, ws_nodes3 x, double margin,
                       const ws_node_lane *lanes, uint32_t nlanes)
{
    ws_node_contact *nc = web->contact;
    const ws_body_state *st = &b->st[cur];
    const ws_move_test *M = &nc->move;
    /* The lanes' flagged nodes joined in lane order, which is node order. */
    long count = 0;
    for (uint32_t i = 0; i < nlanes; i++) {
        memmove(nc->moved + count, nc->moved + lanes[i].n0, lanes[i].count * sizeof(uint32_t));
        count += (long)lanes[i].count;
    }
    /* The moved nodes are found again now, from where they are: each far body's gap becomes
     * the least of what it was and their distances beyond its box now (the lanes'), less its
     * move so far. */
    for (size_t q = 0; count && q < nc->ntrack; q++) {
        ws_track *t = &nc->track[q];
        if (t->near)
            continue;
        double least = INFINITY;
        for (uint32_t i = 0; i < nlanes; i++)
            least = lanes[i].least[q] < least ? lanes[i].least[q] : least;
        const double d = body_move(t, st, M, M->reach);
        if (least - d < t->gap)
            t->gap = least - d;
        if (may_reach(d, t->gap, margin))
            return -1;
    }
    return count;
}

/* The end of node m's candidates in the list c (n of them, sorted by node), from f on. */
static size_t run_end(const ws_ncand *c, size_t n, size_t f, uint32_t m)
{
    for (; f < n && c[f].node == m; f++)
        ;
    return f;
}

void ws_node_index(const ws_ncand *c, size_t nc, uint32_t n, size_t *start)
{
    size_t q = 0;
    for (uint32_t i = 0; i < n; i++) {
        start[i] = q;
        q = run_end(c, nc, q, i);
    }
    start[n] = nc;
}

/* Whether the len candidates at a + i and b + j (of one node) are alike: mostly one, compared
 * in place. The lists may be NULL when len is 0. */
static inline int same_run(const ws_ncand *a, size_t i, const ws_ncand *b, size_t j, size_t len)
{
    if (len == 0)
        return 1;
    if (len == 1)
        return a[i].body == b[j].body && a[i].feat == b[j].feat && a[i].local == b[j].local;
    return !memcmp(a + i, b + j, len * sizeof *a);
}

int ws_node_same(const ws_node_found *F, const size_t *start, const ws_ncand *old)
{
    const ws_ncand *fresh = F->fresh->c;
    size_t f = 0;
    for (size_t q = 0; q < F->count; q++) {
        const uint32_t m = F->nodes[q];
        const size_t a = start[m], len = start[m + 1] - a, f1 = run_end(fresh, F->fresh->n, f, m);
        if (f1 - f != len || !same_run(old, a, fresh, f, len))
            return 0;
        f = f1;
    }
    return 1;
}

long ws_node_merge_plan(ws_mem *mem, const ws_node_found *F, const ws_ncand_list *old, ws_nmerge *M,
                        ws_ncand_list *out, uint32_t *changed)
{
    if (ws_array_reserve(mem, (void **)&out->c, &out->cap, old->n + F->fresh->n + 1,
                         sizeof *out->c) != 0)
        return -1;
    ws_ncand *fresh = M->fresh = F->fresh->c;
    M->old = old;
    size_t f = 0, g = 0, c = 0, shift = 0; /* the changed nodes' shift so far, modulo 2^64 */
    for (size_t q = 0; q < F->count; q++) {
        const uint32_t m = F->nodes[q];
        const size_t e = M->ostart[m], len = M->ostart[m + 1] - e, f0 = f;
        f = run_end(fresh, F->fresh->n, f, m);
        if (len == f - f0 && same_run(old->c, e, fresh, f0, len))
            continue;
        if (f > f0) /* after those of the changed nodes before it */
            memmove(fresh + g, fresh + f0, (f - f0) * sizeof *fresh);
        changed[c] = m;
        M->place[c++] = (ws_nplace){g, e + shift};
        g += f - f0;
        shift += (f - f0) - len;
    }
    M->place[c].fresh = g;
    M->nodes = changed;
    M->count = c;
    M->out = out;
    out->n = old->n + shift;
    return (long)c;
}

void ws_node_merge_range(const ws_nmerge *M, uint32_t n0, uint32_t n1)
{
    const size_t *os = M->ostart;
    const ws_ncand_list *old = M->old, *out = M->out;
    size_t j = 0; /* the first changed node from n0 on (they are few) */
    while (j < M->count && M->nodes[j] < n0)
        j++;
    for (uint32_t i = n0;; j++) {
        /* Nodes [i, m) keep their candidates, shifted by what the changed nodes before them
         * added (all of them: past the last). */
        const uint32_t m = j < M->count && M->nodes[j] < n1 ? M->nodes[j] : n1;
        const size_t shift = j < M->count ? M->place[j].at - os[M->nodes[j]] : out->n - old->n;
        if (os[m] > os[i])
            memcpy(out->c + (os[i] + shift), old->c + os[i], (os[m] - os[i]) * sizeof *out->c);
        for (uint32_t q = i; q < m; q++) /* modulo 2^64: the shift may be negative */
            M->nstart[q] = os[q] + shift;
        if (m == n1)
            break;
        const ws_nplace *P = &M->place[j];
        M->nstart[m] = P->at;
        if (P[1].fresh > P->fresh)
            memcpy(out->c + P->at, M->fresh + P->fresh, (P[1].fresh - P->fresh) * sizeof *out->c);
        i = m + 1;
    }
    if (n1 == M->nn)
        M->nstart[n1] = out->n;
}

/* The candidates of a node against body shape sh just listed, out[n0, n): marked when they are
 * a corner (WS_NCAND_CORNER, node.h). Neither of its faces is one the node is well inside of
 * (convex_candidates lists no edge of such a face). */
static void mark_corner(const ws_shape *sh, ws_ncand *out, size_t n0, size_t n)
{
    if (n - n0 != 3 || !sh->convex || !sh->flat)
        return;
    const uint32_t a = out[n0].local, z = out[n0 + 1].local, e = out[n0 + 2].local;
    if (((a | z) & (WS_NCAND_EDGE | WS_NCAND_INSIDE)) || !(e & WS_NCAND_EDGE))
        return;
    const ws_edge *E = &sh->edges[e & ~WS_NCAND_FLAGS];
    const uint32_t fa = a & ~WS_NCAND_FLAGS, fz = z & ~WS_NCAND_FLAGS;
    if ((E->f1 == fa && E->f2 == fz) || (E->f1 == fz && E->f2 == fa))
        out[n0].local |= WS_NCAND_CORNER;
}

/* ---- the search, FIND_CHUNK nodes at a time: per body, in slot order, those in its grown box
 * (find_near); on a convex body of at most WS_NCAND_FACES faces their plane distances and face
 * tests on vectors (find_faces), any other body node by node (general_candidates); listed node
 * by node, and for a node body by body (docs/design.md, deviation (f)). */
enum { FIND_CHUNK = 64 };

/* A body near a group of nodes: its slot, its reach (the layers and the margin), how many of the
 * group's nodes lie in its grown box and where their values are in the scratch: their places
 * in the group at find_node + node; at find_val + val, FIND_CHUNK apart, their body-frame x,
 * y, z, the largest plane distance D, then their distance to each face's plane; at find_mask +
 * mask, FIND_CHUNK apart, the masks M_*. general: searched node by node, without values. next:
 * the next of its nodes to list. */
typedef struct ws_find_body {
    uint32_t body, count, next;
    int general;
    double reach;
    size_t node, val, mask;
} ws_find_body;

enum { V_X, V_Y, V_Z, V_D, V_FACES }; /* the values of a node, V_FACES + f: face f */
enum { M_LOCAL, M_PASS, M_BOXES, M_OUT, M_NEAR, M_ARRAYS };
/* M_LOCAL: 1 when the node lies in the body's own box grown by the reach (else it has no
 * candidate of the body); M_PASS: the faces it is a candidate of (within reach of it along their
 * normals, within the margin of the outermost one, its projection on the plane within reach of
 * the face's box); M_BOXES: the faces whose box, grown by the reach, holds it; M_OUT: of the
 * faces in M_PASS, those it is not well inside of (see convex_candidates); M_NEAR: the faces
 * whose plane it is not a margin or more behind. */

/* hit[j] = 1 when node j of the group (rows x, y, z of p) lies in the open box (lo, hi)
 * grown by e, else 0; how many do. */
WS_VECTOR_LOOP
static size_t find_near(uint64_t *restrict hit, double (*restrict p)[FIND_CHUNK], size_t m, v3 lo,
                        v3 hi, double e)
{
    size_t count = 0;
    for (size_t j = 0; j < m; j++) {
        hit[j] = inside_box(v3_make(p[0][j], p[1][j], p[2][j]), lo, hi, e);
        count += hit[j];
    }
    return count;
}

/* The values and masks of m nodes against a convex body of shape sh at pose (A, r) (see
 * ws_find_body); val holds their global positions in its first three arrays, which become their
 * body-frame ones. The arithmetic of the one-node search, operation by operation. */
WS_VECTOR_LOOP
static void find_faces(const ws_shape *sh, const m3 *A, v3 r, double reach, double margin, size_t m,
                       double *val, uint64_t *mask)
{
    const m3 At = *A;
    double *restrict sx = val + V_X * FIND_CHUNK, *restrict sy = val + V_Y * FIND_CHUNK,
                     *restrict sz = val + V_Z * FIND_CHUNK, *restrict D = val + V_D * FIND_CHUNK;
    uint64_t *restrict local = mask + M_LOCAL * FIND_CHUNK,
                       *restrict pass = mask + M_PASS * FIND_CHUNK,
                       *restrict boxes = mask + M_BOXES * FIND_CHUNK,
                       *restrict near = mask + M_NEAR * FIND_CHUNK;
    for (size_t j = 0; j < m; j++) {
        v3 s = m3_tmul_v(&At, v3_sub(v3_make(sx[j], sy[j], sz[j]), r));
        sx[j] = s.x;
        sy[j] = s.y;
        sz[j] = s.z;
        local[j] = inside_box(s, sh->lo, sh->hi, reach);
        D[j] = -INFINITY;
        pass[j] = boxes[j] = near[j] = 0;
    }
    for (uint32_t f = 0; f < sh->face_count; f++) {
        const ws_face F = sh->faces[f];
        double *restrict dg = val + (V_FACES + f) * FIND_CHUNK;
        for (size_t j = 0; j < m; j++) {
            v3 s = v3_make(sx[j], sy[j], sz[j]);
            double d = v3_dot(F.normal, s) - F.offset;
            dg[j] = d;
            D[j] = d > D[j] ? d : D[j];
            near[j] |= (uint64_t)(!(d <= -margin)) << f;
            boxes[j] |= inside_box(s, F.lo, F.hi, reach) << f;
        }
    }
    const double deep = -reach - sh->inner;
    for (uint32_t f = 0; f < sh->face_count; f++) {
        const double *restrict dg = val + (V_FACES + f) * FIND_CHUNK;
        for (size_t j = 0; j < m; j++) {
            double d = dg[j];
            pass[j] |= (uint64_t)((d > deep) & (d < reach) & (d >= D[j] - margin)) << f;
        }
    }
    /* The faces that pass for some node: for every node, the projection's test and whether it
     * lies well inside the outline (convex_candidates); what they say of a node a face does not
     * pass for is not read. */
    uint64_t any = 0, *restrict out = mask + M_OUT * FIND_CHUNK;
    for (size_t j = 0; j < m; j++) {
        any |= pass[j];
        out[j] = 0;
    }
    for (; any; any &= any - 1) {
        const uint32_t f = ws_lowest_bit(any);
        const ws_face F = sh->faces[f];
        const double *restrict df = val + (V_FACES + f) * FIND_CHUNK;
        const uint64_t drop = ~((uint64_t)1 << f);
        for (size_t j = 0; j < m; j++) {
            v3 s = v3_madd(v3_make(sx[j], sy[j], sz[j]), F.normal, -df[j]);
            pass[j] &= drop | inside_box(s, F.lo, F.hi, reach) << f;
        }
        /* The projection on f's plane lies dg - df c out of face o's plane: dg itself for a
         * face square to f (c = 0, and df is finite), whose test is then the node's own
         * (M_NEAR), taken for all those faces at once. */
        uint64_t square = 0;
        for (uint32_t o = 0; o < sh->face_count; o++) {
            if (o == f)
                continue;
            const double c = v3_dot(sh->faces[o].normal, F.normal);
            if (c == 0.0) {
                square |= (uint64_t)1 << o;
                continue;
            }
            const double *restrict dg = val + (V_FACES + o) * FIND_CHUNK;
            for (size_t j = 0; j < m; j++)
                out[j] |= (uint64_t)(!(dg[j] - df[j] * c <= -margin)) << f;
        }
        if (square)
            for (size_t j = 0; j < m; j++)
                out[j] |= (uint64_t)((near[j] & square) != 0) << f;
    }
}

/* Room in L for every face and edge of shape sh past its end: one check, not one per
 * candidate. The list's candidates, or NULL when out of memory (or of room, mem NULL). */
static ws_ncand *room_for(ws_mem *mem, ws_ncand_list *L, const ws_shape *sh)
{
    const size_t room = L->n + sh->face_count + sh->edge_count;
    if (room > L->cap &&
        (!mem || ws_array_reserve(mem, (void **)&L->c, &L->cap, room, sizeof *L->c) != 0))
        return NULL;
    return L->c;
}

/* Whether edge E of shape sh, the rounded rim of the contact layer, lies within reach of the
 * node at s (body frame), a check counted when s is in the edge's grown box. The segment's
 * parameter is clamped to it: a node past an end may slide along the edge into its span before
 * it is found again. */
static int near_edge(const ws_shape *sh, const ws_edge *E, v3 s, double reach, uint64_t *checks)
{
    if (!inside_box(s, E->lo, E->hi, reach))
        return 0;
    (*checks)++;
    v3 a = sh->vertices[E->a], d = v3_sub(sh->vertices[E->b], a);
    double t = v3_dot(v3_sub(s, a), d) / v3_dot(d, d);
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    return v3_norm2(v3_sub(s, v3_madd(a, d, t))) < reach * reach;
}

/* Node i, the c-th of body fb's nodes, against that convex body, from its values and masks
 * (find_faces): the faces and edges the general search below would list, in the same order,
 * into L. Only here may a face candidate be marked INSIDE. */
static int convex_candidates(const ws_node_step *S, const ws_find_body *fb, uint32_t c, uint32_t i,
                             ws_ncand_list *L)
{
    const uint32_t k = fb->body;
    const ws_shape *sh = S->b->shape[k];
    const ws_node_geom *g = S->g;
    const double *v = g->find_val + fb->val + c;
    const uint64_t *mk = g->find_mask + fb->mask + c;
    const v3 s = v3_make(v[V_X * FIND_CHUNK], v[V_Y * FIND_CHUNK], v[V_Z * FIND_CHUNK]);
    const uint64_t boxes = mk[M_BOXES * FIND_CHUNK], outside = mk[M_OUT * FIND_CHUNK];
    const size_t n0 = L->n;
    *S->checks += sh->face_count;
    ws_ncand *o = room_for(S->mem, L, sh);
    if (!o)
        return -1;
    size_t q = n0;
    /* Well inside a face's outline: its projection on the plane lies a margin or more behind
     * every other face's plane (those planes bound the face on a convex body, and a plane
     * distance never exceeds the distance within the face's plane). Nodes and bodies move less
     * than half the margin relative to each other until the candidates are found again. */
    for (uint64_t pass = mk[M_PASS * FIND_CHUNK]; pass; pass &= pass - 1) {
        const uint32_t f = ws_lowest_bit(pass);
        o[q++] = (ws_ncand){i, k, g->face_base[k] + f,
                            f | (((outside >> f) & 1u) ? 0u : WS_NCAND_INSIDE)};
    }
    L->n = q;
    /* An edge's box lies in the boxes of both its faces, so an edge within reach of the node
     * needs two of them: most nodes, over the middle of a face, have at most one and skip the
     * edges. */
    if (!(boxes & (boxes - 1)))
        return 0;
    /* Nor can an edge of a face the node is well inside of hold it (docs/design.md, deviation
     * (f)): dropped, the node is a face's alone and may join a run. */
    const uint64_t near = boxes & ~(mk[M_PASS * FIND_CHUNK] & ~outside);
    for (uint32_t e = 0; e < sh->edge_count; e++) {
        const ws_edge *E = &sh->edges[e];
        if (((near >> E->f1) & (near >> E->f2) & 1u) && near_edge(sh, E, s, fb->reach, S->checks))
            o[q++] = (ws_ncand){i, k, g->edge_base[k] + e, e | WS_NCAND_EDGE};
    }
    L->n = q;
    mark_corner(sh, o, n0, q);
    return 0;
}

/* Node i at p (global) against body fb of any shape, feature by feature, into L. */
static int general_candidates(const ws_node_step *S, const ws_find_body *fb, uint32_t i, v3 p,
                              ws_ncand_list *L)
{
    const uint32_t k = fb->body;
    const ws_shape *sh = S->b->shape[k];
    const double reach = fb->reach;
    v3 s = m3_tmul_v(&S->b->A[k], v3_sub(p, S->b->st[S->cur].r[k]));
    if (!inside_box(s, sh->lo, sh->hi, reach))
        return 0;
    ws_ncand *o = room_for(S->mem, L, sh);
    if (!o)
        return -1;
    const size_t n0 = L->n;
    size_t q = n0;
    /* On a convex body a node touches face f only while f is the face whose plane it is
     * farthest out of (the largest signed distance D); until the next detection d_f - D
     * changes by less than the margin, so faces further behind are no candidates (the side
     * faces next to the one a node lies on; docs/design.md, deviation (f)). */
    double D = -INFINITY;
    if (sh->convex)
        for (uint32_t f = 0; f < sh->face_count; f++) {
            double d = v3_dot(sh->faces[f].normal, s) - sh->faces[f].offset;
            D = d > D ? d : D;
        }
    for (uint32_t f = 0; f < sh->face_count; f++) {
        const ws_face *fc = &sh->faces[f];
        (*S->checks)++;
        double d = v3_dot(fc->normal, s) - fc->offset;
        /* Depth counts along the normal only: the point's projection on the face's plane must
         * lie within reach of the face. */
        if (d > -reach - sh->inner && d < reach && d >= D - S->margin &&
            inside_box(v3_madd(s, fc->normal, -d), fc->lo, fc->hi, reach))
            o[q++] = (ws_ncand){i, k, S->g->face_base[k] + f, f};
    }
    for (uint32_t e = 0; e < sh->edge_count; e++)
        if (near_edge(sh, &sh->edges[e], s, reach, S->checks))
            o[q++] = (ws_ncand){i, k, S->g->edge_base[k] + e, e | WS_NCAND_EDGE};
    L->n = q;
    mark_corner(sh, o, n0, q);
    return 0;
}

/* The values a node takes against a body of shape sh searched on vectors (find_faces): its
 * place, its largest plane distance and one distance per face; 0 for a body searched node by
 * node (general_candidates), whose faces do not fit the masks. */
static size_t face_values(const ws_shape *sh)
{
    return sh->convex && sh->face_count <= WS_NCAND_FACES
               ? (V_FACES + sh->face_count) * (size_t)FIND_CHUNK
               : 0;
}

int ws_node_find_scratch(const ws_body_store *b, ws_node_geom *g)
{
    size_t most_val = 1, most_mask = 1;
    for (uint32_t k = 0; k < b->slots; k++) {
        const size_t nv = b->alive[k] ? face_values(b->shape[k]) : 0;
        most_val += nv;
        most_mask += nv ? M_ARRAYS * (size_t)FIND_CHUNK : 0;
    }
    g->find = ws_arena_alloc(g->arena, (b->slots + 1) * sizeof *g->find);
    g->find_node = ws_arena_alloc(g->arena, (b->slots + 1) * FIND_CHUNK * sizeof(uint32_t));
    g->find_val = ws_arena_alloc(g->arena, most_val * sizeof(double));
    g->find_mask = ws_arena_alloc(g->arena, most_mask * sizeof(uint64_t));
    return g->find && g->find_node && g->find_val && g->find_mask ? 0 : -1;
}

/* The bodies near a group of m nodes at p (global x, y, z rows), in slot order, into g->find,
 * each with the group's nodes in its box grown by the web's layer and half the margin (they
 * move less than that before they are found again); how many. A body with no node of any group
 * in its box has no candidate: the others are marked in web->cbody. Per convex body, on
 * vectors: the nodes in its frame, their plane distances and their faces' masks. */
static size_t near_bodies(const ws_node_step *S, ws_web *web, double (*p)[FIND_CHUNK], size_t m)
{
    const ws_body_store *b = S->b;
    ws_node_geom *g = S->g;
    const double pad = web->layer + 0.5 * S->margin;
    uint64_t hit[FIND_CHUNK];
    size_t nb = 0, nnode = 0, nval = 0, nmask = 0;
    for (uint32_t k = 0; k < b->slots; k++) {
        if (!b->alive[k])
            continue;
        const uint32_t c = (uint32_t)find_near(hit, p, m, b->lo[k], b->hi[k], pad);
        if (!c)
            continue;
        web->contact->cbody[k] = 1;
        uint32_t *nd = g->find_node + nnode;
        for (size_t j = 0, e = 0; j < m; j++) {
            nd[e] = (uint32_t)j;
            e += hit[j];
        }
        const size_t nv = face_values(b->shape[k]);
        ws_find_body *fb = &g->find[nb++];
        *fb = (ws_find_body){k,     c,    0,    nv == 0, b->layer[k] + web->layer + S->margin,
                             nnode, nval, nmask};
        for (uint32_t q = 0; nv && q < c; q++)
            for (int j = 0; j < 3; j++)
                g->find_val[nval + (V_X + j) * FIND_CHUNK + q] = p[j][nd[q]];
        if (nv)
            find_faces(b->shape[k], &b->A[k], b->st[S->cur].r[k], fb->reach, S->margin, c,
                       g->find_val + nval, g->find_mask + nmask);
        nnode += c;
        nval += nv;
        nmask += nv ? M_ARRAYS * (size_t)FIND_CHUNK : 0;
    }
    return nb;
}

/* Node candidates of a web at state S->cur (the node-feature pairs within the layers + margin)
 * of the nodes listed (all when NULL), sorted by node, into L; by S->search when set (1: those
 * the committed list holds). 0, or -1 when out of memory. */
static int find_candidates(const ws_node_step *S, ws_web *web, const uint32_t *nodes, size_t count,
                           ws_ncand_list *L)
{
    ws_node_contact *nc = web->contact;
    L->n = 0;
    if (ws_array_reserve(S->mem, (void **)&nc->cbody, &nc->cbody_cap, S->b->slots + 1, 1) != 0)
        return -1;
    if (!nodes) /* a full search: the list holds no other candidates */
        memset(nc->cbody, 0, nc->cbody_cap);
    count = nodes ? count : web->n;
    if (S->search && count)
        return S->search(S, web, nodes, count, L);
    if (nodes) /* found again now: their moves count from here */
        ws_node_to_ref(web, web->x[S->cur], nodes, count);
    return count && ws_node_find_scratch(S->b, S->g) ? -1
                                                     : ws_node_find(S, web, nodes, 0, count, L);
}

int ws_node_find(const ws_node_step *S, ws_web *web, const uint32_t *nodes, uint32_t first,
                 size_t count, ws_ncand_list *L)
{
    const ws_nodes3 x = web->x[S->cur];
    ws_node_geom *g = S->g;
    double p[3][FIND_CHUNK];
    for (size_t q0 = 0; q0 < count; q0 += FIND_CHUNK) {
        const size_t m = count - q0 < FIND_CHUNK ? count - q0 : (size_t)FIND_CHUNK;
        for (size_t j = 0; j < m; j++) {
            uint32_t i = nodes ? nodes[q0 + j] : first + (uint32_t)(q0 + j);
            p[0][j] = x.x[i];
            p[1][j] = x.y[i];
            p[2][j] = x.z[i];
        }
        const size_t nb = near_bodies(S, web, p, m);
        /* Node by node (the order the sub-steps take them in), against each body near it. */
        for (size_t j = 0; j < m; j++) {
            const uint32_t i = nodes ? nodes[q0 + j] : first + (uint32_t)(q0 + j);
            for (size_t q = 0; q < nb; q++) {
                ws_find_body *fb = &g->find[q];
                if (fb->next == fb->count || g->find_node[fb->node + fb->next] != j)
                    continue;
                const uint32_t c = fb->next++;
                if (fb->general
                        ? general_candidates(S, fb, i, v3_make(p[0][j], p[1][j], p[2][j]), L)
                        : g->find_mask[fb->mask + M_LOCAL * FIND_CHUNK + c] &&
                              convex_candidates(S, fb, c, i, L))
                    return -1;
            }
        }
    }
    return 0;
}

int ws_node_geometry(const ws_body_store *b, ws_node_geom *g)
{
    const size_t ns = b->slots + 1;
    uint32_t *base = ws_arena_alloc(g->arena, 3 * ns * sizeof *base);
    g->ready = ws_arena_calloc(g->arena, ns, 1);
    if (!base || !g->ready)
        return -1;
    g->face_base = base;
    g->tri_base = base + ns;
    g->edge_base = base + 2 * ns;
    uint32_t nf = 0, nt = 0, ne = 0;
    for (size_t k = 0; k < b->slots; k++) {
        if (!b->alive[k])
            continue;
        const ws_shape *sh = b->shape[k];
        g->face_base[k] = nf;
        g->tri_base[k] = nt;
        g->edge_base[k] = ne;
        nf += sh->face_count;
        nt += sh->triangle_count;
        ne += sh->edge_count;
    }
    g->face = ws_arena_alloc(g->arena, (nf + 1) * sizeof *g->face);
    g->tri = ws_arena_alloc(g->arena, (nt + 1) * sizeof *g->tri);
    g->edge = ws_arena_alloc(g->arena, (ne + 1) * sizeof *g->edge);
    return g->face && g->tri && g->edge ? 0 : -1;
}

/* Body k's faces, triangles and edges in the global frame at state cur. */
static void prepare_body(const ws_body_store *b, int cur, ws_node_geom *g, uint32_t k)
{
    const ws_shape *sh = b->shape[k];
    const m3 *A = &b->A[k];
    v3 r = b->st[cur].r[k];
    const uint32_t fo = g->face_base[k], to = g->tri_base[k], eo = g->edge_base[k];
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
    for (uint32_t e = 0; e < sh->edge_count; e++) {
        const ws_edge *E = &sh->edges[e];
        ws_wedge *o = &g->edge[eo + e];
        v3 a = sh->vertices[E->a], d = v3_sub(sh->vertices[E->b], a);
        o->p = v3_add(r, m3_mul_v(A, a));
        o->e = m3_mul_v(A, d);
        o->n1 = m3_mul_v(A, E->n1);
        o->n2 = m3_mul_v(A, E->n2);
        o->inv_e2 = 1.0 / v3_dot(d, d);
        o->c = v3_dot(o->n1, o->n2);
    }
}

void ws_node_prepare_some(const ws_body_store *b, int cur, ws_node_geom *g, const ws_web *web,
                          uint32_t first, uint32_t stride)
{
    ws_node_contact *nc = web->contact;
    const size_t m = nc->cbody_cap < b->slots ? nc->cbody_cap : b->slots;
    for (uint32_t k = first; k < m; k += stride)
        if (nc->cbody[k] && !g->ready[k] && b->alive[k]) {
            prepare_body(b, cur, g, k);
            g->ready[k] = 1;
        }
}

int ws_node_contact_begin(const ws_body_store *b, int cur, ws_web *web, double dt, double margin,
                          int all)
{
    ws_node_contact *nc = web->contact;
    nc->search_all = all || nc->refresh || ws_node_moved_begin(b, cur, web, dt, margin) < 0;
    return !nc->search_all;
}

/* The moved nodes' candidates found again (nc->fresh) and brought into the committed list `old`:
 * it serves again, uncopied, when they are those it holds (mostly so), else a merge into the other
 * list, `*list`, is planned, carried out and cut again in the blocks of the nodes that changed,
 * the rest left to the first sub-step's lanes (nc->merging). 0, or -1 when out of memory. */
static int search_moved(const ws_node_step *S, ws_web *web, size_t moved, int old, int *list)
{
    ws_node_contact *nc = web->contact;
    const ws_node_found F = {nc->moved, moved, &nc->fresh};
    const int found = find_candidates(S, web, nc->moved, moved, &nc->fresh);
    if (found < 0)
        return -1;
    if (found == 1 || ws_node_same(&F, nc->cstart[old], nc->cand[old].c)) {
        *list = old;
        return 0;
    }
    ws_nplace *room = ws_arena_alloc(S->g->arena, (moved + 1) * sizeof *room);
    nc->merge = (ws_nmerge){
        .ostart = nc->cstart[old], .nstart = nc->cstart[*list], .place = room, .nn = web->n};
    /* nc->moved keeps the nodes whose candidates changed. */
    nc->merging = room && ws_node_merge_plan(S->mem, &F, &nc->cand[old], &nc->merge,
                                             &nc->cand[*list], nc->moved) >= 0;
    return nc->merging ? ws_node_segments_merged(S->mem, web, &nc->merge, *list, old) : -1;
}

int ws_node_contact_update(const ws_node_step *S, ws_web *web, int *searched)
{
    ws_node_contact *nc = web->contact;
    /* All found again, or those of the nodes the move test flagged merged into the others:
     * either way the list holds every node-feature pair that can touch in this step, and the
     * result is that of finding them every step (tests/test_detection.c). */
    int list = nc->list, all = nc->search_all;
    long moved = 0;
    nc->merging = 0;
    if (!all &&
        (moved = ws_node_moved_end(S->b, S->cur, web, web->x[S->cur], S->margin, S->lanes,
                                   S->nlanes)) < 0)
        all = 1;
    *searched = all || moved > 0;
    if (*searched) {
        const int old = list;
        list ^= 1;
        /* The record of where nodes were found changes now: should the step fail, the next
         * one finds every node again (refresh stays set until a step commits). */
        nc->refresh = 1;
        if (nc->seg_list == list) /* cut from what is overwritten now */
            nc->seg_list = -1;
        int bad;
        if (all) {
            bad = track_bodies(S, web) || find_candidates(S, web, NULL, 0, &nc->cand[list]) < 0;
            if (!bad)
                ws_node_index(nc->cand[list].c, nc->cand[list].n, web->n, nc->cstart[list]);
        } else {
            bad = search_moved(S, web, (size_t)moved, old, &list);
        }
        if (bad)
            return -1;
    }
    nc->next_list = list;
    ws_node_prepare_some(S->b, S->cur, S->g, web, 0, 1);
    /* The list cut into stretches for the evaluation: again whenever it changed (a list that
     * serves again keeps its stretches). */
    if (nc->seg_list != list &&
        ws_node_segments(S->mem, web, nc->cand[list].c, nc->cand[list].n, list) != 0)
        return -1;
    return 0;
}

void ws_node_contact_commit(ws_node_contact *nc)
{
    nc->list = nc->next_list;
    nc->refresh = 0;
}
