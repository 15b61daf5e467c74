/* ompenv.c — see ompenv.h. Only environment and exec; no OpenMP calls here
 * (an OpenMP call before the re-exec would be wasted work). */
#include "util/ompenv.h"

#include <stdlib.h>
#include <unistd.h>

void ompenv_ensure_passive(char **argv)
{
    if (getenv("OMP_WAIT_POLICY"))
        return;
    if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0)
        return;
    execv("/proc/self/exe", argv);
    /* exec failed (no /proc): carry on with libgomp's default */
}
