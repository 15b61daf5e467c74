/* corr__plan.h — internal (corr__): the whole job's progress. corr_run
 * plans the steps its chain will run (DDM, the start map, RHM, the fold
 * repairs, ECTM, coarse to fine's decimation and second ECTM), each
 * weighted by its expected cost, and turns every stage report into the
 * fraction of the whole job done and the time left (corr_progress's
 * fraction and eta_s). Not part of the public corr_ API.
 *
 * The costs are one table (corr_plan.c, CORR__COSTS): seconds per 1000
 * vertices of the pair a step runs on, per iteration for RHM and ECTM,
 * measured on real jobs (docs/decisions.md, 2026-12-06). Only their ratios
 * matter: the time left is the elapsed time scaled by the cost left over
 * the cost done, so a machine twice as fast changes nothing. */
#ifndef CORR__PLAN_H
#define CORR__PLAN_H
#include "corr/corr.h"

typedef enum corr__phase {
    CORR__DECIMATE,     /* coarse to fine: both meshes decimated            */
    CORR__START,        /* the start map from landmarks: distances, Voronoi */
    CORR__START_FMAP,   /* the functional-map start                         */
    CORR__START_MAPS,   /* RHM's set-up from given maps                     */
    CORR__RHM,          /* per RHM iteration                                */
    CORR__REPAIR,       /* the fold repair of RHM's maps (or carried ones)   */
    CORR__REPAIR_RELAX, /* the repair of the maps a chain returns, relaxed  */
    CORR__ECTM,         /* per ECTM outer iteration                         */
    CORR__DDM,          /* per direction denoised (the bases included)      */
    CORR__NPHASES
} corr__phase;

#define CORR__MAX_STEPS 24

typedef struct corr__step {
    corr__phase phase;
    double cost;         /* expected, in the table's unit                    */
    int first, count;    /* ECTM: its outer iterations first+1..first+count  */
    double done;         /* 0..1                                             */
    int maybe;           /* start auto's second RHM run: its cost weighted by
                            CORR__RERUN_SHARE until corr__plan_rerun decides */
    int beyond;          /* ECTM's iterations past the first at which its stop
                            rule may end the run: weighted by
                            CORR__BEYOND_SHARE until a report reaches them */
} corr__step;

/* The share of start-auto jobs whose first RHM run's maps stay folded, so
 * that RHM runs again from the functional-map start: the weight of those
 * steps until it is known (docs/decisions.md, 2026-12-06). */
#define CORR__RERUN_SHARE 0.25
/* The expected share of ECTM's iterations from the first at which its stop
 * rule may end a run to the cap that a job runs: most jobs end at the first
 * (docs/decisions.md, 2026-12-06). */
#define CORR__BEYOND_SHARE 0.05

typedef struct corr__plan {
    corr__step s[CORR__MAX_STEPS];
    int n, cur;          /* steps; the one the latest report belongs to      */
    double base, base_cost; /* the fraction and cost done at the last re-plan */
    double last;         /* the latest fraction given (it never falls)       */
} corr__plan;

/* The steps of corr_run's chain on in with p and rp (checked already). */
void corr__plan_build(corr__plan *pl, const corr_input *in, const ectm_params *p,
                      const rhm_params *rp);
/* Start auto has decided (corr_rhm): RHM runs again from the
 * functional-map start (runs: its steps count in full) or not (they go).
 * Either way the fraction goes on from where it is, over what is left. */
void corr__plan_rerun(corr__plan *pl, int runs);
/* cp's fraction and eta_s from its stage report; elapsed: cp->elapsed. */
void corr__plan_update(corr__plan *pl, corr_progress *cp);
/* The expected cost of one unit of phase ph on nv vertices (for benches
 * and tests that check the table against a measured run). */
double corr__plan_cost(corr__phase ph, int nv);
const char *corr__phase_name(corr__phase ph);

#endif
