#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "geometry/brute_force.hpp"
#include "stokescontact/geometry/line_contact.hpp"
#include "stokescontact/geometry/segment_distance.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace segment_distance_tests {

namespace sc = stokescontact;
using sc::Segment;
using sc::Vec3;

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Every case runs at these length scales; errors are judged relative to the scale.
constexpr double kScales[] = {1e-6, 1.0, 1e6};

Segment scaled(const Segment& s, double k) { return {k * s.p0, k * s.p1}; }

// The result is self-consistent: parameters in [0, 1], points on their segments, and the
// distance is the points' separation.
void expect_consistent(const Segment& a, const Segment& b, const sc::PieceClosestPoints& c,
                       double scale) {
  EXPECT_GE(c.parameter_a, 0.0);
  EXPECT_LE(c.parameter_a, 1.0);
  EXPECT_GE(c.parameter_b, 0.0);
  EXPECT_LE(c.parameter_b, 1.0);
  EXPECT_LE((c.point_a - a.point(c.parameter_a)).norm(), 4 * kEps * scale);
  EXPECT_LE((c.point_b - b.point(c.parameter_b)).norm(), 4 * kEps * scale);
  EXPECT_NEAR((c.point_b - c.point_a).norm(), c.distance, 4 * kEps * scale);
}

// Checks distance (to `tol` units of rounding at the scale) and, where given, parameters.
void expect_case(const Segment& a0, const Segment& b0, double distance0, double tol = 8.0,
                 double s = -1.0, double t = -1.0) {
  for (const double k : kScales) {
    SCOPED_TRACE(testing::Message() << "scale " << k);
    const Segment a = scaled(a0, k), b = scaled(b0, k);
    const sc::PieceClosestPoints c = sc::closest_points(a, b);
    EXPECT_NEAR(c.distance, k * distance0, tol * kEps * k);
    if (s >= 0.0) {
      EXPECT_NEAR(c.parameter_a, s, 1e-12);
    }
    if (t >= 0.0) {
      EXPECT_NEAR(c.parameter_b, t, 1e-12);
    }
    expect_consistent(a, b, c, k);
    // Swapping the arguments mirrors the result.
    const sc::PieceClosestPoints r = sc::closest_points(b, a);
    EXPECT_NEAR(r.distance, c.distance, tol * kEps * k);
  }
}

}  // namespace

TEST(SegmentDistance, Parallel) {
  expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(0.3, 1, 0), Vec3(2, 1, 0)}, 1.0);
}

TEST(SegmentDistance, Antiparallel) {
  expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(2, 1, 0), Vec3(0.3, 1, 0)}, 1.0);
}

// Parallel segments are closest along the whole overlap of their projections: the points
// returned are its midpoint, so a symmetric pair of rods gets a force at its middle.
// Overlaps of every kind (partial, b inside a, a inside b, touching at one point,
// antiparallel), offsets across the axis in and out of plane, every scale, both orders.
TEST(SegmentDistance, ParallelOverlapReturnsItsMidpoint) {
  const Segment a{Vec3(0, 0, 0), Vec3(1, 0, 0)};
  const double spans[][2] = {{0.3, 2.0}, {-1.0, 0.4}, {0.2, 0.7}, {-1.0, 3.0},
                             {1.0, 2.0}, {2.0, 0.3},  {0.7, 0.2}, {0.0, 1.0}};
  const Vec3 offsets[] = {Vec3(0, 1, 0), Vec3(0, 0.3, -0.4), Vec3(0, 1e-3, 0), Vec3(0, 0, 0)};
  for (const auto& span : spans) {
    for (const Vec3& offset : offsets) {
      const Segment b0{Vec3(span[0], 0, 0) + offset, Vec3(span[1], 0, 0) + offset};
      const double lo = std::max(0.0, std::min(span[0], span[1]));
      const double hi = std::min(1.0, std::max(span[0], span[1]));
      const double middle = 0.5 * (lo + hi);
      for (const double k : kScales) {
        SCOPED_TRACE(testing::Message() << "b from " << span[0] << " to " << span[1] << " offset "
                                        << offset.transpose() << " scale " << k);
        const Segment sa = scaled(a, k), sb = scaled(b0, k);
        for (const bool swap : {false, true}) {
          const sc::PieceClosestPoints c =
              swap ? sc::swapped(sc::closest_points(sb, sa)) : sc::closest_points(sa, sb);
          EXPECT_NEAR(c.distance, k * offset.norm(), 4 * kEps * k);
          EXPECT_LE((c.point_a - k * Vec3(middle, 0, 0)).norm(), 4 * kEps * k);
          EXPECT_LE((c.point_b - k * (Vec3(middle, 0, 0) + offset)).norm(), 4 * kEps * k);
          expect_consistent(sa, sb, c, k);
        }
      }
    }
  }
}

