/* Node contacts of an implicit web: forces at the start of the step and their derivatives
 * (node_jacobian.h). The contact is the explicit film's (node_force.c): a penalty normal force
 * on the overlap with damping on its rate, at the contact point midway in the overlap, never
 * pulling; friction by eq. 13, regularised below v_lim. What differs is how a step takes them:
 * the explicit film limits friction to what stops the node within its sub-step (deviation (g)
 * of docs/design.md), while here eq. 13 itself goes into the implicit step as a damper, which
 * backward Euler keeps stable at any step (docs/theory.md, "The implicit film"). */
#include "contact/node_jacobian.h"
#include "contact/penalty.h"

#include <string.h>

static void outer_add(double *J, double c, v3 a, v3 b)
{
    const double av[3] = {a.x, a.y, a.z}, bv[3] = {b.x, b.y, b.z};
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            J[3 * i + k] += c * av[i] * bv[k];
}

/* J += c M N, 3x3 row-major. */
static void mul_add(double *J, double c, const double *M, const double *N)
{
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            double s = 0.0;
            for (int q = 0; q < 3; q++)
                s += M[3 * i + q] * N[3 * q + k];
            J[3 * i + k] += c * s;
        }
}

/* Eq. 13 over the slip t (ws_friction_p): F_t = -mu N phi t, phi = p(s) / |t| (2 / v_lim at
 * rest, its limit), and dp = p'(s) / v_lim, with the slip's direction tt (zero at rest). */
static void link_slip(ws_node_link *L, v3 t, double vlim)
{
    const double tl = v3_norm(t), s = tl / vlim;
    L->t = t;
    L->phi = ws_friction_phi(tl, vlim);
    L->dp = 2.0 / vlim;
    L->tt = v3_make(0, 0, 0);
    if (tl > 0.0) {
        L->dp = ws_friction_slope(s) / vlim;
        L->tt = v3_scale(t, 1.0 / tl);
    }
}

/* The exact derivatives of an active contact L's force (ws_node_exact) with the normal force f,
 * the relative velocity vr and its normal part vn, the contact's parameters p, G as link_of's.
 * df/dx = -k gd^T - c vr^T G, gd the gradient of the distance pushed over (n, but past a
 * convex edge where faces blend: ws_node_touch_at's g; the body's spin, of relative size
 * c |w| / k, left out), and
 * df/du = -c n^T; friction's through its slip and through f. */
static void exact_of(const ws_node_params *p, const ws_node_link *L, v3 vr, double vn, double f,
                     const double G[9], v3 gd, int pinned, ws_node_exact *J)
{
    const v3 n = L->n;
    memset(J, 0, sizeof *J);
    double dfx[3] = {-p->k * gd.x, -p->k * gd.y, -p->k * gd.z};
    const double vrv[3] = {vr.x, vr.y, vr.z};
    for (int k = 0; k < 3; k++)
        for (int q = 0; q < 3; q++)
            dfx[k] -= p->c * vrv[q] * G[3 * q + k];
    const v3 dfxv = v3_make(dfx[0], dfx[1], dfx[2]);
    outer_add(J->Jx, 1.0, n, dfxv);
    for (int k = 0; k < 9; k++)
        J->Jx[k] += f * G[k];
    outer_add(J->Jv, -p->c, n, n);
    if (!(p->mu > 0.0) || pinned)
        return;
    /* Eq. 13 over the tangential slip t: F_t = -mu f phi t (link_slip) and dF_t/dt = -mu f
     * (phi I + (p'/v_lim - phi) tt^T), tt = t / |t|. */
    const v3 t = L->t, tt = L->tt;
    const double phi = L->phi, dp = L->dp, mf = p->mu * f;
    double T[9] = {0}; /* dF_t/dt at fixed f */
    for (int i = 0; i < 3; i++)
        T[4 * i] = -mf * phi;
    outer_add(T, -mf * (dp - phi), tt, tt);
    /* dt/du = I - n n^T; dt/dx = -(vn G + n vr^T G). */
    double Pn[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, Tx[9];
    outer_add(Pn, -1.0, n, n);
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            double s2 = 0.0;
            for (int q = 0; q < 3; q++)
                s2 += vrv[q] * G[3 * q + k];
            const double nv[3] = {n.x, n.y, n.z};
            Tx[3 * i + k] = -(vn * G[3 * i + k] + nv[i] * s2);
        }
    mul_add(J->Jx, 1.0, T, Tx);
    mul_add(J->Jv, 1.0, T, Pn);
    /* Through the normal force: F_t is proportional to f. */
    outer_add(J->Jx, -p->mu * phi, t, dfxv);
    outer_add(J->Jv, p->mu * phi * p->c, t, n);
}

