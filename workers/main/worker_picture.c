/* worker_picture.c — meshcorr-worker --picture: the map of a finished job
 * drawn for the web UI (daemon/web_picture.c runs it on demand). The same
 * picture as `meshcorr eval --out-png` (render_map_png), from the job's own
 * spool files; the meshes come from a client, so they are decoded only
 * after the sandbox is entered, as in a run. */
#include "main/worker.h"
#include "render/render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define WRK_PICTURE_PANEL 400     /* pixels per side of each of its 4 panels */

static double metric_of(const proto_result_ok *r, const char *key)
{
    for (uint32_t i = 0; i < r->nmetrics; i++)
        if (!strcmp(r->metrics[i].key, key))
            return r->metrics[i].value;
    return NAN;
}

int wrk_picture(const char *dir, uint64_t job_id, const wrk_limits *lim, const char *out)
{
    char err[4096] = "", path[4096], tmp[4096];
    unsigned char *jbuf = NULL, *rbuf = NULL;
    proto_msg sub, res;
    wrk_job job;
    bmap *P = NULL;
    int status = 1;
    memset(&sub, 0, sizeof sub);
    memset(&res, 0, sizeof res);
    memset(&job, 0, sizeof job);
    snprintf(path, sizeof path, "%s/%s", dir, SPOOL_JOB_FRAME);
    if (wrk_frame_read(path, PROTO_MSG_SUBMIT, &jbuf, &sub, err, sizeof err))
        goto done;
    snprintf(path, sizeof path, "%s/%s", dir, SPOOL_RESULT_FRAME);
    if (wrk_frame_read(path, PROTO_MSG_RESULT_OK, &rbuf, &res, err, sizeof err))
        goto done;
    if (res.u.result_ok.job_id != job_id) {
        snprintf(err, sizeof err, "%s: the result of another job than %llu", dir, (unsigned long long)job_id);
        goto done;
    }
    if (sbx_enter(SBX_WORKER, "meshcorr-worker", err, sizeof err) ||
        wrk_job_from_submit(&sub.u.submit, lim, &job, err, sizeof err) ||
        wrk_map_of(&res.u.result_ok.p, "result map p", job.S, job.T, &P, err, sizeof err))
        goto done;
    if (!P) {
        snprintf(err, sizeof err, "job %llu's result has no map p", (unsigned long long)job_id);
        goto done;
    }
    char src[64], tgt[64], map[64];
    snprintf(src, sizeof src, "job %llu's source mesh", (unsigned long long)job_id);
    snprintf(tgt, sizeof tgt, "job %llu's target mesh", (unsigned long long)job_id);
    snprintf(map, sizeof map, "P of job %llu", (unsigned long long)job_id);
    render_map_words w = {src, tgt, map, metric_of(&res.u.result_ok, "flipped_fraction"),
                          metric_of(&res.u.result_ok, "collapsed_fraction"), NAN, 0, 0};
    snprintf(tmp, sizeof tmp, "%s.tmp", out);
    if (render_map_png(tmp, job.S, job.T, P, &w, WRK_PICTURE_PANEL, err, sizeof err)) {
        unlink(tmp);
        goto done;
    }
    if (rename(tmp, out)) {
        snprintf(err, sizeof err, "%s: cannot rename %s.tmp into place", out, out);
        unlink(tmp);
        goto done;
    }
    status = SPOOL_EXIT_OK;
done:
    if (status)
        fprintf(stderr, "meshcorr-worker --picture: %s\n", err);
    bmap_free(P);
    wrk_job_close(&job);
    proto_msg_free(&res);
    proto_msg_free(&sub);
    free(rbuf);
    free(jbuf);
    return status;
}
