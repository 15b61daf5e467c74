/* embed_fps.c — farthest-point sampling of landmarks on geodesic distances;
 * see embed.h. Keeps one distance field at a time: memory O(nv + k^2). */
#include "embed/embed.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int embed_farthest_points(geod_solver *s, int start, int k, int *pts, double *D,
                          char *err, size_t errsz)
{
    int nv = geod_solver_nv(s);
    if (k < 1 || k > nv || start < 0 || start >= nv)
        return errbuf_set(err, errsz, EMBED_EINVAL,
                          "farthest points: k = %d not in 1..%d or start %d out of range",
                          k, nv, start);
    double *mind = malloc((size_t)nv * sizeof *mind), *f = malloc((size_t)nv * sizeof *f);
    int rc = EMBED_OK;
    if (!mind || !f) {
        rc = errbuf_set(err, errsz, EMBED_ENOMEM, "out of memory");
        goto out;
    }
    pts[0] = start;
    for (int j = 0; j < k; j++) {
        int g = geod_distances(s, &pts[j], 1, f);
        if (g != GEOD_OK) {
            rc = errbuf_set(err, errsz, EMBED_EGEOD, "distances from vertex %d: %s", pts[j],
                            geod_strerror(g));
            goto out;
        }
        int far = 0;
        for (int i = 0; i < nv; i++) {
            if (!isfinite(f[i])) {
                rc = errbuf_set(err, errsz, EMBED_EDISCONNECTED,
                                "vertex %d unreachable from vertex %d", i, pts[j]);
                goto out;
            }
            mind[i] = j == 0 || f[i] < mind[i] ? f[i] : mind[i];
            if (mind[i] > mind[far])
                far = i;
        }
        /* row and column j: the later field's value stands for both */
        D[(size_t)j * k + j] = 0;
        for (int i = 0; i < j; i++)
            D[(size_t)j * k + i] = D[(size_t)i * k + j] = f[pts[i]];
        if (j + 1 < k)
            pts[j + 1] = far;
    }
out:
    free(mind);
    free(f);
    return rc;
}
