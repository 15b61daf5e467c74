/* ener_def.c — the deformation energy object: reference caches (ĝ⁻¹, â per
 * face; oriented 4 vertices, cos θ̂ and l̂²/d̂ per interior edge), the
 * admissible-edge flags, and the threaded evaluation: per-face and per-edge
 * kernels write into element-local buffers, then a per-vertex gather over
 * sorted incidence lists. Energies are summed per fixed chunk of elements and
 * the chunk sums added in order, so results do not depend on the thread
 * count. The kernels themselves live in ener_membrane.c / ener_bending.c. */
#include "ener/ener_def.h"
#include "util/errbuf.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Elements per energy chunk: fixed, so sums are the same for any thread count. */
#define ENER_CHUNK 512
/* A face is non-degenerate in Y when its area exceeds this fraction of its
 * reference area. */
#define ENER_ADMISSIBLE_AREA_RATIO 1e-12

typedef struct ener__face {
    double ginv[3];  /* ĝ⁻¹ as {a, b, c} */
    double ahat;     /* reference area */
} ener__face;

typedef struct ener__edge {
    int v[4];        /* i, j, k, l: faces (i, j, k) and (j, i, l) */
    double cos_ref;  /* cos θ̂ */
    double weight;   /* l̂² / d̂ */
} ener__edge;

struct ener_def {
    ener_def_params p;
    int nv, nf, ne;          /* ne: interior edges only */
    const int *f;            /* X's faces (caller-owned) */
    const geo_edges *E;      /* caller-owned: vertex -> face lists */
    ener__face *fr;          /* nf */
    ener__edge *er;          /* ne */
    int *et;                 /* ne by 2: the edge's faces (i, j, k), (j, i, l) */
    unsigned char *adm;      /* ne: 1 when admissible */
    unsigned char *fok;      /* nf: scratch for ener_def_update_admissible */
    int *ve_start, *ve_off;  /* vertex -> 12·edge + 3·slot, sorted */
    double *gf, *ge;         /* 9·nf and 12·ne element gradients */
    double *chunk;           /* energy per chunk: faces, then edges */
};

const char *ener_strerror(int code)
{
    switch (code) {
#define ENER_MSG(name, val, msg) case name: return msg;
        ENER_ERRORS(ENER_MSG)
#undef ENER_MSG
    }
    return "unknown error";
}

static int nchunks(int n) { return (n + ENER_CHUNK - 1) / ENER_CHUNK; }

/* Cosine of the angle between the unit normals of (xi, xj, xk) and
 * (xj, xi, xl): the reference value the bending kernel compares against. */
static double edge_cos(const double *xi, const double *xj, const double *xk,
                       const double *xl)
{
    double a[3], b[3], c[3], n1[3], n2[3];
    for (int k = 0; k < 3; k++) {
        a[k] = xj[k] - xi[k];
        b[k] = xk[k] - xi[k];
        c[k] = xl[k] - xj[k];
    }
    n1[0] = a[1] * b[2] - a[2] * b[1];
    n1[1] = a[2] * b[0] - a[0] * b[2];
    n1[2] = a[0] * b[1] - a[1] * b[0];
    /* (xi − xj) × (xl − xj) = −a × c = c × a */
    n2[0] = c[1] * a[2] - c[2] * a[1];
    n2[1] = c[2] * a[0] - c[0] * a[2];
    n2[2] = c[0] * a[1] - c[1] * a[0];
    double s1 = n1[0] * n1[0] + n1[1] * n1[1] + n1[2] * n1[2];
    double s2 = n2[0] * n2[0] + n2[1] * n2[1] + n2[2] * n2[2];
    return (n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2]) / sqrt(s1 * s2);
}

/* |e1 × e2|² = det g of face (y0, y1, y2), without the Gram form's
 * cancellation on slivers. */
