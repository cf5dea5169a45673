/* The film: point masses (position, velocity) joined by springs that follow 1D laws. Nodes are
 * double-buffered like bodies. Knows law (and math, base). Contact with bodies lives in contact/,
 * which reads the web. */
#ifndef WS_WEB_H
#define WS_WEB_H

#include <wrapsim/web.h>

#include "base/base.h"
#include "law/law.h"
#include "math/wmath.h"

/* A node candidate: node `node` of the web against a feature of body `body`: a face, or
 * (local has WS_NCAND_EDGE set) a convex edge. feat indexes the feature prepared in the global
 * frame, local (without the flags) the feature in the body's shape. Candidates are sorted by
 * node, so a sub-step can take them block by block with the nodes. */
typedef struct ws_ncand {
    uint32_t node, body, feat, local;
} ws_ncand;
#define WS_NCAND_EDGE 0x80000000u   /* local names an edge */
#define WS_NCAND_INSIDE 0x40000000u /* the node was found well inside the face's outline */
/* On the first of a node's candidates of a body: they are a corner, two faces of a flat convex
 * shape and then the edge between them (the contacts tell the three apart by the planes). */
#define WS_NCAND_CORNER 0x20000000u
#define WS_NCAND_FLAGS (WS_NCAND_EDGE | WS_NCAND_INSIDE | WS_NCAND_CORNER)
/* A shape's faces and edges (at most its triangles and 3/2 of them, under WS_MESH_MAX_ITEMS)
 * are numbered below the flags. */
_Static_assert(3ull * WS_MESH_MAX_ITEMS / 2 < WS_NCAND_CORNER, "feature numbers reach the flags");
#define WS_NCAND_FACES 64           /* the most faces of a body whose candidates get INSIDE */

/* The candidates of a web cut into stretches of nodes, in node order, within one row of a grid
 * web (a sweep block holds whole rows, ws_web_block_count), within the web otherwise. A run:
 * nodes [n0, n1), each with exactly one candidate, all of the same face and found well inside it
 * (WS_NCAND_INSIDE); node n0 + k has candidate c0 + k. Runs are evaluated on vectors
 * (contact/node_force.c). Otherwise: candidates [c0, c1), of nodes in [n0, n1), evaluated one by
 * one. */
typedef struct ws_nseg {
    uint32_t n0, n1, c0, c1;
    int run;
} ws_nseg;

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

/* A body as a full detection of a web's node candidates saw it, relative to the web's
 * reference body (see ws_web): its CoG (rho) and orientation (q) in the reference body's
 * frame (for a near body, as it was when it last moved past its bound, ws_node_moved); its
 * lever: how far from its CoG a point of it can touch a node. Near the web, or far from it:
 * then every node lies beyond its box (grown by the layers) along its own axis `axis` (0, 1,
 * 2), whose interval is (lo, hi), and `gap` is the least distance beyond it that a node had
 * when last found, less how far the body had moved by then (ws_node_moved). rebase: scratch
 * of ws_node_moved. */
