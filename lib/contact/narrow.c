/* Goyal narrow phase. Everything is done in the frame of body a, where its features were prepared
 * once: the 3x3 solve of eq. 14 reduces to k3 = n . d and a 2x2 solve precomputed per triangle,
 * because n is orthogonal to w and v. */
#include "contact/contact.h"

#include <stdlib.h>

int ws_point_in_face(const ws_shape *sa, uint32_t f, v3 s, double lo, double hi, double *dist)
{
    const ws_face *fc = &sa->faces[f];
    double d = v3_dot(fc->normal, s) - fc->offset; /* k3 */
    if (!(d > lo && d < hi))
        return 0;
    /* One contact per point and face: the first triangle of the face that holds the projection
     * settles it, so a point on an edge shared by two triangles of a face is counted once. */
    for (uint32_t t = fc->first_tri; t < fc->first_tri + fc->tri_count; t++) {
        const ws_tri *q = &sa->tris[t];
        v3 r = v3_sub(s, q->p);
        if (ws_bary_inside(v3_dot(r, q->w), v3_dot(r, q->v), q->g00, q->g01, q->g11)) {
            *dist = d;
            return 1;
        }
    }
    return 0;
}

/* Distance from x to the segment a + t d, t in [0, 1]. */
static double point_segment(v3 x, v3 a, v3 d)
{
    double t = v3_dot(v3_sub(x, a), d) / v3_dot(d, d);
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    return v3_norm(v3_sub(x, v3_madd(a, d, t)));
}

/* How far the projection of s on face f's plane lies outside the face (0 inside): the least
 * distance to its triangles, each measured in the plane. */
static double outside_face(const ws_shape *sa, uint32_t f, v3 s)
{
    const ws_face *fc = &sa->faces[f];
    double best = INFINITY;
    for (uint32_t t = fc->first_tri; t < fc->first_tri + fc->tri_count; t++) {
        const ws_tri *q = &sa->tris[t];
        v3 r = v3_sub(s, q->p);
        r = v3_madd(r, fc->normal, -v3_dot(r, fc->normal));
        v3 x = v3_add(q->p, r);
        double e = fmin(fmin(point_segment(x, q->p, q->w), point_segment(x, q->p, q->v)),
                        point_segment(x, v3_add(q->p, q->w), v3_sub(q->v, q->w)));
        best = fmin(best, e);
    }
    return best;
}

/* s in face g or less than WS_OUTLINE_TOL outside its outline, at a height *d over its plane
 * within (lo, hi). */
static int near_face(const ws_shape *sa, uint32_t g, v3 s, double lo, double hi, double *d)
{
    if (ws_point_in_face(sa, g, s, lo, hi, d))
        return 1;
    const ws_face *fc = &sa->faces[g];
    *d = v3_dot(fc->normal, s) - fc->offset;
    if (!(*d > lo && *d < hi))
        return 0;
    /* The face's box first: most points out of the face are far out. */
    v3 x = v3_madd(s, fc->normal, -*d);
    const double e = WS_OUTLINE_TOL;
    if (x.x < fc->lo.x - e || x.x > fc->hi.x + e || x.y < fc->lo.y - e || x.y > fc->hi.y + e ||
        x.z < fc->lo.z - e || x.z > fc->hi.z + e)
        return 0;
    return outside_face(sa, g, s) < WS_OUTLINE_TOL;
}

int ws_point_on_face(const ws_shape *sa, uint32_t f, v3 s, double lo, double hi, double *dist)
{
    if (ws_point_in_face(sa, f, s, lo, hi, dist))
        return 1;
    /* Widened only a tolerance below the plane: deeper, a point past the rim is outside the
     * solid through a side face, not through this one. */
    double d, e;
    if (!near_face(sa, f, s, fmax(lo, -WS_OUTLINE_TOL), hi, &d))
        return 0;
    /* Over the rim, the face with the greater height takes the point: at a rim between faces
     * of outward normals n_f, n_g, a point at angle phi from n_f about the rim has heights
     * rho cos(phi) and rho cos(alpha - phi), the first greater on f's side of the bisector. */
    for (uint32_t g = 0; g < sa->face_count; g++)
        if (g != f && near_face(sa, g, s, d, hi, &e))
            return 0;
    *dist = d;
    return 1;
}

/* n in the normal cone of an edge whose faces have outward normals n1, n2 (all orthogonal to the
 * edge): n = a n1 + b n2 with a, b >= 0, up to WS_CONE_TOL. */
static int in_cone(v3 n, v3 n1, v3 n2)
{
    double c = v3_dot(n1, n2), r1 = v3_dot(n, n1), r2 = v3_dot(n, n2);
    double den = 1.0 - c * c;
    if (den < 1e-12)
        return r1 > -WS_FEATURE_TOL;
    double a = (r1 - c * r2) / den, b = (r2 - c * r1) / den;
    return a >= -WS_CONE_TOL && b >= -WS_CONE_TOL;
}

static v3 unit(v3 a)
{
    return v3_scale(a, 1.0 / v3_norm(a));
}

/* 0 below lo, 1 above 2 lo, linear between. */
static double ramp(double x, double lo)
{
    return x <= lo ? 0.0 : x >= 2.0 * lo ? 1.0 : x / lo - 1.0;
}

/* How nearly face 1 of edge i (normals n1i, n2i) and face 1 of edge j lie on each other near
 * the edges: the cosine of the angle by which their normals miss being opposed, when the faces
 * reach out from their edges to the same side (each face's direction into itself, away from its
 * edge, is that of n1 c - n2 with c = n1 . n2); -1 when they reach to opposite sides, as for
 * two blocks touching edge to edge diagonally, whose coplanar faces lie side by side. */
