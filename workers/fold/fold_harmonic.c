/* fold_harmonic.c — fold__harmonic (fold__patch.h): a patch placed in the
 * plane by the discrete harmonic (Tutte) map with clamped cotangent
 * weights, solved by Jacobi-preconditioned conjugate gradients; and
 * fold__disk_place, the patch in the unit disk by it; fold__conjugate,
 * a harmonic function's conjugate. */
#include "fold/fold__patch.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The smallest edge weight: cotangent weights turn negative at obtuse
 * angles, and Tutte's theorem wants every weight positive. */
#define FOLD__MIN_WEIGHT 0.05

typedef struct ew {
    int e;
    double w;
    double s;      /* sum of its faces' scales */
    int nfaces;
} ew;

static int cmp_ew(const void *a, const void *b)
{
    const ew *x = a, *y = b;
    return (x->e > y->e) - (x->e < y->e);
}

static double cot_at(const double *o, const double *a, const double *b)
{
    double u[3], v[3];
    for (int d = 0; d < 3; d++) {
        u[d] = a[d] - o[d];
        v[d] = b[d] - o[d];
    }
    double c[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
    double s = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    double dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    return s > 0 ? dot / s : 0;
}

/* CG on A x = b, A = D - W over the free vertices (CSR rows of free ones). */
static void solve(int n, const int *start, const int *col, const double *w, const double *diag,
                  const double *b, double *x, double *r, double *z, double *p, double *q)
{
    double bb = 0;
    for (int i = 0; i < n; i++)
        bb += b[i] * b[i];
    for (int i = 0; i < n; i++) {
        double ax = diag[i] * x[i];
        for (int k = start[i]; k < start[i + 1]; k++)
            ax -= w[k] * x[col[k]];
        r[i] = b[i] - ax;
        z[i] = r[i] / diag[i];
        p[i] = z[i];
    }
    double rz = 0;
    for (int i = 0; i < n; i++)
        rz += r[i] * z[i];
    int maxit = 10 * n + 100;
    for (int it = 0; it < maxit; it++) {
        double rr = 0;
        for (int i = 0; i < n; i++)
            rr += r[i] * r[i];
        if (rr <= 1e-24 * (bb > 0 ? bb : 1))
            break;
        double pq = 0;
        for (int i = 0; i < n; i++) {
            double a = diag[i] * p[i];
            for (int k = start[i]; k < start[i + 1]; k++)
                a -= w[k] * p[col[k]];
            q[i] = a;
            pq += p[i] * a;
        }
        if (!(pq > 0))
            break;
        double alpha = rz / pq, rz1 = 0;
        for (int i = 0; i < n; i++) {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
            z[i] = r[i] / diag[i];
            rz1 += r[i] * z[i];
        }
        double beta = rz1 / rz;
        rz = rz1;
        for (int i = 0; i < n; i++)
            p[i] = z[i] + beta * p[i];
    }
}

/* The patch's edges into list (room for 3 per face), one entry each in
 * edge order: the sum of its faces' cotangent halves, of their scales
 * (1 without scale) and their count; the number of edges. */
static int edge_weights(const mesh *m, const geo_edges *E, const fold__patch *p, const double *scale,
                        ew *list)
{
    int ne = 0;
    for (int q = 0; q < p->nf; q++) {
        int t = p->faces[q];
        const int *f = m->f + 3 * t;
        for (int k = 0; k < 3; k++) {
            list[3 * q + k].e = E->fe[3 * t + k];
            list[3 * q + k].s = scale ? scale[q] : 1;
            list[3 * q + k].nfaces = 1;
            list[3 * q + k].w = 0.5 * cot_at(m->v + 3 * f[k], m->v + 3 * f[(k + 1) % 3],
                                             m->v + 3 * f[(k + 2) % 3]);
        }
    }
    qsort(list, (size_t)p->nf * 3, sizeof(ew), cmp_ew);
    for (int i = 0; i < 3 * p->nf; i++) {       /* merge the two sides of an edge */
        if (ne && list[ne - 1].e == list[i].e) {
            list[ne - 1].w += list[i].w;
            list[ne - 1].s += list[i].s;
            list[ne - 1].nfaces++;
        } else
            list[ne++] = list[i];
    }
    return ne;
}

int fold__harmonic(const mesh *m, const geo_edges *E, const fold__patch *p,
                   const unsigned char *pin, const double *scale, int *loc, double *uv)
{
    int nv = p->nv, ne = 0, rc = -1;
    ew *list = malloc(sizeof(ew) * ((size_t)p->nf * 3 + 1));
    int *id = malloc(sizeof(int) * ((size_t)nv + 1));
    int *start = calloc((size_t)nv + 2, sizeof(int));
    int *col = NULL;
    double *w = NULL, *diag = calloc((size_t)nv + 1, sizeof(double)), *work = NULL;
    int *ea = NULL;
    if (!list || !id || !start || !diag)
        goto out;
    for (int i = 0; i < nv; i++)
        loc[p->verts[i]] = i;
    ne = edge_weights(m, E, p, scale, list);
    /* the free vertices' rows: neighbours that are free (col) or pinned (rhs) */
    int nfree = 0;
    for (int i = 0; i < nv; i++)
        id[i] = pin[i] ? -1 : nfree++;
    if (!(ea = malloc(sizeof(int) * 2 * ((size_t)ne + 1))))
        goto out;
    for (int k = 0; k < ne; k++) {
        int e = list[k].e;
        ea[2 * k] = loc[E->ev[2 * e]];
        ea[2 * k + 1] = loc[E->ev[2 * e + 1]];
        if (list[k].w < FOLD__MIN_WEIGHT)
            list[k].w = FOLD__MIN_WEIGHT;
        list[k].w *= list[k].s / list[k].nfaces;
        for (int s = 0; s < 2; s++)
            if (id[ea[2 * k + s]] >= 0)
                start[id[ea[2 * k + s]] + 1]++;
    }
    for (int i = 0; i < nfree; i++)
        start[i + 1] += start[i];
    col = malloc(sizeof(int) * ((size_t)start[nfree] + 1));
    w = malloc(sizeof(double) * ((size_t)start[nfree] + 1));
    work = malloc(sizeof(double) * 8 * ((size_t)nfree + 1));
    if (!col || !w || !work)
        goto out;
    double *b = work + 2 * (size_t)nfree, *x = work, *r = work + 4 * (size_t)nfree;
    double *z = r + nfree, *pp = z + nfree, *qq = pp + nfree;
    memset(b, 0, sizeof(double) * 2 * (size_t)nfree);
    int *at = id;   /* reuse below: fill position per free row */
    int *fill = malloc(sizeof(int) * ((size_t)nfree + 1));
    if (!fill)
        goto out;
    memcpy(fill, start, sizeof(int) * (size_t)nfree);
    for (int k = 0; k < ne; k++)
        for (int s = 0; s < 2; s++) {
            int a = ea[2 * k + s], c = ea[2 * k + 1 - s];
            if (at[a] < 0)
                continue;
            int i = at[a];
            diag[i] += list[k].w;
            if (at[c] >= 0) {
                col[fill[i]] = at[c];
                w[fill[i]++] = list[k].w;
            } else {
                col[fill[i]] = -1;           /* pinned: to the right-hand side */
                w[fill[i]++] = 0;
                b[i] += list[k].w * uv[2 * c];
                b[nfree + i] += list[k].w * uv[2 * c + 1];
            }
        }
    free(fill);
    /* drop the pinned entries (weight 0, col -1) by pointing them at i */
    for (int i = 0; i < nfree; i++)
        for (int k = start[i]; k < start[i + 1]; k++)
            if (col[k] < 0)
                col[k] = i;
    for (int d = 0; d < 2; d++) {
        for (int i = 0; i < nv; i++)
            if (id[i] >= 0)
                x[id[i]] = uv[2 * i + d];
        solve(nfree, start, col, w, diag, b + (size_t)d * nfree, x, r, z, pp, qq);
        for (int i = 0; i < nv; i++)
            if (id[i] >= 0)
                uv[2 * i + d] = x[id[i]];
    }
    rc = 0;
out:
    for (int i = 0; i < nv; i++)
        loc[p->verts[i]] = -1;
    free(list);
    free(id);
    free(start);
    free(col);
    free(w);
    free(diag);
    free(work);
    free(ea);
    return rc;
}

int fold__disk_place(const mesh *m, const geo_edges *E, const fold__patch *p, int *loc, double *uv)
{
    unsigned char *pin = calloc((size_t)p->nv + 1, 1);
    if (!pin)
        return -1;
    memset(uv, 0, sizeof(double) * 2 * (size_t)p->nv);
    /* the loop on the circle by arc length (uv[2i] holds the length run
     * up to vertex i until the angles are set) */
    double len = 0;
    for (int i = 0; i < p->nb; i++) {
        const double *a = m->v + 3 * p->verts[i], *b = m->v + 3 * p->verts[(i + 1) % p->nb];
        uv[2 * i] = len;
        len += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                    (a[2] - b[2]) * (a[2] - b[2]));
    }
    for (int i = 0; i < p->nb; i++) {
        double th = len > 0 ? 2 * M_PI * uv[2 * i] / len : 2 * M_PI * i / p->nb;
        uv[2 * i] = cos(th);
        uv[2 * i + 1] = sin(th);
        pin[i] = 1;
    }
    int rc = fold__harmonic(m, E, p, pin, NULL, loc, uv);
    free(pin);
    return rc;
}

