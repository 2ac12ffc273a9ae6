#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "geometry/brute_force.hpp"
#include "stokescontact/geometry/arc_distance.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace arc_distance_tests {

namespace sc = stokescontact;
using sc::Arc;
using sc::Segment;
using sc::Vec3;

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kPi = std::numbers::pi;

// The quarter of the unit circle in the xy plane from +x to +y.
const Arc kQuarter{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1.0, 0.5 * kPi};

Arc rotated_in_plane(Arc a, double angle) {
  const Vec3 e1 = std::cos(angle) * a.e1 + std::sin(angle) * a.e2;
  a.e2 = a.axis().cross(e1);
  a.e1 = e1;
  return a;
}

Arc moved(Arc a, const Vec3& shift) {
  a.centre += shift;
  return a;
}

Arc random_arc(brute_force::Rng& rng, double scale) {
  const sc::Quat q = brute_force::random_rotation(rng);
  return {scale * Vec3(brute_force::uniform(rng, -1, 1), brute_force::uniform(rng, -1, 1),
                       brute_force::uniform(rng, -1, 1)),
          q * Vec3::UnitX(), q * Vec3::UnitY(), scale * brute_force::uniform(rng, 0.2, 1.5),
          brute_force::uniform(rng, 0.05, 2.0 * kPi)};
}

Segment random_segment(brute_force::Rng& rng, double scale) {
  const Vec3 p0 =
      scale * Vec3(brute_force::uniform(rng, -1.5, 1.5), brute_force::uniform(rng, -1.5, 1.5),
                   brute_force::uniform(rng, -1.5, 1.5));
  return {p0,
          p0 + scale * brute_force::uniform(rng, 0.0, 3.0) * brute_force::random_unit_vector(rng)};
}

Segment scaled(const Segment& s, double k) { return {k * s.p0, k * s.p1}; }
Arc scaled(Arc a, double k) {
  a.centre *= k;
  a.radius *= k;
  return a;
}

Vec3 point_on(const Segment& s, double p) { return s.point(p); }
Vec3 point_on(const Arc& a, double p) { return a.point(p); }
double end_of(const Segment&) { return 1.0; }
double end_of(const Arc& a) { return a.angle; }

// Parameters in range, points on their pieces, distance = the points' separation.
template <typename A, typename B>
void expect_consistent(const A& a, const B& b, const sc::PieceClosestPoints& c, double scale) {
  EXPECT_GE(c.parameter_a, 0.0);
  EXPECT_LE(c.parameter_a, end_of(a));
  EXPECT_GE(c.parameter_b, 0.0);
  EXPECT_LE(c.parameter_b, end_of(b));
  EXPECT_LE((c.point_a - point_on(a, c.parameter_a)).norm(), 16 * kEps * scale);
  EXPECT_LE((c.point_b - point_on(b, c.parameter_b)).norm(), 16 * kEps * scale);
  EXPECT_NEAR((c.point_b - c.point_a).norm(), c.distance, 16 * kEps * scale);
}

// Distance against a known value at several scales, both argument orders.
template <typename A, typename B>
void expect_distance(const A& a0, const B& b0, double expected) {
  constexpr double tol = 64.0;  // units of rounding at the scale
  for (const double k : {1e-6, 1.0, 1e6}) {
    SCOPED_TRACE(testing::Message() << "scale " << k);
    const A a = scaled(a0, k);
    const B b = scaled(b0, k);
    const sc::PieceClosestPoints c = sc::closest_points(a, b);
    EXPECT_NEAR(c.distance, k * expected, tol * kEps * k);
    expect_consistent(a, b, c, 4 * k);
    EXPECT_NEAR(sc::closest_points(b, a).distance, c.distance, tol * kEps * k);
  }
}

// Random pairs against the brute force: never worse than a realised pair, and within the
// refinement's accuracy of it.
template <typename A, typename B>
int compare_with_brute_force(const A& a, const B& b, double scale, int index) {
  const sc::PieceClosestPoints c = sc::closest_points(a, b);
  const brute_force::Result ref =
      brute_force::curve_distance(brute_force::as_curve(a), brute_force::as_curve(b));
  expect_consistent(a, b, c, 4 * scale);
  if (c.distance <= ref.distance + 64 * kEps * scale && c.distance >= ref.distance - 1e-9 * scale)
    return 0;
  ADD_FAILURE() << "pair " << index << " scale " << scale << ": exact " << c.distance
                << " brute force " << ref.distance;
  return 1;
}

}  // namespace