/* One contact, its force and the matrix's blocks (see ws_node_link), for the node at x (velocity
 * u, a pinned one without friction) touching a body of motion b at `at`, the contact's
 * parameters p; with J not NULL its exact derivatives too (exact_of; zero when it does not
 * push). G: dn/dx (zero for a face but one past a convex edge, (P_e - n n^T) / d for an
 * edge's rim, P_e the projection across the edge), read for J alone. The force is the contact laws' (penalty.h), as the
 * explicit film's. */
static void link_of(const ws_node_params *p, v3 x, v3 u, ws_motion b, const ws_node_touch_at *at,
                    const double G[9], int pinned, ws_node_link *L, ws_node_exact *J)
{
    const v3 n = at->n;
    const ws_node_kin kin = ws_node_kinematics(n, at->d, x, u, b);
    const ws_normal law = ws_normal_law(n, kin.vr, at->hi - at->d, p->k, p->c);
    const double f = law.fn;
    memset(L, 0, sizeof *L);
    L->lever = kin.lever;
    L->n = n;
    L->fn = f;
    L->k = p->k;
    L->c = p->c;
    /* A node the solved step takes less than 2 % of the window into it is left out of that
     * step: a film lying on a flat face (no pressure from its tension) hovers at the window's
     * edge, and each step would bring some of its nodes in by nanometres, at the cost of a
     * second solve. Their force, at most k hi / 50 (0.16 N, 40 um, on the reference case), comes in
     * at the next step. */
    L->fin = 0.02 * p->k * at->hi;
    L->active = f > 0.0;
    L->mu = pinned ? 0.0 : p->mu;
    link_slip(L, law.t, p->vlim);
    if (J) {
        if (L->active)
            exact_of(p, L, kin.vr, law.vn, f, G, at->g, pinned, J);
        else
            memset(J, 0, sizeof *J);
    }
    ws_sym_add_outer(L->K, p->k, n);
    ws_sym_add_outer(L->D, p->c, n);
    if (!L->active) {
        /* Not pushing now: the penalty's linear model alone, for the step to take if it
         * brings the node in (ws_node_link_update, which adds the friction then). */
        L->f = v3_scale(n, f);
        return;
    }
    v3 F = v3_scale(n, f);
    if (p->mu > 0.0 && !pinned) {
        /* Eq. 13 over the tangential slip t: F_t = -mu f phi t (link_slip). The matrix takes
         * friction as the damper its own force is over the slip, mu f phi across the normal
         * (the secant, not the tangent, exact_of's): at rest they are the same (phi = p'(0) /
         * v_lim), but a sliding node's tangent has no damping along the slip (Coulomb's force
         * does not grow with speed), and one linear step would carry the node past the
         * reversal of its slip with nothing to stop it. As a damper, backward Euler ends the
         * step with the force -mu f phi t1 against the slip it ends with, which cannot
         * overshoot. The coupling through f (t n^T) is not symmetric and vanishes at rest. */
        const double mf = p->mu * f;
        F = v3_madd(F, L->t, -mf * L->phi);
        double Dn[WS_SYM] = {0};
        ws_sym_add_outer(Dn, -1.0, n);
        Dn[WS_SYM_XX] += 1.0;
        Dn[WS_SYM_YY] += 1.0;
        Dn[WS_SYM_ZZ] += 1.0;
        for (int k = 0; k < WS_SYM; k++)
            L->D[k] += mf * L->phi * Dn[k];
    }
    L->f = F;
}

