/* The film: point masses (position, velocity) joined by springs that follow 1D laws. Nodes are
 * double-buffered like bodies. Knows law (and math, base). Contact with bodies lives in contact/,
 * which reads the web. */
#ifndef WS_WEB_H
#define WS_WEB_H

#include <wrapsim/web.h>

#include "base/base.h"
#include "law/law.h"
#include "math/wmath.h"

/* Input bounds: sub-steps per world step, and pre-stretch of the generators (a rest length no
 * shorter than 1/11 of the placed spacing: real films stretch by at most a few hundred per
 * cent; far beyond, the springs' stiffness EA / l0 grows without bound and the stable step
 * shrinks to nothing). */
#define WS_WEB_MAX_SUBSTEPS 100000
#define WS_WEB_MAX_PRESTRETCH 10.0

/* Node vectors as structure of arrays: the x, y and z components apart (one allocation of 3 n
 * doubles), so loops over nodes and over grid springs run on whole vectors. */
typedef struct ws_nodes3 {
    double *x, *y, *z;
} ws_nodes3;

static inline v3 nodes_get(ws_nodes3 a, uint32_t i)
{
    return v3_make(a.x[i], a.y[i], a.z[i]);
}

static inline void nodes_set(ws_nodes3 a, uint32_t i, v3 p)
{
    a.x[i] = p.x;
    a.y[i] = p.y;
    a.z[i] = p.z;
}

static inline void nodes_add(ws_nodes3 a, uint32_t i, v3 p)
{
    a.x[i] += p.x;
    a.y[i] += p.y;
    a.z[i] += p.z;
}

#define WS_WEB_CHUNK 256 /* springs evaluated at once */
#define WS_WEB_PAD 4     /* doubles of padding after node vectors and rest lengths (web.c) */
#define WS_WEB_WRAPS 4   /* wrap springs of a closed band evaluated at once */
#define WS_WEB_BLOCK_NODES 384 /* nodes of a sweep block of a grid web, at least (whole rows) */
#define WS_WEB_TMP (3 * WS_WEB_CHUNK + 4 * WS_WEB_WRAPS) /* doubles of ws_web.tmp */

/* A spring law in the form every stateless 1D law of the film's kind takes (lib/law/law.h):
 * F = kc eps + dk g(eps) + c eps_dot, g the C1 ramp of half-width w (qw = 1 / (4 w)). Linear
 * laws have dk = 0. Any other law (a table, relaxation, a user's) is `gen`, evaluated spring
 * by spring with the spring's own history, at time t, `since` after it was committed. */
typedef struct ws_spring_form {
    double kc, dk, w, qw, c;
    const ws_law *gen;
    double t, since;
} ws_spring_form;

