#pragma once
// The two ends of the overlap of near-parallel segments: where a line contact of two rods
// side by side is held when it is held at two points.
//
// d^P (Broms & Tornberg eq. 20-21) holds a pair of rods at its closest points. Side by side
// those sit at an end of the overlap and jump to the other end as the pair turns through
// parallel (Broms Sec. 4 item 2), so a force that separates the pair at the end of the step
// acts at one end, with a lever arm of half the overlap: an explicit step then turns the rod
// through the parallel position and beyond (measured: rods of the Fig. 8 grid spinning at
// 150 rad/s to hold a gap of 0.01 R). Held at both ends of the overlap instead, each end is
// its own constraint: the tilt a step may give the pair is the one that brings each end to
// d_hat, and a pair exactly parallel gets equal forces at both ends (no torque).
//
// The distance of two segments is the smallest of the four end-to-segment distances and,
// where the closest points are inside both segments, that interior minimum. On the overlap
// the gap |b(tau(s)) - a(s)| is convex in s, so for a pair that does not cross inside the
// overlap the two ends bound it from below: each end's constraint is the gap from a segment
// end to the other segment, a function of the poses that is continuous in the orientation, and
// continuous too as the rods slide and the overlap's end passes from one rod's end to the
// other's (overlap_end_gap).
#include <array>
#include <cmath>
#include <optional>

#include "stokescontact/geometry/point_distance.hpp"
#include "stokescontact/geometry/segment_distance.hpp"

namespace stokescontact {

// An end of one segment of a pair: segment 0 (a) or 1 (b), end 0 (p0) or 1 (p1).
struct SegmentEnd {
  int segment = 0;
  int end = 0;
};

// The segment ends that bound the overlap of a and b (the part of a whose projection on b's
// line falls inside b), lower end first along a; none when the lines meet at an angle of
// max_angle or more (in [0, pi/2]), or the overlap is shorter than min_overlap. An overlap
// end at a's end is that end, else the end of b that projects there (ties: a's end).
inline std::optional<std::array<SegmentEnd, 2>> overlap_ends(const Segment& a, const Segment& b, double max_angle,
                                                             double min_overlap) {
  if (is_point(a) || is_point(b)) return std::nullopt;
  const Vec3 da = a.p1 - a.p0, db = b.p1 - b.p0;
  if (!(std::atan2(da.cross(db).norm(), std::abs(da.dot(db))) < max_angle)) return std::nullopt;
  const double inv_aa = 1.0 / da.squaredNorm();
  const double s0 = (b.p0 - a.p0).dot(da) * inv_aa, s1 = (b.p1 - a.p0).dot(da) * inv_aa;
  const SegmentEnd low_b{1, s0 <= s1 ? 0 : 1}, high_b{1, s0 <= s1 ? 1 : 0};
  const double lo = std::max(0.0, std::min(s0, s1)), hi = std::min(1.0, std::max(s0, s1));
  if (!((hi - lo) * std::sqrt(da.squaredNorm()) >= min_overlap)) return std::nullopt;
  return std::array<SegmentEnd, 2>{std::min(s0, s1) > 0.0 ? low_b : SegmentEnd{0, 0},
                                   std::max(s0, s1) < 1.0 ? high_b : SegmentEnd{0, 1}};
}

// The closest points of the segment end e and the other segment, a's point first.
inline PieceClosestPoints end_to_segment(const Segment& a, const Segment& b, SegmentEnd e) {
  const Segment& own = e.segment == 0 ? a : b;
  const Segment& other = e.segment == 0 ? b : a;
  const double s = e.end == 0 ? 0.0 : 1.0;
  const Vec3 p = own.point(s);
  const CurvePoint q = closest_point(other, p);
  return e.segment == 0 ? PieceClosestPoints{s, q.parameter, p, q.point, q.distance}
                        : PieceClosestPoints{q.parameter, s, q.point, p, q.distance};
}

// The other segment's end on the same side of the overlap as e: with e an end of a, b's end
// that projects lower (e = a's p0) or higher (a's p1) along a; with e an end of b, a's end on
// the side b's end points to along a.
inline SegmentEnd same_side_end(const Segment& a, const Segment& b, SegmentEnd e) {
  const Vec3 da = a.p1 - a.p0, db = b.p1 - b.p0;
  if (e.segment == 1) return {0, (e.end == 1 ? db : Vec3(-db)).dot(da) < 0.0 ? 0 : 1};
  const bool b_rises = db.dot(da) >= 0.0;  // b's p1 is its higher end along a
  return {1, (e.end == 1) == b_rises ? 1 : 0};
}

// The gap at the end of the overlap on e's side: the nearer of e and same_side_end(e) to the
// other segment, a's point first. The overlap's end on a side is whichever of the two ends
// there projects inside the other segment, and it passes from one rod's end to the other's as
// the rods slide along each other. An end that projects outside is nearest to the other
// segment's end on its side, so it is at least as far from the other segment as that end is.
// So the nearer of the two is the gap at the overlap's end on either side of the passage,
// continuous through it, where the end fixed at Q* would measure the distance of two rod ends
// and miss the overlap's end closing in (a step of 400 Brownian rods at eta 0.40 that no
// halving separated: docs/results.md, "The overlap's end passes from one rod to the other").
// Both are point pairs' gaps, so holding the nearer never asks for more than d^P >= d_hat.
inline PieceClosestPoints overlap_end_gap(const Segment& a, const Segment& b, SegmentEnd e) {
  const PieceClosestPoints own = end_to_segment(a, b, e);
  const PieceClosestPoints other = end_to_segment(a, b, same_side_end(a, b, e));
  return other.distance < own.distance ? other : own;
}

}  // namespace stokescontact
