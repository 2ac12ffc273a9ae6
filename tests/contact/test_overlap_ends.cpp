// Near-parallel rods held at both ends of their overlap (geometry/overlap_ends.hpp,
// ContactDirections::overlap_ends): the ends found, their gaps against brute force, and one
// contact step of a symmetric and of a tilted pair.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/dynamics/background_flow.hpp"
#include "stokescontact/geometry/overlap_ends.hpp"
#include "stokescontact/mobility/free_draining.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace overlap_ends_tests {

namespace sc = stokescontact;

namespace {

// The smallest distance from points of a's overlap with b to segment b, sampled finely.
double sampled_overlap_minimum(const sc::Segment& a, const sc::Segment& b, double lo, double hi) {
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= 20000; ++k)
    best = std::min(best, sc::closest_point(b, a.point(lo + (hi - lo) * k / 20000.0)).distance);
  return best;
}

}  // namespace

TEST(OverlapEnds, EndsOfSideBySideAndStaggeredSegments) {
  const sc::Segment a{sc::Vec3(0, 0, 0), sc::Vec3(2, 0, 0)};
  // Side by side, same extent: a's own ends (ties go to a).
  auto ends = sc::overlap_ends(a, {sc::Vec3(0, 1, 0), sc::Vec3(2, 1, 0)}, 0.1, 0.5);
  ASSERT_TRUE(ends);
  EXPECT_EQ((*ends)[0].segment, 0);
  EXPECT_EQ((*ends)[0].end, 0);
  EXPECT_EQ((*ends)[1].segment, 0);
  EXPECT_EQ((*ends)[1].end, 1);
  // Staggered, b reversed: the overlap [1, 2] of a starts at b's p1 and ends at a's p1.
  ends = sc::overlap_ends(a, {sc::Vec3(3, 1, 0), sc::Vec3(1, 1, 0)}, 0.1, 0.5);
  ASSERT_TRUE(ends);
  EXPECT_EQ((*ends)[0].segment, 1);
  EXPECT_EQ((*ends)[0].end, 1);
  EXPECT_EQ((*ends)[1].segment, 0);
  EXPECT_EQ((*ends)[1].end, 1);
  // b inside a: both ends are b's.
  ends = sc::overlap_ends(a, {sc::Vec3(0.5, 1, 0), sc::Vec3(1.5, 1, 0)}, 0.1, 0.5);
  ASSERT_TRUE(ends);
  EXPECT_EQ((*ends)[0].segment, 1);
  EXPECT_EQ((*ends)[1].segment, 1);
  // Not a line contact: crossing at 0.2 rad, an overlap of 0.3 < 0.5, no overlap, a point.
  EXPECT_FALSE(sc::overlap_ends(a, {sc::Vec3(0, 1, 0), sc::Vec3(2, 1 + 2 * std::tan(0.2), 0)}, 0.1, 0.5));
  EXPECT_FALSE(sc::overlap_ends(a, {sc::Vec3(1.7, 1, 0), sc::Vec3(3, 1, 0)}, 0.1, 0.5));
  EXPECT_FALSE(sc::overlap_ends(a, {sc::Vec3(3, 1, 0), sc::Vec3(4, 1, 0)}, 0.1, 0.5));
  EXPECT_FALSE(sc::overlap_ends(a, {sc::Vec3(1, 1, 0), sc::Vec3(1, 1, 0)}, 0.1, 0.5));
}