// The same for copies turned and moved at random, as rods' centre segments come out of
// their poses: parallel only to rounding, and still met at the midpoint to rounding.
TEST(SegmentDistance, RoundedParallelOverlapReturnsItsMidpoint) {
  brute_force::Rng rng(16);
  for (int i = 0; i < 2000; ++i) {
    const double k = std::pow(10.0, brute_force::uniform(rng, -6.0, 6.0));
    const Vec3 axis = brute_force::random_unit_vector(rng);
    const Vec3 across = axis.cross(brute_force::random_unit_vector(rng)).normalized();
    const Vec3 origin = k * 100.0 * brute_force::random_unit_vector(rng);
    const double la = brute_force::uniform(rng, 0.5, 4.0), lb = brute_force::uniform(rng, 0.5, 4.0);
    const double shift = brute_force::uniform(rng, -4.0, 4.0);
    const double gap = brute_force::uniform(rng, 0.0, 2.0);
    const Vec3 b_origin = origin + k * (gap * across + shift * axis);
    const Segment a{origin, origin + k * la * axis};
    const Segment b{b_origin, b_origin + k * lb * axis};
    const double lo = std::max(0.0, shift), hi = std::min(la, shift + lb);
    if (hi < lo) continue;  // end to end: the nearest ends, tested elsewhere
    const sc::PieceClosestPoints c = sc::closest_points(a, b);
    const double middle = 0.5 * (lo + hi);
    const double rounding = 64 * kEps * (origin.norm() + 8 * k);
    EXPECT_LE((c.point_a - (origin + k * middle * axis)).norm(), rounding) << "pair " << i;
    EXPECT_LE((c.point_b - (b_origin + k * (middle - shift) * axis)).norm(), rounding)
        << "pair " << i;
    EXPECT_NEAR(c.distance, k * gap, rounding) << "pair " << i;
  }
}

// Nearly parallel, tilted in the plane of the offset so that the exact closest points sit
// at one end of the overlap or the other with the sign of the tilt theta. Within the
// rounding of the coordinates (theta ~ 1e-15 here) the points move to the midpoint of the
// overlap and back, continuously in theta; beyond it they are the exact minimisers. The
// distance stays within rounding of the exact minimum throughout. (The offset h is small
// enough for h + theta to resolve theta's steps: ulp(h) = rounding / 380.)
TEST(SegmentDistance, NearlyParallelMovesContinuouslyToTheMidpoint) {
  const double h = 1.0 / 64.0;
  const double rounding = sc::detail::kLineContactRounding * 1.0;  // the largest coordinate is 1
  const Segment a{Vec3(0, 0, 0), Vec3(1, 0, 0)};
  const auto tilted = [&](double theta) { return Segment{Vec3(0, h, 0), Vec3(1, h + theta, 0)}; };
  double previous = -1.0;
  for (int i = -200; i <= 200; ++i) {
    const double theta = 3.0 * rounding * i / 200.0;
    SCOPED_TRACE(testing::Message() << "theta " << theta);
    const sc::PieceClosestPoints c = sc::closest_points(a, tilted(theta));
    const double exact = theta < 0.0 ? h + theta : h;  // at s = 1 or s = 0
    EXPECT_GE(c.distance, exact - 4 * kEps);
    EXPECT_LE(c.distance, exact + rounding);
    if (std::abs(theta) <= rounding) {
      EXPECT_NEAR(c.parameter_a, 0.5, 1e-12);
    } else if (theta >= 2.05 * rounding) {  // 2 rounding, and V's own rounding
      EXPECT_EQ(c.parameter_a, 0.0);
    } else if (theta <= -2.05 * rounding) {
      EXPECT_EQ(c.parameter_a, 1.0);
    }
    // Steps of 3 rounding / 200 in theta move the points by at most ~ 1/100 of the overlap.
    if (previous >= 0.0) {
      EXPECT_LE(std::abs(c.parameter_a - previous), 0.02);
    }
    previous = c.parameter_a;
  }
}

