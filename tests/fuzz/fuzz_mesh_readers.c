/* fuzz_mesh_readers.c — a bounded, deterministic mutation fuzzer for the
 * OFF, OBJ and PLY readers, the Draco decoder and mesh_check. Seeds are
 * small valid files written from a generated icosphere; each iteration flips,
 * inserts, deletes bytes or truncates, then reads. Passes when nothing
 * crashes (the harness turns a signal into a FAIL) and every refusal comes
 * with an error code and a non-empty message. */
#include "support/harness.h"
#include "support/testfile.h"
#include "support/testmesh.h"
#include "mesh/mesh.h"
#include "mesh/mesh_check.h"
#include "mesh/draco_bridge.h"

#include <stdlib.h>
#include <string.h>

#define FUZZ_ITERATIONS 1500

static unsigned rnd(unsigned long long *st, unsigned n)
{
    return (unsigned)(testmesh_rand(st) * n);
}

/* One mutation of b (len bytes, room for cap) in place; returns new length. */
static size_t mutate(unsigned char *b, size_t len, size_t cap, unsigned long long *st)
{
    static const char *tokens[] = { "-1", "nan", "1e308", "4294967296", "\n", " ", "/", "//",
                                    "f ", "v ", "999999999", "list", "3", "0", "4", "7 ",
                                    "65537" };
    int edits = 1 + (int)rnd(st, 4);
    for (int e = 0; e < edits && len > 0; e++) {
        size_t at = rnd(st, (unsigned)len);
        switch (rnd(st, 5)) {
        case 0:
            b[at] ^= (unsigned char)(1u << rnd(st, 8));
            break;
        case 1:
            b[at] = (unsigned char)rnd(st, 256);
            break;
        case 2: {
            const char *t = tokens[rnd(st, sizeof tokens / sizeof tokens[0])];
            size_t n = strlen(t);
            if (len + n <= cap) {
                memmove(b + at + n, b + at, len - at);
                memcpy(b + at, t, n);
                len += n;
            }
            break;
        }
        case 3: {
            size_t n = 1 + rnd(st, 8);
            n = n > len - at ? len - at : n;
            memmove(b + at, b + at + n, len - at - n);
            len -= n;
            break;
        }
        default:
            len = at;
            break;
        }
    }
    return len;
}

/* Reads path; a success must give a checkable mesh, a failure a message. */
static void read_and_check(const char *path)
{
    char err[512] = "";
    mesh *m = NULL;
    int rc = mesh_read(path, &m, err, sizeof err);
    if (rc) {
        CHECK(rc < 0);
        CHECK(m == NULL);
        if (err[0] == '\0')
            FAILF("%s refused with code %d and no message", path, rc);
        return;
    }
    for (int i = 0; i < 3 * m->nf; i++)
        CHECK(m->f[i] >= 0 && m->f[i] < m->nv);
    mesh_check_report r;
    CHECK_INT(mesh_check_run(m, &r, err, sizeof err), 0);
    char lines[4096];
    mesh_check_problems(&r, path, lines, sizeof lines);
    mesh_free(m);
}

static void fuzz_format(const char *ext, unsigned long long seed)
{
    mesh *m = testmesh_icosphere(0);
    char err[512], path[512], name[64];
    snprintf(path, sizeof path, "%s/seed.%s", harness_tmpdir(), ext);
    CHECK_INT(mesh_write(path, m, err, sizeof err), 0);
    size_t len;
    unsigned char *seed_bytes = testfile_read(path, &len);
    size_t cap = len + 256;
    unsigned char *b = malloc(cap);
    CHECK(b);
    snprintf(name, sizeof name, "mut.%s", ext);
    unsigned long long st = seed;
    for (int it = 0; it < FUZZ_ITERATIONS; it++) {
        memcpy(b, seed_bytes, len);
        size_t n = mutate(b, len, cap, &st);
        read_and_check(testfile_write(name, b, n));
    }
    free(b);
    free(seed_bytes);
    mesh_free(m);
}

TEST_T(fuzz_off_reader, 60) { fuzz_format("off", 11); }
TEST_T(fuzz_obj_reader, 60) { fuzz_format("obj", 12); }
TEST_T(fuzz_ply_reader, 60) { fuzz_format("ply", 13); }

TEST_T(fuzz_ascii_ply_reader, 60)
{
    char ascii[2048];
    mesh *m = testmesh_icosphere(0);
    int at = snprintf(ascii, sizeof ascii,
                      "ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\n"
                      "property float y\nproperty float z\nelement face %d\n"
                      "property list uchar int vertex_indices\nend_header\n", m->nv, m->nf);
    for (int i = 0; i < m->nv; i++)
        at += snprintf(ascii + at, sizeof ascii - (size_t)at, "%.4f %.4f %.4f\n",
                       m->v[3 * i], m->v[3 * i + 1], m->v[3 * i + 2]);
    for (int i = 0; i < m->nf; i++)
        at += snprintf(ascii + at, sizeof ascii - (size_t)at, "3 %d %d %d\n",
                       m->f[3 * i], m->f[3 * i + 1], m->f[3 * i + 2]);
    CHECK(at < (int)sizeof ascii);
    unsigned char b[2048 + 256];
    unsigned long long st = 14;
    for (int it = 0; it < FUZZ_ITERATIONS; it++) {
        memcpy(b, ascii, (size_t)at);
        size_t n = mutate(b, (size_t)at, sizeof b, &st);
        read_and_check(testfile_write("mut.ply", b, n));
    }
    mesh_free(m);
}

TEST_T(fuzz_draco_decoder, 60)
{
    mesh *m = testmesh_icosphere(1);
    unsigned char *seed = NULL;
    size_t len = 0;
    char err[512];
    CHECK_INT(dracob_encode(m->v, m->nv, m->f, m->nf, 16, &seed, &len, err, sizeof err), 0);
    size_t cap = len + 256;
    unsigned char *b = malloc(cap);
    CHECK(b);
    unsigned long long st = 15;
    int decoded = 0;
    for (int it = 0; it < 4 * FUZZ_ITERATIONS; it++) {
        memcpy(b, seed, len);
        size_t n = mutate(b, len, cap, &st);
        double *v = NULL;
        int *f = NULL, nv = 0, nf = 0;
        err[0] = '\0';
        int rc = dracob_decode(b, n, MESH_MAX_VERTICES, MESH_MAX_FACES, &v, &nv, &f, &nf,
                               err, sizeof err);
        if (rc) {
            CHECK(rc < 0);
            if (err[0] == '\0')
                FAILF("Draco buffer of %zu bytes refused with code %d and no message", n, rc);
            CHECK(v == NULL && f == NULL);
            continue;
        }
        decoded++;
        for (int i = 0; i < 3 * nf; i++)
            CHECK(f[i] >= 0 && f[i] < nv);
        mesh dm = { nv, nf, v, f, 0 };
        mesh_check_report r;
        CHECK_INT(mesh_check_run(&dm, &r, err, sizeof err), 0);
        free(v);
        free(f);
    }
    printf("  %d of %d mutated Draco buffers decoded\n", decoded, 4 * FUZZ_ITERATIONS);
    free(b);
    free(seed);
    mesh_free(m);
}