// For random near-parallel pairs that do not cross inside the overlap, the smaller of the two
// end gaps is the smallest gap over the overlap (the gap is convex along it), checked against
// 20001 samples; for every pair each end gap is a point pair's and not below d^P.
TEST(OverlapEnds, EndGapsBoundTheOverlapFromBelow) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const sc::Segment a{sc::Vec3(u(rng), u(rng), u(rng)), sc::Vec3(3 + u(rng), u(rng), u(rng))};
    const sc::Vec3 shift(u(rng), 1.0 + 0.5 * u(rng), 0.5 * u(rng));
    const sc::Vec3 tilt = 0.05 * sc::Vec3(u(rng), u(rng), u(rng));
    const sc::Segment b{a.p0 + shift + sc::Vec3(u(rng), 0, 0), a.p1 + shift + tilt};
    const auto ends = sc::overlap_ends(a, b, 0.1, 0.1);
    if (!ends) continue;
    const sc::PieceClosestPoints closest = sc::closest_points(a, b);
    const sc::PieceClosestPoints low = sc::end_to_segment(a, b, (*ends)[0]);
    const sc::PieceClosestPoints high = sc::end_to_segment(a, b, (*ends)[1]);
    // Each end gap is the gap of a point pair: the true distance never exceeds it.
    EXPECT_GE(low.distance, closest.distance - 1e-12);
    EXPECT_GE(high.distance, closest.distance - 1e-12);
    EXPECT_NEAR(low.distance, (low.point_b - low.point_a).norm(), 1e-12);
    // The overlap on a, from the ends' parameters on a.
    const double lo = low.parameter_a, hi = high.parameter_a;
    ASSERT_LE(lo, hi);
    const double sampled = sampled_overlap_minimum(a, b, lo, hi);
    const bool crossing_inside = closest.parameter_a > lo + 1e-9 && closest.parameter_a < hi - 1e-9 &&
                                 closest.parameter_b > 1e-9 && closest.parameter_b < 1.0 - 1e-9;
    if (!crossing_inside) {
      EXPECT_NEAR(std::min(low.distance, high.distance), sampled, 1e-6) << "trial " << trial;
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

// Centre line b beside centre line a (1.01 apart at b's p0, b tilted by 0.01 so that the pair
// is closest at its low side) slid down along a by `slide`: for slide < 0 b's p0 is the
// overlap's low end, for slide > 0 a's p0 is. The end found at slide = -0.1 (b's p0) measures
// the gap at the overlap's low end, here the pair's distance (closest_points), through the
// passage and beyond, continuously: at slide = 0.1 the distance of a's p0 to b's line,
// (1.01 + 0.01 x 0.1) / sqrt(1 + 0.01^2). b's p0 alone measures the distance of the two rod
// ends there, sqrt(1.01^2 + 0.1^2): 0.0049 too far, half a d_hat of 0.01. With b's ends
// swapped (b pointing down) the same.
TEST(OverlapEnds, EndGapFollowsTheOverlapEndFromOneRodToTheOther) {
  const double tilt = 0.01, gap = 1.01;
  const sc::Segment a{sc::Vec3(0, 0, 0), sc::Vec3(0, 0, 5)};
  const auto b_at = [&](double slide, bool reversed) {
    const sc::Vec3 p0(gap, 0, -slide), p1(gap + 5 * tilt, 0, 5 - slide);
    return reversed ? sc::Segment{p1, p0} : sc::Segment{p0, p1};
  };
  for (const bool reversed : {false, true}) {
    const auto ends = sc::overlap_ends(a, b_at(-0.1, reversed), 0.1, 0.1);
    ASSERT_TRUE(ends);
    const sc::SegmentEnd low = (*ends)[0];
    EXPECT_EQ(low.segment, 1);
    EXPECT_EQ(low.end, reversed ? 1 : 0);
    double largest_step = 0.0, previous = sc::overlap_end_gap(a, b_at(-0.1, reversed), low).distance;
    for (int k = -1000; k <= 1000; ++k) {
      const sc::Segment b = b_at(1e-4 * k, reversed);
      const double measured = sc::overlap_end_gap(a, b, low).distance;
      EXPECT_NEAR(measured, sc::closest_points(a, b).distance, 1e-12) << "slide " << 1e-4 * k;
      largest_step = std::max(largest_step, std::abs(measured - previous));
      previous = measured;
    }
    EXPECT_LT(largest_step, 2e-6);  // continuous: steps of 1e-4 move it by at most tilt x 1e-4
    const sc::Segment b = b_at(0.1, reversed);
    EXPECT_NEAR(sc::overlap_end_gap(a, b, low).distance, (gap + tilt * 0.1) / std::sqrt(1 + tilt * tilt), 1e-14);
    EXPECT_NEAR(sc::end_to_segment(a, b, low).distance, std::sqrt(gap * gap + 0.01), 1e-14);
    EXPECT_EQ(sc::same_side_end(a, b, low).segment, 0);
    EXPECT_EQ(sc::same_side_end(a, b, low).end, 0);
    EXPECT_EQ(sc::same_side_end(a, b, {0, 1}).end, reversed ? 0 : 1);
  }
}

namespace {

const sc::Spherocylinder kRod{4.0, 0.5};
constexpr double kForce = 100.0, kDt = 0.01, kDHat = 0.01;

sc::Pose rod_along_x(double y, double turn = 0.0, const sc::Vec3& frame = sc::Vec3::Zero()) {
  return {frame + sc::Vec3(0.0, y, 0.0), sc::Quat(Eigen::AngleAxisd(turn, sc::Vec3::UnitZ())) *
                                     sc::Quat(Eigen::AngleAxisd(0.5 * std::numbers::pi, sc::Vec3::UnitY()))};
}

// Two rods along x, the second turned by `turn` about z, pressed together by +-kForce
// along y; free draining.
struct Pair {
  std::vector<sc::Spherocylinder> shapes{kRod};
  std::vector<sc::Pose> poses;
  sc::FreeDrainingMobility mobility{sc::spherocylinder_mobility(kRod, 1.0), 2, 6};
  sc::VecX U;

  Pair(double gap, double turn, const sc::Vec3& frame = sc::Vec3::Zero()) {
    poses = {rod_along_x(0.0, 0.0, frame), rod_along_x(2.0 * kRod.radius + gap, turn, frame)};
    sc::VecX F = sc::VecX::Zero(12);
    F(1) = kForce;
    F(7) = -kForce;
    mobility.set_configuration(poses);
    U = mobility.apply(F);
  }
  sc::ContactStepProblem<sc::Spherocylinder> problem() const { return {shapes, poses, U, kDt, kDHat, 0.0, 1.0, {}}; }
};

sc::ContactStepOptions overlap_ends() {
  sc::ContactStepOptions o;
  o.directions = sc::ContactDirections::overlap_ends;
  return o;
}

double max_spin(const sc::ContactStepResult& r) {
  return std::max(r.velocities.segment<3>(3).norm(), r.velocities.segment<3>(9).norm());
}

// The signed angle of rod 1 to rod 0 about z.
double relative_turn(const std::vector<sc::Pose>& poses) {
  const sc::Vec3 a = poses[0].q * sc::Vec3::UnitZ(), b = poses[1].q * sc::Vec3::UnitZ();
  return std::atan2(a.cross(b).z(), a.dot(b));
}

}  // namespace

// Exactly parallel: one contact at each end of the overlap, equal forces summing to the
// exact force of the pair, lambda = f + (target - g0) / (2 dt mu_perp) (test_parallel_rods.cpp),
// and no spin; also with the frame shifted by 1e4 along every axis.
TEST(OverlapEnds, ParallelPairGetsEqualEndForcesAndNoSpin) {
  for (const auto& [name, solver] : {std::pair<const char*, sc::ContactSolver>{"default", sc::DefectCorrectionOptions{}},
                                     {"lcp-newton", sc::LcpSequenceOptions{}}})
  for (const double shift : {0.0, 1e4}) {
    SCOPED_TRACE(std::string(name) + " frame " + std::to_string(shift));
    Pair s(kDHat, 0.0, sc::Vec3::Constant(shift));
    const sc::ContactStepResult r = sc::solve_contact_step(s.problem(), s.mobility, overlap_ends(), solver);
    ASSERT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
    ASSERT_EQ(r.lambda.size(), 2);
    EXPECT_TRUE(r.pairs[0].segment_end && r.pairs[1].segment_end);
    const double target = std::holds_alternative<sc::DefectCorrectionOptions>(solver)
                              ? kDHat * (1.0 + sc::DefectCorrectionOptions{}.margin) : kDHat;
    const double mu = sc::spherocylinder_mobility(kRod, 1.0)(0, 0);
    const double exact = kForce + (target - kDHat) / (2.0 * kDt * mu);
    EXPECT_NEAR(r.lambda.sum(), exact, 1e-4 * exact);
    EXPECT_NEAR(r.lambda(0), r.lambda(1), 1e-4 * exact);
    EXPECT_LT(max_spin(r), 1e-8);
    EXPECT_GE(r.min_distance_ratio, 1.0 - 1e-3);
  }
}

// The same pair across the side of a periodic box (cube of side 12): rod 1 at y = 11.29 meets
// rod 0 at y = 0.3 through its image at y = -0.71, gap d_hat; pressed together across the side.
TEST(OverlapEnds, ParallelPairAcrossAPeriodicSide) {
  Pair s(kDHat, 0.0);
  s.poses = {rod_along_x(0.3), rod_along_x(0.3 - 2.0 * kRod.radius - kDHat + 12.0)};
  sc::VecX F = sc::VecX::Zero(12);
  F(1) = -kForce;
  F(7) = kForce;
  s.mobility.set_configuration(s.poses);
  s.U = s.mobility.apply(F);
  const sc::ContactStepProblem<sc::Spherocylinder> problem{s.shapes, s.poses, s.U, kDt, kDHat, 0.0, 1.0,
                                                           sc::PeriodicBox{sc::Vec3::Constant(12.0)}};
  const sc::ContactStepResult r = sc::solve_contact_step(problem, s.mobility, overlap_ends(), sc::ContactSolver{});
  ASSERT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
  ASSERT_EQ(r.lambda.size(), 2);
  const double mu = sc::spherocylinder_mobility(kRod, 1.0)(0, 0);
  const double exact = kForce + kDHat * sc::DefectCorrectionOptions{}.margin / (2.0 * kDt * mu);
  EXPECT_NEAR(r.lambda.sum(), exact, 1e-4 * exact);
  EXPECT_NEAR(r.lambda(0), r.lambda(1), 1e-4 * exact);
  EXPECT_LT(max_spin(r), 1e-8);
}

// Tilted by 0.02 rad, one end at d_hat and the other 0.08 farther, pressed as above. Held at
// both ends, the step turns the pair towards parallel and not through it by more than the
// linearisation about Q* allows (measured: 6.7e-5 rad, the far end's 1.3e-4 = 0.013 d_hat),
// and every end ends at d_hat or above. (Held at its closest points only, d^P, the same step
// turns it by 1.7 rad and fails separation.) The default solver: 3 applications. (The LCP
// sequence stalls at min d / d_hat 0.995 here after 20 LCPs, 0.996 after 200, and says so.)
TEST(OverlapEnds, TiltedPairTurnsTowardsParallelNotThrough) {
  const double tilt = 0.02;
  {
    const char* name = "default";
    const sc::ContactSolver solver = sc::DefectCorrectionOptions{};
    SCOPED_TRACE(name);
    // The near end of the turned rod (half length 2) comes 2 sin(tilt) closer: start it at d_hat.
    Pair s(kDHat + 2.0 * std::sin(tilt), tilt);
    ASSERT_NEAR(sc::closest_points(kRod, s.poses[0], kRod, s.poses[1]).distance, kDHat, 1e-3 * kDHat);
    const sc::ContactStepResult r = sc::solve_contact_step(s.problem(), s.mobility, overlap_ends(), solver);
    ASSERT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
    EXPECT_GE(r.min_distance_ratio, 1.0 - 1e-3);
    const double after = relative_turn(r.poses);
    EXPECT_GE(after, -0.01 * tilt);
    EXPECT_LE(after, tilt + 1e-12);
    const sc::ContactStepResult p = sc::solve_contact_step(s.problem(), s.mobility, {}, solver);
    std::printf("[tilted pair] %s: overlap ends turn %.3g -> %.3g rad, %zu applications; d^P: %s, %.3g rad, %zu applications\n",
                name, tilt, after, r.mobility_applications, std::string(sc::to_string(p.status)).c_str(),
                relative_turn(p.poses), p.mobility_applications);
  }
}

// Rods crossing at a small angle in the middle of their overlap: the ends do not bound the
// gap there, so the pair keeps its closest points beside its two ends.
TEST(OverlapEnds, CrossingPairKeepsItsClosestPoints) {
  const std::vector<sc::Spherocylinder> shapes{kRod};
  // Rod 1 turned by 0.05 about y (out of the xy plane) crosses rod 0's line seen along y.
  const std::vector<sc::Pose> poses{rod_along_x(0.0),
                                    {sc::Vec3(0.0, 1.0 + kDHat, 0.0),
                                     sc::Quat(Eigen::AngleAxisd(0.5 * std::numbers::pi + 0.05, sc::Vec3::UnitY()))}};
  std::vector<sc::ContactPair> pairs = sc::find_contact_pairs(std::span<const sc::Spherocylinder>(shapes),
                                                              std::span<const sc::Pose>(poses), 0.1);
  ASSERT_EQ(pairs.size(), 1u);
  const std::vector<sc::ContactPair> split =
      sc::split_overlap_ends(pairs, std::span<const sc::Spherocylinder>(shapes), std::span<const sc::Pose>(poses), 0.1,
                             0.1);
  ASSERT_EQ(split.size(), 3u);
  EXPECT_FALSE(split[0].segment_end);
  EXPECT_NEAR(split[0].points.distance, kDHat, 1e-12);
  // The ends lie 2 sin(0.05) apart across the plane: gap sqrt((1 + d_hat)^2 + 0.1^2) - 1.
  const double end_gap = std::hypot(1.0 + kDHat, 4.0 * std::sin(0.05) / 2.0) - 1.0;
  EXPECT_NEAR(split[1].points.distance, end_gap, 1e-3 * kDHat);
  EXPECT_NEAR(split[2].points.distance, end_gap, 1e-3 * kDHat);
}

// Rods side by side and staggered along their axes, overlapping by 0.8 R (a row of the Fig. 8
// grid tilted like falling dominoes overlaps by 0.97 R), the second turned by 0.002 rad about
// z and spun through parallel by the trial step. They cannot turn through each other: held at
// both ends of the overlap (the default, overlap_ends_min_overlap = 0.1) the step stops the
// pair at parallel. Held at its closest points (a minimum overlap of 1 R, which this pair
// misses), the force acts at the end that is closer at Q*, and its torque turns the rod back
// past parallel: measured, 2.2e-3 rad the other way.
TEST(OverlapEnds, StaggeredPairTurningThroughParallelStopsAtParallel) {
  const double theta = 0.002, stagger = kRod.length - 0.8 * kRod.radius;
  Pair s(kDHat, theta);
  s.poses[1].x.x() = stagger;
  s.poses[1].x.y() += 1.0001 * kDHat - sc::closest_points(kRod, s.poses[0], kRod, s.poses[1]).distance;
  s.mobility.set_configuration(s.poses);
  s.U(11) -= 2.0 * theta / kDt;  // rod 1 turns from theta to -theta in the trial step
  for (const double min_overlap : {0.1, 1.0}) {
    sc::ContactStepOptions o = overlap_ends();
    o.overlap_ends_min_overlap = min_overlap;
    const sc::ContactStepResult r = sc::solve_contact_step(s.problem(), s.mobility, o, sc::ContactSolver{});
    std::printf("[staggered pair] min overlap %.1f R: %zu contacts, %s, turn after %.3g rad\n", min_overlap,
                r.pairs.size(), std::string(sc::to_string(r.status)).c_str(), relative_turn(r.poses));
    ASSERT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
    EXPECT_GE(r.min_distance_ratio, 1.0 - 1e-3);
    if (min_overlap < 0.8) {
      EXPECT_EQ(r.pairs.size(), 2u);
      EXPECT_LT(std::abs(relative_turn(r.poses)), 1e-6);
    } else {
      EXPECT_EQ(r.pairs.size(), 1u);
      EXPECT_GT(relative_turn(r.poses), 0.5 * theta);
    }
  }
}

// The 30-rod grid of Fig. 8 (fig8_biaxial --solver default --directions overlap-ends
// --d-hat 0.1 --dt 0.01) after 148 steps and 6 sub-steps of dt / 16: the rows tilted by 1-31
// degrees like falling dominoes, every rod held at d_hat, neighbours in a row staggered along
// their axes by about half a rod. One step of dt = 0.01 in the biaxial compression flow.
// With a minimum overlap of 1 R the side pairs of a row (overlap 0.97 R) were held at their
// closest points, and the default solver and its fallbacks ended on far roots (lambda_max
// 1.7e5, turns of radians, min d / d_hat -2.0; the run stopped in this step, from t = 1.48).
// Held at both ends: converged with lambda_max 63.
TEST(OverlapEnds, DominoTiltedRodGridStepConverges) {
  const sc::Spherocylinder rod{1.0, 0.5};
  const std::vector<std::array<double, 7>> rows{
      {0, -2.6211446544037096, -3.4236260562389242, 0.99995314761209619, -0.0096800093316701374, 0, 0},
      {0, -1.5161696037988615, -3.4975962121606599, 0.99774574905384517, -0.067107527483745752, 0, 0},
      {0, -0.40557719640455292, -3.5655141753705664, 0.99194884587317833, -0.12663920076686191, 0, 0},
      {0, 0.73045493279813944, -3.6082664130563886, 0.98248123698925804, -0.1863615275856515, 0, 0},
      {0, 1.8208261428581805, -3.709126242910473, 0.98218896375951914, -0.1878958207864192, 0, 0},
      {0, 2.9278399967828492, -3.7675389402387571, 0.9821131630307387, -0.18829162222934312, 0, 0},
      {0, -2.8890629514565203, -1.5805289631312318, 0.96653111144157811, -0.25654943113464107, 0, 0},
      {0, -1.7217471990204485, -1.6581144878937111, 0.96598309705262242, -0.2586052130345094, 0, 0},
      {0, -0.55632329014544435, -1.7390650337016729, 0.96616628984815922, -0.25791994952124769, 0, 0},
      {0, 0.61030154166059636, -1.8164980210521606, 0.96619019137243356, -0.25783039792797924, 0, 0},
      {0, 1.7978312831559922, -1.8722820053496931, 0.96424722567192545, -0.26500431653841983, 0, 0},
      {0, 3.0180312917291512, -1.8897201068171239, 0.96217144039350744, -0.27244470868615384, 0, 0},
      {0, -2.9393449796093205, 0.17278324250543994, 0.9635497926262151, -0.26752905847772473, 0, 0},
      {0, -1.7487090730437793, 0.11710264097852321, 0.96612530955627651, -0.25807341249107602, 0, 0},
      {0, -0.58184798930113857, 0.039857531322073619, 0.96668472884980583, -0.25596998849196673, 0, 0},
      {0, 0.58188933029450929, -0.039796421593651495, 0.96651708380536505, -0.25660227339673541, 0, 0},
      {0, 1.7487603153728044, -0.11716562736393696, 0.9661109279089336, -0.25812724570439921, 0, 0},
      {0, 2.9393618851382719, -0.17275527889482664, 0.96357125122226495, -0.26745175979596569, 0, 0},
      {0, -3.0180179939440293, 1.8897214903886501, 0.96218731284595016, -0.27238864697026138, 0, 0},
      {0, -1.7978783363102468, 1.8723507850931933, 0.96428146652701718, -0.26487969592346078, 0, 0},
      {0, -0.61041055750366913, 1.8166313941495866, 0.96606283269505644, -0.25830718783108486, 0, 0},
      {0, 0.55647908129315049, 1.7388674701097999, 0.96625060909007443, -0.25760388279888202, 0, 0},
      {0, 1.7218898464352559, 1.6581887993564901, 0.96601929235216899, -0.25846997273071187, 0, 0},
      {0, 2.8890191634079905, 1.5805570684436505, 0.96651968345624639, -0.25659248136225155, 0, 0},
      {0, -2.9280401479040434, 3.7674685883381041, 0.98210167544725691, -0.18835153061149018, 0, 0},
      {0, -1.8209917617920968, 3.7091141930012923, 0.98215637699295388, -0.18806608182252016, 0, 0},
      {0, -0.73038887183520906, 3.6081722185697971, 0.98251582116575698, -0.18617911042589685, 0, 0},
      {0, 0.40555402807602853, 3.5656176474354275, 0.99196096112006416, -0.1265442674077287, 0, 0},
      {0, 1.5160083174853836, 3.4976103877304912, 0.9977433317775567, -0.067143457562300224, 0, 0},
      {0, 2.6211404662837827, 3.4237023827942528, 0.99995427179319751, -0.0095631753375257488, 0, 0}};
  std::vector<sc::Pose> poses;
  for (const auto& r : rows) poses.push_back({sc::Vec3(r[0], r[1], r[2]), sc::Quat(r[3], r[4], r[5], r[6])});
  const std::vector<sc::Spherocylinder> shapes{rod};
  sc::FreeDrainingMobility mobility(sc::spherocylinder_mobility(rod, 1.0), poses.size(), 6);
  const sc::VecX U = sc::LinearBackgroundFlow::biaxial_compression(1.0).body_velocities(poses, 6);
  const sc::ContactStepProblem<sc::Spherocylinder> problem{shapes, poses, U, 0.01, 0.1 * rod.radius, 0.0, 1.0, {}};
  const sc::ContactStepResult r = sc::solve_contact_step(problem, mobility, overlap_ends(), sc::ContactSolver{});
  std::printf("[domino grid] %s, %zu contacts, lambda_max %.3g, largest correction turn %.3g rad, min d / d_hat %.6f\n",
              std::string(sc::to_string(r.status)).c_str(), r.pairs.size(), r.lambda_max, r.max_correction_turn,
              r.min_distance_ratio);
  ASSERT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
  EXPECT_GE(r.min_distance_ratio, 1.0 - 1e-3);
  EXPECT_LT(r.lambda_max, 1e3);
  EXPECT_LT(r.max_correction_turn, 0.05);
}

// Eight rods L/D = 5 of a run of 400 Brownian rods (eta 0.40, dt D_R = 5e-4, overlap-ends
// directions at 0.3 rad; docs/results.md, "The overlap's end passes from one rod to the
// other"): the first contact step of the step that no halving separated, cut down (rods removed
// one at a time from the 128 within 7 of rod 26, as long as the step still failed with the end
// fixed at Q* and converged with the overlap's end). Rods 26 and 305 are 4.6 degrees apart,
// side by side with their low ends level. Per rod: pose (centre relative to rod 26, quaternion
// w x y z) and U (the Brownian velocity, 3 + 3). The trial step crosses the pair near its high
// ends, the correction slides one rod down along the other, and the overlap's low end passes
// from rod 305's end to rod 26's. Measured at rod 305's end, as the end found at Q*, the low
// end's contact held two rod ends apart while rod 26's end closed in on rod 305: the default
// solver stalled at 0.82 d_hat after 50 corrections, and so did its fallbacks. Measured at the
// overlap's end: converged in 18 corrections; and so with the frame shifted by 1e4.
TEST(OverlapEnds, OverlapEndPassingFromOneRodToTheOtherStaysHeld) {
  const sc::Spherocylinder rod{5.0, 0.5};
  const double dt = 0.023353384385508973, d_hat = 0.01;
  const std::vector<std::array<double, 13>> rows{
      {0, 0, 0,  // rod 26
       0.99480751564283298, 0.0087893526762981185, 0.098118176669233753, -0.02556516198210455,
       -2.1334144397720549, 3.7373215348288009, 2.8502665083848311,
       0.84390995505832989, -2.9775958924957835, -0.98223709958348715},
      {-2.3984896971677543, -0.21029793789340712, -1.2406997252557268,  // rod 54
       0.88999712721145996, -0.098715876575201714, 0.05894299308995022, 0.44123237962884815,
       2.0980505333139003, 1.7551391695446337, -1.1787410740561504,
       2.3295633750792648, -1.4860085325800712, -0.55343533494342989},
      {-3.603408200681657, 1.0422331919760088, -0.55703904492009571,  // rod 61
       0.84488332930704779, 0.1111260731039822, -0.044210783896659799, 0.5214101670688539,
       -1.9234135108364445, 0.81605071306580201, 0.82862971817465247,
       -2.1279951325988153, 0.66150021219642774, 2.2467929427588791},
      {-1.0985532633254476, 1.0409091597530553, -0.64983093325184171,  // rod 96
       0.99571189338657129, -0.052367040088609422, 0.00019264513103190993, -0.076259303489744537,
       -4.5951536824068882, -0.0044606989555129404, 0.44563628698275015,
       -0.6084213223577748, -0.61694960071257376, 0.96594033084572661},
      {-1.1949355409837352, 1.7859019030348469, 5.7829252482849398,  // rod 97
       0.88514411796574832, -0.14553202310042845, -0.084599538671791263, -0.43380092063002146,
       -0.58421916329387269, -0.71463804439138834, -4.7437916255396857,
       0.62532152824745502, -2.1007940498303768, 0.72268162369729783},
      {-2.2112930908744453, 0.30168142548531929, -5.1988266264992404,  // rod 98
       0.95915972279035522, -0.015775007535139038, -0.25264542760835701, -0.12623019932878865,
       -1.6444512214103542, 0.68319552269941475, 1.9798827254719666,
       -1.6704255108696164, 1.695989751020716, -0.58373646415870029},
      {-3.4362048361344337, -0.49862030703249083, -3.5349332408081278,  // rod 145
       0.97441318942685251, 0.069619218576338571, 0.011868759982243527, -0.21338048929621689,
       3.9551033636393527, -0.99649915026086888, 2.9835112289175041,
       1.6508300336928967, -0.14983251860619123, 0.78528699770362509},
      {-1.013973055812416, 0.057821825450740327, 0.1808601819152944,  // rod 305
       0.99508079572298125, -0.026477972425535269, 0.092489677615287313, 0.023638665236670502,
       3.1674126716206508, 5.2862773223359456, 1.1749795398400147,
       -0.24583747224884672, -0.83862158748951432, -0.37248170162864364},
  };
  std::vector<sc::Pose> poses;
  sc::VecX U(6 * static_cast<Eigen::Index>(rows.size()));
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto& r = rows[k];
    poses.push_back({sc::Vec3(r[0], r[1], r[2]), sc::Quat(r[3], r[4], r[5], r[6]).normalized()});
    for (int d = 0; d < 6; ++d) U(6 * static_cast<Eigen::Index>(k) + d) = r[7 + static_cast<std::size_t>(d)];
  }
  const std::vector<sc::Spherocylinder> shapes{rod};
  sc::FreeDrainingMobility mobility(sc::spherocylinder_mobility(rod, 1.0), poses.size(), 6);
  const sc::ContactStepProblem<sc::Spherocylinder> problem{shapes, poses, U, dt, d_hat, 0.0, 1.0, {}};
  sc::ContactStepOptions options = overlap_ends();
  options.overlap_ends_angle = 0.3;
  const sc::ContactStepResult r = sc::solve_contact_step(problem, mobility, options, sc::ContactSolver{});
  std::printf("[overlap end passing] %s, %d corrections, %zu contacts, lambda_max %.3g, min d / d_hat %.6f\n",
              std::string(sc::to_string(r.status)).c_str(), r.iterations, r.pairs.size(), r.lambda_max,
              r.min_distance_ratio);
  ASSERT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
  EXPECT_TRUE(r.fallback.empty()) << r.fallback;
  EXPECT_GE(r.min_distance_ratio, 1.0 - options.separation_margin);
  EXPECT_LE(r.iterations, 30);
  EXPECT_LT(r.max_correction_turn, 0.2);
  // The frame shifted by 1e4 along every axis: the same step, to rounding.
  std::vector<sc::Pose> far = poses;
  for (sc::Pose& p : far) p.x += sc::Vec3::Constant(1e4);
  const sc::ContactStepProblem<sc::Spherocylinder> shifted{shapes, far, U, dt, d_hat, 0.0, 1.0, {}};
  const sc::ContactStepResult f = sc::solve_contact_step(shifted, mobility, options, sc::ContactSolver{});
  ASSERT_EQ(f.status, sc::ContactStepStatus::converged) << f.message;
  EXPECT_GE(f.min_distance_ratio, 1.0 - options.separation_margin);
  EXPECT_NEAR(f.lambda_sum, r.lambda_sum, 1e-6 * r.lambda_sum);
}

