#define _POSIX_C_SOURCE 200809L /* clock_gettime for the bounded spin */
/* The world's own threads (pool.h).
 *
 * A task is published under the mutex with a new generation. Its items are cut into as many
 * consecutive shares as there are workers (the caller is worker 0): each worker runs its own
 * share first, so the same items, and with them the same rows of a film, go to the same
 * worker from task to task and stay in its core's cache; then it takes what is left of the
 * others' shares, so that a worker waiting for its core on a busy machine costs at most what
 * one worker would. An item is taken by writing the task's generation into its claim, which
 * only a worker of that generation can do: a thread that woke late for an older task finds
 * nothing to take.
 *
 * A step publishes tasks a few microseconds to a few tens of microseconds apart (the move
 * test, each sub-step). Waking a sleeping thread costs about as much CPU on both sides (some
 * 5 us, more in a virtual machine), and a thread that wakes late finds its share taken by the
 * others, so that rows change cores: the threads and the caller watch for the next task or
 * the last item for SPIN_NS before they sleep on the condition variables. */
#include "base/pool.h"

#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <time.h>

/* How long a thread watches for work, and the caller for the end of a task, before sleeping:
 * longer than the serial part of a step of the reference case between its tasks (about
 * 30 us), short enough that an idle world's threads soon leave the cores to others. After
 * PAUSE_NS of it the watcher gives its core to any other thread that waits for one
 * (sched_yield) between looks: on a machine with more threads than cores the thread it waits
 * for may be one of them. */
#define SPIN_NS 50000
#define PAUSE_NS 5000
/* Pause rounds between two looks at the clock. */
#define SPIN_ROUNDS 64

typedef struct pool_thread {
    ws_pool *pool;
    pthread_t id;
    uint32_t index; /* worker index, 1.. */
} pool_thread;

struct ws_pool {
    pthread_mutex_t lock;
    pthread_cond_t go, done;
    _Atomic uint64_t generation; /* of the task published last */
    atomic_int stop;
    /* The task published last: written under the lock, read under it by the threads. */
    ws_task_fn *task;
    void *ctx;
    int32_t count, shared;
    atomic_int_least32_t finished; /* items of the task done */
    int sleepers;                  /* threads asleep on go (under the lock) */
    atomic_int caller_asleep;      /* the caller sleeps on done */
    _Atomic uint64_t *claim;       /* per item: the generation that took it last */
    int32_t claim_cap;
    uint32_t threads; /* threads made */
    uint32_t cap;     /* room in thread */
    pool_thread *thread;
};

static void cpu_pause(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
}

static int64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* Whether `ready` became true within SPIN_NS of watching. */
static int spin_until(int (*ready)(ws_pool *, uint64_t), ws_pool *p, uint64_t arg)
{
    const int64_t t0 = now_ns();
    for (;;) {
        for (int k = 0; k < SPIN_ROUNDS; k++) {
            if (ready(p, arg))
                return 1;
            cpu_pause();
        }
        const int64_t t = now_ns() - t0;
        if (t > SPIN_NS)
            return ready(p, arg);
        if (t > PAUSE_NS)
            sched_yield();
    }
}

static int new_task(ws_pool *p, uint64_t seen)
{
    return atomic_load_explicit(&p->generation, memory_order_acquire) != seen ||
           atomic_load_explicit(&p->stop, memory_order_relaxed);
}

static int task_done(ws_pool *p, uint64_t count)
{
    return (uint64_t)atomic_load_explicit(&p->finished, memory_order_acquire) == count;
}

/* Take item i for generation gen: 1 when this worker takes it. */
static int take(ws_pool *p, int32_t i, uint64_t gen)
{
    uint64_t c = atomic_load_explicit(&p->claim[i], memory_order_relaxed);
    return c < gen && atomic_compare_exchange_strong(&p->claim[i], &c, gen);
}

static void item_done(ws_pool *p, int32_t count)
{
    if (atomic_fetch_add(&p->finished, 1) + 1 == count && atomic_load(&p->caller_asleep)) {
        pthread_mutex_lock(&p->lock);
        pthread_cond_signal(&p->done);
        pthread_mutex_unlock(&p->lock);
    }
}

/* Run what worker `worker` of `workers` may take of task generation gen: its own share of the
 * first count - shared items, then what is left of the others' and the shared ones. */
static void run_items(ws_pool *p, ws_task_fn *task, void *ctx, int32_t count, int32_t shared,
                      uint64_t gen, uint32_t worker, uint32_t workers)
{
    const int64_t owned = count - shared;
    const int32_t i0 = (int32_t)((int64_t)worker * owned / workers),
                  i1 = (int32_t)((int64_t)(worker + 1) * owned / workers);
    for (int32_t i = i0; i < i1; i++)
        if (take(p, i, gen)) {
            task(i, i + 1, worker, ctx);
            item_done(p, count);
        }
    for (int32_t k = 0; k < count; k++) {
        const int32_t i = (i1 + k) % count;
        if (take(p, i, gen)) {
            task(i, i + 1, worker, ctx);
            item_done(p, count);
        }
    }
}

static void *pool_main(void *arg)
{
    pool_thread *t = arg;
    ws_pool *p = t->pool;
    uint64_t seen = 0;
    for (;;) {
        if (!spin_until(new_task, p, seen)) {
            pthread_mutex_lock(&p->lock);
            p->sleepers++;
            while (!new_task(p, seen))
                pthread_cond_wait(&p->go, &p->lock);
            p->sleepers--;
            pthread_mutex_unlock(&p->lock);
        }
        if (atomic_load(&p->stop))
            break;
        pthread_mutex_lock(&p->lock);
        seen = atomic_load_explicit(&p->generation, memory_order_relaxed);
        ws_task_fn *task = p->task;
        void *ctx = p->ctx;
        const int32_t count = p->count, shared = p->shared;
        pthread_mutex_unlock(&p->lock);
        run_items(p, task, ctx, count, shared, seen, t->index, p->threads + 1);
    }
    return NULL;
}

