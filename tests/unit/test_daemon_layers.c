/* test_daemon_layers.c — the daemon's modules call downwards only. From the
 * built objects (nm: the symbols each daemon/X.o defines and the ones it
 * uses), a module graph; its only cycle may be srv <-> req (a connection
 * hands a request to its handler, which answers on the connection). The
 * backends, the job module and everything below them never call up: a job's
 * end reaches the watchers through job_listen, a drain's end through the
 * callbacks bk_drain and req_quiesce take. Also: only job.c records a job's
 * state (store_set_state, store_set_running). */
#include "support/harness.h"

#include <glob.h>
#include <stdio.h>
#include <string.h>

#define MAXM 64
#define MAXS 4096

static char mods[MAXM][32];
static int nmods;
static struct { char name[128]; int mod; } defs[MAXS];
static int ndefs;
static struct { char name[128]; int mod; } uses[MAXS * 4];
static int nuses;
static int edge[MAXM][MAXM];

static void read_objects(void)
{
    glob_t g;
    if (glob("build/obj/daemon/*.o", 0, NULL, &g) != 0 || g.gl_pathc < 10)
        FAILF("no daemon objects under build/obj/daemon (run from the repository root after make)");
    for (size_t i = 0; i < g.gl_pathc && nmods < MAXM; i++) {
        const char *base = strrchr(g.gl_pathv[i], '/') + 1;
        int m = nmods++;
        snprintf(mods[m], sizeof mods[m], "%.*s", (int)(strlen(base) - 2), base);
        char cmd[512];
        snprintf(cmd, sizeof cmd, "nm %s", g.gl_pathv[i]);
        FILE *p = popen(cmd, "r");
        CHECK(p != NULL);
        char line[256];
        while (fgets(line, sizeof line, p)) {
            char a[128], b[128], c[128];
            int n = sscanf(line, "%127s %127s %127s", a, b, c);
            if (n == 3 && strchr("TDBR", b[0]) && ndefs < MAXS) {
                snprintf(defs[ndefs].name, sizeof defs[ndefs].name, "%s", c);
                defs[ndefs++].mod = m;
            } else if (n == 2 && strcmp(a, "U") == 0 && nuses < MAXS * 4) {
                snprintf(uses[nuses].name, sizeof uses[nuses].name, "%s", b);
                uses[nuses++].mod = m;
            }
        }
        CHECK_INT(pclose(p), 0);
    }
    globfree(&g);
    for (int u = 0; u < nuses; u++)
        for (int d = 0; d < ndefs; d++)
            if (defs[d].mod != uses[u].mod && strcmp(defs[d].name, uses[u].name) == 0)
                edge[uses[u].mod][defs[d].mod] = 1;
}

static int mod_of(const char *name)
{
    for (int m = 0; m < nmods; m++)
        if (strcmp(mods[m], name) == 0)
            return m;
    FAILF("no module %s among the daemon objects", name);
}

/* reach[a][b]: a calls b, directly or through others (Warshall). */
static int reach[MAXM][MAXM];

TEST(the_only_call_cycle_is_srv_and_req)
{
    read_objects();
    memcpy(reach, edge, sizeof reach);
    for (int k = 0; k < nmods; k++)
        for (int i = 0; i < nmods; i++)
            if (reach[i][k])
                for (int j = 0; j < nmods; j++)
                    reach[i][j] |= reach[k][j];
    int srv = mod_of("srv"), req = mod_of("req"), bad = 0;
    for (int i = 0; i < nmods; i++)
        for (int j = i + 1; j < nmods; j++)
            if (reach[i][j] && reach[j][i] && !((i == srv && j == req) || (i == req && j == srv))) {
                fprintf(stderr, "  %s and %s call each other (through a cycle)\n", mods[i], mods[j]);
                bad++;
            }
    CHECK(reach[srv][req] && reach[req][srv]);   /* the graph is read right */
    CHECK_INT(bad, 0);
    /* the backends and the job module are below the request handlers */
    int job = mod_of("job");
    const char *low[] = {"wsup", "bk_slurm", "bk_prog", "job", "backend"};
    for (size_t i = 0; i < sizeof low / sizeof low[0]; i++) {
        int m = mod_of(low[i]);
        if (reach[m][req] || reach[m][srv] || reach[m][mod_of("drain")])
            FAILF("%s calls up into req, srv or drain", low[i]);
    }
    CHECK(edge[mod_of("wsup")][job] && edge[mod_of("bk_slurm")][job]);
}

TEST(only_the_job_module_records_a_jobs_state)
{
    read_objects();
    const char *writers[] = {"store_set_state", "store_set_running"};
    for (size_t w = 0; w < 2; w++)
        for (int u = 0; u < nuses; u++)
            if (strcmp(uses[u].name, writers[w]) == 0 && strcmp(mods[uses[u].mod], "job") != 0)
                FAILF("%s calls %s: a job's state is recorded by job.c alone", mods[uses[u].mod],
                      writers[w]);
}
