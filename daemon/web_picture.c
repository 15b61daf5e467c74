/* web_picture.c — the picture of a completed job's map on its web page, the
 * one `meshcorr eval --out-png` draws: spool/<id>/map.png, drawn on the
 * first request by `meshcorr-worker --picture` and kept (cached) with the
 * job's files until the job is deleted. The meshes are a client's, so they
 * are decoded in that sandboxed worker process, never in the daemon's own.
 *
 * DESIGN: a request never waits for a drawing. The first one starts a
 * thread that spawns the worker and waits for it (at most
 * WEB_PICTURE_TIMEOUT_S, then SIGKILL) and is answered 503 with
 * Retry-After; the page asks again until the file is there. At most
 * WEB_MAX_PICTURES drawings run at once; a job whose drawing failed is not
 * drawn again (a 500 says so) until the daemon restarts. The state here has
 * a mutex of its own: the drawing threads end without the web's lock. The
 * loop's SIGCHLD handling (libuv) reaps only its own children, so the
 * threads' waitpid sees theirs. */
#include "web.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char **environ;

#define WEB_MAX_PICTURES 2          /* drawings running at once */
#define WEB_PICTURE_TIMEOUT_S 120   /* wall time of one drawing */
#define WEB_PICTURE_MAX_BYTES (32u << 20) /* a map.png larger than this is not served */
#define WEB_PICTURE_FAILED 16       /* jobs whose drawing failed, remembered */

static struct {
    pthread_mutex_t mu;
    uint64_t running[WEB_MAX_PICTURES];    /* 0 = free */
    uint64_t failed[WEB_PICTURE_FAILED];   /* a ring */
    unsigned nfailed;
    char worker[CONF_PATH + 64];
    char max_vertices[16], max_faces[24], max_memory_mb[16];
} pic = {.mu = PTHREAD_MUTEX_INITIALIZER};

typedef struct drawing {
    uint64_t id;
    char dir[CONF_PATH + 64], out[CONF_PATH + 80];
} drawing;

void web_picture_init(const mcd *d)
{
    conf_worker_path(&d->conf, pic.worker, sizeof pic.worker);
    snprintf(pic.max_vertices, sizeof pic.max_vertices, "%u", d->conf.max_vertices);
    snprintf(pic.max_faces, sizeof pic.max_faces, "%llu", conf_max_faces(&d->conf));
    snprintf(pic.max_memory_mb, sizeof pic.max_memory_mb, "%u", conf_worker_memory_mb(&d->conf, d->conf.workers));
}

/* Runs the worker for one drawing and waits for it; 0 when it drew. */
static int draw(const drawing *g)
{
    char id[24], cpu[16];
    snprintf(id, sizeof id, "%llu", (unsigned long long)g->id);
    snprintf(cpu, sizeof cpu, "%d", WEB_PICTURE_TIMEOUT_S);
    char *argv[] = {pic.worker, "--job", (char *)g->dir, "--job-id", id, "--picture", (char *)g->out,
                    "--max-vertices", pic.max_vertices, "--max-faces", pic.max_faces, "--max-cpu-s", cpu,
                    strcmp(pic.max_memory_mb, "0") ? "--max-memory-mb" : NULL, pic.max_memory_mb, NULL};
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    pid_t pid;
    int rc = posix_spawn(&pid, pic.worker, &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc) {
        dlog(DLOG_ERROR, "job %llu: cannot start %s --picture: %s", (unsigned long long)g->id, pic.worker,
             strerror(rc));
        return -1;
    }
    int status = 0;
    struct timespec nap = {0, 50 * 1000 * 1000};
    for (int waited_ms = 0;; waited_ms += 50) {
        pid_t w = waitpid(pid, &status, WNOHANG);
        if (w == pid)
            break;
        if (w < 0 && errno != EINTR)
            return -1;
        if (waited_ms >= 1000 * WEB_PICTURE_TIMEOUT_S) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            dlog(DLOG_WARN, "job %llu: the map's picture took over %d s: stopped", (unsigned long long)g->id,
                 WEB_PICTURE_TIMEOUT_S);
            return -1;
        }
        nanosleep(&nap, NULL);
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        dlog(DLOG_WARN, "job %llu: %s --picture failed (status %d)", (unsigned long long)g->id, pic.worker, status);
        return -1;
    }
    return 0;
}

