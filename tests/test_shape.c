/* Shapes: validation of meshes and the derived data (volume, centroid, inertia, features).
 * Every expected value is the analytic one; tolerances are round-off of sums over a few hundred
 * tetrahedra (relative 1e-12 leaves three orders of magnitude of headroom over ~1e-15). */
#include "helpers.h"

#include <stdio.h>

#define PI 3.14159265358979323846
#define RT 1e-12 /* relative round-off tolerance, see above */

#define ck_rel(got, want, rel)                                                                     \
    do {                                                                                           \
        double g_ = (got), w_ = (want);                                                            \
        ck_assert_msg(fabs(g_ - w_) <= (rel)*fabs(w_), "%s = %.17g, want %.17g", #got, g_, w_);    \
    } while (0)

#define ck_err_has(w, word)                                                                        \
    ck_assert_msg(strstr(ws_world_last_error(w), (word)) != NULL,                                  \
                  "last error '%s' does not mention '%s'", ws_world_last_error(w), (word))

static ws_shape_info info_of(ws_world *w, ws_shape_id s)
{
    ws_shape_info i;
    memset(&i, 0, sizeof i);
    ck_ok(w, ws_shape_get_info(w, s, &i));
    return i;
}

/* Inertia of a solid box (density 1) about its centre, diagonal. */
static void box_inertia(double lx, double ly, double lz, double out[3])
{
    double V = lx * ly * lz;
    out[0] = V * (ly * ly + lz * lz) / 12.0;
    out[1] = V * (lx * lx + lz * lz) / 12.0;
    out[2] = V * (lx * lx + ly * ly) / 12.0;
}

static void check_diag_inertia(const ws_mat3 *J, const double want[3], double rel)
{
    double scale = fmax(want[0], fmax(want[1], want[2]));
    for (int i = 0; i < 3; i++) {
        ck_rel(J->m[4 * i], want[i], rel);
        for (int j = 0; j < 3; j++)
            if (i != j)
                ck_assert_msg(fabs(J->m[3 * i + j]) <= rel * scale, "J[%d][%d] = %g", i, j,
                              J->m[3 * i + j]);
    }
}

/* ---- box ---- */

START_TEST(test_box)
{
    ws_world *w = new_world(2.5e-4);
    const double lx = 0.3, ly = 0.5, lz = 0.7;
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, lx, ly, lz, &s));
    ws_shape_info i = info_of(w, s);
    ck_rel(i.volume, lx * ly * lz, RT);
    double J[3];
    box_inertia(lx, ly, lz, J);
    check_diag_inertia(&i.inertia_unit, J, RT);
    /* Centred on the origin by construction: the centroid is 0 up to round-off of the size. */
    ck_assert_double_eq_tol(i.centroid.x, 0.0, 1e-15);
    ck_assert_double_eq_tol(i.centroid.y, 0.0, 1e-15);
    ck_assert_double_eq_tol(i.centroid.z, 0.0, 1e-15);
    ck_assert_double_eq_tol(i.aabb_min.x, -lx / 2, 1e-15);
    ck_assert_double_eq_tol(i.aabb_max.y, ly / 2, 1e-15);
    ck_assert_double_eq_tol(i.aabb_max.z, lz / 2, 1e-15);
    ck_assert_uint_eq(i.point_count, 8);
    ck_assert_uint_eq(i.triangle_count, 12);
    ck_assert_uint_eq(i.face_count, 6);  /* the two triangles of a side are one face */
    ck_assert_uint_eq(i.edge_count, 12); /* 18 would mean the face diagonals were counted */
    ck_assert_int_eq(i.convex, 1);
    /* Bad edge lengths. */
    ws_shape_id b;
    ck_assert_int_eq(ws_shape_create_box(w, 0.0, 1, 1, &b), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_shape_create_box(w, 1, -1, 1, &b), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_shape_create_box(w, 1, 1, NAN, &b), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "edge");
    ck_assert_int_eq(ws_shape_create_box(w, 1, 1, 1, NULL), WS_ERR_INVALID_ARGUMENT);
    ws_world_destroy(w);
}
END_TEST

/* ---- mesh given off-centre ---- */

