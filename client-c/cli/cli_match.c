/* cli_match.c — `meshcorr match`: the in-process engine on two mesh files.
 * Reads and validates the inputs, runs the pipeline (workers/corr: RHM from
 * landmarks, then ECTM), writes the maps and optional meshes, and shows
 * progress (bar on a terminal, text lines, or JSON lines on stderr). Holds
 * no numerics. */
#include "cli/cli.h"
#include "corr/corr.h"
#include "lmk/lmk.h"
#include "map/bmap.h"
#include "mesh/mesh.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum progress_mode { PROGRESS_AUTO, PROGRESS_TEXT, PROGRESS_JSON, PROGRESS_NONE };

static void usage(FILE *fp)
{
    fprintf(fp,
        "usage: meshcorr match SOURCE TARGET (--init P.map [--init-reverse Q.map] | --landmarks PAIRS\n"
        "         | --source-landmarks A --target-landmarks B) [--one-based]\n"
        "         --out P.map [--out-reverse Q.map] [--out-deformed Y.ply] [--out-remeshed T.ply]\n"
        "         [--model bijective|injective] [--preset release|paper]\n"
        "         [--alpha A] [--eta E] [--beta0 B] [--beta1 B] [--beta-ramp K] [--gamma G]\n"
        "         [--iterations K] [--inner-iterations N] [--tolerance T] [--stop-change C]\n"
        "         [--log-eps E] [--backend cpu|opencl|auto] [--device NAME]\n"
        "         [--stages all|rhm|ectm] [--rhm-alpha A] [--rhm-iterations K] [--rhm-dim M]\n"
        "         [--rhm-landmark-weight G]\n"
        "         [--partial] [--threads N] [--progress auto|text|json|none]\n"
        "Defaults are the authors' released code's (--preset release): alpha 20, eta 6.667e-4,\n"
        "beta 500 -> 1e5 over 200 iterations, gamma 1e4, 300 iterations, 50 L-BFGS steps.\n"
        "Without --init, the initial maps come from the landmarks: a geodesic Voronoi map, then\n"
        "Reversible Harmonic Maps (alpha 5e-4, beta 5e-3 min(k, 100), 8-D embedding, at most\n"
        "200 iterations, landmark weight 0). --stages rhm stops there and writes RHM's maps;\n"
        "--stages ectm runs ECTM alone and needs --init.\n"
        "--backend opencl computes the elastic energy on an OpenCL device with fp64 whose\n"
        "platform or device name contains NAME (see meshcorr devices); auto: a GPU, else the CPU.\n");
}

static int parse_double(const char *opt, const char *s, double *out)
{
    char *e;
    double v = strtod(s, &e);
    if (*s == '\0' || *e != '\0') {
        fprintf(stderr, "meshcorr match: --%s: '%s' is not a number\n", opt, s);
        return -1;
    }
    *out = v;
    return 0;
}

static int parse_int(const char *opt, const char *s, int *out)
{
    char *e;
    long v = strtol(s, &e, 10);
    if (*s == '\0' || *e != '\0' || v < -1000000000L || v > 1000000000L) {
        fprintf(stderr, "meshcorr match: --%s: '%s' is not an integer\n", opt, s);
        return -1;
    }
    *out = (int)v;
    return 0;
}

typedef struct progress_state {
    enum progress_mode mode;
} progress_state;

