/* test_proto_params.c — the one list of job parameters: PROTOCOL.md's
 * table is the list's, every layer's defaults are the list's (wire, client
 * spec, engine), the one validator refuses each bad value naming the field
 * and the engine's checks agree with it at every range end, and a value
 * parsed from text round-trips. */
#include "support/harness.h"
#include "corr/corr.h"
#include "lbo/lbo.h"
#include "meshcorr.h"
#include "proto.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* s equals want (NULL when the validator accepted). */
#define CHECK_STR(s, want) do { const char *s_ = (s);                                    \
        if (!s_ || strcmp(s_, (want)) != 0) FAILF("'%s' is not '%s'", s_ ? s_ : "(null)", (want)); \
    } while (0)

TEST(protocol_md_holds_the_table_of_the_list)
{
    FILE *fp = fopen("protocol/PROTOCOL.md", "rb");
    CHECK(fp != NULL);
    static char doc[1 << 20];
    size_t n = fread(doc, 1, sizeof doc - 1, fp);
    fclose(fp);
    doc[n] = '\0';
    const char *begin = strstr(doc, "<!-- params:begin"), *end = strstr(doc, "<!-- params:end");
    CHECK(begin && end && begin < end);
    begin = strchr(begin, '\n') + 1;
    size_t want_len = proto_params_table(NULL, 0);
    char *want = malloc(want_len + 1);
    proto_params_table(want, want_len + 1);
    if ((size_t)(end - begin) != want_len || memcmp(begin, want, want_len) != 0)
        FAILF("PROTOCOL.md's parameter table is not the list's: run make doc-params");
    free(want);
}

TEST(every_layer_starts_from_the_list_defaults)
{
    proto_params w, e;
    proto_params_init(&w);
    char err[256];
    CHECK_INT(proto_params_check(&w, err, sizeof err), 0);
    /* the engine's defaults, as job parameters */
    ectm_params p;
    rhm_params r;
    ectm_params_init(&p);
    rhm_params_init(&r);
    proto_params_init(&e);
    corr_params_to_job(&p, &r, &e, NULL, 0);
    /* the client's */
    mc_job_spec s;
    mc_job_spec_init(&s);
    for (int i = 0; i < PROTO_NPARAMS; i++) {
        const proto_param_info *f = &proto_param_infos[i];
        if (f->type == PROTO_PARAM_STR)
            continue;
        CHECK_NEAR(proto_param_get(&w, i), f->dflt, 0);
        CHECK_NEAR(proto_param_get(&e, i), f->dflt, 0);
    }
    CHECK_STR(w.backend, "");
    CHECK_INT(s.model, MC_BIJECTIVE);
    CHECK_NEAR(s.alpha, 20, 0);
    CHECK_NEAR(s.eta, 2e-3 / 3, 0);
    CHECK_INT(s.inner_iterations, 50);
    CHECK_INT(s.rhm_dim, 8);
    CHECK_NEAR(s.rhm_alpha, 5e-4, 0);
    CHECK(s.backend == NULL);
    /* and back: the engine of the defaults is the engine's defaults */
    ectm_params p2;
    rhm_params r2;
    CHECK_INT(corr_params_from_job(&w, 0, &p2, &r2, err, sizeof err), 0);
    CHECK(memcmp(&p, &p2, sizeof p) == 0);
    CHECK(memcmp(&r, &r2, sizeof r) == 0);
}

/* proto_params_check's message for one bad field. */
static const char *refusal(int i, double v)
{
    static char err[256];
    proto_params w;
    proto_params_init(&w);
    char *at = (char *)&w + proto_param_infos[i].offset;
    switch (proto_param_infos[i].type) {
    case PROTO_PARAM_ENUM: case PROTO_PARAM_BOOL: *(uint8_t *)at = (uint8_t)v; break;
    case PROTO_PARAM_U32: *(uint32_t *)at = (uint32_t)v; break;
    case PROTO_PARAM_F64: *(double *)at = v; break;
    }
    err[0] = '\0';
    return proto_params_check(&w, err, sizeof err) == PROTO_EBAD_PARAMS ? err : NULL;
}

