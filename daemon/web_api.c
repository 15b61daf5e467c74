/* web_api.c — the JSON API under /api/v1/ (docs/openapi.yaml is its
 * reference): the session, the job list, one job, its progress history,
 * its quality, its maps, its map's picture, its progress as server-sent
 * events (web_events.c), a cancel, the figures and the worker slots. Every
 * call needs a login (web_auth: a Bearer token or a session cookie); a job
 * the caller may not see is answered 404 like one that does not exist.
 * Reads the snapshot web.c took for the request and the read-only job
 * store; a cancel is handed to the loop (web_cancel_request). Submission
 * stays on the socket protocol. */
#include "web.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A URL number: 0 with *v, -1 when s is not a whole decimal number. */
static int number(const char *s, size_t n, uint64_t *v)
{
    if (n == 0 || n > 19)
        return -1;
    uint64_t x = 0;
    for (size_t i = 0; i < n; i++) {
        if (s[i] < '0' || s[i] > '9')
            return -1;
        x = 10 * x + (uint64_t)(s[i] - '0');
    }
    *v = x;
    return 0;
}

static void job_json(web *w, FILE *fp, const store_job *j, const char *params)
{
    int64_t pos;
    const char *stage = web_job_stage(w, j, &pos);
    int64_t now = store_now_ms();
    int64_t end = j->end_ms ? j->end_ms : now;
    fprintf(fp, "{\"id\":%llu,\"label\":", (unsigned long long)j->id);
    web_json_str(fp, j->label);
    fputs(",\"user\":", fp);
    web_json_str(fp, j->user);
    fprintf(fp, ",\"state\":\"%s\",\"stage\":\"%s\",\"priority\":%d,\"progress\":", proto_state_name(j->state),
            stage, j->priority);
    web_json_num(fp, j->state == PROTO_STATE_COMPLETED ? 1.0 : j->fraction);
    fputs(",\"eta_s\":", fp);
    web_json_num(fp, j->state == PROTO_STATE_RUNNING ? j->eta_s : NAN);
    fputs(",\"queue_position\":", fp);
    if (pos >= 0)
        fprintf(fp, "%lld", (long long)pos);
    else
        fputs("null", fp);
    fputs(",\"elapsed_s\":", fp);
    web_json_num(fp, j->start_ms ? (double)(end - j->start_ms) / 1000 : NAN);
    fprintf(fp, ",\"submit_ms\":%lld,\"start_ms\":%lld,\"end_ms\":%lld,\"outer\":%u,\"total\":%u,\"reason\":",
            (long long)j->submit_ms, (long long)j->start_ms, (long long)j->end_ms, j->outer, j->total);
    web_json_str(fp, j->reason);
    fputs(",\"quality\":{\"verdict\":", fp);
    static const char *const verdicts[] = {"ok", "folded", "orientation reversed"};
    if (j->verdict >= 0 && j->verdict <= 2)
        web_json_str(fp, verdicts[j->verdict]);
    else
        fputs("null", fp);
    fputs(",\"flipped\":", fp);
    web_json_num(fp, j->flipped);
    fputs(",\"collapsed\":", fp);
    web_json_num(fp, j->collapsed);
    fputc('}', fp);
    if (params) {
        fputs(",\"params\":", fp);
        web_json_str(fp, params);
    }
    fputc('}', fp);
}

