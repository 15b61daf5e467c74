/* testgt.h — a mesh pair with its dense ground truth (GT) and landmarks
 * picked from it, for the RHM and pipeline tests and benchmarks. Test code
 * only. The loaders SKIP the calling test when the data folder is absent
 * and FAIL it when a file is missing or malformed.
 *
 * Two GT layouts of ../shared/data (see its README.md):
 *   .vts pairs (BCICP: faust_r, tosca_r_*): DIR/A.off, DIR/B.off and
 *     DIR/corres/A.vts, B.vts, 1-based vertex ids, line k of A.vts <-> line
 *     k of B.vts. When DIR/corres/B.sym.vts exists, line k of it is the
 *     left-right symmetric image of line k (the BCICP protocol scores each
 *     point by the smaller of its direct and symmetric errors).
 *   vertex list (cartoon_elasticbasis gt_*.txt): line i is the 0-based
 *     target vertex of source vertex i, written as a float (7.529e+03).
 *
 * Landmarks: nl GT lines chosen by farthest-point sampling (Euclidean, on
 * the source positions, first = line 1); a source vertex already picked is
 * at distance 0 and so is not picked again. */
#ifndef TESTGT_H
#define TESTGT_H
#include <stddef.h>
#include "lmk/lmk.h"
#include "map/bmap.h"
#include "mesh/mesh.h"

#define TESTGT_MAX_LINES 10000000

typedef struct testgt {
    mesh *S, *T;
    int n;          /* ground-truth pairs */
    int *src, *tgt; /* n each, 0-based */
    int *tgt_sym;   /* n: target of src[k] under the symmetric GT, or NULL */
    lmk_set L;      /* landmarks: farthest-point sample of the GT source points */
} testgt;

/* The .vts layout: dir relative to the data folder ("faust_r/vtx_5k"),
 * a and b the shape names ("tr_reg_000"). */
void testgt_vts(testgt *g, const char *dir, const char *a, const char *b, int nl);
/* The vertex-list layout: the two meshes and the GT file, relative to the
 * data folder; the GT has one line per source vertex. */
void testgt_vertex_list(testgt *g, const char *S_rel, const char *T_rel, const char *gt_rel,
                        int nl);
/* FAUST remeshed tr_reg_000 -> tr_reg_001 (testgt_vts on faust_r/vtx_5k). */
void testgt_faust(testgt *g, int nl);
void testgt_close(testgt *g);
/* The error of P against the identity ground truth of two meshes with the
 * same vertices (TOSCA hi-res pairs): the mean Euclidean distance from each
 * source vertex's image to the target vertex of the same index, over
 * sqrt(target area): a lower bound of the geodesic error. */
double testgt_identity_error(const mesh *S, const mesh *T, const bmap *P);
/* The landmark pairs (v, v) of the vertex ids listed in pid_rel (relative
 * to the data folder, 0-based, as TOSCA's Corrs/NAME.pid): the identity
 * pairs of two meshes with the same vertices, by meshcorr match's rule
 * (lmk_from_arrays). Fails the test on error. */
lmk_set *testgt_pid_landmarks(const char *pid_rel, const mesh *S, const mesh *T);

#endif
