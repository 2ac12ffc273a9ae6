#pragma once
// The particle distance d^P: exact closest points between two shapes, as the distance
// between their centre curves minus both radii (every shape is a tube about its curve).
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <type_traits>

#include "stokescontact/geometry/arc_distance.hpp"
#include "stokescontact/geometry/segment_distance.hpp"
#include "stokescontact/geometry/shapes.hpp"

namespace stokescontact {

struct ClosestPoints {
  double distance = 0.0;        // signed: centre-curve distance minus both radii (< 0: overlap)
  Vec3 point_a = Vec3::Zero();  // world surface points realising it
  Vec3 point_b = Vec3::Zero();
  Vec3 normal = Vec3::UnitX();  // unit, from a towards b: point_b - point_a = distance * normal
  Vec3 curve_point_a = Vec3::Zero();  // the centre-curve points under them
  Vec3 curve_point_b = Vec3::Zero();
};

namespace detail {

// Closest centre-curve points of two curves, with the unit tangents there (zero on a
// point) for the fallback normal when the curves meet.
struct CurveContact {
  PieceClosestPoints points;
  Vec3 tangent_a = Vec3::Zero();
  Vec3 tangent_b = Vec3::Zero();
};

inline Vec3 unit_tangent(const Segment& s, double) {
  const Vec3 d = s.p1 - s.p0;
  const double length = d.norm();
  return length > 0.0 ? Vec3(d / length) : Vec3::Zero();
}

inline Vec3 unit_tangent(const Arc& a, double t) { return a.tangent(t); }

// A ball holding an arc: one of angle <= pi lies within half a chord of the chord's
// midpoint (a rounding margin keeps it a true bound).
struct Ball {
  Vec3 centre;
  double radius;
};

inline Ball bounding_ball(const Arc& a) {
  if (a.angle > std::numbers::pi) return {a.centre, a.radius};
  const Vec3 p = a.point(0.0), q = a.point(a.angle);
  return {0.5 * (p + q), 0.5 * (q - p).norm() * (1.0 + 1e-12)};
}

// Cheap lower bounds on a piece pair's distance, to skip arc pairs that cannot beat the
// best so far (segment pairs are as cheap to solve exactly).
inline double gap_lower_bound(const Segment&, const Segment&) {
  return -std::numeric_limits<double>::infinity();
}
inline double gap_lower_bound(const Segment& s, const Arc& a) {
  const Ball ball = bounding_ball(a);
  return closest_point(s, ball.centre).distance - ball.radius;
}
inline double gap_lower_bound(const Arc& a, const Segment& s) { return gap_lower_bound(s, a); }
inline double gap_lower_bound(const Arc& a, const Arc& b) {
  const Ball ball_a = bounding_ball(a), ball_b = bounding_ball(b);
  return (ball_b.centre - ball_a.centre).norm() - ball_a.radius - ball_b.radius;
}

// The piece-pair routines under one name; segment pairs ignore the cutoff.
inline PieceClosestPoints piece_closest_points(const Segment& a, const Segment& b, double) {
  return closest_points(a, b);
}
template <typename A, typename B>
PieceClosestPoints piece_closest_points(const A& a, const B& b, double cutoff) {
  return closest_points(a, b, cutoff);
}

// Minimum over all piece pairs. Segment pairs go first: they are cheap and give arc pairs
// a tight cutoff, so most arc searches stop at their first bounds or are never started.
// Ties keep the earlier pair.
template <std::size_t NSA, std::size_t NAA, std::size_t NSB, std::size_t NAB>
CurveContact curve_contact(const CentreCurve<NSA, NAA>& a, const CentreCurve<NSB, NAB>& b) {
  CurveContact best;
  best.points.distance = std::numeric_limits<double>::infinity();
  const auto scan = [&best](const auto& pieces_a, const auto& pieces_b) {
    for (const auto& pa : pieces_a) {
      for (const auto& pb : pieces_b) {
        if (!(gap_lower_bound(pa, pb) < best.points.distance)) continue;
        const PieceClosestPoints c = piece_closest_points(pa, pb, best.points.distance);
        if (c.distance < best.points.distance)
          best = {c, unit_tangent(pa, c.parameter_a), unit_tangent(pb, c.parameter_b)};
      }
    }
  };
  scan(a.segments, b.segments);
  scan(a.segments, b.arcs);
  scan(a.arcs, b.segments);
  scan(a.arcs, b.arcs);
  return best;
}

// A unit vector perpendicular to the unit vector t.
inline Vec3 any_perpendicular(const Vec3& t) {
  Eigen::Index i = 0;
  t.cwiseAbs().minCoeff(&i);  // the axis least aligned with t
  return t.cross(Vec3::Unit(i)).normalized();
}

// Normal when the centre curves meet (to rounding), so that no direction joins the curve
// points, in order of preference:
//  1. crossing pieces: the normal of the plane of both tangents, turned towards b's
//     reference centre (the normal a rod-rod contact would take just before touching);
//  2. parallel or point pieces: the direction from a's reference centre to b's with the
//     tangent component removed, so the normal stays perpendicular to the curve;
//  3. that direction vanishing too: a fixed perpendicular of the tangent, else +x.
// 1 and 2 flip with (a, b) swapped; 3 (concentric, coincident bodies) does not.
inline Vec3 meeting_normal(const Vec3& tangent_a, const Vec3& tangent_b, const Vec3& centres) {
  const Vec3 cross = tangent_a.cross(tangent_b);
  if (cross.norm() > 1e-6) {
    const Vec3 n = cross.normalized();
    return n.dot(centres) < 0.0 ? Vec3(-n) : n;
  }
  const Vec3 t = tangent_a.squaredNorm() > 0.0 ? tangent_a : tangent_b;
  const Vec3 d = centres - centres.dot(t) * t;
  if (d.norm() > 1e-12 * centres.norm()) return d.normalized();
  return t.squaredNorm() > 0.0 ? any_perpendicular(t) : Vec3::UnitX();
}

// Surface points one radius out from the curve points along the normal.
inline ClosestPoints finish(const CurveContact& c, double radius_a, double radius_b,
                            const Vec3& centre_a, const Vec3& centre_b) {
  ClosestPoints out;
  out.curve_point_a = c.points.point_a;
  out.curve_point_b = c.points.point_b;
  const Vec3 d = out.curve_point_b - out.curve_point_a;
  const double gap = d.norm();
  // A gap within rounding of the coordinates has no meaningful direction: the curves meet.
  const double rounding = 64.0 * std::numeric_limits<double>::epsilon() *
                          (out.curve_point_a.lpNorm<Eigen::Infinity>() +
                           out.curve_point_b.lpNorm<Eigen::Infinity>() + radius_a + radius_b);
  if (gap > rounding && gap > std::sqrt(std::numeric_limits<double>::min())) {
    out.normal = d / gap;
  } else {
    out.normal = meeting_normal(c.tangent_a, c.tangent_b, centre_b - centre_a);
  }
  out.distance = gap - radius_a - radius_b;
  out.point_a = out.curve_point_a + radius_a * out.normal;
  out.point_b = out.curve_point_b - radius_b * out.normal;
  return out;
}

// A shape's centre curve in the world frame; a sphere's is its centre, nothing to rotate.
template <Shape S>
auto world_curve(const S& shape, const Pose& pose) {
  return to_world(centre_curve(shape), pose);
}

inline CentreCurve<1, 0> world_curve(const Sphere&, const Pose& pose) {
  CentreCurve<1, 0> c;
  c.segments[0] = {pose.x, pose.x};
  return c;
}

// A reference centre for a bare curve: the mean of its pieces' end points.
template <std::size_t NS, std::size_t NA>
Vec3 reference_centre(const CentreCurve<NS, NA>& c) {
  Vec3 sum = Vec3::Zero();
  for (const Segment& s : c.segments) sum += s.p0 + s.p1;
  for (const Arc& a : c.arcs) sum += a.point(0.0) + a.point(a.angle);
  return sum / static_cast<double>(2 * (NS + NA));
}

}  // namespace detail

// Closest points between two tubes given by world-frame centre curves and radii >= 0.
template <std::size_t NSA, std::size_t NAA, std::size_t NSB, std::size_t NAB>
ClosestPoints closest_points(const CentreCurve<NSA, NAA>& a, double radius_a,
                             const CentreCurve<NSB, NAB>& b, double radius_b) {
  static_assert(NSA + NAA > 0 && NSB + NAB > 0, "a centre curve needs at least one piece");
  require_non_negative(radius_a, "radius_a");
  require_non_negative(radius_b, "radius_b");
  return detail::finish(detail::curve_contact(a, b), radius_a, radius_b,
                        detail::reference_centre(a), detail::reference_centre(b));
}

namespace detail {

// d^P of two shapes at poses the caller has validated (validate_scene, or poses made by
// advance from valid ones): the contact step measures each flagged pair several times per
// correction, and validating two shapes and two poses per measurement repeated the scene's
// check millions of times per step (docs/results.md, "Fresh memory per step").
template <Shape A, Shape B>
ClosestPoints closest_points_of_valid(const A& a, const Pose& pose_a, const B& b, const Pose& pose_b) {
  CurveContact c;
  if constexpr (std::is_same_v<A, Sphere> && std::is_same_v<B, Sphere>) {
    c.points = {0.0, 0.0, pose_a.x, pose_b.x, (pose_b.x - pose_a.x).norm()};
  } else {
    c = curve_contact(world_curve(a, pose_a), world_curve(b, pose_b));
  }
  return finish(c, a.radius, b.radius, pose_a.x, pose_b.x);
}

}  // namespace detail

// d^P of two shapes at their poses. Throws std::invalid_argument naming the shape field or
// "pose_a" / "pose_b". Two spheres compare centres directly; a sphere against another shape
// is a point against its curve (closed form per piece, no arc search).
template <Shape A, Shape B>
ClosestPoints closest_points(const A& a, const Pose& pose_a, const B& b, const Pose& pose_b) {
  validate(a);
  validate(b);
  validate(pose_a, "pose_a");
  validate(pose_b, "pose_b");
  return detail::closest_points_of_valid(a, pose_a, b, pose_b);
}

}  // namespace stokescontact
