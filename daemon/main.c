/* main.c — meshcorrd's main(): options, store recovery, the scheduler's
 * queue rebuilt from the store, the job bookkeeping (job.c, its expiry
 * sweep included), the backend (backend.h), listeners, the drop from root
 * to --user (priv.c: the store and the backend are set up as that user,
 * the listeners bound as root, then root is gone), the signal handlers
 * (SIGTERM/SIGINT: drain.c; SIGHUP: reload.c), READY=1 to the service
 * manager, then the loop; or `meshcorrd token ...` (token.c) alone. The loop ends once the drain has closed every
 * handle; only then the store closes (no store_submit can be running) and
 * the dashboard threads (--modbus, --http) stop. Holds no request, job or
 * shutdown logic. */
#include "backend.h"
#include "mcd.h"
#include "util/ompenv.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int queue_pending(void *ctx, const store_job *j)
{
    mcd *d = ctx;
    if (sched_add(d->sched, j->id, j->user, j->priority)) {
        dlog(DLOG_ERROR, "out of memory rebuilding the queue");
        return 1;
    }
    return 0;
}

static void on_signal(uv_signal_t *h, int sig)
{
    drain_start(h->data, sig);
}

/* --version, the options into d->conf and the log level: -1 to go on,
 * else the exit status (--version, --help, a usage error). */
static int parse_command_line(mcd *d, int argc, char **argv)
{
    char err[1024];
    if (argc == 2 && strcmp(argv[1], "--version") == 0) {
        printf("meshcorrd %s\n", MC_VERSION);
        return 0;
    }
    conf_init(&d->conf);
    int rc = conf_parse_args(&d->conf, argc, argv, err, sizeof err);
    if (rc == 1) {
        conf_usage(stdout);
        return 0;
    }
    if (rc) {
        fprintf(stderr, "meshcorrd: %s\n", err);
        conf_usage(stderr);
        return 2;
    }
    dlog_set_level(d->conf.log_level);
    return -1;
}

/* SIGTERM and SIGINT start the drain. Set before the port file and the
 * sockets exist: a SIGTERM sent as soon as they do is a drain once the loop
 * runs, never the default death. */
static void signals_start(mcd *d)
{
    uv_signal_init(d->loop, &d->sigterm);
    uv_signal_init(d->loop, &d->sigint);
    d->sigterm.data = d->sigint.data = d;
    uv_signal_start(&d->sigterm, on_signal, SIGTERM);
    uv_signal_start(&d->sigint, on_signal, SIGINT);
}

/* Closes and frees all that main set up; after a start-up failure
 * (status non-zero) the handles a drain would have closed too. */
static void close_all(mcd *d, int status)
{
    if (status) {
        /* a start-up failure: close whatever was opened */
        if (uv_is_active((uv_handle_t *)&d->sigterm)) {
            uv_close((uv_handle_t *)&d->sigterm, NULL);
            uv_close((uv_handle_t *)&d->sigint, NULL);
        }
        srv_stop_listening(d);
        bk_close(d);
        job_close(d);
        snap_close(d);
        web_cancel_close(d);
        uv_run(d->loop, UV_RUN_NOWAIT);
    }
    mbus_stop(d->mbus);
    http_stop(d->http);
    hook_stop();
    tls_close(d);
    snap_free(d->snap);
    uv_loop_close(d->loop);
    web_cancel_free(d->web_cancel);
    store_close(d->store);
    sched_free(d->sched);
    auth_tokens_free(d->tokens);
    free(d->slots);
    free(d->listeners);
}

int main(int argc, char **argv)
{
    static mcd d;
    char err[1024];
    if (argc > 1 && strcmp(argv[1], "token") == 0)
        return token_main(argc - 1, argv + 1);
    int status = parse_command_line(&d, argc, argv);
    if (status >= 0)
        return status;
    priv_user priv;
    if (priv_init(&d.conf, &priv, err, sizeof err)) {
        dlog(DLOG_ERROR, "%s", err);
        return 2;
    }
    signal(SIGPIPE, SIG_IGN);
    /* The workers we spawn inherit it and skip their re-exec: one program load
     * less per job. */
    ompenv_set_passive();
    char vbuf[CONF_PATH + 64];
    const char *validator = conf_validator_path(&d.conf, vbuf, sizeof vbuf);
    if (access(validator, X_OK) != 0)
        dlog(DLOG_WARN, "validator program %s is not executable: every SUBMIT is refused until it is",
             validator);
    status = 1;
    d.loop = uv_default_loop();
    /* the tokens file is read as the user the daemon runs as: SIGHUP reads it again as that user */
    if (priv_become(&priv, d.conf.state_dir, err, sizeof err) ||
        auth_tokens_load(d.conf.tokens, &d.tokens, err, sizeof err) ||
        store_open(d.conf.state_dir, &d.store, err, sizeof err) ||
        job_recover(d.store, strcmp(d.conf.backend, "slurm") == 0, err, sizeof err)) {
        dlog(DLOG_ERROR, "%s", err);
        goto done;
    }
    if (!(d.sched = sched_new()) || store_each_pending(d.store, queue_pending, &d)) {
        dlog(DLOG_ERROR, "cannot rebuild the queue from the store");
        goto done;
    }
    job_init(&d);
    req_init(&d);
    if (web_cancel_init(&d) || hook_start(&d)) {
        dlog(DLOG_ERROR, "out of memory");
        goto done;
    }
    signals_start(&d);
    /* the TLS key is read while root is still at hand, with the binds */
    if (bk_init(&d, err, sizeof err) || snap_init(&d, err, sizeof err) ||
        priv_bind_begin(&priv, err, sizeof err) || tls_init(&d, err, sizeof err) || srv_listen(&d, err, sizeof err) ||
        (d.conf.modbus.port > 0 && mbus_start(&d.conf.modbus, d.snap, &d.mbus, err, sizeof err)) ||
        (d.conf.http.port > 0 && http_start(&d, &d.conf.http, d.tls, &d.http, err, sizeof err)) ||
        priv_drop(&priv, err, sizeof err)) {
        dlog(DLOG_ERROR, "%s", err);
        goto done;
    }
    http_set_tokens(d.http, d.tokens);
    srv_note_tokens(&d);
    job_sweep_start(&d);
    reload_init(&d, argc, argv);
    dlog(DLOG_INFO, "meshcorrd ready: %s backend, %u job(s) pending, state in %s", bk_name(&d),
         sched_queued(d.sched), d.conf.state_dir);
    bk_schedule(&d);
    dev_probe(&d);
    notify_ready(&d);
    uv_run(d.loop, UV_RUN_DEFAULT);
    status = 0;
    dlog(DLOG_INFO, "stopped");
done:
    close_all(&d, status);
    return status;
}