TEST(validator_names_the_field_and_the_bound)
{
    CHECK_STR(refusal(PROTO_P_inner_iterations, 500000), "inner_iterations = 500000: out of range [1, 100000]");
    CHECK_STR(refusal(PROTO_P_rhm_alpha, 2), "rhm_alpha = 2: out of range (0, 1); 0 = the default");
    CHECK_STR(refusal(PROTO_P_rhm_alpha, 1), "rhm_alpha = 1: out of range (0, 1); 0 = the default");
    CHECK_STR(refusal(PROTO_P_rhm_dim, 100000), "rhm_dim = 100000: out of range [3, 64]; 0 = the default");
    CHECK_STR(refusal(PROTO_P_alpha, 0), "alpha = 0: out of range (0, inf)");
    CHECK_STR(refusal(PROTO_P_eta, -1), "eta = -1: out of range [0, inf)");
    CHECK_STR(refusal(PROTO_P_gamma, NAN), "gamma = nan: not a finite number");
    CHECK_STR(refusal(PROTO_P_tolerance, INFINITY), "tolerance = inf: not a finite number");
    CHECK_STR(refusal(PROTO_P_model, 2), "model = 2: not bijective or injective");
    CHECK_STR(refusal(PROTO_P_beta_ramp, 0), "beta_ramp = 0: out of range [1, 1000000]");
    CHECK(refusal(PROTO_P_rhm_dim, 0) == NULL);          /* 0 = the default */
    CHECK(refusal(PROTO_P_rhm_iterations, 0) == NULL);
    CHECK(refusal(PROTO_P_rhm_alpha, 0) == NULL);
    CHECK(refusal(PROTO_P_iterations, 0) != NULL);       /* no 0 rule here */
    proto_params w;
    char err[256];
    proto_params_init(&w);
    const char *ok[] = {"", "cpu", "opencl", "auto", "opencl:NVIDIA H200"};
    for (size_t k = 0; k < sizeof ok / sizeof ok[0]; k++) {
        w.backend = ok[k];
        CHECK_INT(proto_params_check(&w, err, sizeof err), 0);
    }
    w.backend = "gpu-please";
    CHECK_INT(proto_params_check(&w, err, sizeof err), PROTO_EBAD_PARAMS);
    CHECK_STR(err, "backend = 'gpu-please': not cpu, opencl or auto (optionally :DEVICE)");
    char longdev[200];
    snprintf(longdev, sizeof longdev, "opencl:%0*d", PROTO_MAX_DEVICE + 1, 0);
    w.backend = longdev;
    CHECK_INT(proto_params_check(&w, err, sizeof err), PROTO_EBAD_PARAMS);
    CHECK_STR_HAS(err, "device name of 128 bytes");
}

/* The engine's own checks (ectm_params_check, rhm_params_check) accept and
 * refuse exactly where the validator does, at both ends of every range. */
TEST(engine_checks_agree_with_the_validator_at_every_range_end)
{
    char err[256];
    for (int i = 0; i < PROTO_NPARAMS; i++) {
        const proto_param_info *f = &proto_param_infos[i];
        if (f->type == PROTO_PARAM_STR)
            continue;
        double step = f->type == PROTO_PARAM_F64 ? fmax(fabs(f->min), 1) * 1e-9 : 1;
        double probe[4] = {f->min - step, f->min, isinf(f->max) ? 1e300 : f->max,
                           isinf(f->max) ? INFINITY : f->max + step};
        for (int k = 0; k < 4; k++) {
            double v = probe[k];
            if ((f->type != PROTO_PARAM_F64 && (v < 0 || v > UINT32_MAX)) ||
                ((f->flags & PROTO_PARAM_ZERO_DEFAULT) && v == 0))
                continue;               /* not representable, or the wire's 0 rule */
            int want = proto_param_check(i, v, err, sizeof err) != 0;
            ectm_params p;
            rhm_params r;
            ectm_params_init(&p);
            rhm_params_init(&r);
            /* the engine field of row i, set directly */
            switch (i) {
#define ENGINE_SET_ECTM(efield) p.efield = v;
#define ENGINE_SET_RHM(efield) r.efield = v;
#define ENGINE_SET_NONE(efield)
#define ENGINE_SET(name, cli, type, dflt, lo, hi, fl, eng, efield, ...) \
            case PROTO_P_##name: ENGINE_SET_##eng(efield) break;
            PROTO_PARAMS(ENGINE_SET)
#undef ENGINE_SET
            }
            int got = ectm_params_check(&p, err, sizeof err) != 0 || rhm_params_check(&r, err, sizeof err) != 0;
            /* the rows the pipeline reads itself (ENGINE NONE): its own rules */
            if (i == PROTO_P_stages)
                got = corr_chain_run((corr_chain)v, 1) == 0 || v != floor(v);
            else if (i == PROTO_P_ddm_k)
                got = v < 0 || v > LBO_MAX_K;
            else if (i == PROTO_P_ddm_mode)
                got = v != floor(v) || corr_chain_check(CORR_CHAIN_DDM, 1, 1, 0, 0, 0,
                                                         (corr_ddm_mode)v, err, sizeof err) != 0;
            else if (i == PROTO_P_repair)       /* yes (0) or no (1): the worker's reading */
                got = v != 0 && v != 1;
            if (got != want)
                FAILF("%s = %g: validator %s, engine %s", f->name, v, want ? "refuses" : "accepts",
                      got ? "refuses" : "accepts");
        }
    }
}

