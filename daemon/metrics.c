/* metrics.c — --metrics: the status snapshot in Prometheus text format
 * (version 0.0.4) at GET /metrics, served by libmicrohttpd's own polling
 * thread. Other paths are 404, other methods 405. Each request formats the
 * latest published snapshot (snap_read); nothing here touches the daemon's
 * state. MHD bounds what a client can hold: MHD_OPTION_CONNECTION_LIMIT
 * connections, each closed after MHD_OPTION_CONNECTION_TIMEOUT idle seconds.
 * Names follow Prometheus' conventions (tests/support/promcheck.py checks
 * them with Prometheus' own parser): counters end in _total, times are
 * _seconds, every family has HELP and TYPE, and a slot's job is the label
 * job_id (Prometheus itself puts `job`, the scrape job, on every series).
 * With --tls-cert/--tls-key it is HTTPS only (MHD_USE_TLS, the same
 * certificate, key and TLS versions as the tls: listeners); a SIGHUP that
 * renews them starts a new libmicrohttpd daemon on the same listening
 * socket (the old one quiesced, then stopped), so the port never closes. */
#include "mcd.h"
#include "util/errbuf.h"

#include <math.h>
#include <microhttpd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#define METRICS_MAX_CONNECTIONS 16
#define METRICS_TIMEOUT_S 10

struct metrics {
    struct MHD_Daemon *mhd;
    snap *snap;
    mcd_snapshot *copy;          /* used by MHD's one polling thread only */
    int fd;                      /* the listening socket; the running daemon closes it when it stops */
    char *cert, *key;            /* PEM copies MHD reads at its start; NULL: plain HTTP */
    int ipv6;
};

static void family(FILE *fp, const char *name, const char *type, const char *help)
{
    fprintf(fp, "# HELP %s %s\n# TYPE %s %s\n", name, help, name, type);
}

/* v as the text format spells it: NaN, +Inf and -Inf (printf's nan and inf
 * are not), else %.17g; then the line's end. */
static void value(FILE *fp, double v)
{
    if (isnan(v))
        fputs("NaN\n", fp);
    else if (isinf(v))
        fputs(v > 0 ? "+Inf\n" : "-Inf\n", fp);
    else
        fprintf(fp, "%.17g\n", v);
}

/* Per-slot gauges: field selects which figure; slots without progress are
 * left out of the progress gauges. */
enum slot_field { F_STATE, F_STAGE, F_OUTER, F_TOTAL, F_ENERGY, F_BETA, F_ELAPSED, F_PROGRESS, F_ETA };

static void slot_family(FILE *fp, const mcd_snapshot *s, const char *name, const char *help, enum slot_field f)
{
    family(fp, name, "gauge", help);
    for (uint32_t i = 0; i < s->nslots; i++) {
        const snap_slot *o = &s->slots[i];
        if (f != F_STATE && f != F_ELAPSED && !o->has_progress)
            continue;
        double v = 0;
        switch (f) {
        case F_STATE:    v = o->state; break;
        case F_STAGE:    v = o->stage; break;
        case F_OUTER:    v = o->outer; break;
        case F_TOTAL:    v = o->total; break;
        case F_ENERGY:   v = o->energy; break;
        case F_BETA:     v = o->beta; break;
        case F_ELAPSED:  v = o->elapsed_s; break;
        case F_PROGRESS: v = o->fraction; break;
        case F_ETA:      v = o->eta_s; break;
        }
        fprintf(fp, "%s{slot=\"%u\",job_id=\"%llu\"} ", name, i, (unsigned long long)o->job_id);
        value(fp, v);
    }
}

