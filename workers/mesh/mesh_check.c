/* mesh_check.c — see mesh_check.h. Half-edges sorted by vertex pair give the
 * edge table; union-find over vertices of faces gives components, over corners gives the
 * fans around each vertex, over vertices on boundary edges gives loops.
 * Reports only; never changes or repairs the mesh. */
#include "mesh/mesh_check.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct half {
    int a, b;      /* a < b */
    int face;
    int ca, cb;    /* corners (3*face+k) of a and b in face */
    int forward;   /* 1 when the face goes a -> b */
} half;

static int half_cmp(const void *x, const void *y)
{
    const half *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return p->face < q->face ? -1 : p->face > q->face;
}

typedef struct tri_key { int s[3]; int face; } tri_key;

static int tri_cmp(const void *x, const void *y)
{
    const tri_key *p = x, *q = y;
    for (int k = 0; k < 3; k++)
        if (p->s[k] != q->s[k])
            return p->s[k] < q->s[k] ? -1 : 1;
    return p->face < q->face ? -1 : p->face > q->face;
}

/* Sorts n elements of size sz whose first member is an int key in
 * [0, nkeys) into the order of qsort with cmp, where cmp compares that key
 * first: a counting sort by key (O(n + nkeys)), then each bucket (a vertex's
 * half-edges or faces: a few) by insertion, or by qsort when it is large, so
 * a hostile fan stays O(n log n). Falls back to qsort without memory. */
static void key_sort(void *base, size_t n, size_t sz, int nkeys, int (*cmp)(const void *, const void *))
{
    char *a = base, *tmp = malloc(n * sz + 1);
    size_t *start = calloc((size_t)nkeys + 2, sizeof *start);
    if (!tmp || !start) {
        free(tmp);
        free(start);
        qsort(base, n, sz, cmp);
        return;
    }
    for (size_t i = 0; i < n; i++)
        start[*(const int *)(a + i * sz) + 2]++;
    for (int k = 2; k < nkeys + 2; k++)
        start[k] += start[k - 1];
    for (size_t i = 0; i < n; i++)          /* start[k + 1]: next slot of key k */
        memcpy(tmp + start[*(const int *)(a + i * sz) + 1]++ * sz, a + i * sz, sz);
    memcpy(a, tmp, n * sz);
    for (int k = 0; k < nkeys; k++) {       /* bucket k is [start[k], start[k + 1]) */
        size_t lo = start[k], m = start[k + 1] - lo;
        char *b = a + lo * sz;
        if (m > 16) {
            qsort(b, m, sz, cmp);
            continue;
        }
        for (size_t i = 1; i < m; i++) {
            memcpy(tmp, b + i * sz, sz);
            size_t j = i;
            for (; j > 0 && cmp(b + (j - 1) * sz, tmp) > 0; j--)
                memcpy(b + j * sz, b + (j - 1) * sz, sz);
            memcpy(b + j * sz, tmp, sz);
        }
    }
    free(tmp);
    free(start);
}

static int uf_find(int *par, int x)
{
    while (par[x] != x) {
        par[x] = par[par[x]];
        x = par[x];
    }
    return x;
}

static void uf_union(int *par, int x, int y)
{
    x = uf_find(par, x);
    y = uf_find(par, y);
    if (x != y)
        par[x < y ? y : x] = x < y ? x : y;
}

static void sort3(int *s)
{
    int t;
    if (s[0] > s[1]) { t = s[0]; s[0] = s[1]; s[1] = t; }
    if (s[1] > s[2]) { t = s[1]; s[1] = s[2]; s[2] = t; }
    if (s[0] > s[1]) { t = s[0]; s[0] = s[1]; s[1] = t; }
}

