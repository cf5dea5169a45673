/* Ids (lib/base/base.h): a destroyed id never names a live object, whatever the number of
 * create/destroy cycles of its slot, and an id of one world is refused by another. Links the
 * internals to set a slot's generation next to the end of its cycle. */
#include "helpers.h"
#include "world/world_internal.h"

#include <stdint.h>

static ws_body_id make_box(ws_world *w, ws_shape_id s)
{
    ws_body_def d;
    ws_body_def_init(&d);
    d.shape = s;
    d.mass = 1.0;
    ws_body_id b;
    ck_ok(w, ws_body_create(w, &d, &b));
    return b;
}

/* A slot whose generation comes back to its first value is retired: the ids of its earlier
 * occupants stay stale however long the world runs. */
START_TEST(test_generation_wrap)
{
    ws_world *w = new_world(2.5e-4);
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &s));
    ws_body_id a = make_box(w, s);
    uint32_t slot = ws_id_slot(a.bits);
    ws_slot_table *t = &w->body_slots;
    uint32_t first = ws_slots_first_generation(t, slot);
    ck_assert_uint_eq(ws_id_gen(a.bits), first);
    ck_ok(w, ws_body_destroy(w, a));

    /* As if the slot had been through 2^32 - 2 more cycles: its next occupant has the last
     * generation before the first comes round again (the internal hook). */
    t->generation[slot] = first - 1u;
    ws_body_id b = make_box(w, s);
    ck_assert_uint_eq(ws_id_slot(b.bits), slot);
    ck_assert_uint_eq(ws_id_gen(b.bits), first - 1u);
    ck_assert_int_eq(ws_body_is_valid(w, a), 0);
    ck_ok(w, ws_body_destroy(w, b));
    ck_assert_uint_eq(t->retired, 1);

    /* The next bodies take other slots: a's generation would come round in slot `slot`. */
    for (int k = 0; k < 1000; k++) {
        ws_body_id c = make_box(w, s);
        ck_assert_uint_ne(ws_id_slot(c.bits), slot);
        ck_assert_int_eq(ws_body_is_valid(w, a), 0);
        ck_assert_int_eq(ws_body_is_valid(w, b), 0);
        ws_vec3 p;
        ck_assert_int_eq(ws_body_get_position(w, a, &p), WS_ERR_STALE_HANDLE);
        ck_assert_ptr_nonnull(strstr(ws_world_last_error(w), "no live body"));
        ck_ok(w, ws_body_destroy(w, c));
    }
    ck_ok(w, ws_shape_destroy(w, s));
    ws_world_destroy(w);
}
END_TEST

/* Ids of 600 worlds alive at once, each tried in every other world: at most one is accepted.
 * With 16-bit world tags about 2.7 pairs of these worlds shared a tag (600^2 / 2 / 2^16), each
 * pair accepting both ways' body and material ids: about 11 accepted. With salted 32-bit
 * generations the expected count over the 718800 look-ups is 1.7e-4, so one accepted id is
 * allowed (two or more: about 1.4e-8 of runs), and the test cannot fail by chance in practice. */
START_TEST(test_foreign_ids)
{
    enum { N = 600 };
    static ws_world *w[N];
    static ws_body_id b[N];
    static ws_material_id m[N];
    for (int i = 0; i < N; i++) {
        w[i] = new_world(2.5e-4);
        ws_shape_id s;
        ck_ok(w[i], ws_shape_create_box(w[i], 0.1, 0.1, 0.1, &s));
        b[i] = make_box(w[i], s);
        ck_ok(w[i], ws_world_get_default_material(w[i], &m[i]));
    }
    long accepted = 0, tried = 0;
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            if (i == j)
                continue;
            accepted += ws_body_is_valid(w[j], b[i]) + ws_material_is_valid(w[j], m[i]);
            tried += 2;
        }
    report("ids: %d worlds alive, %ld foreign look-ups, %ld accepted", N, tried, accepted);
    ck_assert_int_le(accepted, 1);
    ws_vec3 p;
    ck_assert_int_eq(ws_body_get_position(w[1], b[0], &p), WS_ERR_STALE_HANDLE);
    ck_assert_ptr_nonnull(strstr(ws_world_last_error(w[1]), "another world"));
    for (int i = 0; i < N; i++)
        ws_world_destroy(w[i]);
}
END_TEST

/* A world made where the last one was (same address, same second): the ids of the dead world
 * are refused and the salt differs. */
START_TEST(test_same_address_worlds)
{
    ws_world *prev = new_world(2.5e-4);
    ws_shape_id s;
    ck_ok(prev, ws_shape_create_box(prev, 0.1, 0.1, 0.1, &s));
    ws_body_id old = make_box(prev, s);
    uint32_t prev_salt = prev->body_slots.salt;
    uintptr_t prev_addr = (uintptr_t)prev;
    int same_address = 0;
    for (int k = 0; k < 1000; k++) {
        ws_world_destroy(prev);
        ws_world *w = new_world(2.5e-4);
        same_address += (uintptr_t)w == prev_addr;
        ck_assert_uint_ne(w->body_slots.salt, prev_salt);
        ck_ok(w, ws_shape_create_box(w, 0.1, 0.1, 0.1, &s));
        ws_body_id now = make_box(w, s);
        ck_assert_int_eq(ws_body_is_valid(w, old), 0);
        prev = w;
        prev_salt = w->body_slots.salt;
        prev_addr = (uintptr_t)w;
        old = now;
    }
    report("ids: 1000 worlds made one after the other, %d at the address of the last; every "
           "salt differed from the last and no id of the dead world was accepted",
           same_address);
    ws_world_destroy(prev);
}
END_TEST

/* The id layout: kind in the top 4 bits, the whole 32-bit generation, the slot + 1 below. */
START_TEST(test_id_layout)
{
    uint64_t id = ws_id_pack(WS_KIND_WEB, 0xFFFFFFFFu, WS_ID_MAX_SLOTS - 1u);
    ck_assert_uint_eq(ws_id_kind(id), WS_KIND_WEB);
    ck_assert_uint_eq(ws_id_gen(id), 0xFFFFFFFFu);
    ck_assert_uint_eq(ws_id_slot(id), WS_ID_MAX_SLOTS - 1u);
    ck_assert_uint_eq(ws_id_slot(ws_id_pack(WS_KIND_BODY, 0, 0)), 0);
    ck_assert(ws_id_pack(WS_KIND_BODY, 0, 0) != 0); /* never the null id */
    ck_assert_uint_eq(ws_id_slot(0), UINT32_MAX);
}
END_TEST

static Suite *ids_suite(void)
{
    Suite *s = suite_create("ids");
    add_case(s, "generation_wrap", test_generation_wrap, 20);
    add_case(s, "foreign_ids", test_foreign_ids, 60);
    add_case(s, "same_address_worlds", test_same_address_worlds, 60);
    add_case(s, "id_layout", test_id_layout, 10);
    return s;
}

int main(void)
{
    return run_suite(ids_suite());
}