typedef struct ws_track {
    uint32_t body;
    int near, axis, rebase;
    v3 rho;
    qt q;
    double lo, hi, gap, lever;
} ws_track;

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
    ws_nodes3 fmem;          /* scratch of n nodes' vectors (node_bounds, writers) */
    ws_nodes3 xsub, vsub;    /* state between sub-steps (scratch): a sub-step never writes
                                the state it reads */
    double *tmp;             /* spring forces of a chunk of springs, 3 WS_WEB_CHUNK, then of
                                WS_WEB_WRAPS wrap springs (scratch, WS_WEB_TMP) */
    ws_spring_form form[3];  /* the laws by spring kind in the running sweep (scratch) */
    int no_drag;             /* the running sweep's nodes have no drag (scratch) */
    v3 *fc[2];               /* contact force on each node, mean over the sub-steps */
    uint32_t *fct[2];        /* the nodes whose fc[k] may be non-zero (some more than once):
                                zeroed at the start of a step that writes fc[k] */
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
    ws_law *law[3];          /* by kind; NULL when no spring of that kind */
    /* Laws with history (relaxation...): each spring's own, nstate doubles a spring, spring s
     * at hist + s nstate; committed after an accepted step (ws_web_commit), read during it. */
    double *hist;
    uint32_t nstate;
    int law_failed; /* a spring's law failed in this step (scratch) */
    double layer;
    uint32_t material;
    double damping;          /* node drag, kg/s */
    int substeps;
    /* Node-face candidates: changed only by full detection, into the other list. */
    ws_ncand *cand[2];
    size_t ncand[2], capcand[2];
    double *act;        /* the contacts of a sweep block gone one by one (scratch, sized */
    uint32_t *act_id;   /* with the candidates; contact/node_force.c) */
    size_t act_cap;
    ws_nseg *seg; /* the stretches of the list seg_list (-1: none built) */
    size_t nseg, seg_cap;
    int seg_list;
    size_t act_nl;     /* loads listed in act since the sub-step began (contact/node_force.c) */
    uint32_t lane_end; /* one past the last node of the lane sweeping this copy (n: one lane) */
    /* Lanes 1.. of a parallel sweep: each a ws_web holding only its own scratch (tmp, act,
     * act_id, rtmp, rface and their sizes, fct[0] as its list of touched nodes), nlanes of
     * them (world_step.c). */
    struct ws_web *lanes;
    uint32_t nlanes;
    int runs_off;  /* no short cuts: no runs and no corners, every candidate one by one
                      through its full tests (tests compare the two) */
    uint32_t run_batch;           /* groups of run nodes taken at once; 0: as many as fit
                                     (tests make it small to run the batches often) */
    uint64_t run_nodes, run_deep; /* nodes evaluated in runs; of them, in runs that went one
                                     by one because a node lay below the face (diagnostics) */
    uint64_t corners;             /* corners told apart by their planes (diagnostics) */
    double *rtmp; /* the runs' batch, its kernel's values, the nodes' depths (scratch, */
                  /* contact/node_force.c) */
    size_t rtmp_cap;
    struct ws_run_face *rface; /* per face that runs lie on, what they need of it and its */
    size_t rface_cap;          /* body, filled in sub-step rface_gen (scratch, node_force.c) */
    uint64_t rface_gen;
    int list;      /* the committed list */
    int next_list; /* the list this step used, committed with it */
    /* Force and moment on each body in the last step (global, moment about the CoG). */
    v3 *bforce[2], *bmoment[2];
    size_t bcap;
    /* Node candidates stay valid while no node has moved half the contact margin relative to
     * any body near the web since they were found (contact/node.h, ws_node_moved). Moves are
     * measured in the frame of a reference body, the heaviest dynamic body near the web (none:
     * the global frame), so a stack that slides or turns with its film costs nothing. At a full
     * detection: the web's box (lo, hi) and every body (track: near the web or how far from
     * it, with its pose then); per node, where it was, in the reference frame, when its
     * candidates were found (xdet). moved: the nodes to find again (scratch, n). refresh says
     * every node must be found again before the next step. */
    ws_nodes3 xdet;
    v3 box_lo, box_hi;
    uint32_t ref; /* the reference body's slot, UINT32_MAX for none */
    ws_track *track; /* every body at the full detection, in slot order */
    size_t ntrack, track_cap;
    uint32_t *moved;
    uint8_t *redo;
    ws_ncand *fresh; /* candidates of the moved nodes (scratch) */
    size_t nfresh, fresh_cap;
    int refresh;
    /* The same places in the global frame as the reference body stood at an epoch (its pose
     * then: epoch_r, epoch_A, epoch_q): xep = epoch_r + epoch_A xdet, which a node's global
     * position is compared with (ws_node_moved); lever2: the largest |xdet|^2 since the full
     * detection. */
    ws_nodes3 xep;
    m3 epoch_A;
    v3 epoch_r;
    qt epoch_q;
    double lever2;
    /* Where each node's candidates start in the list last found or merged (n + 1, see
     * ws_node_index). */
    size_t *cstart;
    /* cbody[k] (by body slot, cbody_cap of them): the candidates may name body k (a body near
     * some node searched since the full detection, ws_node_candidates). */
    uint8_t *cbody;
    size_t cbody_cap;
} ws_web;

