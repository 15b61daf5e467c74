/* proto_msg.c — encoding and decoding of every message payload.
 *
 * DESIGN: each message's layout is written ONCE, as a function over a codec
 * context `io` that either writes fields (encoding) or reads them (decoding),
 * so encoder and decoder cannot drift apart. Reading checks every field
 * against the bytes left; every count against its named limit and against
 * (count x smallest element) <= bytes left BEFORE allocating; every string
 * for length, terminator, NUL and UTF-8. The first error sticks and later
 * fields become no-ops. Blobs and strings are left pointing into the payload
 * (see proto.h); arrays are allocated and freed by proto_msg_free. No I/O,
 * no global state. */
#include "proto.h"
#include "proto_int.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct io {
    int dec;                  /* 1 decoding, 0 encoding */
    proto_buf *out;           /* encoding: where fields go */
    const uint8_t *p;         /* decoding: the payload */
    size_t len, pos;
    int err;                  /* first error, sticky */
    char *errbuf;
    size_t errsz;
} io;

static void io_fail(io *c, int code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void io_fail(io *c, int code, const char *fmt, ...)
{
    if (c->err)
        return;
    c->err = code;
    if (c->errbuf && c->errsz) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(c->errbuf, c->errsz, fmt, ap);
        va_end(ap);
    }
}

/* Decoding: 1 when n more bytes are there, else fails with TRUNCATED. */
static int io_have(io *c, size_t n, const char *what)
{
    if (c->err)
        return 0;
    if (n > c->len - c->pos) {
        io_fail(c, PROTO_ETRUNCATED, "%s needs %zu bytes at offset %zu, payload has %zu left",
                what, n, c->pos, c->len - c->pos);
        return 0;
    }
    return 1;
}

/* Encoding: 1 when the output buffer is still fine. */
static int io_out_ok(io *c)
{
    if (c->err)
        return 0;
    if (c->out->err) {
        io_fail(c, c->out->err, "cannot grow the output buffer");
        return 0;
    }
    return 1;
}

static void io_u8(io *c, uint8_t *v)
{
    if (!c->dec) {
        proto_buf_put_u8(c->out, *v);
    } else if (io_have(c, 1, "u8")) {
        *v = c->p[c->pos];
        c->pos += 1;
    }
}

static void io_u16(io *c, uint16_t *v)
{
    if (!c->dec) {
        proto_buf_put_u16(c->out, *v);
    } else if (io_have(c, 2, "u16")) {
        *v = proto_le16(c->p + c->pos);
        c->pos += 2;
    }
}

static void io_u32(io *c, uint32_t *v)
{
    if (!c->dec) {
        proto_buf_put_u32(c->out, *v);
    } else if (io_have(c, 4, "u32")) {
        *v = proto_le32(c->p + c->pos);
        c->pos += 4;
    }
}

static void io_u64(io *c, uint64_t *v)
{
    if (!c->dec) {
        proto_buf_put_u64(c->out, *v);
    } else if (io_have(c, 8, "u64")) {
        *v = proto_le64(c->p + c->pos);
        c->pos += 8;
    }
}

static void io_i32(io *c, int32_t *v)
{
    uint32_t u = (uint32_t)*v;
    io_u32(c, &u);
    if (c->dec && !c->err)
        memcpy(v, &u, 4);
}

static void io_i64(io *c, int64_t *v)
{
    uint64_t u = (uint64_t)*v;
    io_u64(c, &u);
    if (c->dec && !c->err)
        memcpy(v, &u, 8);
}

static void io_f64(io *c, double *v)
{
    uint64_t u;
    memcpy(&u, v, 8);
    io_u64(c, &u);
    if (c->dec && !c->err)
        memcpy(v, &u, 8);
}

/* A u8 enumeration value in [0, last]; both directions refuse others. */
static void io_enum(io *c, uint8_t *v, unsigned last, const char *what)
{
    io_u8(c, v);
    if (!c->err && *v > last)
        io_fail(c, PROTO_EBAD_FRAME, "%s is %u, largest valid value is %u", what, *v, last);
}

