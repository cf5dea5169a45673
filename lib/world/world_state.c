/* One walk over every piece of a world's state that its future depends on: the state hash
 * (ws_world_get_state_hash) and the saved state (lib/io/save.c) are both this walk, so the two
 * cannot disagree on what the state is. The walk writes little-endian bytes, reads them back
 * checking every count and index against the world's structure, and then writes them into the
 * world. What it leaves out is the structure the program builds (shapes, bodies, webs,
 * elements, laws, materials and their parameters) and scratch a step rebuilds. */
#include "world/world_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define HASHED 1 /* the item is part of the state hash */
#define NOIDX UINT32_MAX

static int failed(const ws_walk *k)
{
    return k->status != WS_OK;
}

static int reading(const ws_walk *k)
{
    return k->mode == WS_WALK_CHECK || k->mode == WS_WALK_READ;
}

static void fail(ws_walk *k, ws_status s, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void fail(ws_walk *k, ws_status s, const char *fmt, ...)
{
    if (failed(k))
        return;
    char buf[WS_ERR_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    k->status = ws_fail(k->w, s, "saved state: %s", buf);
}

/* n bytes of the saved state from here, or NULL (and the walk failed) when it ends first. */
static const unsigned char *take(ws_walk *k, size_t n)
{
    if (failed(k))
        return NULL;
    if (k->len - k->pos < n) {
        fail(k, WS_ERR_FORMAT, "truncated: %zu bytes of state, an item at byte %zu needs %zu",
             k->len, k->pos, n);
        return NULL;
    }
    const unsigned char *p = k->in + k->pos;
    k->pos += n;
    return p;
}

static void enc64(unsigned char *b, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
}

static uint64_t dec64(const unsigned char *b)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = (v << 8) | b[i];
    return v;
}

static void enc32(unsigned char *b, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        b[i] = (unsigned char)(v >> (8 * i));
}

static uint32_t dec32(const unsigned char *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

/* Bytes leaving the world: into the buffer (WRITE; counted only without one) or the hash. */
static void emit(ws_walk *k, const unsigned char *b, size_t n, int hashed)
{
    if (k->mode == WS_WALK_HASH) {
        if (hashed)
            k->hash = ws_hash_bytes(k->hash, b, n);
        return;
    }
    if (k->out)
        memcpy(k->out + k->pos, b, n);
    k->pos += n;
}

/* n doubles at p, little-endian (the bits of each, so the walk is exact). */
static void f64s(ws_walk *k, double *p, size_t n, int hashed)
{
    if (failed(k) || (k->mode == WS_WALK_HASH && !hashed) || n == 0) /* p may be NULL then */
        return;
    if (reading(k)) {
        const unsigned char *b = take(k, 8 * n);
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
        if (b && k->mode == WS_WALK_READ && n)
            memcpy(p, b, 8 * n);
        return;
#endif
        if (b && k->mode == WS_WALK_READ)
            for (size_t i = 0; i < n; i++) {
                uint64_t u = dec64(b + 8 * i);
                memcpy(&p[i], &u, sizeof u);
            }
        return;
    }
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    /* The doubles' bytes in memory are the little-endian bytes already. */
    emit(k, (const unsigned char *)p, 8 * n, hashed);
    return;
#endif
    unsigned char chunk[8 * 64];
    for (size_t i0 = 0; i0 < n; i0 += 64) {
        size_t m = n - i0 < 64 ? n - i0 : 64;
        for (size_t i = 0; i < m; i++) {
            uint64_t u;
            memcpy(&u, &p[i0 + i], sizeof u);
            enc64(chunk + 8 * i, u);
        }
        emit(k, chunk, 8 * m, hashed);
    }
}

/* n flags at p, a byte each: 0 or 1 in the file. */
static void flags(ws_walk *k, uint8_t *p, size_t n, int hashed, const char *what)
{
    if (failed(k) || (k->mode == WS_WALK_HASH && !hashed) || n == 0)
        return;
    if (!reading(k)) {
        emit(k, p, n, hashed);
        return;
    }
    const unsigned char *b = take(k, n);
    if (!b)
        return;
    for (size_t i = 0; i < n; i++)
        if (b[i] > 1) {
            fail(k, WS_ERR_FORMAT, "%s %zu is %u in the file; it must be 0 or 1", what, i, b[i]);
            return;
        }
    if (k->mode == WS_WALK_READ)
        memcpy(p, b, n);
}

static void v3s(ws_walk *k, v3 *p, int hashed)
{
    f64s(k, &p->x, 1, hashed);
    f64s(k, &p->y, 1, hashed);
    f64s(k, &p->z, 1, hashed);
}

static void qts(ws_walk *k, qt *p, int hashed)
{
    f64s(k, &p->e0, 1, hashed);
    f64s(k, &p->e1, 1, hashed);
    f64s(k, &p->e2, 1, hashed);
    f64s(k, &p->e3, 1, hashed);
}

/* A 32-bit number: u32v and u64v read into *p in a check as well, so p is a copy there. */
static void u32v(ws_walk *k, uint32_t *p)
{
    if (failed(k) || k->mode == WS_WALK_HASH)
        return;
    if (reading(k)) {
        const unsigned char *b = take(k, 4);
        if (b)
            *p = dec32(b);
        return;
    }
    unsigned char b[4];
    enc32(b, *p);
    emit(k, b, 4, 0);
}

static void u64v(ws_walk *k, uint64_t *p)
{
    if (failed(k) || k->mode == WS_WALK_HASH)
        return;
    if (reading(k)) {
        const unsigned char *b = take(k, 8);
        if (b)
            *p = dec64(b);
        return;
    }
    unsigned char b[8];
    enc64(b, *p);
    emit(k, b, 8, 0);
}

/* An int that is 0 or 1 (a flag) or below `below`. */
static void intv(ws_walk *k, int *p, uint32_t below, const char *what)
{
    uint32_t u = (uint32_t)*p;
    u32v(k, &u);
    if (!reading(k) || failed(k))
        return;
    if (u >= below) {
        fail(k, WS_ERR_FORMAT, "%s is %u in the file, it must be below %u", what, u, below);
        return;
    }
    *p = (int)u;
}

/* A number of the structure: the file must have the world's. "web 2 has 5856 nodes in the
 * file, 100 here". */
static int same(ws_walk *k, uint64_t here, const char *obj, uint32_t index, const char *what)
{
    uint64_t v = here;
    u64v(k, &v);
    if (failed(k))
        return -1;
    if (v == here)
        return 0;
    char who[64];
    if (index == NOIDX)
        snprintf(who, sizeof who, "%s", obj);
    else
        snprintf(who, sizeof who, "%s %u", obj, index);
    fail(k, WS_ERR_FORMAT,
         "%s has %llu %s in the file, %llu here (restore into a world built as the saved one "
         "was)",
         who, (unsigned long long)v, what, (unsigned long long)here);
    return -1;
}

/* The length of a list of items `each` bytes long in the file: written, then read and bounded
 * by `most` and by what is left of the state (so a wrong count asks for no memory). */
static void count(ws_walk *k, size_t *n, size_t most, size_t each, const char *what)
{
    uint64_t v = *n;
    u64v(k, &v);
    if (!reading(k) || failed(k))
        return;
    if (v > (k->len - k->pos) / each) {
        fail(k, WS_ERR_FORMAT, "%s: %llu in the file, more than its %zu bytes left can hold",
             what, (unsigned long long)v, k->len - k->pos);
        return;
    }
    if (v > most) {
        fail(k, WS_ERR_FORMAT, "%s: %llu in the file, more than the %zu this world can have",
             what, (unsigned long long)v, most);
        return;
    }
    *n = (size_t)v;
}

/* Room for what a read will write, taken while checking: growing an array changes no state,
 * so a check that fails later leaves the world as it was. */
static void room(ws_walk *k, void **arr, size_t *cap, size_t need, size_t elem)
{
    if (k->mode != WS_WALK_CHECK || failed(k))
        return;
    if (ws_array_reserve(&k->w->mem, arr, cap, need, elem) != 0)
        fail(k, WS_ERR_OUT_OF_MEMORY, "out of memory for %zu items of %zu bytes", need, elem);
}

static int body_ok(const ws_world *w, uint32_t slot)
{
    return slot < w->bodies.slots && w->bodies.alive[slot];
}

/* ---- the world's clock, bodies and body contacts ---- */

static void walk_bodies(ws_walk *k)
{
    ws_world *w = k->w;
    ws_body_store *b = &w->bodies;
    ws_body_state *st = &b->st[w->cur];
    if (same(k, b->slots, "the world", NOIDX, "body slots"))
        return;
    for (uint32_t i = 0; i < b->slots && !failed(k); i++) {
        if (same(k, b->alive[i], "body", i, "as its alive flag (1: alive, 0: destroyed)"))
            return;
        if (!b->alive[i])
            continue;
        const ws_shape *sh = b->shape[i];
        if (same(k, b->type[i], "body", i, "as its type (0 dynamic, 1 kinematic)") ||
            same(k, sh->vertex_count, "body", i, "shape vertices") ||
            same(k, sh->face_count, "body", i, "shape faces") ||
            same(k, sh->edge_count, "body", i, "shape edges"))
            return;
        v3s(k, &st->r[i], HASHED);
        qts(k, &st->p[i], HASHED);
        v3s(k, &st->v[i], HASHED);
        v3s(k, &st->w[i], HASHED);
    }
}

static void check_cand(ws_walk *k, const ws_cand *c, size_t q)
{
    const ws_world *w = k->w;
    const ws_body_store *b = &w->bodies;
    int ok = body_ok(w, c->a) && body_ok(w, c->b) && c->a != c->b && c->anchored <= 1;
    if (ok && c->kind == WS_CONTACT_POINT_FACE)
        ok = c->fa < b->shape[c->a]->face_count && c->fb < b->shape[c->b]->vertex_count;
    else if (ok && c->kind == WS_CONTACT_EDGE_EDGE)
        ok = c->fa < b->shape[c->a]->edge_count && c->fb < b->shape[c->b]->edge_count;
    else
        ok = 0;
    if (!ok)
        fail(k, WS_ERR_FORMAT,
             "contact candidate %zu (bodies %u, %u, kind %u, features %u, %u) names no "
             "feature pair of this world",
             q, c->a, c->b, c->kind, c->fa, c->fb);
}

static void walk_contacts(ws_walk *k)
{
    ws_world *w = k->w;
    const int cur = w->cur;
    /* Scalars of the world go through copies: a check reads them without writing. */
    uint64_t steps = w->steps, last_full = w->last_full_step;
    int valid = w->cand_valid;
    u64v(k, &steps);
    u64v(k, &last_full);
    intv(k, &valid, 2, "the contact cache's valid flag");
    if (k->mode == WS_WALK_CHECK && !failed(k) && last_full > steps)
        fail(k, WS_ERR_FORMAT, "the last full detection (step %llu) is after the step count %llu",
             (unsigned long long)last_full, (unsigned long long)steps);
    if (k->mode == WS_WALK_READ) {
        w->steps = steps;
        w->last_full_step = last_full;
        w->cand_valid = valid;
        w->contact_check.valid = 0;
    }
    f64s(k, &w->travel, 1, 0);
    /* The candidate feature pairs, with the stick anchors (in the hash). */
    size_t nc = w->ncand[cur];
    count(k, &nc, SIZE_MAX / sizeof(ws_cand) / 2, 6 * 4 + 6 * 8, "contact candidates");
    room(k, (void **)&w->cand[cur], &w->capcand[cur], nc + 1, sizeof(ws_cand));
    for (size_t q = 0; q < nc && !failed(k); q++) {
        ws_cand c = reading(k) ? (ws_cand){0} : w->cand[cur][q];
        u32v(k, &c.a);
        u32v(k, &c.b);
        u32v(k, &c.fa);
        u32v(k, &c.fb);
        u32v(k, &c.kind);
        u32v(k, &c.anchored);
        v3s(k, &c.anchor_a, c.anchored ? HASHED : 0);
        v3s(k, &c.anchor_b, c.anchored ? HASHED : 0);
        if (k->mode == WS_WALK_CHECK)
            check_cand(k, &c, q);
        else if (k->mode == WS_WALK_READ)
            w->cand[cur][q] = c;
    }
    if (k->mode == WS_WALK_READ)
        w->ncand[cur] = nc;
    /* The contacts of the last step: what the contact and energy reports read. */
    size_t nr = w->nrec[cur];
    count(k, &nr, SIZE_MAX / sizeof(ws_contact_rec) / 2, 4 * 4 + 15 * 8, "contact records");
    room(k, (void **)&w->rec[cur], &w->caprec[cur], nr + 1, sizeof(ws_contact_rec));
    for (size_t q = 0; q < nr && !failed(k); q++) {
        ws_contact_rec r = reading(k) ? (ws_contact_rec){0} : w->rec[cur][q];
        u32v(k, &r.a);
        u32v(k, &r.b);
        u32v(k, &r.kind);
        u32v(k, &r.slipping);
        v3s(k, &r.x, 0);
        v3s(k, &r.n, 0);
        v3s(k, &r.ft, 0);
        v3s(k, &r.vt, 0);
        f64s(k, &r.overlap, 1, 0);
        f64s(k, &r.fn, 1, 0);
        f64s(k, &r.energy, 1, 0);
        if (k->mode == WS_WALK_CHECK && !(body_ok(w, r.a) && body_ok(w, r.b)))
            fail(k, WS_ERR_FORMAT, "contact record %zu names bodies %u, %u, not of this world",
                 q, r.a, r.b);
        else if (k->mode == WS_WALK_READ)
            w->rec[cur][q] = r;
    }
    if (k->mode == WS_WALK_READ)
        w->nrec[cur] = nr;
}

/* ---- webs ---- */

/* base: by body slot, where its faces (base[2 slot]) and edges (base[2 slot + 1]) start among
 * the features the step prepares (as ws_node_geometry numbers them). */
static void check_ncand(ws_walk *k, const ws_web *web, const ws_ncand *c, uint32_t prev_node,
                        size_t q, const uint32_t *base)
{
    const ws_world *w = k->w;
    int edge = (c->local & WS_NCAND_EDGE) != 0;
    uint32_t local = c->local & ~WS_NCAND_FLAGS;
    int ok = c->node < web->n && c->node >= prev_node && body_ok(w, c->body) &&
             local < (edge ? w->bodies.shape[c->body]->edge_count
                           : w->bodies.shape[c->body]->face_count) &&
             c->feat == base[2 * (size_t)c->body + (size_t)edge] + local;
    if (!ok)
        fail(k, WS_ERR_FORMAT,
             "node candidate %zu (node %u, body %u, feature %u) names no node-feature pair of "
             "this web, or is out of node order",
             q, c->node, c->body, local);
}

/* A candidate marked as a corner starts three of one node and body, two faces and the edge
 * between them on a flat convex shape (contact/node.c, mark_corner): the contacts read all
 * three, so a marked one must have them. c: the three. */
static int corner_ok(const ws_world *w, const ws_ncand *c)
{
    if (c[1].node != c[0].node || c[2].node != c[0].node || c[1].body != c[0].body ||
        c[2].body != c[0].body)
        return 0;
    const ws_shape *sh = w->bodies.shape[c[0].body];
    const uint32_t a = c[0].local, z = c[1].local, e = c[2].local;
    if (!sh->convex || !sh->flat || ((a | z) & (WS_NCAND_EDGE | WS_NCAND_INSIDE)) ||
        !(e & WS_NCAND_EDGE) || (z & WS_NCAND_CORNER) || (e & WS_NCAND_CORNER))
        return 0;
    const ws_edge *E = &sh->edges[e & ~WS_NCAND_FLAGS];
    const uint32_t fa = a & ~WS_NCAND_FLAGS, fz = z & ~WS_NCAND_FLAGS;
    return (E->f1 == fa && E->f2 == fz) || (E->f1 == fz && E->f2 == fa);
}

static void walk_track(ws_walk *k, ws_track *t)
{
    u32v(k, &t->body);
    intv(k, &t->near, 2, "a tracked body's near flag");
    intv(k, &t->axis, 3, "a tracked body's axis");
    v3s(k, &t->rho, 0);
    qts(k, &t->q, 0);
    f64s(k, &t->lo, 1, 0);
    f64s(k, &t->hi, 1, 0);
    f64s(k, &t->gap, 1, 0);
    f64s(k, &t->lever, 1, 0);
    t->rebase = 0; /* scratch of ws_node_moved */
    if (k->mode == WS_WALK_CHECK && !body_ok(k->w, t->body))
        fail(k, WS_ERR_FORMAT, "a web's detection record names body %u, not of this world",
             t->body);
}

/* Room for the per-body loads of a web over every body slot (as the step makes it): four new
 * arrays taken first, so that running out of memory leaves the old ones and their size. */
static void web_body_room(ws_walk *k, ws_web *web)
{
    ws_world *w = k->w;
    if (k->mode != WS_WALK_CHECK || failed(k) || web->bcap >= w->bodies.slots)
        return;
    size_t cap = w->bodies.capacity;
    v3 *a[4];
    int got = 0;
    for (; got < 4; got++)
        if (!(a[got] = ws_mem_calloc(&w->mem, cap, sizeof(v3))))
            break;
    if (got < 4) {
        while (got-- > 0)
            ws_mem_free(&w->mem, a[got], cap * sizeof(v3));
        fail(k, WS_ERR_OUT_OF_MEMORY, "out of memory for a web's loads on the bodies");
        return;
    }
    v3 **old[4] = {&web->bforce[0], &web->bforce[1], &web->bmoment[0], &web->bmoment[1]};
    for (int q = 0; q < 4; q++) {
        if (web->bcap)
            memcpy(a[q], *old[q], web->bcap * sizeof(v3));
        ws_mem_free(&w->mem, *old[q], web->bcap * sizeof(v3));
        *old[q] = a[q];
    }
    web->bcap = cap;
}

/* A web's contact with the bodies (contact/node.h, web->contact): its committed candidates,
 * the bodies they may name, the record of where the nodes were found (tracks, epochs). */
static void walk_node_contact(ws_walk *k, ws_web *web, uint32_t slot)
{
    ws_world *w = k->w;
    const ws_body_store *b = &w->bodies;
    ws_node_contact *C = web->contact;
    int list = C->list, refresh = C->refresh;
    intv(k, &list, 2, "a web's committed candidate list");
    intv(k, &refresh, 2, "a web's refresh flag");
    /* Which bodies the candidates may name, by body slot: the step prepares the features of
     * those alone, so a candidate of another would read features never prepared. A check
     * keeps them to test the candidates with. */
    size_t had = C->cbody_cap;
    room(k, (void **)&C->cbody, &C->cbody_cap, b->slots + 1, 1);
    if (k->mode == WS_WALK_CHECK && C->cbody_cap > had) /* a new body flag is clear */
        memset(C->cbody + had, 0, C->cbody_cap - had);
    /* A check's scratch: the flags as read, then where each body's features start. */
    uint8_t *named = NULL;
    const size_t scratch = (b->slots + 1) * (1 + 2 * sizeof(uint32_t)) + 4;
    if (k->mode == WS_WALK_CHECK && !failed(k) &&
        !(named = ws_mem_calloc(&w->mem, scratch, 1)))
        fail(k, WS_ERR_OUT_OF_MEMORY, "out of memory checking a web's candidates");
    uint32_t base[2] = {0, 0}, *bases = NULL;
    if (named) {
        bases = (uint32_t *)(void *)(named + ((b->slots + 1 + 3) & ~(size_t)3));
        for (size_t i = 0; i < b->slots; i++) {
            bases[2 * i] = base[0];
            bases[2 * i + 1] = base[1];
            if (b->alive[i]) {
                base[0] += b->shape[i]->face_count;
                base[1] += b->shape[i]->edge_count;
            }
        }
    }
    for (size_t i = 0; i < b->slots && !failed(k); i++) {
        int on = !reading(k) && i < C->cbody_cap && C->cbody[i];
        intv(k, &on, 2, "a web's body flag");
        if (k->mode == WS_WALK_READ)
            C->cbody[i] = (uint8_t)on;
        else if (named)
            named[i] = (uint8_t)on;
    }
    size_t nc = C->cand[C->list].n;
    count(k, &nc, SIZE_MAX / sizeof(ws_ncand) / 2, 4 * 4, "node candidates");
    room(k, (void **)&C->cand[list].c, &C->cand[list].cap, nc + 1, sizeof(ws_ncand));
    /* The contacts' room the step takes, for the candidates of each of its lanes
     * (world_step.c). */
    uint32_t prev = 0;
    ws_ncand last[3] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}}; /* the last three read */
    for (size_t q = 0; q < nc && !failed(k); q++) {
        ws_ncand c = reading(k) ? (ws_ncand){0} : C->cand[C->list].c[q];
        u32v(k, &c.node);
        u32v(k, &c.body);
        u32v(k, &c.feat);
        u32v(k, &c.local);
        if (k->mode == WS_WALK_CHECK) {
            check_ncand(k, web, &c, prev, q, bases);
            /* After a failed step the list may name bodies the flags no longer do; the next
             * step then finds every candidate again (refresh) and reads none of them. */
            if (!failed(k) && !refresh && !named[c.body])
                fail(k, WS_ERR_FORMAT, "node candidate %zu names body %u, which the web's "
                     "flags say it has no candidate of", q, c.body);
            last[0] = last[1];
            last[1] = last[2];
            last[2] = c;
            if (!failed(k) && q >= 2 && (last[0].local & WS_NCAND_CORNER) && !corner_ok(w, last))
                fail(k, WS_ERR_FORMAT, "node candidate %zu is marked a corner but is not one",
                     q - 2);
            if (!failed(k) && q + 2 >= nc && (c.local & WS_NCAND_CORNER))
                fail(k, WS_ERR_FORMAT, "node candidate %zu is marked a corner but is not one",
                     q);
        } else if (k->mode == WS_WALK_READ) {
            C->cand[list].c[q] = c;
        }
        prev = c.node;
    }
    f64s(k, C->xdet.x, 3 * (size_t)web->n, 0);
    f64s(k, C->xep.x, 3 * (size_t)web->n, 0);
    v3s(k, &C->box_lo, 0);
    v3s(k, &C->box_hi, 0);
    uint32_t ref = C->ref;
    u32v(k, &ref);
    if (k->mode == WS_WALK_CHECK && ref != UINT32_MAX && !body_ok(w, ref))
        fail(k, WS_ERR_FORMAT, "web %u's reference body %u is not of this world", slot, ref);
    size_t nt = C->ntrack;
    count(k, &nt, b->slots, 3 * 4 + 11 * 8, "a web's tracked bodies");
    room(k, (void **)&C->track, &C->track_cap, nt + 1, sizeof(ws_track));
    for (size_t q = 0; q < nt && !failed(k); q++) {
        ws_track t = reading(k) ? (ws_track){0} : C->track[q];
        walk_track(k, &t);
        if (k->mode == WS_WALK_READ)
            C->track[q] = t;
    }
    f64s(k, C->epoch_A.m, 9, 0);
    v3s(k, &C->epoch_r, 0);
    qts(k, &C->epoch_q, 0);
    f64s(k, &C->lever2, 1, 0);
    if (named)
        ws_mem_free(&w->mem, named, scratch);
    if (k->mode != WS_WALK_READ || failed(k))
        return;
    /* Read: what follows from the above. */
    for (size_t i = b->slots; i < C->cbody_cap; i++)
        C->cbody[i] = 0;
    C->list = list;
    C->next_list = list;
    C->refresh = refresh;
    C->cand[list].n = nc;
    C->ref = ref;
    C->ntrack = nt;
    ws_node_index(C->cand[list].c, nc, web->n, C->cstart[list]);
    C->seg_list = -1; /* the stretches are cut again from the list read */
}

