/* test_ectm_pins.c — the landmarks ectm_run pins in its P- and Q-steps:
 * after a run, each given source landmark's row of P is its
 * target landmark vertex exactly (weight 1 at that corner of a face at it)
 * and each target landmark's row of Q its source landmark; a bad landmark
 * is refused before anything runs, the field named. On the authors' demo
 * input (SHREC'07 381 -> 390, HOT maps) with the BIM landmarks of those
 * meshes (../shared/data/shrec07_bim/Corrs). */
#include "support/harness.h"
#include "ectm/ectm.h"
#include "lmk/lmk.h"
#include "support/testdemo.h"

#include <stdlib.h>
#include <string.h>

/* The demo's BIM landmarks: *src, *tgt malloc()ed, *n pairs. */
static void demo_landmarks(const testdemo *d, int **src, int **tgt, int *n)
{
    char err[512];
    int nb;
    if (lmk_read_ids(harness_data_path("shrec07_bim/Corrs/381.vts"), 0, d->S->nv, 1000, src, n,
                     err, sizeof err) ||
        lmk_read_ids(harness_data_path("shrec07_bim/Corrs/390.vts"), 0, d->T->nv, 1000, tgt, &nb,
                     err, sizeof err))
        FAILF("%s", err);
    CHECK_INT(nb, *n);
    CHECK(*n >= 10);
}

/* Whether row i of P is exactly the vertex v of the mesh `to`. */
static int row_is_vertex(const bmap *P, const mesh *to, int i, int v)
{
    int f = P->face[i], at = -1;
    for (int c = 0; c < 3; c++)
        if (to->f[3 * f + c] == v)
            at = c;
    if (at < 0)
        return 0;
    for (int c = 0; c < 3; c++)
        if (P->w[3 * i + c] != (c == at ? 1.0 : 0.0))
            return 0;
    return 1;
}

static int count_pinned(const bmap *P, const mesh *to, const int *rows, const int *vtx, int n)
{
    int k = 0;
    for (int j = 0; j < n; j++)
        k += row_is_vertex(P, to, rows[j], vtx[j]);
    return k;
}

TEST_T(landmark_rows_map_exactly_to_their_landmarks, 300)
{
    testdemo d;
    testdemo_load(&d);
    int *ls, *lt, n;
    demo_landmarks(&d, &ls, &lt, &n);
    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 3;
    char err[512];
    /* without pins the projection puts (almost) no landmark on its vertex:
     * the check below can tell pinned from not */
    ectm_result r0;
    if (ectm_run(d.S, d.T, d.P0, d.Q0, NULL, &p, NULL, NULL, &r0, err, sizeof err))
        FAILF("%s", err);
    int free_p = count_pinned(r0.P, d.T, ls, lt, n), free_q = count_pinned(r0.Q, d.S, lt, ls, n);
    printf("  unpinned: %d of %d P rows, %d of %d Q rows on their landmark\n", free_p, n, free_q, n);
    CHECK(free_p < n && free_q < n);
    ectm_result_close(&r0);

    ectm_landmarks L = { ls, lt, n };
    ectm_result r;
    if (ectm_run(d.S, d.T, d.P0, d.Q0, &L, &p, NULL, NULL, &r, err, sizeof err))
        FAILF("%s", err);
    for (int k = 0; k < n; k++) {
        if (!row_is_vertex(r.P, d.T, ls[k], lt[k]))
            FAILF("landmark %d: P row %d is face %d (%g %g %g), not target vertex %d", k, ls[k],
                  r.P->face[ls[k]], r.P->w[3 * ls[k]], r.P->w[3 * ls[k] + 1],
                  r.P->w[3 * ls[k] + 2], lt[k]);
        if (!row_is_vertex(r.Q, d.S, lt[k], ls[k]))
            FAILF("landmark %d: Q row %d is face %d (%g %g %g), not source vertex %d", k, lt[k],
                  r.Q->face[lt[k]], r.Q->w[3 * lt[k]], r.Q->w[3 * lt[k] + 1],
                  r.Q->w[3 * lt[k] + 2], ls[k]);
    }
    /* the pins change the rows they pin, not the shape of the map */
    CHECK_INT(r.P->n, d.S->nv);
    CHECK_INT(r.Q->n, d.T->nv);
    ectm_result_close(&r);

    /* injective: P pinned, no Q */
    p.model = ECTM_INJECTIVE;
    p.iterations = 2;
    if (ectm_run(d.S, d.T, d.P0, NULL, &L, &p, NULL, NULL, &r, err, sizeof err))
        FAILF("%s", err);
    CHECK(r.Q == NULL);
    CHECK_INT(count_pinned(r.P, d.T, ls, lt, n), n);
    ectm_result_close(&r);
    free(ls);
    free(lt);
    testdemo_free(&d);
}