START_TEST(test_mesh_recentred)
{
    ws_world *w = new_world(2.5e-4);
    const double lx = 0.4, ly = 0.6, lz = 0.8, c[3] = {1.0, 2.0, 3.0};
    double v[24];
    for (int k = 0; k < 8; k++) {
        v[3 * k + 0] = c[0] + (cube_v[3 * k + 0] - 0.5) * lx;
        v[3 * k + 1] = c[1] + (cube_v[3 * k + 1] - 0.5) * ly;
        v[3 * k + 2] = c[2] + (cube_v[3 * k + 2] - 0.5) * lz;
    }
    ws_shape_id s;
    ck_ok(w, create_mesh(w, v, 8, cube_t, 12, &s));
    ws_shape_info i = info_of(w, s);
    /* Coordinates of size ~3: the centroid to a few ulp of 3, 1e-12 generous. */
    ck_assert_double_eq_tol(i.centroid.x, c[0], 1e-12);
    ck_assert_double_eq_tol(i.centroid.y, c[1], 1e-12);
    ck_assert_double_eq_tol(i.centroid.z, c[2], 1e-12);
    ck_rel(i.volume, lx * ly * lz, RT);
    double J[3];
    box_inertia(lx, ly, lz, J);
    check_diag_inertia(&i.inertia_unit, J, RT); /* about the centroid, not the origin */
    ck_assert_double_eq_tol(i.aabb_min.x, -lx / 2, 1e-12);
    ck_assert_double_eq_tol(i.aabb_max.z, lz / 2, 1e-12);

    size_t nv = 0, nt = 0;
    ck_ok(w, ws_shape_copy_mesh(w, s, NULL, 0, &nv, NULL, 0, &nt));
    ck_assert_uint_eq(nv, 8);
    ck_assert_uint_eq(nt, 12);
    double rv[24];
    uint32_t rt[36];
    ck_ok(w, ws_shape_copy_mesh(w, s, rv, 8, &nv, rt, 12, &nt));
    for (int k = 0; k < 8; k++)
        for (int a = 0; a < 3; a++)
            ck_assert_double_eq_tol(rv[3 * k + a], v[3 * k + a] - c[a], 1e-12);
    /* Triangles may be re-ordered (grouped by face) but are the given ones, winding kept. */
    for (int k = 0; k < 12; k++) {
        int found = 0;
        for (int m = 0; m < 12 && !found; m++)
            for (int r = 0; r < 3 && !found; r++)
                found = rt[3 * k] == cube_t[3 * m + r] &&
                        rt[3 * k + 1] == cube_t[3 * m + (r + 1) % 3] &&
                        rt[3 * k + 2] == cube_t[3 * m + (r + 2) % 3];
        ck_assert_msg(found, "triangle %d (%u %u %u) is not one of the input", k, rt[3 * k],
                      rt[3 * k + 1], rt[3 * k + 2]);
    }
    /* Too small a buffer: the counts still say how much, and the error says so. */
    ck_assert_int_eq(ws_shape_copy_mesh(w, s, rv, 4, &nv, rt, 12, &nt), WS_ERR_BUFFER_TOO_SMALL);
    ck_assert_uint_eq(nv, 8);
    ck_assert_int_eq(ws_shape_copy_mesh(w, s, NULL, 4, &nv, NULL, 0, &nt), WS_ERR_INVALID_ARGUMENT);
    ws_world_destroy(w);
}
END_TEST

/* ---- placing a body where its mesh was ---- */

/* A corner tetrahedron given in the global frame at (1, 2, 3): its volume centroid is the mean
 * of its four corners, (1, 2, 3) + (a/4)(1, 1, 1). The offset the create call moved it by is
 * that centroid, and a body created at position = offset (identity orientation) puts every
 * original vertex back where it was given; turned by A about its CoG, at offset + A (v - offset).
 * Coordinates ~3: 1e-12 m is a few hundred ulp. */
