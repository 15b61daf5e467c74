/* throttle.c — failed logins per address: guessing tokens costs time.
 *
 * DESIGN: each address (an IPv4 address, an IPv6 /64, a local uid) has a
 * bucket of THROTTLE_FREE_FAILS failed HELLOs, refilled by one every
 * THROTTLE_REFILL_S. A failure that empties it refuses that address's
 * HELLOs for THROTTLE_BASE_BLOCK_S, and every further failure while the
 * bucket is empty doubles that (up to THROTTLE_MAX_BLOCK_S). A refused
 * HELLO is answered without looking at its token, so while an address
 * waits it learns nothing, however fast it asks. A successful login resets
 * nothing: one good account does not buy more guesses. Other addresses are
 * never affected. The web UI's logins (web.c) count and wait in the same
 * table as HELLOs.
 *
 * The log names the address: the first failure of a burst at once, then
 * one line per THROTTLE_LOG_PERIOD_S summing up what came since, so a
 * flood costs a line every few seconds, not one per try. State is a fixed
 * table in this file under a mutex (the loop thread and the HTTP server's
 * thread both call in); an address nobody needs to
 * remember any more (bucket full, not refused, nothing to log) leaves it,
 * and a full table forgets the quietest address first. */
#include "mcd.h"

#include <pthread.h>
#include <string.h>

typedef struct entry {
    char peer[SRV_MAX_PEER];      /* "" = free */
    double tokens;                /* failures it may still make before a refusal */
    uint64_t refill_ms;           /* tokens were last brought up to date */
    uint64_t blocked_until_ms;    /* HELLOs refused before this */
    uint32_t strikes;             /* refusal periods so far: each doubles the next */
    uint64_t last_ms;             /* last failure or refusal */
    uint64_t logged_ms;           /* last line written for it (0: none) */
    uint32_t failed, refused;     /* since that line: tokens checked and wrong, HELLOs refused unchecked */
    char client[64];              /* the client name of the first failure since that line */
    char why[64];                 /* and why it failed */
} entry;

static entry table[THROTTLE_MAX_ADDRS];
static pthread_mutex_t mu = PTHREAD_MUTEX_INITIALIZER;

static void refill(entry *e, uint64_t now)
{
    if (now > e->refill_ms) {
        e->tokens += (double)(now - e->refill_ms) / (1000.0 * THROTTLE_REFILL_S);
        if (e->tokens >= THROTTLE_FREE_FAILS) {
            e->tokens = THROTTLE_FREE_FAILS;
            e->strikes = 0;            /* quiet long enough: start over */
        }
    }
    e->refill_ms = now;
}

static entry *find(const char *peer)
{
    for (int i = 0; i < THROTTLE_MAX_ADDRS; i++)
        if (table[i].peer[0] && strcmp(table[i].peer, peer) == 0)
            return &table[i];
    return NULL;
}

/* A free entry for peer, or the one of the address quietest for longest
 * (not one being refused, while there is another). */
static entry *add(const char *peer, uint64_t now)
{
    entry *pick = NULL;
    for (int i = 0; i < THROTTLE_MAX_ADDRS && !(pick && !pick->peer[0]); i++) {
        entry *e = &table[i];
        if (!e->peer[0] || !pick)
            pick = e;
        else if ((e->blocked_until_ms <= now) != (pick->blocked_until_ms <= now))
            pick = e->blocked_until_ms <= now ? e : pick;
        else if (e->last_ms < pick->last_ms)
            pick = e;
    }
    memset(pick, 0, sizeof *pick);
    snprintf(pick->peer, sizeof pick->peer, "%s", peer);
    pick->tokens = THROTTLE_FREE_FAILS;
    pick->refill_ms = now;
    return pick;
}

/* One line for what came from e's address since its last line. */
static void write_line(entry *e, uint64_t now)
{
    uint32_t n = e->failed + e->refused;
    if (n == 0)
        return;
    char wait[96] = "";
    if (e->blocked_until_ms > now)
        snprintf(wait, sizeof wait, "; its logins are refused for %llu s more",
                 (unsigned long long)((e->blocked_until_ms - now + 999) / 1000));
    if (n == 1 && e->failed == 1)
        dlog(DLOG_WARN, "login from %s refused: %s (client '%s')%s", e->peer, e->why, e->client, wait);
    else
        dlog(DLOG_WARN, "%u failed logins from %s in the last %.0f s (%u token(s) checked and wrong, %u refused "
             "unchecked: too many failed logins; first client '%s')%s", n, e->peer,
             e->logged_ms ? (double)(now - e->logged_ms) / 1000.0 : 0.0, e->failed, e->refused, e->client, wait);
    e->logged_ms = now;
    e->failed = e->refused = 0;
    e->client[0] = '\0';
}

/* Counts one more event and writes the line when one is due. */
static void note(entry *e, uint64_t now)
{
    e->last_ms = now;
    if (!e->logged_ms || now - e->logged_ms >= 1000ull * THROTTLE_LOG_PERIOD_S)
        write_line(e, now);
}

uint32_t throttle_check(const char *peer, uint64_t now_ms)
{
    pthread_mutex_lock(&mu);
    uint32_t wait = 0;
    entry *e = find(peer);
    if (e && e->blocked_until_ms > now_ms) {
        e->refused++;
        note(e, now_ms);
        wait = (uint32_t)((e->blocked_until_ms - now_ms + 999) / 1000);
    }
    pthread_mutex_unlock(&mu);
    return wait;
}

void throttle_fail(const char *peer, const char *client, const char *why, uint64_t now_ms)
{
    pthread_mutex_lock(&mu);
    entry *e = find(peer);
    if (!e)
        e = add(peer, now_ms);
    refill(e, now_ms);
    e->tokens -= 1;
    if (e->tokens < 1) {
        uint32_t s = e->strikes < 20 ? e->strikes : 20;
        uint64_t block = (uint64_t)THROTTLE_BASE_BLOCK_S << s;
        if (block > THROTTLE_MAX_BLOCK_S)
            block = THROTTLE_MAX_BLOCK_S;
        e->blocked_until_ms = now_ms + 1000 * block;
        e->strikes++;
        if (e->tokens < 0)
            e->tokens = 0;
    }
    e->failed++;
    if (!e->client[0]) {
        snprintf(e->client, sizeof e->client, "%s", client);
        snprintf(e->why, sizeof e->why, "%s", why);
    }
    note(e, now_ms);
    pthread_mutex_unlock(&mu);
}

void throttle_sweep(uint64_t now_ms)
{
    pthread_mutex_lock(&mu);
    for (int i = 0; i < THROTTLE_MAX_ADDRS; i++) {
        entry *e = &table[i];
        if (!e->peer[0])
            continue;
        if (e->failed + e->refused && now_ms - e->logged_ms >= 1000ull * THROTTLE_LOG_PERIOD_S)
            write_line(e, now_ms);
        refill(e, now_ms);
        if (e->tokens >= THROTTLE_FREE_FAILS && e->blocked_until_ms <= now_ms && e->failed + e->refused == 0)
            e->peer[0] = '\0';
    }
    pthread_mutex_unlock(&mu);
}
