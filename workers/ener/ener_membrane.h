/* ener_membrane.h — internal to workers/ener: the membrane density
 * â·W(G) of one face from its edge vectors, shared by ener_membrane_face
 * (ener_membrane.c) and the per-face pass of ener_def_eval, which computes
 * the edge vectors and their cross product once for this and the face
 * normal, in two steps around the log. static inline because it sits in the per-face hot loop and the
 * build has no LTO.
 *
 * With e1 = y1 − y0, e2 = y2 − y0 and ĝ⁻¹ = [[a, b], [b, c]]:
 *   tr G  = a·|e1|² − 2b·⟨e1, e2⟩ + c·|e2|²     (the −e2 flips the sign of b)
 *   det G = (|e1|²|e2|² − ⟨e1, e2⟩²)·(ac − b²) = |e1 × e2|² / det ĝ
 *   ∂tr/∂e1 = 2(a·e1 − b·e2),  ∂tr/∂e2 = 2(c·e2 − b·e1)
 *   det g = |n|², n = e1 × e2:  ∂det g/∂e1 = 2·e2 × n,  ∂det g/∂e2 = 2·n × e1
 * and W(A) = ½·tr A + ¼·det A + ¾·L(det A) − 5/4 with L(x) = −log x above ε
 * and its tangent −log ε − (x − ε)/ε below, so ∂W/∂tr = ½ and
 * ∂W/∂det = ¼ + ¾·L'(det) with L' ∈ [−1/ε, 0): finite for every input. */
#ifndef ENER_MEMBRANE_H
#define ENER_MEMBRANE_H
/* Also compiled as OpenCL C (ener_ocl.c puts this file in its program). */
#ifndef __OPENCL_VERSION__
#include <math.h>
#endif

/* det G = |e1 × e2|²/det ĝ with n = e1 × e2 (e1 = y1 − y0, e2 = y2 − y0).
 * The cross product, not g11·g22 − g12²: the Gram form cancels
 * catastrophically on slivers. */
static inline double ener__membrane_det(const double ginv[3], const double n[3])
{
    return (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) * (ginv[0] * ginv[2] - ginv[1] * ginv[1]);
}

/* â·W(G) given det = ener__membrane_det(ginv, n) and
 * logd = log(max(det, log_eps)); g (9 values: y0, y1, y2, may be NULL)
 * receives the gradient times gscale/â (gscale = â for the plain gradient;
 * ener_def_eval passes α·â to fold its weight in). The log is the caller's so that ener_def_eval can
 * take a chunk's logs in one tight loop, away from this longer dependency
 * chain. Below ε, log(max(det, ε)) = log ε is the tangent line's constant. */
static inline double ener__membrane_finish(const double ginv[3], double ahat, double gscale,
                                           double log_eps, const double e1[3],
                                           const double e2[3], const double n[3],
                                           double det, double logd, double g[9])
{
    const double a = ginv[0], b = ginv[1], c = ginv[2];
    const double g11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    const double g22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    const double g12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
    const double tr = a * g11 - 2.0 * b * g12 + c * g22;
    double neglog, dneglog;
    if (det > log_eps) {
        neglog = -logd;
        dneglog = -1.0 / det;
    } else {
        neglog = -logd - (det - log_eps) / log_eps;
        dneglog = -1.0 / log_eps;
    }
    const double w = 0.5 * tr + 0.25 * det + 0.75 * neglog - 1.25;
    if (g) {
        /* â·∂W/∂tr·∂tr/∂e and â·∂W/∂det·(1/det ĝ)·∂|n|²/∂e with
         * ∂|n|²/∂e1 = 2·e2 × n, ∂|n|²/∂e2 = 2·n × e1 (â → gscale). */
        const double sd = 2.0 * gscale * (0.25 + 0.75 * dneglog) * (a * c - b * b);
        const double ta = gscale * a, tb = gscale * b, tc = gscale * c;
        const double m1[3] = {e2[1] * n[2] - e2[2] * n[1], e2[2] * n[0] - e2[0] * n[2],
                              e2[0] * n[1] - e2[1] * n[0]};
        const double m2[3] = {n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2],
                              n[0] * e1[1] - n[1] * e1[0]};
        for (int k = 0; k < 3; k++) {
            const double d1 = ta * e1[k] - tb * e2[k] + sd * m1[k];
            const double d2 = tc * e2[k] - tb * e1[k] + sd * m2[k];
            g[3 + k] = d1;
            g[6 + k] = d2;
            g[k] = -d1 - d2;
        }
    }
    return ahat * w;
}

#endif
