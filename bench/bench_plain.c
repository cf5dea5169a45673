/* Benchmark (not a test): a yardstick for the machine's speed at the time of a run. A plain
 * scalar explicit loop over the film of the wrapped reference case: the same 5856 nodes, their
 * places and masses, the same springs with their rest lengths and the same tension-compression
 * law, gravity and symplectic Euler at dt 0.25 ms, but no contacts and no bodies. Written as a
 * C programmer would write it first: nodes as structures, a list of springs, one loop over the
 * springs and one over the nodes, and compiled without vectors (bench/meson.build).
 *
 * Its figure, taken next to bench_wrapped's on the same core, turns a wall time that drifts
 * with the machine (a shared or virtual one varies by a third from hour to hour) into a ratio
 * that does not (bench/compare.sh runs the two side by side: see README). With `linear`, the
 * leanest loop of all: each spring linear, EA eps, without damping or the compression branch.
 * Never fails on time.
 * Usage: bench_plain [steps] (default 24000) [linear] */
#define TILT_TABLE_NO_MAIN
#include "../examples/tilt_table.c"

#include <stdint.h>

typedef struct plain_node {
    double x[3], v[3], f[3];
    double m, inv_m;
} plain_node;

/* A spring from node a to node b: 1 / rest length and its law, the library's film form: in
 * tension kc eps + dk eps + c eps_dot, in compression kc eps + c eps_dot, joined over a strain
 * of w by a quadratic. */
typedef struct plain_spring {
    uint32_t a, b;
    double inv_l0, kc, dk, w, c;
} plain_spring;

static int plain_linear; /* the leanest law: EA eps (set once, before the loop) */

static double plain_law(const plain_spring *s, double eps, double epsd)
{
    if (plain_linear)
        return (s->kc + s->dk) * eps;
    double ramp;
    if (eps >= s->w)
        ramp = eps;
    else if (eps > -s->w)
        ramp = (eps + s->w) * (eps + s->w) * 0.25 / s->w;
    else
        ramp = 0.0;
    return s->kc * eps + s->dk * ramp + s->c * epsd;
}

static void plain_step(plain_node *nd, size_t n, const plain_spring *sp, size_t ns, double h,
                       double gz)
{
    for (size_t i = 0; i < n; i++) {
        nd[i].f[0] = 0.0;
        nd[i].f[1] = 0.0;
        nd[i].f[2] = nd[i].m * gz;
    }
    for (size_t k = 0; k < ns; k++) {
        plain_node *A = &nd[sp[k].a], *B = &nd[sp[k].b];
        double d[3], l2 = 0.0, ud = 0.0;
        for (int c = 0; c < 3; c++) {
            d[c] = B->x[c] - A->x[c];
            l2 += d[c] * d[c];
            ud += (B->v[c] - A->v[c]) * d[c];
        }
        if (!(l2 > 0.0))
            continue;
        double l = sqrt(l2);
        double t = plain_law(&sp[k], l * sp[k].inv_l0 - 1.0, ud / l * sp[k].inv_l0) / l;
        for (int c = 0; c < 3; c++) {
            A->f[c] += t * d[c];
            B->f[c] -= t * d[c];
        }
    }
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            nd[i].v[c] += h * nd[i].inv_m * nd[i].f[c];
            nd[i].x[c] += h * nd[i].v[c];
        }
}

int main(int argc, char **argv)
{
    (void)tilt_run; /* the example's runner is not used here */
    long steps = argc > 1 ? atol(argv[1]) : 24000;
    plain_linear = argc > 2 && !strcmp(argv[2], "linear");
    tilt_options o;
    tilt_default_options(&o);
    o.wrapped = 1;
    tilt_scene sc;
    if (steps <= 0 || tilt_build(&o, &sc) != WS_OK) {
        fprintf(stderr, "bench_plain: cannot build the scene\n");
        return 1;
    }
    /* The film as the reference case puts it on: places, springs, their strains and tensions. */
    ws_web_info info;
    size_t n = 0, ns = 0, got = 0;
    ws_web_get_info(sc.world, sc.film, &info);
    ws_web_copy_positions(sc.world, sc.film, NULL, 0, &n);
    ws_web_copy_springs(sc.world, sc.film, NULL, 0, &ns);
    double *xyz = malloc(3 * n * sizeof *xyz), *eps = malloc(ns * sizeof *eps),
           *ten = malloc(ns * sizeof *ten);
    uint32_t *pairs = malloc(2 * ns * sizeof *pairs);
    plain_node *nd = calloc(n, sizeof *nd);
    plain_spring *sp = calloc(ns, sizeof *sp);
    if (!xyz || !eps || !ten || !pairs || !nd || !sp ||
        ws_web_copy_positions(sc.world, sc.film, xyz, n, &got) != WS_OK ||
        ws_web_copy_springs(sc.world, sc.film, pairs, ns, &got) != WS_OK ||
        ws_web_copy_spring_strains(sc.world, sc.film, eps, ns, &got) != WS_OK ||
        ws_web_copy_spring_tensions(sc.world, sc.film, ten, ns, &got) != WS_OK) {
        fprintf(stderr, "bench_plain: cannot read the film\n");
        return 1;
    }
    const double m = info.mass / n;
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++)
            nd[i].x[c] = xyz[3 * i + c];
        nd[i].m = m;
        nd[i].inv_m = 1.0 / m;
    }
    /* The example's laws (tilt_wrap): stiffness EA, 1 % of it in compression, damping EA times
     * 0.1 / 2000 s (the paper's 0.1 kg/s over 2000 N/m), the default transition of 1e-3. Each
     * spring is pre-stretched far past the transition, where its tension is EA eps. */
    for (size_t k = 0; k < ns; k++) {
        const double ea = ten[k] / eps[k];
        sp[k] = (plain_spring){pairs[2 * k], pairs[2 * k + 1], 0.0, 0.01 * ea, 0.99 * ea, 1e-3,
                               ea * 0.1 / 2000.0};
        const uint32_t a = sp[k].a, b = sp[k].b;
        double l2 = 0.0;
        for (int c = 0; c < 3; c++)
            l2 += (xyz[3 * b + c] - xyz[3 * a + c]) * (xyz[3 * b + c] - xyz[3 * a + c]);
        sp[k].inv_l0 = (1.0 + eps[k]) / sqrt(l2);
    }
    const double dt = 0.25e-3;
    double t0 = now();
    for (long s = 0; s < steps; s++)
        plain_step(nd, n, sp, ns, dt, -9.81);
    double el = now() - t0;
    double sum = 0.0;
    for (size_t i = 0; i < n; i++)
        sum += nd[i].x[2];
    if (!isfinite(sum)) {
        fprintf(stderr, "bench_plain: the loop ran away\n");
        return 1;
    }
    printf("plain scalar explicit loop: the film of reference case P, %zu nodes, %zu springs "
           "(%s), no contacts, dt 0.25 ms\n",
           n, ns, plain_linear ? "linear, undamped" : "the case's law");
    printf("  %ld steps in %.3f s: %.0f steps/s, %.2f M node-updates/s, %.1f us/step "
           "(24000 steps: %.2f s)\n",
           steps, el, steps / el, (double)n * steps / el / 1e6, 1e6 * el / steps,
           24000.0 * el / steps);
    free(xyz);
    free(eps);
    free(ten);
    free(pairs);
    free(nd);
    free(sp);
    ws_world_destroy(sc.world);
    return 0;
}
