/* corr_cost.c — what a job costs its worker in memory at its peak, from
 * the sizes its SUBMIT check knows (corr.h, corr_cost_bytes): the decoded
 * meshes, the landmarks, the chain of stages and the parameters. The
 * daemon's check refuses a job whose estimate is over the worker's memory
 * limit, so a job that can never run is not queued.
 *
 * The estimate is the process itself plus the largest of the stages, each
 * the sum of what it holds at once. The per-vertex constants are bounds of
 * what runs of each stage took (tests/security/test_sec_cost.c runs real
 * workers and holds the estimate above their peak and within a small
 * factor of it); the terms that grow with the landmarks are the engine's
 * own arrays, counted from the code that allocates them:
 *   - the distances start (start_distances.c): both sides'
 *     descriptions, nv by 2·nl doubles each, then either the principal
 *     axes of R^(2nl) (four dd by dd matrices: covariance, eigenvectors and
 *     LAPACK's copies) or one projection's boxes in R^(2nl) (proj_closest:
 *     2·dd doubles per face and per node, nodes at most a quarter of the
 *     faces);
 *   - the functional-map start (start_fmap, fmap_landmark_descriptors):
 *     the wave-kernel descriptors of both sides, nv by ne·(1 + nl) doubles,
 *     and the work arrays of the landmarks' wave-kernel maps, nv by ne·nl,
 *     at once; then the orientation operators, k by k by 5·(1 + nl) per
 *     side; with ZoomOut its bases of kz functions;
 *   - the Voronoi start: the distances of every vertex to every landmark.
 * A coarse-to-fine job runs RHM on the decimated pair (corr_coarse_wanted:
 * a mesh over twice `coarse` vertices is decimated to `coarse`, but never
 * below its landmarks, which the decimation keeps) and ECTM on the meshes
 * as given.
 *
 * It estimates resident memory; the worker's limit is on address space,
 * which holds the libraries' mappings besides, so the estimate over the
 * limit refuses only jobs that cannot fit (one under it may still end
 * OUT_OF_MEMORY under a limit set close to the libraries' own size). Only
 * sizes and the parameters are read: no solver runs, so the SUBMIT check
 * links none of their libraries. */
#include "corr/corr.h"
#include "fmap/fmap.h"
#include "start/start.h"

#include <stdio.h>
#include <string.h>

#define COST_MB 1048576.0
/* the process before any job: libraries, OpenMP's and Embree's threads,
 * the job frame and the decoded meshes of a small job */
#define COST_BASE (32 * COST_MB)
/* per vertex of both meshes, ECTM: positions, deformations, gradients and
 * L-BFGS's history, the per-face buffers, Embree's tree, the fold repair
 * and the result's maps and Draco bytes */
#define COST_ECTM_VERTEX 2560.0
/* per vertex RHM runs on: the geodesic solver's factorisations, the 8-D
 * embedding from its distance fields, the X-step's factorisation, the
 * projection trees and both maps */
#define COST_RHM_VERTEX 4096.0
/* per vertex of both meshes, the DDM stage's Laplacian and its shift-invert
 * factorisation (the bases and ARPACK's work are counted apart) */
#define COST_DDM_VERTEX 1024.0
/* the elastic energy on an OpenCL device (backend opencl or auto): the
 * OpenCL runtime and its kernel compiler in the process */
#define COST_OPENCL (256 * COST_MB)

/* The vertices RHM runs on for a mesh of nv vertices and a job with nl
 * landmarks: the decimated copy's on the coarse path, else nv. */
static double rhm_vertices(double nv, double nl, int coarse, int on_coarse_path)
{
    if (!on_coarse_path || nv <= 2.0 * coarse)
        return nv;
    double c = nl > coarse ? nl : coarse;
    return c < nv ? c : nv;
}

static double max2(double a, double b)
{
    return a > b ? a : b;
}

/* A stage's memory: the sum of its parts, and the largest part's name. */
typedef struct stage_cost {
    double bytes, top;
    char what[256];
} stage_cost;

static void add(stage_cost *s, double bytes, const char *what)
{
    s->bytes += bytes;
    if (bytes > s->top) {
        s->top = bytes;
        snprintf(s->what, sizeof s->what, "%s", what);
    }
}

