// Line contacts: exactly parallel rods pressed together. Their centre segments are closest
// along the whole overlap, so the contact point is the overlap's midpoint
// (segment_distance.hpp) and a symmetric pair gets a symmetric force: no torque, no spin.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "stokescontact/contact/contact_matrix.hpp"
#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/contact/solvers/lcp_sequence.hpp"
#include "stokescontact/mobility/free_draining.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace parallel_rods_tests {

namespace sc = stokescontact;

namespace {

const sc::Spherocylinder kRod{4.0, 0.5};
constexpr double kForce = 100.0;  // pressing force along y
constexpr double kDt = 0.01;
constexpr double kDHat = 0.01;
constexpr double kViscosity = 1.0;

// A rod lying along world x (body z turned about y), centred at height y.
sc::Pose rod_along_x(double y) {
  return {sc::Vec3(0.0, y, 0.0), sc::Quat(Eigen::AngleAxisd(0.5 * std::numbers::pi, sc::Vec3::UnitY()))};
}

// n rods stacked along y with gap d_hat, pressed together by +-kForce on the outer two (a
// vise), every rod free draining with the slender-body mobility (6 dofs).
struct Stack {
  std::vector<sc::Spherocylinder> shapes{kRod};
  std::vector<sc::Pose> poses;
  sc::FreeDrainingMobility mobility;
  sc::VecX U;

  explicit Stack(std::size_t n)
      : mobility(sc::spherocylinder_mobility(kRod, kViscosity), n, 6), U(6 * static_cast<Eigen::Index>(n)) {
    for (std::size_t k = 0; k < n; ++k) poses.push_back(rod_along_x(static_cast<double>(k) * (2.0 * kRod.radius + kDHat)));
    sc::VecX F = sc::VecX::Zero(U.size());
    F(1) = kForce;
    F(6 * static_cast<Eigen::Index>(n - 1) + 1) = -kForce;
    mobility.set_configuration(poses);
    U = mobility.apply(F);
    mobility.reset_applications();
  }

  sc::ContactStepProblem<sc::Spherocylinder> problem() const { return {shapes, poses, U, kDt, kDHat, 0.0, 1.0, {}}; }
};

// The translational mobility across the rod's axis, 1 / zeta_perp (Yan et al. eq. 50).
double mobility_across() { return sc::spherocylinder_mobility(kRod, kViscosity)(0, 0); }

double max_spin(const sc::ContactStepResult& r) {
  double w = 0.0;
  for (Eigen::Index b = 0; 6 * b < r.velocities.size(); ++b) w = std::max(w, r.velocities.segment<3>(6 * b + 3).norm());
  return w;
}

// The largest turn of any rod over the step: the angle of q_t^-1 q_{t+dt}.
double max_turn(const std::vector<sc::Pose>& before, const std::vector<sc::Pose>& after) {
  double turn = 0.0;
  for (std::size_t b = 0; b < before.size(); ++b) turn = std::max(turn, before[b].q.angularDistance(after[b].q));
  return turn;
}

void print(const std::string& scene, const std::string& solver, const sc::ContactStepResult& r,
           const std::vector<sc::Pose>& before) {
  std::printf("[%s] %-12s status %d Nc %zu lambda", scene.c_str(), solver.c_str(), static_cast<int>(r.status),
              r.flagged_pairs);
  for (Eigen::Index k = 0; k < r.lambda.size(); ++k) std::printf(" %.9g", r.lambda(k));
  std::printf(" |omega| %.3g turn %.3g rad applications %zu iterations %d min d/d_hat %.6f\n", max_spin(r),
              max_turn(before, r.poses), r.mobility_applications, r.iterations, r.min_distance_ratio);
}

// Each solver with its own target gap: the default aims at d_hat (1 + margin), the LCP
// sequence at d_hat (defect_correction.hpp, lcp_sequence.hpp).
struct SolverRun {
  std::string name;
  sc::ContactSolver solver;
  double target_gap;
};

std::vector<SolverRun> runs() {
  return {{"default", sc::DefectCorrectionOptions{}, kDHat * (1.0 + sc::DefectCorrectionOptions{}.margin)},
          {"lcp-newton", sc::LcpSequenceOptions{}, kDHat},
#if STOKESCONTACT_HAS_NLOPT  // eq. 15 on the default solver's working set: its target and corrections
          {"barrier-working-set", sc::contact_solver_from_name("barrier-working-set"),
           kDHat * (1.0 + sc::DefectCorrectionOptions{}.margin)},
#endif
  };
}

void check_stack(const sc::ContactStepResult& r, const std::vector<sc::Pose>& before) {
  EXPECT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
  EXPECT_GE(r.min_distance_ratio, 1.0 - 1e-3);
  EXPECT_LT(max_spin(r), 1e-8);
  EXPECT_LT(max_turn(before, r.poses), 1e-10);
  for (std::size_t k = 0; k < r.pairs.size(); ++k) {
    if (r.pairs[k].j != r.pairs[k].i + 1) continue;  // only neighbours touch
    EXPECT_NEAR(r.lambda(static_cast<Eigen::Index>(k)), kForce, 1e-4 * kForce);
  }
}

}  // namespace

