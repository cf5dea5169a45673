/* A body candidate's clearance (lib/contact/narrow.c, ws_contact_apart; contact.h,
 * WS_CLEAR_PAD): a candidate found apart sideways is not measured again while its moving
 * points stay nearer than its clearance to where they were. What must hold: a candidate it
 * judges apart is one the geometry rejects at that pose, whatever the move; and the clearance
 * reaches to where the pair starts to count, less only the pad: a vertex moved past it onto the
 * face's rim is measured and touches. */
#include "helpers.h"
#include "world/world_internal.h"

#define NCAND 4096

typedef struct pair_scene {
    ws_world *w;
    uint32_t A, B;
} pair_scene;

/* A dynamic box of 5 kg (helpers.h add_box), as its slot. */
static uint32_t box_slot(ws_world *w, double lx, double ly, double lz, ws_vec3 pos)
{
    uint32_t slot;
    ck_ok(w, ws_lookup_body(w, add_box(w, lx, ly, lz, 5.0, pos, no_material(), NULL), &slot));
    return slot;
}

/* B at pose (r, p), A where it is; the bodies' rotations as a step's preparation has them, and
 * a context for that state. */
static ws_contact_ctx place(pair_scene *S, v3 r, qt p)
{
    ws_world *w = S->w;
    ws_body_store *b = &w->bodies;
    b->st[w->cur].r[S->B] = r;
    b->st[w->cur].p[S->B] = qt_normalize(p);
    for (size_t i = 0; i < b->slots; i++)
        b->A[i] = qt_to_m3(b->st[w->cur].p[i]);
    return (ws_contact_ctx){.b = b,
                            .cur = w->cur,
                            .margin = w->def.contact_margin,
                            .params = w->params,
                            .pair_index = w->pair_index,
                            .nmat = (uint32_t)w->pair_dim};
}

static void make_pair(pair_scene *S)
{
    S->w = new_world(2.5e-4);
    S->A = box_slot(S->w, 0.25, 0.25, 0.25, (ws_vec3){0, 0, 0});
    S->B = box_slot(S->w, 0.2, 0.3, 0.15, (ws_vec3){0, 0, 0.5});
}

/* A reproducible uniform number in [0, 1) (xorshift64*). */
static double uniform(uint64_t *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) * 0x1.0p-53;
}

static v3 random_dir(uint64_t *s)
{
    for (;;) {
        v3 d = v3_make(2 * uniform(s) - 1, 2 * uniform(s) - 1, 2 * uniform(s) - 1);
        double n = v3_norm(d);
        if (n > 0.1 && n <= 1.0)
            return v3_scale(d, 1.0 / n);
    }
}

/* 10^(lo + (hi - lo) u): sizes of a move spread over decades. */
static double log_uniform(uint64_t *s, double lo, double hi)
{
    return pow(10.0, lo + (hi - lo) * uniform(s));
}

START_TEST(test_apart_is_never_in_contact)
{
    /* B (0.2 x 0.3 x 0.15 m) on or beside cube A (0.25 m), turned up to 0.3 rad about a random
     * axis and within a centimetre of touching, or resting on A's top with its corners within
     * 3 mm of A's rim, turned up to 0.01 rad; every candidate of the pair (margin 2 cm) is
     * measured there, then B is moved by 1 um to 6 mm and turned by 1e-6 to 0.02 rad, and each
     * candidate judged apart there must be one the geometry rejects. */
    pair_scene S;
    make_pair(&S);
    static ws_cand cand[NCAND], moved[NCAND];
    uint64_t rng = 0x9e3779b97f4a7c15ull;
    size_t apart = 0, judged = 0, expired_touching = 0, wrong = 0;
    for (int trial = 0; trial < 600; trial++) {
        v3 r;
        double turn = 0.3;
        if (trial % 3 == 0) { /* on A's top */
            r = v3_make(0.5 * uniform(&rng) - 0.25, 0.5 * uniform(&rng) - 0.25,
                        0.2 + 0.02 * uniform(&rng) - 0.01);
        } else if (trial % 3 == 1) { /* beside A's +x face */
            r = v3_make(0.225 + 0.02 * uniform(&rng) - 0.01, 0.5 * uniform(&rng) - 0.25,
                        0.3 * uniform(&rng) - 0.15);
        } else { /* resting on A's top, its -x face within 3 mm of A's +x rim */
            r = v3_make(0.225 + 6e-3 * uniform(&rng) - 3e-3, 0.2 * uniform(&rng) - 0.1,
                        0.2 + 0.5 * (S.w->bodies.layer[S.A] + S.w->bodies.layer[S.B]));
            turn = 0.01;
        }
        qt p = qt_from_rotvec(v3_scale(random_dir(&rng), turn * uniform(&rng)));
        ws_contact_ctx x = place(&S, r, p);
        x.margin = 0.02;
        size_t n = 0, cap = NCAND;
        ws_cand *list = cand;
        ck_assert_int_eq(ws_contact_candidates(NULL, &x, S.A, S.B, &list, &n, &cap), 0);
        for (size_t k = 0; k < n; k++) {
            v3 xg, ng;
            double d, share;
            ws_contact_geometry(&x, &cand[k], &xg, &ng, &d, &share);
            apart += cand[k].clear > 0.0;
        }
        /* The move: its size spread over decades, so that some clearances last and some run
         * out. */
        const v3 r2 = v3_add(r, v3_scale(random_dir(&rng), log_uniform(&rng, -6, log10(6e-3))));
        const qt p2 = qt_mul(
            qt_from_rotvec(v3_scale(random_dir(&rng), log_uniform(&rng, -6, log10(0.02)))), p);
        ws_contact_ctx y = place(&S, r2, p2);
        memcpy(moved, cand, n * sizeof *cand);
        for (size_t k = 0; k < n; k++) {
            v3 xg, ng;
            double d, share;
            const int skip = ws_contact_apart(&y, &cand[k]);
            const int touch = ws_contact_geometry(&y, &moved[k], &xg, &ng, &d, &share);
            judged += skip;
            wrong += skip && touch;
            expired_touching += !skip && cand[k].clear > 0.0 && touch;
        }
    }
    report("clearance: %zu candidates found apart, %zu judged apart after the move, %zu "
           "touching once their clearance ran out, %zu judged apart while touching",
           apart, judged, expired_touching, wrong);
    ck_assert_msg(wrong == 0, "%zu candidates judged apart were in contact", wrong);
    /* Not vacuous: the clearance is used, and moves that use it up reach contacts. */
    ck_assert_msg(judged > 1000, "only %zu candidates judged apart", judged);
    ck_assert_msg(expired_touching > 0,
                  "no clearance ran out into a contact (%zu apart, %zu judged)", apart, judged);
    ws_world_destroy(S.w);
}
END_TEST

