#pragma once
// Free-draining mobility: no hydrodynamic interaction, M is block diagonal (Yan et al.
// Sec. IV, the Brownian spherocylinder runs; Broms & Tornberg Sec. 1.1 with the coupling
// switched off). Body i moves under its own force and torque alone:
//   (u_i, omega_i) = R_i N R_i^T (f_i, tau_i),   R_i = rotation of pose i, blockwise,
// where N is the 6x6 body-frame mobility of the body's shape (SPD). Bodies of one shape share
// one N, so a scene of 1e5 identical bodies stores a single 6x6 matrix.
//
// dofs_per_body 3 keeps only the translation block: u_i = R_i N_tt R_i^T f_i. That is exact
// for torque-free bodies and is what a sphere scene uses (no torques ever formed).
//
// Brownian terms, both exact (mobility_operator.hpp, SquareRootMobility and
// ExactDivergenceMobility):
//  - apply_sqrt: B = blockdiag(R_i L_k) with L_k the Cholesky factor of the shape's N (the
//    top-left 3x3 block for 3 dofs), factorised once per shape at construction;
//    B B^T = R N R^T = M. Isotropic shapes skip the rotation (L L^T = N = M); an isotropic
//    translation-only shape (a sphere, 3 dofs) is the scalar sqrt(N_00).
//  - divergence: M_i depends on orientation alone, so only the rotation derivative of the
//    (velocity, torque) coupling block C_i = R C R^T survives; its divergence is the axial
//    vector d_j = eps_jkl (C_i)_lk, i.e. R (eps_jkl C_lk) (derivation in docs/brownian.md).
//    Spheres, Yan's rods and any body with a symmetric coupling block have zero divergence.
#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/parallel_for.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/geometry/shapes.hpp"
#include "stokescontact/mobility/mobility_operator.hpp"

namespace stokescontact {

// Exact single-sphere mobility (Stokes drag and Kirchhoff torque): u = f / (6 pi eta a),
// omega = tau / (8 pi eta a^3), no coupling.
inline Mat6 sphere_mobility(const Sphere& sphere, double viscosity) {
  validate(sphere);
  require_positive(viscosity, "viscosity");
  const double a = sphere.radius, pi = std::numbers::pi;
  Mat6 n = Mat6::Zero();
  n.topLeftCorner<3, 3>().diagonal().setConstant(1.0 / (6.0 * pi * viscosity * a));
  n.bottomRightCorner<3, 3>().diagonal().setConstant(1.0 / (8.0 * pi * viscosity * a * a * a));
  return n;
}

// Slender-body mobility of a spherocylinder, Yan et al. eq. 45-50, body frame (axis n = z):
//   M_tt = nn / zeta_par + (I - nn) / zeta_perp,  M_rr = I / zeta_r,  no coupling,
//   1/zeta_par = 2b / (8 pi L mu), 1/zeta_perp = (b + 2) / (8 pi L mu),
//   1/zeta_r = 3 (b + 2) / (2 pi L^3 mu),  b = -(1 + 2 ln(D / (2L))).
// L is Spherocylinder::length, the centre segment (cylinder) length, and D = 2 radius: this
// is Yan's own L (Appendix A, "cylinders of length L and diameter D, capped with two
// hemispheres", and their L/D and B_2 = pi(2D^3/3 + L D^2 + L^2 D / 4) in Sec. IV-V), so
// the model reproduces the drag their equation-of-state runs used. Slender-body theory is an
// asymptotic result for L/D >> 1; the caps are not resolved, and eq. 46 gives the spin about
// the axis the same mobility as the tumbling modes. b must be positive (else zeta_par <= 0):
// L/D > exp(1/2) / 2 = 0.824; shorter rods are refused.
inline Mat6 spherocylinder_mobility(const Spherocylinder& rod, double viscosity) {
  validate(rod);
  require_positive(viscosity, "viscosity");
  const double L = rod.length, D = 2.0 * rod.radius, pi = std::numbers::pi;
  const double b = L > 0.0 ? -(1.0 + 2.0 * std::log(D / (2.0 * L))) : -1.0;
  if (!(b > 0.0))
    fail_argument("Spherocylinder.length",
                  "slender-body mobility (Yan et al. eq. 50) needs b = -(1 + 2 ln(D/(2L))) > 0, i.e. "
                  "length / (2 radius) > 0.824; got length = " + std::to_string(L) +
                      ", radius = " + std::to_string(rod.radius));
  const double par = 2.0 * b / (8.0 * pi * L * viscosity);
  const double perp = (b + 2.0) / (8.0 * pi * L * viscosity);
  const double rot = 3.0 * (b + 2.0) / (2.0 * pi * L * L * L * viscosity);
  Mat6 n = Mat6::Zero();
  n.diagonal() << perp, perp, par, rot, rot, rot;
  return n;
}

class FreeDrainingMobility {
 public:
  // shape_mobilities[k]: body-frame 6x6 mobility of shape k, rows (u, omega), columns
  // (f, tau), about the body origin, symmetric positive definite; body i has shape
  // shape_of_body[i]. dofs_per_body: 6, or 3 for the translation-only model.
  FreeDrainingMobility(std::vector<Mat6> shape_mobilities, std::vector<std::size_t> shape_of_body,
                       int dofs_per_body = 6)
      : shapes_(std::move(shape_mobilities)), shape_of_body_(std::move(shape_of_body)), dofs_(dofs_per_body) {
    if (dofs_ != 3 && dofs_ != 6) fail_argument("dofs_per_body", "must be 3 or 6, got " + std::to_string(dofs_));
    if (shapes_.empty()) fail_argument("shape_mobilities", "needs at least one shape");
    if (shape_of_body_.empty()) fail_argument("shape_of_body", "needs at least one body");
    for (std::size_t k = 0; k < shapes_.size(); ++k)
      shapes_[k] = validated_mobility(shapes_[k], "shape_mobilities[" + std::to_string(k) + "]");
    for (std::size_t i = 0; i < shape_of_body_.size(); ++i)
      if (shape_of_body_[i] >= shapes_.size())
        fail_argument("shape_of_body[" + std::to_string(i) + "]",
                      "is " + std::to_string(shape_of_body_[i]) + ", only " + std::to_string(shapes_.size()) +
                          " shapes given");
    // A shape whose blocks (those the model uses) are all multiples of I looks the same in
    // every orientation: its bodies skip the rotations.
    for (const Mat6& n : shapes_) {
      isotropic_.push_back(rotation_invariant(n, dofs_ / 3));
      cholesky_.push_back(cholesky_factor(n, dofs_));
      divergence_.push_back(dofs_ == 6 ? coupling_axial_vector(n) : Vec3::Zero());
    }
    for (const bool iso : isotropic_) needs_rotations_ = needs_rotations_ || !iso;
  }

