/* cli_remote.c — the `meshcorr` subcommands that talk to meshcorrd through
 * libmeshcorr: submit, status, watch, result, cancel, delete, list, stats.
 * They share the server options (--server ADDR, --token T, --token-file F,
 * --ca FILE; defaults $MESHCORR_SERVER or MC_DEFAULT_SERVER, the socket the
 * shipped config listens on, $MESHCORR_TOKEN, and $MESHCORR_CA, read by
 * libmeshcorr; a bare path is a Unix socket) and print one line per fact,
 * or JSON where asked. A failed connect says what to do about it. No
 * numerics, no protocol details: meshcorr.h is the whole interface. Every
 * string the server sends (labels, user names, reasons, messages, device
 * names) reaches the terminal through shown() or json_str, which escape
 * control characters, escape sequences and bidi marks (stresc). */
#include "cli/cli.h"
#include "metric/metric.h"
#include "cli/cli_job.h"
#include "cli/cli_progress.h"
#include "lmk/lmk.h"
#include "map/bmap.h"
#include "mesh/draco_bridge.h"
#include "mesh/mesh.h"
#include "meshcorr.h"
#include "util/stresc.h"

#include <ctype.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

/* s, a string from the server, as the terminal may show it (stresc). The
 * result lives until the fourth call after this one (four buffers in
 * turn: enough for the strings of one line). */
static const char *shown(const char *s)
{
    static char bufs[4][STRESC_SIZE(2048)];
    static unsigned next;
    char *b = bufs[next++ % 4];
    return stresc(s, b, sizeof bufs[0]);
}

/* A message or a reason from the server (its lines apart, as a job's
 * checks write them: "X is not usable by the optimizer:\nX: ...") as the
 * terminal may show it: each line through stresc, the lines after the
 * first indented. Labels and names stay on one line (shown). */
static const char *shown_lines(const char *s)
{
    static char buf[STRESC_SIZE(4096) + 1024];
    size_t o = 0;
    buf[0] = '\0';
    for (const char *p = s; p && o + 1 < sizeof buf;) {
        const char *nl = strchr(p, '\n');
        size_t n = nl ? (size_t)(nl - p) : strlen(p);
        stresc_n(p, n, buf + o, sizeof buf - o);
        o += strlen(buf + o);
        if (!nl)
            break;
        o += (size_t)snprintf(buf + o, o < sizeof buf ? sizeof buf - o : 0, "\n  ");
        p = nl + 1;
    }
    return buf;
}

typedef struct remote {
    const char *server, *token;
    const char *token_file;    /* when set, the token is this file's first line */
    const char *ca;            /* --ca: the CA file a tls: server's certificate must chain to */
    char addr[4200];           /* server as an address mc_connect takes */
} remote;

static void remote_defaults(remote *r)
{
    r->server = getenv("MESHCORR_SERVER");
    r->token = getenv("MESHCORR_TOKEN");
    r->token_file = NULL;
    r->ca = NULL;
    if (!r->server || !*r->server)
        r->server = MC_DEFAULT_SERVER;
}

/* The address of r->server: unix:PATH and tcp:HOST:PORT as they are; a
 * bare path (one that starts with / or ., or holds no ':') as unix:PATH. */
static const char *remote_address(remote *r)
{
    const char *s = r->server;
    int path = s[0] == '/' || s[0] == '.' || !strchr(s, ':');
    snprintf(r->addr, sizeof r->addr, "%s%s", path ? "unix:" : "", s);
    return r->addr;
}

/* The token in a --token-file: its first line, without the line end. */
static int read_token_file(const char *cmd, const char *path, char *tok, size_t toksz)
{
    FILE *fp = fopen(path, "r");
    if (!fp) {
        fprintf(stderr, "meshcorr %s: --token-file %s: cannot open\n", cmd, path);
        return -1;
    }
    if (!fgets(tok, (int)toksz, fp))
        tok[0] = '\0';
    fclose(fp);
    tok[strcspn(tok, "\r\n")] = '\0';
    if (!tok[0]) {
        fprintf(stderr, "meshcorr %s: --token-file %s: no token on the first line\n", cmd, path);
        return -1;
    }
    return 0;
}

/* The words of a failed connect: what failed, then what to do. */
static void connect_failed(const char *cmd, const char *addr, int rc, const char *err, const remote *r,
                           const char *token)
{
    size_t al = strlen(addr);
    if (strncmp(err, addr, al) == 0 && strncmp(err + al, ": ", 2) == 0)
        err += al + 2;                       /* libmeshcorr's detail starts with the address */
    err = shown(err);                        /* the server's words may be part of it */
    int has_token = token && *token;
    if (rc == MC_ECONNECT)
        fprintf(stderr, "meshcorr %s: cannot connect to %s: %s (is meshcorrd running there? set "
                "MESHCORR_SERVER or --server)\n", cmd, addr, err);
    else if (rc == MC_EADDRESS) {
        const char *colon = strrchr(r->server, ':');
        int hostport = colon && colon[1] && strspn(colon + 1, "0123456789") == strlen(colon + 1);
        if (hostport)
            fprintf(stderr, "meshcorr %s: %s; did you mean tls:%s (or tcp:%s on loopback)?\n", cmd, err,
                    shown(r->server), shown(r->server));
        else
            fprintf(stderr, "meshcorr %s: %s\n", cmd, err);
    } else if (rc == MC_EUNAUTHORIZED && !has_token && strncmp(addr, "unix:", 5) != 0)
        fprintf(stderr, "meshcorr %s: %s needs a token: --token T, --token-file F or MESHCORR_TOKEN "
                "(the server said: %s)\n", cmd, addr, err);
    else if (rc == MC_EUNAUTHORIZED)
        fprintf(stderr, "meshcorr %s: %s refused %s: %s\n", cmd, addr,
                !has_token ? "this Unix user" : r->token_file ? "the token (from --token-file)"
                                                             : "the token (from --token or $MESHCORR_TOKEN)", err);
    else
        fprintf(stderr, "meshcorr %s: %s: %s\n", cmd, addr, err);
}

