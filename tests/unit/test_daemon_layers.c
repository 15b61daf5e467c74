/* test_daemon_layers.c — the daemon's modules keep the layer order that
 * daemon/README.md states ("Files"): from the built objects (nm: the
 * symbols each daemon/X.o defines and the ones it uses), a module graph in
 * which every call goes to the caller's own floor or below. The one
 * exception is in the table below with its reason (srv <-> req, the only
 * cycle). What travels up does so through callbacks: a job's end reaches
 * the watchers through job_listen, a drain's end through the callbacks
 * bk_drain and req_quiesce take. A daemon object with no floor in the
 * table fails too: a new file is placed in it (and in the README) when it
 * is added. Also: only job.c records a job's state (store_set_state,
 * store_set_running). */
#include "support/harness.h"

#include <glob.h>
#include <stdio.h>
#include <string.h>

/* Floors, bottom (0) to top, as daemon/README.md lists the layers top to
 * bottom; the dashboards (dash, metrics, mbus, mbus_regs) read published
 * snapshots beside snap, and token is a command beside main. */
static const struct { const char *mod; int floor; } floors[] = {
    {"store", 0}, {"sched", 0}, {"wlock", 0}, {"priv", 0}, {"tls", 0}, {"conf", 0},
    {"auth", 0}, {"throttle", 0}, {"fds", 0}, {"dlog", 0},
    {"job", 1},
    {"backend", 2}, {"wsup", 2}, {"bk_slurm", 2}, {"bk_prog", 2}, {"bk_cmd", 2},
    {"notify", 3}, {"snap", 3}, {"devices", 3}, {"val", 3},
    {"dash", 3}, {"metrics", 3}, {"mbus", 3}, {"mbus_regs", 3},
    {"srv", 4}, {"req", 4},
    {"drain", 5}, {"reload", 5},
    {"main", 6}, {"token", 6},
};
static const char *floor_names[] = {
    "store, sched, wlock, priv, tls, conf, auth, throttle, fds, dlog",
    "job",
    "backend, wsup, bk_slurm, bk_prog, bk_cmd",
    "notify, snap, devices, val and the dashboards",
    "srv, req",
    "drain, reload",
    "main, token",
};

/* Calls allowed although they break the rule (an upward call, or a cycle
 * within a floor), each with its reason. */
static const struct { const char *from, *to, *why; } exceptions[] = {
    {"srv", "req", "a connection hands a complete request to its handler"},
    {"req", "srv", "the handler answers on the connection it was handed"},
};

#define MAXM 64
#define MAXS 4096

static char mods[MAXM][32];
static int nmods;
static struct { char name[128]; int mod; } defs[MAXS];
static int ndefs;
static struct { char name[128]; int mod; } uses[MAXS * 4];
static int nuses;
static int edge[MAXM][MAXM];
static char edge_sym[MAXM][MAXM][128];   /* one symbol that makes the call */

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
            if (defs[d].mod != uses[u].mod && strcmp(defs[d].name, uses[u].name) == 0 &&
                !edge[uses[u].mod][defs[d].mod]) {
                edge[uses[u].mod][defs[d].mod] = 1;
                memcpy(edge_sym[uses[u].mod][defs[d].mod], defs[d].name, sizeof defs[d].name);
            }
}

static int mod_of(const char *name)
{
    for (int m = 0; m < nmods; m++)
        if (strcmp(mods[m], name) == 0)
            return m;
    FAILF("no module %s among the daemon objects", name);
}

static int floor_of(const char *mod)
{
    for (size_t i = 0; i < sizeof floors / sizeof floors[0]; i++)
        if (strcmp(floors[i].mod, mod) == 0)
            return floors[i].floor;
    return -1;
}

static const char *excused(int a, int b)
{
    for (size_t i = 0; i < sizeof exceptions / sizeof exceptions[0]; i++)
        if (strcmp(exceptions[i].from, mods[a]) == 0 && strcmp(exceptions[i].to, mods[b]) == 0)
            return exceptions[i].why;
    return NULL;
}

TEST(every_call_goes_to_the_callers_floor_or_below)
{
    read_objects();
    int bad = 0;
    for (int m = 0; m < nmods; m++)
        if (floor_of(mods[m]) < 0) {
            fprintf(stderr, "  daemon/%s.c has no floor in this test's table (daemon/README.md's layers)\n",
                    mods[m]);
            bad++;
        }
    for (int a = 0; a < nmods; a++)
        for (int b = 0; b < nmods; b++) {
            int fa = floor_of(mods[a]), fb = floor_of(mods[b]);
            if (!edge[a][b] || fa < 0 || fb < 0 || fb <= fa || excused(a, b))
                continue;
            fprintf(stderr, "  %s (floor %d: %s) calls up into %s (floor %d: %s): %s\n", mods[a], fa,
                    floor_names[fa], mods[b], fb, floor_names[fb], edge_sym[a][b]);
            bad++;
        }
    /* the graph is read right: these calls exist and go down */
    CHECK(edge[mod_of("wsup")][mod_of("job")] && edge[mod_of("bk_slurm")][mod_of("job")]);
    CHECK(edge[mod_of("job")][mod_of("store")] && edge[mod_of("main")][mod_of("srv")]);
    CHECK_INT(bad, 0);
}

/* reach[a][b]: a calls b, directly or through others (Warshall). */
static int reach[MAXM][MAXM];

TEST(the_only_call_cycle_is_the_listed_exception)
{
    read_objects();
    for (int a = 0; a < nmods; a++)
        for (int b = 0; b < nmods; b++)
            reach[a][b] = edge[a][b] && !(excused(a, b) && excused(b, a));
    for (int k = 0; k < nmods; k++)
        for (int i = 0; i < nmods; i++)
            if (reach[i][k])
                for (int j = 0; j < nmods; j++)
                    reach[i][j] |= reach[k][j];
    int bad = 0;
    for (int i = 0; i < nmods; i++)
        for (int j = i + 1; j < nmods; j++)
            if (reach[i][j] && reach[j][i]) {
                fprintf(stderr, "  %s and %s call each other (through a cycle)\n", mods[i], mods[j]);
                bad++;
            }
    int srv = mod_of("srv"), req = mod_of("req");
    CHECK(edge[srv][req] && edge[req][srv]);   /* the exception is real */
    CHECK_INT(bad, 0);
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
