/* start_distances.c — the distances start (start.h): every vertex
 * described by its geodesic distances to its side's landmarks (and the
 * orientation features), P_ij row v the exact closest point of v's
 * description on side j embedded with its own descriptions (proj.h).
 * Builds maps only; no optimisation. */
#include "start/start.h"
#include "embed/embed.h"
#include "geo/geo_orient.h"
#include "proj/proj.h"
#include "util/errbuf.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Side i's description of its vertices, nv_i by dd = nl + no: the
 * distances to its landmarks divided by √s_i, then no = nl orientation
 * features START_ORIENT_WEIGHT·sin∠(∇d_r, ∇d_{r+1}) (geo_orient.h; r + 1
 * modulo nl), which a mirrored match negates. */
static double *landmark_description(const rhm_side *a, int nl, int dd, int *rc)
{
    double *f = malloc(sizeof(double) * (size_t)nl * a->n);
    double *D = malloc(sizeof(double) * (size_t)dd * a->n);
    double *o = malloc(sizeof(double) * (size_t)a->n);
    *rc = KIND_ENOMEM;
    if (f && D && o) {
        int g = geod_all_pairs_from(a->geod, a->lmk, nl, f);
        *rc = g == GEOD_OK ? KIND_OK : g == GEOD_ENOMEM ? KIND_ENOMEM : KIND_EMESH;
    }
    if (*rc == KIND_OK) {
        double sc = 1 / sqrt(a->area);
        for (int v = 0; v < a->n; v++)
            for (int r = 0; r < nl; r++)
                D[(size_t)v * dd + r] = sc * f[(size_t)r * a->n + v];
        for (int r = 0; nl + r < dd && *rc == KIND_OK; r++) {
            if (geo_gradient_sine(a->m, f + (size_t)r * a->n, 1,
                                  f + (size_t)((r + 1) % nl) * a->n, 1, o)) {
                *rc = KIND_ENOMEM;
                break;
            }
            for (int v = 0; v < a->n; v++)
                D[(size_t)v * dd + nl + r] = START_ORIENT_WEIGHT * o[v];
        }
    }
    if (*rc != KIND_OK) {
        free(D);
        D = NULL;
    }
    free(f);
    free(o);
    return D;
}

/* Moves both sides' descriptions (n[i] rows of dd) into the principal axes
 * of their union: D ← (D − mean)·V, V the eigenvectors of the covariance,
 * by decreasing variance. A rigid motion of R^dd, so every distance, and
 * with it every closest point, stays the same; but the projection's
 * bounds end their sums over the coordinates once they pass the best
 * cost, sooner where the leading coordinates carry the distance, and with
 * fewer than four landmarks (dd < PROJ_HD_MIN_DIM) its 3-D tree holds the
 * first three. The distances to the landmarks are strongly correlated (a
 * surface in R^dd): along the first three landmarks' distances the 3-D bound
 * would let the search visit most faces. */
static int principal_frame(double *D[2], const int n[2], int dd)
{
    double *C = calloc((size_t)dd * dd, sizeof *C), *mu = calloc((size_t)dd, sizeof *mu);
    double *w = malloc(sizeof(double) * (size_t)dd), *V = malloc(sizeof(double) * (size_t)dd * dd);
    double *row = malloc(sizeof(double) * (size_t)dd);
    int rc = KIND_ENOMEM;
    if (!C || !mu || !w || !V || !row)
        goto out;
    long total = (long)n[0] + n[1];
    for (int i = 0; i < 2; i++)
        for (int v = 0; v < n[i]; v++)
            for (int a = 0; a < dd; a++)
                mu[a] += D[i][(size_t)v * dd + a] / (double)total;
    for (int i = 0; i < 2; i++)
        for (int v = 0; v < n[i]; v++) {
            const double *x = D[i] + (size_t)v * dd;
            for (int a = 0; a < dd; a++)
                for (int b = a; b < dd; b++)
                    C[(size_t)a * dd + b] += (x[a] - mu[a]) * (x[b] - mu[b]);
        }
    for (int a = 0; a < dd; a++)
        for (int b = 0; b < a; b++)
            C[(size_t)a * dd + b] = C[(size_t)b * dd + a];
    if (embed_top_eigenpairs(C, dd, dd, w, V, NULL)) {
        rc = KIND_ENUMERIC;
        goto out;
    }
    for (int i = 0; i < 2; i++)
        for (int v = 0; v < n[i]; v++) {
            double *x = D[i] + (size_t)v * dd;
            for (int c = 0; c < dd; c++) {
                double t = 0;
                for (int a = 0; a < dd; a++)
                    t += (x[a] - mu[a]) * V[(size_t)a * dd + c];
                row[c] = t;
            }
            memcpy(x, row, sizeof(double) * (size_t)dd);
        }
    rc = KIND_OK;
out:
    free(C);
    free(mu);
    free(w);
    free(V);
    free(row);
    return rc;
}

/* P_ij row v: the closest point, in R^dd, of v's description (above) on
 * side j embedded with its own; exact (proj.h), in the principal axes of
 * both descriptions (principal_frame). Each search starts unseeded: the radius
 * is set by the closest distance itself, so a neighbour's face as a first
 * guess would not shorten it. */
int start_distances(rhm_side side[2], char *err, size_t errsz)
{
    int nl = side[0].nl, dd = nl + (START_ORIENT_WEIGHT > 0 ? nl : 0), rc = KIND_OK;
    double *D[2] = {NULL, NULL};
    for (int i = 0; i < 2 && rc == KIND_OK; i++)
        if (!(D[i] = landmark_description(&side[i], nl, dd, &rc)))
            errbuf_set(err, errsz, rc, "%s: distances to the landmarks failed",
                       i ? "target" : "source");
    const int n[2] = { side[0].n, side[1].n };
    if (rc == KIND_OK && (rc = principal_frame(D, n, dd)))
        errbuf_set(err, errsz, rc, "the start map: the principal axes of the distances failed");
    for (int i = 0; i < 2 && rc == KIND_OK; i++) {
        rhm_side *a = &side[i], *b = &side[1 - i];
        mesh *emb = mesh_new(b->n, b->m->nf);
        proj_tree *t = NULL;
        char why[256] = "";
        rc = KIND_ENOMEM;
        if (emb) {
            for (int v = 0; v < b->n; v++)
                memcpy(emb->v + 3 * v, D[1 - i] + (size_t)v * dd, 3 * sizeof(double));
            memcpy(emb->f, b->m->f, sizeof(int) * 3 * (size_t)b->m->nf);
            rc = (t = proj_tree_new(emb, why, sizeof why)) ? KIND_OK
                 : errno == ENOMEM                   ? KIND_ENOMEM
                                                     : KIND_ENUMERIC;
        }
        for (int v = 0; rc == KIND_OK && v < a->n; v++)
            a->P->face[v] = -1;
        if (rc == KIND_OK && proj_closest(t, dd, D[1 - i], 1, a->n, D[i], a->P->face, a->P->w, NULL))
            rc = KIND_ENUMERIC;
        if (rc)
            errbuf_set(err, errsz, rc, "the start map %s: projection failed%s%s",
                       i ? "target -> source" : "source -> target", why[0] ? ": " : "", why);
        proj_tree_free(t);
        mesh_free(emb);
    }
    free(D[0]);
    free(D[1]);
    return rc;
}
