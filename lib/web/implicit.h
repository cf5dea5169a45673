/* The implicit film step (web module): linearly implicit backward Euler over a web's nodes, in
 * the manner of Baraff & Witkin (1998), "Large steps in cloth simulation". Over a step h from
 * (x0, v0) with forces f(x, v):
 *
 *     (M - h df/dv - h^2 df/dx) dv = h f(x0, v0) + h^2 df/dx v0,   v1 = v0 + dv,  x1 = x0 + h v1
 *
 * one Newton step of backward Euler. The matrix is never formed: springs keep their direction
 * and three numbers, nodes a diagonal block, and the system is solved by conjugate gradients
 * preconditioned with its 3x3 diagonal blocks (block Jacobi), warm-started from the last
 * solve. Forces from outside the web (the node contacts, contact/node_jacobian.c) come in per
 * node: a force and two symmetric blocks (ws_implicit_add). The matrix takes only the parts of
 * the derivatives that are symmetric and keep it positive definite; what it leaves out is
 * named where it is left (implicit.c, contact/node_jacobian.c) and in docs/theory.md.
 *
 * Vectors of the solve are xyz per node (3 n doubles), the symmetric blocks six doubles
 * (xx, yy, zz, xy, xz, yz). */
#ifndef WS_WEB_IMPLICIT_H
#define WS_WEB_IMPLICIT_H

#include "base/pool.h"
#include "web/web.h"

/* A symmetric 3x3 block: xx, yy, zz, xy, xz, yz. */
enum { WS_SYM_XX, WS_SYM_YY, WS_SYM_ZZ, WS_SYM_XY, WS_SYM_XZ, WS_SYM_YZ, WS_SYM };

/* A spring as the matrix takes it: its unit direction e from end a to end b, its stiffness
 * -df_a/dx_a = ka e e^T + kb I and damping -df_a/dv_a = cs e e^T. */
typedef struct ws_ispring {
    double ex, ey, ez, ka, kb, cs;
    double a, b; /* the solve's: A's block of the spring, a e e^T + b I (a = h^2 ka + h cs,
                    b = h^2 kb), set by ws_implicit_solve */
} ws_ispring;

/* What a bench reads of the solves of a step (ws_implicit's probe; the library keeps none unless
 * a bench sets one, and reads nothing from it). Kinds of rows: 0 a node without an active
 * contact, 1 one whose contacts all stick (eq. 13's slip below v_lim), 2 one with a contact that
 * slips, 3 the bodies (a body one row: the larger of its force and turning rows). A row's
 * measure is the stopping test's, its residual as the velocity change it would give its own
 * mass over the goal (solver_tol g h): the test is met when every row's is at most 1. */
enum { WS_PROBE_KINDS = 4, WS_PROBE_MARKS = 6, WS_PROBE_PASSES = 8 };
typedef struct ws_implicit_probe {
    uint8_t *state;            /* per node, set from the step's links (0 none, 1 an inactive
                                  contact, 2 stick, 3 slip); the bench's, n bytes */
    uint32_t solves;           /* solves of the step (the active set's passes) */
    uint32_t it[WS_PROBE_PASSES]; /* each pass's iterations */
    double start[WS_PROBE_KINDS];   /* the first solve's start: each kind's largest measure */
    uint32_t above0[WS_PROBE_KINDS]; /* and its rows above 1 by kind */
    /* The first solve's rows above 1 by kind after 1, 2, 4, 8, 16 and 32 iterations (zero
     * when it stopped before). */
    uint32_t above[WS_PROBE_MARKS][WS_PROBE_KINDS];
    /* The last solve's binding row: the largest measure before its last iteration (the start
     * when it took none): node index (or n + the body's index), kind and measure. */
    uint32_t bind_row;
    int bind_kind;
    double bind_value;
    /* One node's contacts at the start of the step (watch_on set: node watch): up to 4, each
     * its body, whether it starts active, the normal force at the start, k, c and the unit
     * normal. */
    int watch_on;
    uint32_t watch, watch_count;
    struct {
        uint32_t body;
        int active;
        double fn, k, c, fin;
        double n[3], slip;
        double nu; /* the body's point's velocity along the normal at the start */
    } watch_link[4];
} ws_implicit_probe;

