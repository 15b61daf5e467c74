/* fmap.c — functional maps from descriptors by row-wise least squares with
 * Laplacian commutativity, landmark descriptors, and the nearest-neighbour
 * vertex map in the spectral embedding; see fmap.h. */
#include "fmap/fmap.h"
#include "desc/desc.h"
#include "util/errbuf.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A (k by nd) = Psi^T M F (first k columns of Psi), each column of F
 * divided by its M-norm (a zero column stays zero). 0 when out of memory. */
static int coefficients(const lbo_basis *b, const double *mass, const double *F, int nd, int k,
                        double *A)
{
    double *norm = calloc((size_t)nd, sizeof *norm);
    if (!norm)
        return 0;
    memset(A, 0, (size_t)k * nd * sizeof *A);
    for (int i = 0; i < b->nv; i++) {
        const double *f = F + (size_t)i * nd, *p = b->phi + (size_t)i * b->k;
        for (int c = 0; c < nd; c++)
            norm[c] += mass[i] * f[c] * f[c];
        for (int a = 0; a < k; a++)
            for (int c = 0; c < nd; c++)
                A[(size_t)a * nd + c] += p[a] * mass[i] * f[c];
    }
    for (int c = 0; c < nd; c++) {
        double s = norm[c] > 0 ? 1 / sqrt(norm[c]) : 0;
        for (int a = 0; a < k; a++)
            A[(size_t)a * nd + c] *= s;
    }
    free(norm);
    return 1;
}

static void mat_mul(const double *A, const double *B, int n, int m, int p, double *out)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < p; j++) {
            double s = 0;
            for (int q = 0; q < m; q++)
                s += A[(size_t)i * m + q] * B[(size_t)q * p + j];
            out[(size_t)i * p + j] = s;
        }
}

/* out (n by p) = A^T B, A: m by n, B: m by p. */
static void mat_mul_tn(const double *A, const double *B, int m, int n, int p, double *out)
{
    memset(out, 0, (size_t)n * p * sizeof *out);
    for (int q = 0; q < m; q++)
        for (int i = 0; i < n; i++) {
            double a = A[(size_t)q * n + i];
            for (int j = 0; j < p; j++)
                out[(size_t)i * p + j] += a * B[(size_t)q * p + j];
        }
}

/* out (n by p) = A B^T, A: n by m, B: p by m. */
static void mat_mul_nt(const double *A, const double *B, int n, int m, int p, double *out)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < p; j++) {
            double s = 0;
            for (int q = 0; q < m; q++)
                s += A[(size_t)i * m + q] * B[(size_t)j * m + q];
            out[(size_t)i * p + j] = s;
        }
}

/* D (k1 by k2): D_ac = (λ1_a − λ2_c)², the commutativity penalty of the
 * coefficient C_ac; returns its Frobenius norm (1 when 0), which the
 * solvers divide it by (weights of any basis sizes on one scale). */
static double commutator_weights(const lbo_basis *b1, const lbo_basis *b2, int k1, int k2,
                                 double *D)
{
    double dn = 0;
    for (int a = 0; a < k1; a++)
        for (int c = 0; c < k2; c++) {
            double d = b1->lambda[a] - b2->lambda[c];
            D[(size_t)a * k2 + c] = d * d;
            dn += d * d * d * d;
        }
    return dn > 0 ? sqrt(dn) : 1;
}

