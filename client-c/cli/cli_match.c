/* cli_match.c — `meshcorr match`: the in-process engine on two mesh files.
 * Reads and validates the inputs, runs the pipeline (workers/corr: the
 * stages of --stages: DDM, RHM, ECTM), writes the maps and optional meshes, and shows
 * progress (bar on a terminal, text lines, or JSON lines on stderr). Holds
 * no numerics. */
#include "cli/cli.h"
#include "cli/cli_job.h"
#include "cli/cli_progress.h"
#include "util/ompenv.h"
#include "corr/corr.h"
#include "lmk/lmk.h"
#include "map/bmap.h"
#include "metric/metric.h"
#include "mesh/mesh.h"

#include <getopt.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MATCH_MAX_THREADS 4096   /* --threads: more is a typo, not a machine */

static void usage(FILE *fp)
{
    fprintf(fp,
        "usage: meshcorr match SOURCE TARGET INPUTS --out P.map [--out-reverse Q.map]\n"
        "         [--out-deformed Y.ply] [--out-remeshed T.ply] [--out-stage rhm=P.map]\n"
        "         [--out-stage rhm-reverse=Q.map] [--stages CHAIN]\n"
        "         [--log-eps E] [--threads N] [--progress auto|bar|text|json|none] [job options]\n"
        "--stages rhm stops after RHM and writes its maps; --stages ectm runs ECTM alone\n"
        "(needs --init); --init P.map --stages ddm,ectm denoises the given map by DDM, then\n"
        "refines it by ECTM. --out-stage rhm=FILE writes RHM's map too, on a chain RHM then\n"
        "ECTM (rhm-reverse=FILE: its reverse, bijective model). Job options:\n");
    cli_job_usage(fp);
}

/* Each stage report as the wire's record, shown as `meshcorr watch` shows
 * a job's (cli_progress.h). */
static int on_progress(void *ctx, const corr_progress *cp)
{
    proto_progress rec;
    corr_progress_record(cp, &rec);
    cli_progress_print(stderr, *(const int *)ctx, &rec, 0);
    return 0;
}

/* Reads a mesh and refuses one the job cannot use before any other input
 * is read, so the user hears about the mesh first: with repair, one no
 * repair fixes (repair_mesh_check); without, one the optimizer cannot use
 * as given. */
static mesh *load(const char *path, int repair, int *status)
{
    char err[4096];
    mesh *m = NULL;
    int rc = corr_from_mesh(mesh_read(path, &m, err, sizeof err));
    if (!rc)
        rc = repair ? corr_from_repair(repair_mesh_check(m, path, err, sizeof err))
                    : corr_validate(m, path, err, sizeof err);
    if (rc) {
        fprintf(stderr, "meshcorr match: %s\n", err);
        mesh_free(m);
        *status = proto_kind_exit(-rc);
        return NULL;
    }
    cli_job_note_polygons("match", path, m);
    return m;
}

/* What the repair did to each mesh, one line per kind (stderr). */
static void print_repairs(const corr_fix *fx, const char *src, const char *tgt)
{
    char text[2048], prefix[4200];
    snprintf(prefix, sizeof prefix, "meshcorr match: %s: repaired", src);
    if (repair_counts_text(&fx->S.n, prefix, text, sizeof text))
        fputs(text, stderr);
    snprintf(prefix, sizeof prefix, "meshcorr match: %s: repaired", tgt);
    if (repair_counts_text(&fx->T.n, prefix, text, sizeof text))
        fputs(text, stderr);
}

/* One map's quality line on stdout (the worker's metrics, on the pair the
 * engine ran), with the verdict's warning (whose: its prefix) on stderr;
 * -1 out of memory. */
