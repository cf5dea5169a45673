/* A geometric multigrid preconditioner for the implicit film's solve on grid webs (web module,
 * used by web/implicit.c; docs/theory.md, "The implicit film", says why). The film's grid
 * (node i + nx j, closed around when it is a band) is coarsened by two in each direction, level
 * after level (a band's film level around only), to at most 16 nodes; each coarser matrix is the Galerkin product P^T A P of the
 * finer one with bilinear interpolation P, so it stays symmetric positive definite and needs no
 * law of its own. One application is a V-cycle: damped block Jacobi on the film's own
 * matrix-free operator (its springs' and nodes' blocks in single precision), symmetric block
 * Gauss-Seidel (forward before, backward after the coarse correction) on the coarse levels
 * (their blocks in single precision too; the rows along x where a point sweep would leave
 * the error constant along the row and alternating up are solved whole, a band's closed
 * around, the others node by node), a dense Cholesky factor on the coarsest. The cycle is
 * the same linear, symmetric positive definite map on every call of a solve, so conjugate
 * gradients stay valid with it (docs/theory.md 8a: why the rounding keeps it so).
 *
 * Node vectors are xyz per node (3 n doubles), as in web/implicit.h. */
#ifndef WS_WEB_MULTIGRID_H
#define WS_WEB_MULTIGRID_H

#include "web/web.h"

typedef struct ws_mg ws_mg;

/* A grid web has at least this many nodes (one coarse level of at most MG_COARSEST, 16), and
 * its coarsest level at most WS_MG_COARSEST_MAX (a dense factor). */
#define WS_MG_MIN_NODES 17
#define WS_MG_COARSEST_MAX 128

/* Whether the multigrid can serve the web: a grid (sheet or band) whose springs all join grid
 * neighbours, of at least WS_MG_MIN_NODES nodes, coarsening to at most WS_MG_COARSEST_MAX. */
int ws_mg_grid(const ws_web *web);

/* Whether the web's preconditioner (web->precond, ws_web_preconditioner) is the multigrid:
 * asked for, or AUTO on a grid web of at least WS_WEB_MULTIGRID_AUTO_NODES nodes. */
int ws_mg_chosen(const ws_web *web);

/* The hierarchy of a web (sizes only; the matrices come with ws_mg_setup). *out is NULL, with
 * 0 returned, when the web's preconditioner is block Jacobi (ws_mg_chosen): block Jacobi then
 * serves alone. -1 when out of memory. */
int ws_mg_reserve(ws_mem *mem, const ws_web *web, ws_mg **out);
void ws_mg_free(ws_mem *mem, ws_mg *mg);

/* The coarse matrices for the operator the solve has just set (web->imp: the springs' blocks a,
 * b, the nodes' blocks nd and the block-Jacobi inverses pinv of web/implicit.c) over step h.
 * The springs' share of them is made again only when the springs' blocks changed: begun counts
 * the steps ws_implicit_begin began (im->begun), so a new count or another h makes it anew;
 * the nodes' blocks (the contacts) are taken at every call. 0, or -1 when a coarse matrix is
 * not positive definite (then the solve keeps block Jacobi). */
int ws_mg_setup(ws_mg *mg, const ws_web *web, uint64_t begun, double h);

/* z = B r, one V-cycle; r and z xyz per node, zero at pinned nodes. Returns r . z. With
 * bodies nested (ws_mg_bodies), the film's block of ws_mg_apply_bodies: their residual zero,
 * their answer dropped. */
double ws_mg_apply(ws_mg *mg, const ws_web *web, const double *r, double *z);

/* The bodies of the running solve nested in the hierarchy (docs/theory.md 8b): their six
 * unknowns ride along every coarse level, coupled to its nodes by the contacts' -C J restricted
 * with the levels' interpolation and kept only for the (coarse node, body) pairs that have one,
 * smoothed before the nodes in the forward Gauss-Seidel sweep (after them in the backward one)
 * and solved with the coarsest level; the film's level smooths its nodes alone and hands the
 * bodies' residual down with the nodes'. ws_mg_body_bytes: the scratch this needs for nb
 * bodies and at most nl contacts (0 without a multigrid or bodies, or with more than
 * WS_MG_NEST_BODIES_MAX bodies); ws_mg_bodies: R's bodies (its links, at most R->cap, and
 * factored blocks, set for the solve before ws_mg_setup, which restricts the coupling) with
 * that scratch, or none (R or buf NULL); it returns whether they are nested (1), 0 when none
 * are, there are too many or R's contacts are not sorted by node (the film level walks them
 * in node order). Then the solve keeps the bodies' blocks and coarse space beside the
 * multigrid. */
/* The most bodies nested: the pairs are gathered through a (coarse node, body) table of the
 * first coarse level's nodes times the bodies, and the coarsest factor grows with the cube of
 * its unknowns plus 6 nb; 32 boxes on a band of 92544 nodes take 6 MB of table and a factor of
 * at most 576 unknowns (WS_MG_COARSEST_MAX nodes and the bodies). */
#define WS_MG_NEST_BODIES_MAX 32
struct ws_rigid;
size_t ws_mg_body_bytes(const ws_mg *mg, uint32_t nb, size_t nl);
int ws_mg_bodies(ws_mg *mg, const struct ws_rigid *R, void *buf);

/* z = B r and zb = B rb over the film and the nested bodies: one V-cycle of the coupled matrix,
 * symmetric positive definite (docs/theory.md 8b). rb, zb 6 a body. Returns r . z + rb . zb. */
double ws_mg_apply_bodies(ws_mg *mg, const ws_web *web, const double *r, double *z,
                          const double *rb, double *zb);

/* The number of levels (the film's own one included), for the counts. */
int ws_mg_levels(const ws_mg *mg);

/* Coarse level k's rows (along x) and, into *whole, how many of them its sweeps solve whole
 * (chosen at each set-up); 0 when k is not a coarse level swept (1 .. levels - 2). */
int ws_mg_rows(const ws_mg *mg, int k, int *whole);

/* For tests: row iy of coarse level k solved whole (whole != 0) or node by node, until the
 * next set-up chooses again; its factor made anew. 0, or -1 when k or iy is out of range or a
 * pivot is not positive definite. */
int ws_mg_set_row(ws_mg *mg, int k, int iy, int whole);

#endif
