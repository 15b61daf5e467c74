/* test_engine_layers.c — the engine's modules (the folders of workers/)
 * keep their floors: a module includes and calls only modules on its own
 * floor or below, and no two modules depend on each other. Two graphs are
 * read: the includes of the sources (workers/MOD/ files' `#include
 * "OTHER/..."`), and the calls of the built objects (nm: what each
 * build/obj/workers/MOD/ object uses that another module's objects
 * define), which also catches a function declared by hand instead of
 * through its header. The floors are the table below, derived from the
 * include graph (a module's floor is one above its highest dependency's)
 * and written down in workers/WORKER.md ("Module floors"); a folder the
 * table does not place fails, so a new module is placed when it is added. */
#include "support/harness.h"

#include <dirent.h>
#include <glob.h>
#include <stdio.h>
#include <string.h>

static const struct { const char *mod; int floor; } floors[] = {
    {"util", 0}, {"opt", 0},
    {"mesh", 1}, {"sandbox", 1}, {"chol", 1},
    {"geo", 2}, {"map", 2}, {"lmk", 2}, {"proj", 2},
    {"lbo", 3}, {"geod", 3}, {"ener", 3}, {"viz", 3}, {"ctf", 3}, {"repair", 3},
    {"desc", 4}, {"embed", 4}, {"metric", 4}, {"ddm", 4}, {"ectm", 4},
    {"fmap", 5}, {"fold", 5}, {"rhm", 5},
    {"start", 6},
    {"corr", 7},
    {"main", 8},
};
static const char *floor_names[] = {
    "util, opt",
    "mesh, sandbox, chol",
    "geo, map, lmk, proj",
    "lbo, geod, ener, viz, ctf, repair",
    "desc, embed, metric, ddm, ectm",
    "fmap, fold, rhm",
    "start",
    "corr",
    "main",
};

/* Dependencies allowed although they break the rule, each with its reason.
 * None today; the NULL row ends the list. */
static const struct { const char *from, *to, *why; } exceptions[] = {
    {NULL, NULL, NULL},
};

#define MAXM 48
#define MAXS 8192

static char mods[MAXM][32];
static int nmods;
static int inc[MAXM][MAXM];             /* inc[a][b]: a file of a includes b/... */
static char inc_where[MAXM][MAXM][160]; /* one such file */
static int call[MAXM][MAXM];            /* call[a][b]: an object of a uses b's symbol */
static char call_sym[MAXM][MAXM][128];

static int mod_index(const char *name)
{
    for (int m = 0; m < nmods; m++)
        if (strcmp(mods[m], name) == 0)
            return m;
    return -1;
}

static void read_modules(void)
{
    DIR *d = opendir("workers");
    if (!d)
        FAILF("no workers/ folder (run from the repository root)");
    struct dirent *e;
    while ((e = readdir(d)) && nmods < MAXM) {
        char path[300];
        snprintf(path, sizeof path, "workers/%s", e->d_name);
        DIR *sub = e->d_name[0] != '.' ? opendir(path) : NULL;
        if (sub) {
            closedir(sub);
            snprintf(mods[nmods++], sizeof mods[0], "%.31s", e->d_name);
        }
    }
    closedir(d);
    CHECK(nmods >= 10);
}

static void read_includes(void)
{
    for (int a = 0; a < nmods; a++) {
        const char *ext[] = {"c", "h", "cpp", "cl"};
        for (size_t x = 0; x < sizeof ext / sizeof ext[0]; x++) {
            char pat[128];
            glob_t g;
            snprintf(pat, sizeof pat, "workers/%.31s/*.%.3s", mods[a], ext[x]);
            if (glob(pat, 0, NULL, &g) != 0)
                continue;
            for (size_t i = 0; i < g.gl_pathc; i++) {
                FILE *f = fopen(g.gl_pathv[i], "r");
                CHECK(f != NULL);
                char line[512], name[64];
                while (fgets(line, sizeof line, f))
                    if (sscanf(line, " # include \"%63[^/\"]/", name) == 1 && strchr(line, '/')) {
                        int b = mod_index(name);
                        if (b >= 0 && b != a && !inc[a][b]) {
                            inc[a][b] = 1;
                            snprintf(inc_where[a][b], sizeof inc_where[0][0], "%.159s", g.gl_pathv[i]);
                        }
                    }
                fclose(f);
            }
            globfree(&g);
        }
    }
}

static struct { char name[128]; int mod; } defs[MAXS];
static int ndefs;