static double face_on_face(v3 n1i, v3 n2i, v3 n1j, v3 n2j)
{
    v3 di = v3_madd(n2i, n1i, -v3_dot(n1i, n2i)), dj = v3_madd(n2j, n1j, -v3_dot(n1j, n2j));
    return v3_dot(di, dj) > 0.0 ? -v3_dot(n1i, n1j) : -1.0;
}

/* How flat an edge pair is: f(psi) in [0, 1] (WS_EDGE_FLAT_FACES), for edges crossing at
 * sin(angle) sigma, their faces with outward normals n1i, n2i and n1j, n2j; *nf the bisector
 * n_k - n_l (out of a) of the most nearly opposed pair of those faces lying on each other, which
 * misses being opposed by psi. 0 (and *nf untouched) for edges 2 WS_EDGE_FLAT_SIN or more from
 * parallel. The share of the faces' normal is g = (1 - s(sigma)) f, that of the pair's force
 * 1 - (1 - p(sigma)) f (contact.h). */
static double flat_faces(double sigma, v3 n1i, v3 n2i, v3 n1j, v3 n2j, v3 *nf)
{
    if (sigma >= 2.0 * WS_EDGE_FLAT_SIN)
        return 0.0;
    const v3 ni[4] = {n1i, n1i, n2i, n2i}, oi[4] = {n2i, n2i, n1i, n1i};
    const v3 nj[4] = {n1j, n2j, n1j, n2j}, oj[4] = {n2j, n1j, n2j, n1j};
    double c = -1.0;
    int best = 0;
    for (int k = 0; k < 4; k++) {
        double ck = face_on_face(ni[k], oi[k], nj[k], oj[k]);
        if (ck > c) {
            c = ck;
            best = k;
        }
    }
    /* psi from 1 - cos(psi) = 2 sin^2(psi / 2), exact and well-conditioned near 0 */
    double psi = 2.0 * asin(sqrt(fmin(1.0, fmax(0.0, 0.5 * (1.0 - c)))));
    double f = 1.0 - ramp(psi, WS_EDGE_FLAT_FACES);
    if (!(f > 0.0))
        return 0.0;
    *nf = unit(v3_sub(ni[best], nj[best]));
    return f;
}

/* An edge from p to q and the outward normals n1, n2 of its two faces (its normal cone). */
typedef struct edge_seg {
    v3 p, q, n1, n2;
} edge_seg;

/* An edge pair's contact: the closest points' parameters s, t, the oriented normal n, the signed
 * distance d and the share of the pair's force. */
typedef struct edge_hit {
    double s, t, d, share;
    v3 n;
} edge_hit;

/* Edge ei = pi-qi of a against edge ej = pj-qj of b, all in a's frame (eq. 16-17): closest points
 * pi + s u and pj + t w, separation k3 along the unit common normal. n is oriented out of a (in
 * the cone of a's edge) and must point into b (its reverse in the cone of b's edge). Returns 1 with
 * the parameters, the oriented normal (for nearly parallel edges on faces lying on each other
 * turned towards those faces', flat_faces), the signed distance and the share of the pair's
 * force (WS_EDGE_PARALLEL_SIN: 1 but for nearly parallel edges on faces lying on each other); 0
 * for parallel edges (the system is singular: point-face contacts carry that case), flat pairs
 * whose share is 0, or when the closest points are not interior to both edges or the cones
 * disagree. The contact goes into hit. */
static int edge_edge(const edge_seg *ei, const edge_seg *ej, edge_hit *hit)
{
    const v3 pi = ei->p, pj = ej->p, n1i = ei->n1, n2i = ei->n2, n1j = ej->n1, n2j = ej->n2;
    v3 u = v3_sub(ei->q, pi), w = v3_sub(ej->q, pj);
    v3 n = v3_cross(u, w);
    double uu = v3_dot(u, u), ww = v3_dot(w, w), uw = v3_dot(u, w), nn = v3_dot(n, n);
    if (nn < 1e-8 * uu * ww)
        return 0;
    v3 r = v3_sub(pj, pi);
    double ru = v3_dot(r, u), rw = v3_dot(r, w);
    double s = (ru * ww - uw * rw) / nn, t = (uw * ru - uu * rw) / nn;
    /* Closest points near an edge's end are handed over to the end's point-face contact by the
     * caller (WS_EDGE_END_REACH), measured as that contact measures it. */
    if (!(s > WS_FEATURE_TOL && s < 1.0 - WS_FEATURE_TOL && t > WS_FEATURE_TOL &&
          t < 1.0 - WS_FEATURE_TOL))
        return 0;
    n = v3_scale(n, 1.0 / sqrt(nn));
    v3 nf = n;
    const double sigma = sqrt(nn / (uu * ww));
    const double f = flat_faces(sigma, n1i, n2i, n1j, n2j, &nf);
    /* The flat pair's force fades out below WS_EDGE_PARALLEL_SIN, the corners carrying it. */
    const double wt = 1.0 - f * (1.0 - ramp(sigma, WS_EDGE_PARALLEL_SIN));
    if (!(wt > 0.0))
        return 0;
    const double g = f * (1.0 - ramp(sigma, WS_EDGE_FLAT_SIN));
    double d;
    if (g > 0.0) {
        /* Nearly parallel edges on faces lying on each other: a line contact, whose normal is
         * the faces' (u x w swings by a tilt over sigma); the cone test has nothing to decide.
         * That normal is not orthogonal to both edges: the distance is taken between the
         * closest points (for u x w it is the same). */
        n = unit(v3_add(v3_scale(v3_dot(n, nf) < 0.0 ? v3_neg(n) : n, 1.0 - g), v3_scale(nf, g)));
        d = v3_dot(v3_add(r, v3_sub(v3_scale(w, t), v3_scale(u, s))), n);
    } else {
        if (!in_cone(n, n1i, n2i)) {
            n = v3_neg(n);
            if (!in_cone(n, n1i, n2i))
                return 0;
        }
        if (!in_cone(v3_neg(n), n1j, n2j))
            return 0;
        d = v3_dot(r, n);
    }
    *hit = (edge_hit){.s = s, .t = t, .d = d, .share = wt, .n = n};
    return 1;
}

