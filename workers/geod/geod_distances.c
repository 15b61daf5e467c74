/* geod_distances.c — the three heat-method steps for a batch of distance
 * fields with the solver's factorisations; see geod.h. Builds nothing: all
 * operators come from geod_solver.c. */
#include "geod/geod__solver.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* b (nv) = integrated divergence of X = -grad u / |grad u|, in the weak
 * form b_i = sum_f area_f <grad hat_i, X_f> (equal to the paper's cotan
 * formula), so that L phi = b fits grad phi to X in least squares. Serial
 * over faces in order: deterministic. */
static void divergence(const geod_solver *s, const double *u, double *b)
{
    memset(b, 0, (size_t)s->nv * sizeof *b);
    for (int t = 0; t < s->nf; t++) {
        const double *g = s->grad + 6 * (size_t)t;
        const int *c = s->f + 3 * (size_t)t;
        double X[2];
        for (int d = 0; d < 2; d++)
            X[d] = -(u[c[0]] * g[d] + u[c[1]] * g[2 + d] + u[c[2]] * g[4 + d]);
        double n = sqrt(X[0] * X[0] + X[1] * X[1]);
        if (!(n > 0) || !isfinite(n))
            continue; /* flat heat (no source in reach) or degenerate face */
        double w = s->area[t] / n;
        for (int k = 0; k < 3; k++)
            b[c[k]] += w * (g[2 * k] * X[0] + g[2 * k + 1] * X[1]);
    }
}

static cholmod_dense *solve(geod_solver *s, cholmod_factor *F, cholmod_dense *B)
{
    cholmod_dense *X = cholmod_solve(CHOLMOD_A, F, B, &s->cc);
    if (X && s->cc.status != CHOLMOD_OK)
        cholmod_free_dense(&X, &s->cc);
    return X;
}

/* ncol fields; column c starts heat at src[start[c] .. start[c+1]).
 * dist: ncol by nv, row-major. */
static int fields(geod_solver *s, const int *src, const int *start, int ncol,
                  double *dist)
{
    int nv = s->nv, rc = GEOD_ENOMEM;
    cholmod_dense *B = NULL, *U = NULL, *Bd = NULL, *Ud = NULL, *Phi = NULL;
    int *seen = NULL;
    double *sum = NULL;
    if (!(B = cholmod_zeros(nv, ncol, CHOLMOD_REAL, &s->cc)))
        goto out;
    double *b = B->x;
    for (int c = 0; c < ncol; c++)
        for (int p = start[c]; p < start[c + 1]; p++)
            b[src[p] + (size_t)c * nv] = 1;
    if (!(U = solve(s, s->heat, B)))
        goto fail;
    if (s->heat_dir) { /* average with the Dirichlet solution (0 on the boundary) */
        int ni = s->n_interior;
        if (!(Bd = cholmod_zeros(ni, ncol, CHOLMOD_REAL, &s->cc)))
            goto out;
        double *bd = Bd->x;
        for (int c = 0; c < ncol; c++)
            for (int r = 0; r < ni; r++)
                bd[r + (size_t)c * ni] = b[s->interior[r] + (size_t)c * nv];
        if (!(Ud = solve(s, s->heat_dir, Bd)))
            goto fail;
        double *u = U->x, *ud = Ud->x;
        for (int c = 0; c < ncol; c++) {
            double *uc = u + (size_t)c * nv;
            for (int i = 0; i < nv; i++)
                uc[i] *= 0.5;
            for (int r = 0; r < ni; r++)
                uc[s->interior[r]] += 0.5 * ud[r + (size_t)c * ni];
        }
    }
    const double *u = U->x;
#pragma omp parallel for schedule(static)
    for (int c = 0; c < ncol; c++)
        divergence(s, u + (size_t)c * nv, b + (size_t)c * nv);
    if (!(Phi = solve(s, s->poisson, B)))
        goto fail;

    /* shift per component by the mean over its sources, clamp, pin sources */
    seen = malloc((size_t)s->ncomp * sizeof *seen);
    sum = malloc((size_t)s->ncomp * sizeof *sum);
    if (!seen || !sum)
        goto out;
    const double *phi = Phi->x;
    for (int c = 0; c < ncol; c++) {
        const double *pc = phi + (size_t)c * nv;
        double *dc = dist + (size_t)c * nv;
        memset(seen, 0, (size_t)s->ncomp * sizeof *seen);
        memset(sum, 0, (size_t)s->ncomp * sizeof *sum);
        for (int p = start[c]; p < start[c + 1]; p++) {
            seen[s->comp[src[p]]]++;
            sum[s->comp[src[p]]] += pc[src[p]];
        }
        for (int i = 0; i < nv; i++) {
            int k = s->comp[i];
            double v = seen[k] ? pc[i] - sum[k] / seen[k] : INFINITY;
            dc[i] = v > 0 ? v : 0;
        }
        for (int p = start[c]; p < start[c + 1]; p++)
            dc[src[p]] = 0;
    }
    rc = GEOD_OK;
    goto out;
fail:
    rc = s->cc.status == CHOLMOD_OUT_OF_MEMORY ? GEOD_ENOMEM : GEOD_EFACTOR;
out:
    cholmod_free_dense(&B, &s->cc);
    cholmod_free_dense(&U, &s->cc);
    cholmod_free_dense(&Bd, &s->cc);
    cholmod_free_dense(&Ud, &s->cc);
    cholmod_free_dense(&Phi, &s->cc);
    free(seen);
    free(sum);
    return rc;
}

static int check_sources(const geod_solver *s, const int *src, int n)
{
    if (!src || n < 1)
        return GEOD_EINVAL;
    for (int i = 0; i < n; i++)
        if (src[i] < 0 || src[i] >= s->nv)
            return GEOD_EINVAL;
    return GEOD_OK;
}

int geod_distances(geod_solver *s, const int *sources, int nsrc, double *dist)
{
    if (!s || !dist || check_sources(s, sources, nsrc) != GEOD_OK)
        return GEOD_EINVAL;
    int start[2] = {0, nsrc};
    return fields(s, sources, start, 1, dist);
}

int geod_all_pairs_from(geod_solver *s, const int *sources, int k, double *out)
{
    if (!s || !out || check_sources(s, sources, k) != GEOD_OK)
        return GEOD_EINVAL;
    int start[GEOD_BATCH + 1];
    for (int c = 0; c <= GEOD_BATCH; c++)
        start[c] = c;
    for (int a = 0; a < k; a += GEOD_BATCH) {
        int n = k - a < GEOD_BATCH ? k - a : GEOD_BATCH;
        int rc = fields(s, sources + a, start, n, out + (size_t)a * s->nv);
        if (rc != GEOD_OK)
            return rc;
    }
    return GEOD_OK;
}