START_TEST(test_centroid_offset_places_mesh)
{
    ws_world *w = new_world(2.5e-4);
    const double a = 0.5, c[3] = {1.0, 2.0, 3.0};
    double v[12] = {0, 0, 0, a, 0, 0, 0, a, 0, 0, 0, a};
    static const uint32_t t[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    for (int k = 0; k < 12; k++)
        v[k] += c[k % 3];
    ws_shape_id s;
    ck_ok(w, create_mesh(w, v, 4, t, 4, &s));
    ws_vec3 off;
    ck_ok(w, ws_shape_get_centroid_offset(w, s, &off));
    ck_assert_double_eq_tol(off.x, c[0] + a / 4, 1e-12);
    ck_assert_double_eq_tol(off.y, c[1] + a / 4, 1e-12);
    ck_assert_double_eq_tol(off.z, c[2] + a / 4, 1e-12);
    ws_shape_info i = info_of(w, s);
    ck_assert(off.x == i.centroid.x && off.y == i.centroid.y && off.z == i.centroid.z);

    double rv[12];
    uint32_t rt[12];
    size_t nv, nt;
    ck_ok(w, ws_shape_copy_mesh(w, s, rv, 4, &nv, rt, 4, &nt));
    const double h = 0.5 * sqrt(2.0); /* 90 deg about z: (x, y) -> (-y, x) */
    const ws_quat q[2] = {{1, 0, 0, 0}, {h, 0, 0, h}};
    for (int r = 0; r < 2; r++) {
        ws_body_def bd;
        ws_body_def_init(&bd);
        bd.shape = s;
        bd.mass = 1.0;
        bd.position = off;
        bd.orientation = q[r];
        ws_body_id b;
        ck_ok(w, ws_body_create(w, &bd, &b));
        for (int k = 0; k < 4; k++) {
            ws_vec3 local = {rv[3 * k], rv[3 * k + 1], rv[3 * k + 2]}, g;
            ck_ok(w, ws_body_get_world_point(w, b, &local, &g));
            /* The input vertex, turned about the offset point by the body's orientation. */
            double dx = v[3 * k] - off.x, dy = v[3 * k + 1] - off.y, dz = v[3 * k + 2] - off.z;
            ws_vec3 want = r == 0 ? (ws_vec3){v[3 * k], v[3 * k + 1], v[3 * k + 2]}
                                  : (ws_vec3){off.x - dy, off.y + dx, off.z + dz};
            ck_assert_msg(fabs(g.x - want.x) < 1e-12 && fabs(g.y - want.y) < 1e-12 &&
                              fabs(g.z - want.z) < 1e-12,
                          "orientation %d, vertex %d at (%.15g %.15g %.15g), want (%.15g %.15g "
                          "%.15g)",
                          r, k, g.x, g.y, g.z, want.x, want.y, want.z);
        }
    }
    /* The builders are centred already; bad calls are errors, not crashes. */
    ws_shape_id box;
    ck_ok(w, ws_shape_create_box(w, 1, 2, 3, &box));
    ck_ok(w, ws_shape_get_centroid_offset(w, box, &off));
    ck_assert(fabs(off.x) + fabs(off.y) + fabs(off.z) < 1e-15);
    ck_assert_int_eq(ws_shape_get_centroid_offset(w, box, NULL), WS_ERR_INVALID_ARGUMENT);
    ck_ok(w, ws_shape_destroy(w, box));
    ck_assert_int_eq(ws_shape_get_centroid_offset(w, box, &off), WS_ERR_STALE_HANDLE);
    ck_assert_int_eq(ws_shape_get_centroid_offset(NULL, s, &off), WS_ERR_INVALID_ARGUMENT);
    ws_world_destroy(w);
}
END_TEST

/* ---- tetrahedron ---- */

START_TEST(test_tetrahedron)
{
    ws_world *w = new_world(2.5e-4);
    /* The corner tetrahedron of edge a: V = a^3/6, centroid (a/4)(1,1,1). Its second moments
     * about the origin are int x^2 = a^5/60 and int xy = a^5/120, so about the centroid
     * C_xx = a^5 (1/60 - 1/96) = a^5/160 and C_xy = a^5 (1/120 - 1/96) = -a^5/480, and
     * I_xx = C_yy + C_zz = a^5/80, I_xy = -C_xy = a^5/480. */
    const double a = 0.5;
    const double v[12] = {0, 0, 0, a, 0, 0, 0, a, 0, 0, 0, a};
    static const uint32_t t[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    ws_shape_id s;
    ck_ok(w, create_mesh(w, v, 4, t, 4, &s));
    ws_shape_info i = info_of(w, s);
    ck_rel(i.volume, a * a * a / 6.0, RT);
    ck_rel(i.centroid.x, a / 4, RT);
    ck_rel(i.centroid.y, a / 4, RT);
    ck_rel(i.centroid.z, a / 4, RT);
    const double a5 = a * a * a * a * a;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            ck_rel(i.inertia_unit.m[3 * r + c], r == c ? a5 / 80.0 : a5 / 480.0, RT);
    ck_assert_uint_eq(i.point_count, 4);
    ck_assert_uint_eq(i.face_count, 4);
    ck_assert_uint_eq(i.edge_count, 6);
    ck_assert_int_eq(i.convex, 1);
    ws_world_destroy(w);
}
END_TEST

/* ---- cylinder (regular prism) ---- */

START_TEST(test_cylinder_prism)
{
    ws_world *w = new_world(2.5e-4);
    const double r = 0.3, h = 0.5;
    const int ns[] = {3, 7, 64};
    for (size_t k = 0; k < sizeof ns / sizeof ns[0]; k++) {
        const int n = ns[k];
        ws_shape_id s;
        ck_ok(w, ws_shape_create_cylinder(w, r, h, n, &s));
        ws_shape_info i = info_of(w, s);
        /* n isosceles triangles of apex angle al = 2 pi / n: area A = n r^2 sin(al) / 2. Each
         * triangle (0, p, q) has polar moment (A_t / 6)(|p|^2 + |q|^2 + p.q) = A_t r^2 (2 + cos al)
         * / 6, so J = n r^4 sin(al) (2 + cos al) / 12, split equally between x and y (a regular
         * polygon's second moment is isotropic). Prism of height h, density 1:
         * Izz = h J, Ixx = Iyy = h J / 2 + A h^3 / 12. */
        const double al = 2.0 * PI / n;
        const double A = 0.5 * n * r * r * sin(al);
        const double Jp = n * r * r * r * r * sin(al) * (2.0 + cos(al)) / 12.0;
        ck_rel(i.volume, A * h, RT);
        double want[3] = {h * Jp / 2 + A * h * h * h / 12, h * Jp / 2 + A * h * h * h / 12, h * Jp};
        check_diag_inertia(&i.inertia_unit, want, RT);
        /* The polygon's centroid is its centre, even for odd n. */
        ck_assert_double_eq_tol(i.centroid.x, 0.0, 1e-15);
        ck_assert_double_eq_tol(i.centroid.y, 0.0, 1e-15);
        ck_assert_double_eq_tol(i.centroid.z, 0.0, 1e-15);
        ck_assert_uint_eq(i.point_count, 2 * n);
        ck_assert_uint_eq(i.triangle_count, 4 * n - 4);
        ck_assert_uint_eq(i.face_count, n + 2);
        ck_assert_uint_eq(i.edge_count, 3 * n); /* n side edges and two rims; not the cap fans */
        ck_assert_int_eq(i.convex, 1);
    }
    ws_shape_id s;
    ck_assert_int_eq(ws_shape_create_cylinder(w, r, h, 2, &s), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_shape_create_cylinder(w, r, h, 1025, &s), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_shape_create_cylinder(w, -r, h, 8, &s), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_shape_create_cylinder(w, r, NAN, 8, &s), WS_ERR_INVALID_ARGUMENT);
    ck_err_has(w, "segments");
    ws_world_destroy(w);
}
END_TEST

/* ---- rejected meshes ---- */

static void expect_rejected(ws_world *w, const double *v, size_t nv, const uint32_t *t, size_t nt,
                            ws_status want, const char *word)
{
    ws_world_stats before, after;
    ck_ok(w, ws_world_get_stats(w, &before));
    ws_shape_id s = {12345};
    ws_status st = create_mesh(w, v, nv, t, nt, &s);
    ck_assert_msg(st == want, "expected %s ('%s'), got %s (%s)", ws_status_string(want), word,
                  ws_status_string(st), ws_world_last_error(w));
    ck_err_has(w, word);
    /* A refused mesh says what to do about it, and the text ends with that hint (or with the
     * reason), not with stray digits of a format's padding arguments. */
    const char *e = ws_world_last_error(w);
    size_t n = strlen(e);
    if (want == WS_ERR_BAD_MESH && strstr(e, "triangles, got") == NULL &&
        strstr(e, "does not exist") == NULL) {
        ck_err_has(w, "repair");
        ck_assert_msg(e[n - 1] == ')', "error does not end with its hint: '%s'", e);
    }
    if (want == WS_ERR_INVALID_ARGUMENT)
        ck_assert_msg(n > strlen(word) && strcmp(e + n - strlen(word), word) == 0,
                      "error does not end with '%s': '%s'", word, e);
    ck_assert_int_eq(ws_shape_is_valid(w, s), 0);
    /* Whatever was allocated for the checks was given back. */
    ck_ok(w, ws_world_get_stats(w, &after));
    ck_assert_uint_eq(after.bytes_in_use, before.bytes_in_use);
}

START_TEST(test_rejected_meshes)
{
    ws_world *w = new_world(2.5e-4);
    uint32_t t[48];
    double v[30];
    ws_shape_id ok;
    ck_ok(w, create_mesh(w, cube_v, 8, cube_t, 12, &ok)); /* the base mesh itself is fine */

    /* Open: the last triangle removed. */
    expect_rejected(w, cube_v, 8, cube_t, 11, WS_ERR_BAD_MESH, "closed");

    /* Open, named by the edge the removed triangle left. */
    expect_rejected(w, cube_v, 8, cube_t, 11, WS_ERR_BAD_MESH, "edge (");

    /* Non-manifold: a triangle listed twice puts three triangles on each of its edges. */
    memcpy(t, cube_t, sizeof cube_t);
    memcpy(t + 36, cube_t, 3 * sizeof *cube_t);
    expect_rejected(w, cube_v, 8, t, 13, WS_ERR_BAD_MESH, "not manifold");
    ck_err_has(w, "belongs to 3 triangles");

    /* One triangle flipped: its edges run the same way as their neighbours'. */
    memcpy(t, cube_t, sizeof cube_t);
    t[1] = cube_t[2];
    t[2] = cube_t[1];
    expect_rejected(w, cube_v, 8, t, 12, WS_ERR_BAD_MESH, "winding");

    /* All flipped: consistent, closed, but inside out. */
    for (int k = 0; k < 12; k++) {
        t[3 * k] = cube_t[3 * k];
        t[3 * k + 1] = cube_t[3 * k + 2];
        t[3 * k + 2] = cube_t[3 * k + 1];
    }
    expect_rejected(w, cube_v, 8, t, 12, WS_ERR_BAD_MESH, "volume");

    /* A repeated index. */
    memcpy(t, cube_t, sizeof cube_t);
    t[2] = t[0];
    expect_rejected(w, cube_v, 8, t, 12, WS_ERR_BAD_MESH, "degenerate");

    /* Collinear points in an otherwise closed, consistently wound mesh: vertex 8 is the midpoint
     * of edge 0-1; the bottom triangle (0,3,1) becomes (0,3,8) + (8,3,1), and the sliver (0,8,1)
     * closes the gap against the side triangle (0,1,5). Every edge has two opposite uses. */
    memcpy(v, cube_v, sizeof cube_v);
    v[24] = 0.5, v[25] = 0.0, v[26] = 0.0;
    memcpy(t, cube_t, sizeof cube_t);
    t[3] = 0, t[4] = 3, t[5] = 8;
    const uint32_t extra[6] = {8, 3, 1, 0, 8, 1};
    memcpy(t + 36, extra, sizeof extra);
    expect_rejected(w, v, 9, t, 14, WS_ERR_BAD_MESH, "degenerate");
    /* ... and without the sliver (0,1,5 split instead) the same vertices make a good mesh. */
    t[36 + 3] = 0, t[36 + 4] = 8, t[36 + 5] = 5; /* (0,8,5) */
    t[12] = 8, t[13] = 1, t[14] = 5;             /* (0,1,5) -> (8,1,5) */
    ck_ok(w, create_mesh(w, v, 9, t, 14, &ok));

    /* Index out of range. */
    memcpy(t, cube_t, sizeof cube_t);
    t[17] = 8;
    expect_rejected(w, cube_v, 8, t, 12, WS_ERR_BAD_MESH, "vertex");

    /* Fewer than 4 triangles. */
    expect_rejected(w, cube_v, 8, cube_t, 3, WS_ERR_BAD_MESH, "triangles");

    /* A NaN vertex: an argument error, not a mesh one. */
    memcpy(v, cube_v, sizeof cube_v);
    v[13] = NAN;
    expect_rejected(w, v, 8, cube_t, 12, WS_ERR_INVALID_ARGUMENT, "finite");
    v[13] = INFINITY;
    expect_rejected(w, v, 8, cube_t, 12, WS_ERR_INVALID_ARGUMENT, "finite");

    /* NULL arrays. */
    expect_rejected(w, NULL, 8, cube_t, 12, WS_ERR_INVALID_ARGUMENT, "NULL");
    ws_world_destroy(w);
}
END_TEST

/* ---- a non-convex mesh ---- */

START_TEST(test_l_prism_nonconvex)
{
    ws_world *w = new_world(2.5e-4);
    /* The L = [0,2]x[0,1] + [0,1]x[1,2] extruded over z in [0, hz]; reflex corner at (1,1). */
    const double hz = 0.5;
    const double px[6] = {0, 2, 2, 1, 1, 0}, py[6] = {0, 0, 1, 1, 2, 2}; /* counter-clockwise */
    double v[36];
    for (int k = 0; k < 6; k++) {
        v[3 * k] = v[3 * (k + 6)] = px[k];
        v[3 * k + 1] = v[3 * (k + 6) + 1] = py[k];
        v[3 * k + 2] = 0.0;
        v[3 * (k + 6) + 2] = hz;
    }
    uint32_t t[60], *p = t;
    /* Caps: a fan from vertex 0, which sees the whole L; the bottom one reversed (faces -z). */
    for (uint32_t k = 1; k + 1 < 6; k++) {
        *p++ = 6, *p++ = 6 + k, *p++ = 6 + k + 1;
        *p++ = 0, *p++ = k + 1, *p++ = k;
    }
    /* Sides: the quad over edge (k, k+1) of the polygon, outward because the polygon runs
     * counter-clockwise. */
    for (uint32_t k = 0; k < 6; k++) {
        uint32_t j = (k + 1) % 6;
        *p++ = k, *p++ = j, *p++ = j + 6;
        *p++ = k, *p++ = j + 6, *p++ = k + 6;
    }
    ck_assert_int_eq(p - t, 60);
    ws_shape_id s;
    ck_ok(w, create_mesh(w, v, 12, t, 20, &s));
    ws_shape_info i = info_of(w, s);
    ck_assert_int_eq(i.convex, 0);
    ck_assert_uint_eq(i.face_count, 8); /* two caps, six sides */

    /* Two boxes: B1 = 2 x 1 x hz at (1, 0.5, hz/2), B2 = 1 x 1 x hz at (0.5, 1.5, hz/2). */
    const double V1 = 2 * hz, V2 = hz, V = V1 + V2;
    const double c1[3] = {1, 0.5, hz / 2}, c2[3] = {0.5, 1.5, hz / 2};
    double g[3];
    for (int a = 0; a < 3; a++)
        g[a] = (V1 * c1[a] + V2 * c2[a]) / V;
    ck_rel(i.volume, V, RT);
    ck_rel(i.centroid.x, g[0], RT);
    ck_rel(i.centroid.y, g[1], RT);
    ck_rel(i.centroid.z, g[2], RT);
    /* Inertia about the centroid by the parallel-axis theorem, I = sum J_box + V (|d|^2 1 - d d^T).
     */
    double J1[3], J2[3], I[9] = {0};
    box_inertia(2, 1, hz, J1);
    box_inertia(1, 1, hz, J2);
    const double *cs[2] = {c1, c2}, *Js[2] = {J1, J2}, Vs[2] = {V1, V2};
    for (int b = 0; b < 2; b++) {
        double d[3] = {cs[b][0] - g[0], cs[b][1] - g[1], cs[b][2] - g[2]};
        double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                I[3 * r + c] += (r == c ? Js[b][r] + Vs[b] * d2 : 0.0) - Vs[b] * d[r] * d[c];
    }
    double scale = fmax(I[0], fmax(I[4], I[8]));
    for (int k = 0; k < 9; k++)
        ck_assert_msg(fabs(i.inertia_unit.m[k] - I[k]) <= RT * scale, "I[%d] = %.17g, want %.17g",
                      k, i.inertia_unit.m[k], I[k]);

    /* A non-convex shape still makes a body, with mass from its volume. */
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = s;
    bd.density = 100.0;
    ws_body_id b;
    ck_ok(w, ws_body_create(w, &bd, &b));
    double m = 0;
    ck_ok(w, ws_body_get_mass(w, b, &m));
    ck_rel(m, 100.0 * V, RT);
    ws_world_destroy(w);
}
END_TEST

/* ---- mass from density ---- */

START_TEST(test_mass_from_density)
{
    ws_world *w = new_world(2.5e-4);
    const double a = 0.2, rho = 500.0;
    ws_shape_id s;
    ck_ok(w, ws_shape_create_box(w, a, a, a, &s));
    ws_body_def bd;
    ws_body_def_init(&bd);
    bd.shape = s;
    bd.mass = 0.0;
    bd.density = rho;
    ws_body_id b;
    ck_ok(w, ws_body_create(w, &bd, &b));
    double m = 0;
    ck_ok(w, ws_body_get_mass(w, b, &m));
    ck_rel(m, rho * a * a * a, RT); /* 4 kg */
    ck_rel(m, 4.0, RT);
    ws_mat3 J;
    ck_ok(w, ws_body_get_inertia(w, b, &J));
    double want[3] = {m * a * a / 6, m * a * a / 6, m * a * a / 6};
    check_diag_inertia(&J, want, RT);

    /* An explicit mass wins over the density, and the inertia follows the mass. */
    bd.mass = 3.0;
    bd.position.x = 1.0;
    ck_ok(w, ws_body_create(w, &bd, &b));
    ck_ok(w, ws_body_get_mass(w, b, &m));
    ck_assert_double_eq(m, 3.0);
    ck_ok(w, ws_body_get_inertia(w, b, &J));
    double want3[3] = {3.0 * a * a / 6, 3.0 * a * a / 6, 3.0 * a * a / 6};
    check_diag_inertia(&J, want3, RT);

    /* A given inertia is used as is. */
    bd.inertia.m[0] = 0.1, bd.inertia.m[4] = 0.2, bd.inertia.m[8] = 0.25;
    bd.position.x = 2.0;
    ck_ok(w, ws_body_create(w, &bd, &b));
    ck_ok(w, ws_body_get_inertia(w, b, &J));
    double given[3] = {0.1, 0.2, 0.25};
    check_diag_inertia(&J, given, 0.0);
    ws_world_destroy(w);
}
END_TEST

static void add(Suite *s, const char *name, const TTest *t, double timeout)
{
    TCase *tc = tcase_create(name);
    tcase_set_timeout(tc, timeout);
    tcase_add_test(tc, t);
    suite_add_tcase(s, tc);
}

static Suite *shape_suite(void)
{
    Suite *s = suite_create("shape");
    /* Each case builds a few small meshes: well under a second; 10 s leaves room for slow CI. */
    add(s, "box", test_box, 10);
    add(s, "mesh_recentred", test_mesh_recentred, 10);
    add(s, "centroid_offset_places_mesh", test_centroid_offset_places_mesh, 10);
    add(s, "tetrahedron", test_tetrahedron, 10);
    add(s, "cylinder_prism", test_cylinder_prism, 10);
    add(s, "rejected_meshes", test_rejected_meshes, 10);
    add(s, "l_prism_nonconvex", test_l_prism_nonconvex, 10);
    add(s, "mass_from_density", test_mass_from_density, 10);
    return s;
}

int main(void)
{
    return run_suite(shape_suite());
}
