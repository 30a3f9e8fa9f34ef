/*
 * chi2.h - the chi-square goodness-of-fit p-value for the sampling tests
 * (tests/render): the upper tail of the chi-square distribution through the
 * regularised incomplete gamma function.
 */
#ifndef PK_TEST_CHI2_H
#define PK_TEST_CHI2_H

#include <math.h>


/* ---- the chi-square distribution: regularised incomplete gamma ---------- */

/* Q(a, x) = Gamma(a, x) / Gamma(a), the upper tail (Numerical Recipes 6.2:
 * the series for x < a + 1, Lentz's continued fraction otherwise). */
static inline double gamma_q(double a, double x)
{
    if (x <= 0.0) return 1.0;
    double lg = lgamma(a);
    if (x < a + 1.0) {
        double ap = a, sum = 1.0 / a, del = sum;
        for (int n = 0; n < 10000; n++) {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if (fabs(del) < fabs(sum) * 1e-15) break;
        }
        return 1.0 - sum * exp(-x + a * log(x) - lg);
    }
    double b = x + 1.0 - a, c = 1.0 / 1e-300, d = 1.0 / b, h = d;
    for (int i = 1; i < 10000; i++) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (fabs(d) < 1e-300) d = 1e-300;
        c = b + an / c;
        if (fabs(c) < 1e-300) c = 1e-300;
        d = 1.0 / d;
        double del = d * c;
        h *= del;
        if (fabs(del - 1.0) < 1e-15) break;
    }
    return exp(-x + a * log(x) - lg) * h;
}
/* P(X >= chi2) for X ~ chi-square with dof degrees of freedom. */
static inline double chi2_pvalue(double chi2, int dof) { return gamma_q(0.5 * dof, 0.5 * chi2); }


#endif
