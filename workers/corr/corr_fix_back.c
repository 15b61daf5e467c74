/* corr_fix_back.c — corr_fix_to_user (corr.h): a job's result on the
 * repaired pair in the user's indexing. Apart from corr_fix.c because it
 * frees ECTM's results, which the daemon's validator must not link. */
#include "corr/corr.h"
#include "util/errbuf.h"

#include <string.h>

int corr_fix_to_user(const corr_fix *fx, const ectm_result *res, ectm_result *out, char *err,
                     size_t errsz)
{
    memset(out, 0, sizeof *out);
    out->last = res->last;
    if ((res->P && !(out->P = repair_map_to_user(&fx->S, &fx->T, res->P))) ||
        (res->Q && !(out->Q = repair_map_to_user(&fx->T, &fx->S, res->Q))) ||
        (res->Y && !(out->Y = repair_points_to_user(&fx->S, res->Y))) ||
        (res->Yt && !(out->Yt = repair_points_to_user(&fx->T, res->Yt))) ||
        (res->rhm_P && !(out->rhm_P = repair_map_to_user(&fx->S, &fx->T, res->rhm_P))) ||
        (res->rhm_Q && !(out->rhm_Q = repair_map_to_user(&fx->T, &fx->S, res->rhm_Q)))) {
        ectm_result_close(out);
        return errbuf_set(err, errsz, KIND_ENOMEM, "the result in the mesh's own indexing: out of "
                          "memory");
    }
    return KIND_OK;
}
