/* The spiral wrap of a stretch-wrapping machine (ws_load_wrap_spiral) and the read-outs of a
 * wrapped load: containment by height band and the film's peak strain.
 *
 * The film is one mesh web on a grid of nodes round the load: rows at heights up the load, each
 * following the load's outline at its height with a node on every vertical corner. Where the
 * spiral lays k layers, the springs and nodes there stand for k layers (the web's per-spring
 * stiffness scales and per-node masses). docs/theory.md, "The spiral wrap", gives the model. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <wrapsim/law.h>

#include "loadtest/loadtest.h"
#include "math/wmath.h"
#include "world/world_internal.h"

/* Samples a spring's or node's strip is averaged over, along each of its two directions. */
#define WRAP_SAMPLES 4
/* Layers a spring or node keeps where the spiral leaves no film (the web stays one piece). */
#define WRAP_MIN_LAYERS 0.1

static void spiral_defaults(ws_spiral_wrap_def *d)
{
    ws_def_reset(d, sizeof *d);
    d->width = 0.5;
    d->gauge = 20e-6;
    d->modulus = 150e6;
    d->density = 920.0;
    d->prestretch = 2.0;
    d->neck_in = 0.15;
    d->load_strain = 0.1;
    d->revolutions_bottom = 2.0;
    d->revolutions_top = 2.0;
    d->overlap = 0.5;
    d->passes = 2;
    d->pallet_lock = 1;
    d->lock_height = 0.05;
    d->top_margin = 0.02;
    d->rope_revolutions = 0.0;
    d->rope_height = 0.2;
    d->top_sheet = 0;
    d->top_sheet_gauge = 50e-6;
    d->node_pitch = 0.05;
    d->node_mass_min = 0.0;
    d->substeps = 0;
    d->elongation_at_break = 4.0;
    d->rupture_strain = 0.0;
}

/* The film's rupture strain from its rest length on the load (0: none): the given one, or the
 * elongation at break turned from the film off the roll to the film the pre-stretch left. */
static double spiral_rupture(const ws_spiral_wrap_def *d)
{
    if (d->rupture_strain > 0)
        return d->rupture_strain;
    if (d->elongation_at_break == 0)
        return 0;
    return (1 + d->elongation_at_break) / (1 + d->prestretch) - 1;
}

WS_DEF_INITS(ws_spiral_wrap_def, spiral_defaults, substeps)

static int in_range(double v, double lo, double hi) { return isfinite(v) && v >= lo && v <= hi; }

/* The field a Def gets wrong and why, or NULL. */
static const char *spiral_bad(const ws_spiral_wrap_def *d)
{
    if (!(isfinite(d->width) && d->width > 0 && d->width <= 10))
        return "width must be > 0 and <= 10 m";
    if (!(isfinite(d->gauge) && d->gauge > 0 && d->gauge <= 0.01))
        return "gauge must be > 0 and <= 0.01 m";
    if (!(isfinite(d->modulus) && d->modulus > 0 && d->modulus <= 1e12))
        return "modulus must be > 0 and <= 1e12 Pa";
    if (!(isfinite(d->density) && d->density > 0 && d->density <= 1e5))
        return "density must be > 0 and <= 1e5 kg/m^3";
    if (!in_range(d->prestretch, 0, 10))
        return "prestretch must be 0 .. 10 (0 .. 1000 %)";
    if (!in_range(d->neck_in, 0, 0.9))
        return "neck_in must be 0 .. 0.9";
    if (!(isfinite(d->load_strain) && d->load_strain > 0 && d->load_strain < 1))
        return "load_strain must be > 0 and < 1";
    if (!in_range(d->revolutions_bottom, 0, 1000) || !in_range(d->revolutions_top, 0, 1000))
        return "revolutions_bottom and revolutions_top must be 0 .. 1000";
    if (!in_range(d->overlap, 0, 0.95))
        return "overlap must be 0 .. 0.95";
    if (d->passes != 1 && d->passes != 2)
        return "passes must be 1 (up) or 2 (up and down)";
    if (d->pallet_lock != 0 && d->pallet_lock != 1)
        return "pallet_lock must be 0 or 1";
    if (!in_range(d->lock_height, 0, 1e3) || !in_range(d->top_margin, 0, 1e3))
        return "lock_height and top_margin must be >= 0 m";
    if (!in_range(d->rope_revolutions, 0, 1000))
        return "rope_revolutions must be 0 .. 1000";
    if (d->rope_revolutions > 0 && !(isfinite(d->rope_height) && d->rope_height > 0))
        return "rope_height must be > 0 m when there is roping";
    if (d->top_sheet != 0 && d->top_sheet != 1)
        return "top_sheet must be 0 or 1";
    if (!(isfinite(d->top_sheet_gauge) && d->top_sheet_gauge > 0 && d->top_sheet_gauge < 0.01))
        return "top_sheet_gauge must be > 0 and < 0.01 m";
    if (!(isfinite(d->node_pitch) && d->node_pitch > 0))
        return "node_pitch must be > 0 m";
    if (!in_range(d->node_mass_min, 0, 1e3))
        return "node_mass_min must be >= 0 kg";
    if (d->substeps < 0 || d->substeps > 100000)
        return "substeps must be 1 .. 100000, or 0 for the fewest the stable-step check accepts";
    if (d->integrator != WS_WEB_EXPLICIT && d->integrator != WS_WEB_IMPLICIT)
        return "integrator must be WS_WEB_EXPLICIT (0) or WS_WEB_IMPLICIT (1)";
    if (!in_range(d->elongation_at_break, 0, 100) || !in_range(d->rupture_strain, 0, 100))
        return "elongation_at_break and rupture_strain must be 0 .. 100";
    if (d->rupture_strain == 0 && d->elongation_at_break > 0 &&
        !(d->prestretch < d->elongation_at_break))
        return "prestretch must be below elongation_at_break: a film stretched that far has no "
               "elongation left";
    if (spiral_rupture(d) != 0 && !(spiral_rupture(d) > d->load_strain))
        return "the film would break as it is laid: its rupture strain (rupture_strain, or from "
               "elongation_at_break and prestretch) must be above load_strain";
    return NULL;
}

