#define _POSIX_C_SOURCE 200809L /* clock_gettime for the bounded spin */
/* The world's own threads (pool.h).
 *
 * A task's items are cut into as many consecutive shares as there are workers (the caller is
 * worker 0), and the last `shared` items form a share of no worker's own: each worker runs its
 * own share first, so the same items, and with them the same rows of a film, go to the same
 * worker from task to task and stay in its core's cache; then the shared items, then what is
 * left of the others' shares, so that a worker waiting for its core on a busy machine costs at
 * most what one worker would.
 *
 * What a task costs beyond its items is the cache lines that move between the cores, some
 * 200-700 ns each on this kind of machine (bench_pingpong), so each worker's claims and count
 * of items done lie on a line of their own, which only the others' stealing reads:
 * - the task is published in one line, its fields under a sequence count (odd while they are
 *   written), which a thread reads without a lock;
 * - a share's next item is a counter in its owner's line, tagged with the task's number: a
 *   worker takes an item by raising the counter of the task it read, which a thread that woke
 *   late for an older task cannot do (it finds a newer number, or a share used up);
 * - each worker counts the items it ran on its own line, and the caller waits until the
 *   counts add up to every item published.
 * (Before: the task read under the mutex, one claim word per item side by side, and a shared
 * count of items done raised after each item: several lines moved per task, about 1.2 us of a
 * task of four items, and the same again on a busy machine's bad state.)
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
/* A cache line, and the bits of a share's counter that hold the next item (the rest: the
 * task's number). */
#define LINE 64
#define ITEM_BITS 24
#define ITEM_MASK ((UINT64_C(1) << ITEM_BITS) - 1)

typedef struct pool_thread {
    ws_pool *pool;
    pthread_t id;
    uint32_t index; /* worker index, 1.. */
} pool_thread;

/* A worker's own line: the next item of its share (task number << ITEM_BITS | item), and the
 * items it has run over all tasks. The last one (index workers) is the shared items'. */
typedef struct pool_share {
    _Atomic uint64_t next;
    _Atomic uint64_t done;
    char pad[LINE - 2 * sizeof(uint64_t)];
} pool_share;

/* The task published last, read without a lock: seq is odd while the caller writes it, and
 * seq / 2 is the task's number. */
typedef struct pool_post {
    _Atomic uint64_t seq;
    _Atomic(ws_task_fn *) task;
    _Atomic(void *) ctx;
    atomic_int count, shared;
    atomic_int stop;
    atomic_int caller_asleep; /* the caller sleeps on done */
    char pad[LINE];
} pool_post;

struct ws_pool {
    pool_post post;
    pthread_mutex_t lock;
    pthread_cond_t go, done;
    int sleepers;   /* threads asleep on go (under the lock) */
    uint64_t total; /* items published over all tasks (the caller's) */
    int32_t items;  /* the most items of a task run on the threads */
    uint32_t threads; /* threads made */
    uint32_t cap;     /* room in thread */
    pool_thread *thread;
    char pad[LINE];
    pool_share share[]; /* threads + 2: the workers', then the shared items' */
};

/* What a thread read of a task. */
typedef struct pool_task {
    uint64_t number;
    ws_task_fn *task;
    void *ctx;
    int32_t count, shared;
} pool_task;

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
    return atomic_load_explicit(&p->post.seq, memory_order_acquire) / 2 != seen ||
           atomic_load_explicit(&p->post.stop, memory_order_relaxed);
}

/* The items run over all tasks, by every worker. */
static uint64_t items_done(const ws_pool *p)
{
    uint64_t n = 0;
    for (uint32_t k = 0; k <= p->threads; k++)
        n += atomic_load_explicit(&p->share[k].done, memory_order_acquire);
    return n;
}

static int task_done(ws_pool *p, uint64_t total)
{
    return items_done(p) == total;
}

