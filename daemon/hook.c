/* hook.c — word when a job ends: with `--notify-url USER=URL`, each end of
 * one of USER's jobs is POSTed to URL as a small JSON note (id, user,
 * label, state, reason, elapsed seconds, quality), retried with growing
 * waits (HOOK_ATTEMPTS tries, HOOK_FIRST_RETRY_S doubling) until the
 * listener answers 2xx, then dropped with a log line.
 *
 * Only the admin's configuration names URLs (a client cannot send one), so
 * users cannot make the server reach hosts of their choosing (SSRF). Plain
 * http:// only: run the listener on a trusted network.
 *
 * DESIGN: the loop never waits for a listener. hook_job_ended (loop thread)
 * formats the note and queues it; HOOK_THREADS threads of their own take
 * notes whose time has come and deliver them with blocking sockets bounded
 * by HOOK_TIMEOUT_S, so a listener that never answers holds one thread, not
 * the loop nor the other notes. The queue is bounded (HOOK_MAX_QUEUED). */
#include "mcd.h"
#include "web.h"
#include "util/errbuf.h"

#include <errno.h>
#include <math.h>
#include <netdb.h>
#include <poll.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

typedef struct note {
    struct note *next;
    hook_url url;
    uint64_t id;
    int attempts;                 /* made so far */
    int64_t due_ms;               /* CLOCK_MONOTONIC */
    char body[HOOK_MAX_BODY];
} note;

static struct {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    note *head;                   /* by due time */
    int queued, stopping, started;
    pthread_t threads[HOOK_THREADS];
} H = {.mu = PTHREAD_MUTEX_INITIALIZER, .cv = PTHREAD_COND_INITIALIZER};

static int64_t mono_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

/* Waits for fd to be ready for events until deadline: 1, 0 timed out, -1. */
static int wait_fd(int fd, short events, int64_t deadline)
{
    for (;;) {
        int64_t left = deadline - mono_ms();
        if (left <= 0)
            return 0;
        struct pollfd p = {fd, events, 0};
        int rc = poll(&p, 1, (int)left);
        if (rc < 0 && errno == EINTR)
            continue;
        return rc < 0 ? -1 : rc > 0;
    }
}

/* One POST of n's body: 0 when the listener answered 2xx, else -1 with why. */
static int deliver(const note *n, char *why, size_t wsz)
{
    int64_t deadline = mono_ms() + 1000 * HOOK_TIMEOUT_S;
    struct addrinfo hints = {0}, *ai = NULL;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = AI_NUMERICSERV;
    int rc = getaddrinfo(n->url.host, n->url.port, &hints, &ai);
    if (rc)
        return errbuf_set(why, wsz, -1, "%s: %s", n->url.host, gai_strerror(rc));
    int fd = -1;
    for (struct addrinfo *a = ai; a && fd < 0; a = a->ai_next) {
        fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a->ai_protocol);
        if (fd < 0)
            continue;
        if (connect(fd, a->ai_addr, a->ai_addrlen) == 0)
            break;
        int e = 0;
        socklen_t el = sizeof e;
        if (errno != EINPROGRESS || wait_fd(fd, POLLOUT, deadline) != 1 ||
            getsockopt(fd, SOL_SOCKET, SO_ERROR, &e, &el) || e) {
            snprintf(why, wsz, "connect: %s", e ? strerror(e) : errno == EINPROGRESS ? "timed out" : strerror(errno));
            close(fd);
            fd = -1;
        }
    }
    freeaddrinfo(ai);
    if (fd < 0)
        return -1;
    char req[HOOK_MAX_BODY + CONF_PATH + CONF_HOST + 256];
    int len = snprintf(req, sizeof req,
                       "POST %s HTTP/1.1\r\nHost: %s:%s\r\nUser-Agent: meshcorrd/%s\r\n"
                       "Content-Type: application/json\r\nContent-Length: %zu\r\nConnection: close\r\n\r\n%s",
                       n->url.path, n->url.host, n->url.port, MC_VERSION, strlen(n->body), n->body);
    for (int off = 0; off < len;) {
        ssize_t w = send(fd, req + off, (size_t)(len - off), MSG_NOSIGNAL);
        if (w < 0 && (errno == EAGAIN || errno == EINTR)) {
            if (wait_fd(fd, POLLOUT, deadline) != 1) {
                close(fd);
                return errbuf_set(why, wsz, -1, "send: timed out");
            }
            continue;
        }
        if (w < 0) {
            close(fd);
            return errbuf_set(why, wsz, -1, "send: %s", strerror(errno));
        }
        off += (int)w;
    }
    char resp[256];
    size_t got = 0;
    while (got < sizeof resp - 1 && !memchr(resp, '\n', got)) {
        if (wait_fd(fd, POLLIN, deadline) != 1) {
            close(fd);
            return errbuf_set(why, wsz, -1, "no answer within %d s", HOOK_TIMEOUT_S);
        }
        ssize_t r = recv(fd, resp + got, sizeof resp - 1 - got, 0);
        if (r < 0 && (errno == EAGAIN || errno == EINTR))
            continue;
        if (r <= 0)
            break;
        got += (size_t)r;
    }
    close(fd);
    resp[got] = '\0';
    int status = 0;
    if (sscanf(resp, "HTTP/%*d.%*d %d", &status) != 1)
        return errbuf_set(why, wsz, -1, "the answer is not HTTP");
    if (status < 200 || status > 299)
        return errbuf_set(why, wsz, -1, "HTTP status %d", status);
    return 0;
}

