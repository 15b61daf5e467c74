/* test_ctf.c — coarse to fine (ctf.h): decimation keeps the surface's
 * topology, the kept vertices and the input's positions, and makes no
 * face the optimizer refuses; a map carried from the coarse pair lands
 * where the coarse map sends each fine vertex's closest coarse point
 * (its cost against brute force's), and the identity of a coarse sphere carries to
 * nearly the identity of the fine one. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "corr/corr.h"
#include "ctf/ctf.h"
#include "geo/geo_edges.h"
#include "proj/proj.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int euler(const mesh *m)
{
    geo_edges e = {0};
    char err[256];
    CHECK_INT(geo_edges_build(m, &e, err, sizeof err), 0);
    int chi = m->nv - e.ne + m->nf;
    geo_edges_close(&e);
    return chi;
}

/* A sphere of 10242 vertices and a torus to 1500 and 800 vertices, eight
 * vertices kept. */
TEST(decimation_keeps_topology_kept_vertices_and_positions)
{
    mesh *in[2] = { testmesh_icosphere(5), testmesh_torus(1, 0.35, 80, 40) };
    int target[2] = { 1500, 800 };
    for (int k = 0; k < 2; k++) {
        mesh *m = in[k], *c = NULL;
        int keep[8], *fine = NULL;
        for (int r = 0; r < 8; r++)
            keep[r] = (int)((long)r * (m->nv - 1) / 7);
        char err[512];
        CHECK_INT(ctf_decimate(m, target[k], keep, 8, &c, &fine, err, sizeof err), CTF_OK);
        CHECK(c->nv <= target[k] + target[k] / 20);
        CHECK(c->nv >= target[k] / 2);
        CHECK_INT(euler(c), euler(m));
        CHECK_INT(corr_validate(c, "coarse", err, sizeof err), KIND_OK);
        for (int v = 0; v < c->nv; v++) {
            CHECK(fine[v] >= 0 && fine[v] < m->nv);
            CHECK(v == 0 || fine[v] > fine[v - 1]);
            CHECK(memcmp(c->v + 3 * v, m->v + 3 * fine[v], 3 * sizeof(double)) == 0);
        }
        for (int r = 0; r < 8; r++) {
            int found = 0;
            for (int v = 0; v < c->nv; v++)
                found |= fine[v] == keep[r];
            CHECK(found);
        }
        mesh_free(c);
        free(fine);
        mesh_free(m);
    }
}

TEST(decimation_refuses_bad_sizes_and_vertices)
{
    mesh *m = testmesh_icosphere(2), *c = NULL;
    int *fine = NULL, bad = m->nv;
    char err[512];
    CHECK_INT(ctf_decimate(m, m->nv + 1, NULL, 0, &c, &fine, err, sizeof err), CTF_EINPUT);
    CHECK_INT(ctf_decimate(m, 100, &bad, 1, &c, &fine, err, sizeof err), CTF_EINPUT);
    CHECK(strstr(err, "out of range") != NULL);
    CHECK(c == NULL && fine == NULL);
    mesh_free(m);
}

/* The identity of the coarse sphere onto itself, carried to the fine
 * sphere: each carried row is, at brute force's cost, the closest fine
 * point to the coarse image of the fine vertex's closest coarse point;
 * and it lands near the fine vertex itself. */
TEST(carried_map_matches_brute_force_and_stays_near_the_identity)
{
    mesh *S = testmesh_icosphere(4), *Sc = NULL;
    int *fine = NULL;
    char err[512];
    CHECK_INT(ctf_decimate(S, 400, NULL, 0, &Sc, &fine, err, sizeof err), CTF_OK);
    /* Pc: coarse vertex v -> coarse vertex v */
    bmap *Pc = bmap_new(Sc->nv, Sc->nv);
    for (int v = 0; v < Sc->nv; v++) {
        for (int t = 0; t < Sc->nf; t++)
            for (int k = 0; k < 3; k++)
                if (Sc->f[3 * t + k] == v) {
                    Pc->face[v] = t;
                    for (int j = 0; j < 3; j++)
                        Pc->w[3 * v + j] = j == k;
                    goto next;
                }
    next:;
    }
    bmap *P = NULL;
    CHECK_INT(ctf_prolong(Sc, Sc, Pc, S, S, &P, err, sizeof err), CTF_OK);
    CHECK_INT(P->n, S->nv);
    /* brute force: closest coarse point, then the closest fine point */
    int *f1 = malloc(sizeof(int) * (size_t)S->nv), *f2 = malloc(sizeof(int) * (size_t)S->nv);
    double *b1 = malloc(sizeof(double) * 3 * (size_t)S->nv), *b2 = malloc(sizeof(double) * 3 * (size_t)S->nv);
    double *y = malloc(sizeof(double) * 3 * (size_t)S->nv), *c2 = malloc(sizeof(double) * (size_t)S->nv);
    proj_closest_brute(Sc, 3, Sc->v, S->nv, S->v, f1, b1, NULL);
    for (int v = 0; v < S->nv; v++)
        for (int c = 0; c < 3; c++)
            y[3 * v + c] = b1[3 * v] * Sc->v[3 * Sc->f[3 * f1[v]] + c] +
                           b1[3 * v + 1] * Sc->v[3 * Sc->f[3 * f1[v] + 1] + c] +
                           b1[3 * v + 2] * Sc->v[3 * Sc->f[3 * f1[v] + 2] + c];
    proj_closest_brute(S, 3, S->v, S->nv, y, f2, b2, c2);
    double worst = 0, mean = 0;
    for (int v = 0; v < S->nv; v++) {
        double p[3], d2 = 0, e2 = 0;
        for (int c = 0; c < 3; c++) {
            p[c] = 0;
            for (int k = 0; k < 3; k++)
                p[c] += P->w[3 * v + k] * S->v[3 * S->f[3 * P->face[v] + k] + c];
            d2 += (p[c] - y[3 * v + c]) * (p[c] - y[3 * v + c]);
            e2 += (p[c] - S->v[3 * v + c]) * (p[c] - S->v[3 * v + c]);
        }
        CHECK_NEAR(d2, c2[v], 1e-12);   /* the same cost: ties inside a fine
                                            dihedral may pick the other face */
        worst = fmax(worst, sqrt(e2));
        mean += sqrt(e2) / S->nv;
    }
    /* a unit sphere: 400 coarse vertices are about 0.18 apart */
    printf("identity carried: mean %.4f, worst %.4f\n", mean, worst);
    CHECK(mean < 0.01);
    CHECK(worst < 0.05);
    free(f1);
    free(f2);
    free(b1);
    free(b2);
    free(y);
    free(c2);
    bmap_free(P);
    bmap_free(Pc);
    mesh_free(Sc);
    mesh_free(S);
    free(fine);
}