// Two rods, gap g0 = d_hat, pushed together by f = 100. Free draining, the force and the
// contact force lambda both act across the axis, so each rod translates at mu_perp (f - lambda)
// along y (mu_perp = 1 / zeta_perp) and, with the force at the overlap's midpoint (the rods'
// centres), does not turn. The gap then closes at 2 mu_perp (f - lambda) and
//   g(lambda) = g0 - 2 dt mu_perp (f - lambda) = target  <=>  lambda = f + (target - g0) / (2 dt mu_perp).
// For the LCP sequence (target d_hat) that is exactly f = 100; the default solver aims at
// d_hat (1 + 1e-4): lambda = 100 + 1e-6 / (2 * 0.01 * 0.0513) = 100.00097. Before the
// parallel-segment fix the contact point sat at a rod's end: lambda 2994, |omega| 230 rad/s,
// a turn of 2.3 rad in the step, and "converged" (the LCP sequence: failed separation).
TEST(ParallelRods, PairGetsTheExactForceAndNoSpin) {
  for (const SolverRun& run : runs()) {
    SCOPED_TRACE(run.name);
    Stack s(2);
    const sc::ContactStepResult r = sc::solve_contact_step(s.problem(), s.mobility, {}, run.solver);
    print("two parallel rods", run.name, r, s.poses);
    const double g0 = s.poses[1].x.y() - s.poses[0].x.y() - 2.0 * kRod.radius;
    const double exact = kForce + (run.target_gap - g0) / (2.0 * kDt * mobility_across());
    EXPECT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
    ASSERT_EQ(r.lambda.size(), 1);
    EXPECT_NEAR(r.lambda(0), exact, 1e-4 * exact);
    EXPECT_LT(max_spin(r), 1e-8);
    EXPECT_GE(r.min_distance_ratio, 1.0 - 1e-3);
  }
}

// Five rods in a vise: by symmetry every rod ends at rest and every contact carries f = 100
// (the default solver's margin spreads them by ~1e-5 relative). No rod may turn, with M D
// formed or applied matrix free. (Before the parallel-segment fix, the default solver:
// |omega| 501 rad/s, a turn of 2.3 rad, lambda up to 9469; matrix free, 54 applications and
// failed separation. The LCP sequence, matrix free: 265 applications, |omega| 230 rad/s.
// After: 4 and 5 applications for the default, 4 and 14 for the LCP sequence, no turn.)
TEST(ParallelRods, StackOfFiveDoesNotTurn) {
  for (const SolverRun& run : runs()) {
    for (const sc::MobilityCost cost : {sc::MobilityCost::formed, sc::MobilityCost::matrix_free}) {
      const bool formed = cost == sc::MobilityCost::formed;
      SCOPED_TRACE(run.name + (formed ? " formed" : " matrix free"));
      Stack s(5);
      sc::ContactStepOptions options;
      options.cost = cost;
      const sc::ContactStepResult r = sc::solve_contact_step(s.problem(), s.mobility, options, run.solver);
      print(formed ? "five parallel rods" : "five parallel rods, matrix free", run.name, r, s.poses);
      check_stack(r, s.poses);
    }
  }
}


