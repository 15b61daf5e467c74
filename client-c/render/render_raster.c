/* render_raster.c — see render.h. The z-buffered rasteriser: each face is
 * filled at sample centres RENDER_SUPERSAMPLE times finer than the image's
 * pixels (barycentric coordinates from edge functions; the nearest sample
 * wins, the first face drawn on a tie), then each pixel is the rounded mean
 * of its samples. Orthographic: depth is the coordinate towards the viewer. */
#include "render/render.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define RENDER_MARGIN 0.06       /* of the panel's side, on every side */
#define RENDER_AMBIENT 0.3       /* shade of a face seen edge-on to the light */
#define RENDER_STRIPE 3          /* pixels per hatch stripe */

static const double light[3] = {-0.3, 0.4, 0.866};   /* unit: over the left shoulder */
static const unsigned char hatch[3] = {20, 20, 20};

/* Twice the signed area of (a, b, p) in screen coordinates. */
static double edge(const double *a, const double *b, double px, double py)
{
    return (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0]);
}

/* The face's Lambert shade, two-sided, from its corners in view space. */
static double shade(const double *a, const double *b, const double *c)
{
    double u[3], w[3], n[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        w[k] = c[k] - a[k];
    }
    for (int k = 0; k < 3; k++)
        n[k] = u[(k + 1) % 3] * w[(k + 2) % 3] - u[(k + 2) % 3] * w[(k + 1) % 3];
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    double d = len > 0 ? fabs(n[0] * light[0] + n[1] * light[1] + n[2] * light[2]) / len : 0;
    return RENDER_AMBIENT + (1 - RENDER_AMBIENT) * d;
}

/* q (nv by 3): m's vertices in view space; s (nv by 3): screen x and y in
 * samples (y down) and depth, centred and scaled into a W by H buffer. */
static void project(const mesh *m, const render_view *view, int W, int H, double *q, double *s)
{
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int i = 0; i < m->nv; i++) {
        const double *p = m->v + 3 * i;
        for (int k = 0; k < 3; k++)
            q[3 * i + k] = view->r[k][0] * p[0] + view->r[k][1] * p[1] + view->r[k][2] * p[2];
        for (int k = 0; k < 2; k++) {
            lo[k] = fmin(lo[k], q[3 * i + k]);
            hi[k] = fmax(hi[k], q[3 * i + k]);
        }
    }
    double span = fmax(hi[0] - lo[0], hi[1] - lo[1]), side = W < H ? W : H;
    double scale = span > 0 ? side * (1 - 2 * RENDER_MARGIN) / span : 1;
    double cx = (lo[0] + hi[0]) / 2, cy = (lo[1] + hi[1]) / 2;
    for (int i = 0; i < m->nv; i++) {
        s[3 * i + 0] = W / 2.0 + scale * (q[3 * i + 0] - cx);
        s[3 * i + 1] = H / 2.0 - scale * (q[3 * i + 1] - cy);
        s[3 * i + 2] = q[3 * i + 2];
    }
}

/* Fills face t's samples nearer than the depth buffer z. */
static void fill_face(const mesh *m, int t, const double *q, const double *s,
                      const unsigned char *rgb, int marked, int W, int H,
                      double *z, unsigned char *buf)
{
    const int *f = m->f + 3 * t;
    const double *a = s + 3 * f[0], *b = s + 3 * f[1], *c = s + 3 * f[2];
    double area = edge(a, b, c[0], c[1]);
    if (!(fabs(area) > 1e-12))
        return;   /* seen edge-on, degenerate or not finite */
    double sh = shade(q + 3 * f[0], q + 3 * f[1], q + 3 * f[2]);
    int x0 = (int)fmax(0, floor(fmin(a[0], fmin(b[0], c[0])))),
        x1 = (int)fmin(W - 1, ceil(fmax(a[0], fmax(b[0], c[0])))),
        y0 = (int)fmax(0, floor(fmin(a[1], fmin(b[1], c[1])))),
        y1 = (int)fmin(H - 1, ceil(fmax(a[1], fmax(b[1], c[1]))));
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            double px = x + 0.5, py = y + 0.5;
            double w0 = edge(b, c, px, py) / area, w1 = edge(c, a, px, py) / area, w2 = 1 - w0 - w1;
            if (w0 < 0 || w1 < 0 || w2 < 0)
                continue;
            double depth = w0 * a[2] + w1 * b[2] + w2 * c[2];
            size_t p = (size_t)y * (size_t)W + (size_t)x;
            if (!(depth > z[p]))
                continue;
            z[p] = depth;
            if (marked && (x + y) / (RENDER_STRIPE * RENDER_SUPERSAMPLE) % 2 == 0) {
                memcpy(buf + 3 * p, hatch, 3);
                continue;
            }
            for (int k = 0; k < 3; k++) {
                double col = w0 * rgb[3 * f[0] + k] + w1 * rgb[3 * f[1] + k] + w2 * rgb[3 * f[2] + k];
                buf[3 * p + k] = (unsigned char)lround(fmin(255, fmax(0, sh * col)));
            }
        }
}

int render_mesh(const mesh *m, const unsigned char *rgb, const unsigned char *mark,
                const render_view *view, render_image *im)
{
    const int ss = RENDER_SUPERSAMPLE, W = im->w * ss, H = im->h * ss;
    size_t n = (size_t)W * (size_t)H;
    int rc = RENDER_ENOMEM;
    double *q = malloc(sizeof(double) * 3 * (size_t)m->nv + 1);
    double *s = malloc(sizeof(double) * 3 * (size_t)m->nv + 1);
    double *z = malloc(sizeof(double) * n);
    unsigned char *buf = malloc(3 * n);
    if (!q || !s || !z || !buf)
        goto out;
    for (size_t p = 0; p < n; p++) {
        z[p] = -INFINITY;
        size_t x = p % (size_t)W / ss, y = p / (size_t)W / ss;
        memcpy(buf + 3 * p, im->rgb + 3 * (y * (size_t)im->w + x), 3);
    }
    project(m, view, W, H, q, s);
    for (int t = 0; t < m->nf; t++)
        fill_face(m, t, q, s, rgb, mark && mark[t], W, H, z, buf);
    for (int y = 0; y < im->h; y++)
        for (int x = 0; x < im->w; x++)
            for (int k = 0; k < 3; k++) {
                int sum = 0;
                for (int dy = 0; dy < ss; dy++)
                    for (int dx = 0; dx < ss; dx++)
                        sum += buf[3 * ((size_t)(y * ss + dy) * (size_t)W + (size_t)(x * ss + dx)) + k];
                im->rgb[3 * ((size_t)y * (size_t)im->w + (size_t)x) + k] =
                    (unsigned char)((sum + ss * ss / 2) / (ss * ss));
            }
    rc = RENDER_OK;
out:
    free(q);
    free(s);
    free(z);
    free(buf);
    return rc;
}
