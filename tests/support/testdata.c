/* testdata.c — finds the .off files under the data folder; see testdata.h. */
#include "support/testdata.h"
#include "support/harness.h"

#include <ftw.h>
#include <stdlib.h>
#include <string.h>

static char **found;
static int nfound, capfound;

static int visit(const char *path, const struct stat *st, int type, struct FTW *ftw)
{
    (void)st; (void)ftw;
    size_t len = strlen(path);
    if (type != FTW_F || len < 4 || strcmp(path + len - 4, ".off") != 0)
        return 0;
    if (nfound == capfound) {
        capfound = capfound ? 2 * capfound : 64;
        found = realloc(found, (size_t)capfound * sizeof *found);
        if (!found)
            FAILF("out of memory listing data files");
    }
    found[nfound++] = strdup(path);
    return 0;
}

static int cmp(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

char **testdata_off_files(int *n)
{
    const char *dir = harness_data_dir();
    if (!dir)
        SKIP("../shared/data is absent");
    found = NULL;
    nfound = capfound = 0;
    if (nftw(dir, visit, 16, FTW_PHYS) != 0)
        FAILF("cannot walk %s", dir);
    qsort(found, (size_t)nfound, sizeof *found, cmp);
    *n = nfound;
    return found;
}

void testdata_free(char **paths, int n)
{
    for (int i = 0; i < n; i++)
        free(paths[i]);
    free(paths);
}
