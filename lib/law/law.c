#include "law/law.h"

#include <math.h>
#include <stdio.h>

ws_status ws_law1d_setup(ws_law1d *L, const ws_law_def *d, char *why, size_t why_len)
{
    if (d->type != WS_LAW_LINEAR_ELASTIC && d->type != WS_LAW_LINEAR_VISCOELASTIC &&
        d->type != WS_LAW_TENSION_COMPRESSION) {
        snprintf(why, why_len, "law: unknown type %d", (int)d->type);
        return WS_ERR_INVALID_ARGUMENT;
    }
    if (!(isfinite(d->stiffness) && d->stiffness > 0.0)) {
        snprintf(why, why_len, "law: stiffness must be > 0 N (per unit strain), got %g",
                 d->stiffness);
        return WS_ERR_INVALID_ARGUMENT;
    }
    if (!(isfinite(d->damping) && d->damping >= 0.0)) {
        snprintf(why, why_len, "law: damping must be >= 0 N s, got %g", d->damping);
        return WS_ERR_INVALID_ARGUMENT;
    }
    if (d->type == WS_LAW_TENSION_COMPRESSION &&
        (!(isfinite(d->compression_stiffness) && d->compression_stiffness >= 0.0) ||
         !(isfinite(d->transition) && d->transition > 0.0))) {
        snprintf(why, why_len,
                 "law: the film law needs compression_stiffness >= 0 N and transition > 0, got "
                 "%g and %g",
                 d->compression_stiffness, d->transition);
        return WS_ERR_INVALID_ARGUMENT;
    }
    L->type = d->type;
    L->k = d->stiffness;
    L->kc = d->type == WS_LAW_TENSION_COMPRESSION ? d->compression_stiffness : d->stiffness;
    L->c = d->type == WS_LAW_LINEAR_ELASTIC ? 0.0 : d->damping;
    L->w = d->transition;
    L->users = 0;
    return WS_OK;
}

double ws_law1d_energy(const ws_law1d *L, double eps)
{
    if (L->type != WS_LAW_TENSION_COMPRESSION)
        return 0.5 * L->k * eps * eps;
    /* kc eps^2 / 2 + (k - kc) G(eps), G the integral of the ramp g from 0. */
    double w = L->w, G;
    /* The ramp integrated from -w gives w^2/12 at 0; subtract it so that G(0) = 0. */
    double g0 = w * w / 12.0;
    if (eps <= -w) {
        G = -g0;
    } else if (eps < w) {
        double a = eps + w;
        G = a * a * a / (12.0 * w) - g0;
    } else {
        /* up to w: (2w)^3 / (12 w) = 2w^2/3, then eps^2/2 - w^2/2 */
        G = 2.0 * w * w / 3.0 + 0.5 * (eps * eps - w * w) - g0;
    }
    return 0.5 * L->kc * eps * eps + (L->k - L->kc) * G;
}

double ws_law1d_max_stiffness(const ws_law1d *L)
{
    return fmax(L->k, L->kc);
}