/* ---- the spiral's geometry ---------------------------------------------------------------- */

/* A spiral on a load, in revolutions (a place round the load is its phase, 0 .. 1, from where
 * the film starts) and heights above the platform's top. */
typedef struct spiral {
    double wl, hl;   /* laid width and thickness, m */
    double lo, hi;   /* the film's lowest and highest edge, m */
    double zb, zt;   /* centre heights of the bottom and top revolutions, m */
    double pitch;    /* climb of the film's centre a revolution of the spiral, m */
    double rb, rup, rt, total; /* revolutions at the bottom, up, at the top; in all */
} spiral;

/* Most revolutions a spiral may lay: the layer count walks them all at every sample. */
#define SPIRAL_MAX_REVOLUTIONS 1e4
/* Most nodes of a spiral's film (about 100 bytes each in the world). */
#define SPIRAL_MAX_NODES 1e6

/* The spiral of d on a load `height` high with its deck at `deck`: 0, -1 when the film's band
 * has no height on the load, -2 when it lays more than SPIRAL_MAX_REVOLUTIONS (a film narrow
 * for the load's height). */
static int spiral_of(const ws_spiral_wrap_def *d, double height, double deck, spiral *sp)
{
    /* Volume kept through the pre-stretch: width W (1 - neck_in), length (1 + prestretch). */
    sp->wl = d->width * (1.0 - d->neck_in);
    sp->hl = d->gauge / ((1.0 + d->prestretch) * (1.0 - d->neck_in));
    sp->lo = d->pallet_lock ? d->lock_height : deck + d->lock_height;
    sp->hi = height - d->top_margin;
    if (!(sp->hi > sp->lo))
        return -1;
    sp->zb = sp->lo + 0.5 * sp->wl;
    sp->zt = sp->hi - 0.5 * sp->wl;
    if (sp->zt < sp->zb) /* a film wider than the band: all at mid-height, clipped */
        sp->zb = sp->zt = 0.5 * (sp->lo + sp->hi);
    sp->pitch = sp->wl * (1.0 - d->overlap);
    sp->rb = d->revolutions_bottom;
    sp->rt = d->revolutions_top;
    sp->rup = sp->zt > sp->zb ? (sp->zt - sp->zb) / sp->pitch : 0.0;
    sp->total = sp->rb + sp->rup + sp->rt + (d->passes == 2 ? sp->rup : 0.0);
    return sp->total <= SPIRAL_MAX_REVOLUTIONS ? 0 : -2;
}

/* Height of the film's centre after r revolutions. */
static double spiral_centre(const spiral *sp, double r)
{
    if (r <= sp->rb)
        return sp->zb;
    r -= sp->rb;
    if (r <= sp->rup)
        return sp->zb + r * sp->pitch;
    r -= sp->rup;
    if (r <= sp->rt)
        return sp->zt;
    r -= sp->rt;
    return fmax(sp->zb, sp->zt - r * sp->pitch);
}

/* Film layers at phase ph (revolutions, any real) and height z: the revolutions whose band
 * covers z there. */
static int spiral_layers(const spiral *sp, double ph, double z)
{
    if (z < sp->lo || z > sp->hi)
        return 0;
    ph -= floor(ph);
    int n = 0;
    for (double r = ph; r <= sp->total; r += 1.0)
        n += fabs(z - spiral_centre(sp, r)) <= 0.5 * sp->wl;
    return n;
}

/* Mean layers over a patch: phases ph0 .. ph1, heights z0 .. z1, WRAP_SAMPLES^2 samples at
 * the centres of equal parts. */
static double patch_layers(const spiral *sp, double ph0, double ph1, double z0, double z1)
{
    double sum = 0.0;
    for (int a = 0; a < WRAP_SAMPLES; a++)
        for (int b = 0; b < WRAP_SAMPLES; b++)
            sum += spiral_layers(sp, ph0 + (ph1 - ph0) * (a + 0.5) / WRAP_SAMPLES,
                                 z0 + (z1 - z0) * (b + 0.5) / WRAP_SAMPLES);
    return sum / (WRAP_SAMPLES * WRAP_SAMPLES);
}

ws_status ws_spiral_wrap_layers(const ws_spiral_wrap_def *def, double height, double deck,
                                double perimeter, double s, double z, int *layers)
{
    if (!def || !layers)
        return WS_ERR_INVALID_ARGUMENT;
    ws_spiral_wrap_def d;
    ws_spiral_wrap_def_init(&d);
    if (def->size < 2 * sizeof(uint32_t) || def->magic != d.magic)
        return WS_ERR_UNINITIALIZED_DEF;
    memcpy(&d, def, def->size < sizeof d ? def->size : sizeof d);
    d.size = (uint32_t)sizeof d;
    spiral sp;
    if (spiral_bad(&d) || !(isfinite(perimeter) && perimeter > 0) || !isfinite(s) ||
        !isfinite(z) || !(isfinite(deck) && deck >= 0) || !isfinite(height) ||
        spiral_of(&d, height, deck, &sp) != 0)
        return WS_ERR_INVALID_ARGUMENT;
    *layers = spiral_layers(&sp, s / perimeter, z);
    return WS_OK;
}

/* ---- the grid round the load -------------------------------------------------------------- */

/* The load's outline at a height: the rectangle of its bodies there, in global x and y. */
typedef struct outline {
    double x0, x1, y0, y1;
} outline;