/* A contact that did not push at the start brought into the step, which ends with the normal
 * force fe > 0 by its linear model: its friction over the slip at the start with that normal
 * force, as a damper like any other (link_of). */
static void bring_in(ws_node_link *c, double fe)
{
    c->active = 1;
    if (!(c->mu > 0.0))
        return;
    const double mf = c->mu * fe;
    c->f = v3_madd(v3_scale(c->n, c->fn), c->t, -mf * c->phi);
    double *Dm = c->D;
    memset(Dm, 0, WS_SYM * sizeof(double));
    ws_sym_add_outer(Dm, c->c - mf * c->phi, c->n);
    Dm[WS_SYM_XX] += mf * c->phi;
    Dm[WS_SYM_YY] += mf * c->phi;
    Dm[WS_SYM_ZZ] += mf * c->phi;
}

size_t ws_node_links(const ws_node_pass *P, const ws_web *web, size_t count, const double *guess,
                     double reach, ws_node_link *out, ws_node_exact *exact)
{
    size_t m = 0;
    const ws_body_store *b = P->b;
    const ws_body_state *st = &b->st[P->cur];
    for (size_t k = 0; k < count; k++) {
        const ws_ncand *c = &P->cand[k];
        const uint32_t i = c->node, bi = c->body;
        const v3 xi = nodes_get(P->x, i);
        ws_node_touch_at at;
        if (!ws_node_touch(P, web, c, xi, reach, &at))
            continue;
        double G[9] = {0}; /* the exact derivatives' alone */
        if (exact) /* a face's: zero, but past a convex edge (ws_node_touch_at) */
            outer_add(G, 1.0, at.ta, at.tb);
        if (exact && (c->local & WS_NCAND_EDGE)) {
            /* The rim's normal turns with the node: dn/dx = (I - e e^T - n n^T) / d. */
            const ws_wedge *E = &P->g->edge[c->feat];
            const v3 e = v3_scale(E->e, sqrt(E->inv_e2));
            const double ev[3] = {e.x, e.y, e.z}, nv[3] = {at.n.x, at.n.y, at.n.z};
            for (int r = 0; r < 3; r++)
                for (int q = 0; q < 3; q++)
                    G[3 * r + q] = ((r == q) - ev[r] * ev[q] - nv[r] * nv[q]) / at.d;
        }
        ws_node_exact *J = exact ? &exact[m] : NULL;
        ws_node_link *L = &out[m++];
        const ws_motion mb = {st->r[bi], st->v[bi], b->wg[bi]};
        link_of(&P->pp[b->material[bi]], xi, nodes_get(P->v, i), mb, &at, G, web->inv_m[i] == 0.0,
                L, J);
        L->node = i;
        L->body = bi;
        /* One that the node reaches within the step at its present velocity, plus the guess of
         * its change (the last step's), comes in now, which spares most steps a second solve. */
        v3 u = nodes_get(P->v, i);
        if (guess)
            u = v3_add(u, v3_make(guess[3 * i], guess[3 * i + 1], guess[3 * i + 2]));
        /* Relative to the body's point when the body moves in the solve: a face that moves
         * with the node (a stack turning with the platform) is not reached by the node's own
         * speed, and one brought in while it is not reached pulls the node in by its linear
         * model for the step, to let it go the next (docs/theory.md 8b). */
        if (b->type[bi] == WS_BODY_KINEMATIC) {
            /* A world element moves as it is told over the step, solve or no solve. */
            L->uk = v3_add(mb.v, v3_cross(mb.w, L->lever));
            L->ub = v3_dot(at.n, L->uk);
        } else if (P->bodies_move && b->type[bi] == WS_BODY_DYNAMIC) {
            L->ub = v3_dot(at.n, v3_add(mb.v, v3_cross(mb.w, L->lever)));
        }
        const double nv = v3_dot(at.n, u) - L->ub, fe = L->fn - L->k * P->h * nv;
        if (!L->active && fe > 0.0)
            bring_in(L, fe);
    }
    return m;
}