static void *drawing_thread(void *arg)
{
    drawing *g = arg;
    int rc = draw(g);
    pthread_mutex_lock(&pic.mu);
    for (int i = 0; i < WEB_MAX_PICTURES; i++)
        if (pic.running[i] == g->id)
            pic.running[i] = 0;
    if (rc)
        pic.failed[pic.nfailed++ % WEB_PICTURE_FAILED] = g->id;
    pthread_mutex_unlock(&pic.mu);
    free(g);
    return NULL;
}

/* Starts a drawing of job id unless one runs: 0 started or running, -1
 * when the drawings are at their cap or out of memory, 1 when it failed
 * before. */
static int start(const web *w, uint64_t id)
{
    pthread_mutex_lock(&pic.mu);
    int rc = 0, slot = -1;
    for (unsigned i = 0; i < WEB_PICTURE_FAILED; i++)
        if (pic.failed[i] == id)
            rc = 1;
    for (int i = 0; i < WEB_MAX_PICTURES && !rc; i++) {
        if (pic.running[i] == id)
            goto out;             /* running: wait for it */
        if (!pic.running[i] && slot < 0)
            slot = i;
    }
    if (rc)
        goto out;
    drawing *g = slot >= 0 ? calloc(1, sizeof *g) : NULL;
    if (!g) {
        rc = -1;
        goto out;
    }
    g->id = id;
    store_spool_path(web_store(w), id, NULL, g->dir, sizeof g->dir);
    snprintf(g->out, sizeof g->out, "%s/%s", g->dir, SPOOL_PICTURE);
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
    pthread_t t;
    if (pthread_create(&t, &attr, drawing_thread, g)) {
        free(g);
        rc = -1;
    } else {
        pic.running[slot] = id;
    }
    pthread_attr_destroy(&attr);
out:
    pthread_mutex_unlock(&pic.mu);
    return rc;
}

/* The file whole, at most WEB_PICTURE_MAX_BYTES: 0, or -1 (errno ENOENT when
 * it is not there). */
static int read_file(const char *path, char **buf, size_t *len)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0)
        return -1;
    if (fstat(fd, &st) || st.st_size <= 0 || st.st_size > WEB_PICTURE_MAX_BYTES ||
        !(*buf = malloc((size_t)st.st_size))) {
        close(fd);
        errno = EFBIG;
        return -1;
    }
    size_t got = 0;
    while (got < (size_t)st.st_size) {
        ssize_t n = read(fd, *buf + got, (size_t)st.st_size - got);
        if (n <= 0) {
            free(*buf);
            close(fd);
            errno = EIO;
            return -1;
        }
        got += (size_t)n;
    }
    close(fd);
    *len = got;
    return 0;
}

enum MHD_Result web_picture(web *w, web_req *r, const store_job *j)
{
    if (j->state != PROTO_STATE_COMPLETED)
        return web_reply_error(r, MHD_HTTP_CONFLICT, "job %llu is %s: no map to draw", (unsigned long long)j->id,
                               proto_state_name(j->state));
    char path[CONF_PATH + 80], *buf = NULL;
    size_t len;
    store_spool_path(web_store(w), j->id, SPOOL_PICTURE, path, sizeof path);
    if (read_file(path, &buf, &len) == 0)
        return web_reply(r, MHD_HTTP_OK, "image/png", buf, len, 1);
    if (errno != ENOENT)
        return web_reply_error(r, MHD_HTTP_INTERNAL_SERVER_ERROR, "the picture of job %llu is unreadable",
                               (unsigned long long)j->id);
    int rc = start(w, j->id);
    if (rc > 0)
        return web_reply_error(r, MHD_HTTP_INTERNAL_SERVER_ERROR, "the picture of job %llu could not be drawn",
                               (unsigned long long)j->id);
    struct MHD_Response *res = MHD_create_response_from_buffer(0, (void *)"", MHD_RESPMEM_PERSISTENT);
    if (!res)
        return MHD_NO;
    MHD_add_response_header(res, MHD_HTTP_HEADER_RETRY_AFTER, "1");
    MHD_add_response_header(res, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    enum MHD_Result q = MHD_queue_response(r->conn, MHD_HTTP_SERVICE_UNAVAILABLE, res);
    MHD_destroy_response(res);
    return q;
}
