/* corr.c — the correspondence pipeline (see corr.h): validation, the
 * chosen stages in their order (DDM, RHM from landmarks or from the maps,
 * ECTM), progress fan-in. Combines modules; computes nothing itself. */
#include "corr/corr.h"
#include "corr/corr__ddm.h"
#include "mesh/mesh_check.h"
#include "util/errbuf.h"

#include <string.h>
#include <time.h>

const char *corr_strerror(int code)
{
    switch (code) {
#define CORR_STR(name, val, msg) case name: return msg;
        CORR_ERRORS(CORR_STR)
#undef CORR_STR
    }
    return "unknown pipeline error";
}

const char *corr_stage_name(corr_stage s)
{
    switch (s) {
    case CORR_STAGE_ECTM: return "ectm";
    case CORR_STAGE_START: return "start";
    case CORR_STAGE_RHM: return "rhm";
    case CORR_STAGE_DDM: return "ddm";
    default: return "init";
    }
}

int corr_validate(const mesh *m, const char *name, char *err, size_t errsz)
{
    mesh_check_report rep;
    char detail[512];
    if (mesh_check_run(m, &rep, detail, sizeof detail))
        return errbuf_set(err, errsz, CORR_ENOMEM, "%s: %s", name, detail);
    if (mesh_check_usable(&rep))
        return CORR_OK;
    char lines[2048];
    mesh_check_problems(&rep, name, lines, sizeof lines);
    size_t n = strlen(lines);
    if (n && lines[n - 1] == '\n')
        lines[n - 1] = '\0';
    return errbuf_set(err, errsz, CORR_EMESH, "%s is not usable by the optimizer:\n%s", name, lines);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct relay {
    corr_progress_fn fn;
    void *ctx;
    double t0;
} relay;

static int relay_ectm(void *ctx, const ectm_report *r)
{
    relay *rl = ctx;
    if (!rl->fn)
        return 0;
    corr_progress p = { CORR_STAGE_ECTM, r, now() - rl->t0, NULL, NULL };
    return rl->fn(rl->ctx, &p);
}

static int relay_ddm(void *ctx, const corr_ddm_report *r)
{
    relay *rl = ctx;
    if (!rl->fn)
        return 0;
    corr_progress p = { CORR_STAGE_DDM, NULL, now() - rl->t0, NULL, r };
    return rl->fn(rl->ctx, &p);
}

static int relay_rhm(void *ctx, const rhm_report *r)
{
    relay *rl = ctx;
    if (!rl->fn)
        return 0;
    corr_progress p = { r->iteration ? CORR_STAGE_RHM : CORR_STAGE_START, NULL,
                        now() - rl->t0, r, NULL };
    return rl->fn(rl->ctx, &p);
}

static int from_rhm(int rc)
{
    switch (rc) {
    case RHM_OK: return CORR_OK;
    case RHM_ECANCELED: return CORR_ECANCELED;
    case RHM_ENOMEM: return CORR_ENOMEM;
    case RHM_EPARAM: case RHM_EINPUT: return CORR_EINPUT;
    case RHM_EMESH: return CORR_EMESH;
    default: return CORR_EINIT;
    }
}

int corr_repair(const corr_input *in, bmap *P, bmap *Q, fold_report rep[2], char *err,
                size_t errsz)
{
    fold_params fp;
    fold_params_init(&fp);
    memset(rep, 0, 2 * sizeof *rep);
    int n = in->L ? in->L->n : 0;
    int rc = fold_repair(in->S, in->T, in->L ? in->L->src : NULL, n, &fp, P, &rep[0]);
    if (!rc && Q)
        rc = fold_repair(in->T, in->S, in->L ? in->L->tgt : NULL, n, &fp, Q, &rep[1]);
    if (rc)
        return errbuf_set(err, errsz, rc == FOLD_ENOMEM ? CORR_ENOMEM : CORR_EINIT,
                          "repairing the folds of the maps: %s", fold_strerror(rc));
    return CORR_OK;
}

static int from_ectm(int rc)
{
    switch (rc) {
    case ECTM_OK: return CORR_OK;
    case ECTM_ECANCELED: return CORR_ECANCELED;
    case ECTM_ENOMEM: return CORR_ENOMEM;
    case ECTM_EMAP: case ECTM_EPARAM: return CORR_EINPUT;
    case ECTM_EMESH: return CORR_EMESH;
    default: return CORR_EFAILED;
    }
}

int corr_run(const corr_input *in, const ectm_params *p, corr_progress_fn progress,
             void *ctx, ectm_result *out, char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    relay rl = { progress, ctx, now() };
    int rc = ectm_params_check(p, err, errsz);
    if (rc)
        return CORR_EINPUT;
    if ((rc = corr_validate(in->S, in->S_name, err, errsz)) ||
        (rc = corr_validate(in->T, in->T_name, err, errsz)))
        return rc;
    rhm_params rp;
    if (in->rhm)
        rp = *in->rhm;
    else
        rhm_params_init(&rp);
    int bij = p->model == ECTM_BIJECTIVE;
    if ((rc = corr_stages_check(in->stages, !!in->P0, !!in->Q0, in->L ? in->L->n : 0, !bij,
                                rp.gamma, in->ddm_mode, err, errsz)))
        return rc;
    unsigned run = corr_stages_run(in->stages, !!in->P0);
    if ((run & CORR_RUN_RHM) && rhm_params_check(&rp, err, errsz))
        return CORR_EINPUT;

    bmap *dP = NULL, *dQ = NULL;               /* DDM's maps */
    rhm_result init = {0};                     /* RHM's maps */
    const bmap *P = in->P0, *Q = bij ? in->Q0 : NULL;
    if (run & CORR_RUN_DDM) {
        if ((rc = corr__ddm(in, P, Q, relay_ddm, &rl, &dP, &dQ, err, errsz)))
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
        if (!P && progress) {
            corr_progress cp = { CORR_STAGE_INIT, NULL, now() - rl.t0, NULL, NULL };
            if (progress(ctx, &cp)) {
                rc = errbuf_set(err, errsz, CORR_ECANCELED, "cancelled before the initial map");
                goto done;
            }
        }
        rc = P ? rhm_run_from_maps(in->S, in->T, in->L, P, Q, &rp, relay_rhm, &rl, &init, err, errsz)
               : rhm_run(in->S, in->T, in->L, &rp, relay_rhm, &rl, &init, err, errsz);
        if (rc) {
            rc = from_rhm(rc);
            goto done;
        }
        fold_report rep[2];
        if ((rc = corr_repair(in, init.P12, init.P21, rep, err, errsz)))
            goto done;
        if (!(run & CORR_RUN_ECTM)) {
            out->P = init.P12;
            out->Q = init.P21;
            init.P12 = init.P21 = NULL;
            goto done;
        }
        P = init.P12;
        Q = bij ? init.P21 : NULL;
    }
    rc = from_ectm(ectm_run(in->S, in->T, P, Q, p, relay_ectm, &rl, out, err, errsz));
    if (rc == CORR_OK && !in->P0) {
        /* ECTM's projection folds where its deformed surface passes a thin
         * part at an angle: the same repair, on the maps it returns, in
         * the landmark pipeline where it was measured (bench_shrec07). Not
         * on a given map's chains: there it re-mapped large regions of
         * scattered flips and raised the error (the BCICP map gorilla ->
         * man, ddm,ectm: 0.049 -> 0.083, test_corr_stages) */
        fold_report rep[2];
        if ((rc = corr_repair(in, out->P, out->Q, rep, err, errsz)))
            ectm_result_close(out);
    }
done:
    bmap_free(dP);
    bmap_free(dQ);
    rhm_result_close(&init);
    return rc;
}
