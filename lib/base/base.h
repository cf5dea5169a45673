/* Base services every module may use: allocation through the world's hooks with byte accounting,
 * Def checking, id packing, growable arrays. Knows nothing of physics. */
#ifndef WS_BASE_H
#define WS_BASE_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <wrapsim/common.h>

/* A hot loop compiled three times, for the baseline x86-64, for AVX2 and for AVX-512, the one for
 * the machine chosen when the library loads. The arithmetic is the same (no FMA: neither target
 * enables it, and -ffp-contract=off; the no_fused_ops test counts them in the library), so the
 * results are too, to the bit. */
#if defined(__x86_64__) && defined(__GNUC__) && defined(__has_attribute) && !defined(__clang__)
#if __has_attribute(target_clones)
#define WS_VECTOR_LOOP __attribute__((target_clones("avx512f", "avx2", "default")))
#endif
#endif
#ifndef WS_VECTOR_LOOP
#define WS_VECTOR_LOOP
#endif

/* Written by every ws_*_def_init(); an uninitialised Def almost never carries it. */
#define WS_DEF_MAGIC 0x57534446u /* "WSDF" */

/* Memory accounting around the user's allocator hooks. */
typedef struct ws_mem {
    ws_allocator hooks;
    uint64_t in_use;
    uint64_t peak;
} ws_mem;

void ws_mem_init(ws_mem *mem, const ws_allocator *hooks);
void *ws_mem_alloc(ws_mem *mem, size_t bytes);
void *ws_mem_calloc(ws_mem *mem, size_t count, size_t size);
/* Returns NULL on failure and leaves *ptr untouched. */
void *ws_mem_realloc(ws_mem *mem, void *ptr, size_t old_bytes, size_t new_bytes);
void ws_mem_free(ws_mem *mem, void *ptr, size_t bytes);
char *ws_mem_strdup(ws_mem *mem, const char *s);
void ws_mem_free_str(ws_mem *mem, char *s);

/* Grow an array of `elem` bytes so it holds at least `need` elements; capacity doubles.
 * Returns 0 on success, -1 when out of memory (array unchanged). */
int ws_array_reserve(ws_mem *mem, void **array, size_t *capacity, size_t need, size_t elem);

/* The world's arena (arena.c): the scratch of one step, bump-allocated from blocks of the
 * user's allocator and given back at once by the reset at the start of the next step, so a
 * step in a steady run allocates nothing. Every allocation starts on a WS_ARENA_ALIGN-byte
 * boundary (a cache line: vector loops load whole lines). One thread allocates: the step takes
 * the lanes' scratch before it starts them. */
#define WS_ARENA_ALIGN 64
#define WS_ARENA_MIN_BLOCK 4096
typedef struct ws_arena {
    ws_mem *mem;
    struct ws_arena_block *top; /* the block allocated from (it chains those before) */
    size_t used;                /* bytes of top in use, from its start */
    size_t step_bytes;          /* bytes handed out since the last reset */
    size_t most;                /* the most step_bytes any step reached */
    size_t held;                /* bytes of all blocks, as allocated */
    size_t blocks;
} ws_arena;

void ws_arena_init(ws_arena *a, ws_mem *mem);
/* `bytes` of scratch aligned to WS_ARENA_ALIGN, valid until the next reset; NULL when out of
 * memory (the arena is as it was). calloc: zeroed; NULL too when count * size overflows. */
void *ws_arena_alloc(ws_arena *a, size_t bytes);
void *ws_arena_calloc(ws_arena *a, size_t count, size_t size);
/* Everything allocated is given back. When the last steps chained blocks, one block of the
 * most a step needed replaces them (kept as they are when that allocation fails). */
void ws_arena_reset(ws_arena *a);
/* Its blocks back to the allocator. */
void ws_arena_free(ws_arena *a);

/* Start filling a Def with defaults: zero it and write its size/magic header. 0 for a NULL Def
 * (the init then does nothing), 1 otherwise. */
int ws_def_reset(void *def, size_t size);

/* The size/magic header every Def starts with. */
#define WS_DEF_HEADER_SIZE (2 * sizeof(uint32_t))

/* The end of a Def's layout up to and including `field`: the size an init fills for a caller
 * whose Def ends there. */
#define WS_DEF_END(type, field) (offsetof(type, field) + sizeof(((type *)0)->field))

/* Finish a sized ws_*_def_init(): copy the library's filled Def `full` (of `full_size` bytes) into
 * the caller's Def of `size` bytes: the first min(size, full_size) bytes, zeros after them, and
 * that common size in the header, so create reads no byte the caller does not have. A NULL Def
 * or one smaller than the header is left alone. */
void ws_def_fill(void *def, size_t size, const void *full, size_t full_size);

/* Checks the size/magic header of a Def: 0 when good (any size from the header up: fields past
 * the caller's size take their defaults). */
int ws_def_check(const void *def);

/* Copy a checked caller's Def over a Def of `full` bytes filled with defaults: the caller's
 * fields, as many as its size says, and the full size in the header. */
