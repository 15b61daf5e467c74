/* test_cli_match.c — `meshcorr match` as a user runs it: refusals name the
 * file, line or field; a short real run writes every output; JSON progress
 * is one object per outer iteration; --out-stage rhm writes the RHM maps
 * --stages rhm writes. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testmesh.h"
#include "support/testrun.h"
#include "map/bmap.h"
#include "mesh/mesh.h"

#include <string.h>

/* Runs cmd; its exit status, and its stdout+stderr in out (truncated). */
static int run(const char *cmd, char *out, size_t outsz) { return testrunf(out, outsz, "%s 2>&1", cmd); }

static const char *mesh381(void) { return harness_data_path("shrec07_bim/Meshes/381.off"); }

static char s381[512], s390[512], p0[512], q0[512];

static void paths(void)
{
    snprintf(s381, sizeof s381, "%s", mesh381());
    snprintf(s390, sizeof s390, "%s", harness_data_path("shrec07_bim/Meshes/390.off"));
    snprintf(p0, sizeof p0, "%s", harness_data_path("ectm_demo_381_390/init_381_to_390.map"));
    snprintf(q0, sizeof q0, "%s", harness_data_path("ectm_demo_381_390/init_390_to_381.map"));
}

/* A copy of the demo's initial map with row `row` (0-based) replaced. */
static const char *map_with_row(const char *name, int row, const char *text)
{
    size_t len;
    char *buf = (char *)testfile_read(p0, &len);
    char *out = malloc(len + 256), *w = out;
    int line = 0, data_row = -3;  /* two comment lines + the counts line */
    for (char *p = buf; p < buf + len;) {
        char *nl = memchr(p, '\n', (size_t)(buf + len - p));
        size_t l = nl ? (size_t)(nl - p + 1) : (size_t)(buf + len - p);
        if (data_row == row) {
            w += sprintf(w, "%s\n", text);
        } else {
            memcpy(w, p, l);
            w += l;
        }
        data_row++;
        line++;
        p += l;
    }
    const char *path = testfile_write(name, out, (size_t)(w - out));
    free(buf);
    free(out);
    return path;
}

TEST(match_refuses_map_row_not_summing_to_one_naming_file_and_line)
{
    paths();
    const char *bad = map_with_row("bad.map", 10, "5 0.5 0.2 0.2");
    char cmd[4096], out[8192];
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --out %s/p.map",
             s381, s390, bad, harness_tmpdir());
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "bad.map:14");
    CHECK_STR_HAS(out, "sum");
}

TEST(match_refuses_face_index_out_of_range)
{
    paths();
    const char *bad = map_with_row("range.map", 0, "18474 0.2 0.3 0.5");
    char cmd[4096], out[8192];
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --out %s/p.map",
             s381, s390, bad, harness_tmpdir());
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "range.map:4");
    CHECK_STR_HAS(out, "18474");
}

TEST(match_refuses_map_sized_for_other_meshes)
{
    paths();
    char cmd[4096], out[8192];
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --out %s/p.map",
             s381, s390, q0, harness_tmpdir());
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "init_390_to_381.map");
    CHECK_STR_HAS(out, "9239");
}

TEST(match_refuses_non_manifold_mesh_with_repair_no)
{
    paths();
    char cmd[4096], out[8192];
    const char *scape = harness_data_path("scape/Meshes/mesh000.off");
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --out %s/p.map --repair no",
             scape, s390, p0, harness_tmpdir());
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "not usable");
    CHECK_STR_HAS(out, "non-manifold");
}

TEST(match_refuses_nan_coordinate)
{
    paths();
    const char *nan = testfile_text("nan.off",
        "OFF\n4 4 0\n0 0 0\n1 0 0\n0 nan 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n");
    char cmd[4096], out[8192];
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --out %s/p.map",
             nan, s390, p0, harness_tmpdir());
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "nan.off");
    CHECK_STR_HAS(out, "NaN");
}

TEST(match_refuses_landmark_out_of_range_naming_it)
{
    paths();
    const char *l = testfile_text("l.txt", "# pairs\n0 0\n10 20\n30 40\n50 9239\n");
    char cmd[4096], out[8192];
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --landmarks %s --out %s/p.map",
             s381, s390, l, harness_tmpdir());
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "l.txt");
    CHECK_STR_HAS(out, "landmark 4");
    CHECK_STR_HAS(out, "9239 out of range");
}

