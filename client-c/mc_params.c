/* mc_params.c — the one job parameter list (PROTO_PARAMS) as data for
 * callers that walk it at run time instead of compiling against the macro
 * (the Python package): each row's name, option, type, value names and
 * help, and one mc_job_spec member set from text the way `meshcorr submit`
 * parses its option. Ranges stay the server's to check. */
#include "meshcorr.h"
#include "proto.h"

#include <stdio.h>
#include <string.h>

_Static_assert((int)MC_PARAM_ENUM == (int)PROTO_PARAM_ENUM && (int)MC_PARAM_BOOL == (int)PROTO_PARAM_BOOL &&
               (int)MC_PARAM_U32 == (int)PROTO_PARAM_U32 && (int)MC_PARAM_F64 == (int)PROTO_PARAM_F64 &&
               (int)MC_PARAM_STR == (int)PROTO_PARAM_STR, "one numbering of the parameter types");
_Static_assert((int)MC_DDM_PLAIN == (int)PROTO_DDM_PLAIN && (int)MC_DDM_BIJECTIVE == (int)PROTO_DDM_BIJECTIVE &&
                   (int)MC_DDM_AUTO == (int)PROTO_DDM_AUTO,
               "one numbering of ddm_mode");

int mc_param_count(void)
{
    return PROTO_NPARAMS;
}

static const proto_param_info *row(int i)
{
    return i >= 0 && i < PROTO_NPARAMS ? &proto_param_infos[i] : NULL;
}

const char *mc_param_name(int i)
{
    return row(i) ? row(i)->name : NULL;
}

const char *mc_param_cli(int i)
{
    return row(i) ? row(i)->cli : NULL;
}

int mc_param_type(int i)
{
    return row(i) ? row(i)->type : -1;
}

const char *mc_param_values(int i)
{
    return row(i) ? row(i)->values : NULL;
}

const char *mc_param_help(int i)
{
    return row(i) ? row(i)->help : NULL;
}

size_t mc_job_spec_size(void)
{
    return sizeof(mc_job_spec);
}

int mc_job_spec_set(mc_job_spec *s, const char *name, const char *text, char *err, size_t errsz)
{
    if (!s || !name || !text) {
        snprintf(err, errsz, "no spec, name or value");
        return MC_EARG;
    }
    int i = 0;
    while (i < PROTO_NPARAMS && strcmp(name, proto_param_infos[i].name) &&
           strcmp(name, proto_param_infos[i].cli))
        i++;
    if (i == PROTO_NPARAMS) {
        snprintf(err, errsz, "'%s' is not a job parameter (meshcorr params lists them)", name);
        return MC_EARG;
    }
    proto_params w;
    proto_params_init(&w);
    char perr[256];
    if (proto_param_parse(&w, i, text, perr, sizeof perr)) {
        snprintf(err, errsz, "%s: %s", proto_param_infos[i].name, perr);
        return MC_EARG;
    }
    switch (i) {
#define MC_SET_MEMBER(name, ...) case PROTO_P_##name: s->name = w.name; break;
        PROTO_PARAMS(MC_SET_MEMBER)
#undef MC_SET_MEMBER
    }
    return 0;
}
