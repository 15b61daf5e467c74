/* viz.c — see viz.h. Colour fields and an SVG line plot; no allocation. */
#include "viz/viz.h"

#include <math.h>

void viz_position_colors(const mesh *m, unsigned char *rgb)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < m->nv; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], m->v[3 * i + k]);
            hi[k] = fmax(hi[k], m->v[3 * i + k]);
        }
    for (int i = 0; i < m->nv; i++)
        for (int k = 0; k < 3; k++) {
            double span = hi[k] - lo[k], t = span > 0 ? (m->v[3 * i + k] - lo[k]) / span : 0.5;
            rgb[3 * i + k] = (unsigned char)lround(30 + 210 * t);  /* no pure black */
        }
}

void viz_pull_colors(const bmap *P, const int *tf, const unsigned char *trgb, unsigned char *srgb)
{
    for (int i = 0; i < P->n; i++) {
        const int *f = tf + 3 * P->face[i];
        const double *w = P->w + 3 * i;
        for (int k = 0; k < 3; k++) {
            double c = w[0] * trgb[3 * f[0] + k] + w[1] * trgb[3 * f[1] + k] + w[2] * trgb[3 * f[2] + k];
            srgb[3 * i + k] = (unsigned char)lround(fmin(255, fmax(0, c)));
        }
    }
}

/* Text content with the characters XML reserves escaped. */
static void svg_text(FILE *fp, const char *s)
{
    for (; *s; s++)
        switch (*s) {
        case '<': fputs("&lt;", fp); break;
        case '>': fputs("&gt;", fp); break;
        case '&': fputs("&amp;", fp); break;
        case '"': fputs("&quot;", fp); break;
        default: fputc(*s, fp);
        }
}

void viz_curves_svg(FILE *fp, const char *title, const char *const *names,
                    const double *const *curves, int ncurves, int nsteps, double tmax)
{
    static const char *const colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"};
    const int W = 640, H = 440, L = 70, R = 20, T = 40, B = 60;
    const double pw = W - L - R, ph = H - T - B;
    fprintf(fp, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
                "font-family=\"sans-serif\" font-size=\"13\">\n", W, H);
    fprintf(fp, "<rect width=\"%d\" height=\"%d\" fill=\"white\"/>\n", W, H);
    fprintf(fp, "<text x=\"%d\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">", W / 2);
    svg_text(fp, title);
    fprintf(fp, "</text>\n");
    for (int g = 0; g <= 5; g++) {   /* grid and tick labels */
        double x = L + pw * g / 5, y = T + ph * g / 5;
        fprintf(fp, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n",
                x, T, x, T + ph);
        fprintf(fp, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n",
                L, y, L + pw, y);
        fprintf(fp, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%.3g</text>\n",
                x, T + ph + 18, tmax * g / 5);
        fprintf(fp, "<text x=\"%d\" y=\"%.1f\" text-anchor=\"end\">%d%%</text>\n",
                L - 6, y + 4, 100 - 20 * g);
    }
    fprintf(fp, "<rect x=\"%d\" y=\"%d\" width=\"%.0f\" height=\"%.0f\" fill=\"none\" stroke=\"#333\"/>\n",
            L, T, pw, ph);
    fprintf(fp, "<text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">geodesic error / sqrt(target area)</text>\n",
            L + pw / 2, H - 18);
    fprintf(fp, "<text x=\"18\" y=\"%.1f\" text-anchor=\"middle\" transform=\"rotate(-90 18 %.1f)\">"
                "points within the error</text>\n", T + ph / 2, T + ph / 2);
    for (int c = 0; c < ncurves; c++) {
        const char *col = colors[c % 5];
        fprintf(fp, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"2\" points=\"", col);
        for (int s = 0; s < nsteps; s++)
            fprintf(fp, "%.1f,%.1f ", L + pw * s / (nsteps - 1), T + ph * (1 - curves[c][s]));
        fprintf(fp, "\"/>\n");
        fprintf(fp, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"%s\" stroke-width=\"2\"/>"
                    "<text x=\"%.1f\" y=\"%d\">", L + pw - 250, T + 20 + 18 * c,
                L + pw - 225, T + 20 + 18 * c, col, L + pw - 218, T + 24 + 18 * c);
        svg_text(fp, names[c]);
        fprintf(fp, "</text>\n");
    }
    fprintf(fp, "</svg>\n");
}