/* A BIM .pid file given as --landmarks is refused naming file, line and
 * what it looks like, with what to give instead, by match and by submit
 * (before any server is asked), instead of becoming pairs of its first two
 * columns (21 landmarks on target vertex 0). */
TEST(landmarks_option_refuses_a_bim_pid_file_saying_what_to_give)
{
    char w0[512], w1[512], pid[512], cmd[4096], out[8192];
    snprintf(w0, sizeof w0, "%s", harness_data_path("tosca_hires/Meshes/wolf0.off"));
    snprintf(w1, sizeof w1, "%s", harness_data_path("tosca_hires/Meshes/wolf1.off"));
    snprintf(pid, sizeof pid, "%s", harness_data_path("tosca_hires/Corrs/wolf.pid"));
    static const char want[] = "wolf.pid:1: 4 columns: this looks like a BIM .pid file (point ids with "
                               "barycentric coordinates); landmark pairs are `source_vertex target_vertex` "
                               "a line (--landmarks), or give two lists: --source-landmarks A.vts "
                               "--target-landmarks B.vts";
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --landmarks %s --out %s/p.map", w0, w1, pid,
             harness_tmpdir());
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, want);
    snprintf(cmd, sizeof cmd, "build/meshcorr submit %s %s --landmarks %s --server unix:%s/none.sock", w0, w1,
             pid, harness_tmpdir());
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, want);
    CHECK(strstr(out, "connect") == NULL);
    /* the same file as two lists (the same ids on both poses) is read */
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --source-landmarks %s --target-landmarks %s "
             "--stages rhm --rhm-iterations 1 --progress none --out %s/p.map", w0, w1, pid, pid,
             harness_tmpdir());
    CHECK_INT(run(cmd, out, sizeof out), 0);
}

TEST(match_refuses_bad_option_value)
{
    paths();
    char cmd[4096], out[8192];
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --out x.map --alpha abc",
             s381, s390, p0);
    CHECK_INT(run(cmd, out, sizeof out), 2);
    CHECK_STR_HAS(out, "--alpha: 'abc' is not a number");
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --out x.map --gamma -1",
             s381, s390, p0);
    CHECK_INT(run(cmd, out, sizeof out), 2);
    CHECK_STR_HAS(out, "gamma");
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --out x.map --start cells",
             s381, s390, p0);
    CHECK_INT(run(cmd, out, sizeof out), 2);
    CHECK_STR_HAS(out, "--start: 'cells' is not distances, voronoi, fmap or auto");
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --out x.map --stages ddm "
             "--ddm-mode bijective", s381, s390, p0);
    CHECK(run(cmd, out, sizeof out) != 0);
    CHECK_STR_HAS(out, "bijective DDM (ddm_mode bijective) denoises a map and its reverse");
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --out x.map --ddm-mode both",
             s381, s390, p0);
    CHECK_INT(run(cmd, out, sizeof out), 2);
    CHECK_STR_HAS(out, "--ddm-mode: 'both' is not plain, bijective or auto");
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --out x.map --zoomout 301",
             s381, s390, p0);
    CHECK_INT(run(cmd, out, sizeof out), 2);
    CHECK_STR_HAS(out, "zoomout");
}

