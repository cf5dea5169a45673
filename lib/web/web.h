/* The film: point masses (position, velocity) joined by springs that follow 1D laws. Nodes are
 * double-buffered like bodies. Knows law (and math, base). Contact with bodies lives in contact/,
 * which reads the web. */
#ifndef WS_WEB_H
#define WS_WEB_H

#include <wrapsim/web.h>

#include "base/base.h"
#include "law/law.h"
#include "math/wmath.h"

/* A node-face candidate: node `node` of the web against face `face` of body `body`; wface
 * indexes the face prepared in the global frame, (lo, hi) the contact window of its plane
 * distance: hi = the two layers, lo = -(hi + the body's inner depth). */
typedef struct ws_ncand {
    uint32_t node, body, face, wface; /* for an edge candidate: edge and wedge */
    uint32_t edge;                    /* 1: node against a convex edge of the body */
    double lo, hi;
} ws_ncand;

/* A node contact of the current sub-step, between the normal and the friction passes. */
typedef struct ws_nact {
    uint32_t node, body;
    v3 n, xc, vt, ft;
    double fn, mu, vlim;
} ws_nact;

typedef struct ws_web {
    char *name;
    uint32_t n, ns;          /* nodes, springs */
    int nx, ny, closed;      /* grid: node i + nx j; 0 for a mesh web */
    v3 *x[2], *v[2];         /* state, double-buffered like the bodies' */
    v3 *f;                   /* force accumulator (scratch) */
    v3 *fc[2];               /* contact force on each node, mean over the sub-steps */
    double *m, *inv_m;       /* inv_m = 0: pinned */
    uint32_t *sa, *sb;       /* spring ends */
    double *inv_l0;          /* 1 / rest length */
    uint8_t *kind;           /* ws_spring_kind */
    ws_law1d *law[3];        /* by kind; NULL when no spring of that kind */
    double layer;
    uint32_t material;
    double damping;          /* node drag, kg/s */
    int substeps;
    /* Node-face candidates: changed only by full detection, into the other list. */
    ws_ncand *cand[2];
    size_t ncand[2], capcand[2];
    ws_nact *act;  /* active contacts, scratch sized with the candidates */
    size_t act_cap;
    int list;      /* the committed list */
    int next_list; /* the list this step used, committed with it */
    /* Force and moment on each body in the last step (global, moment about the CoG). */
    v3 *bforce[2], *bmoment[2];
    size_t bcap;
    /* Node candidates stay valid while nothing has moved half the contact margin since they
     * were found: travel bounds that, refresh says they must be found again. */
    double travel, next_travel;
    int refresh;
} ws_web;

/* Allocate a web of n nodes and ns springs (zeroed). */
ws_status ws_web_alloc(ws_mem *mem, ws_web *web, uint32_t n, uint32_t ns);
void ws_web_free(ws_mem *mem, ws_web *web);

/* Spring forces of the laws + node drag + gravity into f, from state (x, v). */
void ws_web_internal_forces(ws_web *web, const v3 *x, const v3 *v, v3 gravity);
/* Symplectic Euler for the nodes over h: v' = v + h f/m, x' = x + h v'. Returns the largest
 * speed. In place is allowed (xs == xd). */
double ws_web_integrate(ws_web *web, const v3 *xs, const v3 *vs, v3 *xd, v3 *vd, double h);
/* Largest stable step for the springs and node drag alone plus a contact of stiffness kc and
 * damping cc on every node (explicit limit with damping, Gershgorin bound on the stiffness). */
double ws_web_stable_dt(const ws_web *web, double kc, double cc);
/* Smallest node mass and largest 2 sum(k) + kc over the free nodes (for error messages). */
void ws_web_stiffest_node(const ws_web *web, double kc, double *min_mass, double *max_k);
/* Strain and tension of spring s in state (x, v). */
double ws_web_spring_strain(const ws_web *web, const v3 *x, uint32_t s);
double ws_web_spring_tension(const ws_web *web, const v3 *x, const v3 *v, uint32_t s);
/* Elastic energy of all springs in state x, J. */
double ws_web_elastic_energy(const ws_web *web, const v3 *x);

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
