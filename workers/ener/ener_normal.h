/* ener_normal.h — internal to workers/ener: the unit face normal and the
 * back-propagation of a gradient w.r.t. that normal onto the face's three
 * corners. The bending term is built from these two pieces both in the
 * single-edge kernel (ener_bending.c) and in the per-face passes of
 * ener_def_eval (ener_def.c), so the two cannot drift apart. static inline
 * because they sit in the per-face hot loop and the build has no LTO.
 *
 * For c = (y1 − y0) × (y2 − y0) = e1 × e2 and n = c/|c|:
 *   ∂⟨n, u⟩/∂c = (u − ⟨n, u⟩·n)/|c| =: v,   and for ⟨e1 × e2, v⟩
 *   ∂/∂e1 = e2 × v,  ∂/∂e2 = v × e1,  ∂/∂y0 = −(∂/∂e1 + ∂/∂e2).
 * The normal is the same for every cyclic rotation of the corners. */
#ifndef ENER_NORMAL_H
#define ENER_NORMAL_H
/* Also compiled as OpenCL C (ener_ocl.c puts this file in its program). */
#ifndef __OPENCL_VERSION__
#include <math.h>
#endif

/* sin² of the face angle at y0 below which a face has no normal. */
#define ENER_NORMAL_SIN2_MIN 1e-30

/* The unit normal from c = e1 × e2 (e1 = y1 − y0, e2 = y2 − y0) into n;
 * returns 1/|c|, or 0 with n = 0 for a face with no normal, which makes the
 * back-propagation below add nothing. */
static inline double ener__unit_normal_of(const double e1[3], const double e2[3],
                                          const double c[3], double n[3])
{
    const double s = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    const double l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    const double l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    if (!(s > ENER_NORMAL_SIN2_MIN * l1 * l2)) {
        n[0] = n[1] = n[2] = 0.0;
        return 0.0;
    }
    const double r = 1.0 / sqrt(s);
    n[0] = c[0] * r;
    n[1] = c[1] * r;
    n[2] = c[2] * r;
    return r;
}

/* Whether a face of Y counts as non-degenerate for the bending term (its
 * edges are "admissible"): its area is above ENER_ADMISSIBLE_AREA_RATIO of
 * its reference area âhat (r2 = 4·ratio², as |c|² = 4·area²), and it is no
 * sliver: |c|² > ENER_SLIVER_MIN·(|e1|² + |e2|² + |e3|²)² (1/12 for an
 * equilateral face). A sliver's normal turns so fast that no line-search step
 * passes: on cow -> camel, tiny camel-ear faces shrunk to slivers in Ỹ left
 * the reverse Y-step at 0 L-BFGS iterations from outer iteration ~60 on;
 * with the sliver rule it runs its 50. */
#define ENER_SLIVER_MIN 1e-10
static inline int ener__face_admissible(const double *y0, const double *y1, const double *y2,
                                        double ahat, double r2)
{
    const double e1[3] = {y1[0] - y0[0], y1[1] - y0[1], y1[2] - y0[2]};
    const double e2[3] = {y2[0] - y0[0], y2[1] - y0[1], y2[2] - y0[2]};
    const double e3[3] = {y2[0] - y1[0], y2[1] - y1[1], y2[2] - y1[2]};
    const double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                         e1[0] * e2[1] - e1[1] * e2[0]};
    const double s = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    const double l = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2] + e2[0] * e2[0]
                   + e2[1] * e2[1] + e2[2] * e2[2] + e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2];
    return s > r2 * ahat * ahat && s > ENER_SLIVER_MIN * l * l;
}

/* The same from the corners (y0, y1, y2). */
static inline double ener__unit_normal(const double *y0, const double *y1,
                                       const double *y2, double n[3])
{
    const double e1[3] = {y1[0] - y0[0], y1[1] - y0[1], y1[2] - y0[2]};
    const double e2[3] = {y2[0] - y0[0], y2[1] - y0[1], y2[2] - y0[2]};
    const double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                         e1[0] * e2[1] - e1[1] * e2[0]};
    return ener__unit_normal_of(e1, e2, c, n);
}

/* Adds to g (9 values: y0, y1, y2) the gradient of a function of the unit
 * normal n = ener__unit_normal(y0, y1, y2) (r its return value) whose
 * gradient w.r.t. n is u. */
static inline void ener__unit_normal_backprop(const double *y0, const double *y1,
                                              const double *y2, const double n[3],
                                              double r, const double u[3], double g[9])
{
    const double e1[3] = {y1[0] - y0[0], y1[1] - y0[1], y1[2] - y0[2]};
    const double e2[3] = {y2[0] - y0[0], y2[1] - y0[1], y2[2] - y0[2]};
    const double nu = n[0] * u[0] + n[1] * u[1] + n[2] * u[2];
    const double v[3] = {(u[0] - nu * n[0]) * r, (u[1] - nu * n[1]) * r,
                         (u[2] - nu * n[2]) * r};
    const double d1[3] = {e2[1] * v[2] - e2[2] * v[1], e2[2] * v[0] - e2[0] * v[2],
                          e2[0] * v[1] - e2[1] * v[0]};
    const double d2[3] = {v[1] * e1[2] - v[2] * e1[1], v[2] * e1[0] - v[0] * e1[2],
                          v[0] * e1[1] - v[1] * e1[0]};
    for (int k = 0; k < 3; k++) {
        g[k] -= d1[k] + d2[k];
        g[3 + k] += d1[k];
        g[6 + k] += d2[k];
    }
}

#endif
