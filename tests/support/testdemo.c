/* testdemo.c — see testdemo.h. */
#include "support/testdemo.h"
#include "support/harness.h"

#include <float.h>
#include <string.h>

#define DEMO "ectm_demo_381_390/"

void testdemo_load(testdemo *d)
{
    char err[1024];
    memset(d, 0, sizeof *d);
    if (mesh_read(harness_data_path("shrec07_bim/Meshes/381.off"), &d->S, err, sizeof err) ||
        mesh_read(harness_data_path("shrec07_bim/Meshes/390.off"), &d->T, err, sizeof err) ||
        bmap_read(harness_data_path(DEMO "init_381_to_390.map"), d->S, d->T, &d->P0, err,
                  sizeof err) ||
        bmap_read(harness_data_path(DEMO "init_390_to_381.map"), d->T, d->S, &d->Q0, err,
                  sizeof err))
        FAILF("%s", err);
}

void testdemo_free(testdemo *d)
{
    mesh_free(d->S);
    mesh_free(d->T);
    bmap_free(d->P0);
    bmap_free(d->Q0);
    memset(d, 0, sizeof *d);
}

double testdemo_uv_distance(const testdemo *d, const bmap *P)
{
    int nt = d->T->nv;
    double *uv = malloc(sizeof(double) * 2 * nt), mn[2] = {DBL_MAX, DBL_MAX}, mx = 0;
    double *pulled = malloc(sizeof(double) * 2 * P->n);
    CHECK(uv && pulled);
    for (int j = 0; j < nt; j++) {
        uv[2 * j] = d->T->v[3 * j + 2];
        uv[2 * j + 1] = d->T->v[3 * j + 1];
        for (int c = 0; c < 2; c++)
            mn[c] = fmin(mn[c], uv[2 * j + c]);
    }
    for (int j = 0; j < 2 * nt; j++) {
        uv[j] -= mn[j % 2];
        mx = fmax(mx, uv[j]);
    }
    for (int j = 0; j < 2 * nt; j++)
        uv[j] /= mx;
    bmap_apply(P, d->T->f, uv, 2, pulled);
    FILE *fp = fopen(harness_data_path(DEMO "reference_final_uv_381.txt"), "r");
    CHECK(fp);
    char line[512];
    int i = 0;
    double sum = 0;
    while (fgets(line, sizeof line, fp)) {
        if (line[0] == '#')
            continue;
        double u, v;
        CHECK_INT(sscanf(line, "%lf %lf", &u, &v), 2);
        CHECK(i < P->n);
        sum += hypot(pulled[2 * i] - u, pulled[2 * i + 1] - v);
        i++;
    }
    fclose(fp);
    CHECK_INT(i, P->n);
    free(uv);
    free(pulled);
    return sum / P->n;
}
