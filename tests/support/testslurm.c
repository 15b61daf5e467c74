/* testslurm.c — entering the private Slurm's namespace and asking it about
 * meshcorrd's jobs (see testslurm.h). Test code only. */
#include "support/testslurm.h"
#include "support/harness.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define RUN_IN_SLURM "tests/slurm/run-in-slurm.sh"

void testslurm_enter(int argc, char **argv)
{
    if (getenv("MESHCORR_SLURM_DIR") || getenv("MESHCORR_SLURM_SKIP"))
        return;
    static const char *need[] = {"/usr/sbin/slurmctld", "/usr/sbin/slurmd", "/usr/sbin/munged",
                                 "/usr/bin/sbatch", "/usr/bin/unshare", RUN_IN_SLURM};
    for (size_t i = 0; i < sizeof need / sizeof need[0]; i++)
        if (access(need[i], X_OK) != 0) {
            char why[512];
            snprintf(why, sizeof why, "%s is missing (deploy/install-deps.sh installs Slurm and munge)", need[i]);
            setenv("MESHCORR_SLURM_SKIP", why, 1);
            return;
        }
    if (system("unshare --pid --fork --net --mount-proc true 2>/dev/null") != 0) {
        setenv("MESHCORR_SLURM_SKIP", "cannot create a pid+network namespace (unshare needs privileges)", 1);
        return;
    }
    char **nargv = calloc((size_t)argc + 8, sizeof *nargv);
    if (!nargv)
        return;
    int k = 0;
    nargv[k++] = "unshare";
    nargv[k++] = "--pid";
    nargv[k++] = "--fork";
    nargv[k++] = "--net";
    nargv[k++] = "--mount-proc";
    nargv[k++] = RUN_IN_SLURM;
    for (int i = 0; i < argc; i++)
        nargv[k++] = argv[i];
    nargv[k] = NULL;
    fflush(stdout);
    execv("/usr/bin/unshare", nargv);
    setenv("MESHCORR_SLURM_SKIP", strerror(errno), 1);
    free(nargv);
}

void testslurm_need(void)
{
    const char *skip = getenv("MESHCORR_SLURM_SKIP"), *err = getenv("MESHCORR_SLURM_ERROR");
    if (skip)
        SKIP("no private Slurm: %s", skip);
    if (!getenv("MESHCORR_SLURM_DIR"))
        SKIP("no private Slurm");
    if (err && *err)
        FAILF("%s", err);
    testdaemon_need_worker();
}

void testslurm_daemon(testdaemon *d, const char *name, const char *const *args)
{
    const char *argv[48];
    int k = 0;
    argv[k++] = "--backend";        argv[k++] = "slurm";
    argv[k++] = "--slurm-cpus";     argv[k++] = "1";
    argv[k++] = "--slurm-poll-ms";  argv[k++] = "300";
    argv[k++] = "--slurm-progress"; argv[k++] = "127.0.0.1:0";
    for (int i = 0; args && args[i] && k < 46; i++)
        argv[k++] = args[i];
    argv[k] = NULL;
    testdaemon_start(d, name, argv);
}

/* "meshcorr-<tag>-" from the daemon's log line naming its jobs. */
static int job_prefix(const testdaemon *d, char *out, size_t sz)
{
    FILE *fp = fopen(d->log, "r");
    char line[4096];
    int found = 0;
    while (fp && fgets(line, sizeof line, fp)) {
        char *p = strstr(line, "job names meshcorr-");
        if (p) {
            char tag[32];
            if (sscanf(p, "job names meshcorr-%31[0-9a-f]-", tag) == 1) {
                snprintf(out, sz, "meshcorr-%s-", tag);
                found = 1;
            }
        }
    }
    if (fp)
        fclose(fp);
    return found ? 0 : -1;
}

/* How many Slurm jobs squeue lists for d's job id; the last one's state into state. */
static int each_listed(const testdaemon *d, uint64_t id, char *state, size_t sz)
{
    char prefix[64], want[96], line[512];
    if (job_prefix(d, prefix, sizeof prefix))
        FAILF("no 'job names' line in %s", d->log);
    snprintf(want, sizeof want, "%s%llu", prefix, (unsigned long long)id);
    FILE *fp = popen("squeue -h -t all -o '%j|%T' 2>/dev/null", "r");
    if (!fp)
        return -1;
    int n = 0;
    if (state)
        state[0] = '\0';
    while (fgets(line, sizeof line, fp)) {
        char *bar = strchr(line, '|');
        if (!bar)
            continue;
        *bar = '\0';
        if (strcmp(line, want) == 0) {
            n++;
            if (state)
                snprintf(state, sz, "%.*s", (int)strcspn(bar + 1, "\n"), bar + 1);
        }
    }
    return pclose(fp) == 0 ? n : -1;
}

int testslurm_count(const testdaemon *d, uint64_t id)
{
    return each_listed(d, id, NULL, 0);
}

const char *testslurm_state(const testdaemon *d, uint64_t id, char *buf, size_t sz)
{
    each_listed(d, id, buf, sz);
    return buf;
}
