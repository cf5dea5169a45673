/* Deformable elements between two bodies (or a body and the fixed world frame): the strain from
 * the states of the two ends, the law's force, and the loads that force puts back on both ends.
 * Pure functions of their arguments: the world owns the pool, resolves ids and reads the body
 * store, then calls these with plain states. Knows law, body (types only) and math. The formulas
 * and their derivations are in docs/elements.md. */
#ifndef WS_ELEMENT_H
#define WS_ELEMENT_H

#include <wrapsim/element.h>

#include "base/base.h"
#include "law/law.h"
#include "math/wmath.h"

/* Body slot of an end fixed to the world frame. */
#define WS_ELEMENT_WORLD UINT32_MAX

typedef struct ws_element {
    ws_element_type type;
    ws_element_formulation form;
    int dim;            /* of the law: 1, 3 or 6 */
    uint32_t body[2];   /* body slots, WS_ELEMENT_WORLD for the world frame */
    uint32_t law;       /* law slot */
    v3 point[2];        /* attachment points in the body frames (global for the world) */
    qt frame[2];        /* element frames in the body frames, unit */
    double l0;          /* rod rest length, m */
    uint32_t nstate;    /* doubles of law history */
    double *state;      /* the committed law history (NULL when nstate is 0) */
    double t_commit;    /* time of the committed history, s */
    double u[6], ud[6]; /* strain and rate of the step in progress: what the commit accepts */
    char *name;
    void *user;
} ws_element;

/* The state of one end, global: CoG, Euler parameters, CoG velocity, angular velocity. */
typedef struct ws_element_end {
    v3 x;
    qt p;
    v3 v;
    v3 w;
} ws_element_end;

/* What the strain is at one state, and what the loads need to map the law's force back. */
typedef struct ws_element_kin {
    double u[6], ud[6]; /* strain and rate as fed to the law (dim of them) */
    v3 pt[2];           /* attachment points, global */
    v3 arm[2];          /* pt - x: from each CoG to its point, global */
    v3 l;               /* pt[1] - pt[0] */
    v3 dir;             /* rod: l / |l| (zero when the points coincide) */
    qt q;               /* law frame, global (identity for a rod) */
    m3 E;               /* its rotation matrix: columns are the law axes */
    v3 theta;           /* relative rotation vector in the law frame, rad */
    /* Invariant forms: tan(|theta|/4) times the global unit axis of theta. The virtual rotation
     * of the mid frame is (d phi_1 + d phi_2)/2 + tau x (d phi_1 - d phi_2)/2. */
    v3 tau;
} ws_element_kin;

/* Loads on both ends: forces (global), moments about each CoG and about each attachment point
 * (global). f[1] = -f[0] exactly. */
typedef struct ws_element_loads {
    v3 f[2];
    v3 m[2];
    v3 mp[2];
} ws_element_loads;

/* The law dimension an element type needs. */
int ws_element_type_dim(ws_element_type type);

/* The strain and its rate at the state of the two ends. */
void ws_element_kinematics(const ws_element *e, const ws_element_end end[2], ws_element_kin *k);

/* Loads on both ends from the law's force F (dim values in the law frame) at kinematics k. */
void ws_element_loads_of(const ws_element *e, const ws_element_kin *k, const double *F,
                         ws_element_loads *out);

/* Kinematics, the law at time t from the committed history, and the loads: 0, or the law's
 * WS_LAW_EVAL_* failure (k filled, F and out unspecified). */
int ws_element_eval(const ws_element *e, const ws_law *L, const ws_element_end end[2], double t,
                    ws_element_kin *k, double *F, ws_element_loads *out);

/* Elastic energy stored in the law at strain k->u and time t, J (NaN when the law cannot say). */
double ws_element_energy(const ws_element *e, const ws_law *L, const ws_element_kin *k, double t);

#endif