double mesh_face_area(const double *v, const int *f, int *degenerate)
{
    const double *p = v + 3 * (size_t)f[0], *q = v + 3 * (size_t)f[1], *s = v + 3 * (size_t)f[2];
    double u[3], w[3], d[3];
    for (int k = 0; k < 3; k++) {
        u[k] = q[k] - p[k];
        w[k] = s[k] - p[k];
        d[k] = s[k] - q[k];
    }
    double c0 = u[1] * w[2] - u[2] * w[1], c1 = u[2] * w[0] - u[0] * w[2],
           c2 = u[0] * w[1] - u[1] * w[0];
    double twice = sqrt(c0 * c0 + c1 * c1 + c2 * c2);
    double l = fmax(fmax(u[0] * u[0] + u[1] * u[1] + u[2] * u[2],
                         w[0] * w[0] + w[1] * w[1] + w[2] * w[2]),
                    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (degenerate)
        *degenerate = f[0] == f[1] || f[1] == f[2] || f[0] == f[2] || !(twice > 2e-12 * l);
    return 0.5 * twice;
}

/* The report before any counting: sizes, no genus, every "first" at -1. */
static void report_init(const mesh *m, mesh_check_report *r)
{
    memset(r, 0, sizeof *r);
    r->nv = m->nv;
    r->nf = m->nf;
    r->genus = -1;
    r->first_bad_index_face = r->first_nonfinite_vertex = r->first_nonmanifold_vertex = -1;
    r->first_degenerate_face = r->first_unreferenced_vertex = -1;
    r->first_nonmanifold_edge[0] = r->first_nonmanifold_edge[1] = -1;
    r->first_duplicate_pair[0] = r->first_duplicate_pair[1] = -1;
    r->first_inconsistent_edge[0] = r->first_inconsistent_edge[1] = -1;
}

/* Non-finite vertices, and the bounding box of the finite ones. */
static void check_vertices(const mesh *m, mesh_check_report *r)
{
    int first = 1;
    for (int i = 0; i < m->nv; i++) {
        const double *p = m->v + 3 * i;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
            if (r->nonfinite_vertices++ == 0)
                r->first_nonfinite_vertex = i;
            continue;
        }
        for (int k = 0; k < 3; k++) {
            if (first || p[k] < r->bbox_min[k])
                r->bbox_min[k] = p[k];
            if (first || p[k] > r->bbox_max[k])
                r->bbox_max[k] = p[k];
        }
        first = 0;
    }
}

/* Faces: index range, degeneracy, area; marks the vertices they use, keys
 * each face in range by its sorted vertices (tk, *ntk) and gathers the
 * half-edges (h, *nh) of those without a repeated vertex (ok). */
static void check_faces(const mesh *m, mesh_check_report *r, int *used, tri_key *tk, int *ntk,
                        half *h, int *nh, char *ok)
{
    const int nv = m->nv, nf = m->nf;
    *nh = *ntk = 0;
    for (int t = 0; t < nf; t++) {
        const int *f = m->f + 3 * t;
        if (f[0] < 0 || f[0] >= nv || f[1] < 0 || f[1] >= nv || f[2] < 0 || f[2] >= nv) {
            if (r->bad_index_faces++ == 0)
                r->first_bad_index_face = t;
            continue;
        }
        for (int k = 0; k < 3; k++)
            used[f[k]] = 1;
        int degenerate;
        double a = mesh_face_area(m->v, m->f + 3 * (size_t)t, &degenerate);
        if (isfinite(a))
            r->area += a;
        if (degenerate && r->degenerate_faces++ == 0)
            r->first_degenerate_face = t;
        tk[*ntk].face = t;
        memcpy(tk[*ntk].s, f, sizeof tk[*ntk].s);
        sort3(tk[*ntk].s);
        (*ntk)++;
        if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2])
            continue;  /* repeated vertex: no meaningful edges */
        ok[t] = 1;
        for (int k = 0; k < 3; k++) {
            int a0 = f[k], b0 = f[(k + 1) % 3];
            half *e = &h[(*nh)++];
            e->face = t;
            e->forward = a0 < b0;
            e->a = e->forward ? a0 : b0;
            e->b = e->forward ? b0 : a0;
            e->ca = 3 * t + (e->forward ? k : (k + 1) % 3);
            e->cb = 3 * t + (e->forward ? (k + 1) % 3 : k);
        }
    }
}

/* Edges: groups the nh half-edges, sorted by vertex pair, into edges,
 * counting the boundary (onb, vpar: its loops), non-manifold and
 * inconsistently oriented ones, and joins the corners each edge glues
 * (cpar). */
