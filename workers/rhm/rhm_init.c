/* rhm_init.c — RHM's start from landmarks (rhm.h): P12 and P21 by
 * projection in the space of geodesic distances to the landmarks, the
 * thesis' geodesic Voronoi map (§3.3.2) with its nearest-neighbour reverse,
 * or a functional map from the landmarks' wave-kernel descriptors (Δ and
 * D_N commutativity) made precise by DDM deblurring (thesis §2.4); then
 * X_ij = P_ij X_j. Builds maps only; no optimisation. */
#include "rhm/rhm__problem.h"
#include "ddm/ddm.h"
#include "embed/embed.h"
#include "fmap/fmap.h"
#include "geo/geo_orient.h"
#include "geod/geod_voronoi.h"
#include "lbo/lbo.h"
#include "util/errbuf.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Sets row r of P to vertex v exactly: weight 1 at v's corner of the face
 * vface[v] (see vertex_faces). */
static void row_at_vertex(bmap *P, int r, const int *vface, const int *vcorner, int v)
{
    P->face[r] = vface[v];
    for (int k = 0; k < 3; k++)
        P->w[3 * r + k] = k == vcorner[v];
}

/* vface[v], vcorner[v]: the first face listing v and v's position in it. */
static int vertex_faces(const mesh *m, int **vface, int **vcorner)
{
    *vface = malloc(sizeof(int) * (size_t)m->nv);
    *vcorner = malloc(sizeof(int) * (size_t)m->nv);
    if (!*vface || !*vcorner)
        return -1;
    for (int v = 0; v < m->nv; v++)
        (*vface)[v] = -1;
    for (int t = m->nf - 1; t >= 0; t--)
        for (int k = 0; k < 3; k++) {
            (*vface)[m->f[3 * t + k]] = t;
            (*vcorner)[m->f[3 * t + k]] = k;
        }
    return 0;
}

/* Side i's description of its vertices, nv_i by dd = nl + no: the
 * distances to its landmarks divided by √s_i, then no = nl orientation
 * features RHM__ORIENT_WEIGHT·sin∠(∇d_r, ∇d_{r+1}) (geo_orient.h; r + 1
 * modulo nl), which a mirrored match negates. */
