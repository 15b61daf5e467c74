/* proto_params.c — a job's parameters as data (proto_param_infos, built from
 * the one list PROTO_PARAMS in proto_params.h) and everything that walks
 * it: defaults, THE validator (proto_params_check), parsing a value from
 * text, the log line, and the PROTOCOL.md table. Pure C, no I/O. */
#include "proto.h"
#include "proto_int.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const proto_param_info proto_param_infos[PROTO_NPARAMS] = {
#define PROTO_PARAM_ROW(name, cli, type, dflt, lo, hi, fl, eng, efield, values, help) \
    {#name, cli, PROTO_PARAM_##type, dflt, lo, hi, fl, values, help, offsetof(proto_params, name)},
    PROTO_PARAMS(PROTO_PARAM_ROW)
#undef PROTO_PARAM_ROW
};

void proto_params_init(proto_params *p)
{
    memset(p, 0, sizeof *p);
    for (int i = 0; i < PROTO_NPARAMS; i++) {
        const proto_param_info *f = &proto_param_infos[i];
        char *at = (char *)p + f->offset;
        switch (f->type) {
        case PROTO_PARAM_ENUM: case PROTO_PARAM_BOOL: *(uint8_t *)at = (uint8_t)f->dflt; break;
        case PROTO_PARAM_U32: *(uint32_t *)at = (uint32_t)f->dflt; break;
        case PROTO_PARAM_F64: *(double *)at = f->dflt; break;
        case PROTO_PARAM_STR: *(const char **)at = ""; break;
        }
    }
}

double proto_param_get(const proto_params *p, int i)
{
    const proto_param_info *f = &proto_param_infos[i];
    const char *at = (const char *)p + f->offset;
    switch (f->type) {
    case PROTO_PARAM_ENUM: case PROTO_PARAM_BOOL: return *(const uint8_t *)at;
    case PROTO_PARAM_U32: return *(const uint32_t *)at;
    case PROTO_PARAM_F64: return *(const double *)at;
    }
    return 0;
}

const char *proto_param_value_name(int i, unsigned v, char *buf, size_t sz)
{
    const char *s = proto_param_infos[i].values;
    for (unsigned k = 0; *s; k++) {
        size_t n = strcspn(s, "|");
        if (k == v) {
            snprintf(buf, sz, "%.*s", (int)n, s);
            return buf;
        }
        s += n + (s[n] == '|');
    }
    return NULL;
}

/* "a, b or c" from "a|b|c". */
static const char *words_of(const char *values, char *buf, size_t sz)
{
    size_t o = 0;
    buf[0] = '\0';
    for (const char *s = values; *s && o < sz;) {
        size_t n = strcspn(s, "|");
        const char *sep = o == 0 ? "" : s[n] ? ", " : " or ";
        o += (size_t)snprintf(buf + o, sz - o, "%s%.*s", sep, (int)n, s);
        s += n + (s[n] == '|');
    }
    return buf;
}

/* The parameter as the message's reader knows it: "alpha =" or "--alpha". */
static const char *named(const proto_param_info *f, int naming, char *buf, size_t sz)
{
    if (naming == PROTO_NAME_CLI)
        snprintf(buf, sz, "--%s", f->cli);
    else
        snprintf(buf, sz, "%s =", f->name);
    return buf;
}

static int check_as(int i, double v, int naming, char *err, size_t errsz)
{
    const proto_param_info *f = &proto_param_infos[i];
    char w[128], n[64], r[160];
    named(f, naming, n, sizeof n);
    if (f->type == PROTO_PARAM_ENUM && (v < f->min || v > f->max || v != floor(v)))
        return proto__errf(err, errsz, PROTO_EBAD_PARAMS, "%s %g: not %s", n, v,
                           words_of(f->values, w, sizeof w));
    if (!isfinite(v))
        return proto__errf(err, errsz, PROTO_EBAD_PARAMS, "%s %g: not a finite number", n, v);
    if ((f->type == PROTO_PARAM_U32 || f->type == PROTO_PARAM_BOOL) && v != floor(v))
        return proto__errf(err, errsz, PROTO_EBAD_PARAMS, "%s %g: not an integer", n, v);
    if (v == 0 && (f->flags & PROTO_PARAM_ZERO_OFF))
        return PROTO_OK;
    if (v < f->min || (v == f->min && (f->flags & PROTO_PARAM_OPEN_MIN)) ||
        v > f->max || (v == f->max && (f->flags & PROTO_PARAM_OPEN_MAX)))
        return proto__errf(err, errsz, PROTO_EBAD_PARAMS, "%s %g: out of range %s", n, v,
                           proto_param_range(i, r, sizeof r));
    return PROTO_OK;
}

