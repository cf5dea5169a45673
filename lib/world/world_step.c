#define _POSIX_C_SOURCE 200809L /* clock_gettime, for the optional phase timing */
/* ws_world_step(): the one orchestrator. Data flows one way:
 *   (1) state at t -> rotation matrices, global angular velocities, inflated boxes;
 *   (2) contact detection: full (broad phase, optional libccd gate, candidate feature pairs) or
 *       the cached candidates carried over;
 *   (3) forces: gravity, then every candidate evaluated (penalty + friction on both bodies),
 *       then the deformable elements (rods, springs, bushings: world_element.c), then the
 *       webs' (with workers and only explicit webs the candidates are evaluated beside the
 *       film's first sub-step and the elements follow the film: the same sums, step_once);
 *   (4) the bodies' friction taken at the end of the step (world_friction.c: one solve over
 *       the bodies, its change added to their loads); integration into the other state
 *       buffer; world elements from their drives at t + dt;
 *   (5) health check; (6) commit by swapping buffers and t += dt.
 * Nothing is committed before (6), so a failed step leaves the world as it was. */
#include "contact/penalty.h"
#include "world/world_internal.h"

#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Wall clock for the optional phase timing (0 when profiling is off, so nothing is asked). */
static double clock_now(const ws_world *w)
{
    if (!w->def.profile)
        return 0.0;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void prepare(ws_world *w)
{
    ws_body_store *b = &w->bodies;
    const ws_body_state *st = &b->st[w->cur];
    v3 g = w->def.gravity;
    double half_margin = 0.5 * w->def.contact_margin;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        m3 A = qt_to_m3(st->p[i]);
        b->A[i] = A;
        b->wg[i] = m3_mul_v(&A, st->w[i]);
        b->f[i] = b->type[i] == WS_BODY_DYNAMIC ? v3_scale(g, b->mass[i]) : v3_make(0, 0, 0);
        b->m[i] = v3_make(0, 0, 0);
        /* Global box of the rotated local box: centre moved, half extents through |A|. */
        const ws_shape *s = b->shape[i];
        v3 c = v3_scale(v3_add(s->lo, s->hi), 0.5), e = v3_scale(v3_sub(s->hi, s->lo), 0.5);
        v3 cg = v3_add(st->r[i], m3_mul_v(&A, c));
        const double *a = A.m;
        double pad = b->layer[i] + half_margin;
        v3 eg = v3_make(fabs(a[0]) * e.x + fabs(a[1]) * e.y + fabs(a[2]) * e.z + pad,
                        fabs(a[3]) * e.x + fabs(a[4]) * e.y + fabs(a[5]) * e.z + pad,
                        fabs(a[6]) * e.x + fabs(a[7]) * e.y + fabs(a[8]) * e.z + pad);
        b->lo[i] = v3_sub(cg, eg);
        b->hi[i] = v3_add(cg, eg);
    }
}

/* Largest distance any body point moves in one step from state buffer k: (|v| + |omega| r) dt
 * (|omega'| = |omega|). */
static double max_step_travel(const ws_world *w, int k)
{
    const ws_body_store *b = &w->bodies;
    const ws_body_state *st = &b->st[k];
    double most = 0.0;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        double s = v3_norm(st->v[i]) + v3_norm(st->w[i]) * b->shape[i]->radius;
        if (s > most)
            most = s;
    }
    return most * w->def.dt;
}

/* A full detection's narrow phase over the broad phase's pairs (S->pairs): the candidates of
 * each pair into cand[nxt], sorted, the stick anchors carried over. With mem NULL (beside the
 * film, on a worker) the list does not grow: -1 when its room runs out, as when out of
 * memory. */
static int detect_narrow(ws_step *S, ws_mem *mem)
{
    ws_world *w = S->w;
    const int nxt = S->nxt;
    /* The room a worker may fill (a test's, tighter), and the pairs counted when it is done. */
    size_t room = w->capcand[nxt], gated = 0, tested = 0;
    if (!mem && w->narrow_tight && room > 2)
        room = 2;
    w->ncand[nxt] = 0;
    for (size_t k = 0; k < S->npairs; k++) {
        uint32_t i = S->pairs[2 * k], j = S->pairs[2 * k + 1];
        if (w->def.use_ccd && !ws_ccd_may_touch_at(S->b, S->cur, i, j, S->contact.margin)) {
            gated++;
            continue;
        }
        tested++;
        if (ws_contact_candidates(mem, &S->contact, i, j, &w->cand[nxt], &w->ncand[nxt],
                                  mem ? &w->capcand[nxt] : &room) != 0)
            return -1;
    }
    S->stats->body_pairs_gated += gated;
    S->stats->body_pairs_tested += tested;
    ws_contact_sort(w->cand[nxt], w->ncand[nxt]);
    ws_contact_carry_anchors(w->cand[nxt], w->ncand[nxt], w->cand[S->cur], w->ncand[S->cur]);
    return 0;
}

/* Room for the candidates and records of a narrow phase beside the film: twice the last
 * list's and some, so that it rarely runs out (then it runs again here, with the room grown:
 * step_once). 0, or -1 when out of memory. */
static int narrow_room(ws_step *S)
{
    ws_world *w = S->w;
    const int nxt = S->nxt;
    return ws_array_reserve(&w->mem, (void **)&w->cand[nxt], &w->capcand[nxt],
                            2 * w->ncand[S->cur] + 64, sizeof *w->cand[nxt]) ||
                   ws_array_reserve(&w->mem, (void **)&w->rec[nxt], &w->caprec[nxt],
                                    w->capcand[nxt] + 1, sizeof *w->rec[nxt])
               ? -1
               : 0;
}

