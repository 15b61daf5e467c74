/* main.c — meshcorrd's main(): options, store recovery, the scheduler's
 * queue rebuilt from the store, the backend (backend.h), listeners, the
 * result-expiry sweep and the signal handlers (SIGHUP: reload.c), READY=1 to
 * the service manager, then the loop. Shutdown (SIGTERM/SIGINT) drains: stop
 * accepting, SIGTERM the workers, their jobs go back to PENDING; once no
 * worker runs and no request is in the thread pool (req.c), close every
 * handle; the loop ends, and only then the store closes (no store_submit
 * can be running); the dashboard threads (--modbus, --metrics) stop after
 * the loop. Holds no request or job logic. */
#include "backend.h"
#include "mcd.h"

#include <signal.h>
#include <stdlib.h>
#include <string.h>

static int queue_pending(void *ctx, const store_job *j)
{
    mcd *d = ctx;
    if (sched_add(d->sched, j->id, j->user, j->priority)) {
        dlog(DLOG_ERROR, "out of memory rebuilding the queue");
        return 1;
    }
    return 0;
}

static int expire_one(void *ctx, const store_job *j)
{
    mcd *d = ctx;
    dlog(DLOG_INFO, "job %llu: %s result older than %u s: deleted", (unsigned long long)j->id,
         proto_state_name(j->state), d->conf.result_ttl_s);
    store_delete(d->store, j->id);
    return 0;
}

static void on_sweep(uv_timer_t *t)
{
    mcd *d = t->data;
    store_each_expired(d->store, store_now_ms() - (int64_t)d->conf.result_ttl_s * 1000, expire_one, d);
}

void mcd_sweep_start(mcd *d)
{
    /* every minute, or every result-ttl when that is shorter */
    uint64_t every = d->conf.result_ttl_s < 60 ? d->conf.result_ttl_s * 1000ull : 60000;
    uv_timer_start(&d->sweep, on_sweep, 0, every);
}

void mcd_drained(mcd *d)
{
    if (!d->draining || d->drained || bk_busy(d) || d->work_inflight)
        return;
    d->drained = 1;
    dlog(DLOG_INFO, "drained: no worker running, no request in the thread pool; closing");
    srv_close_all(d);
    bk_close(d);
    job_close(d);
    snap_close(d);
    uv_close((uv_handle_t *)&d->sweep, NULL);
    uv_close((uv_handle_t *)&d->sigterm, NULL);
    uv_close((uv_handle_t *)&d->sigint, NULL);
    reload_close(d);
    notify_close(d);
}

static void on_signal(uv_signal_t *h, int sig)
{
    mcd *d = h->data;
    if (d->draining) {
        dlog(DLOG_INFO, "signal %d: already shutting down", sig);
        return;
    }
    d->draining = 1;
    dlog(DLOG_INFO, "signal %d: shutting down: %d running job(s) go back to the queue", sig, bk_busy(d));
    notify_stopping(d);
    srv_stop_listening(d);
    bk_drain(d);
    if (d->work_inflight)
        dlog(DLOG_INFO, "waiting for %u request(s) in the thread pool (SUBMITs being stored: their"
             " SUBMIT_OK still goes out)", d->work_inflight);
    mcd_drained(d);
}

int main(int argc, char **argv)
{
    static mcd d;
    char err[1024];
    conf_init(&d.conf);
    int rc = conf_parse_args(&d.conf, argc, argv, err, sizeof err);
    if (rc == 1) {
        conf_usage(stdout);
        return 0;
    }
    if (rc) {
        fprintf(stderr, "meshcorrd: %s\n", err);
        conf_usage(stderr);
        return 2;
    }
    dlog_set_level(d.conf.log_level);
    signal(SIGPIPE, SIG_IGN);
    int status = 1;
    d.loop = uv_default_loop();
    if (auth_tokens_load(d.conf.tokens, &d.tokens, err, sizeof err) ||
        store_open(d.conf.state_dir, &d.store, err, sizeof err) ||
        store_recover(d.store, strcmp(d.conf.backend, "slurm") == 0, err, sizeof err)) {
        dlog(DLOG_ERROR, "%s", err);
        goto done;
    }
    if (!(d.sched = sched_new()) || store_each_pending(d.store, queue_pending, &d)) {
        dlog(DLOG_ERROR, "cannot rebuild the queue from the store");
        goto done;
    }
    job_init(&d);
    if (bk_init(&d, err, sizeof err) || snap_init(&d, err, sizeof err) || srv_listen(&d, err, sizeof err) ||
        (d.conf.modbus.port > 0 && mbus_start(&d.conf.modbus, d.snap, &d.mbus, err, sizeof err)) ||
        (d.conf.metrics.port > 0 && metrics_start(&d.conf.metrics, d.snap, &d.metrics, err, sizeof err))) {
        dlog(DLOG_ERROR, "%s", err);
        goto done;
    }
    uv_timer_init(d.loop, &d.sweep);
    d.sweep.data = &d;
    mcd_sweep_start(&d);
    uv_signal_init(d.loop, &d.sigterm);
    uv_signal_init(d.loop, &d.sigint);
    d.sigterm.data = d.sigint.data = &d;
    uv_signal_start(&d.sigterm, on_signal, SIGTERM);
    uv_signal_start(&d.sigint, on_signal, SIGINT);
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
    if (status) {
        /* a start-up failure: close whatever was opened */
        srv_stop_listening(&d);
        bk_close(&d);
        job_close(&d);
        snap_close(&d);
        uv_run(d.loop, UV_RUN_NOWAIT);
    }
    mbus_stop(d.mbus);
    metrics_stop(d.metrics);
    snap_free(d.snap);
    uv_loop_close(d.loop);
    store_close(d.store);
    sched_free(d.sched);
    auth_tokens_free(d.tokens);
    free(d.slots);
    free(d.listeners);
    return status;
}
