/* test_embed.c — landmark MDS of geodesic distances: the eigen-solver and
 * fit measure against hand-made cases, farthest-point sampling invariants,
 * the unit sphere (distances well reproduced in 8 dimensions) and the flat
 * disk (recovered up to a rigid motion in 2 dimensions). */
#include "support/harness.h"
#include "support/testmesh.h"
#include "embed/embed.h"

#include <math.h>
#include <string.h>

TEST(top_eigenpairs_of_a_known_matrix)
{
    /* Q diag(5, 2, -1) Q^T with Q a rotation in the (0,1) plane */
    double c = cos(0.3), s = sin(0.3), lam[3] = {5, 2, -1};
    double Q[9] = {c, -s, 0, s, c, 0, 0, 0, 1}, A[9] = {0};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++)
                A[3 * i + j] += Q[3 * i + k] * lam[k] * Q[3 * j + k];
    double w[2], V[6], all[3];
    CHECK_INT(embed_top_eigenpairs(A, 3, 2, w, V, all), EMBED_OK);
    CHECK_NEAR(w[0], 5, 1e-12);
    CHECK_NEAR(w[1], 2, 1e-12);
    CHECK_NEAR(all[0], -1, 1e-12);
    CHECK_NEAR(all[2], 5, 1e-12);
    for (int e = 0; e < 2; e++) {
        double big = 0;
        for (int i = 0; i < 3; i++) {
            double av = 0;
            for (int j = 0; j < 3; j++)
                av += A[3 * i + j] * V[2 * j + e];
            CHECK_NEAR(av, w[e] * V[2 * i + e], 1e-12);
            if (fabs(V[2 * i + e]) > fabs(big))
                big = V[2 * i + e];
        }
        CHECK(big > 0);
    }
    CHECK_INT(embed_top_eigenpairs(A, 3, 4, w, V, NULL), EMBED_EINVAL);
}

TEST(distance_fit_of_exact_scaled_and_noisy_pairs)
{
    double g[4] = {1, 2, 3, 4}, e[4], stress, corr;
    embed_distance_fit(g, g, 4, &stress, &corr);
    CHECK_NEAR(stress, 0, 0);
    CHECK_NEAR(corr, 1, 1e-15);
    for (int i = 0; i < 4; i++)
        e[i] = 2 * g[i];
    embed_distance_fit(g, e, 4, &stress, &corr);
    CHECK_NEAR(stress, 1, 1e-15); /* |2g - g| / |g| */
    CHECK_NEAR(corr, 1, 1e-15);
    double r[4] = {4, 3, 2, 1};
    embed_distance_fit(g, r, 4, &stress, &corr);
    CHECK_NEAR(corr, -1, 1e-15);
    CHECK_NEAR(stress, sqrt(20.0 / 30.0), 1e-15);
}

TEST(farthest_points_are_spread_and_keep_their_fields)
{
    mesh *m = testmesh_icosphere(3);
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, NULL, 0);
    CHECK(s != NULL);
    enum { K = 12 };
    int pts[K];
    double *F = malloc((size_t)K * K * sizeof *F);
    CHECK_INT(embed_farthest_points(s, 7, K, pts, F, NULL, 0), EMBED_OK);
    CHECK_INT(pts[0], 7);
    for (int j = 0; j < K; j++) {
        CHECK(F[(size_t)j * K + j] == 0);
        for (int i = 0; i < j; i++) {
            CHECK(pts[i] != pts[j]);
            CHECK(F[(size_t)i * K + j] == F[(size_t)j * K + i]);
        }
    }
    /* pts[1] is the farthest vertex from pts[0]: near the antipode */
    CHECK(F[1] > 0.95 * M_PI);
    /* pts[j] maximises the distance to the earlier points, and D holds the
     * distance fields at the sample */
    double *all = malloc((size_t)K * m->nv * sizeof *all);
    CHECK_INT(geod_all_pairs_from(s, pts, K, all), GEOD_OK);
    for (int j = 1; j < K; j++) {
        double best = 0, got = INFINITY;
        for (int x = 0; x < m->nv; x++) {
            double d = INFINITY;
            for (int i = 0; i < j; i++)
                d = fmin(d, all[(size_t)i * m->nv + x]);
            best = fmax(best, d);
            if (x == pts[j])
                got = d;
        }
        CHECK_NEAR(got, best, 1e-12);
        for (int i = 0; i < j; i++)
            CHECK_NEAR(F[(size_t)i * K + j], all[(size_t)j * m->nv + pts[i]], 1e-12);
    }
    free(all);
    char err[256] = "";
    CHECK_INT(embed_farthest_points(s, m->nv, 3, pts, F, err, sizeof err), EMBED_EINVAL);
    free(F);
    geod_solver_free(s);
    mesh_free(m);
}

/* Great-circle distance is not Euclidean: classical MDS of the EXACT
 * distances of 400 random sphere points gives corr 0.978 and stress 0.16
 * (3-D), 0.23 (8-D), 0.31 (64-D) (the negative eigenvalues are dropped and
 * more dimensions only stretch distances). SMACOF does better. Measured
 * here (level 4, dim 8, k 300): landmark stress 0.230 classical -> 0.099
 * after 80 SMACOF steps, corr 0.9825; sample corr 0.9805, stress 0.103
 * (classical landmark MDS alone had sample stress 0.227). */
