/* fmap_zoomout.c — ZoomOut (Melzi, Ren, Rodolà, Sharma, Wonka, Ovsjanikov
 * 2019): a functional map grown from k0 to kmax basis functions by
 * alternating a vertex map (nearest neighbours in the spectral embedding)
 * and the functional map of that vertex map one size up; see fmap.h. */
#include "fmap/fmap.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* map[i] = the vertex j of M2 whose first k coordinates (Psi2) are nearest
 * to row i of Psi1 C (C: k by k). Exhaustive and exact (on a tie the
 * first found); the previous map[i] (when in range) gives the first bound,
 * so most candidates stop after a few coordinates. */
static void nearest_vertices(const lbo_basis *b1, const double *E, int n2, const double *C, int k,
                             int *map, int *fail, long long *coords)
{
    long long visited = 0;
#pragma omp parallel reduction(+ : visited)
    {
        double *q = malloc((size_t)k * sizeof *q);
        if (!q) {
#pragma omp atomic write
            *fail = 1;
        }
#pragma omp for schedule(static)
        for (int i = 0; i < b1->nv; i++) {
            if (!q)
                continue;
            const double *p = b1->phi + (size_t)i * b1->k;
            for (int c = 0; c < k; c++)
                q[c] = 0;
            for (int a = 0; a < k; a++)
                for (int c = 0; c < k; c++)
                    q[c] += p[a] * C[(size_t)a * k + c];
            int arg = map[i] >= 0 && map[i] < n2 ? map[i] : 0;
            double best = 0;
            for (int c = 0; c < k; c++)
                best += (q[c] - E[(size_t)arg * k + c]) * (q[c] - E[(size_t)arg * k + c]);
            for (int j = 0; j < n2; j++) {
                const double *e = E + (size_t)j * k;
                double d = 0;
                int c = 0;
                for (; c < k && d < best; c++)
                    d += (q[c] - e[c]) * (q[c] - e[c]);
                visited += c;
                if (d < best) {
                    best = d;
                    arg = j;
                }
            }
            map[i] = arg;
        }
        free(q);
    }
    *coords += visited;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int fmap_zoomout(const lbo_basis *b1, const double *m1, const lbo_basis *b2, const double *C0,
                 int k0, int kmax, int step, double *C, int *map, fmap_zoomout_stats *stats,
                 char *err, size_t errsz)
{
    if (k0 < 1 || kmax < k0 || kmax > b1->k || kmax > b2->k || step < 1 || !m1)
        return errbuf_set(err, errsz, FMAP_EINVAL,
                          "ZoomOut: sizes %d -> %d in steps of %d (need 1 <= k0 <= kmax <= the "
                          "bases' %d, %d; step >= 1)%s", k0, kmax, step, b1->k, b2->k,
                          m1 ? "" : "; no source mass");
    int n1 = b1->nv, n2 = b2->nv, fail = 0, rounds = 0;
    long long coords = 0, full = 0;
    double t_nn = 0;
    double *E = malloc((size_t)n2 * kmax * sizeof *E), *Ck = malloc((size_t)kmax * kmax * sizeof *Ck);
    if (!E || !Ck) {
        free(E);
        free(Ck);
        return errbuf_set(err, errsz, FMAP_ENOMEM, "ZoomOut: out of memory");
    }
    for (int i = 0; i < n1; i++)
        map[i] = -1;
    int k = k0;
    for (int a = 0; a < k0; a++)
        memcpy(Ck + (size_t)a * k0, C0 + (size_t)a * k0, (size_t)k0 * sizeof *Ck);
    for (;;) {
        for (int j = 0; j < n2; j++)   /* Psi2's first k columns, packed */
            memcpy(E + (size_t)j * k, b2->phi + (size_t)j * b2->k, (size_t)k * sizeof *E);
        double t0 = now();
        nearest_vertices(b1, E, n2, Ck, k, map, &fail, &coords);
        t_nn += now() - t0;
        full += (long long)n1 * n2 * k;
        if (fail)
            break;
        if (k == kmax)
            break;
        /* C (k' by k') = Psi1^T M1 Pi Psi2 for the vertex map Pi */
        k = k + step < kmax ? k + step : kmax;
        memset(Ck, 0, (size_t)k * k * sizeof *Ck);
        for (int i = 0; i < n1; i++) {
            const double *p1 = b1->phi + (size_t)i * b1->k, *p2 = b2->phi + (size_t)map[i] * b2->k;
            for (int a = 0; a < k; a++) {
                double w = p1[a] * m1[i];
                for (int c = 0; c < k; c++)
                    Ck[(size_t)a * k + c] += w * p2[c];
            }
        }
        rounds++;
    }
    if (!fail)
        memcpy(C, Ck, (size_t)kmax * kmax * sizeof *C);
    if (stats) {
        stats->rounds = rounds;
        stats->nn_seconds = t_nn;
        stats->nn_work = full ? (double)coords / (double)full : 0;
    }
    free(E);
    free(Ck);
    return fail ? errbuf_set(err, errsz, FMAP_ENOMEM, "ZoomOut: out of memory for a row's work")
                : FMAP_OK;
}
