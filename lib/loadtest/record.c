/* The measurements of a load-test run, shared by every test (EUMOS 40509, tilt, impact,
 * vibration): per carton, layer and interface from the load and the contact reports, the events
 * (slip onset, tip onset, a carton leaving the load) and the running maxima. Through the public
 * API of the world, as load.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "loadtest/loadtest.h"
#include "math/wmath.h"
#include "world/world_internal.h"

void ws_lt_event(const ws_lt_sink *sk, int type, int layer, int index, double t, double level,
                 double value)
{
    if (*sk->event_count >= WS_LOADTEST_MAX_EVENTS) {
        (*sk->events_dropped)++;
        return;
    }
    ws_loadtest_event *e = &sk->events[(*sk->event_count)++];
    e->type = type;
    e->layer = layer;
    e->index = index;
    e->time = t;
    e->level = level;
    e->value = value;
}

void ws_lt_criterion(ws_loadtest_criterion *c, double value, double limit, int strict)
{
    c->value = value;
    c->limit = limit;
    c->pass = strict ? value < limit : value <= limit;
}

static double interface_mu(const ws_load *ld, int i)
{
    return ld->friction[i == 0 ? WS_IF_PALLET_PLATFORM
                               : (i == 1 ? WS_IF_CARTON_PALLET : WS_IF_CARTON_CARTON)];
}

/* The support force under each edge of a body from a contact at `point`. */
static ws_status bin_contact(const ws_world *w, const ws_load *ld, const ws_load_key *upper,
                             ws_vec3 point, double fn, double (*bins)[WS_LT_BINS])
{
    ws_body_id id = upper->body < 0 ? ld->info.pallet : ld->carton[upper->body].body;
    ws_vec3 r;
    ws_mat3 a;
    ws_status s;
    if ((s = ws_body_get_position(w, id, &r)) != WS_OK ||
        (s = ws_body_get_rotation(w, id, &a)) != WS_OK)
        return s;
    v3 o = m3_tmul_v(&a, v3_sub(point, r));
    v3 half = upper->body < 0 ? v3_scale(ld->pallet_size, 0.5) : v3_scale(ld->carton_shape, 0.5);
    double *b = bins[upper->body + 1];
    if (o.x > 0.25 * half.x)
        b[WS_LT_BIN_XP] += fn;
    if (o.x < -0.25 * half.x)
        b[WS_LT_BIN_XN] += fn;
    if (o.y > 0.25 * half.y)
        b[WS_LT_BIN_YP] += fn;
    if (o.y < -0.25 * half.y)
        b[WS_LT_BIN_YN] += fn;
    return WS_OK;
}

/* Sort the contacts into interfaces (neighbouring levels), the cartons' bases and the bases'
 * edges. */
