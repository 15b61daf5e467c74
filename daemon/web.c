/* web.c — the web UI of the HTTP endpoint: the login page and its session
 * cookie, logout, the pages (/, /jobs/ID, /workers: HTML shells whose small
 * scripts read /api/v1/), the static assets embedded in the binary (a C
 * array generated from daemon/web/ at build time), and the rule of who sees
 * what: a user sees their own jobs, an admin everyone's; another user's job
 * is answered 404, as one that does not exist.
 *
 * Logins take the tokens of the protocol (the tokens file, hashed): a form
 * with one password field `token`, or `Authorization: Bearer TOKEN` for the
 * API. A failed one is counted by the same per-address throttle as a failed
 * HELLO (throttle.c) and logged with the peer's address; while an address
 * waits its logins are refused unchecked (429). A browser session is a
 * random id (getrandom) in an HttpOnly, SameSite=Strict cookie (Secure under
 * TLS) that expires after WEB_SESSION_TTL_S; the table is capped
 * (WEB_MAX_SESSIONS, WEB_MAX_SESSIONS_PER_USER). A session keeps its
 * token's hash, not the user: every request looks the hash up in the tokens
 * as they are now, so a token revoked by a reload ends its sessions. A
 * change made with a cookie (cancel, logout) must carry the session's CSRF
 * token in X-CSRF-Token.
 *
 * DESIGN: MHD runs this on its own thread, never the loop's: the figures
 * come from the published snapshot and the jobs from a read-only SQLite
 * connection (the store is in WAL mode, so reading never blocks the loop's
 * writes); a cancel is handed to the loop (web_cancel.c). One lock (mu)
 * serialises the requests (two MHD threads run at once for a moment while a
 * TLS reload hands the socket over) and the tokens' swap on a reload. */
#include "web.h"
#include "util/errbuf.h"

#include <errno.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>

struct web_asset {
    const char *name;
    const unsigned char *data;
    size_t len;
};
#include "web_assets.h"

typedef struct session {
    char id[2 * WEB_SESSION_ID_BYTES + 1];   /* "" = free */
    char csrf[2 * WEB_CSRF_BYTES + 1];
    uint8_t token_hash[AUTH_HASH_LEN];
    char user[AUTH_MAX_USER];                /* at login, for the per-user cap */
    int64_t login_ms, expires_ms;
} session;

struct web {
    pthread_mutex_t mu;
    const auth_tokens *tokens;    /* the loop's table; swapped under mu (web_set_tokens) */
    const store *store;           /* spool paths only (store_result_read) */
    char db_path[CONF_PATH + 16];
    sqlite3 *db;                  /* read-only, opened on first use */
    snap *snap;
    mcd_snapshot *copy;
    char backend[CONF_PATH];
    web_cancel *cancels;          /* d->web_cancel: cancels go to the loop through it */
    int tls;
    session sessions[WEB_MAX_SESSIONS];
};

static const char csp[] = "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self'; "
                          "connect-src 'self'; form-action 'self'; frame-ancestors 'none'; base-uri 'none'";

web *web_new(mcd *d, int tls)
{
    web *w = calloc(1, sizeof *w);
    if (!w || !(w->copy = snap_alloc(snap_nslots(d->snap)))) {
        free(w);
        return NULL;
    }
    pthread_mutex_init(&w->mu, NULL);
    w->store = d->store;
    w->snap = d->snap;
    w->tls = tls;
    w->cancels = d->web_cancel;
    snprintf(w->db_path, sizeof w->db_path, "%s/jobs.db", d->conf.state_dir);
    snprintf(w->backend, sizeof w->backend, "%s", d->conf.backend);
    return w;
}

void web_free(web *w)
{
    if (!w)
        return;
    sqlite3_close(w->db);
    snap_release(w->copy);
    pthread_mutex_destroy(&w->mu);
    explicit_bzero(w->sessions, sizeof w->sessions);
    free(w);
}

