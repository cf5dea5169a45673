/* The stick anchor's hand-over between body contacts (lib/contact/force.c,
 * ws_contact_handover), on candidate lists built by hand over a real scene: which contact takes
 * over which anchor, and what it gets. The physics (the friction on a box continuous while its
 * corner crosses a rim) is test_contact.c's test_pulled_corner_keeps_its_friction; here the
 * rules: the deflection carried over, one inheritor per ended contact, never across body
 * pairs, and only from a contact that has ended.
 *
 * The scene: a kinematic cube A (0.25 m) and a dynamic cube B on it, unrotated, B shifted
 * 10 mm along -y and 3 um along +x, so that B's corner V lies 3 um past A's +x rim (past
 * WS_OUTLINE_TOL: V is not on A's top face) at a height of 2 delta - 0.1 mm over it. The edge
 * pair of A's rim edge and B's bottom edge through V is in contact, 3 um from V; the
 * point-face pair (A's top face, V) is not. A small box C stands on A's top face beside B. */
#include "helpers.h"
#include "world/world_internal.h"

#define DELTA 1e-3

typedef struct scene {
    ws_world *w;
    uint32_t A, B, C;
    uint32_t top_face, vertex_v, rim_edge, edge_v, c_vertex;
    ws_contact_ctx x;
} scene;

static ws_body_id box(ws_world *w, ws_body_type type, double lx, double ly, double lz, ws_vec3 pos)
{
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, lx, ly, lz, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.type = type;
    bd.shape = s;
    bd.mass = type == WS_BODY_DYNAMIC ? 5.0 : 0.0;
    bd.position = pos;
    ws_body_id id;
    ck_ok(w, ws_body_create(w, &bd, &id));
    return id;
}

/* The index of the vertex of shape s nearest p (its frame), of the edge joining the vertices
 * nearest p and q, of the face whose outward normal is nearest n. */
static uint32_t vertex_at(const ws_shape *s, v3 p)
{
    uint32_t best = 0;
    for (uint32_t k = 1; k < s->vertex_count; k++)
        if (v3_norm(v3_sub(s->vertices[k], p)) < v3_norm(v3_sub(s->vertices[best], p)))
            best = k;
    return best;
}

static uint32_t edge_between(const ws_shape *s, v3 p, v3 q)
{
    uint32_t i = vertex_at(s, p), j = vertex_at(s, q);
    for (uint32_t k = 0; k < s->edge_count; k++)
        if ((s->edges[k].a == i && s->edges[k].b == j) ||
            (s->edges[k].a == j && s->edges[k].b == i))
            return k;
    ck_abort_msg("no edge between the vertices");
    return 0;
}

static uint32_t face_along(const ws_shape *s, v3 n)
{
    uint32_t best = 0;
    for (uint32_t k = 1; k < s->face_count; k++)
        if (v3_dot(s->faces[k].normal, n) > v3_dot(s->faces[best].normal, n))
            best = k;
    return best;
}

static void make_scene(scene *S)
{
    const double a = 0.25, gap = 2 * DELTA - 1e-4;
    ws_contact_def cd;
    ws_contact_def_init(&cd);
    cd.stiffness = 2e5;
    cd.damping = 10.0;
    cd.friction = 0.5;
    cd.friction_model = WS_FRICTION_STICK;
    S->w = new_world(2.5e-4);
    ck_ok(S->w, ws_world_set_default_contact(S->w, &cd));
    ws_body_id A = box(S->w, WS_BODY_KINEMATIC, a, a, a, (ws_vec3){0, 0, 0});
    ws_body_id B = box(S->w, WS_BODY_DYNAMIC, a, a, a, (ws_vec3){3e-6, -0.01, a + gap});
    ws_body_id C =
        box(S->w, WS_BODY_DYNAMIC, 0.05, 0.006, 0.05, (ws_vec3){0, 0.12, a / 2 + 0.025 + gap});
    ck_ok(S->w, ws_lookup_body(S->w, A, &S->A));
    ck_ok(S->w, ws_lookup_body(S->w, B, &S->B));
    ck_ok(S->w, ws_lookup_body(S->w, C, &S->C));
    ck_assert(S->A < S->B && S->B < S->C);
    ws_world *w = S->w;
    ws_body_store *b = &w->bodies;
    /* The step's preparation, for the contacts' evaluation at the committed state. */
    for (size_t i = 0; i < b->slots; i++) {
        b->A[i] = qt_to_m3(b->st[w->cur].p[i]);
        b->wg[i] = m3_mul_v(&b->A[i], b->st[w->cur].w[i]);
        b->f[i] = b->m[i] = v3_make(0, 0, 0);
    }
    const ws_shape *sa = b->shape[S->A], *sb = b->shape[S->B], *sc = b->shape[S->C];
    const double h = a / 2;
    S->top_face = face_along(sa, v3_make(0, 0, 1));
    S->rim_edge = edge_between(sa, v3_make(h, -h, h), v3_make(h, h, h));
    S->vertex_v = vertex_at(sb, v3_make(h, h, -h));
    S->edge_v = edge_between(sb, v3_make(-h, h, -h), v3_make(h, h, -h));
    S->c_vertex = vertex_at(sc, v3_make(0.025, 0.003, -0.025));
    S->x = (ws_contact_ctx){.b = b,
                            .cur = w->cur,
                            .margin = w->def.contact_margin,
                            .params = w->params,
                            .pair_index = w->pair_index,
                            .nmat = (uint32_t)w->pair_dim};
}

