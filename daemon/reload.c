/* reload.c — SIGHUP: the command line is parsed again (so --config files are
 * read again, later options still winning), the reloadable options take
 * effect and the tokens file is read again, as are the TLS certificate and
 * key (tls.c). A config that no longer parses, a tokens file or a
 * certificate that does not load, keeps the old one and logs why;
 * options that need a restart (listeners, state dir, dashboards, and what
 * the backend says it sets up once: its slots above all) keep their running
 * values with a warning naming them. Then every session is checked against
 * what now holds: one whose token is gone, or now names another user or
 * another admin flag, or a Unix-socket session whose admin flag changed
 * with --admin-uid, is ended (ERROR UNAUTHORIZED, a log line). Opens no
 * sockets, touches no job. */
#include "backend.h"

#include <signal.h>
#include <string.h>

/* Puts back the running values of what takes effect at the next start
 * only, asking each subsystem that sets something up once, and warns naming
 * what changed. */
static void keep_restart_only(mcd *d, mcd_conf *n)
{
    static void (*const keep[])(const mcd_conf *o, mcd_conf *n, char *changed, size_t sz) = {
        srv_keep_on_reload, store_keep_on_reload, dash_keep_on_reload, tls_keep_on_reload,
        priv_keep_on_reload,
    };
    char changed[512] = "";
    for (size_t i = 0; i < sizeof keep / sizeof keep[0]; i++)
        keep[i](&d->conf, n, changed, sizeof changed);
    bk_keep_on_reload(d, n, changed, sizeof changed);
    if (changed[0])
        dlog(DLOG_WARN, "reload: %s changed but take(s) effect at the next start only: keeping the running"
                        " value(s)", changed);
}

/* Ends c's session when what it logged in with no longer gives it the same
 * user and admin flag. */
static void recheck_session(conn *c, void *ctx)
{
    mcd *d = ctx;
    conn_auth *a = srv_conn_auth(c);
    char user[AUTH_MAX_USER], why[AUTH_MAX_USER + 128] = "", err[256];
    int admin;
    if (a->by_token) {
        if (auth_token_user(d->tokens, a->token_hash, user, &admin) != 0)
            snprintf(why, sizeof why, "your token was revoked (reload of the tokens file); this session ends");
        else if (strcmp(user, a->user) != 0)
            snprintf(why, sizeof why, "your token now names user %s; this session ends: log in again", user);
        else if (admin != a->admin)
            snprintf(why, sizeof why, "your token %s admin; this session ends: log in again",
                     admin ? "is now" : "is no longer");
    } else if (a->is_unix && auth_peer_user(srv_conn_fd(c), d->conf.admin_uid, user, &admin, err, sizeof err) == 0 &&
               admin != a->admin) {
        snprintf(why, sizeof why, "your uid %s admin (--admin-uid); this session ends: log in again",
                 admin ? "is now" : "is no longer");
    }
    if (why[0])
        srv_end_session(c, PROTO_EUNAUTHORIZED, why);
}

static void on_sighup(uv_signal_t *h, int sig)
{
    (void)sig;
    mcd *d = h->data;
    if (d->draining)
        return;
    notify_reloading();
    static mcd_conf n;            /* large (paths); the loop is single-threaded */
    char err[1024];
    conf_init(&n);
    if (conf_parse_args(&n, d->argc, d->argv, err, sizeof err) != 0) {
        dlog(DLOG_ERROR, "reload: %s: keeping the running options", err);
    } else {
        keep_restart_only(d, &n);
        d->conf = n;
        dlog_set_level(d->conf.log_level);
        job_sweep_start(d);   /* result-ttl may have changed: sweep now, then at its period */
        dlog(DLOG_INFO, "reload: options applied");
        if (tls_reload(d) && d->http && http_set_tls(d->http, d->tls, err, sizeof err) != 0)
            dlog(DLOG_ERROR, "reload: %s: --http keeps the running certificate", err);
    }
    auth_tokens *t = NULL;
    if (auth_tokens_load(d->conf.tokens, &t, err, sizeof err) != 0) {
        dlog(DLOG_ERROR, "reload: %s: keeping the previous tokens", err);
    } else {
        auth_tokens *old = d->tokens;
        d->tokens = t;
        http_set_tokens(d->http, t);      /* the web's logins stop reading the old table */
        auth_tokens_free(old);
        dlog(DLOG_INFO, "reload: tokens read from %s", auth_tokens_path(t)[0] ? auth_tokens_path(t) : "(none)");
        srv_note_tokens(d);
    }
    srv_each_session(d, recheck_session, d);
    notify_reloaded();
}

void reload_init(mcd *d, int argc, char **argv)
{
    d->argc = argc;
    d->argv = argv;
    uv_signal_init(d->loop, &d->sighup);
    d->sighup.data = d;
    uv_signal_start(&d->sighup, on_sighup, SIGHUP);
}

void reload_close(mcd *d)
{
    uv_close((uv_handle_t *)&d->sighup, NULL);
}