static enum MHD_Result jobs(web *w, web_req *r)
{
    const char *state = MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, "state");
    const char *user = MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, "user");
    if (state && !*state)
        state = NULL;
    if (user && !*user)
        user = NULL;
    if (state) {
        int ok = 0;
        for (int i = 0; i <= PROTO_STATE_LAST; i++)
            ok |= !strcmp(state, proto_state_name(i));
        if (!ok)
            return web_reply_error(r, MHD_HTTP_BAD_REQUEST, "state: not a job state (PENDING, RUNNING, "
                                   "COMPLETED, FAILED, CANCELLED, TIMEOUT, OUT_OF_MEMORY)");
    }
    if (!r->admin)
        user = r->user;           /* a user's list holds their own jobs only */
    sqlite3 *db = web_db(w);
    sqlite3_stmt *st = NULL;
    if (!db || sqlite3_prepare_v2(db, "SELECT id, user, label, priority, state, reason, submit_ms, start_ms, end_ms,"
                                  " params, total, outer_it, verdict, flipped, collapsed, fraction, eta_s FROM jobs"
                                  " WHERE (?1 IS NULL OR user = ?1) AND (?2 IS NULL OR state = ?2)"
                                  " ORDER BY id DESC LIMIT ?3", -1, &st, NULL) != SQLITE_OK) {
        sqlite3_finalize(st);
        return web_reply_error(r, MHD_HTTP_INTERNAL_SERVER_ERROR, "job store unreadable");
    }
    if (user)
        sqlite3_bind_text(st, 1, user, -1, SQLITE_STATIC);
    if (state)
        sqlite3_bind_text(st, 2, state, -1, SQLITE_STATIC);
    sqlite3_bind_int(st, 3, WEB_MAX_LIST);
    char *buf = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&buf, &len);
    if (!fp) {
        sqlite3_finalize(st);
        return MHD_NO;
    }
    fputs("{\"user\":", fp);
    web_json_str(fp, r->user);
    fprintf(fp, ",\"admin\":%s,\"jobs\":[", r->admin ? "true" : "false");
    int n = 0;
    while (sqlite3_step(st) == SQLITE_ROW) {
        store_job j;
        memset(&j, 0, sizeof j);
        j.id = (uint64_t)sqlite3_column_int64(st, 0);
        snprintf(j.user, sizeof j.user, "%s", (const char *)sqlite3_column_text(st, 1));
        web_job_row(st, 2, &j);
        if (n++)
            fputc(',', fp);
        job_json(w, fp, &j, NULL);
    }
    sqlite3_finalize(st);
    fputs("]}\n", fp);
    return web_reply_json(r, MHD_HTTP_OK, fp, &buf, &len);
}

static enum MHD_Result one_job(web *w, web_req *r, const store_job *j, const char *params)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&buf, &len);
    if (!fp)
        return MHD_NO;
    job_json(w, fp, j, params);
    fputc('\n', fp);
    return web_reply_json(r, MHD_HTTP_OK, fp, &buf, &len);
}

/* Progress records after `after` (the answer's "next" continues). */
static enum MHD_Result history(web *w, web_req *r, uint64_t id)
{
    const char *a = MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, "after");
    uint64_t after = 0;
    if (a && number(a, strlen(a), &after))
        return web_reply_error(r, MHD_HTTP_BAD_REQUEST, "after: not a record number");
    char *buf = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&buf, &len);
    if (!fp)
        return MHD_NO;
    fprintf(fp, "{\"id\":%llu,\"points\":[", (unsigned long long)id);
    int64_t next = web_points(w, id, after, WEB_MAX_HISTORY, fp, 0);
    if (next < 0) {
        fclose(fp);
        free(buf);
        return web_reply_error(r, MHD_HTTP_INTERNAL_SERVER_ERROR, "job store unreadable");
    }
    fprintf(fp, "],\"next\":%lld}\n", (long long)next);
    return web_reply_json(r, MHD_HTTP_OK, fp, &buf, &len);
}

/* The quality the job row keeps, and a COMPLETED job's every metric from
 * its result.frame. */
static enum MHD_Result quality(web *w, web_req *r, const store_job *j)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&buf, &len);
    if (!fp)
        return MHD_NO;
    fprintf(fp, "{\"id\":%llu,\"state\":\"%s\",\"verdict\":%d,\"flipped\":", (unsigned long long)j->id,
            proto_state_name(j->state), j->verdict);
    web_json_num(fp, j->flipped);
    fputs(",\"collapsed\":", fp);
    web_json_num(fp, j->collapsed);
    fputs(",\"metrics\":{", fp);
    if (j->state == PROTO_STATE_COMPLETED) {
        proto_msg m;
        uint8_t *frame = NULL;
        char why[256];
        if (store_result_read(web_store(w), j->id, &m, &frame, why, sizeof why) == 0) {
            for (uint32_t i = 0; i < m.u.result_ok.nmetrics; i++) {
                fputs(i ? "," : "", fp);
                web_json_str(fp, m.u.result_ok.metrics[i].key);
                fputc(':', fp);
                web_json_num(fp, m.u.result_ok.metrics[i].value);
            }
            proto_msg_free(&m);
            free(frame);
        }
    }
    fputs("}}\n", fp);
    return web_reply_json(r, MHD_HTTP_OK, fp, &buf, &len);
}

