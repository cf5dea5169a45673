/* The contact laws, written once for every path that evaluates a contact: body against body
 * (force.c), a film node against a body one by one and in runs (node_force.c), and the implicit
 * film's contacts with their derivatives (node_jacobian.c). Each is straight-line code for one
 * contact, a lane (wide.h): a loop over the lanes of a group runs on vectors, a scalar caller
 * fills one lane. What a path adds around them is its own: the explicit film's limit on
 * friction (what stops the node within its sub-step), the stick anchor of body contacts, the
 * implicit film's derivatives. */
#ifndef WS_CONTACT_PENALTY_H
#define WS_CONTACT_PENALTY_H

#include "contact/wide.h"

/* The normal law of a contact whose points move at vr relative to each other (the second
 * body's, or the node's, against the first's), along the unit normal n (from the first to the
 * second), overlapping by gap, for the pair's stiffness k and damping c: the normal velocity vn,
 * the tangential velocity t = vr - vn n, the penalty force fn = k gap - c vn (negative where it
 * would pull) and fp, the force a contact applies: fn, or +0 where fn < 0, since a contact never
 * pulls (a NaN stays one, for the health checks to find). */
typedef struct ws_normal {
    v3 t;
    double vn, fn, fp;
} ws_normal;

static inline ws_normal ws_normal_law(v3 n, v3 vr, double gap, double k, double c)
{
    const double vn = vr.x * n.x + vr.y * n.y + vr.z * n.z;
    const double fn = k * gap - c * vn;
    return (ws_normal){v3_make(vr.x + n.x * (-vn), vr.y + n.y * (-vn), vr.z + n.z * (-vn)), vn, fn,
                       fn < 0.0 ? 0.0 : fn};
}

/* A body's motion as a contact sees it: its CoG r, velocity v and global spin w. */
typedef struct ws_motion {
    v3 r, v, w;
} ws_motion;

/* Where a node at x (velocity u) touches a body b, at depth d along the face's normal n (from
 * the body to the node): the lever from the body's CoG to the contact point, midway in the
 * overlap, and the node's velocity relative to the body's there. */
typedef struct ws_node_kin {
    v3 lever, vr;
} ws_node_kin;

static inline ws_node_kin ws_node_kinematics(v3 n, double d, v3 x, v3 u, ws_motion b)
{
    const double s = -0.5 * d;
    const double ax = (x.x + n.x * s) - b.r.x, ay = (x.y + n.y * s) - b.r.y,
                 az = (x.z + n.z * s) - b.r.z;
    const double bx = b.v.x + (b.w.y * az - b.w.z * ay), by = b.v.y + (b.w.z * ax - b.w.x * az),
                 bz = b.v.z + (b.w.x * ay - b.w.y * ax);
    return (ws_node_kin){v3_make(ax, ay, az), v3_make(u.x - bx, u.y - by, u.z - bz)};
}

/* Eq. 13's regularisation of Coulomb's law over s = slip speed / v_lim: p(s) = s (2 - s) below
 * 1, 1 above (p(0) = 0, p(1) = 1, p'(1) = 0), and its slope p'(s). */
static inline double ws_friction_p(double s)
{
    return s < 1.0 ? s * (2.0 - s) : 1.0;
}

static inline double ws_friction_slope(double s)
{
    return s < 1.0 ? 2.0 - 2.0 * s : 0.0;
}

/* Eq. 13's friction as a damper over a slip speed v: F = -cap phi t with phi = p(s) / v, the
 * law's secant (its limit p'(0) / v_lim = 2 / v_lim at rest). A step that takes the friction
 * at its end as -cap phi t_end, phi from the start, dissipates at any step: the force opposes
 * the slip it acts on, and at most stops it. */
static inline double ws_friction_phi(double v, double vlim)
{
    return v > 0.0 ? ws_friction_p(v / vlim) / v : 2.0 / vlim;
}

/* The friction of a contact slipping at t (a tangential velocity) that slides at the force
 * cap = mu F_n (Coulomb's), for the pair's v_lim: cap p(|t| / v_lim) against t (eq. 13), at most
 * the force that stops a mass m slipping at |t| within a step h, m |t| / h (the explicit film's
 * limit; m = +inf: no limit); zero at rest (|t| = 0), where the direction is none. Also the slip
 * speed v = |t| and s = v / v_lim (at or above 1: sliding at Coulomb's force). */
typedef struct ws_friction {
    v3 f;
    double v, s;
} ws_friction;

static inline ws_friction ws_friction_law(v3 t, double cap, double vlim, double m, double h)
{
    const double v = sqrt(t.x * t.x + t.y * t.y + t.z * t.z);
    const double s = v / vlim;
    const double law = cap * ws_friction_p(s);
    const double stop = m * v / h;
    /* Over the speed, so that the force's direction is t's: at rest a NaN, not taken. */
    const double scale = -(law < stop ? law : stop) / v;
    const uint64_t slips = ws_mask(v > 0.0);
    return (ws_friction){v3_make(ws_pick(slips, t.x * scale, 0.0),
                                 ws_pick(slips, t.y * scale, 0.0),
                                 ws_pick(slips, t.z * scale, 0.0)),
                         v, s};
}

#endif