/* A point inside the solid (d < 0 under face f) is pushed out by one face only: the one it is
 * least deep under among the faces it projects into. Otherwise a deep corner would be pushed
 * sideways out of a near side face as well as up out of the face it came through. */
int ws_shallowest_face(const ws_shape *sa, uint32_t f, v3 s, double d)
{
    for (uint32_t g = 0; g < sa->face_count; g++) {
        double e;
        if (g != f && ws_point_in_face(sa, g, s, d, 0.0, &e) && e > d)
            return 0;
    }
    return 1;
}

/* Point s (frame of shape sa) carried by a point-face contact on one of sa's faces at a
 * distance within (lo, hi): ws_point_on_face and, inside the solid, ws_shallowest_face, the
 * tests of ws_contact_geometry's point-face branch. */
static int point_carried(const ws_shape *sa, v3 s, double lo, double hi)
{
    for (uint32_t f = 0; f < sa->face_count; f++) {
        double d;
        if (ws_point_on_face(sa, f, s, lo, hi, &d) && (d >= 0.0 || ws_shallowest_face(sa, f, s, d)))
            return 1;
    }
    return 0;
}

/* Relative transform of b into a's frame: s_a = R s_b + t. */
static void relative(const ws_body_store *b, int cur, uint32_t ia, uint32_t ib, m3 *R, v3 *t)
{
    const m3 *Aa = &b->A[ia], *Ab = &b->A[ib];
    *R = m3_tmul(Aa, Ab);
    *t = m3_tmul_v(Aa, v3_sub(b->st[cur].r[ib], b->st[cur].r[ia]));
}

/* relative() for the context's state, kept for the pair last asked (candidates come in runs of
 * a pair): the same products, so the same bits. */
static void pair_pose(ws_contact_ctx *x, uint32_t ia, uint32_t ib)
{
    if (!x->pose_ok || x->pose_a != ia || x->pose_b != ib) {
        relative(x->b, x->cur, ia, ib, &x->pose_R, &x->pose_t);
        x->pose_a = ia;
        x->pose_b = ib;
        x->pose_ok = 1;
    }
}

/* The clearances (WS_CLEAR_PAD): how far point s's projection on face f's plane lies from the
 * face, at least, less the tolerances within which it still counts on it. */
static double face_clearance(const ws_shape *sa, uint32_t f, v3 s)
{
    const ws_face *fc = &sa->faces[f];
    const v3 x = v3_madd(s, fc->normal, -(v3_dot(fc->normal, s) - fc->offset));
    const v3 o = v3_make(fmax(0.0, fmax(fc->lo.x - x.x, x.x - fc->hi.x)),
                         fmax(0.0, fmax(fc->lo.y - x.y, x.y - fc->hi.y)),
                         fmax(0.0, fmax(fc->lo.z - x.z, x.z - fc->hi.z)));
    const double tol =
        WS_OUTLINE_TOL + WS_FEATURE_TOL * v3_norm(v3_sub(fc->hi, fc->lo)) + WS_CLEAR_PAD;
    return fmax(0.0, v3_norm(o) - tol);
}

/* How far b's edge pj-qj, projected on the line of a's edge pi-qi, lies past that edge's ends. */
static double edge_clearance(v3 pi, v3 qi, v3 pj, v3 qj)
{
    const v3 u = v3_sub(qi, pi);
    const double la = v3_norm(u);
    const double mp = v3_dot(v3_sub(pj, pi), u) / la, mq = v3_dot(v3_sub(qj, pi), u) / la;
    return fmax(0.0, fmax(-fmax(mp, mq), fmin(mp, mq) - la) - WS_CLEAR_PAD);
}

int ws_contact_apart(ws_contact_ctx *x, const ws_cand *c)
{
    if (!(c->clear > 0.0))
        return 0;
    pair_pose(x, c->a, c->b);
    const m3 *R = &x->pose_R;
    const v3 t = x->pose_t;
    const ws_shape *sb = x->b->shape[c->b];
    const double c2 = c->clear * c->clear;
    if (c->kind == WS_CONTACT_POINT_FACE)
        return v3_norm2(v3_sub(v3_add(m3_mul_v(R, sb->vertices[c->fb]), t), c->ref[0])) < c2;
    v3 p, q;
    if (c->ref_in_b) {
        const ws_shape *sa = x->b->shape[c->a];
        const ws_edge *F = &sa->edges[c->fa];
        p = m3_tmul_v(R, v3_sub(sa->vertices[F->a], t));
        q = m3_tmul_v(R, v3_sub(sa->vertices[F->b], t));
    } else {
        const ws_edge *E = &sb->edges[c->fb];
        p = v3_add(m3_mul_v(R, sb->vertices[E->a]), t);
        q = v3_add(m3_mul_v(R, sb->vertices[E->b]), t);
    }
    return v3_norm2(v3_sub(p, c->ref[0])) < c2 && v3_norm2(v3_sub(q, c->ref[1])) < c2;
}

