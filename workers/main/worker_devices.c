/* worker_devices.c — `meshcorr-worker --list-devices`: one line per compute
 * device a job on this machine can use, for the daemon's STATS (the daemon
 * asks a short-lived worker rather than touching OpenCL itself: forking
 * after PoCL is initialised hangs the child). "cpu:N" first, then each
 * OpenCL device with double precision as "opencl:PLATFORM/DEVICE (TYPE,
 * N CU)". Prints nothing else; never fails for want of OpenCL. */
#include "main/worker.h"
#include "ener/ener_ocl.h"

#include <stdio.h>
#include <unistd.h>

int wrk_list_devices(int threads)
{
    long ncpu = threads > 0 ? threads : sysconf(_SC_NPROCESSORS_ONLN);
    printf("cpu:%ld\n", ncpu);
    static ener_ocl_device dev[ENER_OCL_DEVICES_MAX];
    int n = 0;
    char err[512];
    if (ener_ocl_device_list(threads, dev, ENER_OCL_DEVICES_MAX, &n, err, sizeof err) == 0)
        for (int i = 0; i < n; i++)
            if (dev[i].fp64)
                printf("opencl:%s/%s (%s, %u CU)\n", dev[i].platform, dev[i].name, dev[i].type,
                       dev[i].compute_units);
    return fflush(stdout) == 0 ? 0 : 1;
}