int fmap_from_descriptors(const lbo_basis *b1, const double *m1, const double *F1,
                          const lbo_basis *b2, const double *m2, const double *F2, int nd,
                          int k1, int k2, double mu, double *C, char *err, size_t errsz)
{
    if (k1 < 1 || k1 > b1->k || k2 < 1 || k2 > b2->k)
        return errbuf_set(err, errsz, FMAP_EINVAL,
                          "functional map: basis sizes %d, %d (the bases hold %d, %d)", k1, k2,
                          b1->k, b2->k);
    if (nd < 1 || !(mu >= 0) || !isfinite(mu))
        return errbuf_set(err, errsz, FMAP_EINVAL, "functional map: %d descriptors, mu %g", nd,
                          mu);
    int rc = FMAP_ENOMEM;
    double *A1 = malloc((size_t)k1 * nd * sizeof *A1), *A2 = malloc((size_t)k2 * nd * sizeof *A2);
    double *G = malloc((size_t)k2 * k2 * sizeof *G), *S = malloc((size_t)k2 * k2 * sizeof *S);
    double *D = malloc((size_t)k1 * k2 * sizeof *D);
    if (!A1 || !A2 || !G || !S || !D || !coefficients(b1, m1, F1, nd, k1, A1) ||
        !coefficients(b2, m2, F2, nd, k2, A2)) {
        errbuf_set(err, errsz, FMAP_ENOMEM, "functional map: out of memory (%d descriptors)", nd);
        goto out;
    }
    mat_mul_nt(A2, A2, k2, nd, k2, G);   /* G = A2 A2^T */
    double dn = commutator_weights(b1, b2, k1, k2, D);
    for (int a = 0; a < k1; a++) {
        double *row = C + (size_t)a * k2;
        memcpy(S, G, (size_t)k2 * k2 * sizeof *S);
        for (int c = 0; c < k2; c++) {
            S[(size_t)c * k2 + c] += mu * D[(size_t)a * k2 + c] / dn;
            double s = 0;
            for (int q = 0; q < nd; q++)
                s += A2[(size_t)c * nd + q] * A1[(size_t)a * nd + q];
            row[c] = s;
        }
        int info = LAPACKE_dposv_work(LAPACK_COL_MAJOR, 'U', k2, 1, S, k2, row, k2);
        if (info != 0) {
            rc = errbuf_set(err, errsz, FMAP_ESOLVE,
                            "functional map: row %d's system is singular (LAPACK info %d; "
                            "%d descriptors for %d coefficients, mu %g)", a, info, nd, k2, mu);
            goto out;
        }
    }
    rc = FMAP_OK;
out:
    free(A1);
    free(A2);
    free(G);
    free(S);
    free(D);
    return rc;
}

int fmap_landmark_descriptors(const lbo_basis *b1, const lbo_basis *b2, const lmk_set *L,
                              int ne, double **F1, double **F2, int *nd, char *err,
                              size_t errsz)
{
    *F1 = *F2 = NULL;
    *nd = 0;
    if (ne < 1 || !L || L->n < 0)
        return errbuf_set(err, errsz, FMAP_EINVAL, "landmark descriptors: %d energies", ne);
    int cols = ne * (1 + L->n), rc;
    double sigma, *e = malloc((size_t)ne * sizeof *e);
    double *W1 = malloc((size_t)b1->nv * ne * (L->n > 0 ? L->n : 1) * sizeof *W1);
    double *W2 = malloc((size_t)b2->nv * ne * (L->n > 0 ? L->n : 1) * sizeof *W2);
    *F1 = malloc((size_t)b1->nv * cols * sizeof **F1);
    *F2 = malloc((size_t)b2->nv * cols * sizeof **F2);
    if (!e || !W1 || !W2 || !*F1 || !*F2) {
        rc = errbuf_set(err, errsz, FMAP_ENOMEM, "landmark descriptors: out of memory");
        goto out;
    }
    if (desc_wks_energies(b1, ne, e, &sigma) != DESC_OK) {
        rc = errbuf_set(err, errsz, FMAP_EINVAL, "landmark descriptors: no non-zero eigenvalue");
        goto out;
    }
    for (int side = 0; side < 2; side++) {
        const lbo_basis *b = side ? b2 : b1;
        double *W = side ? W2 : W1, *F = side ? *F2 : *F1;
        const int *ids = side ? L->tgt : L->src;
        if (desc_wks(b, e, ne, sigma, W) != DESC_OK) {
            rc = errbuf_set(err, errsz, FMAP_EINVAL, "landmark descriptors: WKS failed");
            goto out;
        }
        for (int i = 0; i < b->nv; i++)
            memcpy(F + (size_t)i * cols, W + (size_t)i * ne, (size_t)ne * sizeof *F);
        if (L->n == 0)
            continue;
        if (desc_wkm(b, ids, L->n, e, ne, sigma, W) != DESC_OK) {
            rc = errbuf_set(err, errsz, FMAP_EINVAL,
                            "landmark descriptors: a landmark is out of range of mesh %d", side + 1);
            goto out;
        }
        for (int i = 0; i < b->nv; i++)
            memcpy(F + (size_t)i * cols + ne, W + (size_t)i * ne * L->n,
                   (size_t)ne * L->n * sizeof *F);
    }
    *nd = cols;
    rc = FMAP_OK;
out:
    free(e);
    free(W1);
    free(W2);
    if (rc != FMAP_OK) {
        free(*F1);
        free(*F2);
        *F1 = *F2 = NULL;
    }
    return rc;
}

