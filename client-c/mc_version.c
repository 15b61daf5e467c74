/* mc_version.c — mc_version(): the project's version, from the top-level
 * VERSION file (the Makefile passes it as MC_VERSION). */
#include "meshcorr.h"

#ifndef MC_VERSION
#error "MC_VERSION is not defined: build with the Makefile (it reads the VERSION file)"
#endif

const char *mc_version(void)
{
    return MC_VERSION;
}
