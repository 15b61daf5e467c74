/* ddm_deblur.c — DDM's precise map from a functional map: per vertex of
 * M1, the exact nearest point of M2 embedded in R^k2 (or, for
 * ddm_nearest_points, in any R^d), with App. A.2's candidate-face bound;
 * see ddm.h. The rows' products with every vertex, which the bound needs,
 * are taken DDM__ROWS rows to a pass over A (tests/bench/bench_ddm.c). */
#include "ddm/ddm.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DDM__ROWS 8   /* rows of B per pass over A: the four pairs the kernel unrolls */
typedef double ddm__v2 __attribute__((vector_size(16)));   /* GCC's and Clang's vectors */

/* Per face of M2, in R^k2 with corners A0, A1, A2 and e1 = A1 - A0,
 * e2 = A2 - A0: the Gram entries a = e1.e1, h = e1.e2, c = e2.e2, the
 * products p1 = e1.A0, p2 = e2.A0, and the longest edge. */
typedef struct face_pre {
    double a, h, c, p1, p2, lmax;
} face_pre;

static double dot(const double *x, const double *y, int k)
{
    double s = 0;
    for (int j = 0; j < k; j++)
        s += x[j] * y[j];
    return s;
}

/* Q(s, t) = a s^2 + 2 h s t + c t^2 + 2 D s + 2 E t + F on the triangle
 * s, t >= 0, s + t <= 1: the minimum value, its (s, t) in *s, *t. */
static double triangle_min(const face_pre *f, double D, double E, double F, double *s, double *t)
{
    double a = f->a, h = f->h, c = f->c, det = a * c - h * h;
    if (det > 1e-14 * a * c) {
        double ss = (h * E - c * D) / det, tt = (h * D - a * E) / det;
        if (ss >= 0 && tt >= 0 && ss + tt <= 1) {
            *s = ss;
            *t = tt;
            return a * ss * ss + 2 * h * ss * tt + c * tt * tt + 2 * D * ss + 2 * E * tt + F;
        }
    }
    /* the minimum is on the boundary: the best of the three edges */
    double cand[3][2], best = INFINITY;
    double u = a > 0 ? -D / a : 0;
    cand[0][0] = u < 0 ? 0 : u > 1 ? 1 : u;               /* t = 0 */
    cand[0][1] = 0;
    u = c > 0 ? -E / c : 0;
    cand[1][0] = 0;                                        /* s = 0 */
    cand[1][1] = u < 0 ? 0 : u > 1 ? 1 : u;
    double den = a + c - 2 * h;                            /* s + t = 1 */
    u = den > 0 ? (a - h + D - E) / den : 0;
    u = u < 0 ? 0 : u > 1 ? 1 : u;
    cand[2][0] = 1 - u;
    cand[2][1] = u;
    for (int q = 0; q < 3; q++) {
        double ss = cand[q][0], tt = cand[q][1];
        double v = a * ss * ss + 2 * h * ss * tt + c * tt * tt + 2 * D * ss + 2 * E * tt + F;
        if (v < best) {
            best = v;
            *s = ss;
            *t = tt;
        }
    }
    return best;
}

