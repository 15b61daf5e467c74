/* conf.c — meshcorrd's options: defaults, the command line and the config
 * file (`key = value` lines, the same keys as the long options). One table
 * lists every option once; nothing here opens sockets or the store. */
#include "mcd.h"
#include "util/errbuf.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int conf_load_file(mcd_conf *c, const char *path, char *err, size_t errsz);
#include <unistd.h>

enum kind { K_PATH, K_LISTEN, K_U32, K_INT, K_LONG, K_LEVEL, K_CONFIG, K_ENDPOINT, K_FLAG };

#define OFF(f) offsetof(mcd_conf, f)
static const struct option_def {
    const char *name;
    enum kind kind;
    size_t off;
    long long min, max;   /* numeric range */
    const char *help;
} options[] = {
    {"listen", K_LISTEN, 0, 0, 0, "unix:PATH | tls:HOST:PORT | tcp:HOST:PORT (repeatable; PORT 0 = any free port; tcp: loopback only)"},
    {"tls-cert", K_PATH, OFF(tls_cert), 0, 0, "FILE PEM certificate chain for tls: listeners and HTTPS --metrics"},
    {"tls-key", K_PATH, OFF(tls_key), 0, 0, "FILE PEM private key of --tls-cert"},
    {"insecure-tcp", K_FLAG, OFF(insecure_tcp), 0, 1, "let a tcp: listener bind a non-loopback address (tokens in clear)"},
    {"state-dir", K_PATH, OFF(state_dir), 0, 0, "DIR: jobs.db and spool/ (required)"},
    {"workers", K_INT, OFF(workers), 1, 1024, "N worker slots (default 1)"},
    {"config", K_CONFIG, 0, 0, 0, "FILE of `key = value` lines, read where it appears"},
    {"tokens", K_PATH, OFF(tokens), 0, 0, "FILE of `sha256:HEX user [admin]` lines (TCP users; `meshcorrd token new`)"},
    {"worker", K_PATH, OFF(worker), 0, 0, "PATH of meshcorr-worker (default: next to meshcorrd)"},
    {"validator", K_PATH, OFF(validator), 0, 0, "PATH of meshcorr-validate, SUBMIT's check (default: next to meshcorrd)"},
    {"threads-per-worker", K_INT, OFF(threads_per_worker), 0, 4096, "N OpenMP threads per worker (0: all)"},
    {"worker-memory-mb", K_U32, OFF(worker_memory_mb), 0, 1u << 24, "MB of address space per worker (default 3/4 of the memory over --workers; 0: no limit)"},
    {"user", K_PATH, OFF(user), 0, 0, "USER to run as after binding the listeners (required when started as root)"},
    {"max-frame", K_U32, OFF(max_frame), PROTO_HDR_SIZE + 1, PROTO_MAX_FRAME, "BYTES largest request frame"},
    {"max-vertices", K_U32, OFF(max_vertices), 3, 20000000, "N vertices per mesh"},
    {"max-landmarks", K_U32, OFF(max_landmarks), 0, PROTO_MAX_LANDMARKS, "N landmark pairs per job"},
    {"max-jobs-per-user", K_U32, OFF(max_jobs_per_user), 1, 1000000, "N unfinished jobs per user"},
    {"max-queue", K_U32, OFF(max_queue), 1, 10000000, "N pending jobs in all"},
    {"job-timeout", K_U32, OFF(job_timeout_s), 1, 100000000, "SECONDS of wall time per job"},
    {"result-ttl", K_U32, OFF(result_ttl_s), 1, 100000000, "SECONDS a finished job is kept"},
    {"max-output", K_U32, OFF(max_output), 4096, 1u << 31, "BYTES queued to one client before a watcher is dropped"},
    {"max-request-memory", K_U32, OFF(max_request_memory), 65536, 0xFFFFFFFFu, "BYTES of request frames being received from all clients at once (default 1 GiB)"},
    {"max-request-memory-per-user", K_U32, OFF(max_request_memory_per_user), 0, 0xFFFFFFFFu, "BYTES of request frames being received from one user (default 0: a quarter of max-request-memory)"},
    {"max-bytes-per-user", K_LONG, OFF(max_bytes_per_user), 1, LONG_MAX, "BYTES of spool one user's jobs and results may take (default 2 GiB)"},
    {"max-spool-bytes", K_LONG, OFF(max_spool_bytes), 0, LONG_MAX, "BYTES of spool all jobs may take (default 0: 80 % of the state file system)"},
    {"max-watches-per-session", K_U32, OFF(max_watches_per_session), 1, 1000000, "N live WATCHes of one connection (default 64)"},
    {"max-result-sends", K_U32, OFF(max_result_sends), 1, 1000000, "N RESULT replies read or sent at once, all clients (default 16)"},
    {"max-result-sends-per-user", K_U32, OFF(max_result_sends_per_user), 1, 1000000, "N RESULT replies read or sent at once to one user (default 4)"},
    {"max-connections", K_U32, OFF(max_connections), 1, 1000000, "N sessions of non-admin users in all (default 512)"},
    {"max-connections-per-user", K_U32, OFF(max_connections_per_user), 1, 1000000, "N sessions of one user, admins exempt (default 64)"},
    {"max-unauthenticated", K_U32, OFF(max_unauthenticated), 1, 1000000, "N TCP connections before HELLO (default 64)"},
    {"max-unauthenticated-per-address", K_U32, OFF(max_unauth_per_address), 1, 1000000, "N of them from one address, IPv6 /64 or local uid (default 8)"},
    {"admin-reserve", K_U32, OFF(admin_reserve), 0, 1000000, "N descriptors beyond fd-reserve only the Unix socket and admins use (default 32)"},
    {"hello-timeout", K_U32, OFF(hello_timeout_s), 0, 86400, "SECONDS from connect to HELLO (default 10; 0 none)"},
    {"request-timeout", K_U32, OFF(request_timeout_s), 0, 86400, "SECONDS a request frame may take to arrive (default 300; 0 none)"},
    {"idle-timeout", K_U32, OFF(idle_timeout_s), 0, 100000000, "SECONDS a session with nothing going on is kept (default 600; 0 forever)"},
    {"fd-reserve", K_U32, OFF(fd_reserve), 0, 1000000, "N descriptors kept free for workers (default 0: 32 + 4 per slot)"},
    {"admin-uid", K_LONG, OFF(admin_uid), -1, INT_MAX, "UID treated as admin on the Unix socket (root always is)"},
    {"port-file", K_PATH, OFF(port_file), 0, 0, "FILE to write the bound tcp: and tls:HOST:PORT addresses to"},
    {"log-level", K_LEVEL, OFF(log_level), 0, 0, "error|warn|info|debug (default info)"},
    {"modbus", K_ENDPOINT, OFF(modbus), 0, 0, "[HOST:]PORT Modbus TCP status registers (off; 1502 suits; host 127.0.0.1)"},
    {"metrics", K_ENDPOINT, OFF(metrics), 0, 0, "[HOST:]PORT Prometheus GET /metrics over HTTP, HTTPS with --tls-cert (off; host 127.0.0.1)"},
    {"backend", K_PATH, OFF(backend), 0, 0, "local|slurm: where jobs run (default local)"},
    {"slurm-partition", K_PATH, OFF(slurm_partition), 0, 0, "NAME sbatch --partition (default: Slurm's)"},
    {"slurm-account", K_PATH, OFF(slurm_account), 0, 0, "NAME sbatch --account"},
    {"slurm-time", K_PATH, OFF(slurm_time), 0, 0, "LIMIT sbatch --time, e.g. 2:00:00"},
    {"slurm-cpus", K_INT, OFF(slurm_cpus), 1, 4096, "N sbatch --cpus-per-task and worker threads (default 1)"},
    {"slurm-mem", K_PATH, OFF(slurm_mem), 0, 0, "SIZE sbatch --mem, e.g. 8G"},
    {"slurm-max-jobs", K_INT, OFF(slurm_max_jobs), 1, 1000000, "N jobs handed to Slurm at once (default 100)"},
    {"slurm-extra", K_PATH, OFF(slurm_extra), 0, 0, "ARGS more sbatch arguments, split on blanks"},
    {"slurm-spool", K_PATH, OFF(slurm_spool), 0, 0, "DIR <state-dir>/spool as the nodes see it"},
    {"slurm-worker", K_PATH, OFF(slurm_worker), 0, 0, "PATH of meshcorr-worker on the nodes"},
    {"slurm-progress", K_PATH, OFF(slurm_progress), 0, 0, "HOST:PORT the workers' progress listener binds (default 127.0.0.1:0)"},
    {"slurm-progress-host", K_PATH, OFF(slurm_progress_host), 0, 0, "HOST the workers connect to (default: the bind host, or this host's name)"},
    {"slurm-poll-ms", K_U32, OFF(slurm_poll_ms), 50, 3600000, "MS between squeue polls (default 5000)"},
};
#define NOPTIONS (sizeof options / sizeof options[0])

