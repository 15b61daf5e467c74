/* web_events.c — a job's progress as server-sent events
 * (GET /api/v1/jobs/ID/events, text/event-stream): every progress record
 * from where the client is (Last-Event-ID, which a browser's EventSource
 * sends when it reconnects, or ?after=) on, each as `id: RECORD`, `event:
 * progress`, `data: {point}`; then `event: end` with the job's final state,
 * and the stream closes. A comment line goes out at least every
 * WEB_STREAM_KEEPALIVE_S so a quiet stream is not taken for an idle
 * connection.
 *
 * DESIGN: libmicrohttpd runs each connection on a thread of its own
 * (MHD_USE_THREAD_PER_CONNECTION), so a stream's reader may wait: it looks
 * for new records every WEB_STREAM_POLL_MS in the read-only job store under
 * the web's lock, and sleeps without it. The streams are capped
 * (WEB_MAX_STREAMS, WEB_MAX_STREAMS_PER_USER), counted here under a mutex
 * of their own. A TLS reload ends the old server's streams
 * (web_streams_end) so that its stop never waits for a job to end. */
#include "web.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct user_count {
    char user[AUTH_MAX_USER];
    int n;
} user_count;

static struct {
    pthread_mutex_t mu;
    int open;
    unsigned generation;          /* web_streams_end bumps it: older streams end */
    user_count users[WEB_MAX_STREAMS];
} ev = {.mu = PTHREAD_MUTEX_INITIALIZER};

typedef struct stream {
    web *w;
    web_req who;                  /* user and admin: who may see the job */
    uint64_t id, after;
    unsigned generation;
    int ended;                    /* the end event is queued: close after it */
    int64_t sent_ms;              /* the last bytes went out */
    char *buf;                    /* queued text, off bytes of len sent */
    size_t len, off;
} stream;

static int64_t now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

/* Counts a new stream of user: 0, or -1 past a cap. */
static int take(const char *user)
{
    pthread_mutex_lock(&ev.mu);
    int rc = -1;
    user_count *mine = NULL, *free_one = NULL;
    for (int i = 0; i < WEB_MAX_STREAMS; i++) {
        if (ev.users[i].n && !strcmp(ev.users[i].user, user))
            mine = &ev.users[i];
        else if (!ev.users[i].n && !free_one)
            free_one = &ev.users[i];
    }
    if (ev.open < WEB_MAX_STREAMS && (!mine || mine->n < WEB_MAX_STREAMS_PER_USER)) {
        if (!mine) {
            mine = free_one;      /* there is one: fewer than WEB_MAX_STREAMS are open */
            snprintf(mine->user, sizeof mine->user, "%s", user);
        }
        mine->n++;
        ev.open++;
        rc = 0;
    }
    pthread_mutex_unlock(&ev.mu);
    return rc;
}

static void give_back(const char *user)
{
    pthread_mutex_lock(&ev.mu);
    for (int i = 0; i < WEB_MAX_STREAMS; i++)
        if (ev.users[i].n && !strcmp(ev.users[i].user, user)) {
            ev.users[i].n--;
            ev.open--;
            break;
        }
    pthread_mutex_unlock(&ev.mu);
}

void web_streams_end(web *w)
{
    (void)w;
    pthread_mutex_lock(&ev.mu);
    ev.generation++;
    pthread_mutex_unlock(&ev.mu);
}

static unsigned generation(void)
{
    pthread_mutex_lock(&ev.mu);
    unsigned g = ev.generation;
    pthread_mutex_unlock(&ev.mu);
    return g;
}

/* Queues the records after s->after, or the end event once the job has
 * ended and every record went out; -1 when the job is gone or the store
 * unreadable. */
static int fill(stream *s)
{
    free(s->buf);
    s->buf = NULL;
    s->len = s->off = 0;
    FILE *fp = open_memstream(&s->buf, &s->len);
    if (!fp)
        return -1;
    web_lock(s->w);
    store_job j;
    int rc = web_job(s->w, &s->who, s->id, &j, NULL, 0);
    int64_t next = rc ? -1 : web_points(s->w, s->id, s->after, WEB_MAX_HISTORY, fp, 1);
    web_unlock(s->w);
    if (next >= 0 && (uint64_t)next == s->after && store_is_terminal(j.state)) {
        /* read after the state: no record can come after this end */
        fprintf(fp, "event: end\ndata: {\"id\":%llu,\"state\":\"%s\"}\n\n", (unsigned long long)s->id,
                proto_state_name(j.state));
        s->ended = 1;
    }
    if (next >= 0)
        s->after = (uint64_t)next;
    if (fclose(fp) != 0 || next < 0) {
        free(s->buf);
        s->buf = NULL;
        s->len = 0;
        return -1;
    }
    return 0;
}

