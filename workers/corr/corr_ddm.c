/* corr_ddm.c — the pipeline's DDM stage (corr__ddm.h): the mode chosen
 * (auto: by the given pair's round trip), Laplace–Beltrami bases of both
 * meshes on the intrinsic Delaunay operators the geodesics use (lbo.h),
 * then DDM denoising of the given map(s) (ddm.h). */
#include "corr/corr__ddm.h"
#include "ddm/ddm.h"
#include "geod/geod.h"
#include "lbo/lbo.h"
#include "metric/metric.h"
#include "util/errbuf.h"

#include <math.h>
#include <string.h>

_Static_assert(PROTO_DDM_MAX_K <= LBO_MAX_K, "ddm_k's range must fit the eigenpairs'");

typedef struct basis {
    geod_solver *s;
    lbo_basis b;
} basis;

static int basis_open(basis *bs, const mesh *m, const char *name, int k, char *err, size_t errsz)
{
    char detail[512] = "";
    int rc = geod_solver_new(m, 0, &bs->s, detail, sizeof detail);
    if (rc)
        return errbuf_set(err, errsz, corr_from_geod(rc),
                          "DDM: %s: Laplacian: %s", name, detail);
    rc = lbo_eigenpairs(geod_solver_laplacian(bs->s), geod_solver_mass(bs->s), m->nv, k, &bs->b,
                        detail, sizeof detail);
    if (rc)
        return errbuf_set(err, errsz, corr_from_lbo(rc),
                          "DDM: %s: %d eigenpairs: %s", name, k, detail);
    return KIND_OK;
}

static void basis_close(basis *bs)
{
    lbo_basis_close(&bs->b);
    geod_solver_free(bs->s);
}

int corr__ddm(const corr_input *in, const bmap *P0, const bmap *Q0, corr__ddm_report_fn report,
              void *ctx, bmap **P, bmap **Q, char *err, size_t errsz)
{
    *P = *Q = NULL;
    const mesh *S = in->S, *T = in->T;
    int nmin = S->nv < T->nv ? S->nv : T->nv, k = in->ddm_k;   /* in range: corr_check_sizes */
    if (k == 0)
        k = CORR_DDM_K < nmin - 2 ? CORR_DDM_K : nmin - 2;
    corr_ddm_report r = {0, Q0 ? 2 : 1, k, {0, 0}, in->ddm_mode, NAN};
    if (in->ddm_mode == CORR_DDM_AUTO) {      /* bijective only for a pair that agrees */
        double st = NAN, ts = NAN;
        if (Q0 && (metric_round_trip(T, S, Q0, P0, &st) || metric_round_trip(S, T, P0, Q0, &ts)))
            return errbuf_set(err, errsz, KIND_ENOMEM, "DDM: out of memory");
        r.round_trip = Q0 ? (st > ts ? st : ts) : NAN;
        r.mode = Q0 && r.round_trip <= CORR_DDM_AUTO_ROUND_TRIP ? CORR_DDM_BIJECTIVE
                                                                 : CORR_DDM_PLAIN;
    }
    if (report && report(ctx, &r))
        return errbuf_set(err, errsz, KIND_ECANCELLED, "cancelled before DDM");
    basis bs[2];
    memset(bs, 0, sizeof bs);
    int rc;
    if ((rc = basis_open(&bs[0], S, in->S_name, k, err, errsz)) ||
        (rc = basis_open(&bs[1], T, in->T_name, k, err, errsz)))
        goto out;
    if (r.mode == CORR_DDM_BIJECTIVE) {   /* P and Q together: one report at the end */
        char detail[512] = "";
        double energy[DDM_BIJ_ITERATIONS_DEFAULT + 1];
        if (!Q0) {
            rc = errbuf_set(err, errsz, KIND_EPARAMS,
                            "bijective DDM (ddm_mode bijective) needs an initial reverse map");
            goto out;
        }
        if (!(*P = bmap_new(P0->n, P0->nt)) || !(*Q = bmap_new(Q0->n, Q0->nt))) {
            rc = errbuf_set(err, errsz, KIND_ENOMEM, "DDM: out of memory");
            goto out;
        }
        int drc = ddm_denoise_bijective(&bs[0].b, geod_solver_mass(bs[0].s), S, &bs[1].b,
                                        geod_solver_mass(bs[1].s), T, P0, Q0, k,
                                        DDM_BIJ_ALPHA_DEFAULT, DDM_BIJ_ITERATIONS_DEFAULT, *P, *Q,
                                        energy, detail, sizeof detail);
        if (drc) {
            rc = errbuf_set(err, errsz, corr_from_ddm(drc),
                            "bijective DDM denoising of the initial maps: %s", detail);
            goto out;
        }
        r.done = 2;
        r.cost[0] = r.cost[1] = energy[DDM_BIJ_ITERATIONS_DEFAULT] / 2;
        rc = report && report(ctx, &r)
                 ? errbuf_set(err, errsz, KIND_ECANCELLED, "cancelled in DDM") : KIND_OK;
        goto out;
    }
    const bmap *in_map[2] = {P0, Q0};
    bmap **out_map[2] = {P, Q};
    for (int d = 0; d < r.total; d++) {
        const basis *a = &bs[d], *b = &bs[1 - d];
        const mesh *to = d ? S : T;
        char detail[512] = "";
        ddm_stats st;
        if (!(*out_map[d] = bmap_new(in_map[d]->n, in_map[d]->nt))) {
            rc = errbuf_set(err, errsz, KIND_ENOMEM, "DDM: out of memory");
            goto out;
        }
        int drc = ddm_denoise(&a->b, geod_solver_mass(a->s), &b->b, to, in_map[d], k, k,
                              *out_map[d], &st, detail, sizeof detail);
        if (drc) {
            rc = errbuf_set(err, errsz, corr_from_ddm(drc),
                            "DDM denoising of the %s map: %s", d ? "reverse" : "initial", detail);
            goto out;
        }
        r.done = d + 1;
        r.cost[d] = st.cost;
        if (report && report(ctx, &r)) {
            rc = errbuf_set(err, errsz, KIND_ECANCELLED, "cancelled in DDM");
            goto out;
        }
    }
    rc = KIND_OK;
out:
    basis_close(&bs[0]);
    basis_close(&bs[1]);
    if (rc) {
        bmap_free(*P);
        bmap_free(*Q);
        *P = *Q = NULL;
    }
    return rc;
}
