/* corr.c — the correspondence pipeline (see corr.h): validation, the
 * chosen stages in their order (DDM, RHM from landmarks or from the maps,
 * ECTM), progress fan-in: every stage's report goes out with the whole
 * job's fraction and time left (corr__plan.h). Combines modules; computes
 * nothing itself. */
#include "corr/corr.h"
#include "corr/corr__ddm.h"
#include "corr/corr__plan.h"
#include "corr/corr__pieces.h"
#include "mesh/mesh_check.h"
#include "metric/metric.h"
#include "start/start.h"
#include "util/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Where a chain's reports go: the caller's callback, with the job's plan
 * (one for the whole job: the coarse chain shares it). */
typedef struct relay {
    corr_progress_fn fn;
    void *ctx;
    double t0;
    corr__plan *plan;
    int ectm_before, ectm_total;   /* coarse to fine: one count over both ECTM runs */
} relay;

/* p with its time, fraction and time left to the caller; non-zero cancels. */
static int forward(relay *rl, corr_progress *p)
{
    if (!rl || !rl->fn)
        return 0;
    p->elapsed = now() - rl->t0;
    corr__plan_update(rl->plan, p);
    return rl->fn(rl->ctx, p);
}

static int relay_ectm(void *ctx, const ectm_report *r)
{
    relay *rl = ctx;
    ectm_report q = *r;
    if (rl->ectm_total) {            /* the fine run after the coarse one's iterations */
        q.outer += rl->ectm_before;
        q.total = rl->ectm_total;
    }
    corr_progress p = { .stage = CORR_STAGE_ECTM, .ectm = &q };
    return forward(rl, &p);
}

static int relay_ddm(void *ctx, const corr_ddm_report *r)
{
    corr_progress p = { .stage = CORR_STAGE_DDM, .ddm = r };
    return forward(ctx, &p);
}

static int relay_rhm(void *ctx, const rhm_report *r)
{
    corr_progress p = { .stage = r->iteration ? CORR_STAGE_RHM : CORR_STAGE_START, .rhm = r };
    return forward(ctx, &p);
}

/* A repair's report: done of total maps. */
static int relay_repair(relay *rl, int done, int total)
{
    corr_repair_report r = { done, total };
    corr_progress p = { .stage = CORR_STAGE_REPAIR, .repair = &r };
    return forward(rl, &p);
}

/* That share for the more folded of RHM's two maps. */
static double folded(const corr_input *in, const rhm_result *r)
{
    double f1 = corr_folded(in->S, in->T, r->P12), f2 = corr_folded(in->T, in->S, r->P21);
    return f1 > f2 ? f1 : f2;
}

/* The finishing of P and Q (either may be NULL) after stage `after`
 * (corr_finish_select, corr_repair) between two reports of the repair
 * stage (rl NULL: none); a report's non-zero return cancels. */
static int finish_reported(const corr_input *in, relay *rl, corr_after after, int through_rhm,
                           bmap *P, bmap *Q, fold_report rep[2], char *err, size_t errsz)
{
    int relax = corr_finish_select(in, after, through_rhm, &P, &Q);
    int total = !!P + !!Q, rc;
    if (!total)
        return KIND_OK;
    if (relay_repair(rl, 0, total))
        return errbuf_set(err, errsz, KIND_ECANCELLED, "cancelled before the fold repair");
    if ((rc = corr_repair(in, P, Q, relax, rep, err, errsz)))
        return rc;
    if (relay_repair(rl, total, total))
        return errbuf_set(err, errsz, KIND_ECANCELLED, "cancelled after the fold repair");
    return KIND_OK;
}

/* One RHM run from q and its repair; raw: a copy of P12 before it. */
static int rhm_repaired(const corr_input *in, const rhm_params *q, relay *rl,
                        rhm_progress_fn progress, void *ctx, rhm_result *out, bmap **raw,
                        fold_report rep[2], char *err, size_t errsz)
{
    int rc = start_run(in->S, in->T, in->L, q, progress, ctx, out, err, errsz);
    if (rc)
        return rc;
    if (raw) {
        if (!(*raw = bmap_new(out->P12->n, out->P12->nt)))
            return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
        memcpy((*raw)->face, out->P12->face, sizeof(int) * (size_t)out->P12->n);
        memcpy((*raw)->w, out->P12->w, sizeof(double) * 3 * (size_t)out->P12->n);
    }
    return finish_reported(in, rl, CORR_AFTER_RHM, 1, out->P12, out->P21, rep, err, errsz);
}

/* corr_rhm, with the repairs reported and a second run planned through rl
 * (NULL: neither). */
