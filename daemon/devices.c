/* devices.c — the compute devices a job on this server can use, as STATS
 * lists them: asked once, at start, of the worker program itself
 * (`meshcorr-worker --list-devices`), so the daemon never loads OpenCL (a
 * fork after PoCL's initialisation hangs the child). Holds no job logic. */
#include "backend.h"
#include "mcd.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define DEV_PROBE_TIMEOUT_MS 30000

static void on_list(void *ctx, int status, const char *out, const char *err)
{
    mcd *d = ctx;
    if (status != 0) {
        dlog(DLOG_WARN, "meshcorr-worker --list-devices failed (%d): %s", status, err);
        return;
    }
    int n = 0;
    for (const char *p = out; *p && n < MCD_MAX_DEVICES;) {
        size_t len = strcspn(p, "\n");
        if (len) {
            snprintf(d->devices[n], sizeof d->devices[n], "%.*s", (int)len, p);
            n++;
        }
        p += len + (p[len] == '\n');
    }
    d->ndevices = n;
    dlog(DLOG_INFO, "devices: %d (%s%s)", n, n ? d->devices[0] : "", n > 1 ? ", ..." : "");
}

void dev_probe(mcd *d)
{
    char wbuf[CONF_PATH + 64], tbuf[32];
    const char *w = conf_worker_path(&d->conf, wbuf, sizeof wbuf);
    snprintf(tbuf, sizeof tbuf, "%d", d->conf.threads_per_worker);
    char *argv[] = { (char *)w, "--list-devices", "--threads", tbuf, NULL };
    d->ndevices = 0;
    if (bk_cmd_run(d->loop, argv, DEV_PROBE_TIMEOUT_MS, on_list, d))
        dlog(DLOG_WARN, "out of memory asking the worker for its devices");
}

int dev_list(const mcd *d, const char **out, int max)
{
    int n = d->ndevices < max ? d->ndevices : max;
    for (int i = 0; i < n; i++)
        out[i] = d->devices[i];
    return n;
}
