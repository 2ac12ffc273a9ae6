#pragma once
// The Brownian velocity of one step (Yan et al. eq. 29, U_known = U^B, Sec. IV):
//   U^B = sqrt(2 kT / dt) M^(1/2) W,   W ~ N(0, I) of size model.size(), fresh each step,
// so that the step's Brownian displacement dt U^B has covariance 2 kT M dt (fluctuation-
// dissipation) and the mean-square velocity grows as 1/dt. A velocity, not a displacement, so
// that it adds to the other velocities of a step (background flow, M F, the thermal drift)
// before the contact solver and the integrator (Q + dt Psi U) see them.
//
// M^(1/2) W is the model's apply_sqrt when it has one (SquareRootMobility: exact, one
// application), and otherwise Lanczos on the model's apply (core/lanczos.hpp: one application
// per step, counted by the model). A Lanczos run that does not converge throws
// std::runtime_error rather than return a wrong increment.
#include <cmath>
#include <stdexcept>
#include <string>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/gaussian_stream.hpp"
#include "stokescontact/core/lanczos.hpp"
#include "stokescontact/mobility/mobility_operator.hpp"

namespace stokescontact {

// B W with B B^T = M, and how it was obtained.
struct MobilitySqrtProduct {
  VecX value;
  bool exact = false;                    // the model's apply_sqrt (no Lanczos)
  int lanczos_iterations = 0;            // Lanczos steps = mobility applications (0 when exact)
  double lanczos_relative_change = 0.0;  // |y_k - y_{k-1}| / |y_k| at the end (0 when exact)
};

// M^(1/2) W at the model's current configuration: apply_sqrt, else Lanczos (Chow & Saad 2014).
// Throws std::invalid_argument for a W of the wrong size or with non-finite entries, and
// std::runtime_error when Lanczos misses the tolerance or finds M not positive definite.
template <MobilityOperator M>
MobilitySqrtProduct mobility_sqrt(M& model, const VecX& W, const LanczosOptions& options = {}) {
  options.validate();
  require_finite(W, model.size(), "W");
  MobilitySqrtProduct product;
  if constexpr (SquareRootMobility<M>) {
    product.value = model.apply_sqrt(W);
    product.exact = true;
    return product;
  } else {
    const LanczosResult lanczos = lanczos_sqrt([&model](const VecX& v) -> VecX { return model.apply(v); }, W, options);
    if (!lanczos.converged()) {
      const std::string why = lanczos.status == LanczosStatus::not_positive_definite
                                  ? "found the mobility not positive definite"
                                  : "did not converge";
      throw std::runtime_error("mobility_sqrt: Lanczos " + why + " after " + std::to_string(lanczos.iterations) +
                               " applications (relative change " + std::to_string(lanczos.relative_change) +
                               ", tolerance " + std::to_string(options.tolerance) + ")");
    }
    product.value = lanczos.value;
    product.lanczos_iterations = lanczos.iterations;
    product.lanczos_relative_change = lanczos.relative_change;
    return product;
  }
}

// U^B = sqrt(2 kT / dt) M^(1/2) W for a given W (Yan et al. eq. 29; covariance 2 kT M / dt).
// kT = 0 returns zeros without an application. Throws std::invalid_argument naming "kT"
// (< 0 or non-finite), "dt" (<= 0) or "W", and std::runtime_error as mobility_sqrt.
template <MobilityOperator M>
MobilitySqrtProduct brownian_velocity(M& model, double kT, double dt, const VecX& W,
                                      const LanczosOptions& options = {}) {
  require_non_negative(kT, "kT");
  require_positive(dt, "dt");
  options.validate();
  require_finite(W, model.size(), "W");
  if (kT == 0.0) {
    MobilitySqrtProduct zero;
    zero.value = VecX::Zero(model.size());
    zero.exact = SquareRootMobility<M>;
    return zero;
  }
  MobilitySqrtProduct product = mobility_sqrt(model, W, options);
  product.value *= std::sqrt(2.0 * kT / dt);
  return product;
}

// The same with W drawn from `rng`: model.size() consecutive variates, entry 0 first. kT = 0
// draws nothing.
template <MobilityOperator M>
MobilitySqrtProduct brownian_velocity(M& model, double kT, double dt, GaussianStream& rng,
                                      const LanczosOptions& options = {}) {
  require_non_negative(kT, "kT");
  require_positive(dt, "dt");
  options.validate();
  const VecX W = kT == 0.0 ? VecX::Zero(model.size()) : rng.vector(model.size());
  return brownian_velocity(model, kT, dt, W, options);
}

}  // namespace stokescontact
