/* proto_err.c — names and messages for the wire error codes and for the
 * enumerations that travel in messages. Tables only: no state, no I/O. */
#include "proto.h"
#include "proto_int.h"

#include <stdarg.h>
#include <stdio.h>

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
    static const char *const names[] = { "start", "rhm", "ectm", "init", "ddm" };
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