/* Queues n by due time (the lock held). */
static void insert(note *n)
{
    note **p = &H.head;
    while (*p && (*p)->due_ms <= n->due_ms)
        p = &(*p)->next;
    n->next = *p;
    *p = n;
    H.queued++;
    pthread_cond_signal(&H.cv);
}

static void *run(void *arg)
{
    (void)arg;
    pthread_mutex_lock(&H.mu);
    while (!H.stopping) {
        if (!H.head || H.head->due_ms > mono_ms()) {
            if (!H.head) {
                pthread_cond_wait(&H.cv, &H.mu);
            } else {
                int64_t due = H.head->due_ms;
                struct timespec t;
                clock_gettime(CLOCK_REALTIME, &t);
                int64_t wait = due - mono_ms();
                t.tv_sec += wait / 1000;
                t.tv_nsec += (wait % 1000) * 1000000;
                if (t.tv_nsec >= 1000000000) {
                    t.tv_sec++;
                    t.tv_nsec -= 1000000000;
                }
                pthread_cond_timedwait(&H.cv, &H.mu, &t);
            }
            continue;
        }
        note *n = H.head;
        H.head = n->next;
        H.queued--;
        pthread_mutex_unlock(&H.mu);
        char why[256] = "";
        int rc = deliver(n, why, sizeof why);
        n->attempts++;
        pthread_mutex_lock(&H.mu);
        if (rc == 0) {
            dlog(DLOG_INFO, "job %llu: end notified to http://%s:%s%s", (unsigned long long)n->id, n->url.host,
                 n->url.port, n->url.path);
            free(n);
        } else if (n->attempts >= HOOK_ATTEMPTS || H.stopping) {
            dlog(DLOG_WARN, "job %llu: notifying http://%s:%s%s failed %d time(s) (%s): given up",
                 (unsigned long long)n->id, n->url.host, n->url.port, n->url.path, n->attempts, why);
            free(n);
        } else {
            int64_t wait_s = (int64_t)HOOK_FIRST_RETRY_S << (n->attempts - 1);
            dlog(DLOG_INFO, "job %llu: notifying http://%s:%s%s failed (%s): again in %lld s",
                 (unsigned long long)n->id, n->url.host, n->url.port, n->url.path, why, (long long)wait_s);
            n->due_ms = mono_ms() + 1000 * wait_s;
            insert(n);
        }
    }
    pthread_mutex_unlock(&H.mu);
    return NULL;
}

