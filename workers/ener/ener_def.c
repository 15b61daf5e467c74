/* ener_def.c — the deformation energy object: reference caches (ĝ⁻¹, â per
 * face; faces, orientation sign, cos θ̂ and l̂²/d̂ per interior edge), the
 * admissible-edge flags, and the threaded evaluation. The arithmetic lives
 * in ener_membrane.h and ener_normal.h (shared with the single-element
 * kernels ener_membrane.c and ener_bending.c); this file runs it over the
 * mesh.
 *
 * DESIGN. ener_def_eval is four data-parallel passes with a barrier between
 * them, each writing only its own elements' slots:
 *   A  per face: membrane energy and α times its gradient (9 values), unit
 *      normal
 *   B  per admissible edge: cos θ = ±⟨n_t, n_t'⟩ from A's normals, the term
 *      (cos θ̂ − cos θ)²·l̂²/d̂, and η·∂term/∂cos θ
 *   C  per face: the gradient w.r.t. its normal, Σ over its edges of B's
 *      coefficient times the neighbour's normal, back-propagated onto its
 *      3 corners and added to A's 9 values
 *   D  per vertex: the sum of its faces' corner gradients in the sorted
 *      vertex -> face order of geo_edges.
 * Sharing each face's normal between its three edges makes a bending edge
 * cost a dot product, and puts the whole gradient into the per-face buffer,
 * so one gather over vertex -> face lists suffices. Energies are summed per
 * fixed chunk of elements and the chunk sums added in order. No atomics;
 * the result has the same bits for any thread count. */
#include "ener/ener_def.h"
#include "ener/ener_def_ref.h"
#include "ener/ener_membrane.h"
#include "ener/ener_normal.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Elements per energy chunk: fixed, so sums are the same for any thread count. */
#define ENER_CHUNK 512

struct ener_def {
    ener_def_params p;
    int nv, nf, ne;          /* ne: interior edges only */
    const int *f;            /* X's faces (caller-owned) */
    const geo_edges *E;      /* caller-owned: vertex -> face lists */
    ener__face *fr;          /* nf */
    ener__edge *er;          /* ne */
    int *fedge, *fnbr;       /* nf by 3: interior edge index (or −1) and the
                                face across it, for pass C */
    unsigned char *adm;      /* ne: 1 when admissible */
    unsigned char *fok;      /* nf: scratch for ener_def_update_admissible */
    double *fn;              /* nf by 4: unit normal and 1/|c| in Y (pass A) */
    double *gf;              /* nf by 9: corner gradients (passes A, C) */
    double *ecoef;           /* ne: η·∂term/∂⟨n_t, n_t'⟩ (pass B) */
    double *chunk;           /* energy per chunk: faces, then edges */
};

const char *ener_strerror(int code)
{
    switch (code) { ENER_ERRORS(ERRLIST_CASE) }
    return "unknown error";
}

static int nchunks(int n) { return (n + ENER_CHUNK - 1) / ENER_CHUNK; }

static const double *corner(const double *Y, const int *f, int t, int k)
{
    return Y + 3 * (size_t)f[3 * t + k];
}

/* |e1 × e2|² = det g of face t, without the Gram form's cancellation on
 * slivers. */
static double face_det(const double *Y, const int *f, int t)
{
    const double *y0 = corner(Y, f, t, 0), *y1 = corner(Y, f, t, 1);
    const double *y2 = corner(Y, f, t, 2);
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
        const double *x0 = corner(X->v, X->f, t, 0), *x1 = corner(X->v, X->f, t, 1);
        const double *x2 = corner(X->v, X->f, t, 2);
        double e1[3], e2[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = x1[k] - x0[k];
            e2[k] = -(x2[k] - x0[k]);
        }
        /* ĝ = [e1 | −e2]ᵀ[e1 | −e2]; det ĝ = |e1 × e2|² */
        double g11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
        double g22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
        double g12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
        double det = face_det(X->v, X->f, t);
        if (!(det > 0.0) || !isfinite(det))
            return errbuf_set(err, errsz, ENER_EDEGENERATE,
                              "%s: face %d (%d, %d, %d) has zero area in the reference mesh",
                              ener_strerror(ENER_EDEGENERATE), t, X->f[3 * t],
                              X->f[3 * t + 1], X->f[3 * t + 2]);
        ener__face *r = &d->fr[t];
        double sc = d->p.face_scale ? d->p.face_scale[t] : 1.0;
        r->ginv[0] = g22 / (det * sc);
        r->ginv[1] = -g12 / (det * sc);
        r->ginv[2] = g11 / (det * sc);
        r->ahat = 0.5 * sqrt(det);
    }
    return ENER_OK;
}

