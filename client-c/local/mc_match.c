/* mc_match.c — mc_match() and mc_match_stages(), libmeshcorr-engine.so's
 * exports: a job run in the caller's process the way a meshcorrd worker
 * runs it. The job takes the server's road all the way: the client's
 * mapping of mc_job_spec to a SUBMIT (mc__wire.h), encoded and decoded by
 * the protocol codec with its limits, the worker's mapping of a SUBMIT to
 * engine inputs and its checks (wrk_job_from_submit), corr_run, the
 * worker's RESULT_OK (wrk_result_build) and the client's copy of it into
 * mc_job_result (and mc_stage_maps, as mc_result_stage copies it); progress
 * goes through the worker's PROGRESS record. So the in-process map is the
 * server's map. */
#include "mc__wire.h"
#include "main/worker.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

/* Most OpenMP threads a caller may ask for (the worker's --threads limit). */
#define MC_MATCH_MAX_THREADS 1024

typedef struct match_run {
    mc_progress_fn cb;
    void *ctx;
    struct timespec t0;
    int last_outer;            /* the last ECTM iteration reported */
    int stopped;               /* cb asked to stop */
} match_run;

static double since(const struct timespec *t0)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)(t.tv_sec - t0->tv_sec) + 1e-9 * (double)(t.tv_nsec - t0->tv_nsec);
}

static int on_progress(void *ctx, const corr_progress *cp)
{
    match_run *run = ctx;
    if (cp->ectm)
        run->last_outer = cp->ectm->outer;
    if (!run->cb)
        return 0;
    proto_progress wire;
    mc_progress p;
    wrk_progress_fill(cp, 0, since(&run->t0), &wire);
    mc__progress_of(&p, &wire);
    run->stopped = run->cb(run->ctx, &p) != 0;
    return run->stopped;
}

/* The SUBMIT of spec as meshcorrd decodes it: encoded with the codec's
 * limits into *frame, decoded from there into *sub (which borrows from
 * *frame: free sub first). */
static int submit_as_received(const mc_job_spec *spec, proto_buf *frame, proto_msg *sub, char *err,
                              size_t errsz)
{
    proto_msg req;
    memset(&req, 0, sizeof req);
    req.type = PROTO_MSG_SUBMIT;
    int rc = mc__submit_of(spec, &req.u.submit, err, errsz);
    if (rc)
        return rc;
    if ((rc = proto_msg_encode(frame, &req, err, errsz)))
        return rc == PROTO_ENOMEM ? MC_ENOMEM : rc;
    size_t used = 0;
    rc = proto_decode(frame->data, frame->len, PROTO_MAX_FRAME, sub, &used, err, errsz);
    if (rc != PROTO_READY)
        return rc < 0 ? (rc == PROTO_ENOMEM ? MC_ENOMEM : rc) : MC_EPROTO;
    return 0;
}

int mc_match(const mc_job_spec *spec, int threads, unsigned what, mc_progress_fn cb, void *ctx,
             mc_job_result *out, char *err, size_t errsz)
{
    return mc_match_stages(spec, threads, what, cb, ctx, out, NULL, err, errsz);
}

int mc_match_stages(const mc_job_spec *spec, int threads, unsigned what, mc_progress_fn cb,
                    void *ctx, mc_job_result *out, mc_stage_maps *stage, char *err, size_t errsz)
{
    if (!out) {
        snprintf(err, errsz, "mc_match: out is NULL");
        return MC_EARG;
    }
    memset(out, 0, sizeof *out);
    if (stage)
        memset(stage, 0, sizeof *stage);
    if (threads < 0 || threads > MC_MATCH_MAX_THREADS) {
        snprintf(err, errsz, "threads = %d: expected 0 (by the pair's size) to %d", threads,
                 MC_MATCH_MAX_THREADS);
        return MC_EARG;
    }
    match_run run = { cb, ctx, {0, 0}, 0, 0 };
    clock_gettime(CLOCK_MONOTONIC, &run.t0);
    proto_buf frame;
    proto_buf_init(&frame);
    proto_msg sub;
    memset(&sub, 0, sizeof sub);
    wrk_job job;
    memset(&job, 0, sizeof job);
    ectm_result res;
    memset(&res, 0, sizeof res);
    wrk_result result;
    memset(&result, 0, sizeof result);
    wrk_limits lim = { MESH_MAX_VERTICES, MESH_MAX_FACES, threads };

    int rc = submit_as_received(spec, &frame, &sub, err, errsz);
    if (rc || (rc = wrk_job_from_submit(&sub.u.submit, &lim, &job, err, errsz)))
        goto done;
    corr_input in;
    wrk_job_input(&job, &in);
    rc = corr_run(&in, &job.params, on_progress, &run, &res, err, errsz);
    if (rc == KIND_ECANCELLED && run.stopped)
        snprintf(err, errsz, "cancelled by the progress callback after %d of %d outer iterations",
                 run.last_outer, job.params.iterations);
    if (rc) {
        rc = corr_wire_code(rc);
        goto done;
    }
    if ((rc = wrk_result_build(&job, &res, 0, since(&run.t0), &result, err, errsz)))
        goto done;
    if ((rc = mc__result_of(&result.msg.u.result_ok, what, out)) ||
        (stage && (rc = mc__stage_of(&result.msg.u.result_ok, stage)))) {
        mc_result_free(out);
        snprintf(err, errsz, "out of memory for the result");
    }
done:
    if (rc == PROTO_ENOMEM)
        rc = MC_ENOMEM;
    wrk_result_close(&result);
    ectm_result_close(&res);
    wrk_job_close(&job);
    proto_msg_free(&sub);
    proto_buf_free(&frame);
    return rc;
}
