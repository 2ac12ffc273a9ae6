#pragma once
// The thermal drift kT div_q M of overdamped Brownian dynamics of rigid bodies (Delong, Balboa
// Usabiaga & Donev, J. Chem. Phys. 143, 144107 (2015)): the velocity a step adds to U when M
// depends on the configuration, in the body-velocity coordinates of U (a centre moves by dt u,
// an orientation rotates by dt omega through the exponential map, core/rigid_motion.hpp).
//
// A model that knows div_q M (ExactDivergenceMobility) gives kT divergence(): no application,
// no random number drawn. Any other model gets one sample of the random finite difference
// (RFD) of Delong et al., centred:
//   D = (kT / delta) [M(q+) - M(q-)] S^-1 W~,   W~ ~ N(0, I) of size model.size(),
//   q+- = q displaced by the rigid motion +-(delta / 2) S W~ (advance(): centre by
//         +-(delta / 2) length W~_u, orientation rotated by +-(delta / 2) W~_omega, unit q),
//   S = diag(length I_3, I_3) per body (length I_3 alone for 3 dofs: orientations stay),
// whose mean is kT div_q M + O(delta^2) and whose variance stays O(1) as delta -> 0 (a
// one-sided difference would grow as 1/delta). Cost: two applications and three
// set_configuration calls (q+, q-, and back to q). Rounding and the error of an iterative
// model's apply are amplified by 1/delta: keep delta well above the model's own tolerance
// (the default 1e-4 against a multiblob GMRES tolerance of 1e-8 adds ~1e-4 relative).
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/gaussian_stream.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/core/rigid_motion.hpp"
#include "stokescontact/mobility/mobility_operator.hpp"

namespace stokescontact {

struct RfdOptions {
  double delta = 1e-4;  // dimensionless size of the displacement (radians for rotations)
  double length = 1.0;  // translations move by delta / 2 * length * W~_u: a body size

  void validate() const {
    require_positive(delta, "RfdOptions.delta");
    require_positive(length, "RfdOptions.length");
  }
};

namespace detail {

// Checks shared by both drift functions; returns the number of bodies.
template <MobilityOperator M>
std::size_t validate_drift_input(const M& model, std::span<const Pose> poses, double kT, const RfdOptions& options) {
  require_non_negative(kT, "kT");
  options.validate();
  const auto dofs = static_cast<Eigen::Index>(model.dofs_per_body());
  if ((dofs != 3 && dofs != 6) || model.size() % dofs != 0)
    fail_argument("model", "has size " + std::to_string(model.size()) + " with " + std::to_string(dofs) +
                               " dofs per body: not a whole number of bodies of 3 or 6 dofs");
  const auto bodies = static_cast<std::size_t>(model.size() / dofs);
  validate(poses, bodies, "poses");
  return bodies;
}

}  // namespace detail

// One RFD sample of kT div_q M at `poses` (Delong et al. 2015, centred), whatever the model
// offers. The model must be configured at `poses`; it is configured there again on return, and
// also when a displaced configuration or an application throws (the exception then
// propagates). kT = 0 returns zeros, draws nothing and applies nothing. Throws
// std::invalid_argument naming "kT", "RfdOptions.delta", "RfdOptions.length" or "poses".
template <MobilityOperator M>
VecX random_finite_difference_drift(M& model, std::span<const Pose> poses, double kT, GaussianStream& rng,
                                    const RfdOptions& options = {}) {
  const std::size_t bodies = detail::validate_drift_input(model, poses, kT, options);
  const Eigen::Index n = model.size();
  if (kT == 0.0) return VecX::Zero(n);
  const auto d = static_cast<Eigen::Index>(model.dofs_per_body());
  const VecX W = rng.vector(n);
  VecX v = W;  // S^-1 W~
  std::vector<Pose> plus(bodies), minus(bodies);
  for (std::size_t i = 0; i < bodies; ++i) {
    const Eigen::Index at = d * static_cast<Eigen::Index>(i);
    const Vec3 u = options.length * W.segment<3>(at);
    const Vec3 omega = d == 6 ? Vec3(W.segment<3>(at + 3)) : Vec3::Zero();
    v.segment<3>(at) /= options.length;
    plus[i] = advance(poses[i], u, omega, 0.5 * options.delta);
    minus[i] = advance(poses[i], u, omega, -0.5 * options.delta);
  }
  VecX difference;
  try {
    model.set_configuration(std::span<const Pose>(plus));
    difference = model.apply(v);
    model.set_configuration(std::span<const Pose>(minus));
    difference -= model.apply(v);
  } catch (...) {
    model.set_configuration(poses);
    throw;
  }
  model.set_configuration(poses);
  return (kT / options.delta) * difference;
}

// kT div_q M at `poses` (Delong et al. 2015): kT divergence() when the model knows it exactly
// (nothing drawn, no application; the model must be configured at `poses`), else one RFD
// sample as random_finite_difference_drift. Throws as random_finite_difference_drift.
template <MobilityOperator M>
VecX thermal_drift(M& model, std::span<const Pose> poses, double kT, GaussianStream& rng,
                   const RfdOptions& options = {}) {
  if constexpr (ExactDivergenceMobility<M>) {
    detail::validate_drift_input(model, poses, kT, options);
    if (kT == 0.0) return VecX::Zero(model.size());
    return kT * VecX(model.divergence());
  } else {
    return random_finite_difference_drift(model, poses, kT, rng, options);
  }
}

}  // namespace stokescontact
