/* geod_solver.c — builds the heat-method solver: per-face hat gradients,
 * connected components, and the CHOLMOD factorisations of M + t L, its
 * interior block (meshes with boundary) and L + eps M; see geod.h. Solving
 * lives in geod_distances.c. */
#include "geod/geod__solver.h"
#include "geo/geo_area.h"
#include "geo/geo_cotan.h"
#include "geo/geo_edges.h"
#include "geo/geo_tri.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

const char *geod_strerror(int code)
{
    switch (code) {
#define GEOD_STR(name, val, msg) case name: return msg;
        GEOD_ERRORS(GEOD_STR)
#undef GEOD_STR
    }
    return "unknown geodesic error";
}

int geod_solver_nv(const geod_solver *s) { return s->nv; }
double geod_solver_time(const geod_solver *s) { return s->t; }

void geod_solver_free(geod_solver *s)
{
    if (!s)
        return;
    if (s->cc_started) {
        cholmod_free_factor(&s->heat, &s->cc);
        cholmod_free_factor(&s->heat_dir, &s->cc);
        cholmod_free_factor(&s->poisson, &s->cc);
        cholmod_finish(&s->cc);
    }
    free(s->grad);
    free(s->area);
    free(s->comp);
    free(s->interior);
    free(s);
}

/* g_k = (c x e_k) / |c|^2 with c = (p1-p0) x (p2-p0) and e_k the edge
 * opposite corner k, p_{k+2} - p_{k+1}: the gradient of corner k's hat. */
