/* ener_membrane.c — the membrane density â·W(G) of one face and its
 * gradient w.r.t. the face's 9 corner coordinates (ener_def.h states the
 * model; ener_membrane.h holds the arithmetic and its derivation). Pure
 * arithmetic on one element: no allocation, no mesh access. */
#include "ener/ener_def.h"
#include "ener/ener_membrane.h"

#include <math.h>

double ener_membrane_face(const double ginv[3], double ahat, double log_eps,
                          const double *y0, const double *y1, const double *y2,
                          double g[9])
{
    const double e1[3] = {y1[0] - y0[0], y1[1] - y0[1], y1[2] - y0[2]};
    const double e2[3] = {y2[0] - y0[0], y2[1] - y0[1], y2[2] - y0[2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                         e1[0] * e2[1] - e1[1] * e2[0]};
    const double det = ener__membrane_det(ginv, n);
    return ener__membrane_finish(ginv, ahat, ahat, log_eps, e1, e2, n, det,
                                 log(det > log_eps ? det : log_eps), g);
}
