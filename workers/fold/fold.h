/* fold.h — repair of the folds of a map: the flipped and collapsed
 * triangles (metric_fold_faces' rule) of a barycentric map P from S onto T
 * are re-mapped, region by region, by a harmonic map between two disks
 * (in the spirit of the thesis' one-ring relaxation, §3.4.7, made
 * fold-free by Tutte's theorem):
 *
 *   region  the bad faces grown by `rings` rings, split into components,
 *           each with its holes filled (a ring of bad faces round a limb
 *           takes the limb's end with it), kept when it is a disk of at
 *           most a quarter of the faces; what the holes bring in stays
 *           where P maps it unless another region's faces are there;
 *   chart   the target faces P sends the region's boundary and filled
 *           holes into (and, for the remap that drags the landmarks, the
 *           landmarks' images, which the drag must reach), grown by two
 *           rings or more until one piece (at most
 *           30, and half the target) and hole-filled, a disk too, placed
 *           in the unit disk
 *           by its harmonic map (boundary on the circle by arc length);
 *   remap   the region's boundary and its filled holes (faces that
 *           were not bad) stay where P sends them (their
 *           points in the chart); its other vertices are placed by its own
 *           harmonic map inside that boundary and read back through the
 *           chart as points of T. A limb end turned about its axis is
 *           untwisted this way: its boundary ring is only rotated, and the
 *           harmonic map inside a rotated ring does not fold;
 *   tube    a region deeper than twice its boundary's radius (a part's
 *           end behind a ring round it: a hoof below a leg's ring, a
 *           glasses arm's tip) is re-mapped by depth as well: the region
 *           and its chart each laid in a disk by their harmonic height
 *           (0 on the boundary, 1 at the deepest vertex) and its conjugate
 *           as the angle, the radius one minus the depth share (fold__patch.h);
 *           the region's share s goes to the chart's t_b + s (1 - t_b)
 *           inside its boundary's images (at t_b), so the end goes to the
 *           end. A harmonic disk map would crowd both ends toward a point,
 *           exponentially in length over girth (below what double
 *           precision resolves on the glasses' arms), and the two parts'
 *           proportions decide where the end lands. Such a region takes
 *           the tube's remap when it has one, moved-far or not, and a
 *           region holding vertices a tube remap placed takes only a tube
 *           remap in later passes (a disk remap of it would crowd the end
 *           again);
 *   balance the harmonic map then reweighted toward the target's area, a
 *           few rounds (each face's weights scaled by a power of its
 *           image's area ratio; any positive weights keep Tutte's
 *           guarantee): a harmonic map crowds a long part toward a point,
 *           and a limb end longer than the target's would crowd into the
 *           target's tip; the round with the fewest bad images is kept;
 *   accept  a region's new rows are kept only when its faces then have
 *           no more collapsed ones and fewer bad ones (flipped, collapsed,
 *           or crowded: an image below 1e-4 of its face's area, both
 *           meshes at unit area, as a harmonic map crowds a long part),
 *           and when no vertex whose faces were all good moved farther
 *           than the diameter of the image of the boundary and the kept
 *           holes (the map was right there; a foot's ring round a long leg
 *           would spread the foot up the leg); `passes` passes, each
 *           growing the regions of what is left by two rings more, and the
 *           passes again from `rings` while a round of them lowers the
 *           count (3 rounds at most). A repair never makes a map worse.
 *
 * Each region is re-mapped twice: with its landmarks free, and with the
 * placement then dragged so that each landmark lands at its image (small
 * steps of a smooth displacement about it that stops short of the pinned
 * vertices and the other landmarks, each a diffeomorphism, halved where
 * the coarse triangles would fold under it; a landmark
 * pinned inside a harmonic map would fold it round the pin when it is not
 * where that map puts it). Landmarks get their rows back either way. The
 * free one counts only when it puts every landmark within 0.25 of the
 * chart's radius of its image, and a tie goes to the dragged one. The
 * dragged one's chart takes the landmarks' images in; when that chart is
 * torn apart or too large the region is left to the free remap.
 *
 * Landmark source vertices (when given) keep their rows. What it
 * cannot undo: a part mirrored as a whole (its boundary is mapped the
 * wrong way round, so the harmonic map inside it is flipped throughout),
 * and regions that are not disks on either side. Reads no files. */
