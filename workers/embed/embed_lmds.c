/* embed_lmds.c — landmark MDS of geodesic distances and its quality report;
 * see embed.h. Sampling, eigenpairs and the fit measure live in their own
 * files; this one assembles the centred matrix and triangulates. */
#include "embed/embed.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

const char *embed_strerror(int code)
{
    switch (code) {
#define EMBED_STR(name, val, msg) case name: return msg;
        EMBED_ERRORS(EMBED_STR)
#undef EMBED_STR
    }
    return "unknown embedding error";
}

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

int embed_lmds(geod_solver *s, int dim, int k, int start, double *Z,
               embed_quality *q, char *err, size_t errsz)
{
    int nv = geod_solver_nv(s);
    if (dim <= 0)
        dim = EMBED_DIM_DEFAULT;
    if (k <= 0) {
        k = 3 * dim > EMBED_MIN_LANDMARKS ? 3 * dim : EMBED_MIN_LANDMARKS;
        k = k < nv ? k : nv;
    }
    if (dim > EMBED_MAX_DIM || k < dim + 1 || k > nv || start < 0 || start >= nv)
        return errbuf_set(err, errsz, EMBED_EINVAL,
                          "dim %d (max %d), landmarks %d (need dim+1..%d), start %d", dim,
                          EMBED_MAX_DIM, k, nv, start);
    int rc = EMBED_ENOMEM;
    int *pts = malloc((size_t)k * sizeof *pts);
    double *F = malloc((size_t)k * nv * sizeof *F), *D2 = malloc((size_t)k * k * sizeof *D2);
    double *mu = malloc((size_t)k * sizeof *mu), *w = malloc((size_t)dim * sizeof *w);
    double *V = malloc((size_t)k * dim * sizeof *V), *all_w = malloc((size_t)k * sizeof *all_w);
    double *dg = NULL, *de = NULL;
    if (!pts || !F || !D2 || !mu || !w || !V || !all_w) {
        errbuf_set(err, errsz, rc, "out of memory for %d landmarks", k);
        goto out;
    }
    if ((rc = embed_farthest_points(s, start, k, pts, F, err, errsz)) != EMBED_OK)
        goto out;

    /* D2 = squared symmetrised distances; B = -1/2 J D2 J into V's eigen call */
    for (int a = 0; a < k; a++)
        for (int b = 0; b < k; b++) {
            double d = 0.5 * (F[(size_t)a * nv + pts[b]] + F[(size_t)b * nv + pts[a]]);
            D2[(size_t)a * k + b] = d * d;
        }
    double tot = 0;
    for (int a = 0; a < k; a++) {
        mu[a] = 0;
        for (int b = 0; b < k; b++)
            mu[a] += D2[(size_t)a * k + b];
        mu[a] /= k;
        tot += mu[a];
    }
    tot /= k;
    double *B = malloc((size_t)k * k * sizeof *B);
    if (!B) {
        rc = errbuf_set(err, errsz, EMBED_ENOMEM, "out of memory");
        goto out;
    }
    for (int a = 0; a < k; a++)
        for (int b = 0; b < k; b++)
            B[(size_t)a * k + b] = -0.5 * (D2[(size_t)a * k + b] - mu[a] - mu[b] + tot);
    rc = embed_top_eigenpairs(B, k, dim, w, V, all_w);
    free(B);
    if (rc != EMBED_OK) {
        errbuf_set(err, errsz, rc, "eigenpairs of the %d by %d centred matrix", k, k);
        goto out;
    }

    /* pseudo-inverse columns v_i / sqrt(lambda_i), 0 for lambda_i <= 0 */
    for (int i = 0; i < dim; i++) {
        double sc = w[i] > 0 ? 1 / sqrt(w[i]) : 0;
        for (int a = 0; a < k; a++)
            V[(size_t)a * dim + i] *= sc;
    }
#pragma omp parallel for schedule(static)
    for (int x = 0; x < nv; x++) {
        double *z = Z + (size_t)x * dim;
        for (int i = 0; i < dim; i++)
            z[i] = 0;
        for (int a = 0; a < k; a++) {
            double d = F[(size_t)a * nv + x], r = -0.5 * (d * d - mu[a]);
            for (int i = 0; i < dim; i++)
                z[i] += r * V[(size_t)a * dim + i];
        }
    }

    if (q) {
        double kept = 0, all = 0;
        for (int i = 0; i < dim; i++)
            kept += w[i] > 0 ? w[i] : 0;
        for (int a = 0; a < k; a++)
            all += fabs(all_w[a]);
        memset(q, 0, sizeof *q);
        q->landmarks = k;
        q->eigen_kept = all > 0 ? kept / all : 0;
        size_t np = (size_t)k * (k - 1) / 2, n = 0;
        dg = malloc(np * sizeof *dg);
        de = malloc(np * sizeof *de);
        if (!dg || !de) {
            rc = errbuf_set(err, errsz, EMBED_ENOMEM, "out of memory for the report");
            goto out;
        }
        for (int a = 0; a < k; a++)
            for (int b = a + 1; b < k; b++, n++) {
                dg[n] = sqrt(D2[(size_t)a * k + b]);
                de[n] = dist_rows(Z, dim, pts[a], pts[b]);
            }
        embed_distance_fit(dg, de, (int)np, &q->stress_landmarks, &q->corr_landmarks);
        rc = sample_quality(s, Z, dim, q, err, errsz);
    }
out:
    free(pts);
    free(F);
    free(D2);
    free(mu);
    free(w);
    free(V);
    free(all_w);
    free(dg);
    free(de);
    return rc;
}
