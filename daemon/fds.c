/* fds.c — the descriptor budget every listener keeps: how many descriptors
 * are still free under the soft RLIMIT_NOFILE, how many are kept for the
 * workers, the database and the spool (--fd-reserve), and the higher floor
 * below which no TCP client and no Slurm progress connection is taken
 * (--admin-reserve more), so strangers can never use up what the Unix
 * socket and admins need. Counts only; the listeners decide. */
#include "mcd.h"

#include <dirent.h>
#include <errno.h>
#include <sys/resource.h>

/* Counted in /proc/self/fd, exact; the count's own descriptor is not left
 * out, a margin of one. */
long fds_free(void)
{
    struct rlimit rl;
    if (getrlimit(RLIMIT_NOFILE, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY)
        return INT32_MAX;
    DIR *dir = opendir("/proc/self/fd");
    if (!dir)
        return errno == EMFILE || errno == ENFILE ? 0 : INT32_MAX;
    long open = 0;
    while (readdir(dir))
        open++;
    closedir(dir);
    open -= 2;                         /* "." and ".." */
    return (long)rl.rlim_cur - open;
}

long fds_reserve(const mcd_conf *c, int nslots)
{
    if (c->fd_reserve)
        return c->fd_reserve;
    return CONF_FD_RESERVE_BASE + (long)CONF_FD_RESERVE_PER_SLOT * nslots;
}

long fds_tcp_floor(const mcd_conf *c, int nslots)
{
    return fds_reserve(c, nslots) + (long)c->admin_reserve;
}
