/* test_daemon_input.c — bad input through the real daemon and client: a
 * frame of another protocol version, a SUBMIT whose mesh blob fails its
 * checksum (refused, nothing stored), an unknown backend (refused) and a
 * known one per job. Each time the daemon keeps serving the other clients.
 * SUBMITs whose meshes, landmarks or parameters cannot run:
 * test_daemon_refusals.c. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testjob.h"
#include "support/testmesh.h"
#include "proto.h"

#include <signal.h>
#include <string.h>
#include <unistd.h>

TEST_T(frame_of_another_version_is_refused_and_others_are_served, 30)
{
    testdaemon d;
    testdaemon_start(&d, "version", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE), *other = testdaemon_client(&d, NULL);
    proto_hdr h = {PROTO_VERSION + 7, PROTO_MSG_PING, 0, 9, 0};
    uint8_t frame[PROTO_HDR_SIZE];
    proto_frame_put_header(frame, &h);
    CHECK_INT(mc_send_raw(c, frame, sizeof frame), PROTO_EBAD_VERSION);
    CHECK_STR_HAS(mc_errmsg(c), "BAD_VERSION");
    CHECK_INT(mc_ping(other), 0);
    mc_close(c);
    mc_close(other);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(submit_whose_mesh_fails_its_checksum_is_refused_and_nothing_is_stored, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "checksum", NULL);
    char src[512], tgt[512], err[512];
    snprintf(src, sizeof src, "%s", harness_data_path("shrec07_bim/Meshes/386.off"));
    snprintf(tgt, sizeof tgt, "%s", harness_data_path("shrec07_bim/Meshes/52.off"));
    proto_landmark L[4] = {{0, 0}, {10, 10}, {20, 20}, {30, 30}};
    testjob j;
    if (testjob_build(&j, src, tgt, L, 4, NULL, NULL, NULL, err, sizeof err))
        FAILF("%s", err);
    j.msg.request_id = 41;
    proto_buf b;
    proto_buf_init(&b);
    CHECK_INT(proto_msg_encode(&b, &j.msg, err, sizeof err), 0);
    /* flip one byte in the middle of the source mesh's Draco bytes */
    const unsigned char *blob = j.msg.u.submit.source.data;
    size_t len = j.msg.u.submit.source.len;
    unsigned char *at = memmem(b.data, b.len, blob, len);
    CHECK(at != NULL);
    at[len / 2] ^= 0x5a;
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    CHECK_INT(mc_send_raw(c, b.data, b.len), PROTO_EBAD_CHECKSUM);
    CHECK_STR_HAS(mc_errmsg(c), "BAD_CHECKSUM");
    mc_close(c);
    c = testdaemon_client(&d, TESTDAEMON_ALICE);
    mc_job_info *jobs = NULL;
    uint32_t n = 99;
    CHECK_INT(mc_list(c, NULL, 0, &jobs, &n), 0);
    CHECK_INT(n, 0);                                  /* nothing was stored */
    free(jobs);
    mc_close(c);
    proto_buf_free(&b);
    testjob_close(&j);
    testdaemon_stop(&d, SIGTERM);
}

/* A spec for the icosphere pair with the given landmark pairs (2n ids). */
static void sphere_spec(mc_job_spec *s, unsigned char **sb, unsigned char **tb,
                        const uint32_t *lm, uint32_t n)
{
    mesh *S = testmesh_icosphere(2);
    char err[256];
    mc_job_spec_init(s);
    CHECK_INT(mc_encode_mesh(S->v, S->nv, S->f, S->nf, sb, &s->source_len, err, sizeof err), 0);
    CHECK_INT(mc_encode_mesh(S->v, S->nv, S->f, S->nf, tb, &s->target_len, err, sizeof err), 0);
    s->source = *sb;
    s->target = *tb;
    s->landmarks = lm;
    s->nlandmarks = n;
    s->iterations = 2;
    s->beta_ramp = 2;
    s->rhm_iterations = 2;
    mesh_free(S);
}

TEST_T(backend_is_chosen_per_job_and_an_unknown_one_is_refused, 120)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "backend", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    static const uint32_t lm[] = {0, 0, 1, 1, 2, 2, 3, 3};
    mc_job_spec s;
    unsigned char *sb, *tb;
    sphere_spec(&s, &sb, &tb, lm, 4);
    uint64_t id = 0;
    s.backend = "gpu-please";
    CHECK_INT(mc_submit(c, &s, &id), PROTO_EBAD_PARAMS);
    CHECK_STR_HAS(mc_errmsg(c), "not cpu, opencl or auto");
    s.backend = "opencl";
    CHECK_INT(mc_submit(c, &s, &id), 0);
    int st = testdaemon_wait_state(c, id, -1, 90);
    mc_job_status js;
    CHECK_INT(mc_status(c, id, &js), 0);
    if (st == MC_FAILED && strstr(js.reason, "OpenCL"))
        SKIP("no OpenCL device with fp64 here: %s", js.reason);
    if (st != MC_COMPLETED)
        FAILF("the OpenCL job ended %s: %s", mc_state_name(st), js.reason);
    free(sb);
    free(tb);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}

/* STATS lists the devices a worker can use: "cpu:N" at once, then what the
 * worker program reports (OpenCL devices with fp64 when there are any). */
TEST_T(stats_lists_the_devices_the_worker_reports, 60)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "devices", NULL);
    mc_client *c = testdaemon_client(&d, TESTDAEMON_ALICE);
    /* testdaemon runs its workers with one thread each */
    FILE *p = popen("build/meshcorr-worker --list-devices --threads 1 2>/dev/null", "r");
    CHECK(p);
    char want[8][256];
    int nwant = 0;
    while (nwant < 8 && fgets(want[nwant], sizeof want[nwant], p)) {
        want[nwant][strcspn(want[nwant], "\n")] = '\0';
        nwant++;
    }
    CHECK_INT(pclose(p), 0);
    CHECK(nwant >= 1 && strncmp(want[0], "cpu:", 4) == 0);
    mc_server_stats s;
    int same = 0;
    for (int tries = 0; tries < 100 && !same; tries++) {   /* the probe runs at start */
        CHECK_INT(mc_stats(c, &s), 0);
        CHECK(s.ndevices >= 1);
        CHECK(strncmp(s.devices[0], "cpu:", 4) == 0);
        same = (int)s.ndevices == nwant;
        for (int i = 0; same && i < nwant; i++)
            same = strncmp(s.devices[i], want[i], sizeof s.devices[i] - 1) == 0;
        mc_stats_free(&s);
        if (!same)
            usleep(100000);
    }
    CHECK(same);
    mc_close(c);
    testdaemon_stop(&d, SIGTERM);
}
