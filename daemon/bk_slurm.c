/* bk_slurm.c — the `slurm` backend (backend.h): each meshcorr job becomes one
 * Slurm batch job that runs meshcorr-worker on a node against the job's spool
 * directory, which the nodes see on a shared file system (deploy/SLURM.md).
 *
 * One timer drives everything, every --slurm-poll-ms: it reads the jobs'
 * progress files, lists this user's Slurm jobs (`squeue --me`), and then
 * submits pending jobs (`sbatch --parsable`) while fewer than
 * --slurm-max-jobs are in Slurm. Commands run through bk_cmd (uv_spawn), one
 * at a time, so their results never race each other. CANCEL is `scancel`.
 *
 * DESIGN: nothing is submitted twice. The Slurm job id is stored in the job's
 * row as soon as sbatch prints it; a restarted daemon re-attaches to the rows
 * that have one (store_each_slurm), and before its first submission lists
 * Slurm once and adopts any job named meshcorr-<tag>-<id> (tag: a hash of
 * the state directory) whose row has no id yet (a daemon killed between
 * sbatch and the store write). A job's end is decided when Slurm says it
 * ended: result.frame -> COMPLETED (waiting up to BK_SLURM_RESULT_WAIT_MS for
 * the shared file system to show it); a cancel we asked for -> CANCELLED;
 * Slurm's TIMEOUT / OUT_OF_MEMORY -> the same state with Slurm's reason;
 * NODE_FAIL, PREEMPTED, BOOT_FAIL -> PENDING again; error.frame -> FAILED
 * with its message; else FAILED naming Slurm's state. Progress comes over TCP
 * (bk_prog.c, authenticated by a per-job secret in progress.secret, 0600) or,
 * when the worker cannot reach us, from spool/<id>/progress.frames, read from
 * the offset stored in the row. When sbatch or squeue is missing or failing,
 * or the spool is not writable, nothing is submitted: jobs stay PENDING and
 * STATS says why (bk_health). */
#include "backend.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#define BK_SLURM_CMD_TIMEOUT_MS 60000     /* sbatch/squeue/scancel/sacct */
#define BK_SLURM_RESULT_WAIT_MS 15000     /* Slurm says COMPLETED, result.frame not seen yet */
#define BK_SLURM_MISSING_POLLS 3          /* listings without the job before it counts as gone */
#define BK_SLURM_MAX_ARGS 96

typedef struct sjob sjob;
struct sjob {
    uint64_t id;
    char user[AUTH_MAX_USER];
    char slurm_id[32];
    char secret[BK_SECRET_HEX + 1];
    int running;                   /* Slurm said RUNNING (the row is RUNNING) */
    int counted;                   /* sched counts it as the user's running job */
    int cancel, cancel_sent;
    int missing;                   /* listings in a row without it */
    int64_t progress_off;
    int64_t result_wait_until;     /* Slurm said it ended; waiting for the files */
    char reason[256];              /* Slurm's latest reason, as recorded */
    char end_state[32], end_reason[200];  /* Slurm's final word, from the latest listing */
    sjob *next;
};

static struct {
    mcd *d;
    uv_timer_t timer;
    int timer_open, closing;
    int cmd_busy, poll_due, listed_once;
    sjob *jobs;
    int njobs;
    bk_prog *prog;
    int prog_port;
    char prog_host[256];
    char tag[16];
    char spool[CONF_PATH + 16];      /* the daemon's view */
    char node_spool[CONF_PATH + 16]; /* the nodes' view */
    char err_tools[512], err_spool[512], err_squeue[1024], err_sbatch[1024];
} S;

static void step(void);

static sjob *find(uint64_t id)
{
    for (sjob *j = S.jobs; j; j = j->next)
        if (j->id == id)
            return j;
    return NULL;
}

static sjob *add_job(uint64_t id, const char *user)
{
    sjob *j = calloc(1, sizeof *j);
    if (!j)
        return NULL;
    j->id = id;
    snprintf(j->user, sizeof j->user, "%s", user);
    sjob **pj = &S.jobs;
    while (*pj)
        pj = &(*pj)->next;
    *pj = j;
    S.njobs++;
    return j;
}

static void drop_job(sjob *j)
{
    for (sjob **pj = &S.jobs; *pj; pj = &(*pj)->next)
        if (*pj == j) {
            *pj = j->next;
            S.njobs--;
            free(j);
            return;
        }
}

static const char *spool_file(uint64_t id, const char *file, char *buf, size_t sz)
{
    return store_spool_path(S.d->store, id, file, buf, sz);
}

