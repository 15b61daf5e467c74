/* embed_lmds.c — the embedding of embed.h assembled: classical MDS start,
 * SMACOF, principal axes, biharmonic extension, and the quality report.
 * Sampling, eigenpairs, SMACOF, the extension and the fit measure live in
 * their own files. */
#include "embed/embed.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double dist_rows(const double *Z, int dim, int a, int b)
{
    double s = 0;
    for (int i = 0; i < dim; i++) {
        double d = Z[(size_t)a * dim + i] - Z[(size_t)b * dim + i];
        s += d * d;
    }
    return sqrt(s);
}

static unsigned long long xorshift(unsigned long long *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

/* The random-pair half of the report: EMBED_QUALITY_SOURCES fields, each
 * paired with EMBED_QUALITY_TARGETS targets, from a fixed seed. */
static int sample_quality(geod_solver *s, const double *Z, int dim, embed_quality *q,
                          char *err, size_t errsz)
{
    int nv = geod_solver_nv(s), ns = EMBED_QUALITY_SOURCES, nt = EMBED_QUALITY_TARGETS;
    int src[EMBED_QUALITY_SOURCES], rc = EMBED_ENOMEM, n = 0;
    double *f = malloc((size_t)ns * nv * sizeof *f);
    double *dg = malloc((size_t)ns * nt * sizeof *dg), *de = malloc((size_t)ns * nt * sizeof *de);
    if (!f || !dg || !de) {
        errbuf_set(err, errsz, rc, "out of memory for the quality sample");
        goto out;
    }
    unsigned long long seed = 0x9E3779B97F4A7C15ull;
    for (int a = 0; a < ns; a++)
        src[a] = (int)(xorshift(&seed) % (unsigned long long)nv);
    int g = geod_all_pairs_from(s, src, ns, f);
    if (g != GEOD_OK) {
        rc = errbuf_set(err, errsz, EMBED_EGEOD, "quality sample: %s", geod_strerror(g));
        goto out;
    }
    for (int a = 0; a < ns; a++)
        for (int b = 0; b < nt; b++) {
            int t = (int)(xorshift(&seed) % (unsigned long long)nv);
            if (t == src[a])
                continue;
            dg[n] = f[(size_t)a * nv + t];
            de[n++] = dist_rows(Z, dim, src[a], t);
        }
    q->pairs_sample = n;
    embed_distance_fit(dg, de, n, &q->stress_sample, &q->corr_sample);
    rc = EMBED_OK;
out:
    free(f);
    free(dg);
    free(de);
    return rc;
}

/* Classical MDS of the k by k distances D into Y (k by dim); the share of
 * the kept eigenvalues in *kept. */
static int classical(const double *D, int k, int dim, double *Y, double *kept,
                     char *err, size_t errsz)
{
    int rc = EMBED_ENOMEM;
    double *B = malloc((size_t)k * k * sizeof *B), *mu = malloc((size_t)k * sizeof *mu);
    double *w = malloc((size_t)dim * sizeof *w), *V = malloc((size_t)k * dim * sizeof *V);
    double *all_w = malloc((size_t)k * sizeof *all_w);
    if (!B || !mu || !w || !V || !all_w) {
        errbuf_set(err, errsz, rc, "out of memory for %d landmarks", k);
        goto out;
    }
    double tot = 0;
    for (int a = 0; a < k; a++) {
        mu[a] = 0;
        for (int b = 0; b < k; b++)
            mu[a] += D[(size_t)a * k + b] * D[(size_t)a * k + b];
        mu[a] /= k;
        tot += mu[a];
    }
    tot /= k;
    for (int a = 0; a < k; a++)
        for (int b = 0; b < k; b++) {
            double d = D[(size_t)a * k + b];
            B[(size_t)a * k + b] = -0.5 * (d * d - mu[a] - mu[b] + tot);
        }
    if ((rc = embed_top_eigenpairs(B, k, dim, w, V, all_w)) != EMBED_OK) {
        errbuf_set(err, errsz, rc, "eigenpairs of the %d by %d centred matrix", k, k);
        goto out;
    }
    double sum_kept = 0, sum_all = 0;
    for (int i = 0; i < dim; i++) {
        double sc = w[i] > 0 ? sqrt(w[i]) : 0;
        sum_kept += w[i] > 0 ? w[i] : 0;
        for (int a = 0; a < k; a++)
            Y[(size_t)a * dim + i] = sc * V[(size_t)a * dim + i];
    }
    for (int a = 0; a < k; a++)
        sum_all += fabs(all_w[a]);
    *kept = sum_all > 0 ? sum_kept / sum_all : 0;
out:
    free(B);
    free(mu);
    free(w);
    free(V);
    free(all_w);
    return rc;
}

/* Y (k by dim) centred and rotated onto its principal axes, variance
 * descending, each axis' sign fixed by its largest-magnitude entry. */
static int principal_axes(double *Y, int k, int dim)
{
    double *C = calloc((size_t)dim * dim, sizeof *C), *w = malloc((size_t)dim * sizeof *w);
    double *R = malloc((size_t)dim * dim * sizeof *R), *y = malloc((size_t)dim * sizeof *y);
    int rc = EMBED_ENOMEM;
    if (!C || !w || !R || !y)
        goto out;
    for (int c = 0; c < dim; c++) {
        double m = 0;
        for (int a = 0; a < k; a++)
            m += Y[(size_t)a * dim + c];
        m /= k;
        for (int a = 0; a < k; a++)
            Y[(size_t)a * dim + c] -= m;
    }
    for (int a = 0; a < k; a++)
        for (int i = 0; i < dim; i++)
            for (int j = 0; j < dim; j++)
                C[(size_t)i * dim + j] += Y[(size_t)a * dim + i] * Y[(size_t)a * dim + j];
    if ((rc = embed_top_eigenpairs(C, dim, dim, w, R, NULL)) != EMBED_OK)
        goto out;
    for (int a = 0; a < k; a++) {
        double *row = Y + (size_t)a * dim;
        for (int j = 0; j < dim; j++) {
            y[j] = 0;
            for (int i = 0; i < dim; i++)
                y[j] += row[i] * R[(size_t)i * dim + j];
        }
        memcpy(row, y, (size_t)dim * sizeof *y);
    }
    for (int j = 0; j < dim; j++) {
        int big = 0;
        for (int a = 1; a < k; a++)
            if (fabs(Y[(size_t)a * dim + j]) > fabs(Y[(size_t)big * dim + j]))
                big = a;
        if (Y[(size_t)big * dim + j] < 0)
            for (int a = 0; a < k; a++)
                Y[(size_t)a * dim + j] = -Y[(size_t)a * dim + j];
    }
out:
    free(C);
    free(w);
    free(R);
    free(y);
    return rc;
}

static void landmark_fit(const double *D, const double *Y, int k, int dim, double *stress,
                         double *corr, double *dg, double *de)
{
    size_t n = 0;
    for (int a = 0; a < k; a++)
        for (int b = a + 1; b < k; b++, n++) {
            dg[n] = D[(size_t)a * k + b];
            de[n] = dist_rows(Y, dim, a, b);
        }
    embed_distance_fit(dg, de, (int)n, stress, corr);
}

int embed_lmds(geod_solver *s, int dim, int k, int start, double *Z,
               embed_quality *q, char *err, size_t errsz)
{
    int nv = geod_solver_nv(s);
    if (dim <= 0)
        dim = EMBED_DIM_DEFAULT;
    if (k <= 0)
        k = EMBED_LANDMARKS_DEFAULT < nv ? EMBED_LANDMARKS_DEFAULT : nv;
    if (dim > EMBED_MAX_DIM || k < dim + 1 || k > nv || start < 0 || start >= nv)
        return errbuf_set(err, errsz, EMBED_EINVAL,
                          "dim %d (max %d), landmarks %d (need dim+1..%d), start %d", dim,
                          EMBED_MAX_DIM, k, nv, start);
    int rc = EMBED_ENOMEM;
    size_t np = (size_t)k * (k - 1) / 2;
    int *pts = malloc((size_t)k * sizeof *pts);
    double *D = malloc((size_t)k * k * sizeof *D), *Y = malloc((size_t)k * dim * sizeof *Y);
    double *dg = q ? malloc(np * sizeof *dg) : NULL, *de = q ? malloc(np * sizeof *de) : NULL;
    if (!pts || !D || !Y || (q && (!dg || !de))) {
        errbuf_set(err, errsz, rc, "out of memory for %d landmarks", k);
        goto out;
    }
    if ((rc = embed_farthest_points(s, start, k, pts, D, err, errsz)) != EMBED_OK)
        goto out;
    double kept, stress0 = 0, corr0;
    if ((rc = classical(D, k, dim, Y, &kept, err, errsz)) != EMBED_OK)
        goto out;
    if (q)
        landmark_fit(D, Y, k, dim, &stress0, &corr0, dg, de);
    int iters = 0;
    if ((rc = embed_smacof(D, k, dim, EMBED_SMACOF_MAX_ITER, EMBED_SMACOF_TOL, Y, &iters)) ||
        (rc = principal_axes(Y, k, dim))) {
        errbuf_set(err, errsz, rc, "stress majorisation of %d landmarks", k);
        goto out;
    }
    if ((rc = embed_biharmonic(geod_solver_laplacian(s), geod_solver_mass(s), pts, k, Y, dim, Z,
                               err, errsz)))
        goto out;
    if (q) {
        memset(q, 0, sizeof *q);
        q->landmarks = k;
        q->eigen_kept = kept;
        q->stress_classical = stress0;
        q->smacof_iterations = iters;
        landmark_fit(D, Y, k, dim, &q->stress_landmarks, &q->corr_landmarks, dg, de);
        rc = sample_quality(s, Z, dim, q, err, errsz);
    }
out:
    free(pts);
    free(D);
    free(Y);
    free(dg);
    free(de);
    return rc;
}
