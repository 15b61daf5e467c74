/* cli_match.c — `meshcorr match`: the in-process engine on two mesh files.
 * Reads and validates the inputs, runs the pipeline (workers/corr: the
 * stages of --stages: DDM, RHM, ECTM), writes the maps and optional meshes, and shows
 * progress (bar on a terminal, text lines, or JSON lines on stderr). Holds
 * no numerics. */
#include "cli/cli.h"
#include "cli/cli_job.h"
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

enum progress_mode { PROGRESS_AUTO, PROGRESS_TEXT, PROGRESS_JSON, PROGRESS_NONE };

static void usage(FILE *fp)
{
    fprintf(fp,
        "usage: meshcorr match SOURCE TARGET INPUTS --out P.map [--out-reverse Q.map]\n"
        "         [--out-deformed Y.ply] [--out-remeshed T.ply] [--stages CHAIN]\n"
        "         [--log-eps E] [--threads N] [--progress auto|text|json|none] [job options]\n"
        "--stages rhm stops after RHM and writes its maps; --stages ectm runs ECTM alone\n"
        "(needs --init); --init P.map --stages ddm,ectm denoises the given map by DDM, then\n"
        "refines it by ECTM. Job options:\n");
    cli_job_usage(fp);
}

typedef struct progress_state {
    enum progress_mode mode;
} progress_state;

/* One RHM report (stage start: the start map, rhm: an iteration). */
static void rhm_progress(progress_state *ps, const corr_progress *cp)
{
    const rhm_report *r = cp->rhm;
    if (ps->mode == PROGRESS_JSON) {
        fprintf(stderr, "{\"stage\":\"%s\",\"iteration\":%d,\"total\":%d,\"beta\":%.17g,"
                "\"energy\":%.17g,\"elapsed\":%.3f,\"t_setup\":%.3f,\"t_project\":%.3f,"
                "\"t_solve\":%.3f", corr_stage_name(cp->stage), r->iteration, r->total, r->beta,
                r->energy, r->elapsed, r->t_setup, r->t_project, r->t_solve);
        static const char *names[2] = {"forward", "backward"};
        for (int d = 0; d < 2; d++)
            fprintf(stderr, ",\"%s\":{\"dirichlet\":%.17g,\"reverse\":%.17g,\"mismatch\":%.17g,"
                    "\"landmark\":%.17g}", names[d], r->dir[d].dirichlet, r->dir[d].reverse,
                    r->dir[d].mismatch, r->dir[d].landmark);
        fprintf(stderr, "}\n");
    } else if (ps->mode == PROGRESS_TEXT) {
        fprintf(stderr, "rhm %d/%d beta %.4g energy %.10g (dirichlet %.4g, reverse %.4g, "
                "mismatch %.4g, landmark %.4g)  %.1f s\n", r->iteration, r->total, r->beta,
                r->energy, r->dir[0].dirichlet + r->dir[1].dirichlet,
                r->dir[0].reverse + r->dir[1].reverse, r->dir[0].mismatch + r->dir[1].mismatch,
                r->dir[0].landmark + r->dir[1].landmark, r->elapsed);
    } else if (ps->mode == PROGRESS_AUTO) {
        int width = 30, done = (int)((long)width * r->iteration / r->total);
        fprintf(stderr, "\r[%.*s%*s] rhm %d/%d energy %.6g  %.1f s ", done,
                "##############################", width - done, "", r->iteration, r->total,
                r->energy, r->elapsed);
    }
}