/* After the node masses and pins are set: whether they are all alike (same_m, same_inv_m). */
void ws_web_note_masses(ws_web *web);
/* Allocate a web of n nodes and ns springs (zeroed). */
ws_status ws_web_alloc(ws_mem *mem, ws_web *web, uint32_t n, uint32_t ns);
void ws_web_free(ws_mem *mem, ws_web *web);
/* Room for the springs' law histories, initialised as just stretched to the strains the nodes
 * (x[0]) are placed at (after the laws are set). 0, or -1 when out of memory. */
int ws_web_law_state(ws_mem *mem, ws_web *web);
/* After an accepted step ending at t (state x, v), dt long: commit the springs' histories. */
void ws_web_commit(ws_web *web, ws_nodes3 x, ws_nodes3 v, double t, double dt);

/* A sub-step sweeps the nodes in blocks, in order, so that the state it reads and writes stays
 * in cache: block k's forces from the springs, node drag and gravity are complete in f once
 * ws_web_forces_block(k) has run (later blocks' partly), and its nodes [n0, n1) may then get
 * their contact forces and be integrated. A grid web's blocks are whole rows, enough of them
 * for WS_WEB_BLOCK_NODES nodes; a mesh web is one block. Every sweep first takes the laws at
 * (t, since) (ws_web_sweep_laws).
 *
 * Lanes: consecutive blocks swept apart, at once, by copies of the web that share its state
 * and have scratch of their own (world_step.c). The block that starts a lane (edges has
 * WS_WEB_LANE_FIRST) starts its first row itself, and the block that ends one before the last
 * (WS_WEB_LANE_LAST) leaves the next row alone; the springs between the two rows are computed
 * by both, each putting them on its own row, so every node's force gets the same terms in the
 * same order as in one sweep: the results are the same to the bit for any cut into lanes.
 * Lanes need a grid web of two blocks or more whose laws are of film form (no law with history
 * or a user's function, which a lane would call at once with another):
 * ws_web_sweep_parallel. */
uint32_t ws_web_block_count(const ws_web *web);
/* The nodes [n0, n1) of block k. */
void ws_web_block_range(const ws_web *web, uint32_t k, uint32_t *n0, uint32_t *n1);
#define WS_WEB_LANE_FIRST 1
#define WS_WEB_LANE_LAST 2
void ws_web_sweep_laws(ws_web *web, v3 gravity, double t, double since);
int ws_web_sweep_parallel(const ws_web *web);
void ws_web_forces_block(ws_web *web, ws_nodes3 x, ws_nodes3 v, v3 gravity, uint32_t k, int edges,
                         uint32_t *n0, uint32_t *n1);
/* A sweep that writes the velocities vd keeps the nodes' forces in vd until it integrates
 * them, in place of an array of its own: each node's force is complete before its new
 * velocity is written over it, and the state the sweep streams is smaller by an n-node array
 * (f is then vd; ws_web_sweep_end makes it the scratch again). */
void ws_web_sweep_begin(ws_web *web, ws_nodes3 vd);
void ws_web_sweep_end(ws_web *web);
/* Symplectic Euler for nodes [n0, n1) over h: v' = v + h f/m, x' = x + h v', f read from vd
 * (ws_web_sweep_begin). Returns how many of them end faster than vmax (m/s), with a NaN
 * speed or with one whose square overflows (whatever vmax). Source and destination are
 * distinct. */
size_t ws_web_integrate_block(ws_web *web, ws_nodes3 xs, ws_nodes3 vs, ws_nodes3 xd,
                              ws_nodes3 vd, double h, uint32_t n0, uint32_t n1, double vmax);
/* The largest node speed in v (NaN when one is NaN), m/s. */
double ws_web_fastest(const ws_web *web, ws_nodes3 v);
/* Largest stable step for the springs and node drag alone plus a contact of stiffness kc and
 * damping cc on every node (explicit limit with damping, Gershgorin bound on the stiffness). */
double ws_web_stable_dt(const ws_web *web, double kc, double cc);
/* Smallest node mass and largest 2 sum(k) + kc over the free nodes (for error messages). */
void ws_web_stiffest_node(const ws_web *web, double kc, double *min_mass, double *max_k);
/* Strain and tension of spring s in state (x, v), with its committed history. */
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