static int has_file(uint64_t id, const char *file)
{
    char path[CONF_PATH + 64];
    return access(spool_file(id, file, path, sizeof path), F_OK) == 0;
}

/* ---- health --------------------------------------------------------------- */

static void check_local(void)
{
    char buf[PATH_MAX];
    static const char *tools[] = {"sbatch", "squeue", "scancel"};
    S.err_tools[0] = '\0';
    for (size_t i = 0; i < sizeof tools / sizeof tools[0]; i++)
        if (!bk_cmd_which(tools[i], buf, sizeof buf)) {
            const char *path = getenv("PATH");
            snprintf(S.err_tools, sizeof S.err_tools, "%s not found in PATH (%.400s)", tools[i],
                     path ? path : "PATH unset");
            break;
        }
    S.err_spool[0] = '\0';
    if (access(S.spool, W_OK | X_OK) != 0)
        snprintf(S.err_spool, sizeof S.err_spool, "spool %.400s is not writable: %s", S.spool, strerror(errno));
}

static int usable(void)
{
    return !S.err_tools[0] && !S.err_spool[0] && !S.err_squeue[0];
}

static int slurm_health(const mcd *d, char *msg, size_t sz)
{
    (void)d;
    const char *e = S.err_tools[0] ? S.err_tools : S.err_spool[0] ? S.err_spool
                  : S.err_squeue[0] ? S.err_squeue : S.err_sbatch;
    if (e[0]) {
        snprintf(msg, sz, "%s", e);
        return 0;
    }
    if (!S.listed_once) {
        snprintf(msg, sz, "waiting for the first squeue listing");
        return 0;
    }
    snprintf(msg, sz, "%d job(s) in Slurm (max %d); progress on %s:%d", S.njobs, S.d->conf.slurm_max_jobs,
             S.prog_host, S.prog_port);
    return 1;
}

/* Logs a problem once when it appears. */
static void set_err(char *slot, size_t sz, const char *fmt, const char *a, const char *b)
{
    char msg[1024];
    snprintf(msg, sizeof msg, fmt, a, b);
    /* keep it one line */
    for (char *p = msg; *p; p++)
        if (*p == '\n' || *p == '\r')
            *p = ' ';
    if (strcmp(slot, msg) != 0)
        dlog(DLOG_ERROR, "slurm: %s: jobs stay PENDING", msg);
    snprintf(slot, sz, "%s", msg);
}

/* ---- progress file ---------------------------------------------------------- */

