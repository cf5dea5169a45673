/* VTK output: the series Def, its strides, the named blocks of a frame, the forms, and failures
 * (bad Def, unwritable directory, out of memory). The files' contents are read back by VTK itself
 * in bindings/python/tests/test_vtk_files.py; here the C side of the contract. */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "helpers.h"

/* A fresh directory under TMPDIR (or /tmp). */
static void temp_dir(char *dir, size_t cap)
{
    const char *base = getenv("TMPDIR");
    snprintf(dir, cap, "%s/wrapsim_io_XXXXXX", base && *base ? base : "/tmp");
    ck_assert_ptr_nonnull(mkdtemp(dir));
}

/* The whole of a small file as a string (caller frees); NULL when it cannot be read. */
static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s)
        s[n] = 0;
    fclose(f);
    return s;
}

static void remove_dir(const char *dir)
{
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    ck_assert_int_eq(system(cmd), 0);
}

/* A box on the ground wrapped in a 12 x 4 band: bodies, film and contacts to write. */
static ws_world *wrapped_box_named(test_alloc *a, const char *film_name)
{
    ws_world_def d;
    ws_world_def_init(&d);
    d.dt = 1e-3;
    if (a)
        test_alloc_install(&d, a);
    ws_world *w = NULL;
    ck_assert_int_eq(ws_world_create(&d, &w), WS_OK);
    add_ground(w, 1.0, no_material());
    ws_body_id box = add_box(w, 0.3, 0.3, 0.3, 5.0, (ws_vec3){0, 0, 0.152}, no_material(), "box");
    ws_law_def ld;
    ws_law_def_init(&ld);
    ld.type = WS_LAW_LINEAR_ELASTIC;
    ld.stiffness = 50.0;
    ws_law_id law;
    ck_ok(w, ws_law_create(w, &ld, &law));
    ws_web_def wd;
    ws_web_def_init(&wd);
    wd.law = law;
    wd.node_mass = 1e-3;
    wd.substeps = 24; /* its stable step is 0.099 ms, of which the check lets it use half */
    wd.name = film_name;
    ws_band_def bd;
    ws_band_def_init(&bd);
    bd.bodies = &box;
    bd.body_count = 1;
    bd.z_bottom = 0.05;
    bd.z_top = 0.25;
    bd.n_around = 12;
    bd.n_up = 4;
    bd.prestretch_around = 0.2;
    bd.prestretch_up = 0.1;
    ws_web_id web;
    ck_ok(w, ws_web_create_band(w, &wd, &bd, &web));
    return w;
}

static ws_world *wrapped_box(test_alloc *a)
{
    return wrapped_box_named(a, "wrap");
}

START_TEST(def_is_checked)
{
    ws_world *w = wrapped_box(NULL);
    ws_vtk_series *s = (ws_vtk_series *)&s; /* not NULL: a failure must clear it */
    ws_vtk_series_def d;
    memset(&d, 0, sizeof d);
    ck_assert_int_eq(ws_vtk_series_create_def(w, &d, &s), WS_ERR_UNINITIALIZED_DEF);
    ck_assert_ptr_null(s);
    ck_assert_int_eq(ws_vtk_series_create_def(w, NULL, &s), WS_ERR_INVALID_ARGUMENT);
    ck_assert_int_eq(ws_vtk_series_create_def(NULL, &d, &s), WS_ERR_INVALID_ARGUMENT);
    ws_vtk_series_def_init(&d);
    ck_assert_int_eq(d.format, WS_VTK_COMPRESSED);
    ck_assert_int_eq(d.frame_stride, 1);
    ck_assert_int_eq(d.contacts, 1);
    ck_assert_int_eq(d.springs, 0);
    ck_assert_int_eq(d.double_precision, 0);
    ck_assert_int_eq(d.containment_bands, WS_VTK_DEFAULT_BANDS);
    ck_assert_int_eq(ws_vtk_series_create_def(w, &d, &s), WS_ERR_INVALID_ARGUMENT); /* no dir */
    d.directory = "/tmp";
    d.basename = "a/b";
    ck_assert_int_eq(ws_vtk_series_create_def(w, &d, &s), WS_ERR_INVALID_ARGUMENT);
    d.basename = "run";
    /* Each value out of its range, with the field named in the last error. */
    for (int k = 0; k < 6; k++) {
        ws_vtk_series_def e = d;
        const char *field = "";
        switch (k) {
        case 0:
            e.format = 3, field = "format";
            break;
        case 1:
            e.format = -1, field = "format";
            break;
        case 2:
            e.frame_stride = 0, field = "frame_stride";
            break;
        case 3:
            e.time_stride = -0.1, field = "time_stride";
            break;
        case 4:
            e.time_stride = NAN, field = "time_stride";
            break;
        default:
            e.containment_bands = WS_VTK_MAX_BANDS + 1, field = "containment_bands";
            break;
        }
        ck_assert_int_eq(ws_vtk_series_create_def(w, &e, &s), WS_ERR_INVALID_ARGUMENT);
        ck_assert_ptr_null(s);
        ck_assert_msg(strstr(ws_world_last_error(w), field), "case %d: %s", k,
                      ws_world_last_error(w));
    }
    ck_assert_int_eq(ws_vtk_series_write_frame(NULL), WS_ERR_INVALID_ARGUMENT);
    ws_vtk_series_destroy(NULL);
    ws_world_destroy(w);
}
END_TEST