static ws_status detect_full(ws_step *S)
{
    ws_world *w = S->w;
    if (ws_broad_pairs(S->arena, S->b, &S->pairs, &S->npairs) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory in the broad phase");
    if (S->body_later) { /* the narrow phase beside the film, before the body contacts */
        S->narrow_later = 1;
        if (narrow_room(S) != 0)
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for contact candidates");
        return WS_OK;
    }
    if (detect_narrow(S, &w->mem) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for contact candidates");
    return WS_OK;
}

static const char *web_label(const ws_web *web)
{
    return web->name ? web->name : "(unnamed)";
}

/* x rounded up to 4 significant digits so that the number as printed (%.4g) and read back is
 * still >= x: advice that, taken literally, works. */
static double round_up_4(double x)
{
    if (!(x > 0.0 && x < 1e300))
        return x;
    double p = pow(10.0, floor(log10(x)) - 3.0);
    for (double y = ceil(x / p) * p;; y += p) {
        char txt[32];
        snprintf(txt, sizeof txt, "%.4g", y);
        if (strtod(txt, NULL) >= x)
            return strtod(txt, NULL);
    }
}

/* What would make a web stable at sub-step h: sub-steps for the world's dt, or node mass, both
 * from the bound the check uses (h <= stable), so that the advice taken as given is accepted
 * and a little less is not. */
static ws_status web_unstable(ws_world *w, const ws_web *web, double h, double stable,
                              const char *what)
{
    const double f = w->def.stable_fraction;
    const double mmin = ws_web_node_limits(web, 0.0, 0.0, 0.0).min_mass;
    w->stats.numerical_errors++; /* refused or ran away: either way a WS_ERR_NUMERICAL step */
    double allowed = f * stable; /* what the check lets dt/substeps use */
    if (h <= allowed) /* ran away though stable as its laws state them: sub-steps would not help */
        return ws_fail(w, WS_ERR_NUMERICAL,
                       "web '%s': %s, though dt/substeps = %.3g s is within %g of its stable "
                       "step %.3g s: a spring law stiffer or stronger than it states (a user or "
                       "table law), or a body that hits the film too fast. Try a smaller dt.",
                       web_label(web), what, h, f, stable);
    /* Sub-steps: dt / n <= allowed. The quotient is bounded before it becomes an int (a stable
     * step of about 0 would overflow it). */
    char sub[192], mass[128];
    double q = w->def.dt / allowed;
    if (q <= (double)WS_WEB_MAX_SUBSTEPS) {
        int n = (int)ceil(q);
        n += w->def.dt / n > allowed; /* the division rounded the wrong way */
        snprintf(sub, sizeof sub, "Use substeps >= %d (ws_web_set_substeps), or", n);
    } else {
        snprintf(sub, sizeof sub,
                 "Sub-steps cannot help (it would take more than the limit of %d: dt / stable "
                 "step = %.3g); use a softer or less pre-stretched film, or",
                 WS_WEB_MAX_SUBSTEPS, q);
    }
    /* Node mass: the check's own bound inverted (ws_web_node_limits): a stable sub-step of
     * h / f. */
    double m = round_up_4(ws_world_web_mass_for(w, web, h / f) * (1.0 + 1e-9)); /* round-off */
    if (m > 0.0 && m < 1e300)
        snprintf(mass, sizeof mass, "node mass >= %.4g kg (every free node)", m);
    else
        snprintf(mass, sizeof mass, "a node mass (none is large enough: %.3g kg)", m);
    return ws_fail(w, WS_ERR_NUMERICAL,
                   "web '%s': %s: it runs at dt/substeps = %.3g s but its stable step is %.3g s, "
                   "of which it may use %g (stable_fraction): %.3g s (smallest node mass %.3g "
                   "kg). %s %s, or a smaller dt; or make it implicit (ws_web_def.integrator = "
                   "WS_WEB_IMPLICIT), which has no such limit.",
                   web_label(web), what, h, stable, f, allowed, mmin, sub, mass);
}

/* Every web before the step: stable for its sub-step, and room for per-body forces. */
static ws_status webs_ready(ws_world *w)
{
    for (size_t k = 0; k < w->web_slots.slot_count; k++) {
        if (w->web_slots.dense[k] == UINT32_MAX)
            continue;
        ws_web *web = w->webs[k];
        if (web->bcap < w->bodies.slots) {
            /* All four arrays share one capacity: grow them into new blocks and keep the old
             * ones until every new one is there, so an out-of-memory leaves them as they were
             * (a partial grow would leave blocks larger than bcap says, and the free hook would
             * be told the wrong sizes). */
            size_t cap = w->bodies.capacity;
            v3 *grown[4] = {NULL, NULL, NULL, NULL};
            v3 **arr[4] = {&web->bforce[0], &web->bforce[1], &web->bmoment[0], &web->bmoment[1]};
            int ok = 1;
            for (int i = 0; i < 4 && ok; i++)
                ok = (grown[i] = ws_mem_alloc(&w->mem, cap * sizeof(v3))) != NULL;
            if (!ok) {
                for (int i = 0; i < 4; i++)
                    ws_mem_free(&w->mem, grown[i], grown[i] ? cap * sizeof(v3) : 0);
                return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for web '%s'",
                               web_label(web));
            }
            for (int i = 0; i < 4; i++) {
                if (web->bcap)
                    memcpy(grown[i], *arr[i], web->bcap * sizeof(v3));
                for (size_t j = web->bcap; j < cap; j++)
                    grown[i][j] = v3_make(0, 0, 0);
                ws_mem_free(&w->mem, *arr[i], web->bcap * sizeof(v3));
                *arr[i] = grown[i];
            }
            web->bcap = cap;
        }
        /* An implicit web is stable at any step for its stiffness: no refusal. */
        if (w->web_check && web->integrator == WS_WEB_EXPLICIT) {
            double h = w->def.dt / web->substeps, stable = ws_world_web_stable_dt(w, web);
            if (!(h <= w->def.stable_fraction * stable)) /* NaN refuses too */
                return web_unstable(w, web, h, stable, "refused before the step");
        }
    }
    w->web_check = 0;
    return WS_OK;
}

static void body_contacts(ws_step *S);
static int contacts_begin(ws_step *S, uint32_t pieces, int twins);
static void contacts_twins_ready(ws_step *S, int whole);
static void contacts_piece(ws_step *S, uint32_t p);
static void contacts_end(ws_step *S);

/* What every lane of a web's sub-step reads (the lanes' own parts are in w->lane_job). */
typedef struct lane_task {
    ws_world *w;
    ws_web *web; /* read only while the lanes run: each opens its views from it (lane_open) */
    ws_node_pass pass; /* the node contacts' part (pass.x, pass.v: the state read) */
    ws_nodes3 xd, vd;  /* the state written */
    /* The first sub-step of a step: each lane zeroes the contact forces of the next state in
     * its own rows, a block before its contacts add to them, so that they are in its core's
     * cache (and no list of the nodes touched is kept). */
    int zero;
    uint32_t lanes;
    /* The body part of the step, items from `lanes` on of the task (NULL: none in this one),
     * and which: a full detection's narrow phase (BODY_NARROW), the twins (BODY_TWINS), the
     * body contacts (BODY_CONTACTS), each where its sub-step's lanes leave room. */
    ws_step *body;
    int body_part;
    /* Beside a web's lanes (body_plan): the body part in `items` items of the task, the
     * twins in as many parts (BODY_TWINS), the measured pieces [piece0, piece0 + pieces)
     * shared among them (contacts_piece; 0 pieces: the contacts whole, as body_contacts takes
     * them); after a narrow phase (its item the task's only) the twins' cuts cleared, and with
     * twins_after 2 the twins whole too. */
    uint32_t piece0, pieces, items;
    int twins_after;
} lane_task;

enum { BODY_NARROW = 1, BODY_CONTACTS = 2, BODY_TWINS = 4 };

/* Body item j of a sub-step's task: the narrow phase, item j's part of the twins, the contacts
 * (whole, or item j's share of the sub-step's measured pieces), as T says (lane_task). */
static void body_item(const lane_task *T, uint32_t j)
{
    ws_step *S = T->body;
    ws_world *w = S->w;
    if ((T->body_part & BODY_NARROW) && S->narrow_later) {
        S->narrow_bad = detect_narrow(S, NULL) != 0;
        S->narrow_later = 0;
        if (T->twins_after && !S->narrow_bad)
            contacts_twins_ready(S, T->twins_after == 2);
    }
    if ((T->body_part & BODY_TWINS) && !S->narrow_bad)
        ws_contact_twins_part(&S->contact, w->cand[S->nxt], w->ncand[S->nxt], j, T->items);
    if (!(T->body_part & BODY_CONTACTS))
        return;
    if (!T->pieces) {
        body_contacts(S);
        return;
    }
    for (uint32_t p = j * T->pieces / T->items; p < (j + 1) * T->pieces / T->items; p++)
        contacts_piece(S, T->piece0 + p);
}

static void lane_open(ws_world *w, ws_web *web, uint32_t i);

/* One lane's blocks of a sub-step: forces, node contacts, integration, block by block. */
static void sweep_lane(const lane_task *T, ws_lane_job *J)
{
    lane_open(T->w, T->web, (uint32_t)(J - T->w->lane_job));
    ws_world *w = T->w;
    ws_web *web = &J->view;
    const uint32_t rows = ws_web_rows(web), r = ws_web_block_rows(web);
    uint32_t n0 = ws_web_row_node(web, J->r0), n1;
    size_t next = J->r0 ? ws_node_first_segment(&J->cview, n0) : 0;
    ws_node_substep(&J->cview);
    if (T->zero && T->web->contact->merging) /* the lane's part of the step's merge first */
        ws_node_merge_range(&T->web->contact->merge, n0,
                            J->r1 == rows ? web->n : J->cview.lane_end);
    const ws_web_pass P = {T->pass.x, T->pass.v, T->xd, T->vd, T->pass.h, w->def.max_speed};
    ws_web_sweep_begin(web, &P);
    /* Blocks of r rows from the lane's first row (the last may be shorter). */
    for (uint32_t j = J->r0; j < J->r1; j += r) {
        const uint32_t j1 = J->r1 - j > r ? j + r : J->r1;
        const int edges = (j == J->r0 && j > 0 ? WS_WEB_LANE_FIRST : 0) |
                          (j1 == J->r1 && j1 < rows ? WS_WEB_LANE_LAST : 0);
        ws_web_forces_rows(web, &P, j, j1, edges, &n0, &n1);
        if (T->zero) /* where the block's contacts add first: in the cache when they do */
            memset(T->pass.fc + n0, 0, (n1 - n0) * sizeof(v3));
        /* Each row's loads on the bodies folded apart: rows, unlike lanes, do not depend on
         * the worker count, so neither do the totals (lane_close). */
        ws_node_contact *c = &J->cview;
        const size_t from = c->act_nl;
        c->nrow_mark = 0;
        ws_node_contacts(&T->pass, web, n1, &next, &J->checks);
        size_t at = c->row_mark ? from : ws_node_loads_fold(c, from, c->act_nl, from);
        for (size_t m = 0; m < c->nrow_mark; m++)
            at = ws_node_loads_fold(c, c->row_mark[m],
                                    m + 1 < c->nrow_mark ? c->row_mark[m + 1] : c->act_nl, at);
        c->act_nl = at;
        J->fast += ws_web_integrate_block(web, &P, n0, n1);
    }
    ws_web_sweep_end(web);
}

/* Items [start, end) of a sub-step's lanes (ws_task_fn), and after them the body contacts
 * when the task carries them. */
static void lane_items(int32_t start, int32_t end, uint32_t worker, void *ctx)
{
    (void)worker; /* a lane's scratch is its own, whichever worker takes it */
    const lane_task *T = ctx;
    for (int32_t i = start; i < end; i++) {
        if ((uint32_t)i < T->lanes)
            sweep_lane(T, &T->w->lane_job[i]);
        else
            body_item(T, (uint32_t)i - T->lanes);
    }
}

/* The lanes a web's sweep is cut into: one unless the world has workers and the web can be
 * swept in lanes (ws_web_sweep_parallel); else WS_LANES_PER_WORKER a worker, at most one a
 * block. The same lanes, on the same workers, run the move test and every sub-step, so a
 * lane's nodes stay in the cache of the core that runs it. */
static uint32_t web_lanes(const ws_world *w, const ws_web *web)
{
    const uint32_t blocks = ws_web_block_count(web),
                   most = WS_LANES_PER_WORKER * w->def.worker_count;
    uint32_t lanes = w->def.worker_count > 1 ? most : 1;
    if (lanes > blocks)
        lanes = blocks;
    /* An implicit web solves on the calling thread (world_implicit.c): one lane, so that the
     * node contact forces are zeroed here and not by lanes that do not run. */
    if (web->integrator == WS_WEB_IMPLICIT)
        return 1;
    return lanes < 2 || !ws_web_sweep_parallel(web) ? 1 : lanes;
}

/* Whether the lanes' rows cover the web's ny rows in order, each lane some. */
static int lanes_cover(const ws_lane_job *J, uint32_t lanes, uint32_t ny)
{
    int ok = J[0].r0 == 0 && J[lanes - 1].r1 == ny;
    for (uint32_t i = 0; i < lanes; i++)
        ok &= J[i].r0 < J[i].r1 && J[i].r1 <= ny && (i == 0 || J[i].r0 == J[i - 1].r1);
    return ok;
}

enum { LANES_CUT_EVERY = 16 };

/* The rows of each of the lanes (r0, r1), cut so that their work is about equal: a row costs
 * its nodes (springs, integration, a contact each in a run) and 0.6 of a node for each
 * candidate it takes one by one (a fit of the lanes' times on the wrapped reference case).
 * Every lane but the last holds a block's rows at least, the last a row: the run kernel's
 * groups, which may start up to three nodes before a node of the lane's end, stay within it.
 * The results do not depend on the cut. (A cut between blocks, tried, left the two workers'
 * shares of the wrapped case 8 % apart, against 5.5 % by rows.) */
static void lanes_cut(ws_world *w, const ws_web *web, uint32_t lanes)
{
    ws_lane_job *J = w->lane_job;
    if (lanes == 1) {
        J[0].r0 = 0;
        J[0].r1 = ws_web_rows(web);
        return;
    }
    const ws_node_contact *nc = web->contact;
    const uint32_t ny = ws_web_rows(web), r = ws_web_block_rows(web);
    /* The cut of the last steps serves this web for LANES_CUT_EVERY steps: the work moves
     * slowly, and a cut (two passes over the stretches) cost 0.9 instructions a node-update,
     * alone on the calling thread. */
    if (w->cut_web == web && w->steps - w->cut_step < LANES_CUT_EVERY &&
        lanes_cover(J, lanes, ny))
        return;
    w->cut_web = web;
    w->cut_step = w->steps;
    const int segs = nc->seg_list == nc->next_list;
    uint64_t total = 5ull * web->n, acc = 0;
    for (size_t s = 0; segs && s < nc->nseg; s++)
        total += nc->seg[s].run ? 0 : 3ull * (nc->seg[s].c1 - nc->seg[s].c0);
    uint32_t i = 1;
    J[0].r0 = 0;
    for (uint32_t j = 0, s = 0; j < ny && i < lanes; j++) {
        const uint32_t end = ws_web_row_node(web, j + 1);
        acc += 5ull * (end - ws_web_row_node(web, j)); /* row j, with its stretches */
        for (; segs && s < nc->nseg && nc->seg[s].n0 < end; s++)
            acc += nc->seg[s].run ? 0 : 3ull * (nc->seg[s].c1 - nc->seg[s].c0);
        /* Lane i starts after row j once the lanes before have their share, within room. */
        const uint32_t lo = J[i - 1].r0 + r, hi = ny - (lanes - i - 1) * r - 1;
        if ((acc * lanes >= total * i && j + 1 >= lo) || j + 1 == hi) {
            J[i - 1].r1 = J[i].r0 = j + 1;
            i++;
        }
    }
    J[lanes - 1].r1 = ny;
}

/* The candidates lane i sweeps, from its rows' stretches (cut in candidate order, so those of
 * rows [r0, r1) lie between the first stretch of row r0 and that of row r1): the whole list for
 * one lane. */
static size_t lane_cands(const ws_web *web, const ws_lane_job *J, uint32_t lanes, size_t ncand)
{
    const ws_node_contact *nc = web->contact;
    if (lanes == 1)
        return ncand;
    const size_t k0 = ws_node_first_segment(nc, ws_web_row_node(web, J->r0)),
                 k1 = ws_node_first_segment(nc, ws_web_row_node(web, J->r1));
    return (k1 < nc->nseg ? nc->seg[k1].c0 : ncand) - (k0 < nc->nseg ? nc->seg[k0].c0 : ncand);
}

/* The scratch of each of the lanes (cut, lanes_cut) ready for the ncand candidates of the web:
 * the spring chunk and the list of touched nodes from the step's arena, here on the calling
 * thread before the lanes start (they never share the arena's bump pointer), and every lane's
 * marks of where its rows' loads start (a block's rows); the contact room the lanes keep (lane
 * 0's the web's own), each for the candidates of its own rows (lane_cands), so that the rooms
 * of all lanes together hold about the web's candidates, whatever the worker count. The chunk
 * is not cleared: the springs write it before they read it (lane 0's, the web's own, holds
 * the last sub-step's values), and clearing it cost the calling thread 20 kB a step. 0 when
 * out of memory. */
static int lanes_ready(ws_step *S, ws_web *web, uint32_t lanes, size_t ncand)
{
    for (uint32_t i = 0; i < lanes; i++) {
        ws_lane_job *J = &S->w->lane_job[i];
        const size_t own = lane_cands(web, J, lanes, ncand);
        if (!(J->marks = ws_arena_alloc(S->arena, (ws_web_block_rows(web) + 1) * sizeof(size_t))))
            return 0;
        if (i == 0 ? ws_node_scratch(&S->w->mem, web->contact, own) != 0
                   : (!(J->tmp = ws_arena_alloc(S->arena, WS_WEB_TMP * sizeof(double))) ||
                      !(J->fct = ws_arena_alloc(S->arena, (own + 1) * sizeof(uint32_t))) ||
                      ws_node_lane_scratch(&S->w->mem, &J->own, web->contact, web->n, own) != 0))
            return 0;
    }
    return 1;
}

/* Run items [0, count) of task on the host's scheduler, the world's threads or, for one item,
 * right here; the last `shared` items are no worker's own share on the world's threads
 * (ws_pool_run). */
static void run_task(ws_world *w, ws_task_fn *task, uint32_t count, uint32_t shared, void *ctx)
{
    if (count == 1) {
        task(0, 1, 0, ctx);
    } else if (w->def.enqueue_task) {
        void *h = w->def.enqueue_task(task, (int32_t)count, 1, ctx, w->def.task_context);
        if (h)
            w->def.finish_task(h, w->def.task_context);
    } else {
        ws_pool_run(w->pool, task, (int32_t)count, (int32_t)shared, ctx);
    }
}

static void runner_run(void *self, ws_task_fn *task, uint32_t count, void *ctx)
{
    run_task(self, task, count, 0, ctx);
}

ws_runner ws_world_runner(ws_world *w)
{
    const uint32_t k = w->def.worker_count;
    if (k <= 1)
        return (ws_runner){NULL, NULL, 1, 1};
    return (ws_runner){runner_run, w, k, WS_LANES_PER_WORKER * k};
}

/* The move test of a web's nodes, lane by lane (ws_task_fn; the nodes of lane i as it sweeps
 * them): each lane flags its nodes, lists the flagged ones and measures them against the far
 * bodies (ws_node_flag_lane, into fl[i]); and prepares the features of every lanes-th body
 * from slot i on that the web's committed candidates name (ws_node_prepare_some), which only
 * the sweep reads: a body that the search finds near later is prepared after it. (As one
 * item that is no worker's own, tried first, they lengthened the task by their whole cost:
 * the flags' shares are even.) */
typedef struct flag_task {
    ws_world *w;
    ws_web *web;
    uint32_t lanes;
    int cur;
    ws_nodes3 x, v;
    ws_node_lane *fl;
} flag_task;

static void flag_items(int32_t start, int32_t end, uint32_t worker, void *ctx)
{
    (void)worker;
    const flag_task *T = ctx;
    for (int32_t i = start; i < end; i++) {
        ws_node_flag_lane(&T->w->bodies, T->cur, T->web, T->x, T->v, &T->fl[i]);
        ws_node_prepare_some(&T->w->bodies, T->cur, &T->w->node_geom, T->web, (uint32_t)i,
                             T->lanes);
    }
}

/* The flags in the lanes of the last cut when it cuts this web's rows (the nodes stay on
 * their cores), else in lanes of equal rows: a node's flag costs the same everywhere. Returns
 * the lanes' findings (from the arena; NULL when out of memory). */
static ws_node_lane *flag_lanes(ws_step *S, ws_web *web, uint32_t lanes)
{
    ws_world *w = S->w;
    ws_lane_job *J = w->lane_job;
    const uint32_t ny = ws_web_rows(web);
    const size_t ntrack = web->contact->ntrack;
    const int cut = lanes_cover(J, lanes, ny);
    if (!cut)
        w->cut_web = NULL; /* not lanes_cut's */
    for (uint32_t i = 0; i < lanes && !cut; i++) {
        J[i].r0 = (uint32_t)((uint64_t)i * ny / lanes);
        J[i].r1 = (uint32_t)((uint64_t)(i + 1) * ny / lanes);
    }
    ws_node_lane *L = ws_arena_alloc(S->arena, lanes * sizeof *L);
    double *least = ws_arena_alloc(S->arena, (lanes * ntrack + 1) * sizeof *least);
    if (!L || !least)
        return NULL;
    for (uint32_t i = 0; i < lanes; i++)
        L[i] = (ws_node_lane){ws_web_row_node(web, J[i].r0), ws_web_row_node(web, J[i].r1),
                              S->contact.margin, 0, least + i * ntrack};
    flag_task T = {w, web, lanes, S->cur, web->x[S->cur], web->v[S->cur], L};
    run_task(w, flag_items, lanes, 0, &T);
    return L;
}

/* The search of node candidates in pieces on the world's threads (ws_node_search_fn, its
 * context the world): the nodes cut into pieces of about equal counts, one a lane at most and
 * SEARCH_PIECE nodes each at least, each piece searched (ws_node_find) with its own scratch,
 * into its own list, marking the bodies near in its own copy of the marks; then, here, the
 * lists joined in piece order (node order), the marks and the checks added; each piece also
 * compares its nodes' candidates with the committed list's (ws_node_same), which is the same
 * when every piece's is. A node's candidates do not depend on the pieces (ws_node_find), so
 * neither does the list. The pieces
 * cannot grow their lists (the allocator is the calling thread's): one whose room runs out is
 * searched again here. */
enum { SEARCH_PIECE = 48 };

typedef struct search_task {
    ws_world *w;
    const ws_node_step *S;
    const ws_web *web;
    const uint32_t *nodes;
    size_t count;
    uint32_t pieces;
} search_task;

/* Piece i, its list growing through mem (NULL: not at all). */
static void search_piece(const search_task *T, uint32_t i, ws_mem *mem)
{
    ws_lane_job *J = &T->w->lane_job[i];
    const size_t q0 = (size_t)((uint64_t)i * T->count / T->pieces),
                 q1 = (size_t)((uint64_t)(i + 1) * T->count / T->pieces);
    ws_node_step s = *T->S;
    s.mem = mem;
    s.g = &J->geom;
    s.checks = &J->found_checks;
    s.search = NULL;
    J->found.n = 0;
    J->found_checks = 0;
    const uint32_t *nodes = T->nodes ? T->nodes + q0 : NULL;
    if (nodes) /* found again now: their record from here, J->cview.lever2 for the whole's */
        ws_node_to_ref(&J->view, J->view.x[T->S->cur], nodes, q1 - q0);
    J->found_bad = ws_node_find(&s, &J->view, nodes, (uint32_t)q0, q1 - q0, &J->found) != 0;
    const ws_node_contact *nc = T->web->contact;
    const ws_node_found F = {nodes, q1 - q0, &J->found};
    J->found_same =
        nodes && !J->found_bad && ws_node_same(&F, nc->cstart[nc->list], nc->cand[nc->list].c);
}

static void search_items(int32_t start, int32_t end, uint32_t worker, void *ctx)
{
    (void)worker;
    for (int32_t i = start; i < end; i++)
        search_piece(ctx, (uint32_t)i, NULL);
}

static int search_lanes(const ws_node_step *S, ws_web *web, const uint32_t *nodes, size_t count,
                        ws_ncand_list *L)
{
    ws_world *w = S->search_ctx;
    uint32_t pieces = web_lanes(w, web);
    if (count / SEARCH_PIECE < pieces)
        pieces = (uint32_t)(count / SEARCH_PIECE);
    if (pieces < 2) {
        ws_node_step s = *S;
        s.search = NULL;
        if (nodes)
            ws_node_to_ref(web, web->x[S->cur], nodes, count);
        return ws_node_find_scratch(S->b, S->g) ? -1 : ws_node_find(&s, web, nodes, 0, count, L);
    }
    const size_t slots = S->b->slots + 1, room = w->search_tight ? 8 : 2 * (count / pieces) + 64;
    for (uint32_t i = 0; i < pieces; i++) {
        ws_lane_job *J = &w->lane_job[i];
        J->geom = *S->g;
        J->view = *web;
        J->cview = *web->contact;
        J->view.contact = &J->cview;
        J->cview.cbody_cap = slots;
        if (ws_node_find_scratch(S->b, &J->geom) != 0 ||
            !(J->cview.cbody = ws_arena_calloc(S->g->arena, slots, 1)) ||
            ws_array_reserve(S->mem, (void **)&J->found.c, &J->found.cap, room,
                             sizeof *J->found.c) != 0)
            return -1;
    }
    const search_task T = {w, S, web, nodes, count, pieces};
    run_task(w, search_items, pieces, 0, (void *)&T);
    size_t total = 0;
    for (uint32_t i = 0; i < pieces; i++) {
        ws_lane_job *J = &w->lane_job[i];
        if (J->found_bad) {
            w->search_reruns++;
            search_piece(&T, i, S->mem);
        }
        if (J->found_bad)
            return -1;
        total += J->found.n;
    }
    if (ws_array_reserve(S->mem, (void **)&L->c, &L->cap, total + 1, sizeof *L->c) != 0)
        return -1;
    L->n = 0;
    int same = nodes != NULL;
    for (uint32_t i = 0; i < pieces; i++) {
        const ws_lane_job *J = &w->lane_job[i];
        same &= J->found_same;
        if (J->found.n)
            memcpy(L->c + L->n, J->found.c, J->found.n * sizeof *L->c);
        L->n += J->found.n;
        *S->checks += J->found_checks;
        for (size_t k = 0; k + 1 < slots; k++)
            web->contact->cbody[k] |= J->cview.cbody[k];
        /* The largest |xdet|^2 of the pieces' nodes: as one pass over them all would keep. */
        if (J->cview.lever2 > web->contact->lever2)
            web->contact->lever2 = J->cview.lever2;
    }
    return same;
}

void ws_world_lanes_free(ws_world *w)
{
    const size_t jobs = (size_t)WS_LANES_PER_WORKER * w->def.worker_count;
    for (size_t i = 0; w->lane_job && i < jobs; i++) {
        ws_lane_job *J = &w->lane_job[i];
        ws_node_scratch_free(&w->mem, &J->own);
        ws_mem_free(&w->mem, J->found.c, J->found.cap * sizeof *J->found.c);
        J->found = (ws_ncand_list){NULL, 0, 0};
        J->tmp = NULL; /* the arena's */
        J->fct = NULL;
    }
}

/* Lane i's copies of the web and its contact: their state shared, their scratch the lane's own
 * (lane 0: the web's), the nodes the lane ends at. Made by the lane at the start of its sweep
 * (sweep_lane), on its worker: the web and its contact are only read while the lanes run. */
static void lane_open(ws_world *w, ws_web *web, uint32_t i)
{
    ws_lane_job *J = &w->lane_job[i];
    J->view = *web;
    J->cview = *web->contact;
    J->view.contact = &J->cview;
    J->fast = 0;
    J->checks = 0;
    ws_web *v = &J->view;
    ws_node_contact *c = &J->cview;
    c->lane_end = ws_web_row_node(web, J->r1);
    c->run_nodes = c->run_deep = c->corners = 0;
    c->row_mark = J->marks; /* where each row's loads start */
    v->law_failed = 0;
    if (i == 0)
        return;
    v->tmp = J->tmp;
    v->fct[v->fck] = J->fct;
    v->fct_cap[v->fck] = 0; /* the arena's room: nothing grows or frees it through the view */
    v->nfct[v->fck] = 0;
    c->act = J->own.act;
    c->act_id = J->own.act_id;
    c->act_cap = J->own.act_cap;
    c->rtmp = J->own.rtmp;
    c->rtmp_cap = J->own.rtmp_cap;
    c->rface = J->own.rface;
    c->rface_cap = J->own.rface_cap;
    c->rface_gen = J->own.rface_gen;
}

/* What lane i found into the web, in lane order: its loads on the bodies (folded by rows and
 * bodies, ws_node_loads_fold), its touched nodes, its counts. Returns its nodes too fast. */
static size_t lane_close(ws_world *w, ws_web *web, uint32_t i, v3 *bforce, v3 *bmoment)
{
    ws_lane_job *J = &w->lane_job[i];
    ws_web *v = &J->view;
    ws_node_contact *c = &J->cview, *nc = web->contact;
    ws_node_loads(c, bforce, bmoment);
    nc->run_nodes += c->run_nodes;
    nc->run_deep += c->run_deep;
    nc->corners += c->corners;
    web->law_failed |= v->law_failed;
    w->stats.narrow_checks += J->checks;
    const int k = web->fck;
    if (i == 0) {
        nc->rface_gen = c->rface_gen;
        web->nfct[k] = v->nfct[k]; /* lane 0 listed into the web's own list */
    } else {
        J->own.rface_gen = c->rface_gen;
        memcpy(web->fct[k] + web->nfct[k], v->fct[k], v->nfct[k] * sizeof(uint32_t));
        web->nfct[k] += v->nfct[k];
    }
    return J->fast;
}

/* A mesh web's springs in `pieces` pieces of equal counts (ws_task_fn), before the lanes that
 * gather them: each spring's force is written once, by one piece. */
typedef struct springs_task {
    ws_web *web;
    ws_nodes3 x, v;
    uint32_t pieces;
} springs_task;

static void springs_items(int32_t start, int32_t end, uint32_t worker, void *ctx)
{
    (void)worker;
    const springs_task *T = ctx;
    const uint64_t ns = T->web->ns;
    for (int32_t i = start; i < end; i++)
        ws_web_mesh_springs(T->web, T->x, T->v, (uint32_t)(ns * (uint32_t)i / T->pieces),
                            (uint32_t)(ns * (uint32_t)(i + 1) / T->pieces));
}

/* A sub-step of a web over its lanes: on the host's scheduler, the world's threads or, for one
 * lane, right here. Returns how many nodes ended too fast. */
static size_t sweep(ws_world *w, ws_web *web, uint32_t lanes, lane_task *T, v3 *bforce, v3 *bmoment)
{
    const uint32_t body = T->body ? T->items : 0;
    if (web->nx == 0) {
        springs_task ST = {web, T->pass.x, T->pass.v, lanes};
        run_task(w, springs_items, lanes, 0, &ST);
    }
    run_task(w, lane_items, lanes + body, body, T);
    size_t fast = 0;
    for (uint32_t i = 0; i < lanes; i++)
        fast += lane_close(w, web, i, bforce, bmoment);
    return fast;
}

/* The film's pull on each body, its sub-steps averaged, into the body's accumulators. */
static void web_loads(ws_step *S, const ws_web *web)
{
    ws_body_store *b = S->b;
    for (size_t i = 0; i < web->bcap && i < b->slots; i++) {
        b->f[i] = v3_add(b->f[i], web->bforce[S->nxt][i]);
        b->m[i] = v3_add(b->m[i], web->bmoment[S->nxt][i]);
    }
}

/* Whether the body contacts may wait for the film (step_once): with workers, when every web is
 * explicit (an implicit web's solve reads the bodies' loads) and there is one. */
static int bodies_beside_film(const ws_world *w)
{
    int webs = 0;
    for (size_t k = 0; k < w->web_slots.slot_count; k++) {
        if (w->web_slots.dense[k] == UINT32_MAX)
            continue;
        if (w->webs[k]->integrator != WS_WEB_EXPLICIT)
            return 0;
        webs = 1;
    }
    return webs && w->def.worker_count > 1;
}

/* Where the body part goes beside a web's lanes in n sub-steps: a waiting narrow
 * phase alone in the first sub-step's one item (the candidates are not known before it); the
 * twins, in `width` parts, in a sub-step of their own when there is one to
 * spare, else whole after the narrow phase or on this thread before the sub-steps; the
 * measured pieces, `width` a sub-step, in the sub-steps after. Each stage needs the one
 * before it done, and the sub-steps' tasks run one after another. */
typedef struct body_plan {
    int narrow;     /* the narrow phase waits: in sub-step 0 */
    int twins;      /* the twins' sub-step, or -1 */
    int measure;    /* the first sub-step of the measured pieces */
    uint32_t width; /* body items of a sub-step: WS_LANES_PER_WORKER a worker, for balance
                       beside the lanes (the pool's room: as many again as the lanes) */
} body_plan;

static body_plan body_plan_of(const ws_step *S, int n)
{
    body_plan p = {S->narrow_later != 0, -1, 0, WS_LANES_PER_WORKER * S->w->def.worker_count};
    if (n - p.narrow >= 2)
        p.twins = p.narrow;
    p.measure = p.twins >= 0 ? p.twins + 1 : p.narrow && n > 1;
    return p;
}

/* Sub-step s's body part into T (its body_part, items and pieces). */
static void body_task(const body_plan *p, int s, lane_task *T)
{
    T->items = 1;
    if (p->narrow && s == 0) {
        T->body_part |= BODY_NARROW;
        T->twins_after = p->twins < 0 ? 2 : 1;
    }
    if (s == p->twins) {
        T->body_part |= BODY_TWINS;
        T->items = p->width;
    }
    if (s >= p->measure) {
        T->body_part |= BODY_CONTACTS;
        T->piece0 = (uint32_t)(s - p->measure) * p->width;
        T->pieces = p->width;
        T->items = T->body_part & BODY_NARROW ? 1 : p->width;
    }
}

/* Sub-steps of every web: springs, node contacts (the bodies held at t), node integration,
 * swept block by block (ws_web_forces_block). Forces on the bodies go into their accumulators,
 * averaged over the sub-steps. */
static ws_status step_webs(ws_step *S)
{
    ws_world *w = S->w;
    ws_body_store *b = S->b;
    const int cur = S->cur, nxt = S->nxt;
    w->node_geom.arena = S->arena; /* the bodies' features and the node search's tables */
    if (ws_node_geometry(b, &w->node_geom) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory");
    for (size_t k = 0; k < w->web_slots.slot_count; k++) {
        if (w->web_slots.dense[k] == UINT32_MAX)
            continue;
        ws_web *web = w->webs[k];
        /* The node candidates of this step, ready to evaluate (contact/node.c). */
        ws_node_contact *nc = web->contact;
        int searched = 0;
        const uint32_t lanes = web_lanes(w, web);
        ws_node_lane *fl = NULL;
        if (ws_node_contact_begin(b, cur, web, S->dt, S->contact.margin, !w->cand_valid) &&
            !(fl = flag_lanes(S, web, lanes))) {
            nc->refresh = 1; /* the move test's record is not to be trusted: all found again */
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory");
        }
        const double t0 = clock_now(w);
        const ws_node_step ns = {&w->mem,
                                 b,
                                 cur,
                                 &w->node_geom,
                                 S->contact.margin,
                                 &S->stats->narrow_checks,
                                 lanes > 1 ? search_lanes : NULL,
                                 w,
                                 fl,
                                 fl ? lanes : 0};
        if (ws_node_contact_update(&ns, web, &searched) != 0)
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for web '%s'",
                           web_label(web));
        if (searched) { /* counted as detection, not film */
            S->stats->seconds_detection += clock_now(w) - t0;
            S->stats->seconds_web -= clock_now(w) - t0;
        }
        const int list = nc->next_list;
        if (ws_world_node_params(w, web->material) != 0)
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory");
        lanes_cut(w, web, lanes);
        /* Room to list every contact of every sub-step, before anything changes. */
        if (ws_array_reserve(&w->mem, (void **)&web->fct[nxt], &web->fct_cap[nxt],
                             (size_t)web->substeps * nc->cand[list].n + 1, sizeof(uint32_t)) != 0 ||
            !lanes_ready(S, web, lanes, nc->cand[list].n))
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for web '%s'",
                           web_label(web));
        for (size_t i = 0; i < web->bcap; i++)
            web->bforce[nxt][i] = web->bmoment[nxt][i] = v3_make(0, 0, 0);
        /* The node contact forces this step writes: zero where they were not (an implicit
         * web's nodes that had contacts when fc[nxt] was last written), or, swept, every one
         * by the lane of its row in the first sub-step. */
        for (size_t q = 0; lanes == 1 && q < web->nfct[nxt]; q++)
            web->fc[nxt][web->fct[nxt][q]] = v3_make(0, 0, 0);
        web->nfct[nxt] = 0;
        web->fck = nxt;
        if (web->integrator == WS_WEB_IMPLICIT) {
            if (nc->merging) /* no lanes to carry it out */
                ws_node_merge_range(&nc->merge, 0, web->n);
            nc->merging = 0;
            ws_status st = ws_world_web_implicit(S, web, list);
            if (st != WS_OK)
                return st;
            continue;
        }
        int n = web->substeps;
        double h = S->dt / n, share = 1.0 / n;
        /* The body contacts beside the sub-steps (S->body_later: there are workers): beside
         * a web's lanes, or its one lane when that may run on any worker (its laws of the film
         * form: a law that calls the user's code keeps its lane, and so the task, on this
         * thread), as body_plan lays them out, their forces added in the list's order after
         * the last sub-step (contacts_end). Beside a grid web's lanes (a film of many nodes
         * about few bodies, as the reference cases) the body part goes whole into the first
         * and last sub-steps' slack instead: staged, its records and their apply on this
         * thread cost more than the spread gains (bench/NOTES.md, session 28). */
        const int beside = lanes > 1 || ws_web_laws_on_workers(web);
        body_plan plan = {0, -1, 0, 0};
        uint32_t pieces = 0;
        if (beside && S->body_later && (lanes == 1 || web->nx == 0)) {
            plan = body_plan_of(S, n);
            pieces = (uint32_t)(n - plan.measure) * plan.width;
            const int twins = plan.narrow ? 0 : plan.twins >= 0 ? 1 : 2;
            if (!contacts_begin(S, pieces, twins))
                return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory");
        }
        /* Sub-steps alternate between the next state and the web's scratch state so that
         * none writes what it reads, and the last lands in the next state. */
        ws_nodes3 xs = web->x[cur], vs = web->v[cur];
        for (int s = 0; s < n; s++) {
            int last_parity = (n - 1 - s) % 2 == 0;
            ws_nodes3 xd = last_parity ? web->x[nxt] : web->xsub;
            ws_nodes3 vd = last_parity ? web->v[nxt] : web->vsub;
            ws_web_sweep_laws(web, w->def.gravity, S->t + s * h, s * h);
            lane_task T = {w,
                           web,
                           {b, cur, &w->node_geom, w->node_par, nc->cand[list].c, xs, vs, h, share,
                            web->fc[nxt], 0},
                           xd,
                           vd,
                           s == 0,
                           lanes,
                           NULL,
                           0,
                           0,
                           0,
                           1,
                           0};
            /* The body part beside the lanes in body_plan's stages, so that each fills a
             * sub-step's slack; else a narrow phase in the first, the contacts in the last. */
            if (pieces) {
                body_task(&plan, s, &T);
                if (s == n - 1)
                    S->body_later = 0;
            } else {
                if (beside && s == 0 && S->narrow_later)
                    T.body_part |= BODY_NARROW;
                if (beside && S->body_later && s == n - 1) {
                    T.body_part |= BODY_CONTACTS;
                    S->body_later = 0;
                }
            }
            T.body = T.body_part ? S : NULL;
            size_t fast = sweep(w, web, lanes, &T, web->bforce[nxt], web->bmoment[nxt]);
            if (pieces && s == n - 1)
                contacts_end(S);
            nc->merging = 0; /* carried out by the first sub-step's lanes */
            xs = xd;
            vs = vd;
            if (web->law_failed) {
                web->law_failed = 0;
                return ws_fail(w, WS_ERR_CALLBACK,
                               "step at t = %.6g s: a spring law of web '%s' failed (its user "
                               "function returned non-zero or gave a non-finite force); the "
                               "step was undone",
                               w->time, web_label(web));
            }
            if (fast) {
                double vmax = ws_web_fastest(web, vd);
                char what[160];
                if (vmax * vmax > DBL_MAX) /* too fast only as its square overflowed */
                    snprintf(what, sizeof what,
                             "a node ran away at t = %.6g s (speed %.3g m/s, beyond what a "
                             "double can square)",
                             w->time, vmax);
                else
                    snprintf(what, sizeof what,
                             "a node ran away at t = %.6g s (speed %.3g m/s above max_speed %.3g)",
                             w->time, vmax, w->def.max_speed);
                return web_unstable(w, web, h, ws_world_web_stable_dt(w, web), what);
            }
        }
        if (!S->loads_later)
            web_loads(S, web);
    }
    return WS_OK;
}

