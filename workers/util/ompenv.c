/* ompenv.c — see ompenv.h. Only environment and exec; no OpenMP calls here
 * (an OpenMP call before the re-exec would be wasted work). */
#include "util/ompenv.h"

#include <stdlib.h>
#include <unistd.h>

int ompenv_set_passive(void)
{
    if (getenv("OMP_WAIT_POLICY"))
        return 0;
    return setenv("OMP_WAIT_POLICY", "passive", 1) == 0;
}

void ompenv_ensure_passive(char **argv)
{
    if (!ompenv_set_passive())
        return;
    execv("/proc/self/exe", argv);
    /* exec failed (no /proc): carry on with libgomp's default */
}