static int print_quality(const char *what, const char *whose, const mesh *S, const mesh *T,
                         const bmap *P)
{
    metric_summary ms;
    if (metric_summarize(S, T, P, &ms)) {
        fprintf(stderr, "meshcorr match: out of memory\n");
        return -1;
    }
    printf("%s: flipped %.2f %%, collapsed %.2f %%, mean |log area| %.4f, median conformal "
           "%.4f\n", what, 100 * ms.flipped_fraction, 100 * ms.collapsed_fraction,
           ms.mean_abs_log_area, ms.median_conformal);
    int verdict = metric_verdict(ms.flipped_fraction, ms.collapsed_fraction);
    if (verdict) {
        char text[256];
        metric_verdict_text(verdict, ms.flipped_fraction, ms.collapsed_fraction, text, sizeof text);
        fprintf(stderr, "meshcorr match: warning: %s%s\n", whose, text);
    }
    return 0;
}

static int write_mesh_with(const char *path, const mesh *faces_of, const double *v, int nv)
{
    char err[1024];
    mesh out = { nv, faces_of->nf, (double *)v, faces_of->f, 0 };
    if (mesh_write(path, &out, err, sizeof err)) {
        fprintf(stderr, "meshcorr match: %s\n", err);
        return -1;
    }
    return 0;
}

/* The command line of match. */
typedef struct match_opts {
    const char *out, *out_rev, *out_def, *out_rem, *out_rhm, *out_rhm_rev;
    cli_job job;
    ectm_params pe;
    rhm_params rp;
    double log_eps;
    int threads, progress;
    corr_chain stages;
    int ectm_last;              /* the chain ends with ECTM */
} match_opts;

/* Reads the options: -1 to go on, else the exit status (a usage error,
 * --help). */
static int parse_options(int argc, char **argv, match_opts *o)
{
    enum { O_OUT = 1, O_OUT_REVERSE, O_OUT_DEFORMED, O_OUT_REMESHED, O_LOG_EPS,
           O_THREADS, O_PROGRESS, O_OUT_STAGE };
    static const struct option opts[] = {
        CLI_JOB_OPTIONS,
        {"out", required_argument, 0, O_OUT},        {"out-reverse", required_argument, 0, O_OUT_REVERSE},
        {"out-deformed", required_argument, 0, O_OUT_DEFORMED},
        {"out-remeshed", required_argument, 0, O_OUT_REMESHED},
        {"out-stage", required_argument, 0, O_OUT_STAGE},
        {"log-eps", required_argument, 0, O_LOG_EPS},
        {"threads", required_argument, 0, O_THREADS}, {"progress", required_argument, 0, O_PROGRESS},
        {"help", no_argument, 0, 'h'},              {0, 0, 0, 0}};
    memset(o, 0, sizeof *o);
    cli_job_init(&o->job, argc, argv);
    ectm_params_init(&o->pe);               /* log_eps and threads: match's own options */
    o->log_eps = o->pe.log_eps;
    o->progress = CLI_PROGRESS_AUTO;
    int c;
    char *e;
    optind = 1;
    while ((c = cli_getopt("match", argc, argv, opts)) != -1) {
        int r = cli_job_option(&o->job, "match", c, optarg);
        if (r < 0)
            return cli_usage_see("match");
        if (r)
            continue;
        switch (c) {
        case O_OUT: o->out = optarg; break;
        case O_OUT_REVERSE: o->out_rev = optarg; break;
        case O_OUT_DEFORMED: o->out_def = optarg; break;
        case O_OUT_REMESHED: o->out_rem = optarg; break;
        case O_OUT_STAGE:
            if (cli_out_stage("match", optarg, &o->out_rhm, &o->out_rhm_rev))
                return CLI_EXIT_USAGE;
            break;
        case O_LOG_EPS:
            o->log_eps = strtod(optarg, &e);
            if (!*optarg || *e || !(o->log_eps > 0) || !isfinite(o->log_eps))
                return cli_usage_error("match", "--log-eps: '%s' is not a number > 0", optarg);
            break;
        case O_THREADS:
            o->threads = (int)strtol(optarg, &e, 10);
            if (!*optarg || *e || o->threads < 0 || o->threads > MATCH_MAX_THREADS)
                return cli_usage_error("match", "--threads: '%s' is not an integer in [0, %d] (0: by the "
                                       "pair's size)", optarg, MATCH_MAX_THREADS);
            break;
        case O_PROGRESS:
            if (cli_progress_parse(optarg, &o->progress))
                return cli_usage_error("match", "--progress: '%s' is not auto, bar, text, json or none",
                                       optarg);
            break;
        case 'h': usage(stdout); return 0;
        default: return cli_usage_see("match");
        }
    }
    return -1;
}