int ddm_nearest_points(const double *A, int d, const mesh *T, const double *B, int n1,
                       const double *m1, bmap *P, ddm_stats *stats, char *err, size_t errsz)
{
    if (d < 1 || n1 < 1 || P->n != n1 || P->nt != T->nv)
        return errbuf_set(err, errsz, DDM_EINVAL,
                          "nearest points: dimension %d, %d points; map %d by %d for %d by %d", d,
                          n1, P->n, P->nt, n1, T->nv);
    int n2 = T->nv, nf = T->nf, rc = DDM_ENOMEM;
    if (nf < 1)
        return errbuf_set(err, errsz, DDM_EINVAL, "nearest points: the target has no faces");
    for (int q = 0; q < 3 * nf; q++)
        if (T->f[q] < 0 || T->f[q] >= n2)
            return errbuf_set(err, errsz, DDM_EINVAL, "nearest points: face %d has vertex %d of %d",
                              q / 3, T->f[q], n2);
    double *norm2 = malloc((size_t)n2 * sizeof *norm2);
    face_pre *fp = malloc((size_t)nf * sizeof *fp);
    int *vface = malloc((size_t)n2 * sizeof *vface);
    long long solved = 0;
    double cost = 0;
    int fail = 0;
    if (!norm2 || !fp || !vface) {
        errbuf_set(err, errsz, DDM_ENOMEM, "nearest points: out of memory (%d vertices)", n2);
        goto out;
    }
    for (int j = 0; j < n2; j++) {
        norm2[j] = dot(A + (size_t)j * d, A + (size_t)j * d, d);
        vface[j] = -1;
    }
    for (int f = nf - 1; f >= 0; f--)            /* lowest face with corner j, and which corner */
        for (int q = 0; q < 3; q++)
            vface[T->f[3 * f + q]] = 3 * f + q;
    for (int f = 0; f < nf; f++) {
        const double *a0 = A + (size_t)T->f[3 * f] * d, *a1 = A + (size_t)T->f[3 * f + 1] * d;
        const double *a2 = A + (size_t)T->f[3 * f + 2] * d;
        double a = 0, h = 0, c = 0, p1 = 0, p2 = 0;
        for (int j = 0; j < d; j++) {
            double e1 = a1[j] - a0[j], e2 = a2[j] - a0[j];
            a += e1 * e1;
            h += e1 * e2;
            c += e2 * e2;
            p1 += e1 * a0[j];
            p2 += e2 * a0[j];
        }
        double l = fmax(fmax(a, c), a + c - 2 * h);
        fp[f] = (face_pre){a, h, c, p1, p2, sqrt(fmax(l, 0))};
    }
#pragma omp parallel reduction(+ : solved, cost)
    {
        /* DDM__ROWS rows at a time: their products with every A_j in one
         * pass over A (each A_j read once for the block, the block's
         * columns in registers) */
        double *g = malloc((size_t)n2 * DDM__ROWS * sizeof *g);
        double *d2 = malloc((size_t)n2 * DDM__ROWS * sizeof *d2);
        double *bt = aligned_alloc(16, (size_t)d * DDM__ROWS * sizeof *bt);
        if (!g || !d2 || !bt) {
#pragma omp atomic write
            fail = 1;
        }
#pragma omp for schedule(dynamic, 2)
        for (int i0 = 0; i0 < n1; i0 += DDM__ROWS) {
            if (!g || !d2 || !bt)
                continue;
            int nr = n1 - i0 < DDM__ROWS ? n1 - i0 : DDM__ROWS;
            double bb[DDM__ROWS];
            for (int r = 0; r < DDM__ROWS; r++) {  /* B's rows transposed, the block padded */
                const double *b = B + (size_t)(i0 + (r < nr ? r : 0)) * d;
                bb[r] = dot(b, b, d);
                for (int c = 0; c < d; c++)
                    bt[(size_t)c * DDM__ROWS + r] = b[c];
            }
            const ddm__v2 *bv = (const ddm__v2 *)bt;
            for (int j = 0; j < n2; j++) {
                const double *aj = A + (size_t)j * d;
                _Static_assert(DDM__ROWS == 8, "the four accumulators below");
                ddm__v2 acc[DDM__ROWS / 2] = {{0, 0}};   /* 4 registers, not memory */
                for (int c = 0; c < d; c++) {
                    ddm__v2 a = {aj[c], aj[c]};
                    acc[0] += a * bv[4 * c];
                    acc[1] += a * bv[4 * c + 1];
                    acc[2] += a * bv[4 * c + 2];
                    acc[3] += a * bv[4 * c + 3];
                }
                for (int r = 0; r < DDM__ROWS; r++) {
                    double x = acc[r / 2][r % 2], e = norm2[j] - 2 * x + bb[r];
                    g[(size_t)r * n2 + j] = x;
                    d2[(size_t)r * n2 + j] = e > 0 ? e : 0;
                }
            }
            for (int r = 0; r < nr; r++) {
                int i = i0 + r;
                const double *gi = g + (size_t)r * n2, *di = d2 + (size_t)r * n2;
                double best = INFINITY;
                int vbest = 0;
                for (int j = 0; j < n2; j++)
                    if (di[j] < best && vface[j] >= 0) {
                        best = di[j];
                        vbest = j;
                    }
                /* the nearest vertex (Delta_min), as a point of its lowest face */
                int bf = vface[vbest] / 3, corner = vface[vbest] % 3;
                double bw[3] = {corner == 0, corner == 1, corner == 2};
                double rbest = sqrt(best);
                for (int f = 0; f < nf; f++) {   /* the bound, squared: dmin^2 > (rbest + lmax)^2 */
                    const int *fv = T->f + 3 * f;
                    double x0 = di[fv[0]], x1 = di[fv[1]], x2 = di[fv[2]];
                    double dmin2 = x0 < x1 ? x0 : x1, rr = rbest + fp[f].lmax;   /* d2 has no NaN */
                    dmin2 = x2 < dmin2 ? x2 : dmin2;
                    if (dmin2 > rr * rr)
                        continue;
                    solved++;
                    double D = fp[f].p1 - (gi[fv[1]] - gi[fv[0]]), E = fp[f].p2 - (gi[fv[2]] - gi[fv[0]]);
                    double ss = 0, tt = 0, v = triangle_min(fp + f, D, E, di[fv[0]], &ss, &tt);
                    if (v < best) {
                        best = fmax(v, 0);
                        rbest = sqrt(best);
                        bf = f;
                        bw[0] = 1 - ss - tt;
                        bw[1] = ss;
                        bw[2] = tt;
                    }
                }
                P->face[i] = bf;
                double ws = 0;
                for (int q = 0; q < 3; q++)
                    ws += bw[q] = bw[q] < 0 ? 0 : bw[q];
                for (int q = 0; q < 3; q++)
                    P->w[3 * i + q] = bw[q] / ws;
                if (m1)
                    cost += m1[i] * best;
            }
        }
        free(g);
        free(d2);
        free(bt);
    }
    if (fail) {
        errbuf_set(err, errsz, DDM_ENOMEM, "nearest points: out of memory for a row's work");
        goto out;
    }
    if (stats) {
        stats->faces_solved = solved;
        stats->faces_total = (long long)n1 * nf;
        stats->cost = cost;
    }
    rc = DDM_OK;
out:
    free(norm2);
    free(fp);
    free(vface);
    return rc;
}

