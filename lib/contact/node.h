/* Node-face contact of webs (contact module). */
#ifndef WS_CONTACT_NODE_H
#define WS_CONTACT_NODE_H

#include "body/body.h"
#include "web/web.h"

/* Contact parameters of the web's material against each body material. */
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
#define WS_NCAND_FACES 64 /* the most faces of a body whose candidates get INSIDE */

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

/* A growable list of candidates: c[0, n), room for cap. */
typedef struct ws_ncand_list {
    ws_ncand *c;
    size_t n, cap;
} ws_ncand_list;

/* Where a node's candidates come from in a merge (ws_nmerge): the first of its fresh ones,
 * and where its candidates start in the merged list. */
typedef struct ws_nplace {
    size_t fresh, at;
} ws_nplace;

/* A merge of the candidates of nodes found again into the list `out`: the committed list's
 * (old, indexed by ostart, of nn nodes) for the nodes whose candidates did not change, the
 * fresh ones (fresh) of the `count` nodes that changed (nodes, increasing), with their places
 * (place; place[count].fresh: the end of theirs); out's index into nstart. Planned on one
 * thread (ws_node_merge_plan), carried out in pieces of nodes that may run at once
 * (ws_node_merge_range). */
typedef struct ws_nmerge {
    const size_t *ostart;
    size_t *nstart;
    ws_nplace *place;
    uint32_t nn;
    const ws_ncand_list *old;
    ws_ncand_list *out;
    ws_ncand *fresh;
    const uint32_t *nodes;
    size_t count;
} ws_nmerge;

/* A body as a full detection of a web's node candidates saw it, relative to the web's
 * reference body (see ws_node_contact): its CoG (rho) and orientation (q) in the reference body's
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

/* The move test of a step between its parts (ws_node_moved_begin, ws_node_flag_lane,
 * ws_node_moved_end): the reference body's pose (A, r, conjugate orientation pc) and velocity
 * (vr, global turn rate wr) now, the per-node bound lim with the share c of a node's
 * velocity that counts (0: one sub-step, measured from the epoch, which renew starts anew),
 * the reach of a far body, and whether a near body is re-based. */
typedef struct ws_move_test {
    m3 A;
    v3 r, vr, wr;
    qt pc;
    double c, lim, reach;
    int renew, rebase;
} ws_move_test;

/* A web's contact with the bodies (web->contact): its node candidates, the record of where the
 * nodes were found and how the bodies stood (tracks, epochs), the stretches and runs the
 * candidates are cut into, and the scratch their evaluation uses. Made with the web
 * (ws_node_contact_new), freed with it. */
typedef struct ws_node_contact {
    /* Node-face candidates: changed only by full detection, into the other list. */
    ws_ncand_list cand[2];
    double *act;      /* the contacts of a sweep block gone one by one (scratch, sized */
    uint32_t *act_id; /* with the candidates; contact/node_force.c) */
    size_t act_cap;
    ws_nseg *seg; /* the stretches of the list seg_list (-1: none built) */
    size_t nseg, seg_cap;
    int seg_list;
    size_t act_nl;      /* loads (or their folds) listed in act since the sub-step began */
    size_t *row_mark;   /* when set (a grid web's lane), where each row's loads start in the */
    size_t nrow_mark;   /* list, noted by ws_node_contacts (room for a sweep block's rows) */
    uint32_t lane_end;  /* one past the last node of the lane sweeping this copy (n: one lane) */
    int runs_off;       /* no short cuts: no runs and no corners, every candidate one by one
                           through its full tests (tests compare the two) */
    uint32_t run_batch; /* groups of run nodes taken at once; 0: as many as fit
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
    /* Node candidates stay valid while no node has moved half the contact margin relative to
     * any body near the web since they were found (ws_node_moved). Moves are
     * measured in the frame of a reference body, the heaviest dynamic body near the web (none:
     * the global frame), so a stack that slides or turns with its film costs nothing. At a full
     * detection: the web's box (lo, hi) and every body (track: near the web or how far from
     * it, with its pose then); per node, where it was, in the reference frame, when its
     * candidates were found (xdet). moved: the nodes to find again (scratch, n). refresh says
     * every node must be found again before the next step. */
    ws_nodes3 xdet;
    v3 box_lo, box_hi;
    uint32_t ref;    /* the reference body's slot, UINT32_MAX for none */
    ws_track *track; /* every body at the full detection, in slot order */
    size_t ntrack, track_cap;
    uint32_t *moved;
    uint8_t *redo;
    ws_ncand_list fresh; /* candidates of the moved nodes (scratch) */
    int refresh;
    /* The same places in the global frame as the reference body stood at an epoch (its pose
     * then: epoch_r, epoch_A, epoch_q): xep = epoch_r + epoch_A xdet, which a node's global
     * position is compared with (ws_node_moved); lever2: the largest |xdet|^2 since the full
     * detection. */
    ws_nodes3 xep;
    ws_move_test move; /* this step's (scratch) */
    int search_all;    /* this step finds every node again (ws_node_contact_begin) */
    /* A merge planned in this step and not carried out whole (merging): the first sub-step's
     * lanes carry it out, each for its own nodes, before they read the list. */
    ws_nmerge merge;
    int merging;
    m3 epoch_A;
    v3 epoch_r;
    qt epoch_q;
    double lever2;
    /* Where each node's candidates start in each list (n + 1, see ws_node_index): a merge
     * writes the new list's index from the committed one's, so that its pieces read no place
     * another piece writes (ws_node_merge_range). */
    size_t *cstart[2];
    /* cbody[k] (by body slot, cbody_cap of them): the candidates may name body k (a body near
     * some node searched since the full detection, find_candidates in node.c). */
    uint8_t *cbody;
    size_t cbody_cap;
} ws_node_contact;