/* Interior edges in edge-table order: faces, orientation sign, weight and
 * cos θ̂ from X's unit normals (the bending kernel's convention, see
 * ener_bending.c), and the per-face edge lists for pass C. */
static void build_edges(ener_def *d, const mesh *X)
{
    const geo_edges *E = d->E;
    for (int i = 0; i < 3 * d->nf; i++)
        d->fedge[i] = d->fnbr[i] = -1;
    int n = 0;
    for (int e = 0; e < E->ne; e++) {
        int t1 = E->ef[2 * e], t2 = E->ef[2 * e + 1];
        if (t1 < 0 || t2 < 0)
            continue;
        const int *f1 = X->f + 3 * (size_t)t1, *f2 = X->f + 3 * (size_t)t2;
        int c1 = f1[0] == E->eo[2 * e] ? 0 : f1[1] == E->eo[2 * e] ? 1 : 2;
        int c2 = f2[0] == E->eo[2 * e + 1] ? 0 : f2[1] == E->eo[2 * e + 1] ? 1 : 2;
        int vi = f1[(c1 + 1) % 3], vj = f1[(c1 + 2) % 3];
        ener__edge *r = &d->er[n];
        r->t[0] = t1;
        r->t[1] = t2;
        /* face t2 = (l, a, b) runs (j, i, l) cyclically when a = j */
        r->sign = f2[(c2 + 1) % 3] == vj ? 1.0 : -1.0;
        const double *xi = X->v + 3 * (size_t)vi, *xj = X->v + 3 * (size_t)vj;
        double l2 = 0.0;
        for (int k = 0; k < 3; k++)
            l2 += (xj[k] - xi[k]) * (xj[k] - xi[k]);
        r->weight = 3.0 * l2 / (d->fr[t1].ahat + d->fr[t2].ahat);
        double n1[3], n2[3];
        ener__unit_normal(corner(X->v, X->f, t1, 0), corner(X->v, X->f, t1, 1),
                          corner(X->v, X->f, t1, 2), n1);
        ener__unit_normal(corner(X->v, X->f, t2, 0), corner(X->v, X->f, t2, 1),
                          corner(X->v, X->f, t2, 2), n2);
        r->cos_ref = r->sign * (n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2]);
        d->fedge[3 * t1 + c1] = d->fedge[3 * t2 + c2] = n;
        d->fnbr[3 * t1 + c1] = t2;
        d->fnbr[3 * t2 + c2] = t1;
        n++;
    }
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
    d = calloc(1, sizeof *d);
    if (!d)
        goto nomem;
    d->p = *p;
    d->nv = X->nv;
    d->nf = X->nf;
    d->ne = E->ne - geo_edges_boundary_count(E);
    d->f = X->f;
    d->E = E;
    size_t nf = (size_t)d->nf, ne = (size_t)d->ne;
    d->fr = malloc((nf + 1) * sizeof *d->fr);
    d->er = malloc((ne + 1) * sizeof *d->er);
    d->fedge = malloc((3 * nf + 1) * sizeof *d->fedge);
    d->fnbr = malloc((3 * nf + 1) * sizeof *d->fnbr);
    d->adm = malloc(ne + 1);
    d->fok = malloc(nf + 1);
    d->fn = malloc((4 * nf + 1) * sizeof *d->fn);
    d->gf = malloc((9 * nf + 1) * sizeof *d->gf);
    d->ecoef = malloc((ne + 1) * sizeof *d->ecoef);
    d->chunk = malloc(((size_t)nchunks(d->nf) + (size_t)nchunks(d->ne) + 1) *
                      sizeof *d->chunk);
    if (!d->fr || !d->er || !d->fedge || !d->fnbr || !d->adm || !d->fok || !d->fn ||
        !d->gf || !d->ecoef || !d->chunk)
        goto nomem;
    if (build_faces(d, X, err, errsz) != ENER_OK)
        goto fail;
    build_edges(d, X);
    d->p.face_scale = NULL;
    memset(d->adm, 1, ne);
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
    free(d->fedge);
    free(d->fnbr);
    free(d->adm);
    free(d->fok);
    free(d->fn);
    free(d->gf);
    free(d->ecoef);
    free(d->chunk);
    free(d);
}