static ws_cand cand(uint32_t a, uint32_t b, uint32_t fa, uint32_t fb, uint32_t kind)
{
    return (ws_cand){.a = a, .b = b, .fa = fa, .fb = fb, .kind = kind};
}

/* An ended contact's anchors with the deflection D (b's point less a's anchor) at its place. */
static void anchor_with(scene *S, ws_cand *c, v3 D)
{
    v3 xg, n;
    double share;
    ck_assert(ws_contact_place(&S->x, c, &xg, &n, &share));
    const ws_body_store *b = &S->w->bodies;
    const ws_body_state *st = &b->st[S->w->cur];
    c->anchor_b = m3_tmul_v(&b->A[c->b], v3_sub(xg, st->r[c->b]));
    c->anchor_a = m3_tmul_v(&b->A[c->a], v3_sub(v3_sub(xg, D), st->r[c->a]));
}

/* A candidate's deflection from its anchors (b's anchor point less a's). */
static v3 deflection(const scene *S, const ws_cand *c)
{
    const ws_body_store *b = &S->w->bodies;
    const ws_body_state *st = &b->st[S->w->cur];
    return v3_sub(v3_add(st->r[c->b], m3_mul_v(&b->A[c->b], c->anchor_b)),
                  v3_add(st->r[c->a], m3_mul_v(&b->A[c->a], c->anchor_a)));
}

/* Evaluate c[k] as a contact that starts in the step (fresh anchor), into rec[r]. */
static void start(scene *S, ws_cand *c, ws_contact_rec *rec, uint32_t r)
{
    c->anchored = 0;
    ck_assert_msg(ws_contact_eval(&S->x, c, &rec[r]), "the fresh contact is not in contact");
    ck_assert(c->anchored == 1);
    c->fresh = r + 1;
}

/* Two records the same field by field (a record's padding is never written, so the records
 * are not compared as bytes). */
static int same_rec(const ws_contact_rec *p, const ws_contact_rec *q)
{
    const v3 *pv[] = {&p->x, &p->n, &p->ft, &p->vt, &p->defl};
    const v3 *qv[] = {&q->x, &q->n, &q->ft, &q->vt, &q->defl};
    for (int i = 0; i < 5; i++)
        if (memcmp(pv[i], qv[i], sizeof(v3)) != 0)
            return 0;
    return p->a == q->a && p->b == q->b && p->kind == q->kind && p->slipping == q->slipping &&
           p->at_cap == q->at_cap && memcmp(&p->overlap, &q->overlap, sizeof(double)) == 0 &&
           memcmp(&p->fn, &q->fn, sizeof(double)) == 0 &&
           memcmp(&p->energy, &q->energy, sizeof(double)) == 0 &&
           memcmp(&p->energy_t, &q->energy_t, sizeof(double)) == 0;
}

START_TEST(test_handover_carries_the_deflection_once)
{
    /* The point-face pair (A's face, V) ended with a deflection D = (4, -2, 0) um (tangential
     * to its normal z); the edge pair at V, 3 um away, started. The edge pair's normal is the
     * crossing edges' x X y = z (B unrotated), so it takes D whole: its anchors' deflection D
     * (to round-off, 1e-15 m), its friction -k_t D = (-0.8, 0.4, 0) N (at rest: no damping;
     * below the cap mu N = 10 N) added to B's load and taken from A's. A second contact
     * starting at the same place (the same pair again) gets nothing: one inheritor per
     * ended contact. */
    scene S;
    make_scene(&S);
    const v3 D = v3_make(4e-6, -2e-6, 0);
    ws_cand c[3] = {cand(S.A, S.B, S.top_face, S.vertex_v, WS_CONTACT_POINT_FACE),
                    cand(S.A, S.B, S.rim_edge, S.edge_v, WS_CONTACT_EDGE_EDGE),
                    cand(S.A, S.B, S.rim_edge, S.edge_v, WS_CONTACT_EDGE_EDGE)};
    ws_contact_rec rec[2];
    ws_contact_rec scratch;
    ck_assert_msg(!ws_contact_eval(&S.x, &c[0], &scratch), "V counts on A's face");
    anchor_with(&S, &c[0], D);
    c[0].ended = 1;
    start(&S, &c[1], rec, 0);
    start(&S, &c[2], rec, 1);
    const ws_contact_rec fresh = rec[1];
    const v3 fB = S.w->bodies.f[S.B], fA = S.w->bodies.f[S.A];
    const v3 ft0 = rec[0].ft;
    ws_contact_handover(&S.x, c, 3, rec);
    ck_assert_int_eq(c[0].ended, 2);
    const v3 d1 = deflection(&S, &c[1]);
    ck_assert_msg(v3_norm(v3_sub(d1, D)) < 1e-15, "inherited deflection (%g, %g, %g) um",
                  1e6 * d1.x, 1e6 * d1.y, 1e6 * d1.z);
    const v3 want = v3_scale(D, -2e5);
    ck_assert_msg(v3_norm(v3_sub(rec[0].ft, want)) < 1e-9, "friction (%g, %g, %g) N", rec[0].ft.x,
                  rec[0].ft.y, rec[0].ft.z);
    ck_assert_msg(v3_norm(v3_sub(rec[0].defl, D)) < 1e-15, "recorded deflection");
    ck_assert_msg(fabs(rec[0].energy_t - 0.5 * 2e5 * v3_norm2(D)) < 1e-15, "anchor energy");
    const v3 dF = v3_sub(rec[0].ft, ft0);
    ck_assert(v3_norm(v3_sub(v3_sub(S.w->bodies.f[S.B], fB), dF)) < 1e-12);
    ck_assert(v3_norm(v3_add(v3_sub(S.w->bodies.f[S.A], fA), dF)) < 1e-12);
    /* the second starter keeps its fresh anchor and its record */
    ck_assert(v3_norm(deflection(&S, &c[2])) < 1e-15);
    ck_assert(same_rec(&rec[1], &fresh));
    ws_world_destroy(S.w);
}
END_TEST

