/* test_repair.c — input mesh repair (repair.h, corr_fix_open): a clean
 * mesh comes out as it went in; messy meshes the test makes from a clean
 * one (a pinched vertex, an unwelded seam, a floating piece, a hole,
 * degenerate, duplicate and flipped faces) are repaired, reported, matched
 * against their clean original by the real pipeline with error <= 0.01
 * against the identity, and every input vertex gets a row; with repair off
 * the job is refused as before; pieces the landmarks pair are matched pair
 * by pair; a mesh of about 1600 vertices and its subdivision of about
 * 100 000 match either way with no repair (coarse to fine); a mesh of
 * quads is read and matched from the CLI; `meshcorr info` and `meshcorr
 * fix` show and write the repair. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "support/testrun.h"
#include "corr/corr.h"
#include "geo/geo_area.h"
#include "map/bmap.h"
#include "mesh/mesh_check.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A sphere bent out of its symmetries (642 vertices), the clean original. */
static mesh *clean(void)
{
    mesh *m = testmesh_icosphere(3);
    for (int i = 0; i < m->nv; i++) {
        double *p = m->v + 3 * i;
        double x = p[0], y = p[1];
        p[0] = 1.4 * x;
        p[1] = y + 0.3 * x * x;
        p[2] *= 0.8 + 0.2 * (y + 1);
    }
    return m;
}

/* The clean mesh bent and stretched: the target, identity ground truth. */
static mesh *bent(const mesh *c)
{
    mesh *m = mesh_copy(c);
    for (int i = 0; i < m->nv; i++) {
        double *p = m->v + 3 * i;
        p[1] += 0.1 * sin(p[0]);
        p[2] *= 1 + 0.03 * p[0];
    }
    return m;
}

/* A messy mesh and, per vertex, the clean vertex it is (or is next to). */
typedef struct messy {
    mesh *m;
    int *orig;
    int exact;      /* vertices 0..exact-1 are scored against the identity */
} messy;

static messy grow(const mesh *c, int add_v, int add_f)
{
    messy x;
    x.m = mesh_new(c->nv + add_v, c->nf + add_f);
    x.orig = malloc(sizeof(int) * (size_t)(c->nv + add_v));
    CHECK(x.m && x.orig);
    memcpy(x.m->v, c->v, sizeof(double) * 3 * (size_t)c->nv);
    memcpy(x.m->f, c->f, sizeof(int) * 3 * (size_t)c->nf);
    for (int i = 0; i < c->nv + add_v; i++)
        x.orig[i] = i < c->nv ? i : 0;
    x.exact = c->nv;
    return x;
}

/* A small closed tetrahedron that shares vertex v0 with the surface: v0
 * becomes non-manifold (two fans). */
static messy pinched(const mesh *c)
{
    messy x = grow(c, 3, 4);
    int v0 = 17, n = c->nv;
    const double *p = c->v + 3 * v0;
    double d[3][3] = { { 0.03, 0, 0 }, { 0, 0.03, 0 }, { 0, 0, 0.03 } };
    for (int k = 0; k < 3; k++) {
        for (int j = 0; j < 3; j++)
            x.m->v[3 * (n + k) + j] = p[j] * 1.01 + d[k][j];
        x.orig[n + k] = v0;
    }
    int tf[4][3] = { { v0, n + 1, n }, { v0, n, n + 2 }, { v0, n + 2, n + 1 }, { n, n + 1, n + 2 } };
    memcpy(x.m->f + 3 * c->nf, tf, sizeof tf);
    return x;
}

/* Every vertex duplicated at the end; the faces with x > 0 use the
 * duplicates: a seam all round, and originals only the other side used
 * left in no face. */
static messy seam(const mesh *c)
{
    messy x = grow(c, c->nv, 0);
    memcpy(x.m->v + 3 * c->nv, c->v, sizeof(double) * 3 * (size_t)c->nv);
    for (int i = 0; i < c->nv; i++)
        x.orig[c->nv + i] = i;
    for (int t = 0; t < c->nf; t++) {
        int *f = x.m->f + 3 * t;
        if (c->v[3 * f[0]] + c->v[3 * f[1]] + c->v[3 * f[2]] > 0)
            for (int k = 0; k < 3; k++)
                f[k] += c->nv;
    }
    x.exact = 2 * c->nv;
    return x;
}