static void check_edges(const half *h, int nh, mesh_check_report *r, char *onb, int *vpar, int *cpar)
{
    for (int i = 0; i < nh;) {
        int j = i;
        while (j < nh && h[j].a == h[i].a && h[j].b == h[i].b)
            j++;
        int n = j - i;
        r->ne++;
        if (n == 1) {
            onb[h[i].a] = onb[h[i].b] = 1;
            uf_union(vpar, h[i].a, h[i].b);
        } else if (n > 2) {
            if (r->nonmanifold_edges++ == 0) {
                r->first_nonmanifold_edge[0] = h[i].a;
                r->first_nonmanifold_edge[1] = h[i].b;
            }
        } else if (h[i].forward == h[i + 1].forward && r->inconsistent_edges++ == 0) {
            r->first_inconsistent_edge[0] = h[i].a;
            r->first_inconsistent_edge[1] = h[i].b;
        }
        for (int k = i + 1; k < j; k++) {
            uf_union(cpar, h[i].ca, h[k].ca);
            uf_union(cpar, h[i].cb, h[k].cb);
        }
        i = j;
    }
}

/* Fans: the corner sets of a vertex (fans: a count per vertex); more than
 * one is a pinch. Counts the components and boundary loops too. */
static void check_fans(const mesh *m, mesh_check_report *r, const char *ok, int *cpar, int *comp,
                       const char *onb, int *vpar, int *fans)
{
    const int nv = m->nv, nf = m->nf;
    memset(fans, 0, sizeof *fans * (size_t)nv);
    for (int t = 0; t < nf; t++) {
        if (!ok[t])
            continue;
        for (int k = 0; k < 3; k++)
            if (uf_find(cpar, 3 * t + k) == 3 * t + k)
                fans[m->f[3 * t + k]]++;
    }
    for (int i = 0; i < nv; i++) {
        if (fans[i] > 0 && uf_find(comp, i) == i)
            r->components++;
        if (fans[i] > 1 && r->nonmanifold_vertices++ == 0)
            r->first_nonmanifold_vertex = i;
        if (onb[i] && uf_find(vpar, i) == i)
            r->boundary_loops++;
    }
}

int mesh_check_run(const mesh *m, mesh_check_report *r, char *err, size_t errsz)
{
    report_init(m, r);
    int rc = MESH_CHECK_OK;
    const int nv = m->nv, nf = m->nf;
    char *ok = calloc((size_t)nf + 1, 1);           /* face usable for topology */
    int *used = calloc((size_t)nv + 1, sizeof *used);
    half *h = malloc(sizeof *h * (3 * (size_t)nf + 1));
    tri_key *tk = malloc(sizeof *tk * ((size_t)nf + 1));
    int *comp = malloc(sizeof *comp * ((size_t)nv + 1));
    int *cpar = malloc(sizeof *cpar * (3 * (size_t)nf + 1));
    int *vpar = malloc(sizeof *vpar * ((size_t)nv + 1));
    char *onb = calloc((size_t)nv + 1, 1);
    if (!ok || !used || !h || !tk || !comp || !cpar || !vpar || !onb) {
        rc = errbuf_set(err, errsz, MESH_CHECK_ENOMEM, "out of memory checking a mesh of %d vertices",
                        nv);
        goto out;
    }

    check_vertices(m, r);
    int nh, ntk;
    check_faces(m, r, used, tk, &ntk, h, &nh, ok);
    int nrefd = 0;
    for (int i = 0; i < nv; i++) {
        if (used[i])
            nrefd++;
        else if (r->unreferenced_vertices++ == 0)
            r->first_unreferenced_vertex = i;
    }

    key_sort(tk, (size_t)ntk, sizeof *tk, nv, tri_cmp);    /* by s[0], then the rest */
    for (int i = 1; i < ntk; i++)
        if (memcmp(tk[i].s, tk[i - 1].s, sizeof tk[i].s) == 0 && r->duplicate_faces++ == 0) {
            r->first_duplicate_pair[0] = tk[i - 1].face;
            r->first_duplicate_pair[1] = tk[i].face;
        }

    /* Edges: group the sorted half-edges by vertex pair. */
    key_sort(h, (size_t)nh, sizeof *h, nv, half_cmp);      /* by a, then b, face */
    for (int i = 0; i < nv; i++)
        comp[i] = i;
    for (int t = 0; t < nf; t++)
        if (ok[t]) {
            uf_union(comp, m->f[3 * t], m->f[3 * t + 1]);
            uf_union(comp, m->f[3 * t], m->f[3 * t + 2]);
        }
    for (int c = 0; c < 3 * nf; c++)
        cpar[c] = c;
    for (int i = 0; i < nv; i++)
        vpar[i] = i;
    check_edges(h, nh, r, onb, vpar, cpar);
    check_fans(m, r, ok, cpar, comp, onb, vpar, used);  /* used, reused: per-vertex fan count */
    r->euler = (long)nrefd - r->ne + (nf - r->bad_index_faces);
    if (r->components == 1 && r->nonmanifold_edges == 0 && r->nonmanifold_vertices == 0
        && r->bad_index_faces == 0)
        r->genus = (int)((2 - r->euler - r->boundary_loops) / 2);
out:
    free(ok);
    free(used);
    free(h);
    free(tk);
    free(comp);
    free(cpar);
    free(vpar);
    free(onb);
    return rc;
}