static const char *body_label(const ws_world *w, size_t i)
{
    return w->bodies.name[i] ? w->bodies.name[i] : "(unnamed)";
}

static const char *material_label(const ws_world *w, uint32_t m)
{
    return w->mat_name[m] ? w->mat_name[m] : m == 0 ? "(default)" : "(unnamed)";
}

/* x rounded down to 3 significant digits, as printed (%.3g) and read back: a dt to use. */
static double round_down_3(double x)
{
    if (!(x > 0.0 && x < 1e300))
        return x;
    double p = pow(10.0, floor(log10(x)) - 2.0);
    for (double y = floor(x / p) * p;; y -= p) {
        char txt[32];
        snprintf(txt, sizeof txt, "%.3g", y);
        if (strtod(txt, NULL) <= x)
            return strtod(txt, NULL);
    }
}

/* Bodies and their contact pairs against the stable step, before the step (as webs are): the
 * pair with the smallest stable step, and what would do. */
static ws_status bodies_ready(ws_world *w, double *pair_dt)
{
    ws_contact_limit L;
    ws_world_contact_limit(w, &L);
    double dt = w->def.dt;
    *pair_dt = L.dt;
    if (dt <= L.dt)
        return WS_OK;
    w->stats.numerical_errors++;
    const ws_body_store *b = &w->bodies;
    const double n = WS_CONTACTS_PER_BODY;
    /* The stiffness that would do at this dt: the bound (sqrt(C^2 + 4 m K) - C) / K >= dt
     * solved for K = n k (docs/theory.md, section 8); none when the damping alone is too much. */
    double kmax = 4.0 * (L.m_eff - 0.5 * dt * n * L.c) / (n * dt * dt);
    char other[96], fix[160];
    if (b->type[L.body_b] == WS_BODY_DYNAMIC)
        snprintf(other, sizeof other, "'%s' (%.3g kg)", body_label(w, L.body_b),
                 b->mass[L.body_b]);
    else
        snprintf(other, sizeof other, "'%s' (kinematic)", body_label(w, L.body_b));
    if (kmax > 0.0)
        snprintf(fix, sizeof fix, "or stiffness <= %.3g N/m for this pair (ws_world_set_contact)",
                 kmax);
    else
        snprintf(fix, sizeof fix,
                 "or damping below %.3g kg/s for this pair: its damping alone is too much",
                 2.0 * L.m_eff / (n * dt));
    return ws_fail(w, WS_ERR_NUMERICAL,
                   "step at t = %.6g s refused before the step: contact pair of materials '%s' "
                   "and '%s' (stiffness %.3g N/m, damping %.3g kg/s) between bodies '%s' (%.3g "
                   "kg) and %s has a stable step of %.3g s (effective mass %.3g kg on %g "
                   "contacts), below dt = %.3g s. Use dt <= %.3g s (ws_world_set_dt), %s.",
                   w->time, material_label(w, L.mat_a), material_label(w, L.mat_b), L.k, L.c,
                   body_label(w, L.body_a), b->mass[L.body_a], other, L.dt, L.m_eff, n, dt,
                   round_down_3(L.dt), fix);
}

