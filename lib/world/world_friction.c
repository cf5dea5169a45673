/* The bodies' regularised friction taken at the end of the step (docs/theory.md, section 5).
 * Below v_lim eq. 13 is a damper whose rate on a clamped stack is far past the explicit limit
 * 2 / dt (the film presses the boxes together at several times their weight): taken at the
 * step's start the boxes twist back and forth every step and a load creeps faster than the
 * law allows. Here each contact's friction is linearised about the slip at the start,
 * F(t1) = F(t0) - C (t1 - t0) for the slips t0 at the start and t1 at the end, C its slopes on
 * the tangent plane (the secant across the slip, ws_friction_phi; the law's slope along it,
 * ws_friction_slope, zero once it slides, so a sliding box feels Coulomb's force to the bit;
 * where the step reverses a slip, the secant along it too, so that the friction at most stops
 * it), and the bodies' velocity changes dU over the step solve
 *
 *     (M + h sum J^T C J) dU = h F,      J the contact point's motion,
 *
 * all bodies at once (the twist of one box against another is a mode of the pair, not of
 * either: a per-contact or per-body damper overshoots, the boxes swap velocities). The
 * friction's change over the step, -C J dU, is added to the bodies' loads, and the integrators
 * take the loads as before. The matrix is the bodies' block of an implicit web's coupled solve
 * (web/coupled.h) with no film in it, solved by conjugate gradients preconditioned by each
 * body's own block (the whole block's factor cost a pile of 64 cartons 4x a step). A web that
 * puts the bodies in its own solve takes the friction of its bodies' contacts there
 * (world_implicit.c), linearised the same way, and those contacts are left out here. */
#include "contact/penalty.h"
#include "web/coupled.h"
#include "world/world_internal.h"

#include <math.h>
#include <string.h>

/* The solve's stopping rule: the preconditioned residual's norm against the loads'. At 1e-8
 * the friction's change is exact to far below what the step resolves (its force to 1e-8 of
 * the loads): two boxes take 2-3 iterations, a pile of 64 cartons 18 (13 at 1e-6, 22 at
 * 1e-10). */
#define WS_FRICTION_TOL 1e-8

/* The most solves a step: the first, and again while a slip the step reverses turns its pair's
 * slope to the secant (ws_world_friction_turned; a pair turns once, so the turns end; one more
 * solve settles them in the cases measured). The last solve's answer is kept. */
#define WS_FRICTION_SOLVES 4

void ws_world_rigid_bodies(ws_rigid *R, const ws_body_store *b, const uint32_t *slot)
{
    for (size_t i = 0; i < b->slots; i++) {
        const uint32_t j = slot[i];
        if (j == UINT32_MAX)
            continue;
        R->mass[j] = b->mass[i];
        /* The global inertia A J A^T, symmetrised against round-off. */
        const m3 At = m3_transpose(&b->A[i]), JA = m3_mul(&b->J[i], &At);
        const m3 I = m3_mul(&b->A[i], &JA);
        double *S = R->inertia + WS_SYM * (size_t)j;
        S[WS_SYM_XX] = I.m[0], S[WS_SYM_YY] = I.m[4], S[WS_SYM_ZZ] = I.m[8];
        S[WS_SYM_XY] = 0.5 * (I.m[1] + I.m[3]);
        S[WS_SYM_XZ] = 0.5 * (I.m[2] + I.m[6]);
        S[WS_SYM_YZ] = 0.5 * (I.m[5] + I.m[7]);
    }
}

/* Whether record c's friction is a damper for a solve: the regularised law, a friction
 * coefficient, a contact that pushes. */
static int damps(const ws_step *S, const ws_contact_rec *c)
{
    const ws_pair_params *pp = ws_contact_params(&S->contact, c->a, c->b);
    return pp->model == WS_FRICTION_REGULARIZED && pp->mu > 0.0 && c->fn > 0.0;
}

/* Pair P's slopes h C for contact c: the secant across the slip, and along it the law's own
 * slope, cap p'(s) / v_lim (zero at and above v_lim, where the force's size is the cap), or
 * with slope clear the secant there too. */
static void pair_damper(const ws_step *S, ws_rigid_pair *P, const ws_contact_rec *c, double h,
                        int slope)
{
    const ws_pair_params *pp = ws_contact_params(&S->contact, c->a, c->b);
    const double v = v3_norm(c->vt);
    const double hc = h * pp->mu * c->fn * ws_friction_phi(v, pp->vlim),
                 along = slope ? h * pp->mu * c->fn * ws_friction_slope(v / pp->vlim) / pp->vlim
                               : hc;
    memset(P->C, 0, sizeof P->C);
    ws_sym_add_outer(P->C, -hc, c->n);
    P->C[WS_SYM_XX] += hc;
    P->C[WS_SYM_YY] += hc;
    P->C[WS_SYM_ZZ] += hc;
    if (along != hc && v > 0.0)
        ws_sym_add_outer(P->C, along - hc, v3_scale(c->vt, 1.0 / v));
}

