/* Web generators: grid topology (sheet or band), placement, rest lengths from pre-stretch. */
#include "web/web.h"

#include <stdlib.h>
#include <string.h>

uint32_t ws_web_sheet_springs(int nx, int ny, int shear, int closed)
{
    uint32_t cols = (uint32_t)(closed ? nx : nx - 1); /* around-springs per row */
    uint32_t n = cols * (uint32_t)ny + (uint32_t)nx * (uint32_t)(ny - 1);
    if (shear)
        n += 2u * cols * (uint32_t)(ny - 1);
    return n;
}

static void add_spring(ws_web *web, uint32_t *k, uint32_t a, uint32_t b, uint8_t kind)
{
    web->sa[*k] = a;
    web->sb[*k] = b;
    web->kind[*k] = kind;
    (*k)++;
}

void ws_web_build_grid(ws_web *web, int nx, int ny, int shear, int closed, double pre_x,
                       double pre_y)
{
    uint32_t k = 0;
    int cols = closed ? nx : nx - 1;
    web->nx = nx;
    web->ny = ny;
    web->closed = closed;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < cols; i++)
            add_spring(web, &k, (uint32_t)(i + nx * j), (uint32_t)((i + 1) % nx + nx * j),
                       WS_SPRING_AROUND);
    for (int j = 0; j + 1 < ny; j++)
        for (int i = 0; i < nx; i++)
            add_spring(web, &k, (uint32_t)(i + nx * j), (uint32_t)(i + nx * (j + 1)),
                       WS_SPRING_UP);
    if (shear)
        for (int j = 0; j + 1 < ny; j++)
            for (int i = 0; i < cols; i++) {
                int i1 = (i + 1) % nx;
                add_spring(web, &k, (uint32_t)(i + nx * j), (uint32_t)(i1 + nx * (j + 1)),
                           WS_SPRING_SHEAR);
                add_spring(web, &k, (uint32_t)(i1 + nx * j), (uint32_t)(i + nx * (j + 1)),
                           WS_SPRING_SHEAR);
            }
    /* Rest lengths from the lengths as placed: the pre-stretch of each direction; a diagonal's
     * rest length follows from its cell's rest sides. */
    const ws_nodes3 x = web->x[0];
    for (uint32_t s = 0; s < web->ns; s++) {
        double l = v3_norm(v3_sub(nodes_get(x, web->sb[s]), nodes_get(x, web->sa[s])));
        double l0;
        if (web->kind[s] == WS_SPRING_AROUND) {
            l0 = l / (1.0 + pre_x);
        } else if (web->kind[s] == WS_SPRING_UP) {
            l0 = l / (1.0 + pre_y);
        } else {
            /* Split the diagonal into its cell's around and up parts and unstretch each. */
            uint32_t a = web->sa[s], b = web->sb[s];
            int ja = (int)(a / (uint32_t)nx), ib = (int)(b % (uint32_t)nx);
            uint32_t c = (uint32_t)(ib + nx * ja); /* the corner on a's row below b */
            double lx = v3_norm(v3_sub(nodes_get(x, c), nodes_get(x, a)));
            double ly = v3_norm(v3_sub(nodes_get(x, b), nodes_get(x, c)));
            lx /= 1.0 + pre_x;
            ly /= 1.0 + pre_y;
            l0 = sqrt(lx * lx + ly * ly);
        }
        web->inv_l0[s] = 1.0 / l0;
    }
}

void ws_web_place_sheet(ws_web *web, v3 o, v3 ax, v3 ay, double hx, double hy)
{
    for (int j = 0; j < web->ny; j++)
        for (int i = 0; i < web->nx; i++)
            nodes_set(web->x[0], (uint32_t)(i + web->nx * j),
                      v3_madd(v3_madd(o, ax, i * hx), ay, j * hy));
}

static int cmp_xy(const void *pa, const void *pb)
{
    const double *a = pa, *b = pb;
    if (a[0] != b[0])
        return a[0] < b[0] ? -1 : 1;
    if (a[1] != b[1])
        return a[1] < b[1] ? -1 : 1;
    return 0;
}