void ener__def_ref_get(const ener_def *d, ener__def_ref *out)
{
    out->p = d->p;
    out->nv = d->nv;
    out->nf = d->nf;
    out->ne = d->ne;
    out->f = d->f;
    out->E = d->E;
    out->fr = d->fr;
    out->er = d->er;
    out->fedge = d->fedge;
    out->fnbr = d->fnbr;
}

int ener_def_update_admissible(ener_def *d, const double *Y)
{
    const int nf = d->nf, ne = d->ne;
    const double r2 = 4.0 * ENER_ADMISSIBLE_AREA_RATIO * ENER_ADMISSIBLE_AREA_RATIO;
    int count = 0;
#pragma omp parallel
    {
#pragma omp for schedule(static)
        for (int t = 0; t < nf; t++)
            d->fok[t] = (unsigned char)ener__face_admissible(corner(Y, d->f, t, 0), corner(Y, d->f, t, 1),
                                                             corner(Y, d->f, t, 2), d->fr[t].ahat, r2);
#pragma omp for schedule(static) reduction(+ : count)
        for (int e = 0; e < ne; e++) {
            d->adm[e] = d->fok[d->er[e].t[0]] && d->fok[d->er[e].t[1]];
            count += d->adm[e];
        }
    }
    return count;
}

/* Pass A on chunk c of faces: each face's unit normal into fn and its
 * membrane gradient into gf (with grad), the chunk's logs in one tight loop;
 * returns the chunk's membrane energy, summed in face order. */
static inline double membrane_chunk(ener_def *d, const double *Y, const double *grad, int c)
{
    const int nf = d->nf;
    const double log_eps = d->p.log_eps, alpha = d->p.alpha;
    const int *f = d->f;
    const ener__face *fr = d->fr;
    double *fn = d->fn, *gf = d->gf;
    const int t0 = c * ENER_CHUNK;
    const int t1 = nf - t0 < ENER_CHUNK ? nf : t0 + ENER_CHUNK;
    double det[ENER_CHUNK], logd[ENER_CHUNK];
    for (int t = t0; t < t1; t++) {
        const double *y0 = corner(Y, f, t, 0), *y1 = corner(Y, f, t, 1);
        const double *y2 = corner(Y, f, t, 2);
        const double e1[3] = {y1[0] - y0[0], y1[1] - y0[1], y1[2] - y0[2]};
        const double e2[3] = {y2[0] - y0[0], y2[1] - y0[1], y2[2] - y0[2]};
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1],
                             e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        double *un = fn + 4 * (size_t)t;
        un[3] = ener__unit_normal_of(e1, e2, n, un);
        det[t - t0] = ener__membrane_det(fr[t].ginv, n);
    }
    for (int k = 0; k < t1 - t0; k++)
        logd[k] = log(det[k] > log_eps ? det[k] : log_eps);
    double s = 0.0;
    for (int t = t0; t < t1; t++) {
        const double *y0 = corner(Y, f, t, 0), *y1 = corner(Y, f, t, 1);
        const double *y2 = corner(Y, f, t, 2);
        const double e1[3] = {y1[0] - y0[0], y1[1] - y0[1], y1[2] - y0[2]};
        const double e2[3] = {y2[0] - y0[0], y2[1] - y0[1], y2[2] - y0[2]};
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1],
                             e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        s += ener__membrane_finish(fr[t].ginv, fr[t].ahat, alpha * fr[t].ahat,
                                   log_eps, e1, e2, n,
                                   det[t - t0], logd[t - t0],
                                   grad ? gf + 9 * (size_t)t : NULL);
    }
    return s;
}

