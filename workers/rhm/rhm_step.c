/* rhm_step.c — RHM's block steps and energy (rhm__problem.h): the P-step
 * (closest points in R^{2m}, proj.h), the X-step (the sparse SPD normal
 * equations, CHOLMOD) and the eight weighted terms of (3.11).
 *
 * X-step of direction i (j = 1 − i), from setting the gradient in X_ij of
 * (3.11) to zero; X_ij appears in αĒ_D(X_ij), in (1−α)Ē_R(P_ji, X_ij) =
 * (1−α)/s_j² ‖P_ji X_ij − X_j‖²_{M_j} (the reverse direction's
 * reversibility term), in βĒ_Q(P_ij, X_ij) and in γĒ_L(X_ij):
 *   ( α/s_j W_i + (1−α)/s_j² P_jiᵀ M_j P_ji + β/(s_i s_j) M_i + γ/(s_i s_j) D_i ) X_ij
 *     = (1−α)/s_j² P_jiᵀ M_j X_j + β/(s_i s_j) M_i P_ij X_j + γ/(s_i s_j) D_i X_j[b]
 * with D_i = M_i restricted to the landmarks a_r (row a_r of X_j[b] is
 * X_j(b_r)). Each row of P_ji lives on one face of M_i, so P_jiᵀ M_j P_ji
 * fits W_i's pattern, analysed once.
 *
 * P-step of direction i: P_ij appears in (1−α)Ē_R(P_ij, X_ji) and
 * βĒ_Q(P_ij, X_ij); row l costs M_i(l)·[(1−α)/s_i² |p X_ji − x_i,l|² +
 * β/(s_i s_j) |x_ij,l − p X_j|²], the common M_i(l) drops out, and the
 * minimiser is the closest point of [√(β/(s_i s_j)) x_ij,l | √(1−α)/s_i x_i,l]
 * on M_j embedded with vertices [√(β/(s_i s_j)) X_j | √(1−α)/s_i X_ji].
 * From m = 4 on (d = 2m >= PROJ_HD_MIN_DIM) the projection searches a box
 * hierarchy in R^d over Z itself, on b's own tree (its patches; proj.h):
 * no tree is rebuilt, and the heavier block first only ends the boxes'
 * partial sums sooner. Below that the lower bound
 * comes from the first three coordinates of the block listed first; early
 * on (small β) the reversibility block weighs more, and a bound from X_j
 * alone would prune almost nothing, so that block goes first, on a tree
 * rebuilt over the current X_ji. */
#include "rhm/rhm__problem.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int rhm__projection_setup(const rhm__problem *pb, int i, double beta,
                          double *Z, double *Q, double *s)
{
    const rhm__side *a = &pb->side[i], *b = &pb->side[1 - i];
    int m = pb->dim, d = 2 * m;
    double sq = sqrt(beta / (a->s * b->s)), sr = sqrt(1 - pb->p.alpha) / a->s;
    /* the block with the larger weight goes first: its three leading
     * columns give the tree's lower bound */
    int rev = sr > sq;
    double w0 = rev ? sr : sq, w1 = rev ? sq : sr;
    const double *z0 = rev ? b->Xij : b->X, *z1 = rev ? b->X : b->Xij;
    const double *q0 = rev ? a->X : a->Xij, *q1 = rev ? a->Xij : a->X;
    for (int v = 0; v < b->n; v++)
        for (int c = 0; c < m; c++) {
            Z[(size_t)v * d + c] = w0 * z0[(size_t)v * m + c];
            Z[(size_t)v * d + m + c] = w1 * z1[(size_t)v * m + c];
        }
    for (int l = 0; l < a->n; l++)
        for (int c = 0; c < m; c++) {
            Q[(size_t)l * d + c] = w0 * q0[(size_t)l * m + c];
            Q[(size_t)l * d + m + c] = w1 * q1[(size_t)l * m + c];
        }
    *s = w0;
    return rev;
}