int hook_start(mcd *d)
{
    (void)d;
    for (int i = 0; i < HOOK_THREADS; i++) {
        if (pthread_create(&H.threads[i], NULL, run, NULL)) {
            hook_stop();
            return -1;
        }
        H.started = i + 1;
    }
    return 0;
}

/* The --notify-url of user, or NULL. */
static const char *url_of(const mcd *d, const char *user)
{
    size_t n = strlen(user);
    for (int i = 0; i < d->conf.nnotify; i++)
        if (!strncmp(d->conf.notify[i], user, n) && d->conf.notify[i][n] == '=')
            return d->conf.notify[i] + n + 1;
    return NULL;
}

void hook_job_ended(mcd *d, uint64_t id)
{
    store_job j;
    if (!H.started || store_get(d->store, id, &j))
        return;
    const char *url = url_of(d, j.user);
    if (!url)
        return;
    note *n = calloc(1, sizeof *n);
    char why[256];
    if (!n || hook_url_parse(url, &n->url, why, sizeof why)) {
        free(n);
        return;
    }
    n->id = id;
    FILE *fp = fmemopen(n->body, sizeof n->body, "w");
    if (!fp) {
        free(n);
        return;
    }
    fprintf(fp, "{\"id\":%llu,\"user\":", (unsigned long long)id);
    web_json_str(fp, j.user);
    fputs(",\"label\":", fp);
    web_json_str(fp, j.label);
    fprintf(fp, ",\"state\":\"%s\",\"reason\":", proto_state_name(j.state));
    web_json_str(fp, j.reason);
    fputs(",\"elapsed_s\":", fp);
    web_json_num(fp, j.start_ms && j.end_ms >= j.start_ms ? (double)(j.end_ms - j.start_ms) / 1000 : NAN);
    static const char *const verdicts[] = {"ok", "folded", "orientation reversed"};
    fputs(",\"quality\":{\"verdict\":", fp);
    if (j.verdict >= 0 && j.verdict <= 2)
        web_json_str(fp, verdicts[j.verdict]);
    else
        fputs("null", fp);
    fputs(",\"flipped\":", fp);
    web_json_num(fp, j.flipped);
    fputs(",\"collapsed\":", fp);
    web_json_num(fp, j.collapsed);
    fputs("}}", fp);
    int over = ftell(fp) >= (long)sizeof n->body - 1;
    fclose(fp);
    if (over) {
        dlog(DLOG_WARN, "job %llu: its end note is over %u bytes: not sent", (unsigned long long)id, HOOK_MAX_BODY);
        free(n);
        return;
    }
    n->due_ms = mono_ms();
    pthread_mutex_lock(&H.mu);
    if (H.queued >= HOOK_MAX_QUEUED) {
        /* the oldest due goes: the queue stays bounded whatever the listeners do */
        note *old = H.head;
        H.head = old->next;
        H.queued--;
        dlog(DLOG_WARN, "job %llu: end note dropped: %d notes wait", (unsigned long long)old->id, HOOK_MAX_QUEUED);
        free(old);
    }
    insert(n);
    pthread_mutex_unlock(&H.mu);
}

void hook_stop(void)
{
    pthread_mutex_lock(&H.mu);
    H.stopping = 1;
    pthread_cond_broadcast(&H.cv);
    pthread_mutex_unlock(&H.mu);
    for (int i = 0; i < H.started; i++)
        pthread_join(H.threads[i], NULL);
    int dropped = 0;
    while (H.head) {
        note *n = H.head;
        H.head = n->next;
        free(n);
        dropped++;
    }
    if (dropped)
        dlog(DLOG_WARN, "shutting down: %d job end note(s) not sent", dropped);
    H.started = 0;
}
