/* test_chol.c — the CHOLMOD bridge: on a small mesh's cotan Laplacian,
 * each diagonal rule's solve agrees with a dense LAPACK solve of the
 * matrix the rule describes; values rewritten through chol_csc are
 * factorised again; an indefinite matrix is reported as CHOL_ENOTPD, a
 * NUMERIC failure; misuse is refused. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "chol/chol.h"
#include "geo/geo_area.h"
#include "geo/geo_cotan.h"
#include "geo/geo_edges.h"
#include "proto_kind.h"

#include <lapacke.h>
#include <string.h>

typedef struct sys {
    int n;            /* the mesh's vertices, plus one free row when asked */
    geo_csr *L;
    double *mass;
} sys;

static sys laplacian(int level, int extra_row)
{
    char err[256] = "";
    mesh *m = testmesh_icosphere(level);
    geo_edges e = {0};
    sys s = {.n = m->nv + extra_row};
    if (geo_edges_build(m, &e, err, sizeof err) || geo_cotan_laplacian(m, &e, &s.L, err, sizeof err))
        FAILF("Laplacian: %s", err);
    s.mass = calloc((size_t)s.n, sizeof *s.mass);
    geo_vertex_areas(m, s.mass);
    geo_edges_close(&e);
    mesh_free(m);
    return s;
}

static void sys_close(sys *s)
{
    geo_csr_free(s->L);
    free(s->mass);
}

/* a * L's upper triangle as entries of c; dense += the same, both triangles. */
static void add_laplacian(chol *c, const sys *s, double a, double *dense)
{
    for (int i = 0; i < s->L->n; i++)
        for (int p = s->L->row_start[i]; p < s->L->row_start[i + 1]; p++) {
            int j = s->L->col[p];
            dense[(size_t)j * s->n + i] += a * s->L->val[p];
            if (i <= j)
                CHECK_INT(chol_add(c, i, j, a * s->L->val[p]), CHOL_OK);
        }
}

/* Solves with c (factorised) for 3 right-hand sides and with LAPACK's
 * dposv for dense; the largest difference relative to the largest |x|. */
