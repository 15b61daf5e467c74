/* kind.h — the engine's error codes by kind: 0, or minus a kind of job
 * failure of protocol/proto_kind.h (KIND_EMESH = -PROTO_KIND_MESH, ...).
 *
 * The pipeline (corr), RHM and ECTM return these, so a failure keeps its
 * kind from the stage that met it to the client; the modules below them keep
 * lists of their own, each row with a kind (util/errlist.h), which
 * corr_kind.c translates to these. */
#ifndef KIND_H
#define KIND_H
#include "proto_kind.h"

enum kind_code {
    KIND_OK = 0,
#define KIND_CODE(kind, code, exit, text) KIND_E##kind = -PROTO_KIND_##kind,
    PROTO_KINDS(KIND_CODE)
#undef KIND_CODE
};

#endif
