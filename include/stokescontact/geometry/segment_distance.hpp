#pragma once
// Closest points between two segments, exact to rounding in every degenerate case
// (parallel, collinear, crossing, zero length, nearly parallel), at any scale.
#include <algorithm>
#include <limits>

#include "stokescontact/geometry/point_distance.hpp"

namespace stokescontact {

// Closest points between two centre-curve pieces a and b: a segment's parameter s lies in
// [0, 1], an arc's t in [0, angle]; point_b - point_a has length `distance`.
struct PieceClosestPoints {
  double parameter_a = 0.0;
  double parameter_b = 0.0;
  Vec3 point_a = Vec3::Zero();
  Vec3 point_b = Vec3::Zero();
  double distance = 0.0;
};

inline PieceClosestPoints swapped(const PieceClosestPoints& c) {
  return {c.parameter_b, c.parameter_a, c.point_b, c.point_a, c.distance};
}

// A segment whose squared length underflows the normal doubles acts as the point p0 (its
// inverse squared length would overflow).
inline bool is_point(const Segment& s) {
  return !((s.p1 - s.p0).squaredNorm() >= std::numeric_limits<double>::min());
}

namespace detail {

// a is the shorter segment, b the longer one, neither of zero length.
inline PieceClosestPoints closest_points_ordered(const Segment& a, const Segment& b) {
  const Vec3 da = a.p1 - a.p0, db = b.p1 - b.p0, w0 = a.p0 - b.p0;
  const double inv_aa = 1.0 / da.squaredNorm(), inv_bb = 1.0 / db.squaredNorm();
  const auto clamp01 = [](double x) { return std::clamp(x, 0.0, 1.0); };
  // Candidates (s, t) are judged by the squared length of a(s) - b(t) = w0 + s da - t db.
  double best_s = 0.0, best_t = 0.0, best_d2 = std::numeric_limits<double>::infinity();
  const auto consider = [&](double s, double t) {
    const double d2 = (w0 + s * da - t * db).squaredNorm();
    if (d2 < best_d2) best_s = s, best_t = t, best_d2 = d2;
  };
  // The minimum has s or t at an end of [0, 1] (then it is one of these four exact
  // end-to-segment projections), or both inside (then it is the interior solution below).
  // Taking the best of all five covers every case without a threshold choosing the case.
  consider(0.0, clamp01(w0.dot(db) * inv_bb));
  consider(1.0, clamp01((w0 + da).dot(db) * inv_bb));
  consider(clamp01(-w0.dot(da) * inv_aa), 0.0);
  consider(clamp01((db - w0).dot(da) * inv_aa), 1.0);

  // Interior solution, projected onto the plane normal to the longer segment b: there b is
  // a point and a(s) traces the line w + s d, so s = -(w.d)/(d.d). Unlike the determinant
  // of the 2x2 normal equations (relative error eps/theta^2 at angle theta), d = da minus
  // its component along db carries relative error eps/theta only, so the distance at the
  // computed s is off by ~eps |a| even as theta -> 0 (the valley is that flat).
  const Vec3 d = da - da.dot(db) * inv_bb * db;
  const double dd = d.squaredNorm();
  // Below this, a is parallel to b within rounding: the ends above already hold a minimum.
  constexpr double kParallel = 1e-30;  // (1e-15)^2, relative to |da|^2
  if (dd * inv_aa > kParallel) {
    const Vec3 w = w0 - w0.dot(db) * inv_bb * db;
    // Re-clamp each parameter against the other: s -> t = proj of a(s) onto b -> s again.
    const double s = clamp01(-w.dot(d) / dd);
    const double t = clamp01((w0 + s * da).dot(db) * inv_bb);
    consider(clamp01(-(w0 - t * db).dot(da) * inv_aa), t);
  }
  const Vec3 p = a.point(best_s), q = b.point(best_t);
  return {best_s, best_t, p, q, (q - p).norm()};
}

}  // namespace detail

// The shorter segment is always measured against the longer one, so (a, b) and (b, a)
// run the same arithmetic and give mirrored results exactly (unless the lengths tie).
inline PieceClosestPoints closest_points(const Segment& a, const Segment& b) {
  if (is_point(a) || is_point(b)) {  // a point against a segment (or a point)
    const bool point_a = is_point(a);
    const CurvePoint c = closest_point(point_a ? b : a, point_a ? a.p0 : b.p0);
    return point_a ? PieceClosestPoints{0.0, c.parameter, a.p0, c.point, c.distance}
                   : PieceClosestPoints{c.parameter, 0.0, c.point, b.p0, c.distance};
  }
  if ((a.p1 - a.p0).squaredNorm() > (b.p1 - b.p0).squaredNorm())
    return swapped(detail::closest_points_ordered(b, a));
  return detail::closest_points_ordered(a, b);
}

}  // namespace stokescontact