typedef struct ws_web {
    char *name;
    uint32_t n, ns;          /* nodes, springs */
    int nx, ny, closed;      /* grid: node i + nx j; 0 for a mesh web */
    ws_nodes3 x[2], v[2];    /* state, double-buffered like the bodies' */
    ws_nodes3 f;             /* force accumulator (scratch): in a sweep, the velocities it
                                writes (ws_web_sweep_begin), else fmem */
    ws_nodes3 fmem;          /* scratch of n nodes' vectors (ws_web_node_limits, writers) */
    ws_nodes3 xsub, vsub;    /* state between sub-steps (scratch): a sub-step never writes
                                the state it reads */
    double *tmp;             /* spring forces of a chunk of springs, 3 WS_WEB_CHUNK, then of
                                WS_WEB_WRAPS wrap springs (scratch, WS_WEB_TMP) */
    /* The running sweep's laws by spring kind, its gravity, and whether its nodes have no
     * drag (scratch, ws_web_sweep_laws). */
    ws_spring_form form[3];
    v3 g;
    int no_drag;
    v3 *fc[2];               /* contact force on each node, mean over the sub-steps */
    uint32_t *fct[2];        /* the nodes whose fc[k] may be non-zero (some more than once):
                                zeroed at the start of a step that writes fc[k]; an implicit
                                web's (a swept web zeroes fc[k] block by block in its first
                                sub-step, world_step.c, and lists none) */
    size_t nfct[2], fct_cap[2];
    int fck;                 /* the fc the contacts of the running step add to (scratch) */
    double *m, *inv_m;       /* inv_m = 0: pinned */
    /* When every node has the same mass (same_m) or the same inverse mass (same_inv_m: the
     * same mass and none pinned), it is m1 or inv_m1, and the sweep reads it in place of the
     * array (ws_web_note_masses). */
    int same_m, same_inv_m;
    double m1, inv_m1;
    uint32_t *sa, *sb;       /* spring ends */
    double *inv_l0;          /* 1 / rest length */
    uint8_t *kind;           /* ws_spring_kind */
    /* Each spring's force as a multiple of its law's (the film layers a spring stands for), or
     * NULL when every spring takes its law as it is. Mesh webs only: their springs' loops
     * (mesh.c) read it, the grid's never do. */
    double *kscale;
    /* The springs by node (ws_web_spring_index: a mesh web's always, another's when its
     * implicit solve needs them): node i's are inc[inc0[i] .. inc0[i + 1]), each 2 s + 1 when
     * i is spring s's end b, else 2 s, in spring order; and a mesh web's sweep's scratch: each
     * spring's force on its end a, sf[s], when it pulls (son[s] 1). */
    uint32_t *inc0, *inc;
    v3 *sf;
    uint8_t *son;
    ws_law *law[3];          /* by kind; NULL when no spring of that kind */
    /* Laws with history (relaxation...): each spring's own, nstate doubles a spring, spring s
     * at hist + s nstate; committed after an accepted step (ws_web_commit), read during it. */
    double *hist;
    uint32_t nstate;
    int law_failed; /* a spring's law failed in this step (scratch) */
    /* Rupture (ws_web_rupture_check): a spring whose strain passes `rupture` (> 0; 0: none) at
     * the end of a step breaks and from then on carries no force. broken[s] is 1 for a broken
     * spring (state: saved and hashed; NULL until a limit is first set, ns + WS_WEB_PAD bytes);
     * nbroken counts them, and while it is 0 the sweep runs as if there were no rupture at
     * all. The rest is the report: springs broken by the last step, and the first break (the
     * most strained spring of the first step that broke any): its time, spring, strain and the
     * midpoint of its ends. */
    double rupture;
    uint8_t *broken;
    uint32_t nbroken, nbroken_step;
    uint32_t first_spring; /* UINT32_MAX: none broken yet */
    double first_time, first_strain;
    v3 first_at;
    double layer;
    uint32_t material;
    double damping;          /* node drag, kg/s */
    int substeps;
    /* The film's contact with the bodies: its candidates, their tracks and epochs, the runs
     * and their scratch (contact/node.h), made and freed by the world; the web knows it only
     * as a handle. */
    struct ws_node_contact *contact;
    /* Force and moment on each body in the last step (global, moment about the CoG). */
    v3 *bforce[2], *bmoment[2];
    size_t bcap;
    /* The integrator (ws_web_integrator) and, for the implicit one, the solve's tolerance and
     * iterations at most, and its scratch (web/implicit.h, made at its first step). */
    int integrator;
    double solver_tol;
    int solver_maxit;
    int precond; /* ws_web_preconditioner (web/multigrid.c's ws_mg_reserve takes it) */
    int hold_bodies; /* ws_web_def.hold_bodies: the bodies held during the solve */
    struct ws_implicit *imp;
} ws_web;

/* After the node masses and pins are set: whether they are all alike (same_m, same_inv_m). */
void ws_web_note_masses(ws_web *web);
/* Allocate a web of n nodes and ns springs (zeroed). */
/* Node vectors: x, y and z apart in one allocation, WS_WEB_PAD zeros after z (spring_run may
 * read past a grid's last node; the state walk takes the 3 n at once). 1, or 0 when out of
 * memory (a->x NULL). Freed with the same n. */
int ws_nodes_alloc(ws_mem *mem, ws_nodes3 *a, uint32_t n);
void ws_nodes_free(ws_mem *mem, ws_nodes3 *a, uint32_t n);
ws_status ws_web_alloc(ws_mem *mem, ws_web *web, uint32_t n, uint32_t ns);
void ws_web_free(ws_mem *mem, ws_web *web);
/* Room for the springs' law histories, initialised as just stretched to the strains the nodes
 * (x[0]) are placed at (after the laws are set). 0, or -1 when out of memory. */
