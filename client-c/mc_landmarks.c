/* mc_landmarks.c — libmeshcorr's landmark files: a pairs file, or a source
 * and a target list, read by the engine's one reader (workers/lmk) with the
 * base rule and checks of `meshcorr match --landmarks` and
 * `--source-landmarks --target-landmarks`, as the (source, target) vertex
 * id pairs an mc_job_spec carries. Bindings read files through this call so
 * that they have no parser of their own. */
#include "meshcorr.h"
#include "lmk/lmk.h"
#include "mesh/mesh.h"

#include <stdio.h>
#include <stdlib.h>

/* A mesh as the reader sees it: vertex count and positions only (the ids
 * are bounded by nv, a BIM .vts file's positions are checked against v). */
static mesh positions(const double *v, int nv)
{
    return (mesh){.nv = nv, .nf = 0, .v = (double *)v, .f = NULL};   /* read only */
}

int mc_read_landmarks(const char *path, const char *target_path, int one_based, const double *sv, int snv,
                      const double *tv, int tnv, uint32_t **landmarks, uint32_t *n, char *err, size_t errsz)
{
    if (!landmarks || !n) {
        snprintf(err, errsz, "mc_read_landmarks: an output pointer is NULL");
        return MC_EARG;
    }
    *landmarks = NULL;
    *n = 0;
    if (!path) {
        snprintf(err, errsz, "mc_read_landmarks: no path");
        return MC_EARG;
    }
    if (!sv || !tv || snv < 1 || tnv < 1 || snv > MESH_MAX_VERTICES || tnv > MESH_MAX_VERTICES) {
        snprintf(err, errsz, "mc_read_landmarks: need both meshes' positions, 1 to %d vertices each (got %d and %d)",
                 MESH_MAX_VERTICES, snv, tnv);
        return MC_EARG;
    }
    mesh S = positions(sv, snv), T = positions(tv, tnv);
    int base = one_based ? 1 : LMK_BASE_DEFAULT;
    lmk_set *L = NULL;
    int rc = target_path ? lmk_read_lists(path, target_path, base, &S, &T, &L, err, errsz)
                         : lmk_read_pairs(path, base, &S, &T, &L, err, errsz);
    if (rc)
        return rc == LMK_EIO ? MC_EFILE : rc == LMK_ENOMEM ? MC_ENOMEM : MC_EBAD_LANDMARKS;
    uint32_t *pairs = malloc(2 * sizeof *pairs * (size_t)L->n + 1);
    if (!pairs) {
        lmk_free(L);
        snprintf(err, errsz, "%s: out of memory", path);
        return MC_ENOMEM;
    }
    for (int i = 0; i < L->n; i++) {      /* 0-based whatever the file's base */
        pairs[2 * i] = (uint32_t)L->src[i];
        pairs[2 * i + 1] = (uint32_t)L->tgt[i];
    }
    *landmarks = pairs;
    *n = (uint32_t)L->n;
    lmk_free(L);
    return 0;
}