/* A web's contact object for n nodes (zeroed, lists empty); NULL when out of memory. */
ws_node_contact *ws_node_contact_new(ws_mem *mem, uint32_t n);
/* Free it and all it holds (NULL: nothing); n as made. */
void ws_node_contact_free(ws_mem *mem, ws_node_contact *nc, uint32_t n);

typedef struct ws_node_params {
    double k, c, mu, vlim;
} ws_node_params;

/* Faces and triangles of every body in the global frame at t, so a node's check is a few dot
 * products: prepared once per step. Indexed by body slot through face_base and tri_base. */
typedef struct ws_wface {
    v3 n;
    double off;
    uint32_t first_tri, tri_count;
} ws_wface;

typedef struct ws_wtri {
    v3 p, w, v;
    double g00, g01, g11;
} ws_wtri;

/* A convex edge in the global frame: from p along e (|e| = length), with the outward normals of
 * its two faces; inv_e2 = 1 / |e|^2, c = n1 . n2. */
typedef struct ws_wedge {
    v3 p, e, n1, n2;
    double inv_e2, c;
} ws_wedge;

struct ws_find_body;

typedef struct ws_node_geom {
    ws_wface *face;
    ws_wtri *tri;
    ws_wedge *edge;
    uint32_t *face_base, *tri_base, *edge_base;
    /* Scratch of the candidates' search (node.c): the bodies near a group of nodes, with the nodes'
     * values against each, taken from the step's arena (set by the step before the search). */
    ws_arena *arena;
    struct ws_find_body *find;
    double *find_val;
    uint64_t *find_mask;
    uint32_t *find_node;
    /* ready[k]: body k's features are prepared for this step (ws_node_prepare_some). */
    uint8_t *ready;
} ws_node_geom;

struct ws_node_step;
/* A search of node candidates as ws_node_find does it from first = 0, for the nodes listed
 * (0 .. count - 1 when nodes is NULL), into L (empty): the world's, in pieces on its threads.
 * Listed nodes are found again now: it also moves them to the reference frame (ws_node_to_ref),
 * in its pieces.
 * 0, or 1 when the nodes are listed and their candidates found are those the committed list
 * holds for them (ws_node_same, which it may leave undone: then 0), or -1 when out of memory. */
typedef int ws_node_search_fn(const struct ws_node_step *S, ws_web *web, const uint32_t *nodes,
                              size_t count, ws_ncand_list *L);

/* A lane's part of the move test (ws_node_flag_lane): its nodes [n0, n1) and what it found
 * there: the flagged ones, in order, at web->contact->moved + n0 (count of them), and for each
 * track the least distance of those beyond the far body's box (ws_node_moved_end; INFINITY for
 * a near body or none flagged; room for every track). */
typedef struct ws_node_lane {
    uint32_t n0, n1;
    double margin; /* the contact margin, m: the reach of a re-based body */
    size_t count;
    double *least;
} ws_node_lane;

/* What a step's search of node candidates reads and counts: the world's allocator, the bodies
 * at state cur with their features (g, whose scratch the search uses), the contact margin,
 * where feature checks are counted, and who searches (search; NULL: ws_node_find, here), with
 * its context; the lanes that ran the move test (NULL: it ran whole). */
