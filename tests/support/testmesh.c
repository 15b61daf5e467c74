/* testmesh.c — generated test meshes; see testmesh.h. Consistently oriented
 * (outward normals for the closed ones, +z for the disk). */
#include "support/testmesh.h"
#include "support/harness.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

mesh *testmesh_read(const char *rel)
{
    char err[512];
    mesh *m = NULL;
    if (mesh_read(harness_data_path(rel), &m, err, sizeof err) != 0)
        FAILF("%s", err);
    return m;
}

double testmesh_rand(unsigned long long *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (double)(*s >> 11) / 9007199254740992.0;
}

bmap *testmesh_identity(const mesh *X)
{
    bmap *I = bmap_new(X->nv, X->nv);
    if (!I)
        return NULL;
    for (int t = 0; t < X->nf; t++)
        for (int k = 0; k < 3; k++) {
            int v = X->f[3 * t + k];
            I->face[v] = t;
            for (int j = 0; j < 3; j++)
                I->w[3 * v + j] = j == k;
        }
    return I;
}

double testmesh_mean_edge(const mesh *X)
{
    double edge = 0;
    for (int t = 0; t < X->nf; t++) {
        const double *a = X->v + 3 * X->f[3 * t], *b = X->v + 3 * X->f[3 * t + 1];
        edge += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2]));
    }
    return X->nf ? edge / X->nf : 0;
}

static int midpoint(double *v, int *nv, int *key_a, int *key_b, int *key_m, int *nk, int a, int b)
{
    int lo = a < b ? a : b, hi = a < b ? b : a;
    for (int k = 0; k < *nk; k++)
        if (key_a[k] == lo && key_b[k] == hi)
            return key_m[k];
    int m = (*nv)++;
    double x = v[3 * a] + v[3 * b], y = v[3 * a + 1] + v[3 * b + 1], z = v[3 * a + 2] + v[3 * b + 2];
    double n = sqrt(x * x + y * y + z * z);
    v[3 * m] = x / n; v[3 * m + 1] = y / n; v[3 * m + 2] = z / n;
    key_a[*nk] = lo; key_b[*nk] = hi; key_m[*nk] = m; (*nk)++;
    return m;
}