/* Well-formed UTF-8 (no overlongs, no surrogates, <= U+10FFFF) without NUL. */
static int utf8_ok(const uint8_t *s, size_t n)
{
    size_t i = 0;
    while (i < n) {
        uint8_t b = s[i];
        size_t k;
        uint32_t cp, min;
        if (b == 0)
            return 0;
        if (b < 0x80) { i++; continue; }
        if ((b & 0xE0) == 0xC0) { k = 1; cp = b & 0x1Fu; min = 0x80; }
        else if ((b & 0xF0) == 0xE0) { k = 2; cp = b & 0x0Fu; min = 0x800; }
        else if ((b & 0xF8) == 0xF0) { k = 3; cp = b & 0x07u; min = 0x10000; }
        else return 0;
        if (k > n - i - 1)
            return 0;
        for (size_t j = 1; j <= k; j++) {
            if ((s[i + j] & 0xC0) != 0x80)
                return 0;
            cp = cp << 6 | (s[i + j] & 0x3Fu);
        }
        if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
            return 0;
        i += k + 1;
    }
    return 1;
}

/* String: u32 length n (<= PROTO_MAX_STRING), n bytes of UTF-8 without NUL,
 * one 0 byte. Decoded strings point at those bytes in the payload. */
static void io_str(io *c, const char **s, const char *what)
{
    if (c->err)
        return;
    if (!c->dec) {
        const char *t = *s ? *s : "";
        size_t n = strlen(t);
        if (n > PROTO_MAX_STRING)
            { io_fail(c, PROTO_EOVER_LIMIT, "%s is %zu bytes, over PROTO_MAX_STRING (%u)",
                           what, n, PROTO_MAX_STRING); return; }
        if (!utf8_ok((const uint8_t *)t, n))
            { io_fail(c, PROTO_EBAD_STRING, "%s is not valid UTF-8", what); return; }
        proto_buf_put_u32(c->out, (uint32_t)n);
        proto_buf_put(c->out, t, n + 1);
        return;
    }
    uint32_t n = 0;
    io_u32(c, &n);
    if (c->err)
        return;
    if (n > PROTO_MAX_STRING)
        { io_fail(c, PROTO_EOVER_LIMIT, "%s length %u over PROTO_MAX_STRING (%u)",
                       what, n, PROTO_MAX_STRING); return; }
    if (!io_have(c, (size_t)n + 1, what))
        return;
    const uint8_t *t = c->p + c->pos;
    if (t[n] != 0)
        { io_fail(c, PROTO_EBAD_STRING, "%s lacks its 0 terminator", what); return; }
    if (!utf8_ok(t, n))
        { io_fail(c, PROTO_EBAD_STRING, "%s has a NUL or is not valid UTF-8", what); return; }
    *s = (const char *)t;
    c->pos += (size_t)n + 1;
}

/* Decoding: zeroed array of n elements, or NULL (n 0, or error set). */
static void *io_alloc(io *c, uint32_t n, size_t size)
{
    if (c->err || n == 0)
        return NULL;
    void *a = calloc(n, size);
    if (!a)
        io_fail(c, PROTO_ENOMEM, "cannot allocate %u elements of %zu bytes", n, size);
    return a;
}

/* Count of a variable-size list: checked against its limit (both ways) and,
 * decoding, against the bytes left at min_elem bytes per element. */
static void io_count(io *c, uint32_t *n, uint32_t limit, const char *limname,
                     size_t min_elem, const char *what)
{
    io_u32(c, n);
    if (c->err)
        return;
    if (*n > limit)
        { io_fail(c, PROTO_EOVER_LIMIT, "%s count %u over %s (%u)", what, *n, limname, limit); return; }
    if (c->dec && (uint64_t)*n * min_elem > c->len - c->pos)
        io_fail(c, PROTO_ETRUNCATED, "%s count %u needs at least %llu bytes, payload has %zu left",
                what, *n, (unsigned long long)*n * min_elem, c->len - c->pos);
}

/* Checksummed section: u32 count, u32 CRC32C of the element bytes, then
 * count x elem bytes. Decoding checks limit, size and CRC before returning;
 * encoding returns the CRC's offset for io_section_end to fill in. */
