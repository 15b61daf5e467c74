/* start_voronoi.c — the thesis' Voronoi start (§3.3.2, start.h): P12
 * sends each geodesic Voronoi cell of the source landmarks to its target
 * landmark, P21 each target vertex to the source landmark whose target
 * landmark is nearest in the target's embedding. Builds maps only. */
#include "start/start.h"
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

/* §3.3.2: P12 sends every vertex of a geodesic Voronoi cell of the source
 * landmarks to the cell's target landmark; P21 every target vertex to the
 * source landmark whose target landmark is nearest in X2. */
int start_voronoi(rhm_side side[2], char *err, size_t errsz)
{
    rhm_side *a = &side[0], *b = &side[1];
    int dim = a->dim, nl = a->nl, rc = KIND_ENOMEM;
    int *fa = NULL, *ca = NULL, *fb = NULL, *cb = NULL;
    geod_voronoi *vor = NULL;
    char detail[512];
    if (vertex_faces(a->m, &fa, &ca) || vertex_faces(b->m, &fb, &cb)) {
        errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
        goto out;
    }
    int g = geod_voronoi_new(a->geod, a->lmk, nl, &vor, detail, sizeof detail);
    if (g) {
        rc = errbuf_set(err, errsz, g == GEOD_ENOMEM ? KIND_ENOMEM : g == GEOD_EINVAL ? KIND_ELANDMARKS
                                                                                    : KIND_EMESH,
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
    rc = KIND_OK;
out:
    geod_voronoi_free(vor);
    free(fa);
    free(ca);
    free(fb);
    free(cb);
    return rc;
}
