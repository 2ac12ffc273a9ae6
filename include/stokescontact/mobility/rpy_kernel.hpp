#pragma once
// Translation-translation Rotne-Prager-Yamakawa tensor between two equal spheres (blobs)
// of radius a in a fluid of viscosity eta, with the overlapping branch of Rotne & Prager
// (1969), as written by Wajnryb et al. (J. Fluid Mech. 731, R3, 2013):
//   r >  2a: M = 1/(8 pi eta r) [ (1 + 2a^2/(3r^2)) I + (1 - 2a^2/r^2) rr/r^2 ]
//   r <= 2a: M = 1/(6 pi eta a) [ (1 - 9r/(32a)) I + (3r/(32a)) rr/r^2 ]
// Both branches and their first derivatives agree at r = 2a; r = 0 gives the self
// mobility I/(6 pi eta a). The tensor is positive definite for every configuration.
#include <cmath>
#include <numbers>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

// M(r) = mu0 [ f(r) I + g(r) r_hat r_hat^T ] with mu0 = 1/(6 pi eta a).
struct RpyCoefficients {
  double f = 1.0;
  double g = 0.0;
};

inline RpyCoefficients rpy_translation_coefficients(double r, double a) {
  if (r > 2.0 * a) {
    const double s = a / r;  // < 1/2
    return {0.75 * s * (1.0 + 2.0 / 3.0 * s * s), 0.75 * s * (1.0 - 2.0 * s * s)};
  }
  const double t = r / a;  // in [0, 2]
  return {1.0 - 9.0 / 32.0 * t, 3.0 / 32.0 * t};
}

inline double stokes_mobility(double a, double eta) { return 1.0 / (6.0 * std::numbers::pi * eta * a); }

// The 3x3 block coupling blob j (force) to blob i (velocity), r = x_i - x_j.
inline Mat3 rpy_translation(const Vec3& r, double a, double eta) {
  const double d = r.norm();
  const RpyCoefficients c = rpy_translation_coefficients(d, a);
  Mat3 m = c.f * Mat3::Identity();
  if (d > 0.0) m += (c.g / (d * d)) * r * r.transpose();
  return stokes_mobility(a, eta) * m;
}

// The validated parameters of an RPY interaction: one place per model.
struct RpyParameters {
  double viscosity = 1.0;
  double radius = 1.0;  // blob (or sphere) radius a

  void validate(std::string_view owner) const {
    require_positive(viscosity, std::string(owner) + ".viscosity");
    require_positive(radius, std::string(owner) + ".radius");
  }
};

}  // namespace stokescontact
