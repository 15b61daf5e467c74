/* sched.c — which pending job starts next. Pure bookkeeping in memory (the
 * store holds the truth; sched is rebuilt from it at start): no I/O, no
 * libuv, so tests drive it directly.
 *
 * DESIGN: the order is priority first (higher first); among equal
 * priorities, fair share between users: the user with fewer running jobs,
 * then the user served least recently, goes first, so one user's hundred
 * jobs do not starve another's one; then age (lower id first). A full queue
 * is refused by the caller (QUEUE_FULL) before sched_add; nothing here ever
 * drops a job. Picking is a linear scan: queues are bounded by --max-queue. */
#include "mcd.h"

#include <stdlib.h>
#include <string.h>

typedef struct sched_user {
    char name[AUTH_MAX_USER];
    uint32_t pending, running;
    uint64_t last_served;         /* sched's clock at this user's latest start; 0 never */
} sched_user;

typedef struct sched_entry {
    uint64_t id;
    int32_t priority;
    int user;                     /* index into users */
} sched_entry;

struct sched {
    sched_entry *q;
    size_t nq, capq;
    sched_user *users;
    size_t nusers, capusers;
    uint64_t clock;               /* counts starts */
};

sched *sched_new(void)
{
    return calloc(1, sizeof(sched));
}

void sched_free(sched *s)
{
    if (!s)
        return;
    free(s->q);
    free(s->users);
    free(s);
}

static int find_user(const sched *s, const char *name)
{
    for (size_t i = 0; i < s->nusers; i++)
        if (strcmp(s->users[i].name, name) == 0)
            return (int)i;
    return -1;
}

static int user_index(sched *s, const char *name)
{
    int u = find_user(s, name);
    if (u >= 0)
        return u;
    if (s->nusers == s->capusers) {
        size_t cap = s->capusers ? 2 * s->capusers : 8;
        sched_user *n = realloc(s->users, cap * sizeof *n);
        if (!n)
            return -1;
        s->users = n;
        s->capusers = cap;
    }
    sched_user *nu = &s->users[s->nusers];
    memset(nu, 0, sizeof *nu);
    snprintf(nu->name, sizeof nu->name, "%s", name);
    return (int)s->nusers++;
}

int sched_add(sched *s, uint64_t id, const char *user, int32_t priority)
{
    int u = user_index(s, user);
    if (u < 0)
        return -1;
    if (s->nq == s->capq) {
        size_t cap = s->capq ? 2 * s->capq : 64;
        sched_entry *n = realloc(s->q, cap * sizeof *n);
        if (!n)
            return -1;
        s->q = n;
        s->capq = cap;
    }
    s->q[s->nq++] = (sched_entry){id, priority, u};
    s->users[u].pending++;
    return 0;
}

static void remove_at(sched *s, size_t i)
{
    s->users[s->q[i].user].pending--;
    s->q[i] = s->q[--s->nq];
}

int sched_remove(sched *s, uint64_t id)
{
    for (size_t i = 0; i < s->nq; i++)
        if (s->q[i].id == id) {
            remove_at(s, i);
            return 0;
        }
    return -1;
}

/* Non-zero when a should start before b. */
static int before(const sched *s, const sched_entry *a, const sched_entry *b)
{
    if (a->priority != b->priority)
        return a->priority > b->priority;
    const sched_user *ua = &s->users[a->user], *ub = &s->users[b->user];
    if (a->user != b->user) {
        if (ua->running != ub->running)
            return ua->running < ub->running;
        if (ua->last_served != ub->last_served)
            return ua->last_served < ub->last_served;
    }
    return a->id < b->id;
}

uint64_t sched_next(sched *s, char user[AUTH_MAX_USER])
{
    if (s->nq == 0)
        return 0;
    size_t best = 0;
    for (size_t i = 1; i < s->nq; i++)
        if (before(s, &s->q[i], &s->q[best]))
            best = i;
    sched_entry e = s->q[best];
    remove_at(s, best);
    sched_user *u = &s->users[e.user];
    u->running++;
    u->last_served = ++s->clock;
    snprintf(user, AUTH_MAX_USER, "%s", u->name);
    return e.id;
}

int64_t sched_ahead(const sched *s, uint64_t id)
{
    const sched_entry *e = NULL;
    for (size_t i = 0; i < s->nq && !e; i++)
        if (s->q[i].id == id)
            e = &s->q[i];
    if (!e)
        return -1;
    int64_t n = 0;
    for (size_t i = 0; i < s->nq; i++)
        n += &s->q[i] != e && before(s, &s->q[i], e);
    return n;
}

static int order_cmp(const void *x, const void *y, void *ctx)
{
    const sched *s = ctx;
    const sched_entry *a = x, *b = y;
    return before(s, a, b) ? -1 : before(s, b, a) ? 1 : 0;
}

/* before() is a lexicographic order (priority, the user's running count
 * and last start, id), so a job's index in the sorted queue is its
 * sched_ahead. */
uint32_t sched_order(const sched *s, uint64_t *ids, uint32_t max)
{
    sched_entry *tmp = s->nq ? malloc(s->nq * sizeof *tmp) : NULL;
    if (!tmp)
        return 0;
    memcpy(tmp, s->q, s->nq * sizeof *tmp);
    qsort_r(tmp, s->nq, sizeof *tmp, order_cmp, (void *)s);
    uint32_t n = s->nq < max ? (uint32_t)s->nq : max;
    for (uint32_t i = 0; i < n; i++)
        ids[i] = tmp[i].id;
    free(tmp);
    return n;
}

void sched_done(sched *s, const char *user)
{
    int u = find_user(s, user);
    if (u >= 0 && s->users[u].running > 0)
        s->users[u].running--;
}

uint32_t sched_queued(const sched *s)
{
    return (uint32_t)s->nq;
}

int sched_user_at(const sched *s, uint32_t i, const char **name, uint32_t *pending, uint32_t *running)
{
    if (i >= s->nusers)
        return -1;
    *name = s->users[i].name;
    *pending = s->users[i].pending;
    *running = s->users[i].running;
    return 0;
}

uint32_t sched_user_pending(const sched *s, const char *user)
{
    int u = find_user(s, user);
    return u < 0 ? 0 : s->users[u].pending;
}

uint32_t sched_user_running(const sched *s, const char *user)
{
    int u = find_user(s, user);
    return u < 0 ? 0 : s->users[u].running;
}
