/* drain.c — the graceful shutdown (SIGTERM, SIGINT): stop accepting, let the
 * backend stop or hand back its runs (bk_drain: local workers get SIGTERM
 * and their jobs go back to PENDING; Slurm jobs run on, the next start
 * re-attaches), let the SUBMITs and RESULTs in the thread pool finish (their
 * replies still go out), then close every handle so the loop ends; main()
 * closes the store after the loop.
 *
 * DESIGN: nothing acknowledged is lost by a drain. The handles close only
 * once no worker runs (bk_busy) and no request is in the thread pool
 * (work_inflight), so no store_submit can run when the store closes; the
 * backend and req.c call back (check) when either may have become 0, and
 * check does nothing before then, or twice. */
#include "backend.h"

#include <signal.h>

static void check(mcd *d)
{
    if (!d->draining || d->drained || bk_busy(d) || d->work_inflight)
        return;
    d->drained = 1;
    dlog(DLOG_INFO, "drained: no worker running, no request in the thread pool; closing");
    srv_close_all(d);
    bk_close(d);
    job_close(d);
    snap_close(d);
    web_cancel_close(d);
    uv_close((uv_handle_t *)&d->sigterm, NULL);
    uv_close((uv_handle_t *)&d->sigint, NULL);
    /* closing them put back the default action: another SIGTERM now (an
     * impatient service manager) must not kill a daemon that is already
     * closing cleanly; no process is started after this point */
    signal(SIGTERM, SIG_IGN);
    signal(SIGINT, SIG_IGN);
    reload_close(d);
    notify_close(d);
}

void drain_start(mcd *d, int sig)
{
    if (d->draining) {
        dlog(DLOG_INFO, "signal %d: already shutting down", sig);
        return;
    }
    d->draining = 1;
    dlog(DLOG_INFO, "signal %d: shutting down: %d running job(s) go back to the queue", sig, bk_busy(d));
    notify_stopping(d);
    srv_stop_listening(d);
    bk_drain(d, check);
    req_quiesce(d, check);
    if (d->work_inflight)
        dlog(DLOG_INFO, "waiting for %u request(s) in the thread pool (SUBMITs being stored: their"
             " SUBMIT_OK still goes out)", d->work_inflight);
    check(d);
}
