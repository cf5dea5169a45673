/* Node contacts of an implicit web (contact module): each contact's force at the start of the
 * step with its derivatives, for the film's linear solve (web/implicit.h), and the loads on the
 * bodies from the solved step. */
#ifndef WS_CONTACT_NODE_JACOBIAN_H
#define WS_CONTACT_NODE_JACOBIAN_H

#include "contact/node.h"
#include "web/implicit.h"

/* A pushing contact of node `node` and body `body` at the start of a step: the force on the node
 * f (normal force and friction), the lever from the body's CoG to the contact point and the
 * symmetric blocks the matrix takes (K = -df/dx, D = -df/dv, positive semi-definite). The exact
 * derivatives are ws_node_exact's, apart: the step never reads them. */
typedef struct ws_node_link {
    uint32_t node, body;
    int active;  /* in the step's matrix and forces (ws_node_link_update) */
    v3 f, lever;
    v3 n;        /* the unit normal, from the body to the node */
    double fn;   /* the normal force at the start as the penalty gives it, negative when the
                    node lies beyond the window (not clamped) */
    double k, c; /* the contact's stiffness and damping */
    double fin;  /* the least normal force at the end of the step that brings it in once the
                    step is solved (ws_node_link_update) */
    double mu;   /* its friction coefficient, 0 for a pinned node */
    v3 t, tt;    /* the tangential slip at the start and its direction (zero at rest) */
    double phi, dp; /* eq. 13 over the slip: F_t = -mu N phi t; dp = p'(s) / v_lim */
    /* The body's contact point's velocity along n at the start (ub) and its change over the
     * step (dub, the solve's, set by its caller before ws_node_link_update), when the body moves
     * in the film's solve (ws_node_pass's bodies_move); both 0 when it is held there. */
    double ub, dub;
    /* A world element's contact point's velocity at the start (its motion over the step is
     * given, not solved: the face moves h uk in it); zero for the other bodies. */
    v3 uk;
    double K[WS_SYM], D[WS_SYM];
} ws_node_link;

/* A contact's exact derivatives of its force at the start of the step, Jx = df/dx and Jv =
 * df/dv (row-major), for a body that does not spin: what the matrix's K and D approximate (the
 * tests compare both with finite differences). */
typedef struct ws_node_exact {
    double Jx[9], Jv[9];
} ws_node_exact;

/* The contacts of the candidates P->cand[0, count) (sorted by node) with the node state (P->x,
 * P->v) and the bodies at state P->cur (features prepared in P->g), parameters P->pp by body
 * material, the window raised by reach: each into out (room for count), their number returned.
 * A contact that pushes at the start starts active, with its friction, and so does one that the
 * node reaches within the step P->h at its present velocity plus `guess` (xyz per node; NULL:
 * none), relative to its body's point when P->bodies_move and the body is dynamic (with the
 * normal force it would end with); any other (beyond the window, or leaving
 * it) starts inactive with its normal force's linear model alone (f = fn n, K, D along n),
 * which ws_node_link_update may bring in. P's share and fc are not read. exact (room for count,
 * or NULL: not computed) receives each contact's exact derivatives, in the order of out. */
size_t ws_node_links(const ws_node_pass *P, const ws_web *web, size_t count, const double *guess,
                     double reach, ws_node_link *out, ws_node_exact *exact);

/* After a solve over step h (dv; new velocities v1): each contact's normal force at the end of
 * the step by its linear model, fn - k h n.(v1 - ub - dub) - c n.(dv - dub) (the node's motion
 * relative to the body's point, as the solve takes it); an inactive contact becomes active
 * when it pushes by more than fin (an active one stays). Returns how many changed. */
size_t ws_node_link_update(ws_node_link *L, size_t count, const double *dv, ws_nodes3 v1,
                           double h);

/* The motion a contact's static friction test takes at the end of a solved step: its node's
 * velocity v1 and change dv, its body's point's velocity change du (the solve's; zero for a body
 * held in it or a world element), the velocity its normal force's linear model takes the node
 * against (uk, plus the point's velocity at the end when the body moves in the solve) and the
 * velocity of the body's point at the end, which the slip is measured against. */
typedef struct ws_node_end {
    v3 v1, dv, du, uk, ub;
} ws_node_end;

/* Coulomb's static friction over the solved step h for an active contact c with friction, as
 * the explicit film's friction stops a node's slip within its sub-step (friction_of): t1 the
 * node's slip at the end of the step (tangential, against e->ub), F the contact's force over
 * the step as the solve took it (ws_node_link_loads'). When the friction that ends the step
 * without slip, F's tangential part minus m t1 / h (m the node's mass), lies within mu times
 * F's normal part, the contact sticks: returns 1 with that change of force in *dF (the node's
 * velocity then changes by -t1: h dF / m); else 0 (the node slides by eq. 13, as solved). */
int ws_node_link_stick(const ws_node_link *c, const ws_node_end *e, double m, double h, v3 *dF);

/* After the web's solve over step h (dv, the new velocities v1): each contact's force at the
 * end of the step as the solve took it, f + Jx h v1 + Jv dv with the matrix's blocks, times
 * share into the node's record fc and, opposite, onto its body (bforce, bmoment: about the
 * CoG), in node order, for the active contacts; the nodes written listed in touched (room for count), their number
 * returned. */
size_t ws_node_link_loads(const ws_node_link *L, size_t count, const double *dv, ws_nodes3 v1,
                          double h, double share, v3 *fc, uint32_t *touched, v3 *bforce,
                          v3 *bmoment);

#endif
