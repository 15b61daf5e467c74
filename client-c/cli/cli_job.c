/* cli_job.c — see cli_job.h. Parsing and loading only; running a job is the
 * command's business. The job parameters are the rows of PROTO_PARAMS:
 * parsed by proto_param_parse, checked by proto_params_check_as, which
 * names each by its option (--iterations) and its whole range. */
#include "cli/cli_job.h"
#include "corr/corr.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *cli_param_default(int i, char *buf, size_t size)
{
    const proto_param_info *f = &proto_param_infos[i];
    char name[64];
    if (f->type == PROTO_PARAM_STR)
        snprintf(buf, size, "cpu");
    else if (f->type == PROTO_PARAM_ENUM)
        snprintf(buf, size, "%s", proto_param_value_name(i, (unsigned)f->dflt, name, sizeof name));
    else if (f->type == PROTO_PARAM_BOOL)
        snprintf(buf, size, "off");
    else
        snprintf(buf, size, "%.10g", f->dflt);
    return buf;
}

void cli_job_usage(FILE *fp)
{
    fprintf(fp,
        "  inputs:  --landmarks PAIRS | --source-landmarks A --target-landmarks B [--one-based]\n"
        "           | --init P.map [--init-reverse Q.map] [--init-base 0|1|auto] [landmarks]\n"
        "           (landmarks: at least %d pairs; without --init the initial maps come from\n"
        "           them: a start map (--start), then Reversible Harmonic Maps)\n"
        "           PAIRS: `source_vertex target_vertex` a line; A, B: one vertex id a line,\n"
        "           or BIM .vts (`id x y z`) or .pid (`id 0 0 0`) lines, line k of A <-> line k\n"
        "           of B; ids 0-based (as BIM's files; a .vts file's positions are checked\n"
        "           against the mesh) unless --one-based (BCICP and FAUST .vts lists)\n"
        "           --init files: meshcorr-map 1, or a vertex map (one target vertex per\n"
        "           source vertex a line, as BCICP and BIM write them); its base: --init-base,\n"
        "           else auto: a 0 among the indices -> 0-based, else the target's vertex\n"
        "           count among them -> 1-based, else refused as ambiguous\n"
        "  --stages: what runs, in the order ddm, rhm, ectm, e.g. --init P.map --stages\n"
        "           ddm,rhm,ectm (ddm: denoising of the given map through its functional map)\n"
        "  --preset release|paper  the weights of the authors' released code (the defaults\n"
        "           below) or of the paper's text (eta 1e-3, beta 1e3 -> 2e5, gamma 2e4)\n"
        "  --device NAME           with --backend opencl|auto: an OpenCL device with fp64 whose\n"
        "           platform or device name contains NAME (see meshcorr devices)\n"
        "  job parameters (meshcorr params lists them; the server checks the same ranges):\n",
        PROTO_MIN_LANDMARKS);
    for (int i = 0; i < PROTO_NPARAMS; i++) {
        const proto_param_info *f = &proto_param_infos[i];
        char opt[96], dflt[64];
        const char *arg = f->type == PROTO_PARAM_U32 ? " N" : f->type == PROTO_PARAM_F64 ? " X" : "";
        if (f->type == PROTO_PARAM_ENUM || f->type == PROTO_PARAM_STR) {
            snprintf(opt, sizeof opt, "--%s %s", f->cli, f->values);
        } else {
            snprintf(opt, sizeof opt, "--%s%s", f->cli, arg);
        }
        cli_param_default(i, dflt, sizeof dflt);
        char range[160];
        fprintf(fp, "  %-30s %s\n  %-30s default %s", opt, f->help, "", dflt);
        if (f->type == PROTO_PARAM_U32 || f->type == PROTO_PARAM_F64)
            fprintf(fp, ", in %s", proto_param_range(i, range, sizeof range));
        fprintf(fp, "\n");
    }
}

void cli_job_init(cli_job *j, int argc, char **argv)
{
    memset(j, 0, sizeof *j);
    proto_params_init(&j->w);
    j->init_base = VMAP_BASE_AUTO;
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--preset=paper") == 0 ||
            (i + 1 < argc && strcmp(argv[i], "--preset") == 0 && strcmp(argv[i + 1], "paper") == 0)) {
            ectm_params e;
            ectm_params_paper(&e);
            corr_params_to_job(&e, NULL, &j->w, NULL, 0);
        }
}