/* Offered every step for 0.2 s at dt = 1 ms (201 calls, t = 0 .. 0.2 s): a frame stride of 3
 * writes calls 0, 3, ..., 198: 67 frames; a time stride of 0.02 s writes t = 0, 0.02, ..., 0.2:
 * 11; both together: the first call of the frame stride in each 0.02 s slot (t = 0, 0.021,
 * 0.042, ..., 0.180), and none in the slot of 0.2 s, whose only call (n = 200) is not a multiple
 * of 3: 10. */
START_TEST(strides_choose_the_frames)
{
    static const struct {
        int frame_stride;
        double time_stride;
        size_t frames;
    } cases[] = {{1, 0.0, 201}, {3, 0.0, 67}, {1, 0.02, 11}, {3, 0.02, 10}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        ws_world *w = new_world(1e-3);
        char dir[512];
        temp_dir(dir, sizeof dir);
        ws_vtk_series_def d;
        ws_vtk_series_def_init(&d);
        d.directory = dir;
        d.basename = "s";
        d.frame_stride = cases[c].frame_stride;
        d.time_stride = cases[c].time_stride;
        d.contacts = 0;
        ws_vtk_series *s;
        ck_ok(w, ws_vtk_series_create_def(w, &d, &s));
        for (int n = 0; n <= 200; n++) {
            ck_ok(w, ws_vtk_series_write_frame(s));
            if (n < 200)
                ck_ok(w, ws_world_step(w));
        }
        size_t frames = 0;
        ck_ok(w, ws_vtk_series_get_frame_count(s, &frames));
        ck_assert_msg(frames == cases[c].frames, "case %zu: %zu frames, want %zu", c, frames,
                      cases[c].frames);
        /* The .pvd lists exactly those frames. */
        char path[600];
        snprintf(path, sizeof path, "%s/s.pvd", dir);
        char *pvd = slurp(path);
        ck_assert_ptr_nonnull(pvd);
        size_t listed = 0;
        for (const char *p = pvd; (p = strstr(p, "<DataSet ")) != NULL; p++)
            listed++;
        ck_assert_uint_eq(listed, frames);
        if (cases[c].time_stride > 0 && cases[c].frame_stride == 1)
            ck_assert_ptr_nonnull(strstr(pvd, "timestep=\"0.1\""));
        free(pvd);
        ws_vtk_series_destroy(s);
        ws_world_destroy(w);
        remove_dir(dir);
    }
}
END_TEST

/* A frame is a .vtm with the blocks bodies, film (a dataset named after the web), contacts and,
 * when asked, springs, each a file beside it; in the form asked. */
