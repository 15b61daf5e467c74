/* cli_progress.c — one progress record as a bar, a text line or a JSON
 * object (cli_progress.h): the only place the CLI formats progress. */
#include "cli/cli_progress.h"

#include <math.h>
#include <string.h>
#include <unistd.h>

#define CLI_BAR_WIDTH 30

int cli_progress_parse(const char *word, int *mode)
{
    static const char *const words[] = {"auto", "bar", "text", "json", "none"};
    for (int i = 0; i < 5; i++)
        if (strcmp(word, words[i]) == 0) {
            *mode = i;
            return 0;
        }
    return -1;
}

int cli_progress_resolve(int mode, FILE *fp)
{
    if (mode != CLI_PROGRESS_AUTO)
        return mode;
    return isatty(fileno(fp)) ? CLI_PROGRESS_BAR : CLI_PROGRESS_TEXT;
}

static const char *stage_of(const proto_progress *p)
{
    const char *s = proto_stage_name(p->stage);
    return s ? s : "?";
}

/* Seconds as "42 s", "1:02" or "3:05:00". */
static char *duration(double s, char *buf, size_t sz)
{
    long t = (long)(s + 0.5);
    if (t < 60)
        snprintf(buf, sz, "%ld s", t);
    else if (t < 3600)
        snprintf(buf, sz, "%ld:%02ld", t / 60, t % 60);
    else
        snprintf(buf, sz, "%ld:%02ld:%02ld", t / 3600, t / 60 % 60, t % 60);
    return buf;
}

char *cli_progress_share(const proto_progress *p, char *buf, size_t sz)
{
    char eta[32];
    if (p->stage == PROTO_STAGE_QUEUED) {
        if (p->ahead)
            snprintf(buf, sz, "queued: %u job%s ahead", p->ahead, p->ahead == 1 ? "" : "s");
        else
            snprintf(buf, sz, "queued: next");
    } else if (isnan(p->fraction)) {
        snprintf(buf, sz, "-");
    } else if (isnan(p->eta_s)) {
        snprintf(buf, sz, "%.1f %%", 100 * p->fraction);
    } else {
        snprintf(buf, sz, "%.1f %%, %s left", 100 * p->fraction, duration(p->eta_s, eta, sizeof eta));
    }
    return buf;
}

/* A number for JSON: null for NaN and infinities. */
static void json_num(FILE *fp, const char *key, double v)
{
    if (isfinite(v))
        fprintf(fp, ",\"%s\":%.17g", key, v);
    else
        fprintf(fp, ",\"%s\":null", key);
}

static void print_json(FILE *fp, const proto_progress *p, int has_job)
{
    if (has_job)
        fprintf(fp, "{\"job\":%llu", (unsigned long long)p->job_id);
    else
        fprintf(fp, "{\"job\":null");
    fprintf(fp, ",\"stage\":\"%s\",\"outer\":%u,\"total\":%u", stage_of(p), p->outer, p->total);
    json_num(fp, "fraction", p->fraction);
    json_num(fp, "eta", p->eta_s);
    json_num(fp, "elapsed", p->elapsed_s);
    fprintf(fp, ",\"ahead\":%u", p->ahead);
    json_num(fp, "beta", p->beta);
    json_num(fp, "gamma", p->gamma);
    static const char *names[2] = {"source", "target"};
    static const char *terms[PROTO_NTERMS] = {"membrane", "bending", "mismatch", "reverse", "energy"};
    for (int d = 0; d < 2; d++) {
        fprintf(fp, ",\"%s\":{\"inner\":%u", names[d], p->inner[d]);
        for (int t = 0; t < PROTO_NTERMS; t++)
            json_num(fp, terms[t], p->terms[d][t]);
        fputc('}', fp);
    }
    fputs("}\n", fp);
}

/* What a record of its stage has to say: the stage's count, and for the
 * stages with energies every term summed over both directions. */
static void print_body(FILE *fp, const proto_progress *p, int terms)
{
    fprintf(fp, terms ? "%s iter %u/%u" : "%s %u/%u", stage_of(p), p->outer, p->total);
    if (p->stage == PROTO_STAGE_REPAIR || p->stage == PROTO_STAGE_INIT)
        return;
    fprintf(fp, " energy %.3e", p->terms[0][PROTO_TERM_ENERGY] + p->terms[1][PROTO_TERM_ENERGY]);
    if (terms && p->stage != PROTO_STAGE_DDM)
        fprintf(fp, " membrane %.2e bending %.2e mismatch %.2e reverse %.2e beta %.2e",
                p->terms[0][PROTO_TERM_MEMBRANE] + p->terms[1][PROTO_TERM_MEMBRANE],
                p->terms[0][PROTO_TERM_BENDING] + p->terms[1][PROTO_TERM_BENDING],
                p->terms[0][PROTO_TERM_MISMATCH] + p->terms[1][PROTO_TERM_MISMATCH],
                p->terms[0][PROTO_TERM_REVERSE] + p->terms[1][PROTO_TERM_REVERSE], p->beta);
}

void cli_progress_print(FILE *fp, int mode, const proto_progress *p, int has_job)
{
    char share[64];
    cli_progress_share(p, share, sizeof share);
    switch (mode) {
    case CLI_PROGRESS_JSON:
        print_json(fp, p, has_job);
        break;
    case CLI_PROGRESS_TEXT:
        if (has_job)
            fprintf(fp, "job %llu ", (unsigned long long)p->job_id);
        if (p->stage == PROTO_STAGE_QUEUED) {
            fprintf(fp, "%s\n", share);
            break;
        }
        print_body(fp, p, 1);
        fprintf(fp, " (%s) %.1f s\n", share, p->elapsed_s);
        break;
    case CLI_PROGRESS_BAR: {
        double f = isnan(p->fraction) ? 0 : p->fraction;
        int done = (int)(CLI_BAR_WIDTH * f);
        fprintf(fp, "\r[%.*s%*s] ", done, "##############################", CLI_BAR_WIDTH - done, "");
        if (p->stage == PROTO_STAGE_QUEUED) {
            fprintf(fp, "%s\033[K", share);
            break;
        }
        print_body(fp, p, 0);
        fprintf(fp, "  %s  %.1f s\033[K", share, p->elapsed_s);
        break;
    }
    default:
        return;
    }
    fflush(fp);
}

void cli_progress_end(FILE *fp, int mode)
{
    if (mode == CLI_PROGRESS_BAR) {
        fputc('\n', fp);
        fflush(fp);
    }
}