/* An edge pair found apart (ei a's edge, ej b's, both in a's frame; b's edge E in its own
 * frame): the larger of its two clearances (WS_CLEAR_PAD), with its points: b's ends in a's
 * frame, or a's ends in b's frame (s_b = R^T (s_a - t)). */
static void edges_apart(ws_cand *c, const edge_seg *ei, const edge_seg *ej, const m3 *R, v3 t,
                        const ws_shape *sb, const ws_edge *E)
{
    const v3 ai = m3_tmul_v(R, v3_sub(ei->p, t)), bi = m3_tmul_v(R, v3_sub(ei->q, t));
    const double in_a = edge_clearance(ei->p, ei->q, ej->p, ej->q);
    const double in_b = edge_clearance(sb->vertices[E->a], sb->vertices[E->b], ai, bi);
    c->ref_in_b = in_b > in_a;
    c->ref[0] = c->ref_in_b ? ai : ej->p;
    c->ref[1] = c->ref_in_b ? bi : ej->q;
    c->clear = fmax(in_a, in_b);
}

static int push(ws_mem *mem, ws_cand **cand, size_t *n, size_t *cap, uint32_t a, uint32_t b,
                uint32_t fa, uint32_t fb, uint32_t kind)
{
    /* Without an allocator (a worker's call) the list cannot grow: out of room. */
    if (mem ? ws_array_reserve(mem, (void **)cand, cap, *n + 1, sizeof **cand) != 0 : *n >= *cap)
        return -1;
    ws_cand *c = &(*cand)[(*n)++];
    c->a = a;
    c->b = b;
    c->fa = fa;
    c->fb = fb;
    c->kind = kind;
    c->anchored = 0;
    c->anchor_a = c->anchor_b = v3_make(0, 0, 0);
    c->ended = c->fresh = 0;
    c->twin_cut = 0.0;
    c->ref_in_b = 0;
    c->ref[0] = c->ref[1] = v3_make(0, 0, 0);
    c->clear = 0.0; /* measured in its first step */
    return 0;
}

static int inside_box(v3 p, v3 lo, v3 hi, double e)
{
    return p.x > lo.x - e && p.x < hi.x + e && p.y > lo.y - e && p.y < hi.y + e &&
           p.z > lo.z - e && p.z < hi.z + e;
}

/* Points of body pb against faces of body pa. */
static int points_faces(ws_mem *mem, ws_contact_ctx *x, uint32_t pa, uint32_t pb, ws_cand **cand,
                        size_t *n, size_t *cap)
{
    const ws_body_store *b = x->b;
    const ws_shape *sa = b->shape[pa], *sb = b->shape[pb];
    double reach = b->layer[pa] + b->layer[pb] + x->margin;
    m3 R;
    v3 t;
    relative(b, x->cur, pa, pb, &R, &t);
    for (uint32_t k = 0; k < sb->vertex_count; k++) {
        v3 s = v3_add(m3_mul_v(&R, sb->vertices[k]), t);
        if (!inside_box(s, sa->lo, sa->hi, reach + WS_OUTLINE_TOL))
            continue;
        for (uint32_t f = 0; f < sa->face_count; f++) {
            const ws_face *fc = &sa->faces[f];
            x->narrow_checks++;
            double d = v3_dot(fc->normal, s) - fc->offset;
            /* Depth counts along the normal only: the point's projection on the face's plane
             * must lie within reach of the face (its box is flat along the normal). */
            if (d > -reach - sa->inner && d < reach &&
                inside_box(v3_madd(s, fc->normal, -d), fc->lo, fc->hi, reach + WS_OUTLINE_TOL))
                if (push(mem, cand, n, cap, pa, pb, f, k, WS_CONTACT_POINT_FACE) != 0)
                    return -1;
        }
    }
    return 0;
}

/* The distance between the segments p + s u and q + t w (s, t in [0, 1]); for nearly parallel
 * ones a lower bound of it. It changes by no more than the segments' points move, unlike where
 * the lines' closest points lie: those run along the edges at the points' speed over the sine
 * of the edges' angle. */
/* The least distance over the border of the parameter square: from each segment's ends to the
 * other segment. */
static double ends_gap(v3 p, v3 u, v3 q, v3 w)
{
    return fmin(fmin(point_segment(p, q, w), point_segment(v3_add(p, u), q, w)),
                fmin(point_segment(q, p, u), point_segment(v3_add(q, w), p, u)));
}

static double segment_gap(v3 p, v3 u, v3 q, v3 w)
{
    v3 n = v3_cross(u, w), r = v3_sub(q, p);
    double uu = v3_dot(u, u), ww = v3_dot(w, w), uw = v3_dot(u, w), nn = v3_dot(n, n);
    if (nn < 1e-8 * uu * ww) {
        /* The closest points are ill-conditioned: from the interior ones, along the two lines'
         * valley to the border of the parameter square, the distance grows by at most
         * min(|u|, |w|) sin(angle) = |n| / max(|u|, |w|). */
        return ends_gap(p, u, q, w) - sqrt(nn / fmax(uu, ww));
    }
    double ru = v3_dot(r, u), rw = v3_dot(r, w);
    double s = (ru * ww - uw * rw) / nn, t = (uw * ru - uu * rw) / nn;
    if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0)
        return fabs(v3_dot(r, n)) / sqrt(nn);
    return ends_gap(p, u, q, w);
}