static int rhm_chain(const corr_input *in, const rhm_params *rp, relay *rl,
                     rhm_progress_fn progress, void *ctx, rhm_result *out, bmap **raw,
                     fold_report rep[2], char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    if (raw)
        *raw = NULL;
    rhm_params q = *rp;
    int autos = q.start == RHM_START_AUTO;
    q.start = start_first(rp->start);
    int rc = rhm_repaired(in, &q, rl, progress, ctx, out, raw, rep, err, errsz);
    double bad = rc ? 2 : folded(in, out);
    int again = !rc && start_second(rp->start, bad) >= 0;
    if (rl && rl->plan && autos && !rc)
        corr__plan_rerun(rl->plan, again);
    if (!again)
        return rc;
    q.start = start_second(rp->start, bad);
    rhm_result alt;
    bmap *raw2 = NULL;
    fold_report rep2[2];
    char why[1024];
    rc = rhm_repaired(in, &q, rl, progress, ctx, &alt, raw ? &raw2 : NULL, rep2, why, sizeof why);
    if (rc == KIND_ECANCELLED || rc == KIND_ENOMEM) {
        rhm_result_close(&alt);
        bmap_free(raw2);
        return errbuf_set(err, errsz, rc, "%s", why);
    }
    if (rc == KIND_OK && start_keep_second(bad, folded(in, &alt))) {  /* keep the second map */
        rhm_result t = *out;
        *out = alt;
        alt = t;
        if (raw) {
            bmap *b = *raw;
            *raw = raw2;
            raw2 = b;
        }
        memcpy(rep, rep2, sizeof rep2);
    }
    rhm_result_close(&alt);
    bmap_free(raw2);
    return KIND_OK;
}

int corr_rhm(const corr_input *in, const rhm_params *rp, rhm_progress_fn progress, void *ctx,
             rhm_result *out, bmap **raw, fold_report rep[2], char *err, size_t errsz)
{
    return rhm_chain(in, rp, NULL, progress, ctx, out, raw, rep, err, errsz);
}

/* RHM from the given (or denoised) maps P, Q and the repair of its maps. */
static int rhm_from_maps(const corr_input *in, const bmap *P, const bmap *Q,
                         const rhm_params *rp, relay *rl, rhm_result *out, char *err,
                         size_t errsz)
{
    fold_report rep[2];
    int rc = rhm_run_from_maps(in->S, in->T, in->L, P, Q, rp, relay_rhm, rl, out, err, errsz);
    return rc ? rc : finish_reported(in, rl, CORR_AFTER_RHM, 1, out->P12, out->P21, rep, err, errsz);
}

static int run_chain(const corr_input *in, const ectm_params *p, relay *rl, ectm_result *out,
                     char *err, size_t errsz);

/* The finishing of maps carried from the decimated pair to in's meshes. */
static int finish_carried(const corr_input *in, bmap *P, bmap *Q, char *err, size_t errsz)
{
    fold_report rep[2];
    int relax = corr_finish_select(in, CORR_AFTER_CARRY, 1, &P, &Q);
    return P || Q ? corr_repair(in, P, Q, relax, rep, err, errsz) : KIND_OK;
}

/* The chain of in (from landmarks) on the decimated pair, its last maps
 * carried to in's meshes and repaired there: *P, *Q (Q may stay NULL);
 * when that chain ran RHM then ECTM, its RHM maps the same way: *rP, *rQ.
 * *ran = 0 (and nothing done) when there is no usable decimated pair: a
 * mesh still over twice the coarse size (collapses refused everywhere by
 * its normals or its faces' shapes), or a decimation that failed other
 * than for memory (OpenMesh refusing a face, a copy corr_validate
 * refuses); the job then runs on in's meshes as given. The coarse chain
 * reports through rl as part of the job: one plan, ECTM's iterations
 * counted over both runs. */
static int run_coarse(const corr_input *in, const ectm_params *p, relay *rl, bmap **P,
                      bmap **Q, bmap **rP, bmap **rQ, int *ran, char *err, size_t errsz)
{
    corr_coarse c;
    ectm_result cr = {0};
    int rc = corr_coarse_open(in, &c, err, errsz);
    if (rc && rc != KIND_ENOMEM) {
        *ran = 0;
        return KIND_OK;
    }
    *ran = !rc && !corr_coarse_wanted(&c.in);
    if (rc || !*ran) {
        corr_coarse_close(&c);
        return rc;
    }
    rl->ectm_total = 2 * p->iterations;   /* the coarse ECTM's, then the fine one's */
    relay coarse = *rl;
    if (!(rc = run_chain(&c.in, p, &coarse, &cr, err, errsz))) {
        rl->ectm_before = cr.last.outer;   /* fewer than planned if it stopped early */
        if (relay_repair(rl, 0, 1 + !!cr.Q))
            rc = errbuf_set(err, errsz, KIND_ECANCELLED, "cancelled before the fold repair");
        else if (!(rc = corr_coarse_carry(in, &c, cr.P, cr.Q, 0, P, Q, err, errsz)) &&
                 !(rc = finish_carried(in, *P, Q ? *Q : NULL, err, errsz)) &&
                 relay_repair(rl, 1 + !!cr.Q, 1 + !!cr.Q))
            rc = errbuf_set(err, errsz, KIND_ECANCELLED, "cancelled after the fold repair");
        if (!rc && cr.rhm_P &&
            !(rc = corr_coarse_carry(in, &c, cr.rhm_P, cr.rhm_Q, 0, rP, rQ, err, errsz)))
            rc = finish_carried(in, *rP, rQ ? *rQ : NULL, err, errsz);
    }
    ectm_result_close(&cr);
    corr_coarse_close(&c);
    return rc;
}