TEST(values_parse_from_text_by_type)
{
    proto_params w;
    char err[256];
    proto_params_init(&w);
    CHECK_INT(proto_param_parse(&w, PROTO_P_model, "injective", err, sizeof err), 0);
    CHECK_INT(w.model, PROTO_MODEL_INJECTIVE);
    CHECK_INT(proto_param_parse(&w, PROTO_P_start, "voronoi", err, sizeof err), 0);
    CHECK_INT(w.start, PROTO_START_VORONOI);
    CHECK_INT(proto_param_parse(&w, PROTO_P_inner_iterations, "77", err, sizeof err), 0);
    CHECK_INT(w.inner_iterations, 77);
    CHECK_INT(proto_param_parse(&w, PROTO_P_alpha, "2.5e1", err, sizeof err), 0);
    CHECK_NEAR(w.alpha, 25, 0);
    CHECK_INT(proto_param_parse(&w, PROTO_P_alpha, "abc", err, sizeof err), PROTO_EBAD_PARAMS);
    CHECK_STR(err, "'abc' is not a number");
    CHECK_INT(proto_param_parse(&w, PROTO_P_iterations, "1.5", err, sizeof err), PROTO_EBAD_PARAMS);
    CHECK_STR(err, "'1.5' is not an integer in [1, 1000000]");      /* the row's range, not u32's */
    CHECK_INT(proto_param_parse(&w, PROTO_P_zoomout, "-1", err, sizeof err), PROTO_EBAD_PARAMS);
    CHECK_STR(err, "'-1' is not an integer in [51, 300]; or 0 = off");
    CHECK_INT(proto_param_parse(&w, PROTO_P_start, "cells", err, sizeof err), PROTO_EBAD_PARAMS);
    CHECK_STR(err, "'cells' is not distances, voronoi, fmap or auto");
    char line[1024];
    proto_params_format(&w, line, sizeof line);
    CHECK_STR_HAS(line, "model=injective partial=0 alpha=25 ");
    CHECK_STR_HAS(line, " inner_iterations=77 ");
    CHECK_STR_HAS(line, " start=voronoi backend=");
}

/* zoomout: 0 (off) or 51..300; 1..50 refused where a job is parsed (the
 * client and the daemon), not only when the worker starts it. */
TEST(zoomout_is_off_or_larger_than_the_fmap_start_basis)
{
    char err[256];
    CHECK_INT(proto_param_check(PROTO_P_zoomout, 0, err, sizeof err), PROTO_OK);
    CHECK_INT(proto_param_check(PROTO_P_zoomout, 51, err, sizeof err), PROTO_OK);
    CHECK_INT(proto_param_check(PROTO_P_zoomout, 300, err, sizeof err), PROTO_OK);
    CHECK(proto_param_check(PROTO_P_zoomout, 20, err, sizeof err) != PROTO_OK);
    printf("  %s\n", err);
    CHECK(strstr(err, "zoomout") && strstr(err, "51"));
    CHECK(proto_param_check(PROTO_P_zoomout, 301, err, sizeof err) != PROTO_OK);
    proto_params w;
    proto_params_init(&w);
    CHECK_INT(proto_param_parse(&w, PROTO_P_zoomout, "50", err, sizeof err), PROTO_OK);
    CHECK(proto_params_check(&w, err, sizeof err) != PROTO_OK);
    w.zoomout = 0;
    CHECK_INT(proto_params_check(&w, err, sizeof err), PROTO_OK);
}

/* coarse: 0 (off) or PROTO_COARSE_MIN..PROTO_COARSE_MAX, 6000 by default. */
TEST(coarse_is_off_or_a_vertex_count_in_range)
{
    char err[256];
    proto_params w;
    proto_params_init(&w);
    CHECK_INT(w.coarse, 6000);
    CHECK_INT(proto_param_check(PROTO_P_coarse, 0, err, sizeof err), PROTO_OK);
    CHECK_INT(proto_param_check(PROTO_P_coarse, PROTO_COARSE_MIN, err, sizeof err), PROTO_OK);
    CHECK(proto_param_check(PROTO_P_coarse, PROTO_COARSE_MIN - 1, err, sizeof err) != PROTO_OK);
    CHECK(strstr(err, "coarse") && strstr(err, "500"));
    CHECK(proto_param_check(PROTO_P_coarse, (double)PROTO_COARSE_MAX + 1, err, sizeof err) != PROTO_OK);
}

/* The CLI's naming: the option the user typed, its value and the whole
 * range from the list, never the wire's internal form. */
TEST(validator_names_the_option_for_the_cli)
{
    proto_params w;
    char err[256];
    proto_params_init(&w);
    w.iterations = 0;
    CHECK_INT(proto_params_check_as(&w, PROTO_NAME_CLI, err, sizeof err), PROTO_EBAD_PARAMS);
    CHECK_STR(err, "--iterations 0: out of range [1, 1000000]");
    CHECK_INT(proto_params_check(&w, err, sizeof err), PROTO_EBAD_PARAMS);
    CHECK_STR(err, "iterations = 0: out of range [1, 1000000]");
    proto_params_init(&w);
    w.inner_iterations = 500000;
    CHECK_INT(proto_params_check_as(&w, PROTO_NAME_CLI, err, sizeof err), PROTO_EBAD_PARAMS);
    CHECK_STR(err, "--inner-iterations 500000: out of range [1, 100000]");
    proto_params_init(&w);
    w.backend = "gpu";
    CHECK_INT(proto_params_check_as(&w, PROTO_NAME_CLI, err, sizeof err), PROTO_EBAD_PARAMS);
    CHECK_STR(err, "--backend 'gpu': not cpu, opencl or auto (optionally :DEVICE)");
}
