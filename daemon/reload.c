/* reload.c — SIGHUP: the command line is parsed again (so --config files are
 * read again, later options still winning), the reloadable options take
 * effect and the tokens file is read again. A config that no longer parses,
 * or a tokens file that does not load, keeps the old one and logs why;
 * options that need a restart (listeners, state dir, dashboards, and what
 * the backend says it sets up once: its slots above all) keep their running
 * values with a warning naming them. Opens no sockets, touches no
 * job. */
#include "backend.h"

#include <signal.h>
#include <string.h>

/* Puts back the running values of what takes effect at the next start
 * only, asking the backend for its own, and warns naming what changed. */
static void keep_restart_only(mcd *d, mcd_conf *n)
{
    char changed[512];
    bk_keep_on_reload(d, n, changed, sizeof changed);
    int listen_changed = n->nlisten != d->conf.nlisten;
    for (int i = 0; !listen_changed && i < n->nlisten; i++)
        listen_changed = strcmp(n->listen[i], d->conf.listen[i]) != 0;
    bk_note_change(listen_changed, "listen", changed, sizeof changed);
    bk_note_change(strcmp(n->state_dir, d->conf.state_dir) != 0, "state-dir", changed, sizeof changed);
    bk_note_change(strcmp(n->port_file, d->conf.port_file) != 0, "port-file", changed, sizeof changed);
    bk_note_change(n->modbus.port != d->conf.modbus.port || strcmp(n->modbus.host, d->conf.modbus.host),
                   "modbus", changed, sizeof changed);
    bk_note_change(n->metrics.port != d->conf.metrics.port || strcmp(n->metrics.host, d->conf.metrics.host),
                   "metrics", changed, sizeof changed);
    if (changed[0])
        dlog(DLOG_WARN, "reload: %s changed but take(s) effect at the next start only: keeping the running"
                        " value(s)", changed);
    memcpy(n->listen, d->conf.listen, sizeof n->listen);
    n->nlisten = d->conf.nlisten;
    memcpy(n->state_dir, d->conf.state_dir, sizeof n->state_dir);
    memcpy(n->port_file, d->conf.port_file, sizeof n->port_file);
    n->modbus = d->conf.modbus;
    n->metrics = d->conf.metrics;
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
    }
    auth_tokens *t = NULL;
    if (auth_tokens_load(d->conf.tokens, &t, err, sizeof err) != 0) {
        dlog(DLOG_ERROR, "reload: %s: keeping the previous tokens", err);
    } else {
        auth_tokens_free(d->tokens);
        d->tokens = t;
        dlog(DLOG_INFO, "reload: tokens read from %s", d->conf.tokens[0] ? d->conf.tokens : "(none)");
    }
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