static mc_client *remote_connect(const char *cmd, remote *r)
{
    mc_client *c = NULL;
    char err[1200], tok[1024];
    const char *token = r->token;
    if (r->token_file) {
        if (read_token_file(cmd, r->token_file, tok, sizeof tok))
            return NULL;
        token = tok;
    }
    const char *addr = remote_address(r);
    int rc = mc_connect_ca(addr, token, r->ca, &c, err, sizeof err);
    if (rc) {
        connect_failed(cmd, addr, rc, err, r, token);
        return NULL;
    }
    return c;
}

static int fail(const char *cmd, mc_client *c, int rc)
{
    fprintf(stderr, "meshcorr %s: %s\n", cmd, shown_lines(mc_errmsg(c)[0] ? mc_errmsg(c) : mc_strerror(rc)));
    mc_close(c);
    return 1;
}

static int parse_id(const char *cmd, const char *s, uint64_t *id)
{
    char *e;
    unsigned long long v = strtoull(s, &e, 10);
    if (!*s || *e || v == 0) {
        fprintf(stderr, "meshcorr %s: '%s' is not a job id\n", cmd, s);
        return -1;
    }
    *id = v;
    return 0;
}

/* Options every remote subcommand takes; 1 when handled. */
enum { O_SERVER = 1000, O_TOKEN, O_TOKEN_FILE, O_CA };
#define REMOTE_OPTS {"server", required_argument, 0, O_SERVER}, {"token", required_argument, 0, O_TOKEN}, \
                    {"token-file", required_argument, 0, O_TOKEN_FILE}, {"ca", required_argument, 0, O_CA}
#define REMOTE_NOPTS 4
#define REMOTE_USAGE "         [--server ADDR] [--token T | --token-file F] [--ca FILE]\n"

/* The last of --token and --token-file wins; either overrides $MESHCORR_TOKEN. */
static int remote_opt(remote *r, int c)
{
    if (c == O_SERVER) r->server = optarg;
    else if (c == O_TOKEN) r->token = optarg, r->token_file = NULL;
    else if (c == O_TOKEN_FILE) r->token_file = optarg;
    else if (c == O_CA) r->ca = optarg;
    else return 0;
    return 1;
}

/* s as a JSON string, quotes included; what stresc would escape is written
 * as \\uXXXX (a byte that is not UTF-8 as U+FFFD). */
static void json_str(const char *s)
{
    putchar('"');
    for (size_t i = 0, n = strlen(s), len; i < n; i += len) {
        uint32_t cp;
        int ok = stresc_char(s + i, n - i, &len, &cp);
        if (s[i] == '"' || s[i] == '\\')
            printf("\\%c", s[i]);
        else if (ok)
            fwrite(s + i, 1, len, stdout);
        else if (cp >= 0x80 && len == 1)
            printf("\\ufffd");
        else
            printf("\\u%04x", (unsigned)cp);
    }
    putchar('"');
}

/* A record from libmeshcorr as the wire's, for cli_progress. */
static void record_of(const mc_progress *m, proto_progress *p)
{
    memset(p, 0, sizeof *p);
    p->job_id = m->job_id;
    p->stage = (uint8_t)m->stage;
    p->outer = m->outer;
    p->total = m->total;
    for (int d = 0; d < 2; d++) {
        p->inner[d] = m->inner[d];
        p->terms[d][PROTO_TERM_MEMBRANE] = m->membrane[d];
        p->terms[d][PROTO_TERM_BENDING] = m->bending[d];
        p->terms[d][PROTO_TERM_MISMATCH] = m->mismatch[d];
        p->terms[d][PROTO_TERM_REVERSE] = m->reverse[d];
        p->terms[d][PROTO_TERM_ENERGY] = m->energy[d];
    }
    p->beta = m->beta;
    p->gamma = m->gamma;
    p->elapsed_s = m->elapsed_s;
    p->fraction = m->fraction;
    p->eta_s = m->eta_s;
    p->ahead = m->ahead;
}

/* ,"quality":..,"flipped":..,"collapsed":.. of a job (null when not known). */
static void print_quality_json(const mc_quality *q)
{
    printf(",\"quality\":\"%s\",\"quality_verdict\":%d", mc_quality_name(q->verdict), q->verdict);
    printf(isfinite(q->flipped) ? ",\"flipped\":%.9g" : ",\"flipped\":null", q->flipped);
    printf(isfinite(q->collapsed) ? ",\"collapsed\":%.9g" : ",\"collapsed\":null", q->collapsed);
}

static mc_map_row *rows_of(const bmap *P)
{
    mc_map_row *r = malloc((size_t)P->n * sizeof *r + 1);
    for (int i = 0; r && i < P->n; i++) {
        r[i].face = (uint32_t)P->face[i];
        memcpy(r[i].w, &P->w[3 * i], sizeof r[i].w);
    }
    return r;
}

typedef struct watch_opts { long from; int mode, progress_given; } watch_opts;

/* --from K and --progress auto|bar|text|json; -1 after the usage error. */
static int watch_opt(const char *cmd, int c, void *ctx)
{
    watch_opts *w = ctx;
    char *e;
    if (c == 'f') {
        w->from = strtol(optarg, &e, 10);
        if (!*optarg || *e || w->from < 0 || w->from > UINT32_MAX)
            return cli_usage_error(cmd, "--from: '%s' is not an outer iteration in [0, %u]", optarg,
                                   UINT32_MAX), -1;
    } else if (c == 'p') {
        if (cli_progress_parse(optarg, &w->mode) || w->mode == CLI_PROGRESS_NONE)
            return cli_usage_error(cmd, "--progress: '%s' is not auto, bar, text or json", optarg), -1;
        w->progress_given = 1;
    }
    return 0;
}

static int on_progress(void *ctx, const mc_progress *m)
{
    proto_progress p;
    record_of(m, &p);
    cli_progress_print(stdout, ((watch_opts *)ctx)->mode, &p, 1);
    return 0;
}

/* Follows job id on c to its end (c is closed); exit status 0 when it
 * COMPLETED; else the state and reason on stderr and the status of its
 * error kind (proto_kind.h): the one its reason names, else CANCELLED's
 * for a cancelled job and NOMEM's for one out of memory; 1 for any other
 * end (a timeout, a crash). */
