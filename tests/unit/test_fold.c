/* test_fold.c — fold repair (fold.h): a fold planted in the identity map
 * of a mesh onto itself is found (metric_fold_faces) and relaxed away,
 * landmarks stay put, a crowded cap, a cap whose images jumped and a long
 * part's end collapsed onto a short part's are re-mapped, and a map
 * mirrored as a whole is left as it was (the repair never makes a map
 * worse); a thin part's mirrored band with its end collapsed is re-mapped,
 * and so is a collapsed region with a landmark far beyond its boundary's
 * image (the landmarks dragged to their images); the last step moves
 * single vertices whose faces fold back into place, the landmarks not,
 * judged face by face by the metric's own rule, as far as their
 * neighbours spread on a much finer target. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "fold/fold.h"
#include "fold/fold__patch.h"
#include "geo/geo_area.h"
#include "geo/geo_edges.h"
#include "geo/geo_normals.h"
#include "metric/metric.h"
#include "proj/proj.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* P's rows: the closest points of img (nv by 3) on T. */
static bmap *map_of_points(const mesh *T, const double *img, int n)
{
    bmap *P = bmap_new(n, T->nv);
    proj_tree *t = proj_tree_new(T, NULL, 0);
    CHECK(P && t);
    for (int v = 0; v < n; v++)
        P->face[v] = -1;
    CHECK(proj_closest(t, 3, T->v, 1, n, img, P->face, P->w, NULL) == 0);
    proj_tree_free(t);
    return P;
}

static int count_bad(const mesh *S, const mesh *T, const bmap *P, int want)
{
    unsigned char *k = malloc((size_t)S->nf);
    CHECK(metric_fold_faces(S, T, P, k) >= 0);
    int n = 0;
    for (int t = 0; t < S->nf; t++)
        n += k[t] == want;
    free(k);
    return n;
}

/* The identity of a flat disk with the images of a patch (radius 0.3
 * about (0.3, 0)) reflected through the line x = 0.3 inside it: the patch
 * folds over itself. The repair brings every face back the right way. */
TEST(planted_fold_is_found_and_relaxed_away)
{
    mesh *m = testmesh_disk(20);
    int nv = m->nv;
    double *img = malloc(sizeof(double) * 3 * (size_t)nv);
    memcpy(img, m->v, sizeof(double) * 3 * (size_t)nv);
    int fixed = -1, planted = 0;
    for (int v = 0; v < nv; v++) {
        double dx = m->v[3 * v] - 0.3, dy = m->v[3 * v + 1];
        if (dx * dx + dy * dy < 0.09) {
            img[3 * v] = 0.3 - dx;
            planted++;
            if (fixed < 0 && dx * dx + dy * dy < 0.0025)
                fixed = v;   /* a landmark inside the fold, near its centre */
        }
    }
    bmap *P = map_of_points(m, img, nv);
    int flipped = count_bad(m, m, P, METRIC_FACE_FLIPPED);
    printf("  %d vertices reflected, %d of %d faces flipped\n", planted, flipped, m->nf);
    CHECK(flipped > 100);
    double keep[3];
    int keep_face = P->face[fixed];
    memcpy(keep, P->w + 3 * fixed, sizeof keep);

    fold_params fp;
    fold_params_init(&fp);
    fold_report rep;
    CHECK_INT(fold_repair(m, m, &fixed, 1, &fp, P, &rep), FOLD_OK);
    printf("  bad faces %d -> %d, %d vertices re-mapped, %d moved alone\n", rep.bad_before,
           rep.bad_after, rep.region, rep.relaxed);
    CHECK(rep.accepted);
    CHECK_INT(rep.bad_before, flipped);
    CHECK_INT(rep.bad_after, 0);
    CHECK_INT(count_bad(m, m, P, METRIC_FACE_FLIPPED), 0);
    CHECK_INT(count_bad(m, m, P, METRIC_FACE_COLLAPSED), 0);
    CHECK_INT(P->face[fixed], keep_face);
    CHECK(memcmp(P->w + 3 * fixed, keep, sizeof keep) == 0);
    free(img);
    mesh_free(m);
    bmap_free(P);
}

/* The identity of a sphere onto its mirror image (x -> -x, faces reversed
 * so the normals stay outward) reverses orientation everywhere: every face
 * counts as flipped, and no relaxation can fix it; the repair leaves the
 * map as it was. */
