#pragma once
// Particle shapes as small value types. Each is the set of points within `radius` of its
// centre curve, given in the body frame with the origin at the centre of mass.
#include <algorithm>
#include <cmath>
#include <concepts>
#include <numbers>

#include "stokescontact/geometry/centre_curve.hpp"

namespace stokescontact {

// Each shape says whether it is convex: a convex pair touches at one place, so the closest
// points (d^P, Broms & Tornberg eq. 21) give its contact direction; a non-convex pair may touch
// at several, and the contact step spreads its force over surface-node pairs (d^S, eq. 23).
struct Sphere {
  static constexpr bool convex = true;
  double radius = 1.0;
};

// Yan et al. Appendix A: a cylinder whose centre segment has length `length` (L) along the
// body z axis, capped by hemispheres of radius `radius` (R).
struct Spherocylinder {
  static constexpr bool convex = true;
  double length = 1.0;
  double radius = 0.5;
};

// Broms & Tornberg Sec. 3.3.1: a straight arm along body z, a quarter circle of radius
// `bend_radius`, a straight arm along body x; each arm `arm_length` long and ending in a
// hemispherical cap. The paper's particle (a rod of end-to-end length 4 and radius 0.5
// cut in two and joined about the touching corner) is broms_tornberg_boomerang().
struct Boomerang {
  static constexpr bool convex = false;
  double arm_length = 1.5;
  double radius = 0.5;
  double bend_radius = 0.5;
};

inline Boomerang broms_tornberg_boomerang() { return {1.5, 0.5, 0.5}; }

inline void validate(const Sphere& s) { require_positive(s.radius, "Sphere.radius"); }

inline void validate(const Spherocylinder& s) {
  require_non_negative(s.length, "Spherocylinder.length");
  require_positive(s.radius, "Spherocylinder.radius");
}

inline void validate(const Boomerang& b) {
  require_non_negative(b.arm_length, "Boomerang.arm_length");
  require_positive(b.radius, "Boomerang.radius");
  require_positive(b.bend_radius, "Boomerang.bend_radius");
  // A tighter bend would make the tube overlap itself inside the corner.
  if (b.bend_radius < b.radius)
    fail_argument("Boomerang.bend_radius", "must be >= Boomerang.radius");
}

inline double volume(const Sphere& s) { return 4.0 / 3.0 * std::numbers::pi * std::pow(s.radius, 3); }

inline double volume(const Spherocylinder& s) {
  const double r2 = s.radius * s.radius;
  return std::numbers::pi * r2 * (s.length + 4.0 / 3.0 * s.radius);
}

// Two cylinders, two hemispherical caps and a quarter torus (Pappus).
inline double volume(const Boomerang& b) {
  const double pi = std::numbers::pi, r2 = b.radius * b.radius;
  return pi * r2 * (2.0 * b.arm_length + 4.0 / 3.0 * b.radius + 0.5 * pi * b.bend_radius);
}

namespace detail {
// Boomerang centre of mass in the construction frame, where the bend's circle is centred
// at (Rb, 0, Rb), the z arm runs from (0, 0, Rb + a) down to (0, 0, Rb) and the x arm from
// (Rb, 0, 0) to (Rb + a, 0, 0). By the x <-> z mirror symmetry it is (m, 0, m).
inline double boomerang_mass_centre_offset(const Boomerang& b) {
  const double pi = std::numbers::pi;
  const double a = b.arm_length, r = b.radius, rb = b.bend_radius;
  const double cylinder = pi * r * r * a;
  const double cap = 2.0 / 3.0 * pi * r * r * r;
  const double torus = 0.5 * pi * pi * r * r * rb;
  // Centroid of a torus sector of angle alpha lies 2 sin(alpha/2) (Rb^2 + R^2/4) /
  // (alpha Rb) from the circle's centre along the bisector; alpha = pi/2 here.
  const double torus_x = rb - 2.0 * (rb * rb + 0.25 * r * r) / (pi * rb);
  // The z arm and its cap sit at x = 0; the x arm's cap centroid is 3R/8 past its end.
  const double moment = cylinder * (rb + 0.5 * a) + cap * (rb + a + 3.0 / 8.0 * r) + torus * torus_x;
  return moment / volume(b);
}
}  // namespace detail

inline CentreCurve<1, 0> centre_curve(const Sphere&) { return {}; }

inline CentreCurve<1, 0> centre_curve(const Spherocylinder& s) {
  CentreCurve<1, 0> c;
  c.segments[0] = {Vec3(0, 0, -0.5 * s.length), Vec3(0, 0, 0.5 * s.length)};
  return c;
}

// Segments: [0] the z arm (tip first), [1] the x arm (bend first); arcs: [0] the bend.
inline CentreCurve<2, 1> centre_curve(const Boomerang& b) {
  const double a = b.arm_length, rb = b.bend_radius;
  const double m = detail::boomerang_mass_centre_offset(b);
  const Vec3 shift(m, 0.0, m);
  CentreCurve<2, 1> c;
  c.segments[0] = {Vec3(0, 0, rb + a) - shift, Vec3(0, 0, rb) - shift};
  c.arcs[0] = {Vec3(rb, 0, rb) - shift, -Vec3::UnitX(), -Vec3::UnitZ(), rb, 0.5 * std::numbers::pi};
  c.segments[1] = {Vec3(rb, 0, 0) - shift, Vec3(rb + a, 0, 0) - shift};
  return c;
}

// Radius of a ball about the body origin that contains the whole shape.
inline double bounding_radius(const Sphere& s) { return s.radius; }

inline double bounding_radius(const Spherocylinder& s) { return 0.5 * s.length + s.radius; }

inline double bounding_radius(const Boomerang& b) {
  const auto c = centre_curve(b);
  const Arc& bend = c.arcs[0];
  const double reach = std::max({c.segments[0].p0.norm(), c.segments[0].p1.norm(),
                                 c.segments[1].p0.norm(), c.segments[1].p1.norm(),
                                 bend.centre.norm() + bend.radius});
  return reach + b.radius;
}

// What every shape offers to the geometry layer.
template <typename S>
concept Shape = requires(const S& s) {
  { s.radius } -> std::convertible_to<double>;
  { S::convex } -> std::convertible_to<bool>;
  centre_curve(s);
  { bounding_radius(s) } -> std::convertible_to<double>;
  { volume(s) } -> std::convertible_to<double>;
  validate(s);
};

}  // namespace stokescontact