ws_pool *ws_pool_create(ws_mem *mem, uint32_t threads, int32_t items)
{
    ws_pool *p = ws_mem_calloc(mem, 1, sizeof *p);
    if (!p)
        return NULL;
    p->cap = threads;
    p->claim_cap = items;
    p->thread = ws_mem_calloc(mem, threads, sizeof *p->thread);
    p->claim = ws_mem_calloc(mem, (size_t)items, sizeof *p->claim);
    int ok = p->thread && p->claim && pthread_mutex_init(&p->lock, NULL) == 0;
    if (!ok) {
        ws_mem_free(mem, p->thread, p->thread ? threads * sizeof *p->thread : 0);
        ws_mem_free(mem, (void *)p->claim, p->claim ? (size_t)items * sizeof *p->claim : 0);
        ws_mem_free(mem, p, sizeof *p);
        return NULL;
    }
    for (int32_t i = 0; i < items; i++)
        atomic_init(&p->claim[i], 0);
    atomic_init(&p->generation, 0);
    atomic_init(&p->stop, 0);
    atomic_init(&p->finished, 0);
    atomic_init(&p->caller_asleep, 0);
    ok = pthread_cond_init(&p->go, NULL) == 0;
    if (ok && pthread_cond_init(&p->done, NULL) != 0) {
        pthread_cond_destroy(&p->go);
        ok = 0;
    }
    if (!ok) {
        pthread_mutex_destroy(&p->lock);
        ws_mem_free(mem, p->thread, threads * sizeof *p->thread);
        ws_mem_free(mem, (void *)p->claim, (size_t)items * sizeof *p->claim);
        ws_mem_free(mem, p, sizeof *p);
        return NULL;
    }
    for (uint32_t i = 0; i < threads; i++) {
        p->thread[i] = (pool_thread){p, 0, i + 1};
        if (pthread_create(&p->thread[i].id, NULL, pool_main, &p->thread[i]) != 0) {
            ws_pool_destroy(mem, p); /* joins the p->threads made */
            return NULL;
        }
        p->threads = i + 1;
    }
    return p;
}

void ws_pool_destroy(ws_mem *mem, ws_pool *p)
{
    if (!p)
        return;
    pthread_mutex_lock(&p->lock);
    atomic_store(&p->stop, 1);
    pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->lock);
    for (uint32_t i = 0; i < p->threads; i++)
        pthread_join(p->thread[i].id, NULL);
    pthread_cond_destroy(&p->done);
    pthread_cond_destroy(&p->go);
    pthread_mutex_destroy(&p->lock);
    ws_mem_free(mem, p->thread, p->cap * sizeof *p->thread);
    ws_mem_free(mem, (void *)p->claim, (size_t)p->claim_cap * sizeof *p->claim);
    ws_mem_free(mem, p, sizeof *p);
}

void ws_pool_run(ws_pool *p, ws_task_fn *task, int32_t count, int32_t shared, void *ctx)
{
    if (count > p->claim_cap) { /* more items than the pool was made for: run them here */
        for (int32_t i = 0; i < count; i++)
            task(i, i + 1, 0, ctx);
        return;
    }
    pthread_mutex_lock(&p->lock);
    p->task = task;
    p->ctx = ctx;
    p->count = count;
    p->shared = shared;
    atomic_store(&p->finished, 0);
    const uint64_t gen = atomic_load_explicit(&p->generation, memory_order_relaxed) + 1;
    atomic_store_explicit(&p->generation, gen, memory_order_release);
    if (p->sleepers)
        pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->lock);
    run_items(p, task, ctx, count, shared, gen, 0, p->threads + 1);
    if (spin_until(task_done, p, (uint64_t)count))
        return;
    pthread_mutex_lock(&p->lock);
    atomic_store(&p->caller_asleep, 1);
    while (!task_done(p, (uint64_t)count))
        pthread_cond_wait(&p->done, &p->lock);
    atomic_store(&p->caller_asleep, 0);
    pthread_mutex_unlock(&p->lock);
}

/* A task over lanes of consecutive items (ws_runner_for). */
typedef struct lanes_task {
    ws_item_fn *fn;
    void *ctx;
    uint32_t count, lanes;
} lanes_task;

static void lanes_run(int32_t start, int32_t end, uint32_t worker, void *c)
{
    (void)worker;
    const lanes_task *T = c;
    for (int32_t l = start; l < end; l++) {
        const uint32_t i0 = (uint32_t)((uint64_t)T->count * (uint32_t)l / T->lanes),
                       i1 = (uint32_t)((uint64_t)T->count * ((uint32_t)l + 1) / T->lanes);
        for (uint32_t i = i0; i < i1; i++)
            T->fn(T->ctx, i);
    }
}

void ws_runner_for(const ws_runner *run, uint32_t count, ws_item_fn *fn, void *ctx)
{
    if (!run || !run->run || run->workers <= 1 || count < 2) {
        for (uint32_t i = 0; i < count; i++)
            fn(ctx, i);
        return;
    }
    lanes_task T = {fn, ctx, count, count < run->items ? count : run->items};
    run->run(run->self, lanes_run, T.lanes, &T);
}
