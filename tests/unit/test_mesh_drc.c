/* test_mesh_drc.c — Draco: the vertex order survives our encoder (proved
 * vertex by vertex on real meshes), the OFF->OBJ->PLY->DRC->OFF chain, the
 * lossless coding keeps every double bit for bit, and malformed buffers
 * (truncated, random bytes) give errors, never crashes. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testmesh.h"
#include "mesh/mesh.h"
#include "mesh/draco_bridge.h"

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

/* Every decoded vertex is within quantization to `bits` of the original
 * vertex at the SAME index (the very bits when lossless), faces identical:
 * the order is the original one. */
static void check_same_order(const mesh *a, const mesh *b, int bits)
{
    CHECK_INT(b->nv, a->nv);
    CHECK_INT(b->nf, a->nf);
    CHECK(memcmp(a->f, b->f, sizeof(int) * 3 * a->nf) == 0);
    if (bits == DRACOB_LOSSLESS) {
        for (int i = 0; i < 3 * a->nv; i++)
            if (memcmp(&a->v[i], &b->v[i], sizeof(double)) != 0)
                FAILF("vertex %d coordinate %d: %a decoded as %a", i / 3, i % 3, a->v[i], b->v[i]);
        return;
    }
    double tol = bbox_size(a) / (1 << bits);
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
    check_same_order(orig, m, MESH_DRC_QUANTIZATION_BITS);
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
    mesh got = { nv, nf, v, f, 0 };
    check_same_order(m, &got, 16);
    CHECK_NEAR(v[3 * t->nv], 9.0, 1e-3);
    free(v);
    free(f);
    free(buf);
    /* and lossless: the same, every bit kept */
    CHECK_INT(dracob_encode(m->v, m->nv, m->f, m->nf, DRACOB_LOSSLESS, &buf, &len, err, sizeof err), 0);
    CHECK_INT(dracob_decode(buf, len, MESH_MAX_VERTICES, MESH_MAX_FACES, &v, &nv, &f, &nf,
                            err, sizeof err), 0);
    got = (mesh){ nv, nf, v, f, 0 };
    check_same_order(m, &got, DRACOB_LOSSLESS);
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

/* Encodes m with bits, decodes, and returns the encoded size; the decoded
 * positions go to *v (malloc()ed). */
static size_t round_trip(const mesh *m, int bits, double **v)
{
    unsigned char *buf = NULL;
    size_t len = 0;
    char err[512];
    if (dracob_encode(m->v, m->nv, m->f, m->nf, bits, &buf, &len, err, sizeof err))
        FAILF("dracob_encode(%d bits): %s", bits, err);
    int *f = NULL, nv = 0, nf = 0;
    if (dracob_decode(buf, len, MESH_MAX_VERTICES, MESH_MAX_FACES, v, &nv, &f, &nf, err, sizeof err))
        FAILF("dracob_decode(%d bits): %s", bits, err);
    CHECK_INT(nv, m->nv);
    CHECK_INT(nf, m->nf);
    CHECK(memcmp(f, m->f, sizeof(int) * 3 * (size_t)nf) == 0);
    free(f);
    free(buf);
    return len;
}

/* Lossless keeps any double bit for bit: random bit patterns (every
 * exponent), NaN, -0, the smallest denormal, the largest finite values. */
TEST(drc_lossless_round_trip_keeps_every_double_bit_for_bit)
{
    mesh *m = testmesh_icosphere(2);
    unsigned long long st = 0xd0b1e;
    for (int i = 0; i < 3 * m->nv; i++) {
        unsigned long long b = 0;
        for (int k = 0; k < 4; k++)
            b = b << 16 | (unsigned long long)(testmesh_rand(&st) * 65536);
        memcpy(&m->v[i], &b, sizeof b);
    }
    m->v[0] = -0.0;
    m->v[1] = 4.9406564584124654e-324;
    m->v[2] = NAN;
    m->v[3] = -1.7976931348623157e308;
    m->v[4] = INFINITY;
    m->v[5] = 0.1;
    double *v = NULL;
    round_trip(m, DRACOB_LOSSLESS, &v);
    for (int i = 0; i < 3 * m->nv; i++)
        if (memcmp(&v[i], &m->v[i], sizeof(double)) != 0)
            FAILF("coordinate %d: %a decoded as %a", i, m->v[i], v[i]);
    free(v);
    mesh_free(m);
}

/* A mesh read from a text file: lossless is exact, float64 storage; a
 * mesh whose coordinates are all floats goes as float32 (smaller, still
 * exact, NaN included); 16 bits is within its step and smaller still.
 * Prints the sizes on the 4344-vertex wolf. */
TEST(drc_lossless_is_exact_on_a_real_mesh_float32_when_it_can_and_16_bits_smaller)
{
    mesh *m = NULL;
    char err[512];
    CHECK_INT(mesh_read(harness_data_path("tosca_hires/Meshes/wolf0.off"), &m, err, sizeof err), 0);
    double *v = NULL;
    size_t lossless = round_trip(m, DRACOB_LOSSLESS, &v);
    mesh got = { m->nv, m->nf, v, m->f, 0 };
    check_same_order(m, &got, DRACOB_LOSSLESS);
    free(v);
    size_t q16 = round_trip(m, 16, &v);
    got.v = v;
    check_same_order(m, &got, 16);
    free(v);
    mesh *g = mesh_copy(m);
    for (int i = 0; i < 3 * g->nv; i++)
        g->v[i] = (float)g->v[i];
    g->v[4] = NAN;
    size_t f32 = round_trip(g, DRACOB_LOSSLESS, &v);
    for (int i = 0; i < 3 * g->nv; i++)
        if (memcmp(&v[i], &g->v[i], sizeof(double)) != 0)
            FAILF("float32 coordinate %d: %a decoded as %a", i, g->v[i], v[i]);
    free(v);
    printf("  wolf0 (%d vertices, %d faces): lossless %zu bytes (float64), float32 %zu, 16 bits %zu "
           "(%.2f x smaller than lossless)\n", m->nv, m->nf, lossless, f32, q16, (double)lossless / (double)q16);
    CHECK(q16 < f32 && f32 < lossless);
    unsigned char *buf = NULL;
    size_t len = 0;
    CHECK_INT(dracob_encode(m->v, m->nv, m->f, m->nf, -1, &buf, &len, err, sizeof err), DRACOB_EARG);
    CHECK_INT(dracob_encode(m->v, m->nv, m->f, m->nf, 31, &buf, &len, err, sizeof err), DRACOB_EARG);
    mesh_free(g);
    mesh_free(m);
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