size_t ws_node_link_loads(const ws_node_link *L, size_t count, const double *dv, ws_nodes3 v1,
                          double h, double share, v3 *fc, uint32_t *touched, v3 *bforce,
                          v3 *bmoment)
{
    size_t m = 0;
    for (size_t k = 0; k < count; k++) {
        const ws_node_link *c = &L[k];
        const uint32_t i = c->node;
        if (!c->active)
            continue;
        const double *D = dv + 3 * (size_t)i;
        const v3 u = nodes_get(v1, i);
        /* f - K h (v1 - uk) - D dv: the force the node's solve took over the step. */
        double o[3] = {0.0, 0.0, 0.0};
        ws_sym_madd(c->K, h * (u.x - c->uk.x), h * (u.y - c->uk.y), h * (u.z - c->uk.z), o);
        ws_sym_madd(c->D, D[0], D[1], D[2], o);
        const v3 F = v3_sub(c->f, v3_make(o[0], o[1], o[2]));
        const v3 load = v3_scale(F, -share);
        fc[i] = v3_sub(fc[i], load);
        touched[m++] = i;
        bforce[c->body] = v3_add(bforce[c->body], load);
        bmoment[c->body] = v3_add(bmoment[c->body], v3_cross(c->lever, load));
    }
    return m;
}

int ws_node_link_stick(const ws_node_link *c, const ws_node_end *e, double m, double h, v3 *dF)
{
    *dF = v3_make(0.0, 0.0, 0.0);
    if (!c->active || !(c->mu > 0.0) || !(m > 0.0))
        return 0;
    const v3 n = c->n;
    const v3 r = v3_sub(e->v1, e->ub), t1 = v3_madd(r, n, -v3_dot(n, r));
    /* f - h K (v1 - uk) - D (dv - du): the force the solve took over the step. */
    const v3 q = v3_sub(e->v1, e->uk), d = v3_sub(e->dv, e->du);
    double o[3] = {0.0, 0.0, 0.0};
    ws_sym_madd(c->K, h * q.x, h * q.y, h * q.z, o);
    ws_sym_madd(c->D, d.x, d.y, d.z, o);
    const v3 F = v3_sub(c->f, v3_make(o[0], o[1], o[2]));
    const double fn = v3_dot(n, F);
    const v3 stop = v3_scale(t1, -m / h), held = v3_add(v3_madd(F, n, -fn), stop);
    if (!(fn > 0.0) || !(v3_norm(held) <= c->mu * fn))
        return 0;
    *dF = stop;
    return 1;
}

size_t ws_node_link_update(ws_node_link *L, size_t count, const double *dv, ws_nodes3 v1,
                           double h)
{
    size_t changed = 0;
    for (size_t k = 0; k < count; k++) {
        ws_node_link *c = &L[k];
        const uint32_t i = c->node;
        const double *D = dv + 3 * (size_t)i;
        const double nv = c->n.x * v1.x[i] + c->n.y * v1.y[i] + c->n.z * v1.z[i] - c->ub - c->dub,
                     nd = c->n.x * D[0] + c->n.y * D[1] + c->n.z * D[2] - c->dub;
        const double fe = c->fn - c->k * h * nv - c->c * nd;
        /* Contacts come in and never leave within a step: a node that would leave its face
         * keeps the linear model of its force for this one step (which may end pulling a
         * little, the node's momentum and the body's load agreeing), while the set grows
         * to a fixed point in a few solves (taken out and put back, a node at the edge of
         * the window could go on forever). */
        if (!c->active && fe > c->fin) {
            bring_in(c, fe);
            changed++;
        }
    }
    return changed;
}