static int watch_job(const char *cmd, mc_client *c, uint64_t id, watch_opts *w)
{
    int state = -1;
    char reason[1100];
    w->mode = cli_progress_resolve(w->mode, stdout);
    int rc = mc_watch(c, id, (uint32_t)w->from, on_progress, w, &state, reason, sizeof reason);
    cli_progress_end(stdout, w->mode);
    if (rc)
        return fail(cmd, c, rc);
    mc_close(c);
    if (state == MC_COMPLETED) {
        printf("job %llu COMPLETED\n", (unsigned long long)id);
        return 0;
    }
    fflush(stdout);
    fprintf(stderr, "meshcorr %s: job %llu %s%s%s\n", cmd, (unsigned long long)id,
            mc_state_name(state) ? mc_state_name(state) : "?", reason[0] ? ": " : "", shown_lines(reason));
    int kind = proto_kind_of_code(mc_reason_error(reason));
    if (!kind && state == MC_CANCELLED)
        kind = PROTO_KIND_CANCELLED;
    if (!kind && state == MC_OUT_OF_MEMORY)
        kind = PROTO_KIND_NOMEM;
    return kind ? proto_kind_exit(kind) : 1;
}

static int is_drc(const char *path)
{
    size_t n = strlen(path);
    return n > 4 && strcasecmp(path + n - 4, ".drc") == 0;
}

/* The job parameters of a parsed job into the spec, one per row of the list
 * (meshes, landmarks and maps are added by the caller). */
static void spec_of_job(const cli_job *j, mc_job_spec *s)
{
#define SPEC_PARAM(name, cli, type, ...) s->name = j->w.name;
    PROTO_PARAMS(SPEC_PARAM)
#undef SPEC_PARAM
}

/* The command line of submit. */
typedef struct submit_opts {
    remote r;
    mc_job_spec spec;            /* its parameters, priority and label */
    cli_job job;
    int watch, qbits;
    watch_opts w;
} submit_opts;

static void submit_usage(void)
{
    printf("usage: meshcorr submit SOURCE TARGET INPUTS [job options] [--priority N] [--label L]\n"
           "         [--quantization BITS] [--watch [--progress auto|bar|text|json]]\n" REMOTE_USAGE
           "prints the job id; with --watch then follows the job as `meshcorr watch` does\n"
           "(and exits as it: 0 when the job COMPLETED)\n"
           "Meshes go to the server lossless: it computes on exactly the positions read and\n"
           "returns the map `meshcorr match` gives. --quantization BITS (1-%d; 16 is Draco's\n"
           "usual) sends each coordinate quantized over the bounding box instead: a smaller\n"
           "upload, but the map differs from the local one. A .drc file is sent as it is.\n"
           "Job options:\n", MC_QUANTIZATION_MAX_BITS);
    cli_job_usage(stdout);
}

/* Reads and checks the command line, the job's parameters into o->spec:
 * -1 to go on, else the exit status (a usage error, --help). */
static int submit_options(int argc, char **argv, submit_opts *o)
{
    enum { O_PRIORITY = 1, O_LABEL, O_WATCH, O_PROGRESS, O_QUANTIZATION };
    static const struct option opts[] = {
        REMOTE_OPTS, CLI_JOB_OPTIONS,
        {"priority", required_argument, 0, O_PRIORITY}, {"label", required_argument, 0, O_LABEL},
        {"quantization", required_argument, 0, O_QUANTIZATION},
        {"watch", no_argument, 0, O_WATCH}, {"progress", required_argument, 0, O_PROGRESS},
        {"help", no_argument, 0, 'h'}, {0, 0, 0, 0}};
    remote_defaults(&o->r);
    mc_job_spec_init(&o->spec);
    cli_job_init(&o->job, argc, argv);
    o->watch = 0;
    o->qbits = MC_QUANTIZATION_LOSSLESS;
    o->w = (watch_opts){0, CLI_PROGRESS_AUTO, 0};
    int c;
    char *e;
    optind = 1;
    while ((c = cli_getopt("submit", argc, argv, opts)) != -1) {
        if (remote_opt(&o->r, c))
            continue;
        int jr = cli_job_option(&o->job, "submit", c, optarg);
        if (jr < 0)
            return cli_usage_see("submit");
        if (jr)
            continue;
        switch (c) {
        case O_PRIORITY:
            o->spec.priority = (int32_t)strtol(optarg, &e, 10);
            if (!*optarg || *e)
                return cli_usage_error("submit", "--priority: '%s' is not an integer", optarg);
            break;
        case O_LABEL: o->spec.label = optarg; break;
        case O_QUANTIZATION:
            o->qbits = (int)strtol(optarg, &e, 10);
            if (!*optarg || *e || o->qbits < 1 || o->qbits > MC_QUANTIZATION_MAX_BITS)
                return cli_usage_error("submit", "--quantization: '%s' is not a number of bits from 1 to %d",
                                       optarg, MC_QUANTIZATION_MAX_BITS);
            break;
        case O_WATCH: o->watch = 1; break;
        case O_PROGRESS:
            if (watch_opt("submit", 'p', &o->w))
                return CLI_EXIT_USAGE;
            break;
        case 'h': submit_usage(); return 0;
        default: return cli_usage_see("submit");
        }
    }
    if (argc - optind != 2)
        return cli_usage_error("submit", "need SOURCE and TARGET mesh files (%d given)", argc - optind);
    if (o->qbits != MC_QUANTIZATION_LOSSLESS && (is_drc(argv[optind]) || is_drc(argv[optind + 1])))
        return cli_usage_error("submit", "--quantization: a .drc file is sent as it is, with its own coding");
    if (!o->watch && o->w.progress_given)
        return cli_usage_error("submit", "--progress goes with --watch");
    if (cli_job_check(&o->job, "submit"))
        return cli_usage_see("submit");
    spec_of_job(&o->job, &o->spec);
    return -1;
}