// A chain of 5 rods in the setting of Broms & Tornberg Fig. 7 (Sec. 3.2.2): L_rod = 0.5, R_rod =
// L_rod / 20, each rod the previous one turned by theta about the shift direction t = e_x and
// shifted by beta t, every rod but the last pushed towards the next with |f| = 2 d_hat^(1/3),
// dt = 0.05. With t along the common perpendicular the centre segments cross at angle theta
// as seen along x, closest at their centres: the gap is beta - 2 R_rod, so beta = d_hat + 2 R_rod
// gives every pair the gap d_hat. Free draining, all forces pass through the centres along x
// (mobility mu across the axis, no torque): the chain must move as one, at 4 mu f / 5, so
// lambda_k = (k + 1) f / 5 on the pair (k, k + 1), and no rod turns. The trial step alone
// would close the last gap by dt mu f = 6 d_hat.
TEST(RodChain, ChainOfFiveMovesAsOneWithTheExactForces) {
  const double L_rod = 0.5, R_rod = L_rod / 20.0, d_hat = 1e-3, dt = 0.05, theta = 0.7;
  const sc::Spherocylinder rod{L_rod - 2.0 * R_rod, R_rod};
  const double f = 2.0 * std::cbrt(d_hat), beta = d_hat + 2.0 * R_rod;
  const int n = 5;
  std::vector<sc::Pose> poses;
  for (int k = 0; k < n; ++k)
    poses.push_back({sc::Vec3(k * beta, 0.0, 0.0), sc::Quat(Eigen::AngleAxisd(k * theta, sc::Vec3::UnitX()))});
  const std::vector<sc::Spherocylinder> shapes{rod};
  for (const SolverRun& run : runs()) {
    SCOPED_TRACE(run.name);
    sc::FreeDrainingMobility mobility(sc::spherocylinder_mobility(rod, kViscosity), n, 6);
    sc::VecX F = sc::VecX::Zero(6 * n);
    for (int k = 0; k + 1 < n; ++k) F(6 * k) = f;
    mobility.set_configuration(poses);
    const sc::VecX U = mobility.apply(F);
    const double mu = sc::spherocylinder_mobility(rod, kViscosity)(0, 0);
    ASSERT_NEAR(dt * mu * f, 6.0 * d_hat, 0.5 * d_hat);  // the push would overlap the last pair
    const sc::ContactStepProblem<sc::Spherocylinder> problem{shapes, poses, U, dt, d_hat, 0.0, 1.0, {}};
    const sc::ContactStepResult r = sc::solve_contact_step(problem, mobility, {}, run.solver);
    print("chain of five", run.name, r, poses);
    EXPECT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
    EXPECT_GE(r.min_distance_ratio, 1.0 - 1e-7);  // the LCP stops at a residual of 1e-8
    EXPECT_LT(max_turn(poses, r.poses), 1e-12);
    ASSERT_EQ(r.pairs.size(), static_cast<std::size_t>(n - 1));
    // Each solver's target gap g: the pairs end at g, so the chain's ends differ by 4 (g - d_hat)
    // from moving as one; lambda_k differs from (k + 1) f / 5 by at most (g - d_hat) / (dt mu).
    const double target = run.target_gap / kDHat * d_hat;  // runs() states it for kDHat
    const double slack = (target - d_hat) / (dt * mu);
    for (std::size_t k = 0; k < r.pairs.size(); ++k) {
      EXPECT_EQ(r.pairs[k].j, r.pairs[k].i + 1);
      EXPECT_NEAR(r.lambda(static_cast<Eigen::Index>(k)), (r.pairs[k].i + 1) * f / 5.0, 1e-8 * f + 4.0 * slack)
          << "pair " << r.pairs[k].i;
      const auto a = static_cast<std::size_t>(r.pairs[k].i);
      EXPECT_NEAR(sc::closest_points(rod, r.poses[a], rod, r.poses[a + 1]).distance, target,
                  1e-7 * d_hat + 4.0 * (target - d_hat));
    }
  }
}

