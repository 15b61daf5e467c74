/* corr_plan.c — the whole job's fraction done and time left (corr__plan.h):
 * the steps of a chain weighted by the one cost table below, and each
 * stage report placed on them. */
#include "corr/corr__plan.h"

#include <math.h>
#include <string.h>

/* Expected cost of each phase: seconds per 1000 vertices of the pair it
 * runs on (source and target together), per iteration for RHM and ECTM.
 * The figures behind them, measured on real jobs, are in
 * docs/decisions.md (2026-12-06); bench_progress measures them again. */
static const struct {
    corr__phase phase;
    const char *name;
    double cost;
    const char *why;
} CORR__COSTS[CORR__NPHASES] = {
    {CORR__DECIMATE, "decimate", 0.11,
     "quadric decimation of each mesh over twice the coarse size, once"},
    {CORR__START, "start", 0.26,
     "geodesic distances from every landmark and the embeddings' set-up, once"},
    {CORR__START_FMAP, "start_fmap", 1.6,
     "eigenpairs of both meshes, the descriptors, the functional map and its DDM "
     "deblurring: the start that costs most"},
    {CORR__START_MAPS, "start_maps", 0.13,
     "the embeddings' set-up and the anchors of RHM from given maps, once"},
    {CORR__RHM, "rhm", 0.0073,
     "one projection per direction onto the other embedding and one sparse solve"},
    {CORR__REPAIR, "repair", 0.56,
     "finding the folded regions of both maps and re-mapping them (harmonic patches), "
     "once per repair"},
    {CORR__REPAIR_RELAX, "repair_relax", 1.0,
     "the same repair of ECTM's maps, then fold_relax moving the vertices of what is "
     "still folded"},
    {CORR__ECTM, "ectm", 0.0082,
     "one projection and one L-BFGS Y-step (at most inner_iterations) per direction"},
    {CORR__DDM, "ddm", 0.7,
     "the Laplace-Beltrami eigenpairs of both meshes and one deblurring, per direction"},
};

double corr__plan_cost(corr__phase ph, int nv)
{
    return ph >= 0 && ph < CORR__NPHASES ? CORR__COSTS[ph].cost * nv / 1000.0 : 0;
}

const char *corr__phase_name(corr__phase ph)
{
    return ph >= 0 && ph < CORR__NPHASES ? CORR__COSTS[ph].name : "?";
}

static void add(corr__plan *pl, corr__phase ph, int nv, int count)
{
    if (pl->n == CORR__MAX_STEPS)
        return;
    corr__step *s = &pl->s[pl->n++];
    memset(s, 0, sizeof *s);
    s->phase = ph;
    s->count = count > 0 ? count : 1;
    s->cost = corr__plan_cost(ph, nv) * s->count;
}

/* A mesh's vertices on the coarse path: decimated to c over 2c. */
static int coarse_nv(int nv, int c)
{
    return nv > 2 * c ? c : nv;
}

/* The chain of RHM from landmarks on nv vertices: its start, iterations
 * and repair; with start auto, the second run from the functional-map
 * start that may follow, its steps weighted by how often it runs (maybe). */
static void add_rhm(corr__plan *pl, const rhm_params *rp, int nv)
{
    add(pl, rp->start == RHM_START_FMAP ? CORR__START_FMAP : CORR__START, nv, 1);
    add(pl, CORR__RHM, nv, rp->iterations);
    add(pl, CORR__REPAIR, nv, 1);
    if (rp->start != RHM_START_AUTO)
        return;
    for (int k = 0; k < 3 && pl->n < CORR__MAX_STEPS; k++) {
        add(pl, k == 0 ? CORR__START_FMAP : k == 1 ? CORR__RHM : CORR__REPAIR, nv, k == 1 ? rp->iterations : 1);
        pl->s[pl->n - 1].maybe = 1;
        pl->s[pl->n - 1].cost *= CORR__RERUN_SHARE;
    }
}

/* ECTM's iterations on nv vertices: in full up to the first at which its
 * stop rule may end the run, the rest to the cap weighted by how much of
 * them jobs run. */
static void add_ectm(corr__plan *pl, const ectm_params *p, int nv)
{
    int first = ectm_first_stop(p);
    add(pl, CORR__ECTM, nv, first);
    if (first < p->iterations && pl->n < CORR__MAX_STEPS) {
        add(pl, CORR__ECTM, nv, p->iterations - first);
        pl->s[pl->n - 1].beyond = 1;
        pl->s[pl->n - 1].cost *= CORR__BEYOND_SHARE;
    }
}

void corr__plan_build(corr__plan *pl, const corr_input *in, const ectm_params *p,
                      const rhm_params *rp)
{
    memset(pl, 0, sizeof *pl);
    unsigned run = corr_chain_run(in->stages, !!in->P0);
    int nv = in->S->nv + in->T->nv;
    int bij = p->model == ECTM_BIJECTIVE;
    if (run & CORR_RUN_DDM)
        add(pl, CORR__DDM, nv, in->Q0 && bij ? 2 : 1);
    if ((run & CORR_RUN_RHM) && corr_coarse_wanted(in)) {
        int nc = coarse_nv(in->S->nv, rp->coarse) + coarse_nv(in->T->nv, rp->coarse);
        add(pl, CORR__DECIMATE, nv, 1);
        add_rhm(pl, rp, nc);
        if (run & CORR_RUN_ECTM) {
            add_ectm(pl, p, nc);
            add(pl, CORR__REPAIR_RELAX, nc, 1);
        }
        add(pl, CORR__REPAIR, nv, 1);           /* the maps carried to the meshes */
        if (run & CORR_RUN_ECTM) {
            add_ectm(pl, p, nv);
            add(pl, CORR__REPAIR_RELAX, nv, 1);
        }
        return;
    }
    if (run & CORR_RUN_RHM) {
        if (in->P0) {
            add(pl, CORR__START_MAPS, nv, 1);
            add(pl, CORR__RHM, nv, rp->iterations);
            add(pl, CORR__REPAIR, nv, 1);
        } else {
            add_rhm(pl, rp, nv);
        }
    }
    if (run & CORR_RUN_ECTM) {
        add_ectm(pl, p, nv);
        if (!in->P0)             /* a given map's chain repairs only a folded map */
            add(pl, CORR__REPAIR_RELAX, nv, 1);
    }
}