static ws_status read_contacts(ws_world *w, ws_lt_run *rs)
{
    ws_load *ld = rs->ld;
    size_t n;
    ws_status s = ws_world_get_contact_count(w, &n);
    if (s != WS_OK)
        return s;
    if (n > rs->contacts_cap) {
        size_t cap = n + n / 2 + 16;
        void *p = ws_mem_realloc(&ld->mem, rs->contacts, rs->contacts_cap * sizeof *rs->contacts,
                                 cap * sizeof *rs->contacts);
        if (!p)
            return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "%s run: no room for %zu contacts",
                           rs->name, n);
        rs->contacts = p;
        rs->contacts_cap = cap;
    }
    if ((s = ws_world_copy_contacts(w, rs->contacts, rs->contacts_cap, &n)) != WS_OK)
        return s;
    int ni = ld->info.layers + 1, nc = ld->info.cartons;
    for (int i = 0; i < ni; i++) {
        memset(&rs->ifs[i], 0, sizeof rs->ifs[i]);
        rs->ifs_use[i] = 0;
    }
    memset(rs->base, 0, (size_t)nc * sizeof *rs->base);
    memset(rs->base_use, 0, (size_t)nc * sizeof *rs->base_use);
    memset(rs->bins, 0, (size_t)(nc + 1) * sizeof *rs->bins);
    for (size_t k = 0; k < n; k++) {
        const ws_contact_info *c = &rs->contacts[k];
        const ws_load_key *ka = ws_load_find(ld, c->body_a), *kb = ws_load_find(ld, c->body_b);
        if (!ka || !kb || abs(ka->level - kb->level) != 1)
            continue;
        const ws_load_key *lower = ka->level < kb->level ? ka : kb;
        const ws_load_key *upper = ka->level < kb->level ? kb : ka;
        ws_loadtest_interface_state *f = &rs->ifs[lower->level];
        double fn = c->normal_force, slip = v3_norm(c->slip_velocity);
        double ft = v3_norm(c->friction_force);
        f->normal_force += fn;
        f->slip_speed += fn * slip;
        rs->ifs_use[lower->level] += ft;
        f->contacts++;
        if (upper->body >= 0) {
            ws_loadtest_interface_state *b = &rs->base[upper->body];
            b->normal_force += fn;
            b->slip_speed += fn * slip;
            rs->base_use[upper->body] += ft;
            b->contacts++;
        }
        if ((s = bin_contact(w, ld, upper, c->point, fn, rs->bins)) != WS_OK)
            return s;
    }
    for (int i = 0; i < ni; i++) {
        ws_loadtest_interface_state *f = &rs->ifs[i];
        double mu = interface_mu(ld, i);
        f->friction_use = f->normal_force > 0 && mu > 0 ? rs->ifs_use[i] / (mu * f->normal_force)
                                                        : 0;
        f->slip_speed = f->normal_force > 0 ? f->slip_speed / f->normal_force : 0;
    }
    for (int c = 0; c < nc; c++) {
        ws_loadtest_interface_state *b = &rs->base[c];
        /* A carton's base is the interface of its layer: layer l rests on level l + 1. */
        double mu = interface_mu(ld, ld->carton[c].layer + 1);
        b->friction_use = b->normal_force > 0 && mu > 0
                              ? rs->base_use[c] / (mu * b->normal_force)
                              : 0;
        b->slip_speed = b->normal_force > 0 ? b->slip_speed / b->normal_force : 0;
    }
    return WS_OK;
}

/* Tip onset: an edge that carried more than 5 % of the body's support at the first sample now
 * carries less than tip_fraction of it while the body still rests on something. */
static void find_tips(ws_lt_run *rs, double t, double level)
{
    ws_load *ld = rs->ld;
    int nb = ld->info.cartons + 1;
    if (!rs->have_ref_bins) {
        memcpy(rs->ref_bins, rs->bins, (size_t)nb * sizeof *rs->bins);
        rs->have_ref_bins = 1;
        return;
    }
    for (int b = 0; b < nb; b++) {
        if (rs->tipped[b])
            continue;
        const double *now = rs->bins[b], *ref = rs->ref_bins[b];
        double tot_now = now[WS_LT_BIN_XP] + now[WS_LT_BIN_XN];
        double tot_ref = ref[WS_LT_BIN_XP] + ref[WS_LT_BIN_XN];
        double tot_y_now = now[WS_LT_BIN_YP] + now[WS_LT_BIN_YN];
        double tot_y_ref = ref[WS_LT_BIN_YP] + ref[WS_LT_BIN_YN];
        int tip = 0;
        for (int e = 0; e < WS_LT_BINS; e++) {
            double tn = e < 2 ? tot_now : tot_y_now, tr = e < 2 ? tot_ref : tot_y_ref;
            if (tr > 0 && ref[e] > 0.05 * tr && tn > 0.25 * tr && now[e] < rs->tip_fraction * tn)
                tip = 1;
        }
        if (tip) {
            rs->tipped[b] = 1;
            int layer = b == 0 ? -1 : ld->carton[b - 1].layer;
            int index = b == 0 ? -1 : ld->carton[b - 1].index;
            ws_lt_event(&rs->sink, WS_LOADTEST_TIP_ONSET, layer, index, t, level, 0);
        }
    }
}

/* The film: its peak strain over the intact springs, and the event of its first break in the
 * run, at the time it broke (the world's time then, counted back from this sample's t; the
 * event goes before this sample's others, which are at t). */
