/* test_error_kinds.c — a job's error keeps its kind from the engine to the
 * user (protocol/proto_kind.h): every kind of the list maps through every
 * layer (engine code, wire code and name, libmeshcorr's names, the job's
 * reason read back, the CLI's exit status), every engine module's error has
 * a kind, and each kind a real input can provoke is provoked through the
 * real programs: a numerical failure of a landmark job and of a DDM job
 * without landmarks reaches the client as NUMERIC (meshcorr watch exits 3),
 * a worker out of memory as NOMEM (exit 4), bad meshes, landmarks,
 * parameters and maps are refused with their own codes, and meshcorr
 * match exits with the kind's status. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testfile.h"
#include "support/testrun.h"
#include "corr/corr.h"
#include "ctf/ctf.h"
#include "ddm/ddm.h"
#include "geod/geod.h"
#include "lbo/lbo.h"
#include "mesh/mesh.h"
#include "meshcorr.h"
#include "proto.h"

#include <signal.h>
#include <stdlib.h>
#include <string.h>

static char out[1 << 16];

TEST(every_kind_has_one_code_name_text_and_exit_through_every_layer)
{
    int n = 0;
#define KIND_ROW(kind, code, exit, text)                                                        \
    do {                                                                                        \
        int k = PROTO_KIND_##kind;                                                              \
        const char *name = proto_err_name(code);                                                \
        n++;                                                                                    \
        CHECK(code < 0 && strcmp(name, "UNKNOWN") != 0);                                        \
        CHECK_INT(proto_kind_code(k), code);                                                    \
        CHECK_INT(proto_kind_of_code(code), k);                                                 \
        CHECK(proto_kind_name(k) && strcmp(proto_kind_name(k), name) == 0);                     \
        CHECK_INT(proto_err_code(name), code);                                                  \
        /* the engine's pipeline code is -kind, and the worker sends its wire code */           \
        CHECK_INT(KIND_E##kind, -k);                                                            \
        CHECK_INT(corr_wire_code(KIND_E##kind), code);                                          \
        CHECK(strcmp(proto_kind_text(k), text) == 0);                                           \
        /* libmeshcorr names it, and reads it back from a failed job's reason */               \
        CHECK(strcmp(mc_err_name(code), name) == 0);                                            \
        char reason[128];                                                                       \
        snprintf(reason, sizeof reason, "%s: the stage's message", name);                       \
        CHECK_INT(mc_reason_error(reason), code);                                               \
        /* the CLI's exit status: 1 for the input kinds, its own for the others */             \
        CHECK_INT(proto_kind_exit(k), exit);                                                    \
        CHECK(exit == 1 || exit >= 3);                                                          \
    } while (0);
    PROTO_KINDS(KIND_ROW)
#undef KIND_ROW
    CHECK_INT(n, PROTO_NKINDS - 1);
    /* the kinds a user acts on differently exit differently */
    CHECK_INT(proto_kind_exit(PROTO_KIND_NUMERIC), 3);
    CHECK_INT(proto_kind_exit(PROTO_KIND_NOMEM), 4);
    CHECK_INT(proto_kind_exit(PROTO_KIND_CANCELLED), 5);
    /* two kinds never share a code */
    for (int a = 1; a < PROTO_NKINDS; a++)
        for (int b = a + 1; b < PROTO_NKINDS; b++)
            CHECK(proto_kind_code(a) != proto_kind_code(b));
    /* reasons that name no code (a timeout, a crash, a cancel by request) */
    CHECK_INT(mc_reason_error("wall time limit of 10 s exceeded"), 0);
    CHECK_INT(mc_reason_error("cancelled by request"), 0);
    CHECK_INT(mc_reason_error("worker crashed twice: worker killed by signal 9 (Killed)"), 0);
    CHECK_INT(mc_reason_error(""), 0);
    CHECK_INT(mc_reason_error(NULL), 0);
    CHECK_INT(proto_kind_of_code(PROTO_ENOT_FOUND), PROTO_KIND_NONE);
}

/* Each engine module's list says the kind of every code, and the pipeline
 * translates by it: a numerical failure is NUMERIC whatever stage had it
 * (never BAD_LANDMARKS, as it was for RHM, DDM and the fold repair). */
TEST(every_engine_module_error_translates_to_its_kind)
{
#define CHECK_ROW(fn, name, kind) CHECK_INT(fn(name), -PROTO_KIND_##kind);
#define FOLD_ROW(name, val, msg, kind) CHECK_ROW(corr_from_fold, name, kind)
#define DDM_ROW(name, val, msg, kind) CHECK_ROW(corr_from_ddm, name, kind)
#define CTF_ROW(name, val, msg, kind) CHECK_ROW(corr_from_ctf, name, kind)
#define GEOD_ROW(name, val, msg, kind) CHECK_ROW(corr_from_geod, name, kind)
#define LBO_ROW(name, val, msg, kind) CHECK_ROW(corr_from_lbo, name, kind)
#define LMK_ROW(name, val, msg, kind) CHECK_ROW(corr_from_lmk, name, kind)
#define BMAP_ROW(name, val, msg, kind) CHECK_ROW(corr_from_bmap, name, kind)
#define MESH_ROW(name, val, msg, kind) CHECK_ROW(corr_from_mesh, name, kind)
    FOLD_ERRORS(FOLD_ROW)
    DDM_ERRORS(DDM_ROW)
    CTF_ERRORS(CTF_ROW)
    GEOD_ERRORS(GEOD_ROW)
    LBO_ERRORS(LBO_ROW)
    LMK_ERRORS(LMK_ROW)
    BMAP_ERRORS(BMAP_ROW)
    MESH_ERRORS(MESH_ROW)
    CHECK_INT(corr_from_lbo(LBO_EARPACK), KIND_ENUMERIC);
    CHECK_INT(corr_from_lbo(LBO_ENOCONV), KIND_ENUMERIC);
    CHECK_INT(corr_from_geod(GEOD_EFACTOR), KIND_ENUMERIC);
    CHECK_INT(corr_from_bmap(BMAP_ERANGE), KIND_EMAP);
    CHECK_INT(corr_from_lmk(LMK_ERANGE), KIND_ELANDMARKS);
    CHECK_INT(corr_from_geod(12345), KIND_EINTERNAL);   /* a code of no list */
    CHECK_INT(corr_from_geod(GEOD_OK), KIND_OK);
}

/* The icosphere pair as a SUBMIT (testdaemon_pair), 3 + 3 iterations,
 * landmarks lm (n pairs) or none; *sb, *tb: the Draco bytes to free. */
static void pair_spec(mc_job_spec *s, const uint32_t *lm, uint32_t n, unsigned char **sb,
                      unsigned char **tb)
{
    mesh *S, *T;
    testdaemon_pair(0, &S, &T);
    mc_job_spec_init(s);
    size_t sl, tl;
    *sb = testdaemon_encode(S, &sl);
    *tb = testdaemon_encode(T, &tl);
    s->source = *sb;
    s->source_len = sl;
    s->target = *tb;
    s->target_len = tl;
    s->landmarks = lm;
    s->nlandmarks = n;
    s->iterations = 3;
    s->beta_ramp = 3;
    s->inner_iterations = 10;
    s->rhm_iterations = 3;
    mesh_free(S);
    mesh_free(T);
}

/* The identity of the icosphere pair as map rows: vertex i onto vertex i
 * (weight 1 at its corner of the first face that has it); n rows. */
static mc_map_row *identity_rows(uint32_t n)
{
    mesh *S, *T;
    testdaemon_pair(0, &S, &T);
    mc_map_row *r = calloc(n + 1, sizeof *r);
    CHECK(r != NULL);
    for (uint32_t v = 0; v < n && (int)v < T->nv; v++)
        for (int f = 0; f < T->nf; f++) {
            int c = T->f[3 * f] == (int)v ? 0 : T->f[3 * f + 1] == (int)v ? 1 : T->f[3 * f + 2] == (int)v ? 2 : -1;
            if (c >= 0) {
                r[v].face = (uint32_t)f;
                r[v].w[c] = 1;
                break;
            }
        }
    mesh_free(S);
    mesh_free(T);
    return r;
}

/* The job's end through WATCH: state and reason. */
static int watch_end(mc_client *c, uint64_t id, char *reason, size_t sz)
{
    int state = -1;
    CHECK_INT(mc_watch(c, id, 0, NULL, NULL, &state, reason, sz), 0);
    return state;
}

TEST_T(a_numeric_failure_reaches_the_client_as_numeric_with_or_without_landmarks, 180)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "numeric", NULL);
    mc_client *c = testdaemon_client(&d, NULL);
    static const uint32_t lm[] = {0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5};
    mc_job_spec s;
    unsigned char *sb, *tb;
    char reason[1100];

    /* a landmark job whose mismatch weight overflows ECTM's energy: a real
     * input within every range, and a numerical failure of the method */
    pair_spec(&s, lm, 6, &sb, &tb);
    s.beta0 = s.beta1 = 1e308;
    uint64_t id = 0;
    CHECK_INT(mc_submit(c, &s, &id), 0);
    CHECK_INT(watch_end(c, id, reason, sizeof reason), MC_FAILED);
    CHECK_INT(mc_reason_error(reason), PROTO_ENUMERIC);
    CHECK_STR_HAS(reason, "NUMERIC: ");
    CHECK_STR_HAS(reason, "non-finite energy");
    /* the CLI says the kind and exits with its status */
    int rc = testrunf(out, sizeof out, "build/meshcorr watch %llu --server %s 2>&1 >/dev/null",
                      (unsigned long long)id, d.unix_addr);
    CHECK_INT(rc, 3);
    CHECK_STR_HAS(out, "FAILED: NUMERIC: ");

    /* the same failure after DDM on a given map, no landmarks at all: it
     * was BAD_LANDMARKS before the kinds */
    mc_map_row *p = identity_rows(162);
    s.landmarks = NULL;
    s.nlandmarks = 0;
    s.p = p;
    s.np = 162;
    s.stages = MC_STAGES_DDM_ECTM;
    CHECK_INT(mc_submit(c, &s, &id), 0);
    CHECK_INT(watch_end(c, id, reason, sizeof reason), MC_FAILED);
    CHECK_INT(mc_reason_error(reason), PROTO_ENUMERIC);
    CHECK(strstr(reason, "BAD_LANDMARKS") == NULL);
    mc_job_status st;
    CHECK_INT(mc_status(c, id, &st), 0);
    CHECK_INT(mc_reason_error(st.reason), PROTO_ENUMERIC);
    free(p);
    free(sb);
    free(tb);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* A worker out of address space (--worker-memory-mb 72, as
 * test_daemon_ops: the SUBMIT check fits, the run does not): the job ends
 * OUT_OF_MEMORY with the NOMEM kind in its reason, and `meshcorr watch`
 * exits 4. */