/* The cost done so far. */
static double done_cost(const corr__plan *pl)
{
    double done = 0;
    for (int i = 0; i < pl->n; i++)
        done += pl->s[i].cost * pl->s[i].done;
    return done;
}

/* After a re-plan: the fraction goes on from where it is over what is
 * left. */
static void rebase(corr__plan *pl)
{
    pl->base = pl->last;
    pl->base_cost = done_cost(pl);
}

void corr__plan_rerun(corr__plan *pl, int runs)
{
    int k = pl->cur;
    while (k < pl->n && !pl->s[k].maybe)
        k++;
    if (k == pl->n)
        return;
    int end = k;
    while (end < pl->n && pl->s[end].maybe)
        end++;
    if (runs) {
        for (int i = k; i < end; i++) {
            pl->s[i].cost /= CORR__RERUN_SHARE;
            pl->s[i].maybe = 0;
        }
    } else {
        memmove(&pl->s[k], &pl->s[end], sizeof pl->s[0] * (size_t)(pl->n - end));
        pl->n -= end - k;
    }
    rebase(pl);
}

static int is_start(corr__phase ph)
{
    return ph == CORR__START || ph == CORR__START_FMAP || ph == CORR__START_MAPS;
}

/* Whether step s can take a report of stage st (not a second run's step
 * before RHM has decided to run it). */
static int takes(const corr__step *s, corr_stage st)
{
    if (s->maybe || s->beyond)
        return 0;
    switch (st) {
    case CORR_STAGE_START: return is_start(s->phase);
    case CORR_STAGE_RHM: return s->phase == CORR__RHM;
    case CORR_STAGE_ECTM: return s->phase == CORR__ECTM;
    case CORR_STAGE_DDM: return s->phase == CORR__DDM;
    case CORR_STAGE_REPAIR: return s->phase == CORR__REPAIR || s->phase == CORR__REPAIR_RELAX;
    default: return 0;
    }
}

/* The step a report of stage st belongs to: the current one while it is
 * not done, else the next that takes it (the steps between are done:
 * a stage that stopped early, a decimation that reports nothing); -1 for
 * none. */
static int step_of(corr__plan *pl, corr_stage st)
{
    if (pl->cur < pl->n && takes(&pl->s[pl->cur], st) && pl->s[pl->cur].done < 1)
        return pl->cur;
    for (int j = pl->cur + (pl->s[pl->cur].done > 0); j < pl->n; j++)
        if (takes(&pl->s[j], st))
            return j;
    return -1;
}

/* An ECTM report past the iterations its step counts in full: the run
 * goes on beyond the first iteration at which its stop rule may end it,
 * and the next step, which weighted those iterations by
 * CORR__BEYOND_SHARE, counts them in full from here. */
static void reach_beyond(corr__plan *pl, int outer)
{
    if (pl->cur + 1 >= pl->n)
        return;
    corr__step *s = &pl->s[pl->cur], *x = s + 1;
    if (s->phase != CORR__ECTM || s->done == 0 || !x->beyond || outer - s->first <= s->count)
        return;
    x->cost /= CORR__BEYOND_SHARE;
    x->beyond = 0;
    rebase(pl);
}

static double frac(double done, double total)
{
    return total > 0 ? fmin(1, fmax(0, done / total)) : 0;
}

void corr__plan_update(corr__plan *pl, corr_progress *cp)
{
    cp->fraction = pl->last;
    cp->eta_s = NAN;
    if (pl->n == 0)
        return;
    if (cp->ectm)
        reach_beyond(pl, cp->ectm->outer);
    int j = step_of(pl, cp->stage);
    if (j >= 0) {
        for (int i = pl->cur; i < j; i++)
            pl->s[i].done = 1;
        pl->cur = j;
        corr__step *s = &pl->s[j];
        if (cp->stage == CORR_STAGE_START)
            s->done = 1;
        else if (cp->rhm)
            s->done = frac(cp->rhm->iteration, cp->rhm->total);
        else if (cp->ddm)
            s->done = frac(cp->ddm->done, cp->ddm->total);
        else if (cp->repair)
            s->done = frac(cp->repair->done, cp->repair->total);
        else if (cp->ectm) {
            if (s->done == 0)                /* the run's first report: where it counts from */
                s->first = cp->ectm->outer - 1;
            s->done = frac(cp->ectm->outer - s->first, s->count);
        }
    }
    double done = done_cost(pl), total = 0;
    for (int i = 0; i < pl->n; i++)
        total += pl->s[i].cost;
    double f = pl->base + (1 - pl->base) * frac(done - pl->base_cost, total - pl->base_cost);
    if (f > pl->last)
        pl->last = f;
    cp->fraction = pl->last;
    if (done > 0 && cp->elapsed > 0)
        cp->eta_s = cp->elapsed * (total - done) / done;
}