/* A small sphere floating beside the surface. */
static messy floating(const mesh *c)
{
    mesh *s = testmesh_icosphere(1);
    messy x = grow(c, s->nv, s->nf);
    for (int i = 0; i < s->nv; i++) {
        for (int j = 0; j < 3; j++)
            x.m->v[3 * (c->nv + i) + j] = 0.2 * s->v[3 * i + j] + (j == 0 ? 2.5 : 0);
    }
    for (int c3 = 0; c3 < 3 * s->nf; c3++)
        x.m->f[3 * c->nf + c3] = s->f[c3] + c->nv;
    mesh_free(s);
    return x;
}

/* The faces around vertex 40 removed: a hole, vertex 40 in no face. */
static messy holed(const mesh *c)
{
    messy x = grow(c, 0, 0);
    int n = 0;
    for (int t = 0; t < c->nf; t++) {
        const int *f = c->f + 3 * t;
        if (f[0] == 40 || f[1] == 40 || f[2] == 40)
            continue;
        memcpy(x.m->f + 3 * n++, f, 3 * sizeof(int));
    }
    x.m->nf = n;
    return x;
}

/* Faces repeating a vertex, a zero-area face through an edge's midpoint,
 * five faces twice, three faces turned over. */
static messy dirty_faces(const mesh *c)
{
    messy x = grow(c, 1, 2 + 1 + 5);
    int n = c->nv, nf = c->nf;
    const int *e = c->f;                       /* edge f0-f1 of face 0 */
    for (int j = 0; j < 3; j++)
        x.m->v[3 * n + j] = 0.5 * (c->v[3 * e[0] + j] + c->v[3 * e[1] + j]);
    x.orig[n] = e[0];
    int extra[8][3] = { { 5, 5, 9 }, { 7, 8, 7 }, { e[0], n, e[1] } };
    for (int k = 0; k < 5; k++)
        memcpy(extra[3 + k], c->f + 3 * (10 + 7 * k), 3 * sizeof(int));
    memcpy(x.m->f + 3 * nf, extra, sizeof extra);
    for (int t = 100; t < 103; t++) {
        int *f = x.m->f + 3 * t, s = f[1];
        f[1] = f[2];
        f[2] = s;
    }
    return x;
}

/* The mean distance from each scored vertex's image to its clean vertex,
 * over sqrt(area). */
static double identity_error(const messy *x, const mesh *T, const bmap *P)
{
    double e = 0;
    for (int u = 0; u < x->exact; u++) {
        const int *f = T->f + 3 * P->face[u];
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double p = 0;
            for (int c = 0; c < 3; c++)
                p += P->w[3 * u + c] * T->v[3 * f[c] + k];
            double d = p - T->v[3 * x->orig[u] + k];
            d2 += d * d;
        }
        e += sqrt(d2);
    }
    return e / (x->exact * sqrt(geo_total_area(T)));
}

TEST(a_clean_mesh_comes_out_as_it_went_in)
{
    mesh *c = clean();
    repair_mesh r;
    char err[512];
    CHECK_INT(repair_mesh_run(c, "clean", NULL, &r, err, sizeof err), REPAIR_OK);
    CHECK(!repair_counts_any(&r.n));
    CHECK_INT(r.m->nv, c->nv);
    CHECK_INT(r.m->nf, c->nf);
    CHECK(memcmp(r.m->v, c->v, sizeof(double) * 3 * (size_t)c->nv) == 0);
    CHECK(memcmp(r.m->f, c->f, sizeof(int) * 3 * (size_t)c->nf) == 0);
    for (int i = 0; i < c->nv; i++)
        CHECK(r.row[i] == i && !r.carried[i]);
    repair_mesh_close(&r);
    mesh_free(c);
}

TEST(what_cannot_be_repaired_is_refused_with_the_reason)
{
    mesh *c = clean();
    repair_mesh r;
    char err[512];
    c->v[3 * 5 + 1] = NAN;
    CHECK_INT(repair_mesh_run(c, "m.off", NULL, &r, err, sizeof err), REPAIR_EMESH);
    CHECK_STR_HAS(err, "m.off: vertex 5 has a NaN or infinite coordinate");
    c->v[3 * 5 + 1] = 0;
    c->f[7] = c->nv + 3;
    CHECK_INT(repair_mesh_run(c, "m.off", NULL, &r, err, sizeof err), REPAIR_EMESH);
    CHECK_STR_HAS(err, "m.off: face 2 has vertex index");
    mesh_free(c);
}