static void read_progress_file(sjob *j)
{
    char path[CONF_PATH + 64];
    int fd = open(spool_file(j->id, SPOOL_PROGRESS_FILE, path, sizeof path), O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return;
    proto_buf in;
    proto_buf_init(&in);
    static char chunk[65536];
    ssize_t n;
    int64_t start = j->progress_off;
    while ((n = pread(fd, chunk, sizeof chunk, (off_t)(start + (int64_t)in.len))) > 0)
        proto_buf_put(&in, chunk, (size_t)n);
    close(fd);
    if (in.len) {
        size_t before = in.len;
        int rc = job_progress_take(S.d, j->id, &in);
        /* a bad frame: skip what is there now */
        j->progress_off = start + (int64_t)(rc < 0 ? before : before - in.len);
        if (j->progress_off != start)
            store_set_slurm(S.d->store, j->id, j->slurm_id, j->progress_off);
    }
    proto_buf_free(&in);
}

/* ---- a job's end ------------------------------------------------------------ */

static int is_terminal_slurm(const char *st)
{
    static const char *t[] = {"COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "OUT_OF_MEMORY", "NODE_FAIL",
                              "PREEMPTED", "BOOT_FAIL", "DEADLINE", "SPECIAL_EXIT", "REVOKED"};
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        if (strcmp(st, t[i]) == 0)
            return 1;
    return 0;
}

/* Slurm says job j ended in slurm_state (for reason). Returns 0 when the job
 * is finished (and freed), 1 while waiting for its result file. */
static int finish(sjob *j, const char *slurm_state, const char *sreason)
{
    mcd *d = S.d;
    read_progress_file(j);
    int has_result = job_has_result(d, j->id), has_error = has_file(j->id, SPOOL_ERROR_FRAME);
    if (strcmp(slurm_state, "COMPLETED") == 0 && !has_result && !has_error) {
        int64_t now = store_now_ms();
        if (!j->result_wait_until)
            j->result_wait_until = now + BK_SLURM_RESULT_WAIT_MS;
        if (now < j->result_wait_until)
            return 1;                 /* NFS may show the file a little later */
    }
    char reason[PROTO_MAX_STRING + 1], emsg[PROTO_MAX_STRING + 1] = "";
    const char *why = sreason && sreason[0] && strcmp(sreason, "None") != 0 ? sreason : "";
    int state;
    if (has_result) {
        state = PROTO_STATE_COMPLETED;
        snprintf(reason, sizeof reason, "%s", "");
    } else if (j->cancel) {
        state = PROTO_STATE_CANCELLED;
        snprintf(reason, sizeof reason, "cancelled by request (scancel of Slurm job %s)", j->slurm_id);
    } else if (strcmp(slurm_state, "TIMEOUT") == 0 || strcmp(slurm_state, "DEADLINE") == 0) {
        state = PROTO_STATE_TIMEOUT;
        snprintf(reason, sizeof reason, "Slurm job %s: %s%s%s (Slurm's time limit)", j->slurm_id, slurm_state,
                 why[0] ? ": " : "", why);
    } else if (strcmp(slurm_state, "OUT_OF_MEMORY") == 0) {
        state = PROTO_STATE_OUT_OF_MEMORY;
        snprintf(reason, sizeof reason, "Slurm job %s: OUT_OF_MEMORY%s%s (Slurm's memory limit)", j->slurm_id,
                 why[0] ? ": " : "", why);
    } else if (strcmp(slurm_state, "NODE_FAIL") == 0 || strcmp(slurm_state, "PREEMPTED") == 0 ||
               strcmp(slurm_state, "BOOT_FAIL") == 0) {
        state = PROTO_STATE_PENDING;
        snprintf(reason, sizeof reason, "re-queued: Slurm job %s ended %s%s%s", j->slurm_id, slurm_state,
                 why[0] ? ": " : "", why);
    } else if ((state = job_error_end(d, j->id, emsg, sizeof emsg)) >= 0) {
        snprintf(reason, sizeof reason, "%s (Slurm job %s %s)", emsg, j->slurm_id, slurm_state);
    } else if (strcmp(slurm_state, "CANCELLED") == 0) {
        state = PROTO_STATE_CANCELLED;
        snprintf(reason, sizeof reason, "Slurm job %s was cancelled outside meshcorrd%s%s", j->slurm_id,
                 why[0] ? ": " : "", why);
    } else {
        state = PROTO_STATE_FAILED;
        snprintf(reason, sizeof reason, "Slurm job %s ended %s%s%s without a result (see spool/%llu/" SPOOL_SLURM_OUT ")",
                 j->slurm_id, slurm_state, why[0] ? ": " : "", why, (unsigned long long)j->id);
    }
    bk_prog_forget(S.prog, j->id);
    job_ended(d, j->id, j->user, j->counted, state, reason);
    drop_job(j);
    return 0;
}

/* ---- squeue ------------------------------------------------------------------ */

static void map_running(sjob *j, const char *sstate, const char *sreason)
{
    mcd *d = S.d;
    j->missing = 0;
    if (strcmp(sstate, "RUNNING") == 0 || strcmp(sstate, "COMPLETING") == 0 ||
        strcmp(sstate, "SUSPENDED") == 0 || strcmp(sstate, "STAGE_OUT") == 0 ||
        strcmp(sstate, "SIGNALING") == 0 || strcmp(sstate, "RESIZING") == 0) {
        if (!j->running) {
            j->running = 1;
            job_running(d, j->id, 0);
            dlog(DLOG_INFO, "job %llu: RUNNING as Slurm job %s", (unsigned long long)j->id, j->slurm_id);
        }
        return;
    }
    /* PENDING, CONFIGURING, REQUEUED, ...: PENDING with Slurm's reason */
    char reason[256];
    snprintf(reason, sizeof reason, "Slurm job %s %s%s%s", j->slurm_id, sstate, sreason[0] ? ": " : "", sreason);
    if (strcmp(reason, j->reason) != 0) {
        snprintf(j->reason, sizeof j->reason, "%s", reason);
        store_set_reason(d->store, j->id, reason);
    }
}

/* A listed job named meshcorr-<tag>-<id> of ours that no row knows as
 * running in Slurm: its sbatch succeeded but the daemon died before storing
 * the id. Adopt it instead of submitting again. */
static void adopt(uint64_t id, const char *sid, const char *sstate)
{
    store_job row;
    if (find(id) || store_get(S.d->store, id, &row) != 0 || row.state != PROTO_STATE_PENDING || row.slurm_id[0])
        return;
    if (strcmp(sstate, "NODE_FAIL") == 0 || strcmp(sstate, "PREEMPTED") == 0 || strcmp(sstate, "BOOT_FAIL") == 0)
        return;
    sjob *j = add_job(id, row.user);
    if (!j)
        return;
    sched_remove(S.d->sched, id);
    snprintf(j->slurm_id, sizeof j->slurm_id, "%s", sid);
    char path[CONF_PATH + 64];
    FILE *fp = fopen(spool_file(id, SPOOL_SECRET_FILE, path, sizeof path), "r");
    if (fp) {
        if (!fgets(j->secret, sizeof j->secret, fp))
            j->secret[0] = '\0';
        fclose(fp);
    }
    store_set_slurm(S.d->store, id, sid, 0);
    dlog(DLOG_WARN, "job %llu: adopted Slurm job %s (submitted before the daemon's restart)",
         (unsigned long long)id, sid);
}

static void sacct_done(void *ctx, int status, const char *out, const char *err);

static void on_squeue(void *ctx, int status, const char *out, const char *err)
{
    (void)ctx;
    S.cmd_busy = 0;
    if (S.closing)
        return;
    if (status != 0) {
        char st[32];
        snprintf(st, sizeof st, "%d", status);
        set_err(S.err_squeue, sizeof S.err_squeue, "squeue failed (exit %s): %s", st, err[0] ? err : "no output");
        step();
        return;
    }
    if (S.err_squeue[0])
        dlog(DLOG_INFO, "slurm: squeue works again");
    S.err_squeue[0] = '\0';
    for (sjob *j = S.jobs; j; j = j->next)
        j->missing++;
    char prefix[64];
    size_t plen = (size_t)snprintf(prefix, sizeof prefix, "meshcorr-%s-", S.tag);
    const char *line = out;
    /* ended jobs are finished after the scan (finish frees them) */
    while (*line) {
        const char *eol = strchr(line, '\n');
        size_t n = eol ? (size_t)(eol - line) : strlen(line);
        char buf[512], *f[4] = {0};
        if (n < sizeof buf) {
            memcpy(buf, line, n);
            buf[n] = '\0';
            char *p = buf;
            for (int k = 0; k < 4 && p; k++) {
                f[k] = p;
                p = k < 3 ? strchr(p, '|') : NULL;
                if (p)
                    *p++ = '\0';
            }
        }
        line += n + (eol != NULL);
        if (!f[3] || strncmp(f[3], prefix, plen) != 0)
            continue;
        char *e;
        unsigned long long id = strtoull(f[3] + plen, &e, 10);
        if (*e || !id)
            continue;
        sjob *j = find(id);
        if (!j && S.listed_once == 0)
            adopt(id, f[0], f[1]);
        if (!(j = find(id)) || strcmp(j->slurm_id, f[0]) != 0)
            continue;             /* an older run of the same job, or not ours now */
        if (is_terminal_slurm(f[1])) {
            j->missing = 0;
            snprintf(j->end_state, sizeof j->end_state, "%s", f[1]);
            snprintf(j->end_reason, sizeof j->end_reason, "%s", f[2]);
        } else {
            map_running(j, f[1], strcmp(f[2], "None") ? f[2] : "");
        }
    }
    S.listed_once = 1;
    /* finish the ended ones; the ones Slurm no longer lists go to sacct */
    for (sjob *j = S.jobs, *next; j; j = next) {
        next = j->next;
        if (j->end_state[0] && j->missing == 0)
            finish(j, j->end_state, j->end_reason);
    }
    for (sjob *j = S.jobs; j; j = j->next)
        if (j->slurm_id[0] && j->missing >= BK_SLURM_MISSING_POLLS && !S.cmd_busy) {
            char *argv[] = {"sacct", "-n", "-P", "-X", "-o", "State", "-j", j->slurm_id, NULL};
            uint64_t *id = malloc(sizeof *id);
            if (!id)
                break;
            *id = j->id;
            S.cmd_busy = 1;
            if (bk_cmd_run(S.d->loop, argv, BK_SLURM_CMD_TIMEOUT_MS, sacct_done, id)) {
                S.cmd_busy = 0;
                free(id);
            }
            return;                /* sacct_done steps on */
        }
    step();
}

/* Slurm no longer lists the job: accounting's word, else the spool's. */
static void sacct_done(void *ctx, int status, const char *out, const char *err)
{
    (void)err;
    uint64_t id = *(uint64_t *)ctx;
    free(ctx);
    S.cmd_busy = 0;
    if (S.closing)
        return;
    sjob *j = find(id);
    if (j) {
        char st[64] = "";
        if (status == 0)
            sscanf(out, "%63[A-Z_]", st);
        if (!st[0])
            snprintf(st, sizeof st, "%s", has_file(id, SPOOL_RESULT_FRAME) ? "COMPLETED" : "FAILED");
        if (is_terminal_slurm(st))
            finish(j, st, status == 0 ? "" : "no longer known to squeue, no accounting");
        else
            j->missing = 0;        /* accounting says it still runs */
    }
    step();
}

/* ---- sbatch -------------------------------------------------------------- */

static int write_secret(sjob *j, char *err, size_t errsz)
{
    unsigned char raw[BK_SECRET_HEX / 2];
    if (getrandom(raw, sizeof raw, 0) != (ssize_t)sizeof raw)
        return snprintf(err, errsz, "getrandom: %s", strerror(errno)), -1;
    for (size_t i = 0; i < sizeof raw; i++)
        snprintf(j->secret + 2 * i, 3, "%02x", raw[i]);
    char path[CONF_PATH + 64];
    spool_file(j->id, SPOOL_SECRET_FILE, path, sizeof path);
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd < 0)
        return snprintf(err, errsz, "%.400s: %s", path, strerror(errno)), -1;
    ssize_t w = write(fd, j->secret, BK_SECRET_HEX);
    int rc = w == BK_SECRET_HEX && fsync(fd) == 0 ? 0 : -1;
    if (rc)
        snprintf(err, errsz, "%.400s: %s", path, strerror(errno));
    close(fd);
    return rc;
}

