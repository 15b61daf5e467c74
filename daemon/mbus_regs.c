/* mbus_regs.c — the Modbus register map (daemon/MODBUS.md) filled from a
 * status snapshot: block 0 (the daemon) at address 0, then one block of
 * MBUS_SLOT_STRIDE registers per worker slot from MBUS_SLOT_BASE. 32-bit
 * values are two registers, high word first (ABCD); floats are IEEE-754
 * single bits packed by hand (libmodbus 3.1.6's modbus_set_float_* swap the
 * words wrongly). Pure data: no sockets, no threads, no daemon state. */
#include "mcd.h"

#include <string.h>

void mbus_put_u32(uint16_t r[2], uint32_t v)
{
    r[0] = (uint16_t)(v >> 16);
    r[1] = (uint16_t)(v & 0xFFFF);
}

void mbus_put_f32(uint16_t r[2], float v)
{
    uint32_t bits;
    memcpy(&bits, &v, sizeof bits);
    mbus_put_u32(r, bits);
}

size_t mbus_nregs(uint32_t nslots)
{
    return MBUS_SLOT_BASE + (size_t)MBUS_SLOT_STRIDE * nslots;
}

static uint16_t sat16(uint32_t v)
{
    return v > 0xFFFF ? 0xFFFF : (uint16_t)v;
}

void mbus_fill(const mcd_snapshot *s, uint16_t *r)
{
    memset(r, 0, mbus_nregs(s->nslots) * sizeof *r);
    r[0] = (uint16_t)s->seq;
    r[1] = PROTO_VERSION;
    mbus_put_u32(r + 2, s->uptime_s);
    mbus_put_u32(r + 4, s->queued);
    r[6] = sat16(s->running);
    r[7] = sat16(s->workers);
    mbus_put_u32(r + 8, (uint32_t)s->completed);
    mbus_put_u32(r + 10, (uint32_t)s->failed);
    mbus_put_u32(r + 12, (uint32_t)s->cancelled);
    r[14] = MBUS_SLOT_BASE;
    r[15] = MBUS_SLOT_STRIDE;
    for (uint32_t i = 0; i < s->nslots; i++) {
        const snap_slot *o = &s->slots[i];
        uint16_t *b = r + MBUS_SLOT_BASE + MBUS_SLOT_STRIDE * i;
        mbus_put_u32(b, (uint32_t)o->job_id);
        b[2] = o->state;
        b[3] = o->has_progress ? o->stage : 0xFFFF;
        mbus_put_u32(b + 4, o->outer);
        mbus_put_u32(b + 6, o->total);
        mbus_put_f32(b + 8, (float)o->energy);
        mbus_put_f32(b + 10, (float)o->beta);
        mbus_put_u32(b + 12, o->elapsed_s);
        int known = o->has_progress && o->fraction >= 0 && o->fraction <= 1;
        /* rounded down; the 1e-9 keeps 7/20 at 35 % where its double is a hair below */
        b[14] = known ? (uint16_t)(o->fraction * 100 + 1e-9) : 0;
        b[15] = o->has_progress;
        mbus_put_u32(b + 16, o->has_progress && o->eta_s >= 0 && o->eta_s < 4294967295.0
                                 ? (uint32_t)o->eta_s : 0xFFFFFFFFu);
        b[18] = o->total ? (uint16_t)((uint64_t)(o->outer < o->total ? o->outer : o->total) * 100 / o->total) : 0;
        b[19] = known ? (uint16_t)(o->fraction * 10000 + 1e-9) : 0;
    }
}
