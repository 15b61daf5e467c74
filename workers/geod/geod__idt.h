/* geod__idt.h — internal (geod__): the intrinsic Delaunay triangulation of
 * a mesh (Bobenko & Springborn 2007; Fisher et al. 2006), made by intrinsic
 * edge flips, on which the heat-method solver builds its operators.
 *
 * Why: the cotan Laplacian of a mesh with obtuse triangles has negative
 * edge weights; the heat step (M + t L) u = delta then loses its sign
 * structure and round-off swamps u far from the source, where the normalised
 * gradient only keeps the noise's direction, so distances collapse far from
 * the source (docs/decisions.md, "Heat-method geodesics"). On the intrinsic
 * Delaunay triangulation every
 * cotan weight is >= 0 (an M-matrix), the triangular solves add terms of
 * one sign, and that failure is gone.
 *
 * The vertices are the mesh's; only the edges change, each kept as a
 * length (a flipped edge is a geodesic across the two triangles it
 * splits, laid out flat). Triangles may repeat an edge (the triangulation
 * need not be simplicial); flips that would make a triangle with two equal
 * corners, or that involve a triangle glued to itself, are not made.
 * Degenerate input faces (geo_tri.h's rule) keep their edges and get zero
 * weights, as in geo_cotan. Does not touch positions after reading them. */
#ifndef GEOD__IDT_H
#define GEOD__IDT_H
#include "geo/geo_edges.h"
#include "mesh/mesh.h"

typedef struct geod__idt {
    int nf;
    int *f;        /* nf by 3: corner vertices, the mesh's orientation */
    double *len;   /* nf by 3: length of the edge opposite corner k */
    int *twin;     /* nf by 3: half-edge 3t+k across that edge, -1 on a boundary */
    int flips;     /* flips made */
} geod__idt;

/* The triangulation of m (edge table e, built from m) flipped to intrinsic
 * Delaunay. 0 or GEOD_ENOMEM. */
int geod__idt_build(const mesh *m, const geo_edges *e, geod__idt *out);
void geod__idt_close(geod__idt *t);

/* Twice the area of a triangle with side lengths a, b, c (Kahan's stable
 * Heron); 0 when the lengths do not make a triangle. */
double geod__double_area(double a, double b, double c);

/* Cotangent of the angle opposite side a; 0 for a degenerate triangle. */
double geod__cot(double a, double b, double c);

#endif
