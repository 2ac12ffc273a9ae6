#pragma once
// Orientational order of rods and the stress along and across their director.
//
// u_i is body i's axis, the body z axis in the world frame (Pose::rotation().col(2): the axis
// of a Spherocylinder and of a rod's blob grid).
//   order_tensor:  Q = (1/N) sum_i (3/2 u_i u_i^T - 1/2 I), symmetric and traceless.
//   order_along:   e^T Q e = (1/N) sum_i (3/2 (e . u_i)^2 - 1/2), Broms & Tornberg eq. 33 with
//                  e = e_z (the biaxial-compression grid's axis, Fig. 8d).
//   nematic_order: the nematic order parameter S, Q's largest eigenvalue, and the director, its
//                  unit eigenvector (sign arbitrary), as Yan, Zhang & Shelley 2019 Sec. IV.B
//                  use them for L/D = 5 spherocylinders (S ~ 0.2 isotropic, ~0.6 past the
//                  isotropic-nematic transition). All rods along one axis give S = 1; equal
//                  numbers along x, y and z give Q = 0; a uniform distribution on the sphere
//                  gives S -> 0 like 1/sqrt(N).
//   pressure_along_and_across: a pressure tensor P (compressive-positive, e.g. Yan's sigma^col
//                  or n kT I + sigma^col / V, dynamics/collision_stress.hpp) split into
//                  n^T P n along the director n and (tr P - n^T P n) / 2, the mean over the two
//                  directions across it: Yan Sec. IV.B's stress anisotropy. along + 2 across =
//                  tr P, and both are invariant under a common rotation of P and n.
//   stress_anisotropy: Yan Sec. IV.B's measure of it (Fig. 5), sigma_max / sigma_min, the
//                  largest over the smallest eigenvalue of a collision stress tensor (its
//                  symmetric part); +infinity where the smallest is not positive beyond
//                  rounding, at most 1e-12 of the largest (no collision pushes across some
//                  direction), which JSON output writes as null.
#include <cmath>
#include <limits>
#include <span>

#include <Eigen/Eigenvalues>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

inline Mat3 order_tensor(std::span<const Pose> poses) {
  if (poses.empty()) fail_argument("poses", "must hold at least one body");
  Mat3 q = Mat3::Zero();
  for (const Pose& p : poses) {
    validate(p);
    const Vec3 u = p.rotation().col(2);
    q += 1.5 * u * u.transpose();
  }
  q /= static_cast<double>(poses.size());
  q.diagonal().array() -= 0.5;
  return q;
}

// Broms & Tornberg eq. 33 for an axis e (normalised here; e = e_z in the paper).
inline double order_along(std::span<const Pose> poses, const Vec3& axis) {
  require_finite(axis, "axis");
  const double norm = axis.norm();
  if (!(norm > 0.0)) fail_argument("axis", "must be nonzero");
  const Vec3 e = axis / norm;
  return e.dot(order_tensor(poses) * e);
}

struct NematicOrder {
  double S = 0.0;                  // largest eigenvalue of Q
  Vec3 director = Vec3::UnitZ();   // its unit eigenvector
};

inline NematicOrder nematic_order(std::span<const Pose> poses) {
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(order_tensor(poses));
  return {eigen.eigenvalues()(2), eigen.eigenvectors().col(2)};  // ascending
}

struct DirectionalPressure {
  double along = 0.0;   // n^T P n
  double across = 0.0;  // (tr P - n^T P n) / 2
};

inline DirectionalPressure pressure_along_and_across(const Mat3& pressure, const Vec3& director) {
  require_finite(pressure.reshaped(), "pressure");
  require_finite(director, "director");
  const double norm = director.norm();
  if (!(norm > 0.0)) fail_argument("director", "must be nonzero");
  const Vec3 n = director / norm;
  const double along = n.dot(pressure * n);
  return {along, 0.5 * (pressure.trace() - along)};
}

inline double stress_anisotropy(const Mat3& sigma) {
  require_finite(sigma.reshaped(), "sigma");
  const Mat3 symmetric = 0.5 * (sigma + sigma.transpose());
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(symmetric, Eigen::EigenvaluesOnly);
  const double smallest = eigen.eigenvalues()(0), largest = eigen.eigenvalues()(2);
  return smallest > 1e-12 * std::abs(largest) ? largest / smallest : std::numeric_limits<double>::infinity();
}

}  // namespace stokescontact