static size_t io_section(io *c, uint32_t *n, uint32_t limit, const char *limname,
                         size_t elem, const char *what)
{
    io_count(c, n, limit, limname, elem, what);
    if (c->err)
        return 0;
    if (!c->dec) {
        size_t at = c->out->len;
        proto_buf_put_u32(c->out, 0);
        return at;
    }
    uint32_t crc = 0;
    io_u32(c, &crc);
    if (!io_have(c, (size_t)*n * elem, what))
        return 0;
    uint32_t got = proto_crc32c(0, c->p + c->pos, (size_t)*n * elem);
    if (got != crc)
        io_fail(c, PROTO_EBAD_CHECKSUM, "%s CRC32C is 0x%08x, computed 0x%08x", what, crc, got);
    return 0;
}

static void io_section_end(io *c, size_t at)
{
    if (c->dec || !io_out_ok(c))
        return;
    uint8_t *d = c->out->data;
    proto_set_le32(d + at, proto_crc32c(0, d + at + 4, c->out->len - at - 4));
}

static void io_blob(io *c, proto_blob *b, const char *what)
{
    size_t at = io_section(c, &b->len, PROTO_MAX_MESH_BYTES, "PROTO_MAX_MESH_BYTES", 1, what);
    if (c->err)
        return;
    if (!c->dec) {
        proto_buf_put(c->out, b->data, b->len);
    } else {
        b->data = b->len ? c->p + c->pos : NULL;
        c->pos += b->len;
    }
    io_section_end(c, at);
}

static void io_landmarks(io *c, proto_landmark **a, uint32_t *n)
{
    size_t at = io_section(c, n, PROTO_MAX_LANDMARKS, "PROTO_MAX_LANDMARKS", 8, "landmarks");
    if (c->dec)
        *a = io_alloc(c, *n, sizeof **a);
    for (uint32_t i = 0; i < *n && !c->err; i++) {
        io_u32(c, &(*a)[i].src);
        io_u32(c, &(*a)[i].tgt);
    }
    io_section_end(c, at);
}

static void io_map(io *c, proto_map *m, const char *what)
{
    size_t at = io_section(c, &m->n, PROTO_MAX_MAP_ROWS, "PROTO_MAX_MAP_ROWS", 28, what);
    if (c->dec)
        m->rows = io_alloc(c, m->n, sizeof *m->rows);
    for (uint32_t i = 0; i < m->n && !c->err; i++) {
        io_u32(c, &m->rows[i].face);
        for (int k = 0; k < 3; k++)
            io_f64(c, &m->rows[i].w[k]);
    }
    io_section_end(c, at);
}

/* A whole job's fraction done (NaN, or in [0, 1]) and its seconds left
 * (NaN, or finite and >= 0); both directions refuse others. */
static void io_share(io *c, double *fraction, double *eta_s)
{
    io_f64(c, fraction);
    io_f64(c, eta_s);
    if (!c->err && !isnan(*fraction) && !(*fraction >= 0 && *fraction <= 1))
        io_fail(c, PROTO_EBAD_FRAME, "progress fraction %g is not in [0, 1]", *fraction);
    if (!c->err && !isnan(*eta_s) && !(*eta_s >= 0 && isfinite(*eta_s)))
        io_fail(c, PROTO_EBAD_FRAME, "progress eta_s %g is not a time", *eta_s);
}

static void io_progress(io *c, proto_progress *g)
{
    io_u64(c, &g->job_id);
    io_enum(c, &g->stage, PROTO_STAGE_LAST, "progress stage");
    io_u32(c, &g->outer);
    io_u32(c, &g->total);
    for (int d = 0; d < 2; d++) {
        io_u32(c, &g->inner[d]);
        for (int t = 0; t < PROTO_NTERMS; t++)
            io_f64(c, &g->terms[d][t]);
    }
    io_f64(c, &g->beta);
    io_f64(c, &g->gamma);
    io_f64(c, &g->elapsed_s);
    io_share(c, &g->fraction, &g->eta_s);
    io_u32(c, &g->ahead);
}

/* The parameters, one field per PROTO_PARAMS row in list order; ENUM and
 * BOOL values past the row's max are BAD_FRAME both ways (ranges are
 * proto_params_check's, not the codec's). */
