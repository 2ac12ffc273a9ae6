#pragma once
// Rigid-body pose: centre x and unit quaternion q (Broms eq. 1), body <-> world maps.
#include <cmath>
#include <cstddef>
#include <span>
#include <string>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

// A quaternion counts as unit length when | |q| - 1 | <= this tolerance.
inline constexpr double kUnitQuaternionTolerance = 1e-10;

struct Pose {
  Vec3 x = Vec3::Zero();
  Quat q = Quat::Identity();

  Mat3 rotation() const { return q.toRotationMatrix(); }
  Vec3 to_world(const Vec3& body_point) const { return x + q * body_point; }
  Vec3 to_body(const Vec3& world_point) const { return q.conjugate() * (world_point - x); }
  Vec3 direction_to_world(const Vec3& body_direction) const { return q * body_direction; }
};

inline void require_unit(const Quat& q, std::string_view field) {
  require_finite(q.coeffs(), field);
  const double norm = q.norm();
  if (std::abs(norm - 1.0) > kUnitQuaternionTolerance)
    fail_argument(field, "must be a unit quaternion (| |q| - 1 | <= 1e-10), got |q| = " +
                             std::to_string(norm));
}

// x finite and | |q| - 1 | <= kUnitQuaternionTolerance, checked on |q|^2 (no square root; it
// sits on every distance query and every advanced body): (1 - tol)^2 <= |q|^2 <= (1 + tol)^2,
// false for a NaN or infinite coefficient (|q|^2 is then NaN or infinite).
inline bool is_valid(const Pose& pose) {
  constexpr double lo = (1.0 - kUnitQuaternionTolerance) * (1.0 - kUnitQuaternionTolerance);
  constexpr double hi = (1.0 + kUnitQuaternionTolerance) * (1.0 + kUnitQuaternionTolerance);
  const double n2 = pose.q.coeffs().squaredNorm();
  return std::isfinite(pose.x.x()) && std::isfinite(pose.x.y()) && std::isfinite(pose.x.z()) && n2 >= lo && n2 <= hi;
}

// Throws std::invalid_argument naming "pose.x" or "pose.q" when the pose is unusable.
// The names are built only on failure: validation sits on every distance query.
inline void validate(const Pose& pose, std::string_view name = "pose") {
  if (is_valid(pose)) return;
  const std::string prefix(name);
  require_finite(pose.x, prefix + ".x");
  require_unit(pose.q, prefix + ".q");
}

// A configuration: each pose valid, names "poses[k].x" / "poses[k].q" for the first bad one.
inline void validate(std::span<const Pose> poses, std::string_view name = "poses") {
  for (std::size_t k = 0; k < poses.size(); ++k)
    if (!is_valid(poses[k])) validate(poses[k], std::string(name) + "[" + std::to_string(k) + "]");
}

// The same, and exactly `count` poses.
inline void validate(std::span<const Pose> poses, std::size_t count, std::string_view name = "poses") {
  if (poses.size() != count)
    fail_argument(name, "has " + std::to_string(poses.size()) + " poses, expected " + std::to_string(count));
  validate(poses, name);
}

}  // namespace stokescontact
