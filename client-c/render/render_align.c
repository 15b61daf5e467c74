/* render_align.c — see render.h. The rotation that best turns one point
 * set onto another (Horn 1987: the unit quaternion of the largest
 * eigenvalue of a 4 by 4 symmetric matrix; always a proper rotation, so a
 * mirror image is never undone). */
#include "render/render.h"
#include "embed/embed.h"

#include <math.h>

#define RENDER_SNAP 1e-12   /* a rotation this close to the identity is it */

int render_rotation_fit(const double *X, const double *Y, int n, double R[3][3])
{
    double mx[3] = {0, 0, 0}, my[3] = {0, 0, 0}, S[3][3] = {{0}};
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            mx[k] += X[3 * i + k] / n;
            my[k] += Y[3 * i + k] / n;
        }
    for (int i = 0; i < n; i++)
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                S[a][b] += (X[3 * i + a] - mx[a]) * (Y[3 * i + b] - my[b]);
    double N[16] = {
        S[0][0] + S[1][1] + S[2][2], S[1][2] - S[2][1], S[2][0] - S[0][2], S[0][1] - S[1][0],
        S[1][2] - S[2][1], S[0][0] - S[1][1] - S[2][2], S[0][1] + S[1][0], S[2][0] + S[0][2],
        S[2][0] - S[0][2], S[0][1] + S[1][0], -S[0][0] + S[1][1] - S[2][2], S[1][2] + S[2][1],
        S[0][1] - S[1][0], S[2][0] + S[0][2], S[1][2] + S[2][1], -S[0][0] - S[1][1] + S[2][2]};
    double w, q[4];
    if (embed_top_eigenpairs(N, 4, 1, &w, q, NULL))
        return RENDER_EEIGEN;
    double a = q[0], b = q[1], c = q[2], d = q[3], dev = 0;
    double r[3][3] = {{a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
                      {2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)},
                      {2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d}};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            dev = fmax(dev, fabs(r[i][j] - (i == j)));
    /* within rounding of the identity (a shape mapped onto itself): exactly
     * the identity, so that the shape is drawn exactly as itself */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            R[i][j] = dev < RENDER_SNAP ? (i == j) : r[i][j];
    return RENDER_OK;
}