mesh *testmesh_icosphere(int level)
{
    const double t = (1.0 + sqrt(5.0)) / 2.0;
    const double iv[12][3] = {
        {-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
        {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    const int ifc[20][3] = {
        {0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
        {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    int nvmax = 10 * (1 << (2 * level)) + 2, nfmax = 20 * (1 << (2 * level));
    double *v = malloc(sizeof(double) * 3 * nvmax);
    int *f = malloc(sizeof(int) * 3 * nfmax);
    int nv = 12, nf = 20;
    for (int i = 0; i < 12; i++) {
        double n = sqrt(iv[i][0] * iv[i][0] + iv[i][1] * iv[i][1] + iv[i][2] * iv[i][2]);
        for (int k = 0; k < 3; k++) v[3 * i + k] = iv[i][k] / n;
    }
    memcpy(f, ifc, sizeof ifc);
    for (int l = 0; l < level; l++) {
        int ne = nf * 3 / 2;
        int *ka = malloc(sizeof(int) * ne), *kb = malloc(sizeof(int) * ne), *km = malloc(sizeof(int) * ne);
        int nk = 0;
        int *g = malloc(sizeof(int) * 12 * nf);
        for (int i = 0; i < nf; i++) {
            int a = f[3 * i], b = f[3 * i + 1], c = f[3 * i + 2];
            int ab = midpoint(v, &nv, ka, kb, km, &nk, a, b);
            int bc = midpoint(v, &nv, ka, kb, km, &nk, b, c);
            int ca = midpoint(v, &nv, ka, kb, km, &nk, c, a);
            int q[12] = {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca};
            memcpy(g + 12 * i, q, sizeof q);
        }
        memcpy(f, g, sizeof(int) * 12 * nf);
        nf *= 4;
        free(g); free(ka); free(kb); free(km);
    }
    mesh *m = mesh_new(nv, nf);
    memcpy(m->v, v, sizeof(double) * 3 * nv);
    memcpy(m->f, f, sizeof(int) * 3 * nf);
    free(v);
    free(f);
    return m;
}

mesh *testmesh_torus(double R, double r, int nu, int nv)
{
    mesh *m = mesh_new(nu * nv, 2 * nu * nv);
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            double u = 2 * M_PI * i / nu, w = 2 * M_PI * j / nv;
            double *p = m->v + 3 * (i * nv + j);
            p[0] = (R + r * cos(w)) * cos(u);
            p[1] = (R + r * cos(w)) * sin(u);
            p[2] = r * sin(w);
        }
    int t = 0;
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            int a = i * nv + j, b = ((i + 1) % nu) * nv + j;
            int c = ((i + 1) % nu) * nv + (j + 1) % nv, d = i * nv + (j + 1) % nv;
            int q[6] = {a, b, c, a, c, d};
            memcpy(m->f + 6 * t++, q, sizeof q);
        }
    return m;
}

mesh *testmesh_spheroid(double length, int rings, int around)
{
    int nv = rings * around + 2, nf = 2 * around * rings;
    mesh *m = mesh_new(nv, nf);
    for (int k = 0; k < rings; k++)
        for (int j = 0; j < around; j++) {
            double t = M_PI * (k + 1) / (rings + 1), u = 2 * M_PI * j / around;
            double *p = m->v + 3 * (k * around + j);
            p[0] = sin(t) * cos(u);
            p[1] = sin(t) * sin(u);
            p[2] = length * (k + 1) / (rings + 1);
        }
    int s = rings * around, n = s + 1;   /* the poles: z = 0 and z = length */
    m->v[3 * s] = m->v[3 * s + 1] = m->v[3 * s + 2] = 0;
    m->v[3 * n] = m->v[3 * n + 1] = 0;
    m->v[3 * n + 2] = length;
    int t = 0;
    for (int j = 0; j < around; j++) {
        int j1 = (j + 1) % around;
        int q[3] = { s, j1, j };
        memcpy(m->f + 3 * t++, q, sizeof q);
        int r[3] = { n, (rings - 1) * around + j, (rings - 1) * around + j1 };
        memcpy(m->f + 3 * t++, r, sizeof r);
    }
    for (int k = 0; k + 1 < rings; k++)
        for (int j = 0; j < around; j++) {
            int a = k * around + j, b = k * around + (j + 1) % around;
            int c = (k + 1) * around + (j + 1) % around, d = (k + 1) * around + j;
            int q[6] = { a, b, c, a, c, d };
            memcpy(m->f + 3 * t, q, sizeof q);
            t += 2;
        }
    return m;
}

mesh *testmesh_disk(int rings)
{
    /* ring k (1..rings) has 6k vertices; centre vertex 0 */
    int nv = 1 + 3 * rings * (rings + 1), nf = 6 * rings * rings;
    mesh *m = mesh_new(nv, nf);
    int *start = malloc(sizeof(int) * (rings + 1));
    start[0] = 0;
    int at = 1;
    for (int k = 1; k <= rings; k++) {
        start[k] = at;
        for (int j = 0; j < 6 * k; j++, at++) {
            double a = 2 * M_PI * j / (6 * k);
            m->v[3 * at] = (double)k / rings * cos(a);
            m->v[3 * at + 1] = (double)k / rings * sin(a);
        }
    }
    int t = 0;
    for (int k = 1; k <= rings; k++) {
        int nout = 6 * k, nin = 6 * (k - 1);
        int i = 0, o = 0;  /* walk both rings, emitting triangles by angle */
        while (o < nout || i < nin) {
            int ov = start[k] + o % nout, ov1 = start[k] + (o + 1) % nout;
            int iv = k == 1 ? 0 : start[k - 1] + i % nin;
            int iv1 = k == 1 ? 0 : start[k - 1] + (i + 1) % nin;
            /* advance the ring whose next vertex has the smaller angle */
            double ao = (double)(o + 1) / nout, ai = nin ? (double)(i + 1) / nin : 2.0;
            if (o < nout && (ao <= ai || i >= nin)) {
                int q[3] = {iv, ov, ov1};
                memcpy(m->f + 3 * t++, q, sizeof q);
                o++;
            } else {
                int q[3] = {iv, ov, iv1};
                memcpy(m->f + 3 * t++, q, sizeof q);
                i++;
            }
        }
    }
    free(start);
    m->nf = t;
    return m;
}

/* Open addressing over edges (lo, hi): slot -> the midpoint's vertex. */
static int edge_midpoint(long long *key, int *val, size_t cap, mesh *out, int *nv, const mesh *m,
                         int a, int b)
{
    long long lo = a < b ? a : b, hi = a < b ? b : a, k = lo * (long long)m->nv + hi;
    size_t h = (size_t)(k * 0x9E3779B97F4A7C15ULL) & (cap - 1);
    while (key[h] >= 0 && key[h] != k)
        h = (h + 1) & (cap - 1);
    if (key[h] == k)
        return val[h];
    key[h] = k;
    val[h] = (*nv)++;
    for (int c = 0; c < 3; c++)
        out->v[3 * val[h] + c] = 0.5 * (m->v[3 * a + c] + m->v[3 * b + c]);
    return val[h];
}

mesh *testmesh_subdivided(const mesh *m)
{
    size_t cap = 1;
    while (cap < 4 * (size_t)m->nf)   /* at most 3 nf edges: load below 3/4 */
        cap <<= 1;
    long long *key = malloc(sizeof *key * cap);
    int *val = malloc(sizeof *val * cap);
    mesh *out = mesh_new(m->nv + 3 * m->nf, 4 * m->nf);  /* nv shrunk below */
    if (!key || !val || !out) {
        free(key);
        free(val);
        mesh_free(out);
        return NULL;
    }
    for (size_t h = 0; h < cap; h++)
        key[h] = -1;
    memcpy(out->v, m->v, sizeof(double) * 3 * (size_t)m->nv);
    int nv = m->nv;
    for (int t = 0; t < m->nf; t++) {
        int a = m->f[3 * t], b = m->f[3 * t + 1], c = m->f[3 * t + 2];
        int ab = edge_midpoint(key, val, cap, out, &nv, m, a, b);
        int bc = edge_midpoint(key, val, cap, out, &nv, m, b, c);
        int ca = edge_midpoint(key, val, cap, out, &nv, m, c, a);
        int q[12] = { a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca };
        memcpy(out->f + 12 * (size_t)t, q, sizeof q);
    }
    out->nv = nv;
    free(key);
    free(val);
    return out;
}

mesh *testmesh_mirrored(const mesh *m)
{
    mesh *r = mesh_new(m->nv, m->nf);
    if (!r)
        return NULL;
    memcpy(r->v, m->v, sizeof(double) * 3 * (size_t)m->nv);
    for (int v = 0; v < m->nv; v++)
        r->v[3 * v] = -r->v[3 * v];
    for (int t = 0; t < m->nf; t++) {
        r->f[3 * t] = m->f[3 * t];
        r->f[3 * t + 1] = m->f[3 * t + 2];
        r->f[3 * t + 2] = m->f[3 * t + 1];
    }
    return r;
}
