/* cli_eval.c — `meshcorr eval`: the quality figures of a map between two
 * mesh files (workers/metric), optionally against a ground truth and with
 * the reverse map. Reads files and prints; computes nothing itself.
 *
 * Ground-truth formats:
 *   vts-pair     --gt A --gt-target B: line k of A (source vertex) <-> line
 *                k of B (target vertex); first column read (BCICP/FAUST .vts,
 *                BIM .vts "id x y z"); 1-based unless --gt-base 0
 *   vertex-list  --gt G: line i = the target vertex of source vertex i, one
 *                line per source vertex (cartoon gt_*.txt written as floats,
 *                pyFM lion2cat); 0-based unless --gt-base 1 */
#include "cli/cli.h"
#include "geod/geod.h"
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "metric/metric.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EVAL_CURVE_STEPS 26      /* t = 0, 0.01, ..., 0.25 */
#define EVAL_CURVE_MAX 0.25
#define EVAL_MAX_GT_LINES 100000000

static void usage(FILE *fp)
{
    fprintf(fp,
        "usage: meshcorr eval SOURCE TARGET P.map [--reverse Q.map]\n"
        "         [--gt GT [--gt-target GT2] --gt-format vts-pair|vertex-list [--gt-base 0|1]]\n"
        "         [--json]\n"
        "Prints conformal and area distortion, flipped and collapsed triangles, mean-curvature\n"
        "error, coverage of the target, the round trip with Q, and the geodesic error to a\n"
        "ground truth (divided by sqrt(target area); mean and cumulative curve to 0.25).\n");
}

/* Reads the first column of every non-blank, non-'#' line of path as an
 * integer vertex index (written as an integer or a float such as 7.529e+03)
 * minus base, each in [0, nv). *out: malloc()ed, *n its length. */
static int read_indices(const char *path, int base, int nv, int **out, int *n)
{
    FILE *fp = fopen(path, "r");
    if (!fp) {
        fprintf(stderr, "meshcorr eval: %s: cannot open\n", path);
        return -1;
    }
    int cap = 1024, len = 0, line = 0, rc = -1;
    int *v = malloc(sizeof(int) * (size_t)cap);
    char buf[4096];
    while (v && fgets(buf, sizeof buf, fp)) {
        line++;
        char *p = buf, *e;
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\0' || *p == '\n' || *p == '\r' || *p == '#')
            continue;
        double x = strtod(p, &e);
        if (e == p || !(fabs(x - floor(x + 0.5)) < 1e-6)) {
            fprintf(stderr, "meshcorr eval: %s:%d: not a vertex index\n", path, line);
            goto out;
        }
        long k = (long)floor(x + 0.5) - base;
        if (k < 0 || k >= nv) {
            fprintf(stderr, "meshcorr eval: %s:%d: vertex %ld out of range [%d, %d]\n", path,
                    line, k + base, base, nv - 1 + base);
            goto out;
        }
        if (len == cap) {
            if (cap >= EVAL_MAX_GT_LINES) {
                fprintf(stderr, "meshcorr eval: %s: more than %d lines\n", path, EVAL_MAX_GT_LINES);
                goto out;
            }
            int *w = realloc(v, sizeof(int) * (size_t)(cap *= 2));
            if (!w)
                break;
            v = w;
        }
        v[len++] = (int)k;
    }
    if (!v) {
        fprintf(stderr, "meshcorr eval: out of memory\n");
        goto out;
    }
    *out = v;
    *n = len;
    v = NULL;
    rc = 0;
out:
    free(v);
    fclose(fp);
    return rc;
}

