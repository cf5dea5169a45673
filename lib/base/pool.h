/* A small pool of threads of one world, for a step's parallel work when the host gives no
 * scheduler of its own (ws_world_def.enqueue_task). Made with the world, joined when it is
 * destroyed; no state outside it. */
#ifndef WS_POOL_H
#define WS_POOL_H

#include <wrapsim/world.h>

#include "base/base.h"

typedef struct ws_pool ws_pool;

/* A pool of `threads` threads (>= 1) beside the caller's, for tasks of at most `items` items
 * (a larger task runs on the caller alone). NULL when out of memory or when the system gives
 * no thread (what was made is undone). */
ws_pool *ws_pool_create(ws_mem *mem, uint32_t threads, int32_t items);
/* Stop and join the threads, free the pool (NULL: nothing). */
void ws_pool_destroy(ws_mem *mem, ws_pool *pool);
/* Run items [0, count) of `task`, one item a call, on the threads and the caller (worker 0),
 * and return when all have run. The first count - shared items are cut into shares: worker k
 * of n runs its share, items [k c / n, (k + 1) c / n) with c = count - shared, first, then
 * takes what is left of the others' and of the last `shared` items, which are no worker's own
 * and go to whichever is free first (0 <= shared <= count). */
void ws_pool_run(ws_pool *pool, ws_task_fn *task, int32_t count, int32_t shared, void *ctx);

/* How a module below the world runs a task on the step's workers (the world's threads or the
 * host's scheduler; world_step.c's ws_world_runner): run(self, task, count, ctx) returns once
 * items [0, count) of task have run, count at most `items`, at most `workers` of them at once.
 * A runner whose run is NULL has one worker: the caller runs the items itself. */
typedef struct ws_runner {
    void (*run)(void *self, ws_task_fn *task, uint32_t count, void *ctx);
    void *self;
    uint32_t workers, items;
} ws_runner;

/* fn(ctx, i) for i in [0, count) on run's workers (NULL, or one worker: in order here), cut
 * into at most run->items lanes of consecutive items. */
typedef void ws_item_fn(void *ctx, uint32_t i);
void ws_runner_for(const ws_runner *run, uint32_t count, ws_item_fn *fn, void *ctx);

#endif
