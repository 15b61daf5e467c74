/* mesh_faces.c — see mesh__faces.h: the faces a reader collects, and the
 * split of a polygon into triangles. A quad is cut along the diagonal that
 * folds it least (the shorter one when it is nearly flat); a larger polygon
 * by ear clipping in the plane of its Newell normal, and one with no ear
 * left (degenerate, or crossing itself) by a fan, whose slivers the repair
 * then removes. Every triangle keeps the polygon's orientation. */
#include "mesh/mesh__faces.h"

#include "util/errbuf.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Two splits of a quad whose normals' cosines differ by at most this
 * (about 8 degrees of fold near flat) count as equally flat. */
#define QUAD_AGREE 0.01

void mesh__faces_init(mesh__faces *F, long n)
{
    memset(F, 0, sizeof *F);
    if (n > 0 && n <= MESH_MAX_FACES && (F->tri = malloc(sizeof(int) * 3 * (size_t)n)))
        F->cap = n;
}

void mesh__faces_free(mesh__faces *F)
{
    free(F->tri);
    free(F->corner);
    free(F->poly);
    memset(F, 0, sizeof *F);
}

/* Grows *p (elements of size sz) to hold at least need, doubling. */
static int grow(void **p, long *cap, long need, size_t sz)
{
    if (need <= *cap)
        return 0;
    long c = *cap ? *cap : 64;
    while (c < need)
        c *= 2;
    void *q = realloc(*p, sz * (size_t)c);
    if (!q)
        return -1;
    *p = q;
    *cap = c;
    return 0;
}

int mesh__faces_add(mesh__faces *F, const int *c, int k)
{
    if (F->ntri + (k - 2) > MESH_MAX_FACES)
        return MESH_ELIMIT;
    if (grow((void **)&F->tri, &F->cap, F->ntri + (k - 2), 3 * sizeof(int)))
        return MESH_ENOMEM;
    if (k == 3) {
        memcpy(F->tri + 3 * F->ntri++, c, 3 * sizeof(int));
        return MESH_OK;
    }
    if (grow((void **)&F->corner, &F->cap_corner, F->ncorner + k, sizeof(int)) ||
        grow((void **)&F->poly, &F->cap_poly, F->npoly + 1, 3 * sizeof(long)))
        return MESH_ENOMEM;
    long *p = F->poly + 3 * F->npoly++;
    p[0] = F->ntri;
    p[1] = F->ncorner;
    p[2] = k;
    memcpy(F->corner + F->ncorner, c, sizeof(int) * (size_t)k);
    memset(F->tri + 3 * F->ntri, 0, sizeof(int) * 3 * (size_t)(k - 2));
    F->ncorner += k;
    F->ntri += k - 2;
    return MESH_OK;
}

int mesh__faces_error(int rc, const char *path, long line, char *err, size_t errsz)
{
    char at[32] = "";
    if (line > 0)
        snprintf(at, sizeof at, ":%ld", line);
    if (rc == MESH_ELIMIT)
        return errbuf_set(err, errsz, rc, "%s%s: over the limit of %d triangles once its polygons are split",
                          path, at, MESH_MAX_FACES);
    return errbuf_set(err, errsz, rc, "%s%s: out of memory", path, at);
}

static void sub(const double *a, const double *b, double *d)
{
    for (int i = 0; i < 3; i++)
        d[i] = a[i] - b[i];
}

static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross(const double *a, const double *b, double *d)
{
    d[0] = a[1] * b[2] - a[2] * b[1];
    d[1] = a[2] * b[0] - a[0] * b[2];
    d[2] = a[0] * b[1] - a[1] * b[0];
}

