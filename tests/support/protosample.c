/* protosample.c — see protosample.h. */
#include "support/protosample.h"

#include <float.h>
#include <math.h>
#include <string.h>

static char long_str[PROTO_MAX_STRING + 1];
static uint8_t mesh_a[3000], mesh_b[777];
static proto_landmark lms[40];
static proto_map_row rows_p[100], rows_q[60];  /* SUBMIT's */
static proto_map_row res_p[100], res_q[60];    /* RESULT_OK's */
static uint8_t res_mesh[2500];
static proto_job_summary jobs[5];
static proto_metric metrics[4];
static proto_slot slots[3];
static const char *devices[2];

/* PROTO_MAX_STRING bytes: ASCII, then 2-byte "é" and a 4-byte emoji. */
static const char *max_string(void)
{
    size_t n = 0;
    while (n < PROTO_MAX_STRING - 6) {
        long_str[n] = (char)('a' + n % 26);
        n++;
    }
    memcpy(long_str + n, "\xC3\xA9\xF0\x9F\x98\x80", 6);
    long_str[PROTO_MAX_STRING] = 0;
    return long_str;
}

static void fill_bytes(uint8_t *p, size_t n, unsigned seed)
{
    for (size_t i = 0; i < n; i++) {
        seed = seed * 1103515245u + 12345u;
        p[i] = (uint8_t)(seed >> 16);
    }
}

static void fill_rows(proto_map_row *r, uint32_t n, double s)
{
    for (uint32_t i = 0; i < n; i++) {
        r[i].face = i * 7919u + 3u;
        r[i].w[0] = 0.25 + s * i / n;
        r[i].w[1] = 0.5 - s * i / n;
        r[i].w[2] = 1.0 - r[i].w[0] - r[i].w[1];
    }
}

static void fill_progress(proto_progress *g, int v)
{
    g->job_id = v ? 1 : UINT64_MAX;
    g->stage = v ? PROTO_STAGE_START : PROTO_STAGE_ECTM;
    g->outer = 17;
    g->total = 40;
    g->inner[0] = 123;
    g->inner[1] = 98;
    for (int d = 0; d < 2; d++)
        for (int t = 0; t < PROTO_NTERMS; t++)
            g->terms[d][t] = (d + 1) * 1.0e-3 * (t + 1) + (v ? 0 : DBL_MIN);
    g->beta = 0.5;
    g->gamma = v ? 0.0 : 1e300;
    g->elapsed_s = 12.375;
    g->fraction = v ? 0.0 : 0.4375;
    g->eta_s = v ? NAN : 1e6;
    g->ahead = v ? 0 : UINT32_MAX;
}