/* A COMPLETED job's map p (source to target) or q (target to source) as
 * text: one line per vertex, "face w0 w1 w2" (0-based face of the other
 * mesh, barycentric weights). */
static enum MHD_Result map(web *w, web_req *r, const store_job *j, char which)
{
    if (j->state != PROTO_STATE_COMPLETED)
        return web_reply_error(r, MHD_HTTP_CONFLICT, "job %llu is %s: no maps", (unsigned long long)j->id,
                               proto_state_name(j->state));
    proto_msg m;
    uint8_t *frame = NULL;
    char why[256];
    if (store_result_read(web_store(w), j->id, &m, &frame, why, sizeof why))
        return web_reply_error(r, MHD_HTTP_INTERNAL_SERVER_ERROR, "result of job %llu unreadable",
                               (unsigned long long)j->id);
    const proto_map *pm = which == 'p' ? &m.u.result_ok.p : &m.u.result_ok.q;
    if (!pm->n) {
        proto_msg_free(&m);
        free(frame);
        return web_reply_error(r, MHD_HTTP_NOT_FOUND, "job %llu has no map %c (the injective model has p only)",
                               (unsigned long long)j->id, which);
    }
    char *buf = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&buf, &len);
    if (!fp) {
        proto_msg_free(&m);
        free(frame);
        return MHD_NO;
    }
    for (uint32_t i = 0; i < pm->n; i++)
        fprintf(fp, "%u %.17g %.17g %.17g\n", pm->rows[i].face, pm->rows[i].w[0], pm->rows[i].w[1],
                pm->rows[i].w[2]);
    proto_msg_free(&m);
    free(frame);
    if (fclose(fp) != 0) {
        free(buf);
        return MHD_NO;
    }
    return web_reply(r, MHD_HTTP_OK, "text/plain; charset=utf-8", buf, len, 1);
}

static enum MHD_Result cancel(web *w, web_req *r, const store_job *j)
{
    if (!web_csrf_ok(r))
        return web_reply_error(r, MHD_HTTP_FORBIDDEN, "missing or wrong X-CSRF-Token");
    if (store_is_terminal(j->state))
        return web_reply_error(r, MHD_HTTP_CONFLICT, "job %llu is %s: nothing to cancel",
                               (unsigned long long)j->id, proto_state_name(j->state));
    if (web_cancel_request(web_cancels(w), j->id, r->user, r->admin))
        return web_reply_error(r, MHD_HTTP_SERVICE_UNAVAILABLE, "too many cancels waiting: try again");
    dlog(DLOG_INFO, "web: %s asks to cancel job %llu (from %s)", r->user, (unsigned long long)j->id, r->peer);
    char *buf = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&buf, &len);
    if (!fp)
        return MHD_NO;
    fprintf(fp, "{\"id\":%llu,\"cancel\":\"requested\"}\n", (unsigned long long)j->id);
    return web_reply_json(r, MHD_HTTP_ACCEPTED, fp, &buf, &len);
}

