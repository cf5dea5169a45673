/* An implicit web's part of the step (web/implicit.h, contact/node_jacobian.h): per sub-step,
 * the springs and the node contacts at its start, one linear solve, the new node state and the
 * contacts' loads on the bodies. The dynamic bodies the film touches are unknowns of the solve
 * beside its nodes (web/coupled.h, docs/theory.md section 8b), their other loads (gravity, body
 * contacts, elements, webs stepped before) known, but for their contacts' regularised
 * friction, which goes into the solve with them (world_friction.c's pairs; explicit, it
 * chatters past 0.33 ms on a wrapped stack); with hold_bodies they are held at their state at
 * t as for the explicit film (deviation (h) of docs/design.md). */
#include "contact/node_jacobian.h"
#include "contact/penalty.h"
#include "web/coupled.h"
#include "web/multigrid.h"
#include "world/world_internal.h"

#include <float.h>
#include <stdio.h>
#include <string.h>

/* Solves a sub-step at most, as its contacts come in and go (the active set). */
#define WS_IMPLICIT_PASSES 6

static const char *label(const ws_web *web)
{
    return web->name ? web->name : "(unnamed)";
}

/* The solve's bodies for the contacts L[0, nl): every dynamic body one of them touches gets
 * an index (slot[body], UINT32_MAX for the others) and its mass and global inertia; the
 * scratch (with the coarse space's set-up's, for a web of `nodes` nodes) from the step's arena.
 * NULL (and *fail 0) when no dynamic body is touched, NULL with *fail 1 when out of memory. */
static ws_rigid *rigid_make(ws_arena *arena, const ws_body_store *b, const ws_node_link *L,
                            size_t nl, const ws_web *web, uint32_t **slot_out, int *fail)
{
    const uint32_t nodes = web->n, nblk = web->imp->nblk;
    const ws_mg *mg = web->imp->mg;
    *fail = 1;
    uint32_t *slot = ws_arena_alloc(arena, (b->slots + 1) * sizeof *slot);
    ws_rigid *R = ws_arena_alloc(arena, sizeof *R);
    if (!slot || !R)
        return NULL;
    for (size_t i = 0; i < b->slots; i++)
        slot[i] = UINT32_MAX;
    uint32_t nb = 0;
    for (size_t k = 0; k < nl; k++)
        if (b->type[L[k].body] == WS_BODY_DYNAMIC && slot[L[k].body] == UINT32_MAX)
            slot[L[k].body] = nb++;
    *fail = 0;
    if (nb == 0)
        return NULL;
    memset(R, 0, sizeof *R);
    R->nb = nb;
    R->cap = nl;
    const size_t v6 = 6 * (size_t)nb;
    R->link = ws_arena_alloc(arena, (nl + 1) * sizeof *R->link);
    /* The bodies' block and its factor, (6 nb)^2 each: nb is the dynamic bodies the film
     * touches (a stack's boxes, tens at most). */
    double *d = ws_arena_alloc(arena, (nb * (1 + WS_SYM) + 3 * v6 * v6 + 8 * v6 + 6 * v6 +
                                       18 * (nl + 1)) *
                                          sizeof(double));
    R->env = ws_arena_alloc(arena, 2 * v6 * sizeof *R->env);
    R->phi_node = ws_arena_alloc(arena, (nl + 1) * sizeof *R->phi_node);
    R->phi_body = ws_arena_alloc(arena, (nl + 1) * sizeof *R->phi_body);
    R->phi_lever = ws_arena_alloc(arena, 3 * (nl + 1) * sizeof *R->phi_lever);
    R->crow = ws_arena_alloc(arena, ((size_t)nodes + 1) * sizeof *R->crow);
    R->cphi = ws_arena_alloc(arena, 2 * (nl + 1) * sizeof *R->cphi);
    R->cwork = ws_arena_alloc(arena, ws_rigid_coarse_words(nl, nb) * sizeof *R->cwork);
    R->bstart = ws_arena_alloc(arena, ((size_t)nblk + 1) * sizeof *R->bstart);
    R->bpart = ws_arena_alloc(arena, (size_t)nblk * v6 * sizeof *R->bpart);
    if (!R->link || !d || !R->env || !R->phi_node || !R->phi_body || !R->phi_lever || !R->crow ||
        !R->cphi || !R->cwork || !R->bstart || !R->bpart) {
        *fail = 1;
        return NULL;
    }
    memset(d, 0, 6 * v6 * sizeof(double));
    R->b = d, R->x = d + v6, R->r = d + 2 * v6, R->z = d + 3 * v6, R->p = d + 4 * v6;
    R->q = d + 5 * v6;
    R->mass = d + 6 * v6;
    R->inertia = R->mass + nb;
    R->abb = R->inertia + WS_SYM * (size_t)nb;
    R->fac = R->abb + v6 * v6;
    R->cb = R->fac + v6 * v6;
    R->cq = R->cb + v6;
    R->coarse = R->cq + v6;
    R->cyr = R->coarse + v6 * v6;
    R->cy = R->cyr + 6 * v6;
    /* Room for the film's multigrid to nest the bodies in (none without one). */
    const size_t mgb = ws_mg_body_bytes(mg, nb, nl);
    if (mgb && !(R->mgbuf = ws_arena_alloc(arena, mgb))) {
        *fail = 1;
        return NULL;
    }
    ws_world_rigid_bodies(R, b, slot);
    *slot_out = slot;
    return R;
}

