/* web.h — the web UI and the JSON API of the HTTP endpoint, shared by
 * http.c (which hands them requests) and the web files: web.c (logins,
 * sessions, pages, who may see what), web_api.c (/api/v1/), web_json.c
 * (JSON text), web_picture.c (a map's picture, drawn by the worker). Everything here runs on libmicrohttpd's thread(s) under the
 * web's one lock, and reads the daemon only through the published snapshot
 * and a read-only SQLite connection to the job store. */
#ifndef WEB_H
#define WEB_H
#include "mcd.h"

#include <microhttpd.h>
#include <sqlite3.h>
#include <stdio.h>

#define WEB_MAX_BODY 4096           /* bytes of a request body (a login form, a cancel) */
#define WEB_MAX_SESSIONS 1024       /* logged-in browsers in all; past it a login is refused (503) */
#define WEB_MAX_SESSIONS_PER_USER 32 /* of one user: a new login replaces that user's oldest */
#define WEB_SESSION_TTL_S (8 * 3600) /* a session ends this long after its login */
#define WEB_SESSION_ID_BYTES 32     /* getrandom bytes of a session id (hex in the cookie) */
#define WEB_CSRF_BYTES 16           /* of its CSRF token (the X-CSRF-Token header) */
#define WEB_MAX_LIST 500            /* jobs one /api/v1/jobs answer lists, newest first */
#define WEB_MAX_HISTORY 5000        /* progress records one history answer holds */
#define WEB_COOKIE "mc_session"

typedef struct web web;

/* One request, as http.c hands it over. */
typedef struct web_req {
    struct MHD_Connection *conn;
    const char *url, *method;
    const char *body;             /* NUL-terminated; body_len bytes */
    size_t body_len;
    char peer[SRV_MAX_PEER];      /* peer_name: logs and the login throttle */
    /* set by web_auth */
    char user[AUTH_MAX_USER];
    int admin;
    int by_session;               /* a browser's cookie (a change needs the CSRF token) */
    char csrf[2 * WEB_CSRF_BYTES + 1];
} web_req;

/* d is kept for what does not change while the server runs: the store's
 * paths and the backend's name. tls: cookies are Secure. NULL on no memory. */
web *web_new(mcd *d, int tls);
void web_free(web *w);            /* NULL ok */
void web_set_tokens(web *w, const auth_tokens *t);   /* takes the lock */
void web_lock(web *w);
void web_unlock(web *w);
/* web_route.c: answers r (the pages, /login, /logout, static assets and
 * /api/v1/) under the web's lock. */
enum MHD_Result web_handle(web *w, web_req *r);

/* Replies. Every one carries the Content-Security-Policy and no-cache
 * headers. body is freed by MHD when must_free. */
enum MHD_Result web_reply(web_req *r, unsigned status, const char *type, const void *body, size_t len,
                          int must_free);
enum MHD_Result web_reply_text(web_req *r, unsigned status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* {"error": message} with status. */
enum MHD_Result web_reply_error(web_req *r, unsigned status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* The text fp (an open_memstream of *buf, *len) holds, closed, as JSON. */
enum MHD_Result web_reply_json(web_req *r, unsigned status, FILE *fp, char **buf, size_t *len);

/* ---- web.c, for the router (web_route.c) ---- */
/* The embedded asset name (index.html, job.html, ...) with status; 404
 * for a name that is not one. */
enum MHD_Result web_page(web_req *r, unsigned status, const char *name);
/* The login form with msg above it (empty: none). */
enum MHD_Result web_login_page(web_req *r, unsigned status, const char *msg);
/* POST /login: a session for the form's token, or the form again with why. */
enum MHD_Result web_login(web *w, web_req *r);
/* POST /logout: the session ends (CSRF-checked). */
enum MHD_Result web_logout(web *w, web_req *r);

/* ---- web.c, for the API, the streams and the pictures ---- */
/* Logged in by a Bearer token or a session cookie: 0 with r->user and
 * r->admin set; else the reply already queued in *res (401, 429). */
int web_auth(web *w, web_req *r, enum MHD_Result *res);
/* The job store, read-only (opened on first use); NULL with a log line
 * when it cannot be opened. */
sqlite3 *web_db(web *w);
/* The latest published snapshot (a copy owned by w). */
const mcd_snapshot *web_snapshot(web *w);
const store *web_store(const web *w);
const char *web_backend(const web *w);
web_cancel *web_cancels(const web *w);   /* the loop's queue of cancels */
/* The job row of id when r's user may see it (theirs, or an admin):
 * 0, else PROTO_ENOT_FOUND (also for another user's job) or -1. */
int web_job(web *w, const web_req *r, uint64_t id, store_job *j, char *params, size_t psz);
/* The columns label, priority, state, reason, submit_ms, start_ms,
 * end_ms, params, total, outer_it, verdict, flipped, collapsed, fraction,
 * eta_s of a jobs row from column c on into j (params skipped). */
void web_job_row(sqlite3_stmt *st, int c, store_job *j);
/* 1 when r may make a change: by a Bearer token, or by a session with its
 * CSRF token in X-CSRF-Token. */
int web_csrf_ok(const web_req *r);
/* A job's stage name as the list shows it ("rhm", "queued", "" ended) and
 * its queue position (-1 when not queued or past SNAP_MAX_QUEUE). */
const char *web_job_stage(web *w, const store_job *j, int64_t *position);

/* ---- web_api.c ---- */
/* path is r->url after "/api/v1". */
enum MHD_Result web_api(web *w, web_req *r, const char *path);

/* ---- web_events.c ---- */
#define WEB_MAX_STREAMS 32          /* event streams open at once, all users */
#define WEB_MAX_STREAMS_PER_USER 4  /* of one user; past either cap a new one is refused (503) */
#define WEB_STREAM_POLL_MS 250      /* how often a stream looks for new records */
#define WEB_STREAM_KEEPALIVE_S 5    /* a comment line at least this often (the idle timeout is longer) */
/* GET /api/v1/jobs/ID/events of a job r may see: its progress records as
 * server-sent events, from Last-Event-ID (or ?after=) on, then `event:
 * end` with its final state once it has ended. */
enum MHD_Result web_events(web *w, web_req *r, const store_job *j);
/* The streams of the MHD daemon that is being replaced (a TLS reload) end,
 * so that its stop does not wait for them (EventSource reconnects). */
void web_streams_end(web *w);
/* Job id's progress records after record `after`, at most max, written to
 * fp: as the elements of a JSON array (comma-separated), or with sse as
 * server-sent events (`id: RECORD`, `event: progress`, `data: {...}`). The
 * last record's number (after when there was none), or -1 when the store
 * cannot be read. */
int64_t web_points(web *w, uint64_t id, uint64_t after, int max, FILE *fp, int sse);

/* ---- web_picture.c ---- */
/* At start: the worker program and the limits a drawing runs with. */
void web_picture_init(const mcd *d);
/* GET /api/v1/jobs/ID/picture of a job r may see: the PNG, or 503 with
 * Retry-After while it is being drawn. */
enum MHD_Result web_picture(web *w, web_req *r, const store_job *j);

/* ---- web_json.c ---- */
/* s as a JSON string, quotes included: control characters and what
 * stresc escapes become \u escapes, bytes that are not UTF-8 their
 * Latin-1 code points. */
void web_json_str(FILE *fp, const char *s);
/* v as a JSON number; NaN and infinities as null. */
void web_json_num(FILE *fp, double v);

#endif
