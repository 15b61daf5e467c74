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

/* x = F^-1 b for ncol columns; GEOD_OK, GEOD_ENOMEM or GEOD_EFACTOR. */
static int solve(chol *F, const double *b, int ncol, double *x)
{
    int rc = chol_solve(F, b, ncol, x, NULL, 0);
    return rc == CHOL_OK ? GEOD_OK : rc == CHOL_ENOMEM ? GEOD_ENOMEM : GEOD_EFACTOR;
}

/* ncol fields; column c starts heat at src[start[c] .. start[c+1]).
 * dist: ncol by nv, row-major. */
static int fields(geod_solver *s, const int *src, const int *start, int ncol,
                  double *dist)
{
    int nv = s->nv, ni = s->n_interior, rc = GEOD_ENOMEM;
    /* column-major nv (B, U, Phi) or ni (Bd, Ud) by ncol */
    double *b = calloc((size_t)nv * ncol, sizeof *b), *u = malloc((size_t)nv * ncol * sizeof *u);
    double *phi = malloc((size_t)nv * ncol * sizeof *phi), *bd = NULL, *ud = NULL;
    int *seen = malloc((size_t)s->ncomp * sizeof *seen);
    double *sum = malloc((size_t)s->ncomp * sizeof *sum);
    if (!b || !u || !phi || !seen || !sum)
        goto out;
    for (int c = 0; c < ncol; c++)
        for (int p = start[c]; p < start[c + 1]; p++)
            b[src[p] + (size_t)c * nv] = 1;
    if ((rc = solve(s->heat, b, ncol, u)) != GEOD_OK)
        goto out;
    if (s->heat_dir) { /* average with the Dirichlet solution (0 on the boundary) */
        rc = GEOD_ENOMEM;
        if (!(bd = malloc((size_t)ni * ncol * sizeof *bd)) ||
            !(ud = malloc((size_t)ni * ncol * sizeof *ud)))
            goto out;
        for (int c = 0; c < ncol; c++)
            for (int r = 0; r < ni; r++)
                bd[r + (size_t)c * ni] = b[s->interior[r] + (size_t)c * nv];
        if ((rc = solve(s->heat_dir, bd, ncol, ud)) != GEOD_OK)
            goto out;
        for (int c = 0; c < ncol; c++) {
            double *uc = u + (size_t)c * nv;
            for (int i = 0; i < nv; i++)
                uc[i] *= 0.5;
            for (int r = 0; r < ni; r++)
                uc[s->interior[r]] += 0.5 * ud[r + (size_t)c * ni];
        }
    }
#pragma omp parallel for schedule(static)
    for (int c = 0; c < ncol; c++)
        divergence(s, u + (size_t)c * nv, b + (size_t)c * nv);
    if ((rc = solve(s->poisson, b, ncol, phi)) != GEOD_OK)
        goto out;

    /* shift per component by the mean over its sources, clamp, pin sources */
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
out:
    free(b);
    free(u);
    free(phi);
    free(bd);
    free(ud);
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