int fmap_orientation_columns(int ne, int nl, int per, int *cols)
{
    if (per > ne)
        per = ne;
    int n = 0;
    for (int blk = 0; blk <= nl; blk++)
        for (int q = 0; q < per; q++)   /* midpoints of per equal slices of the ne energies */
            cols[n++] = blk * ne + (int)(((long)(2 * q + 1) * ne) / (2 * per));
    return n;
}

int fmap_vertex_map(const lbo_basis *b1, const lbo_basis *b2, const double *C, int k1, int k2,
                    int *map, char *err, size_t errsz)
{
    if (k1 < 1 || k1 > b1->k || k2 < 1 || k2 > b2->k)
        return errbuf_set(err, errsz, FMAP_EINVAL,
                          "vertex map: basis sizes %d, %d (the bases hold %d, %d)", k1, k2,
                          b1->k, b2->k);
    int n2 = b2->nv;
    double *E = malloc((size_t)n2 * k2 * sizeof *E);   /* Psi2's first k2 columns, packed */
    if (!E)
        return errbuf_set(err, errsz, FMAP_ENOMEM, "vertex map: out of memory");
    for (int j = 0; j < n2; j++)
        memcpy(E + (size_t)j * k2, b2->phi + (size_t)j * b2->k, (size_t)k2 * sizeof *E);
    int fail = 0;
#pragma omp parallel
    {
        double *q = malloc((size_t)k2 * sizeof *q);
        if (!q)
            fail = 1;
#pragma omp for schedule(static)
        for (int i = 0; i < b1->nv; i++) {
            if (!q)
                continue;
            const double *p = b1->phi + (size_t)i * b1->k;
            for (int c = 0; c < k2; c++)
                q[c] = 0;
            for (int a = 0; a < k1; a++)
                for (int c = 0; c < k2; c++)
                    q[c] += p[a] * C[(size_t)a * k2 + c];
            double best = INFINITY;
            int arg = 0;
            for (int j = 0; j < n2; j++) {
                const double *e = E + (size_t)j * k2;
                double d = 0;
                for (int c = 0; c < k2 && d < best; c++)
                    d += (q[c] - e[c]) * (q[c] - e[c]);
                if (d < best) {
                    best = d;
                    arg = j;
                }
            }
            map[i] = arg;
        }
        free(q);
    }
    free(E);
    if (fail)
        return errbuf_set(err, errsz, FMAP_ENOMEM, "vertex map: out of memory");
    return FMAP_OK;
}

/* The normal equations' operator of fmap_from_descriptors_oriented:
 * H(X) = X G + mu (D / dn) o X + w (N1 R - R N2), R = N1 X - X N2 (N1, N2
 * symmetric), + sum_d wo_d (O1_d^T R_d - R_d O2_d^T), R_d = O1_d X - X O2_d;
 * tmp, tmp2: k1 by k2. */
typedef struct normal_system {
    int k1, k2, no;
    const double *G, *D, *N1, *N2, *O1, *O2, *wo;
    double mu, w;
    double *tmp, *tmp2;
} normal_system;