void conf_init(mcd_conf *c)
{
    memset(c, 0, sizeof *c);
    c->workers = 1;
    c->max_frame = PROTO_DEFAULT_MAX_FRAME;
    c->max_vertices = CONF_DEFAULT_MAX_VERTICES;
    c->max_landmarks = PROTO_MAX_LANDMARKS;
    c->max_jobs_per_user = CONF_DEFAULT_MAX_JOBS_PER_USER;
    c->max_queue = CONF_DEFAULT_MAX_QUEUE;
    c->job_timeout_s = CONF_DEFAULT_JOB_TIMEOUT_S;
    c->worker_memory_mb = CONF_WORKER_MEMORY_AUTO;
    c->result_ttl_s = CONF_DEFAULT_RESULT_TTL_S;
    c->max_output = CONF_DEFAULT_MAX_OUTPUT;
    c->max_request_memory = CONF_DEFAULT_MAX_REQUEST_MEMORY;
    c->max_bytes_per_user = CONF_DEFAULT_MAX_BYTES_PER_USER;
    c->max_watches_per_session = CONF_DEFAULT_MAX_WATCHES_PER_SESSION;
    c->max_result_sends = CONF_DEFAULT_MAX_RESULT_SENDS;
    c->max_result_sends_per_user = CONF_DEFAULT_MAX_RESULT_SENDS_PER_USER;
    c->max_connections = CONF_DEFAULT_MAX_CONNECTIONS;
    c->max_connections_per_user = CONF_DEFAULT_MAX_CONNECTIONS_PER_USER;
    c->max_unauthenticated = CONF_DEFAULT_MAX_UNAUTHENTICATED;
    c->max_unauth_per_address = CONF_DEFAULT_MAX_UNAUTH_PER_ADDRESS;
    c->admin_reserve = CONF_DEFAULT_ADMIN_RESERVE;
    c->hello_timeout_s = CONF_DEFAULT_HELLO_TIMEOUT_S;
    c->request_timeout_s = CONF_DEFAULT_REQUEST_TIMEOUT_S;
    c->idle_timeout_s = CONF_DEFAULT_IDLE_TIMEOUT_S;
    c->admin_uid = -1;
    c->log_level = DLOG_INFO;
    c->modbus.port = c->metrics.port = -1;
    strcpy(c->backend, "local");
    c->slurm_cpus = 1;
    c->slurm_max_jobs = CONF_DEFAULT_SLURM_MAX_JOBS;
    strcpy(c->slurm_progress, "127.0.0.1:0");   /* a cluster's nodes need it set */
    c->slurm_poll_ms = CONF_DEFAULT_SLURM_POLL_MS;
}

