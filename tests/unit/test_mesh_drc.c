/* test_mesh_drc.c — Draco: the vertex order survives our encoder (proved
 * vertex by vertex on real meshes), the OFF->OBJ->PLY->DRC->OFF chain, and
 * malformed buffers (truncated, random bytes) give errors, never crashes. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testmesh.h"
#include "mesh/mesh.h"
#include "mesh/draco_bridge.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Largest bounding-box side: the quantization error scale. */
static double bbox_size(const mesh *m)
{
    double s = 0;
    for (int k = 0; k < 3; k++) {
        double lo = m->v[k], hi = m->v[k];
        for (int i = 1; i < m->nv; i++) {
            lo = m->v[3 * i + k] < lo ? m->v[3 * i + k] : lo;
            hi = m->v[3 * i + k] > hi ? m->v[3 * i + k] : hi;
        }
        s = hi - lo > s ? hi - lo : s;
    }
    return s;
}

/* Every decoded vertex is within quantization of the original vertex at the
 * SAME index, faces identical: the order is the original one. */
static void check_same_order(const mesh *a, const mesh *b)
{
    CHECK_INT(b->nv, a->nv);
    CHECK_INT(b->nf, a->nf);
    CHECK(memcmp(a->f, b->f, sizeof(int) * 3 * a->nf) == 0);
    double tol = bbox_size(a) / (1 << MESH_DRC_QUANTIZATION_BITS);
    for (int i = 0; i < a->nv; i++)
        for (int k = 0; k < 3; k++)
            if (!(fabs(a->v[3 * i + k] - b->v[3 * i + k]) <= tol))
                FAILF("vertex %d coordinate %d: %.9g decoded as %.9g (tolerance %.3g)",
                      i, k, a->v[3 * i + k], b->v[3 * i + k], tol);
}

static void chain_round_trip(const char *rel)
{
    char err[512], p[4][512];
    const char *ext[4] = { "obj", "ply", "drc", "off" };
    mesh *orig = NULL, *m = NULL;
    CHECK_INT(mesh_read(harness_data_path(rel), &orig, err, sizeof err), 0);
    m = orig;
    for (int s = 0; s < 4; s++) {
        snprintf(p[s], sizeof p[s], "%s/chain.%s", harness_tmpdir(), ext[s]);
        mesh *next = NULL;
        CHECK_INT(mesh_write(p[s], m, err, sizeof err), 0);
        CHECK_INT(mesh_read(p[s], &next, err, sizeof err), 0);
        if (s < 2) {  /* text and PLY double: exact */
            CHECK(memcmp(orig->v, next->v, sizeof(double) * 3 * orig->nv) == 0);
            CHECK(memcmp(orig->f, next->f, sizeof(int) * 3 * orig->nf) == 0);
        }
        if (m != orig)
            mesh_free(m);
        m = next;
    }
    check_same_order(orig, m);
    mesh_free(orig);
    mesh_free(m);
}

TEST(drc_chain_keeps_order_on_shrec_381)
{
    chain_round_trip("shrec07_bim/Meshes/381.off");
}

TEST(drc_chain_keeps_order_on_faust)
{
    chain_round_trip("faust_r/vtx_5k/tr_reg_000.off");
}

TEST(drc_keeps_unreferenced_vertices_and_order_of_generated_torus)
{
    mesh *t = testmesh_torus(2.0, 0.5, 24, 12);
    /* Add an unreferenced vertex at the end and reverse the vertex order so
     * that any reordering by Draco would show. */
    mesh *m = mesh_new(t->nv + 1, t->nf);
    for (int i = 0; i < t->nv; i++)
        memcpy(m->v + 3 * (t->nv - 1 - i), t->v + 3 * i, 3 * sizeof(double));
    for (int j = 0; j < 3 * t->nf; j++)
        m->f[j] = t->nv - 1 - t->f[j];
    m->v[3 * t->nv] = 9;
    unsigned char *buf = NULL;
    size_t len = 0;
    char err[512];
    CHECK_INT(dracob_encode(m->v, m->nv, m->f, m->nf, 16, &buf, &len, err, sizeof err), 0);
    double *v = NULL;
    int *f = NULL, nv = 0, nf = 0;
    CHECK_INT(dracob_decode(buf, len, MESH_MAX_VERTICES, MESH_MAX_FACES, &v, &nv, &f, &nf,
                            err, sizeof err), 0);
    mesh got = { nv, nf, v, f };
    check_same_order(m, &got);
    CHECK_NEAR(v[3 * t->nv], 9.0, 1e-3);
    free(v);
    free(f);
    free(buf);
    mesh_free(m);
    mesh_free(t);
}