/* The landmarks and the given maps into the spec, in *lm, *pr and *qr
 * (the caller frees them); -1 out of memory, with the message printed. */
static int spec_inputs(const lmk_set *L, const bmap *P0, const bmap *Q0, mc_job_spec *spec, uint32_t **lm,
                       mc_map_row **pr, mc_map_row **qr)
{
    if (L) {
        *lm = malloc(2 * sizeof **lm * (size_t)L->n + 1);
        for (int i = 0; *lm && i < L->n; i++) {
            (*lm)[2 * i] = (uint32_t)L->src[i];
            (*lm)[2 * i + 1] = (uint32_t)L->tgt[i];
        }
        spec->landmarks = *lm;
        spec->nlandmarks = (uint32_t)L->n;
    }
    if (P0) {
        spec->p = *pr = rows_of(P0);
        spec->np = (uint32_t)P0->n;
    }
    if (Q0) {
        spec->q = *qr = rows_of(Q0);
        spec->nq = (uint32_t)Q0->n;
    }
    if ((L && !*lm) || (P0 && !*pr) || (Q0 && !*qr)) {
        fprintf(stderr, "meshcorr submit: out of memory\n");
        return -1;
    }
    return 0;
}

int cli_submit(int argc, char **argv)
{
    submit_opts o;
    int status = submit_options(argc, argv, &o);
    if (status >= 0)
        return status;
    const char *src = argv[optind], *tgt = argv[optind + 1];
    char err[4096];
    status = 1;
    mesh *S = NULL, *T = NULL;
    lmk_set *L = NULL;
    bmap *P0 = NULL, *Q0 = NULL;
    mc_map_row *pr = NULL, *qr = NULL;
    uint32_t *lm = NULL;
    unsigned char *sb = NULL, *tb = NULL;
    mc_client *cl = NULL;
    if (mesh_read(src, &S, err, sizeof err) || mesh_read(tgt, &T, err, sizeof err)) {
        fprintf(stderr, "meshcorr submit: %s\n", err);
        goto done;
    }
    cli_job_note_polygons("submit", src, S);
    cli_job_note_polygons("submit", tgt, T);
    if (cli_job_load(&o.job, "submit", S, T, &L, &P0, &Q0))
        goto done;
    if (mc_encode_mesh_file_quantized(src, o.qbits, &sb, &o.spec.source_len, err, sizeof err) ||
        mc_encode_mesh_file_quantized(tgt, o.qbits, &tb, &o.spec.target_len, err, sizeof err)) {
        fprintf(stderr, "meshcorr submit: %s\n", err);
        goto done;
    }
    o.spec.source = sb;
    o.spec.target = tb;
    if (spec_inputs(L, P0, Q0, &o.spec, &lm, &pr, &qr))
        goto done;
    if (!(cl = remote_connect("submit", &o.r)))
        goto done;
    uint64_t id;
    int rc = mc_submit(cl, &o.spec, &id);
    if (rc) {
        fail("submit", cl, rc);
        if (rc == MC_EBAD_MESH)    /* the server names the meshes by their role */
            fprintf(stderr, "meshcorr submit: the source mesh is %s, the target mesh %s\n", src, tgt);
        cl = NULL;
        goto done;
    }
    printf("%llu\n", (unsigned long long)id);
    fflush(stdout);
    status = 0;
    if (o.watch) {
        status = watch_job("submit", cl, id, &o.w);
        cl = NULL;
    }
done:
    mc_close(cl);
    free(sb);
    free(tb);
    free(lm);
    free(pr);
    free(qr);
    lmk_free(L);
    bmap_free(P0);
    bmap_free(Q0);
    mesh_free(S);
    mesh_free(T);
    return status;
}

static void print_time(const char *what, int64_t ms)
{
    if (!ms)
        return;
    time_t t = (time_t)(ms / 1000);
    struct tm tm;
    char buf[64];
    localtime_r(&t, &tm);
    strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", &tm);
    printf("%-9s %s\n", what, buf);
}

/* Parses [--server A] [--token T] [extra...] ID for the one-id commands:
 * 0 parsed; 1 --help (usage printed on stdout: exit 0); -1 bad usage
 * (the one-line error printed: exit 2). on_extra handles the extra
 * options, -1 after printing its own usage error. */
static int one_id(const char *cmd, const char *usage, int argc, char **argv, remote *r, uint64_t *id,
                  const struct option *extra, int (*on_extra)(const char *, int, void *), void *ctx)
{
    struct option opts[16] = {REMOTE_OPTS, {"help", no_argument, 0, 'h'}};
    int n = REMOTE_NOPTS + 1;
    for (int i = 0; extra && extra[i].name && n < 15; i++)
        opts[n++] = extra[i];
    memset(&opts[n], 0, sizeof opts[n]);
    remote_defaults(r);
    int c;
    optind = 1;
    while ((c = cli_getopt(cmd, argc, argv, opts)) != -1) {
        if (remote_opt(r, c))
            continue;
        if (c == 'h') {
            fputs(usage, stdout);
            return 1;
        }
        if (c == '?' || !on_extra)
            return cli_usage_see(cmd), -1;
        if (on_extra(cmd, c, ctx))
            return -1;
    }
    if (argc - optind != 1)
        return cli_usage_error(cmd, "need one job id (%d given)", argc - optind), -1;
    if (parse_id(cmd, argv[optind], id))
        return cli_usage_see(cmd), -1;
    return 0;
}

/* v as a JSON number, null when it is not finite. */
static void json_num(double v)
{
    if (isfinite(v))
        printf("%.17g", v);
    else
        printf("null");
}

/* The quality as the Python package's dict: verdict name, fractions. */
static void print_quality_object(const mc_quality *q)
{
    printf("{\"verdict\":\"%s\",\"flipped\":", mc_quality_name(q->verdict));
    json_num(q->flipped);
    printf(",\"collapsed\":");
    json_num(q->collapsed);
    printf("}");
}

/* A progress record as the Python package's dict: the keys of `meshcorr
 * watch --progress json` and the sums `meshcorr watch` prints. */
