/* A geometric multigrid preconditioner for the implicit film's solve on grid webs (web module,
 * used by web/implicit.c; docs/theory.md, "The implicit film", says why). The film's grid
 * (node i + nx j, closed around when it is a band) is coarsened by two in each direction, level
 * after level (a band's film level around only), to at most 16 nodes; each coarser matrix is the Galerkin product P^T A P of the
 * finer one with bilinear interpolation P, so it stays symmetric positive definite and needs no
 * law of its own. One application is a V-cycle: damped block Jacobi on the film's own
 * matrix-free operator (its springs' and nodes' blocks in single precision), symmetric block
 * Gauss-Seidel (forward before, backward after the coarse correction) on the coarse levels
 * (their blocks in single precision too), a dense Cholesky factor on the coarsest. The cycle is
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

/* z = B r, one V-cycle; r and z xyz per node, zero at pinned nodes. Returns r . z. */
double ws_mg_apply(ws_mg *mg, const ws_web *web, const double *r, double *z);

/* The number of levels (the film's own one included), for the counts. */
int ws_mg_levels(const ws_mg *mg);

#endif