static double cross2(const double *o, const double *a, const double *b)
{
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

int ws_web_place_band(ws_web *web, const double *pts_in, size_t n, uint32_t *hull_idx,
                      double offset, double z0, double z1)
{
    /* Convex hull, counter-clockwise (monotone chain), on a sorted copy. */
    double *pts = (double *)pts_in; /* sorted in place by the caller's scratch copy */
    qsort(pts, n, 2 * sizeof(double), cmp_xy);
    size_t h = 0;
    for (size_t i = 0; i < n; i++) {
        while (h >= 2 && cross2(pts + 2 * hull_idx[h - 2], pts + 2 * hull_idx[h - 1],
                                pts + 2 * i) <= 1e-15)
            h--;
        hull_idx[h++] = (uint32_t)i;
    }
    for (size_t i = n - 1, lower = h + 1; i-- > 0;) {
        while (h >= lower && cross2(pts + 2 * hull_idx[h - 2], pts + 2 * hull_idx[h - 1],
                                    pts + 2 * i) <= 1e-15)
            h--;
        hull_idx[h++] = (uint32_t)i;
    }
    h--; /* the last point repeats the first */
    if (h < 3)
        return -1;

    /* The offset outline: each edge pushed out by `offset`, joined by arcs of that radius around
     * the hull's corners. Its length: the hull's perimeter + 2 pi offset. */
    double per = 0.0;
    for (size_t k = 0; k < h; k++) {
        const double *a = pts + 2 * hull_idx[k], *b = pts + 2 * hull_idx[(k + 1) % h];
        per += hypot(b[0] - a[0], b[1] - a[1]);
    }
    double total = per + 2.0 * WS_PI * offset;
    int na = web->nx, nu = web->ny;
    double step = total / na;
    /* Node 0 sits at the middle of the first edge and the others follow at equal arc length, so
     * a symmetric outline gets a mirror-symmetric band (starting at a corner would give every
     * side the same handedness, and a band that twists the load when it snaps on). */
    const double *e0a = pts + 2 * hull_idx[0], *e0b = pts + 2 * hull_idx[1 % h];
    double start = 0.5 * hypot(e0b[0] - e0a[0], e0b[1] - e0a[1]);
    for (int i = 0; i < na; i++) {
        double s = fmod(start + i * step, total), px = 0, py = 0;
        /* Walk the outline from its start: edge k, then the arc at its end corner. */
        double seg = 0.0;
        for (size_t k = 0; k < h; k++) {
            const double *a = pts + 2 * hull_idx[k], *b = pts + 2 * hull_idx[(k + 1) % h];
            const double *c = pts + 2 * hull_idx[(k + 2) % h];
            double ex = b[0] - a[0], ey = b[1] - a[1], el = hypot(ex, ey);
            double nx = ey / el, ny = -ex / el; /* outward normal of a CCW edge */
            if (s <= seg + el || k + 1 == h) {
                double t = (s - seg) / el;
                if (t <= 1.0 || offset <= 0.0) {
                    t = t > 1.0 ? 1.0 : t;
                    px = a[0] + t * ex + offset * nx;
                    py = a[1] + t * ey + offset * ny;
                    break;
                }
            }
            seg += el;
            /* Arc at corner b from this edge's normal to the next edge's normal. */
            double fx = c[0] - b[0], fy = c[1] - b[1], fl = hypot(fx, fy);
            double a0 = atan2(ny, nx), a1 = atan2(-fx / fl, fy / fl);
            double turn = a1 - a0;
            while (turn < 0.0)
                turn += 2.0 * WS_PI;
            double arc = turn * offset;
            if (s <= seg + arc || k + 1 == h) {
                double ang = a0 + (offset > 0.0 ? (s - seg) / offset : 0.0);
                px = b[0] + offset * cos(ang);
                py = b[1] + offset * sin(ang);
                break;
            }
            seg += arc;
        }
        for (int j = 0; j < nu; j++) {
            double z = nu > 1 ? z0 + (z1 - z0) * j / (nu - 1) : z0;
            nodes_set(web->x[0], (uint32_t)(i + na * j), v3_make(px, py, z));
        }
    }
    return 0;
}

void ws_web_grid_masses(ws_web *web, double rho)
{
    /* Each spring lends half its rest length to each end; a node's rest area is the product of
     * its mean around and up shares (a quarter-cell from each of up to four cells). */
    ws_nodes3 acc = web->f;
    for (uint32_t i = 0; i < web->n; i++)
        acc.x[i] = acc.y[i] = 0.0;
    for (uint32_t s = 0; s < web->ns; s++) {
        double half = 0.5 / web->inv_l0[s];
        if (web->kind[s] == WS_SPRING_AROUND) {
            acc.x[web->sa[s]] += half;
            acc.x[web->sb[s]] += half;
        } else if (web->kind[s] == WS_SPRING_UP) {
            acc.y[web->sa[s]] += half;
            acc.y[web->sb[s]] += half;
        }
    }
    for (uint32_t i = 0; i < web->n; i++) {
        /* A node on a free edge has half a cell on that side: its shares already say so. */
        web->m[i] = rho * acc.x[i] * acc.y[i];
        acc.x[i] = acc.y[i] = 0.0;
    }
}
