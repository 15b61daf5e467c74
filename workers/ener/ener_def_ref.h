/* ener_def_ref.h — internal to workers/ener: read access to an ener_def's
 * reference caches, so that another backend (ener_ocl.c) evaluates the same
 * energy from the same cached ĝ⁻¹, â, edge faces, signs, cos θ̂ and weights
 * instead of computing them a second time. The view points into the
 * ener_def: valid while it lives, never written through. */
#ifndef ENER_DEF_REF_H
#define ENER_DEF_REF_H
#include "ener/ener_def.h"

/* A face is non-degenerate in Y when its area exceeds this fraction of its
 * reference area and it is no sliver (ener__face_admissible, ener_normal.h). A
 * smaller fraction admits slivers whose unit normal turns so fast that no
 * line-search step is accepted (docs/decisions.md, "The admissible area
 * ratio"). */
#define ENER_ADMISSIBLE_AREA_RATIO 1e-6

typedef struct ener__face {
    double ginv[3];  /* ĝ⁻¹ as {a, b, c} */
    double ahat;     /* reference area */
} ener__face;

typedef struct ener__edge {
    int t[2];        /* faces (i, j, k) and the one with l */
    double sign;     /* +1 when face t[1] runs (j, i, l), −1 when (i, j, l) */
    double cos_ref;  /* cos θ̂ */
    double weight;   /* l̂² / d̂ */
} ener__edge;

typedef struct ener__def_ref {
    ener_def_params p;
    int nv, nf, ne;            /* ne: interior edges only */
    const int *f;              /* nf by 3 (X's faces) */
    const geo_edges *E;        /* vertex -> face lists */
    const ener__face *fr;      /* nf */
    const ener__edge *er;      /* ne */
    const int *fedge, *fnbr;   /* nf by 3: interior edge at each corner (or −1)
                                  and the face across it */
} ener__def_ref;

void ener__def_ref_get(const ener_def *d, ener__def_ref *out);

#endif
