/* Constitutive laws F(u, u_dot) of dim 1, 3 or 6 with their derivatives, apart from what uses
 * them. Knows base and math only: the world resolves ids into laws before it calls here.
 *
 * Evaluation is a pure function of (committed state, u, u_dot, t, dt). A law with history keeps
 * nothing itself: each user holds `nstate` doubles, starts them with ws_law_state_init(), passes
 * them to every ws_law_eval() (which never writes them) and advances them with ws_law_commit()
 * once a step is accepted. */
#ifndef WS_LAW_H
#define WS_LAW_H

#include <wrapsim/law.h>

#include <math.h>

#include "base/base.h"

#define WS_LAWF_ELASTIC 1u /* F depends on u (or its history) */
#define WS_LAWF_VISCOUS 2u /* F depends on u_dot */

/* ws_law_eval() results other than 0. */
#define WS_LAW_EVAL_CALLBACK 1  /* a user or time callback returned non-zero */
#define WS_LAW_EVAL_NONFINITE 2 /* the force or a derivative is not finite */

typedef struct ws_law ws_law;

struct ws_law {
    /* The 1D film form (ws_law_film_form): for a stateless 1D law of that form (film != 0),
     * F = kc eps + (k - kc) g_w(eps) + c eps_dot. Other laws leave k = kc = c = 0, w = 1. */
    ws_law_type type;
    double k, kc, c, w;
    uint32_t users; /* webs, elements and laws that use it */
    char *name;

    int dim;
    unsigned flags;  /* WS_LAWF_* */
    uint32_t nstate; /* doubles of history per user */
    int film;        /* 1: the film form above is the whole law */
    int depth;       /* 1 + the depth of the laws it refers to (SUM, SCALED) */
    uint32_t leaves; /* leaf laws an evaluation visits (<= WS_LAW_MAX_LEAVES) */

    /* Linear parts: K (elastic, Kelvin-Voigt, cubic) and C (every damped law). A NULL matrix
     * means the scalar times the identity. */
    double ks, cs;
    double *K, *C; /* dim x dim row-major, or NULL */
    double kmax, cmax;

    double k3[WS_LAW_MAX_DIM]; /* cubic: per component */

    double lo, hi, rw; /* stop: engagement strains and ramp width */

    uint32_t n;              /* table points, Prony branches, scale points or terms */
    double *x, *f, *m, *e;   /* table: strains, forces, Hermite slopes, integral from x[0] */
    double e0;               /* table: the integral from x[0] to 0 */
    double *pk, *ptau;       /* relaxation: branch stiffness and time */
    double *st, *sf;         /* scaled: time table */
    double scale;            /* scaled: constant factor */
    ws_law_time_fn scale_fn; /* scaled */
    void *scale_user;
    ws_law *base;   /* scaled */
    ws_law **terms; /* sum */
    uint32_t *off;  /* sum: offset of each term's state */
    ws_law_user_fn user_fn;
    void *user;

    size_t bytes; /* of the block this law lives in (the struct and its arrays) */
};

/* Validate a Def and build a law in one block from mem. refs: the laws the Def names, resolved
 * by the caller (SUM: its terms in order; SCALED: the base), nrefs of them. On success they
 * count the new law as a user. WS_OK, WS_ERR_INVALID_ARGUMENT with the reason (naming the
 * field) in why, or WS_ERR_OUT_OF_MEMORY. The name is not copied (the caller sets it). */
ws_status ws_law_new(ws_mem *mem, const ws_law_def *d, ws_law *const *refs, size_t nrefs,
                     ws_law **out, char *why, size_t why_len);
/* Free a law built by ws_law_new (not its name); release_refs: also drop it as a user of the
 * laws it refers to (0 when the whole world goes and they may be gone already). */
void ws_law_free(ws_mem *mem, ws_law *L, int release_refs);

/* F[dim], dFdu and dFdud (dim x dim row-major) at (u, ud) from the committed state (NULL: the
 * initial state), at time t, dt after the committed state. ud may be NULL (zero rate); each
 * output may be NULL. Pure: never writes state. 0, or WS_LAW_EVAL_*. */
int ws_law_eval(const ws_law *L, const double *state, const double *u, const double *ud, double t,
                double dt, double *F, double *dFdu, double *dFdud);
/* The initial state: unstrained and relaxed (nstate doubles; nothing when 0). */
void ws_law_state_init(const ws_law *L, double *state);
/* Advance state to the one after a step accepted at (u, ud, t), dt after the committed state.
 * Evaluating at u right after this with dt = 0 gives the F of the trial. */
void ws_law_commit(const ws_law *L, double *state, const double *u, const double *ud, double t,
                   double dt);
/* Stored elastic energy at u from state (NULL: initial) at t = 0 (ws_law_elastic_energy_at for
 * another t; it matters for SCALED only). For a matrix law 1/2 u^T K u, exact when K is
 * symmetric. NaN for a user law (unknown), or when a time callback fails. */
double ws_law_elastic_energy(const ws_law *L, const double *state, const double *u);
double ws_law_elastic_energy_at(const ws_law *L, const double *state, const double *u, double t);
/* Upper bounds on the norms of dF/du and dF/du_dot over every state (the cubic law's at
 * |u| <= 1; a user law's as its Def declares). */
double ws_law_max_stiffness(const ws_law *L);
double ws_law_max_damping(const ws_law *L);
/* 1 when L is 1D, stateless, independent of time and F = kc eps + dk g_w(eps) + c eps_dot with
 * the film law's C1 ramp g_w; fills the four numbers (w > 0 always). 0 otherwise. */
int ws_law_film_form(const ws_law *L, double *kc, double *dk, double *w, double *c);

/* The film law's ramp g_w and its slope (0 below -w, eps above w, (eps + w)^2 / (4w) between). */
static inline double ws_law_film_ramp(double eps, double w, double *slope)
{
    if (eps >= w) {
        *slope = 1.0;
        return eps;
    }
    if (eps <= -w) {
        *slope = 0.0;
        return 0.0;
    }
    double a = eps + w;
    *slope = a / (2.0 * w);
    return a * a / (4.0 * w);
}

#endif
