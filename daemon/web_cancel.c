/* web_cancel.c — a cancel asked on the web, carried out on the loop: the
 * HTTP thread queues (job, user, admin) under a mutex and wakes the loop
 * with a uv_async; the loop takes the queue and cancels each job the way a
 * CANCEL request does (bk_cancel_job), after checking again, on the store as
 * it is now, that the job is the user's (or the user an admin) and has not
 * ended. The queue is bounded (WEB_CANCEL_MAX_QUEUED): past it a request is
 * refused, never waited for, so the HTTP thread never blocks on the loop. */
#include "backend.h"
#include "mcd.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

typedef struct pending_cancel {
    uint64_t id;
    char user[AUTH_MAX_USER];
    int admin;
} pending_cancel;

struct web_cancel {
    uv_async_t async;
    mcd *d;
    pthread_mutex_t mu;
    pending_cancel q[WEB_CANCEL_MAX_QUEUED];
    int n;
    int open;                     /* the async handle is live (not closed by a drain) */
};

static void on_async(uv_async_t *a)
{
    web_cancel *w = a->data;
    pending_cancel q[WEB_CANCEL_MAX_QUEUED];
    pthread_mutex_lock(&w->mu);
    int n = w->n;
    memcpy(q, w->q, (size_t)n * sizeof q[0]);
    w->n = 0;
    pthread_mutex_unlock(&w->mu);
    for (int i = 0; i < n; i++) {
        store_job j;
        if (store_get(w->d->store, q[i].id, &j) || (!q[i].admin && strcmp(j.user, q[i].user)))
            continue;             /* gone (deleted, expired) since the HTTP thread looked */
        if (w->d->draining) {
            dlog(DLOG_INFO, "job %llu: web cancel by %s ignored: shutting down", (unsigned long long)j.id,
                 q[i].user);
            continue;
        }
        int rc = bk_cancel_job(w->d, &j);
        if (rc == PROTO_ESTORAGE)
            dlog(DLOG_ERROR, "job %llu: job store failure cancelling it (web, %s)", (unsigned long long)j.id,
                 q[i].user);
        else if (rc == 0)
            dlog(DLOG_INFO, "job %llu: cancelled on the web by %s", (unsigned long long)j.id, q[i].user);
    }
}

int web_cancel_init(mcd *d)
{
    web_cancel *w = calloc(1, sizeof *w);
    if (!w)
        return -1;
    pthread_mutex_init(&w->mu, NULL);
    w->d = d;
    if (uv_async_init(d->loop, &w->async, on_async)) {
        pthread_mutex_destroy(&w->mu);
        free(w);
        return -1;
    }
    w->async.data = w;
    w->open = 1;
    d->web_cancel = w;
    return 0;
}

int web_cancel_request(web_cancel *w, uint64_t id, const char *user, int admin)
{
    pthread_mutex_lock(&w->mu);
    int rc = -1;
    if (w->open && w->n < WEB_CANCEL_MAX_QUEUED) {
        pending_cancel *p = &w->q[w->n++];
        p->id = id;
        snprintf(p->user, sizeof p->user, "%s", user);
        p->admin = admin;
        uv_async_send(&w->async);
        rc = 0;
    }
    pthread_mutex_unlock(&w->mu);
    return rc;
}

void web_cancel_close(mcd *d)
{
    web_cancel *w = d->web_cancel;
    if (!w || !w->open)
        return;
    pthread_mutex_lock(&w->mu);
    w->open = 0;
    pthread_mutex_unlock(&w->mu);
    uv_close((uv_handle_t *)&w->async, NULL);
}

void web_cancel_free(web_cancel *w)
{
    if (!w)
        return;
    pthread_mutex_destroy(&w->mu);
    free(w);
}
