/* Prescribed motions of world elements: a pure function of time. Knows math (and base, for the
 * tables a drive owns). */
#ifndef WS_DRIVE_H
#define WS_DRIVE_H

#include <wrapsim/body.h>

#include "base/base.h"
#include "math/wmath.h"

/* One phase of a translating profile (pulse, impact): its acceleration law a(tau) over
 * [t0, t0 + T], and the velocity and displacement at its start. */
typedef enum ws_seg_kind {
    WS_SEG_RISE = 0, /* A/2 (1 - cos(pi tau / T)) */
    WS_SEG_HOLD,     /* A */
    WS_SEG_FALL,     /* A/2 (1 + cos(pi tau / T)) */
    WS_SEG_COAST,    /* 0 */
    WS_SEG_LOBE,     /* A/2 (1 - cos(2 pi tau / T)): a raised cosine, velocity change A T / 2 */
    WS_SEG_HALF_SINE /* A sin(pi tau / T): velocity change 2 A T / pi */
} ws_seg_kind;

typedef struct ws_seg {
    ws_seg_kind kind;
    double t0, T, A; /* start (s, from the drive's start_time), duration s, peak m/s^2 */
    double v0, x0;   /* m/s, m at t0 */
} ws_seg;

#define WS_DRIVE_MAX_SEGS 6

typedef struct ws_drive {
    ws_drive_def def; /* validated copy; axis and direction unit; table and PSD pointers NULL */
    ws_pose base;     /* pose when the drive was set */
    double stop_ramp; /* tilt: the stop ramp in use (stop_ramp_time, shortened to fit) */
    int nseg;         /* pulse, impact: the phases */
    ws_seg seg[WS_DRIVE_MAX_SEGS];
    double end_v, end_x; /* pulse, impact: velocity and displacement after the last phase */
    /* Table and random: the played accelerations at the samples and their exact integrals
     * (velocity, displacement) from rest; one allocation of 3 tab_n doubles from the world. */
    double *tab;
    size_t tab_n;
    double tab_h;
} ws_drive;

/* Everything a drive gives at a time: pose, velocities, accelerations (global; of the CoG). */
typedef struct ws_drive_motion {
    ws_pose pose;
    v3 v, w, a, alpha;
    double angle, rate, angacc; /* tilt */
    int has_acc;
} ws_drive_motion;

/* Validate a Def and fill a drive relative to `base`; tables come from `mem` (released with
 * ws_drive_release). Returns WS_OK, WS_ERR_INVALID_ARGUMENT (reason in `why`) or
 * WS_ERR_OUT_OF_MEMORY; on error `d` owns nothing. */
ws_status ws_drive_setup(ws_drive *d, ws_mem *mem, const ws_drive_def *def, const ws_pose *base,
                         char *why, size_t why_len);
/* Free what the drive owns (nothing for most types). */
void ws_drive_release(ws_drive *d, ws_mem *mem);
/* Pose and global velocities at time t. Returns 0; 1 when the result is not finite; or the
 * callback's non-zero result (a callback's non-finite pose also gives -1). */
int ws_drive_eval(const ws_drive *d, double t, ws_pose *pose, v3 *v, v3 *w);
/* Everything at time t (same return as ws_drive_eval). */
int ws_drive_motion_at(const ws_drive *d, double t, ws_drive_motion *m);
/* The tilt angle theta(t) and its rate (exposed for tests and examples), with the default-free
 * stop ramp `stop_ramp` (s). */
void ws_drive_tilt_angle(const ws_drive_def *def, double stop_ramp, double t, double *theta,
                         double *rate, double *angacc);
/* The random history (see ws_vibration_synthesize) into accel[count]; count a power of two. */
ws_status ws_drive_synthesize(const ws_drive_def *def, double *accel, size_t count, char *why,
                              size_t why_len);
/* Check PSD breakpoints and give their Grms (g). */
ws_status ws_drive_psd_grms(const double *f, const double *g2, size_t n, double *grms, char *why,
                            size_t why_len);

#endif