static void print_progress_object(const mc_progress *p)
{
    const char *stage = proto_stage_name(p->stage);
    printf("{\"job\":%llu,\"stage\":\"%s\",\"outer\":%u,\"total\":%u,\"fraction\":",
           (unsigned long long)p->job_id, stage ? stage : "?", p->outer, p->total);
    json_num(p->fraction);
    printf(",\"eta\":");
    json_num(p->eta_s);
    printf(",\"elapsed\":");
    json_num(p->elapsed_s);
    printf(",\"ahead\":%u,\"beta\":", p->ahead);
    json_num(p->beta);
    printf(",\"gamma\":");
    json_num(p->gamma);
    static const char *names[2] = {"source", "target"};
    for (int d = 0; d < 2; d++) {
        const double t[5] = {p->membrane[d], p->bending[d], p->mismatch[d], p->reverse[d], p->energy[d]};
        static const char *terms[5] = {"membrane", "bending", "mismatch", "reverse", "energy"};
        printf(",\"%s\":{", names[d]);
        for (int k = 0; k < 5; k++) {
            printf("%s\"%s\":", k ? "," : "", terms[k]);
            json_num(t[k]);
        }
        printf(",\"inner\":%u}", p->inner[d]);
    }
    const double sum[5] = {p->membrane[0] + p->membrane[1], p->bending[0] + p->bending[1],
                           p->mismatch[0] + p->mismatch[1], p->reverse[0] + p->reverse[1],
                           p->energy[0] + p->energy[1]};
    static const char *terms[5] = {"membrane", "bending", "mismatch", "reverse", "energy"};
    for (int k = 0; k < 5; k++) {
        printf(",\"%s\":", terms[k]);
        json_num(sum[k]);
    }
    printf("}");
}

static int status_opt(const char *cmd, int c, void *ctx)
{
    (void)cmd;
    if (c == 'j')
        *(int *)ctx = 1;
    return 0;
}

int cli_status(int argc, char **argv)
{
    static const struct option extra[] = {{"json", no_argument, 0, 'j'}, {0, 0, 0, 0}};
    remote r;
    uint64_t id;
    int json = 0;
    int u = one_id("status", "usage: meshcorr status ID [--json]\n" REMOTE_USAGE
                   "--json: one object with the fields of the Python package's Job.status()\n",
                   argc, argv, &r, &id, extra, status_opt, &json);
    if (u)
        return u > 0 ? 0 : CLI_EXIT_USAGE;
    mc_client *c = remote_connect("status", &r);
    if (!c)
        return 1;
    mc_job_status s;
    int rc = mc_status(c, id, &s);
    if (rc)
        return fail("status", c, rc);
    if (json) {
        printf("{\"id\":%llu,\"state\":\"%s\",\"priority\":%d,\"user\":", (unsigned long long)s.job_id,
               mc_state_name(s.state) ? mc_state_name(s.state) : "?", s.priority);
        json_str(s.user);
        printf(",\"label\":");
        json_str(s.label);
        printf(",\"reason\":");
        json_str(s.reason);
        printf(",\"submit_ms\":%lld,\"start_ms\":%lld,\"end_ms\":%lld,\"progress\":", (long long)s.submit_ms,
               (long long)s.start_ms, (long long)s.end_ms);
        if (s.has_progress)
            print_progress_object(&s.progress);
        else
            printf("null");
        printf(",\"quality\":");
        print_quality_object(&s.quality);
        printf("}\n");
        mc_close(c);
        return 0;
    }
    printf("job       %llu\nstate     %s\nuser      %s\nlabel     %s\npriority  %d\n", (unsigned long long)s.job_id,
           mc_state_name(s.state), shown(s.user), shown(s.label), s.priority);
    if (s.reason[0])
        printf("reason    %s\n", shown_lines(s.reason));
    print_time("submitted", s.submit_ms);
    print_time("started", s.start_ms);
    print_time("ended", s.end_ms);
    if (s.has_progress) {
        proto_progress p;
        char share[64];
        record_of(&s.progress, &p);
        if (p.stage == PROTO_STAGE_QUEUED)
            printf("progress  %s\n", cli_progress_share(&p, share, sizeof share));
        else
            printf("progress  %s, %s %u/%u, energy %.10g, %.1f s\n", cli_progress_share(&p, share, sizeof share),
                   proto_stage_name(p.stage) ? proto_stage_name(p.stage) : "?", p.outer, p.total,
                   s.progress.energy[0] + s.progress.energy[1], s.progress.elapsed_s);
    }
    if (s.quality.verdict != MC_QUALITY_UNKNOWN)
        printf("quality   %s: %.2f %% flipped, %.2f %% collapsed\n", mc_quality_name(s.quality.verdict),
               100 * s.quality.flipped, 100 * s.quality.collapsed);
    mc_close(c);
    return 0;
}

int cli_watch(int argc, char **argv)
{
    static const struct option extra[] = {{"from", required_argument, 0, 'f'},
                                          {"progress", required_argument, 0, 'p'}, {0, 0, 0, 0}};
    remote r;
    uint64_t id;
    watch_opts w = {0, CLI_PROGRESS_AUTO, 0};
    static const char usage[] = "usage: meshcorr watch ID [--from K] [--progress auto|bar|text|json]\n"
                                REMOTE_USAGE
                                "its place in the queue while it waits, then one record per iteration:\n"
                                "the whole job's share done and time left, each term summed over both\n"
                                "directions (a bar on a terminal); exit 0 when the job COMPLETED, else\n"
                                "the status of its error kind (3 numeric, 4 memory, 5 cancelled; else 1)\n";
    int u = one_id("watch", usage, argc, argv, &r, &id, extra, watch_opt, &w);
    if (u)
        return u > 0 ? 0 : CLI_EXIT_USAGE;
    mc_client *c = remote_connect("watch", &r);
    if (!c)
        return 1;
    return watch_job("watch", c, id, &w);
}

typedef struct result_opts {
    const char *out, *out_rev, *out_def, *target, *rhm, *rhm_rev;
    int json;
} result_opts;

