/* ddm_bijective.c — DDM denoising of a map and its reverse together: each
 * direction's data term (its input map's functional map) plus a
 * consistency term through the other direction's current functional map,
 * solved by alternating exact projections; see ddm.h. */
#include "ddm/ddm.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int check_map(const bmap *M, int n, const mesh *to, const char *what, char *err,
                     size_t errsz)
{
    if (M->n != n || M->nt != to->nv)
        return errbuf_set(err, errsz, DDM_EINVAL,
                          "bijective denoising: %s map %d by %d for meshes of %d and %d vertices",
                          what, M->n, M->nt, n, to->nv);
    for (int i = 0; i < M->n; i++)
        if (M->face[i] < 0 || M->face[i] >= to->nf)
            return errbuf_set(err, errsz, DDM_EINVAL,
                              "bijective denoising: %s map row %d: face %d of %d", what, i,
                              M->face[i], to->nf);
    return DDM_OK;
}

/* Rows of Psi (first k columns) times X (k by k) into out (stride ld). */
static void rows_times(const lbo_basis *b, const double *X, int k, double s, double *out, int ld)
{
    for (int i = 0; i < b->nv; i++) {
        const double *p = b->phi + (size_t)i * b->k;
        double *o = out + (size_t)i * ld;
        for (int c = 0; c < k; c++)
            o[c] = 0;
        for (int a = 0; a < k; a++)
            for (int c = 0; c < k; c++)
                o[c] += p[a] * X[(size_t)a * k + c];
        for (int c = 0; c < k; c++)
            o[c] *= s;
    }
}

static void rows_copy(const lbo_basis *b, int k, double s, double *out, int ld)
{
    for (int i = 0; i < b->nv; i++)
        for (int c = 0; c < k; c++)
            out[(size_t)i * ld + c] = s * b->phi[(size_t)i * b->k + c];
}

/* Scale: an M-orthonormal basis of a mesh of area s has rows of size
 * ~1/sqrt(s), so the data term (in Psi_b's units) and the consistency term
 * (in Psi_a's) are made dimensionless by the areas, sa and sb: the energy
 * does not change when either mesh is scaled. */

/* One direction's step: P (a -> b) minimising
 * (1 - alpha) sb |Psi_a C - P Psi_b|^2 + alpha sa |P Psi_b D - Psi_a|^2
 * (D: the other direction's current functional map, b -> a); A (nb by 2k)
 * and B (na by 2k) are scratch. */
static int step(const lbo_basis *ba, const double *ma, double sa, const lbo_basis *bb,
                double sb, const mesh *to, const double *C, const double *D, int k, double alpha,
                double *A, double *B, bmap *P, char *err, size_t errsz)
{
    double s0 = sqrt((1 - alpha) * sb), s1 = sqrt(alpha * sa);
    rows_copy(bb, k, s0, A, 2 * k);
    rows_times(bb, D, k, s1, A + k, 2 * k);
    rows_times(ba, C, k, s0, B, 2 * k);
    rows_copy(ba, k, s1, B + k, 2 * k);
    return ddm_nearest_points(A, 2 * k, to, B, ba->nv, ma, P, NULL, err, errsz);
}

/* Both terms of one direction for the energy report, as step weighs
 * them, divided by sa (a mean over M_a): the data term |Psi_a C - P
 * Psi_b|^2 and the consistency term |P Psi_b D - Psi_a|^2. */
static double direction_energy(const lbo_basis *ba, const double *ma, double sa,
                               const lbo_basis *bb, double sb, const mesh *to, const bmap *P,
                               const double *C, const double *D, int k, double alpha, double *y,
                               double *z)
{
    double e = 0;
    for (int i = 0; i < P->n; i++) {
        const int *fv = to->f + 3 * (size_t)P->face[i];
        const double *pa = ba->phi + (size_t)i * ba->k;
        for (int c = 0; c < k; c++)
            y[c] = 0;
        for (int q = 0; q < 3; q++)
            for (int c = 0; c < k; c++)
                y[c] += P->w[3 * (size_t)i + q] * bb->phi[(size_t)fv[q] * bb->k + c];
        double data = 0, cons = 0;
        for (int c = 0; c < k; c++) {
            double t = 0;
            for (int a = 0; a < k; a++)
                t += pa[a] * C[(size_t)a * k + c];
            data += (t - y[c]) * (t - y[c]);
            z[c] = 0;
        }
        for (int a = 0; a < k; a++)
            for (int c = 0; c < k; c++)
                z[c] += y[a] * D[(size_t)a * k + c];
        for (int c = 0; c < k; c++)
            cons += (z[c] - pa[c]) * (z[c] - pa[c]);
        e += ma[i] * ((1 - alpha) * sb * data + alpha * sa * cons);
    }
    return e / sa;
}