static double *landmark_description(rhm__side *a, int nl, int dd, int *rc)
{
    double *f = malloc(sizeof(double) * (size_t)nl * a->n);
    double *D = malloc(sizeof(double) * (size_t)dd * a->n);
    double *o = malloc(sizeof(double) * (size_t)a->n);
    *rc = RHM_ENOMEM;
    if (f && D && o) {
        int g = geod_all_pairs_from(a->geod, a->lmk, nl, f);
        *rc = g == GEOD_OK ? RHM_OK : g == GEOD_ENOMEM ? RHM_ENOMEM : RHM_EMESH;
    }
    if (*rc == RHM_OK) {
        double sc = 1 / sqrt(a->s);
        for (int v = 0; v < a->n; v++)
            for (int r = 0; r < nl; r++)
                D[(size_t)v * dd + r] = sc * f[(size_t)r * a->n + v];
        for (int r = 0; nl + r < dd && *rc == RHM_OK; r++) {
            if (geo_gradient_sine(a->m, f + (size_t)r * a->n, 1,
                                  f + (size_t)((r + 1) % nl) * a->n, 1, o)) {
                *rc = RHM_ENOMEM;
                break;
            }
            for (int v = 0; v < a->n; v++)
                D[(size_t)v * dd + nl + r] = RHM__ORIENT_WEIGHT * o[v];
        }
    }
    if (*rc != RHM_OK) {
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
    int rc = RHM_ENOMEM;
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
        rc = RHM_ENUMERIC;
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
    rc = RHM_OK;
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
static int start_distances(rhm__problem *pb, char *err, size_t errsz)
{
    int nl = pb->nl, dd = nl + (RHM__ORIENT_WEIGHT > 0 ? nl : 0), rc = RHM_OK;
    double *D[2] = {NULL, NULL};
    for (int i = 0; i < 2 && rc == RHM_OK; i++)
        if (!(D[i] = landmark_description(&pb->side[i], nl, dd, &rc)))
            errbuf_set(err, errsz, rc, "%s: distances to the landmarks failed",
                       i ? "target" : "source");
    const int n[2] = { pb->side[0].n, pb->side[1].n };
    if (rc == RHM_OK && (rc = principal_frame(D, n, dd)))
        errbuf_set(err, errsz, rc, "the start map: the principal axes of the distances failed");
    for (int i = 0; i < 2 && rc == RHM_OK; i++) {
        rhm__side *a = &pb->side[i], *b = &pb->side[1 - i];
        mesh *emb = mesh_new(b->n, b->m->nf);
        proj_tree *t = NULL;
        char why[256] = "";
        rc = RHM_ENOMEM;
        if (emb) {
            for (int v = 0; v < b->n; v++)
                memcpy(emb->v + 3 * v, D[1 - i] + (size_t)v * dd, 3 * sizeof(double));
            memcpy(emb->f, b->m->f, sizeof(int) * 3 * (size_t)b->m->nf);
            rc = (t = proj_tree_new(emb, why, sizeof why)) ? RHM_OK
                 : errno == ENOMEM                   ? RHM_ENOMEM
                                                     : RHM_ENUMERIC;
        }
        for (int v = 0; rc == RHM_OK && v < a->n; v++)
            a->P->face[v] = -1;
        if (rc == RHM_OK && proj_closest(t, dd, D[1 - i], 1, a->n, D[i], a->P->face, a->P->w, NULL))
            rc = RHM_ENUMERIC;
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

/* §3.3.2: P12 sends every vertex of a geodesic Voronoi cell of the source
 * landmarks to the cell's target landmark; P21 every target vertex to the
 * source landmark whose target landmark is nearest in X2. */
static int start_voronoi(rhm__problem *pb, char *err, size_t errsz)
{
    rhm__side *a = &pb->side[0], *b = &pb->side[1];
    int dim = pb->dim, nl = pb->nl, rc = RHM_ENOMEM;
    int *fa = NULL, *ca = NULL, *fb = NULL, *cb = NULL;
    geod_voronoi *vor = NULL;
    char detail[512];
    if (vertex_faces(a->m, &fa, &ca) || vertex_faces(b->m, &fb, &cb)) {
        errbuf_set(err, errsz, RHM_ENOMEM, "out of memory");
        goto out;
    }
    int g = geod_voronoi_new(a->geod, a->lmk, nl, &vor, detail, sizeof detail);
    if (g) {
        rc = errbuf_set(err, errsz, g == GEOD_ENOMEM ? RHM_ENOMEM : g == GEOD_EINVAL ? RHM_ELANDMARKS
                                                                                    : RHM_EMESH,
                        "Voronoi cells of the source landmarks: %s", detail);
        goto out;
    }
    for (int v = 0; v < a->n; v++)
        row_at_vertex(a->P, v, fb, cb, b->lmk[vor->cell[v]]);
    /* T21(v) = argmin over the images T12(V1) = {q_r} of |X2(q_r) - X2(v)|;
     * every vertex of cell r maps to q_r, so p_r is a valid preimage. */
    for (int v = 0; v < b->n; v++) {
        const double *x = b->X + (size_t)v * dim;
        int best = 0;
        double bd = INFINITY;
        for (int r = 0; r < nl; r++) {
            const double *y = b->X + (size_t)b->lmk[r] * dim;
            double d = 0;
            for (int c = 0; c < dim; c++)
                d += (x[c] - y[c]) * (x[c] - y[c]);
            if (d < bd) {
                bd = d;
                best = r;
            }
        }
        row_at_vertex(b->P, v, fa, ca, a->lmk[best]);
    }
    rc = RHM_OK;
out:
    geod_voronoi_free(vor);
    free(fa);
    free(ca);
    free(fb);
    free(cb);
    return rc;
}

/* Both directions: C_ij from side i's and side j's landmark descriptors
 * with Δ, D_N and orientation commutativity (the orientation operators of
 * FMAP_ORIENT_ENERGIES columns per descriptor block, fmap.h), Psi_i C_ij ~
 * P_ij Psi_j, with zoomout > 0 grown by ZoomOut to that size
 * (fmap_zoomout), deblurred row by row onto side j (ddm.h). */
static int start_fmap(rhm__problem *pb, char *err, size_t errsz)
{
    rhm__side *s = pb->side;
    int k = RHM_FMAP_K, rc = RHM_ENOMEM, nl = pb->nl, kz = pb->p.zoomout;
    for (int i = 0; i < 2; i++)
        if (k > s[i].n - 2)
            k = s[i].n - 2;
    for (int i = 0; i < 2; i++)
        if (kz > s[i].n - 2)
            return errbuf_set(err, errsz, RHM_EPARAM,
                              "params.zoomout = %d: a basis holds at most vertices - 2 = %d "
                              "eigenfunctions here (%d vertices)", kz, s[i].n - 2, s[i].n);
    int kb = kz > k ? kz : k;                    /* the bases' size */
    lbo_basis bz[2], b[2];                       /* kb functions; the first k (descriptors, C) */
    memset(bz, 0, sizeof bz);
    memset(b, 0, sizeof b);
    double *F[2] = {NULL, NULL}, *N[2] = {NULL, NULL}, *C = malloc(sizeof(double) * (size_t)k * k);
    double *O[2] = {NULL, NULL}, *CZ = kz ? malloc(sizeof(double) * (size_t)kz * kz) : NULL;
    int *zmap = kz ? malloc(sizeof(int) * (size_t)(s[0].n > s[1].n ? s[0].n : s[1].n)) : NULL;
    int nd = 0, lrc = 0, *cols = malloc(sizeof(int) * (size_t)(1 + nl) * FMAP_ORIENT_ENERGIES);
    int no = cols ? fmap_orientation_columns(FMAP_ENERGIES_DEFAULT, nl, FMAP_ORIENT_ENERGIES, cols)
                  : 0;
    char detail[512] = "";
    lmk_set L = {nl, s[0].lmk, s[1].lmk}, R = {nl, s[1].lmk, s[0].lmk};
    for (int i = 0; i < 2 && !lrc; i++)
        lrc = lbo_eigenpairs(geod_solver_laplacian(s[i].geod), geod_solver_mass(s[i].geod), s[i].n, kb, &bz[i],
                             detail, sizeof detail);
    for (int i = 0; i < 2 && !lrc; i++)
        if (lbo_basis_first(&bz[i], k, &b[i]))
            goto nomem;
    if (lrc) {
        rc = errbuf_set(err, errsz, RHM_ENUMERIC, "the functional-map start: eigenpairs: %s", detail);
        goto out;
    }
    if (!C || !cols || (kz && (!CZ || !zmap)))
        goto nomem;
    for (int i = 0; i < 2; i++)
        if (!(N[i] = malloc(sizeof(double) * (size_t)k * k)) ||
            !(O[i] = malloc(sizeof(double) * (size_t)k * k * (no > 0 ? no : 1))))
            goto nomem;
    for (int i = 0; i < 2 && !lrc; i++)
        lrc = fmap_normal_operator(s[i].m, &b[i], k, N[i], detail, sizeof detail);
    for (int i = 0; i < 2 && !lrc; i++) {
        int j = 1 - i;
        free(F[0]);
        free(F[1]);
        F[0] = F[1] = NULL;
        lrc = fmap_landmark_descriptors(&b[i], &b[j], i ? &R : &L, FMAP_ENERGIES_DEFAULT, &F[0], &F[1], &nd,
                                        detail, sizeof detail);
        for (int q = 0; q < 2 && !lrc; q++) {
            int side = q ? j : i;
            lrc = fmap_orientation_operators(s[side].m, &b[side], F[q], nd, cols, no, k, O[q], detail,
                                             sizeof detail);
        }
        if (!lrc)
            lrc = fmap_from_descriptors_oriented(&b[i], geod_solver_mass(s[i].geod), F[0], N[i], O[0],
                                                 &b[j], geod_solver_mass(s[j].geod), F[1], N[j], O[1], nd,
                                                 no, k, k, FMAP_MU_LAP_DEFAULT, FMAP_MU_NORMAL_DEFAULT,
                                                 FMAP_MU_ORIENT_DEFAULT, C, NULL, detail, sizeof detail);
        if (!lrc && kz)
            lrc = fmap_zoomout(&bz[i], geod_solver_mass(s[i].geod), &bz[j], C, k, kz, FMAP_ZOOMOUT_STEP,
                               CZ, zmap, NULL, detail, sizeof detail);
        if (!lrc)
            lrc = kz ? ddm_deblur(&bz[i], NULL, &bz[j], s[j].m, CZ, kz, kz, s[i].P, NULL, detail, sizeof detail)
                     : ddm_deblur(&b[i], NULL, &b[j], s[j].m, C, k, k, s[i].P, NULL, detail, sizeof detail);
    }
    rc = lrc ? errbuf_set(err, errsz, RHM_ENUMERIC, "the functional-map start: %s", detail) : RHM_OK;
    goto out;
nomem:
    rc = errbuf_set(err, errsz, RHM_ENOMEM, "out of memory");
out:
    for (int i = 0; i < 2; i++) {
        lbo_basis_close(&b[i]);
        lbo_basis_close(&bz[i]);
        free(F[i]);
        free(N[i]);
        free(O[i]);
    }
    free(cols);
    free(C);
    free(CZ);
    free(zmap);
    return rc;
}

int rhm__init_start(rhm__problem *pb, char *err, size_t errsz)
{
    rhm__side *a = &pb->side[0], *b = &pb->side[1];
    bmap_free(a->P);
    bmap_free(b->P);
    a->P = bmap_new(a->n, b->n);
    b->P = bmap_new(b->n, a->n);
    if (!a->P || !b->P)
        return errbuf_set(err, errsz, RHM_ENOMEM, "out of memory");
    int rc = pb->p.start == RHM_START_VORONOI ? start_voronoi(pb, err, errsz)
           : pb->p.start == RHM_START_FMAP    ? start_fmap(pb, err, errsz)
                                              : start_distances(pb, err, errsz);
    if (rc)
        return rc;
    bmap_apply(a->P, b->m->f, b->X, pb->dim, a->Xij);
    bmap_apply(b->P, a->m->f, a->X, pb->dim, b->Xij);
    return RHM_OK;
}