static void normal_apply(const normal_system *ns, const double *X, double *out)
{
    int k1 = ns->k1, k2 = ns->k2, n = k1 * k2;
    mat_mul(X, ns->G, k1, k2, k2, out);
    for (int q = 0; q < n; q++)
        out[q] += ns->mu * ns->D[q] * X[q];
    if (ns->w != 0) {
        mat_mul(ns->N1, X, k1, k1, k2, ns->tmp);        /* R = N1 X - X N2 */
        mat_mul(X, ns->N2, k1, k2, k2, ns->tmp2);
        for (int q = 0; q < n; q++)
            ns->tmp[q] -= ns->tmp2[q];
        mat_mul(ns->N1, ns->tmp, k1, k1, k2, ns->tmp2);   /* out += w (N1 R - R N2) */
        for (int q = 0; q < n; q++)
            out[q] += ns->w * ns->tmp2[q];
        mat_mul(ns->tmp, ns->N2, k1, k2, k2, ns->tmp2);
        for (int q = 0; q < n; q++)
            out[q] -= ns->w * ns->tmp2[q];
    }
    for (int d = 0; d < ns->no; d++) {
        const double *O1 = ns->O1 + (size_t)d * k1 * k1, *O2 = ns->O2 + (size_t)d * k2 * k2;
        double wd = ns->wo[d];
        if (wd == 0)
            continue;
        mat_mul(O1, X, k1, k1, k2, ns->tmp);         /* R_d = O1 X - X O2 */
        mat_mul(X, O2, k1, k2, k2, ns->tmp2);
        for (int q = 0; q < n; q++)
            ns->tmp[q] -= ns->tmp2[q];
        mat_mul_tn(O1, ns->tmp, k1, k1, k2, ns->tmp2);   /* out += wd (O1^T R - R O2^T) */
        for (int q = 0; q < n; q++)
            out[q] += wd * ns->tmp2[q];
        mat_mul_nt(ns->tmp, O2, k1, k2, k2, ns->tmp2);
        for (int q = 0; q < n; q++)
            out[q] -= wd * ns->tmp2[q];
    }
}

static double frob(const double *A, int n)
{
    double s = 0;
    for (int q = 0; q < n; q++)
        s += A[q] * A[q];
    return sqrt(s);
}

int fmap_from_descriptors_normal(const lbo_basis *b1, const double *m1, const double *F1,
                                 const double *N1, const lbo_basis *b2, const double *m2,
                                 const double *F2, const double *N2, int nd, int k1, int k2,
                                 double mu, double mu_n, double *C, int *iterations, char *err,
                                 size_t errsz)
{
    return fmap_from_descriptors_oriented(b1, m1, F1, N1, NULL, b2, m2, F2, N2, NULL, nd, 0, k1,
                                          k2, mu, mu_n, 0, C, iterations, err, errsz);
}

