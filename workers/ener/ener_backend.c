/* ener_backend.c — the backend seam of ener_backend.h: which engine to use
 * ("cpu", "opencl", "auto") and the dispatch to it. The CPU backend is
 * ener_def itself; the OpenCL one is ener_ocl, built from an ener_def's
 * reference caches. No numerics here. */
#include "ener/ener_backend.h"
#include "ener/ener_ocl.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

struct ener_backend {
    ener_def *cpu;   /* exactly one of the two is set */
    ener_ocl *ocl;
};

/* ener_def_new's code, from the ENER_E* message its detail starts with. */
static int def_code(const char *detail)
{
    static const int codes[] = {
#define ENER_CODE(name, val, msg) name,
        ENER_ERRORS(ENER_CODE)
#undef ENER_CODE
    };
    for (size_t i = 1; i < sizeof codes / sizeof codes[0]; i++) {
        const char *m = ener_strerror(codes[i]);
        if (strncmp(detail, m, strlen(m)) == 0)
            return codes[i];
    }
    return ENER_EINVAL;
}

int ener_backend_new(const mesh *X, const geo_edges *E, const ener_def_params *p,
                     const char *kind, const char *device, int threads, ener_backend **out,
                     char *err, size_t errsz)
{
    *out = NULL;
    const char *k = kind && kind[0] ? kind : "cpu";
    int want_ocl = strcmp(k, "opencl") == 0, want_auto = strcmp(k, "auto") == 0;
    if (!want_ocl && !want_auto && strcmp(k, "cpu") != 0)
        return errbuf_set(err, errsz, ENER_EINVAL, "%s: backend '%s' is not cpu, opencl or auto",
                          ener_strerror(ENER_EINVAL), k);
    ener_backend *b = calloc(1, sizeof *b);
    if (!b)
        return errbuf_set(err, errsz, ENER_ENOMEM, "%s", ener_strerror(ENER_ENOMEM));
    int rc = ENER_OK;
    char detail[1024] = "";
    b->cpu = ener_def_new(X, E, p, detail, sizeof detail);
    if (!b->cpu) {
        rc = errbuf_set(err, errsz, def_code(detail), "%s", detail);
        goto fail;
    }
    if (want_ocl || want_auto) {
        rc = ener_ocl_new(b->cpu, device, want_auto, threads, &b->ocl, err, errsz);
        if (rc == ENER_OK) {
            ener_def_free(b->cpu);   /* the device holds its caches now */
            b->cpu = NULL;
        } else if (want_auto && rc == ENER_ENODEVICE) {
            rc = ENER_OK;            /* no GPU with fp64: the CPU backend */
        } else {
            goto fail;
        }
    }
    *out = b;
    return ENER_OK;
fail:
    ener_backend_free(b);
    return rc;
}

void ener_backend_free(ener_backend *b)
{
    if (!b)
        return;
    ener_def_free(b->cpu);
    ener_ocl_free(b->ocl);
    free(b);
}

int ener_backend_update_admissible(ener_backend *b, const double *Y)
{
    return b->ocl ? ener_ocl_update_admissible(b->ocl, Y) : ener_def_update_admissible(b->cpu, Y);
}

double ener_backend_eval(ener_backend *b, const double *Y, double *grad,
                         double *w_mem, double *w_bnd)
{
    return b->ocl ? ener_ocl_eval(b->ocl, Y, grad, w_mem, w_bnd)
                  : ener_def_eval(b->cpu, Y, grad, w_mem, w_bnd);
}

const char *ener_backend_name(const ener_backend *b)
{
    return b->ocl ? ener_ocl_name(b->ocl) : "cpu";
}

const char *ener_backend_error(const ener_backend *b)
{
    return b->ocl ? ener_ocl_error(b->ocl) : NULL;
}