/* A body of the load as a box: its centre, rotation and half sizes in its own frame. */
typedef struct wbox {
    v3 c;
    ws_mat3 a;
    v3 half;
} wbox;

static ws_status load_boxes(const ws_world *w, const ws_load *ld, wbox *b)
{
    int n = ld->info.cartons + 1;
    for (int k = 0; k < n; k++) {
        ws_body_id id = k ? ld->carton[k - 1].body : ld->info.pallet;
        ws_vec3 c;
        ws_status s;
        if ((s = ws_body_get_position(w, id, &c)) != WS_OK ||
            (s = ws_body_get_rotation(w, id, &b[k].a)) != WS_OK)
            return s;
        b[k].c = v3_make(c.x, c.y, c.z);
        if (!k) {
            b[k].half = v3_scale(ld->pallet_size, 0.5);
        } else {
            double ins = ld->carton[k - 1].layer % 2 ? 2 * WS_LOAD_INSET : 0.0;
            b[k].half = v3_make(0.5 * (ld->carton_shape.x - ld->carton_cut - ins),
                                0.5 * (ld->carton_shape.y - ld->carton_cut - ins),
                                0.5 * ld->carton_shape.z);
        }
    }
    return WS_OK;
}

/* Half extent of a box along global axis i. */
static double box_reach(const wbox *b, int i)
{
    const double *m = b->a.m + 3 * i;
    return fabs(m[0]) * b->half.x + fabs(m[1]) * b->half.y + fabs(m[2]) * b->half.z;
}

/* The outline at global height z: the boxes whose height range holds z within `tol`; 0, or -1
 * when none does. */
static int outline_at(const wbox *b, int n, double z, double tol, outline *o)
{
    int found = 0;
    for (int k = 0; k < n; k++) {
        double hz = box_reach(&b[k], 2);
        if (z < b[k].c.z - hz - tol || z > b[k].c.z + hz + tol)
            continue;
        double hx = box_reach(&b[k], 0), hy = box_reach(&b[k], 1);
        if (!found) {
            o->x0 = b[k].c.x - hx;
            o->x1 = b[k].c.x + hx;
            o->y0 = b[k].c.y - hy;
            o->y1 = b[k].c.y + hy;
        } else {
            o->x0 = fmin(o->x0, b[k].c.x - hx);
            o->x1 = fmax(o->x1, b[k].c.x + hx);
            o->y0 = fmin(o->y0, b[k].c.y - hy);
            o->y1 = fmax(o->y1, b[k].c.y + hy);
        }
        found = 1;
    }
    return found ? 0 : -1;
}

/* Everything the web is made of, in the load's memory. */
typedef struct wrap_mesh {
    int nx, ny, sx, sy; /* nodes a row, rows; segments along x and along y of a row */
    int sheet;          /* 1 with a top sheet: (sx + 1) (sy + 1) nodes after the rows' */
    size_t n, ns;
    double *pos, *mass, *rest, *scale, *phase;
    uint32_t *spr;
    uint8_t *kind;
} wrap_mesh;

static void mesh_free(ws_load *ld, wrap_mesh *m)
{
    ws_mem_free(&ld->mem, m->pos, 3 * m->n * sizeof(double));
    ws_mem_free(&ld->mem, m->mass, m->n * sizeof(double));
    ws_mem_free(&ld->mem, m->phase, m->n * sizeof(double));
    ws_mem_free(&ld->mem, m->rest, m->ns * sizeof(double));
    ws_mem_free(&ld->mem, m->scale, m->ns * sizeof(double));
    ws_mem_free(&ld->mem, m->spr, 2 * m->ns * sizeof(uint32_t));
    ws_mem_free(&ld->mem, m->kind, m->ns);
}

static int mesh_alloc(ws_load *ld, wrap_mesh *m)
{
    const size_t rows = (size_t)m->nx * (size_t)m->ny;
    m->n = rows;
    m->ns = 2 * rows - (size_t)m->nx; /* around: nx a row; up: nx between rows */
    if (m->sheet) {
        /* Its grid's springs along x and y, and one from each edge node to the highest row. */
        const size_t gx = (size_t)m->sx + 1, gy = (size_t)m->sy + 1;
        m->n += gx * gy;
        m->ns += (gx - 1) * gy + gx * (gy - 1) + (size_t)m->nx;
    }
    m->pos = ws_mem_calloc(&ld->mem, 3 * m->n, sizeof(double));
    m->mass = ws_mem_calloc(&ld->mem, m->n, sizeof(double));
    m->phase = ws_mem_calloc(&ld->mem, m->n, sizeof(double));
    m->rest = ws_mem_calloc(&ld->mem, m->ns, sizeof(double));
    m->scale = ws_mem_calloc(&ld->mem, m->ns, sizeof(double));
    m->spr = ws_mem_calloc(&ld->mem, 2 * m->ns, sizeof(uint32_t));
    m->kind = ws_mem_calloc(&ld->mem, m->ns, 1);
    return m->pos && m->mass && m->phase && m->rest && m->scale && m->spr && m->kind ? 0 : -1;
}

/* Node i of a row on outline o pushed out by `off`: its place (corner nodes at their corner,
 * moved by `corner` along both outward normals) and its position along the row's outline from
 * corner 0 (x0, y0), m. Corners are nodes 0, sx, sx + sy, 2 sx + sy. */