static enum MHD_Result stats(web *w, web_req *r, int slots_only)
{
    const mcd_snapshot *s = web_snapshot(w);
    char *buf = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&buf, &len);
    if (!fp)
        return MHD_NO;
    double load[3] = {NAN, NAN, NAN};
    getloadavg(load, 3);
    fputs("{\"backend\":", fp);
    web_json_str(fp, web_backend(w));
    if (!slots_only)
        fprintf(fp, ",\"queued\":%u,\"running\":%u,\"workers\":%u,\"completed\":%llu,\"failed\":%llu,"
                "\"cancelled\":%llu,\"uptime_s\":%u", s->queued, s->running, s->workers,
                (unsigned long long)s->completed, (unsigned long long)s->failed, (unsigned long long)s->cancelled,
                s->uptime_s);
    fputs(",\"load\":[", fp);
    for (int i = 0; i < 3; i++) {
        fputs(i ? "," : "", fp);
        web_json_num(fp, load[i]);
    }
    fputs("],\"slots\":[", fp);
    static const char *const states[] = {"idle", "starting", "busy", "draining"};
    for (uint32_t i = 0; i < s->nslots; i++) {
        const snap_slot *o = &s->slots[i];
        /* another user's job shows as busy, without its id */
        store_job j;
        int mine = o->job_id && web_job(w, r, o->job_id, &j, NULL, 0) == 0;
        fprintf(fp, "%s{\"slot\":%u,\"state\":\"%s\",\"job\":", i ? "," : "", i,
                o->state <= PROTO_SLOT_LAST ? states[o->state] : "?");
        if (mine) {
            fprintf(fp, "%llu,\"user\":", (unsigned long long)o->job_id);
            web_json_str(fp, j.user);
            fputs(",\"label\":", fp);
            web_json_str(fp, j.label);
        } else {
            fputs("null", fp);
        }
        fprintf(fp, ",\"stage\":\"%s\",\"elapsed_s\":%u,\"progress\":", o->has_progress ? proto_stage_name(o->stage)
                : "", o->elapsed_s);
        web_json_num(fp, o->job_id ? o->fraction : NAN);
        fputs(",\"eta_s\":", fp);
        web_json_num(fp, o->job_id ? o->eta_s : NAN);
        fputc('}', fp);
    }
    fputs("]}\n", fp);
    return web_reply_json(r, MHD_HTTP_OK, fp, &buf, &len);
}

static enum MHD_Result session_info(web_req *r)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&buf, &len);
    if (!fp)
        return MHD_NO;
    fputs("{\"user\":", fp);
    web_json_str(fp, r->user);
    fprintf(fp, ",\"admin\":%s,\"csrf\":", r->admin ? "true" : "false");
    if (r->by_session)
        web_json_str(fp, r->csrf);
    else
        fputs("null", fp);
    fputs("}\n", fp);
    return web_reply_json(r, MHD_HTTP_OK, fp, &buf, &len);
}

enum MHD_Result web_api(web *w, web_req *r, const char *path)
{
    enum MHD_Result res;
    if (web_auth(w, r, &res))
        return res;
    int get = !strcmp(r->method, MHD_HTTP_METHOD_GET), post = !strcmp(r->method, MHD_HTTP_METHOD_POST);
    if (!get && !post)
        return web_reply_error(r, MHD_HTTP_METHOD_NOT_ALLOWED, "GET or POST only");
    if (!strcmp(path, "/session") && get)
        return session_info(r);
    if (!strcmp(path, "/stats") && get)
        return stats(w, r, 0);
    if (!strcmp(path, "/workers") && get)
        return stats(w, r, 1);
    if (!strcmp(path, "/jobs") && get)
        return jobs(w, r);
    if (strncmp(path, "/jobs/", 6))
        return web_reply_error(r, MHD_HTTP_NOT_FOUND, "no such API path (docs/openapi.yaml lists them)");
    const char *p = path + 6, *slash = strchr(p, '/');
    size_t n = slash ? (size_t)(slash - p) : strlen(p);
    const char *rest = slash ? slash : "";
    uint64_t id;
    if (number(p, n, &id))
        return web_reply_error(r, MHD_HTTP_NOT_FOUND, "no such job");
    store_job j;
    char params[4096];
    int rc = web_job(w, r, id, &j, params, sizeof params);
    if (rc == PROTO_ENOT_FOUND)
        return web_reply_error(r, MHD_HTTP_NOT_FOUND, "no such job");
    if (rc)
        return web_reply_error(r, MHD_HTTP_INTERNAL_SERVER_ERROR, "job store unreadable");
    if (!*rest && get)
        return one_job(w, r, &j, params);
    if (!strcmp(rest, "/history") && get)
        return history(w, r, id);
    if (!strcmp(rest, "/quality") && get)
        return quality(w, r, &j);
    if ((!strcmp(rest, "/maps/p") || !strcmp(rest, "/maps/q")) && get)
        return map(w, r, &j, rest[6]);
    if (!strcmp(rest, "/events") && get)
        return web_events(w, r, &j);
    if (!strcmp(rest, "/picture") && get)
        return web_picture(w, r, &j);
    if (!strcmp(rest, "/cancel") && post)
        return cancel(w, r, &j);
    return web_reply_error(r, MHD_HTTP_NOT_FOUND, "no such API path (docs/openapi.yaml lists them)");
}