static void format(FILE *fp, const mcd_snapshot *s)
{
    family(fp, "meshcorr_queue_depth", "gauge", "Jobs pending in the queue.");
    fprintf(fp, "meshcorr_queue_depth %u\n", s->queued);
    family(fp, "meshcorr_running_jobs", "gauge", "Worker slots running a job.");
    fprintf(fp, "meshcorr_running_jobs %u\n", s->running);
    family(fp, "meshcorr_jobs_total", "counter", "Jobs ended, by final state, since the job store was created.");
    fprintf(fp, "meshcorr_jobs_total{state=\"completed\"} %llu\n", (unsigned long long)s->completed);
    fprintf(fp, "meshcorr_jobs_total{state=\"failed\"} %llu\n", (unsigned long long)s->failed);
    fprintf(fp, "meshcorr_jobs_total{state=\"cancelled\"} %llu\n", (unsigned long long)s->cancelled);
    family(fp, "meshcorr_workers", "gauge", "Worker slots configured.");
    fprintf(fp, "meshcorr_workers %u\n", s->workers);
    family(fp, "meshcorr_uptime_seconds", "gauge", "Seconds since meshcorrd started.");
    fprintf(fp, "meshcorr_uptime_seconds %u\n", s->uptime_s);
    family(fp, "meshcorr_snapshots_total", "counter", "Status snapshots published (one every 200 ms).");
    fprintf(fp, "meshcorr_snapshots_total %u\n", s->seq);
    slot_family(fp, s, "meshcorr_slot_state", "Worker slot state: 0 idle, 1 starting, 2 busy, 3 draining (job_id 0: none).", F_STATE);
    slot_family(fp, s, "meshcorr_slot_elapsed_seconds", "Wall time since the slot's job started.", F_ELAPSED);
    slot_family(fp, s, "meshcorr_slot_stage",
                "Stage of the latest progress: 0 start, 1 rhm, 2 ectm, 3 init, 4 ddm, 5 repair.", F_STAGE);
    slot_family(fp, s, "meshcorr_slot_outer_iteration", "Iteration of the latest progress's stage.", F_OUTER);
    slot_family(fp, s, "meshcorr_slot_total_iterations", "Iterations planned in that stage.", F_TOTAL);
    slot_family(fp, s, "meshcorr_slot_progress_ratio",
                "The whole job's share done (0 to 1): every stage weighted by its expected cost.", F_PROGRESS);
    slot_family(fp, s, "meshcorr_slot_eta_seconds",
                "Seconds the job has left, from the time its share done took (NaN not known).", F_ETA);
    slot_family(fp, s, "meshcorr_slot_energy", "Total energy of the latest progress (both directions summed).", F_ENERGY);
    slot_family(fp, s, "meshcorr_slot_beta", "Mismatch weight beta of the latest progress.", F_BETA);
}

static enum MHD_Result reply(struct MHD_Connection *conn, unsigned status, const char *body, size_t len,
                             int must_free)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(
        len, (void *)body, must_free ? MHD_RESPMEM_MUST_FREE : MHD_RESPMEM_PERSISTENT);
    if (!r) {
        if (must_free)
            free((void *)body);
        return MHD_NO;
    }
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE,
                            status == MHD_HTTP_OK ? "text/plain; version=0.0.4; charset=utf-8" : "text/plain");
    if (status == MHD_HTTP_METHOD_NOT_ALLOWED)
        MHD_add_response_header(r, MHD_HTTP_HEADER_ALLOW, "GET");
    enum MHD_Result rc = MHD_queue_response(conn, status, r);
    MHD_destroy_response(r);
    return rc;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *conn, const char *url, const char *method,
                                  const char *version, const char *upload, size_t *upload_size, void **state)
{
    (void)version;
    (void)upload;
    (void)state;
    metrics *m = cls;
    if (*upload_size) {            /* a body we do not want: drop it, answer at the end */
        *upload_size = 0;
        return MHD_YES;
    }
    if (strcmp(url, "/metrics") != 0) {
        static const char nf[] = "not found: the metrics are at /metrics\n";
        return reply(conn, MHD_HTTP_NOT_FOUND, nf, sizeof nf - 1, 0);
    }
    if (strcmp(method, MHD_HTTP_METHOD_GET) != 0) {
        static const char na[] = "method not allowed: GET only\n";
        return reply(conn, MHD_HTTP_METHOD_NOT_ALLOWED, na, sizeof na - 1, 0);
    }
    char *buf = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&buf, &len);
    if (!fp)
        return MHD_NO;
    snap_read(m->snap, m->copy);
    format(fp, m->copy);
    if (fclose(fp) != 0) {
        free(buf);
        return MHD_NO;
    }
    return reply(conn, MHD_HTTP_OK, buf, len, 1);
}

static void free_pem(char **p)
{
    if (*p) {
        explicit_bzero(*p, strlen(*p));
        free(*p);
    }
    *p = NULL;
}

/* A libmicrohttpd daemon on m->fd: HTTPS with cert and key, or HTTP when
 * they are NULL; NULL when it does not start. */
static struct MHD_Daemon *serve(metrics *m, const char *cert, const char *key)
{
    /* MHD_USE_ITC: a SIGHUP quiesces it, the socket goes on to a new one */
    unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_ITC | (m->ipv6 ? MHD_USE_IPv6 : 0);
    if (!cert)
        return MHD_start_daemon(flags, 0, NULL, NULL, on_request, m, MHD_OPTION_LISTEN_SOCKET, m->fd,
                                MHD_OPTION_CONNECTION_LIMIT, (unsigned)METRICS_MAX_CONNECTIONS,
                                MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)METRICS_TIMEOUT_S, MHD_OPTION_END);
    return MHD_start_daemon(flags | MHD_USE_TLS, 0, NULL, NULL, on_request, m, MHD_OPTION_LISTEN_SOCKET, m->fd,
                            MHD_OPTION_CONNECTION_LIMIT, (unsigned)METRICS_MAX_CONNECTIONS,
                            MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)METRICS_TIMEOUT_S,
                            MHD_OPTION_HTTPS_MEM_CERT, cert, MHD_OPTION_HTTPS_MEM_KEY, key,
                            MHD_OPTION_HTTPS_PRIORITIES, TLS_PRIORITY, MHD_OPTION_END);
}