START_TEST(frame_has_named_blocks_in_its_form)
{
    for (int format = WS_VTK_COMPRESSED; format <= WS_VTK_ASCII; format++) {
        ws_world *w = wrapped_box(NULL);
        ck_ok(w, ws_world_step_n(w, 20));
        char dir[512], path[700];
        temp_dir(dir, sizeof dir);
        ws_vtk_series_def d;
        ws_vtk_series_def_init(&d);
        d.directory = dir;
        d.basename = "f";
        d.format = format;
        d.springs = 1;
        ws_vtk_series *s;
        ck_ok(w, ws_vtk_series_create_def(w, &d, &s));
        ck_ok(w, ws_vtk_series_write_frame(s));
        snprintf(path, sizeof path, "%s/f_000000.vtm", dir);
        char *vtm = slurp(path);
        ck_assert_ptr_nonnull(vtm);
        const char *order[] = {"name=\"bodies\" file=\"f_000000_bodies.vtp\"",
                               "<Block index=\"1\" name=\"film\">",
                               "name=\"wrap\" file=\"f_000000_film0.vtp\"",
                               "name=\"contacts\" file=\"f_000000_contacts.vtp\"",
                               "<Block index=\"3\" name=\"springs\">",
                               "name=\"wrap\" file=\"f_000000_springs0.vtp\""};
        const char *at = vtm;
        for (size_t k = 0; k < sizeof order / sizeof order[0]; k++) {
            const char *p = strstr(at, order[k]);
            ck_assert_msg(p != NULL, "format %d: '%s' missing or out of order in\n%s", format,
                          order[k], vtm);
            at = p;
        }
        free(vtm);
        snprintf(path, sizeof path, "%s/f_000000_film0.vtp", dir);
        char *film = slurp(path);
        ck_assert_ptr_nonnull(film);
        int zlib = (ws_build_features() & WS_FEATURE_ZLIB) != 0;
        ck_assert_int_eq(strstr(film, "format=\"ascii\"") != NULL, format == WS_VTK_ASCII);
        ck_assert_int_eq(strstr(film, "vtkZLibDataCompressor") != NULL,
                         format == WS_VTK_COMPRESSED && zlib);
        ck_assert_ptr_nonnull(strstr(film, "NumberOfPolys=\"36\"")); /* 12 around x 3 up */
        ck_assert_ptr_nonnull(strstr(film, "Name=\"tension_around\""));
        ck_assert_ptr_nonnull(strstr(film, "Name=\"band_hoop_tension\""));
        free(film);
        ws_vtk_series_destroy(s);
        ws_world_destroy(w);
        remove_dir(dir);
    }
}
END_TEST

/* The .pvd grows in place frame by frame; one that no longer ends as the series left it (cut
 * short, edited) is written whole again at the next frame, listing every frame. */
START_TEST(pvd_is_appended_or_rewritten)
{
    ws_world *w = new_world(1e-3);
    char dir[512], path[600];
    temp_dir(dir, sizeof dir);
    ws_vtk_series *s;
    ck_ok(w, ws_vtk_series_create(w, dir, "p", &s));
    snprintf(path, sizeof path, "%s/p.pvd", dir);
    for (int k = 0; k < 4; k++) {
        if (k == 2) { /* cut short after its first entry, longer than the closing tags */
            FILE *f = fopen(path, "w");
            ck_assert_ptr_nonnull(f);
            fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\">\n"
                  "<Collection>\n<DataSet timestep=\"0.001\" part=\"0\" file=\"p_000000.vtm\"/>\n",
                  f);
            fclose(f);
        }
        ck_ok(w, ws_world_step(w));
        ck_ok(w, ws_vtk_series_write_frame(s));
        char *pvd = slurp(path);
        ck_assert_ptr_nonnull(pvd);
        size_t listed = 0;
        for (const char *p = pvd; (p = strstr(p, "<DataSet ")) != NULL; p++)
            listed++;
        ck_assert_uint_eq(listed, (size_t)k + 1);
        size_t n = strlen(pvd);
        ck_assert_str_eq(pvd + n - strlen("</Collection>\n</VTKFile>\n"),
                         "</Collection>\n</VTKFile>\n");
        ck_assert_ptr_nonnull(strstr(pvd, "file=\"p_000000.vtm\""));
        free(pvd);
    }
    ws_vtk_series_destroy(s);
    ws_world_destroy(w);
    remove_dir(dir);
}
END_TEST

/* A web's name is free text: in the .vtm it is written as XML wants it, and an unnamed web is
 * called web<slot>. */
