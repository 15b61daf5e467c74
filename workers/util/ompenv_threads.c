/* ompenv_threads.c — ompenv_threads_for (ompenv.h): how many threads a job's
 * size pays for. */
#include "util/ompenv.h"

#include <omp.h>

int ompenv_threads_for(int vertices, int requested)
{
    if (requested > 0)
        return requested;
    int cores = omp_get_num_procs();
    int want = vertices / OMPENV_VERTICES_PER_THREAD;
    if (want > cores)
        want = cores;
    return want < 1 ? 1 : want;
}