void protosample_fill(int type, int v, proto_msg *m)
{
    const char *s = v ? "" : max_string();
    memset(m, 0, sizeof *m);
    m->type = (uint8_t)type;
    m->request_id = v ? 0 : 0xDEADBEEFu;
    switch (type) {
    case PROTO_MSG_HELLO:
        m->u.hello = (proto_hello){ PROTO_VERSION, v ? "" : "tok-3f9a\xE2\x82\xAC", s };
        break;
    case PROTO_MSG_HELLO_OK:
        m->u.hello_ok = (proto_hello_ok){ PROTO_VERSION, v ? "" : "alice", (uint8_t)!v,
                                          { PROTO_DEFAULT_MAX_FRAME, 20000000, 65536, 8, 1000, 86400 } };
        break;
    case PROTO_MSG_SUBMIT: {
        proto_submit *u = &m->u.submit;
        fill_bytes(mesh_a, sizeof mesh_a, 1);
        fill_bytes(mesh_b, sizeof mesh_b, 2);
        u->source = (proto_blob){ mesh_a, sizeof mesh_a };
        u->target = (proto_blob){ mesh_b, v ? 1 : (uint32_t)sizeof mesh_b };
        for (uint32_t i = 0; i < 40; i++)
            lms[i] = (proto_landmark){ i * 13u, UINT32_MAX - i };
        u->landmarks = lms;
        u->nlandmarks = v ? 1 : 40;
        if (!v) {
            fill_rows(rows_p, 100, 0.125);
            fill_rows(rows_q, 60, 0.0625);
            u->p = (proto_map){ rows_p, 100 };
            u->q = (proto_map){ rows_q, 60 };
        }
        u->params = (proto_params){ (uint8_t)(v ? PROTO_MODEL_INJECTIVE : PROTO_MODEL_BIJECTIVE),
                                    (uint8_t)!v, 1e-3, 0.1, 1.0, 1e4, 2, 0.25, 30, 200,
                                    1e-8, 1e-6, v ? 0 : 150, v ? 0 : 12, v ? 0 : 1e-3,
                                    v ? 0 : 0.5, (uint8_t)!v, v ? "" : "opencl:pocl",
                                    (uint8_t)(v ? PROTO_CHAIN_ALL : PROTO_CHAIN_DDM_RHM_ECTM),
                                    v ? 0 : 60, (uint8_t)(v ? PROTO_DDM_PLAIN : PROTO_DDM_BIJECTIVE), v ? 0 : 120,
                                    v ? 0 : 4000, (uint8_t)!v };
        u->priority = v ? 0 : -7;
        u->label = s;
        break;
    }
    case PROTO_MSG_SUBMIT_OK: case PROTO_MSG_STATUS: case PROTO_MSG_CANCEL:
    case PROTO_MSG_OK: case PROTO_MSG_DELETE:
        m->u.ok.job_id = v ? 1 : 0x0123456789ABCDEFull;
        break;
    case PROTO_MSG_STATUS_OK: {
        proto_status_ok *u = &m->u.status_ok;
        u->job_id = 42;
        u->state = v ? PROTO_STATE_PENDING : PROTO_STATE_OUT_OF_MEMORY;
        u->priority = INT32_MIN;
        u->user = v ? "" : "bob";
        u->label = s;
        u->reason = v ? "" : "worker exceeded 64 GiB";
        u->submit_ms = 1700000000123;
        u->start_ms = v ? 0 : 1700000000456;
        u->end_ms = v ? 0 : INT64_MAX;
        u->has_progress = (uint8_t)!v;
        if (!v)
            fill_progress(&u->progress, v);
        u->quality = v ? (proto_quality){-1, NAN, NAN} : (proto_quality){1, 0.0625, 1e-3};
        break;
    }
    case PROTO_MSG_LIST:
        m->u.list = (proto_list){ v ? 0u : (1u << PROTO_STATE_RUNNING) | (1u << PROTO_STATE_FAILED),
                                  s, v ? 0 : 100, v ? 0 : 9999 };
        break;
    case PROTO_MSG_LIST_OK:
        for (int i = 0; i < 5; i++)
            jobs[i] = (proto_job_summary){ 100u + (uint64_t)i, (uint8_t)(i % 7), i - 2,
                                           1700000000000 + i, i ? "carol" : max_string(), i == 3 ? "" : "run",
                                           (uint32_t)i, 40, {i % 4 - 1, i ? 0.25 * i : NAN, 1e-4 * i},
                                           i == 4 ? NAN : 0.25 * i, i ? 3.5 * i : NAN, (uint32_t)(7 * i) };
        m->u.list_ok = (proto_list_ok){ v ? NULL : jobs, v ? 0 : 5 };
        break;
    case PROTO_MSG_WATCH:
        m->u.watch = (proto_watch){ 77, v ? 0 : 12 };
        break;
    case PROTO_MSG_PROGRESS:
        fill_progress(&m->u.progress, v);
        break;
    case PROTO_MSG_END:
        m->u.end = (proto_end){ 77, (uint8_t)(v ? PROTO_STATE_COMPLETED : PROTO_STATE_TIMEOUT), s };
        break;
    case PROTO_MSG_RESULT:
        m->u.result = (proto_result){ 5, v ? PROTO_WANT_P : PROTO_WANT_ALL };
        break;
    case PROTO_MSG_RESULT_OK: {
        proto_result_ok *u = &m->u.result_ok;
        u->job_id = 5;
        fill_rows(res_p, 100, 0.3);
        fill_rows(res_q, 60, 0.2);
        u->p = (proto_map){ res_p, v ? 1 : 100 };
        if (!v) {
            u->q = (proto_map){ res_q, 60 };
            fill_bytes(res_mesh, sizeof res_mesh, 3);
            u->deformed = (proto_blob){ res_mesh, sizeof res_mesh };
            metrics[0] = (proto_metric){ "geodesic_error_mean", 0.0123 };
            metrics[1] = (proto_metric){ "flipped_faces", 0.0 };
            metrics[2] = (proto_metric){ s, -INFINITY };
            metrics[3] = (proto_metric){ "", 1e-300 };
            u->metrics = metrics;
            u->nmetrics = 4;
            u->rhm_p = (proto_map){ res_p, 100 };   /* RHM's maps (PROTO_WANT_STAGE_RHM) */
            u->rhm_q = (proto_map){ res_q, 60 };
        }
        break;
    }
    case PROTO_MSG_STATS_OK: {
        proto_stats_ok *u = &m->u.stats_ok;
        *u = (proto_stats_ok){ 12, 2, 3, 1000000, 7, UINT64_MAX, NULL, 0, NULL, 0, "slurm", 0,
                               "squeue failed: slurm_load_jobs error: Unable to contact slurm controller" };
        if (!v) {
            slots[0] = (proto_slot){ 0, PROTO_SLOT_IDLE };
            slots[1] = (proto_slot){ 31, PROTO_SLOT_BUSY };
            slots[2] = (proto_slot){ 0, PROTO_SLOT_DRAINING };
            devices[0] = "cpu:16";
            devices[1] = s;
            u->slots = slots;
            u->nslots = 3;
            u->devices = devices;
            u->ndevices = 2;
        }
        break;
    }
    case PROTO_MSG_ERROR:
        m->u.error = (proto_error_msg){ v ? PROTO_EINTERNAL : PROTO_EQUEUE_FULL, s };
        break;
    default:  /* STATS, PING, PONG: no payload */
        break;
    }
}

