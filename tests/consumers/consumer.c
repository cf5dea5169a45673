/* A program outside the project that uses the installed library (CMake's find_package) or the
 * project as a meson subproject: it must compile, link, load the library and run a step.
 * One box falls freely for N steps of dt from rest: symplectic Euler moves it
 * g dt^2 N (N + 1) / 2 down, which it must report to 1e-12 m (rounding of 100 additions). */
#include <math.h>
#include <stdio.h>
#include <wrapsim/wrapsim.h>

int main(void)
{
    const double dt = 1e-3, g = 9.81;
    const int n = 100;
    ws_world_def wd;
    ws_world_def_init(&wd);
    wd.dt = dt;
    wd.gravity = (ws_vec3){0, 0, -g};
    ws_world *w = NULL;
    ws_shape_id box;
    ws_body_id body;
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.mass = 1.0;
    bd.name = "falling box";
    if (ws_world_create(&wd, &w) != WS_OK || ws_shape_create_box(w, 0.1, 0.1, 0.1, &box) != WS_OK)
        return 1;
    bd.shape = box;
    if (ws_body_create(w, &bd, &body) != WS_OK || ws_world_step_n(w, n) != WS_OK) {
        fprintf(stderr, "consumer: %s\n", ws_world_last_error(w));
        ws_world_destroy(w);
        return 1;
    }
    ws_vec3 r;
    ws_body_get_position(w, body, &r);
    double want = -g * dt * dt * n * (n + 1) / 2.0;
    ws_world_destroy(w);
    if (fabs(r.z - want) > 1e-12 || ws_version_number() != WS_VERSION_NUMBER) {
        fprintf(stderr, "consumer: z = %.15g m, want %.15g m; library %s, header %s\n", r.z, want,
                ws_version_string(), WS_VERSION_STRING);
        return 1;
    }
    printf("consumer: libwrapsim %s, the box fell %.6f m as it must\n", ws_version_string(), -r.z);
    return 0;
}
