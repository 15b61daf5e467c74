/* notify.c — meshcorrd's service-manager notifications (sd_notify, the
 * systemd Type=notify protocol): READY=1 once listening, STATUS= with the
 * queue and slots (sent when it changes, at most once per
 * NOTIFY_STATUS_PERIOD_MS), RELOADING=1 / READY=1 around a SIGHUP reload and
 * STOPPING=1 when a drain starts. Without $NOTIFY_SOCKET every call is a
 * no-op (libsystemd's). Reads the daemon's figures, changes nothing. */
#include "backend.h"

#include <stdlib.h>
#include <string.h>
#include <systemd/sd-daemon.h>
#include <time.h>

#define NOTIFY_STATUS_PERIOD_MS 1000

static char last_status[256];

/* Slots with a job, whatever the backend (the Slurm backend's slots are its
 * jobs in Slurm). */
static int slots_busy(const mcd *d)
{
    int n = 0;
    for (int i = 0; i < bk_nslots(d); i++) {
        uint8_t state;
        uint64_t job;
        bk_slot_info(d, i, &state, &job);
        n += state != PROTO_SLOT_IDLE;
    }
    return n;
}

static void status_line(mcd *d, char *buf, size_t sz)
{
    uint64_t completed = 0, failed = 0, cancelled = 0;
    store_counters(d->store, &completed, &failed, &cancelled);
    snprintf(buf, sz, "%u queued, %d of %d slot(s) busy; %llu completed, %llu failed, %llu cancelled",
             sched_queued(d->sched), slots_busy(d), bk_nslots(d), (unsigned long long)completed,
             (unsigned long long)failed, (unsigned long long)cancelled);
}

static void notify_send(const char *msg)
{
    int rc = sd_notify(0, msg);
    if (rc < 0)
        dlog(DLOG_WARN, "sd_notify: %s", strerror(-rc));
}

static void on_status_timer(uv_timer_t *t)
{
    mcd *d = t->data;
    char line[256], msg[300];
    status_line(d, line, sizeof line);
    if (strcmp(line, last_status) == 0)
        return;
    snprintf(last_status, sizeof last_status, "%s", line);
    snprintf(msg, sizeof msg, "STATUS=%s", line);
    notify_send(msg);
}

void notify_ready(mcd *d)
{
    uv_timer_init(d->loop, &d->notify_timer);
    d->notify_timer.data = d;
    if (!getenv("NOTIFY_SOCKET"))
        return;
    char line[256], msg[320];
    status_line(d, line, sizeof line);
    snprintf(last_status, sizeof last_status, "%s", line);
    snprintf(msg, sizeof msg, "READY=1\nSTATUS=%s", line);
    notify_send(msg);
    uv_timer_start(&d->notify_timer, on_status_timer, NOTIFY_STATUS_PERIOD_MS, NOTIFY_STATUS_PERIOD_MS);
}

void notify_reloading(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    char msg[96];
    snprintf(msg, sizeof msg, "RELOADING=1\nMONOTONIC_USEC=%llu",
             (unsigned long long)ts.tv_sec * 1000000ull + (unsigned long long)ts.tv_nsec / 1000);
    notify_send(msg);
}

void notify_reloaded(void)
{
    notify_send("READY=1");
}

void notify_stopping(mcd *d)
{
    char msg[160];
    snprintf(msg, sizeof msg, "STOPPING=1\nSTATUS=shutting down: %d running job(s) go back to the queue",
             bk_busy(d));
    notify_send(msg);
}

void notify_close(mcd *d)
{
    uv_close((uv_handle_t *)&d->notify_timer, NULL);
}
