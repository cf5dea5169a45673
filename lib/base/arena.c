/* The world's arena: the scratch of one step, bump-allocated from blocks of the user's
 * allocator (through ws_mem, so the byte accounting and the sizes the free hook is told stay
 * right), given back all at once when the next step starts.
 *
 * A step that needs more than the block holds chains another block (at least twice the last)
 * and goes on: the pointers it already handed out stay valid, and nothing of the step has to
 * be done again. Retrying the step with a larger block was the other way; it is not taken
 * because a step is not free of side effects before it fails (drive, law and log callbacks
 * called, statistics counted), so a retry would show the user callbacks twice. At the next
 * reset a chain is replaced by one block of the most the steps have needed, so after the first
 * steps of a run every step takes its scratch from one block and allocates nothing. */
#include "base/base.h"

#include <string.h>

/* A block's header; the bytes handed out follow it. */
typedef struct ws_arena_block {
    struct ws_arena_block *prev; /* the block chained before (NULL: the first) */
    size_t size;                 /* bytes of the block with its header, as allocated */
} ws_arena_block;

/* Room for aligning a block's first allocation: a user's allocator may hand out blocks aligned
 * to anything (8 bytes, say), so up to WS_ARENA_ALIGN - 1 bytes after the header may go. */
#define BLOCK_SLACK (WS_ARENA_ALIGN - 1)

static size_t round_up(size_t n, size_t a)
{
    return (n + a - 1) / a * a;
}

void ws_arena_init(ws_arena *a, ws_mem *mem)
{
    memset(a, 0, sizeof *a);
    a->mem = mem;
}

/* Room in block k from byte `used` on (relative to the block's start) for `bytes` aligned: the
 * offset where they start, or SIZE_MAX when they do not fit. */
static size_t fit(const ws_arena_block *k, size_t used, size_t bytes)
{
    const uintptr_t base = (uintptr_t)k;
    const uintptr_t at = round_up((size_t)(base + used), WS_ARENA_ALIGN);
    const size_t off = (size_t)(at - base);
    if (off > k->size || k->size - off < bytes)
        return SIZE_MAX;
    return off;
}

/* A new block for at least `bytes` (aligned), chained on top. 0, or -1 when out of memory. */
static int chain(ws_arena *a, size_t bytes)
{
    const size_t head = sizeof(ws_arena_block) + BLOCK_SLACK;
    if (bytes > SIZE_MAX / 4 - head)
        return -1;
    size_t size = bytes + head;
    if (a->top && size < 2 * a->top->size)
        size = 2 * a->top->size;
    if (size < WS_ARENA_MIN_BLOCK)
        size = WS_ARENA_MIN_BLOCK;
    ws_arena_block *k = ws_mem_alloc(a->mem, size);
    if (!k)
        return -1;
    k->prev = a->top;
    k->size = size;
    a->top = k;
    a->used = sizeof(ws_arena_block);
    a->blocks++;
    a->held += size;
    return 0;
}

void *ws_arena_alloc(ws_arena *a, size_t bytes)
{
    /* Every allocation a whole number of alignment units: each starts aligned once the first
     * of a block does, and the bytes a step takes (step_bytes) are what one block of that
     * size holds, whatever its address. */
    if (bytes > SIZE_MAX / 4)
        return NULL;
    bytes = round_up(bytes ? bytes : 1, WS_ARENA_ALIGN);
    size_t off = a->top ? fit(a->top, a->used, bytes) : SIZE_MAX;
    if (off == SIZE_MAX) {
        if (chain(a, bytes) != 0)
            return NULL;
        off = fit(a->top, a->used, bytes);
        if (off == SIZE_MAX) /* cannot happen: the block was made for it */
            return NULL;
    }
    a->used = off + bytes;
    a->step_bytes += bytes;
    if (a->step_bytes > a->most)
        a->most = a->step_bytes;
    return (char *)a->top + off;
}

void *ws_arena_calloc(ws_arena *a, size_t count, size_t size)
{
    if (size != 0 && count > SIZE_MAX / size)
        return NULL;
    void *p = ws_arena_alloc(a, count * size);
    if (p)
        memset(p, 0, count * size);
    return p;
}

/* Free the blocks below `keep` in the chain (keep stays, as the first block). */
static void free_below(ws_arena *a, ws_arena_block *keep)
{
    ws_arena_block *k = keep->prev;
    keep->prev = NULL;
    while (k) {
        ws_arena_block *prev = k->prev;
        a->held -= k->size;
        a->blocks--;
        ws_mem_free(a->mem, k, k->size);
        k = prev;
    }
}

void ws_arena_reset(ws_arena *a)
{
    a->step_bytes = 0;
    if (!a->top)
        return;
    a->used = sizeof(ws_arena_block);
    if (a->blocks == 1)
        return;
    /* The last step chained blocks: one block for the most any step needed, in place of the
     * chain. Out of memory, the newest (largest) block is kept and the next step chains again. */
    const size_t size = round_up(a->most + sizeof(ws_arena_block) + BLOCK_SLACK, WS_ARENA_ALIGN);
    ws_arena_block *k = ws_mem_alloc(a->mem, size);
    if (!k) {
        free_below(a, a->top);
        return;
    }
    k->prev = a->top;
    k->size = size;
    a->top = k;
    a->held += size;
    a->blocks++;
    free_below(a, k);
}

void ws_arena_free(ws_arena *a)
{
    if (a->top) {
        free_below(a, a->top);
        a->held -= a->top->size;
        ws_mem_free(a->mem, a->top, a->top->size);
    }
    a->top = NULL;
    a->used = a->step_bytes = 0;
    a->blocks = 0;
}