TEST(SegmentDistance, ParallelWithoutOverlapMeetsAtEnds) {
  expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(2, 1, 0), Vec3(3, 1, 0)}, std::sqrt(2.0), 8.0,
              1.0, 0.0);
}

TEST(SegmentDistance, CollinearOverlapping) {
  expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(0.5, 0, 0), Vec3(2, 0, 0)}, 0.0);
  expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(2, 0, 0), Vec3(-1, 0, 0)}, 0.0);  // contains a
}

TEST(SegmentDistance, CollinearDisjoint) {
  expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(3, 0, 0), Vec3(1.5, 0, 0)}, 0.5, 8.0, 1.0, 1.0);
}

TEST(SegmentDistance, CollinearTouchingEnds) {
  expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(1, 0, 0), Vec3(2, 0, 0)}, 0.0, 8.0, 1.0, 0.0);
}

TEST(SegmentDistance, Crossing) {
  expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(0.25, -1, 0), Vec3(0.25, 3, 0)}, 0.0, 8.0, 0.25,
              0.25);
}

TEST(SegmentDistance, TJunction) {
  expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(0.5, 0, 0), Vec3(0.5, 1, 0)}, 0.0, 8.0, 0.5,
              0.0);
}

TEST(SegmentDistance, SkewPerpendicular) {
  expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(0.5, -1, 2), Vec3(0.5, 1, 2)}, 2.0, 8.0, 0.5,
              0.5);
}

TEST(SegmentDistance, SkewWithClampedInteriorSolution) {
  // The lines' closest points lie beyond b's end: the minimum is at t = 1.
  expect_case({Vec3(0, 0, 0), Vec3(4, 0, 0)}, {Vec3(1, 3, 1), Vec3(2, 2, 1)}, std::sqrt(5.0), 8.0,
              0.5, 1.0);
}

TEST(SegmentDistance, ZeroLengthFirst) {
  expect_case({Vec3(0.5, 2, 0), Vec3(0.5, 2, 0)}, {Vec3(0, 0, 0), Vec3(1, 0, 0)}, 2.0, 8.0, 0.0,
              0.5);
  expect_case({Vec3(-3, 4, 0), Vec3(-3, 4, 0)}, {Vec3(0, 0, 0), Vec3(1, 0, 0)}, 5.0, 8.0, 0.0, 0.0);
}

TEST(SegmentDistance, ZeroLengthSecond) {
  expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(0.5, 0, 2), Vec3(0.5, 0, 2)}, 2.0, 8.0, 0.5,
              0.0);
}

TEST(SegmentDistance, ZeroLengthBoth) {
  expect_case({Vec3(1, 2, 3), Vec3(1, 2, 3)}, {Vec3(1, 2, 5), Vec3(1, 2, 5)}, 2.0);
  expect_case({Vec3(1, 2, 3), Vec3(1, 2, 3)}, {Vec3(1, 2, 3), Vec3(1, 2, 3)}, 0.0);
}

TEST(SegmentDistance, ZeroLengthOnSegment) {
  expect_case({Vec3(0.25, 0, 0), Vec3(0.25, 0, 0)}, {Vec3(0, 0, 0), Vec3(1, 0, 0)}, 0.0, 8.0, 0.0,
              0.25);
}

