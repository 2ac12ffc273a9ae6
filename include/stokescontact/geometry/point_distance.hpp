#pragma once
// Closest point on a segment or an arc to a given point, exact to rounding.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "stokescontact/geometry/primitives.hpp"

namespace stokescontact {

// Parameter and location of the closest point on a centre-curve piece.
struct CurvePoint {
  double parameter = 0.0;  // s in [0, 1] on a segment, t in [0, angle] on an arc
  Vec3 point = Vec3::Zero();
  double distance = 0.0;   // |point - query|
};

inline CurvePoint closest_point(const Segment& segment, const Vec3& query) {
  const Vec3 d = segment.p1 - segment.p0;
  const double dd = d.squaredNorm();
  double s = 0.0;
  if (dd > 0.0) s = std::clamp((query - segment.p0).dot(d) / dd, 0.0, 1.0);
  const Vec3 p = segment.point(s);
  return {s, p, (query - p).norm()};
}

// The circle point nearest to the query lies at the query's polar angle phi in the arc's
// plane; outside [0, angle] the nearer end in angle is closest, because the distance
// grows monotonically with the angular gap |t - phi|. A query on the axis is equidistant
// from the whole arc: the start t = 0 is returned.
inline CurvePoint closest_point(const Arc& arc, const Vec3& query) {
  const Vec3 r = query - arc.centre;
  const double x = r.dot(arc.e1);
  const double y = r.dot(arc.e2);
  double t = 0.0;
  if (x != 0.0 || y != 0.0) {
    double phi = std::atan2(y, x);  // (-pi, pi]
    if (phi < 0.0) phi += 2.0 * std::numbers::pi;  // [0, 2 pi)
    if (phi <= arc.angle) {
      t = phi;
    } else {
      const double gap_to_end = phi - arc.angle;
      const double gap_to_start = 2.0 * std::numbers::pi - phi;
      t = gap_to_end <= gap_to_start ? arc.angle : 0.0;
    }
  }
  const Vec3 p = arc.point(t);
  return {t, p, (query - p).norm()};
}

}  // namespace stokescontact