TEST(map_mirrored_as_a_whole_is_detected_and_left_unchanged)
{
    mesh *m = testmesh_icosphere(3);
    mesh *r = testmesh_mirrored(m);
    double *img = malloc(sizeof(double) * 3 * (size_t)m->nv);
    memcpy(img, r->v, sizeof(double) * 3 * (size_t)m->nv);
    bmap *P = map_of_points(r, img, m->nv);
    metric_summary ms;
    CHECK(metric_summarize(m, r, P, &ms) == 0);
    printf("  identity onto the mirror image: %.1f %% flipped\n", 100 * ms.flipped_fraction);
    CHECK(ms.flipped_fraction > 0.99);
    bmap *before = map_of_points(r, img, m->nv);
    fold_params fp;
    fold_params_init(&fp);
    fp.passes = 2;
    fold_report rep;
    CHECK_INT(fold_repair(m, r, NULL, 0, &fp, P, &rep), FOLD_OK);
    CHECK(!rep.accepted);
    CHECK(rep.bad_after == rep.bad_before);
    CHECK(memcmp(P->face, before->face, sizeof(int) * (size_t)m->nv) == 0);
    CHECK(memcmp(P->w, before->w, sizeof(double) * 3 * (size_t)m->nv) == 0);
    bmap_free(before);
    bmap_free(P);
    free(img);
    mesh_free(r);
    mesh_free(m);
}

TEST(refuses_bad_arguments)
{
    mesh *m = testmesh_disk(3);
    bmap *P = bmap_new(m->nv - 1, m->nv);
    fold_params fp;
    fold_params_init(&fp);
    fold_report rep;
    CHECK_INT(fold_repair(m, m, NULL, 0, &fp, P, &rep), FOLD_EINVAL);
    CHECK_INT(fold_relax(m, m, NULL, 0, P, &rep), FOLD_EINVAL);
    bmap_free(P);
    P = bmap_new(m->nv, m->nv);
    P->face[0] = m->nf;   /* a row off the target */
    CHECK_INT(fold_relax(m, m, NULL, 0, P, &rep), FOLD_EINVAL);
    P->face[0] = 0;
    fp.passes = 0;
    CHECK_INT(fold_repair(m, m, NULL, 0, &fp, P, &rep), FOLD_EINVAL);
    bmap_free(P);
    mesh_free(m);
}

/* The identity of a sphere onto itself with a polar cap (z > 0.75)
 * shrunk toward the pole by 1e-3: no face is flipped and none has an
 * image below the metric's 1e-12 of its area, but the cap's faces are
 * crowded (area ratio ~1e-6), as a harmonic map crowds a long part. The
 * repair counts them as bad and spreads the cap back over the cap. */
TEST(crowded_cap_counts_as_bad_and_is_spread_back)
{
    mesh *m = testmesh_icosphere(4);
    int nv = m->nv;
    double *img = malloc(sizeof(double) * 3 * (size_t)nv);
    memcpy(img, m->v, sizeof(double) * 3 * (size_t)nv);
    for (int v = 0; v < nv; v++)
        if (m->v[3 * v + 2] > 0.75) {
            img[3 * v] *= 1e-3;
            img[3 * v + 1] *= 1e-3;
            img[3 * v + 2] = 1;
        }
    bmap *P = map_of_points(m, img, nv);
    CHECK_INT(count_bad(m, m, P, METRIC_FACE_FLIPPED) + count_bad(m, m, P, METRIC_FACE_COLLAPSED), 0);
    fold_params fp;
    fold_params_init(&fp);
    fold_report rep;
    CHECK_INT(fold_repair(m, m, NULL, 0, &fp, P, &rep), FOLD_OK);
    printf("  crowded faces %d -> %d, %d vertices re-mapped\n", rep.bad_before, rep.bad_after,
           rep.region);
    CHECK(rep.bad_before > 50);
    CHECK(rep.accepted);
    CHECK_INT(rep.bad_after, 0);
    double *y = malloc(sizeof(double) * 3 * (size_t)nv), worst = 0;
    bmap_apply(P, m->f, m->v, 3, y);
    for (int v = 0; v < nv; v++) {
        double d = 0;
        for (int k = 0; k < 3; k++)
            d += (y[3 * v + k] - m->v[3 * v + k]) * (y[3 * v + k] - m->v[3 * v + k]);
        worst = fmax(worst, sqrt(d));
    }
    printf("  farthest vertex from its place: %.3f (the cap's radius is about 0.66)\n", worst);
    CHECK(worst < 0.2);
    free(y);
    free(img);
    bmap_free(P);
    mesh_free(m);
}

