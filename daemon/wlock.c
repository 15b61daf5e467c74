/* wlock.c — a job's worker lock, spool/<id>/worker.lock: whoever holds it
 * runs the job.
 *
 * DESIGN: two workers of one job never run at once, whatever happens to the
 * daemon. The local backend takes the lock (flock, exclusive, non-blocking)
 * before it starts a worker and hands the locked descriptor to the worker as
 * its descriptor SPOOL_LOCK_FD; the daemon closes its own copy once the
 * spawn returned. A flock belongs to the open file, which the child shares
 * from the fork on, through the exec, until its exit; so the lock is held
 * exactly while a process of that run lives, whoever its parent is now (a
 * daemon killed right after the spawn leaves an orphan that still holds
 * it). Hence:
 *   - no worker is started for a job whose lock is held (wlock_take says so);
 *   - recovery after a crash finds the workers a dead daemon left by the
 *     lock, whether or not the store ever recorded their pid, and kills
 *     them (wlock_kill_holders) before the job is re-queued or its result
 *     adopted.
 * Holders are found through /proc/<pid>/fd (every process that has the lock
 * file open), not through a recorded pid: the daemon may have died before
 * writing one, and a child between fork and exec has no worker's command
 * line yet. The file is never removed while its job may run (only with the
 * job's spool directory), or a second worker could lock a new file.
 * File name and descriptor: protocol/spool.h. */
#include "mcd.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define WLOCK_MAX_KILLED 16       /* distinct holders remembered (for the count) */

int wlock_take(const char *path, int *fd)
{
    *fd = -1;
    int f = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0600);
    if (f < 0)
        return -errno;
    if (flock(f, LOCK_EX | LOCK_NB) != 0) {
        int e = errno;
        close(f);
        return e == EWOULDBLOCK ? WLOCK_HELD : -e;
    }
    *fd = f;
    return 0;
}

void wlock_note_pid(int fd, long pid)
{
    char line[32];
    int n = snprintf(line, sizeof line, "%ld\n", pid);
    if (ftruncate(fd, 0) != 0 || pwrite(fd, line, (size_t)n, 0) != n)
        dlog(DLOG_DEBUG, "worker lock: cannot note pid %ld: %s", pid, strerror(errno));
}

/* SIGKILLs every other process with the file (dev, ino) open; adds the pids
 * not seen before to killed[]. */
static void kill_openers(dev_t dev, ino_t ino, long killed[], int *nkilled)
{
    DIR *proc = opendir("/proc");
    if (!proc)
        return;
    struct dirent *pe;
    pid_t self = getpid();
    while ((pe = readdir(proc))) {
        char *e;
        long pid = strtol(pe->d_name, &e, 10);
        if (*e || pid <= 0 || pid == self)
            continue;
        char dir[64], path[64 + 256];
        snprintf(dir, sizeof dir, "/proc/%ld/fd", pid);
        DIR *fds = opendir(dir);
        if (!fds)
            continue;                  /* gone, or not ours to see */
        struct dirent *fe;
        int found = 0;
        while (!found && (fe = readdir(fds))) {
            struct stat st;
            if (fe->d_name[0] == '.')
                continue;
            snprintf(path, sizeof path, "%s/%s", dir, fe->d_name);
            found = stat(path, &st) == 0 && st.st_dev == dev && st.st_ino == ino;
        }
        closedir(fds);
        if (!found)
            continue;
        kill((pid_t)pid, SIGKILL);
        int seen = 0;
        for (int i = 0; i < *nkilled; i++)
            seen |= killed[i] == pid;
        if (!seen && *nkilled < WLOCK_MAX_KILLED)
            killed[(*nkilled)++] = pid;
    }
    closedir(proc);
}

int wlock_kill_holders(const char *path, int wait_ms)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return 0;                      /* never locked: no worker ever ran */
    long killed[WLOCK_MAX_KILLED];
    int nkilled = 0;
    struct timespec t0, now;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (;;) {
        int fd, rc = wlock_take(path, &fd);
        if (rc == 0) {
            close(fd);                 /* free: nothing of that job runs */
            return nkilled;
        }
        if (rc != WLOCK_HELD)
            return -1;
        kill_openers(st.st_dev, st.st_ino, killed, &nkilled);
        clock_gettime(CLOCK_MONOTONIC, &now);
        if ((now.tv_sec - t0.tv_sec) * 1000 + (now.tv_nsec - t0.tv_nsec) / 1000000 >= wait_ms)
            return -1;
        struct timespec pause = {0, 5 * 1000000L};   /* the killed process closes its files */
        nanosleep(&pause, NULL);
    }
}
