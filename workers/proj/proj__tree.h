/* proj__tree.h — internal: the layout of a proj_tree, shared by
 * proj_tree.c (which builds and frees it) and proj_closest.c (which queries
 * it). Nothing outside workers/proj/ includes this. */
#ifndef PROJ__TREE_H
#define PROJ__TREE_H
#include <embree3/rtcore.h>
#include "proj/proj__hd.h"

struct proj_tree {
    RTCDevice device;
    RTCScene scene;
    int nv, nf;
    int *f;         /* nf by 3 copy of the target's faces */
    double scale;   /* bounding-box diagonal plus largest |coordinate| of X̃:
                       the size that float rounding in the BVH is relative to */
    proj__hd *hd;   /* the patches of X̃ for queries in R^d, d >= PROJ_HD_MIN_DIM */
};

#endif
