/* cli_eval.c — `meshcorr eval`: the quality figures of a map between two
 * mesh files (workers/metric), optionally against a ground truth and with
 * the reverse map. Reads files and prints; computes nothing itself. Maps
 * are meshcorr-map 1 files or vertex maps (map/vmap.h, base --map-base).
 *
 * Ground-truth formats (files read by workers/lmk, the reader and base
 * rule of match's landmarks: 0-based unless --gt-base 1, a BIM .vts file's
 * positions checked against its mesh):
 *   vts-pair     --gt A --gt-target B: line k of A (source vertex) <-> line
 *                k of B (target vertex); one id a line (BCICP/FAUST .vts:
 *                1-based, --gt-base 1) or BIM .vts "id x y z" / .pid lines
 *   vertex-list  --gt G: line i = the target vertex of source vertex i, one
 *                line per source vertex (cartoon gt_*.txt written as floats,
 *                pyFM lion2cat) */
#include "cli/cli.h"
#include "geod/geod.h"
#include "lmk/lmk.h"
#include "map/bmap.h"
#include "map/vmap.h"
#include "mesh/mesh.h"
#include "metric/metric.h"
#include "proto.h"
#include "render/render.h"
#include "viz/viz.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EVAL_CURVE_STEPS 26      /* t = 0, 0.01, ..., 0.25 */
#define EVAL_CURVE_MAX 0.25
#define EVAL_MAX_GT_LINES 100000000
#define EVAL_MAX_MAPS 8
#define EVAL_PNG_PANEL 400       /* pixels per side of each of the 4 panels */

static void usage(FILE *fp)
{
    fprintf(fp,
        "usage: meshcorr eval SOURCE TARGET P.map [P2.map ...] [--reverse Q.map]\n"
        "         [--gt GT [--gt-target GT2] --gt-format vts-pair|vertex-list [--gt-base 0|1]]\n"
        "         [--map-base 0|1|auto] [--json] [--out-colors PREFIX] [--out-png FILE [--mark-folds]]\n"
        "         [--out-curve CURVES.svg] [--out-csv CURVES.csv]\n"
        "Maps: meshcorr-map 1 files, or vertex maps (one target vertex per source vertex a line,\n"
        "as BCICP and BIM write them; --map-base as match's --init-base, default auto).\n"
        "Ground truth: vts-pair: line k of GT (a source vertex) <-> line k of GT2 (a target\n"
        "vertex); vertex-list: line i of GT = the target vertex of source vertex i. One id a\n"
        "line, or BIM .vts (`id x y z`) or .pid lines; ids 0-based as match's landmark files\n"
        "(a .vts file's positions are checked against its mesh) unless --gt-base 1 (BCICP\n"
        "and FAUST .vts lists are 1-based).\n"
        "Prints, for each map: conformal and area distortion, flipped and collapsed triangles,\n"
        "mean-curvature error, coverage of the target, the round trip with Q (one map only),\n"
        "and the geodesic error to a ground truth (divided by sqrt(target area); mean and\n"
        "cumulative curve to 0.25). Pictures: --out-colors writes PREFIX.target.ply (the\n"
        "target coloured by position) and PREFIX.source.ply (the source coloured through the\n"
        "first map: same colour, same place); --out-png writes the same colours as a picture,\n"
        "800 pixels wide: left the source through the map, right the target; top row the\n"
        "target's widest side (the world axes of its longest and middle extents across and\n"
        "up), bottom row from behind; the source turned to face as its images on the target\n"
        "do, each shape centred in its panel (--mark-folds hatches the source's flipped and\n"
        "collapsed triangles); captions say which side is which, the map, its flipped and\n"
        "collapsed triangles and its geodesic error. --out-curve and --out-csv write the\n"
        "cumulative error curves of every map (with a ground truth).\n");
}

/* lmk_read_ids_on with the message on stderr, and what to do about it. */
static int read_indices(const char *path, int base, const mesh *m, int **out, int *n)
{
    char err[512];
    int rc = lmk_read_ids_on(path, base, m, EVAL_MAX_GT_LINES, out, n, err, sizeof err);
    if (rc == LMK_OK)
        return 0;
    const char *hint = "";
    if (rc == LMK_ELAYOUT)
        hint = " (--gt, --gt-target)";
    else if (rc == LMK_ERANGE && base == LMK_BASE_DEFAULT && strstr(err, "looks 1-based"))
        hint = ": give --gt-base 1";
    else if (rc == LMK_EBASE)
        hint = ": leave --gt-base out";
    fprintf(stderr, "meshcorr eval: %s%s\n", err, hint);
    return -1;
}

