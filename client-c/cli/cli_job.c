/* cli_job.c — see cli_job.h. Parsing and loading only; running a job is the
 * command's business. */
#include "cli/cli_job.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int parse_double(const char *cmd, const char *opt, const char *s, double *out)
{
    char *e;
    double v = strtod(s, &e);
    if (*s == '\0' || *e != '\0') {
        fprintf(stderr, "meshcorr %s: --%s: '%s' is not a number\n", cmd, opt, s);
        return -1;
    }
    *out = v;
    return 1;
}

static int parse_int(const char *cmd, const char *opt, const char *s, int *out)
{
    char *e;
    long v = strtol(s, &e, 10);
    if (*s == '\0' || *e != '\0' || v < -1000000000L || v > 1000000000L) {
        fprintf(stderr, "meshcorr %s: --%s: '%s' is not an integer\n", cmd, opt, s);
        return -1;
    }
    *out = (int)v;
    return 1;
}

static int parse_word(const char *cmd, const char *opt, const char *s, const char *const *words,
                      int *out)
{
    for (int i = 0; words[i]; i++)
        if (strcmp(s, words[i]) == 0) {
            *out = i;
            return 1;
        }
    fprintf(stderr, "meshcorr %s: --%s: '%s' is not one of", cmd, opt, s);
    for (int i = 0; words[i]; i++)
        fprintf(stderr, "%s %s", i ? "," : "", words[i]);
    fprintf(stderr, "\n");
    return -1;
}

void cli_job_init(cli_job *j, int argc, char **argv)
{
    memset(j, 0, sizeof *j);
    ectm_params_init(&j->p);
    rhm_params_init(&j->rp);
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--preset=paper") == 0 ||
            (i + 1 < argc && strcmp(argv[i], "--preset") == 0 && strcmp(argv[i + 1], "paper") == 0))
            ectm_params_paper(&j->p);
}

int cli_job_option(cli_job *j, const char *cmd, int c, const char *arg)
{
    static const char *const models[] = {"bijective", "injective", NULL};
    static const char *const presets[] = {"release", "paper", NULL};
    static const char *const backends[] = {"cpu", "opencl", "auto", NULL};
    ectm_params *p = &j->p;
    int k;
    switch (c) {
    case CLI_O_INIT: j->init = arg; return 1;
    case CLI_O_INIT_REVERSE: j->init_rev = arg; return 1;
    case CLI_O_LANDMARKS: j->lmk_pairs = arg; return 1;
    case CLI_O_SOURCE_LANDMARKS: j->lmk_src = arg; return 1;
    case CLI_O_TARGET_LANDMARKS: j->lmk_tgt = arg; return 1;
    case CLI_O_ONE_BASED: j->one_based = 1; return 1;
    case CLI_O_MODEL:
        if (parse_word(cmd, "model", arg, models, &k) < 0)
            return -1;
        p->model = k ? ECTM_INJECTIVE : ECTM_BIJECTIVE;
        return 1;
    case CLI_O_PRESET: return parse_word(cmd, "preset", arg, presets, &k);  /* applied by init */
    case CLI_O_ALPHA: return parse_double(cmd, "alpha", arg, &p->alpha);
    case CLI_O_ETA: return parse_double(cmd, "eta", arg, &p->eta);
    case CLI_O_BETA0: return parse_double(cmd, "beta0", arg, &p->beta0);
    case CLI_O_BETA1: return parse_double(cmd, "beta1", arg, &p->beta1);
    case CLI_O_BETA_RAMP: return parse_int(cmd, "beta-ramp", arg, &p->beta_ramp);
    case CLI_O_GAMMA: return parse_double(cmd, "gamma", arg, &p->gamma);
    case CLI_O_ITERATIONS: return parse_int(cmd, "iterations", arg, &p->iterations);
    case CLI_O_INNER_ITERATIONS: return parse_int(cmd, "inner-iterations", arg, &p->inner_iterations);
    case CLI_O_TOLERANCE: return parse_double(cmd, "tolerance", arg, &p->tolerance);
    case CLI_O_STOP_CHANGE: return parse_double(cmd, "stop-change", arg, &p->stop_change);
    case CLI_O_PARTIAL: p->partial = 1; return 1;
    case CLI_O_BACKEND:
        if (parse_word(cmd, "backend", arg, backends, &k) < 0)
            return -1;
        snprintf(p->backend, sizeof p->backend, "%s", backends[k]);
        return 1;
    case CLI_O_DEVICE:
        if (strlen(arg) >= sizeof p->device) {
            fprintf(stderr, "meshcorr %s: --device: name longer than %zu bytes\n", cmd,
                    sizeof p->device - 1);
            return -1;
        }
        snprintf(p->device, sizeof p->device, "%s", arg);
        return 1;
    case CLI_O_RHM_ALPHA: return parse_double(cmd, "rhm-alpha", arg, &j->rp.alpha);
    case CLI_O_RHM_ITERATIONS: return parse_int(cmd, "rhm-iterations", arg, &j->rp.iterations);
    case CLI_O_RHM_DIM: return parse_int(cmd, "rhm-dim", arg, &j->rp.dim);
    case CLI_O_RHM_LANDMARK_WEIGHT:
        return parse_double(cmd, "rhm-landmark-weight", arg, &j->rp.gamma);
    case CLI_O_RHM_START:
        if ((j->rp.start = rhm_start_parse(arg)) < 0) {
            fprintf(stderr, "meshcorr %s: --rhm-start: '%s' is not distances or voronoi\n", cmd, arg);
            return -1;
        }
        return 1;
    }
    return 0;
}