static ws_status film_sample(ws_world *w, ws_lt_run *rs, double t, double level)
{
    const ws_lt_sink *sk = &rs->sink;
    const ws_web_id film = rs->ld->info.film;
    ws_web_peak pk;
    ws_web_rupture ru;
    double now;
    ws_status s;
    if ((s = ws_web_get_peak_strain(w, film, &pk)) != WS_OK ||
        (s = ws_web_get_rupture(w, film, &ru)) != WS_OK || (s = ws_world_get_time(w, &now)) != WS_OK)
        return s;
    if (pk.found)
        *sk->film_peak_strain = fmax(*sk->film_peak_strain, pk.strain);
    if (!rs->ruptured && ru.broken_count > rs->broken) {
        rs->ruptured = 1;
        if (rs->broken_at_start == 0)
            ws_lt_event(sk, WS_LOADTEST_RUPTURE, -1, (int)ru.first_spring,
                        t - (now - ru.first_time), level, ru.first_strain);
        else
            ws_lt_event(sk, WS_LOADTEST_RUPTURE, -1, -1, t, level, (double)ru.broken_count);
    }
    rs->broken = ru.broken_count;
    return WS_OK;
}

ws_status ws_lt_sample(ws_world *w, ws_lt_run *rs, double t, double level, double v, double x,
                       double angle)
{
    ws_load *ld = rs->ld;
    const ws_lt_sink *sk = &rs->sink;
    size_t n;
    ws_status s = ws_load_measure(w, ld, rs->cs, (size_t)ld->info.cartons, &n);
    if (s != WS_OK || (s = read_contacts(w, rs)) != WS_OK)
        return s;
    if (ld->info.film.bits && (s = film_sample(w, rs, t, level)) != WS_OK)
        return s;
    if (fabs(level) > *sk->peak_level)
        *sk->peak_level = fabs(level);
    find_tips(rs, t, level);
    v3 dir = rs->dir;
    for (int l = 0; l < ld->info.layers; l++) {
        double sum = 0;
        int c0 = ld->layer_start[l], c1 = ld->layer_start[l + 1];
        for (int c = c0; c < c1; c++) {
            const ws_load_carton_state *cs = &rs->cs[c];
            sum += cs->displacement.x * dir.x + cs->displacement.y * dir.y +
                   cs->displacement.z * dir.z;
            sk->layer_max[l] = fmax(sk->layer_max[l], cs->horizontal);
            sk->layer_tilt[l] = fmax(sk->layer_tilt[l], cs->tilt);
            v3 rel = v3_add(ld->reference[c], cs->displacement);
            int off = fabs(rel.x) > 0.5 * ld->pallet_size.x ||
                      fabs(rel.y) > 0.5 * ld->pallet_size.y ||
                      cs->displacement.z < -0.5 * ld->carton[c].size.z;
            if (off && !rs->lost[c]) {
                rs->lost[c] = 1;
                (*sk->cartons_lost)++;
                ws_lt_event(sk, WS_LOADTEST_CARTON_LOST, l, ld->carton[c].index, t, level,
                            cs->horizontal);
            }
        }
        rs->layer_disp[l] = sum / (c1 - c0);
    }
    for (int i = 0; i <= ld->info.layers; i++) {
        const ws_loadtest_interface_state *f = &rs->ifs[i];
        sk->interface_slip_max[i] = fmax(sk->interface_slip_max[i], f->slip_speed);
        sk->interface_use_max[i] = fmax(sk->interface_use_max[i], f->friction_use);
        if (!rs->slipped[i] && f->slip_speed > rs->slip_speed) {
            rs->slipped[i] = 1;
            ws_lt_event(sk, WS_LOADTEST_SLIP_ONSET, i, -1, t, level, f->slip_speed);
        }
    }
    if (rs->on_sample) {
        ws_loadtest_sample sm;
        sm.time = t;
        sm.level = level;
        sm.platform_velocity = v;
        sm.platform_position = x;
        sm.cartons = n;
        sm.carton = rs->cs;
        sm.layers = ld->info.layers;
        sm.layer_displacement = rs->layer_disp;
        sm.interfaces = ld->info.layers + 1;
        sm.interface = rs->ifs;
        sm.angle = angle;
        sm.carton_base = rs->base;
        if (rs->on_sample(rs->sample_user, &sm) != 0)
            return ws_fail(w, WS_ERR_CALLBACK, "%s run: on_sample stopped the run at t = %g s",
                           rs->name, t);
    }
    return WS_OK;
}