TEST(SegmentDistance, AlmostZeroLength) {
  // A segment 1e-13 long behaves as the point it nearly is.
  expect_case({Vec3(0.5, 2, 0), Vec3(0.5 + 1e-13, 2, 0)}, {Vec3(0, 0, 0), Vec3(1, 0, 0)}, 2.0);
  // One whose squared length underflows is taken as a point (no 1 / 0 anywhere).
  const Segment tiny{Vec3(0.5, 2, 0), Vec3(0.5, 2, 1e-160)};
  const sc::PieceClosestPoints c = sc::closest_points(tiny, Segment{Vec3(0, 0, 0), Vec3(1, 0, 0)});
  EXPECT_EQ(c.distance, 2.0);
  EXPECT_EQ(c.parameter_b, 0.5);
  EXPECT_EQ(sc::closest_points(Segment{Vec3(0, 0, 0), Vec3(1, 0, 0)}, tiny).distance, 2.0);
}

// Lines in the planes z = 0 and z = h crossing (in projection) at the origin at angle theta:
// the distance is exactly h for every theta, while the crossing's location along the lines
// becomes ill-conditioned as theta -> 0. The distance must stay exact to rounding.
TEST(SegmentDistance, NearlyParallelCrossingInProjection) {
  for (const double theta : {1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12}) {
    for (const double h : {0.0, 1e-9, 1e-3, 0.5}) {
      SCOPED_TRACE(testing::Message() << "theta " << theta << " h " << h);
      const Vec3 d(std::cos(theta), std::sin(theta), 0.0);
      expect_case({Vec3(-1, 0, 0), Vec3(1, 0, 0)},
                  {Vec3(0, 0, h) - 0.7 * d, Vec3(0, 0, h) + 1.3 * d}, h);
    }
  }
}

// Nearly parallel, overlapping, b starting above a's interior and drifting away by theta:
// the minimum h sits at b's first end.
TEST(SegmentDistance, NearlyParallelOverlapping) {
  for (const double theta : {1e-4, 1e-8, 1e-12}) {
    SCOPED_TRACE(testing::Message() << "theta " << theta);
    // Below theta ~ 1e-7 every point of the overlap ties within rounding: no parameter check.
    const bool distinct = theta > 1e-7;
    expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(0.5, 0, 0.25), Vec3(1.5, theta, 0.25)}, 0.25,
                8.0, distinct ? 0.5 : -1.0, distinct ? 0.0 : -1.0);
    // Drifting towards a instead, within a's span: the minimum is at b's second end.
    expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(0.2, 0, 0.25), Vec3(0.8, 0, 0.25 - theta)},
                0.25 - theta, 8.0, 0.8, 1.0);
  }
}

TEST(SegmentDistance, NearlyParallelEndToEnd) {
  for (const double theta : {1e-6, 1e-12}) {
    expect_case({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(1.5, 0, 0), Vec3(2.5, theta, 0)}, 0.5, 8.0,
                1.0, 0.0);
  }
}

TEST(SegmentDistance, VeryDifferentLengths) {
  expect_case({Vec3(0, 0, 0), Vec3(1e6, 0, 0)}, {Vec3(3, 1, 0.5), Vec3(3, 1, 0.5 + 1e-6)},
              std::hypot(1.0, 0.5),
              1e7);  // rounding relative to a's length 1e6
}