static v3 row_node(const wrap_mesh *m, const outline *o, int i, double off, double corner,
                   double z, double *arc)
{
    const double lx = o->x1 - o->x0, ly = o->y1 - o->y0;
    const int sx = m->sx, sy = m->sy;
    double x, y;
    if (i < sx) { /* face -y, along +x */
        double t = (double)i / sx;
        x = o->x0 + t * lx;
        y = o->y0 - off;
        *arc = t * lx;
        if (i == 0) {
            x = o->x0 - corner;
            y = o->y0 - corner;
        }
    } else if (i < sx + sy) { /* face +x, along +y */
        double t = (double)(i - sx) / sy;
        x = o->x1 + off;
        y = o->y0 + t * ly;
        *arc = lx + t * ly;
        if (i == sx) {
            x = o->x1 + corner;
            y = o->y0 - corner;
        }
    } else if (i < 2 * sx + sy) { /* face +y, along -x */
        double t = (double)(i - sx - sy) / sx;
        x = o->x1 - t * lx;
        y = o->y1 + off;
        *arc = lx + ly + t * lx;
        if (i == sx + sy) {
            x = o->x1 + corner;
            y = o->y1 + corner;
        }
    } else { /* face -x, along -y */
        double t = (double)(i - 2 * sx - sy) / sy;
        x = o->x0 - off;
        y = o->y1 - t * ly;
        *arc = 2 * lx + ly + t * ly;
        if (i == 2 * sx + sy) {
            x = o->x0 - corner;
            y = o->y1 + corner;
        }
    }
    return v3_make(x, y, z);
}

/* Where a corner node sits, outward along both normals of its faces (negative: behind both
 * faces' planes), for a row of tension T (N) whose film turns a right angle there: its contact
 * carries the turn, T along each face's normal, with the node-body stiffness kc per contact and
 * the two contact layers `off`. Behind both planes each face pushes kc (off - depth) (two
 * contacts); outside both, the edge alone pushes along the diagonal, kc (off - sqrt2 d). */
static double corner_place(double T, double kc, double off)
{
    const double r2 = sqrt(2.0);
    if (r2 * T / kc < off)
        return (off - r2 * T / kc) / r2; /* the edge's contact */
    return fmin(off - T / kc, 0.0);      /* the two faces' contacts */
}

/* The highest row's node that edge node (ix, iy) of the top sheet's grid joins. */
static size_t sheet_edge_row_node(const wrap_mesh *m, int ix, int iy)
{
    const int sx = m->sx, sy = m->sy;
    int i;
    if (iy == 0)
        i = ix;
    else if (ix == sx)
        i = sx + iy;
    else if (iy == sy)
        i = sx + sy + (sx - ix);
    else
        i = (2 * sx + sy + (sy - iy)) % m->nx;
    return (size_t)(m->ny - 1) * (size_t)m->nx + (size_t)i;
}

static void put_spring(wrap_mesh *m, size_t k, size_t a, size_t b, uint8_t kind, double scale)
{
    const double *pa = m->pos + 3 * a, *pb = m->pos + 3 * b;
    m->spr[2 * k] = (uint32_t)a;
    m->spr[2 * k + 1] = (uint32_t)b;
    m->kind[k] = kind;
    m->scale[k] = scale;
    m->rest[k] = sqrt((pb[0] - pa[0]) * (pb[0] - pa[0]) + (pb[1] - pa[1]) * (pb[1] - pa[1]) +
                      (pb[2] - pa[2]) * (pb[2] - pa[2]));
}

/* The top sheet: a grid over the top face `o` at height z (global), laid loose (its springs as
 * placed), its edge nodes joined to the highest row's nodes over the load's top edges. Its
 * springs take the around law (E h_l dz) for x and the up law (E h_l ds) for y, scaled by its
 * thickness q = gauge / h_l and by the strip each stands for; its nodes the mass of their
 * share of the face (at least mass_min). k0: its first spring. */
static void top_sheet(wrap_mesh *m, const outline *o, double z, double q, double dz,
                      double ds, double rho_h, double mass_min, size_t k0)
{
    const int gx = m->sx + 1, gy = m->sy + 1;
    const size_t n0 = (size_t)m->nx * (size_t)m->ny;
    const double hx = (o->x1 - o->x0) / m->sx, hy = (o->y1 - o->y0) / m->sy;
    for (int iy = 0; iy < gy; iy++)
        for (int ix = 0; ix < gx; ix++) {
            size_t a = n0 + (size_t)iy * gx + ix;
            m->pos[3 * a] = o->x0 + ix * hx;
            m->pos[3 * a + 1] = o->y0 + iy * hy;
            m->pos[3 * a + 2] = z;
            double wx = (ix == 0 || ix == m->sx) ? 0.5 * hx : hx;
            double wy = (iy == 0 || iy == m->sy) ? 0.5 * hy : hy;
            m->mass[a] = fmax(mass_min, rho_h * wx * wy);
        }
    size_t k = k0;
    for (int iy = 0; iy < gy; iy++)
        for (int ix = 0; ix + 1 < gx; ix++, k++) {
            size_t a = n0 + (size_t)iy * gx + ix;
            double wy = (iy == 0 || iy == m->sy) ? 0.5 * hy : hy;
            put_spring(m, k, a, a + 1, WS_SPRING_AROUND, q * wy / dz);
        }
    for (int iy = 0; iy + 1 < gy; iy++)
        for (int ix = 0; ix < gx; ix++, k++) {
            size_t a = n0 + (size_t)iy * gx + ix;
            double wx = (ix == 0 || ix == m->sx) ? 0.5 * hx : hx;
            put_spring(m, k, a, a + (size_t)gx, WS_SPRING_UP, q * wx / ds);
        }
    /* Over the top edges: each edge node of the grid to its node of the highest row. */
    for (int i = 0; i < m->nx; i++, k++) {
        int ix, iy;
        if (i <= m->sx) {
            ix = i;
            iy = 0;
        } else if (i <= m->sx + m->sy) {
            ix = m->sx;
            iy = i - m->sx;
        } else if (i <= 2 * m->sx + m->sy) {
            ix = m->sx - (i - m->sx - m->sy);
            iy = m->sy;
        } else {
            ix = 0;
            iy = m->sy - (i - 2 * m->sx - m->sy);
        }
        size_t a = n0 + (size_t)iy * gx + ix;
        size_t b = sheet_edge_row_node(m, ix, iy);
        double w = 0.5 * (i <= m->sx || (i > m->sx + m->sy && i <= 2 * m->sx + m->sy) ? hx : hy);
        put_spring(m, k, b, a, WS_SPRING_UP, q * 2 * w / ds);
    }
}