TEST(ArcDistance, PointAgainstArcIsClosedForm) {
  const Segment p{Vec3(2, 2, 1), Vec3(2, 2, 1)};
  const sc::PieceClosestPoints c = sc::closest_points(p, kQuarter);
  EXPECT_DOUBLE_EQ(c.distance, sc::closest_point(kQuarter, p.p0).distance);
  EXPECT_NEAR(c.parameter_b, 0.25 * kPi, 1e-15);
  // So is a segment too short for its squared length to be a normal double.
  const Segment tiny{Vec3(2, 2, 0), Vec3(2, 2, 1e-160)};
  EXPECT_EQ(sc::closest_points(kQuarter, tiny).distance,
            sc::closest_point(kQuarter, tiny.p0).distance);
}

TEST(ArcDistance, SegmentCrossingArc) {
  expect_distance(Segment{Vec3(0.5, 0.5, 0), Vec3(1, 1, 0)}, kQuarter, 0.0);
  const double h = std::sqrt(0.5);  // through the plane at (h, h, 0), on the arc
  expect_distance(Segment{Vec3(h - 0.1, h - 0.1, -1), Vec3(h + 0.1, h + 0.1, 1)}, kQuarter, 0.0);
}

TEST(ArcDistance, SegmentTangentToArc) {
  const double h = std::sqrt(0.5);
  expect_distance(Segment{Vec3(h - 1, h + 1, 0), Vec3(h + 1, h - 1, 0)}, kQuarter, 0.0);
  expect_distance(Segment{Vec3(h - 1, h + 1, 0.1), Vec3(h + 1, h - 1, 0.1)}, kQuarter, 0.1);
  expect_distance(Segment{Vec3(h - 1, h + 1, 0), Vec3(h + 1, h - 1, 0)},
                  moved(kQuarter, Vec3(-0.25 * h, -0.25 * h, 0)), 0.25);
}

TEST(ArcDistance, SegmentThroughCentreInPlane) {
  expect_distance(Segment{Vec3(-2, -2, 0), Vec3(2, 2, 0)}, kQuarter, 0.0);
  expect_distance(Segment{Vec3(-2, -2, 0), Vec3(0.1, 0.1, 0)}, kQuarter,
                  1.0 - 0.1 * std::sqrt(2.0));
}

// Every arc point is the same distance from a segment on the axis: f is constant in t.
TEST(ArcDistance, SegmentOnTheAxis) {
  expect_distance(Segment{Vec3(0, 0, -1), Vec3(0, 0, 1)}, kQuarter, 1.0);
  expect_distance(Segment{Vec3(0, 0, 0.5), Vec3(0, 0, 2)}, kQuarter, std::hypot(1.0, 0.5));
}

TEST(ArcDistance, SegmentNearestToAnArcEnd) {
  // Beyond the arc's start, below the x axis: the end (1, 0, 0) is nearest.
  expect_distance(Segment{Vec3(2, -1, 0), Vec3(2, -3, 0)}, kQuarter, std::sqrt(2.0));
  // Beyond the end at (0, 1, 0), the segment's own end nearest.
  expect_distance(Segment{Vec3(-1, 1, 0), Vec3(-3, 1, 0)}, kQuarter, 1.0);
}

TEST(ArcDistance, SegmentInsideFullCircle) {
  const Arc circle{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1.0, 2.0 * kPi};
  expect_distance(Segment{Vec3(-0.3, 0.2, 0), Vec3(0.4, 0.2, 0)}, circle,
                  1.0 - std::hypot(0.4, 0.2));
}

TEST(ArcDistance, ArcsCoaxialStacked) {
  expect_distance(kQuarter, moved(kQuarter, Vec3(0, 0, 0.3)), 0.3);
  expect_distance(kQuarter, moved(rotated_in_plane(kQuarter, 0.4), Vec3(0, 0, 0.3)), 0.3);
}

TEST(ArcDistance, ArcsConcentricCoplanar) {
  Arc outer = rotated_in_plane(kQuarter, 0.2);
  outer.radius = 1.5;
  expect_distance(kQuarter, outer, 0.5);
  outer.centre.z() = 0.2;  // and coaxial at another radius
  expect_distance(kQuarter, outer, std::hypot(0.5, 0.2));
}

TEST(ArcDistance, ArcsOnTheSameCircle) {
  expect_distance(kQuarter, rotated_in_plane(kQuarter, 0.3), 0.0);             // overlapping
  expect_distance(kQuarter, rotated_in_plane(kQuarter, 0.5 * kPi), 0.0);       // end to end
  expect_distance(kQuarter, rotated_in_plane(kQuarter, kPi), std::sqrt(2.0));  // disjoint
  expect_distance(kQuarter, moved(rotated_in_plane(kQuarter, 0.3), Vec3(0, 0, 1e-9)), 1e-9);
}

