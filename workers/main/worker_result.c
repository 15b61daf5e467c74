/* worker_result.c — a finished job's RESULT_OK message (see worker.h):
 * maps to wire rows, the deformed source to Draco, the metric summary to
 * key/value pairs. Computes no map itself. */
#include "main/worker.h"
#include "metric/metric.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

void wrk_result_close(wrk_result *r)
{
    if (!r)
        return;
    free(r->p);
    free(r->q);
    free(r->rhm_p);
    free(r->rhm_q);
    free(r->deformed);
    memset(r, 0, sizeof *r);
}

static proto_map_row *rows_of(const bmap *P)
{
    proto_map_row *rows = malloc(sizeof *rows * ((size_t)P->n + 1));
    if (!rows)
        return NULL;
    for (int i = 0; i < P->n; i++) {
        rows[i].face = (uint32_t)P->face[i];
        memcpy(rows[i].w, P->w + 3 * (size_t)i, sizeof rows[i].w);
    }
    return rows;
}

/* The repair's record: each count of each mesh under its key. */
static int repair_metrics(const corr_fix *fx, proto_metric *m)
{
    static const char *const keys[] = {
#define WRK_SOURCE_KEY(name, text) "repair_source_" #name,
        REPAIR_COUNTS(WRK_SOURCE_KEY)
#undef WRK_SOURCE_KEY
#define WRK_TARGET_KEY(name, text) "repair_target_" #name,
        REPAIR_COUNTS(WRK_TARGET_KEY)
#undef WRK_TARGET_KEY
    };
    const double vals[] = {
#define WRK_SOURCE_VAL(name, text) fx->S.n.name,
        REPAIR_COUNTS(WRK_SOURCE_VAL)
#undef WRK_SOURCE_VAL
#define WRK_TARGET_VAL(name, text) fx->T.n.name,
        REPAIR_COUNTS(WRK_TARGET_VAL)
#undef WRK_TARGET_VAL
    };
    int n = (int)(sizeof keys / sizeof keys[0]);
    for (int i = 0; i < n; i++)
        m[i] = (proto_metric){ keys[i], vals[i] };
    return n;
}

/* The message from res, in the client's indexing (user) where the meshes
 * were repaired; the metrics from the engine's pair. */
static int build(const wrk_job *job, const ectm_result *res, const ectm_result *user,
                 uint64_t job_id, double elapsed, wrk_result *r, char *err, size_t errsz);

int wrk_result_build(const wrk_job *job, const ectm_result *res, uint64_t job_id,
                     double elapsed, wrk_result *r, char *err, size_t errsz)
{
    memset(r, 0, sizeof *r);
    if (!job->fix.repaired)
        return build(job, res, res, job_id, elapsed, r, err, errsz);
    ectm_result user;
    int rc = corr_fix_to_user(&job->fix, res, &user, err, errsz);
    if (rc)
        return corr_wire_code(rc);
    rc = build(job, res, &user, job_id, elapsed, r, err, errsz);
    ectm_result_close(&user);
    return rc;
}

/* The maps of user (P, Q, RHM's) as wire rows in r and the message; on
 * failure r is closed. */
static int build_maps(const ectm_result *user, wrk_result *r, char *err, size_t errsz)
{
    proto_result_ok *ok = &r->msg.u.result_ok;
    if (!(r->p = rows_of(user->P)) || (user->Q && !(r->q = rows_of(user->Q)))) {
        wrk_result_close(r);
        return errbuf_set(err, errsz, PROTO_ENOMEM, "result maps: out of memory");
    }
    ok->p = (proto_map){ r->p, (uint32_t)user->P->n };
    if (user->Q)
        ok->q = (proto_map){ r->q, (uint32_t)user->Q->n };
    if ((user->rhm_P && !(r->rhm_p = rows_of(user->rhm_P))) ||
        (user->rhm_Q && !(r->rhm_q = rows_of(user->rhm_Q)))) {
        wrk_result_close(r);
        return errbuf_set(err, errsz, PROTO_ENOMEM, "result maps: out of memory");
    }
    if (user->rhm_P)
        ok->rhm_p = (proto_map){ r->rhm_p, (uint32_t)user->rhm_P->n };
    if (user->rhm_Q)
        ok->rhm_q = (proto_map){ r->rhm_q, (uint32_t)user->rhm_Q->n };
    return 0;
}

/* The deformed source (ECTM's Y, or the map's image) in Draco, in r and
 * the message; on failure r is closed. */