int proto_param_check(int i, double v, char *err, size_t errsz)
{
    return check_as(i, v, PROTO_NAME_WIRE, err, errsz);
}

/* backend: "" or a word of the row's values, optionally ":DEVICE". */
static int check_backend(const proto_param_info *f, const char *b, int naming, char *err, size_t errsz)
{
    char w[128], n[64];
    if (!b || !b[0])
        return PROTO_OK;
    named(f, naming, n, sizeof n);
    size_t k = strcspn(b, ":");
    for (const char *s = f->values; *s;) {
        size_t len = strcspn(s, "|");
        if (len == k && strncmp(s, b, len) == 0) {
            if (b[k] && strlen(b + k + 1) > PROTO_MAX_DEVICE)
                return proto__errf(err, errsz, PROTO_EBAD_PARAMS,
                                   "%s '%s': device name of %zu bytes, over %d", n, b,
                                   strlen(b + k + 1), PROTO_MAX_DEVICE);
            return PROTO_OK;
        }
        s += len + (s[len] == '|');
    }
    return proto__errf(err, errsz, PROTO_EBAD_PARAMS, "%s '%s': not %s (optionally :DEVICE)", n, b,
                       words_of(f->values, w, sizeof w));
}

int proto_params_check_as(const proto_params *p, int naming, char *err, size_t errsz)
{
    for (int i = 0; i < PROTO_NPARAMS; i++) {
        const proto_param_info *f = &proto_param_infos[i];
        int rc;
        if (f->type == PROTO_PARAM_STR)
            rc = check_backend(f, *(const char *const *)((const char *)p + f->offset), naming, err, errsz);
        else if ((f->flags & PROTO_PARAM_ZERO_DEFAULT) && proto_param_get(p, i) == 0)
            rc = PROTO_OK;
        else
            rc = check_as(i, proto_param_get(p, i), naming, err, errsz);
        if (rc)
            return rc;
    }
    return PROTO_OK;
}

int proto_params_check(const proto_params *p, char *err, size_t errsz)
{
    return proto_params_check_as(p, PROTO_NAME_WIRE, err, errsz);
}

int proto_param_parse(proto_params *p, int i, const char *text, char *err, size_t errsz)
{
    const proto_param_info *f = &proto_param_infos[i];
    char *at = (char *)p + f->offset, name[64], w[128];
    if (f->type == PROTO_PARAM_STR) {
        *(const char **)at = text;
        return PROTO_OK;
    }
    if (f->type == PROTO_PARAM_ENUM) {
        for (unsigned v = 0; proto_param_value_name(i, v, name, sizeof name); v++)
            if (strcmp(text, name) == 0) {
                *(uint8_t *)at = (uint8_t)v;
                return PROTO_OK;
            }
        return proto__errf(err, errsz, PROTO_EBAD_PARAMS, "'%s' is not %s", text,
                           words_of(f->values, w, sizeof w));
    }
    char *e;
    double v = strtod(text, &e);
    if (!*text || *e)
        return proto__errf(err, errsz, PROTO_EBAD_PARAMS, "'%s' is not a number", text);
    if (f->type == PROTO_PARAM_F64) {
        *(double *)at = v;
        return PROTO_OK;
    }
    uint32_t max = f->type == PROTO_PARAM_BOOL ? 1 : UINT32_MAX;
    if (v != floor(v) || v < 0 || v > max) {
        char r[160];
        return proto__errf(err, errsz, PROTO_EBAD_PARAMS, "'%s' is not an integer in %s", text,
                           proto_param_range(i, r, sizeof r));
    }
    if (f->type == PROTO_PARAM_BOOL)
        *(uint8_t *)at = (uint8_t)v;
    else
        *(uint32_t *)at = (uint32_t)v;
    return PROTO_OK;
}