// Random pairs at scales 1e-6 .. 1e6, general and nearly parallel, against the independent
// brute force (which only bounds from above, and agrees after refinement).
TEST(SegmentDistance, RandomPairsMatchBruteForce) {
  brute_force::Rng rng(20240611);
  const int n = brute_force::random_pairs(20000);
  int failures = 0;
  for (int i = 0; i < n; ++i) {
    const double scale = std::pow(10.0, brute_force::uniform(rng, -6.0, 6.0));
    const Vec3 origin =
        scale * Vec3(brute_force::uniform(rng, -3, 3), brute_force::uniform(rng, -3, 3),
                     brute_force::uniform(rng, -3, 3));
    const Segment a{origin, origin + scale * brute_force::uniform(rng, 0, 2) *
                                         brute_force::random_unit_vector(rng)};
    Segment b;
    if (i % 3 == 0) {  // nearly parallel to a, tilted by up to 1e-3 .. 1e-12 rad
      const Vec3 dir = (a.p1 - a.p0).normalized();
      const Vec3 tilt = brute_force::random_unit_vector(rng).cross(dir) *
                        std::pow(10.0, brute_force::uniform(rng, -12, -3));
      const Vec3 start =
          a.point(brute_force::uniform(rng, -0.5, 1.5)) +
          scale * brute_force::uniform(rng, 0, 0.3) * brute_force::random_unit_vector(rng);
      b = {start, start + scale * brute_force::uniform(rng, 0.1, 2) * (dir + tilt)};
    } else {
      const Vec3 start =
          origin + scale * Vec3(brute_force::uniform(rng, -1, 1), brute_force::uniform(rng, -1, 1),
                                brute_force::uniform(rng, -1, 1));
      b = {start,
           start + scale * brute_force::uniform(rng, 0, 2) * brute_force::random_unit_vector(rng)};
    }
    const sc::PieceClosestPoints c = sc::closest_points(a, b);
    const brute_force::Result ref =
        brute_force::curve_distance(brute_force::as_curve(a), brute_force::as_curve(b));
    const double tol = 1e-9 * scale;
    const bool ok =
        c.distance <= ref.distance + 16 * kEps * scale && c.distance >= ref.distance - tol;
    if (!ok) {
      ADD_FAILURE() << "pair " << i << " scale " << scale << ": exact " << c.distance
                    << " brute force " << ref.distance;
      if (++failures > 5) break;
    }
    expect_consistent(a, b, c, 3 * scale);
  }
}

// (a, b) and (b, a) run the same arithmetic unless the lengths tie: mirrored results.
TEST(SegmentDistance, ArgumentOrderMirrorsExactly) {
  brute_force::Rng rng(7);
  for (int i = 0; i < 1000; ++i) {
    const Segment a{brute_force::random_unit_vector(rng),
                    2.0 * brute_force::random_unit_vector(rng)};
    const Segment b{brute_force::random_unit_vector(rng), -brute_force::random_unit_vector(rng)};
    const sc::PieceClosestPoints ab = sc::closest_points(a, b), ba = sc::closest_points(b, a);
    EXPECT_EQ(ab.distance, ba.distance);
    EXPECT_EQ(ab.parameter_a, ba.parameter_b);
    EXPECT_EQ(ab.parameter_b, ba.parameter_a);
    EXPECT_EQ(ab.point_a, ba.point_b);
  }
}

// ---------------------------------------------------------------------------------------
// Line contacts (line_contact.hpp): where the force of a near-parallel pair acts.

namespace {

// a along z on [-1/2, 1/2]; b through (1, 0, 0) along (-sin alpha, 0, cos alpha), 3 long, so a
// projects inside b. The gap from a's point at height z to b's line is cos(alpha) - z sin(alpha)
// (exactly linear), smallest at z = 1/2; with c = sin(alpha) / width the weights are
// w(z) = 1 - c (1/2 - z) (all positive for c < 1) and their centroid is
// z_w = int z w / int w = (c / 12) / (1 - c / 2).
Segment unit_a() { return {Vec3(0, 0, -0.5), Vec3(0, 0, 0.5)}; }
Segment tilted_b(double alpha) {
  const Vec3 u(-std::sin(alpha), 0.0, std::cos(alpha));
  return {Vec3(1, 0, 0) - 1.5 * u, Vec3(1, 0, 0) + 1.5 * u};
}
double centroid_height(double alpha, double width) {
  const double c = std::sin(alpha) / width;
  return (c / 12.0) / (1.0 - 0.5 * c);
}

}  // namespace

TEST(LineContact, ParallelSegmentsMeetAtTheMiddleOfTheOverlap) {
  // a on z in [0, 1], b on z in [0.2, 2.2] one unit away along x: overlap z in [0.2, 1].
  const Segment a{Vec3(0, 0, 0), Vec3(0, 0, 1)}, b{Vec3(1, 0, 0.2), Vec3(1, 0, 2.2)};
  const auto c = sc::line_contact(a, b, {0.1, 0.05});
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->parameter_a, 0.6, 1e-14);
  EXPECT_NEAR(c->parameter_b, 0.2, 1e-14);
  EXPECT_NEAR((c->point_a - Vec3(0, 0, 0.6)).norm(), 0.0, 1e-14);
  EXPECT_NEAR((c->point_b - Vec3(1, 0, 0.6)).norm(), 0.0, 1e-14);
  EXPECT_NEAR((c->normal - Vec3(1, 0, 0)).norm(), 0.0, 1e-14);
  EXPECT_EQ(c->share, 1.0);
}

