#pragma once
// Rotne-Prager-Yamakawa mobility between N equal spheres of radius a (Broms & Tornberg
// Sec. 1.1, the particle-level model of their Fig. 4 runs; Yan et al. Sec. III.A): the pair
// blocks of rpy_kernel.hpp (translation) and rpy_rotation_kernel.hpp (rotation), with the
// overlapping branches of Wajnryb et al. (2013), so M stays SPD when spheres overlap.
//
// dofs_per_body 3: translation only (u from f), what a sphere scene pushed through the centres
// needs. dofs_per_body 6: (u, omega) from (f, tau), all four couplings.
//
// apply is the RPY direct sum of rpy_direct_sum.hpp (the library's one production RPY sum),
// in blob units: centres / a, torques / a in; velocities, angular velocities * a out, both
// in units of mu_t = 1 / (6 pi eta a). dense_matrix assembles the reference pair blocks.
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/mobility/mobility_operator.hpp"
#include "stokescontact/mobility/rpy_direct_sum.hpp"
#include "stokescontact/mobility/rpy_kernel.hpp"
#include "stokescontact/mobility/rpy_rotation_kernel.hpp"

namespace stokescontact {

class RpyMobility {
 public:
  // `spheres` spheres of radius parameters.radius; dofs_per_body 3 (translation) or 6.
  RpyMobility(std::size_t spheres, RpyParameters parameters, int dofs_per_body = 3)
      : n_(static_cast<Eigen::Index>(spheres)), parameters_(parameters), dofs_(dofs_per_body) {
    parameters_.validate("RpyParameters");
    if (dofs_ != 3 && dofs_ != 6) fail_argument("dofs_per_body", "must be 3 or 6, got " + std::to_string(dofs_));
    if (n_ == 0) fail_argument("spheres", "needs at least one sphere");
    x_.resize(3, n_);
  }

  // New centres (orientations are irrelevant to spheres but must be valid). Validates
  // everything before changing anything.
  void set_configuration(std::span<const Pose> poses) {
    validate(poses, static_cast<std::size_t>(n_));
    for (Eigen::Index i = 0; i < n_; ++i) x_.col(i) = poses[static_cast<std::size_t>(i)].x;
    configured_ = true;
  }

  // U = M F, one application; F stacked per sphere (f_i[, tau_i]).
  VecX apply(const VecX& F) {
    require_configured();
    require_finite(F, size(), "F");
    counter_.count();
    const double a = parameters_.radius;
    VecX F_blob = F;
    if (dofs_ == 6)
      for (Eigen::Index i = 0; i < n_; ++i) F_blob.segment<3>(6 * i + 3) /= a;
    VecX U = stokes_mobility(a, parameters_.viscosity) * rpy_direct_sum(x_ / a, F_blob, dofs_);
    if (dofs_ == 6)
      for (Eigen::Index i = 0; i < n_; ++i) U.segment<3>(6 * i + 3) /= a;
    return U;
  }

  // The dense matrix from the pair blocks, formed directly (0 applications).
  MatX dense_matrix() const {
    require_configured();
    MatX m(size(), size());
    const double a = parameters_.radius, eta = parameters_.viscosity;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 16)
#endif
    for (Eigen::Index i = 0; i < n_; ++i)
      for (Eigen::Index j = 0; j < n_; ++j) {
        const Vec3 r = centre(i) - centre(j);
        auto block = m.block(dofs_ * i, dofs_ * j, dofs_, dofs_);
        block.topLeftCorner<3, 3>() = rpy_translation(r, a, eta);
        if (dofs_ == 6) {
          const Mat3 rt = rpy_rotation_translation(r, a, eta);
          block.topRightCorner<3, 3>() = rt;
          block.bottomLeftCorner<3, 3>() = rt;
          block.bottomRightCorner<3, 3>() = rpy_rotation_rotation(r, a, eta);
        }
      }
    return m;
  }

  Eigen::Index size() const { return dofs_ * n_; }
  int dofs_per_body() const { return dofs_; }
  // div_q M = 0 exactly: RPY between spheres is divergence free in the positions (sum_j
  // d/dx_j M_ij vanishes on both branches, the rotation couplings' divergence contracts an
  // antisymmetric tensor) and nothing depends on orientation. The thermal drift is then free
  // (thermal_drift.hpp), where a random finite difference would cost two applications.
  VecX divergence() const { return VecX::Zero(size()); }
  std::size_t applications() const { return counter_.applications(); }
  void reset_applications() { counter_.reset_applications(); }
  const RpyParameters& parameters() const { return parameters_; }

 private:
  Vec3 centre(Eigen::Index i) const { return x_.col(i); }

  void require_configured() const {
    if (!configured_) throw std::logic_error("RpyMobility: call set_configuration before apply");
  }

  Eigen::Index n_ = 0;
  RpyParameters parameters_;
  int dofs_ = 3;
  Mat3X x_;  // centres
  bool configured_ = false;
  ApplicationCounter counter_;
};

}  // namespace stokescontact
