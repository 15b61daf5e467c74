/* geo_cache.h — the reference quantities of one fixed mesh, computed once on
 * first request and cached (geometry-central style): areas, lumped mass,
 * normals, the edge table, dihedral cosines, cotan weights and Laplacian,
 * mean curvature. Each getter computes what it needs (and what that needs)
 * the first time, then returns the same array.
 *
 * Ownership: the cache borrows the mesh (it must outlive the cache and not
 * change while the cache lives); it owns every array it returns, which stay
 * valid until geo_cache_free. Not thread-safe while filling: request what
 * you need from one thread before sharing the cache for reading.
 *
 * Errors: a getter returns NULL (NAN for the total area) when its quantity
 * cannot be built (GEO_ENOMEM; GEO_ENONMANIFOLD for anything that needs the
 * edge table). The first error is kept on the object: geo_cache_error gives
 * its code and geo_cache_errmsg its detail. Shapes are those of the direct
 * functions named in each comment. */
#ifndef GEO_CACHE_H
#define GEO_CACHE_H
#include "geo/geo_csr.h"
#include "geo/geo_edges.h"
#include "mesh/mesh.h"

typedef struct geo_cache geo_cache;

/* NULL on out of memory. */
geo_cache *geo_cache_new(const mesh *m);
void geo_cache_free(geo_cache *c);

const double *geo_cache_face_areas(geo_cache *c);       /* nf, geo_face_areas */
double geo_cache_total_area(geo_cache *c);              /* geo_total_area */
const double *geo_cache_vertex_areas(geo_cache *c);     /* nv, geo_vertex_areas */
const double *geo_cache_face_normals(geo_cache *c);     /* nf by 3, geo_face_normals */
const double *geo_cache_vertex_normals(geo_cache *c);   /* nv by 3, geo_vertex_normals */
const geo_edges *geo_cache_edges(geo_cache *c);         /* geo_edges_build */
const double *geo_cache_dihedral_cosines(geo_cache *c); /* ne, geo_dihedral_cosines */
const double *geo_cache_cotan_weights(geo_cache *c);    /* ne, geo_cotan_weights */
const geo_csr *geo_cache_laplacian(geo_cache *c);       /* nv by nv, geo_cotan_laplacian */
const double *geo_cache_mean_curvature(geo_cache *c);   /* nv, geo_mean_curvature */

/* First error met (GEO_OK if none) and its detail ("" if none). */
int geo_cache_error(const geo_cache *c);
const char *geo_cache_errmsg(const geo_cache *c);

#endif
