/* proj_tree.c — building and freeing the Embree 3 BVH over the target's 3-D
 * triangles, and the patches of the R^d hierarchy (proj_hd.c). No queries here (proj_closest.c), and no pointer kept to the
 * caller's mesh: vertices and faces are copied into Embree's own buffers. */
#include "proj/proj.h"
#include "proj/proj__tree.h"
#include "util/errbuf.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int check_target(const mesh *m, char *err, size_t errsz)
{
    if (!m || m->nv <= 0 || m->nf <= 0)
        return errbuf_set(err, errsz, PROJ_EMESH, "target mesh is empty");
    for (int i = 0; i < 3 * m->nv; i++)
        if (!isfinite(m->v[i]))
            return errbuf_set(err, errsz, PROJ_EMESH,
                              "target vertex %d has a non-finite coordinate", i / 3);
    for (int i = 0; i < 3 * m->nf; i++)
        if (m->f[i] < 0 || m->f[i] >= m->nv)
            return errbuf_set(err, errsz, PROJ_EMESH,
                              "target face %d has vertex index %d out of [0, %d)",
                              i / 3, m->f[i], m->nv);
    return 0;
}

static double scene_scale(const mesh *m)
{
    double lo[3] = { INFINITY, INFINITY, INFINITY };
    double hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    double amax = 0;
    for (int i = 0; i < m->nv; i++)
        for (int k = 0; k < 3; k++) {
            double x = m->v[3 * i + k];
            lo[k] = x < lo[k] ? x : lo[k];
            hi[k] = x > hi[k] ? x : hi[k];
            amax = fabs(x) > amax ? fabs(x) : amax;
        }
    double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
    return diag + amax;
}

/* An Embree failure into err, its out-of-memory read as such; returns
 * whether it was. */
static int embree_failed(enum RTCError e, const char *what, char *err, size_t errsz)
{
    if (e == RTC_ERROR_OUT_OF_MEMORY)
        errbuf_set(err, errsz, PROJ_ENOMEM, "out of memory (%s)", what);
    else
        errbuf_set(err, errsz, PROJ_EEMBREE, "%s (error %d)", what, (int)e);
    return e == RTC_ERROR_OUT_OF_MEMORY;
}

proj_tree *proj_tree_new(const mesh *target, char *err, size_t errsz)
{
    if (check_target(target, err, errsz) < 0) {
        errno = EINVAL;
        return NULL;
    }
    proj_tree *t = calloc(1, sizeof *t);
    if (!t) {
        errbuf_set(err, errsz, PROJ_ENOMEM, "out of memory");
        errno = ENOMEM;
        return NULL;
    }
    int nomem = 1;
    t->nv = target->nv;
    t->nf = target->nf;
    t->scale = scene_scale(target);
    t->f = malloc(sizeof(int) * 3 * (size_t)target->nf);
    if (!t->f) {
        errbuf_set(err, errsz, PROJ_ENOMEM, "out of memory for %d faces", target->nf);
        goto fail;
    }
    memcpy(t->f, target->f, sizeof(int) * 3 * (size_t)target->nf);
    if (!(t->hd = proj__hd_new(target->v, t->f, t->nf))) {
        errbuf_set(err, errsz, PROJ_ENOMEM, "out of memory for %d faces", target->nf);
        goto fail;
    }

    /* One build thread: Embree's parallel BVH build is not deterministic,
     * and the tree's shape decides which of two faces at equal cost a
     * query returns; ECTM's alternations amplify that into different maps
     * from run to run. The build is a small part of a job: one tree per mesh.
      */
    t->device = rtcNewDevice("threads=1");
    if (!t->device) {
        nomem = embree_failed(rtcGetDeviceError(NULL), "rtcNewDevice failed", err, errsz);
        goto fail;
    }
    t->scene = rtcNewScene(t->device);
    RTCGeometry g = rtcNewGeometry(t->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *vb = g ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                            3 * sizeof(float), (size_t)target->nv) : NULL;
    unsigned *ib = g ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                               3 * sizeof(unsigned), (size_t)target->nf) : NULL;
    if (!t->scene || !vb || !ib) {
        if (g)
            rtcReleaseGeometry(g);
        nomem = embree_failed(rtcGetDeviceError(t->device), "Embree could not allocate the scene",
                              err, errsz);
        goto fail;
    }
    for (int i = 0; i < 3 * target->nv; i++)
        vb[i] = (float)target->v[i];
    for (int i = 0; i < 3 * target->nf; i++)
        ib[i] = (unsigned)target->f[i];
    rtcCommitGeometry(g);
    rtcAttachGeometry(t->scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(t->scene);
    enum RTCError e = rtcGetDeviceError(t->device);
    if (e != RTC_ERROR_NONE) {
        nomem = embree_failed(e, "Embree failed to build the BVH", err, errsz);
        goto fail;
    }
    return t;
fail:
    proj_tree_free(t);
    errno = nomem ? ENOMEM : EINVAL;
    return NULL;
}

void proj_tree_free(proj_tree *t)
{
    if (!t)
        return;
    if (t->scene)
        rtcReleaseScene(t->scene);
    if (t->device)
        rtcReleaseDevice(t->device);
    proj__hd_free(t->hd);
    free(t->f);
    free(t);
}