#define IO_PARAM_ENUM(c, f, name, max) io_enum(c, f, max, name)
#define IO_PARAM_BOOL(c, f, name, max) io_enum(c, f, max, name)
#define IO_PARAM_U32(c, f, name, max)  io_u32(c, f)
#define IO_PARAM_F64(c, f, name, max)  io_f64(c, f)
#define IO_PARAM_STR(c, f, name, max)  io_str(c, f, name)
static void io_quality(io *c, proto_quality *q)
{
    io_i32(c, &q->verdict);
    if (!c->err && (q->verdict < -1 || q->verdict > 2))
        io_fail(c, PROTO_EBAD_FRAME, "quality verdict %d is not in [-1, 2]", (int)q->verdict);
    io_f64(c, &q->flipped);
    io_f64(c, &q->collapsed);
}

static void io_params(io *c, proto_params *p)
{
#define IO_PARAM(name, cli, type, dflt, lo, hi, ...) IO_PARAM_##type(c, &p->name, #name, hi);
    PROTO_PARAMS(IO_PARAM)
#undef IO_PARAM
}

/* Smallest wire sizes of list elements (strings empty), for io_count. */
#define SUMMARY_MIN (8 + 1 + 4 + 8 + 5 + 5 + 4 + 4 + 20 + 8 + 8 + 4)
#define METRIC_MIN  (5 + 8)
#define SLOT_MIN    (8 + 1)
#define DEVICE_MIN  5

static void io_hello_ok(io *c, proto_hello_ok *h)
{
    io_u16(c, &h->version);
    io_str(c, &h->user, "user");
    io_enum(c, &h->admin, 1, "admin");
    io_u32(c, &h->limits.max_frame);
    io_u32(c, &h->limits.max_vertices);
    io_u32(c, &h->limits.max_landmarks);
    io_u32(c, &h->limits.max_jobs_per_user);
    io_u32(c, &h->limits.max_queue);
    io_u32(c, &h->limits.max_wall_s);
}

static void io_submit(io *c, proto_submit *s)
{
    io_blob(c, &s->source, "source mesh");
    io_blob(c, &s->target, "target mesh");
    io_landmarks(c, &s->landmarks, &s->nlandmarks);
    io_map(c, &s->p, "initial map P");
    io_map(c, &s->q, "initial map Q");
    io_params(c, &s->params);
    io_i32(c, &s->priority);
    io_str(c, &s->label, "label");
}

static void io_status_ok(io *c, proto_status_ok *s)
{
    io_u64(c, &s->job_id);
    io_enum(c, &s->state, PROTO_STATE_LAST, "job state");
    io_i32(c, &s->priority);
    io_str(c, &s->user, "user");
    io_str(c, &s->label, "label");
    io_str(c, &s->reason, "reason");
    io_i64(c, &s->submit_ms);
    io_i64(c, &s->start_ms);
    io_i64(c, &s->end_ms);
    io_enum(c, &s->has_progress, 1, "has_progress");
    if (s->has_progress)
        io_progress(c, &s->progress);
    io_quality(c, &s->quality);
}

static void io_job_summary(io *c, proto_job_summary *j)
{
    io_u64(c, &j->job_id);
    io_enum(c, &j->state, PROTO_STATE_LAST, "job state");
    io_i32(c, &j->priority);
    io_i64(c, &j->submit_ms);
    io_str(c, &j->user, "user");
    io_str(c, &j->label, "label");
    io_u32(c, &j->outer);
    io_u32(c, &j->total);
    io_quality(c, &j->quality);
    io_share(c, &j->fraction, &j->eta_s);
    io_u32(c, &j->ahead);
}

static void io_list_ok(io *c, proto_list_ok *l)
{
    io_count(c, &l->n, PROTO_MAX_LIST, "PROTO_MAX_LIST", SUMMARY_MIN, "job list");
    if (c->dec)
        l->jobs = io_alloc(c, l->n, sizeof *l->jobs);
    for (uint32_t i = 0; i < l->n && !c->err; i++)
        io_job_summary(c, &l->jobs[i]);
}

static void io_result_ok(io *c, proto_result_ok *r)
{
    io_u64(c, &r->job_id);
    io_map(c, &r->p, "map P");
    io_map(c, &r->q, "map Q");
    io_blob(c, &r->deformed, "deformed mesh");
    io_count(c, &r->nmetrics, PROTO_MAX_METRICS, "PROTO_MAX_METRICS", METRIC_MIN, "metrics");
    if (c->dec)
        r->metrics = io_alloc(c, r->nmetrics, sizeof *r->metrics);
    for (uint32_t i = 0; i < r->nmetrics && !c->err; i++) {
        io_str(c, &r->metrics[i].key, "metric key");
        io_f64(c, &r->metrics[i].value);
    }
    /* RHM's maps: a trailing part, written only when there are rows and
     * read only when bytes are left, so RESULT_OK without them is the
     * same bytes as before */
    if (c->err || (c->dec ? c->pos == c->len : !r->rhm_p.n && !r->rhm_q.n))
        return;
    io_map(c, &r->rhm_p, "RHM's map P");
    io_map(c, &r->rhm_q, "RHM's map Q");
}

