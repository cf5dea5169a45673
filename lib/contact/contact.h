/* Contact: broad phase over bodies, Goyal narrow phase (point-to-face eq. 14-15, edge-to-edge
 * eq. 16-17) in a contact layer, a cache of candidate feature pairs, penalty normal force and
 * Coulomb friction (regularised, eq. 13, or stick). Knows shape and body. */
#ifndef WS_CONTACT_H
#define WS_CONTACT_H

#include <wrapsim/contact.h>
#include <wrapsim/world.h>

#include "base/base.h"
#include "body/body.h"
#include "shape/shape.h"

/* Barycentric and edge-parameter tolerance: a point on a shared edge of two triangles is inside
 * both (then only one contact is kept per face), an edge pair meeting at an end is left to the
 * point-face contacts. */
#define WS_FEATURE_TOL 1e-9

/* How far an edge-edge normal may lie outside an edge's normal cone (in the cone's coefficients:
 * about that angle in radians for a square edge). At the cone's boundary the other body's edge
 * lies across one of the edge's faces: a line contact, such as a box pressed on the top edge of
 * a stop, or two cartons side by side whose edges meet where their equal faces end. Where the
 * line crosses the face's border, the edge pair carries it; the contact must not come and go
 * with the sign of a tilt of a micro-radian (it did with WS_FEATURE_TOL here: loads squeezed
 * side to side kept jittering, each corner's force switching on and off). 1e-2 is ten times the
 * tilts a resting load's compliance gives its bodies (overlaps of 0.1-0.3 mm differing across
 * faces of 0.3 m: 1e-4 to 1e-3), and small beside any edge that truly turns away. */
#define WS_CONE_TOL 1e-2

/* Nearly parallel edges on faces lying on each other: the edge pair's normal is the faces'. Two
 * faces lying on each other (stacked or side-by-side boxes: outward normals opposed within an angle
 * psi, each face reaching out from its edge to the same side) touch over the convex polygon where
 * they overlap; where two of their border edges cross at a small angle sigma (a yaw of sigma
 * between equal boxes: at mid-edge), the edge pair carries that corner of it. Its normal as eq.
 * 16-17 give it, u x w, is ill-conditioned there: a relative tilt delta of the edges out of the
 * faces' plane turns it by delta / sigma, so for sigma of a few mrad the tilts of a resting load
 * (1e-5 to 1e-3 rad) swing it across the cone test's tolerance (WS_CONE_TOL) and the pair switched
 * on and off with them, a kick of its whole force each time (two stacked boxes at 2.6 mrad of yaw
 * rattled so, the force of 50 N coming and going every other step). The faces' normal (the bisector
 * n_k - n_l of the two opposed faces' normals, out of a) is what the contact has, and it is
 * well-conditioned: the pair's normal is u x w turned towards it by a share g = (1 - s(sigma))
 * f(psi), s rising linearly from 0 at WS_EDGE_FLAT_SIN to 1 at twice it, f falling linearly from 1
 * at psi = WS_EDGE_FLAT_FACES to 0 at twice it, and a pair with g > 0 skips the cone test (its
 * edges lie on each other's faces: a line contact, the case the tolerance is for). In the blend the
 * normal swings by at most (1 - g) delta / sigma <= delta / (2 WS_EDGE_FLAT_SIN): 1e-2 for a tilt
 * of 1e-3, within WS_CONE_TOL. The pair itself stays above 1e-3 (WS_EDGE_PARALLEL_SIN; dropping it
 * to 0.1 left the corner to the neighbouring contacts and let squeezed cartons turn 2.5 times as
 * far). Edges whose faces do not lie on each other (an edge resting across another edge, two blocks
 * touching edge to edge diagonally) keep u x w and the cone test: there the normal lies well inside
 * both cones. */
#define WS_EDGE_FLAT_SIN 0.05
#define WS_EDGE_FLAT_FACES 0.05