static int result_opt(const char *cmd, int c, void *ctx)
{
    (void)cmd;
    result_opts *o = ctx;
    if (c == 'o') o->out = optarg;
    else if (c == 'O') o->out_rev = optarg;
    else if (c == 'd') o->out_def = optarg;
    else if (c == 't') o->target = optarg;
    else if (c == 'j') o->json = 1;
    else if (c == 's') return cli_out_stage("result", optarg, &o->rhm, &o->rhm_rev);
    return 0;
}

static int write_map(const char *path, const mc_map_row *rows, uint32_t n, int nt, const char *comment)
{
    bmap *P = bmap_new((int)n, nt);
    char err[1024];
    if (!P) {
        fprintf(stderr, "meshcorr result: out of memory\n");
        return -1;
    }
    for (uint32_t i = 0; i < n; i++) {
        P->face[i] = (int)rows[i].face;
        memcpy(&P->w[3 * i], rows[i].w, sizeof rows[i].w);
    }
    int rc = bmap_write(path, P, comment, err, sizeof err);
    if (rc)
        fprintf(stderr, "meshcorr result: %s\n", err);
    bmap_free(P);
    return rc;
}

/* The deformed source of res, decoded from Draco, to path; -1 with the
 * message printed. */
static int write_deformed(const char *path, const mc_job_result *res)
{
    char err[1024];
    mesh Y = {0};
    int rc = 0;
    if (dracob_decode(res->deformed, res->deformed_len, MESH_MAX_VERTICES, MESH_MAX_FACES, &Y.v, &Y.nv,
                      &Y.f, &Y.nf, err, sizeof err) || mesh_write(path, &Y, err, sizeof err)) {
        fprintf(stderr, "meshcorr result: deformed mesh: %s\n", err);
        rc = -1;
    }
    free(Y.v);
    free(Y.f);
    return rc;
}

/* The files o asks for from job id's result res and RHM's maps st: the
 * maps (their target's vertex count from --target, else the reverse map's
 * rows) and the deformed source; -1 with the message printed. */
static int write_result_files(const result_opts *o, uint64_t id, const mc_job_result *res,
                              const mc_stage_maps *st)
{
    char comment[128], err[1024];
    snprintf(comment, sizeof comment, "meshcorrd job %llu", (unsigned long long)id);
    int nt = (int)res->nq;
    if (o->target) {
        mesh *T = NULL;
        if (mesh_read(o->target, &T, err, sizeof err)) {
            fprintf(stderr, "meshcorr result: %s\n", err);
            return -1;
        }
        nt = T->nv;
        mesh_free(T);
    }
    if (o->out && !nt) {
        fprintf(stderr, "meshcorr result: injective job: give --target MESH for the map's header\n");
        return -1;
    }
    if (o->out && write_map(o->out, res->p, res->np, nt, comment))
        return -1;
    if (o->out_rev && (!res->nq || write_map(o->out_rev, res->q, res->nq, (int)res->np, comment))) {
        if (!res->nq)
            fprintf(stderr, "meshcorr result: job %llu has no reverse map (injective)\n", (unsigned long long)id);
        return -1;
    }
    if ((o->rhm || o->rhm_rev) && !st->np) {
        fprintf(stderr, "meshcorr result: job %llu has no RHM map of its own (its chain did not run "
                "RHM then ECTM)\n", (unsigned long long)id);
        return -1;
    }
    char rcomment[160];
    snprintf(rcomment, sizeof rcomment, "meshcorrd job %llu: the reversible harmonic map ECTM started from",
             (unsigned long long)id);
    if (o->rhm && (!nt || write_map(o->rhm, st->p, st->np, nt, rcomment))) {
        if (!nt)
            fprintf(stderr, "meshcorr result: injective job: give --target MESH for the map's header\n");
        return -1;
    }
    if (o->rhm_rev && (!st->nq || write_map(o->rhm_rev, st->q, st->nq, (int)st->np, rcomment))) {
        if (!st->nq)
            fprintf(stderr, "meshcorr result: job %llu has no reverse RHM map (injective)\n",
                    (unsigned long long)id);
        return -1;
    }
    if (o->out_def && write_deformed(o->out_def, res))
        return -1;
    return 0;
}

/* Job id's metrics on stdout, one `name value` a line or (--json) one
 * object with the files written, and the worse map's quality warning on
 * stderr. */
static void print_result_metrics(const result_opts *o, uint64_t id, const mc_job_result *res)
{
    double verdict = 0, fl[2] = {0, 0}, co[2] = {0, 0};
    if (o->json)
        printf("{\"id\":%llu,\"metrics\":{", (unsigned long long)id);
    for (uint32_t i = 0; i < res->nmetrics; i++) {
        const char *k = res->metric_keys[i];
        double v = res->metric_values[i];
        if (o->json) {
            printf("%s", i ? "," : "");
            json_str(k);
            putchar(':');
            json_num(v);
        } else {
            printf("%s %.10g\n", shown(k), v);
        }
        if (!strcmp(k, "quality_verdict"))
            verdict = v;
        for (int d = 0; d < 2; d++) {
            if (!strcmp(k, d ? "reverse_flipped_fraction" : "flipped_fraction"))
                fl[d] = v;
            if (!strcmp(k, d ? "reverse_collapsed_fraction" : "collapsed_fraction"))
                co[d] = v;
        }
    }
    if (o->json) {
        printf("},\"p_rows\":%u,\"q_rows\":%u", res->np, res->nq);
        const char *const files[3][2] = {{"out", o->out}, {"out_reverse", o->out_rev}, {"out_deformed", o->out_def}};
        for (int f = 0; f < 3; f++) {
            printf(",\"%s\":", files[f][0]);
            if (files[f][1])
                json_str(files[f][1]);
            else
                printf("null");
        }
        printf("}\n");
    }
    if (verdict > 0) {
        /* the worse of the two maps, by the worker's rule */
        int d = metric_verdict(fl[1], co[1]) > metric_verdict(fl[0], co[0]);
        char text[256];
        metric_verdict_text((int)verdict, fl[d], co[d], text, sizeof text);
        fprintf(stderr, "meshcorr result: warning: job %llu: %s%s\n", (unsigned long long)id,
                d ? "the reverse map: " : "", text);
    }
}