int mesh_check_usable(const mesh_check_report *r)
{
    return r->nf > 0 && r->components == 1 && r->bad_index_faces == 0
        && r->nonfinite_vertices == 0 && r->nonmanifold_edges == 0
        && r->nonmanifold_vertices == 0 && r->degenerate_faces == 0
        && r->duplicate_faces == 0 && r->unreferenced_vertices == 0
        && r->inconsistent_edges == 0;
}

typedef struct out_buf { char *p; size_t left; int lines; } out_buf;

static void line(out_buf *o, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void line(out_buf *o, const char *path, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    o->lines++;
    if (o->left <= 1)
        return;
    int n = snprintf(o->p, o->left, "%s: %s\n", path, msg);
    size_t used = n < 0 ? 0 : (size_t)n < o->left ? (size_t)n : o->left - 1;
    o->p += used;
    o->left -= used;
}

int mesh_check_problems(const mesh_check_report *r, const char *path, char *out, size_t outsz)
{
    out_buf o = { out, outsz, 0 };
    if (out && outsz)
        out[0] = '\0';
    else
        o.left = 0;
    if (r->nf == 0)
        line(&o, path, "the mesh has no faces");
    if (r->bad_index_faces)
        line(&o, path, "%d faces with a vertex index out of range [0, %d), first face %d",
             r->bad_index_faces, r->nv, r->first_bad_index_face);
    if (r->nonfinite_vertices)
        line(&o, path, "%d vertices with a NaN or infinite coordinate, first vertex %d",
             r->nonfinite_vertices, r->first_nonfinite_vertex);
    if (r->nonmanifold_edges)
        line(&o, path, "%d non-manifold edges (more than two faces), first edge %d-%d",
             r->nonmanifold_edges, r->first_nonmanifold_edge[0], r->first_nonmanifold_edge[1]);
    if (r->nonmanifold_vertices)
        line(&o, path, "%d non-manifold vertices (faces around them form more than one fan), "
             "first vertex %d", r->nonmanifold_vertices, r->first_nonmanifold_vertex);
    if (r->degenerate_faces)
        line(&o, path, "%d degenerate (zero-area) faces, first face %d",
             r->degenerate_faces, r->first_degenerate_face);
    if (r->duplicate_faces)
        line(&o, path, "%d duplicate faces (same vertex set), first pair faces %d and %d",
             r->duplicate_faces, r->first_duplicate_pair[0], r->first_duplicate_pair[1]);
    if (r->unreferenced_vertices)
        line(&o, path, "%d unreferenced vertices (in no face), first vertex %d",
             r->unreferenced_vertices, r->first_unreferenced_vertex);
    if (r->components > 1)
        line(&o, path, "%d connected components; one is needed", r->components);
    if (r->inconsistent_edges)
        line(&o, path, "inconsistent orientation on %d edges, first edge %d-%d",
             r->inconsistent_edges, r->first_inconsistent_edge[0], r->first_inconsistent_edge[1]);
    return o.lines;
}
