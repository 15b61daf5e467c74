/* cli_devices.c — `meshcorr devices`: lists the OpenCL platforms and devices
 * the "opencl" and "auto" backends can choose from (name, type, compute
 * units, fp64, global memory), and says why when there are none. Holds no
 * OpenCL code: the list comes from workers/ener/ener_ocl.h. */
#include "cli/cli.h"
#include "ener/ener_ocl.h"

#include <stdio.h>
#include <string.h>

int cli_devices(int argc, char **argv)
{
    (void)argv;
    if (argc > 1) {
        if (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0) {
            printf("usage: meshcorr devices\n"
                   "Lists OpenCL devices; `meshcorr match --backend opencl --device NAME` takes\n"
                   "the first device with fp64 whose platform or device name contains NAME.\n");
            return 0;
        }
        return cli_usage_error("devices", "%s '%s'", argv[1][0] == '-' ? "unknown option" : "unexpected argument",
                               argv[1]);
    }
    static ener_ocl_device dev[ENER_OCL_DEVICES_MAX];
    int n = 0;
    char err[2048];
    if (ener_ocl_device_list(0, dev, ENER_OCL_DEVICES_MAX, &n, err, sizeof err)) {
        fprintf(stderr, "meshcorr devices: %s\n", err);
        printf("no OpenCL devices: --backend auto uses the CPU\n");
        return 1;
    }
    int usable = 0;
    for (int i = 0; i < n; i++) {
        printf("%s\n  platform       %s\n  type           %s\n  compute units  %u\n"
               "  fp64           %s\n  global memory  %.2f GiB\n",
               dev[i].name, dev[i].platform, dev[i].type, dev[i].compute_units,
               dev[i].fp64 ? "yes" : "no (not usable by the optimizer)",
               (double)dev[i].global_mem / (1024.0 * 1024.0 * 1024.0));
        usable += dev[i].fp64;
    }
    printf("%d device(s), %d with fp64\n", n, usable);
    return 0;
}
