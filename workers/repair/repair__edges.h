/* repair__edges.h — the edge table repair_orient and repair_split share:
 * one half-edge per face corner, sorted by its vertex pair (a < b) and face,
 * so the faces of an edge are neighbours in the array. */
#ifndef REPAIR__EDGES_H
#define REPAIR__EDGES_H

typedef struct repair__half {
    int a, b;     /* the edge's vertices, a < b */
    int t;        /* the face */
    int k;        /* the face's edge from corner k to corner k + 1 */
    int fwd;      /* 1 when the face runs a -> b */
} repair__half;

/* The 3 nf half-edges of f, sorted; malloc()ed, NULL without memory. */
repair__half *repair__edges(const int *f, int nf);
/* The end of the group of edges that starts at i (the first index past it). */
int repair__edge_end(const repair__half *h, int nh, int i);

#endif