/* The identity of a sphere onto itself with the vertices of a polar cap
 * (z > 0.75) sent to scattered points all over the sphere, as a map that
 * jumped does: the cap's faces are flipped or stretched across the
 * sphere, its images lie in many places, and only its boundary ring is
 * still right. The repair re-maps the cap inside that ring: no bad face is
 * left and every cap vertex lands back on the cap, near where it belongs. */
TEST(cap_whose_images_jumped_is_re_mapped_inside_its_boundary)
{
    mesh *m = testmesh_icosphere(4);
    int nv = m->nv, moved = 0;
    double *img = malloc(sizeof(double) * 3 * (size_t)nv);
    memcpy(img, m->v, sizeof(double) * 3 * (size_t)nv);
    unsigned s = 12345;
    for (int v = 0; v < nv; v++)
        if (m->v[3 * v + 2] > 0.75) {
            s = s * 1103515245u + 12345u;
            int u = (int)((s >> 8) % (unsigned)nv);
            memcpy(img + 3 * v, m->v + 3 * u, 3 * sizeof(double));
            moved++;
        }
    bmap *P = map_of_points(m, img, nv);
    int bad = count_bad(m, m, P, METRIC_FACE_FLIPPED) + count_bad(m, m, P, METRIC_FACE_COLLAPSED);
    printf("  %d cap vertices scattered: %d of %d faces bad\n", moved, bad, m->nf);
    CHECK(bad > 50);
    fold_params fp;
    fold_params_init(&fp);
    fold_report rep;
    CHECK_INT(fold_repair(m, m, NULL, 0, &fp, P, &rep), FOLD_OK);
    printf("  bad faces %d -> %d, %d vertices re-mapped in %d regions\n", rep.bad_before,
           rep.bad_after, rep.region, rep.regions);
    CHECK(rep.accepted);
    CHECK_INT(rep.bad_after, 0);
    CHECK_INT(count_bad(m, m, P, METRIC_FACE_FLIPPED) + count_bad(m, m, P, METRIC_FACE_COLLAPSED), 0);
    double *y = malloc(sizeof(double) * 3 * (size_t)nv), worst = 0;
    bmap_apply(P, m->f, m->v, 3, y);
    for (int v = 0; v < nv; v++)
        if (m->v[3 * v + 2] > 0.75) {
            double d = 0;
            for (int k = 0; k < 3; k++)
                d += (y[3 * v + k] - m->v[3 * v + k]) * (y[3 * v + k] - m->v[3 * v + k]);
            if (sqrt(d) > worst)
                worst = sqrt(d);
        }
    printf("  farthest cap vertex from its place: %.3f (the cap's radius is about 0.66)\n", worst);
    CHECK(worst < 0.2);
    free(y);
    free(img);
    bmap_free(P);
    mesh_free(m);
}

/* A long part onto a short one: the source is a tube 6.4 times as long as
 * it is wide, the target one of the same connectivity 1.6 times (the
 * sphere's meridian stretched along z), the map the identity of their
 * vertices with the last 12 rings and the pole all sent to the target's
 * pole (collapsed). The harmonic map of the long end inside its ring
 * crowds it into the short end's tip (48 faces below 1e-4 of their area
 * are left without the reweighting; with it, the re-mapped vertices land
 * up to 0.245 from their own rings, 5 rings' spacing); the end is a tube
 * (deeper than twice its ring's radius), placed by depth (fold.h): no
 * bad face is left, and every re-mapped vertex lands within one ring's
 * spacing of its own ring. */
