/* The world's own threads (pool.h). A task is published under the mutex with a new generation;
 * the threads woken by it and the caller take its items one at a time, the next not yet taken,
 * until none is left, and count each item done. The caller returns when every item is done,
 * not when every thread has looked: on a machine busy with other work a thread may wake late,
 * and then finds nothing left to take (the caller has run its share). */
#include "base/pool.h"

#include <pthread.h>

typedef struct pool_thread {
    ws_pool *pool;
    pthread_t id;
    uint32_t index; /* worker index, 1.. */
} pool_thread;

struct ws_pool {
    pthread_mutex_t lock;
    pthread_cond_t go, done;
    uint64_t generation; /* of the task published last */
    int stop;
    ws_task_fn *task;
    void *ctx;
    int32_t count, next, finished; /* items of the task; the next to take; those done */
    uint32_t threads;              /* threads made */
    uint32_t cap;                  /* room in thread */
    pool_thread *thread;
};

/* Take and run items of the task published last until none is left; called and returning
 * with the lock held. */
static void take_items(ws_pool *p, uint32_t worker)
{
    while (p->next < p->count) {
        const int32_t i = p->next++;
        ws_task_fn *task = p->task;
        void *ctx = p->ctx;
        pthread_mutex_unlock(&p->lock);
        task(i, i + 1, worker, ctx);
        pthread_mutex_lock(&p->lock);
        if (++p->finished == p->count)
            pthread_cond_signal(&p->done);
    }
}

static void *pool_main(void *arg)
{
    pool_thread *t = arg;
    ws_pool *p = t->pool;
    uint64_t seen = 0;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (!p->stop && p->generation == seen)
            pthread_cond_wait(&p->go, &p->lock);
        if (p->stop)
            break;
        seen = p->generation;
        take_items(p, t->index);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

ws_pool *ws_pool_create(ws_mem *mem, uint32_t threads)
{
    ws_pool *p = ws_mem_calloc(mem, 1, sizeof *p);
    if (!p)
        return NULL;
    p->cap = threads;
    p->thread = ws_mem_calloc(mem, threads, sizeof *p->thread);
    if (!p->thread || pthread_mutex_init(&p->lock, NULL) != 0) {
        ws_mem_free(mem, p->thread, p->thread ? threads * sizeof *p->thread : 0);
        ws_mem_free(mem, p, sizeof *p);
        return NULL;
    }
    int ok = pthread_cond_init(&p->go, NULL) == 0;
    if (ok && pthread_cond_init(&p->done, NULL) != 0) {
        pthread_cond_destroy(&p->go);
        ok = 0;
    }
    if (!ok) {
        pthread_mutex_destroy(&p->lock);
        ws_mem_free(mem, p->thread, threads * sizeof *p->thread);
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
    p->stop = 1;
    pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->lock);
    for (uint32_t i = 0; i < p->threads; i++)
        pthread_join(p->thread[i].id, NULL);
    pthread_cond_destroy(&p->done);
    pthread_cond_destroy(&p->go);
    pthread_mutex_destroy(&p->lock);
    ws_mem_free(mem, p->thread, p->cap * sizeof *p->thread);
    ws_mem_free(mem, p, sizeof *p);
}

void ws_pool_run(ws_pool *p, ws_task_fn *task, int32_t count, void *ctx)
{
    pthread_mutex_lock(&p->lock);
    p->task = task;
    p->ctx = ctx;
    p->count = count;
    p->next = 0;
    p->finished = 0;
    p->generation++;
    pthread_cond_broadcast(&p->go);
    take_items(p, 0);
    while (p->finished < p->count)
        pthread_cond_wait(&p->done, &p->lock);
    pthread_mutex_unlock(&p->lock);
}
