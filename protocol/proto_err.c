/* proto_err.c — names and messages for the wire error codes and for the
 * enumerations that travel in messages. Tables only: no state, no I/O. */
#include "proto.h"
#include "proto_int.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

const char *proto_strerror(int code)
{
    switch (code) {
#define PROTO_CASE(sym, val, name, msg) case sym: return msg;
    PROTO_ERRORS(PROTO_CASE)
#undef PROTO_CASE
    }
    return "unknown error";
}

const char *proto_err_name(int code)
{
    switch (code) {
#define PROTO_CASE(sym, val, name, msg) case sym: return name;
    PROTO_ERRORS(PROTO_CASE)
#undef PROTO_CASE
    }
    return "UNKNOWN";
}

int proto_err_code(const char *name)
{
#define PROTO_CASE(sym, val, text, msg) if (val && strcmp(name, text) == 0) return sym;
    PROTO_ERRORS(PROTO_CASE)
#undef PROTO_CASE
    return 0;
}

int proto_kind_code(int kind)
{
    switch (kind) {
    case PROTO_KIND_NONE: return 0;
#define PROTO_CASE(k, code, exit, text) case PROTO_KIND_##k: return code;
    PROTO_KINDS(PROTO_CASE)
#undef PROTO_CASE
    }
    return PROTO_EINTERNAL;
}

int proto_kind_of_code(int code)
{
#define PROTO_CASE(k, c, exit, text) if (code == c) return PROTO_KIND_##k;
    PROTO_KINDS(PROTO_CASE)
#undef PROTO_CASE
    return PROTO_KIND_NONE;
}

const char *proto_kind_name(int kind)
{
    return kind > PROTO_KIND_NONE && kind < PROTO_NKINDS ? proto_err_name(proto_kind_code(kind)) : NULL;
}

const char *proto_kind_text(int kind)
{
    switch (kind) {
#define PROTO_CASE(k, code, exit, text) case PROTO_KIND_##k: return text;
    PROTO_KINDS(PROTO_CASE)
#undef PROTO_CASE
    }
    return "unknown error kind";
}

int proto_kind_exit(int kind)
{
    switch (kind) {
#define PROTO_CASE(k, code, exit, text) case PROTO_KIND_##k: return exit;
    PROTO_KINDS(PROTO_CASE)
#undef PROTO_CASE
    }
    return 1;
}

const char *proto_type_name(int type)
{
    switch (type) {
#define PROTO_CASE(name, val) case val: return #name;
    PROTO_TYPES(PROTO_CASE)
#undef PROTO_CASE
    }
    return NULL;
}

const char *proto_state_name(int state)
{
    switch (state) {
#define PROTO_CASE(name, val) case val: return #name;
    PROTO_STATES(PROTO_CASE)
#undef PROTO_CASE
    }
    return NULL;
}

const char *proto_stage_name(int stage)
{
    static const char *const names[] = { "start", "rhm", "ectm", "init", "ddm", "repair", "queued" };
    return stage >= 0 && stage <= PROTO_STAGE_LAST ? names[stage] : NULL;
}

const char *proto_slot_name(int slot)
{
    static const char *const names[] = { "idle", "starting", "busy", "draining" };
    return slot >= 0 && slot <= PROTO_SLOT_LAST ? names[slot] : NULL;
}

int proto__errf(char *err, size_t errsz, int code, const char *fmt, ...)
{
    if (err && errsz) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errsz, fmt, ap);
        va_end(ap);
    }
    return code;
}
