/* corr_chain.c — the stage chains of a job (corr.h, corr_chain): which
 * stages a value runs, whether a chain can run on the given inputs, and
 * reading a chain written "ddm,rhm,ectm" with a reason when it cannot be
 * one. */
#include "corr/corr.h"
#include "util/errbuf.h"

#include <stdio.h>
#include <string.h>

unsigned corr_chain_run(corr_chain s, int have_map)
{
    switch (s) {
    case CORR_CHAIN_ALL: return have_map ? CORR_RUN_ECTM : CORR_RUN_RHM | CORR_RUN_ECTM;
    case CORR_CHAIN_RHM: return CORR_RUN_RHM;
    case CORR_CHAIN_ECTM: return CORR_RUN_ECTM;
    case CORR_CHAIN_DDM: return CORR_RUN_DDM;
    case CORR_CHAIN_DDM_ECTM: return CORR_RUN_DDM | CORR_RUN_ECTM;
    case CORR_CHAIN_DDM_RHM: return CORR_RUN_DDM | CORR_RUN_RHM;
    case CORR_CHAIN_DDM_RHM_ECTM: return CORR_RUN_DDM | CORR_RUN_RHM | CORR_RUN_ECTM;
    case CORR_CHAIN_RHM_ECTM: return CORR_RUN_RHM | CORR_RUN_ECTM;
    }
    return 0;
}

int corr_chain_check(corr_chain s, int have_map, int have_reverse, int nlandmarks,
                      int injective, double rhm_landmark_weight, corr_ddm_mode ddm_mode,
                      char *err, size_t errsz)
{
    unsigned run = corr_chain_run(s, have_map);
    if (!run)
        return errbuf_set(err, errsz, KIND_EPARAMS, "stages value %d is not one of the list", (int)s);
    if (ddm_mode != CORR_DDM_PLAIN && ddm_mode != CORR_DDM_BIJECTIVE && ddm_mode != CORR_DDM_AUTO)
        return errbuf_set(err, errsz, KIND_EPARAMS, "ddm_mode value %d is not one of the list",
                          (int)ddm_mode);
    if (have_reverse && !have_map)
        return errbuf_set(err, errsz, KIND_EMAP, "an initial reverse map needs an initial map");
    if (have_reverse && injective)
        return errbuf_set(err, errsz, KIND_EPARAMS, "an initial reverse map needs the bijective model");
    if ((run & CORR_RUN_DDM) && !have_map)
        return errbuf_set(err, errsz, KIND_EPARAMS,
                          "the DDM stage denoises a given map: it needs an initial map");
    if ((run & CORR_RUN_DDM) && ddm_mode == CORR_DDM_BIJECTIVE && !have_reverse)
        return errbuf_set(err, errsz, KIND_EPARAMS,
                          "bijective DDM (ddm_mode bijective) denoises a map and its reverse "
                          "together: it needs an initial reverse map too");
    if (!have_map) {
        if (!(run & CORR_RUN_RHM))
            return errbuf_set(err, errsz, KIND_EPARAMS, "the ECTM stage alone needs an initial map");
        if (nlandmarks == 0)
            return errbuf_set(err, errsz, KIND_ELANDMARKS,
                              "neither an initial map nor landmarks were given");
        if (nlandmarks < PROTO_MIN_LANDMARKS)
            return errbuf_set(err, errsz, KIND_ELANDMARKS,
                              "RHM from landmarks needs at least %d landmark pairs, got %d",
                              PROTO_MIN_LANDMARKS, nlandmarks);
    }
    if ((run & CORR_RUN_RHM) && have_map && rhm_landmark_weight > 0 && nlandmarks == 0)
        return errbuf_set(err, errsz, KIND_EPARAMS,
                          "RHM's weak landmark term (rhm_landmark_weight %g) needs landmarks",
                          rhm_landmark_weight);
    return KIND_OK;
}

static const char *const stage_word[3] = {"ddm", "rhm", "ectm"};   /* the order they run in */

int corr_chain_parse(const char *text, corr_chain *out, char *err, size_t errsz)
{
    if (strcmp(text, "all") == 0) {
        *out = CORR_CHAIN_ALL;
        return 0;
    }
    unsigned run = 0;
    int last = -1;
    const char *s = text;
    for (;;) {
        size_t n = strcspn(s, ",");
        int w = -1;
        for (int k = 0; k < 3; k++)
            if (strlen(stage_word[k]) == n && strncmp(s, stage_word[k], n) == 0)
                w = k;
        if (w < 0) {
            if (n == 3 && strncmp(s, "all", 3) == 0)
                errbuf_set(err, errsz, -1, "'%s': all stands alone", text);
            else
                errbuf_set(err, errsz, -1, "'%s': '%.*s' is not a stage (ddm, rhm, ectm, or all)",
                           text, (int)n, s);
            return -1;
        }
        if (run & (1u << w)) {
            errbuf_set(err, errsz, -1, "'%s': %s is named twice", text, stage_word[w]);
            return -1;
        }
        if (w < last) {
            errbuf_set(err, errsz, -1,
                       "'%s': %s before %s: stages run in the order ddm, rhm, ectm (DDM cleans "
                       "the given map, RHM needs a start, ECTM only refines and comes last)",
                       text, stage_word[last], stage_word[w]);
            return -1;
        }
        run |= 1u << w;
        last = w;
        if (!s[n])
            break;
        s += n + 1;
    }
    for (int v = CORR_CHAIN_RHM; v <= CORR_CHAIN_RHM_ECTM; v++)
        if (corr_chain_run((corr_chain)v, 1) == run) {
            *out = (corr_chain)v;
            return 0;
        }
    errbuf_set(err, errsz, -1, "'%s' is not a chain of ddm, rhm, ectm", text);
    return -1;
}