int ws_web_law_state(ws_mem *mem, ws_web *web);
/* After an accepted step ending at t (state x, v), dt long: break the springs strained past
 * the rupture limit (when one is set), commit the springs' histories. */
void ws_web_commit(ws_web *web, ws_nodes3 x, ws_nodes3 v, double t, double dt);

/* The springs by node (inc0, inc), made once the springs are set (when not made yet), and
 * with ws_web_mesh_index a mesh web's sweep's room for their forces (sf, son) too (mesh.c). 0,
 * or -1 when out of memory. */
int ws_web_spring_index(ws_mem *mem, ws_web *web);
int ws_web_mesh_index(ws_mem *mem, ws_web *web);

/* A sub-step sweeps the nodes in blocks, in order, so that the state it reads and writes stays
 * in cache: the forces from the springs, node drag and gravity of a block's rows [j0, j1) are
 * complete in f once ws_web_forces_rows(j0, j1) has run (later rows' partly), and its nodes
 * [n0, n1) may then get their contact forces and be integrated. A grid web's blocks are whole
 * rows, ws_web_block_rows of them (enough for WS_WEB_BLOCK_NODES nodes; a lane may end with
 * fewer). A mesh web's rows are runs of WS_WEB_MESH_ROW nodes (the last takes the rest), and its
 * springs' forces are computed first, all of them (ws_web_mesh_springs, in pieces on any
 * workers), then each node's gathered in spring order: the sums of the springs' scatter, to the
 * bit. Every sweep first takes the laws at (t, since) and the gravity (ws_web_sweep_laws).
 *
 * Lanes: consecutive blocks swept apart, at once, by copies of the web that share its state
 * and have scratch of their own (world_step.c). The block that starts a lane (edges has
 * WS_WEB_LANE_FIRST) starts its first row itself, and the block that ends one before the last
 * (WS_WEB_LANE_LAST) leaves the next row alone; the springs between the two rows are computed
 * by both, each putting them on its own row, so every node's force gets the same terms in the
 * same order as in one sweep: the results are the same to the bit for any cut into lanes.
 * A mesh web's lanes need no edges: its springs are all in before any lane starts.
 * Lanes need a web of two blocks or more whose laws are of film form (no law with history
 * or a user's function, which a lane would call at once with another):
 * ws_web_sweep_parallel. */
#define WS_WEB_MESH_ROW 64
uint32_t ws_web_block_count(const ws_web *web);
uint32_t ws_web_block_rows(const ws_web *web); /* rows of a block */
uint32_t ws_web_rows(const ws_web *web);       /* ny, or a mesh web's rows */
uint32_t ws_web_row_len(const ws_web *web);    /* nx, or WS_WEB_MESH_ROW */
/* The first node of row j (n for j = ws_web_rows). */
static inline uint32_t ws_web_row_node(const ws_web *web, uint32_t j)
{
    return web->nx > 0            ? (uint32_t)web->nx * j
           : j < ws_web_rows(web) ? WS_WEB_MESH_ROW * j
                                  : web->n;
}
#define WS_WEB_LANE_FIRST 1
#define WS_WEB_LANE_LAST 2
/* A sweep's state: the state it reads (x, v) and the one it writes (xd, vd; distinct from x,
 * v), its sub-step h (s), and the speed above which a node counts as too fast, vmax (m/s). */
typedef struct ws_web_pass {
    ws_nodes3 x, v, xd, vd;
    double h, vmax;
} ws_web_pass;
void ws_web_sweep_laws(ws_web *web, v3 gravity, double t, double since);
int ws_web_sweep_parallel(const ws_web *web);
/* Whether every law of the web is of film form, so that its sweep calls no user's function
 * and may run on any worker (in lanes, or in one beside other work). */
int ws_web_laws_on_workers(const ws_web *web);
void ws_web_forces_rows(ws_web *web, const ws_web_pass *p, uint32_t j0, uint32_t j1, int edges,
                        uint32_t *n0, uint32_t *n1);