ws_status ws_load_wrap_spiral(ws_world *w, ws_load *ld, const ws_spiral_wrap_def *def,
                              ws_web_id *out)
{
    ws_status s = ws_load_check_world(w, ld, "ws_load_wrap_spiral");
    if (s != WS_OK)
        return s;
    NOT_IN_STEP(w, "ws_load_wrap_spiral");
    NEED_OUT(w, out, "ws_load_wrap_spiral");
    ws_spiral_wrap_def d;
    ws_spiral_wrap_def_init(&d);
    if ((s = ws_def_take(w, &d, sizeof d, def, "spiral_wrap")) != WS_OK)
        return s;
    const char *bad = spiral_bad(&d);
    if (bad)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "spiral wrap: %s", bad);
    if (ld->info.film.bits)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "spiral wrap: the load is wrapped already");
    /* Heights above the platform's top, under the pallet (the band's rule, ws_load_wrap_band). */
    ws_vec3 pc;
    if ((s = ws_body_get_position(w, ld->info.pallet, &pc)) != WS_OK)
        return s;
    const double zp = pc.z - 0.5 * ld->pallet_size.z - 2 * ld->contact_layer;
    const double H = ld->info.load_height;
    spiral sp;
    int geometry = spiral_of(&d, H, ld->info.pallet_top, &sp);
    if (geometry == -1)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "spiral wrap: lock_height and top_margin leave no film on a load %.3g m "
                       "high (deck at %.3g m)",
                       H, ld->info.pallet_top);
    if (geometry != 0)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "spiral wrap: width %.3g m, neck_in and overlap climb %.3g m a revolution: "
                       "%.3g revolutions on a load %.3g m high, at most %g",
                       d.width, sp.pitch, sp.total, H, SPIRAL_MAX_REVOLUTIONS);
    /* Rows and nodes round the load's widest outline (its pallet's) bounded before any of
     * them is counted in an int. */
    const double perimeter = 2 * (ld->pallet_size.x + ld->pallet_size.y);
    if (!((sp.hi - sp.lo) / d.node_pitch * perimeter / d.node_pitch <= SPIRAL_MAX_NODES))
        return ws_fail(
            w, WS_ERR_INVALID_ARGUMENT,
            "spiral wrap: node_pitch %.3g m makes about %.3g nodes on the load: at most %g",
            d.node_pitch, (sp.hi - sp.lo) * perimeter / (d.node_pitch * d.node_pitch),
            SPIRAL_MAX_NODES);
    if (!(d.node_pitch < 0.25 * (sp.hi - sp.lo)))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "spiral wrap: node_pitch must be under a quarter of the film's height "
                       "on the load (%.3g m), got %.3g m",
                       sp.hi - sp.lo, d.node_pitch);
    if (d.rope_revolutions > 0 && !(d.rope_height >= sp.lo && d.rope_height <= sp.hi))
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "spiral wrap: rope_height must lie on the film, %.3g .. %.3g m, got %.3g m",
                       sp.lo, sp.hi, d.rope_height);

    int nb = ld->info.cartons + 1;
    wbox *box = ws_mem_calloc(&ld->mem, (size_t)nb, sizeof *box);
    if (!box)
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "spiral wrap: out of memory");
    wrap_mesh m;
    memset(&m, 0, sizeof m);
    outline *rows = NULL;
    size_t nrows = 0;
    if ((s = load_boxes(w, ld, box)) != WS_OK)
        goto done;
    /* Rows from the film's lowest edge to its highest, at most node_pitch apart; the nodes of
     * a row's side as many as the widest outline needs. */
    m.ny = (int)ceil((sp.hi - sp.lo) / d.node_pitch) + 1;
    nrows = (size_t)m.ny;
    const double dz = (sp.hi - sp.lo) / (m.ny - 1);
    rows = ws_mem_calloc(&ld->mem, nrows, sizeof *rows);
    if (!rows) {
        s = ws_fail(w, WS_ERR_OUT_OF_MEMORY, "spiral wrap: out of memory");
        goto done;
    }
    const double tol = 2 * ld->contact_layer + 1e-9;
    double lx = 0, ly = 0;
    for (int j = 0; j < m.ny; j++) {
        double z = zp + sp.lo + j * dz;
        if (outline_at(box, nb, z, tol, &rows[j]) != 0 &&
            outline_at(box, nb, z, 0.5 * dz, &rows[j]) != 0) {
            s = ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                        "spiral wrap: nothing of the load at %.3g m above the platform to lay "
                        "the film on",
                        z - zp);
            goto done;
        }
        lx = fmax(lx, rows[j].x1 - rows[j].x0);
        ly = fmax(ly, rows[j].y1 - rows[j].y0);
    }
    m.sx = (int)ceil(lx / d.node_pitch);
    m.sy = (int)ceil(ly / d.node_pitch);
    m.nx = 2 * (m.sx + m.sy);
    m.sheet = d.top_sheet;
    if (mesh_alloc(ld, &m) != 0) {
        s = ws_fail(w, WS_ERR_OUT_OF_MEMORY, "spiral wrap: out of memory for %d x %d nodes", m.nx,
                    m.ny);
        goto done;
    }
    const int nx = m.nx;
    const double off = 2 * ld->contact_layer; /* the body's layer and the node's */
    const double kc = ld->point_stiffness[WS_IF_FILM_CARTON];
    const double ds_ref = (lx + ly) / (m.sx + m.sy); /* a column's width, m (law EA up) */
    const double ea_around = d.modulus * sp.hl * dz, ea_up = d.modulus * sp.hl * ds_ref;
    /* The row the rope lies in, if any. */
    int rope_row = d.rope_revolutions > 0 ? (int)lround((d.rope_height - sp.lo) / dz) : -1;
    for (int j = 0; j < m.ny; j++) {
        const outline *o = &rows[j];
        const double z = sp.lo + j * dz;
        /* Each row's strip: half-way to its neighbours, within the film. */
        const double z0 = j ? z - 0.5 * dz : z, z1 = j + 1 < m.ny ? z + 0.5 * dz : z;
        const double strip = z1 - z0;
        const double per = 2 * ((o->x1 - o->x0) + (o->y1 - o->y0));
        /* Phases: the film starts at the middle of the -y face. */
        for (int i = 0; i < nx; i++) {
            double arc;
            row_node(&m, o, i, off, 0.0, 0.0, &arc);
            m.phase[(size_t)j * nx + i] = (arc - 0.5 * (o->x1 - o->x0)) / per;
        }
        /* Around-springs: layers over their strip; the row's tension from its mean layers. */
        double sum_len = 0, sum_n = 0;
        for (int i = 0; i < nx; i++) {
            size_t k = (size_t)j * nx + i;
            int i1 = (i + 1) % nx;
            double p0 = m.phase[k], p1 = m.phase[(size_t)j * nx + i1];
            if (p1 < p0)
                p1 += 1.0;
            double a0, a1;
            v3 q0 = row_node(&m, o, i, off, off, 0.0, &a0);
            v3 q1 = row_node(&m, o, i1, off, off, 0.0, &a1);
            double len = v3_norm(v3_sub(q1, q0));
            double n = strip > 0 ? patch_layers(&sp, p0, p1, z0, z1) : 0.0;
            if (j == rope_row)
                n += d.rope_revolutions * sp.wl / fmax(strip, 1e-9);
            n = fmax(n, WRAP_MIN_LAYERS);
            m.scale[k] = n * strip / dz;
            m.spr[2 * k] = (uint32_t)k;
            m.spr[2 * k + 1] = (uint32_t)((size_t)j * nx + i1);
            m.kind[k] = WS_SPRING_AROUND;
            sum_len += len;
            sum_n += m.scale[k] * len;
        }
        /* One tension along the row: the film stands without shear (docs/theory.md). */
        const double T = ea_around * d.load_strain * sum_n / sum_len;
        const double cp = corner_place(T, kc, off);
        for (int i = 0; i < nx; i++) {
            size_t k = (size_t)j * nx + i;
            double arc;
            v3 q = row_node(&m, o, i, off, cp, zp + z, &arc);
            m.pos[3 * k] = q.x;
            m.pos[3 * k + 1] = q.y;
            m.pos[3 * k + 2] = q.z;
        }
        for (int i = 0; i < nx; i++) {
            size_t k = (size_t)j * nx + i;
            const double *a = m.pos + 3 * k, *b = m.pos + 3 * ((size_t)j * nx + (i + 1) % nx);
            double len = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                              (b[2] - a[2]) * (b[2] - a[2]));
            double strain = T / (ea_around * m.scale[k]);
            m.rest[k] = len / (1.0 + strain);
        }
        /* Node masses: each node's share of its strip and its neighbours' half segments. */
        for (int i = 0; i < nx; i++) {
            size_t k = (size_t)j * nx + i;
            size_t kl = (size_t)j * nx + (i + nx - 1) % nx;
            const double *pl = m.pos + 3 * kl;
            const double *pc0 = m.pos + 3 * k, *pr = m.pos + 3 * ((size_t)j * nx + (i + 1) % nx);
            double wl = 0.5 * hypot(pc0[0] - pl[0], pc0[1] - pl[1]);
            double wr = 0.5 * hypot(pr[0] - pc0[0], pr[1] - pc0[1]);
            double pl0 = m.phase[k] - wl / per, pr0 = m.phase[k] + wr / per;
            double n = strip > 0 ? patch_layers(&sp, pl0, pr0, z0, z1) : 0.0;
            double area = (wl + wr) * strip;
            double mass = d.density * sp.hl * fmax(n, WRAP_MIN_LAYERS) * area;
            if (j == rope_row)
                mass += d.density * sp.hl * sp.wl * d.rope_revolutions * (wl + wr);
            m.mass[k] = fmax(mass, d.node_mass_min);
            if (!(m.mass[k] > 0)) /* a one-row strip of no height: its neighbours' film */
                m.mass[k] = d.density * sp.hl * WRAP_MIN_LAYERS * (wl + wr) * 0.5 * dz;
        }
    }
    /* Up-springs: as placed (nothing stretched up the load), layers over their column. */
    for (int j = 0; j + 1 < m.ny; j++)
        for (int i = 0; i < nx; i++) {
            size_t a = (size_t)j * nx + i, b = a + (size_t)nx;
            size_t k = (size_t)nx * (size_t)m.ny + (size_t)j * nx + i;
            const double *pa = m.pos + 3 * a, *pb = m.pos + 3 * b;
            const double *pl = m.pos + 3 * ((size_t)j * nx + (i + nx - 1) % nx);
            const double *pr = m.pos + 3 * ((size_t)j * nx + (i + 1) % nx);
            double wl = 0.5 * hypot(pa[0] - pl[0], pa[1] - pl[1]);
            double wr = 0.5 * hypot(pr[0] - pa[0], pr[1] - pa[1]);
            const outline *o = &rows[j];
            double per = 2 * ((o->x1 - o->x0) + (o->y1 - o->y0));
            double z0 = sp.lo + j * dz;
            double n = patch_layers(&sp, m.phase[a] - wl / per, m.phase[a] + wr / per, z0,
                                    z0 + dz);
            m.scale[k] = fmax(n, WRAP_MIN_LAYERS) * (wl + wr) / ds_ref;
            m.rest[k] = sqrt((pb[0] - pa[0]) * (pb[0] - pa[0]) + (pb[1] - pa[1]) * (pb[1] - pa[1]) +
                             (pb[2] - pa[2]) * (pb[2] - pa[2]));
            m.spr[2 * k] = (uint32_t)a;
            m.spr[2 * k + 1] = (uint32_t)b;
            m.kind[k] = WS_SPRING_UP;
        }
    if (m.sheet)
        top_sheet(&m, &rows[m.ny - 1], zp + H + off, d.top_sheet_gauge / sp.hl, dz, ds_ref,
                  d.density * d.top_sheet_gauge, d.node_mass_min,
                  2 * (size_t)nx * (size_t)m.ny - (size_t)nx);
    {
        /* The film may reach the platform (a low pallet lock, a sagging edge): there it meets
         * the platform as it meets the pallet. The pair's damping also sets the light film's
         * stable step (h < 2 m / c), which the default contact's damping would cut tenfold. */
        ws_contact_def fp;
        if ((s = ws_world_get_contact(w, ld->info.film_material, ld->info.pallet_material,
                                      &fp)) != WS_OK ||
            (s = ws_world_set_contact(w, ld->info.film_material, ld->info.platform_material,
                                      &fp)) != WS_OK)
            goto done;
        ws_law_id around, up;
        if ((s = ws_load_film_law(w, ea_around, "spiral film around", &around)) != WS_OK ||
            (s = ws_load_film_law(w, ea_up, "spiral film up", &up)) != WS_OK)
            goto done;
        ws_web_def wd;
        ws_web_def_init(&wd);
        wd.contact_layer = ld->contact_layer;
        wd.material = ld->info.film_material;
        wd.law = around;
        wd.law_cross = up;
        wd.substeps = d.substeps > 0 ? d.substeps : 1;
        wd.integrator = d.integrator;
        wd.name = "spiral film";
        wd.rupture_strain = spiral_rupture(&d);
        ws_web_mesh_def md;
        ws_web_mesh_def_init(&md);
        md.positions = m.pos;
        md.node_count = m.n;
        md.node_masses = m.mass;
        md.springs = m.spr;
        md.spring_count = m.ns;
        md.rest_lengths = m.rest;
        md.kinds = m.kind;
        md.stiffness_scales = m.scale;
        if ((s = ws_web_create_mesh(w, &wd, &md, &ld->info.film)) != WS_OK)
            goto done;
        if (d.substeps == 0 && d.integrator == WS_WEB_EXPLICIT &&
            (s = ws_load_fit_substeps(w, ld->info.film, "ws_load_wrap_spiral")) != WS_OK) {
            ws_web_destroy(w, ld->info.film);
            ld->info.film = (ws_web_id){0};
            goto done;
        }
        ld->film_nx = m.nx;
        ld->film_ny = m.ny;
        ld->film_spiral = 1;
        *out = ld->info.film;
    }