TEST(ArcDistance, ArcsCrossing) {
  // Touching at an end of each: kQuarter's start (1, 0, 0).
  const Arc vertical{Vec3(0.5, 0.5, 0), Vec3(1, -1, 0).normalized(), Vec3::UnitZ(), std::sqrt(0.5),
                     0.5 * kPi};
  expect_distance(kQuarter, vertical, 0.0);
  // A unit circle through the z axis and kQuarter's midpoint p, crossing it inside both arcs.
  const Vec3 p = Vec3(1, 1, 0).normalized();
  const double c = std::cos(0.3), s = std::sin(0.3);
  const Arc tilted{Vec3::Zero(), c * p - s * Vec3::UnitZ(), s * p + c * Vec3::UnitZ(), 1.0, 1.0};
  expect_distance(kQuarter, tilted, 0.0);
  expect_distance(kQuarter, moved(tilted, 0.1 * p), 0.1);  // pushed out along p
}

// Where curves cross at a small angle theta, f falls to 0 at a slope of only ~ R theta,
// the shallowest valleys there are; the distance must still come out 0 to rounding. Issue
// 16's case: arc a and the same arc turned by theta about a line in its plane through its
// centre share the point where the line meets them. Before: up to 1.9e-9 (theta = 1e-8).
TEST(ArcDistance, ArcsCrossingAtSmallAnglesMeetExactly) {
  const Arc a{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 0.5, 0.5 * kPi};
  const Vec3 line(std::cos(kPi / 8), std::sin(kPi / 8), 0.0);
  for (double theta = 1e-12; theta <= 1.5e-3; theta *= 10.0) {
    const Eigen::AngleAxisd turn(theta, line);
    Arc b = a;
    b.e1 = turn * a.e1, b.e2 = turn * a.e2;
    for (const double k : {1e-6, 1.0, 1e6}) {
      SCOPED_TRACE(testing::Message() << "theta " << theta << " scale " << k);
      const Arc ak = scaled(a, k), bk = scaled(b, k);
      EXPECT_LE(sc::closest_points(ak, bk).distance, 4 * kEps * k);
      EXPECT_LE(sc::closest_points(bk, ak).distance, 4 * kEps * k);
    }
  }
}

// The same with the turning line through an arc point P in the arc's plane at an angle to
// the radius, so that b crosses a at P (and where the line leaves the circle), and b's
// centre moves off a's: the valleys at those crossings are as shallow.
TEST(ArcDistance, TurnedCopiesMeetExactly) {
  const Arc a{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 0.5, 0.5 * kPi};
  for (const double t : {0.3, 0.92, 1.4}) {
    for (const double phi : {0.4, 1.2, 2.2, 4.0}) {
      for (double theta = 1e-12; theta <= 1.5e-3; theta *= 10.0) {
        SCOPED_TRACE(testing::Message() << "t " << t << " phi " << phi << " theta " << theta);
        const Vec3 p = a.point(t);
        const Vec3 line = std::cos(phi) * p.normalized() + std::sin(phi) * a.tangent(t);
        const Eigen::AngleAxisd turn(theta, line);
        const Arc b{p - turn * p, turn * a.e1, turn * a.e2, a.radius, a.angle};
        EXPECT_LE(sc::closest_points(a, b).distance, 4 * kEps);
        EXPECT_LE(sc::closest_points(b, a).distance, 4 * kEps);
      }
    }
  }
}

// A segment through an arc point P at a small angle alpha to the tangent there, tilted in
// the arc's plane (it crosses the circle again at ~ 2 alpha) or out of it. Before: up to
// 3e-11 short of 0.
TEST(ArcDistance, SegmentNearlyTangentThroughAnArcPointMeetsIt) {
  const Arc a{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 0.5, 0.5 * kPi};
  for (const double t : {0.1, kPi / 8, 1.0, 1.5}) {
    const Vec3 p = a.point(t), tangent = a.tangent(t), radial = p.normalized();
    const Vec3 tilts[] = {radial, -radial, Vec3::UnitZ(), (radial + Vec3::UnitZ()).normalized()};
    for (const Vec3& tilt : tilts) {
      for (const double alpha : {0.0, 1e-12, 1e-10, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2}) {
        const Vec3 d = (std::cos(alpha) * tangent + std::sin(alpha) * tilt).normalized();
        for (const double k : {1e-6, 1.0, 1e6}) {
          SCOPED_TRACE(testing::Message() << "t " << t << " tilt " << tilt.transpose() << " alpha "
                                          << alpha << " scale " << k);
          const Segment s = scaled(Segment{p - 0.3 * d, p + 0.45 * d}, k);
          const Arc ak = scaled(a, k);
          EXPECT_LE(sc::closest_points(s, ak).distance, 4 * kEps * k);
          EXPECT_LE(sc::closest_points(ak, s).distance, 4 * kEps * k);
        }
      }
    }
  }
}