static int edges_edges(ws_mem *mem, ws_contact_ctx *x, uint32_t ia, uint32_t ib, ws_cand **cand,
                       size_t *n, size_t *cap)
{
    const ws_body_store *b = x->b;
    const ws_shape *sa = b->shape[ia], *sb = b->shape[ib];
    double reach = b->layer[ia] + b->layer[ib] + x->margin;
    m3 R;
    v3 t;
    relative(b, x->cur, ia, ib, &R, &t);
    for (uint32_t eb = 0; eb < sb->edge_count; eb++) {
        const ws_edge *E = &sb->edges[eb];
        v3 pj = v3_add(m3_mul_v(&R, sb->vertices[E->a]), t);
        v3 qj = v3_add(m3_mul_v(&R, sb->vertices[E->b]), t);
        v3 lo = v3_min(pj, qj), hi = v3_max(pj, qj);
        if (hi.x < sa->lo.x - reach || lo.x > sa->hi.x + reach || hi.y < sa->lo.y - reach ||
            lo.y > sa->hi.y + reach || hi.z < sa->lo.z - reach || lo.z > sa->hi.z + reach)
            continue;
        for (uint32_t ea = 0; ea < sa->edge_count; ea++) {
            const ws_edge *F = &sa->edges[ea];
            /* Edge boxes first: most pairs are far apart. */
            if (hi.x < F->lo.x - reach || lo.x > F->hi.x + reach || hi.y < F->lo.y - reach ||
                lo.y > F->hi.y + reach || hi.z < F->lo.z - reach || lo.z > F->hi.z + reach)
                continue;
            v3 pi = sa->vertices[F->a], qi = sa->vertices[F->b];
            x->narrow_checks++;
            /* A contact of the two (eq. 16-17: closest points within both edges, |d| below the
             * layers + the inner depth) is one of the segments' distance. Until the next full
             * detection the bodies' points move less than the margin together, and so does
             * the segments' distance: within the layers + margin + inner depth now, or no
             * contact before then. Parallel edges too: they may turn until then. */
            if (segment_gap(pi, v3_sub(qi, pi), pj, v3_sub(qj, pj)) <
                reach + fmin(sa->inner, sb->inner))
                if (push(mem, cand, n, cap, ia, ib, ea, eb, WS_CONTACT_EDGE_EDGE) != 0)
                    return -1;
        }
    }
    return 0;
}

int ws_contact_candidates(ws_mem *mem, ws_contact_ctx *x, uint32_t i, uint32_t j, ws_cand **cand,
                          size_t *n, size_t *cap)
{
    if (points_faces(mem, x, i, j, cand, n, cap) != 0)
        return -1;
    if (points_faces(mem, x, j, i, cand, n, cap) != 0)
        return -1;
    return edges_edges(mem, x, i, j, cand, n, cap);
}

/* Geometry of one candidate at the committed state: contact point (global), normal (global, a to
 * b) and signed distance. Returns 1 when the layers overlap. */
int ws_contact_geometry(ws_contact_ctx *x, ws_cand *c, v3 *xg, v3 *ng, double *dist,
                        double *share)
{
    c->clear = 0.0;
    const ws_body_store *b = x->b;
    const ws_body_state *st = &b->st[x->cur];
    uint32_t ia = c->a, ib = c->b;
    const ws_shape *sa = b->shape[ia], *sb = b->shape[ib];
    double reach = b->layer[ia] + b->layer[ib];
    const m3 *Aa = &b->A[ia], *Ab = &b->A[ib];
    x->narrow_checks++;
    if (c->kind == WS_CONTACT_POINT_FACE) {
        v3 pg = v3_add(st->r[ib], m3_mul_v(Ab, sb->vertices[c->fb]));
        v3 s = m3_tmul_v(Aa, v3_sub(pg, st->r[ia]));
        double d;
        if (!ws_point_on_face(sa, c->fa, s, -reach - sa->inner, reach, &d)) {
            c->ref[0] = s;
            c->clear = face_clearance(sa, c->fa, s);
            return 0;
        }
        if (d < 0.0 && !ws_shallowest_face(sa, c->fa, s, d))
            return 0;
        *ng = m3_mul_v(Aa, sa->faces[c->fa].normal);
        *xg = v3_madd(pg, *ng, -0.5 * d); /* mid-way between the point and the face */
        *dist = d;
        *share = 1.0 - c->twin_cut;
        return 1;
    }
    const ws_edge *F = &sa->edges[c->fa], *E = &sb->edges[c->fb];
    pair_pose(x, ia, ib);
    const m3 R = x->pose_R;
    const v3 t = x->pose_t;
    v3 pi = sa->vertices[F->a], qi = sa->vertices[F->b];
    v3 pj = v3_add(m3_mul_v(&R, sb->vertices[E->a]), t);
    v3 qj = v3_add(m3_mul_v(&R, sb->vertices[E->b]), t);
    const edge_seg ei = {pi, qi, F->n1, F->n2};
    const edge_seg ej = {pj, qj, m3_mul_v(&R, E->n1), m3_mul_v(&R, E->n2)};
    edge_hit h;
    if (!edge_edge(&ei, &ej, &h)) {
        edges_apart(c, &ei, &ej, &R, t, sb, E);
        return 0;
    }
    const double s = h.s, u = h.t, d = h.d;
    const v3 n = h.n;
    if (!(d > -reach - fmin(sa->inner, sb->inner) && d < reach))
        return 0;
    /* A closest point within WS_EDGE_END_REACH of an edge's end is the end's (a corner's) when
     * that end counts on the other body's face: the point-face contact carries it, and the pair
     * not (contact.h). */
    const double la = sqrt(v3_dot(v3_sub(qi, pi), v3_sub(qi, pi)));
    const double lb = sqrt(v3_dot(v3_sub(qj, pj), v3_sub(qj, pj)));
    if (fmin(s, 1.0 - s) * la < WS_EDGE_END_REACH) {
        /* a's nearer end in b's frame: s_b = R^T (s_a - t) */
        v3 ea = m3_tmul_v(&R, v3_sub(s < 0.5 ? pi : qi, t));
        if (point_carried(sb, ea, -reach - sb->inner, reach))
            return 0;
    }
    if (fmin(u, 1.0 - u) * lb < WS_EDGE_END_REACH &&
        point_carried(sa, u < 0.5 ? pj : qj, -reach - sa->inner, reach))
        return 0;
    v3 xi = v3_madd(pi, v3_sub(qi, pi), s), xj = v3_madd(pj, v3_sub(qj, pj), u);
    v3 mid = v3_scale(v3_add(xi, xj), 0.5);
    *xg = v3_add(st->r[ia], m3_mul_v(Aa, mid));
    *ng = m3_mul_v(Aa, n);
    *dist = d;
    *share = h.share;
    return 1;
}