static int on_progress(void *ctx, const corr_progress *cp)
{
    progress_state *ps = ctx;
    if (cp->rhm) {
        rhm_progress(ps, cp);
        fflush(stderr);
        return 0;
    }
    if (cp->ddm) {               /* directions denoised of total, each one's objective */
        const corr_ddm_report *d = cp->ddm;
        const char *mode = d->mode == CORR_DDM_BIJECTIVE ? "bijective" : "plain";
        if (ps->mode == PROGRESS_JSON) {
            fprintf(stderr, "{\"stage\":\"ddm\",\"done\":%d,\"total\":%d,\"k\":%d,\"mode\":\"%s\",",
                    d->done, d->total, d->k, mode);
            if (isfinite(d->round_trip))
                fprintf(stderr, "\"round_trip\":%.17g,", d->round_trip);
            else
                fprintf(stderr, "\"round_trip\":null,");
            fprintf(stderr, "\"objective\":[%.17g,%.17g],\"elapsed\":%.3f}\n", d->cost[0], d->cost[1],
                    cp->elapsed);
        } else if (ps->mode != PROGRESS_NONE) {
            if (d->done == 0 && isfinite(d->round_trip))   /* ddm_mode auto's choice */
                fprintf(stderr, "ddm: %s (the given maps' round trip %.4f %s %g)\n", mode,
                        d->round_trip, d->mode == CORR_DDM_BIJECTIVE ? "<=" : ">",
                        CORR_DDM_AUTO_ROUND_TRIP);
            fprintf(stderr, "ddm %d/%d (k %d) objective %.6g  %.1f s\n", d->done, d->total, d->k,
                    d->done ? d->cost[d->done - 1] : 0.0, cp->elapsed);
        }
        fflush(stderr);
        return 0;
    }
    if (cp->stage != CORR_STAGE_ECTM) {
        if (ps->mode == PROGRESS_JSON)
            fprintf(stderr, "{\"stage\":\"%s\",\"elapsed\":%.3f}\n", corr_stage_name(cp->stage), cp->elapsed);
        else if (ps->mode != PROGRESS_NONE)
            fprintf(stderr, "stage %s\n", corr_stage_name(cp->stage));
        return 0;
    }
    const ectm_report *r = cp->ectm;
    if (ps->mode == PROGRESS_JSON) {
        fprintf(stderr,
                "{\"stage\":\"ectm\",\"outer\":%d,\"total\":%d,\"beta\":%.17g,\"gamma\":%.17g,\"energy\":%.17g,"
                "\"elapsed\":%.3f,\"t_project\":%.3f,\"t_solve\":%.3f",
                r->outer, r->total, r->beta, r->gamma, r->energy, r->elapsed,
                r->t_project, r->t_solve);
        static const char *names[2] = {"source", "target"};
        for (int d = 0; d < 2; d++)
            fprintf(stderr,
                    ",\"%s\":{\"membrane\":%.17g,\"bending\":%.17g,\"mismatch\":%.17g,"
                    "\"reverse\":%.17g,\"energy\":%.17g,\"inner\":%d,\"admissible\":%d}",
                    names[d], r->dir[d].w_mem, r->dir[d].w_bnd, r->dir[d].mismatch,
                    r->dir[d].reverse, r->dir[d].energy, r->dir[d].inner_iterations,
                    r->dir[d].admissible_edges);
        fprintf(stderr, "}\n");
    } else if (ps->mode == PROGRESS_TEXT) {
        fprintf(stderr, "iter %d/%d beta %.4g energy %.10g (source %.6g, target %.6g) "
                "inner %d/%d  %.1f s\n", r->outer, r->total, r->beta, r->energy,
                r->dir[0].energy, r->dir[1].energy, r->dir[0].inner_iterations,
                r->dir[1].inner_iterations, r->elapsed);
    } else if (ps->mode == PROGRESS_AUTO) {
        int width = 30, done = (int)((long)width * r->outer / r->total);
        fprintf(stderr, "\r[%.*s%*s] %d/%d energy %.6g  %.1f s ", done,
                "##############################", width - done, "", r->outer, r->total,
                r->energy, r->elapsed);
        if (r->outer == r->total)
            fputc('\n', stderr);
    }
    fflush(stderr);
    return 0;
}

/* Reads a mesh and refuses one the optimizer cannot use before any other
 * input is read, so the user hears about the mesh first. */
static mesh *load(const char *path)
{
    char err[4096];
    mesh *m = NULL;
    if (mesh_read(path, &m, err, sizeof err) || corr_validate(m, path, err, sizeof err)) {
        fprintf(stderr, "meshcorr match: %s\n", err);
        mesh_free(m);
        return NULL;
    }
    return m;
}

