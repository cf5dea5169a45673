/* What a task on the world's threads costs beyond its items: tasks of `items` items, each a
 * fixed chain of `work` dependent additions, run on a pool of one thread beside the caller
 * (as a world of 2 workers runs its lanes), against the same items run one after another on
 * the caller. A step of the wrapped film hands 3-4 such tasks to the pool (the move test, the
 * search, each sub-step); what the pool adds to each is the price of the cache lines that
 * cross between the cores (bench_pingpong). A figure, not a test: on a machine whose second
 * core is busy the task takes as long as the items in a row, or longer.
 *
 * Usage: build/bench/bench_pool [tasks] [items] [work]   (default 200000 4 200)
 * Prints ns per task on the pool, ns for its items in a row, and their ratio. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "base/pool.h"

static long work_per_item;

/* An item: `work_per_item` additions, each waiting for the one before. */
static void item(int32_t start, int32_t end, uint32_t worker, void *ctx)
{
    volatile double *sink = (double *)ctx + 8 * worker; /* its worker's own line */
    for (int32_t i = start; i < end; i++) {
        double x = *sink;
        for (long k = 0; k < work_per_item; k++)
            x += 1e-9 * (double)k;
        *sink = x;
    }
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    const long tasks = argc > 1 ? atol(argv[1]) : 200000;
    const int items = argc > 2 ? atoi(argv[2]) : 4;
    work_per_item = argc > 3 ? atol(argv[3]) : 200;
    if (tasks < 1 || items < 1 || items > 64 || work_per_item < 0) {
        fprintf(stderr, "bench_pool: tasks >= 1, items 1..64, work >= 0\n");
        return 2;
    }
    ws_mem mem;
    ws_mem_init(&mem, NULL);
    ws_pool *pool = ws_pool_create(&mem, 1, items);
    if (!pool) {
        fprintf(stderr, "bench_pool: no pool\n");
        return 2;
    }
    /* One sink a worker, a cache line apart, so that the items share nothing. */
    static double sink[2][8];
    static double pooled_sink[2][8];
    double t0 = now();
    for (long t = 0; t < tasks; t++)
        for (int32_t i = 0; i < items; i++)
            item(i, i + 1, 0, sink);
    const double serial = (now() - t0) / (double)tasks;
    t0 = now();
    for (long t = 0; t < tasks; t++)
        ws_pool_run(pool, item, items, 0, pooled_sink);
    const double pooled = (now() - t0) / (double)tasks;
    ws_pool_destroy(&mem, pool);
    printf("pool of 2: %.0f ns a task of %d items (%ld additions each); in a row %.0f ns; "
           "ratio %.3f\n",
           1e9 * pooled, items, work_per_item, 1e9 * serial, pooled / serial);
    return 0;
}