static int build_deformed(const wrk_job *job, const ectm_result *user, wrk_result *r,
                          char *err, size_t errsz)
{
    /* a chain that ends before ECTM has no deformation: its mesh is the
     * map's image P X~ of the source (what ECTM's Y approximates) */
    double *image = NULL;
    if (!user->Y) {
        if (!(image = malloc(sizeof(double) * 3 * (size_t)job->S->nv + 1))) {
            wrk_result_close(r);
            return errbuf_set(err, errsz, PROTO_ENOMEM, "result mesh: out of memory");
        }
        bmap_apply(user->P, job->T->f, job->T->v, 3, image);
    }
    mesh deformed = { job->S->nv, job->S->nf, user->Y ? user->Y : image, job->S->f, 0 };
    size_t len = 0;
    char detail[512];
    int erc = mesh_encode_drc(&deformed, &r->deformed, &len, detail, sizeof detail);
    free(image);
    if (erc) {
        wrk_result_close(r);
        return errbuf_set(err, errsz, PROTO_EINTERNAL, "deformed mesh: %s", detail);
    }
    if (len > PROTO_MAX_MESH_BYTES) {
        wrk_result_close(r);
        return errbuf_set(err, errsz, PROTO_EOVER_LIMIT,
                          "deformed mesh: %zu Draco bytes, over PROTO_MAX_MESH_BYTES (%u)", len,
                          PROTO_MAX_MESH_BYTES);
    }
    r->msg.u.result_ok.deformed = (proto_blob){ r->deformed, (uint32_t)len };
    return 0;
}

/* The metrics of res's maps on the engine's pair in (the reverse map's
 * when there is one, the repair's counts, RHM's map's), in r and the
 * message; on failure r is closed. */
static int build_metrics(const wrk_job *job, const corr_input *in, const ectm_result *res,
                         double elapsed, wrk_result *r, char *err, size_t errsz)
{
    proto_result_ok *ok = &r->msg.u.result_ok;
    metric_summary ms, mq = {0};
    if (metric_summarize(in->S, in->T, res->P, &ms) ||
        (res->Q && metric_summarize(in->T, in->S, res->Q, &mq))) {
        wrk_result_close(r);
        return errbuf_set(err, errsz, PROTO_ENOMEM, "metrics: out of memory");
    }
    int verdict = metric_verdict(ms.flipped_fraction, ms.collapsed_fraction);
    if (res->Q) {
        int vq = metric_verdict(mq.flipped_fraction, mq.collapsed_fraction);
        verdict = vq > verdict ? vq : verdict;
    }
    const proto_metric m[] = {
        { "mean_abs_log_area", ms.mean_abs_log_area },
        { "median_conformal", ms.median_conformal },
        { "flipped_fraction", ms.flipped_fraction },
        { "collapsed_fraction", ms.collapsed_fraction },
        { "final_energy", res->last.energy },
        { "elapsed_s", elapsed },
        { "iterations", res->last.outer },
        { "quality_verdict", verdict },
        /* the reverse map Q's, when there is one (last: nmetrics drops them) */
        { "reverse_mean_abs_log_area", mq.mean_abs_log_area },
        { "reverse_median_conformal", mq.median_conformal },
        { "reverse_flipped_fraction", mq.flipped_fraction },
        { "reverse_collapsed_fraction", mq.collapsed_fraction },
    };
    _Static_assert(sizeof m / sizeof m[0] == WRK_BASE_METRICS, "WRK_BASE_METRICS");
    memcpy(r->metrics, m, sizeof m);
    ok->metrics = r->metrics;
    ok->nmetrics = sizeof m / sizeof m[0] - (res->Q ? 0 : 4);
    if (job->fix.repaired)
        ok->nmetrics += (uint32_t)repair_metrics(&job->fix, r->metrics + ok->nmetrics);
    if (res->rhm_P) {
        /* RHM's map's quality, as the final map's, on the engine's pair */
        metric_summary mr;
        if (metric_summarize(in->S, in->T, res->rhm_P, &mr)) {
            wrk_result_close(r);
            return errbuf_set(err, errsz, PROTO_ENOMEM, "metrics: out of memory");
        }
        const proto_metric rm[WRK_RHM_KEYS] = {
            { "rhm_mean_abs_log_area", mr.mean_abs_log_area },
            { "rhm_median_conformal", mr.median_conformal },
            { "rhm_flipped_fraction", mr.flipped_fraction },
            { "rhm_collapsed_fraction", mr.collapsed_fraction },
            { "ectm_scaled_reference", res->scaled },
        };
        memcpy(r->metrics + ok->nmetrics, rm, sizeof rm);
        ok->nmetrics += WRK_RHM_KEYS;
    }
    return 0;
}

static int build(const wrk_job *job, const ectm_result *res, const ectm_result *user,
                 uint64_t job_id, double elapsed, wrk_result *r, char *err, size_t errsz)
{
    r->msg.type = PROTO_MSG_RESULT_OK;
    r->msg.u.result_ok.job_id = job_id;
    corr_input in;              /* the engine's pair, for the metrics */
    wrk_job_input(job, &in);
    int rc = build_maps(user, r, err, errsz);
    if (!rc)
        rc = build_deformed(job, user, r, err, errsz);
    if (!rc)
        rc = build_metrics(job, &in, res, elapsed, r, err, errsz);
    return rc;
}
