/* Output files and paths, the same checks on Linux and on Windows (under
 * Wine; export/output_posix.c and output_win32.c): a scene file in a folder
 * whose name has non-ASCII letters is written, loaded and meshed; the mesh
 * is written there and read back byte for byte against the same mesh
 * written to a memory stream; an output being written leaves the old file
 * in place until commit (a reader never sees a partial file), and a
 * discarded one leaves no temporary file; a folder is refused as an output
 * and as a scene. On Windows a path that is not UTF-8 is refused too. */
#define _POSIX_C_SOURCE 200809L
#include "testlib.h"
#include "testfs.h"

#include <errno.h>
#include <stdlib.h>

#ifdef _WIN32
#include <wchar.h>
#include <windows.h>
#else
#include <sys/stat.h>
#endif

static const char SCENE[] =
    "{\"format\": \"libblend-scene\", \"version\": 1, \"convention\": \"zero\","
    " \"bounds\": {\"min\": [-2, -2, -2], \"max\": [2, 2, 2]},"
    " \"root\": {\"type\": \"displacement\", \"op\": \"union\", \"r\": 0.3, \"p\": 2, \"args\": ["
    "  {\"type\": \"sphere\", \"center\": [-0.5, 0, 0], \"radius\": 0.8},"
    "  {\"type\": \"sphere\", \"center\": [0.6, 0, 0], \"radius\": 0.7}]}}";

/* fopen of a UTF-8 path, as a user's program would do it on each system */
static FILE *open_utf8(const char *path, const char *mode) {
#ifdef _WIN32
    wchar_t wp[1024], wm[8];
    if (!MultiByteToWideChar(CP_UTF8, 0, path, -1, wp, 1024) ||
        !MultiByteToWideChar(CP_UTF8, 0, mode, -1, wm, 8))
        return NULL;
    return _wfopen(wp, wm);
#else
    return fopen(path, mode);
#endif
}

static int make_dir_utf8(const char *path) {
#ifdef _WIN32
    wchar_t wp[1024];
    return MultiByteToWideChar(CP_UTF8, 0, path, -1, wp, 1024) && _wmkdir(wp) == 0 ? 0 : -1;
#else
    return mkdir(path, 0777);
#endif
}

static void remove_utf8(const char *path, int dir) {
#ifdef _WIN32
    wchar_t wp[1024];
    if (!MultiByteToWideChar(CP_UTF8, 0, path, -1, wp, 1024)) return;
    if (dir)
        RemoveDirectoryW(wp);
    else
        DeleteFileW(wp);
#else
    if (dir)
        rmdir(path);
    else
        unlink(path);
#endif
}

/* the whole file, or NULL; *n its length */
static unsigned char *slurp(const char *path, size_t *n) {
    FILE *f = open_utf8(path, "rb");
    if (!f) return NULL;
    size_t cap = 1 << 16, len = 0;
    unsigned char *b = malloc(cap);
    size_t got;
    while (b && (got = fread(b + len, 1, cap - len, f)) > 0) {
        len += got;
        if (len == cap) {
            unsigned char *nb = realloc(b, cap *= 2);
            if (!nb) free(b);
            b = nb;
        }
    }
    fclose(f);
    *n = len;
    return b;
}

static int exists_utf8(const char *path) {
    FILE *f = open_utf8(path, "rb");
    if (f) fclose(f);
    return f != NULL;
}

