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
 * its two faces; inv_e2 = 1 / |e|^2. */
typedef struct ws_wedge {
    v3 p, e, n1, n2;
    double inv_e2;
} ws_wedge;

typedef struct ws_node_geom {
    ws_wface *face;
    ws_wtri *tri;
    ws_wedge *edge;
    uint32_t *face_base, *tri_base, *edge_base;
    size_t face_cap, tri_cap, edge_cap, face_base_cap, tri_base_cap, edge_base_cap;
} ws_node_geom;

/* Fill g for the bodies at state cur. 0, or -1 when out of memory (only when bodies were
 * added since the last call). */
int ws_node_geometry(ws_mem *mem, const ws_body_store *b, int cur, ws_node_geom *g);
void ws_node_geometry_free(ws_mem *mem, ws_node_geom *g);

/* Node-face candidates of a web within the layers + margin (full detection). 0, or -1 when out
 * of memory. */
int ws_node_candidates(ws_mem *mem, const ws_body_store *b, int cur, const ws_node_geom *g,
                       ws_web *web, const v3 *x, double margin, ws_ncand **out, size_t *n,
                       size_t *cap, uint64_t *checks);

/* Evaluate the candidates at node state (x, v) for a sub-step h: forces into web->f, `share`
 * of them (1 / substeps) into the bodies' accumulators, the node contact forces fc and the
 * per-body totals. pp is indexed by body material. */
void ws_node_contacts(ws_body_store *b, int cur, const ws_node_geom *g, ws_web *web, const v3 *x,
                      const v3 *v, const ws_ncand *cand, size_t n, const ws_node_params *pp,
                      double h, double share, v3 *fc, v3 *bforce, v3 *bmoment, uint64_t *checks);

#endif