void ws_def_copy(void *dst, size_t full, const void *src);

/* Ids: [kind:4][generation:32][slot+1:28]; zero is the null id (slot+1 is never 0).
 *
 * Stale ids: each slot's generation steps by one at every destroy and a slot is retired, never
 * reused, when its generation would come back to the first one it had, so within a world no
 * generation of a slot repeats and a destroyed id can never name a live object (a retired slot
 * costs its 12 bytes of table; it happens after 2^32 create/destroy cycles of that slot).
 *
 * Foreign ids: a world has no tag in its ids; instead every slot's generations start at a value
 * mixed from a per-world 32-bit salt (from the world's address, the wall clock to the
 * nanosecond and the processor clock) and the slot, so an id of another world passes only if
 * its generation equals that of this world's live occupant of the slot: about 2^-32 per look-up
 * (no global counter: the library has no mutable global state). */
enum {
    WS_KIND_BODY = 1,
    WS_KIND_SHAPE = 2,
    WS_KIND_MATERIAL = 3,
    WS_KIND_LAW = 4,
    WS_KIND_WEB = 5,
    WS_KIND_ELEMENT = 6
};
#define WS_ID_SLOT_BITS 28
#define WS_ID_GEN_SHIFT WS_ID_SLOT_BITS
#define WS_ID_KIND_SHIFT 60
#define WS_ID_SLOT_MASK ((1u << WS_ID_SLOT_BITS) - 1u)
/* The most objects of one kind a world can hold. */
#define WS_ID_MAX_SLOTS ((1u << WS_ID_SLOT_BITS) - 2u)
/* The most vertices or triangles of a mesh (features are numbered below the film's flags). */
#define WS_MESH_MAX_ITEMS ((1u << 24) - 2u)

/* Index of the lowest set bit of m (m != 0). */
static inline uint32_t ws_lowest_bit(uint64_t m)
{
#if defined(__GNUC__)
    return (uint32_t)__builtin_ctzll(m);
#else
    uint32_t f = 0;
    while (!(m & 1u)) {
        m >>= 1;
        f++;
    }
    return f;
#endif
}

static inline uint64_t ws_id_pack(unsigned kind, uint32_t gen, uint32_t slot)
{
    return ((uint64_t)(kind & 0xFu) << WS_ID_KIND_SHIFT) | ((uint64_t)gen << WS_ID_GEN_SHIFT) |
           (uint64_t)((slot + 1u) & WS_ID_SLOT_MASK);
}
static inline unsigned ws_id_kind(uint64_t bits) { return (unsigned)(bits >> WS_ID_KIND_SHIFT); }
static inline uint32_t ws_id_gen(uint64_t bits) { return (uint32_t)(bits >> WS_ID_GEN_SHIFT); }
/* Slot index, or UINT32_MAX for the null id. */
static inline uint32_t ws_id_slot(uint64_t bits)
{
    return (uint32_t)(bits & WS_ID_SLOT_MASK) - 1u;
}

/* A generational slot table: maps id slots to dense indices of a pool. */
typedef struct ws_slot_table {
    uint32_t *dense;      /* slot -> dense index, UINT32_MAX when free */
    uint32_t *generation; /* slot -> generation of the live (or next) occupant */
    uint32_t *free_list;  /* free slots, used as a stack */
    size_t free_count;
    size_t slot_count;
    size_t capacity;
    uint32_t salt;  /* the world's salt of first generations (see the ids above) */
    size_t retired; /* slots whose generations ran through a whole cycle, never reused */
} ws_slot_table;

/* A world's salt, mixed from its address and the clocks. */
uint32_t ws_id_salt(const void *world);
/* The first generation of a slot of a table. */
uint32_t ws_slots_first_generation(const ws_slot_table *t, uint32_t slot);
void ws_slots_destroy(ws_mem *mem, ws_slot_table *t);
/* Take a slot; returns 0 and the slot, -1 on out of memory or too many slots. */
int ws_slots_take(ws_mem *mem, ws_slot_table *t, uint32_t *slot);
void ws_slots_release(ws_slot_table *t, uint32_t slot);
/* 1 when `bits` is an id of kind `kind` naming a live slot of t with its generation. */
static inline int ws_slots_is_live(const ws_slot_table *t, uint64_t bits, unsigned kind)
{
    if (bits == 0 || ws_id_kind(bits) != kind)
        return 0;
    uint32_t s = ws_id_slot(bits);
    return s < t->slot_count && t->dense[s] != UINT32_MAX && t->generation[s] == ws_id_gen(bits);
}
/* The id of the live occupant of a slot. */
static inline uint64_t ws_slots_id(const ws_slot_table *t, unsigned kind, uint32_t slot)
{
    return ws_id_pack(kind, t->generation[slot], slot);
}

/* FNV-1a over bytes, continuing from h. */
uint64_t ws_hash_bytes(uint64_t h, const void *data, size_t n);
#define WS_HASH_SEED 0xcbf29ce484222325ull

int ws_is_finite3(const ws_vec3 *v);

#endif