typedef struct ws_node_step {
    ws_mem *mem;
    const ws_body_store *b;
    int cur;
    ws_node_geom *g;
    double margin;
    uint64_t *checks;
    ws_node_search_fn *search;
    void *search_ctx;
    const ws_node_lane *lanes;
    uint32_t nlanes;
} ws_node_step;

/* The search's scratch in g, from its arena (g->arena), at its most for a group of nodes: for
 * ws_node_find. 0, or -1 when out of memory. */
int ws_node_find_scratch(const ws_body_store *b, ws_node_geom *g);
/* The candidates of `count` nodes of web at state S->cur, nodes[0, count) (increasing) or, when
 * nodes is NULL, first .. first + count - 1, appended to L in node order, body by body in slot
 * order: the same for a node however the nodes are cut into pieces. Each body near one of them
 * is marked in web->contact->cbody (room for every body slot). Checks count in *S->checks.
 * With S->mem NULL (a piece on a worker) L does not grow: -1 when its room runs out, as when
 * out of memory. 0 otherwise. */
int ws_node_find(const ws_node_step *S, ws_web *web, const uint32_t *nodes, uint32_t first,
                 size_t count, ws_ncand_list *L);

/* The first of the two calls of a step before a web's sub-steps: whether every node is to be
 * found again at state cur (when `all`, the record of the last search is invalid, or a body
 * may have come near: 0 returned), or the per-node move test is to run (1 returned: over every
 * node, in any pieces, ws_node_flag_lane, then ws_node_contact_update). */
int ws_node_contact_begin(const ws_body_store *b, int cur, ws_web *web, double dt, double margin,
                          int all);
/* The second: the candidates brought up to date at state cur (all found again, or those of
 * the nodes that moved merged in; S->lanes: the move test's), the bodies' features prepared (g)
 * and the list cut into stretches, with the room its evaluation needs.
 * The list to evaluate is nc->next_list, nc->cand[next_list]; *searched says whether nodes
 * were searched. Feature checks are counted in *checks. 0, or -1 when out of memory (nothing
 * committed changed; the next step searches every node). */
int ws_node_contact_update(const ws_node_step *S, ws_web *web, int *searched);
/* After an accepted step: its list becomes the committed one. */
void ws_node_contact_commit(ws_node_contact *nc);

/* Room in g, from its arena (g->arena, the step's), and the numbers of the bodies' features
 * (face_base, tri_base, edge_base), with no body prepared yet: a step prepares only the bodies
 * some web's candidates may name (ws_node_prepare_some). The tables last until the arena's next
 * reset. 0, or -1 when out of memory. */
int ws_node_geometry(const ws_body_store *b, ws_node_geom *g);

/* The features, in the global frame at state cur, of the bodies whose candidates web may hold
 * (web->cbody) and that are not prepared yet in this step: of the body slots first, first +
 * stride, ... (pieces with the same stride and distinct firsts may run at once: each body's
 * tables are its own), or of all (ws_node_prepare). */
void ws_node_prepare_some(const ws_body_store *b, int cur, ws_node_geom *g, const ws_web *web,
                          uint32_t first, uint32_t stride);
static inline void ws_node_prepare(const ws_body_store *b, int cur, ws_node_geom *g,
                                   const ws_web *web)
{
    ws_node_prepare_some(b, cur, g, web, 0, 1);
}

/* Which nodes must find their candidates again before this step, state cur, (x, v), dt: a
 * node whose move relative to the web's reference body, with what its sub-steps may add, could
 * reach 3/16 of the margin (1/4 with one sub-step, tested in the global frame from an epoch of
 * the reference body's pose: a node may then be flagged from 7/8 of that on); and when a near
 * body moved or turned by margin / 8 at its lever relative to the reference, the nodes it may
 * meet (in its box grown by the layers and the margin, or holding a candidate of it), its
 * record starting again from now. They go to web->moved (count returned) with web->redo set,
 * and their xdet is moved to where they are now. -1: every node must be found again (a body
 * was made since the full detection, or a far body may have come near the web). Until a node
 * is found again its move relative to a near body stays under half the margin, the distance a
 * candidate list is built to cover, and a body it holds no candidate of cannot touch it: see
 * node.c. */

/* ws_node_moved in parts, so that the per-node test runs in pieces (a lane's nodes): the
 * bodies' part, -1 when every node must be found again, else 0 with the test set up in
 * nc->move; the lane's nodes flagged in nc->redo (the lanes may run at once on distinct
 * nodes), with those a re-based near body may meet, listed and measured against the far bodies
 * (L: the lanes cover the nodes in order, whole rows of a grid web); the rest, given the lanes, as
 * ws_node_moved returns, but with the listed nodes not yet moved to the reference frame: the search
 * of their candidates does that (ws_node_to_ref, in its pieces when it has any). */
