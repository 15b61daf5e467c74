/* corr_coarse.c — the landmark pipeline of a fine pair on decimated copies
 * (corr.h, corr_coarse_*): both meshes decimated with their landmarks
 * kept, the chain run there, the maps carried back to the input meshes
 * and repaired. Combines ctf and the pipeline; computes nothing itself. */
#include "corr/corr.h"
#include "ctf/ctf.h"
#include "util/errbuf.h"

#include <stdlib.h>
#include <string.h>

/* The coarse pair's vertices; 0: off. */
static int coarse_size(const corr_input *in)
{
    rhm_params d;
    rhm_params_init(&d);
    return in->rhm ? in->rhm->coarse : d.coarse;
}

int corr_coarse_wanted(const corr_input *in)
{
    long c = coarse_size(in);
    return c > 0 && !in->P0 && in->L && (corr_chain_run(in->stages, 0) & CORR_RUN_RHM) &&
           (in->S->nv > 2 * c || in->T->nv > 2 * c);
}

/* m decimated into *out (left NULL when m is small already), with the
 * landmark vertices lmk[0..n) renumbered to the copy's in clmk. */
static int coarse_side(const mesh *m, const char *name, const int *lmk, int n, int nc,
                       mesh **out, int *clmk, char *err, size_t errsz)
{
    memcpy(clmk, lmk, sizeof(int) * (size_t)n);
    if (m->nv <= 2L * nc)
        return KIND_OK;
    char why[512];
    int *fine = NULL;
    int rc = ctf_decimate(m, nc, lmk, n, out, &fine, why, sizeof why);
    if (rc)
        return errbuf_set(err, errsz, corr_from_ctf(rc), "%s: decimation: %s", name, why);
    int *at = malloc(sizeof(int) * (size_t)m->nv);
    if (!at) {
        free(fine);
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
    }
    for (int c = 0; c < (*out)->nv; c++)
        at[fine[c]] = c;
    for (int r = 0; r < n; r++)
        clmk[r] = at[lmk[r]];   /* present: ctf_decimate keeps them */
    free(at);
    free(fine);
    return corr_validate(*out, name, err, errsz);
}

int corr_coarse_open(const corr_input *in, corr_coarse *c, char *err, size_t errsz)
{
    memset(c, 0, sizeof *c);
    const lmk_set *L = in->L;
    c->lsrc = malloc(sizeof(int) * ((size_t)L->n + 1));
    c->ltgt = malloc(sizeof(int) * ((size_t)L->n + 1));
    if (!c->lsrc || !c->ltgt)
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
    int rc, nc = coarse_size(in);
    if ((rc = coarse_side(in->S, in->S_name, L->src, L->n, nc, &c->S, c->lsrc, err, errsz)) ||
        (rc = coarse_side(in->T, in->T_name, L->tgt, L->n, nc, &c->T, c->ltgt, err, errsz))) {
        corr_coarse_close(c);
        return rc;
    }
    c->L = (lmk_set){ L->n, c->lsrc, c->ltgt };
    c->in = *in;
    c->in.S = c->S ? c->S : in->S;
    c->in.T = c->T ? c->T : in->T;
    c->in.L = &c->L;
    return KIND_OK;
}

int corr_coarse_carry(const corr_input *in, const corr_coarse *c, const bmap *Pc,
                      const bmap *Qc, int repair, bmap **P, bmap **Q, char *err, size_t errsz)
{
    *P = NULL;
    if (Q)
        *Q = NULL;
    char why[512];
    int rc = ctf_prolong(c->in.S, c->in.T, Pc, in->S, in->T, P, why, sizeof why);
    if (!rc && Qc && Q)
        rc = ctf_prolong(c->in.T, c->in.S, Qc, in->T, in->S, Q, why, sizeof why);
    if (rc)
        rc = errbuf_set(err, errsz, corr_from_ctf(rc), "carrying the coarse maps to the meshes: %s", why);
    fold_report rep[2];
    if (!rc && repair)
        rc = corr_repair(in, *P, Q ? *Q : NULL, 0, rep, err, errsz);
    if (rc) {
        bmap_free(*P);
        *P = NULL;
        if (Q) {
            bmap_free(*Q);
            *Q = NULL;
        }
    }
    return rc;
}

void corr_coarse_close(corr_coarse *c)
{
    mesh_free(c->S);
    mesh_free(c->T);
    free(c->lsrc);
    free(c->ltgt);
    memset(c, 0, sizeof *c);
}
