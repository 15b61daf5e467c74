/* metric.c — see metric.h. Per-triangle measures and their summary; no I/O. */
#include "metric/metric.h"
#include "geo/geo_area.h"
#include "geo/geo_normals.h"

#include <math.h>
#include <stdio.h>
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

/* Face t's log area ratio (metric_area_distortion). */
static double face_logratio(const mesh *S, const double *img, double src_area, double tgt_area,
                            int t)
{
    const int *f = S->f + 3 * t;
    double e1[3], e2[3], a0, a1;
    tri_frame(S->v + 3 * f[0], S->v + 3 * f[1], S->v + 3 * f[2], e1, e2, &a0);
    tri_frame(img + 3 * f[0], img + 3 * f[1], img + 3 * f[2], e1, e2, &a1);
    return log((a1 / tgt_area) / (a0 / src_area));
}

void metric_area_distortion(const mesh *S, const double *img, double src_area,
                            double tgt_area, double *logratio)
{
    for (int t = 0; t < S->nf; t++)
        logratio[t] = face_logratio(S, img, src_area, tgt_area, t);
}

/* First fundamental form of (e1, e2): g = [[e1·e1, e1·e2], [e1·e2, e2·e2]]. */
static void fform(const double e1[3], const double e2[3], double g[3])
{
    g[0] = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    g[1] = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
    g[2] = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
}

/* Face t's conformal distortion (metric_conformal_distortion). */
static double face_conformal(const mesh *S, const double *img, int t)
{
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
    return detG > 0 ? tr / sqrt(detG) - 2 : INFINITY;
}

void metric_conformal_distortion(const mesh *S, const double *img, double *conf)
{
    for (int t = 0; t < S->nf; t++)
        conf[t] = face_conformal(S, img, t);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

void metric_face_normals(const mesh *S, const mesh *T, const bmap *P, const double *img,
                         const double *tn, int t, double n[3], double m[3])
{
    const int *f = S->f + 3 * t;
    const double *a = img + 3 * f[0], *b = img + 3 * f[1], *c = img + 3 * f[2];
    n[0] = (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]);
    n[1] = (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]);
    n[2] = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    m[0] = m[1] = m[2] = 0;
    for (int k = 0; k < 3; k++) {
        int row = f[k];
        const int *tf = T->f + 3 * P->face[row];
        for (int j = 0; j < 3; j++)
            for (int d = 0; d < 3; d++)
                m[d] += P->w[3 * row + j] * tn[3 * tf[j] + d];
    }
}

/* The fold rule of metric_fold_faces on one face, with the image img, the
 * target's vertex normals tn and the face's area distortion lr and
 * conformal distortion cf. */
static int face_kind(const mesh *S, const mesh *T, const bmap *P, const double *img,
                     const double *tn, int t, double lr, double cf)
{
    if (!(exp(lr) > 1e-12) || !isfinite(cf))
        return METRIC_FACE_COLLAPSED;
    double n[3], m[3];
    metric_face_normals(S, T, P, img, tn, t, n, m);
    return n[0] * m[0] + n[1] * m[1] + n[2] * m[2] < 0 ? METRIC_FACE_FLIPPED : METRIC_FACE_OK;
}

int metric_face_kind(const mesh *S, const mesh *T, const bmap *P, const double *img,
                     const double *tn, double src_area, double tgt_area, int t, double *lr)
{
    double l = face_logratio(S, img, src_area, tgt_area, t);
    if (lr)
        *lr = l;
    return face_kind(S, T, P, img, tn, t, l, face_conformal(S, img, t));
}

/* img, tn, lr, cf of the map (see face_kind); 0, or -1 when out of memory
 * (all four then freed and NULL). */
static int map_images(const mesh *S, const mesh *T, const bmap *P, double **img, double **tn,
                      double **lr, double **cf)
{
    *img = malloc(sizeof(double) * ((size_t)S->nv * 3 + 1));
    *tn = malloc(sizeof(double) * ((size_t)T->nv * 3 + 1));
    *lr = malloc(sizeof(double) * ((size_t)S->nf + 1));
    *cf = malloc(sizeof(double) * ((size_t)S->nf + 1));
    if (!*img || !*tn || !*lr || !*cf) {
        free(*img);
        free(*tn);
        free(*lr);
        free(*cf);
        *img = *tn = *lr = *cf = NULL;
        return -1;
    }
    bmap_apply(P, T->f, T->v, 3, *img);
    geo_vertex_normals(T, *tn);
    metric_area_distortion(S, *img, geo_total_area(S), geo_total_area(T), *lr);
    metric_conformal_distortion(S, *img, *cf);
    return 0;
}

int metric_fold_faces(const mesh *S, const mesh *T, const bmap *P, unsigned char *kind)
{
    double *img, *tn, *lr, *cf;
    if (map_images(S, T, P, &img, &tn, &lr, &cf))
        return -1;
    int bad = 0;
    for (int t = 0; t < S->nf; t++)
        bad += (kind[t] = (unsigned char)face_kind(S, T, P, img, tn, t, lr[t], cf[t])) != 0;
    free(img);
    free(tn);
    free(lr);
    free(cf);
    return bad;
}

int metric_summarize(const mesh *S, const mesh *T, const bmap *P, metric_summary *out)
{
    int nf = S->nf;
    double *img, *tn, *lr, *cf;
    out->mean_abs_log_area = out->median_conformal = out->mean_conformal = NAN;
    out->flipped_fraction = out->collapsed_fraction = NAN;
    if (map_images(S, T, P, &img, &tn, &lr, &cf))
        return -1;
    int ok = 0, collapsed = 0, flipped = 0;
    double sum = 0, csum = 0;
    for (int t = 0; t < nf; t++) {
        int kind = face_kind(S, T, P, img, tn, t, lr[t], cf[t]);
        if (kind == METRIC_FACE_COLLAPSED) {
            collapsed++;
            continue;
        }
        flipped += kind == METRIC_FACE_FLIPPED;
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
    free(img);
    free(tn);
    free(lr);
    free(cf);
    return 0;
}

int metric_verdict(double flipped_fraction, double collapsed_fraction)
{
    if (flipped_fraction > 0.5)
        return METRIC_VERDICT_REVERSED;
    if (!(flipped_fraction + collapsed_fraction <= METRIC_FOLDED_MAX))
        return METRIC_VERDICT_FOLDED;
    return METRIC_VERDICT_OK;
}

void metric_verdict_text(int verdict, double flipped_fraction, double collapsed_fraction,
                         char *buf, size_t bufsz)
{
    if (verdict == METRIC_VERDICT_REVERSED)
        snprintf(buf, bufsz, "the map reverses orientation (%.1f %% of its triangles are flipped): "
                 "the shape came out mirrored; check the landmarks", 100 * flipped_fraction);
    else if (verdict == METRIC_VERDICT_FOLDED)
        snprintf(buf, bufsz, "the map is folded: %.1f %% of its triangles are flipped and %.1f %% "
                 "collapsed (more than %.0f %%)", 100 * flipped_fraction, 100 * collapsed_fraction,
                 100 * METRIC_FOLDED_MAX);
    else if (bufsz)
        buf[0] = '\0';
}
