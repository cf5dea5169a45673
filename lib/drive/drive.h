/* Prescribed motions of world elements: a pure function of time. Knows math only. */
#ifndef WS_DRIVE_H
#define WS_DRIVE_H

#include <wrapsim/body.h>

#include "math/wmath.h"

typedef struct ws_drive {
    ws_drive_def def; /* validated copy; axis and direction unit */
    ws_pose base;     /* pose when the drive was set */
} ws_drive;

/* Validate a Def and fill a drive relative to `base`. Returns WS_OK or WS_ERR_INVALID_ARGUMENT
 * with the reason in `why`. */
ws_status ws_drive_setup(ws_drive *d, const ws_drive_def *def, const ws_pose *base, char *why,
                         size_t why_len);
/* Pose and global velocities at time t. Returns 0, or the callback's non-zero result. */
int ws_drive_eval(const ws_drive *d, double t, ws_pose *pose, v3 *v, v3 *w);
/* The tilt angle theta(t) and its rate (exposed for tests and examples). */
void ws_drive_tilt_angle(const ws_drive_def *def, double t, double *theta, double *rate);

#endif
