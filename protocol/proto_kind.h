/* proto_kind.h — the kinds of a job's failure: the one list every layer
 * takes a failed job's error from, so a kind survives from the engine to
 * the user.
 *
 *   engine     the pipeline's codes are CORR_E<KIND> = -PROTO_KIND_<KIND>
 *              (workers/corr/corr.h); each engine module's error list has a
 *              kind column, from which the pipeline translates its codes
 *              (corr_from_rhm, corr_from_ectm, ...)
 *   worker     error.frame carries the kind's wire code (the second column,
 *              a row of PROTO_ERRORS)
 *   daemon     the job ends FAILED (OUT_OF_MEMORY for NOMEM, CANCELLED for
 *              CANCELLED) with the reason "NAME: message", NAME the wire
 *              code's name (proto_err_name)
 *   client     libmeshcorr reads NAME back (mc_reason_error); the CLI exits
 *              with the kind's status (third column) and names the kind;
 *              the Python package's Job.error is a MeshcorrError of that code
 *
 * tests/unit/test_error_kinds.c walks the list through every layer, and
 * provokes each kind it can with a real input. Tables only: no state. */
#ifndef PROTO_KIND_H
#define PROTO_KIND_H

/*  kind        wire code              exit  what it means */
#define PROTO_KINDS(X)                                                                           \
    X(MESH,      PROTO_EBAD_MESH,      1, "a mesh is not usable")                                \
    X(LANDMARKS, PROTO_EBAD_LANDMARKS, 1, "the landmarks do not fit the meshes")                 \
    X(PARAMS,    PROTO_EBAD_PARAMS,    1, "a parameter is out of range or does not fit the inputs") \
    X(MAP,       PROTO_EBAD_MAP,       1, "a given initial map is not usable")                   \
    X(NUMERIC,   PROTO_ENUMERIC,       3, "a stage failed numerically")                          \
    X(NOMEM,     PROTO_ENOMEM,         4, "out of memory")                                       \
    X(CANCELLED, PROTO_ECANCELLED,     5, "cancelled")                                           \
    X(IO,        PROTO_ESTORAGE,       1, "a file could not be read or written")                 \
    X(INTERNAL,  PROTO_EINTERNAL,      1, "internal error")

/* NONE (0) is no failure: the kind of an engine module's OK row. */
enum proto_kind {
    PROTO_KIND_NONE = 0,
#define PROTO_KIND_ENUM(kind, code, exit, text) PROTO_KIND_##kind,
    PROTO_KINDS(PROTO_KIND_ENUM)
#undef PROTO_KIND_ENUM
    PROTO_NKINDS
};

/* The wire code of kind k; PROTO_EINTERNAL for a value outside the list, 0
 * for NONE. */
int proto_kind_code(int kind);
/* The kind whose wire code is code; PROTO_KIND_NONE for a code that is no
 * kind's (a session's refusal such as NOT_FOUND). */
int proto_kind_of_code(int code);
/* "NUMERIC": the name of the kind's wire code; NULL outside the list. */
const char *proto_kind_name(int kind);
/* "a stage failed numerically"; "unknown error kind" outside the list. */
const char *proto_kind_text(int kind);
/* The exit status of the CLI for a job that failed with kind k (1 for a
 * value outside the list). */
int proto_kind_exit(int kind);

#endif