/* A pair's reports as the whole job's: its fraction scaled into the
 * pair's share of the pair-by-pair job, the job's time. */
typedef struct piece_relay {
    corr_progress_fn fn;
    void *ctx;
    double t0, base, share;
} piece_relay;

static int piece_report(void *ctx, const corr_progress *p)
{
    piece_relay *pr = ctx;
    corr_progress q = *p;
    q.elapsed = now() - pr->t0;
    q.fraction = pr->base + pr->share * p->fraction;
    q.eta_s = q.fraction > 0 ? q.elapsed * (1 - q.fraction) / q.fraction : NAN;
    return pr->fn(pr->ctx, &q);
}

/* A job in pieces the landmarks pair (corr__pieces.h): each pair's chain
 * on its own, in turn, its share of the job by its vertices; the maps
 * joined. */
static int run_pieces(const corr_input *in, const corr__pieces *pc, const ectm_params *p,
                      corr_progress_fn progress, void *ctx, ectm_result *out, char *err,
                      size_t errsz)
{
    ectm_result *res = calloc((size_t)pc->n, sizeof *res);
    if (!res)
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory for the pieces' results");
    double total = in->S->nv + in->T->nv, done = 0, t0 = now();
    int rc = KIND_OK;
    for (int k = 0; k < pc->n && !rc; k++) {
        const corr__piece *q = &pc->p[k];
        piece_relay pr = { progress, ctx, t0, done / total, (q->S->nv + q->T->nv) / total };
        corr__plan plan;
        memset(&plan, 0, sizeof plan);
        relay rl = { progress ? piece_report : NULL, &pr, t0, &plan, 0, 0 };
        rc = run_chain(&q->in, p, &rl, &res[k], err, errsz);
        done += q->S->nv + q->T->nv;
    }
    if (!rc)
        rc = corr__pieces_join(in, pc, res, out, err, errsz);
    for (int k = 0; k < pc->n; k++)
        ectm_result_close(&res[k]);
    free(res);
    return rc;
}

int corr_run(const corr_input *in, const ectm_params *p, corr_progress_fn progress,
             void *ctx, ectm_result *out, char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    corr__pieces pc;
    int rc = corr__pieces_open(in, &pc, err, errsz);
    if (rc)
        return rc;
    if (pc.n) {
        rc = run_pieces(in, &pc, p, progress, ctx, out, err, errsz);
        corr__pieces_close(&pc);
        return rc;
    }
    corr__plan plan;
    memset(&plan, 0, sizeof plan);
    relay rl = { progress, ctx, now(), &plan, 0, 0 };
    return run_chain(in, p, &rl, out, err, errsz);
}

/* The checks before a chain runs: the ECTM parameters, both meshes, the
 * chain against its inputs, the sizes; *rp, RHM's parameters (the job's or
 * the defaults), checked when the chain runs RHM; *run, the stages that
 * run. */
static int check_chain(const corr_input *in, const ectm_params *p, rhm_params *rp, unsigned *run,
                       char *err, size_t errsz)
{
    int rc = ectm_params_check(p, err, errsz);
    if (rc)
        return rc;
    if ((rc = corr_validate(in->S, in->S_name, err, errsz)) ||
        (rc = corr_validate(in->T, in->T_name, err, errsz)))
        return rc;
    if (in->rhm)
        *rp = *in->rhm;
    else
        rhm_params_init(rp);
    int bij = p->model == ECTM_BIJECTIVE;
    if ((rc = corr_chain_check(in->stages, !!in->P0, !!in->Q0, in->L ? in->L->n : 0, !bij,
                                rp->gamma, in->ddm_mode, err, errsz)) ||
        (rc = corr_check_sizes(in, err, errsz)))
        return rc;
    *run = corr_chain_run(in->stages, !!in->P0);
    if ((*run & CORR_RUN_RHM) && (rc = rhm_params_check(rp, err, errsz)))
        return rc;
    return KIND_OK;
}

