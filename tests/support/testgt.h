/* testgt.h — the FAUST remeshed pair tr_reg_000 -> tr_reg_001 with its
 * dense ground truth (faust_r/vtx_5k/corres/tr_reg_00[01].vts, 1-based, line k <-> line
 * k) and landmarks picked from it, for the RHM and pipeline tests. Test code
 * only; SKIPs the calling test when the data folder is absent. */
#ifndef TESTGT_H
#define TESTGT_H
#include "lmk/lmk.h"
#include "mesh/mesh.h"

typedef struct testgt {
    mesh *S, *T;
    int n;          /* ground-truth pairs (5000) */
    int *src, *tgt; /* 0-based */
    lmk_set L;      /* landmarks: farthest-point sample of the GT source points */
} testgt;

/* nl landmarks: GT lines chosen by farthest-point sampling (Euclidean, on
 * the source positions, first = line 1), skipping repeated source vertices. */
void testgt_faust(testgt *g, int nl);
void testgt_close(testgt *g);

#endif