TEST(LineContact, SmallTiltMovesTheForceToTheWeightedCentroid) {
  for (const double alpha : {1e-3, 1e-2, -1e-2}) {
    for (const double width : {0.1, 1.0}) {
      SCOPED_TRACE(std::to_string(alpha) + " width " + std::to_string(width));
      const auto c = sc::line_contact(unit_a(), tilted_b(alpha), {width, 0.05});
      ASSERT_TRUE(c.has_value());
      // alpha < 0 mirrors the gap: closest at z = -1/2, centroid at -z_w.
      const double expected = (alpha > 0 ? 1.0 : -1.0) * centroid_height(std::abs(alpha), width);
      // The 64-point midpoint rule integrates z w (quadratic) with relative error h^2 = 2.4e-4.
      EXPECT_NEAR(c->point_a.z(), expected, 3e-4 * std::abs(expected) + 1e-15);
      EXPECT_NEAR(c->point_a.x(), 0.0, 1e-15);
      // The point on b is a's point projected onto b, and the normal is their separation.
      const Vec3 sep = c->point_b - c->point_a;
      EXPECT_NEAR(sep.dot(tilted_b(alpha).p1 - tilted_b(alpha).p0), 0.0, 1e-12);
      EXPECT_NEAR((c->normal - sep.normalized()).norm(), 0.0, 1e-14);
    }
  }
}

TEST(LineContact, SpreadingFadesBetweenOneAndTwoAnglesAndIsGoneBeyond) {
  const double angle = 0.05, width = 0.1;
  // alpha = 1.5 angle: half the spread point, half the closest point (z = 1/2, a's end).
  const double alpha = 1.5 * angle;
  const auto c = sc::line_contact(unit_a(), tilted_b(alpha), {width, angle});
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->share, 0.5, 1e-12);
  EXPECT_NEAR(c->point_a.z(), 0.5 * 0.5 + 0.5 * centroid_height(alpha, width), 3e-4 * 0.3);
  EXPECT_FALSE(sc::line_contact(unit_a(), tilted_b(2.0 * angle + 1e-9), {width, angle}).has_value());
  // Crossing segments: none.
  EXPECT_FALSE(sc::line_contact(unit_a(), Segment{Vec3(1, -1, 0), Vec3(1, 1, 0)}, {width, angle}).has_value());
  // End to end (no overlap of the projections): none.
  EXPECT_FALSE(sc::line_contact(unit_a(), Segment{Vec3(0, 0, 1), Vec3(0, 0, 2)}, {width, angle}).has_value());
}

TEST(LineContact, ContinuousThroughParallelAndMirroredWhenSwapped) {
  // The closest points jump from one end of the overlap to the other as alpha passes 0; the
  // line contact moves by O(alpha).
  const auto minus = sc::line_contact(unit_a(), tilted_b(-1e-9), {1.0, 0.05});
  const auto plus = sc::line_contact(unit_a(), tilted_b(1e-9), {1.0, 0.05});
  ASSERT_TRUE(minus && plus);
  EXPECT_LT((minus->point_a - plus->point_a).norm(), 1e-9);
  EXPECT_GT((sc::closest_points(unit_a(), tilted_b(-1e-9)).point_a - sc::closest_points(unit_a(), tilted_b(1e-9)).point_a).norm(),
            0.5);
  const auto swapped = sc::line_contact(tilted_b(1e-2), unit_a(), {1.0, 0.05});
  const auto straight = sc::line_contact(unit_a(), tilted_b(1e-2), {1.0, 0.05});
  ASSERT_TRUE(swapped && straight);
  EXPECT_EQ(swapped->point_a, straight->point_b);
  EXPECT_EQ(swapped->point_b, straight->point_a);
  EXPECT_EQ(swapped->normal, Vec3(-straight->normal));
  EXPECT_THROW((void)sc::line_contact(unit_a(), tilted_b(0.0), {0.0, 0.05}), std::invalid_argument);
}

}  // namespace segment_distance_tests