/* Each messy mesh: what its repair reports, and that the repaired mesh is
 * one the optimizer takes. */
TEST(each_kind_of_mess_is_repaired_and_counted)
{
    mesh *c = clean();
    messy (*make[5])(const mesh *) = { pinched, seam, floating, holed, dirty_faces };
    for (int k = 0; k < 5; k++) {
        messy x = make[k](c);
        repair_mesh r;
        char err[2048];
        CHECK_INT(repair_mesh_run(x.m, "messy", NULL, &r, err, sizeof err), REPAIR_OK);
        if (corr_validate(r.m, "repaired", err, sizeof err))
            FAILF("case %d: %s", k, err);
        const repair_counts *n = &r.n;
        switch (k) {
        case 0: CHECK(n->split_vertices == 1 && n->pieces == 1 && n->piece_vertices == 3); break;
        case 1: CHECK(n->welded > 0 && n->unreferenced > 0 && n->split_vertices == 0 &&
                      r.m->nv == c->nv); break;
        case 2: CHECK(n->pieces == 1 && n->piece_vertices == 42); break;
        case 3: CHECK(n->unreferenced == 1 && n->pieces == 0 && r.m->nv == c->nv - 1); break;
        case 4:
            CHECK(n->degenerate_faces == 3 && n->duplicate_faces == 5 &&
                      n->flipped_faces == 3 && n->unreferenced == 1); break;
        }
        char text[2048];
        CHECK(repair_counts_text(n, "messy", text, sizeof text) >= 1);
        repair_mesh_close(&r);
        free(x.orig);
        mesh_free(x.m);
    }
    mesh_free(c);
}

/* Two vertices of one piece at the same position (as cow.off's 44 and
 * 2903): the weld makes them one vertex with two fans and the split undoes
 * it; each copy stands for the vertex whose faces it carries, in the
 * vertex map as in the rows. */
TEST(a_pinch_the_weld_made_is_undone_into_the_vertices_given)
{
    mesh *m = clean();
    int a = 17, b = 300;
    memcpy(m->v + 3 * b, m->v + 3 * a, 3 * sizeof(double));
    repair_mesh r;
    char err[2048];
    CHECK_INT(repair_mesh_run(m, "pinch", NULL, &r, err, sizeof err), REPAIR_OK);
    CHECK_INT(r.n.split_vertices, 1);
    CHECK_INT(r.n.welded, 0);
    CHECK_INT(r.m->nv, m->nv);
    CHECK(r.row[a] != r.row[b]);
    CHECK_INT(r.vert[r.row[a]], a);
    CHECK_INT(r.vert[r.row[b]], b);
    for (int t = 0; t < r.m->nf; t++)   /* every corner stands for its own face's vertex */
        for (int k = 0; k < 3; k++)
            CHECK_INT(r.vert[r.m->f[3 * t + k]], m->f[3 * r.face[t] + r.corner[3 * t + k]]);
    repair_mesh_close(&r);
    mesh_free(m);
}

/* The job as the engine runs it: repaired, matched, back in the messy
 * mesh's indexing. */
static void match(const messy *x, const mesh *c, int *lm, int nl)
{
    mesh *T = bent(c);
    lmk_set L = { nl, lm, lm + nl };
    corr_input user = { x->m, T, "messy", "clean", &L, NULL, NULL, NULL, CORR_CHAIN_ALL, 0,
                        CORR_DDM_AUTO };
    corr_fix fx;
    corr_input in;
    char err[4096];
    if (corr_fix_open(&user, 1, &fx, &in, err, sizeof err))
        FAILF("%s", err);
    CHECK(fx.repaired);
    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 40;
    ectm_result res, back;
    if (corr_run(&in, &p, NULL, NULL, &res, err, sizeof err))
        FAILF("corr_run: %s", err);
    if (corr_fix_to_user(&fx, &res, &back, err, sizeof err))
        FAILF("%s", err);
    CHECK_INT(back.P->n, x->m->nv);                  /* every input vertex has a row */
    CHECK_INT(back.Q->n, T->nv);
    for (int u = 0; u < back.P->n; u++)
        CHECK(back.P->face[u] >= 0 && back.P->face[u] < T->nf);
    double e = identity_error(x, T, back.P);
    printf("  identity error %.5f\n", e);
    CHECK(e <= 0.01);
    ectm_result_close(&res);
    ectm_result_close(&back);
    corr_fix_close(&fx);
    mesh_free(T);
}