void web_lock(web *w)
{
    pthread_mutex_lock(&w->mu);
}

void web_unlock(web *w)
{
    pthread_mutex_unlock(&w->mu);
}

void web_set_tokens(web *w, const auth_tokens *t)
{
    web_lock(w);
    w->tokens = t;
    web_unlock(w);
}

sqlite3 *web_db(web *w)
{
    if (w->db)
        return w->db;
    if (sqlite3_open_v2(w->db_path, &w->db, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, NULL) != SQLITE_OK) {
        dlog(DLOG_ERROR, "http: cannot open %s read-only: %s", w->db_path, sqlite3_errmsg(w->db));
        sqlite3_close(w->db);
        w->db = NULL;
        return NULL;
    }
    sqlite3_busy_timeout(w->db, 1000);
    return w->db;
}

const mcd_snapshot *web_snapshot(web *w)
{
    snap_read(w->snap, w->copy);
    return w->copy;
}

const store *web_store(const web *w)
{
    return w->store;
}

const char *web_backend(const web *w)
{
    return w->backend;
}

web_cancel *web_cancels(const web *w)
{
    return w->cancels;
}

/* ---- replies ---- */

enum MHD_Result web_reply(web_req *r, unsigned status, const char *type, const void *body, size_t len,
                          int must_free)
{
    struct MHD_Response *res = MHD_create_response_from_buffer(
        len, (void *)body, must_free ? MHD_RESPMEM_MUST_FREE : MHD_RESPMEM_PERSISTENT);
    if (!res) {
        if (must_free)
            free((void *)body);
        return MHD_NO;
    }
    MHD_add_response_header(res, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    MHD_add_response_header(res, "Content-Security-Policy", csp);
    MHD_add_response_header(res, "X-Content-Type-Options", "nosniff");
    MHD_add_response_header(res, "Referrer-Policy", "no-referrer");
    MHD_add_response_header(res, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    if (status == MHD_HTTP_METHOD_NOT_ALLOWED)
        MHD_add_response_header(res, MHD_HTTP_HEADER_ALLOW, strncmp(r->url, "/api/", 5) ? "GET" : "GET, POST");
    if (status == MHD_HTTP_UNAUTHORIZED && !strncmp(r->url, "/api/", 5))
        MHD_add_response_header(res, MHD_HTTP_HEADER_WWW_AUTHENTICATE, "Bearer realm=\"meshcorr\"");
    enum MHD_Result rc = MHD_queue_response(r->conn, status, res);
    MHD_destroy_response(res);
    return rc;
}

static enum MHD_Result reply_vtext(web_req *r, unsigned status, const char *type, const char *fmt, va_list ap)
{
    char *buf = NULL;
    int n = vasprintf(&buf, fmt, ap);
    if (n < 0)
        return MHD_NO;
    return web_reply(r, status, type, buf, (size_t)n, 1);
}

enum MHD_Result web_reply_text(web_req *r, unsigned status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    enum MHD_Result rc = reply_vtext(r, status, "text/plain; charset=utf-8", fmt, ap);
    va_end(ap);
    return rc;
}

enum MHD_Result web_reply_error(web_req *r, unsigned status, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    char *buf = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&buf, &len);
    if (!fp)
        return MHD_NO;
    fputs("{\"error\":", fp);
    web_json_str(fp, msg);
    fputs("}\n", fp);
    return web_reply_json(r, status, fp, &buf, &len);
}

enum MHD_Result web_reply_json(web_req *r, unsigned status, FILE *fp, char **buf, size_t *len)
{
    if (fclose(fp) != 0) {
        free(*buf);
        return MHD_NO;
    }
    return web_reply(r, status, "application/json", *buf, *len, 1);
}

/* 303 to where, with the cookie header when cookie is not NULL. */
static enum MHD_Result redirect(web_req *r, const char *where, const char *cookie)
{
    struct MHD_Response *res = MHD_create_response_from_buffer(0, (void *)"", MHD_RESPMEM_PERSISTENT);
    if (!res)
        return MHD_NO;
    MHD_add_response_header(res, MHD_HTTP_HEADER_LOCATION, where);
    MHD_add_response_header(res, "Content-Security-Policy", csp);
    MHD_add_response_header(res, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    if (cookie)
        MHD_add_response_header(res, MHD_HTTP_HEADER_SET_COOKIE, cookie);
    enum MHD_Result rc = MHD_queue_response(r->conn, MHD_HTTP_SEE_OTHER, res);
    MHD_destroy_response(res);
    return rc;
}

/* ---- sessions ---- */

static void hex(const uint8_t *b, size_t n, char *out)
{
    static const char digits[] = "0123456789abcdef";
    for (size_t i = 0; i < n; i++) {
        out[2 * i] = digits[b[i] >> 4];
        out[2 * i + 1] = digits[b[i] & 15];
    }
    out[2 * n] = '\0';
}

static int random_hex(size_t n, char *out)
{
    uint8_t b[64];
    size_t got = 0;
    while (got < n) {
        ssize_t k = getrandom(b + got, n - got, 0);
        if (k < 0 && errno != EINTR)
            return -1;
        got += k > 0 ? (size_t)k : 0;
    }
    hex(b, n, out);
    explicit_bzero(b, sizeof b);
    return 0;
}

/* Equal strings, in a time that does not depend on where they differ. */
static int same_secret(const char *a, const char *b)
{
    size_t na = strlen(a), nb = strlen(b);
    unsigned char diff = na != nb;
    for (size_t i = 0; i < na && i < nb; i++)
        diff |= (unsigned char)(a[i] ^ b[i]);
    return diff == 0;
}

static void drop_expired(web *w, int64_t now)
{
    for (int i = 0; i < WEB_MAX_SESSIONS; i++)
        if (w->sessions[i].id[0] && w->sessions[i].expires_ms <= now)
            explicit_bzero(&w->sessions[i], sizeof w->sessions[i]);
}

/* A new session of user: the free entry (or that user's oldest when they
 * have WEB_MAX_SESSIONS_PER_USER), NULL when the table is full. */
static session *session_new(web *w, const char *user, const uint8_t hash[AUTH_HASH_LEN], int64_t now)
{
    drop_expired(w, now);
    session *free_one = NULL, *oldest = NULL;
    int mine = 0;
    for (int i = 0; i < WEB_MAX_SESSIONS; i++) {
        session *s = &w->sessions[i];
        if (!s->id[0]) {
            if (!free_one)
                free_one = s;
        } else if (!strcmp(s->user, user)) {
            mine++;
            if (!oldest || s->login_ms < oldest->login_ms)
                oldest = s;
        }
    }
    session *s = mine >= WEB_MAX_SESSIONS_PER_USER ? oldest : free_one;
    if (!s)
        return NULL;
    memset(s, 0, sizeof *s);
    if (random_hex(WEB_SESSION_ID_BYTES, s->id) || random_hex(WEB_CSRF_BYTES, s->csrf)) {
        memset(s, 0, sizeof *s);
        return NULL;
    }
    memcpy(s->token_hash, hash, AUTH_HASH_LEN);
    snprintf(s->user, sizeof s->user, "%s", user);
    s->login_ms = now;
    s->expires_ms = now + 1000ll * WEB_SESSION_TTL_S;
    return s;
}

static session *session_of(web *w, web_req *r, int64_t now)
{
    const char *id = MHD_lookup_connection_value(r->conn, MHD_COOKIE_KIND, WEB_COOKIE);
    if (!id || strlen(id) != 2 * WEB_SESSION_ID_BYTES)
        return NULL;
    drop_expired(w, now);
    for (int i = 0; i < WEB_MAX_SESSIONS; i++)
        if (w->sessions[i].id[0] && same_secret(w->sessions[i].id, id))
            return &w->sessions[i];
    return NULL;
}

/* The token in text checked: 0 with user/admin and its hash; else why in
 * err, counted by the throttle and logged. *wait: the seconds the address
 * must wait (nothing was checked). */
static int login(web *w, web_req *r, const char *token, uint8_t hash[AUTH_HASH_LEN], uint32_t *wait)
{
    uint64_t now = uv_hrtime() / 1000000;
    *wait = throttle_check(r->peer, now);
    if (*wait)
        return -1;
    int rc = auth_token_hash(token, hash);
    if (rc == 0 && w->tokens)
        rc = auth_token_user(w->tokens, hash, r->user, &r->admin);
    else
        rc = -1;
    if (rc) {
        /* throttle_fail logs it with the address (a burst summed up) */
        throttle_fail(r->peer, "web", token[0] ? "unknown token" : "no token", now);
    }
    return rc;
}

int web_auth(web *w, web_req *r, enum MHD_Result *res)
{
    int64_t now = store_now_ms();
    const char *authz = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_AUTHORIZATION);
    if (authz && !strncmp(authz, "Bearer ", 7)) {
        uint8_t hash[AUTH_HASH_LEN];
        uint32_t wait;
        if (login(w, r, authz + 7, hash, &wait) == 0)
            return 0;
        *res = wait ? web_reply_error(r, MHD_HTTP_TOO_MANY_REQUESTS, "too many failed logins from %s: retry in %u s",
                                      r->peer, wait)
                    : web_reply_error(r, MHD_HTTP_UNAUTHORIZED, "unknown token");
        return -1;
    }
    session *s = session_of(w, r, now);
    if (s && w->tokens && auth_token_user(w->tokens, s->token_hash, r->user, &r->admin) == 0) {
        r->by_session = 1;
        snprintf(r->csrf, sizeof r->csrf, "%s", s->csrf);
        return 0;
    }
    if (s)                        /* its token was revoked: the session ends */
        explicit_bzero(s, sizeof *s);
    if (!strncmp(r->url, "/api/", 5))
        *res = web_reply_error(r, MHD_HTTP_UNAUTHORIZED, "log in: Authorization: Bearer TOKEN, or a session");
    else
        *res = redirect(r, "/login", NULL);
    return -1;
}

/* ---- pages ---- */

static const struct web_asset *asset(const char *name)
{
    for (size_t i = 0; i < sizeof web__assets / sizeof web__assets[0]; i++)
        if (!strcmp(web__assets[i].name, name))
            return &web__assets[i];
    return NULL;
}

static const char *type_of(const char *name)
{
    const char *dot = strrchr(name, '.');
    if (dot && !strcmp(dot, ".css"))
        return "text/css; charset=utf-8";
    if (dot && !strcmp(dot, ".js"))
        return "text/javascript; charset=utf-8";
    return "text/html; charset=utf-8";
}

enum MHD_Result web_page(web_req *r, unsigned status, const char *name)
{
    const struct web_asset *a = asset(name);
    if (!a)
        return web_reply_text(r, MHD_HTTP_NOT_FOUND, "not found\n");
    return web_reply(r, status, type_of(name), a->data, a->len, 0);
}

/* The login page with msg (plain text, escaped for HTML) where it has its
 * <!--msg--> mark. */
enum MHD_Result web_login_page(web_req *r, unsigned status, const char *msg)
{
    const struct web_asset *a = asset("login.html");
    const char *mark = "<!--msg-->";
    const char *at = a ? memmem(a->data, a->len, mark, strlen(mark)) : NULL;
    if (!at)
        return web_reply_text(r, MHD_HTTP_INTERNAL_SERVER_ERROR, "login page missing\n");
    char *buf = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&buf, &len);
    if (!fp)
        return MHD_NO;
    fwrite(a->data, 1, (size_t)(at - (const char *)a->data), fp);
    if (msg[0]) {
        fputs("<p class=\"error\" id=\"msg\">", fp);
        for (const char *p = msg; *p; p++)
            if (*p == '<')
                fputs("&lt;", fp);
            else if (*p == '>')
                fputs("&gt;", fp);
            else if (*p == '&')
                fputs("&amp;", fp);
            else
                fputc(*p, fp);
        fputs("</p>", fp);
    }
    const char *rest = at + strlen(mark);   /* the asset has no terminating NUL */
    fwrite(rest, 1, a->len - (size_t)(rest - (const char *)a->data), fp);
    if (fclose(fp) != 0) {
        free(buf);
        return MHD_NO;
    }
    return web_reply(r, status, "text/html; charset=utf-8", buf, len, 1);
}

