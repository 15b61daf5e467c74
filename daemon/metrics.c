/* metrics.c — the status snapshot in Prometheus text format (version
 * 0.0.4), what GET /metrics of the HTTP endpoint (http.c) answers. Names
 * follow Prometheus' conventions (tests/support/promcheck.py checks them
 * with Prometheus' own parser): counters end in _total, times are
 * _seconds, every family has HELP and TYPE, and a slot's job is the label
 * job_id (Prometheus itself puts `job`, the scrape job, on every series).
 * Formats a copy of the snapshot; touches nothing else. */
#include "mcd.h"

#include <math.h>
#include <stdio.h>

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

static void histogram(FILE *fp, const char *name, const char *help, const snap_hist *h)
{
    static const double bounds[SNAP_NBUCKETS] = SNAP_BUCKETS;
    family(fp, name, "histogram", help);
    uint64_t cum = 0;
    for (int b = 0; b < SNAP_NBUCKETS; b++) {
        cum += h->bucket[b];
        fprintf(fp, "%s_bucket{le=\"%g\"} %llu\n", name, bounds[b], (unsigned long long)cum);
    }
    fprintf(fp, "%s_bucket{le=\"+Inf\"} %llu\n", name, (unsigned long long)h->count);
    fprintf(fp, "%s_sum ", name);
    value(fp, h->sum);
    fprintf(fp, "%s_count %llu\n", name, (unsigned long long)h->count);
}

/* A label value as the text format escapes it: backslash, quote, newline. */
static void label_value(FILE *fp, const char *v)
{
    for (; *v; v++)
        if (*v == '\\' || *v == '"')
            fprintf(fp, "\\%c", *v);
        else if (*v == '\n')
            fputs("\\n", fp);
        else
            fputc(*v, fp);
}

static void user_family(FILE *fp, const mcd_snapshot *s, const char *name, const char *help, int running)
{
    family(fp, name, "gauge", help);
    for (uint32_t i = 0; i < s->nusers; i++) {
        fprintf(fp, "%s{user=\"", name);
        label_value(fp, s->users[i].name);
        fprintf(fp, "\"} %u\n", running ? s->users[i].running : s->users[i].pending);
    }
}

void metrics_format(FILE *fp, const mcd_snapshot *s)
{
    family(fp, "meshcorr_build_info", "gauge", "The build of meshcorrd: always 1, its version as a label.");
    fprintf(fp, "meshcorr_build_info{version=\"%s\"} 1\n", MC_VERSION);
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
    user_family(fp, s, "meshcorr_user_queue_depth", "Jobs of one user pending in the queue (users with jobs).", 0);
    user_family(fp, s, "meshcorr_user_running_jobs", "Jobs of one user running (users with jobs).", 1);
    histogram(fp, "meshcorr_job_duration_seconds",
              "Runs from their start to their end, by how long they took (since meshcorrd started).", &s->duration);
    histogram(fp, "meshcorr_job_queue_wait_seconds",
              "Runs from their job's submit to their start (since meshcorrd started).", &s->wait);
}