static void face_gradients(const mesh *m, double *grad, double *area)
{
    for (int t = 0; t < m->nf; t++) {
        double c[3];
        double *g = grad + 9 * (size_t)t;
        if (geo__face_cross(m, t, c)) {
            memset(g, 0, 9 * sizeof *g);
            area[t] = 0;
            continue;
        }
        const double *p[3];
        geo__corners(m, t, p);
        double cc = geo__dot(c, c);
        for (int k = 0; k < 3; k++) {
            double e[3];
            geo__sub(p[(k + 2) % 3], p[(k + 1) % 3], e);
            geo__cross(c, e, g + 3 * k);
            for (int d = 0; d < 3; d++)
                g[3 * k + d] /= cc;
        }
        area[t] = 0.5 * sqrt(cc);
    }
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

/* The upper triangle of a * L + diag(d) restricted to the vertices keep
 * (ascending, or NULL for all; remap: vertex -> row or -1), as a CHOLMOD
 * symmetric (stype 1) matrix. A row with a zero diagonal (a vertex without
 * a non-degenerate face) gets 1: it is decoupled, and the system stays
 * definite. */
static cholmod_sparse *assemble(const geo_csr *L, double a, const double *d,
                                const int *keep, int nkeep, const int *remap,
                                cholmod_common *cc)
{
    size_t nnz = 0;
    for (int r = 0; r < nkeep; r++) {
        int j = keep ? keep[r] : r;
        for (int p = L->row_start[j]; p < L->row_start[j + 1]; p++)
            nnz += L->col[p] <= j && (!remap || remap[L->col[p]] >= 0);
    }
    cholmod_sparse *A = cholmod_allocate_sparse(nkeep, nkeep, nnz, 1, 1, 1,
                                                CHOLMOD_REAL, cc);
    if (!A)
        return NULL;
    int *cp = A->p, *ri = A->i;
    double *x = A->x;
    size_t at = 0;
    for (int r = 0; r < nkeep; r++) {
        int j = keep ? keep[r] : r;
        cp[r] = (int)at;
        for (int p = L->row_start[j]; p < L->row_start[j + 1]; p++) {
            int c = L->col[p];
            if (c > j || (remap && remap[c] < 0))
                continue;
            ri[at] = remap ? remap[c] : c;
            x[at] = a * L->val[p];
            if (c == j) {
                x[at] += d[j];
                if (!(x[at] != 0))
                    x[at] = 1;
            }
            at++;
        }
    }
    cp[nkeep] = (int)at;
    return A;
}

static cholmod_factor *factorise(cholmod_sparse *A, cholmod_common *cc,
                                 const char *what, char *err, size_t errsz)
{
    cholmod_factor *F = cholmod_analyze(A, cc);
    if (F && cholmod_factorize(A, F, cc) && cc->status == CHOLMOD_OK)
        return F;
    errbuf_set(err, errsz, GEOD_EFACTOR, "factorising %s failed (CHOLMOD status %d)",
               what, cc->status);
    cholmod_free_factor(&F, cc);
    return NULL;
}

geod_solver *geod_solver_new(const mesh *m, double t_factor, char *err, size_t errsz)
{
    geod_solver *s = NULL;
    geo_edges e = {0};
    geo_csr *L = NULL;
    double *mass = NULL, *d = NULL;
    int *remap = NULL;
    cholmod_sparse *A = NULL;
    int ok = 0;
    if (!m || m->nv < 1 || m->nf < 1) {
        errbuf_set(err, errsz, GEOD_EMESH, "geodesics need a mesh with faces");
        return NULL;
    }
    if (!(t_factor > 0) || !isfinite(t_factor))
        t_factor = GEOD_T_FACTOR_DEFAULT;
    int rc = geo_edges_build(m, &e, err, errsz);
    if (rc != GEO_OK) {
        if (rc != GEO_ENOMEM)
            errbuf_set(err, errsz, GEOD_EMESH, "edge table: %s", geo_strerror(rc));
        goto out;
    }
    if (geo_cotan_laplacian(m, &e, &L, err, errsz) != GEO_OK)
        goto out;
    s = calloc(1, sizeof *s);
    mass = malloc((size_t)m->nv * sizeof *mass);
    d = malloc((size_t)m->nv * sizeof *d);
    if (!s || !mass || !d ||
        !(s->grad = malloc(9 * (size_t)m->nf * sizeof *s->grad)) ||
        !(s->area = malloc((size_t)m->nf * sizeof *s->area)) ||
        !(s->comp = malloc((size_t)m->nv * sizeof *s->comp))) {
        errbuf_set(err, errsz, GEOD_ENOMEM, "out of memory for a %d-vertex solver", m->nv);
        goto out;
    }
    s->m = m;
    s->nv = m->nv;
    s->nf = m->nf;
    face_gradients(m, s->grad, s->area);
    s->ncomp = components(&e, m->nv, s->comp);
    geo_vertex_areas(m, mass);

    double h = 0, msum = 0, lsum = 0;
    int nmass = 0;
    for (int k = 0; k < e.ne; k++) {
        double v[3];
        geo__sub(m->v + 3 * (size_t)e.ev[2 * k], m->v + 3 * (size_t)e.ev[2 * k + 1], v);
        h += sqrt(geo__dot(v, v));
    }
    h /= e.ne;
    for (int i = 0; i < m->nv; i++)
        if (mass[i] > 0) {
            msum += mass[i];
            lsum += geo_csr_get(L, i, i);
            nmass++;
        }
    if (!(h > 0) || !isfinite(h) || nmass == 0 || !(msum > 0) || !(lsum > 0) ||
        !isfinite(msum) || !isfinite(lsum)) {
        errbuf_set(err, errsz, GEOD_EMESH,
                   "degenerate mesh: mean edge length %g, total area %g", h, msum);
        goto out;
    }
    s->t = t_factor * h * h;
    double eps = GEOD_POISSON_REG * lsum / msum;

    cholmod_start(&s->cc);
    s->cc_started = 1;
    s->cc.print = 0;
    s->cc.nmethods = 1; /* AMD only: deterministic, no METIS */
    s->cc.method[0].ordering = CHOLMOD_AMD;
    s->cc.postorder = 1;

    for (int i = 0; i < m->nv; i++)
        d[i] = mass[i];
    if (!(A = assemble(L, s->t, d, NULL, m->nv, NULL, &s->cc)) ||
        !(s->heat = factorise(A, &s->cc, "M + t L", err, errsz)))
        goto fail_cholmod;
    cholmod_free_sparse(&A, &s->cc);
    for (int i = 0; i < m->nv; i++)
        d[i] = eps * mass[i];
    if (!(A = assemble(L, 1.0, d, NULL, m->nv, NULL, &s->cc)) ||
        !(s->poisson = factorise(A, &s->cc, "L + eps M", err, errsz)))
        goto fail_cholmod;
    cholmod_free_sparse(&A, &s->cc);

    if (geo_edges_boundary_count(&e) > 0) {
        if (!(remap = malloc((size_t)m->nv * sizeof *remap)) ||
            !(s->interior = malloc((size_t)m->nv * sizeof *s->interior))) {
            errbuf_set(err, errsz, GEOD_ENOMEM, "out of memory for the interior list");
            goto out;
        }
        for (int i = 0; i < m->nv; i++)
            remap[i] = 0;
        for (int k = 0; k < e.ne; k++)
            if (e.ef[2 * k + 1] < 0)
                remap[e.ev[2 * k]] = remap[e.ev[2 * k + 1]] = -1;
        for (int i = 0; i < m->nv; i++)
            if (remap[i] == 0) {
                remap[i] = s->n_interior;
                s->interior[s->n_interior++] = i;
            }
        for (int i = 0; i < m->nv; i++)
            d[i] = mass[i];
        if (s->n_interior > 0 &&
            (!(A = assemble(L, s->t, d, s->interior, s->n_interior, remap, &s->cc)) ||
             !(s->heat_dir = factorise(A, &s->cc, "the interior block of M + t L",
                                       err, errsz))))
            goto fail_cholmod;
    } else {
        s->n_interior = m->nv;
    }
    ok = 1;
    goto out;

fail_cholmod:
    if (s->cc.status == CHOLMOD_OUT_OF_MEMORY)
        errbuf_set(err, errsz, GEOD_ENOMEM, "CHOLMOD ran out of memory (%d vertices)", m->nv);
    else if (!A)
        errbuf_set(err, errsz, GEOD_EFACTOR, "CHOLMOD could not build a matrix (status %d)",
                   s->cc.status);
out:
    if (s && s->cc_started)
        cholmod_free_sparse(&A, &s->cc);
    free(mass);
    free(d);
    free(remap);
    geo_csr_free(L);
    geo_edges_close(&e);
    if (!ok) {
        geod_solver_free(s);
        return NULL;
    }
    return s;
}