TEST_T(match_short_run_writes_maps_meshes_and_json_progress, 300)
{
    paths();
    const char *d = harness_tmpdir();
    char cmd[4096], out[65536];
    snprintf(cmd, sizeof cmd,
             "build/meshcorr match %s %s --init %s --init-reverse %s --iterations 3 "
             "--out %s/p.map --out-reverse %s/q.map --out-deformed %s/y.ply "
             "--out-remeshed %s/t.off --progress json", s381, s390, p0, q0, d, d, d, d);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    int objects = 0;
    for (char *p = out; (p = strstr(p, "\"stage\":\"ectm\",\"outer\":")); p++)
        objects++;
    CHECK_INT(objects, 3);
    CHECK_STR_HAS(out, "\"membrane\":");
    CHECK_STR_HAS(out, "\"bending\":");
    CHECK_STR_HAS(out, "\"reverse\":");
    char err[512], path[600];
    mesh *S = NULL, *T = NULL, *Y = NULL, *R = NULL;
    bmap *P = NULL, *Q = NULL;
    CHECK_INT(mesh_read(s381, &S, err, sizeof err), 0);
    CHECK_INT(mesh_read(s390, &T, err, sizeof err), 0);
    snprintf(path, sizeof path, "%s/p.map", d);
    if (bmap_read(path, S, T, &P, err, sizeof err)) FAILF("%s", err);
    snprintf(path, sizeof path, "%s/q.map", d);
    if (bmap_read(path, T, S, &Q, err, sizeof err)) FAILF("%s", err);
    snprintf(path, sizeof path, "%s/y.ply", d);
    CHECK_INT(mesh_read(path, &Y, err, sizeof err), 0);
    CHECK_INT(Y->nv, S->nv);
    CHECK(memcmp(Y->f, S->f, sizeof(int) * 3 * S->nf) == 0);
    snprintf(path, sizeof path, "%s/t.off", d);
    CHECK_INT(mesh_read(path, &R, err, sizeof err), 0);
    /* The remeshed target's vertices are P·X̃ in the target's frame. */
    double *px = malloc(sizeof(double) * 3 * S->nv);
    bmap_apply(P, T->f, T->v, 3, px);
    for (int i = 0; i < 3 * S->nv; i++)
        CHECK_NEAR(R->v[i], px[i], 1e-9);
    free(px);
    mesh_free(S); mesh_free(T); mesh_free(Y); mesh_free(R);
    bmap_free(P); bmap_free(Q);
}

/* The landmark path end to end with few iterations: JSON progress shows the
 * start map, every RHM iteration and every ECTM iteration; --stages rhm
 * writes RHM's maps; --stages ectm without --init is refused. */
TEST_T(match_from_landmarks_reports_start_rhm_and_ectm_stages, 120)
{
    char s0[512], s1[512], cmd[4096], out[65536];
    snprintf(s0, sizeof s0, "%s", harness_data_path("faust_r/vtx_5k/tr_reg_000.off"));
    snprintf(s1, sizeof s1, "%s", harness_data_path("faust_r/vtx_5k/tr_reg_001.off"));
    const char *l = testfile_text("l.txt", "0 10\n1000 1200\n2000 2100\n3000 3300\n");
    const char *d = harness_tmpdir();
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --landmarks %s --rhm-iterations 3 "
             "--iterations 2 --out %s/p.map --out-reverse %s/q.map --progress json",
             s0, s1, l, d, d);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    /* from 4 landmarks and 3 iterations the distances start's maps stay
     * folded, so start auto (the default) runs RHM again from the
     * functional-map start: two starts, 3 + 3 RHM iterations */
    int starts = 0, rhm = 0, ectm = 0;
    for (char *p = out; (p = strstr(p, "{\"job\":null,\"stage\":\"start\",\"outer\":0,")); p++)
        starts++;
    for (char *p = out; (p = strstr(p, "\"stage\":\"rhm\",\"outer\":")); p++)
        rhm++;
    for (char *p = out; (p = strstr(p, "\"stage\":\"ectm\",\"outer\":")); p++)
        ectm++;
    CHECK_INT(starts, 2);
    CHECK_INT(rhm, 6);
    CHECK_INT(ectm, 2);
    /* RHM's terms in the record's slots: membrane is the Dirichlet energy */
    CHECK_STR_HAS(out, "\"membrane\":");
    CHECK_STR_HAS(out, "\"fraction\":");
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --landmarks %s --rhm-iterations 2 "
             "--stages rhm --out %s/r.map --progress text", s0, s1, l, d);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    CHECK_STR_HAS(out, "rhm iter 2/2 energy");
    char path[600], err[512];
    mesh *S = NULL, *T = NULL;
    bmap *P = NULL;
    CHECK_INT(mesh_read(s0, &S, err, sizeof err), 0);
    CHECK_INT(mesh_read(s1, &T, err, sizeof err), 0);
    snprintf(path, sizeof path, "%s/r.map", d);
    if (bmap_read(path, S, T, &P, err, sizeof err)) FAILF("%s", err);
    bmap_free(P);
    mesh_free(S);
    mesh_free(T);
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --landmarks %s --stages ectm --out x.map",
             s0, s1, l);
    CHECK_INT(run(cmd, out, sizeof out), 2);
    CHECK_STR_HAS(out, "--stages ectm needs --init");
}