static void io_stats_ok(io *c, proto_stats_ok *s)
{
    io_u32(c, &s->queued);
    io_u32(c, &s->running);
    io_u32(c, &s->workers);
    io_u64(c, &s->completed);
    io_u64(c, &s->failed);
    io_u64(c, &s->cancelled);
    io_count(c, &s->nslots, PROTO_MAX_SLOTS, "PROTO_MAX_SLOTS", SLOT_MIN, "worker slots");
    if (c->dec)
        s->slots = io_alloc(c, s->nslots, sizeof *s->slots);
    for (uint32_t i = 0; i < s->nslots && !c->err; i++) {
        io_u64(c, &s->slots[i].job_id);
        io_enum(c, &s->slots[i].state, PROTO_SLOT_LAST, "slot state");
    }
    io_count(c, &s->ndevices, PROTO_MAX_DEVICES, "PROTO_MAX_DEVICES", DEVICE_MIN, "devices");
    if (c->dec)
        s->devices = io_alloc(c, s->ndevices, sizeof *s->devices);
    for (uint32_t i = 0; i < s->ndevices && !c->err; i++)
        io_str(c, &s->devices[i], "device name");
    io_str(c, &s->backend, "backend name");
    io_u8(c, &s->backend_ok);
    io_str(c, &s->backend_status, "backend status");
}

/* The payload of message m, in both directions. */
static void io_payload(io *c, proto_msg *m)
{
    switch (m->type) {
    case PROTO_MSG_HELLO: {
        proto_hello *h = &m->u.hello;
        io_u16(c, &h->version);
        io_str(c, &h->token, "token");
        io_str(c, &h->client, "client name");
        break;
    }
    case PROTO_MSG_HELLO_OK:
        io_hello_ok(c, &m->u.hello_ok);
        break;
    case PROTO_MSG_SUBMIT:
        io_submit(c, &m->u.submit);
        break;
    case PROTO_MSG_SUBMIT_OK: case PROTO_MSG_STATUS: case PROTO_MSG_CANCEL:
    case PROTO_MSG_OK: case PROTO_MSG_DELETE:
        /* all five union members are the same proto_job_ref */
        io_u64(c, &m->u.ok.job_id);
        break;
    case PROTO_MSG_STATUS_OK:
        io_status_ok(c, &m->u.status_ok);
        break;
    case PROTO_MSG_LIST: {
        proto_list *l = &m->u.list;
        io_u32(c, &l->state_mask);
        io_str(c, &l->user, "user");
        io_u32(c, &l->max_count);
        io_u64(c, &l->after_id);
        if (!c->err && l->state_mask >> (PROTO_STATE_LAST + 1))
            io_fail(c, PROTO_EBAD_FRAME, "state mask 0x%x has bits past the last state", l->state_mask);
        break;
    }
    case PROTO_MSG_LIST_OK:
        io_list_ok(c, &m->u.list_ok);
        break;
    case PROTO_MSG_WATCH:
        io_u64(c, &m->u.watch.job_id);
        io_u32(c, &m->u.watch.from_outer);
        break;
    case PROTO_MSG_PROGRESS:
        io_progress(c, &m->u.progress);
        break;
    case PROTO_MSG_END:
        io_u64(c, &m->u.end.job_id);
        io_enum(c, &m->u.end.state, PROTO_STATE_LAST, "job state");
        io_str(c, &m->u.end.reason, "reason");
        break;
    case PROTO_MSG_RESULT:
        io_u64(c, &m->u.result.job_id);
        io_u32(c, &m->u.result.what);
        if (!c->err && (m->u.result.what & ~PROTO_WANT_ALL))
            io_fail(c, PROTO_EBAD_FRAME, "RESULT what 0x%x has unknown bits", m->u.result.what);
        break;
    case PROTO_MSG_RESULT_OK:
        io_result_ok(c, &m->u.result_ok);
        break;
    case PROTO_MSG_STATS_OK:
        io_stats_ok(c, &m->u.stats_ok);
        break;
    case PROTO_MSG_ERROR:
        io_i32(c, &m->u.error.code);
        io_str(c, &m->u.error.message, "error message");
        if (!c->err && m->u.error.code >= 0)
            io_fail(c, PROTO_EBAD_FRAME, "ERROR code %d is not negative", m->u.error.code);
        break;
    case PROTO_MSG_STATS: case PROTO_MSG_PING: case PROTO_MSG_PONG:
        break;
    default:
        io_fail(c, PROTO_EBAD_TYPE, "unknown message type %u", m->type);
        break;
    }
}