/* 'text' quoted for sh */
static void shq(char *out, size_t sz, const char *text)
{
    size_t k = 0;
    if (k + 1 < sz)
        out[k++] = '\'';
    for (const char *p = text; *p && k + 5 < sz; p++) {
        if (*p == '\'') {
            memcpy(out + k, "'\\''", 4);
            k += 4;
        } else {
            out[k++] = *p;
        }
    }
    if (k + 1 < sz)
        out[k++] = '\'';
    out[k] = '\0';
}

static void on_sbatch(void *ctx, int status, const char *out, const char *err)
{
    uint64_t id = *(uint64_t *)ctx;
    free(ctx);
    S.cmd_busy = 0;
    sjob *j = find(id);
    char *e;
    unsigned long long sid = status == 0 ? strtoull(out, &e, 10) : 0;
    if (!j) {                      /* shutting down: keep the id for the next start */
        if (sid) {
            char ids[32];
            snprintf(ids, sizeof ids, "%llu", sid);
            store_set_slurm(S.d->store, id, ids, 0);
        }
        return;
    }
    if (!sid) {
        /* back to the queue; retried at the next poll */
        char st[32];
        snprintf(st, sizeof st, "%d", status);
        set_err(S.err_sbatch, sizeof S.err_sbatch, "sbatch failed (exit %s): %s", st,
                err[0] ? err : out[0] ? out : "no output");
        job_requeue(S.d, id, j->user, j->counted, NULL);
        drop_job(j);
        return;                    /* no step(): wait for the timer */
    }
    if (S.err_sbatch[0])
        dlog(DLOG_INFO, "slurm: sbatch works again");
    S.err_sbatch[0] = '\0';
    snprintf(j->slurm_id, sizeof j->slurm_id, "%llu", sid);
    if (store_set_slurm(S.d->store, id, j->slurm_id, 0))
        dlog(DLOG_ERROR, "job %llu: cannot store its Slurm job id %s", (unsigned long long)id, j->slurm_id);
    snprintf(j->reason, sizeof j->reason, "Slurm job %s submitted", j->slurm_id);
    store_set_reason(S.d->store, id, j->reason);
    dlog(DLOG_INFO, "job %llu: submitted to Slurm as job %s", (unsigned long long)id, j->slurm_id);
    if (!S.closing)
        step();
}

