/* Node-face contact of webs (contact module). */
#ifndef WS_CONTACT_NODE_H
#define WS_CONTACT_NODE_H

#include "body/body.h"
#include "web/web.h"

/* Contact parameters of the web's material against each body material. */
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
    size_t face_cap, tri_cap, edge_cap, face_base_cap, tri_base_cap, edge_base_cap;
    /* Scratch of ws_node_candidates (node.c): the bodies near a group of nodes, with the nodes'
     * values against each. */
    struct ws_find_body *find;
    double *find_val;
    uint64_t *find_mask;
    uint32_t *find_node;
    size_t find_cap, find_val_cap, find_mask_cap, find_node_cap;
    /* ready[k]: body k's features are prepared for this step (ws_node_prepare). */
    uint8_t *ready;
    size_t ready_cap;
} ws_node_geom;

/* Room in g and the numbers of the bodies' features (face_base, tri_base, edge_base), with no
 * body prepared yet: a step prepares only the bodies some web's candidates may name
 * (ws_node_prepare). 0, or -1 when out of memory (only when bodies were added since the last
 * call). */
int ws_node_geometry(ws_mem *mem, const ws_body_store *b, int cur, ws_node_geom *g);

/* The features, in the global frame at state cur, of the bodies whose candidates web may hold
 * (web->cbody) and that are not prepared yet in this step. */
void ws_node_prepare(const ws_body_store *b, int cur, ws_node_geom *g, const ws_web *web);
void ws_node_geometry_free(ws_mem *mem, ws_node_geom *g);

/* Node candidates of a web: every node-face and node-edge pair within the layers + margin, for
 * the nodes listed (all when `nodes` is NULL), sorted by node; g's scratch is used. 0, or -1
 * when out of memory. */
int ws_node_candidates(ws_mem *mem, const ws_body_store *b, int cur, ws_node_geom *g, ws_web *web,
                       ws_nodes3 x, double margin, const uint32_t *nodes, size_t count,
                       ws_ncand **out, size_t *n, size_t *cap, uint64_t *checks);

/* A full detection's record (see ws_web): the web's box from x and the bodies whose boxes come
 * within reach of it, with their pose at state cur; xdet = x. 0, or -1 when out of memory. */
int ws_node_track(ws_mem *mem, const ws_body_store *b, int cur, ws_web *web, ws_nodes3 x,
                  double margin);

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
long ws_node_moved(const ws_body_store *b, int cur, ws_web *web, ws_nodes3 x, ws_nodes3 v,
                   double dt, double margin);

/* Where each of n nodes' candidates start in the list c (nc of them, sorted by node): start[i]
 * is the first of node i or of a later node, start[n] = nc. */
void ws_node_index(const ws_ncand *c, size_t nc, uint32_t n, size_t *start);

/* Whether the found candidates `fresh` of `nodes` (count of them, in increasing order) are
 * those the committed list `old` (indexed by start, ws_node_index) holds for them: then it
 * stays as it is. */
int ws_node_same(const uint32_t *nodes, size_t count, const size_t *start, const ws_ncand *old,
                 const ws_ncand *fresh, size_t nfresh);

/* Candidates of the committed list `old` (indexed by start, of web->n nodes) for the nodes not
 * in `nodes` (count of them, in increasing order) and the found ones `fresh` (of those nodes,
 * in that order), merged by node into out, start becoming its index; the nodes whose fresh
 * candidates are not those they had into `changed` (room for count; it may be `nodes`
 * itself), in order, *nchanged of them. 0, or -1 when out of memory (start unchanged). */
int ws_node_merge(ws_mem *mem, const uint32_t *nodes, size_t count, uint32_t nn, size_t *start,
                  const ws_ncand *old, size_t nold, const ws_ncand *fresh, size_t nfresh,
                  ws_ncand **out, size_t *n, size_t *cap, uint32_t *changed, size_t *nchanged);

/* Room for evaluating ncand candidates (web->act). 0, or -1 when out of memory. */
int ws_node_scratch(ws_mem *mem, ws_web *web, size_t ncand);
void ws_node_scratch_free(ws_mem *mem, ws_web *web);

/* Cut the candidates (sorted by node) of list `list` of a web into its stretches (web->seg,
 * see ws_nseg), which ws_node_contacts evaluates. 0, or -1 when out of memory. */
int ws_node_segments(ws_mem *mem, ws_web *web, const ws_ncand *cand, size_t n, int list);

/* The same for list `list` merged (ws_node_merge) from list `from`, where only the nodes
 * `nodes` (count of them, in increasing order) have other candidates: when the stretches are
 * those of `from`, only the blocks (rows) that hold one of the nodes are cut again. 0, or -1 when
 * out of memory. */
int ws_node_segments_merged(ws_mem *mem, ws_web *web, const ws_ncand *cand, size_t n, int list,
                            int from, const uint32_t *nodes, size_t count);

/* A sub-step starts (on the web or a lane of it): the runs' faces are taken afresh, the list of
 * loads is empty. */
void ws_node_substep(ws_web *web);
/* The loads on the bodies listed since ws_node_substep, in node order, added to the per-body
 * totals bforce and bmoment (global, moment about the CoG), which the step adds to the
 * bodies. Lanes' lists are added in the order of their nodes, so the totals are those of one
 * sweep to the bit. */
void ws_node_loads(ws_web *web, v3 *bforce, v3 *bmoment);
/* The first stretch whose nodes start at n0 or later (where a lane starting at n0 begins). */
size_t ws_node_first_segment(const ws_web *web, uint32_t n0);
/* Room in `lane`, a lane's own scratch (world_step.c), for evaluating ncand candidates of web
 * `web` with its stretches cut. 0, or -1 when out of memory. */
int ws_node_lane_scratch(ws_mem *mem, ws_web *lane, const ws_web *web, size_t ncand);

/* Evaluate the stretches from *next on whose nodes lie below n1 (the end of a sweep block),
 * moving *next past them, at node state (x, v), for a sub-step h: forces into web->f, the node
 * contact forces (`share` = 1 / substeps of them) into fc, and the opposite loads on the bodies
 * (the same share) listed for ws_node_loads (bforce and bmoment are not written here). cand is the
 * list the stretches were cut from; pp is indexed by body material. The result does not depend on
 * how the candidates are cut. */
void ws_node_contacts(ws_body_store *b, int cur, const ws_node_geom *g, ws_web *web, ws_nodes3 x,
                      ws_nodes3 v, const ws_ncand *cand, uint32_t n1, size_t *next,
                      const ws_node_params *pp, double h, double share, v3 *fc, uint64_t *checks);

#endif
