#pragma once
// Closest points between two segments, exact to rounding in every degenerate case
// (parallel, collinear, crossing, zero length, nearly parallel), at any scale. Where the
// minimisers are degenerate, parallel segments side by side, they are the middle of the
// overlap (a line contact's force belongs there; see centre_line_contact).
#include <algorithm>
#include <cmath>
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

// Rounding allowance for line contacts, relative to the largest coordinate (see below).
inline constexpr double kLineContactRounding = 6.0 * std::numeric_limits<double>::epsilon();

// Line contacts. Over the overlap of the projections (the s where a(s) projects inside b)
// the separation is a(s) - b(tau(s)) = w + s d, d = da less its component along b: it
// turns by V = |d| (overlap length in s) from one end of the overlap to the other.
// Parallel segments (d = 0) are closest along the whole overlap: the exact minimisers are
// degenerate. A nearly parallel pair's are an end of the overlap, and which end flips as
// the angle passes through 0. For a contact force neither end is right: the force of a
// line contact acts along the whole overlap and its resultant belongs at the middle (an
// end gives a symmetric pair of rods a torque it does not have, and the end jumps as the
// rods turn through parallel). So where V is within rounding of 0, the closest points move
// to the middle of the overlap:
//   V <= r:       the overlap's midpoint (s_m, tau(s_m));
//   r < V < 2 r:  s moves from the exact minimiser towards s_m by the fraction 2 - V / r,
//                 so the result is continuous in the orientation;
//   V >= 2 r:     the exact minimiser, untouched (any pair tilted beyond rounding);
// with r = kLineContactRounding times the largest coordinate of the end points. Their
// rounding alone turns d by up to 2 sqrt(3) eps times that, so a pair whose V is below r
// is parallel as far as its coordinates can tell. The separation changes by at most
// fraction * V <= r over the move (r / 2 from an end of the overlap), so the distance
// stays exact to rounding. Without overlap (parallel segments end to end) the nearest end
// points stand. (s, t) is the exact minimiser, updated in place; a(s) projects onto b's
// line at tau(s) = tau0 + kappa s.
inline void centre_line_contact(const Segment& a, const Segment& b, double tau0, double kappa,
                                const Vec3& d, double& s, double& t) {
  double lo = 0.0, hi = 1.0;  // the overlap, in s
  if (kappa != 0.0) {
    const double inv_kappa = 1.0 / kappa;
    const double s0 = -tau0 * inv_kappa, s1 = (1.0 - tau0) * inv_kappa;
    lo = std::max(lo, std::min(s0, s1));
    hi = std::min(hi, std::max(s0, s1));
  } else if (!(tau0 >= 0.0 && tau0 <= 1.0)) {
    return;
  }
  if (!(lo <= hi)) return;
  // V >= 2 r, the common case, is first ruled out against |end point| >= the coordinates.
  const double turn2 = d.squaredNorm() * (hi - lo) * (hi - lo);  // V^2
  const double norm2 = std::max(std::max(a.p0.squaredNorm(), a.p1.squaredNorm()),
                                std::max(b.p0.squaredNorm(), b.p1.squaredNorm()));
  constexpr double k = kLineContactRounding;
  if (!(turn2 < 4.0 * k * k * norm2)) return;
  const double coordinates = a.p0.cwiseAbs()
                                 .cwiseMax(a.p1.cwiseAbs())
                                 .cwiseMax(b.p0.cwiseAbs())
                                 .cwiseMax(b.p1.cwiseAbs())
                                 .maxCoeff();
  const double rounding = k * coordinates;
  const double fraction = std::clamp(2.0 - std::sqrt(turn2) / rounding, 0.0, 1.0);
  if (!(fraction > 0.0)) return;
  const double s_moved = std::lerp(s, 0.5 * (lo + hi), fraction);  // the midpoint at fraction 1
  const double t_moved = std::clamp(tau0 + kappa * s_moved, 0.0, 1.0);
  // A minimum off the overlap (a tiny overlap of crossing segments) stays where it is.
  const double moved = (b.point(t_moved) - a.point(s_moved)).norm();
  if (moved <= (b.point(t) - a.point(s)).norm() + rounding) s = s_moved, t = t_moved;
}

// a is the shorter segment, b the longer one, neither of zero length.
inline PieceClosestPoints closest_points_ordered(const Segment& a, const Segment& b) {
  const Vec3 da = a.p1 - a.p0, db = b.p1 - b.p0, w0 = a.p0 - b.p0;
  const double inv_aa = 1.0 / da.squaredNorm(), inv_bb = 1.0 / db.squaredNorm();
  const auto clamp01 = [](double x) { return std::clamp(x, 0.0, 1.0); };
  // a(s) projects onto b's line at tau(s) = tau0 + kappa s.
  const double tau0 = w0.dot(db) * inv_bb, kappa = da.dot(db) * inv_bb;
  // Candidates (s, t) are judged by the squared length of a(s) - b(t) = w0 + s da - t db.
  double best_s = 0.0, best_t = 0.0, best_d2 = std::numeric_limits<double>::infinity();
  const auto consider = [&](double s, double t) {
    const double d2 = (w0 + s * da - t * db).squaredNorm();
    if (d2 < best_d2) best_s = s, best_t = t, best_d2 = d2;
  };
  // The minimum has s or t at an end of [0, 1] (then it is one of these four exact
  // end-to-segment projections), or both inside (then it is the interior solution below).
  // Taking the best of all five covers every case without a threshold choosing the case.
  consider(0.0, clamp01(tau0));
  consider(1.0, clamp01((w0 + da).dot(db) * inv_bb));
  consider(clamp01(-w0.dot(da) * inv_aa), 0.0);
  consider(clamp01((db - w0).dot(da) * inv_aa), 1.0);

  // Interior solution, projected onto the plane normal to the longer segment b: there b is
  // a point and a(s) traces the line w + s d, so s = -(w.d)/(d.d). Unlike the determinant
  // of the 2x2 normal equations (relative error eps/theta^2 at angle theta), d = da minus
  // its component along db carries relative error eps/theta only, so the distance at the
  // computed s is off by ~eps |a| even as theta -> 0 (the valley is that flat).
  const Vec3 d = da - kappa * db;
  const double dd = d.squaredNorm();
  // Below this, a is parallel to b within rounding: the ends above already hold a minimum
  // (which centre_line_contact moves to the middle of the overlap).
  constexpr double kParallel = 1e-30;  // (1e-15)^2, relative to |da|^2
  if (dd * inv_aa > kParallel) {
    const Vec3 w = w0 - tau0 * db;
    // Re-clamp each parameter against the other: s -> t = proj of a(s) onto b -> s again.
    const double s = clamp01(-w.dot(d) / dd);
    const double t = clamp01((w0 + s * da).dot(db) * inv_bb);
    consider(clamp01(-(w0 - t * db).dot(da) * inv_aa), t);
  }
  centre_line_contact(a, b, tau0, kappa, d, best_s, best_t);
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
