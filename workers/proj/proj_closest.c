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
 * In high dimension the three tree coordinates see little of the distance
 * and the tree hands over many faces; each is then first checked against
 * its bounding box in R^d (a second exact lower bound, 2d numbers per face
 * made per call) before the triangle itself. Measured (one run each way):
 * RHM on FAUST 5K, d = 16, 200 iterations: P-steps 8.4 s -> 6.7 s; ECTM
 * 381 -> 390, d = 6, seeded, 1 thread: 15.7 -> 10.7 ms at beta 500 but
 * 4.2 -> 5.5 ms at beta 1e5 (making the boxes costs more than they save),
 * hence only from PROJ_BOX_MIN_DIM on. */
#include "proj/proj.h"
#include "proj/proj__tree.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

#define PROJ_BOX_MIN_DIM 8

typedef struct proj__row {
    int d;
    const double *Z;
    const int *f;
    const double *q;
    double s;
    const double *box; /* nf by 2d: per face, the low corner then the high one; or NULL */
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

/* Whether the squared R^d distance from the query to face t's bounding
 * box, a lower bound of its cost tighter than the tree's three
 * coordinates, is below the best cost so far. The partial sums only grow,
 * so the answer is known once one reaches the best: the same answer as
 * the whole sum's, sooner where the leading coordinates carry the
 * distance (the callers' embeddings come in principal axes). */
static bool box_may_win(const proj__row *r, int t)
{
    const double *lo = r->box + 2 * (size_t)r->d * t, *hi = lo + r->d;
    double c = 0;
    for (int k = 0; k < r->d; k++) {
        double e = r->q[k] < lo[k] ? lo[k] - r->q[k] : r->q[k] > hi[k] ? r->q[k] - hi[k] : 0;
        c += e * e;
        if (!(c < r->best))
            return false;
    }
    return true;
}

static bool visit_face(struct RTCPointQueryFunctionArguments *args)
{
    proj__row *r = args->userPtr;
    double bary[3];
    if (r->box && !box_may_win(r, (int)args->primID))
        return false;
    double c = face_cost(r, (int)args->primID, bary);
    if (!(c < r->best))
        return false;
    r->best = c;
    r->face = (int)args->primID;
    r->bary[0] = bary[0], r->bary[1] = bary[1], r->bary[2] = bary[2];
    args->query->radius = query_radius(r);
    return true;
}

int proj_closest(const proj_tree *t, int d, const double *Z, double s,
                 int n, const double *Q, int *face, double *bary, double *cost)
{
    if (d < 3 || !(s > 0) || !isfinite(s) || n < 0)
        return PROJ_EINVAL;
    for (int i = 0; i < n; i++)
        if (face[i] >= t->nf)
            return PROJ_EFACE;

    double *box = d >= PROJ_BOX_MIN_DIM ? malloc(2 * (size_t)d * t->nf * sizeof *box) : NULL;
    if (box) {
        #pragma omp parallel for schedule(static)
        for (int f = 0; f < t->nf; f++) {
            const int *v = t->f + 3 * (size_t)f;
            double *lo = box + 2 * (size_t)d * f, *hi = lo + d;
            for (int k = 0; k < d; k++) {
                double a = Z[(size_t)d * v[0] + k], b = Z[(size_t)d * v[1] + k], c = Z[(size_t)d * v[2] + k];
                lo[k] = fmin(a, fmin(b, c));
                hi[k] = fmax(a, fmax(b, c));
            }
        }
    }
    #pragma omp parallel for schedule(dynamic, 256)
    for (int i = 0; i < n; i++) {
        const double *q = Q + (size_t)d * i;
        proj__row r = { .d = d, .Z = Z, .f = t->f, .q = q, .s = s, .box = box,
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
        face[i] = r.face;
        bary[3 * (size_t)i] = r.bary[0];
        bary[3 * (size_t)i + 1] = r.bary[1];
        bary[3 * (size_t)i + 2] = r.bary[2];
        if (cost)
            cost[i] = r.best;
    }
    free(box);
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
        face[i] = r.face;
        bary[3 * (size_t)i] = r.bary[0];
        bary[3 * (size_t)i + 1] = r.bary[1];
        bary[3 * (size_t)i + 2] = r.bary[2];
        if (cost)
            cost[i] = r.best;
    }
}