int cli_job_option(cli_job *j, const char *cmd, int c, const char *arg)
{
    char err[256];
    if (c >= CLI_O_PARAM && c < CLI_O_PARAM + PROTO_NPARAMS) {
        int i = c - CLI_O_PARAM;
        const proto_param_info *f = &proto_param_infos[i];
        if (i == PROTO_P_stages) {          /* a chain: say why one is not */
            corr_chain s;
            if (corr_chain_parse(arg, &s, err, sizeof err)) {
                fprintf(stderr, "meshcorr %s: --%s: %s\n", cmd, f->cli, err);
                return -1;
            }
            j->w.stages = (uint8_t)s;
            return 1;
        }
        if (proto_param_parse(&j->w, i, f->type == PROTO_PARAM_BOOL ? "1" : arg, err, sizeof err)) {
            fprintf(stderr, "meshcorr %s: --%s: %s\n", cmd, f->cli, err);
            return -1;
        }
        return 1;
    }
    switch (c) {
    case CLI_O_INIT: j->init = arg; return 1;
    case CLI_O_INIT_REVERSE: j->init_rev = arg; return 1;
    case CLI_O_INIT_BASE:
        if (strcmp(arg, "0") == 0) j->init_base = 0;
        else if (strcmp(arg, "1") == 0) j->init_base = 1;
        else if (strcmp(arg, "auto") == 0) j->init_base = VMAP_BASE_AUTO;
        else {
            fprintf(stderr, "meshcorr %s: --init-base: '%s' is not 0, 1 or auto\n", cmd, arg);
            return -1;
        }
        return 1;
    case CLI_O_LANDMARKS: j->lmk_pairs = arg; return 1;
    case CLI_O_SOURCE_LANDMARKS: j->lmk_src = arg; return 1;
    case CLI_O_TARGET_LANDMARKS: j->lmk_tgt = arg; return 1;
    case CLI_O_ONE_BASED: j->one_based = 1; return 1;
    case CLI_O_PRESET:                      /* applied by cli_job_init */
        if (strcmp(arg, "release") && strcmp(arg, "paper")) {
            fprintf(stderr, "meshcorr %s: --preset: '%s' is not one of release, paper\n", cmd, arg);
            return -1;
        }
        return 1;
    case CLI_O_DEVICE: j->device = arg; return 1;
    }
    return 0;
}

int cli_job_check(cli_job *j, const char *cmd)
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
    if (j->w.model == PROTO_MODEL_INJECTIVE && j->init_rev) {
        fprintf(stderr, "meshcorr %s: --init-reverse needs the bijective model\n", cmd);
        return -1;
    }
    unsigned run = corr_chain_run((corr_chain)j->w.stages, !!j->init);
    char sname[64] = "";
    proto_param_value_name(PROTO_P_stages, j->w.stages, sname, sizeof sname);
    if (run && !j->init && !(run & CORR_RUN_RHM)) {
        fprintf(stderr, "meshcorr %s: --stages %s needs --init\n", cmd, sname);
        return -1;
    }
    if (run && !j->init && (run & CORR_RUN_DDM)) {
        fprintf(stderr, "meshcorr %s: --stages %s needs --init (DDM denoises a given map)\n", cmd,
                sname);
        return -1;
    }
    if (j->device) {
        if (strchr(j->w.backend, ':')) {
            fprintf(stderr, "meshcorr %s: --device and a backend with :DEVICE exclude each other\n", cmd);
            return -1;
        }
        if (strlen(j->device) > PROTO_MAX_DEVICE) {
            fprintf(stderr, "meshcorr %s: --device: name longer than %d bytes\n", cmd, PROTO_MAX_DEVICE);
            return -1;
        }
        snprintf(j->backend, sizeof j->backend, "%.30s:%s", j->w.backend[0] ? j->w.backend : "cpu",
                 j->device);
        j->w.backend = j->backend;
        j->device = NULL;
    }
    if (proto_params_check_as(&j->w, PROTO_NAME_CLI, err, sizeof err)) {
        fprintf(stderr, "meshcorr %s: %s\n", cmd, err);
        return -1;
    }
    return 0;
}

int cli_job_engine(const cli_job *j, const char *cmd, int threads, ectm_params *p, rhm_params *r)
{
    char err[512];
    if (corr_params_from_job(&j->w, threads, p, r, err, sizeof err)) {
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
        rc = vmap_read_any(j->init, j->init_base, S, T, P0, err, sizeof err);
    if (!rc && j->init_rev)
        rc = vmap_read_any(j->init_rev, j->init_base, T, S, Q0, err, sizeof err);
    int base = j->one_based ? 1 : LMK_BASE_DEFAULT;
    const char *hint = "";
    if (!rc && j->lmk_pairs) {
        rc = lmk_read_pairs(j->lmk_pairs, base, S, T, L, err, sizeof err);
        if (rc == LMK_ELAYOUT)
            hint = " (--landmarks), or give two lists: --source-landmarks A.vts --target-landmarks B.vts";
    } else if (!rc && j->lmk_src && j->lmk_tgt) {
        rc = lmk_read_lists(j->lmk_src, j->lmk_tgt, base, S, T, L, err, sizeof err);
        if (rc == LMK_ELAYOUT)
            hint = " (--source-landmarks, --target-landmarks); pairs go to --landmarks";
    }
    if (rc == LMK_ERANGE && !j->one_based && strstr(err, "looks 1-based"))
        hint = ": give --one-based";
    else if (rc == LMK_EBASE)
        hint = ": leave --one-based out";
    if (rc) {
        fprintf(stderr, "meshcorr %s: %s%s\n", cmd, err, hint);
        lmk_free(*L);
        bmap_free(*P0);
        bmap_free(*Q0);
        *L = NULL;
        *P0 = *Q0 = NULL;
        return -1;
    }
    return 0;
}

void cli_job_note_polygons(const char *cmd, const char *path, const mesh *m)
{
    if (m->polygons)
        fprintf(stderr, "meshcorr %s: %s: %d polygon%s split into triangles; the faces a map names on "
                "it are those triangles (meshcorr convert writes them)\n", cmd, path, m->polygons,
                m->polygons == 1 ? "" : "s");
}
