/* geod_solver.c — builds the heat-method solver: per-face hat gradients,
 * connected components, and the CHOLMOD factorisations of M + t L, its
 * interior block (meshes with boundary) and L + eps M; see geod.h. Solving
 * lives in geod_distances.c. */
#include "geod/geod__solver.h"
#include "geod/geod__idt.h"
#include "geo/geo_csr.h"
#include "geo/geo_edges.h"
#include "geo/geo_tri.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <suitesparse/cholmod.h>

const char *geod_strerror(int code)
{
    switch (code) { GEOD_ERRORS(ERRLIST_CASE) }
    return "unknown geodesic error";
}

int geod_solver_nv(const geod_solver *s) { return s->nv; }
int geod_solver_flips(const geod_solver *s) { return s->flips; }
const geo_csr *geod_solver_laplacian(const geod_solver *s) { return s->L; }
const double *geod_solver_mass(const geod_solver *s) { return s->mass; }

void geod_solver_free(geod_solver *s)
{
    if (!s)
        return;
    chol_free(s->heat);
    chol_free(s->heat_dir);
    chol_free(s->poisson);
    free(s->f);
    geo_csr_free(s->L);
    free(s->mass);
    free(s->grad);
    free(s->area);
    free(s->comp);
    free(s->interior);
    free(s);
}

/* Per intrinsic triangle, in its own plane frame (corner 0 at the origin,
 * corner 1 on the x axis, corner 2 above): the hat gradients
 * g_k = J (p_{k+2} - p_{k+1}) / (2 A), J the quarter turn, and the area.
 * Degenerate triangles get zero gradients and area. */
static void face_gradients(const geod__idt *T, double *grad, double *area)
{
    for (int t = 0; t < T->nf; t++) {
        const double *l = T->len + 3 * (size_t)t;
        double *g = grad + 6 * (size_t)t, a2 = geod__double_area(l[0], l[1], l[2]);
        if (!(a2 > GEO__DEGENERATE_REL * (l[1] * l[1] + l[2] * l[2]))) {
            memset(g, 0, 6 * sizeof *g);
            area[t] = 0;
            continue;
        }
        /* |p0 p1| = l[2], |p2 p0| = l[1] */
        double x2 = (l[2] * l[2] + l[1] * l[1] - l[0] * l[0]) / (2 * l[2]);
        double p[3][2] = {{0, 0}, {l[2], 0}, {x2, a2 / l[2]}};
        for (int k = 0; k < 3; k++) {
            const double *q = p[(k + 2) % 3], *r = p[(k + 1) % 3];
            g[2 * k] = -(q[1] - r[1]) / a2;
            g[2 * k + 1] = (q[0] - r[0]) / a2;
        }
        area[t] = 0.5 * a2;
    }
}

/* The cotan Laplacian L (positive semi-definite, weight (cot a + cot b) / 2
 * per edge) and the lumped mass (a third of each incident triangle's area)
 * of the intrinsic triangulation. L as CSR with both triangles: CHOLMOD
 * sorts the triplets and sums duplicate edges; loops (an edge from a vertex
 * to itself) are dropped, they add nothing to x^T L x. */
static geo_csr *idt_laplacian(const geod__idt *T, int nv, const double *area, double *mass)
{
    cholmod_common common, *cc = &common;
    cholmod_start(cc);
    cc->print = 0;
    cholmod_triplet *tr = cholmod_allocate_triplet((size_t)nv, (size_t)nv,
                                                   12 * (size_t)T->nf + (size_t)nv, 0, CHOLMOD_REAL, cc);
    cholmod_sparse *A = NULL;
    geo_csr *L = NULL;
    if (!tr) {
        cholmod_finish(cc);
        return NULL;
    }
    int *ti = tr->i, *tj = tr->j;
    double *tx = tr->x;
    size_t n = 0;
    memset(mass, 0, (size_t)nv * sizeof *mass);
    for (int i = 0; i < nv; i++) {   /* every row stores its diagonal, even a zero one */
        ti[n] = tj[n] = i;
        tx[n++] = 0;
    }
    for (int t = 0; t < T->nf; t++)
        for (int k = 0; k < 3; k++) {
            const double *l = T->len + 3 * (size_t)t;
            mass[T->f[3 * t + k]] += area[t] / 3;
            int i = T->f[3 * t + (k + 1) % 3], j = T->f[3 * t + (k + 2) % 3];
            double w = area[t] > 0 ? 0.5 * geod__cot(l[k], l[(k + 1) % 3], l[(k + 2) % 3]) : 0;
            if (i == j || w == 0)
                continue;
            int e[4][2] = {{i, i}, {j, j}, {i, j}, {j, i}};
            for (int q = 0; q < 4; q++) {
                ti[n] = e[q][0];
                tj[n] = e[q][1];
                tx[n++] = q < 2 ? w : -w;
            }
        }
    tr->nnz = n;
    if ((A = cholmod_triplet_to_sparse(tr, n, cc)) && (L = geo_csr_new(nv, (int)cholmod_nnz(A, cc)))) {
        /* symmetric with both triangles: column c of the CSC matrix is row c */
        memcpy(L->row_start, A->p, ((size_t)nv + 1) * sizeof *L->row_start);
        memcpy(L->col, A->i, (size_t)L->row_start[nv] * sizeof *L->col);
        memcpy(L->val, A->x, (size_t)L->row_start[nv] * sizeof *L->val);
    }
    cholmod_free_sparse(&A, cc);
    cholmod_free_triplet(&tr, cc);
    cholmod_finish(cc);
    return L;
}

