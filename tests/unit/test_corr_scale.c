/* test_corr_scale.c — when ECTM's membrane takes the regional area scale of
 * RHM's maps (corr_scale_reference): from maps that keep areas well on the
 * whole, not from maps whose area ratios are large, whether they come from
 * face-by-face errors or from a smooth, conformal stretch. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "corr/corr.h"
#include "metric/metric.h"

#include <math.h>

static metric_summary summary(const mesh *A, const mesh *B, const bmap *P)
{
    metric_summary m;
    CHECK_INT(metric_summarize(A, B, P, &m), 0);
    return m;
}

/* The unit sphere's points moved by the Möbius map w -> 3w of their
 * stereographic coordinate: conformal, growing the south half's area and
 * shrinking the north's. */
static void moebius(mesh *M)
{
    for (int v = 0; v < M->nv; v++) {
        double *p = M->v + 3 * v, r = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        double x = p[0] / r, y = p[1] / r, z = p[2] / r;
        if (1 - z < 1e-12)
            continue;                          /* the north pole stays */
        double wx = 3 * x / (1 - z), wy = 3 * y / (1 - z), w2 = wx * wx + wy * wy;
        p[0] = 2 * wx / (w2 + 1);
        p[1] = 2 * wy / (w2 + 1);
        p[2] = (w2 - 1) / (w2 + 1);
    }
}

TEST(scale_reference_only_from_maps_that_keep_areas_on_the_whole)
{
    mesh *X = testmesh_icosphere(3), *grown = mesh_copy(X), *rough = mesh_copy(X);
    mesh *conf = mesh_copy(X);
    bmap *I = testmesh_identity(X);
    CHECK(X && grown && rough && conf && I);
    /* the upper half grown smoothly: a pair whose parts differ in size */
    for (int v = 0; v < X->nv; v++) {
        double z = X->v[3 * v + 2], f = 1 + 0.5 * (z > 0 ? z : 0);
        grown->v[3 * v] *= f;
        grown->v[3 * v + 1] *= f;
    }
    /* every coordinate moved at random by up to 2/3 of the mean edge */
    double edge = testmesh_mean_edge(X);
    unsigned long long seed = 7;
    for (int i = 0; i < 3 * X->nv; i++)
        rough->v[i] += edge * 2 / 3 * (2 * testmesh_rand(&seed) - 1);
    moebius(conf);
    metric_summary g = summary(X, grown, I), r = summary(X, rough, I), c = summary(X, conf, I);
    printf("  mean |log area ratio| / median conformal distortion: grown %.3f / %.4f, "
           "rough %.3f / %.4f, conformal %.3f / %.4f\n", g.mean_abs_log_area, g.median_conformal,
           r.mean_abs_log_area, r.median_conformal, c.mean_abs_log_area, c.median_conformal);
    CHECK(g.mean_abs_log_area > 0.1);                 /* not the identity's areas */
    CHECK(c.median_conformal < 0.02);                 /* smooth: only its areas are off */
    corr_input gi = { .S = X, .T = grown }, ri = { .S = X, .T = rough }, ci = { .S = X, .T = conf };
    CHECK_INT(corr_scale_reference(&gi, I, I), 1);
    CHECK_INT(corr_scale_reference(&gi, I, NULL), 1);
    CHECK_INT(corr_scale_reference(&ri, I, I), 0);
    CHECK_INT(corr_scale_reference(&ri, I, NULL), 0);
    CHECK_INT(corr_scale_reference(&ci, I, I), 0);
    bmap_free(I);
    mesh_free(X);
    mesh_free(grown);
    mesh_free(rough);
    mesh_free(conf);
}
