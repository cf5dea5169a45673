/* Unit tests of the world's arena (lib/base/arena.c): the scratch of a step, bump-allocated
 * from blocks of the user's allocator. What must hold: every allocation aligned to
 * WS_ARENA_ALIGN and disjoint from the others of its step; the step's scratch survives the
 * chaining of a new block (earlier pointers stay valid, their bytes unchanged); after a reset
 * a chain becomes one block that holds what the largest step took, so the same step again
 * allocates nothing from the user; an allocator that fails gives NULL and leaves the arena
 * usable; every block goes back to the free hook with the size it was allocated with, and
 * nothing is left after the arena is freed. */
#include "helpers.h"

#include "base/base.h"

#include <string.h>

static ws_mem tracked(test_alloc *a)
{
    ws_allocator h = {0};
    a->track = 1;
    a->allocs_left = -1;
    h.alloc = ta_alloc;
    h.realloc = ta_realloc;
    h.free = ta_free;
    h.user = a;
    ws_mem m;
    ws_mem_init(&m, &h);
    return m;
}

/* One "step": n allocations of growing sizes, each filled with its own byte, all checked at
 * the end (an overlap or a block moved under a pointer changes some byte). Returns 0, or the
 * number of the allocation that failed (1-based). */
static int one_step(ws_arena *ar, int n)
{
    unsigned char *p[64];
    size_t len[64];
    for (int i = 0; i < n; i++) {
        len[i] = (size_t)(100 + 97 * i * i);
        if (!(p[i] = ws_arena_alloc(ar, len[i])))
            return i + 1;
        ck_assert_msg(((uintptr_t)p[i] % WS_ARENA_ALIGN) == 0, "allocation %d at %p", i,
                      (void *)p[i]);
        memset(p[i], i + 1, len[i]);
    }
    for (int i = 0; i < n; i++)
        for (size_t k = 0; k < len[i]; k++)
            if (p[i][k] != (unsigned char)(i + 1))
                ck_abort_msg("allocation %d byte %zu overwritten", i, k);
    return 0;
}

START_TEST(test_arena_chain_then_one_block)
{
    test_alloc a = {0};
    ws_mem m = tracked(&a);
    ws_arena ar;
    ws_arena_init(&ar, &m);
    ws_arena_reset(&ar); /* an empty arena resets to nothing */
    ck_assert_int_eq(a.live, 0);
    ck_assert_int_eq(one_step(&ar, 40), 0);
    ck_assert_msg(ar.blocks > 1, "40 growing allocations fit the first block (%zu)", ar.blocks);
    ck_assert_int_eq((long long)ar.held, a.bytes);
    ws_arena_reset(&ar);
    ck_assert_msg(ar.blocks == 1, "after the reset %zu blocks", ar.blocks);
    ck_assert_int_eq((long long)ar.held, a.bytes);
    /* The same step again: from the one block, no allocation from the user. */
    const long before = a.live;
    const long long bytes = a.bytes;
    for (int s = 0; s < 3; s++) {
        ck_assert_int_eq(one_step(&ar, 40), 0);
        ck_assert_int_eq(ar.blocks, 1);
        ws_arena_reset(&ar);
    }
    ck_assert_int_eq(a.live, before);
    ck_assert_int_eq(a.bytes, bytes);
    ck_assert(ws_arena_calloc(&ar, SIZE_MAX / 8, 16) == NULL); /* count * size overflows */
    ck_assert(ws_arena_alloc(&ar, SIZE_MAX - 8) == NULL);
    ws_arena_free(&ar);
    ck_assert_msg(a.live == 0 && a.bytes == 0, "%ld blocks, %lld bytes left", a.live, a.bytes);
    ck_assert_msg(a.size_errors == 0, "%s", a.size_error);
    test_alloc_done(&a);
}
END_TEST