  // `bodies` bodies of one shape.
  FreeDrainingMobility(const Mat6& body_mobility, std::size_t bodies, int dofs_per_body = 6)
      : FreeDrainingMobility(std::vector<Mat6>{body_mobility}, std::vector<std::size_t>(bodies, 0),
                             dofs_per_body) {}

  // New poses, same bodies. Validates everything before changing anything.
  void set_configuration(std::span<const Pose> poses) {
    const std::size_t n = shape_of_body_.size();
    validate(poses, n);
    if (needs_rotations_) {
      std::vector<Mat3> rotations(n);
      for (std::size_t i = 0; i < n; ++i) rotations[i] = poses[i].rotation();
      rotations_ = std::move(rotations);
    }
    configured_ = true;
  }

  // U = M F, one application; F stacked per body (f_i[, tau_i]).
  VecX apply(const VecX& F) {
    require_configured();
    require_finite(F, size(), "F");
    counter_.count();
    VecX U(size());
    // Serial: a few flops per body, bound by memory bandwidth; threads would not pay.
    const auto n = static_cast<Eigen::Index>(shape_of_body_.size());
    for (Eigen::Index i = 0; i < n; ++i) {
      if (dofs_ == 6)
        apply_body<6>(i, F, U);
      else
        apply_body<3>(i, F, U);
    }
    return U;
  }

  // B W with B B^T = M (B = blockdiag(R_i L_k), see the top), one application; W stacked per
  // body like F.
  VecX apply_sqrt(const VecX& W) {
    require_configured();
    require_finite(W, size(), "W");
    counter_.count();
    VecX U(size());
    const auto n = static_cast<Eigen::Index>(shape_of_body_.size());
    for (Eigen::Index i = 0; i < n; ++i) {
      if (dofs_ == 6)
        apply_sqrt_body<6>(i, W, U);
      else
        apply_sqrt_body<3>(i, W, U);
    }
    return U;
  }