#ifndef FOLD_H
#define FOLD_H
#include <stddef.h>
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "util/errlist.h"

#define FOLD_ERRORS(X)                                                       \
    X(FOLD_OK,      0, "ok", NONE)                                            \
    X(FOLD_EINVAL, -1, "invalid argument (map, meshes or parameters)", INTERNAL) \
    X(FOLD_ENOMEM, -2, "out of memory", NOMEM)                                \
    X(FOLD_EMESH,  -3, "a mesh is not manifold (its edge table failed)", MESH)

ERRLIST_ENUM(fold, FOLD_ERRORS);
const char *fold_strerror(int code);

typedef struct fold_params {
    int rings;        /* growth of the regions around the bad faces (>= 0) */
    int passes;       /* passes over what is left, 2 rings more each (>= 1) */
} fold_params;
/* rings = 2, passes = 4. */
void fold_params_init(fold_params *p);

typedef struct fold_report {
    int bad_before, bad_after;   /* flipped + collapsed + crowded faces   */
    int region;                  /* source vertices re-mapped (accepted)   */
    int regions;                 /* regions accepted, over all passes      */
    int relaxed;                 /* fold_relax: vertex moves made           */
    int accepted;                /* 1: P was changed                        */
} fold_report;

/* Repairs P (S -> T) in place. fixed: nfixed source vertices that keep
 * their rows (landmarks), or NULL. Returns FOLD_OK (rep filled; P unchanged
 * unless rep->accepted), FOLD_EINVAL, FOLD_ENOMEM or FOLD_EMESH (P
 * unchanged). */
int fold_repair(const mesh *S, const mesh *T, const int *fixed, int nfixed,
                const fold_params *p, bmap *P, fold_report *rep);

/* The last step for a map that is to be returned, after fold_repair:
 * each vertex of a bad face (flipped, collapsed or crowded, as the repair
 * counts them) that also has a good face, but the fixed ones (landmarks),
 * moved alone to the point of T that leaves its faces the fewest bad ones
 * (a collapsed one counting as more than all of them), when that is fewer
 * than now: the thesis' one-ring relaxation (§3.4.7) as a search. The
 * points tried: ten of each target face that the vertex's or its
 * neighbours' images lie in, and of each face reached from them with a
 * corner within twice the neighbours' spread (their farthest image from
 * their mean) of that mean, and where none of those will do, 28 of each
 * of the 64 faces found first; among equally good ones, the nearest to the
 * mean. Where no point leaves fewer bad faces, a point that leaves as
 * many is taken when the faces' least lean (the cosine between an
 * image's normal and the target's normals where its corners land) rises
 * by 0.05: a sliver turned over, which no single move unfolds, is
 * unfolded by such moves of its corners in turn. Each sweep takes the vertices
 * most astray first (their image's distance from their neighbours'
 * images' mean over the neighbours' spread: of a vertex pushed past a
 * neighbour and that neighbour, the one to move); sweeps while a vertex
 * moves, 10 at most. A vertex whose faces are all bad (inside a fold, or
 * a part mirrored as a whole) has nothing to be mended against and stays.
 * What it mends is what no region remap improves: the odd vertex of a part
 * stretched across a crease. It hides the folds of a map that is wrong as a
 * whole just as well, though, so it is not
 * for a map whose folds are read to judge it (corr_rhm's choice of start).
 * Returns FOLD_OK (rep: bad_before, bad_after, relaxed; accepted when a
 * vertex moved), FOLD_EINVAL, FOLD_ENOMEM or FOLD_EMESH (P unchanged). */
int fold_relax(const mesh *S, const mesh *T, const int *fixed, int nfixed, bmap *P,
               fold_report *rep);

#endif