/* Whether web is the first of the world's implicit webs that puts the bodies in its solve: the
 * body-body contacts' friction goes into that web's solve alone (once a step). */
static int first_coupled(const ws_world *w, const ws_web *web)
{
    for (size_t k = 0; k < w->web_slots.slot_count; k++) {
        if (w->web_slots.dense[k] == UINT32_MAX)
            continue;
        const ws_web *o = w->webs[k];
        if (o->integrator == WS_WEB_IMPLICIT && !o->hold_bodies)
            return o == web;
    }
    return 0;
}

/* The velocity of body bi's point at lever r at t. */
static v3 point_velocity(const ws_body_store *b, int cur, uint32_t bi, v3 r)
{
    return v3_add(b->st[cur].v[bi], v3_cross(b->wg[bi], r));
}

/* The change over the solved step of the velocity of body j's point at lever r (the solve's dU,
 * R->x, 6 a body). */
static v3 point_change(const ws_rigid *R, uint32_t j, v3 r)
{
    const double *dU = R->x + 6 * (size_t)j;
    return v3_add(v3_make(dU[0], dU[1], dU[2]), v3_cross(v3_make(dU[3], dU[4], dU[5]), r));
}

/* The contacts L into the film's matrix for step h (ws_implicit_add), and, for those with a
 * body of the solve (slot), into R: the link, the body's right-hand side h (F + sum J^T (-(f0 +
 * h K J U0) + h K v0)) with F its known load, and the node's force f0 + h K J U0, so that both
 * see the contact's relative motion over the step (docs/theory.md, section 8b). */
static void links_into(ws_implicit *im, ws_rigid *R, const uint32_t *slot, const ws_body_store *b,
                       int cur, const ws_node_link *L, size_t nl, ws_nodes3 v, double h)
{
    if (R) {
        R->nl = 0;
        for (size_t i = 0; i < b->slots; i++) {
            const uint32_t j = slot[i];
            if (j == UINT32_MAX)
                continue;
            double *B = R->b + 6 * (size_t)j;
            B[0] = h * b->f[i].x, B[1] = h * b->f[i].y, B[2] = h * b->f[i].z;
            B[3] = h * b->m[i].x, B[4] = h * b->m[i].y, B[5] = h * b->m[i].z;
        }
    }
    for (size_t k = 0; k < nl; k++) {
        const ws_node_link *c = &L[k];
        if (!c->active)
            continue;
        const uint32_t j = R ? slot[c->body] : UINT32_MAX;
        if (j == UINT32_MAX) {
            /* A world element's face moves h uk over the step (zero for the others). */
            double ku[3] = {0.0, 0.0, 0.0};
            ws_sym_madd(c->K, h * c->uk.x, h * c->uk.y, h * c->uk.z, ku);
            ws_implicit_add(im, c->node, v3_add(c->f, v3_make(ku[0], ku[1], ku[2])), c->K,
                            c->D);
            continue;
        }
        const v3 u0 = point_velocity(b, cur, c->body, c->lever), u = nodes_get(v, c->node);
        double ku[3] = {0.0, 0.0, 0.0}, kv[3] = {0.0, 0.0, 0.0};
        ws_sym_madd(c->K, h * u0.x, h * u0.y, h * u0.z, ku);
        ws_sym_madd(c->K, h * u.x, h * u.y, h * u.z, kv);
        const v3 f = v3_add(c->f, v3_make(ku[0], ku[1], ku[2]));
        ws_implicit_add(im, c->node, f, c->K, c->D);
        ws_rigid_link *q = &R->link[R->nl++];
        q->node = c->node;
        q->body = j;
        q->lever = c->lever;
        for (int s = 0; s < WS_SYM; s++)
            q->C[s] = h * h * c->K[s] + h * c->D[s];
        const v3 g = v3_sub(f, v3_make(kv[0], kv[1], kv[2])), m = v3_cross(c->lever, g);
        double *B = R->b + 6 * (size_t)j;
        B[0] -= h * g.x, B[1] -= h * g.y, B[2] -= h * g.z;
        B[3] -= h * m.x, B[4] -= h * m.y, B[5] -= h * m.z;
    }
}

