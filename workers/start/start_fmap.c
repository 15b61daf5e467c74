/* start_fmap.c — the functional-map start (start.h): in both directions a
 * functional map from the landmarks' wave-kernel descriptors (Δ, D_N and
 * orientation commutativity), grown by ZoomOut when asked, deblurred by
 * DDM into a pointwise map (thesis §2.4). Builds maps only. */
#include "start/start.h"
#include "ddm/ddm.h"
#include "fmap/fmap.h"
#include "lbo/lbo.h"
#include "proto.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

_Static_assert(PROTO_ZOOMOUT_MAX <= LBO_MAX_K, "zoomout's range must fit the eigenpairs'");
_Static_assert(PROTO_ZOOMOUT_MIN == START_FMAP_K + 1, "ZoomOut grows the fmap start's basis");

/* Both directions: C_ij from side i's and side j's landmark descriptors
 * with Δ, D_N and orientation commutativity (the orientation operators of
 * FMAP_ORIENT_ENERGIES columns per descriptor block, fmap.h), Psi_i C_ij ~
 * P_ij Psi_j, with zoomout > 0 grown by ZoomOut to that size
 * (fmap_zoomout), deblurred row by row onto side j (ddm.h). */
int start_fmap(rhm_side side[2], int zoomout, char *err, size_t errsz)
{
    rhm_side *s = side;
    int k = START_FMAP_K, rc = KIND_ENOMEM, nl = s[0].nl, kz = zoomout;
    for (int i = 0; i < 2; i++)
        if (k > s[i].n - 2)
            k = s[i].n - 2;
    for (int i = 0; i < 2; i++)
        if (kz > s[i].n - 2)
            return errbuf_set(err, errsz, KIND_EPARAMS,
                              "params.zoomout = %d: a basis holds at most vertices - 2 = %d "
                              "eigenfunctions here (%d vertices)", kz, s[i].n - 2, s[i].n);
    int kb = kz > k ? kz : k;                    /* the bases' size */
    lbo_basis bz[2], b[2];                       /* kb functions; the first k (descriptors, C) */
    memset(bz, 0, sizeof bz);
    memset(b, 0, sizeof b);
    double *F[2] = {NULL, NULL}, *N[2] = {NULL, NULL}, *C = malloc(sizeof(double) * (size_t)k * k);
    double *O[2] = {NULL, NULL}, *CZ = kz ? malloc(sizeof(double) * (size_t)kz * kz) : NULL;
    int *zmap = kz ? malloc(sizeof(int) * (size_t)(s[0].n > s[1].n ? s[0].n : s[1].n)) : NULL;
    int nd = 0, lrc = 0, *cols = malloc(sizeof(int) * (size_t)(1 + nl) * FMAP_ORIENT_ENERGIES);
    int no = cols ? fmap_orientation_columns(FMAP_ENERGIES_DEFAULT, nl, FMAP_ORIENT_ENERGIES, cols)
                  : 0;
    char detail[512] = "";
    lmk_set L = {nl, s[0].lmk, s[1].lmk}, R = {nl, s[1].lmk, s[0].lmk};
    for (int i = 0; i < 2 && !lrc; i++)
        lrc = lbo_eigenpairs(geod_solver_laplacian(s[i].geod), geod_solver_mass(s[i].geod), s[i].n, kb, &bz[i],
                             detail, sizeof detail);
    for (int i = 0; i < 2 && !lrc; i++)
        if (lbo_basis_first(&bz[i], k, &b[i]))
            goto nomem;
    if (lrc) {
        rc = errbuf_set(err, errsz, KIND_ENUMERIC, "the functional-map start: eigenpairs: %s", detail);
        goto out;
    }
    if (!C || !cols || (kz && (!CZ || !zmap)))
        goto nomem;
    for (int i = 0; i < 2; i++)
        if (!(N[i] = malloc(sizeof(double) * (size_t)k * k)) ||
            !(O[i] = malloc(sizeof(double) * (size_t)k * k * (no > 0 ? no : 1))))
            goto nomem;
    for (int i = 0; i < 2 && !lrc; i++)
        lrc = fmap_normal_operator(s[i].m, &b[i], k, N[i], detail, sizeof detail);
    for (int i = 0; i < 2 && !lrc; i++) {
        int j = 1 - i;
        free(F[0]);
        free(F[1]);
        F[0] = F[1] = NULL;
        lrc = fmap_landmark_descriptors(&b[i], &b[j], i ? &R : &L, FMAP_ENERGIES_DEFAULT, &F[0], &F[1], &nd,
                                        detail, sizeof detail);
        for (int q = 0; q < 2 && !lrc; q++) {
            int side = q ? j : i;
            lrc = fmap_orientation_operators(s[side].m, &b[side], F[q], nd, cols, no, k, O[q], detail,
                                             sizeof detail);
        }
        if (!lrc)
            lrc = fmap_from_descriptors_oriented(&b[i], geod_solver_mass(s[i].geod), F[0], N[i], O[0],
                                                 &b[j], geod_solver_mass(s[j].geod), F[1], N[j], O[1], nd,
                                                 no, k, k, FMAP_MU_LAP_DEFAULT, FMAP_MU_NORMAL_DEFAULT,
                                                 FMAP_MU_ORIENT_DEFAULT, C, NULL, detail, sizeof detail);
        if (!lrc && kz)
            lrc = fmap_zoomout(&bz[i], geod_solver_mass(s[i].geod), &bz[j], C, k, kz, FMAP_ZOOMOUT_STEP,
                               CZ, zmap, NULL, detail, sizeof detail);
        if (!lrc)
            lrc = kz ? ddm_deblur(&bz[i], NULL, &bz[j], s[j].m, CZ, kz, kz, s[i].P, NULL, detail, sizeof detail)
                     : ddm_deblur(&b[i], NULL, &b[j], s[j].m, C, k, k, s[i].P, NULL, detail, sizeof detail);
    }
    rc = lrc ? errbuf_set(err, errsz, KIND_ENUMERIC, "the functional-map start: %s", detail) : KIND_OK;
    goto out;
nomem:
    rc = errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
out:
    for (int i = 0; i < 2; i++) {
        lbo_basis_close(&b[i]);
        lbo_basis_close(&bz[i]);
        free(F[i]);
        free(N[i]);
        free(O[i]);
    }
    free(cols);
    free(C);
    free(CZ);
    free(zmap);
    return rc;
}
