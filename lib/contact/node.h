/* Node-face contact of webs (contact module). */
#ifndef WS_CONTACT_NODE_H
#define WS_CONTACT_NODE_H

#include "body/body.h"
#include "web/web.h"

/* Contact parameters of the web's material against each body material. */
typedef struct ws_node_params {
    double k, c, mu, vlim;
} ws_node_params;

/* Node-face candidates of a web within the layers + margin (full detection). 0, or -1 when out
 * of memory. */
int ws_node_candidates(ws_mem *mem, const ws_body_store *b, int cur, ws_web *web, const v3 *x,
                       double margin, ws_ncand **out, size_t *n, size_t *cap, uint64_t *checks);

/* Evaluate the candidates at node state (x, v) for a sub-step h: forces into web->f, `share`
 * of them (1 / substeps) into the bodies' accumulators, the node contact forces fc and the
 * per-body totals. pp is indexed by body material. */
void ws_node_contacts(ws_body_store *b, int cur, ws_web *web, const v3 *x, const v3 *v,
                      const ws_ncand *cand, size_t n, const ws_node_params *pp, double h,
                      double share, v3 *fc, v3 *bforce, v3 *bmoment, uint64_t *checks);

#endif
