/* testsec.c — jobs, spool bytes and memory for the security tests
 * (testsec.h). Test code only. */
#include "support/testsec.h"
#include "support/harness.h"
#include "support/testmesh.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

uint64_t testsec_submit_sphere(mc_client *c, int level, int stages, int iterations, int *rc)
{
    mesh *S, *T;
    testdaemon_sphere_pair(level, &S, &T);
    size_t sl, tl;
    unsigned char *sb = testdaemon_encode(S, &sl), *tb = testdaemon_encode(T, &tl);
    static const uint32_t lm[] = {0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5};
    mc_job_spec spec;
    mc_job_spec_init(&spec);
    spec.source = sb;
    spec.source_len = sl;
    spec.target = tb;
    spec.target_len = tl;
    spec.landmarks = lm;
    spec.nlandmarks = 6;
    spec.stages = stages;
    spec.iterations = (uint32_t)iterations;
    spec.inner_iterations = 10;
    spec.beta_ramp = iterations > 1 ? (uint32_t)iterations : 1;
    spec.rhm_iterations = 3;
    spec.stop_change = 0;
    spec.label = "icosphere pair";
    uint64_t id = 0;
    *rc = mc_submit(c, &spec, &id);
    free(sb);
    free(tb);
    mesh_free(S);
    mesh_free(T);
    return id;
}

size_t testsec_sphere_bytes(int level)
{
    mesh *S = testmesh_icosphere(level);
    CHECK(S != NULL);
    size_t len;
    free(testdaemon_encode(S, &len));
    mesh_free(S);
    return len;
}

long long testsec_spool_bytes(const testdaemon *d, uint64_t id)
{
    char dir[700], path[1000];
    snprintf(dir, sizeof dir, "%s/spool/%llu", d->state, (unsigned long long)id);
    DIR *dp = opendir(dir);
    if (!dp)
        return 0;
    long long n = 0;
    struct dirent *de;
    while ((de = readdir(dp))) {
        struct stat st;
        snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
        if (de->d_name[0] != '.' && stat(path, &st) == 0 && S_ISREG(st.st_mode))
            n += (long long)st.st_size;
    }
    closedir(dp);
    return n;
}

int testsec_spool_has(const testdaemon *d, uint64_t id, const char *name)
{
    char path[800];
    snprintf(path, sizeof path, "%s/spool/%llu/%s", d->state, (unsigned long long)id, name);
    return access(path, F_OK) == 0;
}

long long testsec_daemon_rss(const testdaemon *d)
{
    char path[64], line[256];
    snprintf(path, sizeof path, "/proc/%d/status", (int)d->pid);
    FILE *fp = fopen(path, "r");
    if (!fp)
        FAILF("%s: the daemon is gone", path);
    long long kb = -1;
    while (fgets(line, sizeof line, fp))
        if (sscanf(line, "VmRSS: %lld kB", &kb) == 1)
            break;
    fclose(fp);
    CHECK(kb >= 0);
    return kb * 1024;
}