#define DIFF(cond, name) do { if (cond) return name; } while (0)

/* Bit for bit (NaN equals NaN). */
static int quality_ne(const proto_quality *a, const proto_quality *b)
{
    return a->verdict != b->verdict || memcmp(&a->flipped, &b->flipped, sizeof a->flipped) ||
           memcmp(&a->collapsed, &b->collapsed, sizeof a->collapsed);
}

static int str_ne(const char *a, const char *b)
{
    return strcmp(a ? a : "", b ? b : "") != 0;
}

static int blob_ne(proto_blob a, proto_blob b)
{
    return a.len != b.len || (a.len && memcmp(a.data, b.data, a.len) != 0);
}

static int map_ne(proto_map a, proto_map b)
{
    return a.n != b.n || (a.n && memcmp(a.rows, b.rows, a.n * sizeof *a.rows) != 0);
}

/* Equal, or both NaN. */
static int same_num(double a, double b)
{
    return a == b || (isnan(a) && isnan(b));
}

static const char *progress_diff(const proto_progress *a, const proto_progress *b)
{
    DIFF(a->job_id != b->job_id || a->stage != b->stage, "progress job/stage");
    DIFF(a->outer != b->outer || a->total != b->total, "progress outer/total");
    DIFF(memcmp(a->inner, b->inner, sizeof a->inner) != 0, "progress inner");
    DIFF(memcmp(a->terms, b->terms, sizeof a->terms) != 0, "progress terms");
    DIFF(a->beta != b->beta || a->gamma != b->gamma || a->elapsed_s != b->elapsed_s,
         "progress beta/gamma/elapsed");
    DIFF(!same_num(a->fraction, b->fraction) || !same_num(a->eta_s, b->eta_s) || a->ahead != b->ahead,
         "progress fraction/eta_s/ahead");
    return NULL;
}