/* PREFIX.target.ply coloured by position, PREFIX.source.ply through P. */
static int write_colors(const char *prefix, const mesh *S, const mesh *T, const bmap *P)
{
    char path[4200], err[1024];
    int rc = -1;
    unsigned char *trgb = malloc(3 * (size_t)T->nv + 1), *srgb = malloc(3 * (size_t)S->nv + 1);
    if (!trgb || !srgb) {
        fprintf(stderr, "meshcorr eval: out of memory\n");
        goto out;
    }
    viz_position_colors(T, trgb);
    viz_pull_colors(P, T->f, trgb, srgb);
    snprintf(path, sizeof path, "%s.target.ply", prefix);
    if (mesh_write_ply_rgb(path, T, trgb, err, sizeof err))
        goto fail;
    snprintf(path, sizeof path, "%s.source.ply", prefix);
    if (mesh_write_ply_rgb(path, S, srgb, err, sizeof err))
        goto fail;
    rc = 0;
    goto out;
fail:
    fprintf(stderr, "meshcorr eval: %s\n", err);
out:
    free(trgb);
    free(srgb);
    return rc;
}

static const char *base_name(const char *path)
{
    const char *s = strrchr(path, '/');
    return s && s[1] ? s + 1 : path;
}

/* FILE: render_map_png's picture of P, captioned with the files' names. */
static int write_png(const char *path, const mesh *S, const mesh *T, const bmap *P, render_map_words *w)
{
    char err[1024];
    w->source = base_name(w->source);
    w->target = base_name(w->target);
    w->map = base_name(w->map);
    int rc = render_map_png(path, S, T, P, w, EVAL_PNG_PANEL, err, sizeof err);
    if (rc)
        fprintf(stderr, "meshcorr eval: %s\n", err);
    return rc;
}

static int write_curves(const char *svg, const char *csv, const char *const *names,
                        const double *const *curves, int n)
{
    if (svg) {
        FILE *fp = fopen(svg, "w");
        if (!fp) {
            fprintf(stderr, "meshcorr eval: %s: cannot create\n", svg);
            return -1;
        }
        viz_curves_svg(fp, "Cumulative geodesic error", names, curves, n, EVAL_CURVE_STEPS,
                       EVAL_CURVE_MAX);
        if (fclose(fp)) {
            fprintf(stderr, "meshcorr eval: %s: write failed\n", svg);
            return -1;
        }
    }
    if (csv) {
        FILE *fp = fopen(csv, "w");
        if (!fp) {
            fprintf(stderr, "meshcorr eval: %s: cannot create\n", csv);
            return -1;
        }
        fprintf(fp, "error");
        for (int a = 0; a < n; a++)
            fprintf(fp, ",\"%s\"", names[a]);
        fprintf(fp, "\n");
        for (int k = 0; k < EVAL_CURVE_STEPS; k++) {
            fprintf(fp, "%.4g", EVAL_CURVE_MAX * k / (EVAL_CURVE_STEPS - 1));
            for (int a = 0; a < n; a++)
                fprintf(fp, ",%.6g", curves[a][k]);
            fprintf(fp, "\n");
        }
        if (fclose(fp)) {
            fprintf(stderr, "meshcorr eval: %s: write failed\n", csv);
            return -1;
        }
    }
    return 0;
}

/* The command line of eval. */
typedef struct eval_opts {
    const char *rev, *gt, *gt2, *fmt;
    const char *out_colors, *out_curve, *out_csv, *out_png;
    int base, json, folds, map_base, pair;
    int nmaps;
    const char *spath, *tpath;
    char *const *ppaths;
} eval_opts;

/* Reads and checks the command line, outputs included: -1 to go on, else
 * the exit status (a usage error, --help). */
