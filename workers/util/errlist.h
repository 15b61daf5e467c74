/* errlist.h — what a module makes of its error list.
 *
 * A module writes its errors once, as rows X(NAME, value, message) or
 * X(NAME, value, message, kind) of a list macro (MESH_ERRORS, ...); the kind
 * column, where there is one, names the job-failure kind of
 * protocol/proto_kind.h that corr_kind.c translates the code to. From the
 * list, ERRLIST_ENUM declares the enum of the names and ERRLIST_CASE makes
 * the cases of the module's message function:
 *
 *     ERRLIST_ENUM(mesh, MESH_ERRORS);         -> enum mesh_error { ... };
 *     switch (code) { MESH_ERRORS(ERRLIST_CASE) }
 */
#ifndef ERRLIST_H
#define ERRLIST_H

#define ERRLIST_NAME_VALUE(name, val, ...) name = val,
#define ERRLIST_ENUM(mod, LIST) enum mod##_error { LIST(ERRLIST_NAME_VALUE) }

#define ERRLIST_FIRST(first, ...) first
#define ERRLIST_CASE(name, val, ...) case name: return ERRLIST_FIRST(__VA_ARGS__, 0);

#endif