done:
    mesh_free(ld, &m);
    ws_mem_free(&ld->mem, rows, nrows * sizeof *rows);
    ws_mem_free(&ld->mem, box, (size_t)nb * sizeof *box);
    return s;
}

/* ---- read-outs ---------------------------------------------------------------------------- */

/* The film's nodes (positions, contact forces) and spring tensions, in the load's memory. */
typedef struct film_state {
    size_t n, ns;
    double *x, *f, *t;
} film_state;

static void film_free(ws_load *ld, film_state *fs)
{
    ws_mem_free(&ld->mem, fs->x, 3 * fs->n * sizeof(double));
    ws_mem_free(&ld->mem, fs->f, 3 * fs->n * sizeof(double));
    ws_mem_free(&ld->mem, fs->t, fs->ns * sizeof(double));
    memset(fs, 0, sizeof *fs);
}

/* Read the film: positions, the last step's contact forces, and the tensions (tension = 1) or
 * the strains (0) of its springs. */
static ws_status film_read(const ws_world *w, ws_load *ld, film_state *fs, int tension,
                           const char *fn)
{
    memset(fs, 0, sizeof *fs);
    ws_status s = ws_load_check_world(w, ld, fn);
    if (s != WS_OK)
        return s;
    if (!ld->info.film.bits || ld->film_nx <= 0)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT, "%s: the load is not wrapped", fn);
    ws_web_info wi;
    if ((s = ws_web_get_info(w, ld->info.film, &wi)) != WS_OK)
        return s;
    fs->n = wi.node_count;
    fs->ns = wi.spring_count;
    fs->x = ws_mem_calloc(&ld->mem, 3 * fs->n, sizeof(double));
    fs->f = ws_mem_calloc(&ld->mem, 3 * fs->n, sizeof(double));
    fs->t = ws_mem_calloc(&ld->mem, fs->ns ? fs->ns : 1, sizeof(double));
    if (!fs->x || !fs->f || !fs->t) {
        film_free(ld, fs);
        return ws_fail(w, WS_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    }
    size_t c;
    if ((s = ws_web_copy_positions(w, ld->info.film, fs->x, fs->n, &c)) != WS_OK ||
        (s = ws_web_copy_contact_forces(w, ld->info.film, fs->f, fs->n, &c)) != WS_OK ||
        (s = tension ? ws_web_copy_spring_tensions(w, ld->info.film, fs->t, fs->ns, &c)
                     : ws_web_copy_spring_strains(w, ld->info.film, fs->t, fs->ns, &c)) != WS_OK)
        film_free(ld, fs);
    return s;
}

