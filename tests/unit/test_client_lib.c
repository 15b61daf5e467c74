/* test_client_lib.c — libmeshcorr as a user gets it: in-memory meshes encoded
 * with their vertex order and positions kept (or quantized on request) and
 * decoded back, the parameter list as data, a shared library that links no
 * engine library, and `make install` (the library part, into a
 * temporary DESTDIR) giving a header, static and shared libraries and a
 * pkg-config file that a small program builds with and talks to a real
 * meshcorrd through. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testfile.h"
#include "support/testldd.h"
#include "support/testmesh.h"
#include "support/testrun.h"
#include "mesh/draco_bridge.h"
#include "mesh/mesh.h"
#include "meshcorr.h"

#include <math.h>
#include <signal.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

TEST(in_memory_mesh_encodes_to_draco_keeping_vertex_order_and_faces)
{
    mesh *m = testmesh_icosphere(2);
    CHECK(m);
    unsigned long long seed = 7;
    for (int i = 0; i < 3 * m->nv; i++)
        m->v[i] += 0.05 * testmesh_rand(&seed);
    unsigned char *buf = NULL;
    size_t len = 0;
    char err[512];
    CHECK_INT(mc_encode_mesh(m->v, m->nv, m->f, m->nf, &buf, &len, err, sizeof err), 0);
    CHECK(buf && len > 0);
    double *v = NULL;
    int *f = NULL, nv = 0, nf = 0;
    CHECK_INT(dracob_decode(buf, len, MESH_MAX_VERTICES, MESH_MAX_FACES, &v, &nv, &f, &nf, err, sizeof err), 0);
    CHECK_INT(nv, m->nv);
    CHECK_INT(nf, m->nf);
    /* lossless by default: the same doubles */
    CHECK(memcmp(v, m->v, sizeof(double) * 3 * (size_t)nv) == 0);
    for (int t = 0; t < nf; t++) {     /* the same triangle, possibly rotated */
        int r = 0;
        while (r < 3 && f[3 * t] != m->f[3 * t + r])
            r++;
        CHECK(r < 3);
        for (int k = 0; k < 3; k++)
            CHECK_INT(f[3 * t + k], m->f[3 * t + (r + k) % 3]);
    }
    free(v);
    free(f);
    free(buf);
    mesh_free(m);
}

/* --quantization's library side: 16 bits is within a step of the bounding
 * box and smaller; a file encodes as its arrays do; bits out of range and a
 * .drc file given bits are told apart. */
TEST(quantized_encoding_is_smaller_within_its_step_and_bad_bits_are_refused)
{
    mesh *m = NULL;
    char err[512], path[600];
    snprintf(path, sizeof path, "%s", harness_data_path("tosca_hires/Meshes/wolf0.off"));
    CHECK_INT(mesh_read(path, &m, err, sizeof err), 0);
    unsigned char *lb = NULL, *qb = NULL, *fb = NULL;
    size_t ll = 0, ql = 0, fl = 0;
    CHECK_INT(mc_encode_mesh(m->v, m->nv, m->f, m->nf, &lb, &ll, err, sizeof err), 0);
    CHECK_INT(mc_encode_mesh_quantized(m->v, m->nv, m->f, m->nf, 16, &qb, &ql, err, sizeof err), 0);
    CHECK_INT(mc_encode_mesh_file(path, &fb, &fl, err, sizeof err), 0);
    CHECK(fl == ll && memcmp(fb, lb, ll) == 0);
    free(fb);
    CHECK_INT(mc_encode_mesh_file_quantized(path, 16, &fb, &fl, err, sizeof err), 0);
    CHECK(fl == ql && memcmp(fb, qb, ql) == 0);
    CHECK(ql < ll);
    double *v = NULL, ext = 0;
    int *f = NULL, nv = 0, nf = 0;
    CHECK_INT(dracob_decode(qb, ql, MESH_MAX_VERTICES, MESH_MAX_FACES, &v, &nv, &f, &nf, err, sizeof err), 0);
    for (int k = 0; k < 3; k++) {
        double lo = m->v[k], hi = m->v[k];
        for (int i = 1; i < m->nv; i++)
            lo = fmin(lo, m->v[3 * i + k]), hi = fmax(hi, m->v[3 * i + k]);
        ext = fmax(ext, hi - lo);
    }
    int moved = 0;
    for (int i = 0; i < 3 * nv; i++) {
        CHECK_NEAR(v[i], m->v[i], ext / 65535.0);
        moved += v[i] != m->v[i];
    }
    CHECK(moved > 0);
    free(v);
    free(f);
    unsigned char *bad = (unsigned char *)"x";
    size_t bl = 1;
    CHECK_INT(mc_encode_mesh_quantized(m->v, m->nv, m->f, m->nf, 31, &bad, &bl, err, sizeof err), MC_EARG);
    CHECK(bad == NULL && bl == 0);
    CHECK_STR_HAS(err, "quantization of 31 bits");
    CHECK_INT(mc_encode_mesh_file_quantized(path, -1, &bad, &bl, err, sizeof err), MC_EARG);
    CHECK_STR_HAS(err, "quantization of -1 bits");
    free(lb);
    free(qb);
    free(fb);
    mesh_free(m);
}