/* The value of field name in an application/x-www-form-urlencoded body,
 * decoded into out; 0, or -1 when absent or too long. */
static int form_field(const char *body, const char *name, char *out, size_t sz)
{
    size_t nl = strlen(name);
    for (const char *p = body; p && *p; p = strchr(p, '&') ? strchr(p, '&') + 1 : NULL) {
        if (strncmp(p, name, nl) || p[nl] != '=')
            continue;
        const char *v = p + nl + 1, *end = strchr(v, '&');
        size_t n = end ? (size_t)(end - v) : strlen(v);
        if (n >= sz)
            return -1;
        memcpy(out, v, n);
        out[n] = '\0';
        for (char *c = out; *c; c++)
            if (*c == '+')
                *c = ' ';
        MHD_http_unescape(out);
        return 0;
    }
    return -1;
}

enum MHD_Result web_login(web *w, web_req *r)
{
    char token[AUTH_MAX_LINE + 1];
    if (form_field(r->body, "token", token, sizeof token))
        token[0] = '\0';
    uint8_t hash[AUTH_HASH_LEN];
    uint32_t wait;
    int rc = login(w, r, token, hash, &wait);
    explicit_bzero(token, sizeof token);
    if (wait) {
        char msg[128];
        snprintf(msg, sizeof msg, "Too many failed logins from %s: retry in %u s.", r->peer, wait);
        return web_login_page(r, MHD_HTTP_TOO_MANY_REQUESTS, msg);
    }
    if (rc)
        return web_login_page(r, MHD_HTTP_UNAUTHORIZED, "Unknown token.");
    session *s = session_new(w, r->user, hash, store_now_ms());
    if (!s) {
        dlog(DLOG_WARN, "web login of %s from %s refused: %d sessions open", r->user, r->peer, WEB_MAX_SESSIONS);
        return web_login_page(r, MHD_HTTP_SERVICE_UNAVAILABLE, "Too many sessions open: try again later.");
    }
    dlog(DLOG_INFO, "web login: %s%s from %s", r->user, r->admin ? " (admin)" : "", r->peer);
    char cookie[256];
    snprintf(cookie, sizeof cookie, WEB_COOKIE "=%s; Path=/; Max-Age=%d; HttpOnly; SameSite=Strict%s", s->id,
             WEB_SESSION_TTL_S, w->tls ? "; Secure" : "");
    return redirect(r, "/", cookie);
}