TEST_T(messy_meshes_match_their_clean_original, 600)
{
    mesh *c = clean();
    int lm[16] = { 0, 100, 200, 300, 400, 500, 600, 640 };
    memcpy(lm + 8, lm, 8 * sizeof(int));
    messy (*make[5])(const mesh *) = { pinched, seam, floating, holed, dirty_faces };
    const char *names[5] = { "pinched vertex", "unwelded seam", "floating piece", "hole",
                             "degenerate, duplicate and flipped faces" };
    for (int k = 0; k < 5; k++) {
        printf("  %s:\n", names[k]);
        messy x = make[k](c);
        match(&x, c, lm, 8);
        free(x.orig);
        mesh_free(x.m);
    }
    mesh_free(c);
}

TEST(repair_off_refuses_as_before)
{
    mesh *c = clean();
    messy x = pinched(c);
    int lm[16] = { 0, 100, 200, 300, 400, 500, 600, 640 };
    memcpy(lm + 8, lm, 8 * sizeof(int));
    lmk_set L = { 8, lm, lm + 8 };
    corr_input user = { x.m, c, "messy.off", "clean", &L, NULL, NULL, NULL, CORR_CHAIN_ALL, 0,
                        CORR_DDM_AUTO };
    corr_fix fx;
    corr_input in;
    char err[4096];
    CHECK_INT(corr_fix_open(&user, 0, &fx, &in, err, sizeof err), KIND_EMESH);
    CHECK_STR_HAS(err, "messy.off is not usable by the optimizer");
    CHECK_STR_HAS(err, "non-manifold vertices");
    free(x.orig);
    mesh_free(x.m);
    mesh_free(c);
}


/* Different resolutions need no repair: coarse to fine matches a mesh of
 * about 1600 vertices and a bent copy of it subdivided three times (about
 * 100 000, so the chain runs on its decimated copy), either one the
 * source. The subdivision keeps the coarse vertices as its first ones, so
 * the identity of those is the ground truth both ways: the coarse mesh's
 * vertices onto the fine one's, and the fine mesh's first vertices back
 * onto the coarse one's. */
TEST_T(a_coarse_mesh_and_its_fine_subdivision_match_through_coarse_to_fine, 900)
{
    mesh *c = testmesh_spheroid(2.5, 38, 42);
    mesh *f1 = testmesh_subdivided(c), *f2 = testmesh_subdivided(f1), *f = testmesh_subdivided(f2);
    mesh_free(f1);
    mesh_free(f2);
    CHECK(c && f);
    for (int i = 0; i < f->nv; i++) {
        double *p = f->v + 3 * i;
        p[0] += 0.15 * sin(p[2]);
    }
    CHECK(c->nv < 2000 && f->nv > 100000);
    int lm[16];
    for (int k = 0; k < 8; k++)
        lm[k] = lm[8 + k] = (int)((long)k * (c->nv - 1) / 7);
    lmk_set L = { 8, lm, lm + 8 };
    int *orig = malloc(sizeof(int) * (size_t)c->nv);
    for (int i = 0; i < c->nv; i++)
        orig[i] = i;
    messy there = { c, orig, c->nv }, back = { f, orig, c->nv };
    for (int fine_first = 0; fine_first < 2; fine_first++) {
        corr_input in = { fine_first ? f : c, fine_first ? c : f, fine_first ? "fine" : "coarse",
                          fine_first ? "coarse" : "fine", &L, NULL, NULL, NULL, CORR_CHAIN_ALL, 0,
                          CORR_DDM_AUTO };
        CHECK(corr_coarse_wanted(&in));
        ectm_params p;
        ectm_params_init(&p);
        p.iterations = 40;
        ectm_result res;
        char err[2048];
        if (corr_run(&in, &p, NULL, NULL, &res, err, sizeof err))
            FAILF("corr_run: %s", err);
        const bmap *to_fine = fine_first ? res.Q : res.P, *to_coarse = fine_first ? res.P : res.Q;
        CHECK(to_fine && to_fine->n == c->nv && to_coarse && to_coarse->n == f->nv);
        double e = identity_error(&there, f, to_fine), eb = identity_error(&back, c, to_coarse);
        printf("  %d vertices onto %d: identity error %.5f, back %.5f\n", in.S->nv, in.T->nv, e, eb);
        CHECK(e <= 0.01);
        CHECK(eb <= 0.01);
        ectm_result_close(&res);
    }
    free(orig);
    mesh_free(c);
    mesh_free(f);
}