static double kinetic(const ws_body_store *b, const ws_body_state *st, size_t i)
{
    return 0.5 * b->mass[i] * v3_norm2(st->v[i]) +
           0.5 * v3_dot(st->w[i], m3_mul_v(&b->J[i], st->w[i]));
}

/* Energy guard (docs/theory.md, section 8): the bodies' kinetic energy may grow in a step by the
 * work the known loads did (gravity, film, elements: their force and moment on each body times
 * its mean velocities; drives: the contact forces of kinematic bodies times their speed) plus
 * WS_ENERGY_GROWTH_FACTOR times the kinetic and contact energy at its start. Stable penalty
 * contacts release at most what they store; more is a runaway, whatever max_speed says. */
static ws_status energy_guard(const ws_step *S)
{
    ws_world *w = S->w;
    const ws_body_store *b = S->b;
    const ws_body_state *s0 = &b->st[S->cur], *s1 = &b->st[S->nxt];
    const double dt = S->dt;
    const size_t nrec = S->nrec;
    double t0 = 0.0, t1 = 0.0, work = 0.0, stored = 0.0;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i] || b->type[i] != WS_BODY_DYNAMIC)
            continue;
        t0 += kinetic(b, s0, i);
        t1 += kinetic(b, s1, i);
        v3 f = v3_sub(b->f[i], S->guard_f[i]), m = v3_sub(b->m[i], S->guard_m[i]);
        v3 w1 = m3_mul_v(&b->A[i], s1->w[i]);
        work += 0.5 * dt *
                (v3_dot(f, v3_add(s0->v[i], s1->v[i])) + v3_dot(m, v3_add(b->wg[i], w1)));
    }
    for (size_t k = 0; k < nrec; k++) {
        const ws_contact_rec *r = &w->rec[S->nxt][k];
        stored += r->energy + r->energy_t;
        v3 F = v3_add(v3_scale(r->n, r->fn), r->ft); /* on b; a gets -F */
        uint32_t ends[2] = {r->a, r->b};
        for (int e = 0; e < 2; e++) {
            uint32_t j = ends[e];
            if (b->type[j] == WS_BODY_DYNAMIC)
                continue;
            v3 arm = v3_sub(r->x, s0->r[j]);
            v3 v0 = v3_add(s0->v[j], v3_cross(b->wg[j], arm));
            v3 v1 = v3_add(s1->v[j], v3_cross(m3_mul_v(&b->A[j], s1->w[j]), arm));
            work += 0.5 * dt * (fabs(v3_dot(F, v0)) + fabs(v3_dot(F, v1)));
        }
    }
    double allowed = fmax(work, 0.0) + WS_ENERGY_GROWTH_FACTOR * (t0 + stored) +
                     1e-9 * (t0 + t1) + 1e-300;
    if (t1 - t0 <= allowed)
        return WS_OK;
    S->stats->numerical_errors++;
    ws_contact_limit L;
    ws_world_contact_limit(w, &L);
    return ws_fail(w, WS_ERR_NUMERICAL,
                   "step at t = %.6g s: runaway energy: the bodies' kinetic energy grew from %.3g "
                   "J to %.3g J in one step, more than the loads' work (gravity, film, "
                   "elements, drives: %.3g J) plus %g times the kinetic and contact energy at "
                   "its start (%.3g J). The step was undone. dt = %.3g s; the bodies' stable "
                   "step is %.3g s (materials '%s' and '%s'): reduce dt, or the stiffness of "
                   "the contacts or elements.",
                   w->time, t0, t1, work, WS_ENERGY_GROWTH_FACTOR, t0 + stored, dt,
                   ws_world_stable_dt(w), material_label(w, L.mat_a), material_label(w, L.mat_b));
}