START_TEST(test_handover_only_within_a_pair)
{
    /* A contact between A and C that starts in the step, reported (by hand) at the very place
     * of the ended (A, B) contact: it must not take B's anchor, and the (A, B) contact is left
     * for an inheritor of its own pair. Then a fresh (A, B) contact does take it. */
    scene S;
    make_scene(&S);
    const v3 D = v3_make(4e-6, -2e-6, 0);
    ws_cand c[3] = {cand(S.A, S.B, S.top_face, S.vertex_v, WS_CONTACT_POINT_FACE),
                    cand(S.A, S.B, S.rim_edge, S.edge_v, WS_CONTACT_EDGE_EDGE),
                    cand(S.A, S.C, S.top_face, S.c_vertex, WS_CONTACT_POINT_FACE)};
    ws_contact_rec rec[2];
    anchor_with(&S, &c[0], D);
    c[0].ended = 1;
    start(&S, &c[2], rec, 0);
    v3 xg, n;
    double share;
    ck_assert(ws_contact_place(&S.x, &c[0], &xg, &n, &share));
    rec[0].x = xg;
    const ws_cand before = c[2];
    ws_contact_handover(&S.x, c, 3, rec);
    ck_assert_int_eq(c[0].ended, 1);
    ck_assert(memcmp(&c[2].anchor_a, &before.anchor_a, sizeof(v3)) == 0 &&
              memcmp(&c[2].anchor_b, &before.anchor_b, sizeof(v3)) == 0);
    start(&S, &c[1], rec, 1);
    c[2].fresh = 0;
    ws_contact_handover(&S.x, c, 3, rec);
    ck_assert_int_eq(c[0].ended, 2);
    ck_assert(v3_norm(v3_sub(deflection(&S, &c[1]), D)) < 1e-15);
    ws_world_destroy(S.w);
}
END_TEST

START_TEST(test_handover_only_from_an_ended_contact)
{
    /* The point-face pair still in contact (not ended: its mark 0, anchored) beside a starting
     * edge pair: nothing is handed over; a contact's anchor passes only when it is gone. The
     * same with the ended contact farther than WS_ANCHOR_REACH: its place moved (by hand) 0.2 mm
     * off, the starter keeps its fresh anchor. */
    scene S;
    make_scene(&S);
    const v3 D = v3_make(4e-6, -2e-6, 0);
    ws_cand c[2] = {cand(S.A, S.B, S.top_face, S.vertex_v, WS_CONTACT_POINT_FACE),
                    cand(S.A, S.B, S.rim_edge, S.edge_v, WS_CONTACT_EDGE_EDGE)};
    ws_contact_rec rec[1];
    anchor_with(&S, &c[0], D);
    c[0].anchored = 1;
    c[0].ended = 0;
    start(&S, &c[1], rec, 0);
    ws_contact_handover(&S.x, c, 2, rec);
    ck_assert(v3_norm(deflection(&S, &c[1])) < 1e-15);
    c[0].ended = 1;
    rec[0].x = v3_add(rec[0].x, v3_make(0, 2e-4, 0));
    ws_contact_handover(&S.x, c, 2, rec);
    ck_assert_int_eq(c[0].ended, 1);
    ck_assert(v3_norm(deflection(&S, &c[1])) < 1e-15);
    ws_world_destroy(S.w);
}
END_TEST

static Suite *handover_suite(void)
{
    Suite *s = suite_create("contact_handover");
    TCase *tc = tcase_create("rules");
    tcase_set_timeout(tc, 20);
    tcase_add_test(tc, test_handover_carries_the_deflection_once);
    tcase_add_test(tc, test_handover_only_within_a_pair);
    tcase_add_test(tc, test_handover_only_from_an_ended_contact);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return run_suite(handover_suite());
}