int fold__conjugate(const mesh *m, const geo_edges *E, const fold__patch *p, const double *u,
                    int *loc, double *theta, double *flux)
{
    int nf = p->nf, rc = -1;
    ew *list = malloc(sizeof(ew) * ((size_t)nf * 3 + 1));
    int *fq = malloc(sizeof(int) * ((size_t)m->nf + 1)), *queue = malloc(sizeof(int) * ((size_t)nf + 1));
    unsigned char *seen = calloc((size_t)nf + 1, 1);
    if (!list || !fq || !queue || !seen)
        goto out;
    for (int i = 0; i < p->nv; i++)
        loc[p->verts[i]] = i;
    /* the edges' weights, as fold__harmonic takes them */
    for (int q = 0; q < nf; q++) {
        int t = p->faces[q];
        const int *f = m->f + 3 * t;
        for (int k = 0; k < 3; k++) {
            list[3 * q + k].e = E->fe[3 * t + k];
            list[3 * q + k].w = 0.5 * cot_at(m->v + 3 * f[k], m->v + 3 * f[(k + 1) % 3],
                                             m->v + 3 * f[(k + 2) % 3]);
        }
    }
    for (int t = 0; t < m->nf; t++)
        fq[t] = -1;
    for (int q = 0; q < nf; q++)
        fq[p->faces[q]] = q;
    qsort(list, (size_t)nf * 3, sizeof(ew), cmp_ew);
    int ne = 0;
    for (int i = 0; i < 3 * nf; i++) {
        if (ne && list[ne - 1].e == list[i].e)
            list[ne - 1].w += list[i].w;
        else
            list[ne++] = list[i];
    }
    for (int i = 0; i < p->nv; i++)
        flux[i] = 0;
    for (int k = 0; k < ne; k++) {
        int a = loc[E->ev[2 * list[k].e]], b = loc[E->ev[2 * list[k].e + 1]];
        double w = list[k].w < FOLD__MIN_WEIGHT ? FOLD__MIN_WEIGHT : list[k].w;
        flux[a] += w * (u[b] - u[a]);
        flux[b] += w * (u[a] - u[b]);
    }
    /* breadth first over the faces: crossing edge (a, b), a -> b as the
     * face left runs it, theta falls by w (u_b - u_a), the flux of grad u
     * through the dual edge */
    int head = 0, tail = 0;
    theta[0] = 0;
    seen[0] = 1;
    queue[tail++] = 0;
    while (head < tail) {
        int q = queue[head++], t = p->faces[q];
        const int *f = m->f + 3 * t;
        for (int k = 0; k < 3; k++) {
            int e = E->fe[3 * t + k];
            int t2 = E->ef[2 * e] == t ? E->ef[2 * e + 1] : E->ef[2 * e];
            if (t2 < 0 || t2 >= m->nf || fq[t2] < 0 || seen[fq[t2]])
                continue;
            int lo = 0, hi = ne - 1;
            while (lo < hi) {
                int mid = (lo + hi) / 2;
                if (list[mid].e < e)
                    lo = mid + 1;
                else
                    hi = mid;
            }
            double w = list[lo].w < FOLD__MIN_WEIGHT ? FOLD__MIN_WEIGHT : list[lo].w;
            int a = loc[f[(k + 1) % 3]], b = loc[f[(k + 2) % 3]];
            theta[fq[t2]] = theta[q] - w * (u[b] - u[a]);
            seen[fq[t2]] = 1;
            queue[tail++] = fq[t2];
        }
    }
    rc = tail == nf ? 0 : 1;
out:
    for (int i = 0; i < p->nv; i++)
        loc[p->verts[i]] = -1;
    free(list);
    free(fq);
    free(queue);
    free(seen);
    return rc;
}
