/* ener_bending.c — the bending term (cos θ̂ − cos θ)²·w of one interior edge
 * and its gradient w.r.t. the 12 coordinates of i, j, k, l (ener_def.h
 * states the model). Pure arithmetic on one element: no allocation, no mesh
 * access. Built from the unit-normal pieces of ener_normal.h, as the per-face
 * passes of ener_def_eval are:
 *   n1 = n(yi, yj, yk), n2 = n(yj, yi, yl), cos θ = ⟨n1, n2⟩,
 *   ∂E/∂n1 = f·n2, ∂E/∂n2 = f·n1 with f = −2w(cos θ̂ − cos θ).
 * A face with no normal (zero cross product) makes the term 0 with a zero
 * gradient. Callers exclude such edges beforehand
 * (ener_def_update_admissible); this only keeps the kernel finite. */
#include "ener/ener_def.h"
#include "ener/ener_normal.h"

double ener_bending_edge(double cos_ref, double weight,
                         const double *yi, const double *yj,
                         const double *yk, const double *yl, double g[12])
{
    double n1[3], n2[3];
    const double r1 = ener__unit_normal(yi, yj, yk, n1);
    const double r2 = ener__unit_normal(yj, yi, yl, n2);
    if (g)
        for (int k = 0; k < 12; k++)
            g[k] = 0.0;
    if (r1 == 0.0 || r2 == 0.0)
        return 0.0;
    const double diff = cos_ref - (n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2]);
    if (g) {
        const double f = -2.0 * weight * diff;
        const double u1[3] = {f * n2[0], f * n2[1], f * n2[2]};
        const double u2[3] = {f * n1[0], f * n1[1], f * n1[2]};
        double g1[9] = {0}, g2[9] = {0};
        ener__unit_normal_backprop(yi, yj, yk, n1, r1, u1, g1);
        ener__unit_normal_backprop(yj, yi, yl, n2, r2, u2, g2);
        for (int k = 0; k < 3; k++) {
            g[k] = g1[k] + g2[3 + k];
            g[3 + k] = g1[3 + k] + g2[k];
            g[6 + k] = g1[6 + k];
            g[9 + k] = g2[6 + k];
        }
    }
    return weight * diff * diff;
}