static int submit(uint64_t id, const char *user)
{
    mcd *d = S.d;
    const mcd_conf *cf = &d->conf;
    sjob *j = add_job(id, user);
    if (!j) {
        dlog(DLOG_ERROR, "job %llu: out of memory", (unsigned long long)id);
        return -1;
    }
    j->counted = 1;
    char err[512];
    store_clear_run(d->store, id);
    if (write_secret(j, err, sizeof err)) {
        set_err(S.err_spool, sizeof S.err_spool, "cannot write the job's secret: %s%s", err, "");
        job_requeue(d, id, user, 1, NULL);
        drop_job(j);
        return -1;
    }
    char wbuf[PATH_MAX], dir[CONF_PATH + 64], name[64], out[CONF_PATH + 96], cpus[32], opt[4][CONF_PATH + 32];
    char wrap[6 * PATH_MAX + 8 * CONF_PATH], q_worker[2 * PATH_MAX], q_dir[2 * CONF_PATH + 160], q_sec[2 * CONF_PATH + 200];
    const char *worker = cf->slurm_worker[0] ? cf->slurm_worker : conf_worker_path(&d->conf, wbuf, sizeof wbuf);
    snprintf(dir, sizeof dir, "%s/%llu", S.node_spool, (unsigned long long)id);
    snprintf(name, sizeof name, "--job-name=meshcorr-%s-%llu", S.tag, (unsigned long long)id);
    snprintf(out, sizeof out, "--output=%s/" SPOOL_SLURM_OUT, dir);
    snprintf(cpus, sizeof cpus, "--cpus-per-task=%d", cf->slurm_cpus);
    char secret_path[CONF_PATH + 96];
    snprintf(secret_path, sizeof secret_path, "%s/" SPOOL_SECRET_FILE, dir);
    shq(q_worker, sizeof q_worker, worker);
    shq(q_dir, sizeof q_dir, dir);
    shq(q_sec, sizeof q_sec, secret_path);
    snprintf(wrap, sizeof wrap,
             "exec %s --job %s --job-id %llu --threads %d --max-vertices %u --max-faces %llu"
             " --progress-tcp %s:%d --secret-file %s",
             q_worker, q_dir, (unsigned long long)id, cf->slurm_cpus, cf->max_vertices, conf_max_faces(&d->conf),
             S.prog_host, S.prog_port, q_sec);
    char *argv[BK_SLURM_MAX_ARGS];
    int k = 0, o = 0;
    argv[k++] = "sbatch";
    argv[k++] = "--parsable";
    argv[k++] = name;
    argv[k++] = out;
    argv[k++] = cpus;
    argv[k++] = "--ntasks=1";
    argv[k++] = "--nodes=1";
    const struct { const char *flag, *v; } opts[] = {
        {"--partition", cf->slurm_partition}, {"--account", cf->slurm_account},
        {"--time", cf->slurm_time}, {"--mem", cf->slurm_mem}};
    for (size_t i = 0; i < 4; i++)
        if (opts[i].v[0]) {
            snprintf(opt[o], sizeof opt[o], "%s=%s", opts[i].flag, opts[i].v);
            argv[k++] = opt[o++];
        }
    char extra[CONF_PATH];
    snprintf(extra, sizeof extra, "%s", cf->slurm_extra);
    for (char *save = NULL, *t = strtok_r(extra, " \t", &save); t && k < BK_SLURM_MAX_ARGS - 4;
         t = strtok_r(NULL, " \t", &save))
        argv[k++] = t;
    argv[k++] = "--wrap";
    argv[k++] = wrap;
    argv[k] = NULL;
    uint64_t *ctx = malloc(sizeof *ctx);
    if (!ctx)
        return -1;
    *ctx = id;
    S.cmd_busy = 1;
    dlog(DLOG_DEBUG, "job %llu: sbatch ... --wrap \"%s\"", (unsigned long long)id, wrap);
    if (bk_cmd_run(d->loop, argv, BK_SLURM_CMD_TIMEOUT_MS, on_sbatch, ctx)) {
        S.cmd_busy = 0;
        free(ctx);
        return -1;
    }
    return 0;
}