int ws_node_moved_begin(const ws_body_store *b, int cur, ws_web *web, double dt, double margin);
void ws_node_flag_lane(const ws_body_store *b, int cur, ws_web *web, ws_nodes3 x, ws_nodes3 v,
                       ws_node_lane *L);
long ws_node_moved_end(const ws_body_store *b, int cur, ws_web *web, ws_nodes3 x, double margin,
                       const ws_node_lane *lanes, uint32_t nlanes);
/* The listed nodes (count of them; all when only is NULL) to the reference frame M (of this
 * step's move test: ws_node_to_ref): their record (xdet, xep) from where they are, x;
 * web->contact->lever2 grows to hold them. Distinct nodes may be moved at once through views of
 * one contact, each its own lever2 (the largest of them is the whole's). */
void ws_node_ref_nodes(ws_web *web, ws_nodes3 x, const ws_move_test *M, const uint32_t *only,
                       size_t count);
static inline void ws_node_to_ref(ws_web *web, ws_nodes3 x, const uint32_t *nodes, size_t count)
{
    ws_node_ref_nodes(web, x, &web->contact->move, nodes, count);
}
/* The whole of it in one lane; least: room for a double a track (web->contact->ntrack). */
static inline long ws_node_moved(const ws_body_store *b, int cur, ws_web *web, ws_nodes3 x,
                                 ws_nodes3 v, double dt, double margin, double *least)
{
    if (ws_node_moved_begin(b, cur, web, dt, margin) < 0)
        return -1;
    ws_node_lane L = {0, web->n, margin, 0, least};
    ws_node_flag_lane(b, cur, web, x, v, &L);
    const long count = ws_node_moved_end(b, cur, web, x, margin, &L, 1);
    if (count > 0)
        ws_node_to_ref(web, x, web->contact->moved, (size_t)count);
    return count;
}

/* Where each of n nodes' candidates start in the list c (nc of them, sorted by node): start[i]
 * is the first of node i or of a later node, start[n] = nc. */
void ws_node_index(const ws_ncand *c, size_t nc, uint32_t n, size_t *start);

/* Nodes found again: `count` of them in increasing order, and their candidates as found
 * (fresh, sorted by node). */
typedef struct ws_node_found {
    const uint32_t *nodes;
    size_t count;
    const ws_ncand_list *fresh;
} ws_node_found;

/* Whether the candidates found F are those the committed list `old` (indexed by start,
 * ws_node_index) holds for F's nodes: then it stays as it is. */
int ws_node_same(const ws_node_found *F, const size_t *start, const ws_ncand *old);

/* The plan of the merge M of the nodes found again F into the committed list old: M's ostart
 * (old's index), nn, nstart (room for out's index) and place (room for F->count + 1) are set
 * by the caller, the rest here. out is grown and sized for it, the nodes whose fresh
 * candidates are not those they had go into `changed` (room for F->count; it may be F->nodes
 * itself) in order, and their fresh candidates to the front of F's list: how many, or -1 when
 * out of memory (old and its index unchanged). Nothing is written in out: ws_node_merge_range
 * does. */
long ws_node_merge_plan(ws_mem *mem, const ws_node_found *F, const ws_ncand_list *old, ws_nmerge *M,
                        ws_ncand_list *out, uint32_t *changed);
/* The merge M carried out for the nodes [n0, n1): their candidates in out, their places in
 * nstart (and nstart[nn] when n1 = nn). Pieces on distinct nodes may run at once; each reads
 * only what the plan and the committed list hold. */
void ws_node_merge_range(const ws_nmerge *M, uint32_t n0, uint32_t n1);

/* Room for evaluating ncand candidates (web->act). 0, or -1 when out of memory. */
int ws_node_scratch(ws_mem *mem, ws_node_contact *nc, size_t ncand);
void ws_node_scratch_free(ws_mem *mem, ws_node_contact *nc);

/* Cut the candidates (sorted by node) of list `list` of a web into its stretches (web->seg,
 * see ws_nseg), which ws_node_contacts evaluates. 0, or -1 when out of memory. */
int ws_node_segments(ws_mem *mem, ws_web *web, const ws_ncand *cand, size_t n, int list);

