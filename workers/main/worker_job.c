/* worker_job.c — SUBMIT -> wrk_job: the one place where wire fields become
 * engine inputs, each validated with the engine's own rule (see worker.h).
 * Reads no files and runs no optimisation. */
#include "main/worker.h"
#include "util/errbuf.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void wrk_job_close(wrk_job *job)
{
    if (!job)
        return;
    mesh_free(job->S);
    mesh_free(job->T);
    lmk_free(job->L);
    bmap_free(job->P0);
    bmap_free(job->Q0);
    memset(job, 0, sizeof *job);
}

static int load_mesh(const proto_blob *b, const char *name, const wrk_limits *lim, mesh **out,
                     char *err, size_t errsz)
{
    int rc = mesh_read_drc_mem(b->data, b->len, lim->max_vertices, lim->max_faces, name, out,
                               err, errsz);
    if (rc)                 /* over the limits included: "N points / M faces, over ..." */
        return rc == MESH_ENOMEM ? PROTO_ENOMEM : PROTO_EBAD_MESH;
    rc = corr_validate(*out, name, err, errsz);
    if (rc)
        return rc == CORR_ENOMEM ? PROTO_ENOMEM : PROTO_EBAD_MESH;
    return 0;
}

static int map_params(const proto_params *w, const wrk_limits *lim, ectm_params *p,
                      rhm_params *r, char *err, size_t errsz)
{
    rhm_params_init(r);
    r->threads = lim->threads;
    if (w->rhm_iterations) {
        r->iterations = w->rhm_iterations > 1000000 ? 1000001 : (int)w->rhm_iterations;
    }
    if (w->rhm_dim)
        r->dim = w->rhm_dim > 1000 ? 1001 : (int)w->rhm_dim;
    if (w->rhm_alpha != 0)
        r->alpha = w->rhm_alpha;
    r->gamma = w->rhm_landmark_weight;
    r->start = w->rhm_start;
    char detail[256];
    if (rhm_params_check(r, detail, sizeof detail))
        return errbuf_set(err, errsz, PROTO_EBAD_PARAMS, "%s", detail);   /* "RHM parameter ..." */
    ectm_params_init(p);
    /* backend: "" (cpu), "cpu", "opencl", "auto", optionally ":DEVICE" */
    if (w->backend[0]) {
        const char *colon = strchr(w->backend, ':');
        size_t n = colon ? (size_t)(colon - w->backend) : strlen(w->backend);
        if (n >= sizeof p->backend || (colon && strlen(colon + 1) >= sizeof p->device))
            return errbuf_set(err, errsz, PROTO_EBAD_PARAMS, "parameter backend: '%s' is too long",
                              w->backend);
        memcpy(p->backend, w->backend, n);
        p->backend[n] = '\0';
        if (colon)
            snprintf(p->device, sizeof p->device, "%s", colon + 1);
    }
    p->model = w->model == PROTO_MODEL_INJECTIVE ? ECTM_INJECTIVE : ECTM_BIJECTIVE;
    p->partial = w->partial;
    p->alpha = w->alpha;
    p->eta = w->eta;
    p->gamma = w->gamma;
    /* counts above INT_MAX become INT_MAX, which ectm_params_check refuses */
    p->iterations = w->iterations > INT_MAX ? INT_MAX : (int)w->iterations;
    p->inner_iterations = w->inner_iterations > INT_MAX ? INT_MAX : (int)w->inner_iterations;
    p->tolerance = w->tolerance;
    p->stop_change = w->stop_change;
    p->threads = lim->threads;
    p->beta0 = w->beta0;
    p->beta1 = w->beta1;
    p->beta_ramp = w->beta_ramp > INT_MAX ? INT_MAX : (int)w->beta_ramp;
    if (ectm_params_check(p, err, errsz))
        return PROTO_EBAD_PARAMS;
    return 0;
}

static int map_landmarks(const proto_submit *s, const mesh *S, const mesh *T, lmk_set **out,
                         char *err, size_t errsz)
{
    *out = NULL;
    if (s->nlandmarks == 0)
        return 0;
    long *a = malloc(sizeof(long) * s->nlandmarks), *b = malloc(sizeof(long) * s->nlandmarks);
    int rc = 0;
    if (!a || !b) {
        rc = errbuf_set(err, errsz, PROTO_ENOMEM, "landmarks: out of memory");
        goto done;
    }
    for (uint32_t k = 0; k < s->nlandmarks; k++) {
        a[k] = s->landmarks[k].src;
        b[k] = s->landmarks[k].tgt;
    }
    rc = lmk_from_arrays(a, b, s->nlandmarks, 0, "landmarks", "landmarks", S, T, out, err, errsz);
    if (rc)
        rc = rc == LMK_ENOMEM ? PROTO_ENOMEM : PROTO_EBAD_LANDMARKS;
done:
    free(a);
    free(b);
    return rc;
}

static int map_map(const proto_map *w, const char *name, const mesh *from, const mesh *to,
                   bmap **out, char *err, size_t errsz)
{
    *out = NULL;
    if (w->n == 0)
        return 0;
    if (w->n != (uint32_t)from->nv)
        return errbuf_set(err, errsz, PROTO_EBAD_PARAMS,
                          "%s has %u rows, its mesh has %d vertices", name, w->n, from->nv);
    bmap *P = bmap_new(from->nv, to->nv);
    if (!P)
        return errbuf_set(err, errsz, PROTO_ENOMEM, "%s: out of memory", name);
    for (int i = 0; i < P->n; i++) {
        char where[64];
        snprintf(where, sizeof where, "%s: row %d", name, i);
        double *wt = P->w + 3 * (size_t)i;
        memcpy(wt, w->rows[i].w, sizeof w->rows[i].w);
        if (bmap_check_row(w->rows[i].face, wt, to->nf, where, err, errsz)) {
            bmap_free(P);
            return PROTO_EBAD_PARAMS;
        }
        P->face[i] = (int)w->rows[i].face;
    }
    *out = P;
    return 0;
}

int wrk_job_from_submit(const proto_submit *s, const wrk_limits *lim, wrk_job *job,
                        char *err, size_t errsz)
{
    memset(job, 0, sizeof *job);
    int rc;
    if ((rc = map_params(&s->params, lim, &job->params, &job->rhm, err, errsz)) ||
        (rc = load_mesh(&s->source, "source mesh", lim, &job->S, err, errsz)) ||
        (rc = load_mesh(&s->target, "target mesh", lim, &job->T, err, errsz)) ||
        (rc = map_landmarks(s, job->S, job->T, &job->L, err, errsz)) ||
        (rc = map_map(&s->p, "initial map p", job->S, job->T, &job->P0, err, errsz)) ||
        (rc = map_map(&s->q, "initial map q", job->T, job->S, &job->Q0, err, errsz)))
        wrk_job_close(job);
    return rc;
}
