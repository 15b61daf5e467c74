/* corr__ddm.h — internal (corr__): the pipeline's DDM stage (corr_ddm.c),
 * called by corr_run. Not part of the public corr_ API. */
#ifndef CORR__DDM_H
#define CORR__DDM_H
#include "corr/corr.h"

typedef int (*corr__ddm_report_fn)(void *ctx, const corr_ddm_report *r);

/* Denoises P0 (S -> T) and, when Q0 is not NULL, Q0 (T -> S) through their
 * functional maps in the first k eigenfunctions of each mesh (k: in->ddm_k,
 * or min(CORR_DDM_K, nv - 2) when 0): ddm_denoise with k1 = k2 = k.
 * *P, *Q (NULL when Q0 is): new maps the caller frees. report (may be
 * NULL) hears the start (done 0) and each direction; a non-zero return
 * cancels. KIND_OK, KIND_EPARAMS (bijective without Q0),
 * KIND_ENUMERIC (the Laplacian's factorisation or the eigen-solver
 * failed), KIND_EMESH, KIND_ENOMEM, KIND_ECANCELLED; detail in err. */
int corr__ddm(const corr_input *in, const bmap *P0, const bmap *Q0, corr__ddm_report_fn report,
              void *ctx, bmap **P, bmap **Q, char *err, size_t errsz);

#endif
