#pragma once
// The map Psi from body velocities (u, omega) to coordinate rates (Broms eq. 4) and the
// forward-Euler step x' = x + dt u, q' = exp(dt omega / 2) q that keeps q unit length, for
// one body (advance) and for every body of a configuration (advance_all).
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "stokescontact/core/pose.hpp"

namespace stokescontact {

using Psi = Eigen::Matrix<double, 7, 6>;

// Coordinate rates d(x, q)/dt = Psi(q) (u, omega), with dq/dt = (1/2) [0, omega] q and
// omega the angular velocity in the world frame; q stored as (w, x, y, z) rows 3..6.
inline Psi psi_matrix(const Quat& q) {
  Psi psi = Psi::Zero();
  psi.topLeftCorner<3, 3>().setIdentity();
  const double w = q.w();
  const Vec3 v = q.vec();
  psi.block<1, 3>(3, 3) = -0.5 * v.transpose();  // d(w)/dt = -(1/2) omega . v
  Mat3 v_cross;
  v_cross << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  psi.block<3, 3>(4, 3) = 0.5 * (w * Mat3::Identity() - v_cross);  // d(v)/dt
  return psi;
}

// Unit quaternion exp([0, theta]) for a rotation vector theta (angle |theta| * 2 / 2):
// the rotation by angle |phi| about phi / |phi| where phi = 2 theta.
inline Quat quaternion_exp(const Vec3& half_rotation) {
  const double angle = half_rotation.norm();
  // sin(a)/a by its Taylor series near 0, where the division loses accuracy.
  const double sinc = angle < 1e-4 ? 1.0 - angle * angle / 6.0 : std::sin(angle) / angle;
  Quat e;
  e.w() = std::cos(angle);
  e.vec() = sinc * half_rotation;
  return e;
}

// One step of the rigid motion with constant (u, omega) over dt: the exact rotation by
// omega dt, renormalised so that rounding never accumulates into |q| != 1. With omega = 0
// exactly (every body of a model without rotations, dofs_per_body 3) q is kept as it is.
inline Pose advance(const Pose& pose, const Vec3& u, const Vec3& omega, double dt) {
  validate(pose);
  require_finite(u, "u");
  require_finite(omega, "omega");
  require_finite(dt, "dt");
  Pose next;
  next.x = pose.x + dt * u;
  if (omega.isZero(0.0)) {
    next.q = pose.q;
    return next;
  }
  next.q = quaternion_exp(0.5 * dt * omega) * pose.q;
  next.q.normalize();
  return next;
}

// Q' = Q + dt Psi U for every body (Broms eq. 16 with U, eq. 13 with U + M D lambda).
// `velocities` stacks (u) or (u, omega) per body, dofs_per_body 3 or 6 (3: orientations kept).
inline std::vector<Pose> advance_all(std::span<const Pose> poses, const VecX& velocities, int dofs_per_body,
                                     double dt) {
  if (dofs_per_body != 3 && dofs_per_body != 6)
    fail_argument("dofs_per_body", "must be 3 or 6, got " + std::to_string(dofs_per_body));
  if (velocities.size() != static_cast<Eigen::Index>(poses.size()) * dofs_per_body)
    fail_argument("velocities", "size must be dofs_per_body * N = " +
                                    std::to_string(poses.size() * static_cast<std::size_t>(dofs_per_body)) +
                                    ", got " + std::to_string(velocities.size()));
  std::vector<Pose> next(poses.size());
  for (std::size_t b = 0; b < next.size(); ++b) {
    const Eigen::Index row = static_cast<Eigen::Index>(b) * dofs_per_body;
    const Vec3 omega = dofs_per_body == 6 ? Vec3(velocities.segment<3>(row + 3)) : Vec3::Zero();
    next[b] = advance(poses[b], velocities.segment<3>(row), omega, dt);
  }
  return next;
}

}  // namespace stokescontact