/* Edges within a few 1e-4 of parallel on faces lying on each other: the pair's force fades out, the
 * corners carry it. Such a pair is the vertex of the faces' overlap polygon where two of its
 * borders cross, with interior angle pi - sigma. As sigma -> 0 the vertex straightens: the
 * polygon's support is carried by its true corners (point-face contacts, and the edge pairs of
 * edges crossing at large angles), and the nearly straight vertex's spring only adds force and
 * stiffness along a line they already hold. Its existence is the worst of it: the crossing lies at
 * the lateral offset e of the two borders over sigma from the point where they are nearest, and
 * inside both edges only while |e| < sigma L / 2 (L the edge's length). A resting stack's offsets
 * change by tens of nm a step (the faces' rocking turns the 3D lines' closest points as well: the
 * normal's tilt over sigma), so at sigma = 1.4-1.7e-4 (case R's seam, sigma L = 35-42 um) the
 * crossing swept the whole edge in a step, and the one step it lay inside both edges the pair came
 * in at its full overlap (50-65 N), a kick of 5-6.6 mm/s and 0.01-0.06 rad/s on both boxes that
 * rocked the stack for tens of steps. A hard bound under which the pair is skipped would move that
 * jump to the bound (a pair inside the edges at its full force when sigma crosses it: cubes at a
 * yaw of 5e-4 rattled so in 3 of 8 runs); instead the pair's share p(sigma) of its force rises
 * linearly from 0 at WS_EDGE_PARALLEL_SIN to 1 at twice it, applied to every stiffness and damping
 * of its laws (normal and tangential: force.c), so its force and the bodies' solve's friction from
 * it (mu N) are continuous in sigma. With the flatness f(psi) of WS_EDGE_FLAT_FACES the share is
 * w = 1 - (1 - p(sigma)) f(psi): 1 for edges whose faces do not lie on each other (f = 0: they keep
 * the 1e-4 parallel bound of the singular closest points, and the cone test), and continuous in psi
 * as in sigma. The bound: the crossing's range sigma L must be much more than what moves it a step,
 * and more than the creep of a stuck interface under load (mu N / k_t, 9-18 um for the reference
 * boxes) so that a creep does not carry it over the edge: at 5e-4 sigma L is 125 um on a 0.25 m
 * edge, 7-14 times the creep, 1000 times a step's offset. The stacks measured
 * (test_nearly_aligned_stack_no_kicks) kicked at yaws of 1.5-2e-4 and stood still from 3e-4; the
 * fade's top, 1e-3 (250 um), keeps the pairs of the yaws of test_yawed_stack_contacts_settle (1e-3
 * up) whole. A flat pair below the bound leaves its vertex to the corners, which is the
 * face-on-face support the point-face contacts give aligned boxes (yaw 0). */
#define WS_EDGE_PARALLEL_SIN 5e-4

/* How far past a face's outline (m, in the face's plane) a point of another body still counts on
 * the face, when it lies over the face's half of the rim (ws_point_on_face); edge pairs ending
 * at such a point are left to its point-face contact (WS_EDGE_END_REACH). Two equal,
 * aligned boxes stacked (or a box flush against one of its own size) have each box's corners on
 * the other face's rim: 8 springs, two a corner. A moment of ~1 N m (a film's uneven pull)
 * turns the boxes by ~1e-6 rad and moves the corners 1.25e-7 m (over a 0.25 m box's
 * half-height) to either side of the rim; the barycentric tolerance (WS_FEATURE_TOL: 0.25 nm on
 * such a face) made the support follow those signs: half its springs gone, or all on one edge,
 * where the squeeze rocks the stack. Past this tolerance a corner hands over (it loses its
 * second spring, or an edge pair takes it) in one step, so the tolerance must exceed the
 * micro-radian offsets (5e-7 m: 4 times them, with a 1e-7 m shift besides) and stay well below
 * the creep of a stuck interface under load (the stick law's mu N / k_t: 9-18 um for the
 * reference boxes): there a hand-over jolts the anchors (at 1e-6 m a stuck stack on a tilting
 * plane slips at its corners, test_stick_stack_settles_on_tilt; at 1e-5-1e-4 m a sliding box's
 * onset is seen 2 deg late, its anchors reset mid-slide). A corner counted past the rim moves
 * the force's line by 2e-6 of a 0.25 m face. Not the resting tilts of WS_CONE_TOL (1e-4 to
 * 1e-3 rad, 12-125 um at the corners): those are real offsets, which the edge pairs carry. */
