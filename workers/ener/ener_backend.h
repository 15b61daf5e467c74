/* ener_backend.h — one interface to W_def (ener_def.h states the model) on
 * whichever engine computes it: "cpu" (ener_def: OpenMP threads) or
 * "opencl" (ener_ocl.h: the same per-element-then-gather passes as OpenCL
 * kernels, in double precision). Both give the same energy and gradient to
 * ~1e-10 relative, so the optimizer does not care which one it holds.
 *
 * Choosing: kind "cpu", "opencl" or "auto"; device is a substring of an
 * OpenCL platform or device name (case-insensitive; "" = any). "opencl"
 * takes the first matching device with fp64, GPUs first, and fails when
 * there is none; "auto" takes a matching GPU with fp64, else "cpu".
 *
 * Ownership: the backend keeps pointers to X's faces and to E (the caller
 * keeps them alive) and owns everything else. Not for two threads at once.
 * Errors: creation returns an ENER_E* code with the detail in err; a failure during update_admissible or eval (a lost device, device
 * memory exhausted) is the backend's first error, kept: from then on eval
 * returns NaN and update_admissible the error code, and
 * ener_backend_error() says what happened. */
#ifndef ENER_BACKEND_H
#define ENER_BACKEND_H
#include <stddef.h>
#include "ener/ener_def.h"

#define ENER_BACKEND_KIND_MAX 16     /* bytes of a kind name, NUL included  */
#define ENER_BACKEND_DEVICE_MAX 128  /* bytes of a device name, NUL included */

typedef struct ener_backend ener_backend;

/* The backend into *out, or an error with *out = NULL and the detail in
 * err: ENER_EINVAL (unknown kind, bad parameters), ENER_EDEGENERATE,
 * ENER_ENODEVICE (no OpenCL platform, no device matching the name, no
 * fp64), ENER_EBUILD (with the build log), ENER_ENOMEM / ENER_EDEVICE (with
 * OpenCL's error name). threads: the host threads the backend may use
 * (0 = all cores); for PoCL it sets POCL_MAX_PTHREAD_COUNT and
 * POCL_CPU_MAX_CU_COUNT unless the user set them (PoCL reads them once per
 * process). */
int ener_backend_new(const mesh *X, const geo_edges *E, const ener_def_params *p,
                     const char *kind, const char *device, int threads, ener_backend **out,
                     char *err, size_t errsz);
void ener_backend_free(ener_backend *b);

/* ener_def_update_admissible on this backend: the number of admissible
 * edges, or a negative ENER_E* code (see ener_backend_error). */
int ener_backend_update_admissible(ener_backend *b, const double *Y);

/* ener_def_eval on this backend; NaN after a failure. */
double ener_backend_eval(ener_backend *b, const double *Y, double *grad,
                         double *w_mem, double *w_bnd);

/* "cpu" or "opencl: DEVICE (PLATFORM)". */
const char *ener_backend_name(const ener_backend *b);
/* The first failure's detail, or NULL when none. */
const char *ener_backend_error(const ener_backend *b);

#endif