/* A published vertex map as --init (TOSCA gorilla_01 -> man_01): the BIM
 * map, 0-based but holding neither 0 nor 5000, is refused until
 * --init-base 0 says its base; then --stages ddm,ectm reports DDM and
 * every ECTM iteration. A bad line of a vertex map is named; a chain out
 * of order is refused with the reason; ddm without --init is refused. */
TEST_T(match_refines_a_vertex_map_with_ddm_then_ectm, 300)
{
    char s0[512], s1[512], bim[512], bcicp[512], cmd[4096], out[65536];
    snprintf(s0, sizeof s0, "%s", harness_data_path("tosca_r_nonisometric/vtx_5k/8_gorilla_01.off"));
    snprintf(s1, sizeof s1, "%s", harness_data_path("tosca_r_nonisometric/vtx_5k/8_man_01.off"));
    snprintf(bim, sizeof bim, "%s", harness_data_path("tosca_r_nonisometric/vtx_5k/maps_baseline/"
                                                      "BIM/8_gorilla_01_8_man_01.map"));
    snprintf(bcicp, sizeof bcicp, "%s", harness_data_path("tosca_r_nonisometric/vtx_5k/maps_baseline/"
                                                          "WKSini_direct_BCICP/8_gorilla_01_8_man_01.map"));
    const char *d = harness_tmpdir();
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --stages ddm --out %s/p.map",
             s0, s1, bim, d);
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "8_gorilla_01_8_man_01.map: neither 0 nor 5000 among the indices");
    CHECK_STR_HAS(out, "--init-base 0 or 1");
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --init-base 0 --stages ddm,ectm "
             "--ddm-k 50 --iterations 2 --inner-iterations 5 --out %s/p.map --out-reverse %s/q.map "
             "--progress json", s0, s1, bim, d, d);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    CHECK_STR_HAS(out, "{\"job\":null,\"stage\":\"ddm\",\"outer\":0,\"total\":1,");
    CHECK_STR_HAS(out, "{\"job\":null,\"stage\":\"ddm\",\"outer\":1,\"total\":1,");
    int ectm = 0;
    for (char *p = out; (p = strstr(p, "\"stage\":\"ectm\",\"outer\":")); p++)
        ectm++;
    CHECK_INT(ectm, 2);
    CHECK_STR_HAS(out, "map quality:");
    /* line 100 of a BCICP map (1-based) pointing past the target */
    size_t len;
    char *buf = (char *)testfile_read(bcicp, &len), *w = malloc(len + 64), *o = w;
    int line = 1;
    for (char *p = buf; p < buf + len; p++) {
        if (line == 100 && (p == buf || p[-1] == '\n')) {
            o += sprintf(o, "5001\n");
            p = strchr(p, '\n');
            line++;
            continue;
        }
        *o++ = *p;
        line += *p == '\n';
    }
    const char *bad = testfile_write("bad_vertex.map", w, (size_t)(o - w));
    free(buf);
    free(w);
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --stages ddm --out %s/p.map",
             s0, s1, bad, d);
    CHECK_INT(run(cmd, out, sizeof out), 1);
    CHECK_STR_HAS(out, "bad_vertex.map:100: target vertex 5001 out of range [1, 5000]");
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --init %s --stages ectm,ddm --out %s/p.map",
             s0, s1, bcicp, d);
    CHECK_INT(run(cmd, out, sizeof out), 2);
    CHECK_STR_HAS(out, "--stages: 'ectm,ddm': ectm before ddm");
    const char *l = testfile_text("l3.txt", "0 10\n1000 1200\n2000 2100\n");
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --landmarks %s --stages ddm,ectm --out %s/p.map",
             s0, s1, l, d);
    CHECK_INT(run(cmd, out, sizeof out), 2);
    CHECK_STR_HAS(out, "--stages ddm,ectm needs --init");
}