int cli_result(int argc, char **argv)
{
    static const struct option extra[] = {
        {"out", required_argument, 0, 'o'}, {"out-reverse", required_argument, 0, 'O'},
        {"out-deformed", required_argument, 0, 'd'}, {"target", required_argument, 0, 't'},
        {"json", no_argument, 0, 'j'}, {"out-stage", required_argument, 0, 's'}, {0, 0, 0, 0}};
    remote r;
    uint64_t id;
    result_opts o = {0};
    static const char usage[] = "usage: meshcorr result ID --out P.map [--out-reverse Q.map] [--out-deformed Y.ply]\n"
                                "         [--out-stage rhm=R.map] [--out-stage rhm-reverse=RQ.map]\n"
                                "         [--target MESH (injective jobs: the target's vertex count for P.map)]\n"
                                "         [--json]\n" REMOTE_USAGE
                                "prints the job's metrics, one `name value` a line; --json: one object\n"
                                "{\"id\", \"metrics\": {name: value}, \"p_rows\", \"q_rows\", the files written}\n"
                                "(with --json the map files are optional)\n";
    int u = one_id("result", usage, argc, argv, &r, &id, extra, result_opt, &o);
    if (u)
        return u > 0 ? 0 : CLI_EXIT_USAGE;
    if (!o.out && !o.out_rev && !o.out_def && !o.json && !o.rhm && !o.rhm_rev)
        return cli_usage_error("result", "need --out P.map (or --out-reverse, --out-deformed, "
                               "--out-stage, --json)");
    if (cli_output_check("result", "--out", o.out) || cli_output_check("result", "--out-reverse", o.out_rev) ||
        cli_output_check("result", "--out-deformed", o.out_def) ||
        cli_output_check("result", "--out-stage rhm", o.rhm) ||
        cli_output_check("result", "--out-stage rhm-reverse", o.rhm_rev))
        return CLI_EXIT_USAGE;
    mc_client *c = remote_connect("result", &r);
    if (!c)
        return 1;
    mc_job_result res;
    mc_stage_maps st = {0};
    unsigned what = MC_WANT_METRICS | (o.out || o.out_rev || o.json || o.rhm ? MC_WANT_P | MC_WANT_Q : 0) |
                    (o.out_def ? MC_WANT_DEFORMED : 0);
    int rc = mc_result(c, id, what, &res), status = 1;
    if (rc)
        return fail("result", c, rc);
    if ((o.rhm || o.rhm_rev) && (rc = mc_result_stage(c, id, "rhm", &st))) {
        mc_result_free(&res);
        return fail("result", c, rc);
    }
    if (write_result_files(&o, id, &res, &st))
        goto done;
    print_result_metrics(&o, id, &res);
    status = 0;
done:
    mc_result_free(&res);
    mc_stage_maps_free(&st);
    mc_close(c);
    return status;
}

static int simple(const char *cmd, const char *usage, int argc, char **argv, int (*fn)(mc_client *, uint64_t),
                  const char *done)
{
    remote r;
    uint64_t id;
    int u = one_id(cmd, usage, argc, argv, &r, &id, NULL, NULL, NULL);
    if (u)
        return u > 0 ? 0 : CLI_EXIT_USAGE;
    mc_client *c = remote_connect(cmd, &r);
    if (!c)
        return 1;
    int rc = fn(c, id);
    if (rc)
        return fail(cmd, c, rc);
    printf("job %llu %s\n", (unsigned long long)id, done);
    mc_close(c);
    return 0;
}

int cli_cancel(int argc, char **argv)
{
    return simple("cancel", "usage: meshcorr cancel ID\n" REMOTE_USAGE, argc, argv, mc_cancel, "cancelled");
}

int cli_delete(int argc, char **argv)
{
    return simple("delete", "usage: meshcorr delete ID\n" REMOTE_USAGE, argc, argv, mc_delete, "deleted");
}

/* A LIST row's progress column: how many jobs are ahead, or "next", while
 * it waits (as watch says), the percentage done while it runs and once
 * COMPLETED, else "-". */
static const char *list_progress(const mc_job_info *j, char *buf, size_t sz)
{
    if (j->state == MC_PENDING && j->ahead)
        snprintf(buf, sz, "%u ahead", j->ahead);
    else if (j->state == MC_PENDING)
        snprintf(buf, sz, "next");
    else if (j->state == MC_COMPLETED)
        snprintf(buf, sz, "100 %%");
    else if (j->state == MC_RUNNING && isfinite(j->fraction))
        snprintf(buf, sz, "%.0f %%", 100 * j->fraction);
    else
        snprintf(buf, sz, "-");
    return buf;
}

/* --state S: a state's bit, or -1 after the usage error naming the states. */
static int state_bit(const char *arg)
{
    int s = mc_state_parse(arg);
    if (s >= 0)
        return s;
    const char *names[16];
    int n = 0;
    for (; n < 16 && mc_state_name(n); n++)
        names[n] = mc_state_name(n);
    char up[64], buf[256], all[256] = "";
    snprintf(up, sizeof up, "%s", arg);
    for (char *p = up; *p; p++)
        *p = (char)toupper((unsigned char)*p);
    const char *sg = cli_suggest(up, names, n, "", buf, sizeof buf);
    for (int i = 0, o = 0; i < n; i++)
        o += snprintf(all + o, sizeof all - (size_t)o, "%s%s", i ? ", " : "", names[i]);
    if (sg)
        cli_usage_error("list", "--state: '%s' is not a job state; did you mean %s?", arg, sg);
    else
        cli_usage_error("list", "--state: '%s' is not a job state (%s)", arg, all);
    return -1;
}

