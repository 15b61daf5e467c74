/* corr_check.c — the checks of a job's inputs that run before any stage
 * (corr.h): a mesh the optimizer can use (corr_validate) and the sizes the
 * meshes bound (corr_check_sizes). Apart from corr.c so that the daemon's
 * validator (meshcorr-validate) links the checks without the stages. */
#include "corr/corr.h"
#include "mesh/mesh_check.h"
#include "util/errbuf.h"

#include <string.h>

int corr_validate(const mesh *m, const char *name, char *err, size_t errsz)
{
    mesh_check_report rep;
    char detail[512];
    if (mesh_check_run(m, &rep, detail, sizeof detail))
        return errbuf_set(err, errsz, KIND_ENOMEM, "%s: %s", name, detail);
    if (mesh_check_usable(&rep))
        return KIND_OK;
    char lines[2048];
    mesh_check_problems(&rep, name, lines, sizeof lines);
    size_t n = strlen(lines);
    if (n && lines[n - 1] == '\n')
        lines[n - 1] = '\0';
    return errbuf_set(err, errsz, KIND_EMESH, "%s is not usable by the optimizer:\n%s", name, lines);
}

int corr_check_sizes(const corr_input *in, char *err, size_t errsz)
{
    const mesh *S = in->S, *T = in->T;
    int most = (S->nv < T->nv ? S->nv : T->nv) - 2;
    unsigned run = corr_chain_run(in->stages, !!in->P0);
    if ((run & CORR_RUN_DDM) && in->ddm_k > most)
        return errbuf_set(err, errsz, KIND_EPARAMS,
                          "params.ddm_k = %d: DDM's basis holds at most vertices - 2 = %d "
                          "eigenfunctions here (%s: %d vertices, %s: %d)",
                          in->ddm_k, most, in->S_name, S->nv, in->T_name, T->nv);
    const rhm_params *rp = in->rhm;
    int fmap = rp && (rp->start == RHM_START_FMAP || rp->start == RHM_START_AUTO);
    if ((run & CORR_RUN_RHM) && !in->P0 && fmap && rp->zoomout > most)
        return errbuf_set(err, errsz, KIND_EPARAMS,
                          "params.zoomout = %d: a basis holds at most vertices - 2 = %d "
                          "eigenfunctions here (%s: %d vertices, %s: %d)",
                          rp->zoomout, most, in->S_name, S->nv, in->T_name, T->nv);
    return KIND_OK;
}