void conf_usage(FILE *fp)
{
    fprintf(fp, "usage: meshcorrd --state-dir DIR --listen ADDR [options]\n"
                "       meshcorrd token new USER [--admin] | token hash [USER [--admin]] < TOKEN\n"
                "       meshcorrd --version\n\noptions (also `key = value` in --config):\n");
    for (size_t i = 0; i < NOPTIONS; i++)
        fprintf(fp, "  --%-20s %s\n", options[i].name, options[i].help);
}

static int set_path(char *dst, const char *name, const char *v, char *err, size_t errsz)
{
    if (strlen(v) >= CONF_PATH)
        return errbuf_set(err, errsz, -1, "--%s: path longer than %d bytes", name, CONF_PATH - 1);
    strcpy(dst, v);
    return 0;
}

/* "PORT", "HOST:PORT" or "[V6]:PORT"; HOST is kept as given. */
static int set_endpoint(conf_endpoint *e, const char *name, const char *v, char *err, size_t errsz)
{
    const char *colon = strrchr(v, ':'), *port = colon ? colon + 1 : v;
    const char *host = v;
    size_t hlen = colon ? (size_t)(colon - v) : 0;
    if (hlen >= 2 && host[0] == '[' && host[hlen - 1] == ']') {
        host++;
        hlen -= 2;
    }
    char *e2;
    errno = 0;
    long n = strtol(port, &e2, 10);
    if (!*port || *e2 || errno || n < 1 || n > 65535 || (colon && hlen == 0) || hlen >= CONF_HOST)
        return errbuf_set(err, errsz, -1, "--%s: '%s' is not PORT or HOST:PORT (PORT in [1, 65535])", name, v);
    if (colon) {
        memcpy(e->host, host, hlen);
        e->host[hlen] = '\0';
    } else {
        strcpy(e->host, "127.0.0.1");
    }
    e->port = (int)n;
    return 0;
}

