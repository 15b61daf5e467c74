/* cli_progress.h — a job's progress as the CLI shows it, the same for a
 * job run in process (`meshcorr match`) and one followed through meshcorrd
 * (`meshcorr watch`, `submit --watch`, `status`): every record is the
 * wire's (proto_progress, PROTOCOL.md PROGRESS), shown as a bar on a
 * terminal, a text line or a JSON object, with one set of names: job,
 * stage, outer, total, fraction, eta, elapsed, ahead, beta, gamma, and
 * source and target (membrane, bending, mismatch, reverse, energy,
 * inner). */
#ifndef CLI_PROGRESS_H
#define CLI_PROGRESS_H
#include <stdio.h>
#include "proto.h"

enum cli_progress_mode { CLI_PROGRESS_AUTO, CLI_PROGRESS_BAR, CLI_PROGRESS_TEXT, CLI_PROGRESS_JSON,
                         CLI_PROGRESS_NONE };

/* "auto", "bar", "text", "json" or "none" into *mode; -1 for another word. */
int cli_progress_parse(const char *word, int *mode);
/* auto as what it means on fp: the bar on a terminal, else text lines. */
int cli_progress_resolve(int mode, FILE *fp);

/* One record on fp in mode (not auto). has_job: the record is a job's of
 * the server (p->job_id); in process it is none (JSON "job": null). */
void cli_progress_print(FILE *fp, int mode, const proto_progress *p, int has_job);
/* Ends a bar's line (nothing in other modes). */
void cli_progress_end(FILE *fp, int mode);
/* "31.2 %, 1:02 left" (or "31.2 %" while the time left is not known) into
 * buf; "queued: 3 jobs ahead" for a queued record; returns buf. */
char *cli_progress_share(const proto_progress *p, char *buf, size_t sz);

#endif
