/* viz.h — pictures of a map, for a person to look at rather than read:
 *   colour transfer: the target coloured by position, the source coloured
 *   through the map (same colour = same place), written as coloured PLYs;
 *   the cumulative geodesic-error curve as an SVG plot.
 * Pure functions over caller arrays, plus a FILE writer; no mesh I/O here. */
#ifndef VIZ_H
#define VIZ_H
#include <stdio.h>
#include "map/bmap.h"
#include "mesh/mesh.h"

/* rgb (nv by 3 bytes): a smooth colour field of the position of each vertex
 * in m's bounding box (x -> red, y -> green, z -> blue, stretched to the
 * box so every mesh uses the whole colour cube). */
void viz_position_colors(const mesh *m, unsigned char *rgb);

/* srgb (P->n by 3): the colours of the target (trgb, nt by 3) at the points
 * the map sends each source vertex to (barycentric interpolation). */
void viz_pull_colors(const bmap *P, const int *tf, const unsigned char *trgb, unsigned char *srgb);

/* An SVG plot of cumulative error curves: curves[c][s] is the fraction of
 * points with error <= tmax·s/(nsteps−1); names[c] label the legend. */
void viz_curves_svg(FILE *fp, const char *title, const char *const *names,
                    const double *const *curves, int ncurves, int nsteps, double tmax);

#endif