/* The same for list `list` merged (M, planned) from list `from`, where only M's nodes have
 * other candidates: when the stretches are those of `from`, only the blocks (rows) that hold
 * one of them are cut again, after their merge is carried out here (the rest is left to
 * ws_node_merge_range); else the whole merge is carried out here and the list cut whole. 0, or
 * -1 when out of memory. */
int ws_node_segments_merged(ws_mem *mem, ws_web *web, const ws_nmerge *M, int list, int from);

/* A sub-step starts (on the web or a lane of it): the runs' faces are taken afresh, the list of
 * loads is empty. */
void ws_node_substep(ws_node_contact *nc);
/* The loads on the bodies listed since ws_node_substep, in the list's order, added to the
 * per-body totals bforce and bmoment (global, moment about the CoG), which the step adds to the
 * bodies; the list is then empty. */
void ws_node_loads(ws_node_contact *nc, v3 *bforce, v3 *bmoment);
/* The loads listed at [from, to) (in node order) folded, each run of loads on one body summed
 * from its first, the sums written from place `at` (<= from) on: the place after them. A sweep
 * folds each row's loads (world_step.c), rows, unlike lanes, do not depend on the worker count,
 * so the totals (ws_node_loads) are the same to the bit for any number of lanes. */
size_t ws_node_loads_fold(ws_node_contact *nc, size_t from, size_t to, size_t at);
/* The first stretch whose nodes start at n0 or later (where a lane starting at n0 begins). */
size_t ws_node_first_segment(const ws_node_contact *nc, uint32_t n0);
/* Room in `lane`, a lane's own scratch (world_step.c), for evaluating ncand candidates of a
 * web of n nodes whose contact is nc, with its stretches cut. 0, or -1 when out of memory. */
int ws_node_lane_scratch(ws_mem *mem, ws_node_contact *lane, const ws_node_contact *nc, uint32_t n,
                         size_t ncand);

/* What every sweep block of a web's sub-step evaluates its node contacts with: the bodies at
 * state cur (b, with their features in the global frame g), the contact parameters by body
 * material (pp), the list of candidates the stretches were cut from (cand), the node state
 * (x, v), the sub-step h, the share 1 / substeps of each contact force the node's record gets
 * and that record (fc). */
typedef struct ws_node_pass {
    ws_body_store *b;
    int cur;
    const ws_node_geom *g;
    const ws_node_params *pp;
    const ws_ncand *cand;
    ws_nodes3 x, v;
    double h, share;
    v3 *fc;
    /* The implicit film's (ws_node_links): the dynamic bodies move in the film's solve, so the
     * step's active set takes a node's motion relative to its body's contact point; 0: the
     * bodies held (the solve takes them at rest over the step). */
    int bodies_move;
} ws_node_pass;

/* Evaluate the stretches from *next on whose nodes lie below n1 (the end of a sweep block),
 * moving *next past them, with what P gives (ws_node_pass): forces into web->f, the node
 * contact forces (`share` = 1 / substeps of them) into fc, and the opposite loads on the bodies
 * (the same share) listed for ws_node_loads (bforce and bmoment are not written here). cand is the
 * list the stretches were cut from; pp is indexed by body material. The result does not depend on
 * how the candidates are cut. */
void ws_node_contacts(const ws_node_pass *P, ws_web *web, uint32_t n1, size_t *next,
                      uint64_t *checks);

/* Where a node touches a body: the unit normal n from the body to the node, the distance d
 * it is pushed over (the overlap is hi - d) and the window's top hi (the two layers); for the
 * exact derivatives, g, d's gradient in the node's place, and a face's normal's, dn/dx =
 * ta tb^T: n and zero, but for a node past a convex body's edge, whose push turns from one
 * face's normal to the other's (node_force.c, NODE_BLEND_WIDTH). (The rim's turning is
 * ws_node_links's.) */
typedef struct ws_node_touch_at {
    v3 n, g, ta, tb;
    double d, hi;
} ws_node_touch_at;

/* Whether candidate c holds the node at x, by the full tests of the one-by-one path (no short
 * cuts: eq. 14 for a face, below it the push past a convex body's edge or the shallowest face
 * of another body, the rim for an edge), with
 * the bodies of P (b, state cur, features g) and the window's top raised by `reach` (0: the
 * contact window itself): then where, in *at. For the implicit film, which evaluates each
 * node's contacts once a step, and those it may reach within it (contact/node_jacobian.c). */
int ws_node_touch(const ws_node_pass *P, const ws_web *web, const ws_ncand *c, v3 x, double reach,
                  ws_node_touch_at *at);

#endif
