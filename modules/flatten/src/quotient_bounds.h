#pragma once
// Divisions the area energy can skip without changing a bit (conformal_area_energy.h).
//
// (1) SurelyInside: whether the rounded quotient fl(n / d) lies inside [lo (1 + m), hi (1 - m)] (m =
// `margin`, far above the rounding unit u ~ 1.1e-16; both bounds as LogRatioExcess rounds them, or
// anything wider), decided from two products instead of the division, when that is certain. With
// lo' = fl(lo fl(1 + 2m)) and hi' = fl(hi fl(1 - 2m)) normal, d > 0, and the products a = fl(lo' d),
// b = fl(hi' d) normal and finite: a >= lo (1 + 2m)(1 - u)^3 d > fl(lo fl(1 + m)) d, and likewise
// b < fl(hi fl(1 - m)) d. So n in [a, b] puts the exact n / d strictly inside the rounded bounds, and
// rounding (monotone; the bounds are doubles) keeps fl(n / d) inside them. Anything else (d <= 0,
// NaN, subnormal or overflowing products, lo <= 0, hi' < lo') answers false, which says nothing: the caller
// divides as before.
//
// (2) quotient_of_zero: n / d for d > 0 is n itself when n is +-0 (0 / d keeps n's sign, also for a
// subnormal or infinite d), so that division is skipped (issue 26, session 37 "stall": the area
// energy's two divisions a face held ~1/4 of its samples; most faces sit inside the bounds, where
// the penalty and its derivative are 0).
#include <limits>

namespace cf::flat_detail {

class SurelyInside {
 public:
  SurelyInside(double lo, double hi, double margin)
      : lo_(lo * (1 + 2 * margin)), hi_(hi * (1 - 2 * margin)),
        usable_(lo_ >= std::numeric_limits<double>::min() && hi_ >= lo_) {}
  // true only when fl(n / d) is certainly within the bounds (see above); false: unknown.
  bool operator()(double n, double d) const {
    if (!usable_ || !(d > 0)) return false;
    const double a = lo_ * d, b = hi_ * d;
    return a >= std::numeric_limits<double>::min() && b <= std::numeric_limits<double>::max() && n >= a && n <= b;
  }

 private:
  double lo_, hi_;
  bool usable_;  // lo' normal (so lo > 0) and hi' >= lo' (a non-empty range)
};

// n / d for d > 0 (not NaN), with the division skipped when n is +-0 (the same bits: see above).
inline double quotient_of_zero(double n, double d) { return n == 0 ? n : n / d; }

}  // namespace cf::flat_detail
