/* test_stage_names.c — a job's stages and chains of stages are one list
 * each (protocol/proto.h: PROTO_STAGES, PROTO_CHAINS): the engine's
 * corr_stage and corr_chain, the client library's MC_STAGE_* and
 * MC_STAGES_*, mc_stage_name(), the names the stages parameter accepts and
 * the Python package's STAGES all come from them, row by row. */
#include "support/harness.h"
#include "support/testrun.h"
#include "corr/corr.h"
#include "meshcorr.h"
#include "proto.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

static char out[4096];

TEST(every_stage_has_one_value_and_name_in_engine_protocol_and_client)
{
    int n = 0;
#define STAGE_ROW(name, val)                                                                     \
    do {                                                                                         \
        n++;                                                                                     \
        CHECK_INT(CORR_STAGE_##name, val);                                                       \
        CHECK_INT(MC_STAGE_##name, val);                                                         \
        CHECK(proto_stage_name(val) != NULL);                                                    \
        CHECK(mc_stage_name(val) && strcmp(mc_stage_name(val), proto_stage_name(val)) == 0);                                  \
    } while (0);
    PROTO_STAGES(STAGE_ROW)
#undef STAGE_ROW
    CHECK_INT(n, PROTO_STAGE_LAST + 1);
    CHECK(proto_stage_name(PROTO_STAGE_LAST + 1) == NULL);
    CHECK(mc_stage_name(-1) == NULL);
}

TEST(every_chain_has_one_value_and_its_parameter_name_reads_back)
{
    int n = 0;
    char buf[64], err[256];
#define CHAIN_ROW(name, val)                                                                     \
    do {                                                                                         \
        n++;                                                                                     \
        CHECK_INT(CORR_CHAIN_##name, val);                                                       \
        CHECK_INT(MC_STAGES_##name, val);                                                        \
        const char *text = proto_param_value_name(PROTO_P_stages, val, buf, sizeof buf);      \
        corr_chain c = (corr_chain)-1;                                                           \
        if (corr_chain_parse(text, &c, err, sizeof err))                                         \
            FAILF("stages value %d is named \"%s\", which the engine refuses: %s", val, text, err); \
        CHECK_INT(c, val);                                                                       \
    } while (0);
    PROTO_CHAINS(CHAIN_ROW)
#undef CHAIN_ROW
    CHECK_INT(n, PROTO_CHAIN_LAST + 1);
}

TEST(pythons_stage_names_are_the_protocols)
{
    if (access("/usr/bin/python3", X_OK) != 0)
        SKIP("/usr/bin/python3 is not installed");
    char want[256] = "";
    for (int s = 0; proto_stage_name(s); s++)
        snprintf(want + strlen(want), sizeof want - strlen(want), "%s%s", s ? "," : "", proto_stage_name(s));
    int rc = testrunf(out, sizeof out,
                      "MESHCORR_LIB=build/libmeshcorr.so.1 PYTHONPATH=client-c/python PYTHONDONTWRITEBYTECODE=1 "
                      "/usr/bin/python3 -c 'import meshcorr.result as r; print(\"stages=\" + \",\".join(r.STAGES))' 2>&1");
    if (rc != 0)
        FAILF("python exited %d: %s", rc, out);
    char line[300];
    snprintf(line, sizeof line, "stages=%s\n", want);
    CHECK_STR_HAS(out, line);
}