char *proto_params_format(const proto_params *p, char *buf, size_t sz)
{
    size_t o = 0;
    buf[0] = '\0';
    for (int i = 0; i < PROTO_NPARAMS && o < sz; i++) {
        const proto_param_info *f = &proto_param_infos[i];
        const char *sep = i ? " " : "";
        char name[64];
        const char *vn;
        if (f->type == PROTO_PARAM_STR)
            o += (size_t)snprintf(buf + o, sz - o, "%s%s=%s", sep, f->name,
                                  *(const char *const *)((const char *)p + f->offset));
        else if (f->type == PROTO_PARAM_ENUM &&
                 (vn = proto_param_value_name(i, (unsigned)proto_param_get(p, i), name, sizeof name)))
            o += (size_t)snprintf(buf + o, sz - o, "%s%s=%s", sep, f->name, vn);
        else
            o += (size_t)snprintf(buf + o, sz - o, "%s%s=%.10g", sep, f->name, proto_param_get(p, i));
    }
    return buf;
}

/* 100000, not 1e+05: integers in full. */
static const char *num(double v, char *buf, size_t sz)
{
    if (v == floor(v) && fabs(v) < 1e15)
        snprintf(buf, sz, "%.0f", v);
    else
        snprintf(buf, sz, "%g", v);
    return buf;
}

static const char *wire_type(int type)
{
    switch (type) {
    case PROTO_PARAM_ENUM: case PROTO_PARAM_BOOL: return "u8";
    case PROTO_PARAM_U32: return "u32";
    case PROTO_PARAM_F64: return "f64";
    default: return "str";
    }
}

const char *proto_param_range(int i, char *buf, size_t sz)
{
    const proto_param_info *f = &proto_param_infos[i];
    char name[64], lo[32], hi[32];
    if (f->type == PROTO_PARAM_ENUM) {
        size_t o = 0;
        buf[0] = '\0';
        for (unsigned v = 0; proto_param_value_name(i, v, name, sizeof name) && o < sz; v++)
            o += (size_t)snprintf(buf + o, sz - o, "%s%u `%s`", v ? ", " : "", v, name);
    } else if (f->type == PROTO_PARAM_STR) {
        snprintf(buf, sz, "`\"\"`, or %s, optionally `:DEVICE` (at most %d bytes)",
                 words_of(f->values, name, sizeof name), PROTO_MAX_DEVICE);
    } else if (f->type == PROTO_PARAM_BOOL) {
        snprintf(buf, sz, "0 or 1");
    } else {
        snprintf(buf, sz, "%s%s, %s%s%s", (f->flags & PROTO_PARAM_OPEN_MIN) ? "(" : "[",
                 num(f->min, lo, sizeof lo), isinf(f->max) ? "inf" : num(f->max, hi, sizeof hi),
                 (f->flags & PROTO_PARAM_OPEN_MAX) || isinf(f->max) ? ")" : "]",
                 (f->flags & PROTO_PARAM_ZERO_DEFAULT) ? "; 0 = the default"
                 : (f->flags & PROTO_PARAM_ZERO_OFF)   ? "; or 0 = off"
                                                       : "");
    }
    return buf;
}

size_t proto_params_table(char *buf, size_t sz)
{
    size_t o = 0;
    char tmp[256], dflt[64], name[64];
#define OUT(...) o += (size_t)snprintf(buf + (o < sz ? o : sz), o < sz ? sz - o : 0, __VA_ARGS__)
    OUT("| # | field | type | default | range | CLI option | meaning |\n");
    OUT("|---:|---|---|---|---|---|---|\n");
    for (int i = 0; i < PROTO_NPARAMS; i++) {
        const proto_param_info *f = &proto_param_infos[i];
        if (f->type == PROTO_PARAM_STR)
            snprintf(dflt, sizeof dflt, "`\"\"`");
        else if (f->type == PROTO_PARAM_ENUM)
            snprintf(dflt, sizeof dflt, "%u `%s`", (unsigned)f->dflt,
                     proto_param_value_name(i, (unsigned)f->dflt, name, sizeof name));
        else
            num(f->dflt, dflt, sizeof dflt);
        OUT("| %d | `%s` | %s | %s | %s | `--%s` | %s |\n", i + 1, f->name, wire_type(f->type), dflt,
            proto_param_range(i, tmp, sizeof tmp), f->cli, f->help);
    }
#undef OUT
    return o;
}