TEST(in_memory_mesh_with_a_bad_index_is_refused_with_a_message)
{
    static const double v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const int f[] = {0, 1, 3};
    unsigned char *buf = (unsigned char *)"x";
    size_t len = 9;
    char err[512] = "";
    CHECK_INT(mc_encode_mesh(v, 3, f, 1, &buf, &len, err, sizeof err), MC_EARG);
    CHECK(buf == NULL && len == 0);
    CHECK_STR_HAS(err, "out of range");
    CHECK_INT(mc_encode_mesh(v, 2, f, 1, &buf, &len, err, sizeof err), MC_EARG);
}

TEST(in_memory_mesh_with_a_nan_is_refused_naming_the_vertex)
{
    double v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const int f[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    v[3 * 2 + 1] = NAN;
    unsigned char *buf = NULL;
    size_t len = 0;
    char err[512] = "";
    CHECK_INT(mc_encode_mesh(v, 4, f, 4, &buf, &len, err, sizeof err), MC_EARG);
    CHECK(buf == NULL && len == 0);
    CHECK_STR_HAS(err, "vertex 2: y coordinate is NaN");
}

static const char prog[] =
    "#include <meshcorr.h>\n"
    "#include <stdio.h>\n"
    "#include <stdlib.h>\n"
    "int main(int argc, char **argv)\n"
    "{\n"
    "    static const double v[] = {0,0,0, 1,0,0, 0,1,0, 0,0,1};\n"
    "    static const int f[] = {0,2,1, 0,1,3, 0,3,2, 1,2,3};\n"
    "    unsigned char *b; size_t n; char err[256];\n"
    "    if (mc_encode_mesh(v, 4, f, 4, &b, &n, err, sizeof err)) return 3;\n"
    "    free(b);\n"
    "    printf(\"strerror %s\\n\", mc_strerror(MC_ENOT_FOUND));\n"
    "    mc_client *c;\n"
    "    int rc = mc_connect(argc > 1 ? argv[1] : \"unix:/nonexistent\", NULL, &c, err, sizeof err);\n"
    "    if (rc) { printf(\"connect %s\\n\", mc_strerror(rc)); return 1; }\n"
    "    rc = mc_ping(c);\n"
    "    printf(\"user %s ping %d\\n\", mc_user(c), rc);\n"
    "    mc_close(c);\n"
    "    return rc != 0;\n"
    "}\n";

TEST(draco_bytes_decode_back_to_the_arrays_and_junk_is_refused)
{
    mesh *m = testmesh_icosphere(1);
    CHECK(m);
    unsigned char *buf = NULL;
    size_t len = 0;
    char err[512];
    CHECK_INT(mc_encode_mesh(m->v, m->nv, m->f, m->nf, &buf, &len, err, sizeof err), 0);
    double *v = NULL;
    int *f = NULL, nv = 0, nf = 0;
    CHECK_INT(mc_decode_mesh(buf, len, &v, &nv, &f, &nf, err, sizeof err), 0);
    CHECK_INT(nv, m->nv);
    CHECK_INT(nf, m->nf);
    CHECK(memcmp(v, m->v, sizeof(double) * 3 * (size_t)nv) == 0);
    free(v);
    free(f);
    CHECK_INT(mc_decode_mesh(buf, len / 2, &v, &nv, &f, &nf, err, sizeof err), MC_EFILE);
    CHECK(!v && !f && err[0]);
    free(buf);
    mesh_free(m);
}

/* mc_read_landmarks is the CLI's reader: a pairs file, two lists (a BIM
 * .vts list's base told by its positions), --one-based; a missing file and
 * a malformed one are refused naming the file and line; exported in its
 * own version node. */
TEST(landmark_files_read_as_the_clis_pairs_and_lists_with_file_and_line_errors)
{
    mesh *m = testmesh_icosphere(1);   /* 42 vertices */
    CHECK(m);
    uint32_t *lm = NULL, n = 0;
    char err[512], src[512], tgt[512], out[512];
    const char *p = testfile_text("pairs.txt", "# source target\n0 5\n1 6\n\n2 7\n3 8\n");
    CHECK_INT(mc_read_landmarks(p, NULL, 0, m->v, m->nv, m->v, m->nv, &lm, &n, err, sizeof err), 0);
    CHECK_INT(n, 4);
    for (uint32_t k = 0; k < n; k++) {
        CHECK_INT(lm[2 * k], k);
        CHECK_INT(lm[2 * k + 1], k + 5);
    }
    free(lm);

    snprintf(src, sizeof src, "%s", testfile_text("a.txt", "1\n2\n3\n"));
    snprintf(tgt, sizeof tgt, "%s", testfile_text("b.txt", "4\n5\n6\n"));
    CHECK_INT(mc_read_landmarks(src, tgt, 1, m->v, m->nv, m->v, m->nv, &lm, &n, err, sizeof err), 0);
    CHECK_INT(n, 3);
    CHECK(lm[0] == 0 && lm[1] == 3 && lm[4] == 2 && lm[5] == 5);
    free(lm);
    /* a .vts list whose positions are each line's vertex at base 1 */
    char vts[512] = "";
    for (int i = 0; i < 3; i++)
        snprintf(vts + strlen(vts), sizeof vts - strlen(vts), "%d %.17g %.17g %.17g\n", i + 1,
                 m->v[3 * i], m->v[3 * i + 1], m->v[3 * i + 2]);
    snprintf(src, sizeof src, "%s", testfile_text("a.vts", vts));
    CHECK_INT(mc_read_landmarks(src, tgt, 0, m->v, m->nv, m->v, m->nv, &lm, &n, err, sizeof err), 0);
    CHECK(n == 3 && lm[0] == 0 && lm[2] == 1 && lm[1] == 4);
    free(lm);

    CHECK_INT(mc_read_landmarks("/nonexistent/lm.txt", NULL, 0, m->v, m->nv, m->v, m->nv, &lm, &n, err,
                                sizeof err), MC_EFILE);
    CHECK(!lm && n == 0);
    CHECK_STR_HAS(err, "/nonexistent/lm.txt");
    p = testfile_text("junk.txt", "0 1\n2 x\n3 4\n");
    CHECK_INT(mc_read_landmarks(p, NULL, 0, m->v, m->nv, m->v, m->nv, &lm, &n, err, sizeof err),
              MC_EBAD_LANDMARKS);
    CHECK_STR_HAS(err, "junk.txt:2:");
    p = testfile_text("far.txt", "0 1\n2 3\n4 99\n");
    CHECK_INT(mc_read_landmarks(p, NULL, 0, m->v, m->nv, m->v, m->nv, &lm, &n, err, sizeof err),
              MC_EBAD_LANDMARKS);
    CHECK_STR_HAS(err, "far.txt:3:");
    CHECK_STR_HAS(err, "99");
    CHECK_INT(mc_read_landmarks(NULL, NULL, 0, m->v, m->nv, m->v, m->nv, &lm, &n, err, sizeof err), MC_EARG);
    CHECK_INT(mc_read_landmarks(p, NULL, 0, m->v, 0, m->v, m->nv, &lm, &n, err, sizeof err), MC_EARG);

    CHECK_INT(testrunf(out, sizeof out, "nm -D --defined-only build/libmeshcorr.so.1 | grep -w mc_read_landmarks"), 0);
    CHECK_STR_HAS(out, "mc_read_landmarks@@MESHCORR_1.4");
    mesh_free(m);
}

TEST(parameter_list_as_data_sets_each_member_as_the_cli_parses_its_option)
{
#define COUNT_ROW(...) +1
    CHECK_INT(mc_param_count(), 0 PROTO_PARAMS(COUNT_ROW));
#undef COUNT_ROW
    CHECK_INT(mc_job_spec_size(), sizeof(mc_job_spec));
    CHECK(strcmp(mc_param_name(0), "model") == 0 && strcmp(mc_param_values(0), "bijective|injective") == 0);
    CHECK_INT(mc_param_type(0), MC_PARAM_ENUM);
    int last = mc_param_count() - 1;
    CHECK(strcmp(mc_param_name(last), "repair") == 0 && mc_param_type(last) == MC_PARAM_ENUM &&
          strcmp(mc_param_values(last), "yes|no") == 0);
    CHECK(strcmp(mc_param_name(last - 1), "coarse") == 0 && mc_param_type(last - 1) == MC_PARAM_U32);
    CHECK(strcmp(mc_param_name(last - 2), "zoomout") == 0 && mc_param_type(last - 2) == MC_PARAM_U32);
    CHECK(strcmp(mc_param_name(last - 3), "ddm_mode") == 0 && mc_param_type(last - 3) == MC_PARAM_ENUM);
    CHECK(strcmp(mc_param_name(last - 4), "ddm_k") == 0 && mc_param_type(last - 4) == MC_PARAM_U32);
    CHECK(strcmp(mc_param_name(last - 6), "backend") == 0 && mc_param_type(last - 6) == MC_PARAM_STR);
    CHECK(mc_param_name(last + 1) == NULL && mc_param_type(-1) == -1);
    for (int i = 0; i <= last; i++)
        CHECK(mc_param_cli(i) && mc_param_help(i)[0] && mc_param_values(i));

    mc_job_spec s;
    mc_job_spec_init(&s);
    char err[256];
    CHECK_INT(mc_job_spec_set(&s, "model", "injective", err, sizeof err), 0);
    CHECK_INT(s.model, MC_INJECTIVE);
    CHECK_INT(mc_job_spec_set(&s, "inner-iterations", "77", err, sizeof err), 0);   /* the option's name */
    CHECK_INT(s.inner_iterations, 77);
    CHECK_INT(mc_job_spec_set(&s, "partial", "1", err, sizeof err), 0);
    CHECK_INT(s.partial, 1);
    CHECK_INT(mc_job_spec_set(&s, "beta0", "1234.5", err, sizeof err), 0);
    CHECK(s.beta0 == 1234.5);
    const char *backend = "opencl:gpu";
    CHECK_INT(mc_job_spec_set(&s, "backend", backend, err, sizeof err), 0);
    CHECK(s.backend == backend);
    CHECK_INT(mc_job_spec_set(&s, "stages", "ddm,rhm,ectm", err, sizeof err), 0);    /* a chain */
    CHECK_INT(s.stages, MC_STAGES_DDM_RHM_ECTM);
    CHECK_INT(mc_job_spec_set(&s, "ddm-k", "60", err, sizeof err), 0);
    CHECK_INT(s.ddm_k, 60);
    CHECK_INT(s.ddm_mode, MC_DDM_AUTO);                                              /* the default */
    CHECK_INT(mc_job_spec_set(&s, "ddm-mode", "bijective", err, sizeof err), 0);
    CHECK_INT(s.ddm_mode, MC_DDM_BIJECTIVE);
    CHECK_INT(mc_job_spec_set(&s, "zoomout", "120", err, sizeof err), 0);
    CHECK_INT(s.zoomout, 120);
    CHECK_INT(s.coarse, 6000);                                   /* its default */
    CHECK_INT(mc_job_spec_set(&s, "coarse", "0", err, sizeof err), 0);   /* off */
    CHECK_INT(s.coarse, 0);
    CHECK(s.alpha == 20 && s.iterations == 600);                 /* the others keep their defaults */
    CHECK_INT(mc_job_spec_set(&s, "model", "sideways", err, sizeof err), MC_EARG);
    CHECK_STR_HAS(err, "sideways");
    CHECK_INT(mc_job_spec_set(&s, "iterations", "many", err, sizeof err), MC_EARG);
    CHECK_STR_HAS(err, "iterations");
    CHECK_INT(mc_job_spec_set(&s, "no_such", "1", err, sizeof err), MC_EARG);
    CHECK_STR_HAS(err, "'no_such' is not a job parameter");
    CHECK_INT(s.model, MC_INJECTIVE);
}

TEST(error_codes_have_the_protocols_names_and_the_librarys)
{
    CHECK(strcmp(mc_err_name(MC_ENOT_FOUND), "NOT_FOUND") == 0);
    CHECK(strcmp(mc_err_name(-21), "BAD_PARAMS") == 0);
    CHECK(strcmp(mc_err_name(MC_EARG), "MC_EARG") == 0);
    CHECK(strcmp(mc_err_name(MC_EFILE), "MC_EFILE") == 0);
    CHECK(strcmp(mc_err_name(-99), "UNKNOWN") == 0);
}

TEST(shared_library_links_no_engine_library)
{
    testldd_check_slim("build/libmeshcorr.so.1");
}

TEST_T(installed_library_builds_a_program_with_pkg_config_that_talks_to_meshcorrd, 240)
{
    testdaemon_need_worker();
    char dest[600], out[8192], path[800];
    snprintf(dest, sizeof dest, "%s/dest", harness_tmpdir());
    CHECK_INT(testrunf(out, sizeof out, "env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s install-lib "
                       "DESTDIR=%s PREFIX=/opt/mc 2>&1", dest), 0);
    static const char *const files[] = {"include/meshcorr/meshcorr.h", "lib/libmeshcorr.a", "lib/libmeshcorr.so.1",
                                        "lib/libmeshcorr.so", "lib/pkgconfig/meshcorr.pc"};
    struct stat st;
    for (int i = 0; i < 5; i++) {
        snprintf(path, sizeof path, "%s/opt/mc/%s", dest, files[i]);
        if (stat(path, &st))
            FAILF("make install-lib did not install %s", path);
    }
    snprintf(path, sizeof path, "%s/opt/mc/lib/pkgconfig/meshcorr.pc", dest);
    char *pc = (char *)testfile_read(path, &(size_t){0});
    CHECK_STR_HAS(pc, "prefix=/opt/mc\n");
    free(pc);
    CHECK_INT(testrunf(out, sizeof out, "readelf -d %s/opt/mc/lib/libmeshcorr.so.1", dest), 0);
    CHECK_STR_HAS(out, "Library soname: [libmeshcorr.so.1]");
    snprintf(path, sizeof path, "%s/opt/mc/lib/libmeshcorr.so.1", dest);
    testldd_check_slim(path);

    const char *src = testfile_text("prog.c", prog);
    char bin[700];
    snprintf(bin, sizeof bin, "%s/prog", harness_tmpdir());
    int rc = testrunf(out, sizeof out,
                      "export PKG_CONFIG_PATH=%s/opt/mc/lib/pkgconfig PKG_CONFIG_SYSROOT_DIR=%s; "
                      "cc -std=c11 -Wall -Werror -o %s %s $(pkg-config --cflags --libs meshcorr) 2>&1",
                      dest, dest, bin, src);
    if (rc)
        FAILF("building against the installed library failed:\n%s", out);
    CHECK_INT(testrunf(out, sizeof out, "readelf -d %s", bin), 0);
    CHECK_STR_HAS(out, "Shared library: [libmeshcorr.so.1]");

    testdaemon d;
    testdaemon_start(&d, "d", NULL);
    rc = testrunf(out, sizeof out, "LD_LIBRARY_PATH=%s/opt/mc/lib %s %s 2>&1", dest, bin, d.unix_addr);
    if (rc)
        FAILF("the program failed (%d):\n%s", rc, out);
    char want[256];
    snprintf(want, sizeof want, "strerror %s\n", mc_strerror(MC_ENOT_FOUND));
    CHECK_STR_HAS(out, want);
    CHECK_STR_HAS(out, " ping 0");
    CHECK(strstr(out, "user ") && !strstr(out, "user  "));
    CHECK_INT(testrunf(out, sizeof out, "LD_LIBRARY_PATH=%s/opt/mc/lib %s unix:%s/none.sock", dest, bin,
                       harness_tmpdir()), 1);
    CHECK_STR_HAS(out, "connect ");
    testdaemon_stop(&d, SIGTERM);
}
