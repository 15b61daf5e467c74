/* testfit.h — the exponent of a cost-against-size fit, for the speed
 * benchmarks: the least-squares slope of log y against log x.
 * Test code only. */
#ifndef TESTFIT_H
#define TESTFIT_H

/* Slope of log y[k] against log x[k] over n points (y below 1e-3 counts as
 * 1e-3, so a stage too quick to time does not blow the fit); NAN when
 * n < 2 or all x are equal. */
double testfit_exponent(const double *x, const double *y, int n);

#endif
