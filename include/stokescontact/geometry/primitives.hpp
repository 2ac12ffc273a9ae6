#pragma once
// Pieces of a centre curve: straight segments and circular arcs. Every shape's surface
// is the set of points one radius from its centre curve (Broms Sec. 2.1).
#include <cmath>

#include "stokescontact/core/pose.hpp"

namespace stokescontact {

// P(s) = (1 - s) p0 + s p1, s in [0, 1]; p0 == p1 is a point (a sphere's centre).
struct Segment {
  Vec3 p0 = Vec3::Zero();
  Vec3 p1 = Vec3::Zero();

  Vec3 point(double s) const { return p0 + s * (p1 - p0); }
  double length() const { return (p1 - p0).norm(); }
};

// C(t) = centre + radius (cos t e1 + sin t e2), t in [0, angle], e1 and e2 orthonormal.
struct Arc {
  Vec3 centre = Vec3::Zero();
  Vec3 e1 = Vec3::UnitX();
  Vec3 e2 = Vec3::UnitY();
  double radius = 1.0;
  double angle = 0.0;

  Vec3 point(double t) const { return centre + radius * (std::cos(t) * e1 + std::sin(t) * e2); }
  Vec3 tangent(double t) const { return -std::sin(t) * e1 + std::cos(t) * e2; }
  Vec3 axis() const { return e1.cross(e2); }
  double length() const { return radius * angle; }
};

inline Segment to_world(const Segment& s, const Pose& pose) {
  return {pose.to_world(s.p0), pose.to_world(s.p1)};
}

inline Arc to_world(const Arc& a, const Pose& pose) {
  return {pose.to_world(a.centre), pose.direction_to_world(a.e1), pose.direction_to_world(a.e2),
          a.radius, a.angle};
}

}  // namespace stokescontact