/* `meshcorr info` says what the repair would do; `meshcorr fix` writes a
 * mesh the optimizer takes, with the vertex map back to the input. */
TEST(info_and_fix_show_and_write_the_repair)
{
    mesh *c = clean();
    messy x = seam(c);
    char in[600], fixed[600], vm[600], err[512], out[8192];
    snprintf(in, sizeof in, "%s/seam.off", harness_tmpdir());
    snprintf(fixed, sizeof fixed, "%s/fixed.ply", harness_tmpdir());
    snprintf(vm, sizeof vm, "%s/fixed.vmap", harness_tmpdir());
    CHECK_INT(mesh_write(in, x.m, err, sizeof err), 0);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr info %s 2>&1", in), 1);
    CHECK_STR_HAS(out, "the optimizer cannot use this mesh as given");
    CHECK_STR_HAS(out, "a job repairs it");
    CHECK_STR_HAS(out, "vertices welded to another at the same position");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr fix %s %s --vertex-map %s 2>&1", in, fixed, vm),
              0);
    CHECK_STR_HAS(out, "seam.off: repaired:");
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr info %s 2>&1", fixed), 0);
    mesh *r = NULL;
    CHECK_INT(mesh_read(fixed, &r, err, sizeof err), 0);
    CHECK_INT(r->nv, c->nv);
    FILE *fp = fopen(vm, "r");
    CHECK(fp);
    int v, n = 0;
    while (fscanf(fp, "%d", &v) == 1) {      /* each output vertex sits where its input vertex does */
        CHECK(v >= 0 && v < x.m->nv);
        CHECK(memcmp(r->v + 3 * n, x.m->v + 3 * v, 3 * sizeof(double)) == 0);
        n++;
    }
    fclose(fp);
    CHECK_INT(n, r->nv);
    /* nothing to repair: written as it is */
    snprintf(in, sizeof in, "%s/clean.off", harness_tmpdir());
    CHECK_INT(mesh_write(in, c, err, sizeof err), 0);
    CHECK_INT(testrunf(out, sizeof out, "build/meshcorr fix %s %s 2>&1", in, fixed), 0);
    CHECK_STR_HAS(out, "nothing to repair");
    mesh_free(r);
    free(x.orig);
    mesh_free(x.m);
    mesh_free(c);
}

/* The clean mesh written as a file of quads: each triangle paired with an
 * unpaired neighbour across an edge becomes one quad, the rest stay
 * triangles. Returns the number of quads. */
static int write_quads(const mesh *c, const char *path)
{
    int *mate = malloc(sizeof(int) * (size_t)c->nf), nq = 0;
    for (int t = 0; t < c->nf; t++)
        mate[t] = -1;
    for (int t = 0; t < c->nf; t++)
        for (int u = t + 1; u < c->nf && mate[t] < 0; u++) {
            int shared = 0;
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    shared += c->f[3 * t + i] == c->f[3 * u + j];
            if (shared == 2 && mate[u] < 0) {
                mate[t] = u;
                mate[u] = t;
                nq++;
            }
        }
    FILE *fp = fopen(path, "w");
    fprintf(fp, "OFF\n%d %d 0\n", c->nv, c->nf - nq);
    for (int v = 0; v < c->nv; v++)
        fprintf(fp, "%.17g %.17g %.17g\n", c->v[3 * v], c->v[3 * v + 1], c->v[3 * v + 2]);
    for (int t = 0; t < c->nf; t++) {
        const int *a = c->f + 3 * t;
        if (mate[t] < 0) {
            fprintf(fp, "3 %d %d %d\n", a[0], a[1], a[2]);
            continue;
        }
        if (mate[t] < t)
            continue;
        const int *b = c->f + 3 * mate[t];
        for (int i = 0; i < 3; i++) {       /* a's edge (a[i], a[i+1]) is b's: b's third corner between */
            int p = a[i], q = a[(i + 1) % 3], far = -1;
            for (int j = 0; j < 3; j++)
                if (b[j] != p && b[j] != q)
                    far = b[j];
            int on = 0;
            for (int j = 0; j < 3; j++)
                on += b[j] == p || b[j] == q;
            if (on == 2) {
                fprintf(fp, "4 %d %d %d %d\n", p, far, q, a[(i + 2) % 3]);
                break;
            }
        }
    }
    fclose(fp);
    free(mate);
    return nq;
}

