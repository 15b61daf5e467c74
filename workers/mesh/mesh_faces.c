/* mesh_faces.c — see mesh__faces.h: the faces a reader collects, and the
 * split of a polygon into triangles. A convex quad is cut along its shorter
 * diagonal; any other polygon is cut by ear clipping in the plane of its
 * Newell normal, and a polygon with no ear left (degenerate, or crossing
 * itself) by a fan, whose slivers the repair then removes. Every triangle
 * keeps the polygon's orientation. */
#include "mesh/mesh__faces.h"

#include "util/errbuf.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    int n = k;
    for (int i = 0; i < k; i++)
        at[i] = i;
    while (n > 3) {
        int found = -1;
        for (int i = 0; i < n && found < 0; i++) {
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
    }
    for (int i = 1; i + 1 < n; i++)
        emit(&out, c[at[0]], c[at[i]], c[at[i + 1]]);
}

/* Polygon c (k >= 4 corners) of positions v into k - 2 triangles at out.
 * q: scratch of 2k doubles, at: of k ints. */
static void split(const double *v, const int *c, int k, int *out, double *q, int *at)
{
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
    if (k == 4 && area2(q, q + 2, q + 4) > 0 && area2(q + 2, q + 4, q + 6) > 0 &&
        area2(q + 4, q + 6, q) > 0 && area2(q + 6, q, q + 2) > 0) {
        double d02[3], d13[3];
        sub(v + 3 * (size_t)c[2], v + 3 * (size_t)c[0], d02);
        sub(v + 3 * (size_t)c[3], v + 3 * (size_t)c[1], d13);
        if (dot(d02, d02) <= dot(d13, d13)) {
            emit(&out, c[0], c[1], c[2]);
            emit(&out, c[0], c[2], c[3]);
        } else {
            emit(&out, c[1], c[2], c[3]);
            emit(&out, c[1], c[3], c[0]);
        }
        return;
    }
    clip_ears(c, q, k, at, out);
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
    free(m->f);
    m->f = F->tri ? F->tri : calloc(1, sizeof(int));
    m->nf = (int)F->ntri;
    m->polygons = (int)F->npoly;
    F->tri = NULL;
    mesh__faces_free(F);
    return m->f ? MESH_OK : MESH_ENOMEM;
}