int conf_set(mcd_conf *c, const char *key, const char *v, char *err, size_t errsz)
{
    const struct option_def *o = NULL;
    for (size_t i = 0; i < NOPTIONS; i++)
        if (strcmp(options[i].name, key) == 0)
            o = &options[i];
    if (!o)
        return errbuf_set(err, errsz, -1, "unknown option '%s'", key);
    char *field = (char *)c + o->off;
    switch (o->kind) {
    case K_PATH:
        return set_path(field, o->name, v, err, errsz);
    case K_LISTEN:
        if (c->nlisten == CONF_MAX_LISTEN)
            return errbuf_set(err, errsz, -1, "--listen: more than %d addresses", CONF_MAX_LISTEN);
        if (strncmp(v, "unix:", 5) != 0 && strncmp(v, "tcp:", 4) != 0 && strncmp(v, "tls:", 4) != 0)
            return errbuf_set(err, errsz, -1, "--listen: '%s' is not unix:PATH, tls:HOST:PORT or tcp:HOST:PORT", v);
        return set_path(c->listen[c->nlisten++], o->name, v, err, errsz);
    case K_CONFIG:
        return conf_load_file(c, v, err, errsz);
    case K_ENDPOINT:
        return set_endpoint((conf_endpoint *)field, o->name, v, err, errsz);
    case K_FLAG:
        if (!strcmp(v, "1") || !strcmp(v, "yes") || !strcmp(v, "true"))
            *(int *)field = 1;
        else if (!strcmp(v, "0") || !strcmp(v, "no") || !strcmp(v, "false"))
            *(int *)field = 0;
        else
            return errbuf_set(err, errsz, -1, "--%s: '%s' is not yes or no (1 or 0)", o->name, v);
        return 0;
    case K_LEVEL: {
        static const char *names[] = {"error", "warn", "info", "debug"};
        for (int i = 0; i < 4; i++)
            if (strcmp(v, names[i]) == 0) {
                c->log_level = i;
                return 0;
            }
        return errbuf_set(err, errsz, -1, "--log-level: '%s' is not error, warn, info or debug", v);
    }
    default: {
        char *e;
        errno = 0;
        long long n = strtoll(v, &e, 10);
        if (*v == '\0' || *e != '\0' || errno || n < o->min || n > o->max)
            return errbuf_set(err, errsz, -1, "--%s: '%s' is not an integer in [%lld, %lld]",
                              o->name, v, o->min, o->max);
        if (o->kind == K_U32)
            *(uint32_t *)field = (uint32_t)n;
        else if (o->kind == K_INT)
            *(int *)field = (int)n;
        else
            *(long *)field = (long)n;
        return 0;
    }
    }
}

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    char *e = s + strlen(s);
    while (e > s && isspace((unsigned char)e[-1]))
        *--e = '\0';
    return s;
}

static int conf_load_file(mcd_conf *c, const char *path, char *err, size_t errsz)
{
    FILE *fp = fopen(path, "r");
    if (!fp)
        return errbuf_set(err, errsz, -1, "%s: %s", path, strerror(errno));
    char line[CONF_PATH + 128], sub[512];
    int lineno = 0, rc = 0;
    while (!rc && fgets(line, sizeof line, fp)) {
        lineno++;
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        char *s = trim(line);
        if (!*s)
            continue;
        char *eq = strchr(s, '=');
        if (!eq) {
            rc = errbuf_set(err, errsz, -1, "%s:%d: expected `key = value`", path, lineno);
            break;
        }
        *eq = '\0';
        if ((rc = conf_set(c, trim(s), trim(eq + 1), sub, sizeof sub)))
            errbuf_set(err, errsz, rc, "%s:%d: %s", path, lineno, sub);
    }
    fclose(fp);
    return rc;
}

static int is_flag(const char *key)
{
    for (size_t i = 0; i < NOPTIONS; i++)
        if (strcmp(options[i].name, key) == 0)
            return options[i].kind == K_FLAG;
    return 0;
}

