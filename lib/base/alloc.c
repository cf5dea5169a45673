#include "base/base.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void *default_alloc(void *user, size_t bytes)
{
    (void)user;
    return malloc(bytes);
}

static void *default_realloc(void *user, void *ptr, size_t old_bytes, size_t new_bytes)
{
    (void)user;
    (void)old_bytes;
    return realloc(ptr, new_bytes);
}

static void default_free(void *user, void *ptr, size_t bytes)
{
    (void)user;
    (void)bytes;
    free(ptr);
}

void ws_mem_init(ws_mem *mem, const ws_allocator *hooks)
{
    memset(mem, 0, sizeof *mem);
    if (hooks && hooks->alloc && hooks->realloc && hooks->free) {
        mem->hooks = *hooks;
    } else {
        mem->hooks.alloc = default_alloc;
        mem->hooks.realloc = default_realloc;
        mem->hooks.free = default_free;
        mem->hooks.user = NULL;
    }
}

void *ws_mem_alloc(ws_mem *mem, size_t bytes)
{
    if (bytes == 0)
        bytes = 1;
    void *p = mem->hooks.alloc(mem->hooks.user, bytes);
    if (p) {
        mem->in_use += bytes;
        if (mem->in_use > mem->peak)
            mem->peak = mem->in_use;
    }
    return p;
}

void *ws_mem_calloc(ws_mem *mem, size_t count, size_t size)
{
    if (size != 0 && count > SIZE_MAX / size)
        return NULL;
    void *p = ws_mem_alloc(mem, count * size);
    if (p)
        memset(p, 0, count * size > 0 ? count * size : 1);
    return p;
}

void *ws_mem_realloc(ws_mem *mem, void *ptr, size_t old_bytes, size_t new_bytes)
{
    if (!ptr)
        return ws_mem_alloc(mem, new_bytes);
    if (new_bytes == 0)
        new_bytes = 1;
    if (old_bytes == 0)
        old_bytes = 1;
    void *p = mem->hooks.realloc(mem->hooks.user, ptr, old_bytes, new_bytes);
    if (p) {
        mem->in_use = mem->in_use - old_bytes + new_bytes;
        if (mem->in_use > mem->peak)
            mem->peak = mem->in_use;
    }
    return p;
}

void ws_mem_free(ws_mem *mem, void *ptr, size_t bytes)
{
    if (!ptr)
        return;
    if (bytes == 0)
        bytes = 1;
    mem->hooks.free(mem->hooks.user, ptr, bytes);
    mem->in_use -= bytes;
}

char *ws_mem_strdup(ws_mem *mem, const char *s)
{
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char *p = ws_mem_alloc(mem, n);
    if (p)
        memcpy(p, s, n);
    return p;
}

void ws_mem_free_str(ws_mem *mem, char *s)
{
    if (s)
        ws_mem_free(mem, s, strlen(s) + 1);
}

int ws_array_reserve(ws_mem *mem, void **array, size_t *capacity, size_t need, size_t elem)
{
    if (need <= *capacity)
        return 0;
    size_t cap = *capacity ? *capacity : 8;
    while (cap < need) {
        if (cap > SIZE_MAX / 2 / elem)
            return -1;
        cap *= 2;
    }
    void *p = ws_mem_realloc(mem, *array, *capacity * elem, cap * elem);
    if (!p)
        return -1;
    *array = p;
    *capacity = cap;
    return 0;
}

int ws_def_reset(void *def, size_t size)
{
    if (!def)
        return 0;
    memset(def, 0, size);
    uint32_t *hdr = def;
    hdr[0] = (uint32_t)size;
    hdr[1] = WS_DEF_MAGIC;
    return 1;
}

void ws_def_fill(void *def, size_t size, const void *full, size_t full_size)
{
    if (!def || size < WS_DEF_HEADER_SIZE)
        return;
    size_t n = size < full_size ? size : full_size;
    memcpy(def, full, n);
    if (size > n)
        memset((unsigned char *)def + n, 0, size - n);
    uint32_t hdr = (uint32_t)n;
    memcpy(def, &hdr, sizeof hdr);
}

int ws_def_check(const void *def)
{
    uint32_t hdr[2];
    if (!def)
        return -1;
    memcpy(hdr, def, sizeof hdr);
    if (hdr[1] != WS_DEF_MAGIC || hdr[0] < WS_DEF_HEADER_SIZE)
        return -1;
    return 0;
}

