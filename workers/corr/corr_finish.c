/* corr_finish.c — the finishing of a stage's maps: the fold repair
 * (corr_repair: fold_repair, then fold_relax where the policy says) and the
 * policy, one table, of which maps get it after which stage. */
#include "corr/corr.h"
#include "fold/fold.h"
#include "metric/metric.h"
#include "util/errbuf.h"

#include <string.h>

typedef enum finish_when { FINISH_NEVER, FINISH_ALWAYS, FINISH_IF_FOLDED } finish_when;

/* ANY matches a chain either way. */
#define ANY (-1)

static const struct finish_rule {
    corr_after after;
    int from_map;      /* the chain starts from a given map (1), landmarks (0) */
    int through_rhm;   /* the chain runs RHM */
    finish_when when;
    int relax;         /* fold_relax after fold_repair */
} rules[] = {
    /* RHM's maps: repaired, not relaxed, so that the start's choice reads
     * their folds and ECTM starts from maps without them. */
    { CORR_AFTER_RHM,   ANY, ANY, FINISH_ALWAYS,    0 },
    /* Maps carried from the decimated pair: as RHM's. */
    { CORR_AFTER_CARRY, ANY, ANY, FINISH_ALWAYS,    0 },
    /* ECTM's maps from RHM's in the landmark pipeline: its projection folds
     * where the deformed surface passes a thin part at an angle. */
    { CORR_AFTER_ECTM,  0,   ANY, FINISH_ALWAYS,    1 },
    /* A given map's chain through RHM: each map ECTM would return folded. */
    { CORR_AFTER_ECTM,  1,   1,   FINISH_IF_FOLDED, 1 },
    /* ECTM from the given (or only denoised) map: its folds are scattered
     * over the whole map and the repair's regions raise the error
     * (docs/decisions.md, "Fold repair after ECTM"). */
    { CORR_AFTER_ECTM,  1,   0,   FINISH_NEVER,     0 },
};

double corr_folded(const mesh *A, const mesh *B, const bmap *P)
{
    metric_summary m;
    if (metric_summarize(A, B, P, &m))
        return 2;
    return m.flipped_fraction + m.collapsed_fraction;
}

/* m when the map m from A onto B would be returned folded (metric_verdict), else NULL. */
static bmap *if_folded(const mesh *A, const mesh *B, bmap *m)
{
    return m && metric_verdict(corr_folded(A, B, m), 0) != METRIC_VERDICT_OK ? m : NULL;
}

int corr_finish_select(const corr_input *in, corr_after after, int through_rhm, bmap **P,
                       bmap **Q)
{
    int from_map = in->P0 != NULL;
    for (size_t i = 0; i < sizeof rules / sizeof rules[0]; i++) {
        const struct finish_rule *r = &rules[i];
        if (r->after != after || (r->from_map != ANY && r->from_map != from_map) ||
            (r->through_rhm != ANY && r->through_rhm != !!through_rhm))
            continue;
        if (r->when == FINISH_NEVER) {
            *P = NULL;
            *Q = NULL;
        } else if (r->when == FINISH_IF_FOLDED) {
            *P = if_folded(in->S, in->T, *P);
            *Q = if_folded(in->T, in->S, *Q);
        }
        return r->relax;
    }
    *P = *Q = NULL;   /* no row: the table covers every case (test_corr_chain) */
    return 0;
}

int corr_repair(const corr_input *in, bmap *P, bmap *Q, int relax, fold_report rep[2],
                char *err, size_t errsz)
{
    fold_params fp;
    fold_params_init(&fp);
    memset(rep, 0, 2 * sizeof *rep);
    int n = in->L ? in->L->n : 0;
    const int *ls = in->L ? in->L->src : NULL, *lt = in->L ? in->L->tgt : NULL;
    fold_report r;
    int rc = P ? fold_repair(in->S, in->T, ls, n, &fp, P, &rep[0]) : 0;
    if (!rc && Q)
        rc = fold_repair(in->T, in->S, lt, n, &fp, Q, &rep[1]);
    if (!rc && relax && P && !(rc = fold_relax(in->S, in->T, ls, n, P, &r))) {
        rep[0].relaxed = r.relaxed;
        rep[0].bad_after = r.bad_after;
    }
    if (!rc && relax && Q && !(rc = fold_relax(in->T, in->S, lt, n, Q, &r))) {
        rep[1].relaxed = r.relaxed;
        rep[1].bad_after = r.bad_after;
    }
    if (rc)
        return errbuf_set(err, errsz, corr_from_fold(rc),
                          "repairing the folds of the maps: %s", fold_strerror(rc));
    return KIND_OK;
}