TEST(long_part_onto_short_part_is_re_mapped_without_crowding)
{
    int rings = 60, around = 24;
    mesh *S = testmesh_spheroid(12.8, rings, around), *T = testmesh_spheroid(3.2, rings, around);
    int nv = S->nv, first = (rings - 12) * around;
    double *img = malloc(sizeof(double) * 3 * (size_t)nv);
    memcpy(img, T->v, sizeof(double) * 3 * (size_t)nv);
    for (int v = first; v < nv; v++)     /* the end's rings and its pole: onto the pole */
        if (v < rings * around || v == nv - 1)
            memcpy(img + 3 * v, T->v + 3 * (nv - 1), 3 * sizeof(double));
    bmap *P = map_of_points(T, img, nv);
    fold_params fp;
    fold_params_init(&fp);
    fold_report rep;
    CHECK_INT(fold_repair(S, T, NULL, 0, &fp, P, &rep), FOLD_OK);
    printf("  bad faces %d -> %d, %d vertices re-mapped in %d regions\n", rep.bad_before,
           rep.bad_after, rep.region, rep.regions);
    CHECK(rep.accepted);
    CHECK_INT(rep.bad_after, 0);
    bmap_apply(P, T->f, T->v, 3, img);
    double worst = 0;
    for (int v = first; v < nv; v++)
        worst = fmax(worst, fabs(img[3 * v + 2] - T->v[3 * v + 2]));
    printf("  farthest along the tube from its own ring: %.3f (ring spacing %.3f)\n", worst,
           3.2 / (rings + 1));
    CHECK(worst < 3.2 / (rings + 1));
    free(img);
    bmap_free(P);
    mesh_free(S);
    mesh_free(T);
}

/* A thin part as the glasses' arms are (52 -> 58): a tube 12.8 times as
 * long as it is wide mapped onto itself, with a band of 10 rings near its
 * end mirrored across the tube's axis (flipped) and, beyond it, the last 6
 * rings and the pole sent to the pole (collapsed). The band's region, its
 * hole filled, takes the end with it, so its chart must join the images of
 * its ring and of the end kept beyond the band, 14 rings apart: grown by
 * at most 6 rings from each side, as it was, it stayed torn and the band
 * flipped (320 -> 200 bad faces). No bad face is left, and every vertex
 * lands within a few rings of its own. */
TEST(mirrored_band_and_collapsed_end_of_a_thin_part_are_re_mapped)
{
    int rings = 120, around = 10;
    double length = 25.6;
    mesh *m = testmesh_spheroid(length, rings, around);
    int nv = m->nv;
    double *img = malloc(sizeof(double) * 3 * (size_t)nv);
    memcpy(img, m->v, sizeof(double) * 3 * (size_t)nv);
    for (int v = 95 * around; v < 105 * around; v++)
        img[3 * v] = -img[3 * v];
    for (int v = (rings - 6) * around; v < nv; v++)
        if (v < rings * around || v == nv - 1)
            memcpy(img + 3 * v, m->v + 3 * (nv - 1), 3 * sizeof(double));
    bmap *P = map_of_points(m, img, nv);
    int flipped = count_bad(m, m, P, METRIC_FACE_FLIPPED),
        collapsed = count_bad(m, m, P, METRIC_FACE_COLLAPSED);
    printf("  planted: %d flipped, %d collapsed of %d faces\n", flipped, collapsed, m->nf);
    CHECK(flipped > 100 && collapsed > 50);
    fold_params fp;
    fold_params_init(&fp);
    fold_report rep;
    CHECK_INT(fold_repair(m, m, NULL, 0, &fp, P, &rep), FOLD_OK);
    printf("  bad faces %d -> %d, %d vertices re-mapped in %d regions\n", rep.bad_before,
           rep.bad_after, rep.region, rep.regions);
    CHECK(rep.accepted);
    CHECK_INT(rep.bad_after, 0);
    CHECK_INT(count_bad(m, m, P, METRIC_FACE_FLIPPED) + count_bad(m, m, P, METRIC_FACE_COLLAPSED), 0);
    bmap_apply(P, m->f, m->v, 3, img);
    double worst = 0;
    for (int v = 0; v < nv; v++)
        if (v < rings * around)
            worst = fmax(worst, fabs(img[3 * v + 2] - m->v[3 * v + 2]));
    printf("  farthest along the tube from its own ring: %.3f (ring spacing %.3f)\n", worst,
           length / (rings + 1));
    CHECK(worst < 5 * length / (rings + 1));
    free(img);
    bmap_free(P);
    mesh_free(m);
}

/* A conformal map of the unit sphere onto itself that crowds the north
 * cap toward a point of the equator: the stereographic coordinate (from
 * the south pole) divided by k, then a quarter turn that takes the north
 * pole to +x. One-to-one and orientation-preserving. */
static void squeeze(const double *x, double k, double *y)
{
    if (x[2] < -1 + 1e-12) {            /* the south pole: to -x */
        y[0] = -1;
        y[1] = y[2] = 0;
        return;
    }
    double wx = x[0] / (1 + x[2]) / k, wy = x[1] / (1 + x[2]) / k, r2 = wx * wx + wy * wy;
    y[0] = (1 - r2) / (1 + r2);
    y[1] = 2 * wy / (1 + r2);
    y[2] = -2 * wx / (1 + r2);
}