double corr_cost_bytes(const corr_input *in, const ectm_params *p, char *what, size_t wsz)
{
    rhm_params rdef;
    rhm_params_init(&rdef);
    const rhm_params *r = in->rhm ? in->rhm : &rdef;
    double nS = in->S->nv, nT = in->T->nv, fS = in->S->nf, fT = in->T->nf, N = nS + nT;
    double nl = in->L ? in->L->n : 0;
    unsigned run = corr_chain_run(in->stages, in->P0 != NULL);
    char buf[256];
    stage_cost ectm = {0}, rhm = {0}, ddm = {0};
    if (run & CORR_RUN_ECTM) {
        snprintf(buf, sizeof buf, "ECTM on meshes of %.0f and %.0f vertices", nS, nT);
        add(&ectm, COST_ECTM_VERTEX * N, buf);
        if (p && (strcmp(p->backend, "opencl") == 0 || strcmp(p->backend, "auto") == 0))
            add(&ectm, COST_OPENCL, "the OpenCL runtime of ECTM's energy");
    }
    if (run & CORR_RUN_RHM) {
        /* corr_coarse_wanted's rule, restated: this file stays free of the
         * solvers' code, so the SUBMIT check links none of their libraries */
        int coarse_path = r->coarse > 0 && !in->P0 && in->L && (nS > 2.0 * r->coarse || nT > 2.0 * r->coarse);
        double ns = rhm_vertices(nS, nl, r->coarse, coarse_path), nt = rhm_vertices(nT, nl, r->coarse, coarse_path);
        /* faces scale with the vertices when a mesh is decimated */
        double n2 = ns + nt, nmax = max2(ns, nt), fmax = max2(ns * fS / nS, nt * fT / nT);
        snprintf(buf, sizeof buf, "RHM on meshes of %.0f and %.0f vertices", ns, nt);
        add(&rhm, COST_RHM_VERTEX * n2, buf);
        if (!in->P0 && nl > 0) {
            /* distances: both descriptions (dd doubles a vertex), with the
             * larger of one side's distance fields, the principal axes'
             * four dd x dd matrices and one projection's boxes */
            double dd = 2 * nl;
            double dist = 8 * dd * n2 + max2(max2(8 * nl * nmax, 4 * 8 * dd * dd), 8 * 2 * dd * 1.25 * fmax);
            /* fmap: descriptors and the wave-kernel maps' work arrays of
             * both sides, the orientation operators, ZoomOut's bases */
            double k = START_FMAP_K, kz = r->zoomout;
            double fmap = 8 * FMAP_ENERGIES_DEFAULT * (2 * nl + 1) * n2 +
                          2 * 8 * k * k * FMAP_ORIENT_ENERGIES * (nl + 1) + 8 * 2 * kz * n2;
            double vor = 8 * nl * ns;   /* Voronoi: every source vertex's distance to every landmark */
            int start = r->start;
            const char *name = "the distances start's descriptions and projections";
            double lmk = dist;
            if (start == RHM_START_VORONOI) {
                lmk = vor;
                name = "the Voronoi start's distances";
            } else if (start == RHM_START_FMAP || (start == RHM_START_AUTO && fmap > dist)) {
                lmk = fmap;
                name = "the functional-map start's landmark descriptors";
            }
            char from[64] = "";
            if (ns < nS || nt < nT)
                snprintf(from, sizeof from, " (decimated from %.0f and %.0f)", nS, nT);
            snprintf(buf, sizeof buf, "%s: %.0f landmarks on meshes of %.0f and %.0f vertices%s", name, nl, ns,
                     nt, from);
            add(&rhm, lmk, buf);
        }
    }
    if (run & CORR_RUN_DDM) {
        double nmin = nS < nT ? nS : nT, k = in->ddm_k ? in->ddm_k : CORR_DDM_K < nmin - 2 ? CORR_DDM_K : nmin - 2;
        double nmax = max2(nS, nT), fmax = max2(fS, fT);
        /* both bases, ARPACK's Lanczos vectors on the larger mesh, the
         * deblurring projection's boxes in R^k */
        snprintf(buf, sizeof buf, "DDM's bases of %.0f functions on meshes of %.0f and %.0f vertices", k, nS, nT);
        add(&ddm, 8 * k * N + 8 * (2 * k + 1) * nmax + 20 * k * fmax, buf);
        add(&ddm, COST_DDM_VERTEX * N, buf);
    }
    const stage_cost *top = &ectm;
    if (rhm.bytes > top->bytes)
        top = &rhm;
    if (ddm.bytes > top->bytes)
        top = &ddm;
    if (what)
        snprintf(what, wsz, "%s", top->bytes > 0 ? top->what : "the process itself");
    return COST_BASE + top->bytes;
}
