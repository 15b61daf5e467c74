/* worker_job.c — SUBMIT -> wrk_job: the one place where wire fields become
 * engine inputs, each validated with the engine's own rule (see worker.h).
 * Reads no files and runs no optimisation. */
#include "main/worker.h"
#include "util/errbuf.h"
#include "util/ompenv.h"

#include <math.h>
#include <omp.h>
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
    corr_fix_close(&job->fix);
    memset(job, 0, sizeof *job);
}

static int load_mesh(const proto_blob *b, const char *name, const wrk_limits *lim, mesh **out,
                     char *err, size_t errsz)
{
    int rc = mesh_read_drc_mem(b->data, b->len, lim->max_vertices, lim->max_faces, name, out,
                               err, errsz);
    /* over the limits included: "N points / M faces, over ..." */
    return rc ? corr_wire_code(corr_from_mesh(rc)) : 0;
}

/* The meshes as the engine will run them: used as given, repaired, or
 * refused (corr_fix_open), landmarks and maps carried along. */
static int fix_meshes(wrk_job *job, char *err, size_t errsz)
{
    corr_input user = { job->S, job->T, "source mesh", "target mesh", job->L, job->P0, job->Q0,
                        &job->rhm, job->stages, job->ddm_k, job->ddm_mode }, in;
    return corr_wire_code(corr_fix_open(&user, job->repair, &job->fix, &in, err, errsz));
}

/* The inputs' combination: a map or landmarks, q only with p and bijective. */
static int check_inputs(const proto_submit *s, char *err, size_t errsz)
{
    if (s->p.n == 0 && s->nlandmarks == 0)
        return errbuf_set(err, errsz, corr_wire_code(KIND_ELANDMARKS),
                          "landmarks: none, and no initial map p: need one or at least %d pairs",
                          PROTO_MIN_LANDMARKS);
    if (s->q.n && !s->p.n)
        return errbuf_set(err, errsz, corr_wire_code(KIND_EMAP), "initial map q without p");
    if (s->q.n && s->params.model == PROTO_MODEL_INJECTIVE)
        return errbuf_set(err, errsz, corr_wire_code(KIND_EPARAMS),
                          "initial map q needs the bijective model");
    return 0;
}

/* A chain of stages that can run on the inputs (corr_chain_check); after
 * the landmarks are read, so that their own rule speaks first, and with
 * the landmarks the run will have (a repair leaves out those on vertices
 * it dropped). */
static int check_stages(const proto_submit *s, const wrk_job *job, char *err, size_t errsz)
{
    char why[256];
    corr_input in;
    wrk_job_input(job, &in);
    int rc = corr_chain_check((corr_chain)s->params.stages, s->p.n > 0, s->q.n > 0,
                              in.L ? in.L->n : 0, s->params.model == PROTO_MODEL_INJECTIVE,
                               s->params.rhm_landmark_weight, (corr_ddm_mode)s->params.ddm_mode,
                               why, sizeof why);
    return rc ? errbuf_set(err, errsz, corr_wire_code(rc), "params.stages: %s", why) : 0;
}

void wrk_job_input(const wrk_job *job, corr_input *in)
{
    *in = (corr_input){ job->S, job->T, "source mesh", "target mesh", job->L, job->P0, job->Q0,
                        &job->rhm, job->stages, job->ddm_k, job->ddm_mode };
    if (job->fix.repaired) {
        const corr_fix *fx = &job->fix;
        in->S = fx->S.m;
        in->T = fx->T.m;
        in->L = job->L ? &fx->L : NULL;
        in->P0 = fx->P0;
        in->Q0 = fx->Q0;
    }
}

/* The sizes the decoded meshes bound (corr_check_sizes), as the run would
 * find them at its start. */
static int check_sizes(const wrk_job *job, char *err, size_t errsz)
{
    corr_input in;
    wrk_job_input(job, &in);
    return corr_wire_code(corr_check_sizes(&in, err, errsz));
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
    rc = corr_wire_code(corr_from_lmk(rc));
done:
    free(a);
    free(b);
    return rc;
}

int wrk_map_of(const proto_map *w, const char *name, const mesh *from, const mesh *to, bmap **out, char *err,
               size_t errsz)
{
    *out = NULL;
    if (w->n == 0)
        return 0;
    if (w->n != (uint32_t)from->nv)
        return errbuf_set(err, errsz, corr_wire_code(KIND_EMAP),
                          "%s has %u rows, its mesh has %d vertices", name, w->n, from->nv);
    bmap *P = bmap_new(from->nv, to->nv);
    if (!P)
        return errbuf_set(err, errsz, PROTO_ENOMEM, "%s: out of memory", name);
    for (int i = 0; i < P->n; i++) {
        double *wt = P->w + 3 * (size_t)i;
        memcpy(wt, w->rows[i].w, sizeof w->rows[i].w);
        if (bmap_check_row(w->rows[i].face, wt, to->nf, name, NULL, 0)) {
            char where[64];                  /* the row's name only when it is bad */
            snprintf(where, sizeof where, "%s: row %d", name, i);
            bmap_check_row(w->rows[i].face, wt, to->nf, where, err, errsz);
            bmap_free(P);
            return corr_wire_code(KIND_EMAP);
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
    if ((rc = corr_params_from_job(&s->params, lim->threads, &job->params, &job->rhm, err, errsz))) {
        wrk_job_close(job);
        return corr_wire_code(rc);
    }
    job->stages = (corr_chain)s->params.stages;
    job->ddm_k = (int)s->params.ddm_k;
    job->ddm_mode = (corr_ddm_mode)s->params.ddm_mode;
    job->repair = s->params.repair == 0;     /* "yes|no" */
    if ((rc = check_inputs(s, err, errsz)) ||
        (rc = load_mesh(&s->source, "source mesh", lim, &job->S, err, errsz)) ||
        (rc = load_mesh(&s->target, "target mesh", lim, &job->T, err, errsz)) ||
        (rc = map_landmarks(s, job->S, job->T, &job->L, err, errsz)) ||
        (rc = wrk_map_of(&s->p, "initial map p", job->S, job->T, &job->P0, err, errsz)) ||
        (rc = wrk_map_of(&s->q, "initial map q", job->T, job->S, &job->Q0, err, errsz)) ||
        (rc = fix_meshes(job, err, errsz)) ||
        (rc = check_stages(s, job, err, errsz)) ||
        (rc = check_sizes(job, err, errsz))) {
        wrk_job_close(job);
        return rc;
    }
    /* The job's size decides the threads unless the worker was given a
     * count: before any parallel region, so a small job never starts a
     * second one. */
    int threads = ompenv_threads_for(job->S->nv + job->T->nv, lim->threads);
    job->params.threads = job->rhm.threads = threads;
    omp_set_num_threads(threads);
    return 0;
}