int ws_contact_place(ws_contact_ctx *x, const ws_cand *c, v3 *xg, v3 *ng, double *share)
{
    const ws_body_store *b = x->b;
    const ws_body_state *st = &b->st[x->cur];
    const uint32_t ia = c->a, ib = c->b;
    const ws_shape *sa = b->shape[ia], *sb = b->shape[ib];
    const m3 *Aa = &b->A[ia];
    if (c->kind == WS_CONTACT_POINT_FACE) {
        v3 pg = v3_add(st->r[ib], m3_mul_v(&b->A[ib], sb->vertices[c->fb]));
        v3 s = m3_tmul_v(Aa, v3_sub(pg, st->r[ia]));
        const ws_face *fc = &sa->faces[c->fa];
        *ng = m3_mul_v(Aa, fc->normal);
        *xg = v3_madd(pg, *ng, -0.5 * (v3_dot(fc->normal, s) - fc->offset));
        *share = 1.0 - c->twin_cut;
        return 1;
    }
    const ws_edge *F = &sa->edges[c->fa], *E = &sb->edges[c->fb];
    m3 R;
    v3 t;
    relative(b, x->cur, ia, ib, &R, &t);
    const v3 pi = sa->vertices[F->a], pj = v3_add(m3_mul_v(&R, sb->vertices[E->a]), t);
    const v3 u = v3_sub(sa->vertices[F->b], pi),
             w = v3_sub(v3_add(m3_mul_v(&R, sb->vertices[E->b]), t), pj);
    v3 n = v3_cross(u, w);
    const double uu = v3_dot(u, u), ww = v3_dot(w, w), uw = v3_dot(u, w), nn = v3_dot(n, n);
    if (nn < 1e-8 * uu * ww)
        return 0;
    /* The segments' closest points: the lines', clamped to the segments. */
    const v3 r = v3_sub(pi, pj);
    const double ru = v3_dot(r, u), rw = v3_dot(r, w);
    double s = fmin(1.0, fmax(0.0, (uw * rw - ru * ww) / nn));
    double tt = (uw * s + rw) / ww;
    if (tt < 0.0 || tt > 1.0) {
        tt = fmin(1.0, fmax(0.0, tt));
        s = fmin(1.0, fmax(0.0, (uw * tt - ru) / uu));
    }
    /* The pair's normal and share as edge_edge has them (the flat faces' blend and fade). */
    n = v3_scale(n, 1.0 / sqrt(nn));
    v3 nf = n;
    const double sigma = sqrt(nn / (uu * ww));
    const double f = flat_faces(sigma, F->n1, F->n2, m3_mul_v(&R, E->n1), m3_mul_v(&R, E->n2), &nf);
    const double wt = 1.0 - f * (1.0 - ramp(sigma, WS_EDGE_PARALLEL_SIN));
    if (!(wt > 0.0))
        return 0;
    const double g = f * (1.0 - ramp(sigma, WS_EDGE_FLAT_SIN));
    if (g > 0.0)
        n = unit(v3_add(v3_scale(v3_dot(n, nf) < 0.0 ? v3_neg(n) : n, 1.0 - g), v3_scale(nf, g)));
    const v3 mid = v3_scale(v3_add(v3_madd(pi, u, s), v3_madd(pj, w, tt)), 0.5);
    *xg = v3_add(st->r[ia], m3_mul_v(Aa, mid));
    *ng = m3_mul_v(Aa, n);
    *share = wt;
    return 1;
}

/* ---- twin corners (WS_TWIN_REACH) ---- */

/* A point-face candidate's vertex (global), its face's outward normal (global) and, when s is not
 * NULL, the vertex in the face owner's frame. */
static void pf_place(const ws_contact_ctx *x, const ws_cand *c, v3 *pg, v3 *ng, v3 *s)
{
    const ws_body_store *b = x->b;
    const ws_body_state *st = &b->st[x->cur];
    const m3 *Aa = &b->A[c->a];
    *pg = v3_add(st->r[c->b], m3_mul_v(&b->A[c->b], b->shape[c->b]->vertices[c->fb]));
    if (s) /* the twin search's sites do without it */
        *s = m3_tmul_v(Aa, v3_sub(*pg, st->r[c->a]));
    *ng = m3_mul_v(Aa, b->shape[c->a]->faces[c->fa].normal);
}