static double face_det(const double *y0, const double *y1, const double *y2)
{
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = y1[k] - y0[k];
        e2[k] = y2[k] - y0[k];
    }
    double n0 = e1[1] * e2[2] - e1[2] * e2[1];
    double n1 = e1[2] * e2[0] - e1[0] * e2[2];
    double n2 = e1[0] * e2[1] - e1[1] * e2[0];
    return n0 * n0 + n1 * n1 + n2 * n2;
}

static int build_faces(ener_def *d, const mesh *X, char *err, size_t errsz)
{
    for (int t = 0; t < d->nf; t++) {
        const double *x0 = X->v + 3 * (size_t)X->f[3 * t];
        const double *x1 = X->v + 3 * (size_t)X->f[3 * t + 1];
        const double *x2 = X->v + 3 * (size_t)X->f[3 * t + 2];
        double e1[3], e2[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = x1[k] - x0[k];
            e2[k] = x2[k] - x0[k];
        }
        double g11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
        double g22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
        double g12 = -(e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2]);
        double det = face_det(x0, x1, x2);
        if (!(det > 0.0) || !isfinite(det))
            return errbuf_set(err, errsz, ENER_EDEGENERATE,
                              "%s: face %d (%d, %d, %d) has zero area in the reference mesh",
                              ener_strerror(ENER_EDEGENERATE), t, X->f[3 * t],
                              X->f[3 * t + 1], X->f[3 * t + 2]);
        ener__face *r = &d->fr[t];
        r->ginv[0] = g22 / det;
        r->ginv[1] = -g12 / det;
        r->ginv[2] = g11 / det;
        r->ahat = 0.5 * sqrt(det);
    }
    return ENER_OK;
}

static void build_edges(ener_def *d, const mesh *X)
{
    const geo_edges *E = d->E;
    int n = 0;
    for (int e = 0; e < E->ne; e++) {
        int t1 = E->ef[2 * e], t2 = E->ef[2 * e + 1];
        if (t1 < 0 || t2 < 0)
            continue;
        const int *f1 = X->f + 3 * (size_t)t1;
        int ck = f1[0] == E->eo[2 * e] ? 0 : f1[1] == E->eo[2 * e] ? 1 : 2;
        d->et[2 * n] = t1;
        d->et[2 * n + 1] = t2;
        ener__edge *r = &d->er[n++];
        r->v[0] = f1[(ck + 1) % 3];
        r->v[1] = f1[(ck + 2) % 3];
        r->v[2] = f1[ck];
        r->v[3] = E->eo[2 * e + 1];
        const double *xi = X->v + 3 * (size_t)r->v[0], *xj = X->v + 3 * (size_t)r->v[1];
        double l2 = 0.0;
        for (int k = 0; k < 3; k++)
            l2 += (xj[k] - xi[k]) * (xj[k] - xi[k]);
        r->weight = 3.0 * l2 / (d->fr[t1].ahat + d->fr[t2].ahat);
        r->cos_ref = edge_cos(xi, xj, X->v + 3 * (size_t)r->v[2],
                              X->v + 3 * (size_t)r->v[3]);
    }
}

/* Vertex -> (edge, slot) incidence as buffer offsets 12·edge + 3·slot,
 * sorted by edge then slot (filled in that order). */
static void build_vertex_edges(ener_def *d)
{
    for (int e = 0; e < d->ne; e++)
        for (int s = 0; s < 4; s++)
            d->ve_start[d->er[e].v[s] + 1]++;
    for (int i = 0; i < d->nv; i++)
        d->ve_start[i + 1] += d->ve_start[i];
    int *fill = d->ve_start; /* reuse as cursor, restored below */
    for (int e = 0; e < d->ne; e++)
        for (int s = 0; s < 4; s++)
            d->ve_off[fill[d->er[e].v[s]]++] = 12 * e + 3 * s;
    for (int i = d->nv; i > 0; i--)
        d->ve_start[i] = d->ve_start[i - 1];
    d->ve_start[0] = 0;
}