int rhm__step_p(rhm__problem *pb, int i, double beta, char *why, size_t whysz)
{
    rhm__side *a = &pb->side[i], *b = &pb->side[1 - i];
    int d = 2 * pb->dim;
    double *Z = malloc(sizeof(double) * (size_t)b->n * d);
    double *Q = malloc(sizeof(double) * (size_t)a->n * d);
    mesh *emb = NULL;
    proj_tree *tmp = NULL;
    int rc = KIND_ENOMEM;
    if (!Z || !Q)
        goto out;
    double s;
    const proj_tree *tree = b->tree;
    if (rhm__projection_setup(pb, i, beta, Z, Q, &s) && d < PROJ_HD_MIN_DIM) {
        /* a tree over the current X_ji: rebuilt, as X_ji moves */
        if (!(emb = mesh_new(b->n, b->m->nf)))
            goto out;
        for (int v = 0; v < b->n; v++)
            for (int c = 0; c < 3; c++)
                emb->v[3 * v + c] = Z[(size_t)v * d + c] / s;
        memcpy(emb->f, b->m->f, sizeof(int) * 3 * (size_t)b->m->nf);
        if (!(tmp = proj_tree_new(emb, why, whysz))) {
            rc = errno == ENOMEM ? KIND_ENOMEM : KIND_ENUMERIC;
            goto out;
        }
        tree = tmp;
    }
    rc = proj_closest(tree, d, Z, s, a->n, Q, a->P->face, a->P->w, NULL) ? KIND_ENUMERIC : KIND_OK;
out:
    proj_tree_free(tmp);
    mesh_free(emb);
    free(Z);
    free(Q);
    return rc;
}

/* Position of entry (r, c), r <= c, in the upper-triangular compressed
 * columns cp, ri. */
static size_t entry(const int *cp, const int *ri, int r, int c)
{
    int lo = cp[c], hi = cp[c + 1] - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (ri[mid] < r)
            lo = mid + 1;
        else
            hi = mid;
    }
    return (size_t)lo;
}

int rhm__step_x(rhm__problem *pb, int i, double beta)
{
    rhm__side *a = &pb->side[i], *b = &pb->side[1 - i];
    int m = pb->dim, n = a->n;
    double alpha = pb->p.alpha, gamma = pb->p.gamma;
    double cD = alpha / b->s, cR = (1 - alpha) / (b->s * b->s), cQ = beta / (a->s * b->s);
    double cL = gamma / (a->s * b->s);
    const geo_csr *W = a->W;
    const int *cp, *ri;
    double *x;
    chol_csc(a->A, &cp, &ri, &x);
    /* α/s_j W_i (upper triangle) + β/(s_i s_j) M_i */
    for (int c = 0; c < n; c++) {
        int q = W->row_start[c];
        for (int e = cp[c]; e < cp[c + 1]; e++) {
            while (W->col[q] != ri[e])
                q++;
            x[e] = cD * W->val[q] + (ri[e] == c ? cQ * a->mass[c] : 0);
        }
    }
    for (int r = 0; r < pb->nl; r++)
        x[entry(cp, ri, a->lmk[r], a->lmk[r])] += cL * a->mass[a->lmk[r]];
    double cA = pb->p.anchor / (a->s * b->s);
    if (a->anchor && cA > 0)
        for (int l = 0; l < n; l++)
            if (a->anchor_w[l] > 0)
                x[entry(cp, ri, l, l)] += cA * a->mass[l] * a->anchor_w[l];
    /* (1−α)/s_j² P_jiᵀ M_j P_ji */
    const bmap *Pji = b->P;
    for (int l = 0; l < b->n; l++) {
        const int *f = a->m->f + 3 * Pji->face[l];
        const double *w = Pji->w + 3 * l;
        for (int u = 0; u < 3; u++)
            for (int v = 0; v < 3; v++)
                if (f[u] <= f[v] && w[u] != 0 && w[v] != 0)
                    x[entry(cp, ri, f[u], f[v])] += cR * b->mass[l] * w[u] * w[v];
    }
    /* right-hand side, column-major n by m */
    double *bx = calloc((size_t)n * m, sizeof *bx);   /* then the solution */
    double *PX = malloc(sizeof(double) * (size_t)n * m);
    int rc = KIND_ENOMEM;
    if (!bx || !PX)
        goto out;
    for (int l = 0; l < b->n; l++) {
        const int *f = a->m->f + 3 * Pji->face[l];
        const double *w = Pji->w + 3 * l, *xj = b->X + (size_t)l * m;
        for (int u = 0; u < 3; u++)
            for (int c = 0; c < m; c++)
                bx[(size_t)c * n + f[u]] += cR * b->mass[l] * w[u] * xj[c];
    }
    bmap_apply(a->P, b->m->f, b->X, m, PX);
    for (int l = 0; l < n; l++)
        for (int c = 0; c < m; c++)
            bx[(size_t)c * n + l] += cQ * a->mass[l] * PX[(size_t)l * m + c];
    for (int r = 0; r < pb->nl; r++) {
        int l = a->lmk[r];
        for (int c = 0; c < m; c++)
            bx[(size_t)c * n + l] += cL * a->mass[l] * b->X[(size_t)b->lmk[r] * m + c];
    }
    if (a->anchor && cA > 0)
        for (int l = 0; l < n; l++)
            for (int c = 0; c < m && a->anchor_w[l] > 0; c++)
                bx[(size_t)c * n + l] += cA * a->mass[l] * a->anchor_w[l] * a->anchor[(size_t)l * m + c];
    rc = KIND_ENUMERIC;
    if (chol_factorise(a->A, NULL, 0) != CHOL_OK || chol_solve(a->A, bx, m, bx, NULL, 0) != CHOL_OK)
        goto out;
    const double *sx = bx;
    for (int l = 0; l < n; l++)
        for (int c = 0; c < m; c++)
            a->Xij[(size_t)l * m + c] = sx[(size_t)c * n + l];
    rc = KIND_OK;
out:
    free(bx);
    free(PX);
    return rc;
}