/* The distance of vertices pi and pj in the faces' plane: that of the bisector ni - nj of their
 * faces' normals, symmetric in i and j. */
static double plane_distance(v3 pi, v3 ni, v3 pj, v3 nj)
{
    const v3 nb = unit(v3_sub(ni, nj)), d = v3_sub(pi, pj);
    return v3_norm(v3_madd(d, nb, -v3_dot(d, nb)));
}

/* The fade tau in [0, 1] of the pairing of two point-face candidates of opposite body order
 * (vertices pi, pj, face normals ni, nj, global) and their distance in the faces' plane
 * (plane_distance): 1 for faces lying on each other (f(psi) of the edge pairs,
 * WS_EDGE_FLAT_FACES) and vertices within WS_TWIN_REACH, falling linearly to 0 at twice
 * either. */
static double twin_fade(v3 pi, v3 ni, v3 pj, v3 nj, double *dt)
{
    const double c = -v3_dot(ni, nj);
    const double psi = 2.0 * asin(sqrt(fmin(1.0, fmax(0.0, 0.5 * (1.0 - c)))));
    const double f = 1.0 - ramp(psi, WS_EDGE_FLAT_FACES);
    *dt = INFINITY;
    if (!(f > 0.0))
        return 0.0;
    *dt = plane_distance(pi, ni, pj, nj);
    return f * (1.0 - ramp(*dt, WS_TWIN_REACH));
}

/* A point-face candidate's vertex and its face's outward normal (global), as pf_place gives
 * them: what the twin search compares. */
typedef struct twin_site {
    v3 p, n;
} twin_site;

/* The sites of a run's candidates, TWIN_SITES at a time: a run of a box's corners fits whole
 * and is placed once for all the candidates it is compared with, where placing each one for
 * every comparison was most of the search; a longer run (a mesh body's) is placed a window at a
 * time, the same sites. */
#define TWIN_SITES 64
typedef struct twin_window {
    size_t k0, k1; /* the candidates held, c[k0..k1) */
    twin_site s[TWIN_SITES];
} twin_window;

/* One part's twin search: the step's candidates and a window on each of a pair's two runs. */
typedef struct twin_search {
    const ws_contact_ctx *x;
    const ws_cand *c;
    double cos_flat; /* cos(2 WS_EDGE_FLAT_FACES): faces whose normals miss opposition by more
                        have no twins */
    twin_window ab, ba;
} twin_search;

/* Site k of a run ending at `end`, through window w. */
static twin_site site_of(const twin_search *t, twin_window *w, size_t k, size_t end)
{
    if (k < w->k0 || k >= w->k1) {
        w->k0 = k;
        w->k1 = end - k < TWIN_SITES ? end : k + TWIN_SITES;
        for (size_t m = k; m < w->k1; m++)
            pf_place(t->x, &t->c[m], &w->s[m - k].p, &w->s[m - k].n, NULL);
    }
    return w->s[k - w->k0];
}

/* Whether the pairing of sites i and j fades in (twin_fade above 0) and, when it does, their
 * distance in the faces' plane: twin_fade's decision, reached without its arcsine and square
 * roots for all but a sliver of pairs (they were half the search), so the same pairs fade in.
 * The normals' cosine decides by more than 1e-9, and a bound decides that the vertices lie out
 * of reach: the distance is |d x (ni - nj)| / |ni - nj| and |ni - nj| <= 2, so past the fade's
 * end, 2 WS_TWIN_REACH, by 1 % (room for the bound's rounding) half the cross product's length
 * puts the pair out. In the sliver it goes as twin_fade goes, or through twin_fade. */
static int twin_fades_in(const twin_search *t, twin_site i, twin_site j, double *dt)
{
    const double c = -v3_dot(i.n, j.n);
    if (c < t->cos_flat - 1e-9)
        return 0;
    const v3 cross = v3_cross(v3_sub(i.p, j.p), v3_sub(i.n, j.n));
    const double out = 2.0 * (2.0 * WS_TWIN_REACH * 1.01);
    if (v3_dot(cross, cross) > out * out)
        return 0;
    if (c <= t->cos_flat + 1e-9)
        return twin_fade(i.p, i.n, j.p, j.n, dt) > 0.0;
    *dt = plane_distance(i.p, i.n, j.p, j.n);
    return ramp(*dt, WS_TWIN_REACH) < 1.0;
}

/* The nearest in the faces' plane to site si among the run c[q0..q1) held through window w,
 * with a fade above 0: its index (the first of equals), or q1. */
static size_t twin_nearest(const twin_search *t, twin_site si, twin_window *w, size_t q0,
                           size_t q1)
{
    size_t best = q1;
    double best_d = INFINITY;
    for (size_t j = q0; j < q1; j++) {
        double d;
        if (twin_fades_in(t, si, site_of(t, w, j, q1), &d) && d < best_d) {
            best = j;
            best_d = d;
        }
    }
    return best;
}

/* A point-face candidate's margin to its drop across the rim, WS_OUTLINE_TOL less the distance
 * of its vertex's projection past the face's outline (the tolerance inside the face, 0 from
 * where ws_point_on_face stops counting it), and whether it is in contact now (the tests of
 * ws_contact_geometry's point-face branch). */