// LineContactRods (geometry/line_contact.hpp) in the contact layer: the pair keeps d^P as its
// distance, and D applies the force at the line contact. Rod a along z at the origin (centre
// segment z in [-1/2, 1/2], radius 1/2), rod b 3 long through (1.2, 0, 0) along (-sin alpha, 0,
// cos alpha). The centre-line gap at height z of a is 1.2 cos(alpha) - z sin(alpha), smallest at
// a's top end; with c = sin(alpha) / width the force sits at z_w = (c / 12) / (1 - c / 2) on a,
// along n = (cos alpha, 0, sin alpha), so D's torque on a is -(z_w e_z x n) = (0, -z_w cos alpha,
// 0). A plain Spherocylinder pair has its force at the top end instead: torque -0.5 cos alpha.
TEST(LineContactRods, ContactMatrixActsAtTheLineContact) {
  const double alpha = 0.01, width = 0.1;
  const sc::LineContactRod a{sc::Spherocylinder{1.0, 0.5}, {width, 0.05}};
  const sc::LineContactRod b{sc::Spherocylinder{3.0, 0.5}, {width, 0.05}};
  const std::vector<sc::Pose> poses = {{sc::Vec3::Zero(), sc::Quat::Identity()},
                                       {sc::Vec3(1.2, 0, 0), sc::Quat(Eigen::AngleAxisd(-alpha, sc::Vec3::UnitY()))}};
  const double exact = 1.2 * std::cos(alpha) - 0.5 * std::sin(alpha) - 1.0;
  const double c = std::sin(alpha) / width, z_w = (c / 12.0) / (1.0 - 0.5 * c);
  const std::vector<sc::LineContactRod> line_shapes{a, b};
  const auto line_pairs = sc::find_contact_pairs(std::span<const sc::LineContactRod>(line_shapes),
                                                 std::span<const sc::Pose>(poses), 0.5);
  ASSERT_EQ(line_pairs.size(), 1u);
  EXPECT_NEAR(line_pairs[0].points.distance, exact, 1e-14);  // d^P unchanged
  ASSERT_TRUE(line_pairs[0].force_points.has_value());
  EXPECT_NEAR(line_pairs[0].force_points->curve_point_a.z(), z_w, 3e-4 * z_w);
  const auto D_line = sc::contact_matrix(std::span<const sc::ContactPair>(line_pairs), std::span<const sc::Pose>(poses));
  EXPECT_NEAR(D_line.coeff(0, 0), -std::cos(alpha), 1e-12);  // force -n on a
  EXPECT_NEAR(D_line.coeff(2, 0), -std::sin(alpha), 1e-12);
  EXPECT_NEAR(D_line.coeff(4, 0), -z_w * std::cos(alpha), 3e-4 * z_w);
  // The same rods as plain Spherocylinders: the closest points, at a's top end.
  const std::vector<sc::Spherocylinder> plain{a, b};
  const auto pairs = sc::find_contact_pairs(std::span<const sc::Spherocylinder>(plain), std::span<const sc::Pose>(poses), 0.5);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_FALSE(pairs[0].force_points.has_value());
  const auto D = sc::contact_matrix(std::span<const sc::ContactPair>(pairs), std::span<const sc::Pose>(poses));
  EXPECT_NEAR(D.coeff(4, 0), -0.5 * std::cos(alpha), 1e-12);
}

}  // namespace parallel_rods_tests