ener_def *ener_def_new(const mesh *X, const geo_edges *E, const ener_def_params *p,
                       char *err, size_t errsz)
{
    ener_def *d = NULL;
    if (!X || !E || !p || E->nv != X->nv || E->nf != X->nf) {
        errbuf_set(err, errsz, ENER_EINVAL, "%s: edge table not built from this mesh",
                   ener_strerror(ENER_EINVAL));
        goto fail;
    }
    if (!(p->alpha >= 0.0) || !(p->eta >= 0.0) || !(p->log_eps > 0.0) ||
        !isfinite(p->alpha) || !isfinite(p->eta) || !isfinite(p->log_eps)) {
        errbuf_set(err, errsz, ENER_EINVAL,
                   "%s: alpha = %g, eta = %g, log_eps = %g (need alpha, eta >= 0, log_eps > 0)",
                   ener_strerror(ENER_EINVAL), p->alpha, p->eta, p->log_eps);
        goto fail;
    }
    int ne = E->ne - geo_edges_boundary_count(E);
    if (ne > INT_MAX / 12) {
        errbuf_set(err, errsz, ENER_EINVAL, "%s: %d interior edges is over %d",
                   ener_strerror(ENER_EINVAL), ne, INT_MAX / 12);
        goto fail;
    }
    d = calloc(1, sizeof *d);
    if (!d)
        goto nomem;
    d->p = *p;
    d->nv = X->nv;
    d->nf = X->nf;
    d->ne = ne;
    d->f = X->f;
    d->E = E;
    size_t nf = (size_t)d->nf, nen = (size_t)ne, nv = (size_t)d->nv;
    d->fr = malloc((nf ? nf : 1) * sizeof *d->fr);
    d->er = malloc((nen ? nen : 1) * sizeof *d->er);
    d->et = malloc((2 * nen + 1) * sizeof *d->et);
    d->adm = malloc(nen + 1);
    d->fok = malloc(nf + 1);
    d->ve_start = calloc(nv + 1, sizeof *d->ve_start);
    d->ve_off = malloc((4 * nen + 1) * sizeof *d->ve_off);
    d->gf = malloc((9 * nf + 1) * sizeof *d->gf);
    d->ge = calloc(12 * nen + 1, sizeof *d->ge);
    d->chunk = malloc(((size_t)nchunks(d->nf) + (size_t)nchunks(ne) + 1) * sizeof *d->chunk);
    if (!d->fr || !d->er || !d->et || !d->adm || !d->fok || !d->ve_start || !d->ve_off ||
        !d->gf || !d->ge || !d->chunk)
        goto nomem;
    if (build_faces(d, X, err, errsz) != ENER_OK)
        goto fail;
    build_edges(d, X);
    build_vertex_edges(d);
    memset(d->adm, 1, nen);
    return d;
nomem:
    errbuf_set(err, errsz, ENER_ENOMEM, "%s: energy caches for %d faces",
               ener_strerror(ENER_ENOMEM), X->nf);
fail:
    ener_def_free(d);
    return NULL;
}

void ener_def_free(ener_def *d)
{
    if (!d)
        return;
    free(d->fr);
    free(d->er);
    free(d->et);
    free(d->adm);
    free(d->fok);
    free(d->ve_start);
    free(d->ve_off);
    free(d->gf);
    free(d->ge);
    free(d->chunk);
    free(d);
}

int ener_def_update_admissible(ener_def *d, const double *Y)
{
    const int nf = d->nf, ne = d->ne;
    const int *f = d->f;
    const double r2 = 4.0 * ENER_ADMISSIBLE_AREA_RATIO * ENER_ADMISSIBLE_AREA_RATIO;
    int count = 0;
#pragma omp parallel
    {
#pragma omp for schedule(static)
        for (int t = 0; t < nf; t++) {
            double det = face_det(Y + 3 * (size_t)f[3 * t], Y + 3 * (size_t)f[3 * t + 1],
                                  Y + 3 * (size_t)f[3 * t + 2]);
            /* area > ratio·â  ⟺  det g > 4·ratio²·â² */
            d->fok[t] = det > r2 * d->fr[t].ahat * d->fr[t].ahat;
        }
#pragma omp for schedule(static) reduction(+ : count)
        for (int e = 0; e < ne; e++) {
            d->adm[e] = d->fok[d->et[2 * e]] && d->fok[d->et[2 * e + 1]];
            count += d->adm[e];
        }
    }
    return count;
}