/* make demo's cow -> camel in small: a region whose boundary lands round a
 * small disk while a landmark's image lies far outside it. The sphere onto
 * itself by squeeze (k = 3) but for the cap z > 0.7, collapsed onto the
 * north pole's image, and two landmarks in the cap: the north pole, kept
 * at its own place (far beyond the disk the cap's boundary lands round),
 * and a vertex near z = 0.8 on the +x side, sent to the image of its
 * mirror point across x = 0 (the free harmonic remap leaves it far from
 * that). The remap with the landmarks dragged must reach the pole's
 * image, so its chart takes the landmarks' images in; grown from the
 * boundary's image alone it left the pole outside, the dragged remap gave
 * up, the free one was refused, and all 792 collapsed faces stayed. None
 * is left collapsed now; what the drag past the boundary's image costs is
 * a few flips round the pole: 6 of 5120 faces (32 when the drag's steps
 * were not halved where they fold the coarse triangles). */
TEST(collapsed_region_whose_landmark_lies_beyond_its_boundarys_image_is_dragged)
{
    mesh *m = testmesh_icosphere(4);
    int nv = m->nv, lm[2] = { 0, -1 };
    for (int v = 1; v < nv; v++)
        if (m->v[3 * v + 2] > m->v[3 * lm[0] + 2])
            lm[0] = v;
    double best = INFINITY;
    for (int v = 0; v < nv; v++)
        if (m->v[3 * v] > 0 && fabs(m->v[3 * v + 1]) < 0.1 && fabs(m->v[3 * v + 2] - 0.8) < best) {
            best = fabs(m->v[3 * v + 2] - 0.8);
            lm[1] = v;
        }
    double *img = malloc(sizeof(double) * 3 * (size_t)nv), pole[3];
    squeeze(m->v + 3 * lm[0], 3, pole);
    for (int v = 0; v < nv; v++) {
        if (m->v[3 * v + 2] > 0.7)
            memcpy(img + 3 * v, pole, sizeof pole);
        else
            squeeze(m->v + 3 * v, 3, img + 3 * v);
    }
    memcpy(img + 3 * lm[0], m->v + 3 * lm[0], 3 * sizeof(double));
    double mirror[3] = { -m->v[3 * lm[1]], m->v[3 * lm[1] + 1], m->v[3 * lm[1] + 2] };
    squeeze(mirror, 3, img + 3 * lm[1]);
    bmap *P = map_of_points(m, img, nv);
    int collapsed = count_bad(m, m, P, METRIC_FACE_COLLAPSED);
    printf("  planted: %d flipped, %d collapsed of %d faces\n", count_bad(m, m, P, METRIC_FACE_FLIPPED),
           collapsed, m->nf);
    CHECK(collapsed > 500);
    int keep_face[2] = { P->face[lm[0]], P->face[lm[1]] };
    fold_params fp;
    fold_params_init(&fp);
    fold_report rep;
    CHECK_INT(fold_repair(m, m, lm, 2, &fp, P, &rep), FOLD_OK);
    int flipped = count_bad(m, m, P, METRIC_FACE_FLIPPED);
    printf("  bad faces %d -> %d, %d vertices re-mapped in %d regions; %d flipped\n", rep.bad_before,
           rep.bad_after, rep.region, rep.regions, flipped);
    CHECK(rep.accepted);
    CHECK_INT(count_bad(m, m, P, METRIC_FACE_COLLAPSED), 0);
    CHECK(flipped < 16);
    CHECK_INT(P->face[lm[0]], keep_face[0]);
    CHECK_INT(P->face[lm[1]], keep_face[1]);
    free(img);
    bmap_free(P);
    mesh_free(m);
}