int cli_job_check(const cli_job *j, const char *cmd)
{
    char err[512];
    if (!j->init && !j->lmk_pairs && !(j->lmk_src && j->lmk_tgt)) {
        fprintf(stderr, "meshcorr %s: need --init or landmarks (--landmarks, or "
                "--source-landmarks with --target-landmarks)\n", cmd);
        return -1;
    }
    if (!!j->lmk_src != !!j->lmk_tgt) {
        fprintf(stderr, "meshcorr %s: --source-landmarks and --target-landmarks go together\n", cmd);
        return -1;
    }
    if (j->init_rev && !j->init) {
        fprintf(stderr, "meshcorr %s: --init-reverse needs --init\n", cmd);
        return -1;
    }
    if (j->p.model == ECTM_INJECTIVE && j->init_rev) {
        fprintf(stderr, "meshcorr %s: --init-reverse needs the bijective model\n", cmd);
        return -1;
    }
    if (ectm_params_check(&j->p, err, sizeof err) || rhm_params_check(&j->rp, err, sizeof err)) {
        fprintf(stderr, "meshcorr %s: %s\n", cmd, err);
        return -1;
    }
    return 0;
}

int cli_job_load(const cli_job *j, const char *cmd, const mesh *S, const mesh *T,
                 lmk_set **L, bmap **P0, bmap **Q0)
{
    char err[4096];
    *L = NULL;
    *P0 = *Q0 = NULL;
    int rc = 0;
    if (j->init)
        rc = bmap_read(j->init, S, T, P0, err, sizeof err);
    if (!rc && j->init_rev)
        rc = bmap_read(j->init_rev, T, S, Q0, err, sizeof err);
    if (!rc && !j->init && j->lmk_pairs)
        rc = lmk_read_pairs(j->lmk_pairs, j->one_based, S, T, L, err, sizeof err);
    else if (!rc && !j->init)
        rc = lmk_read_lists(j->lmk_src, j->lmk_tgt, j->one_based, S, T, L, err, sizeof err);
    if (rc) {
        fprintf(stderr, "meshcorr %s: %s\n", cmd, err);
        lmk_free(*L);
        bmap_free(*P0);
        bmap_free(*Q0);
        *L = NULL;
        *P0 = *Q0 = NULL;
        return -1;
    }
    return 0;
}
