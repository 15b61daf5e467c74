/* rhm_run.c — the RHM loop (rhm.h): set-up, the start map from landmarks
 * through the caller's rhm_start_fn, block coordinate descent with the β
 * schedule and the stopping rule, progress and cancellation. The numerics
 * are rhm_step.c's. */
#include "rhm/rhm__problem.h"
#include "util/errbuf.h"

#include <math.h>
#include <omp.h>
#include <string.h>
#include <time.h>

double rhm__now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The loop from the current state (maps and X_ij set): the start's report
 * (iteration 0), then iterations until K or the stopping rule. On success
 * the maps move into out. */
int rhm__iterate(rhm__problem *pb, double t0, rhm_progress_fn progress, void *ctx,
                 rhm_result *out, char *err, size_t errsz)
{
    const rhm_params *p = &pb->p;
    rhm_report r;
    memset(&r, 0, sizeof r);
    r.total = p->iterations;
    r.beta = rhm_beta(p, 1);
    r.energy = rhm__energy(pb, r.beta, r.dir);
    r.t_setup = r.elapsed = rhm__now() - t0;
    if (progress && progress(ctx, &r))
        return errbuf_set(err, errsz, KIND_ECANCELLED, "RHM cancelled after the initial map");
    for (int k = 1; k <= p->iterations; k++) {
        double prev = r.energy, beta = rhm_beta(p, k);
        int rc;
        for (int i = 0; i < 2; i++) {
            double ta = rhm__now();
            char why[256] = "";
            if ((rc = rhm__step_p(pb, i, beta, why, sizeof why)))
                return errbuf_set(err, errsz, rc, "RHM iteration %d: projection failed%s%s", k,
                                  why[0] ? ": " : "", why);
            double tb = rhm__now();
            if ((rc = rhm__step_x(pb, i, beta)))
                return errbuf_set(err, errsz, rc, "RHM iteration %d: X-step solve failed "
                                  "(CHOLMOD status %d)", k, chol_status(pb->side[i].A));
            r.t_project += tb - ta;
            r.t_solve += rhm__now() - tb;
        }
        r.iteration = k;
        r.beta = beta;
        r.energy = rhm__energy(pb, beta, r.dir);
        r.elapsed = rhm__now() - t0;
        if (!isfinite(r.energy))
            return errbuf_set(err, errsz, KIND_ENUMERIC, "RHM iteration %d: energy is not finite", k);
        if (progress && progress(ctx, &r))
            return errbuf_set(err, errsz, KIND_ECANCELLED, "RHM cancelled at iteration %d", k);
        if (k >= p->min_iterations && fabs(r.energy - prev) < p->stop_change * prev)
            break;
    }
    out->last = r;
    out->P12 = pb->side[0].P;
    out->P21 = pb->side[1].P;
    pb->side[0].P = pb->side[1].P = NULL;
    return KIND_OK;
}

int rhm__start(rhm__problem *pb, rhm_start_fn start, char *err, size_t errsz)
{
    rhm__side *a = &pb->side[0], *b = &pb->side[1];
    bmap_free(a->P);
    bmap_free(b->P);
    a->P = bmap_new(a->n, b->n);
    b->P = bmap_new(b->n, a->n);
    if (!a->P || !b->P)
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
    rhm_side view[2];
    for (int i = 0; i < 2; i++) {
        const rhm__side *sd = &pb->side[i];
        view[i] = (rhm_side){ .m = sd->m, .n = sd->n, .area = sd->s, .X = sd->X, .dim = pb->dim,
                              .geod = sd->geod, .lmk = sd->lmk, .nl = pb->nl, .P = sd->P };
    }
    int rc = start(&pb->p, view, err, errsz);
    if (rc)
        return rc;
    bmap_apply(a->P, b->m->f, b->X, pb->dim, a->Xij);
    bmap_apply(b->P, a->m->f, a->X, pb->dim, b->Xij);
    return KIND_OK;
}

int rhm_run_start(const mesh *S, const mesh *T, const lmk_set *L, const rhm_params *p,
                  rhm_start_fn start, rhm_progress_fn progress, void *ctx, rhm_result *out,
                  char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    out->start = -1;
    double t0 = rhm__now();
    if (p->threads > 0)
        omp_set_num_threads(p->threads);
    rhm__problem *pb = NULL;
    int rc = rhm__problem_new(S, T, L, p, &pb, err, errsz);
    if (rc)
        return rc;
    if (!(rc = rhm__start(pb, start, err, errsz)))
        rc = rhm__iterate(pb, t0, progress, ctx, out, err, errsz);
    rhm__problem_free(pb);
    return rc;
}