#define WS_OUTLINE_TOL 5e-7

/* A corner's hand-over between its point-face contact and an edge pair, measured one way. A
 * box's corner V just past another body's face rim is carried either by its point-face contact
 * (V within WS_OUTLINE_TOL of the face's outline, in the face's plane) or by the edge pair of an
 * edge E through V with the rim edge, whose closest point lies near V along E. The two used to
 * measure different things: the pair was left out while its closest point lay within
 * WS_OUTLINE_TOL of E's end along the 3D edge; but the common normal of E and the rim tilts with
 * E out of the face's plane, which moves that closest point along E by the gap h between them
 * times the tilt: 2e-7 m for the layers' 2 mm and a tilt of 1e-4 (two stacked cubes on a
 * tilting plane). Between the two measures a corner was carried twice (twice its force for a
 * step) at one sign of the tilt, and by nothing at the other (it came back later at its full
 * overlap: 80 N in case R): a kick and tens of steps of rocking. Now an edge pair whose closest
 * point lies within WS_EDGE_END_REACH of an edge's end is left out exactly when that end counts
 * on the other body's face by the point-face contact's own tests (ws_point_on_face, and
 * ws_shallowest_face inside the solid), and kept otherwise, however near the end (up to
 * WS_FEATURE_TOL): exactly one of the two carries the corner wherever the pair's closest point
 * lies inside E, which for a corner past the rim by the tolerance or more holds while h times
 * the tilt stays below WS_OUTLINE_TOL (tilts below 2.5e-4 at the full 2 mm; at larger tilts a
 * corner that far past the rim may find its crossing beyond its end, the gap that a clamped
 * pair would close: not done). The reach bounds where the pair yields: above the tolerance plus
 * the shift (2e-5 m for a tilt of 1e-2 over 2 mm, WS_CONE_TOL), and small beside a face, since a
 * pair crossing the rim within it of a corner that already counts is the same support (a moment
 * arm of 5e-5 m, 2e-4 of a 0.25 m face). */
#define WS_EDGE_END_REACH 5e-5

/* How near (m) a contact that starts in a step must lie to one between the same two bodies that
 * ended in it to take over its stick anchor (ws_contact_handover). A corner's load passes
 * between its point-face contact and the edge pair crossing the rim near it in one step
 * (WS_EDGE_END_REACH): the pair's closest point then lies within WS_EDGE_END_REACH of the
 * corner along its edge, and both contacts' points lie mid-way across the layers' gap, at
 * heights that differ by the edge's tilt times that reach (a nm or less). Twice the reach holds
 * that with room for a step's motion, and is small beside a box's face (4e-4 of 0.25 m) and
 * the distances between its supports: two contacts this near are one support. */
#define WS_ANCHOR_REACH (2.0 * WS_EDGE_END_REACH)

/* Twin corners: how near (m, in the faces' plane) a point-face contact of body A's vertex on
 * B's face and one of B's vertex on A's face must lie to be one vertex of the faces' overlap
 * polygon, carried once between them (ws_contact_twins). Two equal boxes stacked flush have
 * each corner of the interface twice, a corner of either box on the other's rim; shifted or
 * turned so that one of the two lies past the rim by WS_OUTLINE_TOL it drops out, and the
 * interface's stiffness halved on a half-micron shift. Twins' shares of their laws sum to 1
 * and follow each one's margin to its drop, m = WS_OUTLINE_TOL - (its distance past the other
 * face's outline, 0 inside): share_A = 1 - m_B / (m_A + m_B), 1/2 each when aligned, 0 for one
 * at its drop. Both counted, the two corners lie within sqrt(2) WS_OUTLINE_TOL of each other
 * (each within the tolerance of the other's rim, on both of its borders); twice the tolerance
 * holds them, and the pairing fades out linearly from there to twice it (the shares then back
 * to 1 each: contacts that far apart are two vertices), as it does over the faces' angle by
 * WS_EDGE_FLAT_FACES (faces that do not lie on each other). */