int fmap_from_descriptors_oriented(const lbo_basis *b1, const double *m1, const double *F1,
                                   const double *N1, const double *O1, const lbo_basis *b2,
                                   const double *m2, const double *F2, const double *N2,
                                   const double *O2, int nd, int no, int k1, int k2, double mu,
                                   double mu_n, double mu_o, double *C, int *iterations,
                                   char *err, size_t errsz)
{
    if (iterations)
        *iterations = 0;
    if (!(mu_n >= 0) || !isfinite(mu_n))
        return errbuf_set(err, errsz, FMAP_EINVAL, "functional map: D_N weight %g", mu_n);
    if (!(mu_o >= 0) || !isfinite(mu_o) || no < 0 || (no > 0 && (!O1 || !O2)))
        return errbuf_set(err, errsz, FMAP_EINVAL,
                          "functional map: orientation weight %g, %d operators", mu_o, no);
    if (mu_o == 0)
        no = 0;
    int rc = fmap_from_descriptors(b1, m1, F1, b2, m2, F2, nd, k1, k2, mu, C, err, errsz);
    if (rc != FMAP_OK || (mu_n == 0 && no == 0))
        return rc;
    int n = k1 * k2;
    double *wo = malloc(((size_t)no + 1) * sizeof *wo);
    double *A1 = malloc((size_t)k1 * nd * sizeof *A1), *A2 = malloc((size_t)k2 * nd * sizeof *A2);
    double *G = malloc((size_t)k2 * k2 * sizeof *G), *D = malloc((size_t)n * sizeof *D);
    double *B = malloc((size_t)n * sizeof *B), *r = malloc((size_t)n * sizeof *r);
    double *p = malloc((size_t)n * sizeof *p), *Hp = malloc((size_t)n * sizeof *Hp);
    double *t1 = malloc((size_t)n * sizeof *t1), *t2 = malloc((size_t)n * sizeof *t2);
    double *Jd = malloc((size_t)n * sizeof *Jd);
    rc = FMAP_ENOMEM;
    if (!wo || !Jd || !A1 || !A2 || !G || !D || !B || !r || !p || !Hp || !t1 || !t2 ||
        !coefficients(b1, m1, F1, nd, k1, A1) || !coefficients(b2, m2, F2, nd, k2, A2)) {
        errbuf_set(err, errsz, FMAP_ENOMEM, "functional map: out of memory (%d descriptors)", nd);
        goto out;
    }
    mat_mul_nt(A2, A2, k2, nd, k2, G);   /* G = A2 A2^T */
    double dn = commutator_weights(b1, b2, k1, k2, D);
    for (int q = 0; q < n; q++)
        D[q] /= dn;
    mat_mul_nt(A1, A2, k1, nd, k2, B);   /* B = A1 A2^T */
    double nn = mu_n > 0 ? frob(N1, k1 * k1) * frob(N2, k2 * k2) : 0;
    for (int d = 0; d < no; d++) {   /* each operator pair at mu_o / no / (||O1_d|| ||O2_d||) */
        double on = frob(O1 + (size_t)d * k1 * k1, k1 * k1) *
                    frob(O2 + (size_t)d * k2 * k2, k2 * k2);
        wo[d] = on > 0 ? mu_o / no / on : 0;
    }
    normal_system ns = {k1, k2, no, G, D, N1, N2, O1, O2, wo, mu, nn > 0 ? mu_n / nn : 0, t1, t2};
    /* Jacobi preconditioner: H's diagonal, H(E_ac) at E_ac = e_a e_c^T:
     * G_cc + mu D_ac + w (|N1 e_a|^2 + |e_c^T N2|^2 - 2 N1_aa N2_cc) + the
     * same for each O_d (their columns and rows need not be symmetric) */
    for (int a = 0; a < k1; a++)
        for (int c = 0; c < k2; c++) {
            double h = G[(size_t)c * k2 + c] + mu * D[(size_t)a * k2 + c];
            for (int d = -1; d < no; d++) {
                const double *X1 = d < 0 ? N1 : O1 + (size_t)d * k1 * k1;
                const double *X2 = d < 0 ? N2 : O2 + (size_t)d * k2 * k2;
                double wd = d < 0 ? ns.w : wo[d], s1 = 0, s2 = 0;
                if (wd == 0)
                    continue;
                for (int q = 0; q < k1; q++)
                    s1 += X1[(size_t)q * k1 + a] * X1[(size_t)q * k1 + a];
                for (int q = 0; q < k2; q++)
                    s2 += X2[(size_t)c * k2 + q] * X2[(size_t)c * k2 + q];
                h += wd * (s1 + s2 - 2 * X1[(size_t)a * k1 + a] * X2[(size_t)c * k2 + c]);
            }
            Jd[(size_t)a * k2 + c] = h > 0 ? 1 / h : 1;
        }
    normal_apply(&ns, C, Hp);   /* preconditioned conjugate gradients from the Laplacian-only C */
    double rr = 0, rz = 0, bnorm = frob(B, n);
    for (int q = 0; q < n; q++) {
        r[q] = B[q] - Hp[q];
        p[q] = Jd[q] * r[q];
        rr += r[q] * r[q];
        rz += r[q] * p[q];
    }
    int it = 0;
    while (sqrt(rr) > FMAP_CG_TOL * bnorm && it < FMAP_CG_MAX_ITER) {
        normal_apply(&ns, p, Hp);
        double pHp = 0;
        for (int q = 0; q < n; q++)
            pHp += p[q] * Hp[q];
        if (!(pHp > 0)) {
            rc = errbuf_set(err, errsz, FMAP_ESOLVE,
                            "functional map with D_N: the system is not positive definite");
            goto out;
        }
        double alpha = rz / pHp, rr2 = 0, rz2 = 0;
        for (int q = 0; q < n; q++) {
            C[q] += alpha * p[q];
            r[q] -= alpha * Hp[q];
            rr2 += r[q] * r[q];
            rz2 += r[q] * Jd[q] * r[q];
        }
        for (int q = 0; q < n; q++)
            p[q] = Jd[q] * r[q] + rz2 / rz * p[q];
        rr = rr2;
        rz = rz2;
        it++;
    }
    if (iterations)
        *iterations = it;
    if (sqrt(rr) > FMAP_CG_TOL * bnorm) {
        rc = errbuf_set(err, errsz, FMAP_ESOLVE,
                        "functional map with D_N: %d conjugate-gradient steps left residual %.3g",
                        it, sqrt(rr) / bnorm);
        goto out;
    }
    rc = FMAP_OK;
out:
    free(Jd);
    free(wo);
    free(A1);
    free(A2);
    free(G);
    free(D);
    free(B);
    free(r);
    free(p);
    free(Hp);
    free(t1);
    free(t2);
    return rc;
}
