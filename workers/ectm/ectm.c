/* ectm.c — the ECTM alternating optimisation (see ectm.h): set-up of the two
 * sides, the P/Q projections, the Y/Ỹ L-BFGS solves with their quadratic
 * terms, reporting and cancellation. Energies of the shells are ener_backend's,
 * projections proj's, the solver opt's: this file only combines them. */
#include "ectm/ectm.h"
#include "ener/ener_backend.h"
#include "geo/geo_area.h"
#include "geo/geo_edges.h"
#include "opt/opt_lbfgs.h"
#include "proj/proj.h"
#include "proto.h"
#include "util/errbuf.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void ectm_result_close(ectm_result *r)
{
    if (!r)
        return;
    bmap_free(r->P);
    bmap_free(r->Q);
    bmap_free(r->rhm_P);
    bmap_free(r->rhm_Q);
    free(r->Y);
    free(r->Yt);
    memset(r, 0, sizeof *r);
}

/* One mesh of the pair with everything the optimisation keeps for it. */
typedef struct side {
    mesh *X;              /* scaled copy of the input                       */
    geo_scaling frame;    /* how X was scaled from the input (identity when partial) */
    geo_edges E;
    ener_backend *def;
    double *mass;         /* lumped vertex areas of X                       */
    proj_tree *tree;      /* BVH over X: the other side projects onto it    */
    double *Y;            /* deformation of X (nv by 3)                     */
    bmap *P;              /* this side's vertices onto the other mesh       */
    double *PX;           /* P·X_other (nv by 3)                            */
    double *PY;           /* P·Y_other (nv by 3)                            */
    /* Transpose of the OTHER side's map, for the gradient of
     * γ‖P_other·Y − X_other‖² w.r.t. this side's Y: for vertex v of this
     * side, rows tr_row[tr_start[v]..tr_start[v+1]) of the other map with the
     * weight tr_w of v in them. Sorted by row: deterministic gather. */
    int *tr_start, *tr_row;
    double *tr_w;
    double *resid;        /* scratch: per row of the other map, residual (3) */
    double *Zq;           /* scratch: projection embedding / queries         */
    double *Zt;
    /* The Y-step's L-BFGS pairs, kept from one outer iteration to the next
     * (β and the maps change little between them), and the β they are
     * exact for: the β term's Hessian is 2β·M, so a new β moves every y by
     * 2Δβ·M·s (opt_memory_add_diagonal with mass3 = M per coordinate). */
    opt_memory *mem;
    double mem_beta;
    double *mass3;
    /* Pinned rows (the given landmarks): row pin_row[k] of P goes to the
     * other mesh's vertex pin_vtx[k], on the projection's face when it has
     * that vertex, else on the lowest-numbered face there (its E). */
    int npin;
    int *pin_row, *pin_vtx;
} side;