int ddm_deblur(const lbo_basis *b1, const double *m1, const lbo_basis *b2, const mesh *T,
               const double *C, int k1, int k2, bmap *P, ddm_stats *stats, char *err,
               size_t errsz)
{
    if (k1 < 1 || k1 > b1->k || k2 < 1 || k2 > b2->k)
        return errbuf_set(err, errsz, DDM_EINVAL,
                          "deblurring: basis sizes %d, %d (the bases hold %d, %d)", k1, k2,
                          b1->k, b2->k);
    if (T->nv != b2->nv || P->n != b1->nv || P->nt != T->nv)
        return errbuf_set(err, errsz, DDM_EINVAL,
                          "deblurring: target of %d vertices for a basis of %d; map %d by %d "
                          "for %d by %d", T->nv, b2->nv, P->n, P->nt, b1->nv, T->nv);
    int n1 = b1->nv, n2 = T->nv;
    double *A = malloc((size_t)n2 * k2 * sizeof *A), *B = malloc((size_t)n1 * k2 * sizeof *B);
    if (!A || !B) {
        free(A);
        free(B);
        return errbuf_set(err, errsz, DDM_ENOMEM, "deblurring: out of memory (%d, %d vertices)",
                          n1, n2);
    }
    for (int j = 0; j < n2; j++)
        memcpy(A + (size_t)j * k2, b2->phi + (size_t)j * b2->k, (size_t)k2 * sizeof *A);
    for (int i = 0; i < n1; i++) {                /* B = rows of Psi1 C */
        const double *p = b1->phi + (size_t)i * b1->k;
        double *b = B + (size_t)i * k2;
        for (int c = 0; c < k2; c++)
            b[c] = 0;
        for (int a = 0; a < k1; a++)
            for (int c = 0; c < k2; c++)
                b[c] += p[a] * C[(size_t)a * k2 + c];
    }
    int rc = ddm_nearest_points(A, k2, T, B, n1, m1, P, stats, err, errsz);
    if (rc == DDM_EINVAL && err && errsz) {
        char detail[512];
        snprintf(detail, sizeof detail, "%s", err);
        errbuf_set(err, errsz, rc, "deblurring: %s", detail);
    }
    free(A);
    free(B);
    return rc;
}
