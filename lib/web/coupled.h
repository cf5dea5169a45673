/* Rigid bodies in an implicit web's solve (web module): the six velocity unknowns of each body
 * the film touches beside its nodes' (docs/theory.md, section 8b). A contact between node i and
 * body j at lever r from the body's centre of mass couples them through the contact point's
 * velocity J U = V + W x r (J = [I, -[r]x], U = (V, W) the body's velocity and spin, global):
 * with C = h^2 K + h D the contact's block of the film's matrix A (K = -df/dx, D = -df/dv over
 * the relative motion), the coupled matrix is
 *
 *     [ A          -C J           ]
 *     [ -J^T C     M_j + J^T C J  ]     summed over the contacts,
 *
 * M_j = diag(m I, I_w) the body's mass and global inertia: symmetric positive definite
 * whenever A is (its energy is the film's plus (dv - J dU)^T C (dv - J dU) + dU^T M dU). The
 * solve's vectors keep their film part as before (3 doubles a node) and put the bodies' in the
 * arrays here (6 a body: velocity change, then spin change). Body contacts whose friction is
 * in the solve (ws_rigid_pair) add (J_b dU_b - J_a dU_a)^T C (J_b dU_b - J_a dU_a) between two
 * bodies' rows. The bodies' block A_bb (the lower right, pairs and all) is a principal block of
 * this matrix, so positive definite with it: the preconditioner solves it whole, by its Cholesky
 * factor, and stays symmetric positive definite. The module knows no body: the world fills a
 * body's mass, inertia and right-hand side and the contacts' levers and blocks. */
#ifndef WS_WEB_COUPLED_H
#define WS_WEB_COUPLED_H

#include "web/implicit.h"

/* A node-body contact of the solve: node, body (its index among the solve's bodies, not a
 * body slot), lever from the body's centre of mass to the contact point (global, m), and its
 * block C = h^2 K + h D (symmetric). */
typedef struct ws_rigid_link {
    uint32_t node, body;
    v3 lever;
    double C[WS_SYM];
} ws_rigid_link;

/* A contact of two bodies (a body contact of the world) whose friction is in the solve: its
 * eq. 13 as the damper it is over the slip, c (I - n n^T) with c = mu N p(s) / |t| at the
 * start (2 mu N / v_lim at rest), between the contact points of its two bodies (a, b: indices
 * among the solve's bodies, UINT32_MAX for a world element, whose motion is given), levers
 * ra, rb from their centres of mass (global, m); C = h c (I - n n^T). */
typedef struct ws_rigid_pair {
    uint32_t a, b;
    uint32_t tag; /* the caller's: which of its contacts this is */
    v3 ra, rb;
    double C[WS_SYM];
} ws_rigid_pair;

typedef struct ws_rigid {
    uint32_t nb;    /* bodies in the solve */
    size_t nl, cap; /* contacts in the solve, room for them */
    ws_rigid_link *link;
    /* The body-body contacts whose friction is in the solve (docs/theory.md section 8b): they
     * add (J_b dU_b - J_a dU_a)^T C (J_b dU_b - J_a dU_a) to the energy of the matrix. */
    ws_rigid_pair *pair;
    size_t npair;
    double *mass;                  /* per body: its mass, kg */
    double *inertia;               /* per body: its global inertia, symmetric (WS_SYM doubles) */
    /* The bodies' block of the coupled matrix, A_bb = diag(M_j) + sum J^T C J over the film's
     * contacts + the pairs' terms (both ends' diagonal blocks and, between two bodies of the
     * solve, the off-diagonal ones), (6 nb)^2 doubles row-major, and its Cholesky factor fac
     * (lower triangle) over the envelope env (12 nb: row i's first entry that is not zero,
     * then column i's last),
     * set by ws_rigid_factor: the bodies solved together, a pair's strong coupling with them
     * (docs/theory.md section 8b). */
    double *abb, *fac;
    uint32_t *env;
    /* Set: the pairs' off-diagonal blocks left out of abb (each body alone, as the
     * preconditioner once had it): a test's comparison; the operator keeps them. */
    int apart;
    double *b, *x, *r, *z, *p, *q; /* the solve's vectors, 6 a body (x: dU, kept between
                                      the solves of one step) */
    /* The coarse space of the preconditioner: a column per body and direction, the body
     * moving (or turning) by one unit and every node it touches with the contact point, Phi.
     * coarse: the Cholesky factor of Phi^T A Phi ((6 nb)^2 doubles); cb, cq: 6 nb doubles.
     * Scratch of its set-up: crow, a film node's row among Phi's nodes (a uint32_t a film
     * node); cphi, a row's entry and a flag (2 (cap + 1)); cy, 18 doubles a row (cap + 1);
     * cyr, 36 nb doubles; cwork, ws_rigid_coarse_words(cap, nb) words: the coarse factor's
     * envelope (12 nb, as env's), then the rows' contacts and
     * entries of Phi, each body's, and the lists of one body's columns. NULL coarse: none. */
    double *coarse, *cb, *cq, *cy, *cyr;
    uint32_t *crow, *cphi, *cwork;
    /* The coarse space's contacts (room for cap), set by ws_rigid_coarse: the first link of
     * each node-body pair at an unpinned node, as node, body and lever (3 doubles). */
    size_t nphi;
    uint32_t *phi_node, *phi_body;
    double *phi_lever;
    /* Scratch for the film's multigrid to nest the bodies in (ws_mg_body_bytes; NULL: none,
     * then the preconditioner is the block one with the coarse space). */
    void *mgbuf;
    /* The links of each of the solve's blocks of nodes (web/implicit.h's ws_iblock), from
     * bstart[b] to bstart[b + 1], and each block's share of the bodies' rows in the operator
     * (6 nb a block): set by the solve when the world gives room for them and the links are
     * in node order (blocked; otherwise the links in one pass). */
    size_t *bstart;
    double *bpart;
    int blocked;
} ws_rigid;