int ws_world_friction_pairs(ws_step *S, ws_rigid *R, const uint32_t *slot, double h)
{
    const ws_world *w = S->w;
    const ws_body_store *b = S->b;
    const ws_contact_rec *rec = w->rec[S->nxt];
    R->npair = 0;
    R->pair = NULL;
    if (S->nrec == 0)
        return 0;
    if (!(R->pair = ws_arena_alloc(S->arena, S->nrec * sizeof *R->pair)))
        return -1;
    if (!S->friction_taken) {
        if (!(S->friction_taken = ws_arena_alloc(S->arena, S->nrec)))
            return -1;
        memset(S->friction_taken, 0, S->nrec);
    }
    for (size_t k = 0; k < S->nrec; k++) {
        const ws_contact_rec *c = &rec[k];
        const uint32_t ja = slot[c->a], jb = slot[c->b];
        /* Both sides in the solve, or one of them a world element (its motion given): a
         * dynamic body outside the solve keeps the pair's friction in its own step. */
        const int out_a = ja == UINT32_MAX && b->type[c->a] == WS_BODY_DYNAMIC,
                  out_b = jb == UINT32_MAX && b->type[c->b] == WS_BODY_DYNAMIC;
        if ((ja == UINT32_MAX && jb == UINT32_MAX) || out_a || out_b || S->friction_taken[k] ||
            !damps(S, c))
            continue;
        ws_rigid_pair *P = &R->pair[R->npair++];
        P->a = ja;
        P->b = jb;
        P->tag = (uint32_t)k;
        P->ra = v3_sub(c->x, b->st[S->cur].r[c->a]);
        P->rb = v3_sub(c->x, b->st[S->cur].r[c->b]);
        pair_damper(S, P, c, h, 1);
        S->friction_taken[k] = WS_FRICTION_TAKEN;
    }
    return 0;
}

size_t ws_world_friction_turned(ws_step *S, ws_rigid *R, double h)
{
    const ws_contact_rec *rec = S->w->rec[S->nxt];
    size_t turned = 0;
    for (size_t q = 0; q < R->npair; q++) {
        ws_rigid_pair *P = &R->pair[q];
        const ws_contact_rec *c = &rec[P->tag];
        /* At rest the slope is the secant already; a pair turned once stays so. */
        if (S->friction_taken[P->tag] == WS_FRICTION_TURNED || !(v3_norm(c->vt) > 0.0))
            continue;
        const v3 t1 = v3_add(c->vt, ws_rigid_pair_slip(R, q, R->x));
        if (v3_dot(t1, c->vt) < 0.0) {
            pair_damper(S, P, c, h, 0);
            S->friction_taken[P->tag] = WS_FRICTION_TURNED;
            turned++;
        }
    }
    return turned;
}

void ws_world_friction_loads(ws_step *S, const ws_rigid *R, double h)
{
    ws_body_store *b = S->b;
    ws_contact_rec *rec = S->w->rec[S->nxt];
    for (size_t q = 0; q < R->npair; q++) {
        const ws_rigid_pair *P = &R->pair[q];
        ws_contact_rec *c = &rec[P->tag];
        const v3 d = ws_rigid_pair_slip(R, q, R->x);
        double g[3] = {0.0, 0.0, 0.0};
        ws_sym_madd(P->C, d.x, d.y, d.z, g);
        const v3 F = v3_scale(v3_make(g[0], g[1], g[2]), -1.0 / h);
        const v3 Mb = v3_cross(P->rb, F), Ma = v3_cross(P->ra, F);
        c->ft = v3_add(c->ft, F);
        /* A contact's load on the bodies, for the energy guard as the rest of it. */
        if (P->b != UINT32_MAX) {
            b->f[c->b] = v3_add(b->f[c->b], F);
            b->m[c->b] = v3_add(b->m[c->b], Mb);
            S->guard_f[c->b] = v3_add(S->guard_f[c->b], F);
            S->guard_m[c->b] = v3_add(S->guard_m[c->b], Mb);
        }
        if (P->a != UINT32_MAX) {
            b->f[c->a] = v3_sub(b->f[c->a], F);
            b->m[c->a] = v3_sub(b->m[c->a], Ma);
            S->guard_f[c->a] = v3_sub(S->guard_f[c->a], F);
            S->guard_m[c->a] = v3_sub(S->guard_m[c->a], Ma);
        }
    }
}

