/* ener_ocl.h — W_def (ener_def.h) evaluated by OpenCL kernels in double
 * precision, and the OpenCL device list. Callers normally go through
 * ener_backend.h; this header is for the backend, `meshcorr devices` and
 * tests.
 *
 * The reference caches are taken from an ener_def (so both backends start
 * from the same numbers) and copied to the device once, with the faces and
 * the vertex -> face lists; Y and the element buffers stay on the device.
 * Each eval uploads Y (nv by 3) and reads back the gradient and one partial
 * energy per work-group; update_admissible uploads Y and reads back one
 * partial count per work-group.
 *
 * Environment, set before the first OpenCL call of the process unless the
 * user set them: POCL_CACHE_DIR (PoCL reports no device without a writable
 * kernel cache) to $XDG_CACHE_HOME/meshcorr-pocl or /tmp/meshcorr-pocl-UID,
 * created 0700; POCL_MAX_PTHREAD_COUNT and POCL_CPU_MAX_CU_COUNT to the
 * thread budget. PoCL reads them once per process. Do not fork() after the
 * first OpenCL call (PoCL's threads do not survive it): use fork+exec.
 * One ener_ocl must not be used from two threads at once. */
#ifndef ENER_OCL_H
#define ENER_OCL_H
#include <stddef.h>
#include "ener/ener_def.h"

#define ENER_OCL_NAME_MAX 128      /* bytes kept of a platform or device name */
#define ENER_OCL_DEVICES_MAX 64    /* devices ener_ocl_device_list reports */

typedef struct ener_ocl ener_ocl;

typedef struct ener_ocl_device {
    char platform[ENER_OCL_NAME_MAX];
    char name[ENER_OCL_NAME_MAX];
    char type[16];                  /* "GPU", "CPU", "accelerator", "other" */
    unsigned compute_units;
    int fp64;                       /* 1 when double precision is supported */
    unsigned long long global_mem;  /* bytes */
} ener_ocl_device;

/* Up to max devices of all platforms into out, their number into *n.
 * ENER_ENODEVICE with the likely reason in err when there is no platform
 * or no device at all. threads as for ener_ocl_new. */
int ener_ocl_device_list(int threads, ener_ocl_device *out, int max, int *n,
                         char *err, size_t errsz);

/* An OpenCL evaluator of d's energy on the first device whose platform or
 * device name contains `device` (case-insensitive; "" or NULL = any) and
 * that supports fp64, GPUs before other devices; gpu_only: GPUs only.
 * threads: host threads for a CPU device (0 = all cores). d may be freed
 * once this returns; d's mesh faces and edge table need not outlive it
 * either. Errors as ener_backend_new's. */
int ener_ocl_new(const ener_def *d, const char *device, int gpu_only, int threads,
                 ener_ocl **out, char *err, size_t errsz);
void ener_ocl_free(ener_ocl *o);
int ener_ocl_update_admissible(ener_ocl *o, const double *Y);
double ener_ocl_eval(ener_ocl *o, const double *Y, double *grad,
                     double *w_mem, double *w_bnd);
/* "opencl: DEVICE (PLATFORM)" */
const char *ener_ocl_name(const ener_ocl *o);
/* The first failure's detail, or NULL. */
const char *ener_ocl_error(const ener_ocl *o);

/* Test hook: builds the prelude followed by src on the device chosen as in
 * ener_ocl_new, through the same build function; ENER_EBUILD with the build
 * log in err when it does not compile. */
int ener__ocl_build_check(const char *device, const char *src, char *err, size_t errsz);

#endif
