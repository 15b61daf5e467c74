/* rhm_init.c — RHM's start from landmarks (thesis §3.3.2): the geodesic
 * Voronoi map P12, its nearest-neighbour reverse P21 and X_ij = P_ij X_j.
 * Builds maps only; no optimisation. */
#include "rhm/rhm__problem.h"
#include "geod/geod_voronoi.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>

/* Sets row r of P to vertex v exactly: weight 1 at v's corner of the face
 * vface[v] (see vertex_faces). */
static void row_at_vertex(bmap *P, int r, const int *vface, const int *vcorner, int v)
{
    P->face[r] = vface[v];
    for (int k = 0; k < 3; k++)
        P->w[3 * r + k] = k == vcorner[v];
}

/* vface[v], vcorner[v]: the first face listing v and v's position in it. */
static int vertex_faces(const mesh *m, int **vface, int **vcorner)
{
    *vface = malloc(sizeof(int) * (size_t)m->nv);
    *vcorner = malloc(sizeof(int) * (size_t)m->nv);
    if (!*vface || !*vcorner)
        return -1;
    for (int v = 0; v < m->nv; v++)
        (*vface)[v] = -1;
    for (int t = m->nf - 1; t >= 0; t--)
        for (int k = 0; k < 3; k++) {
            (*vface)[m->f[3 * t + k]] = t;
            (*vcorner)[m->f[3 * t + k]] = k;
        }
    return 0;
}

int rhm__init_voronoi(rhm__problem *pb, char *err, size_t errsz)
{
    rhm__side *a = &pb->side[0], *b = &pb->side[1];
    int dim = pb->dim, nl = pb->nl, rc = RHM_ENOMEM;
    int *fa = NULL, *ca = NULL, *fb = NULL, *cb = NULL;
    geod_voronoi *vor = NULL;
    char detail[512];
    bmap_free(a->P);
    bmap_free(b->P);
    a->P = bmap_new(a->n, b->n);
    b->P = bmap_new(b->n, a->n);
    if (!a->P || !b->P || vertex_faces(a->m, &fa, &ca) || vertex_faces(b->m, &fb, &cb)) {
        errbuf_set(err, errsz, RHM_ENOMEM, "out of memory");
        goto out;
    }
    int g = geod_voronoi_new(a->geod, a->lmk, nl, &vor, detail, sizeof detail);
    if (g) {
        rc = errbuf_set(err, errsz, g == GEOD_ENOMEM ? RHM_ENOMEM : g == GEOD_EINVAL ? RHM_EINPUT
                                                                                    : RHM_EMESH,
                        "Voronoi cells of the source landmarks: %s", detail);
        goto out;
    }
    for (int v = 0; v < a->n; v++)
        row_at_vertex(a->P, v, fb, cb, b->lmk[vor->cell[v]]);
    /* T21(v) = argmin over the images T12(V1) = {q_r} of |X2(q_r) - X2(v)|;
     * every vertex of cell r maps to q_r, so p_r is a valid preimage. */
    for (int v = 0; v < b->n; v++) {
        const double *x = b->X + (size_t)v * dim;
        int best = 0;
        double bd = INFINITY;
        for (int r = 0; r < nl; r++) {
            const double *y = b->X + (size_t)b->lmk[r] * dim;
            double d = 0;
            for (int c = 0; c < dim; c++)
                d += (x[c] - y[c]) * (x[c] - y[c]);
            if (d < bd) {
                bd = d;
                best = r;
            }
        }
        row_at_vertex(b->P, v, fa, ca, a->lmk[best]);
    }
    bmap_apply(a->P, b->m->f, b->X, dim, a->Xij);
    bmap_apply(b->P, a->m->f, a->X, dim, b->Xij);
    rc = RHM_OK;
out:
    geod_voronoi_free(vor);
    free(fa);
    free(ca);
    free(fb);
    free(cb);
    return rc;
}