/* A web's rupture: which springs are broken (in the hash) and the report of the first break.
 * Only a web given a rupture limit has it, so that a world without one hashes as before
 * rupture existed; a save of format 1 has none (restored: none broken). */
static void walk_rupture(ws_walk *k, ws_web *web, uint32_t slot)
{
    if (k->version == 1) {
        if (k->mode == WS_WALK_READ && web->broken) {
            memset(web->broken, 0, web->ns);
            web->nbroken = web->nbroken_step = 0;
            web->first_spring = UINT32_MAX;
        }
        return;
    }
    if (same(k, web->broken != NULL, "web", slot,
             "as its rupture flag (1: a rupture limit was set on it)") ||
        !web->broken)
        return;
    flags(k, web->broken, web->ns, HASHED, "a web's broken flag of spring");
    uint32_t step = web->nbroken_step, first = web->first_spring;
    double ft = web->first_time, fe = web->first_strain;
    v3 fa = web->first_at;
    u32v(k, &step);
    u32v(k, &first);
    f64s(k, &ft, 1, 0);
    f64s(k, &fe, 1, 0);
    v3s(k, &fa, 0);
    if (k->mode == WS_WALK_CHECK && !failed(k) &&
        (step > web->ns || (first != UINT32_MAX && first >= web->ns)))
        fail(k, WS_ERR_FORMAT,
             "web %u's rupture report names %u springs broken in the last step and spring %u "
             "first, of %u",
             slot, step, first, web->ns);
    if (k->mode != WS_WALK_READ || failed(k))
        return;
    ws_web_rupture_recount(web);
    web->nbroken_step = step;
    web->first_spring = first;
    web->first_time = ft;
    web->first_strain = fe;
    web->first_at = fa;
}