int ddm_denoise_bijective(const lbo_basis *b1, const double *m1, const mesh *S,
                          const lbo_basis *b2, const double *m2, const mesh *T, const bmap *P0,
                          const bmap *Q0, int k, double alpha, int iterations, bmap *P, bmap *Q,
                          double *energy, char *err, size_t errsz)
{
    if (k < 1 || k > b1->k || k > b2->k || !m1 || !m2)
        return errbuf_set(err, errsz, DDM_EINVAL,
                          "bijective denoising: basis size %d (the bases hold %d, %d)%s", k,
                          b1->k, b2->k, m1 && m2 ? "" : ", a mass missing");
    if (!(alpha >= 0 && alpha < 1) || iterations < 0)
        return errbuf_set(err, errsz, DDM_EINVAL,
                          "bijective denoising: consistency weight %g (in [0, 1)), %d rounds (>= 0)",
                          alpha, iterations);
    if (S->nv != b1->nv || T->nv != b2->nv)
        return errbuf_set(err, errsz, DDM_EINVAL,
                          "bijective denoising: meshes of %d and %d vertices for bases of %d and %d",
                          S->nv, T->nv, b1->nv, b2->nv);
    int rc;
    if ((rc = check_map(P0, S->nv, T, "input", err, errsz)) ||
        (rc = check_map(Q0, T->nv, S, "input reverse", err, errsz)) ||
        (rc = check_map(P, S->nv, T, "output", err, errsz)) ||
        (rc = check_map(Q, T->nv, S, "output reverse", err, errsz)))
        return rc;
    int n1 = S->nv, n2 = T->nv, nmax = n1 > n2 ? n1 : n2;
    double s1 = 0, s2 = 0;                       /* the areas: sums of the lumped masses */
    for (int i = 0; i < n1; i++)
        s1 += m1[i];
    for (int j = 0; j < n2; j++)
        s2 += m2[j];
    size_t kk = (size_t)k * k;
    double *C12 = malloc(kk * sizeof *C12), *C21 = malloc(kk * sizeof *C21);
    double *D12 = malloc(kk * sizeof *D12), *D21 = malloc(kk * sizeof *D21);
    double *y = malloc(2 * (size_t)k * sizeof *y);
    double *A = malloc((size_t)nmax * 2 * k * sizeof *A), *B = malloc((size_t)nmax * 2 * k * sizeof *B);
    rc = DDM_ENOMEM;
    if (!C12 || !C21 || !D12 || !D21 || !y || !A || !B) {
        errbuf_set(err, errsz, DDM_ENOMEM, "bijective denoising: out of memory");
        goto out;
    }
    if ((rc = ddm_functional_map(b1, m1, b2, T, P0, k, k, C12, err, errsz)) ||
        (rc = ddm_functional_map(b2, m2, b1, S, Q0, k, k, C21, err, errsz)) ||
        (rc = ddm_deblur(b1, m1, b2, T, C12, k, k, P, NULL, err, errsz)) ||
        (rc = ddm_deblur(b2, m2, b1, S, C21, k, k, Q, NULL, err, errsz)))
        goto out;
    for (int r = 0; r <= iterations; r++) {
        if (r > 0) {
            if ((rc = ddm_functional_map(b2, m2, b1, S, Q, k, k, D21, err, errsz)) ||
                (rc = step(b1, m1, s1, b2, s2, T, C12, D21, k, alpha, A, B, P, err, errsz)))
                goto out;
            if ((rc = ddm_functional_map(b1, m1, b2, T, P, k, k, D12, err, errsz)) ||
                (rc = step(b2, m2, s2, b1, s1, S, C21, D12, k, alpha, A, B, Q, err, errsz)))
                goto out;
        }
        if (energy) {
            if ((rc = ddm_functional_map(b2, m2, b1, S, Q, k, k, D21, err, errsz)) ||
                (rc = ddm_functional_map(b1, m1, b2, T, P, k, k, D12, err, errsz)))
                goto out;
            energy[r] = direction_energy(b1, m1, s1, b2, s2, T, P, C12, D21, k, alpha, y, y + k) +
                        direction_energy(b2, m2, s2, b1, s1, S, Q, C21, D12, k, alpha, y, y + k);
        }
    }
    rc = DDM_OK;
out:
    free(C12);
    free(C21);
    free(D12);
    free(D21);
    free(y);
    free(A);
    free(B);
    return rc;
}
