/* init_affine.c — see init_affine.h. The fit is a 4×4 normal-equation solve
 * (Gaussian elimination with partial pivoting); the projection is proj's. */
#include "init/init_affine.h"
#include "proj/proj.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Solves M·x = b for 4×4 M (destroyed) and 3 right-hand sides b (4×3,
 * destroyed, solution written back). Returns the smallest pivot relative to
 * the largest diagonal entry: a conditioning estimate. */
static double solve4(double M[4][4], double b[4][3])
{
    double maxdiag = 0, minpiv = INFINITY;
    for (int i = 0; i < 4; i++)
        maxdiag = fmax(maxdiag, fabs(M[i][i]));
    for (int c = 0; c < 4; c++) {
        int p = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(M[r][c]) > fabs(M[p][c]))
                p = r;
        if (p != c) {
            for (int k = 0; k < 4; k++) { double x = M[c][k]; M[c][k] = M[p][k]; M[p][k] = x; }
            for (int k = 0; k < 3; k++) { double x = b[c][k]; b[c][k] = b[p][k]; b[p][k] = x; }
        }
        minpiv = fmin(minpiv, fabs(M[c][c]));
        if (M[c][c] == 0)
            return 0;
        for (int r = c + 1; r < 4; r++) {
            double f = M[r][c] / M[c][c];
            for (int k = c; k < 4; k++) M[r][k] -= f * M[c][k];
            for (int k = 0; k < 3; k++) b[r][k] -= f * b[c][k];
        }
    }
    for (int c = 3; c >= 0; c--)
        for (int k = 0; k < 3; k++) {
            double s = b[c][k];
            for (int j = c + 1; j < 4; j++) s -= M[c][j] * b[j][k];
            b[c][k] = s / M[c][c];
        }
    return maxdiag > 0 ? minpiv / maxdiag : 0;
}

int init_affine_fit(const mesh *S, const mesh *T, const lmk_set *L,
                    double A[9], double t[3], char *err, size_t errsz)
{
    /* Centre the source landmarks and scale them to unit RMS radius so the
     * conditioning test does not depend on the mesh's units. */
    double c[3] = {0, 0, 0}, r2 = 0;
    for (int k = 0; k < L->n; k++)
        for (int d = 0; d < 3; d++)
            c[d] += S->v[3 * L->src[k] + d] / L->n;
    for (int k = 0; k < L->n; k++)
        for (int d = 0; d < 3; d++) {
            double x = S->v[3 * L->src[k] + d] - c[d];
            r2 += x * x / L->n;
        }
    double sc = r2 > 0 ? 1 / sqrt(r2) : 0;
    double M[4][4] = {{0}}, b[4][3] = {{0}};
    for (int k = 0; k < L->n; k++) {
        double u[4];
        for (int d = 0; d < 3; d++)
            u[d] = (S->v[3 * L->src[k] + d] - c[d]) * sc;
        u[3] = 1;
        for (int i = 0; i < 4; i++) {
            for (int j = 0; j < 4; j++)
                M[i][j] += u[i] * u[j];
            for (int d = 0; d < 3; d++)
                b[i][d] += u[i] * T->v[3 * L->tgt[k] + d];
        }
    }
    if (sc == 0 || solve4(M, b) < 1e-6)
        return errbuf_set(err, errsz, INIT_EDEGENERATE,
                          "the %d source landmarks are (nearly) coplanar: the affine "
                          "initialisation needs 4 that span 3-D space", L->n);
    /* y = Bᵀ·[(x − c)·sc; 1]  =>  A = sc·B[0..2]ᵀ, t = B[3] − A·c */
    for (int d = 0; d < 3; d++) {
        for (int j = 0; j < 3; j++)
            A[3 * d + j] = sc * b[j][d];
        t[d] = b[3][d] - (A[3 * d] * c[0] + A[3 * d + 1] * c[1] + A[3 * d + 2] * c[2]);
    }
    return INIT_OK;
}

int init_affine_map(const mesh *S, const mesh *T, const lmk_set *L,
                    bmap **out, char *err, size_t errsz)
{
    *out = NULL;
    double A[9], t[3];
    int rc = init_affine_fit(S, T, L, A, t, err, errsz);
    if (rc)
        return rc;
    double *q = malloc(sizeof(double) * ((size_t)S->nv * 3 + 1));
    bmap *P = bmap_new(S->nv, T->nv);
    proj_tree *tree = proj_tree_new(T, err, errsz);
    if (!q || !P || !tree) {
        rc = errbuf_set(err, errsz, INIT_ENOMEM, "out of memory for the affine initialisation");
        goto out;
    }
    for (int i = 0; i < S->nv; i++) {
        const double *x = S->v + 3 * i;
        for (int d = 0; d < 3; d++)
            q[3 * i + d] = A[3 * d] * x[0] + A[3 * d + 1] * x[1] + A[3 * d + 2] * x[2] + t[d];
        P->face[i] = -1;
    }
    proj_closest(tree, 3, T->v, 1.0, S->nv, q, P->face, P->w, NULL);
    *out = P;
    P = NULL;
out:
    proj_tree_free(tree);
    bmap_free(P);
    free(q);
    return rc;
}