static ws_status health(const ws_step *S)
{
    ws_world *w = S->w;
    const ws_body_store *b = S->b;
    const ws_body_state *n = &b->st[S->nxt];
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i] || b->type[i] != WS_BODY_DYNAMIC)
            continue;
        double sp = v3_norm(n->v[i]), om = v3_norm(n->w[i]);
        int finite = ws_is_finite3(&n->r[i]) && isfinite(sp) && isfinite(om) &&
                     isfinite(qt_norm(n->p[i]));
        if (finite && sp <= w->def.max_speed && om <= w->def.max_angular_speed)
            continue;
        S->stats->numerical_errors++;
        double dts = ws_world_stable_dt(w);
        const char *what = !finite ? "its state became NaN or infinite"
                           : sp > w->def.max_speed ? "it ran away (speed above max_speed)"
                                                   : "it ran away (spin above max_angular_speed)";
        return ws_fail(w, WS_ERR_NUMERICAL,
                       "step at t = %.6g s: body '%s' (index %zu): %s; speed %.3g m/s, spin "
                       "%.3g rad/s. The step was undone. dt = %.3g s; the explicit limit for the "
                       "stiffest contact on the lightest body is about %.3g s: reduce dt (or the "
                       "contact stiffness, or raise the mass).",
                       w->time, body_label(w, i), i, what, sp, om, w->def.dt, dts);
    }
    return WS_OK;
}