TEST_T(a_mesh_of_quads_matches_its_clean_original_from_the_cli, 600)
{
    mesh *c = clean(), *T = bent(c);
    char src[600], tgt[600], lmk[600], out[600], text[8192], err[512];
    snprintf(src, sizeof src, "%s/quads.off", harness_tmpdir());
    snprintf(tgt, sizeof tgt, "%s/bent.off", harness_tmpdir());
    snprintf(lmk, sizeof lmk, "%s/quads.lmk", harness_tmpdir());
    snprintf(out, sizeof out, "%s/quads.map", harness_tmpdir());
    int nq = write_quads(c, src);
    CHECK(nq > c->nf / 3);
    CHECK_INT(mesh_write(tgt, T, err, sizeof err), 0);
    FILE *fp = fopen(lmk, "w");
    for (int v = 0; v < 640; v += 80)
        fprintf(fp, "%d %d\n", v, v);
    fclose(fp);
    char want[128];
    snprintf(want, sizeof want, "faces           %d triangles (the file's %d polygons split", c->nf, nq);
    CHECK_INT(testrunf(text, sizeof text, "build/meshcorr info %s 2>&1", src), 0);
    CHECK_STR_HAS(text, want);
    char fixed[600];
    snprintf(fixed, sizeof fixed, "%s/quads-fixed.off", harness_tmpdir());
    CHECK_INT(testrunf(text, sizeof text, "build/meshcorr fix %s %s 2>&1", src, fixed), 0);
    snprintf(want, sizeof want, "nothing to repair; its %d polygons written as triangles", nq);
    CHECK_STR_HAS(text, want);
    CHECK_INT(testrunf(text, sizeof text,
                       "build/meshcorr match %s %s --landmarks %s --out %s --iterations 40 "
                       "--progress none 2>&1", src, tgt, lmk, out), 0);
    snprintf(want, sizeof want, "quads.off: %d polygons split into triangles; the faces a map names", nq);
    CHECK_STR_HAS(text, want);
    mesh *q = NULL;
    bmap *P = NULL;
    CHECK_INT(mesh_read(src, &q, err, sizeof err), 0);
    CHECK_INT(bmap_read(out, q, T, &P, err, sizeof err), 0);
    CHECK_INT(P->n, c->nv);
    messy x = { q, malloc(sizeof(int) * (size_t)c->nv), c->nv };
    for (int v = 0; v < c->nv; v++)
        x.orig[v] = v;
    double e = identity_error(&x, T, P);
    printf("  %d quads; identity error %.5f\n", nq, e);
    CHECK(e <= 0.01);
    free(x.orig);
    bmap_free(P);
    mesh_free(q);
    mesh_free(T);
    mesh_free(c);
}

/* Two shapes side by side: the bent sphere and a small sphere beside it. */
static mesh *two_pieces(void)
{
    mesh *a = clean(), *b = testmesh_icosphere(2);
    mesh *m = mesh_new(a->nv + b->nv, a->nf + b->nf);
    CHECK(m != NULL);
    memcpy(m->v, a->v, sizeof(double) * 3 * (size_t)a->nv);
    memcpy(m->f, a->f, sizeof(int) * 3 * (size_t)a->nf);
    for (int i = 0; i < b->nv; i++) {
        m->v[3 * (a->nv + i)] = 0.6 * b->v[3 * i] * 1.2 + 3;
        m->v[3 * (a->nv + i) + 1] = 0.6 * b->v[3 * i + 1];
        m->v[3 * (a->nv + i) + 2] = 0.6 * b->v[3 * i + 2] * (1 + 0.3 * b->v[3 * i]);
    }
    for (int c = 0; c < 3 * b->nf; c++)
        m->f[3 * a->nf + c] = b->f[c] + a->nv;
    mesh_free(a);
    mesh_free(b);
    return m;
}

/* Landmarks on both pieces pair them: each pair is matched on its own and
 * every vertex of both lands near its own; with landmarks on the large
 * piece only, the small one is left out and carried by the nearest point.
 * RHM's maps kept beside ECTM's are joined and carried back the same way. */