static void side_close(side *s)
{
    mesh_free(s->X);
    geo_edges_close(&s->E);
    ener_backend_free(s->def);
    free(s->mass);
    proj_tree_free(s->tree);
    free(s->Y);
    bmap_free(s->P);
    free(s->PX);
    free(s->PY);
    free(s->tr_start);
    free(s->tr_row);
    free(s->tr_w);
    free(s->resid);
    free(s->Zq);
    free(s->Zt);
    opt_memory_free(s->mem);
    free(s->mass3);
    free(s->pin_row);
    free(s->pin_vtx);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int side_open(side *s, const mesh *in, int partial, const ener_def_params *dp,
                     const ectm_params *p, const char *which, char *err, size_t errsz)
{
    char detail[512];
    memset(s, 0, sizeof *s);
    s->X = mesh_copy(in);
    if (!s->X)
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory copying the %s mesh", which);
    s->frame.scale = 1;
    if (!partial && geo_normalize_area(s->X, &s->frame, detail, sizeof detail))
        return errbuf_set(err, errsz, KIND_EMESH, "%s mesh: %s", which, detail);
    if (geo_edges_build(s->X, &s->E, detail, sizeof detail))
        return errbuf_set(err, errsz, KIND_EMESH, "%s mesh: %s", which, detail);
    int erc = ener_backend_new(s->X, &s->E, dp, p->backend, p->device, p->threads, &s->def,
                               detail, sizeof detail);
    if (erc)
        return errbuf_set(err, errsz, erc == ENER_ENOMEM ? KIND_ENOMEM
                                      : erc == ENER_EDEGENERATE || erc == ENER_EINVAL ? KIND_EMESH
                                      : KIND_EPARAMS,
                          "%s mesh: %s", which, detail);
    s->tree = proj_tree_new(s->X, detail, sizeof detail);
    if (!s->tree)
        return errbuf_set(err, errsz, KIND_ENOMEM, "%s mesh: %s", which, detail);
    size_t n3 = (size_t)s->X->nv * 3;
    s->mass = malloc(sizeof(double) * ((size_t)s->X->nv + 1));
    s->Y = malloc(sizeof(double) * (n3 + 1));
    s->PX = malloc(sizeof(double) * (n3 + 1));
    s->PY = malloc(sizeof(double) * (n3 + 1));
    s->tr_start = malloc(sizeof(int) * ((size_t)s->X->nv + 2));
    s->Zq = malloc(sizeof(double) * ((size_t)s->X->nv * 6 + 1));
    s->mass3 = malloc(sizeof(double) * (n3 + 1));
    opt_params op;
    opt_params_init(&op);
    s->mem = opt_memory_new((int)n3, op.memory);
    if (!s->mass || !s->Y || !s->PX || !s->PY || !s->tr_start || !s->Zq || !s->mass3 || !s->mem)
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory for the %s mesh", which);
    geo_vertex_areas(s->X, s->mass);
    for (size_t i = 0; i < n3; i++)
        s->mass3[i] = s->mass[i / 3];
    return KIND_OK;
}

/* Rebuilds a's transpose of b's map (b->P maps b's vertices onto a's faces). */
static int side_transpose(side *a, const side *b)
{
    int n = a->X->nv, rows = b->X->nv;
    if (!a->tr_row) {
        a->tr_row = malloc(sizeof(int) * ((size_t)rows * 3 + 1));
        a->tr_w = malloc(sizeof(double) * ((size_t)rows * 3 + 1));
        a->resid = malloc(sizeof(double) * ((size_t)rows * 3 + 1));
        if (!a->tr_row || !a->tr_w || !a->resid)
            return KIND_ENOMEM;
    }
    memset(a->tr_start, 0, sizeof(int) * ((size_t)n + 2));
    for (int j = 0; j < rows; j++)
        for (int k = 0; k < 3; k++)
            a->tr_start[a->X->f[3 * b->P->face[j] + k] + 2]++;
    for (int v = 0; v < n; v++)
        a->tr_start[v + 2] += a->tr_start[v + 1];
    for (int j = 0; j < rows; j++)   /* rows in increasing order: sorted lists */
        for (int k = 0; k < 3; k++) {
            int v = a->X->f[3 * b->P->face[j] + k];
            int at = a->tr_start[v + 1]++;
            a->tr_row[at] = j;
            a->tr_w[at] = b->P->w[3 * j + k];
        }
    return KIND_OK;
}

/* The Y-step energy of side a given the other side b:
 *   W_def(X_a, Y) + β Σ_i m_i |Y_i − (P_a X_b)_i|²
 *   + γ Σ_j m_b,j |(P_b Y)_j − X_b,j|²   (bijective only)               */
typedef struct ystep {
    side *a;
    const side *b;
    double beta, gamma;
    int bijective;
    double w_mem, w_bnd, mismatch, reverse;
    int admissible;
} ystep;

static double ystep_eval(void *ctx, const double *Y, double *g, int n3)
{
    ystep *st = ctx;
    side *a = st->a;
    const side *b = st->b;
    double w_mem, w_bnd;
    double e = ener_backend_eval(a->def, Y, g, &w_mem, &w_bnd);
    double mis = 0;
    const double beta = st->beta, gamma = st->gamma;
    int nv = n3 / 3;
    for (int i = 0; i < nv; i++) {
        double m = a->mass[i];
        for (int k = 0; k < 3; k++) {
            double d = Y[3 * i + k] - a->PX[3 * i + k];
            mis += m * d * d;
            g[3 * i + k] += 2 * beta * m * d;
        }
    }
    mis *= beta;
    double rev = 0;
    if (st->bijective && gamma > 0) {
        int rows = b->X->nv;
        const int *af = a->X->f;
        #pragma omp parallel for schedule(static)
        for (int j = 0; j < rows; j++) {
            const int *fv = af + 3 * b->P->face[j];
            const double *w = b->P->w + 3 * j;
            for (int k = 0; k < 3; k++)
                a->resid[3 * j + k] = w[0] * Y[3 * fv[0] + k] + w[1] * Y[3 * fv[1] + k]
                                    + w[2] * Y[3 * fv[2] + k] - b->X->v[3 * j + k];
        }
        for (int j = 0; j < rows; j++) {
            const double *r = a->resid + 3 * j;
            rev += b->mass[j] * (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        }
        rev *= gamma;
        #pragma omp parallel for schedule(static)
        for (int v = 0; v < nv; v++) {
            double gx = 0, gy = 0, gz = 0;
            for (int s = a->tr_start[v]; s < a->tr_start[v + 1]; s++) {
                int j = a->tr_row[s];
                double c = 2 * gamma * b->mass[j] * a->tr_w[s];
                gx += c * a->resid[3 * j];
                gy += c * a->resid[3 * j + 1];
                gz += c * a->resid[3 * j + 2];
            }
            g[3 * v] += gx;
            g[3 * v + 1] += gy;
            g[3 * v + 2] += gz;
        }
    }
    st->w_mem = w_mem;
    st->w_bnd = w_bnd;
    st->mismatch = mis;
    st->reverse = rev;
    return e + mis + rev;
}

/* After each accepted L-BFGS iteration: refresh the admissible edge set (the
 * paper's rule); when it changed, so did the energy: the solver evaluates
 * it again at Y. */
static int ystep_iter(void *ctx, const double *Y, double fx, double gnorm, int iter)
{
    (void)fx; (void)gnorm; (void)iter;
    ystep *st = ctx;
    int count = ener_backend_update_admissible(st->a->def, Y);
    if (count != st->admissible) {
        st->admissible = count;
        return OPT_ITER_CHANGED;
    }
    return OPT_ITER_GO;
}

/* The landmarks refused before anything runs: each index in range for its
 * mesh, no source vertex twice (it would be pinned to two points). */
static int check_landmarks(const ectm_landmarks *L, const mesh *S, const mesh *T, char *err,
                           size_t errsz)
{
    if (!L || L->n == 0)
        return KIND_OK;
    if (L->n < 0)
        return errbuf_set(err, errsz, KIND_EPARAMS, "landmarks.n = %d < 0", L->n);
    if (!L->src || !L->tgt)
        return errbuf_set(err, errsz, KIND_EPARAMS, "landmarks.%s is NULL with landmarks.n = %d",
                          L->src ? "tgt" : "src", L->n);
    for (int k = 0; k < L->n; k++) {
        if (L->src[k] < 0 || L->src[k] >= S->nv)
            return errbuf_set(err, errsz, KIND_EPARAMS,
                              "landmarks.src[%d] = %d out of range [0, %d) (source vertices)", k,
                              L->src[k], S->nv);
        if (L->tgt[k] < 0 || L->tgt[k] >= T->nv)
            return errbuf_set(err, errsz, KIND_EPARAMS,
                              "landmarks.tgt[%d] = %d out of range [0, %d) (target vertices)", k,
                              L->tgt[k], T->nv);
    }
    int *first = malloc(sizeof(int) * (size_t)S->nv);   /* each source vertex's first pair */
    if (!first)
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory checking the landmarks");
    for (int v = 0; v < S->nv; v++)
        first[v] = -1;
    int rc = KIND_OK;
    for (int k = 0; k < L->n && !rc; k++) {
        if (first[L->src[k]] >= 0)
            rc = errbuf_set(err, errsz, KIND_EPARAMS, "landmarks.src[%d] = %d repeats landmarks.src[%d]",
                            k, L->src[k], first[L->src[k]]);
        first[L->src[k]] = k;
    }
    free(first);
    return rc;
}

/* a's pinned rows: row rows[k] to the vertex vtx[k] of b's mesh, k < n; a row
 * given twice keeps its first vertex. */
static int side_pins(side *a, const side *b, const int *rows, const int *vtx, int n)
{
    if (n <= 0)
        return KIND_OK;
    a->pin_row = malloc(sizeof(int) * (size_t)n);
    a->pin_vtx = malloc(sizeof(int) * (size_t)n);
    char *taken = calloc((size_t)a->X->nv, 1);
    if (!a->pin_row || !a->pin_vtx || !taken) {
        free(taken);
        return KIND_ENOMEM;
    }
    const int *vf = b->E.vf_start;
    for (int k = 0; k < n; k++) {
        if (taken[rows[k]] || vf[vtx[k]] == vf[vtx[k] + 1])   /* no face there: nothing to pin to */
            continue;
        taken[rows[k]] = 1;
        a->pin_row[a->npin] = rows[k];
        a->pin_vtx[a->npin++] = vtx[k];
    }
    free(taken);
    return KIND_OK;
}

/* Sets a's pinned rows of P onto their vertices of b's mesh, in every P-step:
 * a pin skipped where it would fold the row's faces folds less locally but
 * loses what the pins gain elsewhere (docs/decisions.md, "ECTM pins its
 * landmarks in every P-step"). */
static void apply_pins(side *a, const side *b)
{
    const int *bf = b->X->f;
    for (int k = 0; k < a->npin; k++) {
        int i = a->pin_row[k], v = a->pin_vtx[k], f = a->P->face[i];
        if (bf[3 * f] != v && bf[3 * f + 1] != v && bf[3 * f + 2] != v)
            f = b->E.vf_face[b->E.vf_start[v]];     /* the lowest-numbered face at v */
        a->P->face[i] = f;
        for (int c = 0; c < 3; c++)
            a->P->w[3 * i + c] = bf[3 * f + c] == v ? 1.0 : 0.0;
    }
}

/* P-step of side a onto b: rows minimise β|p·X_b − Y_a,i|² + γ|p·Y_b − X_a,i|²,
 * then the pinned rows (the landmarks) are set to their vertices. */
static void pstep(side *a, const side *b, double beta, double gamma, int bijective)
{
    int d = bijective ? 6 : 3;
    int na = a->X->nv, nb = b->X->nv;
    double sb = sqrt(beta), sg = sqrt(gamma);
    double *Z = b->Zt, *Q = a->Zq;
    for (int j = 0; j < nb; j++)
        for (int k = 0; k < 3; k++) {
            Z[d * j + k] = sb * b->X->v[3 * j + k];
            if (bijective)
                Z[d * j + 3 + k] = sg * b->Y[3 * j + k];
        }
    for (int i = 0; i < na; i++)
        for (int k = 0; k < 3; k++) {
            Q[d * i + k] = sb * a->Y[3 * i + k];
            if (bijective)
                Q[d * i + 3 + k] = sg * a->X->v[3 * i + k];
        }
    proj_closest(b->tree, d, Z, sb, na, Q, a->P->face, a->P->w, NULL);  /* d, s valid */
    apply_pins(a, b);
    bmap_apply(a->P, b->X->f, b->X->v, 3, a->PX);
}

/* A Y-step stops when one L-BFGS iteration lowers its energy by less than this
 * fraction of what the step has gained so far (or after inner_iterations).
 * With pairs kept across outer iterations, the later iterations of a Y-step
 * gain little that the next outer iteration would not; the fraction trades
 * those evaluations against the final energy (docs/decisions.md, "ECTM's
 * Y-step stops on a relative gain"). */
#define ECTM_INNER_REL_DECREASE 0.05

typedef struct pair {
    side s[2];
    ectm_params p;
    int bijective;
} pair;

static double dir_energy(const ectm_params *p, const ectm_terms *t)
{
    return p->alpha * t->w_mem + p->eta * t->w_bnd + t->mismatch + t->reverse;
}

/* Y-step of side a (other side b), filling the direction's terms. */
static int solve_y(pair *pr, int ai, double beta, ectm_terms *terms, double *scratch)
{
    side *a = &pr->s[ai];
    const side *b = &pr->s[1 - ai];
    ystep st = {0};
    st.a = a;
    st.b = b;
    st.beta = beta;
    st.gamma = pr->p.gamma;
    st.bijective = pr->bijective;
    st.admissible = ener_backend_update_admissible(a->def, a->Y);
    opt_params op;
    opt_params_init(&op);
    op.max_iter = pr->p.inner_iterations;
    op.gtol = pr->p.tolerance;
    op.rel_decrease = ECTM_INNER_REL_DECREASE;
    opt_stats os;
    int n3 = a->X->nv * 3;
    if (beta != a->mem_beta)
        opt_memory_add_diagonal(a->mem, a->mass3, 2 * (beta - a->mem_beta));
    a->mem_beta = beta;
    int rc = opt_minimize(n3, a->Y, ystep_eval, ystep_iter, &st, &op, a->mem, &os);
    if (rc == OPT_ENOMEM)
        return KIND_ENOMEM;
    if (rc == OPT_ENONFINITE)
        return KIND_ENUMERIC;
    /* Terms at the returned Y: the last evaluation's, unless that was a
     * rejected trial point (an admissible set that changed without changing
     * its count is not evaluated again, here as within the solve), which saves
     * an evaluation per Y-step. */
    double f = os.last_at_x ? os.f : ystep_eval(&st, a->Y, scratch, n3);
    if (!isfinite(f))
        return KIND_ENUMERIC;
    terms->w_mem = st.w_mem;
    terms->w_bnd = st.w_bnd;
    terms->mismatch = st.mismatch;
    terms->reverse = st.reverse;
    terms->inner_iterations = os.iterations;
    terms->evaluations = os.evaluations;
    terms->admissible_edges = st.admissible;
    terms->energy = f;
    return KIND_OK;
}

/* Builds Q by nearest neighbour: each vertex of b goes to the closest point of
 * a's image P_a·X_b (a's connectivity, positions a->PX). */
static int reverse_by_nearest(side *a, side *b, char *err, size_t errsz)
{
    mesh img = { a->X->nv, a->X->nf, a->PX, a->X->f, 0 };
    proj_tree *t = proj_tree_new(&img, err, errsz);
    if (!t)
        return KIND_ENOMEM;
    for (int j = 0; j < b->X->nv; j++)
        b->P->face[j] = -1;
    int rc = proj_closest(t, 3, img.v, 1.0, b->X->nv, b->X->v, b->P->face, b->P->w, NULL);
    proj_tree_free(t);
    return rc ? KIND_EPARAMS : KIND_OK;
}

static int check_map(const bmap *P, const mesh *from, const mesh *to, const char *name,
                     char *err, size_t errsz)
{
    if (P->n != from->nv || P->nt != to->nv)
        return errbuf_set(err, errsz, KIND_EMAP,
                          "%s is sized %d -> %d vertices, the meshes have %d -> %d",
                          name, P->n, P->nt, from->nv, to->nv);
    for (int i = 0; i < P->n; i++)
        if (P->face[i] < 0 || P->face[i] >= to->nf)
            return errbuf_set(err, errsz, KIND_EMAP, "%s row %d: face %d out of range [0, %d)",
                              name, i, P->face[i], to->nf);
    return KIND_OK;
}

static void total_energy(const pair *pr, ectm_report *r)
{
    r->dir[0].energy = dir_energy(&pr->p, &r->dir[0]);
    r->dir[1].energy = pr->bijective ? dir_energy(&pr->p, &r->dir[1]) : 0;
    r->energy = r->dir[0].energy + r->dir[1].energy;
}

/* Puts a deformation back into the input frame of the mesh it approximates. */
static double *unscaled(const double *Y, int nv, const geo_scaling *f)
{
    double *out = malloc(sizeof(double) * ((size_t)nv * 3 + 1));
    if (!out)
        return NULL;
    memcpy(out, Y, sizeof(double) * (size_t)nv * 3);
    geo_denormalize(f, out, nv);
    return out;
}

/* The sides' maps from the start P0 (and Q0, or the reverse by nearest
 * point when bijective), their pins and Y ← P X̃ (Ỹ ← Q X). KIND_OK,
 * KIND_ENOMEM or reverse_by_nearest's code. */
static int pair_start(pair *pr, const bmap *P0, const bmap *Q0, const ectm_landmarks *L,
                      char *err, size_t errsz)
{
    side *a = &pr->s[0], *b = &pr->s[1];
    int rc;
    a->Zt = malloc(sizeof(double) * ((size_t)a->X->nv * 6 + 1));
    b->Zt = malloc(sizeof(double) * ((size_t)b->X->nv * 6 + 1));
    a->P = bmap_new(a->X->nv, b->X->nv);
    b->P = bmap_new(b->X->nv, a->X->nv);
    if (!a->Zt || !b->Zt || !a->P || !b->P)
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
    if (L && L->n > 0 &&
        (side_pins(a, b, L->src, L->tgt, L->n) ||
         (pr->bijective && side_pins(b, a, L->tgt, L->src, L->n))))
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
    memcpy(a->P->face, P0->face, sizeof(int) * (size_t)a->X->nv);
    memcpy(a->P->w, P0->w, sizeof(double) * 3 * (size_t)a->X->nv);
    bmap_apply(a->P, b->X->f, b->X->v, 3, a->PX);
    memcpy(a->Y, a->PX, sizeof(double) * 3 * (size_t)a->X->nv);   /* Y ← P X̃ */
    if (!pr->bijective)
        return KIND_OK;
    if (Q0) {
        memcpy(b->P->face, Q0->face, sizeof(int) * (size_t)b->X->nv);
        memcpy(b->P->w, Q0->w, sizeof(double) * 3 * (size_t)b->X->nv);
    } else if ((rc = reverse_by_nearest(a, b, err, errsz))) {
        return rc;
    }
    bmap_apply(b->P, a->X->f, a->X->v, 3, b->PX);
    memcpy(b->Y, b->PX, sizeof(double) * 3 * (size_t)b->X->nv);   /* Ỹ ← Q X */
    if (side_transpose(a, b) || side_transpose(b, a))
        return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
    return KIND_OK;
}

/* Outer iteration k at β = beta (scaled): per direction the P-step then
 * the Y-step, then the energies into r. KIND_OK or the failing step's
 * code, named in err. */
static int outer_iteration(pair *pr, int k, double beta, ectm_report *r, double *scratch,
                           char *err, size_t errsz)
{
    const ectm_params *p = &pr->p;
    side *a = &pr->s[0], *b = &pr->s[1];
    for (int dir = 0; dir < (pr->bijective ? 2 : 1); dir++) {
        side *u = &pr->s[dir], *v = &pr->s[1 - dir];
        /* P ← projection (Q for dir 1), then Y ← L-BFGS (Ỹ for dir 1) */
        double tp = now();
        pstep(u, v, beta, p->gamma, pr->bijective);
        if (pr->bijective && side_transpose(v, u))
            return errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
        double ts = now();
        r->t_project += ts - tp;
        int rc = solve_y(pr, dir, beta, &r->dir[dir], scratch);
        r->t_solve += now() - ts;
        const char *be = ener_backend_error(u->def);
        if (rc && be)
            rc = KIND_EPARAMS;
        if (rc)
            return errbuf_set(err, errsz, rc, "%s in the %s Y-step at outer iteration %d%s%s",
                              be                      ? "energy backend failed"
                              : rc == KIND_ENUMERIC ? "non-finite energy"
                                                    : proto_kind_text(-rc),
                              dir ? "target" : "source", k, be ? ": " : "", be ? be : "");
    }
    if (pr->bijective) {
        /* The source's γ term changed with the new Q: report it current. */
        ystep st0 = { .a = a, .b = b, .beta = beta, .gamma = p->gamma, .bijective = 1 };
        ystep_eval(&st0, a->Y, scratch, a->X->nv * 3);
        r->dir[0].mismatch = st0.mismatch;
        r->dir[0].reverse = st0.reverse;
    }
    total_energy(pr, r);
    return KIND_OK;
}

/* Both sides, each with the membrane's reference scaled by its initial
 * map when p->scale_reference asks for it (the target's only with Q0). */
static int sides_open(pair *pr, const mesh *S, const mesh *T, const bmap *P0, const bmap *Q0,
                      const ener_def_params *dp, const ectm_params *p, char *err, size_t errsz)
{
    int scaled = p->scale_reference && !p->partial;
    ener_def_params ds = *dp, dt = *dp;
    double *sS = scaled ? ectm_area_scale(S, T, P0) : NULL;
    double *sT = scaled && Q0 && pr->bijective ? ectm_area_scale(T, S, Q0) : NULL;
    int rc = KIND_OK;
    if ((scaled && !sS) || (scaled && Q0 && pr->bijective && !sT))
        rc = errbuf_set(err, errsz, KIND_ENOMEM, "out of memory for the reference's scale");
    ds.face_scale = sS;
    dt.face_scale = sT;
    if (!rc)
        rc = side_open(&pr->s[0], S, p->partial, &ds, p, "source", err, errsz);
    if (!rc)
        rc = side_open(&pr->s[1], T, p->partial, &dt, p, "target", err, errsz);
    free(sS);
    free(sT);
    return rc;
}

int ectm_run(const mesh *S, const mesh *T, const bmap *P0, const bmap *Q0,
             const ectm_landmarks *L, const ectm_params *p, ectm_progress_fn progress,
             void *ctx, ectm_result *out, char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    int rc = ectm_params_check(p, err, errsz);
    if (rc)
        return rc;
    if ((rc = check_landmarks(L, S, T, err, errsz)))
        return rc;
    if ((rc = check_map(P0, S, T, "the initial map", err, errsz)))
        return rc;
    if (Q0 && (rc = check_map(Q0, T, S, "the initial reverse map", err, errsz)))
        return rc;
    if (p->threads > 0)
        omp_set_num_threads(p->threads);

    double t0 = now();
    pair pr;
    memset(&pr, 0, sizeof pr);
    pr.p = *p;
    pr.bijective = p->model == ECTM_BIJECTIVE;
    double *scratch = NULL;
    ener_def_params dp = { p->alpha, p->eta, p->log_eps, NULL };
    double beta_scale = 1.0;
    if (p->partial) {
        /* α/s on the source, β/(s·s̃): areas of the unscaled inputs. */
        double s = geo_total_area(S), st = geo_total_area(T);
        dp.alpha = p->alpha / s;
        pr.p.alpha = dp.alpha;
        beta_scale = 1.0 / (s * st);
    }
    if ((rc = sides_open(&pr, S, T, P0, Q0, &dp, p, err, errsz)))
        goto done;
    side *a = &pr.s[0], *b = &pr.s[1];
    int nmax = a->X->nv > b->X->nv ? a->X->nv : b->X->nv;
    if (!(scratch = malloc(sizeof(double) * ((size_t)nmax * 3 + 1)))) {
        rc = errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
        goto done;
    }
    if ((rc = pair_start(&pr, P0, Q0, L, err, errsz)))
        goto done;
    ectm_report r;
    memset(&r, 0, sizeof r);
    r.total = p->iterations;
    r.gamma = p->gamma;
    double window[ECTM_STOP_WINDOW];   /* the last energies, by k mod the window */
    for (int k = 1; k <= p->iterations; k++) {
        double beta = ectm_beta(p, k) * beta_scale;
        r.outer = k;
        r.beta = ectm_beta(p, k);
        if ((rc = outer_iteration(&pr, k, beta, &r, scratch, err, errsz)))
            goto done;
        r.elapsed = now() - t0;
        out->last = r;
        if (!isfinite(r.energy)) {
            rc = errbuf_set(err, errsz, KIND_ENUMERIC, "energy is not finite at outer iteration %d", k);
            goto done;
        }
        if (progress && progress(ctx, &r)) {
            rc = errbuf_set(err, errsz, KIND_ECANCELLED, "cancelled at outer iteration %d", k);
            goto done;
        }
        /* The energy W iterations ago sits in the slot this one takes. */
        double *then = &window[k % ECTM_STOP_WINDOW];
        if (ectm_stop_may_end(p, k) && *then - r.energy < p->stop_change * fabs(r.energy))
            break;
        *then = r.energy;
    }
    rc = KIND_OK;
    out->scaled = p->scale_reference && !p->partial;
    out->Y = unscaled(a->Y, a->X->nv, &b->frame);
    if (pr.bijective)
        out->Yt = unscaled(b->Y, b->X->nv, &a->frame);
    out->P = a->P;
    a->P = NULL;
    if (pr.bijective) {
        out->Q = b->P;
        b->P = NULL;
    }
    if (!out->Y || (pr.bijective && !out->Yt)) {
        ectm_result_close(out);
        rc = errbuf_set(err, errsz, KIND_ENOMEM, "out of memory");
    }
done:
    side_close(&pr.s[0]);
    side_close(&pr.s[1]);
    free(scratch);
    return rc;
}
