/* geo_dihedral.c — dihedral cosines from face normals; see geo_dihedral.h. */
#include "geo/geo_dihedral.h"
#include "geo/geo_tri.h"

void geo_dihedral_cosines(const geo_edges *e, const double *fn, double *cosines)
{
    for (int k = 0; k < e->ne; k++) {
        int s = e->ef[2 * k], t = e->ef[2 * k + 1];
        if (t < 0) {
            cosines[k] = 1;
            continue;
        }
        const double *a = fn + 3 * (size_t)s, *b = fn + 3 * (size_t)t;
        if (geo__dot(a, a) == 0 || geo__dot(b, b) == 0) {
            cosines[k] = 1;
            continue;
        }
        double c = geo__dot(a, b);
        cosines[k] = c > 1 ? 1 : c < -1 ? -1 : c;
    }
}
