/* geo_area.c — face areas, lumped mass, unit-area normalisation; see
 * geo_area.h. Serial, in face order: sums are deterministic. */
#include "geo/geo_area.h"
#include "geo/geo_edges.h"
#include "geo/geo_tri.h"
#include "util/errbuf.h"

#include <math.h>

static double face_area(const mesh *m, int t)
{
    double c[3];
    geo__face_cross(m, t, c);
    return 0.5 * sqrt(geo__dot(c, c));
}

void geo_face_areas(const mesh *m, double *area)
{
    for (int t = 0; t < m->nf; t++)
        area[t] = face_area(m, t);
}

double geo_total_area(const mesh *m)
{
    double a = 0;
    for (int t = 0; t < m->nf; t++)
        a += face_area(m, t);
    return a;
}

void geo_vertex_areas(const mesh *m, double *mass)
{
    for (int i = 0; i < m->nv; i++)
        mass[i] = 0;
    for (int t = 0; t < m->nf; t++) {
        double a3 = face_area(m, t) / 3;
        for (int k = 0; k < 3; k++)
            mass[m->f[3 * t + k]] += a3;
    }
}

int geo_normalize_area(mesh *m, geo_scaling *s, char *err, size_t errsz)
{
    double area = 0, c[3] = {0, 0, 0};
    for (int t = 0; t < m->nf; t++) {
        const double *p[3];
        double a = face_area(m, t);
        geo__corners(m, t, p);
        area += a;
        for (int d = 0; d < 3; d++)
            c[d] += a * (p[0][d] + p[1][d] + p[2][d]) / 3;
    }
    if (!(area > 0) || !isfinite(area))
        return errbuf_set(err, errsz, GEO_EDEGENERATE,
                          "cannot normalise to unit area: total area is %g", area);
    s->scale = 1 / sqrt(area);
    for (int d = 0; d < 3; d++)
        s->centroid[d] = c[d] / area;
    for (int i = 0; i < m->nv; i++)
        for (int d = 0; d < 3; d++)
            m->v[3 * i + d] = (m->v[3 * i + d] - s->centroid[d]) * s->scale;
    return GEO_OK;
}

void geo_denormalize(const geo_scaling *s, double *p, int np)
{
    for (int i = 0; i < np; i++)
        for (int d = 0; d < 3; d++)
            p[3 * i + d] = p[3 * i + d] / s->scale + s->centroid[d];
}