TEST_T(a_job_out_of_memory_reaches_the_client_as_nomem, 90)
{
    testdaemon_need_worker();
    testdaemon d;
    const char *args[] = {"--worker-memory-mb", "72", NULL};
    testdaemon_start(&d, "nomem", args);
    mc_client *c = testdaemon_client(&d, NULL);
    uint64_t id = testdaemon_submit_ok(c, 2, 1, 0);
    char reason[1100];
    int end = watch_end(c, id, reason, sizeof reason);
    if (end != MC_OUT_OF_MEMORY)
        FAILF("job ended %s: %s", mc_state_name(end), reason);
    CHECK_INT(mc_reason_error(reason), PROTO_ENOMEM);
    int rc = testrunf(out, sizeof out, "build/meshcorr watch %llu --server %s 2>&1 >/dev/null",
                      (unsigned long long)id, d.unix_addr);
    CHECK_INT(rc, 4);
    CHECK_STR_HAS(out, "OUT_OF_MEMORY: NOMEM: ");
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(bad_meshes_landmarks_parameters_and_maps_are_refused_with_their_own_kind, 120)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "refusals", NULL);
    mc_client *c = testdaemon_client(&d, NULL);
    static const uint32_t lm[] = {0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5};
    static const uint32_t lm_far[] = {0, 0, 1, 1, 2, 500};
    mc_job_spec s;
    unsigned char *sb, *tb;
    uint64_t id = 0;
    pair_spec(&s, lm_far, 3, &sb, &tb);
    CHECK_INT(mc_submit(c, &s, &id), PROTO_EBAD_LANDMARKS);
    CHECK_STR_HAS(mc_errmsg(c), "target vertex 500 out of range");

    s.landmarks = lm;
    s.nlandmarks = 6;
    s.inner_iterations = 500000;
    CHECK_INT(mc_submit(c, &s, &id), PROTO_EBAD_PARAMS);
    CHECK_STR_HAS(mc_errmsg(c), "inner_iterations = 500000: out of range [1, 100000]");
    s.inner_iterations = 10;

    /* an initial map with a row too few, and a reverse map without a map:
     * the map's own kind (they were BAD_PARAMS) */
    mc_map_row *p = identity_rows(162);
    s.p = p;
    s.np = 161;
    CHECK_INT(mc_submit(c, &s, &id), PROTO_EBAD_MAP);
    CHECK_STR_HAS(mc_errmsg(c), "initial map p has 161 rows, its mesh has 162 vertices");
    s.p = NULL;
    s.np = 0;
    s.q = p;
    s.nq = 162;
    CHECK_INT(mc_submit(c, &s, &id), PROTO_EBAD_MAP);
    CHECK_STR_HAS(mc_errmsg(c), "initial map q without p");
    s.q = NULL;
    s.nq = 0;
    CHECK_STR_HAS(mc_err_name(PROTO_EBAD_MAP), "BAD_MAP");

    /* a mesh of two pieces */
    mesh *S, *T;
    testdaemon_pair(0, &S, &T);
    mesh *two = mesh_new(2 * S->nv, 2 * S->nf);
    CHECK(two != NULL);
    for (int v = 0; v < S->nv; v++)
        for (int k = 0; k < 3; k++) {
            two->v[3 * v + k] = S->v[3 * v + k];
            two->v[3 * (S->nv + v) + k] = S->v[3 * v + k] + (k == 0 ? 5 : 0);
        }
    for (int f = 0; f < 3 * S->nf; f++) {
        two->f[f] = S->f[f];
        two->f[3 * S->nf + f] = S->f[f] + S->nv;
    }
    size_t len;
    unsigned char *twob = testdaemon_encode(two, &len);
    s.source = twob;
    s.source_len = len;
    s.repair = 1;                   /* "no": a second piece is refused, not left out */
    CHECK_INT(mc_submit(c, &s, &id), PROTO_EBAD_MESH);
    CHECK_STR_HAS(mc_errmsg(c), "source mesh");
    free(twob);
    mesh_free(two);
    mesh_free(S);
    mesh_free(T);
    free(p);
    free(sb);
    free(tb);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(meshcorr_match_exits_with_the_kind_of_its_failure, 120)
{
    mesh *S, *T;
    testdaemon_pair(0, &S, &T);
    char src[600], tgt[600], err[512], pm[700];
    snprintf(src, sizeof src, "%s/s.off", harness_tmpdir());
    snprintf(tgt, sizeof tgt, "%s/t.off", harness_tmpdir());
    snprintf(pm, sizeof pm, "%s/p.map", harness_tmpdir());
    CHECK_INT(mesh_write(src, S, err, sizeof err), 0);
    CHECK_INT(mesh_write(tgt, T, err, sizeof err), 0);
    char lmk[700], far[700];
    snprintf(lmk, sizeof lmk, "%s", testfile_text("pairs.lmk", "0 0\n1 1\n2 2\n3 3\n4 4\n5 5\n"));
    snprintf(far, sizeof far, "%s", testfile_text("far.lmk", "0 0\n1 1\n2 500\n"));
    static const char job[] = "--iterations 3 --beta-ramp 3 --inner-iterations 10 --rhm-iterations 3 "
                              "--progress none";
    /* NUMERIC: exit 3, the kind's name before the stage's message */
    int rc = testrunf(out, sizeof out, "build/meshcorr match %s %s --landmarks %s --out %s %s "
                      "--beta0 1e308 --beta1 1e308 2>&1", src, tgt, lmk, pm, job);
    CHECK_INT(rc, 3);
    CHECK_STR_HAS(out, "meshcorr match: NUMERIC: ");
    /* LANDMARKS: 1, naming the file's line */
    rc = testrunf(out, sizeof out, "build/meshcorr match %s %s --landmarks %s --out %s %s 2>&1", src, tgt,
                  far, pm, job);
    CHECK_INT(rc, 1);
    CHECK_STR_HAS(out, "500 out of range");
    /* IO: a mesh that is not there, named */
    rc = testrunf(out, sizeof out, "build/meshcorr match %s/none.off %s --landmarks %s --out %s %s 2>&1",
                  harness_tmpdir(), tgt, lmk, pm, job);
    CHECK_INT(rc, 1);
    CHECK_STR_HAS(out, "none.off");
    /* and a job that can run exits 0 */
    rc = testrunf(out, sizeof out, "build/meshcorr match %s %s --landmarks %s --out %s %s 2>&1", src, tgt, lmk,
                  pm, job);
    CHECK_INT(rc, 0);
    mesh_free(S);
    mesh_free(T);
}
