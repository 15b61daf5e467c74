/* backend.h — where meshcorrd's jobs run. A backend takes jobs from the
 * scheduler (sched_next), runs them against their spool directory with
 * meshcorr-worker (workers/WORKER.md), feeds their PROGRESS records to
 * job_progress_take, and reports each run's start and end to job.c
 * (job_running, job_ended), which records them and tells the watchers;
 * a backend decides only which state its worker's run ended in. Two of them, chosen by `backend =`:
 *
 *   local  wsup.c      worker processes on this machine (--workers slots)
 *   slurm  bk_slurm.c  one Slurm batch job per meshcorr job (sbatch, squeue,
 *                      scancel), progress over TCP (bk_prog.c) or a file
 *
 * The rest of the daemon calls only the bk_ functions below. A backend never
 * blocks the loop: commands it runs go through uv_spawn (bk_cmd.c). */
#ifndef BACKEND_H
#define BACKEND_H
#include "mcd.h"

typedef struct bk_ops {
    const char *name;
    int (*init)(mcd *d, char *err, size_t errsz);
    void (*schedule)(mcd *d);                  /* start what can start */
    int (*cancel)(mcd *d, uint64_t id);        /* 0 when the backend has the job and stops it */
    /* shutdown: stop or hand back the runs; then idle(d) each time one of
     * those this daemon waits for (busy()) has ended */
    void (*drain)(mcd *d, mcd_idle_fn idle);
    int (*busy)(const mcd *d);                 /* runs this daemon must wait for on shutdown */
    int (*nslots)(const mcd *d);               /* STATS slots */
    void (*slot_info)(const mcd *d, int i, uint8_t *state, uint64_t *job_id);
    int (*health)(const mcd *d, char *msg, size_t sz);  /* 1 usable, 0 not (msg says why) */
    void (*close)(mcd *d);                     /* closes its handles (the loop then ends) */
    /* SIGHUP: n is the re-read configuration; puts back into n the running
     * values of the options this backend applies only at start (its slot
     * count above all: the snapshot and the dashboards are sized from it),
     * and names those that differed in changed ("" none). */
    void (*keep_on_reload)(const mcd *d, mcd_conf *n, char *changed, size_t sz);
} bk_ops;

extern const bk_ops bk_local, bk_slurm;

/* Picks d->conf.backend's ops and initialises it. */
int bk_init(mcd *d, char *err, size_t errsz);
void bk_schedule(mcd *d);
int bk_cancel(mcd *d, uint64_t id);
void bk_drain(mcd *d, mcd_idle_fn idle);
int bk_busy(const mcd *d);
int bk_nslots(const mcd *d);
void bk_slot_info(const mcd *d, int i, uint8_t *state, uint64_t *job_id);
int bk_health(const mcd *d, char *msg, size_t sz);
const char *bk_name(const mcd *d);
void bk_close(mcd *d);
void bk_keep_on_reload(const mcd *d, mcd_conf *n, char *changed, size_t sz);

/* ---- bk_cmd.c: one external command, asynchronously ---------------------- */
#define BK_CMD_MAX_OUTPUT 65536   /* stdout and stderr kept, each */
typedef struct bk_cmd bk_cmd;
/* status: the exit status, or -1 when it could not start or was killed
 * (err then says why); out/err are NUL-terminated (cut at BK_CMD_MAX_OUTPUT). */
typedef void (*bk_cmd_fn)(void *ctx, int status, const char *out, const char *err);
/* Runs argv[0] (searched in PATH) with its stdout and stderr captured; kills
 * it after timeout_ms. fn is always called once, from the loop, also when
 * the command cannot start. 0, or -1 out of memory (fn not called). */
int bk_cmd_run(uv_loop_t *loop, char *const argv[], uint64_t timeout_ms, bk_cmd_fn fn, void *ctx);
/* The file of an executable named name in PATH into buf; NULL if none. */
const char *bk_cmd_which(const char *name, char *buf, size_t sz);

/* ---- bk_prog.c: progress connections from Slurm workers ----------------- */
/* A worker connects to the listener and sends one line
 *   MCPROGRESS <job-id> <secret>\n
 * then PROGRESS frames, as on the local worker's pipe. The secret is the
 * 64 hex digits bk_slurm wrote to the job's progress.secret; a wrong job or
 * secret closes the connection. */
#define BK_PROG_HELLO "MCPROGRESS"
#define BK_SECRET_HEX 64
typedef struct bk_prog bk_prog;
/* The job's secret, or NULL when the job is not one the backend runs. */
typedef const char *(*bk_prog_secret_fn)(void *ctx, uint64_t id);
/* Binds hostport ("HOST:PORT", PORT 0 = any); *port is the bound port. */
int bk_prog_listen(mcd *d, const char *hostport, bk_prog_secret_fn fn, void *ctx, bk_prog **out,
                   int *port, char *err, size_t errsz);
/* Drops job id's connection (it ended). */
void bk_prog_forget(bk_prog *p, uint64_t id);
/* Whether job id has a live authenticated connection. */
void bk_prog_close(bk_prog *p);

#endif
