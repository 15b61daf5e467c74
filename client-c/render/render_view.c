/* render_view.c — see render.h. A view from a mesh's principal axes (the
 * eigenvectors of its vertices' covariance), and views turned from it. */
#include "render/render.h"
#include "embed/embed.h"

#include <math.h>

/* Rows i and j of r turned by deg degrees in their plane (about the axis
 * of the third row). */
static void turn_rows(double r[3][3], int i, int j, double deg)
{
    double c = cos(deg * M_PI / 180), s = sin(deg * M_PI / 180);
    for (int k = 0; k < 3; k++) {
        double a = r[i][k], b = r[j][k];
        r[i][k] = c * a + s * b;
        r[j][k] = -s * a + c * b;
    }
}

render_view render_view_turned(const render_view *v, double deg)
{
    render_view t = *v;
    turn_rows(t.r, 0, 2, deg);   /* x and z: about screen y */
    return t;
}

int render_view_principal(const mesh *m, double az, double el, render_view *out)
{
    double mean[3] = {0, 0, 0}, cov[9] = {0}, w[3], V[9];
    for (int i = 0; i < m->nv; i++)
        for (int k = 0; k < 3; k++)
            mean[k] += m->v[3 * i + k] / m->nv;
    for (int i = 0; i < m->nv; i++)
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                cov[3 * a + b] += (m->v[3 * i + a] - mean[a]) * (m->v[3 * i + b] - mean[b]);
    if (embed_top_eigenpairs(cov, 3, 3, w, V, NULL))
        return RENDER_EEIGEN;
    /* V's columns, descending spread, each with its largest entry positive */
    render_view v;
    for (int k = 0; k < 3; k++) {
        v.r[0][k] = V[3 * k + 0];
        v.r[1][k] = V[3 * k + 1];
    }
    /* towards the viewer: x cross y, so the picture is never a mirror image */
    for (int k = 0; k < 3; k++)
        v.r[2][k] = v.r[0][(k + 1) % 3] * v.r[1][(k + 2) % 3] - v.r[0][(k + 2) % 3] * v.r[1][(k + 1) % 3];
    *out = render_view_turned(&v, az);
    turn_rows(out->r, 1, 2, -el);   /* y and z: about screen x, looking down */
    return RENDER_OK;
}
