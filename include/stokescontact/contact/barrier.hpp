#pragma once
// Barrier functions of Broms & Tornberg (2023): b (eq. 10, C2 at d_hat), b0 and b1
// (eq. 24, C0 and C1 at d_hat), with the two regularisations of Remark 4 / Fig. 3:
//  - eps_reg shifts the argument and the threshold, d -> d + eps_reg, d_hat -> d_hat + eps_reg;
//  - eps_cap replaces the function below the (shifted) argument x = eps_cap by its tangent
//    line there, so every barrier is C1 and finite for all d, overlaps (d <= 0) included.
// With x = d + eps_reg, h = d_hat + eps_reg:
//   b(d)  = -(x - h)^2 ln(x / h),   b0(d) = -ln(x / h),   b1(d) = (x - h) ln(x / h)
// for eps_cap <= x < h; 0 for d >= d_hat; the tangent line at x = eps_cap for x < eps_cap.
#include <cmath>
#include <span>
#include <string>

#include "stokescontact/core/errors.hpp"

namespace stokescontact {

struct BarrierParameters {
  double d_hat = 0.0;    // threshold: every barrier is 0 for d >= d_hat
  double eps_reg = 0.0;  // shift of argument and threshold (Remark 4), >= 0
  double eps_cap = 0.0;  // tangent-line extension below x = d + eps_reg = eps_cap, 0 < eps_cap < d_hat + eps_reg

  void validate() const {
    require_positive(d_hat, "BarrierParameters.d_hat");
    require_non_negative(eps_reg, "BarrierParameters.eps_reg");
    require_positive(eps_cap, "BarrierParameters.eps_cap");
    if (!(eps_cap < d_hat + eps_reg))
      fail_argument("BarrierParameters.eps_cap", "must be < d_hat + eps_reg = " + std::to_string(d_hat + eps_reg) +
                                                     ", got " + std::to_string(eps_cap));
  }
};

// The paper's suggestion (Remark 4): the cap at a small fraction of the shifted threshold.
inline BarrierParameters barrier_parameters(double d_hat, double eps_reg = 0.0, double cap_fraction = 1e-2) {
  require_positive(d_hat, "d_hat");
  require_non_negative(eps_reg, "eps_reg");
  if (!(cap_fraction > 0.0 && cap_fraction < 1.0))
    fail_argument("cap_fraction", "must lie in (0, 1), got " + std::to_string(cap_fraction));
  return {d_hat, eps_reg, cap_fraction * (d_hat + eps_reg)};
}

enum class BarrierFunction {
  b,   // eq. 10, C2 at d_hat: the barrier of the optimisation problem (15)
  b0,  // eq. 24, C0 at d_hat: -b0' = 1/x weights the contact force directions (23)
  b1,  // eq. 24, C1 at d_hat
};

// A barrier and its first and second derivatives with respect to d.
struct BarrierValue {
  double value = 0.0;
  double first = 0.0;
  double second = 0.0;
};

namespace detail {

// The unregularised barriers at 0 < x < h; ln(x/h) as log1p((x - h)/h) keeps the relative
// accuracy where x is close to h.
inline BarrierValue raw_barrier(BarrierFunction f, double x, double h) {
  const double g = x - h;
  const double lg = std::log1p(g / h);
  switch (f) {
    case BarrierFunction::b:
      return {-g * g * lg, -2.0 * g * lg - g * g / x, -2.0 * lg - 4.0 * g / x + g * g / (x * x)};
    case BarrierFunction::b0:
      return {-lg, -1.0 / x, 1.0 / (x * x)};
    case BarrierFunction::b1:
      return {g * lg, lg + g / x, 1.0 / x + h / (x * x)};
  }
  return {};
}

}  // namespace detail

// b, b0 or b1 at distance d (any finite d), regularised by p.
inline BarrierValue barrier(BarrierFunction f, double d, const BarrierParameters& p) {
  p.validate();
  require_finite(d, "d");
  if (d >= p.d_hat) return {};
  const double h = p.d_hat + p.eps_reg;
  const double x = d + p.eps_reg;
  if (x >= p.eps_cap) return detail::raw_barrier(f, x, h);
  const BarrierValue c = detail::raw_barrier(f, p.eps_cap, h);  // tangent line at the cap
  return {c.value + c.first * (x - p.eps_cap), c.first, 0.0};
}

inline BarrierValue barrier_b(double d, const BarrierParameters& p) { return barrier(BarrierFunction::b, d, p); }
inline BarrierValue barrier_b0(double d, const BarrierParameters& p) { return barrier(BarrierFunction::b0, d, p); }
inline BarrierValue barrier_b1(double d, const BarrierParameters& p) { return barrier(BarrierFunction::b1, d, p); }

// Barrier energy sum_i b(d_i) (eq. 11, 22): zero exactly when every d_i >= d_hat.
inline double barrier_energy(std::span<const double> distances, const BarrierParameters& p,
                             BarrierFunction f = BarrierFunction::b) {
  double energy = 0.0;
  for (const double d : distances) energy += barrier(f, d, p).value;
  return energy;
}

}  // namespace stokescontact