/* The loads of the contacts with a body of the solve, as ws_node_link_loads wrote them (the
 * body held), made those of the solve: + h K J U0 + (h K + D) J dU, into the node's record and,
 * opposite, its body's. */
static void loads_moved(const ws_rigid *R, const uint32_t *slot, const ws_body_store *b, int cur,
                        const ws_node_link *L, size_t nl, double h, double share, v3 *fc,
                        v3 *bforce, v3 *bmoment)
{
    for (size_t k = 0; k < nl; k++) {
        const ws_node_link *c = &L[k];
        const uint32_t j = slot[c->body];
        if (!c->active || j == UINT32_MAX)
            continue;
        const v3 u0 = point_velocity(b, cur, c->body, c->lever),
                 du = point_change(R, j, c->lever);
        double o[3] = {0.0, 0.0, 0.0};
        ws_sym_madd(c->K, h * (u0.x + du.x), h * (u0.y + du.y), h * (u0.z + du.z), o);
        ws_sym_madd(c->D, du.x, du.y, du.z, o);
        const v3 d = v3_scale(v3_make(o[0], o[1], o[2]), share);
        fc[c->node] = v3_add(fc[c->node], d);
        bforce[c->body] = v3_sub(bforce[c->body], d);
        bmoment[c->body] = v3_sub(bmoment[c->body], v3_cross(c->lever, d));
    }
}

/* The solve's change of each contact's body point velocity along its normal (dub), for the
 * active set's test of the contacts' end forces (ws_node_link_update). */
static void body_moves(const ws_rigid *R, const uint32_t *slot, ws_node_link *L, size_t nl)
{
    for (size_t k = 0; k < nl; k++) {
        const uint32_t j = slot[L[k].body];
        if (j == UINT32_MAX)
            continue;
        L[k].dub = v3_dot(L[k].n, point_change(R, j, L[k].lever));
    }
}

/* Coulomb's static friction over the solved sub-step h (ws_node_link_stick, docs/theory.md 8c):
 * each sticking contact's node ends it moving with its body's point along the face, its
 * velocity in vd changed by h dF / m, and dF times share into the node's record and, opposite,
 * onto its body, in link order (node order: the same sums for any worker count). Contacts with
 * a body of the solve (R, slot) measure the slip against the point as the solve moved it. */