int cli_list(int argc, char **argv)
{
    static const struct option opts[] = {REMOTE_OPTS, {"state", required_argument, 0, 's'},
                                         {"user", required_argument, 0, 'u'}, {"json", no_argument, 0, 'j'},
                                         {"help", no_argument, 0, 'h'}, {0, 0, 0, 0}};
    static const char usage[] = "usage: meshcorr list [--state S]... [--user U] [--json]\n" REMOTE_USAGE
                                "your jobs; an admin's: every user's (--user U: only U's)\n"
                                "--json: one array of job objects\n";
    remote r;
    remote_defaults(&r);
    int json = 0;
    uint32_t mask = 0;
    const char *user = NULL;
    int c;
    optind = 1;
    while ((c = cli_getopt("list", argc, argv, opts)) != -1) {
        if (remote_opt(&r, c))
            continue;
        if (c == 's') {
            int s = state_bit(optarg);
            if (s < 0)
                return CLI_EXIT_USAGE;
            mask |= 1u << s;
        } else if (c == 'u') {
            user = optarg;
        } else if (c == 'j') {
            json = 1;
        } else if (c == 'h') {
            fputs(usage, stdout);
            return 0;
        } else {
            return cli_usage_see("list");
        }
    }
    if (optind != argc)
        return cli_usage_error("list", "unexpected argument '%s'", argv[optind]);
    mc_client *cl = remote_connect("list", &r);
    if (!cl)
        return 1;
    if (!user && mc_is_admin(cl))
        user = MC_LIST_ALL_USERS;          /* an admin sees everyone's jobs */
    mc_job_info *jobs;
    uint32_t n;
    int rc = mc_list(cl, user, mask, &jobs, &n);
    if (rc)
        return fail("list", cl, rc);
    if (json) {
        printf("[");
        for (uint32_t i = 0; i < n; i++) {
            printf("%s{\"id\":%llu,\"state\":\"%s\",\"user\":", i ? ",\n " : "",
                   (unsigned long long)jobs[i].job_id, mc_state_name(jobs[i].state));
            json_str(jobs[i].user);
            printf(",\"priority\":%d,\"submit_ms\":%lld,\"outer\":%u,\"total\":%u,\"label\":", jobs[i].priority,
                   (long long)jobs[i].submit_ms, jobs[i].outer, jobs[i].total);
            json_str(jobs[i].label);
            print_quality_json(&jobs[i].quality);
            printf(isfinite(jobs[i].fraction) ? ",\"fraction\":%.6g" : ",\"fraction\":null", jobs[i].fraction);
            printf(isfinite(jobs[i].eta_s) ? ",\"eta\":%.3f" : ",\"eta\":null", jobs[i].eta_s);
            printf(",\"ahead\":%u}", jobs[i].ahead);
        }
        printf("]\n");
        free(jobs);
        mc_close(cl);
        return 0;
    }
    printf("%-8s %-13s %-10s %4s %11s %-8s %-10s %s\n", "ID", "STATE", "USER", "PRIO", "ITER", "QUALITY",
           "PROGRESS", "LABEL");
    for (uint32_t i = 0; i < n; i++) {
        char it[32], pg[32];
        snprintf(it, sizeof it, "%u/%u", jobs[i].outer, jobs[i].total);
        int v = jobs[i].quality.verdict;
        printf("%-8llu %-13s %-10s %4d %11s %-8s %-10s %s\n", (unsigned long long)jobs[i].job_id,
               mc_state_name(jobs[i].state), shown(jobs[i].user), jobs[i].priority, it,
               v == MC_QUALITY_UNKNOWN ? "-" : mc_quality_name(v), list_progress(&jobs[i], pg, sizeof pg),
               shown(jobs[i].label));
    }
    free(jobs);
    mc_close(cl);
    return 0;
}

int cli_stats(int argc, char **argv)
{
    static const struct option opts[] = {REMOTE_OPTS, {"json", no_argument, 0, 'j'}, {"help", no_argument, 0, 'h'},
                                         {0, 0, 0, 0}};
    remote r;
    remote_defaults(&r);
    int c, json = 0;
    optind = 1;
    while ((c = cli_getopt("stats", argc, argv, opts)) != -1) {
        if (remote_opt(&r, c))
            continue;
        if (c == 'h') {
            fputs("usage: meshcorr stats [--json]\n" REMOTE_USAGE, stdout);
            return 0;
        }
        if (c != 'j')
            return cli_usage_see("stats");
        json = 1;
    }
    if (optind != argc)
        return cli_usage_error("stats", "unexpected argument '%s'", argv[optind]);
    mc_client *cl = remote_connect("stats", &r);
    if (!cl)
        return 1;
    mc_server_stats s;
    int rc = mc_stats(cl, &s);
    if (rc)
        return fail("stats", cl, rc);
    static const char *slot[] = {"idle", "starting", "busy", "draining"};
    if (json) {
        printf("{\"queued\":%u,\"running\":%u,\"workers\":%u,\"completed\":%llu,\"failed\":%llu,"
               "\"cancelled\":%llu,\"slots\":[", s.queued, s.running, s.workers, (unsigned long long)s.completed,
               (unsigned long long)s.failed, (unsigned long long)s.cancelled);
        for (uint32_t i = 0; i < s.nslots; i++)
            printf("%s{\"state\":\"%s\",\"job\":%llu}", i ? "," : "", slot[s.slot_state[i] & 3],
                   (unsigned long long)s.slot_job[i]);
        printf("],\"devices\":[");
        for (uint32_t i = 0; i < s.ndevices; i++) {
            printf("%s", i ? "," : "");
            json_str(s.devices[i]);
        }
        printf("]}\n");
        mc_stats_free(&s);
        mc_close(cl);
        return 0;
    }
    printf("queued    %u\nrunning   %u\nworkers   %u\ncompleted %llu\nfailed    %llu\ncancelled %llu\n", s.queued,
           s.running, s.workers, (unsigned long long)s.completed, (unsigned long long)s.failed,
           (unsigned long long)s.cancelled);
    for (uint32_t i = 0; i < s.nslots; i++)
        printf("slot %u    %s%s%.0llu\n", i, slot[s.slot_state[i] & 3], s.slot_job[i] ? " job " : "",
               (unsigned long long)s.slot_job[i]);
    for (uint32_t i = 0; i < s.ndevices; i++)
        printf("device    %s\n", shown(s.devices[i]));
    mc_stats_free(&s);
    mc_close(cl);
    return 0;
}