/* ---- scancel ------------------------------------------------------------- */

static void on_scancel(void *ctx, int status, const char *out, const char *err)
{
    (void)out;
    uint64_t id = *(uint64_t *)ctx;
    free(ctx);
    S.cmd_busy = 0;
    if (status != 0)
        dlog(DLOG_WARN, "job %llu: scancel failed (exit %d): %s", (unsigned long long)id, status, err);
    if (!S.closing)
        step();
}

static int send_cancel(sjob *j)
{
    char *argv[] = {"scancel", j->slurm_id, NULL};
    uint64_t *ctx = malloc(sizeof *ctx);
    if (!ctx)
        return -1;
    *ctx = j->id;
    j->cancel_sent = 1;
    S.cmd_busy = 1;
    dlog(DLOG_INFO, "job %llu: scancel %s", (unsigned long long)j->id, j->slurm_id);
    if (bk_cmd_run(S.d->loop, argv, BK_SLURM_CMD_TIMEOUT_MS, on_scancel, ctx)) {
        S.cmd_busy = 0;
        free(ctx);
        return -1;
    }
    return 0;
}

/* ---- the driver ---------------------------------------------------------- */

/* Runs the next command if none runs: a cancel, a due listing, a submission. */
static void step(void)
{
    if (S.cmd_busy || S.closing)
        return;
    for (sjob *j = S.jobs; j; j = j->next)
        if (j->cancel && !j->cancel_sent && j->slurm_id[0]) {
            send_cancel(j);
            return;
        }
    if (S.err_tools[0])
        return;
    if (S.poll_due) {
        S.poll_due = 0;
        char *argv[] = {"squeue", "--me", "-h", "-t", "all", "-o", "%i|%T|%r|%j", NULL};
        S.cmd_busy = 1;
        if (bk_cmd_run(S.d->loop, argv, BK_SLURM_CMD_TIMEOUT_MS, on_squeue, NULL))
            S.cmd_busy = 0;
        return;
    }
    if (!S.listed_once || !usable() || S.err_sbatch[0] || S.d->draining || S.njobs >= S.d->conf.slurm_max_jobs)
        return;
    char user[AUTH_MAX_USER];
    uint64_t id = sched_next(S.d->sched, user);
    if (id)
        submit(id, user);
}

