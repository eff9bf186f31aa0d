#ifndef KINCAL_DATA_MINIMIZE_H_
#define KINCAL_DATA_MINIMIZE_H_

// Minimisation of a function of one variable without derivatives.

#include <cmath>

#include "data/error.h"

namespace kincal {

struct GoldenSectionResult {
  double x = 0.0;   // the better of the two last interior points
  double f = 0.0;   // f(x)
  double lo = 0.0;  // the final bracket [lo, hi]: it holds the minimum of a
  double hi = 0.0;  // function unimodal on [a, b]
};

// Golden-section search for the minimum of `f` on [a, b] (a < b), f
// unimodal there (Kiefer 1953; Numerical Recipes 10.2). Each iteration keeps
// the side of the bracket holding the smaller of its two interior values
// (the right side on a tie) and shrinks it by g = (sqrt 5 - 1) / 2 = 0.618,
// reusing one of them: `iterations` cost iterations + 2 evaluations of f and
// leave a bracket of (b - a) g^iterations (58 reach 1e-12 of it). The ends
// a, b themselves are never evaluated.
template <typename F>
GoldenSectionResult GoldenSectionMinimize(const F& f, double a, double b,
                                          int iterations) {
  KINCAL_CHECK(a < b && iterations >= 0, "golden section on ["
                                             << a << ", " << b << "], "
                                             << iterations << " iterations");
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < iterations; ++it) {
    if (f1 < f2) {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - g * (b - a);
      f1 = f(x1);
    } else {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + g * (b - a);
      f2 = f(x2);
    }
  }
  GoldenSectionResult r;
  r.x = f1 < f2 ? x1 : x2;
  r.f = f1 < f2 ? f1 : f2;
  r.lo = a;
  r.hi = b;
  return r;
}

}  // namespace kincal

#endif  // KINCAL_DATA_MINIMIZE_H_