static void stick_links(const ws_step *S, ws_web *web, const ws_rigid *R, const uint32_t *slot,
                        const ws_node_link *L, size_t nl, ws_nodes3 vd, double h, double share)
{
    const double *dv = web->imp->dv;
    v3 *fc = web->fc[S->nxt], *bforce = web->bforce[S->nxt], *bmoment = web->bmoment[S->nxt];
    for (size_t k = 0; k < nl; k++) {
        const ws_node_link *c = &L[k];
        const uint32_t i = c->node;
        if (!c->active || !(c->mu > 0.0))
            continue;
        const uint32_t j = R ? slot[c->body] : UINT32_MAX;
        const v3 u0 = point_velocity(S->b, S->cur, c->body, c->lever);
        ws_node_end e = {nodes_get(vd, i), v3_make(dv[3 * i], dv[3 * i + 1], dv[3 * i + 2]),
                         v3_make(0, 0, 0), c->uk, u0};
        if (j != UINT32_MAX) {
            e.du = point_change(R, j, c->lever);
            e.ub = v3_add(u0, e.du);
            e.uk = e.ub;
        }
        v3 dF;
        if (!ws_node_link_stick(c, &e, web->m[i], h, &dF))
            continue;
        nodes_set(vd, i, v3_madd(e.v1, dF, h / web->m[i]));
        const v3 d = v3_scale(dF, share);
        fc[i] = v3_add(fc[i], d);
        bforce[c->body] = v3_sub(bforce[c->body], d);
        bmoment[c->body] = v3_sub(bmoment[c->body], v3_cross(c->lever, d));
    }
}

/* A bench's probe: each node's contact state over the step's links, a slipping contact above
 * a sticking one above an inactive one. */
static void probe_states(ws_implicit_probe *pr, const ws_node_pass *P, const ws_node_link *L,
                         size_t nl)
{
    for (size_t k = 0; k < nl; k++) {
        const double vlim = P->pp[P->b->material[L[k].body]].vlim;
        const uint8_t q = !L[k].active ? 1 : v3_norm(L[k].t) < vlim ? 2 : 3;
        if (q > pr->state[L[k].node])
            pr->state[L[k].node] = q;
        if (pr->watch_on && L[k].node == pr->watch && pr->watch_count < 4) {
            const uint32_t j = pr->watch_count++;
            pr->watch_link[j].body = L[k].body;
            pr->watch_link[j].active = L[k].active;
            pr->watch_link[j].fn = L[k].fn;
            pr->watch_link[j].k = L[k].k;
            pr->watch_link[j].c = L[k].c;
            pr->watch_link[j].fin = L[k].fin;
            pr->watch_link[j].n[0] = L[k].n.x;
            pr->watch_link[j].n[1] = L[k].n.y;
            pr->watch_link[j].n[2] = L[k].n.z;
            pr->watch_link[j].slip = v3_norm(L[k].t);
            pr->watch_link[j].nu =
                v3_dot(L[k].n, point_velocity(P->b, P->cur, L[k].body, L[k].lever));
        }
    }
}

