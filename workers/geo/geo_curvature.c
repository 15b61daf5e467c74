/* geo_curvature.c — mean curvature from L X; see geo_curvature.h. */
#include "geo/geo_curvature.h"
#include "geo/geo_edges.h"
#include "geo/geo_tri.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>

int geo_mean_curvature(const mesh *m, const geo_csr *L, const double *mass,
                       const double *vn, double *H, char *err, size_t errsz)
{
    if (L->n != m->nv)
        return errbuf_set(err, errsz, GEO_EMISMATCH, "Laplacian is %d by %d; mesh has %d vertices",
                          L->n, L->n, m->nv);
    double *lx = malloc(((size_t)m->nv * 3 + 1) * sizeof *lx);
    if (!lx)
        return errbuf_set(err, errsz, GEO_ENOMEM, "out of memory for L X (%d vertices)", m->nv);
    geo_csr_mul(L, m->v, 3, lx);
    for (int i = 0; i < m->nv; i++) {
        const double *y = lx + 3 * (size_t)i, *n = vn + 3 * (size_t)i;
        double s = geo__dot(y, n);
        if (!(mass[i] > 0) || geo__dot(n, n) == 0)
            H[i] = 0;
        else
            H[i] = (s < 0 ? -0.5 : 0.5) * sqrt(geo__dot(y, y)) / mass[i];
    }
    free(lx);
    return GEO_OK;
}