static ssize_t reader(void *cls, uint64_t pos, char *out, size_t max)
{
    (void)pos;
    stream *s = cls;
    for (;;) {
        if (s->off < s->len) {
            size_t n = s->len - s->off < max ? s->len - s->off : max;
            memcpy(out, s->buf + s->off, n);
            s->off += n;
            s->sent_ms = now_ms();
            return (ssize_t)n;
        }
        if (s->ended || generation() != s->generation)
            return MHD_CONTENT_READER_END_OF_STREAM;
        if (fill(s))
            return MHD_CONTENT_READER_END_WITH_ERROR;
        if (s->len)
            continue;
        if (now_ms() - s->sent_ms >= 1000 * WEB_STREAM_KEEPALIVE_S) {
            static const char keepalive[] = ": keepalive\n\n";
            memcpy(out, keepalive, sizeof keepalive - 1 < max ? sizeof keepalive - 1 : max);
            s->sent_ms = now_ms();
            return (ssize_t)(sizeof keepalive - 1 < max ? sizeof keepalive - 1 : max);
        }
        struct timespec nap = {0, WEB_STREAM_POLL_MS * 1000000L};
        nanosleep(&nap, NULL);
    }
}

static void free_stream(void *cls)
{
    stream *s = cls;
    give_back(s->who.user);
    free(s->buf);
    free(s);
}

enum MHD_Result web_events(web *w, web_req *r, const store_job *j)
{
    const char *from = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, "Last-Event-ID");
    if (!from)
        from = MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, "after");
    uint64_t after = 0;
    if (from) {
        char *end;
        errno = 0;
        after = strtoull(from, &end, 10);
        if (errno || *end || end == from)
            return web_reply_error(r, MHD_HTTP_BAD_REQUEST, "Last-Event-ID or after: not a record number");
    }
    if (take(r->user))
        return web_reply_error(r, MHD_HTTP_SERVICE_UNAVAILABLE, "too many event streams open (%d in all, %d per "
                               "user): close one, or poll /api/v1/jobs/%llu/history", WEB_MAX_STREAMS,
                               WEB_MAX_STREAMS_PER_USER, (unsigned long long)j->id);
    stream *s = calloc(1, sizeof *s);
    if (!s) {
        give_back(r->user);
        return MHD_NO;
    }
    s->w = w;
    snprintf(s->who.user, sizeof s->who.user, "%s", r->user);
    s->who.admin = r->admin;
    s->id = j->id;
    s->after = after;
    s->generation = generation();
    s->sent_ms = now_ms();
    struct MHD_Response *res = MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 4096, reader, s, free_stream);
    if (!res) {
        free_stream(s);
        return MHD_NO;
    }
    MHD_add_response_header(res, MHD_HTTP_HEADER_CONTENT_TYPE, "text/event-stream");
    MHD_add_response_header(res, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    MHD_add_response_header(res, "X-Accel-Buffering", "no");
    enum MHD_Result rc = MHD_queue_response(r->conn, MHD_HTTP_OK, res);
    MHD_destroy_response(res);
    return rc;
}

/* The history's one reader: the stream and GET .../history share it. */
int64_t web_points(web *w, uint64_t id, uint64_t after, int max, FILE *fp, int sse)
{
    sqlite3 *db = web_db(w);
    sqlite3_stmt *st = NULL;
    if (!db || sqlite3_prepare_v2(db, "SELECT rowid, stage, outer_it, total,"
                                  " membrane0 + coalesce(membrane1, 0), bending0 + coalesce(bending1, 0),"
                                  " mismatch0 + coalesce(mismatch1, 0), reverse0 + coalesce(reverse1, 0),"
                                  " energy0 + coalesce(energy1, 0), beta, gamma, elapsed_s, fraction"
                                  " FROM history WHERE job = ? AND rowid > ? ORDER BY rowid LIMIT ?",
                                  -1, &st, NULL) != SQLITE_OK) {
        sqlite3_finalize(st);
        return -1;
    }
    sqlite3_bind_int64(st, 1, (sqlite3_int64)id);
    sqlite3_bind_int64(st, 2, (sqlite3_int64)after);
    sqlite3_bind_int(st, 3, max);
    static const char *const keys[] = {"membrane", "bending", "mismatch", "reverse", "energy", "beta", "gamma",
                                       "elapsed_s", "fraction"};
    int64_t next = (int64_t)after;
    int n = 0;
    while (sqlite3_step(st) == SQLITE_ROW) {
        next = sqlite3_column_int64(st, 0);
        int stage = sqlite3_column_int(st, 1);
        if (sse)
            fprintf(fp, "id: %lld\nevent: progress\ndata: ", (long long)next);
        else if (n)
            fputc(',', fp);
        n++;
        fprintf(fp, "{\"stage\":\"%s\",\"outer\":%d,\"total\":%d", proto_stage_name(stage),
                sqlite3_column_int(st, 2), sqlite3_column_int(st, 3));
        for (int k = 0; k < 9; k++) {
            fprintf(fp, ",\"%s\":", keys[k]);
            web_json_num(fp, sqlite3_column_type(st, 4 + k) == SQLITE_NULL ? NAN : sqlite3_column_double(st, 4 + k));
        }
        fputs(sse ? "}\n\n" : "}", fp);
    }
    sqlite3_finalize(st);
    return next;
}