double ener_def_eval(ener_def *d, const double *Y, double *grad,
                     double *w_mem, double *w_bnd)
{
    const int nf = d->nf, ne = d->ne, nv = d->nv;
    const int ncf = nchunks(nf), nce = nchunks(ne);
    const double log_eps = d->p.log_eps, alpha = d->p.alpha, eta = d->p.eta;
    const int *f = d->f;
    const ener__face *fr = d->fr;
    const ener__edge *er = d->er;
    const unsigned char *adm = d->adm;
    double *gf = d->gf, *ge = d->ge, *chunk = d->chunk;
    const int *vf_start = d->E->vf_start, *vf_face = d->E->vf_face;
    const int *vf_corner = d->E->vf_corner;
    const int *ve_start = d->ve_start, *ve_off = d->ve_off;

#pragma omp parallel
    {
#pragma omp for schedule(static) nowait
        for (int c = 0; c < ncf; c++) {
            const int t1 = c * ENER_CHUNK + ENER_CHUNK < nf ? c * ENER_CHUNK + ENER_CHUNK : nf;
            double s = 0.0;
            for (int t = c * ENER_CHUNK; t < t1; t++) {
                const int *ft = f + 3 * (size_t)t;
                s += ener_membrane_face(fr[t].ginv, fr[t].ahat, log_eps,
                                        Y + 3 * (size_t)ft[0], Y + 3 * (size_t)ft[1],
                                        Y + 3 * (size_t)ft[2],
                                        grad ? gf + 9 * (size_t)t : NULL);
            }
            chunk[c] = s;
        }
#pragma omp for schedule(static)
        for (int c = 0; c < nce; c++) {
            const int e1 = c * ENER_CHUNK + ENER_CHUNK < ne ? c * ENER_CHUNK + ENER_CHUNK : ne;
            double s = 0.0;
            for (int e = c * ENER_CHUNK; e < e1; e++) {
                double *g = grad ? ge + 12 * (size_t)e : NULL;
                if (!adm[e]) {
                    if (g)
                        memset(g, 0, 12 * sizeof *g);
                    continue;
                }
                const int *v = er[e].v;
                s += ener_bending_edge(er[e].cos_ref, er[e].weight,
                                       Y + 3 * (size_t)v[0], Y + 3 * (size_t)v[1],
                                       Y + 3 * (size_t)v[2], Y + 3 * (size_t)v[3], g);
            }
            chunk[ncf + c] = s;
        }
        if (grad) {
#pragma omp for schedule(static)
            for (int i = 0; i < nv; i++) {
                double mx = 0.0, my = 0.0, mz = 0.0, bx = 0.0, by = 0.0, bz = 0.0;
                for (int s = vf_start[i]; s < vf_start[i + 1]; s++) {
                    const double *g = gf + 9 * (size_t)vf_face[s] + 3 * vf_corner[s];
                    mx += g[0];
                    my += g[1];
                    mz += g[2];
                }
                for (int s = ve_start[i]; s < ve_start[i + 1]; s++) {
                    const double *g = ge + ve_off[s];
                    bx += g[0];
                    by += g[1];
                    bz += g[2];
                }
                double *o = grad + 3 * (size_t)i;
                o[0] = alpha * mx + eta * bx;
                o[1] = alpha * my + eta * by;
                o[2] = alpha * mz + eta * bz;
            }
        }
    }
    double em = 0.0, eb = 0.0;
    for (int c = 0; c < ncf; c++)
        em += chunk[c];
    for (int c = 0; c < nce; c++)
        eb += chunk[ncf + c];
    if (w_mem)
        *w_mem = em;
    if (w_bnd)
        *w_bnd = eb;
    return alpha * em + eta * eb;
}
