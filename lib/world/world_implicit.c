/* An implicit web's part of the step (web/implicit.h, contact/node_jacobian.h): per sub-step,
 * the springs and the node contacts at its start, one linear solve, the new node state and the
 * contacts' loads on the bodies, which are held at their state at t as for the explicit film
 * (deviation (h) of docs/design.md). */
#include "contact/node_jacobian.h"
#include "world/world_internal.h"

#include <float.h>
#include <stdio.h>

/* Solves a sub-step at most, as its contacts come in and go (the active set). */
#define WS_IMPLICIT_PASSES 6

static const char *label(const ws_web *web)
{
    return web->name ? web->name : "(unnamed)";
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
        const ws_node_pass np = {b, cur, &w->node_geom, w->node_par, cl->c, xs, vs, h, share, NULL};
        const size_t nl = ws_node_links(&np, web, cl->n, im->warm ? im->dv : NULL,
                                        S->contact.margin, links);
        /* The active set: a solve with the contacts that push, then with those whose linear
         * model pushes at the end of the step, until no contact changes (at most
         * WS_IMPLICIT_PASSES solves; the last set is kept). Each solve starts from the last. */
        int ok = 1;
        for (int pass = 0; pass < WS_IMPLICIT_PASSES; pass++) {
            if (pass > 0)
                ws_implicit_reset(im);
            for (size_t k = 0; k < nl; k++)
                if (links[k].active)
                    ws_implicit_add(im, links[k].node, links[k].f, links[k].K, links[k].D);
            if ((ok = ws_implicit_solve(web, vs, h) == 0) == 0)
                break;
            ws_implicit_velocities(web, vs, vd);
            if (pass + 1 == WS_IMPLICIT_PASSES ||
                ws_node_link_update(links, nl, im->dv, vd, h) == 0)
                break;
        }
        if (!ok) {
            S->stats->numerical_errors++;
            return ws_fail(w, WS_ERR_NUMERICAL,
                           "web '%s': the implicit step's linear solve did not converge at t = "
                           "%.6g s: residual %.3g of its scale after %d iterations (tolerance "
                           "%.3g, at most %d); the step was undone. Raise "
                           "solver_max_iterations or solver_tolerance, or take a smaller dt",
                           label(web), w->time, im->last_residual, im->last_iterations,
                           web->solver_tol, web->solver_maxit);
        }
        const size_t fast = ws_implicit_finish(web, xs, vs, xd, vd, h, w->def.max_speed);
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