TEST_T(pieces_the_landmarks_pair_are_matched_piece_by_piece, 600)
{
    mesh *c = two_pieces();
    mesh *T = bent(c);
    int big = 642, lm[12] = { 0, 100, 200, 300, 400, 500, 600, 640, big + 0, big + 40, big + 90,
                              big + 150 };
    for (int round = 0; round < 2; round++) {
        int nl = round == 0 ? 12 : 8;            /* 8: the large piece's only */
        int pairs[24];
        memcpy(pairs, lm, (size_t)nl * sizeof(int));
        memcpy(pairs + nl, lm, (size_t)nl * sizeof(int));
        lmk_set L = { nl, pairs, pairs + nl };
        /* a stray triangle makes the source need repair at all */
        mesh *S = mesh_new(c->nv + 3, c->nf + 1);
        memcpy(S->v, c->v, sizeof(double) * 3 * (size_t)c->nv);
        memcpy(S->f, c->f, sizeof(int) * 3 * (size_t)c->nf);
        double tri[9] = { 0, 5, 0, 0.1, 5, 0, 0, 5.1, 0 };
        memcpy(S->v + 3 * c->nv, tri, sizeof tri);
        int tf[3] = { c->nv, c->nv + 1, c->nv + 2 };
        memcpy(S->f + 3 * c->nf, tf, sizeof tf);
        corr_input user = { S, T, "two", "bent", &L, NULL, NULL, NULL, CORR_CHAIN_ALL, 0,
                            CORR_DDM_AUTO }, in;
        corr_fix fx;
        char err[4096];
        if (corr_fix_open(&user, 1, &fx, &in, err, sizeof err))
            FAILF("%s", err);
        ectm_params p;
        ectm_params_init(&p);
        p.iterations = 40;
        ectm_result res, back;
        if (corr_run(&in, &p, NULL, NULL, &res, err, sizeof err))
            FAILF("corr_run: %s", err);
        if (corr_fix_to_user(&fx, &res, &back, err, sizeof err))
            FAILF("%s", err);
        CHECK_INT(back.P->n, S->nv);
        if (round == 0) {
            /* RHM's maps, joined from the pairs and carried back as the
             * final ones: stages rhm's maps of the same job */
            in.stages = CORR_CHAIN_RHM;
            ectm_result rr, rb;
            if (corr_run(&in, &p, NULL, NULL, &rr, err, sizeof err) ||
                corr_fix_to_user(&fx, &rr, &rb, err, sizeof err))
                FAILF("stages rhm: %s", err);
            CHECK(back.rhm_P && back.rhm_Q);
            CHECK(back.rhm_P->n == rb.P->n && back.rhm_Q->n == rb.Q->n);
            CHECK(!memcmp(back.rhm_P->face, rb.P->face, sizeof(int) * (size_t)rb.P->n));
            CHECK(!memcmp(back.rhm_P->w, rb.P->w, sizeof(double) * 3 * (size_t)rb.P->n));
            CHECK(!memcmp(back.rhm_Q->w, rb.Q->w, sizeof(double) * 3 * (size_t)rb.Q->n));
            ectm_result_close(&rr);
            ectm_result_close(&rb);
        }
        int *orig = malloc(sizeof(int) * (size_t)S->nv);
        for (int i = 0; i < S->nv; i++)
            orig[i] = i < c->nv ? i : 0;
        messy whole = { S, orig, c->nv }, large = { S, orig, big };
        double e = identity_error(&whole, T, back.P), el = identity_error(&large, T, back.P);
        printf("  landmarks on %s: pieces left out %d + %d; identity error %.5f (large piece %.5f)\n",
               round == 0 ? "both pieces" : "the large piece", fx.S.n.pieces, fx.T.n.pieces, e, el);
        if (round == 0) {
            CHECK(fx.S.n.pieces == 1 && fx.T.n.pieces == 0);   /* the stray triangle only */
            CHECK(e <= 0.01);
        } else {
            CHECK(fx.S.n.pieces == 2 && fx.T.n.pieces == 1);
            CHECK(el <= 0.01 && e > 0.02);                     /* the small piece carried */
        }
        free(orig);
        ectm_result_close(&res);
        ectm_result_close(&back);
        corr_fix_close(&fx);
        mesh_free(S);
    }
    mesh_free(T);
    mesh_free(c);
}
