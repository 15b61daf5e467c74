/* priv.c — meshcorrd does not run as root. Started as root it needs --user
 * USER: it resolves USER first, creates the state directory for USER (or
 * takes over an empty one), opens the job store and sets the backend up
 * with USER as its effective user (so every file it creates is USER's),
 * binds its listeners (--listen, --modbus, --http) as root, then drops
 * to USER for good (setgroups, setgid, setuid) and checks that root cannot
 * be regained. Everything after that, the workers and validators it starts
 * included, runs as USER. Started as anyone else it runs as that user;
 * --user then must name that user or be left out.
 *
 * DESIGN: no thread of the daemon's own is running before the drop except
 * the dashboards' (started while binding); glibc changes the credentials
 * of every thread of the process together. */
#include "mcd.h"
#include "util/errbuf.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <grp.h>
#include <pwd.h>
#include <signal.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <unistd.h>

int priv_init(const mcd_conf *c, priv_user *u, char *err, size_t errsz)
{
    memset(u, 0, sizeof *u);
    uid_t me = geteuid();
    if (!c->user[0]) {
        if (me == 0)
            return errbuf_set(err, errsz, -1,
                              "refusing to run as root: give --user USER (meshcorrd binds its listeners as root,"
                              " then runs as USER) or start it as an unprivileged user");
        return 0;
    }
    errno = 0;
    struct passwd *pw = getpwnam(c->user);
    if (!pw)
        return errbuf_set(err, errsz, -1, "--user %s: no such user%s%s", c->user, errno ? ": " : "",
                          errno ? strerror(errno) : "");
    if (pw->pw_uid == 0)
        return errbuf_set(err, errsz, -1, "--user %s: that is root; name an unprivileged user", c->user);
    if (me != 0) {
        if (pw->pw_uid != me)
            return errbuf_set(err, errsz, -1, "--user %s: only root can become another user (running as uid %u)",
                              c->user, (unsigned)me);
        return 0;                    /* already that user: nothing to drop */
    }
    u->active = 1;
    u->uid = pw->pw_uid;
    u->gid = pw->pw_gid;
    snprintf(u->name, sizeof u->name, "%s", pw->pw_name);
    return 0;
}

/* 1 when the directory open at fd has no entry but . and .. (it is closed). */
static int dir_is_empty(int fd)
{
    DIR *dp = fdopendir(fd);
    if (!dp) {
        close(fd);
        return 0;
    }
    struct dirent *de;
    int empty = 1;
    while (empty && (de = readdir(dp)))
        empty = strcmp(de->d_name, ".") == 0 || strcmp(de->d_name, "..") == 0;
    closedir(dp);
    return empty;
}

/* As root: dir exists and belongs to u (created, or taken over when empty). */
static int state_dir_for(const priv_user *u, const char *dir, char *err, size_t errsz)
{
    if (mkdir(dir, 0700) != 0 && errno != EEXIST)
        return errbuf_set(err, errsz, -1, "--state-dir %s: %s", dir, strerror(errno));
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        int e = errno;
        if (fd >= 0)
            close(fd);
        return errbuf_set(err, errsz, -1, "--state-dir %s: %s", dir, strerror(e));
    }
    if (st.st_uid == u->uid) {
        close(fd);
        return 0;
    }
    /* a new directory, or one an administrator made (a mount point): USER's
     * now. A used one stays as it is: its files are another user's. */
    int dup_fd = dup(fd);
    if (dup_fd >= 0 && dir_is_empty(dup_fd) && fchown(fd, u->uid, u->gid) == 0) {
        close(fd);
        dlog(DLOG_INFO, "state directory %s now belongs to %s", dir, u->name);
        return 0;
    }
    close(fd);
    return errbuf_set(err, errsz, -1,
                      "--state-dir %s belongs to uid %u, not to --user %s (uid %u), and is not empty:"
                      " chown -R %s %s, or start meshcorrd as its owner",
                      dir, (unsigned)st.st_uid, u->name, (unsigned)u->uid, u->name, dir);
}

int priv_become(const priv_user *u, const char *state_dir, char *err, size_t errsz)
{
    if (!u->active)
        return 0;
    if (state_dir_for(u, state_dir, err, errsz))
        return -1;
    if (initgroups(u->name, u->gid) != 0 || setegid(u->gid) != 0 || seteuid(u->uid) != 0)
        return errbuf_set(err, errsz, -1, "--user %s: cannot take its ids: %s", u->name, strerror(errno));
    return 0;
}

int priv_bind_begin(const priv_user *u, char *err, size_t errsz)
{
    if (u->active && seteuid(0) != 0)
        return errbuf_set(err, errsz, -1, "cannot take root back to bind the listeners: %s", strerror(errno));
    return 0;
}

int priv_drop(const priv_user *u, char *err, size_t errsz)
{
    if (!u->active)
        return 0;
    /* the kernel clears a parent-death signal on a change of credentials:
     * the one the starter asked for (a supervisor, a test) is set again */
    int pdeath = 0;
    pid_t parent = getppid();
    prctl(PR_GET_PDEATHSIG, &pdeath, 0, 0, 0);
    if (setresgid(u->gid, u->gid, u->gid) != 0 || setresuid(u->uid, u->uid, u->uid) != 0)
        return errbuf_set(err, errsz, -1, "--user %s: cannot drop root: %s", u->name, strerror(errno));
    uid_t r, e, s;
    gid_t gr, ge, gs;
    if (setuid(0) == 0 || seteuid(0) == 0 || (u->gid != 0 && setgid(0) == 0) || getresuid(&r, &e, &s) != 0 ||
        getresgid(&gr, &ge, &gs) != 0 || r != u->uid || e != u->uid || s != u->uid || gr != u->gid ||
        ge != u->gid || gs != u->gid)
        return errbuf_set(err, errsz, -1, "--user %s: root could be regained after the drop: refusing to run",
                          u->name);
    if (pdeath) {
        prctl(PR_SET_PDEATHSIG, pdeath, 0, 0, 0);
        if (getppid() != parent)
            raise(pdeath);           /* the parent died while the signal was off */
    }
    dlog(DLOG_INFO, "running as %s (uid %u, gid %u) from now on", u->name, (unsigned)u->uid, (unsigned)u->gid);
    return 0;
}

/* The user is changed once, at start. */
void priv_keep_on_reload(const mcd_conf *o, mcd_conf *n, char *changed, size_t sz)
{
    conf_note_change(strcmp(o->user, n->user) != 0, "user", changed, sz);
    memcpy(n->user, o->user, sizeof n->user);
}