/* Checks the options together, the job's and the outputs included, and
 * sets the engine's parameters: 0, else the exit status of a usage
 * error. */
static int check_options(int argc, match_opts *o)
{
    if (argc - optind != 2)
        return cli_usage_error("match", "need SOURCE and TARGET mesh files (%d given)", argc - optind);
    if (!o->out)
        return cli_usage_error("match", "need --out P.map");
    if (cli_job_check(&o->job, "match") || cli_job_engine(&o->job, "match", o->threads, &o->pe, &o->rp))
        return cli_usage_see("match");
    o->pe.log_eps = o->log_eps;
    o->stages = (corr_chain)o->job.w.stages;
    o->ectm_last = corr_chain_run(o->stages, !!o->job.init) & CORR_RUN_ECTM;
    if (!o->ectm_last && o->out_def)
        return cli_usage_error("match", "--out-deformed needs the ECTM stage (the deformation is ECTM's)");
    if (o->pe.model == ECTM_INJECTIVE && o->out_rev)
        return cli_usage_error("match", "--out-reverse needs the bijective model");
    unsigned run = corr_chain_run(o->stages, !!o->job.init);
    if ((o->out_rhm || o->out_rhm_rev) && (run & (CORR_RUN_RHM | CORR_RUN_ECTM)) !=
                                              (CORR_RUN_RHM | CORR_RUN_ECTM))
        return cli_usage_error("match", "--out-stage rhm needs a chain that runs RHM then ECTM "
                               "(stages all from landmarks, rhm,ectm or ddm,rhm,ectm); with "
                               "--stages rhm, --out is RHM's map");
    if (o->pe.model == ECTM_INJECTIVE && o->out_rhm_rev)
        return cli_usage_error("match", "--out-stage rhm-reverse needs the bijective model");
    if (cli_output_check("match", "--out", o->out) || cli_output_check("match", "--out-reverse", o->out_rev) ||
        cli_output_check("match", "--out-deformed", o->out_def) ||
        cli_output_check("match", "--out-remeshed", o->out_rem) ||
        cli_output_check("match", "--out-stage rhm", o->out_rhm) ||
        cli_output_check("match", "--out-stage rhm-reverse", o->out_rhm_rev))
        return CLI_EXIT_USAGE;
    return 0;
}

/* The maps of res (in the user's indexing: RHM's too when asked) with a
 * comment saying what made them, the deformed source and the remeshed
 * source, each where its option asks; -1 with the message printed. */
static int write_outputs(const match_opts *o, const char *src, const char *tgt, const mesh *S,
                         const mesh *T, const ectm_result *res)
{
    char err[1024], comment[512];
    char chain[64] = "";
    proto_param_value_name(PROTO_P_stages, (unsigned)o->stages, chain, sizeof chain);
    if (!o->ectm_last)
        snprintf(comment, sizeof comment, "meshcorr match %s -> %s, stages %s (%s)", src, tgt, chain,
                 corr_chain_run(o->stages, !!o->job.init) & CORR_RUN_RHM ? "reversible harmonic map"
                                                                          : "DDM-denoised map");
    else
        snprintf(comment, sizeof comment,
                 "meshcorr match %s -> %s, %s model, %d iterations, final energy %.10g",
                 src, tgt, o->pe.model == ECTM_BIJECTIVE ? "bijective" : "injective",
                 res->last.outer, res->last.energy);
    if (bmap_write(o->out, res->P, comment, err, sizeof err) ||
        (o->out_rev && res->Q && bmap_write(o->out_rev, res->Q, comment, err, sizeof err))) {
        fprintf(stderr, "meshcorr match: %s\n", err);
        return -1;
    }
    if (o->out_rhm || o->out_rhm_rev) {
        char rc_comment[600];
        snprintf(rc_comment, sizeof rc_comment, "meshcorr match %s -> %s, stages %s: the reversible "
                 "harmonic map ECTM started from", src, tgt, chain);
        if ((o->out_rhm && bmap_write(o->out_rhm, res->rhm_P, rc_comment, err, sizeof err)) ||
            (o->out_rhm_rev && bmap_write(o->out_rhm_rev, res->rhm_Q, rc_comment, err, sizeof err))) {
            fprintf(stderr, "meshcorr match: %s\n", err);
            return -1;
        }
    }
    if (o->out_def && write_mesh_with(o->out_def, S, res->Y, S->nv))
        return -1;
    if (o->out_rem) {
        double *pt = malloc(sizeof(double) * 3 * (size_t)S->nv + 1);
        if (!pt) {
            fprintf(stderr, "meshcorr match: out of memory\n");
            return -1;
        }
        bmap_apply(res->P, T->f, T->v, 3, pt);
        int w = write_mesh_with(o->out_rem, S, pt, S->nv);
        free(pt);
        if (w)
            return -1;
    }
    return 0;
}

