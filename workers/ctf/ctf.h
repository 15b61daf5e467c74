/* ctf.h — coarse to fine (the paper's limitation section): a
 * pair too fine for RHM's cost is matched on decimated copies and the maps
 * are carried back to the full meshes, where ECTM finishes them. */
#ifndef CTF_H
#define CTF_H
#include <stddef.h>
#ifdef __cplusplus
extern "C" {
#endif
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "util/errlist.h"

#define CTF_ERRORS(X)                                                       \
    X(CTF_OK,       0, "ok", NONE)                                            \
    X(CTF_EINPUT,  -1, "invalid input", INTERNAL)                             \
    X(CTF_ENOMEM,  -2, "out of memory", NOMEM)                                \
    X(CTF_EFAILED, -3, "decimation or projection failed", NUMERIC)

ERRLIST_ENUM(ctf, CTF_ERRORS);

#define CTF_MAX_NORMAL_TURN 60.0  /* degrees a face's normal may turn per collapse */
#define CTF_MIN_ASPECT 4.0        /* thinnest face a collapse may make (OpenMesh's ratio) */

/* A copy of m decimated to target_nv vertices (fewer collapses where none
 * is legal), with the keep vertices kept: *out, and fine_vertex[c] the
 * vertex of m that coarse vertex c is (increasing; malloc'd). */
int ctf_decimate(const mesh *m, int target_nv, const int *keep, int nkeep, mesh **out,
                 int **fine_vertex, char *err, size_t errsz);

/* The map Pc (Sc -> Tc) carried to S -> T: each vertex of S goes to its
 * closest point on Sc, its image is the same barycentric mix of the coarse
 * images of that face's corners, projected onto T. *out: S->nv rows onto T. */
int ctf_prolong(const mesh *Sc, const mesh *Tc, const bmap *Pc, const mesh *S, const mesh *T,
                bmap **out, char *err, size_t errsz);

#ifdef __cplusplus
}
#endif
#endif