static double against_dense(chol *c, double *dense, int n)
{
    char err[256] = "";
    int ncol = 3;
    double *b = malloc(sizeof(double) * (size_t)n * ncol), *x = malloc(sizeof(double) * (size_t)n * ncol);
    unsigned long long seed = 7;
    for (int k = 0; k < n * ncol; k++)
        b[k] = testmesh_rand(&seed) - 0.5;
    if (chol_solve(c, b, ncol, x, err, sizeof err) != CHOL_OK)
        FAILF("solve: %s", err);
    CHECK_INT(LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', n, ncol, dense, n, b, n), 0);
    double worst = 0, big = 0;
    for (int k = 0; k < n * ncol; k++) {
        worst = fmax(worst, fabs(x[k] - b[k]));
        big = fmax(big, fabs(b[k]));
    }
    free(b);
    free(x);
    return worst / big;
}

static chol *start(const sys *s, enum chol_order order)
{
    char err[256] = "";
    chol *c = NULL;
    if (chol_new(s->n, (size_t)s->L->row_start[s->L->n], order, &c, err, sizeof err) != CHOL_OK)
        FAILF("new: %s", err);
    return c;
}

static void assemble_and_factorise(chol *c, enum chol_diag rule, const double *d)
{
    char err[256] = "";
    if (chol_assemble(c, rule, d, err, sizeof err) != CHOL_OK ||
        chol_factorise(c, err, sizeof err) != CHOL_OK)
        FAILF("%s", err);
}

/* KEEP: the entries carry the diagonal themselves (L + M, the mass added
 * as entries of their own, summed with L's diagonal). */
TEST_T(keep_solves_as_the_entries_say, 20)
{
    sys s = laplacian(2, 0);
    chol *c = start(&s, CHOL_ORDER_CHOLMOD);
    double *dense = calloc((size_t)s.n * s.n, sizeof *dense);
    add_laplacian(c, &s, 1.0, dense);
    for (int i = 0; i < s.n; i++) {
        CHECK_INT(chol_add(c, i, i, s.mass[i]), CHOL_OK);
        dense[(size_t)i * s.n + i] += s.mass[i];
    }
    assemble_and_factorise(c, CHOL_DIAG_KEEP, NULL);
    double rel = against_dense(c, dense, s.n);
    printf("  keep: %d rows, largest difference to LAPACK %.2g\n", s.n, rel);
    CHECK(rel < 1e-10);
    free(dense);
    chol_free(c);
    sys_close(&s);
}

/* SHIFT: t L + diag(d), d the mass (the heat operator's form); entries
 * given below the diagonal land on their mirror. */
TEST_T(shift_adds_d_to_the_diagonal, 20)
{
    sys s = laplacian(2, 0);
    chol *c = start(&s, CHOL_ORDER_AMD);
    double *dense = calloc((size_t)s.n * s.n, sizeof *dense), t = 0.01;
    for (int i = 0; i < s.n; i++)   /* both triangles' halves: the lower half goes to its mirror */
        for (int p = s.L->row_start[i]; p < s.L->row_start[i + 1]; p++) {
            int j = s.L->col[p];
            dense[(size_t)j * s.n + i] += t * s.L->val[p];
            if (i != j)
                CHECK_INT(chol_add(c, i, j, 0.5 * t * s.L->val[p]), CHOL_OK);
            else
                CHECK_INT(chol_add(c, i, i, t * s.L->val[p]), CHOL_OK);
        }
    for (int i = 0; i < s.n; i++)
        dense[(size_t)i * s.n + i] += s.mass[i];
    assemble_and_factorise(c, CHOL_DIAG_SHIFT, s.mass);
    double rel = against_dense(c, dense, s.n);
    printf("  shift: %d rows, largest difference to LAPACK %.2g\n", s.n, rel);
    CHECK(rel < 1e-10);
    free(dense);
    chol_free(c);
    sys_close(&s);
}

/* SHIFT_UNIT: L + eps M with one more row that has no entry and d 0: its
 * diagonal becomes 1, the row is decoupled (x = b there), the rest is the
 * dense solve of L + eps M. */
TEST_T(shift_unit_decouples_an_empty_row, 20)
{
    sys s = laplacian(1, 1);
    chol *c = start(&s, CHOL_ORDER_AMD);
    double *dense = calloc((size_t)s.n * s.n, sizeof *dense), *d = malloc(s.n * sizeof *d);
    add_laplacian(c, &s, 1.0, dense);
    for (int i = 0; i < s.n; i++) {
        d[i] = 1e-3 * s.mass[i];   /* 0 on the extra row */
        dense[(size_t)i * s.n + i] += d[i];
    }
    CHECK(d[s.n - 1] == 0);
    dense[(size_t)(s.n - 1) * s.n + s.n - 1] = 1;
    assemble_and_factorise(c, CHOL_DIAG_SHIFT_UNIT, d);
    const int *cp, *ri;
    double *v;
    chol_csc(c, &cp, &ri, &v);
    CHECK_INT(cp[s.n] - cp[s.n - 1], 1);
    CHECK_INT(ri[cp[s.n - 1]], s.n - 1);
    CHECK(v[cp[s.n - 1]] == 1);
    double rel = against_dense(c, dense, s.n);
    printf("  shift_unit: %d rows, largest difference to LAPACK %.2g\n", s.n, rel);
    CHECK(rel < 1e-10);
    free(dense);
    free(d);
    chol_free(c);
    sys_close(&s);
}

/* The values rewritten through chol_csc (all doubled) and factorised
 * again on the same analysis: the solution halves; x may be b. */
TEST_T(rewritten_values_are_factorised_again, 20)
{
    char err[256] = "";
    sys s = laplacian(1, 0);
    chol *c = start(&s, CHOL_ORDER_CHOLMOD);
    double *dense = calloc((size_t)s.n * s.n, sizeof *dense);
    add_laplacian(c, &s, 1.0, dense);
    assemble_and_factorise(c, CHOL_DIAG_SHIFT, s.mass);
    double *b = malloc(s.n * sizeof *b), *x1 = malloc(s.n * sizeof *x1);
    for (int i = 0; i < s.n; i++)
        b[i] = x1[i] = i % 3 - 1;
    CHECK_INT(chol_solve(c, x1, 1, x1, err, sizeof err), CHOL_OK);
    const int *cp, *ri;
    double *v;
    chol_csc(c, &cp, &ri, &v);
    for (int k = 0; k < cp[s.n]; k++)
        v[k] *= 2;
    CHECK_INT(chol_factorise(c, err, sizeof err), CHOL_OK);
    CHECK_INT(chol_solve(c, b, 1, b, err, sizeof err), CHOL_OK);
    for (int i = 0; i < s.n; i++)
        CHECK_NEAR(b[i], 0.5 * x1[i], 1e-12 * fabs(x1[i]) + 1e-15);
    free(b);
    free(x1);
    free(dense);
    chol_free(c);
    sys_close(&s);
}

static int kind_of(int code)
{
    switch (code) {
#define CHOL_KIND(name, val, msg, kind) case name: return PROTO_KIND_##kind;
        CHOL_ERRORS(CHOL_KIND)
#undef CHOL_KIND
    }
    return -1;
}

/* The Laplacian alone with an empty extra row kept as it is: a zero
 * pivot, so the factorisation stops with CHOL_ENOTPD, whose kind is
 * NUMERIC, and names the column; a solve is then refused. And the same
 * matrix negated and large enough for CHOLMOD's supernodal LL': a
 * negative pivot, CHOL_ENOTPD too. */
TEST_T(singular_or_negative_matrix_is_reported_as_not_positive_definite, 30)
{
    char err[256] = "";
    sys s = laplacian(1, 1);
    chol *c = start(&s, CHOL_ORDER_AMD);
    double *dense = calloc((size_t)s.n * s.n, sizeof *dense), x[1] = {1};
    add_laplacian(c, &s, 1.0, dense);
    CHECK_INT(chol_assemble(c, CHOL_DIAG_KEEP, NULL, err, sizeof err), CHOL_OK);
    CHECK_INT(chol_factorise(c, err, sizeof err), CHOL_ENOTPD);
    CHECK_STR_HAS(err, "not positive definite at column");
    CHECK_INT(kind_of(CHOL_ENOTPD), PROTO_KIND_NUMERIC);
    CHECK_INT(kind_of(CHOL_ENOMEM), PROTO_KIND_NOMEM);
    CHECK_INT(chol_solve(c, x, 1, x, err, sizeof err), CHOL_EINVAL);
    CHECK_STR_HAS(err, "not factorised");
    free(dense);
    chol_free(c);
    sys_close(&s);

    s = laplacian(5, 0);
    c = start(&s, CHOL_ORDER_AMD);
    double *d = malloc(s.n * sizeof *d);
    for (int i = 0; i < s.L->n; i++)
        for (int p = s.L->row_start[i]; p < s.L->row_start[i + 1]; p++)
            if (i <= s.L->col[p])
                CHECK_INT(chol_add(c, i, s.L->col[p], -s.L->val[p]), CHOL_OK);
    for (int i = 0; i < s.n; i++)
        d[i] = -s.mass[i];
    CHECK_INT(chol_assemble(c, CHOL_DIAG_SHIFT, d, err, sizeof err), CHOL_OK);
    CHECK_INT(chol_factorise(c, err, sizeof err), CHOL_ENOTPD);
    CHECK_STR_HAS(err, "not positive definite at column");
    free(d);
    chol_free(c);
    sys_close(&s);
}

TEST_T(misuse_is_refused, 10)
{
    char err[256] = "";
    chol *c = NULL;
    CHECK_INT(chol_new(0, 4, CHOL_ORDER_AMD, &c, err, sizeof err), CHOL_EINVAL);
    CHECK(c == NULL);
    CHECK_INT(chol_new(2, 1, CHOL_ORDER_AMD, &c, err, sizeof err), CHOL_OK);
    CHECK_INT(chol_add(c, 0, 2, 1), CHOL_EINVAL);   /* out of range */
    CHECK_INT(chol_add(c, 0, 0, 1), CHOL_OK);
    CHECK_INT(chol_add(c, 1, 1, 1), CHOL_EINVAL);   /* past the room */
    CHECK_INT(chol_assemble(c, CHOL_DIAG_SHIFT, NULL, err, sizeof err), CHOL_EINVAL);
    CHECK_STR_HAS(err, "needs its values");
    CHECK_INT(chol_assemble(c, CHOL_DIAG_SHIFT_UNIT, (double[]){0, 0}, err, sizeof err), CHOL_OK);
    CHECK_INT(chol_assemble(c, CHOL_DIAG_KEEP, NULL, err, sizeof err), CHOL_EINVAL);
    CHECK_STR_HAS(err, "already assembled");
    CHECK_INT(chol_add(c, 0, 0, 1), CHOL_EINVAL);
    CHECK_INT(chol_factorise(c, err, sizeof err), CHOL_OK);   /* diag(1, 1) */
    double x[2] = {3, 4};
    CHECK_INT(chol_solve(c, x, 0, x, err, sizeof err), CHOL_EINVAL);
    CHECK_INT(chol_solve(c, x, 1, x, err, sizeof err), CHOL_OK);
    CHECK(x[0] == 3 && x[1] == 4);
    chol_free(c);
}
