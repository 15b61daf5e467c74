/* geo_normals.c — face and vertex normals; see geo_normals.h. */
#include "geo/geo_normals.h"
#include "geo/geo_tri.h"

#include <math.h>

void geo_face_normals(const mesh *m, double *n)
{
    for (int t = 0; t < m->nf; t++) {
        double c[3];
        int degenerate = geo__face_cross(m, t, c);
        double len = sqrt(geo__dot(c, c));
        for (int d = 0; d < 3; d++)
            n[3 * t + d] = degenerate ? 0 : c[d] / len;
    }
}

void geo_vertex_normals(const mesh *m, double *n)
{
    for (int i = 0; i < 3 * m->nv; i++)
        n[i] = 0;
    for (int t = 0; t < m->nf; t++) {
        double c[3];
        if (geo__face_cross(m, t, c))
            continue;
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++)
                n[3 * m->f[3 * t + k] + d] += c[d];
    }
    for (int i = 0; i < m->nv; i++) {
        double len = sqrt(geo__dot(n + 3 * i, n + 3 * i));
        for (int d = 0; d < 3; d++)
            n[3 * i + d] = len > 0 ? n[3 * i + d] / len : 0;
    }
}