static void on_tick(uv_timer_t *t)
{
    (void)t;
    check_local();
    S.err_sbatch[0] = '\0';        /* a failed sbatch is retried once per period */
    for (sjob *j = S.jobs, *next; j; j = next) {
        next = j->next;
        read_progress_file(j);
        if (j->result_wait_until) {
            /* still waiting for result.frame after Slurm's COMPLETED */
            finish(j, "COMPLETED", "");
        }
    }
    S.poll_due = 1;
    step();
}

static const char *secret_of(void *ctx, uint64_t id)
{
    (void)ctx;
    sjob *j = find(id);
    return j && j->secret[0] ? j->secret : NULL;
}

static int reattach(void *ctx, const store_job *row)
{
    (void)ctx;
    sjob *j = add_job(row->id, row->user);
    if (!j)
        return 1;
    snprintf(j->slurm_id, sizeof j->slurm_id, "%s", row->slurm_id);
    j->progress_off = row->progress_off;
    j->running = row->state == PROTO_STATE_RUNNING;
    snprintf(j->reason, sizeof j->reason, "%.255s", row->reason);
    char path[CONF_PATH + 64];
    FILE *fp = fopen(spool_file(row->id, SPOOL_SECRET_FILE, path, sizeof path), "r");
    if (fp) {
        if (!fgets(j->secret, sizeof j->secret, fp))
            j->secret[0] = '\0';
        fclose(fp);
    }
    dlog(DLOG_INFO, "job %llu: re-attached to Slurm job %s (%s)", (unsigned long long)row->id, row->slurm_id,
         proto_state_name(row->state));
    return 0;
}

static int slurm_init(mcd *d, char *err, size_t errsz)
{
    const mcd_conf *cf = &d->conf;
    memset(&S, 0, sizeof S);
    S.d = d;
    store_spool_path(d->store, 0, NULL, S.spool, sizeof S.spool);
    char *slash = strrchr(S.spool, '/');   /* ".../spool/0" -> ".../spool" */
    if (slash)
        *slash = '\0';
    snprintf(S.node_spool, sizeof S.node_spool, "%s", cf->slurm_spool[0] ? cf->slurm_spool : S.spool);
    /* the job-name tag: FNV-1a of the state directory */
    uint32_t h = 2166136261u;
    for (const char *p = cf->state_dir; *p; p++)
        h = (h ^ (unsigned char)*p) * 16777619u;
    snprintf(S.tag, sizeof S.tag, "%08x", h);
    if (bk_prog_listen(d, cf->slurm_progress, secret_of, NULL, &S.prog, &S.prog_port, err, errsz))
        return -1;
    if (cf->slurm_progress_host[0]) {
        snprintf(S.prog_host, sizeof S.prog_host, "%.255s", cf->slurm_progress_host);
    } else {
        const char *colon = strrchr(cf->slurm_progress, ':');
        snprintf(S.prog_host, sizeof S.prog_host, "%.*s", (int)(colon - cf->slurm_progress), cf->slurm_progress);
        if (strcmp(S.prog_host, "0.0.0.0") == 0 || strcmp(S.prog_host, "::") == 0)
            gethostname(S.prog_host, sizeof S.prog_host - 1);
    }
    if (store_each_slurm(d->store, reattach, NULL))
        return snprintf(err, errsz, "slurm: cannot read the jobs already in Slurm from the store"), -1;
    check_local();
    if (S.err_tools[0])
        dlog(DLOG_ERROR, "slurm: %s: jobs stay PENDING until it is installed", S.err_tools);
    if (S.err_spool[0])
        dlog(DLOG_ERROR, "slurm: %s: jobs stay PENDING", S.err_spool);
    uv_timer_init(d->loop, &S.timer);
    S.timer_open = 1;
    uv_timer_start(&S.timer, on_tick, 0, cf->slurm_poll_ms);
    dlog(DLOG_INFO, "slurm backend: %d job(s) re-attached, at most %d in Slurm, spool %s (nodes: %s),"
         " job names meshcorr-%s-<id>", S.njobs, cf->slurm_max_jobs, S.spool, S.node_spool, S.tag);
    return 0;
}