/* A block of the solve's nodes (ws_implicit.blk): its nodes [n0, n1) and, in ws_implicit.rng
 * [r0, r1), the runs of springs that touch them in the springs' order. A pass over a block's
 * runs that adds each spring's term to the ends within the block adds to every node what a
 * pass over all the springs adds, in the same order: blocks run on any workers give the bits
 * of one pass. A run's springs have the same ends in the block (WS_RUN_A, WS_RUN_B or both),
 * so its loop tests none. */
typedef struct ws_iblock {
    uint32_t n0, n1, r0, r1;
} ws_iblock;

enum { WS_RUN_A = 1, WS_RUN_B = 2, WS_RUN_AB = 3 };
typedef struct ws_irun {
    uint32_t first, end, ends;
} ws_irun;

/* Sums of a block pass (ws_implicit.part): each block's into its own slots, added in block
 * order after the pass. */
enum { WS_PART_SUM, WS_PART_MAX, WS_PARTS };

typedef struct ws_implicit {
    uint32_t n, ns;
    /* The blocks the solve's passes run in (a grid web's rows, ws_web_block_rows at a time; a
     * mesh web's nodes one block), the runs of springs they list (2 a run), each block's sums
     * (WS_PARTS a block), and the step's workers (set by the world for each step). */
    uint32_t nblk;
    ws_iblock *blk;
    ws_irun *rng;
    size_t nrng;
    double *part;
    ws_runner run;
    double *f;       /* force on each node at (x0, v0): springs, drag, gravity, contacts */
    double *fs;      /* the same without the contacts (ws_implicit_reset) */
    double *kc, *dc; /* per node, symmetric: -df/dx and -df/dv of its contacts */
    ws_ispring *sp;  /* per spring */
    double *sf;      /* per spring, its force on end a at the step's start, F e (xyz) */
    double *op;      /* per spring, the solve's A block as its products read it, packed: e and
                        a, b of ws_ispring (5 doubles a spring; ws_implicit_apply_op) */
    double *b, *dv, *r, *z, *p, *q; /* the solve's vectors; dv kept for the warm start */
    double *pinv;    /* per node: the inverse of A's diagonal block (symmetric) */
    double *nd;      /* per node: A's own part of the node, M + h (drag + dc) + h^2 kc (the
                        solve's, symmetric) */
    int warm;        /* dv holds the last converged solution */
    uint64_t begun;  /* steps begun (ws_implicit_begin): the springs' blocks change with it */
    /* The preconditioner: multigrid (web/multigrid.h; NULL when the web's Def chooses block
     * Jacobi, ws_mg_chosen), block Jacobi otherwise or when jacobi_only is set (a test's
     * comparison; the bodies in the solve then go without their coarse space,
     * web/coupled.h). */
    struct ws_mg *mg;
    int jacobi_only;
    /* Rigid bodies in the solve beside the nodes (web/coupled.h), set by the caller around a
     * solve; NULL: none (the bodies held). */
    struct ws_rigid *rig;
    /* Counts (ws_web_get_solver_stats). */
    uint64_t solves, iterations;
    int last_iterations;
    double last_residual;
    /* The stopping test: 0, every row's residual against its own weight impulse (the
     * solve's); 1, the residual's norm against the right-hand side's (earlier versions'),
     * kept for a bench's comparison. */
    int stop_relative;
    /* Where the last solve left its residual, by kind of row (0 a node without contacts, 1 a
     * node with contacts, 2 the bodies'): the largest residual over its row's weight impulse
     * m g h (g standard gravity), and the residual's squared norm (N^2 s^2, the bodies'
     * turning rows in N^2 m^2 s^2). Filled at the end of every solve, for a bench. */
    double last_worst[3], last_rr[3];
    ws_implicit_probe *probe; /* a bench's record of the solves (NULL: none) */
    int cold_bodies; /* set: the bodies start from rest, not from the warm film (a bench's
                        comparison) */
} ws_implicit;

/* fn(ctx, b) for every block b of the solve (im->blk), on the step's workers (im->run): the
 * blocks in order on one worker, shared among lanes of consecutive blocks on more. */
typedef ws_item_fn ws_block_fn;
void ws_implicit_blocks_run(const ws_implicit *im, ws_block_fn *fn, void *ctx);

/* The implicit scratch of a web (web->imp), made when missing. 0, or -1 when out of memory. */
int ws_implicit_reserve(ws_mem *mem, ws_web *web);
void ws_implicit_free(ws_mem *mem, ws_web *web);

