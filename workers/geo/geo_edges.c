/* geo_edges.c — builds the edge table by sorting half-edges (no hashing,
 * deterministic), and the vertex -> face incidence lists. Only topology: no
 * coordinates are read here. */
#include "geo/geo_edges.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

const char *geo_strerror(int code)
{
    switch (code) { GEO_ERRORS(ERRLIST_CASE) }
    return "unknown geometry error";
}

typedef struct { int a, b, face, corner; } half;

static int half_cmp(const void *x, const void *y)
{
    const half *p = x, *q = y;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    if (p->b != q->b) return p->b < q->b ? -1 : 1;
    if (p->face != q->face) return p->face < q->face ? -1 : 1;
    return 0;
}

void geo_edges_close(geo_edges *e)
{
    if (!e)
        return;
    free(e->ev); free(e->ef); free(e->eo); free(e->fe);
    free(e->vf_start); free(e->vf_face); free(e->vf_corner);
    memset(e, 0, sizeof *e);
}

int geo_edges_build(const mesh *m, geo_edges *out, char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    size_t nh = (size_t)m->nf * 3;
    half *h = malloc((nh + 1) * sizeof *h);
    int rc = GEO_ENOMEM;
    out->nv = m->nv;
    out->nf = m->nf;
    out->fe = malloc((nh + 1) * sizeof *out->fe);
    out->vf_start = calloc((size_t)m->nv + 1, sizeof *out->vf_start);
    out->vf_face = malloc((nh + 1) * sizeof *out->vf_face);
    out->vf_corner = malloc((nh + 1) * sizeof *out->vf_corner);
    if (!h || !out->fe || !out->vf_start || !out->vf_face || !out->vf_corner)
        goto fail;
    for (int t = 0; t < m->nf; t++)
        for (int k = 0; k < 3; k++) {
            int i = m->f[3 * t + (k + 1) % 3], j = m->f[3 * t + (k + 2) % 3];
            half *x = &h[3 * t + k];
            x->a = i < j ? i : j;
            x->b = i < j ? j : i;
            x->face = t;
            x->corner = k;
        }
    qsort(h, nh, sizeof *h, half_cmp);
    int ne = 0;
    for (size_t s = 0; s < nh; ne++) {
        size_t r = s + 1;
        while (r < nh && h[r].a == h[s].a && h[r].b == h[s].b)
            r++;
        if (r - s > 2) {
            rc = errbuf_set(err, errsz, GEO_ENONMANIFOLD,
                            "edge (%d, %d) has %zu faces (first: %d, %d, %d)",
                            h[s].a, h[s].b, r - s, h[s].face, h[s + 1].face, h[s + 2].face);
            goto fail;
        }
        s = r;
    }
    out->ne = ne;
    out->ev = malloc((size_t)(2 * ne + 1) * sizeof(int));
    out->ef = malloc((size_t)(2 * ne + 1) * sizeof(int));
    out->eo = malloc((size_t)(2 * ne + 1) * sizeof(int));
    if (!out->ev || !out->ef || !out->eo)
        goto fail;
    int e = 0;
    for (size_t s = 0; s < nh; e++) {
        size_t r = s + 1;
        while (r < nh && h[r].a == h[s].a && h[r].b == h[s].b)
            r++;
        out->ev[2 * e] = h[s].a;
        out->ev[2 * e + 1] = h[s].b;
        for (int side = 0; side < 2; side++) {
            if (s + (size_t)side < r) {
                const half *x = &h[s + side];
                out->ef[2 * e + side] = x->face;
                out->eo[2 * e + side] = m->f[3 * x->face + x->corner];
                out->fe[3 * x->face + x->corner] = e;
            } else {
                out->ef[2 * e + side] = -1;
                out->eo[2 * e + side] = -1;
            }
        }
        s = r;
    }
    for (size_t k = 0; k < nh; k++)
        out->vf_start[m->f[k] + 1]++;
    for (int i = 0; i < m->nv; i++)
        out->vf_start[i + 1] += out->vf_start[i];
    int *fill = calloc((size_t)m->nv + 1, sizeof *fill);
    if (!fill)
        goto fail;
    for (int t = 0; t < m->nf; t++)  /* faces in increasing order: sorted lists */
        for (int k = 0; k < 3; k++) {
            int i = m->f[3 * t + k];
            int at = out->vf_start[i] + fill[i]++;
            out->vf_face[at] = t;
            out->vf_corner[at] = k;
        }
    free(fill);
    free(h);
    return GEO_OK;
fail:
    if (rc == GEO_ENOMEM)
        errbuf_set(err, errsz, rc, "out of memory building the edge table");
    free(h);
    geo_edges_close(out);
    return rc;
}

int geo_edges_boundary_count(const geo_edges *e)
{
    int n = 0;
    for (int i = 0; i < e->ne; i++)
        n += e->ef[2 * i + 1] < 0;
    return n;
}