TEST(drc_decode_refuses_counts_over_caller_limits)
{
    mesh *m = testmesh_icosphere(2);
    unsigned char *buf = NULL;
    size_t len = 0;
    char err[512];
    CHECK_INT(dracob_encode(m->v, m->nv, m->f, m->nf, 16, &buf, &len, err, sizeof err), 0);
    double *v = NULL;
    int *f = NULL, nv = 0, nf = 0;
    CHECK_INT(dracob_decode(buf, len, m->nv - 1, MESH_MAX_FACES, &v, &nv, &f, &nf, err, sizeof err),
              DRACOB_ELIMIT);
    CHECK_STR_HAS(err, "over the limit");
    CHECK(v == NULL && f == NULL);
    CHECK_INT(dracob_encode(m->v, m->nv, (const int[]){ 0, 1, 99999 }, 1, 16, &buf, &len,
                            err, sizeof err), DRACOB_EARG);
    CHECK_STR_HAS(err, "out of range");
    free(buf);
    mesh_free(m);
}

TEST(drc_truncated_buffers_are_refused_with_a_message)
{
    mesh *m = testmesh_icosphere(3);
    unsigned char *buf = NULL;
    size_t len = 0;
    char err[512];
    CHECK_INT(dracob_encode(m->v, m->nv, m->f, m->nf, 16, &buf, &len, err, sizeof err), 0);
    size_t cuts[] = { 0, 1, 5, 10, 20, 40, 61, len / 4, len / 2, len - 100, len - 1 };
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        double *v = NULL;
        int *f = NULL, nv = 0, nf = 0;
        err[0] = '\0';
        int rc = dracob_decode(buf, cuts[i], MESH_MAX_VERTICES, MESH_MAX_FACES, &v, &nv, &f, &nf,
                               err, sizeof err);
        if (rc == 0)
            FAILF("a buffer cut to %zu of %zu bytes decoded", cuts[i], len);
        CHECK(err[0] != '\0');
        CHECK(v == NULL && f == NULL);
    }
    /* Through the file reader: the message names the file. */
    mesh *r = NULL;
    CHECK_INT(mesh_read(testfile_write("half.drc", buf, len / 2), &r, err, sizeof err), MESH_EDRACO);
    CHECK_STR_HAS(err, "half.drc");
    free(buf);
    mesh_free(m);
}

TEST_T(drc_random_61_byte_buffers_never_crash, 60)
{
    unsigned long long st = 0x5eed;
    unsigned char b[61];
    int refused = 0;
    for (int it = 0; it < 3000; it++) {
        for (int i = 0; i < 61; i++)
            b[i] = (unsigned char)(testmesh_rand(&st) * 256);
        if (it % 2)  /* half of them with a valid magic and version */
            memcpy(b, "DRACO\x02\x02\x01\x01", 9);
        double *v = NULL;
        int *f = NULL, nv = 0, nf = 0;
        char err[512] = "";
        int rc = dracob_decode(b, sizeof b, MESH_MAX_VERTICES, MESH_MAX_FACES, &v, &nv, &f, &nf,
                               err, sizeof err);
        if (rc) {
            refused++;
            CHECK(err[0] != '\0');
        }
        free(v);
        free(f);
    }
    CHECK(refused > 2900);
}

TEST(drc_quantized_encoding_refuses_a_nan_naming_the_vertex_and_coordinate)
{
    mesh *m = testmesh_icosphere(1);
    m->v[3 * 7 + 2] = NAN;
    unsigned char *buf = NULL;
    size_t len = 0;
    char err[512] = "";
    CHECK_INT(dracob_encode(m->v, m->nv, m->f, m->nf, 16, &buf, &len, err, sizeof err), DRACOB_EARG);
    CHECK(buf == NULL);
    CHECK_STR_HAS(err, "vertex 7: z coordinate is NaN");
    m->v[3 * 7 + 2] = 0;
    m->v[3 * 3] = INFINITY;
    CHECK_INT(dracob_encode(m->v, m->nv, m->f, m->nf, 16, &buf, &len, err, sizeof err), DRACOB_EARG);
    CHECK_STR_HAS(err, "vertex 3: x coordinate is infinite");
    mesh_free(m);
}

TEST(drc_unquantized_encoding_keeps_float32_positions_nan_included)
{
    mesh *m = testmesh_icosphere(1);
    m->v[4] = NAN;
    unsigned char *buf = NULL;
    size_t len = 0;
    char err[512];
    CHECK_INT(dracob_encode(m->v, m->nv, m->f, m->nf, 0, &buf, &len, err, sizeof err), 0);
    double *v = NULL;
    int *f = NULL, nv = 0, nf = 0;
    CHECK_INT(dracob_decode(buf, len, MESH_MAX_VERTICES, MESH_MAX_FACES, &v, &nv, &f, &nf,
                            err, sizeof err), 0);
    CHECK_INT(nv, m->nv);
    CHECK(isnan(v[4]));
    for (int i = 0; i < 3 * nv; i++)
        if (i != 4)
            CHECK(v[i] == (double)(float)m->v[i]);
    CHECK_INT(dracob_encode(m->v, m->nv, m->f, m->nf, -1, &buf, &len, err, sizeof err),
              DRACOB_EARG);
    free(v);
    free(f);
    mesh_free(m);
}