int web_csrf_ok(const web_req *r)
{
    if (!r->by_session)
        return 1;
    const char *t = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, "X-CSRF-Token");
    return t && same_secret(t, r->csrf);
}

enum MHD_Result web_logout(web *w, web_req *r)
{
    enum MHD_Result res;
    if (web_auth(w, r, &res))
        return res;
    if (!r->by_session)
        return web_reply_error(r, MHD_HTTP_BAD_REQUEST, "no session to end");
    if (!web_csrf_ok(r))
        return web_reply_error(r, MHD_HTTP_FORBIDDEN, "missing or wrong X-CSRF-Token");
    session *s = session_of(w, r, store_now_ms());
    if (s)
        explicit_bzero(s, sizeof *s);
    dlog(DLOG_INFO, "web logout: %s from %s", r->user, r->peer);
    return redirect(r, "/login",
                    w->tls ? WEB_COOKIE "=; Path=/; Max-Age=0; HttpOnly; SameSite=Strict; Secure"
                           : WEB_COOKIE "=; Path=/; Max-Age=0; HttpOnly; SameSite=Strict");
}

/* ---- jobs as the pages and the API show them ---- */

static double col_real(sqlite3_stmt *st, int i)
{
    return sqlite3_column_type(st, i) == SQLITE_NULL ? NAN : sqlite3_column_double(st, i);
}