  // div_q M at the current configuration: per body (R_i d_k, 0) for 6 dofs, 0 for 3 (see the
  // top). No application.
  VecX divergence() const {
    require_configured();
    VecX d = VecX::Zero(size());
    if (dofs_ == 3) return d;
    for (std::size_t i = 0; i < shape_of_body_.size(); ++i) {
      const std::size_t k = shape_of_body_[i];
      if (isotropic_[k]) continue;  // coupling c I: symmetric, d_k = 0
      d.segment<3>(6 * static_cast<Eigen::Index>(i)) = rotations_[i] * divergence_[k];
    }
    return d;
  }

  // The block-diagonal matrix, formed directly (0 applications).
  MatX dense_matrix() const {
    require_configured();
    MatX m = MatX::Zero(size(), size());
    for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(shape_of_body_.size()); ++i)
      m.block(dofs_ * i, dofs_ * i, dofs_, dofs_) = block(i).topLeftCorner(dofs_, dofs_);
    return m;
  }

  // The same matrix, sparse: dofs^2 entries per body (BlockDiagonalMobility, 0 applications).
  Eigen::SparseMatrix<double> block_diagonal() const {
    require_configured();
    // Written straight into compressed storage, column by column (each body's columns hold
    // only its own block's nonzeros): two passes, counting then filling (each forms the
    // blocks again: no N blocks held); no insertions.
    const auto n = static_cast<Eigen::Index>(shape_of_body_.size());
    std::vector<int> counts(static_cast<std::size_t>(size()));
    parallel_for(n, [&](std::ptrdiff_t i) {
      const Mat6 b = block(i);
      for (int c = 0; c < dofs_; ++c)
        counts[static_cast<std::size_t>(dofs_ * i + c)] = static_cast<int>((b.col(c).head(dofs_).array() != 0.0).count());
    });
    Eigen::SparseMatrix<double> m(size(), size());
    int* outer = m.outerIndexPtr();
    outer[0] = 0;
    for (Eigen::Index c = 0; c < size(); ++c) outer[c + 1] = outer[c] + counts[static_cast<std::size_t>(c)];
    m.resizeNonZeros(outer[size()]);
    parallel_for(n, [&](std::ptrdiff_t i) {
      const Mat6 b = block(i);
      for (int c = 0; c < dofs_; ++c) {
        int k = outer[dofs_ * i + c];
        for (int r = 0; r < dofs_; ++r)
          if (b(r, c) != 0.0) {
            m.innerIndexPtr()[k] = static_cast<int>(dofs_ * i + r);
            m.valuePtr()[k++] = b(r, c);
          }
      }
    });
    return m;
  }

  Eigen::Index size() const { return dofs_ * static_cast<Eigen::Index>(shape_of_body_.size()); }
  int dofs_per_body() const { return dofs_; }
  std::size_t applications() const { return counter_.applications(); }
  void reset_applications() { counter_.reset_applications(); }

  // The validated (symmetrised) body-frame mobility of shape k.
  const Mat6& shape_mobility(std::size_t k) const { return shapes_.at(k); }

 private:
  // Relative asymmetry allowed in a given N before it is refused (then N is symmetrised).
  static constexpr double kSymmetryTolerance = 1e-10;

  static Mat6 validated_mobility(const Mat6& n, const std::string& field) {
    require_finite(n.reshaped(), field);
    const double scale = n.cwiseAbs().maxCoeff();
    if (!((n - n.transpose()).cwiseAbs().maxCoeff() <= kSymmetryTolerance * scale))
      fail_argument(field, "must be symmetric");
    const Mat6 sym = 0.5 * (n + n.transpose());
    // The dynamic-size solver on purpose: SelfAdjointEigenSolver is one of Eigen's costliest
    // templates to compile (seconds per instantiation), and the MatX one is the instantiation
    // the rest of the library (defect correction, Lanczos) and the tests already use, so a
    // translation unit pays for it once, not once per fixed size. Same algorithm, 6x6.
    const double min_eigenvalue =
        Eigen::SelfAdjointEigenSolver<MatX>(MatX(sym), Eigen::EigenvaluesOnly).eigenvalues()(0);
    if (!(min_eigenvalue > 0.0))
      fail_argument(field, "must be positive definite, smallest eigenvalue " + std::to_string(min_eigenvalue));
    return sym;
  }

  // Lower Cholesky factor of the top-left dofs x dofs block of N (SPD, checked above).
  static Mat6 cholesky_factor(const Mat6& n, int dofs) {
    Mat6 l = Mat6::Zero();
    if (dofs == 6)
      l = n.llt().matrixL();
    else
      l.topLeftCorner<3, 3>() = n.topLeftCorner<3, 3>().llt().matrixL();
    return l;
  }