/* Pass B on chunk c of interior edges: each edge's coefficient into ecoef
 * (0 for an inadmissible edge or a zero normal); returns the chunk's bending
 * energy, summed in edge order. */
static inline double bending_chunk(ener_def *d, int c)
{
    const int ne = d->ne;
    const double eta = d->p.eta;
    const ener__edge *er = d->er;
    const unsigned char *adm = d->adm;
    const double *fn = d->fn;
    double *ecoef = d->ecoef;
    const int e1 = ne - c * ENER_CHUNK < ENER_CHUNK ? ne : c * ENER_CHUNK + ENER_CHUNK;
    double s = 0.0;
    for (int e = c * ENER_CHUNK; e < e1; e++) {
        const double *n1 = fn + 4 * (size_t)er[e].t[0];
        const double *n2 = fn + 4 * (size_t)er[e].t[1];
        if (!adm[e] || n1[3] == 0.0 || n2[3] == 0.0) {
            ecoef[e] = 0.0;
            continue;
        }
        const double cs = er[e].sign * (n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2]);
        const double diff = er[e].cos_ref - cs;
        s += er[e].weight * diff * diff;
        ecoef[e] = -2.0 * eta * er[e].weight * diff * er[e].sign;
    }
    return s;
}

/* Pass C on face t: the bending gradient w.r.t. its normal, back-propagated
 * onto its corners and added to gf. */
static inline void bending_face_grad(ener_def *d, const double *Y, int t)
{
    const int *f = d->f, *fedge = d->fedge, *fnbr = d->fnbr;
    const double *fn = d->fn, *ecoef = d->ecoef;
    double u[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 3; k++) {
        const int e = fedge[3 * t + k];
        if (e < 0)
            continue;
        const double *m = fn + 4 * (size_t)fnbr[3 * t + k];
        u[0] += ecoef[e] * m[0];
        u[1] += ecoef[e] * m[1];
        u[2] += ecoef[e] * m[2];
    }
    const double *n = fn + 4 * (size_t)t;
    ener__unit_normal_backprop(corner(Y, f, t, 0), corner(Y, f, t, 1),
                               corner(Y, f, t, 2), n, n[3], u,
                               d->gf + 9 * (size_t)t);
}

/* Pass D on vertex i: the sum of its faces' corner gradients, in the sorted
 * vertex -> face order, into grad. */
static inline void vertex_grad(const ener_def *d, double *grad, int i)
{
    const int *vf_start = d->E->vf_start, *vf_face = d->E->vf_face;
    const int *vf_corner = d->E->vf_corner;
    const double *gf = d->gf;
    double gx = 0.0, gy = 0.0, gz = 0.0;
    for (int s = vf_start[i]; s < vf_start[i + 1]; s++) {
        const double *g = gf + 9 * (size_t)vf_face[s] + 3 * vf_corner[s];
        gx += g[0];
        gy += g[1];
        gz += g[2];
    }
    grad[3 * (size_t)i] = gx;
    grad[3 * (size_t)i + 1] = gy;
    grad[3 * (size_t)i + 2] = gz;
}

double ener_def_eval(ener_def *d, const double *Y, double *grad,
                     double *w_mem, double *w_bnd)
{
    const int nf = d->nf, ne = d->ne, nv = d->nv;
    const int ncf = nchunks(nf), nce = nchunks(ne);
    const double alpha = d->p.alpha, eta = d->p.eta;
    double *chunk = d->chunk;

#pragma omp parallel
    {
        /* A: normals and det G, then the membrane terms */
#pragma omp for schedule(static)
        for (int c = 0; c < ncf; c++)
            chunk[c] = membrane_chunk(d, Y, grad, c);
        /* B: bending terms */
#pragma omp for schedule(static)
        for (int c = 0; c < nce; c++)
            chunk[ncf + c] = bending_chunk(d, c);
        if (grad) {
            /* C: bending gradient per face through its normal */
#pragma omp for schedule(static)
            for (int t = 0; t < nf; t++)
                bending_face_grad(d, Y, t);
            /* D: gather per vertex in sorted face order */
#pragma omp for schedule(static)
            for (int i = 0; i < nv; i++)
                vertex_grad(d, grad, i);
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
