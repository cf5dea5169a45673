/* Constitutive laws F(eps, eps_dot) with their derivatives, apart from what uses them. Knows
 * math only. Evaluation is a pure function of the arguments (no history yet). */
#ifndef WS_LAW_H
#define WS_LAW_H

#include <wrapsim/law.h>

#include "base/base.h"

typedef struct ws_law1d {
    ws_law_type type;
    double k, kc, c, w;
    uint32_t users; /* webs (and later elements) that use it */
    char *name;
} ws_law1d;

/* Validate a Def into a law; WS_OK or WS_ERR_INVALID_ARGUMENT with the reason in `why`. */
ws_status ws_law1d_setup(ws_law1d *L, const ws_law_def *d, char *why, size_t why_len);

/* F, dF/deps, dF/deps_dot at (eps, eps_dot). Inline: it sits in the web's spring loop. */
static inline double ws_law1d_eval(const ws_law1d *L, double eps, double epsd, double *dF,
                                   double *dFd)
{
    double F, k;
    switch (L->type) {
    case WS_LAW_TENSION_COMPRESSION: {
        /* F = kc eps + (k - kc) g(eps): g = 0 below -w, eps above w, (eps + w)^2 / (4w) between,
         * which is C1: g' runs 0 -> 1 linearly across the join. */
        double g, gp;
        if (eps >= L->w) {
            g = eps;
            gp = 1.0;
        } else if (eps <= -L->w) {
            g = 0.0;
            gp = 0.0;
        } else {
            double a = eps + L->w;
            g = a * a / (4.0 * L->w);
            gp = a / (2.0 * L->w);
        }
        F = L->kc * eps + (L->k - L->kc) * g + L->c * epsd;
        k = L->kc + (L->k - L->kc) * gp;
        break;
    }
    default: /* linear elastic (c = 0) and Kelvin-Voigt */
        F = L->k * eps + L->c * epsd;
        k = L->k;
        break;
    }
    if (dF)
        *dF = k;
    if (dFd)
        *dFd = L->c;
    return F;
}

/* Integral of the elastic force from 0 to eps (N, i.e. J per metre of rest length). */
double ws_law1d_energy(const ws_law1d *L, double eps);
/* Largest tangent stiffness dF/deps over all strains (N) and the damping (N s). */
double ws_law1d_max_stiffness(const ws_law1d *L);

#endif