START_TEST(names_are_escaped_in_the_vtm)
{
    for (int named = 0; named < 2; named++) {
        ws_world *w = wrapped_box_named(NULL, named ? "film \"A\" & <B>'s" : NULL);
        char dir[512], path[600];
        temp_dir(dir, sizeof dir);
        ws_vtk_series *s;
        ck_ok(w, ws_vtk_series_create(w, dir, "e", &s));
        ck_ok(w, ws_vtk_series_write_frame(s));
        snprintf(path, sizeof path, "%s/e_000000.vtm", dir);
        char *vtm = slurp(path);
        ck_assert_ptr_nonnull(vtm);
        const char *want =
            named ? "name=\"film &quot;A&quot; &amp; &lt;B&gt;&apos;s\"" : "name=\"web0\"";
        ck_assert_msg(strstr(vtm, want) != NULL, "%s not in\n%s", want, vtm);
        free(vtm);
        ws_vtk_series_destroy(s);
        ws_world_destroy(w);
        remove_dir(dir);
    }
}
END_TEST

/* A directory that is not there is refused when the series starts, naming it; a file that
 * cannot be written is WS_ERR_IO with its path, and no frame is counted. */
START_TEST(unwritable_directory_is_an_io_error)
{
    ws_world *w = wrapped_box(NULL);
    ws_vtk_series *s = NULL;
    ck_assert_int_eq(ws_vtk_series_create(w, "/nonexistent/wrapsim", "r", &s), WS_ERR_IO);
    ck_assert_ptr_null(s);
    ck_assert_ptr_nonnull(strstr(ws_world_last_error(w), "/nonexistent/wrapsim"));
    /* A directory that exists but whose frame file cannot be created: a directory in its way. */
    char dir[512], path[600];
    temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/r_000000_bodies.vtp", dir);
    ck_assert_int_eq(mkdir(path, 0700), 0);
    ck_ok(w, ws_vtk_series_create(w, dir, "r", &s));
    ck_assert_int_eq(ws_vtk_series_write_frame(s), WS_ERR_IO);
    ck_assert_ptr_nonnull(strstr(ws_world_last_error(w), "r_000000_bodies.vtp"));
    size_t n = 1;
    ck_ok(w, ws_vtk_series_get_frame_count(s, &n));
    ck_assert_uint_eq(n, 0);
    ck_assert_int_eq(ws_world_write_vtp(w, "/nonexistent/x.vtp"), WS_ERR_IO);
    ck_assert_int_eq(ws_world_write_vtp(w, ""), WS_ERR_INVALID_ARGUMENT);
    ws_vtk_series_destroy(s);
    ws_world_destroy(w);
    remove_dir(dir);
}
END_TEST

/* Every allocation of creating a series and writing two frames fails in turn: each failure is
 * WS_ERR_OUT_OF_MEMORY (never a crash or a partial .pvd), and every byte comes back. */
START_TEST(allocation_failures_are_reported_and_freed)
{
    char dir[512];
    temp_dir(dir, sizeof dir);
    int succeeded = 0;
    for (long fail = 0; fail < 400 && !succeeded; fail++) {
        test_alloc a = {.allocs_left = -1, .track = 1};
        ws_world *w = wrapped_box(&a);
        ck_ok(w, ws_world_step_n(w, 5));
        a.allocs_left = fail;
        ws_vtk_series *s = NULL;
        ws_status st = ws_vtk_series_create(w, dir, "m", &s);
        if (st == WS_OK && (st = ws_vtk_series_write_frame(s)) == WS_OK)
            st = ws_vtk_series_write_frame(s);
        ck_assert_msg(st == WS_OK || st == WS_ERR_OUT_OF_MEMORY, "fail after %ld: %s", fail,
                      ws_status_string(st));
        succeeded = st == WS_OK;
        a.allocs_left = -1;
        ws_vtk_series_destroy(s);
        ws_world_destroy(w);
        ck_assert_msg(a.size_errors == 0, "fail after %ld: %ld wrong sizes, first: %s", fail,
                      a.size_errors, a.size_error);
        ck_assert_int_eq(a.live, 0);
        ck_assert_int_eq(a.bytes, 0);
        test_alloc_done(&a);
    }
    ck_assert_msg(succeeded, "never succeeded in 400 allocations");
    remove_dir(dir);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io");
    add_case(s, "def", def_is_checked, 10);
    add_case(s, "strides", strides_choose_the_frames, 60);
    add_case(s, "blocks", frame_has_named_blocks_in_its_form, 30);
    add_case(s, "pvd", pvd_is_appended_or_rewritten, 10);
    add_case(s, "names", names_are_escaped_in_the_vtm, 10);
    add_case(s, "io_error", unwritable_directory_is_an_io_error, 10);
    add_case(s, "oom", allocation_failures_are_reported_and_freed, 120);
    return run_suite(s);
}