/* Detection (stage 2): a full one, or the cached candidates copied as they are; then room for
 * one contact record per candidate, so that evaluation cannot fail half-way. */
static ws_status detect(ws_step *S)
{
    ws_world *w = S->w;
    const int cur = S->cur, nxt = S->nxt;
    /* Cached candidates hold every feature pair within the layers + margin at the last full
     * detection. Two bodies can close that margin only if each has moved by half of it, so a
     * full detection is forced early when the travel bound says so, whatever the interval. */
    S->full = !w->cand_valid || S->t < w->def.full_detection_until ||
              w->steps - w->last_full_step >= (uint64_t)w->def.detection_interval ||
              2.0 * w->travel >= w->def.contact_margin;
    ws_status s;
    if (S->full) {
        if ((s = detect_full(S)) != WS_OK)
            return s;
    } else {
        if (ws_array_reserve(&w->mem, (void **)&w->cand[nxt], &w->capcand[nxt], w->ncand[cur],
                             sizeof *w->cand[nxt]) != 0)
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for contact candidates");
        if (w->ncand[cur])
            memcpy(w->cand[nxt], w->cand[cur], w->ncand[cur] * sizeof *w->cand[nxt]);
        w->ncand[nxt] = w->ncand[cur];
    }
    if (!S->narrow_later &&
        ws_array_reserve(&w->mem, (void **)&w->rec[nxt], &w->caprec[nxt], w->ncand[nxt] + 1,
                         sizeof *w->rec[nxt]) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for contact records");
    return WS_OK;
}

/* The body contacts' record of each body's load for the energy guard (gravity taken out),
 * once they are all added. */
static void guard_record(ws_step *S)
{
    const ws_body_store *b = S->b;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        v3 g = b->type[i] == WS_BODY_DYNAMIC ? v3_scale(S->w->def.gravity, b->mass[i])
                                              : v3_make(0, 0, 0);
        S->guard_f[i] = v3_sub(b->f[i], g);
        S->guard_m[i] = b->m[i];
    }
}

/* Twin corners (two bodies' vertices at one corner of their faces' overlap) share one
 * corner's laws: their shares, from the same state the evaluation reads, before any
 * candidate is evaluated; the cuts cleared, and with `whole` found (else the parts of a
 * body item each find theirs, body_item). */
static void contacts_twins_ready(ws_step *S, int whole)
{
    ws_world *w = S->w;
    if (whole)
        ws_contact_twins(&S->contact, w->cand[S->nxt], w->ncand[S->nxt]);
    else
        ws_contact_twins_clear(w->cand[S->nxt], w->ncand[S->nxt]);
}

/* The body contacts (stage 3): every candidate evaluated into a record of nxt, its forces
 * added to the bodies' accumulators in the list's order, and the guard's record. A contact
 * that starts in the step next to one between the same bodies that ends in it (a corner's
 * load passing between its point-face contact and an edge pair) takes over that one's stick
 * anchor, so the friction it carried does not vanish for a step: the candidates are marked
 * here, in the list's order, and matched after. */
static void body_contacts(ws_step *S)
{
    ws_world *w = S->w;
    const int nxt = S->nxt;
    /* A full detection's narrow phase first, when it still waits (detect_full); when it ran
     * out of room beside the film, both run again on the calling thread (step_once). */
    if (S->narrow_later) {
        S->narrow_bad = detect_narrow(S, NULL) != 0;
        S->narrow_later = 0;
    }
    if (S->narrow_bad)
        return;
    contacts_twins_ready(S, 1);
    size_t nrec = 0, fresh = 0, ended = 0;
    for (size_t k = 0; k < w->ncand[nxt]; k++) {
        ws_cand *c = &w->cand[nxt][k];
        const uint32_t was = c->anchored;
        c->ended = c->fresh = 0;
        if (ws_contact_eval(&S->contact, c, &w->rec[nxt][nrec])) {
            if (!was && c->anchored) {
                c->fresh = (uint32_t)nrec + 1;
                fresh++;
            }
            nrec++;
        } else if (was) {
            c->ended = 1;
            ended++;
        }
    }
    if (fresh && ended)
        ws_contact_handover(&S->contact, w->cand[nxt], w->ncand[nxt], w->rec[nxt]);
    S->nrec = nrec;
    guard_record(S);
}

/* The body contacts in measured pieces beside a web's lanes (step_webs, body_plan):
 * piece p of `pieces` measures its share of the candidates (ws_contact_measure, on any worker)
 * into a record of its own a candidate; contacts_end then takes the records in the list's
 * order, adds their forces and hands the anchors over on the calling thread, so that the
 * records, the anchors and the bodies' sums are body_contacts' to the bit. contacts_begin
 * makes the room, and the twins ready as `twins` says (0: after the narrow phase, in its
 * item; 1: their cuts cleared for the parts; 2: whole). */
enum { MEASURED_NONE = 0, MEASURED = 1, MEASURED_FRESH = 2, MEASURED_ENDED = 3 };

static int contacts_begin(ws_step *S, uint32_t pieces, int twins)
{
    ws_world *w = S->w;
    const size_t room = w->capcand[S->nxt] + 1; /* the narrow phase beside stays within it */
    S->mrec = ws_arena_alloc(S->arena, room * sizeof *S->mrec);
    S->mstate = ws_arena_alloc(S->arena, room);
    S->mchecks = ws_arena_alloc(S->arena, pieces * sizeof *S->mchecks);
    S->mpieces = pieces;
    if (!S->mrec || !S->mstate || !S->mchecks)
        return 0;
    if (twins) /* 1: the cuts cleared for the parts; 2: the twins whole, here */
        contacts_twins_ready(S, twins == 2);
    return 1;
}

