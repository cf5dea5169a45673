/* Checkpoint and restart: a world's state saved to memory or a file and restored. What the
 * state is, and how each piece is checked, is the world's walk (world/world_state.c); this file
 * is the format around it: header, version, byte order, checksum, files. */
#include "world/world_internal.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#define HEADER 32
static const unsigned char magic[8] = {'W', 'S', 'S', 'T', 'A', 'T', 'E', 0};
#define BOM 0x01020304u

static void put32(unsigned char *b, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        b[i] = (unsigned char)(v >> (8 * i));
}

static void put64(unsigned char *b, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
}

static uint32_t get32(const unsigned char *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static uint64_t get64(const unsigned char *b)
{
    return (uint64_t)get32(b) | (uint64_t)get32(b + 4) << 32;
}

ws_status ws_world_save(const ws_world *world, void *buf, size_t cap, size_t *needed)
{
    NEED_WORLD(world);
    NEED_OUT(world, needed, "ws_world_save");
    ws_world *w = (ws_world *)world; /* the write walk only reads the world */
    if (!buf && cap)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_world_save: buffer is NULL but capacity is %zu", cap);
    ws_walk k = {WS_WALK_WRITE, 0, NULL, NULL, 0, 0, WS_OK, NULL, 0};
    ws_world_walk(w, &k);
    *needed = HEADER + k.pos;
    if (!buf)
        return WS_OK;
    if (cap < *needed)
        return ws_fail(w, WS_ERR_BUFFER_TOO_SMALL, "ws_world_save: room for %zu bytes, it needs %zu",
                       cap, *needed);
    unsigned char *b = buf;
    k = (ws_walk){WS_WALK_WRITE, 0, b + HEADER, NULL, 0, 0, WS_OK, NULL, 0};
    ws_world_walk(w, &k);
    memcpy(b, magic, sizeof magic);
    put32(b + 8, WS_SAVE_FORMAT_VERSION);
    put32(b + 12, BOM);
    put64(b + 16, k.pos);
    put64(b + 24, ws_hash_bytes(WS_HASH_SEED, b + HEADER, k.pos));
    return WS_OK;
}

ws_status ws_world_restore(ws_world *w, const void *buf, size_t len)
{
    NEED_WORLD(w);
    if (!buf)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_world_restore: buffer is NULL");
    const unsigned char *b = buf;
    if (len < HEADER)
        return ws_fail(w, WS_ERR_FORMAT,
                       "saved state: truncated: %zu bytes, a save has at least %d (its header)",
                       len, HEADER);
    if (memcmp(b, magic, sizeof magic) != 0)
        return ws_fail(w, WS_ERR_FORMAT,
                       "saved state: not a saved libwrapsim state (its first bytes are not "
                       "\"WSSTATE\")");
    uint32_t version = get32(b + 8), bom = get32(b + 12);
    if (bom != BOM)
        return ws_fail(w, WS_ERR_FORMAT,
                       "saved state: byte-order mark 0x%08x, not 0x%08x: this library reads "
                       "little-endian saves only",
                       bom, BOM);
    if (version > WS_SAVE_FORMAT_VERSION)
        return ws_fail(w, WS_ERR_FORMAT,
                       "saved state: version %u is newer than this library's %d", version,
                       WS_SAVE_FORMAT_VERSION);
    if (version == 0)
        return ws_fail(w, WS_ERR_FORMAT, "saved state: version 0 does not exist");
    uint64_t plen = get64(b + 16), sum = get64(b + 24);
    if (plen != len - HEADER)
        return ws_fail(w, WS_ERR_FORMAT,
                       "saved state: %s: the header gives %llu bytes of state, the buffer holds "
                       "%zu",
                       plen > len - HEADER ? "truncated" : "trailing bytes",
                       (unsigned long long)plen, len - HEADER);
    uint64_t have = ws_hash_bytes(WS_HASH_SEED, b + HEADER, (size_t)plen);
    if (have != sum)
        return ws_fail(w, WS_ERR_FORMAT,
                       "saved state: checksum mismatch (stored %016llx, computed %016llx): the "
                       "save is corrupted",
                       (unsigned long long)sum, (unsigned long long)have);
    /* Check all of it against the world, then write it: nothing changes unless all is good. */
    ws_walk k = {WS_WALK_CHECK, 0, NULL, b + HEADER, 0, (size_t)plen, WS_OK, NULL, version};
    ws_status s = ws_world_walk(w, &k);
    if (s != WS_OK)
        return s;
    k = (ws_walk){WS_WALK_READ, 0, NULL, b + HEADER, 0, (size_t)plen, WS_OK, NULL, version};
    return ws_world_walk(w, &k);
}

ws_status ws_world_save_file(const ws_world *world, const char *path)
{
    NEED_WORLD(world);
    ws_world *w = (ws_world *)world;
    if (!path || !*path)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "ws_world_save_file: the path is NULL or empty");
    size_t n;
    ws_status s = ws_world_save(world, NULL, 0, &n);
    if (s != WS_OK)
        return s;
    size_t plen = strlen(path);
    unsigned char *buf = ws_mem_alloc(&w->mem, n);
    char *tmp = ws_mem_alloc(&w->mem, plen + 5);
    if (!buf || !tmp) {
        ws_mem_free(&w->mem, buf, buf ? n : 0);
        ws_mem_free(&w->mem, tmp, tmp ? plen + 5 : 0);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_world_save_file: out of memory (%zu bytes)",
                       n);
    }
    memcpy(tmp, path, plen);
    memcpy(tmp + plen, ".tmp", 5);
    s = ws_world_save(world, buf, n, &n);
    FILE *f = s == WS_OK ? fopen(tmp, "wb") : NULL;
    if (s == WS_OK && !f) {
        s = ws_fail(w, WS_ERR_IO, "ws_world_save_file: cannot open '%s' for writing: %s", tmp,
                    strerror(errno));
    } else if (f) {
        int bad = fwrite(buf, 1, n, f) != n;
        bad |= fclose(f) != 0;
        if (bad) {
            s = ws_fail(w, WS_ERR_IO, "ws_world_save_file: cannot write '%s': %s", tmp,
                        strerror(errno));
            remove(tmp);
        } else if (rename(tmp, path) != 0) {
            s = ws_fail(w, WS_ERR_IO, "ws_world_save_file: cannot rename '%s' to '%s': %s", tmp,
                        path, strerror(errno));
            remove(tmp);
        }
    }
    ws_mem_free(&w->mem, buf, n);
    ws_mem_free(&w->mem, tmp, plen + 5);
    return s;
}