#define WS_TWIN_REACH (2.0 * WS_OUTLINE_TOL)

/* A candidate's clearance (ws_contact_apart): how far its moving points may move in a's frame
 * before it can touch, kept from the step it was found apart sideways. A point-face pair touches
 * only with the vertex's projection on the face's plane within WS_OUTLINE_TOL of the face
 * (ws_point_on_face; the barycentric tolerance is WS_FEATURE_TOL of the face's size), and the
 * projection moves no more than the vertex: its distance from the face's box, less those
 * tolerances, is a clearance. An edge pair touches only with the lines' closest points inside both
 * edges (edge_edge), and the projection of b's closest point on a's line is a's: b's edge
 * projected on a's line must overlap a's edge, and the projections of b's ends move no more than
 * the ends: how far the projected edge lies past a's is a clearance, whatever the pair's flatness
 * and cones; and the same with the bodies' parts swapped, a's edge projected on b's line in b's
 * frame (the larger of the two is kept). Less this pad, for the rounding of the points found two
 * ways (b's vertex through the global frame in the geometry, through the pair's relative pose in
 * the test: 1e-16 of a metre's coordinates) and of the distances: 1e-9 m is 10^6 times that and
 * nothing beside the millimetres that cartons' gaps give. The clearance bounds where the pair can
 * be, not where it was on the way: the test compares the points now with the points then. */
#define WS_CLEAR_PAD 1e-9

/* Eq. 14's inclusion test from the two dot products b1 = r.w, b2 = r.v and the triangle's
 * inverse Gram matrix: (k1, k2) in the triangle, edges included (with the tolerance). */
static inline int ws_bary_inside(double b1, double b2, double g00, double g01, double g11)
{
    double k1 = g00 * b1 + g01 * b2, k2 = g01 * b1 + g11 * b2;
    return (k1 >= -WS_FEATURE_TOL) & (k2 >= -WS_FEATURE_TOL) & (k1 + k2 <= 1.0 + WS_FEATURE_TOL);
}

/* A candidate feature pair, kept between full detections. Point-face: a owns face fa, b owns
 * point fb. Edge-edge: a owns edge fa, b owns edge fb. The anchors (body frames) belong to the
 * stick friction model. ended and fresh are scratch of one step's evaluation (world_step.c
 * body_contacts), not state (neither saved nor hashed): ended is 1 for a contact anchored at
 * the step's start and out of contact now (2 once its anchor is taken over), fresh 1 + the
 * index of the record of a contact that started in the step with a new anchor, else 0;
 * twin_cut what a twin corner gives up of its laws (ws_contact_twins; 0, as a zeroed record
 * has it, for none). */
typedef struct ws_cand {
    uint32_t a, b, fa, fb;
    uint32_t kind;
    uint32_t anchored;
    v3 anchor_a, anchor_b;
    uint32_t ended, fresh;
    double twin_cut; /* scratch: 1 less a point-face contact's twin share (ws_contact_twins) */
    /* Where the candidate's moving points lay when it was last found apart (b's vertex in a's
     * frame; an edge's ends in the other body's frame, b's in a's or, ref_in_b, a's in b's),
     * and how far (m) they may each move from there before it can touch (ws_contact_apart);
     * clear 0: measure it. A hint, not state: neither saved nor hashed, 0 after a restore,
     * carried into a full detection's list with the anchors. */
    uint32_t ref_in_b;
    v3 ref[2];
    double clear;
} ws_cand;

/* An active contact of the last step. Normal from a to b; forces those on b. */
typedef struct ws_contact_rec {
    uint32_t a, b, kind, slipping, at_cap;
    v3 x, n, ft, vt, defl;
    double overlap, fn, energy;
    double energy_t; /* the stick anchor spring's, J (0 for the regularised law) */
} ws_contact_rec;

/* Contact parameters resolved for evaluation. */
typedef struct ws_pair_params {
    double k, c, mu, vlim, kt, ct;
    int model;
    double zt; /* stick damping ratio, used when ct is 0 */
} ws_pair_params;