static void walk_web(ws_walk *k, ws_web *web, uint32_t slot)
{
    ws_world *w = k->w;
    const int cur = w->cur;
    const ws_body_store *b = &w->bodies;
    if (same(k, web->n, "web", slot, "nodes") || same(k, web->ns, "web", slot, "springs") ||
        same(k, web->nstate, "web", slot, "doubles of law history a spring"))
        return;
    /* The node state and the springs' law histories (in the hash). */
    f64s(k, web->x[cur].x, 3 * (size_t)web->n, HASHED);
    f64s(k, web->v[cur].x, 3 * (size_t)web->n, HASHED);
    f64s(k, web->hist, (size_t)web->ns * web->nstate, HASHED);
    walk_rupture(k, web, slot);
    /* The last step's contact forces on the nodes and loads on the bodies (reports). */
    f64s(k, &web->fc[cur][0].x, 3 * (size_t)web->n, 0);
    web_body_room(k, web);
    room(k, (void **)&web->fct[cur], &web->fct_cap[cur], (size_t)web->n + 1, sizeof(uint32_t));
    for (size_t i = 0; i < b->slots && !failed(k); i++) {
        v3 f = v3_make(0, 0, 0), m = f;
        if (!reading(k) && i < web->bcap && web->bforce[cur]) {
            f = web->bforce[cur][i];
            m = web->bmoment[cur][i];
        }
        v3s(k, &f, 0);
        v3s(k, &m, 0);
        if (k->mode == WS_WALK_READ) {
            web->bforce[cur][i] = f;
            web->bmoment[cur][i] = m;
        }
    }
    walk_node_contact(k, web, slot);
    if (k->mode != WS_WALK_READ || failed(k))
        return;
    /* Read: the nodes whose contact force may be non-zero, from the forces read. */
    web->nfct[cur] = 0;
    for (uint32_t i = 0; i < web->n; i++)
        if (web->fc[cur][i].x != 0.0 || web->fc[cur][i].y != 0.0 || web->fc[cur][i].z != 0.0)
            web->fct[cur][web->nfct[cur]++] = i;
}

