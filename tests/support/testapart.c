/* testapart.c — see testapart.h. */
#include "support/testapart.h"
#include "support/harness.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

int testapart_run(void (*fn)(const void *arg, void *out), const void *arg, void *out,
                  size_t size, char *why, size_t whysz)
{
    int fd[2];
    if (pipe(fd))
        FAILF("pipe: %s", strerror(errno));
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid < 0)
        FAILF("fork: %s", strerror(errno));
    if (pid == 0) {
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        close(fd[0]);
        fn(arg, out);
        fflush(stdout);
        size_t put = 0;
        while (put < size) {
            ssize_t w = write(fd[1], (const char *)out + put, size - put);
            if (w < 0 && errno == EINTR)
                continue;
            if (w <= 0)
                _exit(1);
            put += (size_t)w;
        }
        _exit(0);
    }
    close(fd[1]);
    size_t got = 0;
    while (got < size) {
        ssize_t r = read(fd[0], (char *)out + got, size - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        got += (size_t)r;
    }
    close(fd[0]);
    int st = 0;
    while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {}
    if (got == size)
        return 0;
    memset(out, 0, size);
    if (WIFSIGNALED(st))
        snprintf(why, whysz, "crashed (signal %d)", WTERMSIG(st));
    else
        snprintf(why, whysz, "failed (exit %d; message above)", WIFEXITED(st) ? WEXITSTATUS(st) : -1);
    return -1;
}