ws_status ws_world_web_implicit(ws_step *S, ws_web *web, int list)
{
    ws_world *w = S->w;
    ws_body_store *b = S->b;
    const int cur = S->cur, nxt = S->nxt;
    const ws_ncand_list *cl = &web->contact->cand[list];
    /* The node contacts of the step's sub-steps (scratch of the step). */
    ws_node_link *links = NULL;
    if (ws_implicit_reserve(&w->mem, web) != 0 ||
        !(links = ws_arena_alloc(S->arena, (cl->n + 1) * sizeof *links)))
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for web '%s'", label(web));
    ws_implicit *im = web->imp;
    im->run = ws_world_runner(w);
    const int n = web->substeps;
    const double h = S->dt / n, share = 1.0 / n;
    ws_nodes3 xs = web->x[cur], vs = web->v[cur];
    for (int s = 0; s < n; s++) {
        const int last_parity = (n - 1 - s) % 2 == 0;
        ws_nodes3 xd = last_parity ? web->x[nxt] : web->xsub;
        ws_nodes3 vd = last_parity ? web->v[nxt] : web->vsub;
        if (ws_implicit_begin(web, xs, vs, w->def.gravity, S->t + s * h, s * h) != 0)
            return ws_fail(w, WS_ERR_CALLBACK,
                           "step at t = %.6g s: a spring law of web '%s' failed (its user "
                           "function returned non-zero or gave a non-finite force or "
                           "derivative); the step was undone",
                           w->time, label(web));
        /* The contacts the step may reach: those of nodes within a step's travel of the
         * window's top, bounded by the margin the candidates cover. */
        const ws_node_pass np = {b, cur,   &w->node_geom, w->node_par,      cl->c, xs, vs,
                                 h, share, NULL,          !web->hold_bodies};
        const size_t nl = ws_node_links(&np, web, cl->n, im->warm ? im->dv : NULL,
                                        S->contact.margin, links, NULL);
        if (im->probe && im->probe->state)
            probe_states(im->probe, &np, links, nl);
        uint32_t *slot = NULL;
        int nomem = 0;
        ws_rigid *R = web->hold_bodies
                          ? NULL
                          : rigid_make(S->arena, b, links, nl, web, &slot, &nomem);
        if (nomem)
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for web '%s'",
                           label(web));
        if (R && im->jacobi_only)
            R->coarse = NULL; /* a test's comparison: the plain block-diagonal preconditioner */
        /* The body-body friction in the solve: one solve a step (no sub-steps), of the first
         * web that couples the bodies. */
        if (R && n == 1 && !S->body_later && first_coupled(w, web) &&
            ws_world_friction_pairs(S, R, slot, h) != 0)
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for web '%s'",
                           label(web));
        /* The active set: a solve with the contacts that push, then with those whose linear
         * model pushes at the end of the step, and with the bodies' friction turned to the
         * secant where the step reverses a slip, until nothing changes (at most
         * WS_IMPLICIT_PASSES solves; the last set is kept). Each solve starts from the last. */
        int ok = 1;
        for (int pass = 0; pass < WS_IMPLICIT_PASSES; pass++) {
            if (pass > 0)
                ws_implicit_reset(im);
            links_into(im, R, slot, b, cur, links, nl, vs, h);
            im->rig = R;
            ok = ws_implicit_solve(web, vs, h) == 0;
            im->rig = NULL;
            if (!ok)
                break;
            ws_implicit_velocities(web, vs, vd);
            if (R)
                body_moves(R, slot, links, nl);
            if (pass + 1 == WS_IMPLICIT_PASSES)
                break;
            /* Both tests run: each readies its own change for the next solve. */
            const size_t moved = ws_node_link_update(links, nl, im->dv, vd, h);
            const size_t turned = R && R->npair ? ws_world_friction_turned(S, R, h) : 0;
            if (moved == 0 && turned == 0)
                break;
        }
        if (!ok) {
            S->stats->numerical_errors++;
            return ws_fail(w, WS_ERR_NUMERICAL,
                           "web '%s': the implicit step's linear solve did not converge at t = "
                           "%.6g s: a row's residual %.3g of its weight impulse after %d "
                           "iterations (tolerance %.3g, at most %d); the step was undone. Raise "
                           "solver_max_iterations or solver_tolerance, or take a smaller dt",
                           label(web), w->time, im->last_residual, im->last_iterations,
                           web->solver_tol, web->solver_maxit);
        }
        stick_links(S, web, R, slot, links, nl, vd, h, share);
        const size_t fast = ws_implicit_finish(web, xs, xd, vd, h, w->def.max_speed);
        if (fast) {
            S->stats->numerical_errors++;
            const double vmax = ws_web_fastest(web, vd);
            return ws_fail(w, WS_ERR_NUMERICAL,
                           "web '%s': a node ran away in the implicit step at t = %.6g s "
                           "(speed %.3g m/s above max_speed %.3g); the step was undone. A body "
                           "that hits the film too fast, or a law stiffer than its derivative "
                           "says: try a smaller dt",
                           label(web), w->time, vmax, w->def.max_speed);
        }
        const size_t nt = web->nfct[nxt];
        web->nfct[nxt] +=
            ws_node_link_loads(links, nl, im->dv, vd, h, share, web->fc[nxt], web->fct[nxt] + nt,
                               web->bforce[nxt], web->bmoment[nxt]);
        if (R)
            loads_moved(R, slot, b, cur, links, nl, h, share, web->fc[nxt], web->bforce[nxt],
                        web->bmoment[nxt]);
        if (R && R->npair)
            ws_world_friction_loads(S, R, h);
        xs = xd;
        vs = vd;
    }
    /* The film's pull on each body, its sub-steps averaged, into the body's accumulators. */
    for (size_t i = 0; i < web->bcap && i < b->slots; i++) {
        b->f[i] = v3_add(b->f[i], web->bforce[nxt][i]);
        b->m[i] = v3_add(b->m[i], web->bmoment[nxt][i]);
    }
    return WS_OK;
}