static void contacts_piece(ws_step *S, uint32_t p)
{
    ws_world *w = S->w;
    const int nxt = S->nxt;
    if (S->narrow_bad)
        return;
    ws_contact_ctx x = S->contact; /* its own count of checks */
    x.narrow_checks = 0;
    const size_t n = w->ncand[nxt], k0 = n * p / S->mpieces, k1 = n * (p + 1) / S->mpieces;
    for (size_t k = k0; k < k1; k++) {
        ws_cand *c = &w->cand[nxt][k];
        const uint32_t was = c->anchored;
        c->ended = c->fresh = 0;
        if (ws_contact_measure(&x, c, &S->mrec[k]))
            S->mstate[k] = !was && c->anchored ? MEASURED_FRESH : MEASURED;
        else
            S->mstate[k] = was ? MEASURED_ENDED : MEASURED_NONE;
    }
    S->mchecks[p] = x.narrow_checks;
}

static void contacts_end(ws_step *S)
{
    ws_world *w = S->w;
    const int nxt = S->nxt;
    if (S->narrow_bad)
        return;
    size_t nrec = 0, fresh = 0, ended = 0;
    for (size_t k = 0; k < w->ncand[nxt]; k++) {
        ws_cand *c = &w->cand[nxt][k];
        if (S->mstate[k] == MEASURED_ENDED) {
            c->ended = 1;
            ended++;
        }
        if (S->mstate[k] != MEASURED && S->mstate[k] != MEASURED_FRESH)
            continue;
        w->rec[nxt][nrec] = S->mrec[k];
        ws_contact_apply(&S->contact, &w->rec[nxt][nrec]);
        if (S->mstate[k] == MEASURED_FRESH) {
            c->fresh = (uint32_t)nrec + 1;
            fresh++;
        }
        nrec++;
    }
    for (uint32_t p = 0; p < S->mpieces; p++)
        S->contact.narrow_checks += S->mchecks[p];
    if (fresh && ended)
        ws_contact_handover(&S->contact, w->cand[nxt], w->ncand[nxt], w->rec[nxt]);
    S->nrec = nrec;
    guard_record(S);
}

/* What contact_operator takes of each contact: its normal spring, its normal damper, or its
 * friction below v_lim as the damper it is there (regularised law only). */
enum { RATE_SPRING, RATE_DAMPER, RATE_FRICTION };

/* One application of the bodies' contact operator, y = M^-1 K x over the contacts of this step
 * (K from each contact's normal spring or damper, or its friction's slope at rest 2 mu F_n /
 * v_lim on the tangent plane, the steepest of eq. 13): x and y hold a velocity and a spin a
 * body slot (kinematic bodies' are zero: they do not move with the contacts). */
static void contact_operator(const ws_step *S, int what, const v3 *x, v3 *y)
{
    const ws_world *w = S->w;
    const ws_body_store *b = S->b;
    const ws_body_state *st = &b->st[S->cur];
    const size_t n = b->slots;
    for (size_t i = 0; i < 2 * n; i++)
        y[i] = v3_make(0, 0, 0);
    for (size_t k = 0; k < S->nrec; k++) {
        const ws_contact_rec *r = &w->rec[S->nxt][k];
        const ws_pair_params *p =
            &w->params[w->pair_index[b->material[r->a] * w->pair_dim + b->material[r->b]]];
        const v3 ra = v3_sub(r->x, st->r[r->a]), rb = v3_sub(r->x, st->r[r->b]);
        /* The motion of b relative to a at the point, and the contact's pull on a. */
        const v3 u = v3_sub(v3_add(x[r->b], v3_cross(x[n + r->b], rb)),
                            v3_add(x[r->a], v3_cross(x[n + r->a], ra)));
        const double un = v3_dot(r->n, u);
        v3 f;
        if (what != RATE_FRICTION) {
            f = v3_scale(r->n, (what == RATE_DAMPER ? p->c : p->k) * un);
        } else {
            if (p->model != WS_FRICTION_REGULARIZED || !(r->fn > 0.0) || !(p->vlim > 0.0))
                continue;
            const double c = ws_friction_slope(0.0) * p->mu * r->fn / p->vlim;
            f = v3_scale(v3_sub(u, v3_scale(r->n, un)), c);
        }
        y[r->a] = v3_add(y[r->a], f);
        y[n + r->a] = v3_add(y[n + r->a], v3_cross(ra, f));
        y[r->b] = v3_sub(y[r->b], f);
        y[n + r->b] = v3_sub(y[n + r->b], v3_cross(rb, f));
    }
    for (size_t i = 0; i < n; i++) {
        if (!b->alive[i] || b->type[i] != WS_BODY_DYNAMIC) {
            y[i] = y[n + i] = v3_make(0, 0, 0);
            continue;
        }
        y[i] = v3_scale(y[i], b->inv_mass[i]);
        /* The world inverse inertia A Jinv A^T. */
        y[n + i] = m3_mul_v(&b->A[i], m3_mul_v(&b->Jinv[i], m3_tmul_v(&b->A[i], y[n + i])));
    }
}

/* The kinetic-energy norm of x, sqrt(x^T M x). */
static double mass_norm(const ws_body_store *b, const v3 *x)
{
    const size_t n = b->slots;
    double s = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (!b->alive[i] || b->type[i] != WS_BODY_DYNAMIC)
            continue;
        s += b->mass[i] * v3_norm2(x[i]) +
             v3_dot(x[n + i], m3_mul_v(&b->A[i], m3_mul_v(&b->J[i], m3_tmul_v(&b->A[i], x[n + i]))));
    }
    return sqrt(s);
}

/* The largest eigenvalue of M^-1 K (or M^-1 C, or friction's) for the contacts of this step,
 * by power iteration in the M inner product, where the operator is symmetric: each iterate's
 * ratio |y|_M / |x|_M is at most the eigenvalue and rises to it. x and y: scratch of 2 slots
 * each. */
static double contact_rate(const ws_step *S, int what, v3 *x, v3 *y)
{
    const ws_body_store *b = S->b;
    const size_t n = b->slots;
    /* A start with a share of every mode: no symmetry of a stack (all bodies alike, all
     * moving alike) can hide one. Every component differs from body to body: with the spin
     * about z alike on all, the bodies' relative twists (friction's fastest modes) had none. */
    for (size_t i = 0; i < n; i++) {
        const double q = 1.0 + 0.37 * (double)(i % 7);
        x[i] = v3_make(0.9 * q, -0.55 * q * q, 1.3 / q);
        x[n + i] = v3_make(2.1 / q, 3.3 * q, -1.7 * q * q);
    }
    double lam = 0.0, nx = mass_norm(b, x);
    for (int it = 0; it < WS_CONTACT_RATE_ITERATIONS && nx > 0.0; it++) {
        contact_operator(S, what, x, y);
        const double ny = mass_norm(b, y);
        lam = ny / nx;
        if (!(ny > 0.0))
            break;
        for (size_t i = 0; i < 2 * n; i++)
            x[i] = v3_scale(y[i], 1.0 / ny);
        nx = 1.0;
    }
    return lam;
}

/* The contacts now acting against the step (docs/theory.md, section 8): the per-pair bound that
 * bodies_ready checks leaves out bodies that rock and bounce on several partners at once (two
 * boxes stacked on a platform: omega^2 = 27.4 k/m against the pair's 16 k/m), so when dt is
 * within WS_CONTACT_CHECK_FRACTION of that bound the system's own highest mode is measured, and
 * a step beyond its bound is refused before the bodies move. */
static ws_status contacts_ready(ws_step *S)
{
    ws_world *w = S->w;
    if (S->nrec == 0 || !(S->dt > WS_CONTACT_CHECK_FRACTION * S->pair_dt))
        return WS_OK;
    ws_contact_check *cc = &w->contact_check;
    if (!cc->valid || w->steps < cc->step || w->steps - cc->step >= WS_CONTACT_CHECK_EVERY ||
        4 * S->nrec > 5 * cc->nrec || cc->pair_dt != S->pair_dt) {
        const size_t n = S->b->slots;
        v3 *x = ws_arena_alloc(S->arena, 4 * (n + 1) * sizeof(v3));
        if (!x)
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory");
        v3 *y = x + 2 * (n + 1);
        const double K = contact_rate(S, RATE_SPRING, x, y);
        const double C = contact_rate(S, RATE_DAMPER, x, y);
        /* ws_contact_stable_dt with m = 1; no bound when no contact pushes. */
        *cc = (ws_contact_check){1,         w->steps, S->nrec, S->pair_dt,
                                 K > 0.0 ? (sqrt(C * C + 4.0 * K) - C) / K : 0.0,
                                 sqrt(K > 0.0 ? K : 0.0), C};
    }
    const double stable = cc->stable, K = cc->omega * cc->omega, C = cc->rate;
    if (!(stable > 0.0) || S->dt <= stable)
        return WS_OK;
    S->stats->numerical_errors++;
    return ws_fail(w, WS_ERR_NUMERICAL,
                   "step at t = %.6g s refused before the step: the %zu contacts now acting on "
                   "the bodies have a stable step of %.3g s (their highest mode: omega = %.3g "
                   "rad/s, damping rate %.3g 1/s; bodies rocking and bouncing on several "
                   "partners at once, which the per-pair bound of %.3g s leaves out), below dt "
                   "= %.3g s. Use dt <= %.3g s (ws_world_set_dt), or softer contacts.",
                   w->time, S->nrec, stable, sqrt(K), C, S->pair_dt, S->dt,
                   round_down_3(stable));
}

/* The regularised friction's explicit limit (docs/theory.md, section 8): below v_lim eq. 13 is
 * a damper the bodies' step takes explicitly, stable while dt lambda <= 2 for the highest rate
 * lambda of M^-1 C over the contacts acting. Beyond it the contacts slip back and forth every
 * step at their cap and a load creeps faster than the law allows, with no energy for the guard
 * to see; the reference cases' film clamps the boxes into that. Not refused (the wrapped
 * reference cases run there by their definition): measured every WS_CONTACT_CHECK_EVERY
 * steps; what WS_FRICTION_HELD measures in a row all pass, the largest such, is kept in the
 * stats and said once to the log hook when past 1. */
