/* testfit.c — cost-against-size exponents; see testfit.h. */
#include "support/testfit.h"

#include <math.h>

double testfit_exponent(const double *x, const double *y, int n)
{
    if (n < 2)
        return NAN;
    double xm = 0, ym = 0, sxy = 0, sxx = 0;
    for (int k = 0; k < n; k++) {
        xm += log(x[k]) / n;
        ym += log(fmax(y[k], 1e-3)) / n;
    }
    for (int k = 0; k < n; k++) {
        double dx = log(x[k]) - xm;
        sxy += dx * (log(fmax(y[k], 1e-3)) - ym);
        sxx += dx * dx;
    }
    return sxx > 0 ? sxy / sxx : NAN;
}