/* Σ_l mass_l |A_l − B_l|² over n rows of m columns. */
static double mass_dist2(const double *mass, const double *A, const double *B, int n, int m)
{
    double sum = 0;
    for (int l = 0; l < n; l++) {
        double d2 = 0;
        for (int c = 0; c < m; c++) {
            double t = A[(size_t)l * m + c] - B[(size_t)l * m + c];
            d2 += t * t;
        }
        sum += mass[l] * d2;
    }
    return sum;
}

double rhm__energy(const rhm__problem *pb, double beta, rhm_terms dir[2])
{
    int m = pb->dim;
    double alpha = pb->p.alpha, total = 0;
    for (int i = 0; i < 2; i++) {
        const rhm__side *a = &pb->side[i], *b = &pb->side[1 - i];
        rhm_terms *t = &dir[i];
        memset(t, 0, sizeof *t);
        double *WX = malloc(sizeof(double) * (size_t)a->n * m);
        double *PY = malloc(sizeof(double) * (size_t)a->n * m);
        if (!WX || !PY) {
            free(WX);
            free(PY);
            return NAN;
        }
        geo_csr_mul(a->W, a->Xij, m, WX);
        double dir_e = 0;
        for (size_t k = 0; k < (size_t)a->n * m; k++)
            dir_e += a->Xij[k] * WX[k];
        t->dirichlet = alpha / b->s * dir_e;
        bmap_apply(a->P, b->m->f, b->Xij, m, PY);
        t->reverse = (1 - alpha) / (a->s * a->s) * mass_dist2(a->mass, PY, a->X, a->n, m);
        bmap_apply(a->P, b->m->f, b->X, m, PY);
        t->mismatch = beta / (a->s * b->s) * mass_dist2(a->mass, a->Xij, PY, a->n, m);
        double lm = 0;
        for (int r = 0; r < pb->nl; r++) {
            const double *x = a->Xij + (size_t)a->lmk[r] * m, *y = b->X + (size_t)b->lmk[r] * m;
            double d2 = 0;
            for (int c = 0; c < m; c++)
                d2 += (x[c] - y[c]) * (x[c] - y[c]);
            lm += a->mass[a->lmk[r]] * d2;
        }
        t->landmark = pb->p.gamma / (a->s * b->s) * lm;
        if (a->anchor && pb->p.anchor > 0) {
            double an = 0;
            for (int l = 0; l < a->n; l++) {
                double d2 = 0;
                for (int c = 0; c < m; c++) {
                    double u = a->Xij[(size_t)l * m + c] - a->anchor[(size_t)l * m + c];
                    d2 += u * u;
                }
                an += a->mass[l] * a->anchor_w[l] * d2;
            }
            t->landmark += pb->p.anchor / (a->s * b->s) * an;
        }
        total += t->dirichlet + t->reverse + t->mismatch + t->landmark;
        free(WX);
        free(PY);
    }
    return total;
}