/* The stick model's tangential damping for a pair of bodies of effective mass m_eff (kg; the
 * dynamic one's mass against a kinematic body): the absolute one when set, else the ratio of
 * critical, zt sqrt(kt m_eff) (world.h). */
static inline double ws_stick_damping(const ws_pair_params *p, double m_eff)
{
    return p->ct > 0.0 ? p->ct : p->zt * sqrt(p->kt * m_eff);
}

/* Everything a contact evaluation reads. */
typedef struct ws_contact_ctx {
    ws_body_store *b;
    int cur;
    double margin;
    const ws_pair_params *params; /* indexed by pair_index[ma * nmat + mb] */
    const uint32_t *pair_index;
    uint32_t nmat;
    uint64_t narrow_checks;
    /* The last body pair's relative pose (b in a's frame), kept while a run of its candidates
     * is measured: a context serves one committed state (a step's; a new one after the bodies
     * move). Zero-initialised: none kept. */
    uint32_t pose_a, pose_b, pose_ok;
    m3 pose_R;
    v3 pose_t;
} ws_contact_ctx;

static inline const ws_pair_params *ws_contact_params(const ws_contact_ctx *x, uint32_t a,
                                                      uint32_t b)
{
    return &x->params[x->pair_index[x->b->material[a] * x->nmat + x->b->material[b]]];
}

/* Candidates of one body pair (i, j), appended to *cand. Returns 0, or -1 out of memory; with
 * mem NULL the list does not grow (a call on a worker): -1 when its room runs out. */
int ws_contact_candidates(ws_mem *mem, ws_contact_ctx *x, uint32_t i, uint32_t j, ws_cand **cand,
                          size_t *n, size_t *cap);

/* Point s (frame of shape sa) against face f: 1 and the signed distance if its projection lies in
 * the face and the distance is within (lo, hi). */
int ws_point_in_face(const ws_shape *sa, uint32_t f, v3 s, double lo, double hi, double *dist);

/* ws_point_in_face for another body's point, with the rim widened by WS_OUTLINE_TOL: a point
 * whose projection lies outside the face but within that of its outline counts on it if it is
 * above the face's plane (or less than the tolerance below it), and no other face holding it
 * has a greater height over its plane (over the rim, the face whose normal is nearer the
 * direction from the rim to the point takes it: one face per point). Contacts between bodies
 * use this; film nodes do not. */
int ws_point_on_face(const ws_shape *sa, uint32_t f, v3 s, double lo, double hi, double *dist);

/* A point inside the solid (d < 0 under face f): 1 if f is the face it is least deep under among
 * the faces it projects into, so only that face pushes it out. */
int ws_shallowest_face(const ws_shape *sa, uint32_t f, v3 s, double d);

/* Geometry of a candidate at the committed state: contact point and normal (global, a to b),
 * the signed distance and the contact's share of its laws' stiffness and damping (in (0, 1]:
 * below 1 for a nearly parallel flat edge pair, WS_EDGE_PARALLEL_SIN, and for a twin corner,
 * the candidate's share as ws_contact_twins set it); 1 when the layers overlap. Its clearance
 * is set as it finds it: what ws_contact_apart reads when it is apart sideways, else 0. */
int ws_contact_geometry(ws_contact_ctx *x, ws_cand *c, v3 *xg, v3 *ng, double *dist,
                        double *share);

/* 1 when candidate c is still apart by its clearance (c->clear, c->ref): its moving points have
 * not moved that far since it was found apart, so ws_contact_geometry would reject it. Such a
 * candidate is not anchored (it was apart, and anchors only come with contact). */
int ws_contact_apart(ws_contact_ctx *x, const ws_cand *c);

/* Evaluate one candidate at the committed state: 1 when in contact, with the record filled, the
 * forces added to both bodies' accumulators and the stick anchors of *c updated. */
int ws_contact_eval(ws_contact_ctx *x, ws_cand *c, ws_contact_rec *rec);
/* ws_contact_eval in two halves, so that candidates can be measured on several threads and
 * their forces added in the list's order after: the record and the anchors (1 when in
 * contact; it reads the bodies' state, writes *c, *rec and x->narrow_checks), and the
 * record's force and moment added to both bodies' accumulators, as ws_contact_eval adds them. */
