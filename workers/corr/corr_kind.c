/* corr_kind.c — the pipeline's errors as the kinds of a job's failure
 * (proto_kind.h): their texts, their wire codes, and the translation of
 * every engine module's codes the pipeline meets, made from the kind
 * column of each module's error list. Tables only. */
#include "corr/corr.h"
#include "ctf/ctf.h"
#include "ddm/ddm.h"
#include "geod/geod.h"
#include "lbo/lbo.h"

int corr_wire_code(int code)
{
    return proto_kind_code(-code);
}

/* A module's code as -kind; a code its list does not have is INTERNAL. */
#define CORR_FROM_CASE(name, val, msg, kind) case name: return -PROTO_KIND_##kind;
#define CORR_FROM(module, LIST)                                                        \
    int corr_from_##module(int rc)                                                     \
    {                                                                                  \
        switch (rc) {                                                                  \
            LIST(CORR_FROM_CASE)                                                       \
        }                                                                              \
        return KIND_EINTERNAL;                                                         \
    }
CORR_FROM(fold, FOLD_ERRORS)
CORR_FROM(ddm, DDM_ERRORS)
CORR_FROM(ctf, CTF_ERRORS)
CORR_FROM(geod, GEOD_ERRORS)
CORR_FROM(lbo, LBO_ERRORS)
CORR_FROM(lmk, LMK_ERRORS)
CORR_FROM(bmap, BMAP_ERRORS)
CORR_FROM(mesh, MESH_ERRORS)
CORR_FROM(repair, REPAIR_ERRORS)
