/* embed_smacof.c — metric MDS by stress majorisation (SMACOF, de Leeuw
 * 1977; the Guttman transform with unit weights) of a small dense distance
 * matrix; see embed.h. Knows nothing about meshes.
 *
 * Unit weights on purpose: weights that favour short distances (1/D, 1/D^2)
 * give RHM starts that fold more (docs/decisions.md, "SMACOF with unit
 * weights, summed in a fixed order"). */
#include "embed/embed.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Row sums in parallel, their total in row order: the same value on every
 * run (a reduction over a dynamic schedule adds the rows in an order that
 * depends on the threads' timing, and SMACOF's stopping test on this value
 * then made the embedding, and every map after it, differ from run to run
 * in the last digits, which ECTM amplifies into different maps). rows: k
 * doubles of scratch. */
static double raw_stress(const double *D, const double *Y, int k, int dim, double *rows)
{
#pragma omp parallel for schedule(dynamic, 16)
    for (int i = 0; i < k; i++) {
        double s = 0;
        for (int j = i + 1; j < k; j++) {
            double d2 = 0;
            for (int c = 0; c < dim; c++) {
                double t = Y[(size_t)i * dim + c] - Y[(size_t)j * dim + c];
                d2 += t * t;
            }
            double r = sqrt(d2) - D[(size_t)i * k + j];
            s += r * r;
        }
        rows[i] = s;
    }
    double s = 0;
    for (int i = 0; i < k; i++)
        s += rows[i];
    return s;
}

int embed_smacof(const double *D, int k, int dim, int max_iter, double tol, double *Y,
                 int *iterations)
{
    double *Yn = malloc((size_t)k * dim * sizeof *Yn), *rows = malloc((size_t)k * sizeof *rows);
    int it = 0;
    if (!Yn || !rows) {
        free(Yn);
        free(rows);
        return EMBED_ENOMEM;
    }
    double s = raw_stress(D, Y, k, dim, rows);
    while (it < max_iter && s > 0) {
        /* Y <- B(Y) Y / k: b_ij = -D_ij / |y_i - y_j| (0 where the points
         * coincide), b_ii = -sum_j b_ij */
#pragma omp parallel for schedule(static)
        for (int i = 0; i < k; i++) {
            double *yn = Yn + (size_t)i * dim, bii = 0;
            const double *yi = Y + (size_t)i * dim;
            for (int c = 0; c < dim; c++)
                yn[c] = 0;
            for (int j = 0; j < k; j++) {
                if (j == i)
                    continue;
                const double *yj = Y + (size_t)j * dim;
                double d2 = 0;
                for (int c = 0; c < dim; c++)
                    d2 += (yi[c] - yj[c]) * (yi[c] - yj[c]);
                double b = d2 > 0 ? -D[(size_t)i * k + j] / sqrt(d2) : 0;
                bii -= b;
                for (int c = 0; c < dim; c++)
                    yn[c] += b * yj[c];
            }
            for (int c = 0; c < dim; c++)
                yn[c] = (yn[c] + bii * yi[c]) / k;
        }
        memcpy(Y, Yn, (size_t)k * dim * sizeof *Y);
        it++;
        double sn = raw_stress(D, Y, k, dim, rows);
        int done = s - sn <= tol * s;
        s = sn;
        if (done)
            break;
    }
    free(Yn);
    free(rows);
    if (iterations)
        *iterations = it;
    return EMBED_OK;
}