static void read_objects(void)
{
    static struct { char name[128]; int mod; } uses[MAXS * 2];
    int nuses = 0, nobj = 0;
    for (int m = 0; m < nmods; m++) {
        char pat[128];
        glob_t g;
        snprintf(pat, sizeof pat, "build/obj/workers/%.31s/*.o", mods[m]);
        if (glob(pat, 0, NULL, &g) != 0)
            continue;
        for (size_t i = 0; i < g.gl_pathc; i++, nobj++) {
            char cmd[512], line[512];
            snprintf(cmd, sizeof cmd, "nm %s", g.gl_pathv[i]);
            FILE *p = popen(cmd, "r");
            CHECK(p != NULL);
            while (fgets(line, sizeof line, p)) {
                char a[128], b[128], c[128];
                int n = sscanf(line, "%127s %127s %127s", a, b, c);
                if (n == 3 && strchr("TDBRW", b[0]) && ndefs < MAXS) {
                    memcpy(defs[ndefs].name, c, sizeof c);
                    defs[ndefs++].mod = m;
                } else if (n == 2 && strcmp(a, "U") == 0 && nuses < MAXS * 2) {
                    memcpy(uses[nuses].name, b, sizeof b);
                    uses[nuses++].mod = m;
                }
            }
            CHECK_INT(pclose(p), 0);
        }
        globfree(&g);
    }
    if (nobj < 20)
        FAILF("no engine objects under build/obj/workers (run from the repository root after make)");
    for (int u = 0; u < nuses; u++)
        for (int d = 0; d < ndefs; d++)
            if (defs[d].mod != uses[u].mod && strcmp(defs[d].name, uses[u].name) == 0 &&
                !call[uses[u].mod][defs[d].mod]) {
                call[uses[u].mod][defs[d].mod] = 1;
                memcpy(call_sym[uses[u].mod][defs[d].mod], defs[d].name, sizeof defs[d].name);
            }
}

static int floor_of(int m)
{
    for (size_t i = 0; i < sizeof floors / sizeof floors[0]; i++)
        if (strcmp(floors[i].mod, mods[m]) == 0)
            return floors[i].floor;
    return -1;
}

static int excused(int a, int b)
{
    for (size_t i = 0; exceptions[i].from; i++)
        if (strcmp(exceptions[i].from, mods[a]) == 0 && strcmp(exceptions[i].to, mods[b]) == 0)
            return 1;
    return 0;
}

/* The edges of g that go up a floor, printed; their count. */
static int upward(int g[MAXM][MAXM], const char *verb, char what[MAXM][MAXM][160], char sym[MAXM][MAXM][128])
{
    int bad = 0;
    for (int a = 0; a < nmods; a++)
        for (int b = 0; b < nmods; b++) {
            int fa = floor_of(a), fb = floor_of(b);
            if (!g[a][b] || fa < 0 || fb < 0 || fb <= fa || excused(a, b))
                continue;
            fprintf(stderr, "  %s (floor %d: %s) %s %s (floor %d: %s): %s\n", mods[a], fa, floor_names[fa],
                    verb, mods[b], fb, floor_names[fb], what ? what[a][b] : sym[a][b]);
            bad++;
        }
    return bad;
}

TEST(every_module_has_a_floor)
{
    read_modules();
    int bad = 0;
    for (int m = 0; m < nmods; m++)
        if (floor_of(m) < 0) {
            fprintf(stderr, "  workers/%s/ has no floor in this test's table (workers/WORKER.md)\n", mods[m]);
            bad++;
        }
    for (size_t i = 0; i < sizeof floors / sizeof floors[0]; i++)
        if (mod_index(floors[i].mod) < 0) {
            fprintf(stderr, "  the table places %s, which workers/ does not have\n", floors[i].mod);
            bad++;
        }
    CHECK_INT(bad, 0);
}

TEST(every_include_goes_to_the_modules_floor_or_below)
{
    read_modules();
    read_includes();
    /* the graph is read right: these includes exist and go down */
    CHECK(inc[mod_index("corr")][mod_index("rhm")] && inc[mod_index("geo")][mod_index("mesh")]);
    CHECK_INT(upward(inc, "includes", inc_where, NULL), 0);
}

TEST(every_call_goes_to_the_modules_floor_or_below)
{
    read_modules();
    read_objects();
    CHECK(call[mod_index("main")][mod_index("corr")] && call[mod_index("ectm")][mod_index("opt")]);
    CHECK_INT(upward(call, "calls up into", NULL, call_sym), 0);
}

/* reach[a][b]: a depends on b (includes or calls), directly or not. */
static int reach[MAXM][MAXM];

TEST(no_two_modules_depend_on_each_other)
{
    read_modules();
    read_includes();
    read_objects();
    for (int a = 0; a < nmods; a++)
        for (int b = 0; b < nmods; b++)
            reach[a][b] = (inc[a][b] || call[a][b]) && !(excused(a, b) && excused(b, a));
    for (int k = 0; k < nmods; k++)
        for (int i = 0; i < nmods; i++)
            if (reach[i][k])
                for (int j = 0; j < nmods; j++)
                    reach[i][j] |= reach[k][j];
    int bad = 0;
    for (int i = 0; i < nmods; i++)
        for (int j = i + 1; j < nmods; j++)
            if (reach[i][j] && reach[j][i]) {
                fprintf(stderr, "  %s and %s depend on each other (through a cycle)\n", mods[i], mods[j]);
                bad++;
            }
    CHECK_INT(bad, 0);
}