TEST(bad_landmark_is_refused_with_its_field_named)
{
    testdemo d;
    testdemo_load(&d);
    ectm_params p;
    ectm_params_init(&p);
    int src[3] = { 10, 20, 30 }, tgt[3] = { 11, 21, 31 };
    ectm_landmarks L = { src, tgt, 3 };
    ectm_result r;
    char err[512];

    src[2] = d.S->nv;                       /* one past the source's last vertex */
    CHECK_INT(ectm_run(d.S, d.T, d.P0, d.Q0, &L, &p, NULL, NULL, &r, err, sizeof err), KIND_EPARAMS);
    CHECK_STR_HAS(err, "landmarks.src[2] = 6938 out of range [0, 6938)");
    CHECK(r.P == NULL && r.Q == NULL);
    src[2] = 30;

    tgt[1] = -1;
    CHECK_INT(ectm_run(d.S, d.T, d.P0, d.Q0, &L, &p, NULL, NULL, &r, err, sizeof err), KIND_EPARAMS);
    CHECK_STR_HAS(err, "landmarks.tgt[1] = -1 out of range [0, 9239)");
    tgt[1] = d.T->nv;
    CHECK_INT(ectm_run(d.S, d.T, d.P0, d.Q0, &L, &p, NULL, NULL, &r, err, sizeof err), KIND_EPARAMS);
    CHECK_STR_HAS(err, "landmarks.tgt[1] = 9239");
    tgt[1] = 21;

    src[2] = 10;                            /* source vertex 10 pinned twice */
    CHECK_INT(ectm_run(d.S, d.T, d.P0, d.Q0, &L, &p, NULL, NULL, &r, err, sizeof err), KIND_EPARAMS);
    CHECK_STR_HAS(err, "landmarks.src[2] = 10 repeats landmarks.src[0]");
    src[2] = 30;

    L.n = -1;
    CHECK_INT(ectm_run(d.S, d.T, d.P0, d.Q0, &L, &p, NULL, NULL, &r, err, sizeof err), KIND_EPARAMS);
    CHECK_STR_HAS(err, "landmarks.n = -1");
    L.n = 3;
    L.tgt = NULL;
    CHECK_INT(ectm_run(d.S, d.T, d.P0, d.Q0, &L, &p, NULL, NULL, &r, err, sizeof err), KIND_EPARAMS);
    CHECK_STR_HAS(err, "landmarks.tgt is NULL");
    testdemo_free(&d);
}

/* A target vertex given twice (lmk allows it): Q's row goes to the first
 * pair's source vertex; P pins both source vertices onto it. */
TEST_T(target_vertex_given_twice_pins_q_to_the_first_pair, 300)
{
    testdemo d;
    testdemo_load(&d);
    ectm_params p;
    ectm_params_init(&p);
    p.iterations = 1;
    int src[2] = { 100, 200 }, tgt[2] = { 500, 500 };
    ectm_landmarks L = { src, tgt, 2 };
    ectm_result r;
    char err[512];
    if (ectm_run(d.S, d.T, d.P0, d.Q0, &L, &p, NULL, NULL, &r, err, sizeof err))
        FAILF("%s", err);
    CHECK(row_is_vertex(r.P, d.T, 100, 500));
    CHECK(row_is_vertex(r.P, d.T, 200, 500));
    CHECK(row_is_vertex(r.Q, d.S, 500, 100));
    ectm_result_close(&r);
    testdemo_free(&d);
}