void ws_lt_permanent(const ws_lt_run *rs, double *layer_permanent, double *bottom_out,
                     double *shift_out)
{
    const ws_load *ld = rs->ld;
    double bottom = 0, shift = 0;
    double prev_x = 0, prev_y = 0; /* the pallet's own displacement is zero by definition */
    for (int l = 0; l < ld->info.layers; l++) {
        double mx = 0, my = 0;
        int c0 = ld->layer_start[l], c1 = ld->layer_start[l + 1];
        for (int c = c0; c < c1; c++) {
            const ws_load_carton_state *cs = &rs->cs[c];
            if (layer_permanent)
                layer_permanent[l] = fmax(layer_permanent[l], cs->horizontal);
            if (ld->carton_bottom[c] < 0.2)
                bottom = fmax(bottom, cs->horizontal);
            mx += cs->displacement.x;
            my += cs->displacement.y;
        }
        mx /= c1 - c0;
        my /= c1 - c0;
        shift = fmax(shift, hypot(mx - prev_x, my - prev_y));
        prev_x = mx;
        prev_y = my;
    }
    if (bottom_out)
        *bottom_out = bottom;
    if (shift_out)
        *shift_out = shift;
}

void ws_lt_end(ws_lt_run *rs)
{
    ws_load *ld = rs->ld;
    size_t nb = (size_t)ld->info.cartons + 1;
    ws_mem_free(&ld->mem, rs->contacts, rs->contacts_cap * sizeof *rs->contacts);
    ws_mem_free(&ld->mem, rs->cs, (nb - 1) * sizeof *rs->cs);
    ws_mem_free(&ld->mem, rs->base, (nb - 1) * sizeof *rs->base);
    ws_mem_free(&ld->mem, rs->base_use, (nb - 1) * sizeof *rs->base_use);
    ws_mem_free(&ld->mem, rs->bins, nb * sizeof *rs->bins);
    ws_mem_free(&ld->mem, rs->ref_bins, nb * sizeof *rs->ref_bins);
    ws_mem_free(&ld->mem, rs->tipped, nb);
    ws_mem_free(&ld->mem, rs->lost, nb);
    rs->contacts = NULL;
    rs->cs = NULL;
    rs->base = NULL;
    rs->base_use = NULL;
    rs->bins = rs->ref_bins = NULL;
    rs->tipped = rs->lost = NULL;
    rs->contacts_cap = 0;
}

ws_status ws_lt_begin(ws_world *w, ws_lt_run *rs, ws_load *ld, const ws_lt_sink *sink,
                      const char *name)
{
    size_t nb = (size_t)ld->info.cartons + 1;
    rs->ld = ld;
    rs->sink = *sink;
    rs->name = name;
    rs->cs = ws_mem_calloc(&ld->mem, nb - 1, sizeof *rs->cs);
    rs->base = ws_mem_calloc(&ld->mem, nb - 1, sizeof *rs->base);
    rs->base_use = ws_mem_calloc(&ld->mem, nb - 1, sizeof *rs->base_use);
    rs->bins = ws_mem_calloc(&ld->mem, nb, sizeof *rs->bins);
    rs->ref_bins = ws_mem_calloc(&ld->mem, nb, sizeof *rs->ref_bins);
    rs->tipped = ws_mem_calloc(&ld->mem, nb, 1);
    rs->lost = ws_mem_calloc(&ld->mem, nb, 1);
    ws_web_rupture ru;
    if (ld->info.film.bits && ws_web_get_rupture(w, ld->info.film, &ru) == WS_OK)
        rs->broken = rs->broken_at_start = ru.broken_count; /* a break in the run is news */
    if (!rs->cs || !rs->base || !rs->base_use || !rs->bins || !rs->ref_bins || !rs->tipped ||
        !rs->lost) {
        ws_lt_end(rs);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "%s run: out of memory for %zu bodies", name,
                       nb);
    }
    return WS_OK;
}
