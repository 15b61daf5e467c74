/* render_view.c — see render.h. A view of a mesh's widest side, from the
 * world axes of its bounding box (files put their shapes along the axes,
 * up along one of them), and views turned from it. */
#include "render/render.h"

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

render_view render_view_widest(const mesh *m, double az, double el)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < m->nv; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], m->v[3 * i + k]);
            hi[k] = fmax(hi[k], m->v[3 * i + k]);
        }
    int ax[3] = {0, 1, 2};   /* the world axes by extent, greatest first */
    for (int a = 0; a < 3; a++)
        for (int b = a + 1; b < 3; b++)
            if (hi[ax[b]] - lo[ax[b]] > hi[ax[a]] - lo[ax[a]]) {
                int t = ax[a];
                ax[a] = ax[b];
                ax[b] = t;
            }
    render_view v = {{{0}}};
    v.r[0][ax[0]] = 1;
    v.r[1][ax[1]] = 1;
    /* towards the viewer: x cross y, so the picture is never a mirror image */
    for (int k = 0; k < 3; k++)
        v.r[2][k] = v.r[0][(k + 1) % 3] * v.r[1][(k + 2) % 3] - v.r[0][(k + 2) % 3] * v.r[1][(k + 1) % 3];
    render_view out = render_view_turned(&v, az);
    turn_rows(out.r, 1, 2, -el);   /* y and z: about screen x, looking down */
    return out;
}