ws_status ws_world_restore_file(ws_world *w, const char *path)
{
    NEED_WORLD(w);
    if (!path || !*path)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_world_restore_file: the path is NULL or empty");
    FILE *f = fopen(path, "rb");
    if (!f)
        return ws_fail(w, WS_ERR_IO, "ws_world_restore_file: cannot open '%s': %s", path,
                       strerror(errno));
    /* Read it whole, growing the buffer: a size from seeking is not portable to pipes. */
    size_t cap = 1 << 16, n = 0;
    unsigned char *buf = ws_mem_alloc(&w->mem, cap);
    ws_status s = WS_OK;
    while (buf) {
        n += fread(buf + n, 1, cap - n, f);
        if (n < cap)
            break;
        unsigned char *more = ws_mem_realloc(&w->mem, buf, cap, 2 * cap);
        if (!more) {
            ws_mem_free(&w->mem, buf, cap);
            buf = NULL;
            break;
        }
        buf = more;
        cap *= 2;
    }
    if (!buf)
        s = ws_fail(w, WS_ERR_OUT_OF_MEMORY, "ws_world_restore_file: out of memory reading '%s'",
                    path);
    else if (ferror(f))
        s = ws_fail(w, WS_ERR_IO, "ws_world_restore_file: cannot read '%s'", path);
    fclose(f);
    if (s == WS_OK)
        s = ws_world_restore(w, buf, n);
    if (s != WS_OK && s != WS_ERR_OUT_OF_MEMORY && s != WS_ERR_IO) {
        /* Name the file in the reason. */
        char keep[WS_ERR_LEN];
        memcpy(keep, w->err, sizeof keep);
        ws_fail(w, s, "'%s': %s", path, keep);
    }
    if (buf)
        ws_mem_free(&w->mem, buf, cap);
    return s;
}
