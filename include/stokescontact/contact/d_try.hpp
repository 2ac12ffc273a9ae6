#pragma once
// The threshold d_try that flags pairs at the trial configuration Q* = Q_t + dt Psi U
// (Broms & Tornberg eq. 16) and sets the barrier in D (eq. 22), chosen per time step from
// the trial velocities U (stacked per body: u, then omega when dofs_per_body is 6):
//   eq. 31 (spheres):          d_try = d_hat + dt max_i |u_i|
//   eq. 30 (rods, boomerangs): d_try = d_hat + dt max_i |tip velocity of body i|
// Both are scaled as a whole by a user multiplier >= 1 (the paper's robustness test, Sec.
// 3.1.2, uses 1, 1.1 and 1.2).
//
// Those two rules take absolute speeds, so a suspension carried by a uniform flow, or
// sheared about a far-away plane, flags more pairs the faster it moves. The library's
// default rule is relative (DTryRule::relative, contact/continuous_detection.hpp): one
// threshold per pair from the pair's own relative motion, d_try_ij = m (d_hat + dt L_ij) with
// L_ij the bound on the rate of change of its distance (geometry/swept_distance.hpp); a
// pair whose distance falls below d_hat anywhere in the trial step is then always flagged.
//
// Our eq. 30 takes the fastest point of each body's centre curve, not one tip: a distance
// is the centre-curve distance less the (rotation-invariant) radii, so no distance changes
// faster than the sum of the two bodies' fastest centre-curve points. For a rod this is the
// faster of its two tips, u +- (L/2) omega x v (the paper writes the tip -L/2 v, whose speed
// may be the smaller one), with L the centre segment's length; for a sphere it is |u|,
// eq. 31; for a boomerang's bend it is bounded by the corners of triangles enclosing the arc.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "stokescontact/contact/scene.hpp"

namespace stokescontact {

// How the contact step chooses d_try when it is not given.
//   relative: per pair, m (d_hat + dt L_ij), L_ij from the pair's relative motion (Galilean
//             invariant; catches every pair that comes within d_hat during the trial step);
//   absolute: the paper's single threshold, eq. 31 (3 dofs) or eq. 30 (6 dofs).
enum class DTryRule { relative, absolute };

namespace detail {

inline void require_dofs(int dofs_per_body) {
  if (dofs_per_body != 3 && dofs_per_body != 6)
    fail_argument("dofs_per_body", "must be 3 or 6, got " + std::to_string(dofs_per_body));
}

inline void require_velocities(const VecX& U, std::size_t bodies, int dofs_per_body) {
  require_dofs(dofs_per_body);
  if (U.size() != static_cast<Eigen::Index>(bodies) * dofs_per_body)
    fail_argument("U", "size must be dofs_per_body * N = " + std::to_string(bodies * dofs_per_body) +
                           ", got " + std::to_string(U.size()));
  require_finite(U, "U");
}

inline double d_try_from_speed(double d_hat, double dt, double max_speed, double multiplier) {
  require_positive(d_hat, "d_hat");
  require_positive(dt, "dt");
  require_finite(multiplier, "multiplier");
  if (!(multiplier >= 1.0)) fail_argument("multiplier", "must be >= 1, got " + std::to_string(multiplier));
  return multiplier * (d_hat + dt * max_speed);
}

// Body-frame points whose convex hull holds the centre curve: segment ends, and for an arc
// its ends plus, per piece of at most a quarter turn, the corner where the tangents at the
// piece's ends meet (the arc piece lies in that triangle).
template <std::size_t NS, std::size_t NA>
std::vector<Vec3> centre_curve_hull_points(const CentreCurve<NS, NA>& curve) {
  std::vector<Vec3> points;
  for (const Segment& s : curve.segments) {
    points.push_back(s.p0);
    points.push_back(s.p1);
  }
  for (const Arc& a : curve.arcs) {
    const int pieces = std::max(1, static_cast<int>(std::ceil(a.angle / (0.5 * std::numbers::pi))));
    const double step = a.angle / pieces;
    for (int k = 0; k < pieces; ++k) {
      const double mid = (k + 0.5) * step;
      points.push_back(a.point(k * step));
      points.push_back(a.centre + a.radius / std::cos(0.5 * step) * (std::cos(mid) * a.e1 + std::sin(mid) * a.e2));
    }
    points.push_back(a.point(a.angle));
  }
  return points;
}

}  // namespace detail

// eq. 31: U holds (u_i) or (u_i, omega_i) per body, dofs_per_body = 3 or 6.
inline double d_try_spheres(double d_hat, double dt, const VecX& U, int dofs_per_body, double multiplier = 1.0) {
  detail::require_dofs(dofs_per_body);
  if (U.size() % dofs_per_body != 0)
    fail_argument("U", "size must be a multiple of dofs_per_body, got " + std::to_string(U.size()));
  require_finite(U, "U");
  double max_speed = 0.0;
  for (Eigen::Index k = 0; k + dofs_per_body <= U.size(); k += dofs_per_body)
    max_speed = std::max(max_speed, U.segment<3>(k).norm());
  return detail::d_try_from_speed(d_hat, dt, max_speed, multiplier);
}

// eq. 30 for any shape (rods, boomerangs; spheres give eq. 31): U holds (u_i, omega_i).
template <Shape S>
double d_try_tip_velocity(double d_hat, double dt, std::span<const S> shapes, std::span<const Pose> poses,
                          const VecX& U, double multiplier = 1.0) {
  validate_scene(shapes, poses);
  detail::require_velocities(U, poses.size(), 6);
  double max_speed = 0.0;
  std::vector<Vec3> hull;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (k == 0 || shapes.size() > 1) hull = detail::centre_curve_hull_points(centre_curve(shape_of(shapes, k)));
    const Vec3 u = U.segment<3>(6 * static_cast<Eigen::Index>(k));
    const Vec3 omega = U.segment<3>(6 * static_cast<Eigen::Index>(k) + 3);
    for (const Vec3& r : hull)
      max_speed = std::max(max_speed, (u + omega.cross(poses[k].direction_to_world(r))).norm());
  }
  return detail::d_try_from_speed(d_hat, dt, max_speed, multiplier);
}

template <Shape S>
double d_try_tip_velocity(double d_hat, double dt, const S& shape, std::span<const Pose> poses, const VecX& U,
                          double multiplier = 1.0) {
  return d_try_tip_velocity(d_hat, dt, std::span<const S>(&shape, 1), poses, U, multiplier);
}

}  // namespace stokescontact