/* The task published last, read consistently (its fields between two equal even counts). */
static pool_task read_task(ws_pool *p)
{
    for (;;) {
        const uint64_t s = atomic_load_explicit(&p->post.seq, memory_order_acquire);
        if (s & 1) {
            cpu_pause();
            continue;
        }
        pool_task t = {s / 2,
                       atomic_load_explicit(&p->post.task, memory_order_relaxed),
                       atomic_load_explicit(&p->post.ctx, memory_order_relaxed),
                       atomic_load_explicit(&p->post.count, memory_order_relaxed),
                       atomic_load_explicit(&p->post.shared, memory_order_relaxed)};
        atomic_thread_fence(memory_order_acquire);
        if (atomic_load_explicit(&p->post.seq, memory_order_relaxed) == s)
            return t;
    }
}

/* Take the next item of share q, items [i0, i1) of task t: the item, or -1 when none is left
 * (or the share has gone on to a newer task). */
static int32_t take(pool_share *q, uint64_t t, int32_t i0, int32_t i1)
{
    uint64_t v = atomic_load_explicit(&q->next, memory_order_relaxed);
    for (;;) {
        const uint64_t vt = v >> ITEM_BITS;
        if (vt > t)
            return -1;
        const int32_t i = vt == t ? (int32_t)(v & ITEM_MASK) : i0;
        if (i >= i1)
            return -1;
        if (atomic_compare_exchange_weak_explicit(&q->next, &v,
                                                  t << ITEM_BITS | (uint64_t)(i + 1),
                                                  memory_order_acq_rel, memory_order_relaxed))
            return i;
    }
}

/* The items of share q of task T on `workers` workers: worker q's own, or (q == workers) the
 * shared ones. */
static void share_items(const pool_task *T, uint32_t q, uint32_t workers, int32_t *i0,
                        int32_t *i1)
{
    const int64_t owned = T->count - T->shared;
    *i0 = q == workers ? (int32_t)owned : (int32_t)((int64_t)q * owned / workers);
    *i1 = q == workers ? T->count : (int32_t)((int64_t)(q + 1) * owned / workers);
}

/* Run what worker `worker` of `workers` may take of task T: its own share, the shared items,
 * then what is left of the others' shares. Its count of items run is raised after each item
 * (its own line: only the caller reads it), so that a worker that loses its core while it
 * looks for more does not hold up a task whose items are all done. */
static void run_items(ws_pool *p, const pool_task *T, uint32_t worker, uint32_t workers)
{
    _Atomic uint64_t *done = &p->share[worker].done;
    uint64_t ran = 0;
    for (uint32_t k = 0; k <= workers; k++) {
        /* Its own share, then the shared one (index workers), then the next worker's on. */
        const uint32_t q = k == 0 ? worker : k == 1 ? workers : (worker + k - 1) % workers;
        if (k > 1 && q == worker)
            continue;
        int32_t i0, i1, i;
        share_items(T, q, workers, &i0, &i1);
        if (i0 >= i1)
            continue;
        while ((i = take(&p->share[q], T->number, i0, i1)) >= 0) {
            T->task(i, i + 1, worker, T->ctx);
            ran++;
            atomic_store_explicit(done, atomic_load_explicit(done, memory_order_relaxed) + 1,
                                  memory_order_seq_cst);
        }
    }
    if (!ran)
        return;
    if (worker && atomic_load_explicit(&p->post.caller_asleep, memory_order_seq_cst)) {
        pthread_mutex_lock(&p->lock);
        pthread_cond_signal(&p->done);
        pthread_mutex_unlock(&p->lock);
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
        if (atomic_load(&p->post.stop))
            break;
        const pool_task T = read_task(p);
        seen = T.number;
        run_items(p, &T, t->index, p->threads + 1);
    }
    return NULL;
}