TEST(sphere_embedding_reproduces_geodesic_distances)
{
    mesh *m = testmesh_icosphere(4);
    char err[256] = "";
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, err, sizeof err);
    if (!s)
        FAILF("%s", err);
    double *Z = malloc((size_t)m->nv * EMBED_DIM_DEFAULT * sizeof *Z);
    embed_quality q;
    CHECK_INT(embed_lmds(s, 0, 0, 0, Z, &q, err, sizeof err), EMBED_OK);
    printf("  k %d: landmarks corr %.4f stress %.4f (classical %.4f, %d SMACOF steps); sample (%d "
           "pairs) corr %.4f stress %.4f; eigen kept %.3f\n", q.landmarks, q.corr_landmarks,
           q.stress_landmarks, q.stress_classical, q.smacof_iterations, q.pairs_sample,
           q.corr_sample, q.stress_sample, q.eigen_kept);
    CHECK_INT(q.landmarks, EMBED_LANDMARKS_DEFAULT);
    CHECK(q.pairs_sample > 0.9 * EMBED_QUALITY_SOURCES * EMBED_QUALITY_TARGETS);
    CHECK(q.corr_landmarks > 0.98 && q.corr_sample > 0.975);
    CHECK(q.stress_landmarks < 0.12 && q.stress_sample < 0.12);
    CHECK(q.stress_landmarks < 0.5 * q.stress_classical);
    for (int i = 0; i < m->nv * EMBED_DIM_DEFAULT; i++)
        CHECK(isfinite(Z[i]));
    free(Z);
    geod_solver_free(s);
    mesh_free(m);
}

/* Orthogonal Procrustes in 2-D: residual of the best rotation or
 * reflection of the centred Z onto the centred P, over |P|. */
static double procrustes_2d(const double *Z, const double *P3, int n)
{
    double cz[2] = {0}, cp[2] = {0};
    for (int i = 0; i < n; i++)
        for (int d = 0; d < 2; d++) {
            cz[d] += Z[2 * i + d] / n;
            cp[d] += P3[3 * i + d] / n;
        }
    double C[4] = {0}, zz = 0, pp = 0;
    for (int i = 0; i < n; i++) {
        double z[2] = {Z[2 * i] - cz[0], Z[2 * i + 1] - cz[1]};
        double p[2] = {P3[3 * i] - cp[0], P3[3 * i + 1] - cp[1]};
        for (int a = 0; a < 2; a++)
            for (int b = 0; b < 2; b++)
                C[2 * a + b] += z[a] * p[b];
        zz += z[0] * z[0] + z[1] * z[1];
        pp += p[0] * p[0] + p[1] * p[1];
    }
    /* nuclear norm of a 2x2 matrix = max over rotations and reflections */
    double rot = hypot(C[0] + C[3], C[1] - C[2]), ref = hypot(C[0] - C[3], C[1] + C[2]);
    double res = zz + pp - 2 * fmax(rot, ref);
    return sqrt(fmax(res, 0) / pp);
}

/* Measured (817 vertices, k 300): Procrustes 0.0123 of the disk's size;
 * landmarks corr 0.99985, stress 0.0086 (classical 0.0126); sample corr
 * 0.99986, stress 0.0080. */
TEST(disk_embedding_in_2d_recovers_the_disk)
{
    mesh *m = testmesh_disk(16);
    char err[256] = "";
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, err, sizeof err);
    if (!s)
        FAILF("%s", err);
    double *Z = malloc((size_t)m->nv * 2 * sizeof *Z);
    embed_quality q;
    CHECK_INT(embed_lmds(s, 2, 0, 0, Z, &q, err, sizeof err), EMBED_OK);
    double pe = procrustes_2d(Z, m->v, m->nv);
    printf("  Procrustes %.5f; landmarks corr %.5f stress %.4f (classical %.4f); sample corr %.5f "
           "stress %.4f; eigen kept %.3f\n", pe, q.corr_landmarks, q.stress_landmarks,
           q.stress_classical, q.corr_sample, q.stress_sample, q.eigen_kept);
    CHECK(pe < 0.02);
    CHECK(q.corr_landmarks > 0.999 && q.corr_sample > 0.999);
    CHECK(q.stress_landmarks < 0.015 && q.stress_sample < 0.015);
    CHECK(q.eigen_kept > 0.85); /* measured 0.896 */
    /* a 1-D embedding of a disk must fit worse: the report is not constant */
    embed_quality q1;
    CHECK_INT(embed_lmds(s, 1, 0, 0, Z, &q1, err, sizeof err), EMBED_OK);
    CHECK(q1.stress_landmarks > 2 * q.stress_landmarks);
    CHECK(q1.eigen_kept < q.eigen_kept);
    free(Z);
    geod_solver_free(s);
    mesh_free(m);
}

