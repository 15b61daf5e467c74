/* geo_cache.c — lazy, cached reference quantities; see geo_cache.h. Every
 * value is computed by the direct geo_ function: nothing is re-derived here. */
#include "geo/geo_cache.h"
#include "geo/geo_area.h"
#include "geo/geo_cotan.h"
#include "geo/geo_curvature.h"
#include "geo/geo_dihedral.h"
#include "geo/geo_normals.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <stdio.h>

struct geo_cache {
    const mesh *m;
    double *face_areas, *vertex_areas, *face_normals, *vertex_normals;
    double total_area;
    int have_total_area;
    geo_edges edges;
    int have_edges;
    double *dihedral, *cotan_weights, *mean_curvature;
    geo_csr *laplacian;
    int error;
    char errmsg[256];
};

geo_cache *geo_cache_new(const mesh *m)
{
    geo_cache *c = calloc(1, sizeof *c);
    if (c)
        c->m = m;
    return c;
}

void geo_cache_free(geo_cache *c)
{
    if (!c)
        return;
    free(c->face_areas); free(c->vertex_areas);
    free(c->face_normals); free(c->vertex_normals);
    free(c->dihedral); free(c->cotan_weights); free(c->mean_curvature);
    geo_edges_close(&c->edges);
    geo_csr_free(c->laplacian);
    free(c);
}

int geo_cache_error(const geo_cache *c) { return c->error; }
const char *geo_cache_errmsg(const geo_cache *c) { return c->errmsg; }

/* Keeps the first error. */
static void fail(geo_cache *c, int code, const char *msg)
{
    if (c->error)
        return;
    c->error = code;
    snprintf(c->errmsg, sizeof c->errmsg, "%s", msg);
}

static double *alloc_array(geo_cache *c, size_t n, const char *what)
{
    double *p = malloc((n + 1) * sizeof *p);
    if (!p) {
        char msg[128];
        snprintf(msg, sizeof msg, "out of memory for the %s (%zu values)", what, n);
        fail(c, GEO_ENOMEM, msg);
    }
    return p;
}

const double *geo_cache_face_areas(geo_cache *c)
{
    if (!c->face_areas && (c->face_areas = alloc_array(c, (size_t)c->m->nf, "face areas")))
        geo_face_areas(c->m, c->face_areas);
    return c->face_areas;
}

double geo_cache_total_area(geo_cache *c)
{
    if (!c->have_total_area) {
        const double *a = geo_cache_face_areas(c);
        if (!a)
            return NAN;
        double s = 0; /* face order, as geo_total_area */
        for (int t = 0; t < c->m->nf; t++)
            s += a[t];
        c->total_area = s;
        c->have_total_area = 1;
    }
    return c->total_area;
}

const double *geo_cache_vertex_areas(geo_cache *c)
{
    if (!c->vertex_areas && (c->vertex_areas = alloc_array(c, (size_t)c->m->nv, "vertex areas")))
        geo_vertex_areas(c->m, c->vertex_areas);
    return c->vertex_areas;
}

const double *geo_cache_face_normals(geo_cache *c)
{
    if (!c->face_normals && (c->face_normals = alloc_array(c, 3 * (size_t)c->m->nf, "face normals")))
        geo_face_normals(c->m, c->face_normals);
    return c->face_normals;
}

const double *geo_cache_vertex_normals(geo_cache *c)
{
    if (!c->vertex_normals &&
        (c->vertex_normals = alloc_array(c, 3 * (size_t)c->m->nv, "vertex normals")))
        geo_vertex_normals(c->m, c->vertex_normals);
    return c->vertex_normals;
}

const geo_edges *geo_cache_edges(geo_cache *c)
{
    if (!c->have_edges) {
        char msg[256];
        int rc = geo_edges_build(c->m, &c->edges, msg, sizeof msg);
        if (rc) {
            fail(c, rc, msg);
            return NULL;
        }
        c->have_edges = 1;
    }
    return &c->edges;
}

const double *geo_cache_dihedral_cosines(geo_cache *c)
{
    if (!c->dihedral) {
        const geo_edges *e = geo_cache_edges(c);
        const double *fn = geo_cache_face_normals(c);
        if (!e || !fn || !(c->dihedral = alloc_array(c, (size_t)e->ne, "dihedral cosines")))
            return NULL;
        geo_dihedral_cosines(e, fn, c->dihedral);
    }
    return c->dihedral;
}

const double *geo_cache_cotan_weights(geo_cache *c)
{
    if (!c->cotan_weights) {
        const geo_edges *e = geo_cache_edges(c);
        if (!e || !(c->cotan_weights = alloc_array(c, (size_t)e->ne, "cotan weights")))
            return NULL;
        geo_cotan_weights(c->m, e, c->cotan_weights);
    }
    return c->cotan_weights;
}

const geo_csr *geo_cache_laplacian(geo_cache *c)
{
    if (!c->laplacian) {
        const geo_edges *e = geo_cache_edges(c);
        char msg[256];
        int rc;
        if (!e)
            return NULL;
        if ((rc = geo_cotan_laplacian(c->m, e, &c->laplacian, msg, sizeof msg)) != 0)
            fail(c, rc, msg);
    }
    return c->laplacian;
}

const double *geo_cache_mean_curvature(geo_cache *c)
{
    if (!c->mean_curvature) {
        const geo_csr *L = geo_cache_laplacian(c);
        const double *mass = geo_cache_vertex_areas(c);
        const double *vn = geo_cache_vertex_normals(c);
        char msg[256];
        int rc;
        if (!L || !mass || !vn ||
            !(c->mean_curvature = alloc_array(c, (size_t)c->m->nv, "mean curvature")))
            return NULL;
        if ((rc = geo_mean_curvature(c->m, L, mass, vn, c->mean_curvature, msg, sizeof msg)) != 0) {
            fail(c, rc, msg);
            free(c->mean_curvature);
            c->mean_curvature = NULL;
        }
    }
    return c->mean_curvature;
}