/* ECTM from P (and Q, bijective) with the job's landmarks pinned in its P-
 * and Q-steps, its reference scaled by RHM's maps where corr_scale.c
 * says (else as p asks), into out, then the finishing of the maps it returns
 * (corr_finish.c's policy); out is closed when the repair fails. */
static int run_ectm(const corr_input *in, const ectm_params *p, relay *rl, unsigned run,
                    const bmap *P, const bmap *Q, ectm_result *out, char *err, size_t errsz)
{
    ectm_landmarks el = { in->L ? in->L->src : NULL, in->L ? in->L->tgt : NULL,
                          in->L ? in->L->n : 0 };
    ectm_params q = *p;
    if (run & CORR_RUN_RHM)
        q.scale_reference = corr_scale_reference(in, P, Q);
    int rc = ectm_run(in->S, in->T, P, Q, &el, &q, relay_ectm, rl, out, err, errsz);
    if (rc != KIND_OK)
        return rc;
    fold_report rep[2];
    if ((rc = finish_reported(in, rl, CORR_AFTER_ECTM, !!(run & CORR_RUN_RHM), out->P, out->Q, rep,
                              err, errsz)))
        ectm_result_close(out);
    return rc;
}

/* RHM's maps (*sP, *sQ: init's or the coarse chain's) stay in the result
 * beside ECTM's: out owns them from here. */
static void keep_rhm_maps(ectm_result *out, rhm_result *init, bmap **sP, bmap **sQ)
{
    out->rhm_P = *sP;
    out->rhm_Q = *sQ;
    if (*sP == init->P12)
        init->P12 = NULL;
    if (*sQ && *sQ == init->P21)
        init->P21 = NULL;
    *sP = *sQ = NULL;
}

/* corr_run's body on in, reporting through rl: the job's chain, or the
 * coarse pair's (run_coarse) as part of it. The outermost call plans the
 * job. */
static int run_chain(const corr_input *in, const ectm_params *p, relay *rl, ectm_result *out,
                     char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    rhm_params rp;
    unsigned run = 0;
    int rc = check_chain(in, p, &rp, &run, err, errsz);
    if (rc)
        return rc;
    int bij = p->model == ECTM_BIJECTIVE;
    corr_input planned = *in;
    planned.rhm = &rp;
    if (rl->plan->n == 0)
        corr__plan_build(rl->plan, &planned, p, &rp);

    bmap *dP = NULL, *dQ = NULL;               /* DDM's maps */
    rhm_result init = {0};                     /* RHM's maps (or the coarse chain's) */
    bmap *sP = NULL, *sQ = NULL;               /* RHM's maps for the result: init's, or the
                                                * coarse chain's carried back */
    const bmap *P = in->P0, *Q = bij ? in->Q0 : NULL;
    if (run & CORR_RUN_DDM) {
        if ((rc = corr__ddm(in, P, Q, relay_ddm, rl, &dP, &dQ, err, errsz)))
            goto done;
        P = dP;
        Q = dQ;
        if (!(run & (CORR_RUN_RHM | CORR_RUN_ECTM))) {
            out->P = dP;
            out->Q = dQ;
            dP = dQ = NULL;
            goto done;
        }
    }
    if (run & CORR_RUN_RHM) {
        int coarse = 0;
        if (corr_coarse_wanted(in)) {
            /* the chain on the decimated pair; ECTM below finishes its
             * maps on in's meshes */
            rc = run_coarse(in, p, rl, &init.P12, &init.P21, &sP, bij ? &sQ : NULL, &coarse,
                            err, errsz);
            if (!rc && !coarse) {              /* no usable decimated pair: planned again */
                rp.coarse = 0;
                corr__plan_build(rl->plan, &planned, p, &rp);
            }
        }
        fold_report rep[2];
        if (!rc && !coarse && P)
            rc = rhm_from_maps(in, P, Q, &rp, rl, &init, err, errsz);
        else if (!rc && !coarse)
            rc = rhm_chain(in, &rp, rl, relay_rhm, rl, &init, NULL, rep, err, errsz);
        if (rc)
            goto done;
        if (!(run & CORR_RUN_ECTM)) {
            out->P = init.P12;
            out->Q = init.P21;
            init.P12 = init.P21 = NULL;
            goto done;
        }
        P = init.P12;
        Q = bij ? init.P21 : NULL;
        if (!coarse) {
            sP = init.P12;
            sQ = bij ? init.P21 : NULL;
        }
    }
    rc = run_ectm(in, p, rl, run, P, Q, out, err, errsz);
    if (rc == KIND_OK && (run & CORR_RUN_RHM))
        keep_rhm_maps(out, &init, &sP, &sQ);
done:
    if (sP != init.P12)
        bmap_free(sP);
    if (sQ != init.P21)
        bmap_free(sQ);
    bmap_free(dP);
    bmap_free(dQ);
    rhm_result_close(&init);
    return rc;
}