int cli_match(int argc, char **argv)
{
    match_opts o;
    int status = parse_options(argc, argv, &o);
    if (status >= 0)
        return status;
    if ((status = check_options(argc, &o)))
        return status;
    char err[1024];
    int progress = cli_progress_resolve(o.progress, stderr);

    status = 1;
    mesh *S = NULL, *T = NULL;
    bmap *P0 = NULL, *Q0 = NULL;
    lmk_set *L = NULL;
    ectm_result res = {0}, eng = {0};       /* the user's indexing, the engine's */
    corr_fix fix = {0};
    const char *src = argv[optind], *tgt = argv[optind + 1];
    int repair = o.job.w.repair == 0;          /* "yes|no" */
    if (!(S = load(src, repair, &status)) || !(T = load(tgt, repair, &status)) ||
        cli_job_load(&o.job, "match", S, T, &L, &P0, &Q0))
        goto done;
    /* --threads, else as many as the pair's size pays for (as the worker) */
    o.pe.threads = o.rp.threads = ompenv_threads_for(S->nv + T->nv, o.threads);
    omp_set_num_threads(o.pe.threads);
    corr_input user = { S, T, src, tgt, L, P0, Q0, &o.rp, o.stages, (int)o.job.w.ddm_k,
                        (corr_ddm_mode)o.job.w.ddm_mode }, in;
    int rc = corr_fix_open(&user, repair, &fix, &in, err, sizeof err);
    if (rc) {
        fprintf(stderr, "meshcorr match: %s\n", err);
        status = proto_kind_exit(-rc);
        goto done;
    }
    if (fix.repaired)
        print_repairs(&fix, src, tgt);
    rc = corr_run(&in, &o.pe, on_progress, &progress, &eng, err, sizeof err);
    cli_progress_end(stderr, progress);
    if (!rc && fix.repaired)
        rc = corr_fix_to_user(&fix, &eng, &res, err, sizeof err);
    else if (!rc) {
        res = eng;                           /* the user's indexing already */
        memset(&eng, 0, sizeof eng);
    }
    if (rc) {
        /* the kind's name and exit status, as a job through meshcorrd ends */
        fprintf(stderr, "meshcorr match: %s: %s\n", proto_kind_name(-rc), err);
        status = proto_kind_exit(-rc);
        goto done;
    }
    if (write_outputs(&o, src, tgt, S, T, &res))
        goto done;
    /* the last line: how good the map is; RHM's before it when it is
     * written too */
    const ectm_result *ran = fix.repaired ? &eng : &res;
    if (((o.out_rhm || o.out_rhm_rev) &&
         print_quality("rhm map quality", "RHM's map: ", in.S, in.T, ran->rhm_P)) ||
        print_quality("map quality", "", in.S, in.T, ran->P))
        goto done;
    status = 0;
done:
    ectm_result_close(&res);
    ectm_result_close(&eng);
    corr_fix_close(&fix);
    lmk_free(L);
    bmap_free(P0);
    bmap_free(Q0);
    mesh_free(S);
    mesh_free(T);
    return status;
}
