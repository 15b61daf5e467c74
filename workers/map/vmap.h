/* vmap.h — vertex-to-vertex maps, the layout BCICP, BIM and most MATLAB
 * tools write: a text file with one line per source vertex, line i holding
 * the target vertex matched to source vertex i. Read as a barycentric map
 * (bmap.h) with weight 1 at that vertex, in the lowest-numbered target face
 * that lists it, so everything that takes a bmap takes a vertex map.
 *
 * Format: one integer per line (written as an integer, or as a number
 * exactly equal to one, e.g. "7.529e+03" from a float writer); blank lines
 * and lines starting with '#' are skipped; exactly source->nv entries.
 *
 * Index base, VMAP_BASE_AUTO (the rule, applied to the whole file first):
 *   a 0 among the indices           -> 0-based;
 *   else target->nv among them      -> 1-based;
 *   else neither                    -> refused as ambiguous (a 0-based map
 *     need not hit vertex 0 nor a 1-based one vertex nv: both occur among
 *     the published BIM maps), naming the file; the caller then says
 *     0 or 1 (`--init-base`).
 * An explicit base 0 or 1 is taken as given.
 *
 * Errors (negative BMAP_E* codes, the message naming file and line):
 * BMAP_EIO unreadable; BMAP_EPARSE not one integer on a line, ambiguous
 * base; BMAP_ESIZE more or fewer entries than source vertices; BMAP_ERANGE
 * an index outside [base, target->nv - 1 + base] or a target vertex on no
 * face; BMAP_ENOMEM. */
#ifndef VMAP_H
#define VMAP_H
#include <stddef.h>
#include "map/bmap.h"
#include "mesh/mesh.h"

#define VMAP_BASE_AUTO (-1)

/* *out: bmap_new(source->nv, target->nv); *base_used (may be NULL): the
 * base applied (0 or 1). */
int vmap_read(const char *path, int base, const mesh *source, const mesh *target, bmap **out,
              int *base_used, char *err, size_t errsz);

/* An initial-map file of either kind: "# meshcorr-map 1" as its first line
 * -> bmap_read (base is then unused), else vmap_read. */
int vmap_read_any(const char *path, int base, const mesh *source, const mesh *target,
                  bmap **out, char *err, size_t errsz);

#endif