int conf_parse_args(mcd_conf *c, int argc, char **argv, char *err, size_t errsz)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0)
            return 1;
        if (strncmp(a, "--", 2) != 0)
            return errbuf_set(err, errsz, -1, "unexpected argument '%s'", a);
        char key[64];
        const char *eq = strchr(a, '='), *val;
        size_t klen = eq ? (size_t)(eq - a - 2) : strlen(a + 2);
        if (klen >= sizeof key)
            return errbuf_set(err, errsz, -1, "unknown option '%s'", a);
        memcpy(key, a + 2, klen);
        key[klen] = '\0';
        if (eq) {
            val = eq + 1;
        } else if (is_flag(key)) {
            val = "1";                 /* --insecure-tcp alone turns it on */
        } else {
            if (i + 1 >= argc)
                return errbuf_set(err, errsz, -1, "--%s needs a value", key);
            val = argv[++i];
        }
        if (conf_set(c, key, val, err, errsz))
            return -1;
    }
    if (!c->state_dir[0])
        return errbuf_set(err, errsz, -1, "--state-dir is required");
    if (c->nlisten == 0)
        return errbuf_set(err, errsz, -1, "at least one --listen address is required");
    if (strcmp(c->backend, "local") != 0 && strcmp(c->backend, "slurm") != 0)
        return errbuf_set(err, errsz, -1, "--backend: '%s' is not local or slurm", c->backend);
    return 0;
}

/* set, or name next to meshcorrd (the name alone when that cannot be read) */
static const char *next_to_daemon(const char *set, const char *name, char *buf, size_t sz)
{
    if (set[0])
        return set;
    size_t len = strlen(name) + 1;
    ssize_t n = sz > len ? readlink("/proc/self/exe", buf, sz - len) : -1;
    if (n <= 0)
        return name;
    buf[n] = '\0';
    char *slash = strrchr(buf, '/');
    memcpy(slash ? slash + 1 : buf, name, len);
    return buf;
}

const char *conf_worker_path(const mcd_conf *c, char *buf, size_t sz)
{
    return next_to_daemon(c->worker, "meshcorr-worker", buf, sz);
}

const char *conf_validator_path(const mcd_conf *c, char *buf, size_t sz)
{
    return next_to_daemon(c->validator, "meshcorr-validate", buf, sz);
}

unsigned long long conf_max_faces(const mcd_conf *c)
{
    unsigned long long mf = 4ull * c->max_vertices;
    return mf > 40000000 ? 40000000 : mf;
}

uint32_t conf_worker_memory_mb(const mcd_conf *c, int nslots)
{
    if (c->worker_memory_mb != CONF_WORKER_MEMORY_AUTO)
        return c->worker_memory_mb;
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    double mb = pages > 0 && page > 0 ? (double)pages * (double)page / (1 << 20) : 0;
    mb = mb * CONF_WORKER_MEMORY_SHARE / (nslots > 0 ? nslots : 1);
    if (mb < CONF_WORKER_MEMORY_MIN_MB)
        mb = CONF_WORKER_MEMORY_MIN_MB;
    return mb > (1u << 24) ? 1u << 24 : (uint32_t)mb;
}

int conf_credential_path(const char *what, const char *path, char *out, size_t sz, char *err, size_t errsz)
{
    static const char var[] = "${CREDENTIALS_DIRECTORY}";
    if (strncmp(path, var, sizeof var - 1) != 0) {
        if ((size_t)snprintf(out, sz, "%s", path) >= sz)
            return errbuf_set(err, errsz, -1, "%s %s: the path is too long", what, path);
        return 0;
    }
    const char *creds = getenv("CREDENTIALS_DIRECTORY");
    if (!creds || !*creds)
        return errbuf_set(err, errsz, -1, "%s %s: $CREDENTIALS_DIRECTORY is not set (systemd sets it for a "
                          "unit with LoadCredential=)", what, path);
    if ((size_t)snprintf(out, sz, "%s%s", creds, path + sizeof var - 1) >= sz)
        return errbuf_set(err, errsz, -1, "%s %s: the path is too long", what, path);
    return 0;
}

void conf_note_change(int differs, const char *name, char *changed, size_t sz)
{
    size_t len = strlen(changed);
    if (differs && len + 1 < sz)
        snprintf(changed + len, sz - len, "%s%s", len ? ", " : "", name);
}