ws_pool *ws_pool_create(ws_mem *mem, uint32_t threads, int32_t items)
{
    const size_t bytes = sizeof(ws_pool) + (threads + 2) * sizeof(pool_share);
    ws_pool *p = ws_mem_calloc(mem, 1, bytes);
    if (!p)
        return NULL;
    p->cap = threads;
    p->items = items;
    p->thread = ws_mem_calloc(mem, threads, sizeof *p->thread);
    int ok = p->thread && pthread_mutex_init(&p->lock, NULL) == 0;
    if (!ok) {
        ws_mem_free(mem, p->thread, p->thread ? threads * sizeof *p->thread : 0);
        ws_mem_free(mem, p, bytes);
        return NULL;
    }
    for (uint32_t k = 0; k < threads + 2; k++) {
        atomic_init(&p->share[k].next, 0);
        atomic_init(&p->share[k].done, 0);
    }
    atomic_init(&p->post.seq, 0);
    atomic_init(&p->post.task, NULL);
    atomic_init(&p->post.ctx, NULL);
    atomic_init(&p->post.count, 0);
    atomic_init(&p->post.shared, 0);
    atomic_init(&p->post.stop, 0);
    atomic_init(&p->post.caller_asleep, 0);
    ok = pthread_cond_init(&p->go, NULL) == 0;
    if (ok && pthread_cond_init(&p->done, NULL) != 0) {
        pthread_cond_destroy(&p->go);
        ok = 0;
    }
    if (!ok) {
        pthread_mutex_destroy(&p->lock);
        ws_mem_free(mem, p->thread, threads * sizeof *p->thread);
        ws_mem_free(mem, p, bytes);
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
    atomic_store(&p->post.stop, 1);
    pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->lock);
    for (uint32_t i = 0; i < p->threads; i++)
        pthread_join(p->thread[i].id, NULL);
    pthread_cond_destroy(&p->done);
    pthread_cond_destroy(&p->go);
    pthread_mutex_destroy(&p->lock);
    ws_mem_free(mem, p->thread, p->cap * sizeof *p->thread);
    ws_mem_free(mem, p, sizeof(ws_pool) + (p->cap + 2) * sizeof(pool_share));
}

void ws_pool_run(ws_pool *p, ws_task_fn *task, int32_t count, int32_t shared, void *ctx)
{
    if (count > p->items) { /* more items than the pool was made for: run them here */
        for (int32_t i = 0; i < count; i++)
            task(i, i + 1, 0, ctx);
        return;
    }
    /* Published: the count odd while the fields change, even again after. */
    const uint64_t s = atomic_load_explicit(&p->post.seq, memory_order_relaxed);
    atomic_store_explicit(&p->post.seq, s + 1, memory_order_relaxed);
    atomic_thread_fence(memory_order_release);
    atomic_store_explicit(&p->post.task, task, memory_order_relaxed);
    atomic_store_explicit(&p->post.ctx, ctx, memory_order_relaxed);
    atomic_store_explicit(&p->post.count, count, memory_order_relaxed);
    atomic_store_explicit(&p->post.shared, shared, memory_order_relaxed);
    atomic_store_explicit(&p->post.seq, s + 2, memory_order_release);
    p->total += (uint64_t)count;
    /* A thread that checked for a task under the lock before this one was published sleeps,
     * or is about to: wake it. */
    pthread_mutex_lock(&p->lock);
    if (p->sleepers)
        pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->lock);
    const pool_task T = {(s + 2) / 2, task, ctx, count, shared};
    run_items(p, &T, 0, p->threads + 1);
    if (spin_until(task_done, p, p->total))
        return;
    pthread_mutex_lock(&p->lock);
    atomic_store_explicit(&p->post.caller_asleep, 1, memory_order_seq_cst);
    /* Against a worker's count raised then the flag read (run_items): one of the two sees
     * the other's write. */
    atomic_thread_fence(memory_order_seq_cst);
    while (!task_done(p, p->total))
        pthread_cond_wait(&p->done, &p->lock);
    atomic_store(&p->post.caller_asleep, 0);
    pthread_mutex_unlock(&p->lock);
}
