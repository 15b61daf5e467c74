/* rhm_given.c — RHM from given maps (rhm.h, rhm_run_from_maps): the maps
 * checked and copied in, the missing reverse by nearest neighbour in the
 * embedding, X_ij = P_ij X_j, the anchors that hold X_ij to that start
 * (the anchor term, rhm_step.c), then the loop of rhm_run.c. */
#include "rhm/rhm__problem.h"
#include "util/errbuf.h"

#include <float.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static int check_map(const bmap *P, const mesh *from, const mesh *to, const char *name,
                     char *err, size_t errsz)
{
    if (P->n != from->nv || P->nt != to->nv)
        return errbuf_set(err, errsz, KIND_EMAP, "RHM: %s is %d by %d, the meshes have %d and %d "
                          "vertices", name, P->n, P->nt, from->nv, to->nv);
    for (int i = 0; i < P->n; i++)
        if (P->face[i] < 0 || P->face[i] >= to->nf)
            return errbuf_set(err, errsz, KIND_EMAP, "RHM: %s row %d: face %d of %d", name, i,
                              P->face[i], to->nf);
    return KIND_OK;
}

static void copy_map(bmap *dst, const bmap *src)
{
    memcpy(dst->face, src->face, sizeof(int) * (size_t)src->n);
    memcpy(dst->w, src->w, sizeof(double) * 3 * (size_t)src->n);
}

/* b->P (side 1 -> side 0) from a->Xij = P12 X2: row v = the source vertex u
 * minimising |Xij(u) - X2(v)|, weight 1 at u's corner of the lowest face
 * listing u (ties to the lower u). */
static int reverse_by_nearest(rhm__problem *pb)
{
    rhm__side *a = &pb->side[0], *b = &pb->side[1];
    int m = pb->dim;
    int *vf = malloc(sizeof(int) * ((size_t)a->n + 1));
    if (!vf)
        return KIND_ENOMEM;
    for (int q = 3 * a->m->nf - 1; q >= 0; q--)
        vf[a->m->f[q]] = q;
#pragma omp parallel for schedule(static)
    for (int v = 0; v < b->n; v++) {
        const double *x = b->X + (size_t)v * m;
        double best = DBL_MAX;
        int arg = 0;
        for (int u = 0; u < a->n; u++) {
            const double *y = a->Xij + (size_t)u * m;
            double d = 0;
            for (int c = 0; c < m; c++)
                d += (x[c] - y[c]) * (x[c] - y[c]);
            if (d < best) {
                best = d;
                arg = u;
            }
        }
        b->P->face[v] = vf[arg] / 3;
        for (int c = 0; c < 3; c++)
            b->P->w[3 * (size_t)v + c] = c == vf[arg] % 3;
    }
    free(vf);
    return KIND_OK;
}

int rhm__anchors_set(rhm__problem *pb, rhm__side *sd, int k)
{
    int n = sd->n, m = pb->dim;
    sd->anchor = malloc(sizeof(double) * (size_t)n * m);
    sd->anchor_w = calloc((size_t)n, sizeof(double));
    double *d = k > 0 ? malloc(sizeof(double) * (size_t)n) : NULL;
    if (!sd->anchor || !sd->anchor_w || (k > 0 && !d)) {
        free(d);
        return KIND_ENOMEM;
    }
    memcpy(sd->anchor, sd->Xij, sizeof(double) * (size_t)n * m);
    if (k <= 0 || k >= n) {
        for (int l = 0; l < n; l++)
            sd->anchor_w[l] = 1;
        return KIND_OK;
    }
    for (int l = 0; l < n; l++)
        d[l] = DBL_MAX;
    int v = 0;
    for (int r = 0; r < k; r++) {
        sd->anchor_w[v] = (double)n / k;
        int next = 0;
        for (int l = 0; l < n; l++) {
            double e = 0;
            for (int c = 0; c < m; c++) {
                double t = sd->X[(size_t)l * m + c] - sd->X[(size_t)v * m + c];
                e += t * t;
            }
            if (e < d[l])
                d[l] = e;
            if (d[l] > d[next])
                next = l;
        }
        v = next;
    }
    free(d);
    return KIND_OK;
}

int rhm_run_from_maps(const mesh *S, const mesh *T, const lmk_set *L, const bmap *P12,
                      const bmap *P21, const rhm_params *p, rhm_progress_fn progress, void *ctx,
                      rhm_result *out, char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    out->start = -1;
    double t0 = rhm__now();
    int rc;
    if (!P12)
        return errbuf_set(err, errsz, KIND_EMAP, "RHM from given maps: no map");
    if ((rc = check_map(P12, S, T, "the given map", err, errsz)) ||
        (P21 && (rc = check_map(P21, T, S, "the given reverse map", err, errsz))))
        return rc;
    if (p->gamma > 0 && (!L || L->n == 0))
        return errbuf_set(err, errsz, KIND_EPARAMS, "RHM's weak landmark term (landmark weight %g) "
                          "needs landmarks", p->gamma);
    if (p->threads > 0)
        omp_set_num_threads(p->threads);
    rhm__problem *pb = NULL;
    if ((rc = rhm__problem_new_maps(S, T, L, p, &pb, err, errsz)))
        return rc;
    rhm__side *a = &pb->side[0], *b = &pb->side[1];
    a->P = bmap_new(a->n, b->n);
    b->P = bmap_new(b->n, a->n);
    if (!a->P || !b->P) {
        rc = errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
        goto out;
    }
    copy_map(a->P, P12);
    bmap_apply(a->P, b->m->f, b->X, pb->dim, a->Xij);
    if (P21)
        copy_map(b->P, P21);
    else if ((rc = reverse_by_nearest(pb))) {
        errbuf_set(err, errsz, rc, "out of memory");
        goto out;
    }
    bmap_apply(b->P, a->m->f, a->X, pb->dim, b->Xij);
    if (p->anchor > 0 && ((rc = rhm__anchors_set(pb, a, p->anchors)) ||
                          (rc = rhm__anchors_set(pb, b, p->anchors)))) {
        errbuf_set(err, errsz, rc, "out of memory");
        goto out;
    }
    rc = rhm__iterate(pb, t0, progress, ctx, out, err, errsz);
out:
    rhm__problem_free(pb);
    return rc;
}