static int same_map(const bmap *a, const bmap *b)
{
    return a->n == b->n && !memcmp(a->face, b->face, sizeof(int) * (size_t)a->n) &&
           !memcmp(a->w, b->w, sizeof(double) * 3 * (size_t)a->n);
}

static bmap *read_map(const char *dir, const char *name, const mesh *S, const mesh *T)
{
    char path[1024], err[512];
    bmap *P = NULL;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (bmap_read(path, S, T, &P, err, sizeof err))
        FAILF("%s", err);
    return P;
}

/* --out-stage rhm=FILE and rhm-reverse=FILE on a chain from landmarks:
 * the files hold the maps --stages rhm writes for the same job, and RHM's
 * quality line comes before the final map's. Refused before any work: a
 * chain without RHM then ECTM, rhm-reverse with the injective model, a
 * name that is not a stage's map, a FILE in a missing folder. */
TEST_T(match_out_stage_rhm_writes_the_maps_stages_rhm_writes, 120)
{
    const char *d = harness_tmpdir();
    char s0[600], s1[600], cmd[8192], out[65536], err[512];
    mesh *S = testmesh_icosphere(3), *T = testmesh_icosphere(3);
    for (int i = 0; i < T->nv; i++) {
        double *x = &T->v[3 * i];
        x[0] *= 1.3;
        x[2] += 0.15 * x[0] * x[0];
    }
    snprintf(s0, sizeof s0, "%s/s.off", d);
    snprintf(s1, sizeof s1, "%s/t.off", d);
    if (mesh_write(s0, S, err, sizeof err) || mesh_write(s1, T, err, sizeof err))
        FAILF("%s", err);
    const char *l = testfile_text("l6.txt", "0 0\n1 1\n2 2\n3 3\n4 4\n5 5\n");
    const char *job = "--rhm-iterations 4 --iterations 2 --inner-iterations 5 --progress none";
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --landmarks %s %s --out %s/p.map "
             "--out-stage rhm=%s/r.map --out-stage rhm-reverse=%s/rq.map", s0, s1, l, job, d, d, d);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    char *rq = strstr(out, "rhm map quality: flipped ");
    CHECK(rq && strstr(rq + 1, "\nmap quality: flipped "));
    snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --landmarks %s %s --stages rhm "
             "--out %s/r2.map --out-reverse %s/rq2.map", s0, s1, l, job, d, d);
    CHECK_INT(run(cmd, out, sizeof out), 0);
    bmap *r = read_map(d, "r.map", S, T), *r2 = read_map(d, "r2.map", S, T);
    bmap *q = read_map(d, "rq.map", T, S), *q2 = read_map(d, "rq2.map", T, S);
    bmap *p = read_map(d, "p.map", S, T);
    CHECK(same_map(r, r2));
    CHECK(same_map(q, q2));
    CHECK(!same_map(p, r));                 /* ECTM's map is another */
    bmap_free(r); bmap_free(r2); bmap_free(q); bmap_free(q2); bmap_free(p);

    static const struct { const char *opts, *msg; } bad[] = {
        {"--stages rhm --out-stage rhm=%s/x.map", "--out-stage rhm needs a chain that runs RHM then ECTM"},
        {"--model injective --out-stage rhm-reverse=%s/x.map",
         "--out-stage rhm-reverse needs the bijective model"},
        {"--out-stage ectm=%s/x.map", "--out-stage: 'ectm' is not a stage's map (rhm, rhm-reverse)"},
        {"--out-stage rhm=%s/no/such/x.map", "--out-stage rhm "}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char opts[1024];
        snprintf(opts, sizeof opts, bad[k].opts, d);
        snprintf(cmd, sizeof cmd, "build/meshcorr match %s %s --landmarks %s %s --out %s/y.map %s",
                 s0, s1, l, job, d, opts);
        CHECK_INT(run(cmd, out, sizeof out), 2);
        CHECK_STR_HAS(out, bad[k].msg);
        CHECK(!strstr(out, "map quality"));  /* refused before the work */
    }
    mesh_free(S);
    mesh_free(T);
}
