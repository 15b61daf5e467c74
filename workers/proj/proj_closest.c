/* proj_closest.c — the P-step query: for each row, the closest point of the
 * target embedded in R^d, found with a shrinking Embree point query over the
 * 3-D BVH (exact), and the all-faces reference. No BVH building here
 * (proj_tree.c), no geometry of its own (proj_point_triangle).
 *
 * Why it is exact: with Z[:, 0:3] = s·X̃, every candidate p satisfies
 * |q − p|² ≥ s²·dist₃(q[0:3]/s, triangle of X̃)², so a triangle whose 3-D
 * distance exceeds √best/s cannot win. Embree stores floats, so the radius
 * is padded (relative 1e-5 of the scene's size and 1e-6 of the query's
 * distance from the origin) to keep rounding from excluding the winner.
 *
 * In R^d from PROJ_HD_MIN_DIM on the three tree coordinates see little of
 * the distance: the 3-D ball of radius √best holds a number of faces that
 * grows with the mesh's resolution. There each call fits the tree's box
 * hierarchy (proj_hd.c: patches of X̃, boxes in R^d) to Z and searches it;
 * the Embree tree is not used. Boxes are doubles, bounded four coordinates a
 * step without branches, with leaves of 16 faces (docs/decisions.md, "The R^d
 * projection's box hierarchy"). Below that dimension
 * (ECTM, d = 6) the leading coordinates, s·X̃, carry most of the distance
 * and the Embree tree stays. */
#include "proj/proj.h"
#include "proj/proj__hd.h"
#include "proj/proj__tree.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

typedef struct proj__row {
    int d;
    const double *Z;
    const int *f;
    const double *q;
    double s;
    double pad;        /* absolute padding of the query radius */
    double best;       /* best cost so far (+inf: none) */
    int face;          /* its face, or -1 */
    double bary[3];
} proj__row;

static double face_cost(const proj__row *r, int t, double bary[3])
{
    const int *v = r->f + 3 * (size_t)t;
    size_t d = (size_t)r->d;
    return proj_point_triangle(r->d, r->q, r->Z + d * v[0], r->Z + d * v[1],
                               r->Z + d * v[2], bary);
}

static float query_radius(const proj__row *r)
{
    if (isinf(r->best))
        return INFINITY;
    return (float)(sqrt(r->best) / r->s * (1 + 1e-6) + r->pad);
}

static bool visit_face(struct RTCPointQueryFunctionArguments *args)
{
    proj__row *r = args->userPtr;
    double bary[3];
    double c = face_cost(r, (int)args->primID, bary);
    if (!(c < r->best))
        return false;
    r->best = c;
    r->face = (int)args->primID;
    r->bary[0] = bary[0], r->bary[1] = bary[1], r->bary[2] = bary[2];
    args->query->radius = query_radius(r);
    return true;
}

/* Row i of the answer from the search's best face r. */
static void store_row(const proj__row *r, int i, int *face, double *bary, double *cost)
{
    face[i] = r->face;
    bary[3 * (size_t)i] = r->bary[0];
    bary[3 * (size_t)i + 1] = r->bary[1];
    bary[3 * (size_t)i + 2] = r->bary[2];
    if (cost)
        cost[i] = r->best;
}

int proj_closest(const proj_tree *t, int d, const double *Z, double s,
                 int n, const double *Q, int *face, double *bary, double *cost)
{
    if (d < 3 || !(s > 0) || !isfinite(s) || n < 0)
        return PROJ_EINVAL;
    for (int i = 0; i < n; i++)
        if (face[i] >= t->nf)
            return PROJ_EFACE;

    if (d >= PROJ_HD_MIN_DIM) {
        double *box = malloc(sizeof(double) * proj__hd_box_size(t->hd, d));
        if (!box)
            return PROJ_ENOMEM;
        proj__hd_fit(t->hd, d, Z, box);
        #pragma omp parallel for schedule(dynamic, 256)
        for (int i = 0; i < n; i++) {
            const double *q = Q + (size_t)d * i;
            int fi = face[i];
            double best = INFINITY, b[3] = { 1, 0, 0 };
            if (fi >= 0) {
                const proj__row r = { .d = d, .Z = Z, .f = t->f, .q = q };
                best = face_cost(&r, fi, b);
            }
            proj__hd_closest(t->hd, d, Z, box, q, &fi, &best, b);
            face[i] = fi;
            bary[3 * (size_t)i] = b[0];
            bary[3 * (size_t)i + 1] = b[1];
            bary[3 * (size_t)i + 2] = b[2];
            if (cost)
                cost[i] = best;
        }
        free(box);
        return 0;
    }
    #pragma omp parallel for schedule(dynamic, 256)
    for (int i = 0; i < n; i++) {
        const double *q = Q + (size_t)d * i;
        proj__row r = { .d = d, .Z = Z, .f = t->f, .q = q, .s = s,
                        .best = INFINITY, .face = -1 };
        double qmax = fmax(fabs(q[0]), fmax(fabs(q[1]), fabs(q[2]))) / s;
        r.pad = 1e-5 * t->scale + 1e-6 * qmax + FLT_MIN;
        if (face[i] >= 0) {
            r.face = face[i];
            r.best = face_cost(&r, face[i], r.bary);
        }
        struct RTCPointQuery pq = { .x = (float)(q[0] / s), .y = (float)(q[1] / s),
                                    .z = (float)(q[2] / s), .time = 0,
                                    .radius = query_radius(&r) };
        struct RTCPointQueryContext ctx;
        rtcInitPointQueryContext(&ctx);
        rtcPointQuery(t->scene, &pq, &ctx, visit_face, &r);
        store_row(&r, i, face, bary, cost);
    }
    return 0;
}

void proj_closest_brute(const mesh *target, int d, const double *Z,
                        int n, const double *Q, int *face, double *bary, double *cost)
{
    #pragma omp parallel for schedule(dynamic, 16)
    for (int i = 0; i < n; i++) {
        proj__row r = { .d = d, .Z = Z, .f = target->f, .q = Q + (size_t)d * i,
                        .best = INFINITY, .face = -1 };
        for (int t = 0; t < target->nf; t++) {
            double w[3];
            double c = face_cost(&r, t, w);
            if (c < r.best) {
                r.best = c;
                r.face = t;
                r.bary[0] = w[0], r.bary[1] = w[1], r.bary[2] = w[2];
            }
        }
        store_row(&r, i, face, bary, cost);
    }
}