void web_job_row(sqlite3_stmt *st, int c, store_job *j)
{
    snprintf(j->label, sizeof j->label, "%s", (const char *)sqlite3_column_text(st, c));
    j->priority = sqlite3_column_int(st, c + 1);
    j->state = store_state_of((const char *)sqlite3_column_text(st, c + 2));
    snprintf(j->reason, sizeof j->reason, "%s", (const char *)sqlite3_column_text(st, c + 3));
    j->submit_ms = sqlite3_column_int64(st, c + 4);
    j->start_ms = sqlite3_column_int64(st, c + 5);
    j->end_ms = sqlite3_column_int64(st, c + 6);
    j->total = (uint32_t)sqlite3_column_int64(st, c + 8);
    j->outer = (uint32_t)sqlite3_column_int64(st, c + 9);
    j->verdict = sqlite3_column_int(st, c + 10);
    j->flipped = col_real(st, c + 11);
    j->collapsed = col_real(st, c + 12);
    j->fraction = col_real(st, c + 13);
    j->eta_s = col_real(st, c + 14);
}

int web_job(web *w, const web_req *r, uint64_t id, store_job *j, char *params, size_t psz)
{
    sqlite3 *db = web_db(w);
    sqlite3_stmt *st = NULL;
    if (!db || sqlite3_prepare_v2(db, "SELECT user, label, priority, state, reason, submit_ms, start_ms, end_ms,"
                                  " params, total, outer_it, verdict, flipped, collapsed, fraction, eta_s"
                                  " FROM jobs WHERE id = ?", -1, &st, NULL) != SQLITE_OK) {
        sqlite3_finalize(st);
        return -1;
    }
    sqlite3_bind_int64(st, 1, (sqlite3_int64)id);
    int rc = sqlite3_step(st);
    if (rc != SQLITE_ROW) {
        sqlite3_finalize(st);
        return rc == SQLITE_DONE ? PROTO_ENOT_FOUND : -1;
    }
    memset(j, 0, sizeof *j);
    j->id = id;
    snprintf(j->user, sizeof j->user, "%s", (const char *)sqlite3_column_text(st, 0));
    if (!r->admin && strcmp(j->user, r->user)) {
        sqlite3_finalize(st);
        return PROTO_ENOT_FOUND;
    }
    web_job_row(st, 1, j);
    if (params)
        snprintf(params, psz, "%s", (const char *)sqlite3_column_text(st, 8));
    sqlite3_finalize(st);
    return 0;
}

const char *web_job_stage(web *w, const store_job *j, int64_t *position)
{
    *position = -1;
    const mcd_snapshot *s = w->copy;      /* the copy web_snapshot took for this request */
    if (j->state == PROTO_STATE_PENDING) {
        for (uint32_t i = 0; i < s->nqueue; i++)
            if (s->queue[i] == j->id)
                *position = i;
        return "queued";
    }
    if (j->state != PROTO_STATE_RUNNING)
        return "";
    for (uint32_t i = 0; i < s->nslots; i++)
        if (s->slots[i].job_id == j->id)
            return s->slots[i].has_progress ? proto_stage_name(s->slots[i].stage) : "start";
    return "start";
}
