/* bench_rhm.c — Reversible Harmonic Maps, 200 iterations (the release's
 * cap; no early stop) on the FAUST remeshed pair tr_reg_000 -> tr_reg_001
 * (about 5K vertices each) from 12 landmarks: wall time against the RHM
 * paper's ~115 s for 200 iterations on 5K-vertex shapes with a GPU, and where
 * the time goes (setup, P-steps, X-steps). Prints figures, never fails on
 * time. */
#include "support/harness.h"
#include "support/testgt.h"
#include "start/start.h"

TEST_T(rhm_200_iterations_on_faust_5k, 1200)
{
    testgt g;
    testgt_faust(&g, 12);
    rhm_params p;
    rhm_params_init(&p);
    p.stop_change = 0;
    rhm_result r;
    char err[512];
    if (start_run(g.S, g.T, &g.L, &p, NULL, NULL, &r, err, sizeof err))
        FAILF("%s", err);
    const rhm_report *q = &r.last;
    printf("rhm FAUST 000 -> 001 (%d -> %d vertices), %d iterations: %.1f s "
           "(%.2fx faster than the paper's ~115 s on a GPU); setup %.1f s, "
           "P-steps %.1f s, X-steps %.1f s\n", g.S->nv, g.T->nv, q->iteration, q->elapsed,
           115.0 / q->elapsed, q->t_setup, q->t_project, q->t_solve);
    rhm_result_close(&r);
    testgt_close(&g);
}