/* The platform's top, global z: where the load's heights are measured from. */
static ws_status platform_top(const ws_world *w, const ws_load *ld, double *zp)
{
    ws_vec3 pc;
    ws_status s = ws_body_get_position(w, ld->info.pallet, &pc);
    *zp = pc.z - 0.5 * ld->pallet_size.z - 2 * ld->contact_layer;
    return s;
}

ws_status ws_load_get_containment(const ws_world *w, const ws_load *cld,
                                  ws_load_containment *bands, size_t count)
{
    /* The read-out allocates its buffers in the load's memory, whose accounting it updates. */
    ws_load *ld = (ws_load *)(uintptr_t)cld;
    ws_status s = ws_load_check_world(w, ld, "ws_load_get_containment");
    if (s != WS_OK)
        return s;
    NEED_OUT(w, bands, "ws_load_get_containment");
    if (count < 1 || count > 64)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_load_get_containment: count must be 1 .. 64 bands, got %zu", count);
    film_state fs;
    double zp;
    if ((s = film_read(w, ld, &fs, 1, "ws_load_get_containment")) != WS_OK)
        return s;
    if ((s = platform_top(w, ld, &zp)) != WS_OK) {
        film_free(ld, &fs);
        return s;
    }
    const double H = ld->info.load_height;
    for (size_t b = 0; b < count; b++) {
        memset(&bands[b], 0, sizeof bands[b]);
        bands[b].z_low = H * (double)b / (double)count;
        bands[b].z_high = H * (double)(b + 1) / (double)count;
    }
    /* A height's band; heights off the load go to the nearest. The squeeze across the load's
     * two vertical mid-planes through the pallet's centre: each node's force counts inwards,
     * towards the plane, from whichever side it is on (friction along a face, pointing away,
     * counts against), so in equilibrium each plane's squeeze is the tension of the film's
     * crossings of it, twice the hoop tension. */
    ws_vec3 centre;
    if ((s = ws_body_get_position(w, ld->info.pallet, &centre)) != WS_OK) {
        film_free(ld, &fs);
        return s;
    }
    const double per_band = H / (double)count;
    for (size_t i = 0; i < fs.n; i++) {
        double h = fs.x[3 * i + 2] - zp;
        double q = floor(h / per_band);
        size_t b = q < 0 ? 0 : q >= (double)count ? count - 1 : (size_t)q;
        const double *f = fs.f + 3 * i;
        double sx = fs.x[3 * i] < centre.x ? 1.0 : -1.0;
        double sy = fs.x[3 * i + 1] < centre.y ? 1.0 : -1.0;
        bands[b].force -= (sx * f[0] + sy * f[1]) / 8.0; /* f is on the node: the load's is -f */
        bands[b].contact_force += sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    }
    /* Rows by their mean height; a row's around-springs are nx j .. nx j + nx - 1. */
    const int nx = ld->film_nx, ny = ld->film_ny;
    for (int j = 0; j < ny && (size_t)nx * (size_t)(j + 1) <= fs.ns; j++) {
        double z = 0, t = 0;
        for (int i = 0; i < nx; i++) {
            z += fs.x[3 * ((size_t)j * nx + i) + 2];
            t += fs.t[(size_t)j * nx + i];
        }
        double q = floor((z / nx - zp) / per_band);
        size_t b = q < 0 ? 0 : q >= (double)count ? count - 1 : (size_t)q;
        bands[b].hoop_tension += t / nx;
        bands[b].rows++;
    }
    for (size_t b = 0; b < count; b++)
        bands[b].line_load = bands[b].force / per_band;
    film_free(ld, &fs);
    return WS_OK;
}