int metrics_start(const conf_endpoint *e, const tls_creds *tls, snap *s, metrics **out, char *err, size_t errsz)
{
    *out = NULL;
    metrics *m = calloc(1, sizeof *m);
    if (!m || !(m->copy = snap_alloc(snap_nslots(s)))) {
        free(m);
        return errbuf_set(err, errsz, -1, "metrics: out of memory");
    }
    m->snap = s;
    m->fd = -1;
    m->fd = dash_listen(e, "metrics", err, errsz);
    if (m->fd < 0) {
        metrics_stop(m);
        return -1;
    }
    struct sockaddr_storage sa;
    socklen_t sl = sizeof sa;
    getsockname(m->fd, (struct sockaddr *)&sa, &sl);
    m->ipv6 = sa.ss_family == AF_INET6;
    if (tls && (!(m->cert = strdup(tls_creds_cert_pem(tls))) || !(m->key = strdup(tls_creds_key_pem(tls))))) {
        metrics_stop(m);
        return errbuf_set(err, errsz, -1, "metrics: out of memory");
    }
    if (tls && !MHD_is_feature_supported(MHD_FEATURE_TLS)) {
        metrics_stop(m);
        return errbuf_set(err, errsz, -1, "--metrics %s:%d: this libmicrohttpd has no TLS, and --tls-cert asks "
                          "for HTTPS", e->host, e->port);
    }
    if (!(m->mhd = serve(m, m->cert, m->key))) {
        metrics_stop(m);
        return errbuf_set(err, errsz, -1, "--metrics %s:%d: libmicrohttpd did not start%s", e->host, e->port,
                          tls ? " with the --tls-cert certificate and --tls-key key" : "");
    }
    if (tls)
        dlog(DLOG_INFO, "metrics over HTTPS (the --tls-cert certificate)");
    *out = m;
    return 0;
}

int metrics_set_tls(metrics *m, const tls_creds *tls, char *err, size_t errsz)
{
    if (!m->cert || !tls)
        return 0;                  /* plain HTTP stays plain until the next start */
    if (!strcmp(m->cert, tls_creds_cert_pem(tls)) && !strcmp(m->key, tls_creds_key_pem(tls)))
        return 0;                  /* the same pair: nothing to restart */
    char *cert = strdup(tls_creds_cert_pem(tls)), *key = strdup(tls_creds_key_pem(tls));
    if (!cert || !key) {
        free_pem(&cert);
        free_pem(&key);
        return errbuf_set(err, errsz, -1, "metrics: out of memory");
    }
    /* the old daemon stops taking connections; the new one listens on the
     * same socket; then the old one ends its connections and stops */
    struct MHD_Daemon *old = m->mhd;
    if (MHD_quiesce_daemon(old) != m->fd) {
        free_pem(&cert);
        free_pem(&key);
        return errbuf_set(err, errsz, -1, "metrics: libmicrohttpd could not be quiesced");
    }
    struct MHD_Daemon *nd = serve(m, cert, key);
    if (!nd) {
        /* the old daemon no longer accepts: start it again with its own pair */
        nd = serve(m, m->cert, m->key);
        MHD_stop_daemon(old);
        m->mhd = nd;
        free_pem(&cert);
        free_pem(&key);
        if (!nd)
            dlog(DLOG_ERROR, "metrics: libmicrohttpd did not start again: /metrics is off until the next start");
        return errbuf_set(err, errsz, -1, "metrics: libmicrohttpd did not start with the new certificate");
    }
    MHD_stop_daemon(old);
    m->mhd = nd;
    free_pem(&m->cert);
    free_pem(&m->key);
    m->cert = cert;
    m->key = key;
    dlog(DLOG_INFO, "reload: metrics serve the new certificate");
    return 0;
}

void metrics_stop(metrics *m)
{
    if (!m)
        return;
    if (m->mhd)
        MHD_stop_daemon(m->mhd);   /* joins its thread, closes the listening socket */
    else if (m->fd >= 0)
        close(m->fd);
    free_pem(&m->cert);
    free_pem(&m->key);
    snap_release(m->copy);
    free(m);
}
