/* The time a cache line takes to go from one core to the other and back: the cost of every
 * hand-over between the world's thread and a worker (a task posted, a lane done). On a virtual
 * machine it depends on where the host puts the two virtual cores (the same core complex or
 * not), and it can change from hour to hour; workers.sh prints it beside the speed-ups, since a
 * step of the film hands work over several times a sub-step.
 *
 * Usage: build/bench/bench_pingpong [round trips]   (default 2000000)
 * Prints the mean round trip in ns between the first two cores it may run on. */
#define _GNU_SOURCE
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

typedef struct {
    _Atomic long turn; /* odd: the second thread's move; even: the first's */
    long trips;
    int core;
} court;

static void keep_on(int core)
{
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(core, &set);
    pthread_setaffinity_np(pthread_self(), sizeof set, &set);
}

static void *answer(void *arg)
{
    court *c = arg;
    keep_on(c->core);
    for (long i = 0; i < c->trips; i++) {
        while (atomic_load_explicit(&c->turn, memory_order_acquire) != 2 * i + 1)
            ;
        atomic_store_explicit(&c->turn, 2 * i + 2, memory_order_release);
    }
    return NULL;
}

/* The first two cores this process may use (-1 when it has one). */
static int two_cores(int *a, int *b)
{
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) != 0)
        return -1;
    *a = *b = -1;
    for (int k = 0; k < CPU_SETSIZE; k++) {
        if (!CPU_ISSET(k, &set))
            continue;
        if (*a < 0)
            *a = k;
        else {
            *b = k;
            return 0;
        }
    }
    return -1;
}

int main(int argc, char **argv)
{
    long trips = argc > 1 ? atol(argv[1]) : 2000000;
    int first, second;
    if (trips < 1 || two_cores(&first, &second) != 0) {
        fprintf(stderr, "bench_pingpong: needs two cores and a positive number of round trips\n");
        return 2;
    }
    court c = {.trips = trips, .core = second};
    atomic_init(&c.turn, 0);
    pthread_t other;
    keep_on(first);
    if (pthread_create(&other, NULL, answer, &c) != 0) {
        fprintf(stderr, "bench_pingpong: no second thread\n");
        return 2;
    }
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (long i = 0; i < trips; i++) {
        atomic_store_explicit(&c.turn, 2 * i + 1, memory_order_release);
        while (atomic_load_explicit(&c.turn, memory_order_acquire) != 2 * i + 2)
            ;
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    pthread_join(other, NULL);
    double ns = (double)(t1.tv_sec - t0.tv_sec) * 1e9 + (double)(t1.tv_nsec - t0.tv_nsec);
    printf("core %d <-> core %d: round trip %.1f ns (%ld trips)\n", first, second, ns / (double)trips,
           trips);
    return 0;
}