/* A mesh web's springs [s0, s1) at the sweep's state (x, v): their forces into sf, son. */
void ws_web_mesh_springs(ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s0, uint32_t s1);
/* A mesh web's nodes [n0, n1) (mesh.c): the start of their forces in f, their springs' (all
 * of them in sf, son) and their gravity and drag (velocities v). */
void ws_web_mesh_gather(ws_web *web, ws_nodes3 v, uint32_t n0, uint32_t n1);
/* A sweep keeps the nodes' forces in the velocities it writes (p->vd) until it integrates
 * them, in place of an array of its own: each node's force is complete before its new
 * velocity is written over it, and the state the sweep streams is smaller by an n-node array
 * (f is then vd; ws_web_sweep_end makes it the scratch again). */
void ws_web_sweep_begin(ws_web *web, const ws_web_pass *p);
void ws_web_sweep_end(ws_web *web);
/* Symplectic Euler for nodes [n0, n1) over p->h: v' = v + h f/m, x' = x + h v', f read from
 * p->vd (ws_web_sweep_begin). Returns how many of them end faster than p->vmax, with a NaN
 * speed or with one whose square overflows (whatever vmax). */
size_t ws_web_integrate_block(ws_web *web, const ws_web_pass *p, uint32_t n0, uint32_t n1);
/* The largest node speed in v (NaN when one is NaN), m/s. */
double ws_web_fastest(const ws_web *web, ws_nodes3 v);
/* What the free nodes bear with a contact of stiffness kc and damping cc on every node, from
 * each node's stiffness k = kc + 2 sum of its springs' largest stiffness / l0 (the Gershgorin
 * bound of its row) and damping c = cc + 2 sum of theirs / l0 + the node drag: the largest
 * stable step for them all (explicit limit with damping), s; the smallest node mass that makes
 * every one stable at step h (the inverse of that bound, node by node: the largest of
 * h^2 k / 4 + h c / 2), kg, 0 without free nodes; their smallest mass (for error messages). */
typedef struct ws_web_limits {
    double dt, mass, min_mass;
} ws_web_limits;
ws_web_limits ws_web_node_limits(const ws_web *web, double kc, double cc, double h);
/* Room for the broken flags (all clear) before a rupture limit is first set. 0, or -1 when
 * out of memory. */
int ws_web_rupture_alloc(ws_mem *mem, ws_web *web);
/* After an accepted step ending at t in state x: break every intact spring whose strain is
 * above web->rupture (> 0), and note them for the report. */
void ws_web_rupture_check(ws_web *web, ws_nodes3 x, double t);
/* Count the broken flags into nbroken (after they were restored). */
void ws_web_rupture_recount(ws_web *web);
/* Strain and tension of spring s in state (x, v), with its committed history; a broken
 * spring's tension is 0. */
double ws_web_spring_strain(const ws_web *web, ws_nodes3 x, uint32_t s);
double ws_web_spring_tension(const ws_web *web, ws_nodes3 x, ws_nodes3 v, uint32_t s);
/* Elastic energy of all springs in state x, J. */
double ws_web_elastic_energy(const ws_web *web, ws_nodes3 x);

#endif

/* ---- generators (build.c): fill positions, springs, rest lengths, kinds of an allocated web */

/* Sheet nx x ny: node i + nx j at o + i hx ax + j hy ay. Springs: around (x), up (y), shear. */
uint32_t ws_web_sheet_springs(int nx, int ny, int shear, int closed);
void ws_web_build_grid(ws_web *web, int nx, int ny, int shear, int closed, double pre_x,
                       double pre_y);
/* Place a sheet's nodes. */
void ws_web_place_sheet(ws_web *web, v3 o, v3 ax, v3 ay, double hx, double hy);
/* Place a band: around the convex hull of `pts` (xy pairs, count n) pushed out by `offset`,
 * n_around nodes at equal arc length, rows from z0 to z1. Returns 0, or -1 when the points have
 * no area (fewer than 3 non-collinear). `scratch` holds 2 n + 2 doubles... (2 n uint32). */
int ws_web_place_band(ws_web *web, const double *pts, size_t n, uint32_t *scratch, double offset,
                      double z0, double z1);
/* Masses from an areal density over each node's share of the rest area of its grid cells. */
void ws_web_grid_masses(ws_web *web, double areal_density);