/* Start a step h from (x, v): the springs' forces and matrix terms from their laws at (t,
 * since) as the explicit sweep takes them, node drag and gravity; the contacts' terms zeroed.
 * 0, or 1 when a spring's law failed (a callback or a non-finite value). */
int ws_implicit_begin(ws_web *web, ws_nodes3 x, ws_nodes3 v, v3 gravity, double t, double since);

/* The contacts' terms taken out again (for another set of them). */
void ws_implicit_reset(ws_implicit *im);

/* Node i's share of a force from outside the web: force f, and the symmetric blocks K = -df/dx
 * and D = -df/dv (positive semi-definite) it adds to the matrix. */
void ws_implicit_add(ws_implicit *im, uint32_t i, v3 f, const double K[WS_SYM],
                     const double D[WS_SYM]);

/* Solve for dv over the step h at (x, v) (the state begin took) to web->solver_tol, at most
 * web->solver_maxit iterations; with imp->rig set, its bodies' velocity changes too (their
 * rows, right-hand side and start in it: web/coupled.h). It stops when every row's residual,
 * as the velocity change it would give its own mass (a node's m_i, a body's m_j; a body's
 * turning rows through its inertia), is at most solver_tol g h (g standard gravity): each
 * row solved to that fraction of its own weight over the step. 0 when it converged, else -1
 * (dv then holds the last iterate). The iterations and the worst row's residual over its
 * weight impulse are kept in the counts. */
int ws_implicit_solve(ws_web *web, ws_nodes3 v, double h);

/* The new velocities alone, vd = v + dv. */
void ws_implicit_velocities(const ws_web *web, ws_nodes3 v, ws_nodes3 vd);

/* The new places xd = x + h vd, with the new velocities vd as ws_implicit_velocities set them
 * (and the static friction changed them). Returns how many nodes end faster than vmax, with a
 * NaN speed or with one whose square overflows. */
size_t ws_implicit_finish(const ws_web *web, ws_nodes3 x, ws_nodes3 xd, ws_nodes3 vd,
                          double h, double vmax);

/* y = A p over step h (the matrix the solve uses), p and y xyz per node, y zero at pinned
 * nodes. */
void ws_implicit_apply(const ws_web *web, double h, const double *p, double *y);

/* y = A p with the parts the running solve set (its springs' and nodes' blocks), p and y xyz
 * per node, y zero at pinned nodes; returns p . y. */
double ws_implicit_apply_op(const ws_web *web, const double *p, double *y);

/* The exact derivatives of spring s's force on its end a at (x, v), the law taken at (t,
 * since): Jx = df_a/dx_b (= -df_a/dx_a) and Jv = df_a/dv_b, row-major. They hold the terms
 * the matrix leaves out (compression's negative transverse stiffness, the rate's dependence
 * on the direction). 0, or 1 when the law failed. */
int ws_implicit_spring_exact(const ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s, double t,
                             double since, double Jx[9], double Jv[9]);

/* S's inverse into out (out may be S) for a symmetric positive definite block, by its
 * cofactors; -1 (out untouched) when S is not positive definite or the result not finite. */
int ws_sym_invert(const double *S, double *out);

/* S += c e e^T for a symmetric block S. */
static inline void ws_sym_add_outer(double *S, double c, v3 e)
{
    S[WS_SYM_XX] += c * e.x * e.x;
    S[WS_SYM_YY] += c * e.y * e.y;
    S[WS_SYM_ZZ] += c * e.z * e.z;
    S[WS_SYM_XY] += c * e.x * e.y;
    S[WS_SYM_XZ] += c * e.x * e.z;
    S[WS_SYM_YZ] += c * e.y * e.z;
}

/* y += S x for a symmetric block S. */
static inline void ws_sym_madd(const double *S, double x, double y, double z, double *o)
{
    o[0] += S[WS_SYM_XX] * x + S[WS_SYM_XY] * y + S[WS_SYM_XZ] * z;
    o[1] += S[WS_SYM_XY] * x + S[WS_SYM_YY] * y + S[WS_SYM_YZ] * z;
    o[2] += S[WS_SYM_XZ] * x + S[WS_SYM_YZ] * y + S[WS_SYM_ZZ] * z;
}

#endif