  // d_j = eps_jkl C_lk for the body-frame coupling C = N_(velocity, torque), the top-right
  // block: (C_32 - C_23, C_13 - C_31, C_21 - C_12) = 2 a, with (C - C^T) / 2 = [a x]; zero iff
  // C = C^T. An axial vector, so the world-frame value is R d.
  static Vec3 coupling_axial_vector(const Mat6& n) {
    const Mat3 c = n.topRightCorner<3, 3>();
    return {c(2, 1) - c(1, 2), c(0, 2) - c(2, 0), c(1, 0) - c(0, 1)};
  }

  static bool rotation_invariant(const Mat6& n, int blocks) {
    for (int r = 0; r < blocks; ++r)
      for (int c = 0; c < blocks; ++c) {
        const Mat3 b = n.block<3, 3>(3 * r, 3 * c);
        if (b != b(0, 0) * Mat3::Identity()) return false;
      }
    return true;
  }

  // u_i = R N R^T f_i for body i: to the body frame, N, back to the world frame (D = dofs).
  template <int D>
  void apply_body(Eigen::Index i, const VecX& F, VecX& U) const {
    using VecD = Eigen::Matrix<double, D, 1>;
    const std::size_t k = shape_of_body_[static_cast<std::size_t>(i)];
    const auto n = shapes_[k].template topLeftCorner<D, D>();
    if (isotropic_[k]) {  // R N R^T = N
      U.template segment<D>(D * i).noalias() = n * F.template segment<D>(D * i);
      return;
    }
    const Mat3& R = rotations_[static_cast<std::size_t>(i)];
    VecD f;
    for (int b = 0; b < D; b += 3) f.template segment<3>(b) = R.transpose() * F.template segment<3>(D * i + b);
    const VecD u = n * f;
    for (int b = 0; b < D; b += 3) U.template segment<3>(D * i + b) = R * u.template segment<3>(b);
  }

  // B_i W_i = R L W_i for body i (L W_i for isotropic shapes, sqrt(N_00) W_i for a sphere's 3).
  template <int D>
  void apply_sqrt_body(Eigen::Index i, const VecX& W, VecX& U) const {
    using VecD = Eigen::Matrix<double, D, 1>;
    const std::size_t k = shape_of_body_[static_cast<std::size_t>(i)];
    const auto l = cholesky_[k].template topLeftCorner<D, D>().template triangularView<Eigen::Lower>();
    if (isotropic_[k]) {
      if constexpr (D == 3)
        U.template segment<3>(3 * i) = cholesky_[k](0, 0) * W.template segment<3>(3 * i);
      else
        U.template segment<D>(D * i).noalias() = l * W.template segment<D>(D * i);
      return;
    }
    const VecD u = l * W.template segment<D>(D * i);
    const Mat3& R = rotations_[static_cast<std::size_t>(i)];
    for (int b = 0; b < D; b += 3) U.template segment<3>(D * i + b) = R * u.template segment<3>(b);
  }

  // World-frame 6x6 block of body i: R N R^T blockwise (for the dense matrix).
  Mat6 block(Eigen::Index i) const {
    const std::size_t k = shape_of_body_[static_cast<std::size_t>(i)];
    if (isotropic_[k]) return shapes_[k];
    const Mat3& R = rotations_[static_cast<std::size_t>(i)];
    Mat6 rotation = Mat6::Zero();
    rotation.topLeftCorner<3, 3>() = R;
    rotation.bottomRightCorner<3, 3>() = R;
    return rotation * shapes_[k] * rotation.transpose();
  }

  void require_configured() const {
    if (!configured_) throw std::logic_error("FreeDrainingMobility: call set_configuration before apply");
  }

  std::vector<Mat6> shapes_;
  std::vector<std::size_t> shape_of_body_;
  int dofs_ = 6;
  std::vector<bool> isotropic_;
  std::vector<Mat6> cholesky_;    // per shape: lower Cholesky factor of N's used block
  std::vector<Vec3> divergence_;  // per shape: body-frame divergence eps_jkl C_lk (6 dofs)
  bool needs_rotations_ = false;
  std::vector<Mat3> rotations_;  // per body, only when some shape is anisotropic
  bool configured_ = false;
  ApplicationCounter counter_;
};

}  // namespace stokescontact