void ws_def_copy(void *dst, size_t full, const void *src)
{
    uint32_t size;
    memcpy(&size, src, sizeof size);
    memcpy(dst, src, size < full ? size : full);
    uint32_t hdr = (uint32_t)full;
    memcpy(dst, &hdr, sizeof hdr);
}

/* A 64-bit finaliser (splitmix64's): every input bit moves about half of the output bits. */
static uint64_t mix64(uint64_t x)
{
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    x ^= x >> 31;
    return x;
}

uint32_t ws_id_salt(const void *world)
{
    /* Two worlds made one after the other at the same address differ in the wall clock, read
     * to the nanosecond; the processor clock and a stack address add what they can. */
    struct timespec ts = {0, 0};
    (void)timespec_get(&ts, TIME_UTC);
    uint64_t h = mix64((uint64_t)(uintptr_t)world);
    h = mix64(h ^ (uint64_t)ts.tv_sec);
    h = mix64(h ^ (uint64_t)ts.tv_nsec);
    h = mix64(h ^ (uint64_t)clock());
    h = mix64(h ^ (uint64_t)(uintptr_t)&ts);
    return (uint32_t)(h ^ (h >> 32));
}

uint32_t ws_slots_first_generation(const ws_slot_table *t, uint32_t slot)
{
    uint64_t h = mix64(((uint64_t)t->salt << 32) | slot);
    return (uint32_t)(h ^ (h >> 32));
}

void ws_slots_destroy(ws_mem *mem, ws_slot_table *t)
{
    ws_mem_free(mem, t->dense, t->capacity * sizeof *t->dense);
    ws_mem_free(mem, t->generation, t->capacity * sizeof *t->generation);
    ws_mem_free(mem, t->free_list, t->capacity * sizeof *t->free_list);
    uint32_t salt = t->salt;
    memset(t, 0, sizeof *t);
    t->salt = salt;
}

int ws_slots_take(ws_mem *mem, ws_slot_table *t, uint32_t *slot)
{
    if (t->free_count > 0) {
        *slot = t->free_list[--t->free_count];
        return 0;
    }
    if (t->slot_count >= WS_ID_MAX_SLOTS)
        return -1;
    if (t->slot_count == t->capacity) {
        size_t cap = t->capacity ? 2 * t->capacity : 16;
        uint32_t *d = ws_mem_alloc(mem, cap * sizeof *d);
        uint32_t *g = ws_mem_alloc(mem, cap * sizeof *g);
        uint32_t *f = ws_mem_alloc(mem, cap * sizeof *f);
        if (!d || !g || !f) {
            ws_mem_free(mem, d, d ? cap * sizeof *d : 0);
            ws_mem_free(mem, g, g ? cap * sizeof *g : 0);
            ws_mem_free(mem, f, f ? cap * sizeof *f : 0);
            return -1;
        }
        if (t->capacity) {
            memcpy(d, t->dense, t->capacity * sizeof *d);
            memcpy(g, t->generation, t->capacity * sizeof *g);
            memcpy(f, t->free_list, t->free_count * sizeof *f);
        }
        ws_mem_free(mem, t->dense, t->capacity * sizeof *d);
        ws_mem_free(mem, t->generation, t->capacity * sizeof *g);
        ws_mem_free(mem, t->free_list, t->capacity * sizeof *f);
        t->dense = d;
        t->generation = g;
        t->free_list = f;
        t->capacity = cap;
    }
    *slot = (uint32_t)t->slot_count;
    t->generation[*slot] = ws_slots_first_generation(t, *slot);
    t->dense[*slot] = UINT32_MAX;
    t->slot_count++;
    return 0;
}

void ws_slots_release(ws_slot_table *t, uint32_t slot)
{
    t->dense[slot] = UINT32_MAX;
    t->generation[slot]++; /* modulo 2^32 */
    /* Back at the first generation: every id this slot could carry has been used; reusing it
     * would let a long-dead id name the new occupant. */
    if (t->generation[slot] == ws_slots_first_generation(t, slot)) {
        t->retired++;
        return;
    }
    t->free_list[t->free_count++] = slot;
}

uint64_t ws_hash_bytes(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

int ws_is_finite3(const ws_vec3 *v)
{
    return isfinite(v->x) && isfinite(v->y) && isfinite(v->z);
}
