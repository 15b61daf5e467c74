/* rhm_problem.c — building and freeing an RHM job's state (rhm__problem.h):
 * per side the heat-method solver, the landmark-MDS embedding, cotan
 * Laplacian, lumped mass, the projection tree over the embedding's first
 * three coordinates, and the X-step matrix pattern with its symbolic
 * factorisation. Computes no iteration. */
#include "rhm/rhm__problem.h"
#include "embed/embed.h"
#include "geo/geo_area.h"
#include "geo/geo_cotan.h"
#include "geo/geo_edges.h"
#include "util/errbuf.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

static void side_close(rhm__side *sd)
{
    free(sd->mass);
    geo_csr_free(sd->W);
    free(sd->X);
    geod_solver_free(sd->geod);
    proj_tree_free(sd->tree);
    free(sd->lmk);
    bmap_free(sd->P);
    free(sd->Xij);
    free(sd->anchor);
    free(sd->anchor_w);
    chol_free(sd->A);
}

void rhm__problem_free(rhm__problem *pb)
{
    if (!pb)
        return;
    for (int i = 0; i < 2; i++)
        side_close(&pb->side[i]);
    free(pb);
}

/* sd->A = W + diag(mass) in W's pattern (only the pattern matters to the
 * analysis), ordered by CHOLMOD's own choice and analysed. Faces are
 * edges of the mesh, so every product P_jiᵀ M_j P_ji fits this pattern. */
static int x_step_matrix(rhm__side *sd, const char *name, char *err, size_t errsz)
{
    const geo_csr *W = sd->W;
    char detail[256] = "";
    int rc = chol_new(W->n, (size_t)W->row_start[W->n], CHOL_ORDER_CHOLMOD, &sd->A, detail,
                      sizeof detail);
    for (int c = 0; rc == CHOL_OK && c < W->n; c++)   /* W symmetric: row c = column c */
        for (int q = W->row_start[c]; q < W->row_start[c + 1]; q++)
            if (W->col[q] <= c)
                chol_add(sd->A, W->col[q], c, W->val[q]);
    if (rc == CHOL_OK && (rc = chol_assemble(sd->A, CHOL_DIAG_SHIFT, sd->mass, detail,
                                             sizeof detail)) == CHOL_OK)
        rc = chol_analyse(sd->A, detail, sizeof detail);
    if (rc == CHOL_OK)
        return KIND_OK;
    if (rc == CHOL_ENOMEM)
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
    return errbuf_set(err, errsz, KIND_ENUMERIC, "%s: the X-step matrix: %s", name, detail);
}

static int side_build(rhm__problem *pb, rhm__side *sd, const mesh *m, const char *name,
                      char *err, size_t errsz)
{
    char detail[512];
    int rc;
    geo_edges e = {0};
    sd->m = m;
    sd->n = m->nv;
    sd->s = geo_total_area(m);
    sd->mass = malloc(sizeof(double) * (size_t)m->nv);
    sd->X = malloc(sizeof(double) * (size_t)m->nv * (size_t)pb->dim);
    sd->Xij = malloc(sizeof(double) * (size_t)m->nv * (size_t)pb->dim);
    if (!sd->mass || !sd->X || !sd->Xij)
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
    geo_vertex_areas(m, sd->mass);
    if ((rc = geod_solver_new(m, 0, &sd->geod, detail, sizeof detail)))
        return errbuf_set(err, errsz, rc == GEOD_ENOMEM ? KIND_ENOMEM : KIND_EMESH, "%s: geodesics: %s",
                          name, detail);
    if (m->nv <= pb->dim)
        return errbuf_set(err, errsz, KIND_EMESH, "%s: %d vertices are too few for a %d-D embedding",
                          name, m->nv, pb->dim);
    if ((rc = embed_lmds(sd->geod, pb->dim, 0, 0, sd->X, NULL, detail, sizeof detail)))
        return errbuf_set(err, errsz, rc == EMBED_ENOMEM ? KIND_ENOMEM : KIND_EMESH,
                          "%s: embedding: %s", name, detail);
    if ((rc = geo_edges_build(m, &e, detail, sizeof detail)) ||
        (rc = geo_cotan_laplacian(m, &e, &sd->W, detail, sizeof detail))) {
        geo_edges_close(&e);
        return errbuf_set(err, errsz, KIND_EMESH, "%s: Laplacian: %s", name, detail);
    }
    geo_edges_close(&e);
    /* the tree: M's connectivity, positions = the embedding's first three columns */
    mesh *emb = mesh_new(m->nv, m->nf);
    if (!emb)
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
    for (int v = 0; v < m->nv; v++)
        memcpy(emb->v + 3 * v, sd->X + (size_t)v * pb->dim, 3 * sizeof(double));
    memcpy(emb->f, m->f, sizeof(int) * 3 * (size_t)m->nf);
    sd->tree = proj_tree_new(emb, detail, sizeof detail);
    int nomem = errno == ENOMEM;
    mesh_free(emb);
    if (!sd->tree)
        return errbuf_set(err, errsz, nomem ? KIND_ENOMEM : KIND_ENUMERIC,
                          "%s: projection tree: %s", name, detail);
    return x_step_matrix(sd, name, err, errsz);
}

/* min_landmarks: PROTO_MIN_LANDMARKS for a start from landmarks, 0 for
 * given maps (L may then be NULL). */
static int problem_new(const mesh *S, const mesh *T, const lmk_set *L, int min_landmarks,
                       const rhm_params *p, rhm__problem **out, char *err, size_t errsz)
{
    *out = NULL;
    int rc = rhm_params_check(p, err, errsz);
    if (rc)
        return rc;
    static const lmk_set none = {0, NULL, NULL};
    if (!L)
        L = &none;
    if (L->n < min_landmarks)
        return errbuf_set(err, errsz, KIND_ELANDMARKS, "RHM needs at least %d landmark pairs, got %d",
                          min_landmarks, L->n);
    for (int r = 0; r < L->n; r++) {
        if (L->src[r] < 0 || L->src[r] >= S->nv || L->tgt[r] < 0 || L->tgt[r] >= T->nv)
            return errbuf_set(err, errsz, KIND_ELANDMARKS, "landmark %d (%d, %d) out of range",
                              r + 1, L->src[r], L->tgt[r]);
    }
    rhm__problem *pb = calloc(1, sizeof *pb);
    if (!pb)
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
    pb->p = *p;
    pb->dim = p->dim;
    pb->nl = L->n;
    for (int i = 0; i < 2; i++) {
        const int *src = i ? L->tgt : L->src;
        if (!(pb->side[i].lmk = malloc(sizeof(int) * ((size_t)L->n + 1)))) {
            rc = errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
            goto fail;
        }
        if (L->n)
            memcpy(pb->side[i].lmk, src, sizeof(int) * (size_t)L->n);
        if ((rc = side_build(pb, &pb->side[i], i ? T : S, i ? "target" : "source", err, errsz)))
            goto fail;
    }
    *out = pb;
    return KIND_OK;
fail:
    rhm__problem_free(pb);
    return rc;
}

int rhm__problem_new(const mesh *S, const mesh *T, const lmk_set *L, const rhm_params *p,
                     rhm__problem **out, char *err, size_t errsz)
{
    return problem_new(S, T, L, PROTO_MIN_LANDMARKS, p, out, err, errsz);
}

int rhm__problem_new_maps(const mesh *S, const mesh *T, const lmk_set *L, const rhm_params *p,
                          rhm__problem **out, char *err, size_t errsz)
{
    return problem_new(S, T, L, 0, p, out, err, errsz);
}