static ws_status friction_check(ws_step *S)
{
    ws_world *w = S->w;
    const uint64_t since = w->steps + 1 - w->friction_step;
    if (w->def.friction_step != WS_FRICTION_STEP_EXPLICIT || S->nrec == 0 ||
        (w->friction_step && since < WS_CONTACT_CHECK_EVERY))
        return WS_OK;
    const size_t n = S->b->slots;
    if (ws_array_reserve(&w->mem, (void **)&w->friction_scratch, &w->friction_cap, 4 * (n + 1),
                         sizeof(v3)) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory");
    w->friction_step = w->steps + 1;
    v3 *x = w->friction_scratch;
    const double lam = contact_rate(S, RATE_FRICTION, x, x + 2 * (n + 1));
    w->friction_uses[w->nuse++ % WS_FRICTION_HELD] = S->dt * lam / 2.0;
    if (w->nuse < WS_FRICTION_HELD)
        return WS_OK;
    double use = w->friction_uses[0]; /* what the last WS_FRICTION_HELD measures all pass */
    for (int i = 1; i < WS_FRICTION_HELD; i++)
        use = fmin(use, w->friction_uses[i]);
    if (use > S->stats->friction_step_use)
        S->stats->friction_step_use = use;
    if (use > 1.0 && !w->friction_warned) {
        w->friction_warned = 1;
        ws_log(w, WS_LOG_WARNING,
               "at t = %.6g s the bodies' regularised friction has been past its explicit "
               "limit for %d measures in a row (%d steps): dt = %.3g s is at least %.3g times "
               "2 / lambda (now lambda = %.3g 1/s, the %zu contacts' friction below v_lim as "
               "dampers): the contacts slip back and forth every step and the load creeps "
               "faster than the law allows. Use dt <= %.3g s (ws_world_set_dt) or "
               "WS_FRICTION_STICK.",
               w->time, WS_FRICTION_HELD, WS_FRICTION_HELD * WS_CONTACT_CHECK_EVERY, S->dt, use,
               lam, S->nrec, round_down_3(S->dt / use));
    }
    return WS_OK;
}

/* Stage 4: dynamic bodies integrated into nxt; kinematic ones held, or posed by their drives
 * at t + dt. */
static ws_status integrate(ws_step *S)
{
    ws_world *w = S->w;
    ws_body_store *b = S->b;
    const int cur = S->cur, nxt = S->nxt;
    const double t = S->t, dt = S->dt;
    for (size_t i = 0; i < b->slots; i++) {
        if (!b->alive[i])
            continue;
        if (b->type[i] == WS_BODY_DYNAMIC) {
            if (w->def.integrator == WS_INTEGRATOR_PAPER_EXPLICIT)
                ws_body_integrate_paper(b, i, cur, nxt, dt);
            else
                ws_body_integrate_symplectic(b, i, cur, nxt, dt);
            continue;
        }
        ws_body_state *n = &b->st[nxt];
        if (!b->has_drive[i]) {
            n->r[i] = b->st[cur].r[i];
            n->p[i] = b->st[cur].p[i];
            n->v[i] = v3_make(0, 0, 0);
            n->w[i] = v3_make(0, 0, 0);
            continue;
        }
        ws_pose pose;
        v3 v, om;
        if (ws_drive_eval(&b->drive[i], t + dt, &pose, &v, &om) != 0) {
            if (b->drive[i].def.type == WS_DRIVE_CALLBACK)
                return ws_fail(w, WS_ERR_CALLBACK,
                               "step at t = %.6g s: the drive of body '%s' (index %zu) failed: "
                               "its callback returned non-zero or gave a non-finite pose or "
                               "velocity at t = %.6g s; the step was undone",
                               t, body_label(w, i), i, t + dt);
            S->stats->numerical_errors++;
            return ws_fail(w, WS_ERR_NUMERICAL,
                           "step at t = %.6g s: the drive of body '%s' (index %zu) gives a "
                           "non-finite pose or velocity at t = %.6g s; the step was undone",
                           t, body_label(w, i), i, t + dt);
        }
        m3 A = qt_to_m3(pose.orientation);
        n->r[i] = pose.position;
        n->p[i] = pose.orientation;
        n->v[i] = v;
        n->w[i] = m3_tmul_v(&A, om);
    }
    return WS_OK;
}

/* Stage 6: what the step wrote becomes the committed state. */
static void commit(ws_step *S)
{
    ws_world *w = S->w;
    w->nrec[S->nxt] = S->nrec;
    ws_world_commit_elements(w, S->t); /* the law histories of the strains this step used */
    w->cur = S->nxt;
    w->time = S->t + S->dt;
    if (S->full) {
        w->last_full_step = w->steps;
        w->cand_valid = 1;
        S->stats->full_detections++;
        w->travel = 0.0;
    }
    w->travel += max_step_travel(w, w->cur); /* this step's motion bound */
    for (size_t k = 0; k < w->web_slots.slot_count; k++) {
        if (w->web_slots.dense[k] == UINT32_MAX)
            continue;
        ws_web *web = w->webs[k];
        ws_node_contact_commit(web->contact);
        ws_web_commit(web, web->x[w->cur], web->v[w->cur], w->time, S->dt);
    }
    w->steps++;
}

/* One step; ws_world_step guards it against calls from its own callbacks. */
static ws_status step_once(ws_world *w)
{
    const double t_start = clock_now(w);
    ws_status s;
    double pair_dt;
    if ((s = bodies_ready(w, &pair_dt)) != WS_OK)
        return s;
    /* The last step's scratch is given back; this step's comes from the arena. */
    ws_arena_reset(&w->arena);
    ws_body_store *b = &w->bodies;
    ws_step S = {.w = w,
                 .b = b,
                 .cur = w->cur,
                 .nxt = w->cur ^ 1,
                 .t = w->time,
                 .dt = w->def.dt,
                 .contact = {.b = b,
                             .cur = w->cur,
                             .margin = w->def.contact_margin,
                             .params = w->params,
                             .pair_index = w->pair_index,
                             .nmat = (uint32_t)w->pair_dim},
                 .stats = &w->stats,
                 .arena = &w->arena,
                 .pair_dt = pair_dt};
    /* The energy guard's record of the contacts' loads on each body. */
    if (!(S.guard_f = ws_arena_alloc(S.arena, 2 * (b->slots + 1) * sizeof(v3))))
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory");
    S.guard_m = S.guard_f + b->slots + 1;

    prepare(w);
    /* The body contacts read only the bodies' state at t, and the film does not read the
     * bodies' loads: with workers and only explicit webs they run as one more item of the
     * film's first sub-step in lanes, on whichever worker is free first, with a full
     * detection's narrow phase before them, and their check and the elements follow the film
     * (the loads summed as before: contacts, elements, webs). A step they refuse then leaves
     * the world as it was all the same: the film wrote only the next state and its scratch. */
    S.body_later = S.loads_later = bodies_beside_film(w);
    double t_mark = clock_now(w);
    if ((s = detect(&S)) != WS_OK)
        return s;
    double t_eval = clock_now(w);
    S.stats->seconds_detection += t_eval - t_mark;
    if (!S.body_later) {
        body_contacts(&S);
        if ((s = contacts_ready(&S)) != WS_OK || (s = friction_check(&S)) != WS_OK)
            return s;
        if ((s = ws_world_element_forces(w, S.cur, S.t)) != WS_OK) /* rods, springs, bushings */
            return s;
    }

    double t_web = clock_now(w);
    S.stats->seconds_contacts += t_web - t_eval;
    if (w->web_slots.slot_count) {
        if ((s = webs_ready(w)) != WS_OK || (s = step_webs(&S)) != WS_OK)
            return s;
        S.stats->seconds_web += clock_now(w) - t_web;
    }
    if (S.loads_later) {
        const double t_late = clock_now(w);
        if (S.body_later) /* no web was swept in lanes */
            body_contacts(&S);
        if (S.narrow_bad) { /* its room ran out beside the film: again here, growing it */
            S.narrow_bad = 0;
            w->narrow_reruns++;
            if (detect_narrow(&S, &w->mem) != 0 ||
                ws_array_reserve(&w->mem, (void **)&w->rec[S.nxt], &w->caprec[S.nxt],
                                 w->ncand[S.nxt] + 1, sizeof *w->rec[S.nxt]) != 0)
                return ws_fail(w, WS_ERR_OUT_OF_MEMORY,
                               "step: out of memory for contact candidates");
            body_contacts(&S);
        }
        if ((s = contacts_ready(&S)) != WS_OK || (s = friction_check(&S)) != WS_OK ||
            (s = ws_world_element_forces(w, S.cur, S.t)) != WS_OK)
            return s;
        S.stats->seconds_contacts += clock_now(w) - t_late;
        for (size_t k = 0; k < w->web_slots.slot_count; k++)
            if (w->web_slots.dense[k] != UINT32_MAX)
                web_loads(&S, w->webs[k]);
    }
    if ((s = ws_world_friction_step(&S)) != WS_OK || (s = integrate(&S)) != WS_OK)
        return s;
    S.stats->narrow_checks += S.contact.narrow_checks;
    if ((s = health(&S)) != WS_OK || (s = energy_guard(&S)) != WS_OK)
        return s;
    commit(&S);
    S.stats->seconds_total += clock_now(w) - t_start;
    return WS_OK;
}

ws_status ws_world_step(ws_world *w)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_world_step");
    /* A callback (drive, law, log hook) that changed the world would pull pools and buffers
     * from under the step: every call that changes the world checks this flag. */
    w->in_step = 1;
    ws_status s = step_once(w);
    w->in_step = 0;
    return s;
}

ws_status ws_world_step_n(ws_world *w, int64_t steps)
{
    NEED_WORLD(w);
    NOT_IN_STEP(w, "ws_world_step_n");
    if (steps < 0)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_world_step_n: steps must be >= 0, got %lld",
                       (long long)steps);
    for (int64_t k = 0; k < steps; k++) {
        ws_status s = ws_world_step(w);
        if (s != WS_OK)
            return s;
    }
    return WS_OK;
}