static int parse_options(int argc, char **argv, eval_opts *o)
{
    static const struct option opts[] = {
        {"reverse", required_argument, 0, 'r'},  {"gt", required_argument, 0, 'g'},
        {"gt-target", required_argument, 0, 't'}, {"gt-format", required_argument, 0, 'f'},
        {"gt-base", required_argument, 0, 'b'},  {"json", no_argument, 0, 'j'},
        {"out-colors", required_argument, 0, 'c'}, {"out-curve", required_argument, 0, 's'},
        {"out-csv", required_argument, 0, 'v'},  {"out-png", required_argument, 0, 'p'},
        {"mark-folds", no_argument, 0, 'm'},     {"map-base", required_argument, 0, 'B'},
        {"help", no_argument, 0, 'h'},
        {0, 0, 0, 0}};
    *o = (eval_opts){.base = LMK_BASE_DEFAULT, .map_base = VMAP_BASE_AUTO};
    int c;
    optind = 1;
    while ((c = cli_getopt("eval", argc, argv, opts)) != -1) {
        switch (c) {
        case 'r': o->rev = optarg; break;
        case 'g': o->gt = optarg; break;
        case 't': o->gt2 = optarg; break;
        case 'f': o->fmt = optarg; break;
        case 'b':
            if (strcmp(optarg, "0") && strcmp(optarg, "1"))
                return cli_usage_error("eval", "--gt-base: '%s' is not 0 or 1", optarg);
            o->base = optarg[0] - '0';
            break;
        case 'B':
            if (strcmp(optarg, "0") && strcmp(optarg, "1") && strcmp(optarg, "auto"))
                return cli_usage_error("eval", "--map-base: '%s' is not 0, 1 or auto", optarg);
            o->map_base = strcmp(optarg, "auto") ? optarg[0] - '0' : VMAP_BASE_AUTO;
            break;
        case 'j': o->json = 1; break;
        case 'c': o->out_colors = optarg; break;
        case 's': o->out_curve = optarg; break;
        case 'v': o->out_csv = optarg; break;
        case 'p': o->out_png = optarg; break;
        case 'm': o->folds = 1; break;
        case 'h': usage(stdout); return 0;
        default: return cli_usage_see("eval");
        }
    }
    o->pair = o->fmt && strcmp(o->fmt, "vts-pair") == 0;
    int list = o->fmt && strcmp(o->fmt, "vertex-list") == 0;
    o->nmaps = argc - optind - 2;
    if (o->nmaps < 1 || o->nmaps > EVAL_MAX_MAPS)
        return cli_usage_error("eval", "need SOURCE TARGET and 1 to %d maps (%d file%s given)", EVAL_MAX_MAPS,
                               argc - optind, argc - optind == 1 ? "" : "s");
    if (o->rev && o->nmaps != 1)
        return cli_usage_error("eval", "--reverse goes with a single map");
    if ((o->out_curve || o->out_csv) && !o->gt)
        return cli_usage_error("eval", "--out-curve and --out-csv need a ground truth (--gt)");
    if (o->folds && !o->out_png)
        return cli_usage_error("eval", "--mark-folds goes with --out-png");
    if (o->fmt && !o->pair && !list)
        return cli_usage_error("eval", "--gt-format: '%s' is not vts-pair or vertex-list", o->fmt);
    if (o->gt && !o->fmt)
        return cli_usage_error("eval", "--gt needs --gt-format vts-pair or vertex-list");
    if (o->gt && o->pair != !!o->gt2)
        return cli_usage_error("eval", "--gt-target goes with --gt-format vts-pair, and only with it");
    char colors[4200];
    snprintf(colors, sizeof colors, "%s.target.ply", o->out_colors ? o->out_colors : "");
    if (cli_output_check("eval", "--out-colors", o->out_colors ? colors : NULL) ||
        cli_output_check("eval", "--out-png", o->out_png) || cli_output_check("eval", "--out-curve", o->out_curve) ||
        cli_output_check("eval", "--out-csv", o->out_csv))
        return CLI_EXIT_USAGE;
    o->spath = argv[optind];
    o->tpath = argv[optind + 1];
    o->ppaths = argv + optind + 2;
    return -1;
}

/* The ground truth's pairs (*gsrc)[k] -> (*gtgt)[k], *ngt of them: the
 * vts-pair files line by line, or a vertex list (source vertex k -> line
 * k). 0, or -1 with the message printed (out of memory included). */