int proto_msg_encode(proto_buf *b, const proto_msg *m, char *err, size_t errsz)
{
    if (b->err)
        return proto__errf(err, errsz, b->err, "output buffer already failed");
    proto_msg copy = *m;  /* io_payload takes non-const pointers; it only reads */
    io c = { .dec = 0, .out = b, .errbuf = err, .errsz = errsz };
    size_t start = b->len;
    uint8_t hdr[PROTO_HDR_SIZE] = { 0 };
    proto_buf_put(b, hdr, sizeof hdr);
    io_payload(&c, &copy);
    io_out_ok(&c);
    size_t plen = b->len - start - PROTO_HDR_SIZE;
    if (!c.err && plen > PROTO_MAX_FRAME - PROTO_HDR_SIZE)
        io_fail(&c, PROTO_ETOO_LARGE, "%s payload of %zu bytes over PROTO_MAX_FRAME (%u)",
                proto_type_name(m->type), plen, PROTO_MAX_FRAME);
    if (c.err) {
        b->len = start;
        b->err = 0;
        return c.err;
    }
    proto_hdr h = { .version = PROTO_VERSION, .type = m->type, .flags = 0,
                    .request_id = m->request_id, .payload_len = (uint32_t)plen };
    proto_frame_put_header(b->data + start, &h);
    return PROTO_OK;
}

int proto_msg_decode(const proto_hdr *hdr, const void *payload, proto_msg *m,
                     char *err, size_t errsz)
{
    memset(m, 0, sizeof *m);
    m->type = hdr->type;
    m->request_id = hdr->request_id;
    io c = { .dec = 1, .p = payload, .len = hdr->payload_len, .errbuf = err, .errsz = errsz };
    io_payload(&c, m);
    if (!c.err && c.pos != c.len)
        io_fail(&c, PROTO_ETRAILING, "%s payload has %zu bytes after its last field",
                proto_type_name(m->type), c.len - c.pos);
    if (c.err)
        proto_msg_free(m);
    return c.err;
}

int proto_decode(const void *buf, size_t len, size_t max_frame, proto_msg *m,
                 size_t *used, char *err, size_t errsz)
{
    proto_hdr h;
    *used = 0;
    memset(m, 0, sizeof *m);
    int rc = proto_frame_scan(buf, len, max_frame, &h, err, errsz);
    if (rc != PROTO_READY)
        return rc;
    rc = proto_msg_decode(&h, (const uint8_t *)buf + PROTO_HDR_SIZE, m, err, errsz);
    if (rc == PROTO_OK)
        *used = PROTO_HDR_SIZE + (size_t)h.payload_len;
    return rc;
}

void proto_msg_free(proto_msg *m)
{
    if (!m)
        return;
    switch (m->type) {
    case PROTO_MSG_SUBMIT:
        free(m->u.submit.landmarks);
        free(m->u.submit.p.rows);
        free(m->u.submit.q.rows);
        break;
    case PROTO_MSG_LIST_OK:
        free(m->u.list_ok.jobs);
        break;
    case PROTO_MSG_RESULT_OK:
        free(m->u.result_ok.p.rows);
        free(m->u.result_ok.q.rows);
        free(m->u.result_ok.metrics);
        free(m->u.result_ok.rhm_p.rows);
        free(m->u.result_ok.rhm_q.rows);
        break;
    case PROTO_MSG_STATS_OK:
        free(m->u.stats_ok.slots);
        free(m->u.stats_ok.devices);
        break;
    default:
        break;
    }
    memset(m, 0, sizeof *m);
}
