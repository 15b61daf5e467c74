/* geod_voronoi.c — nearest-landmark cells from per-landmark heat-method
 * fields; see geod_voronoi.h. Computes no distances itself. */
#include "geod/geod_voronoi.h"
#include "util/errbuf.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

void geod_voronoi_free(geod_voronoi *v)
{
    if (!v)
        return;
    free(v->landmarks);
    free(v->cell);
    free(v->nearest);
    free(v->dist);
    free(v);
}

int geod_voronoi_new(geod_solver *s, const int *landmarks, int nl,
                     geod_voronoi **out, char *err, size_t errsz)
{
    int rc = GEOD_OK;
    geod_voronoi *v = NULL;
    int *owner = NULL;
    *out = NULL;
    int nv = geod_solver_nv(s);
    if (!landmarks || nl < 1 || nl > GEOD_VORONOI_MAX_LANDMARKS)
        return errbuf_set(err, errsz, GEOD_EINVAL, "landmark count %d not in 1..%d", nl,
                          GEOD_VORONOI_MAX_LANDMARKS);
    if ((size_t)nl > SIZE_MAX / sizeof(double) / (size_t)nv)
        return errbuf_set(err, errsz, GEOD_ENOMEM, "%d fields of %d vertices overflow", nl, nv);
    if (!(owner = malloc((size_t)nv * sizeof *owner)))
        return errbuf_set(err, errsz, GEOD_ENOMEM, "out of memory");
    for (int i = 0; i < nv; i++)
        owner[i] = -1;
    for (int a = 0; a < nl; a++) {
        int p = landmarks[a];
        if (p < 0 || p >= nv) {
            rc = errbuf_set(err, errsz, GEOD_EINVAL, "landmark %d: vertex %d not in 0..%d",
                            a, p, nv - 1);
            goto out;
        }
        if (owner[p] >= 0) {
            rc = errbuf_set(err, errsz, GEOD_EINVAL, "landmarks %d and %d are both vertex %d",
                            owner[p], a, p);
            goto out;
        }
        owner[p] = a;
    }
    v = calloc(1, sizeof *v);
    if (!v || !(v->landmarks = malloc((size_t)nl * sizeof *v->landmarks)) ||
        !(v->cell = malloc((size_t)nv * sizeof *v->cell)) ||
        !(v->nearest = malloc((size_t)nv * sizeof *v->nearest)) ||
        !(v->dist = malloc((size_t)nl * nv * sizeof *v->dist))) {
        rc = errbuf_set(err, errsz, GEOD_ENOMEM, "out of memory for %d fields", nl);
        goto out;
    }
    v->nl = nl;
    v->nv = nv;
    memcpy(v->landmarks, landmarks, (size_t)nl * sizeof *landmarks);
    rc = geod_all_pairs_from(s, landmarks, nl, v->dist);
    if (rc != GEOD_OK) {
        errbuf_set(err, errsz, rc, "distance fields: %s", geod_strerror(rc));
        goto out;
    }
    for (int i = 0; i < nv; i++) {
        int best = 0;
        for (int a = 1; a < nl; a++)
            if (v->dist[(size_t)a * nv + i] < v->dist[(size_t)best * nv + i])
                best = a;
        if (owner[i] >= 0)
            best = owner[i];
        v->cell[i] = best;
        v->nearest[i] = v->dist[(size_t)best * nv + i];
    }
out:
    free(owner);
    if (rc != GEOD_OK)
        geod_voronoi_free(v);
    else
        *out = v;
    return rc;
}