int cli_eval(int argc, char **argv)
{
    static const struct option opts[] = {
        {"reverse", required_argument, 0, 'r'},  {"gt", required_argument, 0, 'g'},
        {"gt-target", required_argument, 0, 't'}, {"gt-format", required_argument, 0, 'f'},
        {"gt-base", required_argument, 0, 'b'},  {"json", no_argument, 0, 'j'},
        {"help", no_argument, 0, 'h'},           {0, 0, 0, 0}};
    const char *rev = NULL, *gt = NULL, *gt2 = NULL, *fmt = NULL;
    int base = -1, json = 0, c, bad = 0;
    optind = 1;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'r': rev = optarg; break;
        case 'g': gt = optarg; break;
        case 't': gt2 = optarg; break;
        case 'f': fmt = optarg; break;
        case 'b':
            if (strcmp(optarg, "0") && strcmp(optarg, "1")) {
                fprintf(stderr, "meshcorr eval: --gt-base: '%s' is not 0 or 1\n", optarg);
                bad = 1;
            }
            base = optarg[0] - '0';
            break;
        case 'j': json = 1; break;
        case 'h': usage(stdout); return 0;
        default: bad = 1;
        }
    }
    int pair = fmt && strcmp(fmt, "vts-pair") == 0, list = fmt && strcmp(fmt, "vertex-list") == 0;
    if (!bad && argc - optind != 3) {
        fprintf(stderr, "meshcorr eval: need SOURCE TARGET P.map\n");
        bad = 1;
    }
    if (!bad && gt && !pair && !list) {
        fprintf(stderr, "meshcorr eval: --gt needs --gt-format vts-pair or vertex-list\n");
        bad = 1;
    }
    if (!bad && gt && pair != !!gt2) {
        fprintf(stderr, "meshcorr eval: --gt-target goes with --gt-format vts-pair, and only with it\n");
        bad = 1;
    }
    if (bad) {
        usage(stderr);
        return 2;
    }
    if (base < 0)
        base = pair ? 1 : 0;
    const char *spath = argv[optind], *tpath = argv[optind + 1], *ppath = argv[optind + 2];
    char err[1024];
    int status = 1, ngt = 0, n2 = 0;
    mesh *S = NULL, *T = NULL;
    bmap *P = NULL, *Q = NULL;
    int *gsrc = NULL, *gtgt = NULL;
    double *gerr = NULL;
    geod_solver *gs = NULL;
    if (mesh_read(spath, &S, err, sizeof err) || mesh_read(tpath, &T, err, sizeof err) ||
        bmap_read(ppath, S, T, &P, err, sizeof err) ||
        (rev && bmap_read(rev, T, S, &Q, err, sizeof err))) {
        fprintf(stderr, "meshcorr eval: %s\n", err);
        goto done;
    }
    if (gt && pair) {
        if (read_indices(gt, base, S->nv, &gsrc, &ngt) || read_indices(gt2, base, T->nv, &gtgt, &n2))
            goto done;
        if (ngt != n2 || ngt == 0) {
            fprintf(stderr, "meshcorr eval: %s has %d lines but %s has %d: line k of one must "
                    "match line k of the other\n", gt, ngt, gt2, n2);
            goto done;
        }
    } else if (gt) {
        if (read_indices(gt, base, T->nv, &gtgt, &ngt))
            goto done;
        if (ngt != S->nv) {
            fprintf(stderr, "meshcorr eval: %s has %d lines, but the source %s has %d vertices "
                    "(one line per source vertex)\n", gt, ngt, spath, S->nv);
            goto done;
        }
        if (!(gsrc = malloc(sizeof(int) * (size_t)ngt)))
            goto oom;
        for (int k = 0; k < ngt; k++)
            gsrc[k] = k;
    }
    metric_summary ms;
    double curv, cover = metric_coverage(T, P, METRIC_COVER_RADIUS), trip = NAN;
    if (metric_summarize(S, T, P, &ms) || metric_curvature_error(S, T, P, &curv) ||
        (Q && metric_round_trip(S, T, P, Q, &trip)))
        goto oom;
    double gmean = NAN, curve[EVAL_CURVE_STEPS];
    if (gt) {
        if (!(gs = geod_solver_new(T, 0, err, sizeof err))) {
            fprintf(stderr, "meshcorr eval: %s: %s\n", tpath, err);
            goto done;
        }
        if (!(gerr = malloc(sizeof(double) * (size_t)ngt)))
            goto oom;
        const bmap *maps[1] = { P };
        int rc = metric_geodesic_errors(gs, T, maps, 1, gsrc, gtgt, ngt, gerr);
        if (rc) {
            fprintf(stderr, "meshcorr eval: geodesic distances on %s failed: %s\n", tpath,
                    rc == -1 ? "out of memory" : geod_strerror(rc));
            goto done;
        }
        gmean = 0;
        for (int k = 0; k < ngt; k++)
            gmean += gerr[k] / ngt;
        metric_error_curve(gerr, ngt, EVAL_CURVE_MAX, EVAL_CURVE_STEPS, curve);
    }
    if (json) {
        printf("{\"map\":\"%s\",\"conformal_median\":%.9g,\"conformal_mean\":%.9g,"
               "\"area_mean_abs_log\":%.9g,\"flipped\":%.9g,\"collapsed\":%.9g,"
               "\"curvature_error\":%.9g,\"coverage\":%.9g", ppath, ms.median_conformal,
               ms.mean_conformal, ms.mean_abs_log_area, ms.flipped_fraction,
               ms.collapsed_fraction, curv, cover);
        if (Q)
            printf(",\"round_trip\":%.9g", trip);
        if (gt) {
            printf(",\"geodesic\":{\"points\":%d,\"mean\":%.9g,\"curve\":[", ngt, gmean);
            for (int s = 0; s < EVAL_CURVE_STEPS; s++)
                printf("%s[%.4g,%.6g]", s ? "," : "", EVAL_CURVE_MAX * s / (EVAL_CURVE_STEPS - 1), curve[s]);
            printf("]}");
        }
        printf("}\n");
    } else {
        printf("map %s: %s (%d vertices) -> %s (%d vertices)\n", ppath, spath, S->nv, tpath, T->nv);
        printf("conformal distortion: median %.4f, mean %.4f\n", ms.median_conformal, ms.mean_conformal);
        printf("area distortion: mean |log area ratio| %.4f\n", ms.mean_abs_log_area);
        printf("flipped triangles: %.2f %%\n", 100 * ms.flipped_fraction);
        printf("collapsed triangles: %.2f %%\n", 100 * ms.collapsed_fraction);
        printf("mean-curvature error: %.4f\n", curv);
        printf("target area within %.2f of a mapped point: %.2f %%\n", METRIC_COVER_RADIUS, 100 * cover);
        if (Q)
            printf("round trip |QPX - X|: %.4f\n", trip);
        if (gt) {
            printf("geodesic error (/sqrt(area)): mean %.4f over %d points\n", gmean, ngt);
            for (int s = 0; s < EVAL_CURVE_STEPS; s += 5)
                printf("  error <= %.2f: %.1f %%\n", EVAL_CURVE_MAX * s / (EVAL_CURVE_STEPS - 1), 100 * curve[s]);
        }
    }
    status = 0;
    goto done;
oom:
    fprintf(stderr, "meshcorr eval: out of memory\n");
done:
    geod_solver_free(gs);
    free(gerr);
    free(gsrc);
    free(gtgt);
    bmap_free(P);
    bmap_free(Q);
    mesh_free(S);
    mesh_free(T);
    return status;
}