START_TEST(test_arena_out_of_memory)
{
    /* The user's allocator fails at its n-th call for each n in turn, in the first step and in
     * the reset after it: NULL from the allocation that needed the block, the arena still
     * usable (the next step, with memory back, runs whole), and every byte back in the end. */
    int failures = 0;
    for (long n = 0; n < 12; n++) {
        test_alloc a = {0};
        ws_mem m = tracked(&a);
        ws_arena ar;
        ws_arena_init(&ar, &m);
        a.allocs_left = n;
        const int failed = one_step(&ar, 40);
        ws_arena_reset(&ar); /* may fail to take the one block: keeps the newest */
        a.allocs_left = -1;
        failures += failed != 0;
        ck_assert_int_eq((long long)ar.held, a.bytes);
        ck_assert_int_eq(one_step(&ar, 40), 0);
        ws_arena_reset(&ar);
        ck_assert_int_eq(one_step(&ar, 40), 0);
        ws_arena_free(&ar);
        ck_assert_msg(a.live == 0 && a.bytes == 0, "n = %ld: %ld blocks, %lld bytes left", n,
                      a.live, a.bytes);
        ck_assert_msg(a.size_errors == 0, "n = %ld: %s", n, a.size_error);
        test_alloc_done(&a);
    }
    ck_assert_msg(failures > 0, "no allocation failed");
}
END_TEST

START_TEST(test_arena_calloc_zeroes_reused_room)
{
    /* Room handed out again after a reset holds the last step's bytes; calloc clears them. */
    test_alloc a = {0};
    ws_mem m = tracked(&a);
    ws_arena ar;
    ws_arena_init(&ar, &m);
    unsigned char *p = ws_arena_alloc(&ar, 1000);
    ck_assert_ptr_nonnull(p);
    memset(p, 0xAB, 1000);
    ws_arena_reset(&ar);
    unsigned char *q = ws_arena_calloc(&ar, 250, 4);
    ck_assert_ptr_eq(p, q); /* the same room */
    for (int k = 0; k < 1000; k++)
        ck_assert_int_eq(q[k], 0);
    ws_arena_free(&ar);
    ck_assert_int_eq(a.live, 0);
    test_alloc_done(&a);
}
END_TEST

/* An allocator whose blocks start 56 bytes past a 64-byte boundary (aligned to 8, never to 16
 * or more; the worst start for the arena's first allocation after its 16-byte header): the
 * arena's allocations are aligned all the same, and the room of a block holds what it was made
 * for. The block's true start is kept in the 8 bytes before it. */
static void *odd_alloc(void *u, size_t n)
{
    unsigned char *raw = ta_alloc(u, n + 128);
    if (!raw)
        return NULL;
    unsigned char *p = raw + (64 - (uintptr_t)raw % 64) % 64 + 56;
    memcpy(p - 8, &raw, sizeof raw);
    return p;
}
static void *odd_realloc(void *u, void *p, size_t o, size_t n)
{
    (void)u;
    (void)p;
    (void)o;
    (void)n;
    return NULL; /* the arena never reallocates */
}
static void odd_free(void *u, void *p, size_t n)
{
    unsigned char *raw;
    memcpy(&raw, (unsigned char *)p - 8, sizeof raw);
    ta_free(u, raw, n + 128);
}

START_TEST(test_arena_blocks_aligned_to_8)
{
    test_alloc a = {0};
    a.track = 1;
    a.allocs_left = -1;
    ws_allocator h = {0};
    h.alloc = odd_alloc;
    h.realloc = odd_realloc;
    h.free = odd_free;
    h.user = &a;
    ws_mem m;
    ws_mem_init(&m, &h);
    ws_arena ar;
    ws_arena_init(&ar, &m);
    for (int s = 0; s < 4; s++) { /* chained, then one block */
        ck_assert_int_eq(one_step(&ar, 40), 0);
        ws_arena_reset(&ar);
    }
    ck_assert_int_eq(ar.blocks, 1);
    /* What a step took, in one piece, fits the one block. */
    ck_assert_ptr_nonnull(ws_arena_alloc(&ar, ar.most));
    ck_assert_int_eq(ar.blocks, 1);
    ws_arena_free(&ar);
    ck_assert_msg(a.live == 0 && a.bytes == 0 && a.size_errors == 0, "%ld blocks, %lld bytes, %s",
                  a.live, a.bytes, a.size_error);
    test_alloc_done(&a);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("arena");
    add_case(s, "chain_then_one_block", test_arena_chain_then_one_block, 10);
    add_case(s, "out_of_memory", test_arena_out_of_memory, 10);
    add_case(s, "calloc_zeroes_reused_room", test_arena_calloc_zeroes_reused_room, 10);
    add_case(s, "blocks_aligned_to_8", test_arena_blocks_aligned_to_8, 10);
    return run_suite(s);
}