/* One RHM report (stage voronoi: the start, rhm: an iteration). */
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
    static const struct option opts[] = {
        {"init", required_argument, 0, 'i'},        {"init-reverse", required_argument, 0, 'I'},
        {"out", required_argument, 0, 'o'},         {"out-reverse", required_argument, 0, 'O'},
        {"out-deformed", required_argument, 0, 'd'}, {"out-remeshed", required_argument, 0, 'r'},
        {"model", required_argument, 0, 'm'},       {"preset", required_argument, 0, 'p'},
        {"alpha", required_argument, 0, 'a'},       {"eta", required_argument, 0, 'e'},
        {"beta0", required_argument, 0, 'b'},       {"beta1", required_argument, 0, 'B'},
        {"beta-ramp", required_argument, 0, 'R'},   {"gamma", required_argument, 0, 'g'},
        {"iterations", required_argument, 0, 'k'},  {"inner-iterations", required_argument, 0, 'n'},
        {"tolerance", required_argument, 0, 't'},   {"stop-change", required_argument, 0, 's'},
        {"partial", no_argument, 0, 'P'},           {"threads", required_argument, 0, 'T'},
        {"progress", required_argument, 0, 'G'},    {"help", no_argument, 0, 'h'},
        {"landmarks", required_argument, 0, 'L'},   {"source-landmarks", required_argument, 0, 'x'},
        {"target-landmarks", required_argument, 0, 'y'}, {"one-based", no_argument, 0, '1'},
        {"log-eps", required_argument, 0, 'E'},
        {"stages", required_argument, 0, 'S'},      {"rhm-alpha", required_argument, 0, 'A'},
        {"rhm-iterations", required_argument, 0, 'K'}, {"rhm-dim", required_argument, 0, 'M'},
        {"rhm-landmark-weight", required_argument, 0, 'W'},
        {"backend", required_argument, 0, 'Z'},     {"device", required_argument, 0, 'D'},
        {0, 0, 0, 0}};
    const char *init = NULL, *init_rev = NULL, *out = NULL, *out_rev = NULL;
    const char *out_def = NULL, *out_rem = NULL;
    const char *lmk_pairs = NULL, *lmk_src = NULL, *lmk_tgt = NULL;
    int one_based = 0;
    corr_stages stages = CORR_STAGES_ALL;
    rhm_params rp;
    rhm_params_init(&rp);
    ectm_params p;
    ectm_params_init(&p);
    /* The preset is applied first, whatever its position: explicit weights win. */
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--preset=paper") == 0 ||
            (i + 1 < argc && strcmp(argv[i], "--preset") == 0 && strcmp(argv[i + 1], "paper") == 0))
            ectm_params_paper(&p);
    progress_state ps = { PROGRESS_AUTO };
    int c, bad = 0;
    optind = 1;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'i': init = optarg; break;
        case 'I': init_rev = optarg; break;
        case 'o': out = optarg; break;
        case 'O': out_rev = optarg; break;
        case 'd': out_def = optarg; break;
        case 'r': out_rem = optarg; break;
        case 'm':
            if (strcmp(optarg, "bijective") == 0) p.model = ECTM_BIJECTIVE;
            else if (strcmp(optarg, "injective") == 0) p.model = ECTM_INJECTIVE;
            else { fprintf(stderr, "meshcorr match: --model: '%s' is not bijective or injective\n", optarg); bad = 1; }
            break;
        case 'p':
            if (strcmp(optarg, "paper") != 0 && strcmp(optarg, "release") != 0) {
                fprintf(stderr, "meshcorr match: --preset: '%s' is not release or paper\n", optarg);
                bad = 1;
            }
            break;
        case 'a': bad |= parse_double("alpha", optarg, &p.alpha) != 0; break;
        case 'e': bad |= parse_double("eta", optarg, &p.eta) != 0; break;
        case 'b': bad |= parse_double("beta0", optarg, &p.beta0) != 0; break;
        case 'B': bad |= parse_double("beta1", optarg, &p.beta1) != 0; break;
        case 'R': bad |= parse_int("beta-ramp", optarg, &p.beta_ramp) != 0; break;
        case 'g': bad |= parse_double("gamma", optarg, &p.gamma) != 0; break;
        case 'k': bad |= parse_int("iterations", optarg, &p.iterations) != 0; break;
        case 'n': bad |= parse_int("inner-iterations", optarg, &p.inner_iterations) != 0; break;
        case 't': bad |= parse_double("tolerance", optarg, &p.tolerance) != 0; break;
        case 's': bad |= parse_double("stop-change", optarg, &p.stop_change) != 0; break;
        case 'E': bad |= parse_double("log-eps", optarg, &p.log_eps) != 0; break;
        case 'Z':
            if (strcmp(optarg, "cpu") && strcmp(optarg, "opencl") && strcmp(optarg, "auto")) {
                fprintf(stderr, "meshcorr match: --backend: '%s' is not cpu, opencl or auto\n", optarg);
                bad = 1;
            } else {
                snprintf(p.backend, sizeof p.backend, "%s", optarg);
            }
            break;
        case 'D':
            if (strlen(optarg) >= sizeof p.device) {
                fprintf(stderr, "meshcorr match: --device: name longer than %zu bytes\n",
                        sizeof p.device - 1);
                bad = 1;
            } else {
                snprintf(p.device, sizeof p.device, "%s", optarg);
            }
            break;
        case 'P': p.partial = 1; break;
        case 'T': bad |= parse_int("threads", optarg, &p.threads) != 0; break;
        case 'G':
            if (strcmp(optarg, "auto") == 0) ps.mode = PROGRESS_AUTO;
            else if (strcmp(optarg, "text") == 0) ps.mode = PROGRESS_TEXT;
            else if (strcmp(optarg, "json") == 0) ps.mode = PROGRESS_JSON;
            else if (strcmp(optarg, "none") == 0) ps.mode = PROGRESS_NONE;
            else { fprintf(stderr, "meshcorr match: --progress: '%s' is not auto, text, json or none\n", optarg); bad = 1; }
            break;
        case 'L': lmk_pairs = optarg; break;
        case 'x': lmk_src = optarg; break;
        case 'y': lmk_tgt = optarg; break;
        case '1': one_based = 1; break;
        case 'S':
            if (strcmp(optarg, "all") == 0) stages = CORR_STAGES_ALL;
            else if (strcmp(optarg, "rhm") == 0) stages = CORR_STAGES_RHM;
            else if (strcmp(optarg, "ectm") == 0) stages = CORR_STAGES_ECTM;
            else { fprintf(stderr, "meshcorr match: --stages: '%s' is not all, rhm or ectm\n", optarg); bad = 1; }
            break;
        case 'A': bad |= parse_double("rhm-alpha", optarg, &rp.alpha) != 0; break;
        case 'K': bad |= parse_int("rhm-iterations", optarg, &rp.iterations) != 0; break;
        case 'M': bad |= parse_int("rhm-dim", optarg, &rp.dim) != 0; break;
        case 'W': bad |= parse_double("rhm-landmark-weight", optarg, &rp.gamma) != 0; break;
        case 'h': usage(stdout); return 0;
        default: bad = 1;
        }
    }
    int have_lmk = lmk_pairs || (lmk_src && lmk_tgt);
    if (!bad && (argc - optind != 2 || !out || (!init && !have_lmk))) {
        fprintf(stderr, "meshcorr match: need SOURCE TARGET, --out, and --init or landmarks\n");
        bad = 1;
    }
    if (!bad && !!lmk_src != !!lmk_tgt) {
        fprintf(stderr, "meshcorr match: --source-landmarks and --target-landmarks go together\n");
        bad = 1;
    }
    if (bad) {
        usage(stderr);
        return 2;
    }
    if (stages == CORR_STAGES_ECTM && !init) {
        fprintf(stderr, "meshcorr match: --stages ectm needs --init\n");
        return 2;
    }
    if (stages == CORR_STAGES_RHM && (init || out_def)) {
        fprintf(stderr, "meshcorr match: --stages rhm starts from landmarks and has no deformation "
                "(no --init, no --out-deformed)\n");
        return 2;
    }
    if (p.model == ECTM_INJECTIVE && (init_rev || out_rev)) {
        fprintf(stderr, "meshcorr match: --init-reverse/--out-reverse need the bijective model\n");
        return 2;
    }
    char err[1024];
    if (ectm_params_check(&p, err, sizeof err) || rhm_params_check(&rp, err, sizeof err)) {
        fprintf(stderr, "meshcorr match: %s\n", err);
        return 2;
    }
    if (ps.mode == PROGRESS_AUTO && !isatty(STDERR_FILENO))
        ps.mode = PROGRESS_TEXT;

    int status = 1;
    mesh *S = NULL, *T = NULL;
    bmap *P0 = NULL, *Q0 = NULL;
    lmk_set *L = NULL;
    ectm_result res = {0};
    const char *src = argv[optind], *tgt = argv[optind + 1];
    if (!(S = load(src)) || !(T = load(tgt)))
        goto done;
    if (init) {
        if (bmap_read(init, S, T, &P0, err, sizeof err)) {
            fprintf(stderr, "meshcorr match: %s\n", err);
            goto done;
        }
    } else if (lmk_pairs ? lmk_read_pairs(lmk_pairs, one_based, S, T, &L, err, sizeof err)
                         : lmk_read_lists(lmk_src, lmk_tgt, one_based, S, T, &L, err, sizeof err)) {
        fprintf(stderr, "meshcorr match: %s\n", err);
        goto done;
    }
    if (init_rev && bmap_read(init_rev, T, S, &Q0, err, sizeof err)) {
        fprintf(stderr, "meshcorr match: %s\n", err);
        goto done;
    }
    rp.threads = p.threads;
    corr_input in = { S, T, src, tgt, L, P0, Q0, &rp, stages };
    if (corr_run(&in, &p, on_progress, &ps, &res, err, sizeof err)) {
        fprintf(stderr, "\nmeshcorr match: %s\n", err);
        goto done;
    }
    char comment[512];
    if (stages == CORR_STAGES_RHM)
        snprintf(comment, sizeof comment, "meshcorr match %s -> %s, reversible harmonic map", src, tgt);
    else
        snprintf(comment, sizeof comment,
                 "meshcorr match %s -> %s, %s model, %d iterations, final energy %.10g",
                 src, tgt, p.model == ECTM_BIJECTIVE ? "bijective" : "injective",
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