START_TEST(test_clearance_reaches_the_rim)
{
    /* B unrotated over A's top, its bottom face at the layers' mid-gap, shifted along +x (and
     * +y by 5 cm) so that its corner V at (-0.1, -0.15, -0.075) of B lies over A's top face's
     * plane e = 3 mm past A's +x rim (B's -x face at x = 0.125 + e), at y = -0.1. Candidate:
     * A's top face, B's vertex V. Its clearance is e less WS_OUTLINE_TOL, the barycentric
     * tolerance of the face (1e-9 of its 0.35 m diagonal) and WS_CLEAR_PAD: to 1e-15 m. Moved
     * towards the rim by the clearance less 1 nm, V is judged apart; moved to half the outline
     * tolerance past the rim (by e - WS_OUTLINE_TOL / 2, just more than the clearance), it is
     * measured and counts on the face. */
    pair_scene S;
    make_pair(&S);
    const double e = 3e-3;
    const double layers = S.w->bodies.layer[S.A] + S.w->bodies.layer[S.B];
    const double z = 0.125 + 0.075 + 0.5 * layers;
    ws_contact_ctx x = place(&S, v3_make(0.125 + e + 0.1, 0.05, z), qt_identity());
    const ws_shape *sa = S.w->bodies.shape[S.A], *sb = S.w->bodies.shape[S.B];
    uint32_t top = 0, v = 0;
    for (uint32_t f = 1; f < sa->face_count; f++)
        if (sa->faces[f].normal.z > sa->faces[top].normal.z)
            top = f;
    for (uint32_t k = 1; k < sb->vertex_count; k++)
        if (v3_norm(v3_sub(sb->vertices[k], v3_make(-0.1, -0.15, -0.075))) <
            v3_norm(v3_sub(sb->vertices[v], v3_make(-0.1, -0.15, -0.075))))
            v = k;
    ws_cand c = {.a = S.A, .b = S.B, .fa = top, .fb = v, .kind = WS_CONTACT_POINT_FACE};
    v3 xg, ng;
    double d, share;
    ck_assert(!ws_contact_geometry(&x, &c, &xg, &ng, &d, &share));
    const double expect =
        e - WS_OUTLINE_TOL - WS_FEATURE_TOL * sqrt(2 * 0.25 * 0.25) - WS_CLEAR_PAD;
    report("clearance of a vertex 3 mm past the rim: %.15g m (expected %.15g)", c.clear, expect);
    ck_assert_msg(fabs(c.clear - expect) < 1e-15, "clearance %.17g, expected %.17g", c.clear,
                  expect);
    ws_cand near = c;
    ws_contact_ctx y =
        place(&S, v3_make(0.125 + e + 0.1 - (c.clear - 1e-9), 0.05, z), qt_identity());
    ck_assert_msg(ws_contact_apart(&y, &near), "moved by less than its clearance, not apart");
    ck_assert(!ws_contact_geometry(&y, &near, &xg, &ng, &d, &share));
    ws_cand on = c;
    y = place(&S, v3_make(0.125 + 0.5 * WS_OUTLINE_TOL + 0.1, 0.05, z), qt_identity());
    ck_assert_msg(!ws_contact_apart(&y, &on), "moved onto the rim, judged apart");
    ck_assert_msg(ws_contact_geometry(&y, &on, &xg, &ng, &d, &share),
                  "half the outline tolerance past the rim, the vertex does not count");
    ck_assert(on.clear == 0.0);
    ws_world_destroy(S.w);
}
END_TEST

static Suite *clearance_suite(void)
{
    Suite *s = suite_create("contact_clearance");
    add_case(s, "apart", test_apart_is_never_in_contact, 60);
    add_case(s, "rim", test_clearance_reaches_the_rim, 60);
    return s;
}

int main(void)
{
    return run_suite(clearance_suite());
}