static void walk_webs(ws_walk *k)
{
    ws_world *w = k->w;
    if (same(k, w->web_slots.slot_count, "the world", NOIDX, "web slots"))
        return;
    for (uint32_t s = 0; s < w->web_slots.slot_count && !failed(k); s++) {
        ws_web *web = s < w->web_cap && w->web_slots.dense[s] != UINT32_MAX ? w->webs[s] : NULL;
        if (same(k, web != NULL, "web", s, "as its alive flag (1: alive, 0: destroyed)"))
            return;
        if (web)
            walk_web(k, web, s);
    }
}

/* ---- elements ---- */

static void walk_elements(ws_walk *k)
{
    ws_world *w = k->w;
    if (same(k, w->element_slots.slot_count, "the world", NOIDX, "element slots"))
        return;
    for (uint32_t s = 0; s < w->element_slots.slot_count && !failed(k); s++) {
        ws_element *e = s < w->element_cap && w->element_slots.dense[s] != UINT32_MAX
                            ? w->elements[s]
                            : NULL;
        if (same(k, e != NULL, "element", s, "as its alive flag (1: alive, 0: destroyed)"))
            return;
        if (!e)
            continue;
        if (same(k, e->nstate, "element", s, "doubles of law history"))
            return;
        f64s(k, e->state, e->nstate, HASHED);
        f64s(k, &e->t_commit, 1, 0);
    }
}

ws_status ws_world_walk(ws_world *w, ws_walk *k)
{
    k->w = w;
    k->status = WS_OK;
    k->pos = 0;
    f64s(k, &w->time, 1, HASHED);
    walk_bodies(k);
    walk_contacts(k);
    walk_webs(k);
    walk_elements(k);
    if (reading(k) && !failed(k) && k->pos != k->len)
        fail(k, WS_ERR_FORMAT, "%zu bytes of state, %zu more than this world's state",
             k->len, k->len - k->pos);
    if (k->mode == WS_WALK_READ && !failed(k))
        w->web_check = 1; /* the stable step is checked again before the next step */
    return k->status;
}