static int read_ground_truth(const eval_opts *o, const mesh *S, const mesh *T, int **gsrc, int **gtgt, int *ngt)
{
    int n2 = 0;
    if (o->pair) {
        if (read_indices(o->gt, o->base, S, gsrc, ngt) || read_indices(o->gt2, o->base, T, gtgt, &n2))
            return -1;
        if (*ngt != n2 || *ngt == 0) {
            fprintf(stderr, "meshcorr eval: %s has %d lines but %s has %d: line k of one must "
                    "match line k of the other\n", o->gt, *ngt, o->gt2, n2);
            return -1;
        }
        return 0;
    }
    if (read_indices(o->gt, o->base, T, gtgt, ngt))
        return -1;
    if (*ngt != S->nv) {
        fprintf(stderr, "meshcorr eval: %s has %d lines, but the source %s has %d vertices "
                "(one line per source vertex)\n", o->gt, *ngt, o->spath, S->nv);
        return -1;
    }
    if (!(*gsrc = malloc(sizeof(int) * (size_t)*ngt))) {
        fprintf(stderr, "meshcorr eval: out of memory\n");
        return -1;
    }
    for (int k = 0; k < *ngt; k++)
        (*gsrc)[k] = k;
    return 0;
}

/* The figures of one map, as one JSON line or as text; gmean and curve
 * only when ngt > 0, trip only with a reverse map. */
static void print_figures(const eval_opts *o, int a, const mesh *S, const mesh *T, const metric_summary *ms,
                          double curv, double cover, int has_q, double trip, int ngt, double gmean,
                          const double *curve)
{
    const char *ppath = o->ppaths[a];
    if (o->json) {
        printf("{\"map\":\"%s\",\"conformal_median\":%.9g,\"conformal_mean\":%.9g,"
               "\"area_mean_abs_log\":%.9g,\"flipped\":%.9g,\"collapsed\":%.9g,"
               "\"curvature_error\":%.9g,\"coverage\":%.9g", ppath, ms->median_conformal,
               ms->mean_conformal, ms->mean_abs_log_area, ms->flipped_fraction,
               ms->collapsed_fraction, curv, cover);
        if (has_q)
            printf(",\"round_trip\":%.9g", trip);
        if (ngt) {
            printf(",\"geodesic\":{\"points\":%d,\"mean\":%.9g,\"curve\":[", ngt, gmean);
            for (int k = 0; k < EVAL_CURVE_STEPS; k++)
                printf("%s[%.4g,%.6g]", k ? "," : "", EVAL_CURVE_MAX * k / (EVAL_CURVE_STEPS - 1), curve[k]);
            printf("]}");
        }
        printf("}\n");
        return;
    }
    printf("%smap %s: %s (%d vertices) -> %s (%d vertices)\n", a ? "\n" : "", ppath,
           o->spath, S->nv, o->tpath, T->nv);
    printf("conformal distortion: median %.4f, mean %.4f\n", ms->median_conformal, ms->mean_conformal);
    printf("area distortion: mean |log area ratio| %.4f\n", ms->mean_abs_log_area);
    printf("flipped triangles: %.2f %%\n", 100 * ms->flipped_fraction);
    printf("collapsed triangles: %.2f %%\n", 100 * ms->collapsed_fraction);
    printf("mean-curvature error: %.4f\n", curv);
    printf("target area within %.2f of a mapped point: %.2f %%\n", METRIC_COVER_RADIUS, 100 * cover);
    if (has_q)
        printf("round trip |QPX - X|: %.4f\n", trip);
    if (ngt) {
        printf("geodesic error (/sqrt(area)): mean %.4f over %d points\n", gmean, ngt);
        for (int k = 0; k < EVAL_CURVE_STEPS; k += 5)
            printf("  error <= %.2f: %.1f %%\n", EVAL_CURVE_MAX * k / (EVAL_CURVE_STEPS - 1), 100 * curve[k]);
    }
}

/* The geodesic error of each of the nmaps maps at the ngt ground-truth
 * pairs on T (tpath): its mean (gmean) and its curve (curves); 0, or -1
 * with the message printed (out of memory included). */
static int geodesic_figures(const char *tpath, const mesh *T, bmap *const *maps, int nmaps, const int *gsrc,
                            const int *gtgt, int ngt, double *gmean, double (*curves)[EVAL_CURVE_STEPS])
{
    char err[1024];
    geod_solver *gs = NULL;
    double *gerr = NULL;
    int status = -1;
    if (geod_solver_new(T, 0, &gs, err, sizeof err)) {
        fprintf(stderr, "meshcorr eval: %s: %s\n", tpath, err);
        goto done;
    }
    if (!(gerr = malloc(sizeof(double) * (size_t)ngt * (size_t)nmaps))) {
        fprintf(stderr, "meshcorr eval: out of memory\n");
        goto done;
    }
    int rc = metric_geodesic_errors(gs, T, (const bmap *const *)maps, nmaps, gsrc, gtgt, ngt, gerr);
    if (rc) {
        fprintf(stderr, "meshcorr eval: geodesic distances on %s failed: %s\n", tpath,
                rc == -1 ? "out of memory" : geod_strerror(rc));
        goto done;
    }
    for (int a = 0; a < nmaps; a++) {
        const double *e = gerr + (size_t)a * (size_t)ngt;
        gmean[a] = 0;
        for (int k = 0; k < ngt; k++)
            gmean[a] += e[k] / ngt;
        metric_error_curve(e, ngt, EVAL_CURVE_MAX, EVAL_CURVE_STEPS, curves[a]);
    }
    status = 0;
done:
    geod_solver_free(gs);
    free(gerr);
    return status;
}