static int write_mesh_with(const char *path, const mesh *faces_of, const double *v, int nv)
{
    char err[1024];
    mesh out = { nv, faces_of->nf, (double *)v, faces_of->f };
    if (mesh_write(path, &out, err, sizeof err)) {
        fprintf(stderr, "meshcorr match: %s\n", err);
        return -1;
    }
    return 0;
}

int cli_match(int argc, char **argv)
{
    enum { O_OUT = 1, O_OUT_REVERSE, O_OUT_DEFORMED, O_OUT_REMESHED, O_LOG_EPS,
           O_THREADS, O_PROGRESS };
    static const struct option opts[] = {
        CLI_JOB_OPTIONS,
        {"out", required_argument, 0, O_OUT},        {"out-reverse", required_argument, 0, O_OUT_REVERSE},
        {"out-deformed", required_argument, 0, O_OUT_DEFORMED},
        {"out-remeshed", required_argument, 0, O_OUT_REMESHED},
        {"log-eps", required_argument, 0, O_LOG_EPS},
        {"threads", required_argument, 0, O_THREADS}, {"progress", required_argument, 0, O_PROGRESS},
        {"help", no_argument, 0, 'h'},              {0, 0, 0, 0}};
    const char *out = NULL, *out_rev = NULL, *out_def = NULL, *out_rem = NULL;
    cli_job job;
    cli_job_init(&job, argc, argv);
    ectm_params pe;
    rhm_params rp;
    ectm_params_init(&pe);               /* log_eps and threads: match's own options */
    double log_eps = pe.log_eps;
    int threads = 0;
    progress_state ps = { PROGRESS_AUTO };
    int c;
    char *e;
    optind = 1;
    while ((c = cli_getopt("match", argc, argv, opts)) != -1) {
        int r = cli_job_option(&job, "match", c, optarg);
        if (r < 0)
            return cli_usage_see("match");
        if (r)
            continue;
        switch (c) {
        case O_OUT: out = optarg; break;
        case O_OUT_REVERSE: out_rev = optarg; break;
        case O_OUT_DEFORMED: out_def = optarg; break;
        case O_OUT_REMESHED: out_rem = optarg; break;
        case O_LOG_EPS:
            log_eps = strtod(optarg, &e);
            if (!*optarg || *e || !(log_eps > 0) || !isfinite(log_eps))
                return cli_usage_error("match", "--log-eps: '%s' is not a number > 0", optarg);
            break;
        case O_THREADS:
            threads = (int)strtol(optarg, &e, 10);
            if (!*optarg || *e || threads < 0 || threads > MATCH_MAX_THREADS)
                return cli_usage_error("match", "--threads: '%s' is not an integer in [0, %d] (0: by the "
                                       "pair's size)", optarg, MATCH_MAX_THREADS);
            break;
        case O_PROGRESS:
            if (strcmp(optarg, "auto") == 0) ps.mode = PROGRESS_AUTO;
            else if (strcmp(optarg, "text") == 0) ps.mode = PROGRESS_TEXT;
            else if (strcmp(optarg, "json") == 0) ps.mode = PROGRESS_JSON;
            else if (strcmp(optarg, "none") == 0) ps.mode = PROGRESS_NONE;
            else
                return cli_usage_error("match", "--progress: '%s' is not auto, text, json or none", optarg);
            break;
        case 'h': usage(stdout); return 0;
        default: return cli_usage_see("match");
        }
    }
    if (argc - optind != 2)
        return cli_usage_error("match", "need SOURCE and TARGET mesh files (%d given)", argc - optind);
    if (!out)
        return cli_usage_error("match", "need --out P.map");
    if (cli_job_check(&job, "match") || cli_job_engine(&job, "match", threads, &pe, &rp))
        return cli_usage_see("match");
    pe.log_eps = log_eps;
    corr_stages stages = (corr_stages)job.w.stages;
    int ectm_last = corr_stages_run(stages, !!job.init) & CORR_RUN_ECTM;
    if (!ectm_last && out_def)
        return cli_usage_error("match", "--out-deformed needs the ECTM stage (the deformation is ECTM's)");
    if (pe.model == ECTM_INJECTIVE && out_rev)
        return cli_usage_error("match", "--out-reverse needs the bijective model");
    if (cli_output_check("match", "--out", out) || cli_output_check("match", "--out-reverse", out_rev) ||
        cli_output_check("match", "--out-deformed", out_def) ||
        cli_output_check("match", "--out-remeshed", out_rem))
        return CLI_EXIT_USAGE;
    char err[1024];
    if (ps.mode == PROGRESS_AUTO && !isatty(STDERR_FILENO))
        ps.mode = PROGRESS_TEXT;

    int status = 1;
    mesh *S = NULL, *T = NULL;
    bmap *P0 = NULL, *Q0 = NULL;
    lmk_set *L = NULL;
    ectm_result res = {0};
    const char *src = argv[optind], *tgt = argv[optind + 1];
    if (!(S = load(src)) || !(T = load(tgt)) || cli_job_load(&job, "match", S, T, &L, &P0, &Q0))
        goto done;
    /* --threads, else as many as the pair's size pays for (as the worker) */
    pe.threads = rp.threads = ompenv_threads_for(S->nv + T->nv, threads);
    omp_set_num_threads(pe.threads);
    corr_input in = { S, T, src, tgt, L, P0, Q0, &rp, stages, (int)job.w.ddm_k,
                      (corr_ddm_mode)job.w.ddm_mode };
    if (corr_run(&in, &pe, on_progress, &ps, &res, err, sizeof err)) {
        fprintf(stderr, "\nmeshcorr match: %s\n", err);
        goto done;
    }
    char comment[512];
    char chain[64] = "";
    proto_param_value_name(PROTO_P_stages, (unsigned)stages, chain, sizeof chain);
    if (!ectm_last)
        snprintf(comment, sizeof comment, "meshcorr match %s -> %s, stages %s (%s)", src, tgt, chain,
                 corr_stages_run(stages, !!job.init) & CORR_RUN_RHM ? "reversible harmonic map"
                                                                    : "DDM-denoised map");
    else
        snprintf(comment, sizeof comment,
                 "meshcorr match %s -> %s, %s model, %d iterations, final energy %.10g",
                 src, tgt, pe.model == ECTM_BIJECTIVE ? "bijective" : "injective",
                 res.last.outer, res.last.energy);
    if (bmap_write(out, res.P, comment, err, sizeof err) ||
        (out_rev && res.Q && bmap_write(out_rev, res.Q, comment, err, sizeof err))) {
        fprintf(stderr, "meshcorr match: %s\n", err);
        goto done;
    }
    if (out_def && write_mesh_with(out_def, S, res.Y, S->nv))
        goto done;
    if (out_rem) {
        double *pt = malloc(sizeof(double) * 3 * (size_t)S->nv + 1);
        if (!pt) {
            fprintf(stderr, "meshcorr match: out of memory\n");
            goto done;
        }
        bmap_apply(res.P, T->f, T->v, 3, pt);
        int w = write_mesh_with(out_rem, S, pt, S->nv);
        free(pt);
        if (w)
            goto done;
    }
    /* the last line: how good the map is (the worker's metrics and rule) */
    metric_summary ms;
    if (metric_summarize(S, T, res.P, &ms)) {
        fprintf(stderr, "meshcorr match: out of memory\n");
        goto done;
    }
    printf("map quality: flipped %.2f %%, collapsed %.2f %%, mean |log area| %.4f, median conformal "
           "%.4f\n", 100 * ms.flipped_fraction, 100 * ms.collapsed_fraction, ms.mean_abs_log_area,
           ms.median_conformal);
    int verdict = metric_verdict(ms.flipped_fraction, ms.collapsed_fraction);
    if (verdict) {
        char text[256];
        metric_verdict_text(verdict, ms.flipped_fraction, ms.collapsed_fraction, text, sizeof text);
        fprintf(stderr, "meshcorr match: warning: %s\n", text);
    }
    status = 0;
done:
    ectm_result_close(&res);
    lmk_free(L);
    bmap_free(P0);
    bmap_free(Q0);
    mesh_free(S);
    mesh_free(T);
    return status;
}
