/* testdemo.h — the authors' ECTM demo input (SHREC'07 381 -> 390 with the
 * HOT initial maps of ../shared/data/ectm_demo_381_390) and the distance of
 * a map to their published result, for test_ectm and bench_ectm. Test code
 * only. Loading SKIPs the calling test when the data folder is absent. */
#ifndef TESTDEMO_H
#define TESTDEMO_H
#include "mesh/mesh.h"
#include "map/bmap.h"

typedef struct testdemo {
    mesh *S, *T;      /* 381 (6938 vertices) and 390 (9239 vertices) */
    bmap *P0, *Q0;    /* the HOT initial maps 381 -> 390 and 390 -> 381 */
} testdemo;

void testdemo_load(testdemo *d);
void testdemo_free(testdemo *d);   /* NULL members are fine */

/* The demo's texture rule: uv = (z, y) of each target vertex, minus the
 * per-column minimum, divided by the largest value of the result. Returns
 * the mean distance of the uv that P (381 -> 390) pulls back to the
 * authors' result (reference_final_uv_381.txt): 0.0447 for P0, 0.0024 for
 * a re-run of the authors' code. */
double testdemo_uv_distance(const testdemo *d, const bmap *P);

#endif