TEST(bad_embedding_arguments_are_refused)
{
    mesh *m = testmesh_icosphere(1);
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, NULL, 0);
    CHECK(s != NULL);
    double *Z = malloc((size_t)m->nv * 8 * sizeof *Z);
    char err[256] = "";
    CHECK_INT(embed_lmds(s, EMBED_MAX_DIM + 1, 0, 0, Z, NULL, err, sizeof err), EMBED_EINVAL);
    CHECK_INT(embed_lmds(s, 8, 8, 0, Z, NULL, err, sizeof err), EMBED_EINVAL);
    CHECK_INT(embed_lmds(s, 8, m->nv + 1, 0, Z, NULL, err, sizeof err), EMBED_EINVAL);
    CHECK_INT(embed_lmds(s, 2, 0, -1, Z, NULL, err, sizeof err), EMBED_EINVAL);
    CHECK_STR_HAS(err, "start -1");
    /* the default k is capped at nv (42 vertices) */
    CHECK_INT(embed_lmds(s, 3, 0, 0, Z, NULL, err, sizeof err), EMBED_OK);
    free(Z);
    geod_solver_free(s);
    mesh_free(m);
}

/* SMACOF from a perturbed start recovers points whose distances are
 * Euclidean (stress to round-off), and never raises the stress. */
TEST(smacof_recovers_euclidean_configurations)
{
    enum { K = 40, DIM = 3 };
    double P[K * DIM], Y[K * DIM], D[K * K];
    unsigned long long st = 11;
    for (int i = 0; i < K * DIM; i++)
        P[i] = testmesh_rand(&st);
    for (int i = 0; i < K; i++)
        for (int j = 0; j < K; j++) {
            double d2 = 0;
            for (int c = 0; c < DIM; c++)
                d2 += (P[i * DIM + c] - P[j * DIM + c]) * (P[i * DIM + c] - P[j * DIM + c]);
            D[i * K + j] = sqrt(d2);
        }
    for (int i = 0; i < K * DIM; i++)
        Y[i] = P[i] + 0.1 * (testmesh_rand(&st) - 0.5);
    double g[K * (K - 1) / 2], e[K * (K - 1) / 2], stress[4], corr;
    int its[4] = {0, 1, 5, 2000};
    for (int r = 0; r < 4; r++) {
        double Yr[K * DIM];
        memcpy(Yr, Y, sizeof Y);
        CHECK_INT(embed_smacof(D, K, DIM, its[r], 0, Yr, NULL), EMBED_OK);
        int n = 0;
        for (int i = 0; i < K; i++)
            for (int j = i + 1; j < K; j++, n++) {
                double d2 = 0;
                for (int c = 0; c < DIM; c++)
                    d2 += (Yr[i * DIM + c] - Yr[j * DIM + c]) * (Yr[i * DIM + c] - Yr[j * DIM + c]);
                g[n] = D[i * K + j];
                e[n] = sqrt(d2);
            }
        embed_distance_fit(g, e, n, &stress[r], &corr);
    }
    printf("  stress after 0/1/5/2000 steps: %.3g %.3g %.3g %.3g\n", stress[0], stress[1],
           stress[2], stress[3]);
    CHECK(stress[1] <= stress[0] && stress[2] <= stress[1] && stress[3] <= stress[2]);
    CHECK(stress[3] < 1e-6);
}

/* The biharmonic extension keeps the fixed rows and, from every fourth
 * vertex of a level-4 sphere with its true coordinates, rebuilds the rest
 * closely. Measured: max error 0.0004 on the unit sphere. */
TEST(biharmonic_extension_interpolates_and_rebuilds_a_sphere)
{
    mesh *m = testmesh_icosphere(4);
    char err[256] = "";
    geod_solver *s = NULL;
    geod_solver_new(m, 0, &s, err, sizeof err);
    if (!s)
        FAILF("%s", err);
    int k = 0, *fixed = malloc(m->nv * sizeof *fixed);
    double *Y = malloc((size_t)m->nv * 3 * sizeof *Y), *Z = malloc((size_t)m->nv * 3 * sizeof *Z);
    for (int v = 0; v < m->nv; v += 4, k++) {
        fixed[k] = v;
        memcpy(Y + 3 * k, m->v + 3 * v, 3 * sizeof *Y);
    }
    CHECK_INT(embed_biharmonic(geod_solver_laplacian(s), geod_solver_mass(s), fixed, k, Y, 3, Z,
                               err, sizeof err), EMBED_OK);
    double worst = 0;
    for (int v = 0; v < m->nv; v++) {
        double d2 = 0;
        for (int c = 0; c < 3; c++)
            d2 += (Z[3 * v + c] - m->v[3 * v + c]) * (Z[3 * v + c] - m->v[3 * v + c]);
        if (v % 4 == 0)
            CHECK(d2 == 0);
        worst = fmax(worst, sqrt(d2));
    }
    printf("  %d of %d vertices fixed; max error %.4f\n", k, m->nv, worst);
    CHECK(worst < 0.002);
    free(fixed);
    free(Y);
    free(Z);
    geod_solver_free(s);
    mesh_free(m);
}
