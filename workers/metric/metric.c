/* metric.c — see metric.h. Per-triangle measures and their summary; no I/O. */
#include "metric/metric.h"
#include "geo/geo_area.h"
#include "geo/geo_normals.h"

#include <math.h>
#include <stdlib.h>

static void tri_frame(const double *a, const double *b, const double *c,
                      double e1[3], double e2[3], double *area)
{
    for (int d = 0; d < 3; d++) {
        e1[d] = b[d] - a[d];
        e2[d] = c[d] - a[d];
    }
    double n[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                    e1[0] * e2[1] - e1[1] * e2[0] };
    *area = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

void metric_area_distortion(const mesh *S, const double *img, double src_area,
                            double tgt_area, double *logratio)
{
    for (int t = 0; t < S->nf; t++) {
        const int *f = S->f + 3 * t;
        double e1[3], e2[3], a0, a1;
        tri_frame(S->v + 3 * f[0], S->v + 3 * f[1], S->v + 3 * f[2], e1, e2, &a0);
        tri_frame(img + 3 * f[0], img + 3 * f[1], img + 3 * f[2], e1, e2, &a1);
        logratio[t] = log((a1 / tgt_area) / (a0 / src_area));
    }
}

/* First fundamental form of (e1, e2): g = [[e1·e1, e1·e2], [e1·e2, e2·e2]]. */
static void fform(const double e1[3], const double e2[3], double g[3])
{
    g[0] = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    g[1] = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
    g[2] = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
}

void metric_conformal_distortion(const mesh *S, const double *img, double *conf)
{
    for (int t = 0; t < S->nf; t++) {
        const int *f = S->f + 3 * t;
        double e1[3], e2[3], a0, a1, g0[3], g1[3];
        tri_frame(S->v + 3 * f[0], S->v + 3 * f[1], S->v + 3 * f[2], e1, e2, &a0);
        fform(e1, e2, g0);
        tri_frame(img + 3 * f[0], img + 3 * f[1], img + 3 * f[2], e1, e2, &a1);
        fform(e1, e2, g1);
        /* σ₁², σ₂² are the eigenvalues of G = g0⁻¹ g1: tr and det give
         * σ₁/σ₂ + σ₂/σ₁ = tr/√det, since (σ₁² + σ₂²)/(σ₁σ₂). */
        double det0 = g0[0] * g0[2] - g0[1] * g0[1];
        double det1 = g1[0] * g1[2] - g1[1] * g1[1];
        double tr = (g0[2] * g1[0] - 2 * g0[1] * g1[1] + g0[0] * g1[2]) / det0;
        double detG = det1 / det0;
        conf[t] = detG > 0 ? tr / sqrt(detG) - 2 : INFINITY;
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

int metric_summarize(const mesh *S, const mesh *T, const bmap *P, metric_summary *out)
{
    int nf = S->nf, rc = -1;
    double *img = malloc(sizeof(double) * ((size_t)S->nv * 3 + 1));
    double *tn = malloc(sizeof(double) * ((size_t)T->nv * 3 + 1));
    double *lr = malloc(sizeof(double) * ((size_t)nf + 1));
    double *cf = malloc(sizeof(double) * ((size_t)nf + 1));
    out->mean_abs_log_area = out->median_conformal = out->mean_conformal = NAN;
    out->flipped_fraction = out->collapsed_fraction = NAN;
    if (!img || !tn || !lr || !cf)
        goto out;
    bmap_apply(P, T->f, T->v, 3, img);
    geo_vertex_normals(T, tn);
    metric_area_distortion(S, img, geo_total_area(S), geo_total_area(T), lr);
    metric_conformal_distortion(S, img, cf);
    int ok = 0, collapsed = 0, flipped = 0;
    double sum = 0, csum = 0;
    for (int t = 0; t < nf; t++) {
        const int *f = S->f + 3 * t;
        if (!(exp(lr[t]) > 1e-12) || !isfinite(cf[t])) {
            collapsed++;
            continue;
        }
        const double *a = img + 3 * f[0], *b = img + 3 * f[1], *c = img + 3 * f[2];
        double n[3] = { (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]),
                        (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]),
                        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) };
        /* the target's normal where the triangle's corners land */
        double dot = 0;
        for (int k = 0; k < 3; k++) {
            int row = f[k];
            const int *tf = T->f + 3 * P->face[row];
            for (int j = 0; j < 3; j++)
                for (int d = 0; d < 3; d++)
                    dot += P->w[3 * row + j] * tn[3 * tf[j] + d] * n[d];
        }
        flipped += dot < 0;
        sum += fabs(lr[t]);
        csum += cf[t];
        cf[ok++] = cf[t];
    }
    out->collapsed_fraction = (double)collapsed / nf;
    out->flipped_fraction = (double)flipped / nf;
    if (ok) {
        out->mean_abs_log_area = sum / ok;
        out->mean_conformal = csum / ok;
        qsort(cf, (size_t)ok, sizeof *cf, cmp_double);
        out->median_conformal = ok % 2 ? cf[ok / 2] : 0.5 * (cf[ok / 2 - 1] + cf[ok / 2]);
    }
    rc = 0;
out:
    free(img);
    free(tn);
    free(lr);
    free(cf);
    return rc;
}