// Two linked unit rings, each through the other's centre: every point of one is exactly
// 1 from the other (a degenerate, constant f the search must still settle).
TEST(ArcDistance, LinkedRings) {
  const Arc a{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1.0, 2.0 * kPi};
  const Arc b{Vec3(1, 0, 0), Vec3::UnitX(), Vec3::UnitZ(), 1.0, 2.0 * kPi};
  expect_distance(a, b, 1.0);
}

TEST(ArcDistance, ZeroAngleArcIsAPoint) {
  Arc p = kQuarter;
  p.angle = 0.0;
  expect_distance(Segment{Vec3(1, 2, 0), Vec3(3, 2, 0)}, p, 2.0);
  expect_distance(p, rotated_in_plane(kQuarter, kPi), std::sqrt(2.0));
}

// A cutoff below the distance may end the search early but never reports less than it.
TEST(ArcDistance, CutoffOnlySkipsWhatCannotWin) {
  brute_force::Rng rng(99);
  for (int i = 0; i < 2000; ++i) {
    const Arc a = random_arc(rng, 1.0), b = random_arc(rng, 1.0);
    const Segment s = random_segment(rng, 1.0);
    const sc::PieceClosestPoints ab = sc::closest_points(a, b);
    EXPECT_GE(sc::closest_points(a, b, 0.5 * ab.distance).distance, 0.5 * ab.distance);
    EXPECT_EQ(sc::closest_points(a, b, 2.0 * ab.distance + 1e-3).distance, ab.distance);
    const sc::PieceClosestPoints sa = sc::closest_points(s, a);
    EXPECT_GE(sc::closest_points(s, a, 0.5 * sa.distance).distance, 0.5 * sa.distance);
    EXPECT_EQ(sc::closest_points(s, a, 2.0 * sa.distance + 1e-3).distance, sa.distance);
  }
}

TEST(ArcDistance, RandomSegmentArcPairsMatchBruteForce) {
  brute_force::Rng rng(314159);
  int failures = 0;
  for (int i = 0; i < brute_force::random_pairs(20000) && failures < 5; ++i) {
    const double scale = std::pow(10.0, brute_force::uniform(rng, -6.0, 6.0));
    const Arc a = random_arc(rng, scale);
    Segment s = random_segment(rng, scale);
    if (i % 4 == 0) {  // through the bend's inside, near the centre
      const Vec3 p = a.centre + 0.5 * a.radius * brute_force::random_unit_vector(rng);
      s = {p - a.radius * brute_force::random_unit_vector(rng),
           p + a.radius * brute_force::random_unit_vector(rng)};
    }
    failures +=
        i % 2 ? compare_with_brute_force(s, a, scale, i) : compare_with_brute_force(a, s, scale, i);
  }
}

TEST(ArcDistance, RandomArcArcPairsMatchBruteForce) {
  brute_force::Rng rng(271828);
  int failures = 0;
  for (int i = 0; i < brute_force::random_pairs(20000) && failures < 5; ++i) {
    const double scale = std::pow(10.0, brute_force::uniform(rng, -6.0, 6.0));
    const Arc a = random_arc(rng, scale);
    Arc b = random_arc(rng, scale);
    if (i % 4 == 0)
      b.centre =
          a.centre + 0.3 * scale * brute_force::random_unit_vector(rng);  // close, often linked
    if (i % 8 == 1)
      b = moved(rotated_in_plane(a, brute_force::uniform(rng, -1, 1)),
                0.05 * scale * a.axis());  // nearly coaxial
    failures += compare_with_brute_force(a, b, scale, i);
  }
}

TEST(ArcDistance, ArgumentOrderGivesTheSameDistance) {
  brute_force::Rng rng(5);
  for (int i = 0; i < 2000; ++i) {
    const Arc a = random_arc(rng, 1.0), b = random_arc(rng, 1.0);
    const Segment s = random_segment(rng, 1.0);
    const sc::PieceClosestPoints ab = sc::closest_points(a, b), ba = sc::closest_points(b, a);
    EXPECT_NEAR(ab.distance, ba.distance, 1e-12);
    const sc::PieceClosestPoints sa = sc::closest_points(s, a), as = sc::closest_points(a, s);
    EXPECT_EQ(sa.distance, as.distance);  // the same search, mirrored
    EXPECT_EQ(sa.point_a, as.point_b);
  }
}

}  // namespace arc_distance_tests