static void slurm_schedule(mcd *d)
{
    (void)d;
    step();
}

static int slurm_cancel(mcd *d, uint64_t id)
{
    (void)d;
    sjob *j = find(id);
    if (!j)
        return -1;
    j->cancel = 1;
    step();
    return 0;
}

/* Slurm jobs run on without the daemon; the next start re-attaches. */
static void slurm_drain(mcd *d, mcd_idle_fn idle)
{
    (void)d;
    (void)idle;                   /* busy() is 0: nothing to wait for */
    if (S.njobs)
        dlog(DLOG_INFO, "slurm: %d job(s) stay in Slurm; the next start re-attaches to them", S.njobs);
}

static int slurm_busy(const mcd *d)
{
    (void)d;
    return 0;
}

static int slurm_nslots(const mcd *d)
{
    return d->conf.slurm_max_jobs;
}

static void slurm_slot_info(const mcd *d, int i, uint8_t *state, uint64_t *job_id)
{
    (void)d;
    sjob *j = S.jobs;
    for (int k = 0; j && k < i; k++)
        j = j->next;
    *state = !j ? PROTO_SLOT_IDLE : j->running ? PROTO_SLOT_BUSY : PROTO_SLOT_STARTING;
    *job_id = j ? j->id : 0;
}

static void slurm_close(mcd *d)
{
    (void)d;
    S.closing = 1;
    if (S.timer_open)
        uv_close((uv_handle_t *)&S.timer, NULL);
    S.timer_open = 0;
    bk_prog_close(S.prog);
    S.prog = NULL;
    while (S.jobs)
        drop_job(S.jobs);
}

/* slurm-max-jobs is the slot count (the snapshot, STATS and the Modbus
 * registers are sized from it at start); the progress listener, the spool
 * paths and the poll timer are set up once too. The sbatch options
 * (partition, account, time, cpus, mem, extra, worker) are read at each
 * submission: a reload applies them to the next one. */
static void slurm_keep_on_reload(const mcd *d, mcd_conf *n, char *changed, size_t sz)
{
    const mcd_conf *o = &d->conf;
    conf_note_change(n->slurm_max_jobs != o->slurm_max_jobs, "slurm-max-jobs", changed, sz);
    conf_note_change(n->slurm_poll_ms != o->slurm_poll_ms, "slurm-poll-ms", changed, sz);
    conf_note_change(strcmp(n->slurm_spool, o->slurm_spool) != 0, "slurm-spool", changed, sz);
    conf_note_change(strcmp(n->slurm_progress, o->slurm_progress) != 0, "slurm-progress", changed, sz);
    conf_note_change(strcmp(n->slurm_progress_host, o->slurm_progress_host) != 0, "slurm-progress-host",
                   changed, sz);
    n->slurm_max_jobs = o->slurm_max_jobs;
    n->slurm_poll_ms = o->slurm_poll_ms;
    memcpy(n->slurm_spool, o->slurm_spool, sizeof n->slurm_spool);
    memcpy(n->slurm_progress, o->slurm_progress, sizeof n->slurm_progress);
    memcpy(n->slurm_progress_host, o->slurm_progress_host, sizeof n->slurm_progress_host);
}

const bk_ops bk_slurm = {
    "slurm", slurm_init, slurm_schedule, slurm_cancel, slurm_drain, slurm_busy,
    slurm_nslots, slurm_slot_info, slurm_health, slurm_close, slurm_keep_on_reload,
};