static double dist3(const double *a, const double *b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* Pushes up to most vertices (every step-th whose star touches no star
 * pushed before) 1.6 times the way to a neighbour: img (m's vertices on
 * entry) gets their images, touched their stars' vertices, *first the
 * first one pushed. Returns how many were pushed. */
static int push_stars(const mesh *m, const geo_edges *E, int step, int most, double *img,
                      unsigned char *touched, int *first)
{
    int n = 0;
    *first = -1;
    for (int v = 0; v < m->nv && n < most; v += step) {
        int free_star = !touched[v];
        for (int i = E->vf_start[v]; i < E->vf_start[v + 1] && free_star; i++)
            for (int k = 0; k < 3; k++)
                free_star &= !touched[m->f[3 * E->vf_face[i] + k]];
        if (!free_star)
            continue;
        const int *f = m->f + 3 * E->vf_face[E->vf_start[v]];
        int u = f[0] == v ? f[1] : f[0];
        for (int d = 0; d < 3; d++)
            img[3 * v + d] = m->v[3 * v + d] + 1.6 * (m->v[3 * u + d] - m->v[3 * v + d]);
        for (int i = E->vf_start[v]; i < E->vf_start[v + 1]; i++)
            for (int k = 0; k < 3; k++)
                touched[m->f[3 * E->vf_face[i] + k]] = 1;
        if (*first < 0)
            *first = v;
        n++;
    }
    return n;
}

/* The identity of a sphere onto itself with a few scattered vertices'
 * images pushed past a neighbour's (1.6 times the way to it): each such
 * star folds over (the region remaps are not run here). The relaxation
 * (fold_relax) leaves no face bad, and moves only vertices of bad faces,
 * each to within its star's reach of its true place; the first pushed
 * vertex is a landmark and keeps its row (its neighbours move round it).
 * metric_face_kind, which it judges by, agrees with metric_fold_faces on
 * every face, before and after. The identity onto the mirror image, all
 * of whose faces are flipped, it leaves as it is: no star has a good face
 * to relax against. */
TEST(relaxation_moves_single_folded_vertices_back_but_not_landmarks)
{
    mesh *m = testmesh_icosphere(3);
    int nv = m->nv, nf = m->nf;
    geo_edges E;
    char err[128];
    CHECK(geo_edges_build(m, &E, err, sizeof err) == 0);
    double *img = malloc(sizeof(double) * 3 * (size_t)nv);
    memcpy(img, m->v, sizeof(double) * 3 * (size_t)nv);
    unsigned char *touched = calloc((size_t)nv, 1), *badv = calloc((size_t)nv, 1);
    int lm, nmoved = push_stars(m, &E, 37, 8, img, touched, &lm);
    CHECK(nmoved >= 4);
    bmap *P = map_of_points(m, img, nv), *before = map_of_points(m, img, nv);
    unsigned char *kind = malloc((size_t)nf), *k2 = malloc((size_t)nf);
    double *tn = malloc(sizeof(double) * 3 * (size_t)nv);
    geo_vertex_normals(m, tn);
    double area = geo_total_area(m);
    int bad = metric_fold_faces(m, m, P, kind);
    for (int t = 0; t < nf; t++) {
        CHECK_INT(metric_face_kind(m, m, P, img, tn, area, area, t, NULL), kind[t]);
        for (int k = 0; k < 3 && kind[t]; k++)
            badv[m->f[3 * t + k]] = 1;
    }
    printf("  %d stars pushed over: %d bad faces\n", nmoved, bad);
    CHECK(bad >= 2 * nmoved);
    CHECK(badv[lm]);

    fold_report rep;
    CHECK_INT(fold_relax(m, m, &lm, 1, P, &rep), FOLD_OK);
    printf("  relaxed: %d -> %d bad faces, %d moves\n", rep.bad_before, rep.bad_after, rep.relaxed);
    CHECK_INT(rep.bad_before, bad);
    CHECK_INT(rep.bad_after, 0);
    CHECK(rep.accepted);
    CHECK_INT(metric_fold_faces(m, m, P, k2), 0);
    bmap_apply(P, m->f, m->v, 3, img);
    for (int t = 0; t < nf; t++)
        CHECK_INT(metric_face_kind(m, m, P, img, tn, area, area, t, NULL), METRIC_FACE_OK);
    for (int v = 0; v < nv; v++) {
        if (!badv[v] || v == lm) {
            CHECK_INT(P->face[v], before->face[v]);
            CHECK(memcmp(P->w + 3 * v, before->w + 3 * v, 3 * sizeof(double)) == 0);
            continue;
        }
        double far = 0;   /* the star's reach: its farthest neighbour */
        const double *x = m->v + 3 * v, *y = img + 3 * v;
        for (int i = E.vf_start[v]; i < E.vf_start[v + 1]; i++)
            for (int k = 0; k < 3; k++) {
                const double *z = m->v + 3 * m->f[3 * E.vf_face[i] + k];
                far = fmax(far, dist3(x, z));
            }
        CHECK(dist3(x, y) < far);
    }

    mesh *r = testmesh_mirrored(m);
    bmap *M = map_of_points(r, r->v, nv), *M0 = map_of_points(r, r->v, nv);
    CHECK_INT(metric_fold_faces(m, r, M, kind), nf);
    CHECK_INT(fold_relax(m, r, NULL, 0, M, &rep), FOLD_OK);
    CHECK_INT(rep.bad_after, nf);
    CHECK_INT(rep.relaxed, 0);
    CHECK(!rep.accepted);
    CHECK(memcmp(M->face, M0->face, sizeof(int) * (size_t)nv) == 0);
    CHECK(memcmp(M->w, M0->w, sizeof(double) * 3 * (size_t)nv) == 0);
    bmap_free(M);
    bmap_free(M0);
    mesh_free(r);

    geo_edges_close(&E);
    free(img);
    free(touched);
    free(badv);
    free(kind);
    free(k2);
    free(tn);
    bmap_free(P);
    bmap_free(before);
    mesh_free(m);
}

/* The icosphere of level 2 onto that of level 5 (each source edge spans
 * eight target edges): a few vertices pushed past a neighbour, their
 * images taken to T's closest points. Each pushed vertex must travel
 * farther than the faces its star lands in and their neighbours to get
 * back among its neighbours; the relaxation looks as far as the
 * neighbours spread, unfolds every face and leaves the other vertices. */
TEST(relaxation_reaches_as_far_as_the_neighbours_spread_on_a_finer_target)
{
    mesh *S = testmesh_icosphere(2), *T = testmesh_icosphere(5);
    int nv = S->nv;
    geo_edges E;
    char err[128];
    CHECK(geo_edges_build(S, &E, err, sizeof err) == 0);
    double *img = malloc(sizeof(double) * 3 * (size_t)nv);
    memcpy(img, S->v, sizeof(double) * 3 * (size_t)nv);
    unsigned char *touched = calloc((size_t)nv, 1);
    int first, nmoved = push_stars(S, &E, 29, 4, img, touched, &first);
    CHECK_INT(nmoved, 4);
    bmap *P = map_of_points(T, img, nv), *before = map_of_points(T, img, nv);
    int bad = count_bad(S, T, P, METRIC_FACE_FLIPPED);
    CHECK(bad >= 2 * nmoved);
    fold_report rep;
    CHECK_INT(fold_relax(S, T, NULL, 0, P, &rep), FOLD_OK);
    printf("  %d stars pushed over onto a target 64 times finer: %d -> %d bad faces, %d moves\n", nmoved,
           rep.bad_before, rep.bad_after, rep.relaxed);
    CHECK_INT(rep.bad_after, 0);
    CHECK_INT(count_bad(S, T, P, METRIC_FACE_FLIPPED) + count_bad(S, T, P, METRIC_FACE_COLLAPSED), 0);
    bmap_apply(P, T->f, T->v, 3, img);
    double worst = 0;
    for (int v = 0; v < nv; v++) {
        if (!touched[v]) {
            CHECK_INT(P->face[v], before->face[v]);
            CHECK(memcmp(P->w + 3 * v, before->w + 3 * v, 3 * sizeof(double)) == 0);
            continue;
        }
        /* a moved vertex lies well inside its neighbours' images: nearer
         * their mean than a third of their spread */
        double c[3] = { 0, 0, 0 }, spread = 0;
        int n = 0;
        for (int i = E.vf_start[v]; i < E.vf_start[v + 1]; i++)
            for (int k = 0; k < 3; k++) {
                int u = S->f[3 * E.vf_face[i] + k];
                for (int d = 0; d < 3 && u != v; d++)
                    c[d] += img[3 * u + d];
                n += u != v;
            }
        for (int d = 0; d < 3; d++)
            c[d] /= n;
        for (int i = E.vf_start[v]; i < E.vf_start[v + 1]; i++)
            for (int k = 0; k < 3; k++)
                spread = fmax(spread, dist3(img + 3 * S->f[3 * E.vf_face[i] + k], c));
        worst = fmax(worst, dist3(img + 3 * v, c) / spread);
    }
    printf("  farthest from its neighbours' mean: %.2f of their spread\n", worst);
    CHECK(worst < 1.0 / 3);
    geo_edges_close(&E);
    free(img);
    free(touched);
    bmap_free(P);
    bmap_free(before);
    mesh_free(S);
    mesh_free(T);
}

/* Signed doubled area of patch face q in the placement uv (loc: the mesh's
 * vertices' places in the patch). */
static double placed_area(const mesh *m, const fold__patch *p, const int *loc, const double *uv, int q)
{
    const int *f = m->f + 3 * p->faces[q];
    const double *a = uv + 2 * loc[f[0]], *b = uv + 2 * loc[f[1]], *c = uv + 2 * loc[f[2]];
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* The end of a tube 25.6 long and 2 wide (the last 60 of 120 rings of 10
 * vertices and its pole: 13 times as deep as its ring's radius, as the
 * glasses' arm ends are) laid in the disk: the harmonic disk map crowds
 * its far rings toward a point; the tube chart (fold__tube_chart) keeps
 * every face the right way round, the rings in order from the circle
 * (ring 60) to the centre (the pole), the last ring far from the centre
 * still. */
TEST(tube_chart_of_a_long_end_is_one_to_one_with_its_rings_in_order)
{
    int rings = 120, around = 10, from = 60;
    mesh *m = testmesh_spheroid(25.6, rings, around);
    int nv = m->nv, pole = nv - 1;
    char err[128];
    geo_edges E;
    CHECK(geo_edges_build(m, &E, err, sizeof err) == 0);
    unsigned char *in = calloc((size_t)m->nf, 1);
    int *loc = malloc(sizeof(int) * (size_t)nv);
    for (int v = 0; v < nv; v++)
        loc[v] = -1;
    for (int t = 0; t < m->nf; t++) {
        in[t] = 1;
        for (int k = 0; k < 3; k++) {
            int v = m->f[3 * t + k];
            in[t] &= v == pole || (v < rings * around && v / around >= from);
        }
    }
    fold__patch p;
    CHECK_INT(fold__disk(m, &E, in, loc, &p), 0);
    CHECK_INT(p.nb, around);
    double *depth = malloc(sizeof(double) * (size_t)p.nv), *uv = malloc(sizeof(double) * 2 * (size_t)p.nv);
    CHECK_INT(fold__depth(m, &p, loc, depth), 0);
    CHECK_INT(fold__disk_place(m, &E, &p, loc, uv), 0);
    for (int i = 0; i < p.nv; i++)
        loc[p.verts[i]] = i;
    int folded_disk = 0, last = loc[(rings - 1) * around];
    for (int q = 0; q < p.nf; q++)
        folded_disk += !(placed_area(m, &p, loc, uv, q) > 0);
    double last_disk = hypot(uv[2 * last], uv[2 * last + 1]);
    for (int i = 0; i < p.nv; i++)
        loc[p.verts[i]] = -1;
    double lambda;
    CHECK_INT(fold__tube_chart(m, &E, &p, loc, depth, uv, &lambda), 0);
    for (int i = 0; i < p.nv; i++)
        loc[p.verts[i]] = i;
    int folded_tube = 0;
    for (int q = 0; q < p.nf; q++)
        folded_tube += !(placed_area(m, &p, loc, uv, q) > 0);
    double last_tube = hypot(uv[2 * last], uv[2 * last + 1]);
    printf("  faces folded: disk map %d, tube chart %d of %d; the last ring's radius: disk map "
           "%.2e, tube chart %.2e (rate %.1f)\n", folded_disk, folded_tube, p.nf, last_disk,
           last_tube, lambda);
    CHECK_INT(folded_tube, 0);
    CHECK(last_tube > 100 * last_disk);
    /* the rings' radii fall from 1 at the boundary ring to 0 at the pole */
    double prev = 1 + 1e-12;
    for (int k = from; k < rings; k++) {
        double lo = INFINITY, hi = 0;
        for (int j = 0; j < around; j++) {
            int i = loc[k * around + j];
            double r = hypot(uv[2 * i], uv[2 * i + 1]);
            lo = fmin(lo, r);
            hi = fmax(hi, r);
        }
        CHECK(hi <= prev);
        prev = lo;
    }
    CHECK(hypot(uv[2 * loc[pole]], uv[2 * loc[pole] + 1]) == 0);
    for (int i = 0; i < p.nv; i++)
        loc[p.verts[i]] = -1;
    free(depth);
    free(uv);
    free(in);
    free(loc);
    fold__patch_close(&p);
    geo_edges_close(&E);
    mesh_free(m);
}