int cli_eval(int argc, char **argv)
{
    eval_opts o;
    int status = parse_options(argc, argv, &o);
    if (status >= 0)
        return status;
    const char *spath = o.spath, *tpath = o.tpath;
    char *const *ppaths = o.ppaths;
    int nmaps = o.nmaps;
    char err[1024];
    int ngt = 0;
    status = 1;
    mesh *S = NULL, *T = NULL;
    bmap *maps[EVAL_MAX_MAPS] = {0}, *Q = NULL;
    int *gsrc = NULL, *gtgt = NULL;
    if (mesh_read(spath, &S, err, sizeof err) || mesh_read(tpath, &T, err, sizeof err) ||
        (o.rev && vmap_read_any(o.rev, o.map_base, T, S, &Q, err, sizeof err))) {
        fprintf(stderr, "meshcorr eval: %s\n", err);
        goto done;
    }
    for (int a = 0; a < nmaps; a++)
        if (vmap_read_any(ppaths[a], o.map_base, S, T, &maps[a], err, sizeof err)) {
            fprintf(stderr, "meshcorr eval: %s\n", err);
            goto done;
        }
    if (o.gt && read_ground_truth(&o, S, T, &gsrc, &gtgt, &ngt))
        goto done;
    double curves[EVAL_MAX_MAPS][EVAL_CURVE_STEPS], gmean[EVAL_MAX_MAPS];
    render_map_words words = {spath, tpath, ppaths[0], NAN, NAN, NAN, 0, o.folds};
    if (o.gt && geodesic_figures(tpath, T, maps, nmaps, gsrc, gtgt, ngt, gmean, curves))
        goto done;
    for (int a = 0; a < nmaps; a++) {
        const bmap *P = maps[a];
        const char *ppath = ppaths[a];
        metric_summary ms;
        double curv, cover = metric_coverage(T, P, METRIC_COVER_RADIUS), trip = NAN;
        if (metric_summarize(S, T, P, &ms) || (Q && metric_round_trip(S, T, P, Q, &trip)))
            goto oom;
        int crc = metric_curvature_error(S, T, P, &curv, err, sizeof err);
        if (crc) {              /* a mesh eval can read but not measure: say which and why */
            fprintf(stderr, "meshcorr eval: curvature error of %s: %s\n", ppath, err);
            status = crc == METRIC_ENOMEM ? proto_kind_exit(PROTO_KIND_NOMEM) : 1;
            goto done;
        }
        if (a == 0) {
            words.flipped = ms.flipped_fraction;
            words.collapsed = ms.collapsed_fraction;
        }
        print_figures(&o, a, S, T, &ms, curv, cover, Q != NULL, trip, o.gt ? ngt : 0, o.gt ? gmean[a] : NAN,
                      curves[a]);
    }
    if (o.out_colors && write_colors(o.out_colors, S, T, maps[0]))
        goto done;
    words.gt_points = o.gt ? ngt : 0;
    words.gt_mean = o.gt ? gmean[0] : NAN;
    if (o.out_png && write_png(o.out_png, S, T, maps[0], &words))
        goto done;
    if (o.out_curve || o.out_csv) {
        const double *cv[EVAL_MAX_MAPS];
        for (int a = 0; a < nmaps; a++)
            cv[a] = curves[a];
        if (write_curves(o.out_curve, o.out_csv, (const char *const *)ppaths, cv, nmaps))
            goto done;
    }
    status = 0;
    goto done;
oom:
    fprintf(stderr, "meshcorr eval: out of memory\n");
done:
    free(gsrc);
    free(gtgt);
    for (int a = 0; a < EVAL_MAX_MAPS; a++)
        bmap_free(maps[a]);
    bmap_free(Q);
    mesh_free(S);
    mesh_free(T);
    return status;
}
