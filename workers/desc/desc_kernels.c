/* desc_kernels.c — heat and wave kernel signatures and wave kernel maps
 * from a Laplace–Beltrami basis; see desc.h. */
#include "desc/desc.h"

#include <math.h>
#include <stdlib.h>

/* Index of the first eigenvalue above the zero threshold, or -1; never 0
 * (lbo's spectra always start with the constants). */
static int first_nonzero(const lbo_basis *b)
{
    if (!b || b->k < 2)
        return -1;
    double lmax = b->lambda[b->k - 1];
    for (int j = 1; j < b->k; j++)
        if (b->lambda[j] > DESC_ZERO_REL * lmax)
            return j;
    return -1;
}

int desc_hks_times(const lbo_basis *b, int nt, double *t)
{
    int j1 = first_nonzero(b);
    if (j1 < 0 || nt < 1)
        return DESC_EINVAL;
    double lo = log(4 * log(10.0) / b->lambda[b->k - 1]), hi = log(4 * log(10.0) / b->lambda[j1]);
    for (int q = 0; q < nt; q++)
        t[q] = exp(nt > 1 ? lo + (hi - lo) * q / (nt - 1) : lo);
    return DESC_OK;
}

int desc_wks_energies(const lbo_basis *b, int ne, double *e, double *sigma)
{
    int j1 = first_nonzero(b);
    if (j1 < 0 || ne < 1)
        return DESC_EINVAL;
    double lo = log(b->lambda[j1]), hi = log(b->lambda[b->k - 1]);
    double s = DESC_WKS_SIGMA_REL * (hi - lo);
    if (!(s > 0))   /* one distinct non-zero eigenvalue */
        s = 1;
    if (hi - lo > 4 * s) {
        lo += 2 * s;
        hi -= 2 * s;
    }
    for (int q = 0; q < ne; q++)
        e[q] = ne > 1 ? lo + (hi - lo) * q / (ne - 1) : 0.5 * (lo + hi);
    *sigma = s;
    return DESC_OK;
}

int desc_hks(const lbo_basis *b, const double *t, int nt, double *out)
{
    if (!b || b->k < 1 || nt < 1)
        return DESC_EINVAL;
    int k = b->k;
    double *w = malloc((size_t)k * nt * sizeof *w);
    if (!w)
        return DESC_ENOMEM;
    for (int j = 0; j < k; j++)
        for (int q = 0; q < nt; q++)
            w[(size_t)j * nt + q] = exp(-b->lambda[j] * t[q]);
    for (int i = 0; i < b->nv; i++) {
        const double *p = b->phi + (size_t)i * k;
        double *o = out + (size_t)i * nt;
        for (int q = 0; q < nt; q++)
            o[q] = 0;
        for (int j = 0; j < k; j++)
            for (int q = 0; q < nt; q++)
                o[q] += w[(size_t)j * nt + q] * p[j] * p[j];
    }
    free(w);
    return DESC_OK;
}

/* w: k by ne, the normalised filters C_e g_e(lambda_j). 0 or DESC_EINVAL. */
static int wave_filters(const lbo_basis *b, const double *e, int ne, double sigma, double *w)
{
    int j1 = first_nonzero(b);
    if (j1 < 0 || ne < 1 || !(sigma > 0))
        return DESC_EINVAL;
    for (int q = 0; q < ne; q++) {
        double sum = 0;
        for (int j = 0; j < b->k; j++) {
            double d = j < j1 ? 0 : e[q] - log(b->lambda[j]);
            double g = j < j1 ? 0 : exp(-d * d / (2 * sigma * sigma));
            w[(size_t)j * ne + q] = g;
            sum += g;
        }
        if (!(sum > 0))
            return DESC_EINVAL;
        for (int j = 0; j < b->k; j++)
            w[(size_t)j * ne + q] /= sum;
    }
    return DESC_OK;
}

int desc_wks(const lbo_basis *b, const double *e, int ne, double sigma, double *out)
{
    if (!b || b->k < 1 || ne < 1)
        return DESC_EINVAL;
    int k = b->k, rc;
    double *w = malloc((size_t)k * ne * sizeof *w);
    if (!w)
        return DESC_ENOMEM;
    if ((rc = wave_filters(b, e, ne, sigma, w)) == DESC_OK)
        for (int i = 0; i < b->nv; i++) {
            const double *p = b->phi + (size_t)i * k;
            double *o = out + (size_t)i * ne;
            for (int q = 0; q < ne; q++)
                o[q] = 0;
            for (int j = 0; j < k; j++)
                for (int q = 0; q < ne; q++)
                    o[q] += w[(size_t)j * ne + q] * p[j] * p[j];
        }
    free(w);
    return rc;
}

int desc_wkm(const lbo_basis *b, const int *lmk, int nl, const double *e, int ne, double sigma,
             double *out)
{
    if (!b || b->k < 1 || ne < 1 || nl < 1)
        return DESC_EINVAL;
    for (int a = 0; a < nl; a++)
        if (lmk[a] < 0 || lmk[a] >= b->nv)
            return DESC_EINVAL;
    int k = b->k, rc, cols = nl * ne;
    double *w = malloc((size_t)k * ne * sizeof *w), *c = malloc((size_t)k * cols * sizeof *c);
    if (!w || !c) {
        free(w);
        free(c);
        return DESC_ENOMEM;
    }
    if ((rc = wave_filters(b, e, ne, sigma, w)) == DESC_OK) {
        /* c[j][a ne + q] = w_jq phi_j(l_a): the coefficients of each column */
        for (int j = 0; j < k; j++)
            for (int a = 0; a < nl; a++)
                for (int q = 0; q < ne; q++)
                    c[(size_t)j * cols + a * ne + q] =
                        w[(size_t)j * ne + q] * b->phi[(size_t)lmk[a] * k + j];
        for (int i = 0; i < b->nv; i++) {
            const double *p = b->phi + (size_t)i * k;
            double *o = out + (size_t)i * cols;
            for (int q = 0; q < cols; q++)
                o[q] = 0;
            for (int j = 0; j < k; j++)
                for (int q = 0; q < cols; q++)
                    o[q] += c[(size_t)j * cols + q] * p[j];
        }
    }
    free(w);
    free(c);
    return rc;
}