/* The solve's bodies: every dynamic body of a contact whose friction damps and no web took,
 * an index in slot (UINT32_MAX for the others), with its mass and global inertia and the
 * solve's scratch, from the step's arena. NULL with *fail 0 when there is none, with *fail 1
 * when out of memory. */
static ws_rigid *bodies_make(ws_step *S, uint32_t **slot_out, int *fail)
{
    const ws_body_store *b = S->b;
    const ws_contact_rec *rec = S->w->rec[S->nxt];
    *fail = 1;
    uint32_t *slot = ws_arena_alloc(S->arena, (b->slots + 1) * sizeof *slot);
    if (!slot)
        return NULL;
    for (size_t i = 0; i < b->slots; i++)
        slot[i] = UINT32_MAX;
    uint32_t nb = 0;
    for (size_t k = 0; k < S->nrec; k++) {
        const ws_contact_rec *c = &rec[k];
        if ((S->friction_taken && S->friction_taken[k]) || !damps(S, c))
            continue;
        const uint32_t ends[2] = {c->a, c->b};
        for (int e = 0; e < 2; e++)
            if (b->type[ends[e]] == WS_BODY_DYNAMIC && slot[ends[e]] == UINT32_MAX)
                slot[ends[e]] = nb++;
    }
    *fail = 0;
    if (nb == 0)
        return NULL;
    *fail = 1;
    const size_t v6 = 6 * (size_t)nb;
    ws_rigid *R = ws_arena_alloc(S->arena, sizeof *R);
    double *d = ws_arena_alloc(S->arena, (nb * (1 + WS_SYM + 36) + 6 * v6) * sizeof *d);
    if (!R || !d)
        return NULL;
    memset(R, 0, sizeof *R);
    R->nb = nb;
    R->mass = d;
    R->inertia = R->mass + nb;
    R->fac = R->inertia + WS_SYM * (size_t)nb; /* each body's own block, 36 doubles */
    R->b = R->fac + 36 * (size_t)nb;
    R->x = R->b + v6;
    R->r = R->x + v6;
    R->z = R->r + v6;
    R->p = R->z + v6;
    R->q = R->p + v6;
    ws_world_rigid_bodies(R, b, slot);
    for (size_t i = 0; i < b->slots; i++) {
        const uint32_t j = slot[i];
        if (j == UINT32_MAX)
            continue;
        double *B = R->b + 6 * (size_t)j;
        B[0] = S->dt * b->f[i].x, B[1] = S->dt * b->f[i].y, B[2] = S->dt * b->f[i].z;
        B[3] = S->dt * b->m[i].x, B[4] = S->dt * b->m[i].y, B[5] = S->dt * b->m[i].z;
    }
    *fail = 0;
    *slot_out = slot;
    return R;
}

ws_status ws_world_friction_step(ws_step *S)
{
    ws_world *w = S->w;
    if (w->def.friction_step != WS_FRICTION_STEP_IMPLICIT || S->nrec == 0)
        return WS_OK;
    uint32_t *slot = NULL;
    int fail = 0;
    ws_rigid *R = bodies_make(S, &slot, &fail);
    if (!R) {
        return fail ? ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for the friction")
                    : WS_OK;
    }
    if (ws_world_friction_pairs(S, R, slot, S->dt) != 0)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "step: out of memory for the friction");
    /* Positive definite for bodies of positive mass (the masses plus the dampers' energies):
     * conjugate gradients converge, in a few iterations where the dampers are weak against
     * the masses and in at most the rows' count where they are not. A NaN among the loads
     * is left as it is for the health check to name. */
    const int maxit = 10 * 6 * (int)R->nb + 100;
    for (int solve = 0;; solve++) {
        int it = 0;
        double res = 0.0;
        if (ws_rigid_pairs_solve(R, WS_FRICTION_TOL, maxit, &it, &res) != 0) {
            if (!isfinite(res) || res == 0.0)
                return WS_OK;
            S->stats->numerical_errors++;
            return ws_fail(w, WS_ERR_NUMERICAL,
                           "step at t = %.6g s: the bodies' friction at the end of the step "
                           "(%zu contacts, %u bodies) did not converge: residual %.3g of the "
                           "loads' after %d iterations (tolerance %.3g); the step was undone. "
                           "Take a smaller dt, or WS_FRICTION_STEP_EXPLICIT",
                           w->time, R->npair, R->nb, res, it, WS_FRICTION_TOL);
        }
        if (solve + 1 == WS_FRICTION_SOLVES || ws_world_friction_turned(S, R, S->dt) == 0)
            break;
    }
    ws_world_friction_loads(S, R, S->dt);
    return WS_OK;
}