int ws_contact_measure(ws_contact_ctx *x, ws_cand *c, ws_contact_rec *rec);
void ws_contact_apply(const ws_contact_ctx *x, const ws_contact_rec *rec);

/* Where a candidate's features lie nearest each other at the committed state, whether or not
 * they touch or its tests pass: the point mid-way between them (global; a point-face pair's
 * point moved half its height over the face's plane towards it, an edge pair's segments'
 * closest points), the unit normal's line (global; for an edge pair as ws_contact_geometry
 * has it, but of either sign) and its share of the pair's laws. 0 when it has none (parallel
 * edges, or a flat pair faded out). */
int ws_contact_place(ws_contact_ctx *x, const ws_cand *c, v3 *xg, v3 *ng, double *share);

/* The twin corners' shares (WS_TWIN_REACH) of the step's sorted candidates c[0..n) at the
 * committed state, as each one's twin_cut (0 for edge pairs and corners without a twin): for
 * each two bodies, a point-face contact of one's vertex on the other's face and one the other
 * way are twins when each is the other's nearest in the faces' plane among those whose faces
 * lie on each other (the first of equals). Both in contact, each gives up tau m_other / (m_A +
 * m_B), tau the pairing's fade; one out of contact leaves the other whole (its own cut, as
 * placed for the hand-over, is the same formula). To run before the candidates are
 * evaluated. */
void ws_contact_twins(ws_contact_ctx *x, ws_cand *c, size_t n);
/* ws_contact_twins in parts, for several threads: every cut cleared first, then part `part` of
 * `parts` takes the runs (a, b), a < b, that start in its share of the list, writing only
 * their candidates' cuts and those of their runs (b, a): the parts never meet. */
void ws_contact_twins_clear(ws_cand *c, size_t n);
void ws_contact_twins_part(const ws_contact_ctx *x, ws_cand *c, size_t n, uint32_t part,
                           uint32_t parts);

/* The first candidate of c[0..n) (sorted by ws_contact_sort) between a and b in that order. */
static inline size_t ws_contact_pair_start(const ws_cand *c, size_t n, uint32_t a, uint32_t b)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (c[mid].a < a || (c[mid].a == a && c[mid].b < b))
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* The stick anchors' hand-over, after every candidate of the step's sorted list c[0..n) was
 * evaluated (records rec) and its scratch marks set: each contact that started in the step
 * (fresh, in the list's order) takes over the anchor of the nearest contact between the same
 * two bodies, in either order, that ended in the step within WS_ANCHOR_REACH of its point
 * (the first of equals), each ended one given once. The deflection the ended anchors have
 * now, along the ended contact's tangent plane and scaled by its share of the laws over the
 * new one's, is projected on the new contact's tangent plane; the new contact's friction is
 * evaluated again from it, its record and the bodies' loads updated. */
void ws_contact_handover(ws_contact_ctx *x, ws_cand *c, size_t n, ws_contact_rec *rec);

/* Sort candidates by key and carry stick anchors (and clearances) over from the previous list
 * (also sorted). */
void ws_contact_sort(ws_cand *c, size_t n);
void ws_contact_carry_anchors(ws_cand *nw, size_t n_new, const ws_cand *old, size_t n_old);

/* Body pairs whose inflated boxes overlap and not both kinematic, by sweep and prune along x:
 * *npairs of them in *pairs (two slots each, the lower first), from the arena a, as is the
 * sweep's order. 0, or -1 when out of memory. */
int ws_broad_pairs(ws_arena *a, const ws_body_store *b, uint32_t **pairs, size_t *npairs);

/* libccd gate: 1 if the convex hulls of bodies i and j, inflated by their layers + margin/2, may
 * touch (or if the gate cannot tell: non-convex shapes, no libccd). */
int ws_ccd_may_touch_at(const ws_body_store *b, int cur, uint32_t i, uint32_t j, double margin);

#endif