static double pf_margin(const ws_contact_ctx *x, const ws_cand *c, v3 s, int *touching)
{
    const ws_body_store *b = x->b;
    const ws_shape *sa = b->shape[c->a];
    const double reach = b->layer[c->a] + b->layer[c->b];
    double d;
    *touching = ws_point_on_face(sa, c->fa, s, -reach - sa->inner, reach, &d) &&
                (d >= 0.0 || ws_shallowest_face(sa, c->fa, s, d));
    if (ws_point_in_face(sa, c->fa, s, -INFINITY, INFINITY, &d))
        return WS_OUTLINE_TOL;
    return fmax(0.0, WS_OUTLINE_TOL - outside_face(sa, c->fa, s));
}

/* What twin i gives up of its laws to its twin j (margins mi, mj, fade tau). */
static double twin_cut(double mi, double mj, double tau)
{
    const double sum = mi + mj;
    return tau * (sum > 0.0 ? mj / sum : 0.5);
}

void ws_contact_twins(ws_contact_ctx *x, ws_cand *c, size_t n)
{
    ws_contact_twins_clear(c, n);
    ws_contact_twins_part(x, c, n, 0, 1);
}

void ws_contact_twins_clear(ws_cand *c, size_t n)
{
    for (size_t k = 0; k < n; k++)
        c[k].twin_cut = 0.0;
}

void ws_contact_twins_part(const ws_contact_ctx *x, ws_cand *c, size_t n, uint32_t part,
                           uint32_t parts)
{
    /* The runs that start in the part's share of the list: from the first run start at or
     * after its first candidate. */
    const size_t k0 = n * part / parts, k1 = n * (part + 1) / parts;
    size_t p0 = k0;
    while (p0 > 0 && p0 < n && c[p0 - 1].a == c[p0].a && c[p0 - 1].b == c[p0].b)
        p0++;
    twin_search t = {.x = x, .c = c, .cos_flat = cos(2.0 * WS_EDGE_FLAT_FACES)};
    /* Each run of point-face candidates between a and b (a < b) against the one between b and
     * a: mutual nearest neighbours in the faces' plane are twins. */
    while (p0 < k1) {
        size_t p1 = p0;
        while (p1 < n && c[p1].a == c[p0].a && c[p1].b == c[p0].b)
            p1++;
        const uint32_t a = c[p0].a, b = c[p0].b;
        size_t r0 = p0, r1 = p1;
        p0 = p1;
        if (a >= b)
            continue;
        while (r0 < r1 && c[r0].kind != WS_CONTACT_POINT_FACE)
            r0++;
        while (r1 > r0 && c[r1 - 1].kind != WS_CONTACT_POINT_FACE)
            r1--;
        size_t q0 = ws_contact_pair_start(c, n, b, a), q1 = q0;
        while (q1 < n && c[q1].a == b && c[q1].b == a)
            q1++;
        while (q0 < q1 && c[q0].kind != WS_CONTACT_POINT_FACE)
            q0++;
        while (q1 > q0 && c[q1 - 1].kind != WS_CONTACT_POINT_FACE)
            q1--;
        if (r0 == r1 || q0 == q1)
            continue;
        t.ab.k0 = t.ab.k1 = t.ba.k0 = t.ba.k1 = 0; /* both windows empty */
        for (size_t i = r0; i < r1; i++) {
            const size_t j = twin_nearest(&t, site_of(&t, &t.ab, i, r1), &t.ba, q0, q1);
            if (j == q1 || twin_nearest(&t, site_of(&t, &t.ba, j, q1), &t.ab, r0, r1) != i)
                continue;
            v3 pi, ni, si, pj, nj, sj;
            pf_place(x, &c[i], &pi, &ni, &si);
            pf_place(x, &c[j], &pj, &nj, &sj);
            double dt;
            const double tau = twin_fade(pi, ni, pj, nj, &dt);
            int ti, tj;
            const double mi = pf_margin(x, &c[i], si, &ti), mj = pf_margin(x, &c[j], sj, &tj);
            /* A twin out of contact carries nothing: the other carries its corner whole. */
            c[i].twin_cut = tj || !ti ? twin_cut(mi, mj, tau) : 0.0;
            c[j].twin_cut = ti || !tj ? twin_cut(mj, mi, tau) : 0.0;
        }
    }
}

static int cand_cmp(const ws_cand *p, const ws_cand *q)
{
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    if (p->kind != q->kind)
        return p->kind < q->kind ? -1 : 1;
    if (p->fa != q->fa)
        return p->fa < q->fa ? -1 : 1;
    if (p->fb != q->fb)
        return p->fb < q->fb ? -1 : 1;
    return 0;
}

static int cand_qcmp(const void *p, const void *q)
{
    return cand_cmp(p, q);
}

void ws_contact_sort(ws_cand *c, size_t n)
{
    if (n > 1) /* qsort must not see a NULL array, even with n = 0 */
        qsort(c, n, sizeof *c, cand_qcmp);
}

void ws_contact_carry_anchors(ws_cand *nw, size_t n_new, const ws_cand *old, size_t n_old)
{
    size_t i = 0, j = 0;
    while (i < n_new && j < n_old) {
        int k = cand_cmp(&nw[i], &old[j]);
        if (k == 0) {
            nw[i].anchored = old[j].anchored;
            nw[i].anchor_a = old[j].anchor_a;
            nw[i].anchor_b = old[j].anchor_b;
            /* the same features: where they were found apart holds for the new list too */
            nw[i].ref_in_b = old[j].ref_in_b;
            nw[i].ref[0] = old[j].ref[0];
            nw[i].ref[1] = old[j].ref[1];
            nw[i].clear = old[j].clear;
            i++;
            j++;
        } else if (k < 0) {
            i++;
        } else {
            j++;
        }
    }
}