TEST(OverlapEnds, BadOptionsNameTheField) {
  Pair s(kDHat, 0.0);
  sc::ContactStepOptions o = overlap_ends();
  o.overlap_ends_angle = 0.0;
  try {
    (void)sc::solve_contact_step(s.problem(), s.mobility, o, sc::ContactSolver{});
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ContactStepOptions.overlap_ends_angle"), std::string::npos) << e.what();
  }
  o = overlap_ends();
  o.overlap_ends_min_overlap = 0.0;
  try {
    (void)sc::solve_contact_step(s.problem(), s.mobility, o, sc::ContactSolver{});
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ContactStepOptions.overlap_ends_min_overlap"), std::string::npos)
        << e.what();
  }
  const std::vector<sc::Sphere> spheres{sc::Sphere{1.0}};
  const std::vector<sc::Pose> poses{{sc::Vec3::Zero(), sc::Quat::Identity()}, {sc::Vec3(3, 0, 0), sc::Quat::Identity()}};
  const sc::VecX U = sc::VecX::Zero(6);
  sc::FreeDrainingMobility mobility(sc::Mat6::Identity(), 2, 3);
  const sc::ContactStepProblem<sc::Sphere> problem{spheres, poses, U, kDt, kDHat, 0.0, 1.0, {}};
  try {
    (void)sc::solve_contact_step(problem, mobility, overlap_ends(), sc::ContactSolver{});
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ContactStepOptions.directions"), std::string::npos) << e.what();
  }
}

}  // namespace overlap_ends_tests