const char *protosample_diff(const proto_msg *a, const proto_msg *b)
{
    DIFF(a->type != b->type, "type");
    DIFF(a->request_id != b->request_id, "request_id");
    switch (a->type) {
    case PROTO_MSG_HELLO: {
        const proto_hello *x = &a->u.hello, *y = &b->u.hello;
        DIFF(x->version != y->version, "hello.version");
        DIFF(str_ne(x->token, y->token), "hello.token");
        DIFF(str_ne(x->client, y->client), "hello.client");
        return NULL;
    }
    case PROTO_MSG_HELLO_OK: {
        const proto_hello_ok *x = &a->u.hello_ok, *y = &b->u.hello_ok;
        DIFF(x->version != y->version || x->admin != y->admin, "hello_ok.version/admin");
        DIFF(str_ne(x->user, y->user), "hello_ok.user");
        DIFF(memcmp(&x->limits, &y->limits, sizeof x->limits) != 0, "hello_ok.limits");
        return NULL;
    }
    case PROTO_MSG_SUBMIT: {
        const proto_submit *x = &a->u.submit, *y = &b->u.submit;
        DIFF(blob_ne(x->source, y->source), "submit.source");
        DIFF(blob_ne(x->target, y->target), "submit.target");
        DIFF(x->nlandmarks != y->nlandmarks ||
             (x->nlandmarks && memcmp(x->landmarks, y->landmarks, x->nlandmarks * sizeof *x->landmarks)),
             "submit.landmarks");
        DIFF(map_ne(x->p, y->p), "submit.p");
        DIFF(map_ne(x->q, y->q), "submit.q");
        const proto_params *p = &x->params, *q = &y->params;
        for (int i = 0; i < PROTO_NPARAMS; i++) {      /* every row of the one list */
            const proto_param_info *f = &proto_param_infos[i];
            if (f->type == PROTO_PARAM_STR)
                DIFF(str_ne(*(const char *const *)((const char *)p + f->offset),
                            *(const char *const *)((const char *)q + f->offset)), f->name);
            else
                DIFF(proto_param_get(p, i) != proto_param_get(q, i), f->name);
        }
        DIFF(x->priority != y->priority, "submit.priority");
        DIFF(str_ne(x->label, y->label), "submit.label");
        return NULL;
    }
    case PROTO_MSG_SUBMIT_OK: case PROTO_MSG_STATUS: case PROTO_MSG_CANCEL:
    case PROTO_MSG_OK: case PROTO_MSG_DELETE:
        DIFF(a->u.ok.job_id != b->u.ok.job_id, "job_id");
        return NULL;
    case PROTO_MSG_STATUS_OK: {
        const proto_status_ok *x = &a->u.status_ok, *y = &b->u.status_ok;
        DIFF(x->job_id != y->job_id || x->state != y->state || x->priority != y->priority,
             "status_ok.job/state/priority");
        DIFF(str_ne(x->user, y->user) || str_ne(x->label, y->label) || str_ne(x->reason, y->reason),
             "status_ok strings");
        DIFF(x->submit_ms != y->submit_ms || x->start_ms != y->start_ms || x->end_ms != y->end_ms,
             "status_ok times");
        DIFF(x->has_progress != y->has_progress, "status_ok.has_progress");
        DIFF(quality_ne(&x->quality, &y->quality), "status_ok.quality");
        return x->has_progress ? progress_diff(&x->progress, &y->progress) : NULL;
    }
    case PROTO_MSG_LIST: {
        const proto_list *x = &a->u.list, *y = &b->u.list;
        DIFF(x->state_mask != y->state_mask || x->max_count != y->max_count ||
             x->after_id != y->after_id, "list numbers");
        DIFF(str_ne(x->user, y->user), "list.user");
        return NULL;
    }
    case PROTO_MSG_LIST_OK:
        DIFF(a->u.list_ok.n != b->u.list_ok.n, "list_ok.n");
        for (uint32_t i = 0; i < a->u.list_ok.n; i++) {
            const proto_job_summary *x = &a->u.list_ok.jobs[i], *y = &b->u.list_ok.jobs[i];
            DIFF(x->job_id != y->job_id || x->state != y->state || x->priority != y->priority ||
                 x->submit_ms != y->submit_ms || x->outer != y->outer || x->total != y->total,
                 "list_ok job numbers");
            DIFF(str_ne(x->user, y->user) || str_ne(x->label, y->label), "list_ok job strings");
            DIFF(quality_ne(&x->quality, &y->quality), "list_ok job quality");
            DIFF(!same_num(x->fraction, y->fraction) || !same_num(x->eta_s, y->eta_s) || x->ahead != y->ahead,
                 "list_ok job progress");
        }
        return NULL;
    case PROTO_MSG_WATCH:
        DIFF(a->u.watch.job_id != b->u.watch.job_id || a->u.watch.from_outer != b->u.watch.from_outer,
             "watch");
        return NULL;
    case PROTO_MSG_PROGRESS:
        return progress_diff(&a->u.progress, &b->u.progress);
    case PROTO_MSG_END:
        DIFF(a->u.end.job_id != b->u.end.job_id || a->u.end.state != b->u.end.state, "end");
        DIFF(str_ne(a->u.end.reason, b->u.end.reason), "end.reason");
        return NULL;
    case PROTO_MSG_RESULT:
        DIFF(a->u.result.job_id != b->u.result.job_id || a->u.result.what != b->u.result.what, "result");
        return NULL;
    case PROTO_MSG_RESULT_OK: {
        const proto_result_ok *x = &a->u.result_ok, *y = &b->u.result_ok;
        DIFF(x->job_id != y->job_id, "result_ok.job_id");
        DIFF(map_ne(x->p, y->p), "result_ok.p");
        DIFF(map_ne(x->q, y->q), "result_ok.q");
        DIFF(map_ne(x->rhm_p, y->rhm_p), "result_ok.rhm_p");
        DIFF(map_ne(x->rhm_q, y->rhm_q), "result_ok.rhm_q");
        DIFF(blob_ne(x->deformed, y->deformed), "result_ok.deformed");
        DIFF(x->nmetrics != y->nmetrics, "result_ok.nmetrics");
        for (uint32_t i = 0; i < x->nmetrics; i++) {
            DIFF(str_ne(x->metrics[i].key, y->metrics[i].key), "metric key");
            DIFF(memcmp(&x->metrics[i].value, &y->metrics[i].value, 8) != 0, "metric value");
        }
        return NULL;
    }
    case PROTO_MSG_STATS_OK: {
        const proto_stats_ok *x = &a->u.stats_ok, *y = &b->u.stats_ok;
        DIFF(x->queued != y->queued || x->running != y->running || x->workers != y->workers,
             "stats_ok gauges");
        DIFF(x->completed != y->completed || x->failed != y->failed || x->cancelled != y->cancelled,
             "stats_ok counters");
        DIFF(x->nslots != y->nslots || x->ndevices != y->ndevices, "stats_ok counts");
        for (uint32_t i = 0; i < x->nslots; i++)
            DIFF(x->slots[i].job_id != y->slots[i].job_id || x->slots[i].state != y->slots[i].state,
                 "stats_ok slot");
        for (uint32_t i = 0; i < x->ndevices; i++)
            DIFF(str_ne(x->devices[i], y->devices[i]), "stats_ok device");
        DIFF(str_ne(x->backend, y->backend) || x->backend_ok != y->backend_ok ||
             str_ne(x->backend_status, y->backend_status), "stats_ok backend");
        return NULL;
    }
    case PROTO_MSG_ERROR:
        DIFF(a->u.error.code != b->u.error.code, "error.code");
        DIFF(str_ne(a->u.error.message, b->u.error.message), "error.message");
        return NULL;
    default:
        return NULL;
    }
}