/* The velocity change over the step of pair q's contact point on body b relative to a's,
 * J_b dU_b - J_a dU_a, for the bodies' velocity changes dU (6 a body). */
v3 ws_rigid_pair_slip(const ws_rigid *R, size_t q, const double *dU);

/* The bodies' block A_bb of the coupled matrix (the masses, the film's contacts' J^T C J, the
 * pairs' blocks between their bodies) into R->abb and factored into R->fac for the
 * preconditioner. 0, or -1 when it is not positive definite (a NaN, a body of no mass). */
int ws_rigid_factor(ws_rigid *R);

/* z = A_bb^-1 r, the bodies solved together (6 doubles a body; z may be r). */
void ws_rigid_block_solve(const ws_rigid *R, const double *r, double *z);

/* Each of the nblk blocks' first link into start (nblk + 1: the last R->nl), the links being
 * in node order (web/implicit.h's ws_iblock). */
void ws_rigid_block_starts(const ws_rigid *R, const ws_iblock *blk, uint32_t nblk, size_t *start);

/* The bodies' part of y = A p: yr = M pr + the coupling's terms into yr (the film's contacts'
 * and the body-body pairs'), and the coupling's
 * -C J pr added into the film part y (y untouched at pinned nodes). Returns the dot product
 * these add: p . (what it added to y) + pr . yr. */
double ws_rigid_apply(const ws_rigid *R, const ws_web *web, const double *p, const double *pr,
                      double *y, double *yr);

/* The words of R->cwork for room for cap contacts and nb bodies. */
size_t ws_rigid_coarse_words(size_t cap, uint32_t nb);

/* Phi^T A Phi for the operator the running solve set (its film part by ws_implicit_apply_op),
 * factored into R->coarse. 0, or -1 when it is not positive definite. */
int ws_rigid_coarse(ws_rigid *R, const ws_web *web);

/* Phi^T A Phi (symmetrised: the mean of it and its transpose) into R->coarse, not factored: the
 * same to the bit (a zero's sign aside) as Phi^T (A (Phi e_c)) column by column with
 * ws_implicit_apply_op and ws_rigid_apply (a test compares them), each body's six columns over
 * its own nodes, the springs at them (web->inc0, inc) and the rows and contacts these reach,
 * not over the film; the body-body pairs' terms (none in that test) added after the film's,
 * the same to round-off. */
void ws_rigid_coarse_matrix(ws_rigid *R, const ws_web *web);

/* The bodies' part of the preconditioner and the coarse correction: zr = A_bb^-1 rr (the
 * bodies solved together), then, with R->coarse, c = (Phi^T A Phi)^-1 Phi^T (rf, rr) added as
 * Phi c into (zf, zr), zf the film's part already preconditioned. Returns what this adds to
 * r . z. */
double ws_rigid_precondition(const ws_rigid *R, const double *rf, double *zf, const double *rr,
                             double *zr);

/* The CG's update of the bodies' part: x += alpha p, r -= alpha q; returns r . r. */
double ws_rigid_step(ws_rigid *R, double alpha);

/* The CG's new direction of the bodies' part: p = z + beta p. */
void ws_rigid_direction(ws_rigid *R, double beta);

/* a . b over the bodies' part. */
double ws_rigid_dot(const ws_rigid *R, const double *a, const double *b);

/* The bodies and their pairs alone (no film: R->nl = 0), A = diag(M_j) + the pairs' terms,
 * solved for R->x from R->b by conjugate gradients preconditioned by each body's own block
 * (its mass and its pairs' J^T C J at its end, inverted into R->fac, 36 doubles a body; the
 * pairs' coupling between bodies in the operator alone), from x = 0, until sqrt(r . z) is at
 * most tol times its start, at most maxit iterations; R->r, z, p, q are its scratch. The
 * count of iterations into *iterations and the last ratio into *residual. 0, or -1 when a
 * block is not positive definite or it did not converge. Its cost is a pass over the pairs an
 * iteration, where the whole block's factor costs the cube of the bodies' rows (a pallet's
 * cartons: 4x a step). */
int ws_rigid_pairs_solve(ws_rigid *R, double tol, int maxit, int *iterations, double *residual);

#endif