ws_status ws_load_get_film_peak(const ws_world *w, const ws_load *ld, double *strain,
                                uint32_t *spring, double *height)
{
    ws_status s = ws_load_check_world(w, ld, "ws_load_get_film_peak");
    if (s != WS_OK)
        return s;
    NEED_OUT(w, strain, "ws_load_get_film_peak");
    if (!ld->info.film.bits || ld->film_nx <= 0)
        return ws_fail(w, WS_ERR_INVALID_ARGUMENT,
                       "ws_load_get_film_peak: the load is not wrapped");
    /* Intact springs only: a broken one carries nothing and its two ends drift apart, so its
     * strain (tens once the film has torn) says nothing of the film that holds the load. */
    ws_web_peak pk;
    double zp;
    if ((s = ws_web_get_peak_strain(w, ld->info.film, &pk)) != WS_OK ||
        (s = platform_top(w, ld, &zp)) != WS_OK)
        return s;
    *strain = pk.found ? pk.strain : 0.0;
    if (spring)
        *spring = pk.found ? pk.spring : 0;
    if (height)
        *height = pk.found ? 0.5 * (pk.position_a.z + pk.position_b.z) - zp : 0.0;
    return WS_OK;
}

ws_status ws_load_film_containment(const ws_world *w, const ws_load *ld, ws_containment_band *out)
{
    if (!ld->film_spiral)
        return ws_web_get_containment(w, ld->info.film, out, 3);
    ws_load_containment b[3];
    ws_status s = ws_load_get_containment(w, ld, b, 3);
    if (s != WS_OK)
        return s;
    ws_vec3 pc;
    double zp = 0;
    if (ws_body_get_position(w, ld->info.pallet, &pc) == WS_OK)
        zp = pc.z - 0.5 * ld->pallet_size.z - 2 * ld->contact_layer;
    for (int k = 0; k < 3; k++) {
        out[k].z_low = zp + b[k].z_low;
        out[k].z_high = zp + b[k].z_high;
        out[k].hoop_tension = b[k].rows ? b[k].hoop_tension / b[k].rows : 0.0;
        out[k].line_load = b[k].line_load;
        out[k].contact_force = b[k].contact_force;
    }
    return WS_OK;
}