static int find_root(int *parent, int i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

/* comp[i] in 0..ncomp-1, numbered in order of first vertex. */
static int components(const geo_edges *e, int nv, int *comp)
{
    for (int i = 0; i < nv; i++)
        comp[i] = i;
    for (int k = 0; k < e->ne; k++) {
        int a = find_root(comp, e->ev[2 * k]), b = find_root(comp, e->ev[2 * k + 1]);
        if (a != b)
            comp[a > b ? a : b] = a < b ? a : b;
    }
    for (int i = 0; i < nv; i++)
        comp[i] = find_root(comp, i);
    /* a root is its component's smallest vertex: label in place, -(label+1)
     * marking entries already relabelled */
    int n = 0;
    for (int i = 0; i < nv; i++)
        comp[i] = comp[i] == i ? -(n++) - 1 : comp[comp[i]];
    for (int i = 0; i < nv; i++)
        comp[i] = -comp[i] - 1;
    return n;
}

/* *out = the factorised a * L + c * M (M = diag(mass)) restricted to the vertices keep
 * (ascending, or NULL for all; remap: vertex -> row or -1). A row with a
 * zero diagonal (a vertex without a non-degenerate face) gets 1: it is
 * decoupled, and the system stays definite. AMD ordering only: the
 * factors are the same whatever METIS would do. GEOD_OK, GEOD_ENOMEM or
 * GEOD_EFACTOR, naming what in err. */
static int factor(const geo_csr *L, double a, double c, const double *mass, const int *keep, int nkeep,
                  const int *remap, const char *what, chol **out, char *err, size_t errsz)
{
    char detail[256] = "";
    size_t nnz = 0;
    for (int r = 0; r < nkeep; r++) {
        int j = keep ? keep[r] : r;
        nnz += (size_t)(L->row_start[j + 1] - L->row_start[j]);
    }
    double *dk = malloc((size_t)nkeep * sizeof *dk);
    int rc = dk ? chol_new(nkeep, nnz, CHOL_ORDER_AMD, out, detail, sizeof detail) : CHOL_ENOMEM;
    for (int r = 0; rc == CHOL_OK && r < nkeep; r++) {
        int j = keep ? keep[r] : r;
        dk[r] = c * mass[j];
        for (int p = L->row_start[j]; p < L->row_start[j + 1]; p++) {
            int col = L->col[p];
            if (col <= j && (!remap || remap[col] >= 0))
                chol_add(*out, remap ? remap[col] : col, r, a * L->val[p]);
        }
    }
    if (rc == CHOL_OK && (rc = chol_assemble(*out, CHOL_DIAG_SHIFT_UNIT, dk, detail, sizeof detail)) == CHOL_OK)
        rc = chol_factorise(*out, detail, sizeof detail);
    free(dk);
    if (rc == CHOL_OK)
        return GEOD_OK;
    chol_free(*out);
    *out = NULL;
    return errbuf_set(err, errsz, rc == CHOL_ENOMEM ? GEOD_ENOMEM : GEOD_EFACTOR, "%s: %s", what,
                      detail[0] ? detail : "out of memory");
}

/* The heat time's scale h (the mean extrinsic edge length) and the
 * Poisson regularisation eps = GEOD_POISSON_REG * mean(L_ii) / mean(M_ii)
 * over the vertices with mass. GEOD_OK, or GEOD_EMESH for a degenerate
 * mesh. */
static int operator_scales(const mesh *m, const geo_edges *e, const geo_csr *L, const double *mass,
                           double *h_out, double *eps, char *err, size_t errsz)
{
    double h = 0, msum = 0, lsum = 0;
    int nmass = 0;
    for (int k = 0; k < e->ne; k++) {
        double v[3];
        geo__sub(m->v + 3 * (size_t)e->ev[2 * k], m->v + 3 * (size_t)e->ev[2 * k + 1], v);
        h += sqrt(geo__dot(v, v));
    }
    h /= e->ne;
    for (int i = 0; i < m->nv; i++)
        if (mass[i] > 0) {
            msum += mass[i];
            lsum += geo_csr_get(L, i, i);
            nmass++;
        }
    if (!(h > 0) || !isfinite(h) || nmass == 0 || !(msum > 0) || !(lsum > 0) ||
        !isfinite(msum) || !isfinite(lsum))
        return errbuf_set(err, errsz, GEOD_EMESH, "degenerate mesh: mean edge length %g, total area %g",
                          h, msum);
    *h_out = h;
    *eps = GEOD_POISSON_REG * lsum / msum;
    return GEOD_OK;
}

/* On a mesh with boundary: s->interior (the vertices on no boundary edge)
 * and the factorised interior block of M + t L (none when every vertex is
 * on the boundary); on a closed mesh every vertex is interior and there is
 * no block. GEOD_OK, GEOD_ENOMEM or GEOD_EFACTOR. */
static int factor_interior(geod_solver *s, const geo_edges *e, char *err, size_t errsz)
{
    if (geo_edges_boundary_count(e) == 0) {
        s->n_interior = s->nv;
        return GEOD_OK;
    }
    int *remap = malloc((size_t)s->nv * sizeof *remap);   /* vertex -> interior row, or -1 */
    if (!remap || !(s->interior = malloc((size_t)s->nv * sizeof *s->interior))) {
        free(remap);
        return errbuf_set(err, errsz, GEOD_ENOMEM, "out of memory for the interior list");
    }
    for (int i = 0; i < s->nv; i++)
        remap[i] = 0;
    for (int k = 0; k < e->ne; k++)
        if (e->ef[2 * k + 1] < 0)
            remap[e->ev[2 * k]] = remap[e->ev[2 * k + 1]] = -1;
    for (int i = 0; i < s->nv; i++)
        if (remap[i] == 0) {
            remap[i] = s->n_interior;
            s->interior[s->n_interior++] = i;
        }
    int rc = s->n_interior > 0
           ? factor(s->L, s->t, 1.0, s->mass, s->interior, s->n_interior, remap,
                    "factorising the interior block of M + t L", &s->heat_dir, err, errsz)
           : GEOD_OK;
    free(remap);
    return rc;
}

int geod_solver_new(const mesh *m, double t_factor, geod_solver **out, char *err, size_t errsz)
{
    geod_solver *s = NULL;
    int code = GEOD_ENOMEM;   /* what a failure below returns, unless it says */
    *out = NULL;
    geo_edges e = {0};
    geod__idt idt = {0};
    geo_csr *L = NULL;
    double *mass = NULL, h = 0, eps = 0;
    if (!m || m->nv < 1 || m->nf < 1) {
        return errbuf_set(err, errsz, GEOD_EMESH, "geodesics need a mesh with faces");
    }
    if (!(t_factor > 0) || !isfinite(t_factor))
        t_factor = GEOD_T_FACTOR_DEFAULT;
    int rc = geo_edges_build(m, &e, err, errsz);
    if (rc != GEO_OK) {
        if (rc != GEO_ENOMEM)
            code = errbuf_set(err, errsz, GEOD_EMESH, "edge table: %s", geo_strerror(rc));
        goto out;
    }
    s = calloc(1, sizeof *s);
    mass = malloc((size_t)m->nv * sizeof *mass);
    if (!s || !mass ||
        !(s->grad = malloc(6 * (size_t)m->nf * sizeof *s->grad)) ||
        !(s->area = malloc((size_t)m->nf * sizeof *s->area)) ||
        !(s->comp = malloc((size_t)m->nv * sizeof *s->comp))) {
        code = errbuf_set(err, errsz, GEOD_ENOMEM, "out of memory for a %d-vertex solver", m->nv);
        goto out;
    }
    s->nv = m->nv;
    s->nf = m->nf;
    if (geod__idt_build(m, &e, &idt) != GEOD_OK) {
        code = errbuf_set(err, errsz, GEOD_ENOMEM, "out of memory for the intrinsic triangulation");
        goto out;
    }
    s->flips = idt.flips;
    face_gradients(&idt, s->grad, s->area);
    if (!(L = idt_laplacian(&idt, m->nv, s->area, mass))) {
        code = errbuf_set(err, errsz, GEOD_ENOMEM, "out of memory for a %d-vertex Laplacian", m->nv);
        goto out;
    }
    s->f = idt.f;
    idt.f = NULL;
    s->L = L;
    s->mass = mass;
    s->ncomp = components(&e, m->nv, s->comp);
    if ((code = operator_scales(m, &e, L, mass, &h, &eps, err, errsz)) != GEOD_OK)
        goto out;
    s->t = t_factor * h * h;
    if ((code = factor(L, s->t, 1.0, mass, NULL, m->nv, NULL, "factorising M + t L", &s->heat, err,
                       errsz)) != GEOD_OK ||
        (code = factor(L, 1.0, eps, mass, NULL, m->nv, NULL, "factorising L + eps M", &s->poisson, err,
                       errsz)) != GEOD_OK ||
        (code = factor_interior(s, &e, err, errsz)) != GEOD_OK)
        goto out;
out:
    geod__idt_close(&idt);
    if (!s || !s->L) {   /* not handed over to the solver */
        geo_csr_free(L);
        free(mass);
    }
    geo_edges_close(&e);
    if (code != GEOD_OK) {
        geod_solver_free(s);
        return code;
    }
    *out = s;
    return GEOD_OK;
}