static void test_non_ascii_paths(void **state) {
    (void)state;
    char tmp[512], dir[700], scene[800], mesh[800];
    assert_int_equal(test_mkdtemp(tmp, sizeof tmp, "libblend-out"), 0);
    /* "Szenen-Überblick ñ 場面" in UTF-8 */
    snprintf(dir, sizeof dir,
             "%s/Szenen-\xc3\x9c"
             "berblick \xc3\xb1 \xe5\xa0\xb4\xe9\x9d\xa2",
             tmp);
    assert_int_equal(make_dir_utf8(dir), 0);
    snprintf(scene, sizeof scene, "%s/kugeln-\xc3\xa9t\xc3\xa9.json", dir);
    snprintf(mesh, sizeof mesh,
             "%s/ma\xc3\xb1"
             "ana.ply",
             dir);
    lb_error e = {LB_OK, ""};
    assert_int_equal(lb_output_write_file(scene, SCENE, strlen(SCENE), &e), LB_OK);
    lb_scene *sc = NULL;
    if (lb_scene_load(scene, &sc, &e) != LB_OK) fail_msg("load %s: %s", scene, e.message);
    lb_evaluator *ev = NULL;
    assert_int_equal(lb_evaluator_create(sc, &ev, &e), LB_OK);
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    lb_scene_bounds(sc, o.bmin, o.bmax);
    o.resolution = 32;
    o.threads = 2;
    lb_mesh *m = NULL;
    assert_int_equal(lb_mesh_create(ev, &o, &m, &e), LB_OK);
    assert_true(m->ntriangles > 500);
    assert_int_equal(lb_mesh_write(m, mesh, LB_MESH_FORMAT_AUTO, &e), LB_OK);
    /* read back: the same bytes as the mesh written to a stream */
    size_t n = 0, ns = 0;
    unsigned char *bytes = slurp(mesh, &n);
    assert_non_null(bytes);
    FILE *mem = tmpfile();
    assert_non_null(mem);
    assert_int_equal(lb_mesh_write_stream(m, mem, LB_MESH_FORMAT_PLY, &e), LB_OK);
    ns = (size_t)ftell(mem);
    rewind(mem);
    unsigned char *ref = malloc(ns);
    assert_non_null(ref);
    assert_int_equal(fread(ref, 1, ns, mem), ns);
    fclose(mem);
    assert_int_equal(n, ns);
    assert_memory_equal(bytes, ref, n);
    /* and its header says what it holds */
    char want[128];
    snprintf(want, sizeof want, "element vertex %lu\n", (unsigned long)m->nvertices);
    assert_non_null(strstr((const char *)bytes, want));
    printf("%s: %lu bytes, %lu triangles, read back whole\n", mesh, (unsigned long)n,
           (unsigned long)m->ntriangles);
    free(bytes);
    free(ref);

    /* replacing a file: the old bytes stay until commit */
    lb_output *out = NULL;
    assert_int_equal(lb_output_open(mesh, &out, &e), LB_OK);
    fputs("partial", lb_output_stream(out));
    fflush(lb_output_stream(out));
    bytes = slurp(mesh, &n);
    assert_non_null(bytes);
    assert_int_equal(n, ns);
    free(bytes);
    const char *temp = lb_output_temp_name(out);
    char temp_copy[1024] = "";
    if (temp) snprintf(temp_copy, sizeof temp_copy, "%s", temp);
    lb_output_discard(out);
    bytes = slurp(mesh, &n);
    assert_non_null(bytes);
    assert_int_equal(n, ns); /* discarded: the old file, whole */
    free(bytes);
    if (temp_copy[0]) assert_false(exists_utf8(temp_copy));
    assert_int_equal(lb_output_open(mesh, &out, &e), LB_OK);
    fputs("new bytes", lb_output_stream(out));
    assert_int_equal(lb_output_commit(out, &e), LB_OK);
    bytes = slurp(mesh, &n);
    assert_non_null(bytes);
    assert_int_equal(n, 9);
    assert_memory_equal(bytes, "new bytes", 9);
    free(bytes);

    /* a folder is neither an output nor a scene */
    assert_int_equal(lb_output_open(dir, &out, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "folder"));
    lb_scene *none = NULL;
    assert_int_equal(lb_scene_load(dir, &none, &e), LB_ERR_INVALID_ARGUMENT);
    assert_null(none);
    assert_non_null(strstr(e.message, "is a directory"));
#ifdef _WIN32
    /* bytes that are not UTF-8 name no file on Windows: refused, not guessed */
    char bad[800];
    snprintf(bad, sizeof bad, "%s/caf\xe9.ply", dir);
    assert_int_equal(lb_output_open(bad, &out, &e), LB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(e.message, "not UTF-8"));
#endif

    lb_mesh_free(m);
    lb_evaluator_free(ev);
    lb_scene_free(sc);
    remove_utf8(mesh, 0);
    remove_utf8(scene, 0);
    remove_utf8(dir, 1);
    test_rmdir(tmp);
}

int main(void) {
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_non_ascii_paths)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