/* Twice the signed area of 2-D triangle (a, b, c): positive counter-clockwise. */
static double area2(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

static void emit(int **out, int a, int b, int c)
{
    (*out)[0] = a;
    (*out)[1] = b;
    (*out)[2] = c;
    *out += 3;
}

/* Ear clipping of the k corners c with 2-D positions q (counter-clockwise
 * when the polygon is oriented along its normal): k - 2 triangles into out.
 * at: scratch of k ints. */
static void clip_ears(const int *c, const double *q, int k, int *at, int *out)
{
    int n = k, from = 0;
    for (int i = 0; i < k; i++)
        at[i] = i;
    while (n > 3) {
        int found = -1;
        for (int s = 0; s < n && found < 0; s++) {   /* from the last ear on: its neighbours */
            int i = (from + s) % n;
            int a = at[(i + n - 1) % n], b = at[i], d = at[(i + 1) % n];
            if (area2(q + 2 * a, q + 2 * b, q + 2 * d) <= 0)
                continue;   /* reflex or flat: not an ear */
            int inside = 0;
            for (int j = 0; j < n && !inside; j++) {
                int e = at[j];
                if (e == a || e == b || e == d || c[e] == c[a] || c[e] == c[b] || c[e] == c[d])
                    continue;
                inside = area2(q + 2 * a, q + 2 * b, q + 2 * e) >= 0 &&
                         area2(q + 2 * b, q + 2 * d, q + 2 * e) >= 0 &&
                         area2(q + 2 * d, q + 2 * a, q + 2 * e) >= 0;
            }
            if (!inside)
                found = i;
        }
        if (found < 0)
            break;   /* no ear: the rest as a fan */
        emit(&out, c[at[(found + n - 1) % n]], c[at[found]], c[at[(found + 1) % n]]);
        memmove(at + found, at + found + 1, sizeof(int) * (size_t)(n - found - 1));
        n--;
        from = found > 0 ? found - 1 : 0;
    }
    for (int i = 1; i + 1 < n; i++)
        emit(&out, c[at[0]], c[at[i]], c[at[i + 1]]);
}

/* How well the triangles (a, b, c) and (a, c, d) of a quad split along
 * a-c agree: the cosine between their normals, -2 when one has no area. */
static double agreement(const double *v, int a, int b, int c, int d)
{
    double e1[3], e2[3], e3[3], n1[3], n2[3];
    sub(v + 3 * (size_t)b, v + 3 * (size_t)a, e1);
    sub(v + 3 * (size_t)c, v + 3 * (size_t)a, e2);
    sub(v + 3 * (size_t)d, v + 3 * (size_t)a, e3);
    cross(e1, e2, n1);
    cross(e2, e3, n2);
    double l = sqrt(dot(n1, n1) * dot(n2, n2));
    return l > 0 ? dot(n1, n2) / l : -2;
}

/* Quad c as two triangles at out: (0 1 2)(0 2 3) along02, else (1 2 3)(1 3 0). */
static void cut_quad(const int *c, int along02, int *out)
{
    int s = along02 ? 0 : 1;
    emit(&out, c[s], c[s + 1], c[(s + 2) % 4]);
    emit(&out, c[s], c[(s + 2) % 4], c[(s + 3) % 4]);
}

/* Quad c into two triangles at out: along the diagonal whose triangles
 * agree better (a concave quad's other diagonal gives one turned over; a
 * bent one's, a sharper fold), along the shorter one when the two agree
 * within QUAD_AGREE (nearly flat either way, the better-shaped pair). */
static void split_quad(const double *v, const int *c, int *out)
{
    double a02 = agreement(v, c[0], c[1], c[2], c[3]), a13 = agreement(v, c[1], c[2], c[3], c[0]);
    double d02[3], d13[3];
    sub(v + 3 * (size_t)c[2], v + 3 * (size_t)c[0], d02);
    sub(v + 3 * (size_t)c[3], v + 3 * (size_t)c[1], d13);
    cut_quad(c, fabs(a02 - a13) <= QUAD_AGREE ? dot(d02, d02) <= dot(d13, d13) : a02 > a13, out);
}

/* Polygon c (k >= 5 corners) of positions v into k - 2 triangles at out.
 * q: scratch of 2k doubles, at: of k ints. */
static void split(const double *v, const int *c, int k, int *out, double *q, int *at)
{
    if (k == 4) {
        split_quad(v, c, out);
        return;
    }
    double n[3] = { 0, 0, 0 };
    for (int i = 0; i < k; i++) {   /* Newell's normal */
        const double *a = v + 3 * (size_t)c[i], *b = v + 3 * (size_t)c[(i + 1) % k];
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    double len = sqrt(dot(n, n));
    if (!(len > 0)) {                /* no plane: a fan */
        for (int i = 1; i + 1 < k; i++)
            emit(&out, c[0], c[i], c[i + 1]);
        return;
    }
    for (int i = 0; i < 3; i++)
        n[i] /= len;
    double u[3], w[3], t[3] = { 1, 0, 0 };
    if (fabs(n[0]) > 0.9)
        t[0] = 0, t[1] = 1;
    cross(n, t, u);
    double lu = sqrt(dot(u, u));
    for (int i = 0; i < 3; i++)
        u[i] /= lu;
    cross(n, u, w);                  /* (u, w, n) right-handed: the polygon turns counter-clockwise */
    for (int i = 0; i < k; i++) {
        double d[3];
        sub(v + 3 * (size_t)c[i], v + 3 * (size_t)c[0], d);
        q[2 * i] = dot(d, u);
        q[2 * i + 1] = dot(d, w);
    }
    clip_ears(c, q, k, at, out);
}

/* An undirected edge as one sortable key. */
static unsigned long long edge_key(int a, int b)
{
    return a < b ? (unsigned long long)a << 32 | (unsigned)b : (unsigned long long)b << 32 | (unsigned)a;
}

static int by_key(const void *x, const void *y)
{
    unsigned long long a = *(const unsigned long long *)x, b = *(const unsigned long long *)y;
    return (a > b) - (a < b);
}

/* How many of the nk sorted keys are k. */
static long key_count(const unsigned long long *keys, long nk, unsigned long long k)
{
    long lo = 0, hi = nk;
    while (lo < hi) {
        long mid = lo + (hi - lo) / 2;
        if (keys[mid] < k)
            lo = mid + 1;
        else
            hi = mid;
    }
    long n = 0;
    while (lo + n < nk && keys[lo + n] == k)
        n++;
    return n;
}

/* A quad cut along an edge that other faces have too (around a vertex of
 * two quads, say, both cuts along the same diagonal give one triangle
 * twice) is cut along its other diagonal instead, when no face has that
 * one. Returns -1 out of memory. */
static int unshare_quad_cuts(mesh__faces *F)
{
    long nq = 0;
    for (long i = 0; i < F->npoly; i++)
        nq += F->poly[3 * i + 2] == 4;
    if (!nq)
        return 0;
    long nk = 3 * F->ntri;
    unsigned long long *keys = malloc(sizeof *keys * ((size_t)nk + 1));
    if (!keys)
        return -1;
    for (long t = 0; t < F->ntri; t++)
        for (int k = 0; k < 3; k++)
            keys[3 * t + k] = edge_key(F->tri[3 * t + k], F->tri[3 * t + (k + 1) % 3]);
    qsort(keys, (size_t)nk, sizeof *keys, by_key);
    for (long i = 0; i < F->npoly; i++) {
        const long *p = F->poly + 3 * i;
        if (p[2] != 4)
            continue;
        const int *c = F->corner + p[1];
        int *t = F->tri + 3 * p[0];
        int along02 = t[0] == c[0] && t[2] == c[2];   /* cut_quad's two ways */
        unsigned long long cut = along02 ? edge_key(c[0], c[2]) : edge_key(c[1], c[3]);
        unsigned long long other = along02 ? edge_key(c[1], c[3]) : edge_key(c[0], c[2]);
        if (key_count(keys, nk, cut) > 2 && key_count(keys, nk, other) == 0)
            cut_quad(c, !along02, t);
    }
    free(keys);
    return 0;
}

int mesh__faces_finish(mesh__faces *F, mesh *m)
{
    long most = 0;
    for (long i = 0; i < F->npoly; i++)
        most = F->poly[3 * i + 2] > most ? F->poly[3 * i + 2] : most;
    double *q = malloc(sizeof(double) * (2 * (size_t)most + 1));
    int *at = malloc(sizeof(int) * ((size_t)most + 1));
    if (!q || !at) {
        free(q);
        free(at);
        return MESH_ENOMEM;
    }
    for (long i = 0; i < F->npoly; i++) {
        const long *p = F->poly + 3 * i;
        split(m->v, F->corner + p[1], (int)p[2], F->tri + 3 * p[0], q, at);
    }
    free(q);
    free(at);
    if (unshare_quad_cuts(F))
        return MESH_ENOMEM;
    free(m->f);
    m->f = F->tri ? F->tri : calloc(1, sizeof(int));
    m->nf = (int)F->ntri;
    m->polygons = (int)F->npoly;
    F->tri = NULL;
    mesh__faces_free(F);
    return m->f ? MESH_OK : MESH_ENOMEM;
}
