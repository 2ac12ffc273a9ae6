// TimeStepper with Brownian motion (TimeStepperOptions::brownian; Yan et al. eq. 29 with
// U_known = U^B, docs/brownian.md): the increments' statistics, reproducibility, the Brownian
// bridge of a halved step, hard spheres that stay apart, and bad input (a negative kT, a box
// too small for its bodies, an overlapping start).
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/core/rigid_motion.hpp"
#include "stokescontact/dynamics/time_stepper.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/scenes/periodic_placement.hpp"
#include "stokescontact/scenes/sphere_packing.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace brownian_stepping_tests {

namespace sc = stokescontact;

namespace {

using SphereStepper = sc::TimeStepper<sc::Sphere, sc::FreeDrainingMobility>;

// Unit spheres in viscosity 1: mobilities 1 / (6 pi) (translation) and 1 / (8 pi) (rotation).
constexpr double kMuTranslation = 1.0 / (6.0 * std::numbers::pi);
constexpr double kMuRotation = 1.0 / (8.0 * std::numbers::pi);

sc::TimeStepperOptions brownian_options(double dt, double kT, std::uint64_t seed) {
  sc::TimeStepperOptions o;
  o.dt = dt;
  o.d_hat = 0.01;
  o.brownian.emplace();
  o.brownian->kT = kT;
  o.brownian->seed = seed;
  return o;
}

// Spheres on a line 50 apart: no pair ever comes near contact in the runs below.
std::vector<sc::Pose> far_apart(std::size_t n) {
  std::vector<sc::Pose> poses;
  for (std::size_t i = 0; i < n; ++i) poses.push_back({sc::Vec3(50.0 * static_cast<double>(i), 0, 0), sc::Quat::Identity()});
  return poses;
}

// The rotation taking orientation a to b as a rotation vector (angle times axis), world frame.
sc::Vec3 rotation_vector(const sc::Pose& a, const sc::Pose& b) {
  const Eigen::AngleAxisd r(b.rotation() * a.rotation().transpose());
  return r.angle() * r.axis();
}

// Sample covariance of the per-step displacements and rotations of free spheres against
// 2 kT M dt: variances within 5% (about 6 standard errors of 18000 samples), cross terms and
// means at the noise level.
TEST(BrownianStepping, FreeSphereIncrementsHaveCovarianceTwoKTMdt) {
  const double dt = 0.01, kT = 0.7;
  const std::size_t bodies = 3;
  const int steps = 2000;
  auto mobility = sc::FreeDrainingMobility(sc::sphere_mobility(sc::Sphere{1.0}, 1.0), bodies, 6);
  SphereStepper stepper({sc::Sphere{1.0}}, far_apart(bodies), mobility, brownian_options(dt, kT, 42));
  Eigen::Matrix<double, 6, 6> second = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> first = Eigen::Matrix<double, 6, 1>::Zero();
  double samples = 0.0;
  for (int k = 0; k < steps; ++k) {
    const std::vector<sc::Pose> before = stepper.poses();
    const sc::StepDiagnostics d = stepper.step();
    ASSERT_EQ(d.active_pairs, 0u);
    for (std::size_t b = 0; b < bodies; ++b) {
      Eigen::Matrix<double, 6, 1> increment;
      increment << stepper.poses()[b].x - before[b].x, rotation_vector(before[b], stepper.poses()[b]);
      first += increment;
      second += increment * increment.transpose();
      samples += 1.0;
    }
  }
  const Eigen::Matrix<double, 6, 1> mean = first / samples;
  const Eigen::Matrix<double, 6, 6> covariance = second / samples - mean * mean.transpose();
  for (int a = 0; a < 6; ++a) {
    const double expected = 2.0 * kT * (a < 3 ? kMuTranslation : kMuRotation) * dt;
    EXPECT_NEAR(covariance(a, a) / expected, 1.0, 0.05) << "component " << a;
    EXPECT_LT(std::abs(mean(a)), 6.0 * std::sqrt(expected / samples)) << "component " << a;
    for (int b = 0; b < a; ++b)
      EXPECT_LT(std::abs(covariance(a, b)), 0.05 * expected) << "components " << a << ", " << b;
  }
}

// The same seed gives the same trajectory bit for bit; another seed another; kT = 0 is the
// deterministic stepper exactly (nothing drawn).
TEST(BrownianStepping, TheSeedFixesTheTrajectory) {
  const auto run = [](const sc::TimeStepperOptions& o, bool with_forces) {
    auto mobility = sc::FreeDrainingMobility(sc::sphere_mobility(sc::Sphere{1.0}, 1.0), 2, 6);
    SphereStepper stepper({sc::Sphere{1.0}}, far_apart(2), mobility, o);
    if (with_forces) stepper.set_external_forces(sc::VecX::LinSpaced(12, -1.0, 1.0));
    stepper.run(20);
    return stepper.poses();
  };
  const std::vector<sc::Pose> a = run(brownian_options(0.01, 1.0, 7), false);
  const std::vector<sc::Pose> b = run(brownian_options(0.01, 1.0, 7), false);
  const std::vector<sc::Pose> c = run(brownian_options(0.01, 1.0, 8), false);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(a[i].x, b[i].x);
    EXPECT_EQ(a[i].q.coeffs(), b[i].q.coeffs());
    EXPECT_GT((a[i].x - c[i].x).norm(), 1e-3);
  }
  sc::TimeStepperOptions deterministic = brownian_options(0.01, 0.0, 7);
  const std::vector<sc::Pose> cold = run(deterministic, true);
  deterministic.brownian.reset();
  const std::vector<sc::Pose> none = run(deterministic, true);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(cold[i].x, none[i].x);
    EXPECT_EQ(cold[i].q.coeffs(), none[i].q.coeffs());
  }
}

// A step whose first attempt fails is halved with a Brownian bridge: the two halves end where
// the whole step would have (constant mobility), so a failure does not redraw the noise.
TEST(BrownianStepping, AHalvedStepKeepsItsBrownianIncrement) {
  const double dt = 0.01;
  // No contacts anywhere: Q(lambda) = Q* with lambda empty; `fail_whole_step` refuses the full dt.
  const auto solver = [dt](bool fail_whole_step) {
    return SphereStepper::CustomContactSolver(
        [dt, fail_whole_step](const sc::ContactStepProblem<sc::Sphere>& problem, sc::FreeDrainingMobility&,
                              const sc::ContactStepOptions&) {
          sc::ContactStepResult r;
          if (fail_whole_step && problem.dt == dt) {
            r.status = sc::ContactStepStatus::failed_separation;
            r.message = "refused on purpose";
            return r;
          }
          r.poses = sc::advance_all(problem.poses, problem.U, 3, problem.dt);
          r.velocities = problem.U;
          r.min_distance_ratio = 1e9;
          return r;
        });
  };
  const auto first_step = [&](bool fail_whole_step, int& substeps) {
    auto mobility = sc::FreeDrainingMobility(sc::sphere_mobility(sc::Sphere{1.0}, 1.0), 3, 3);
    SphereStepper stepper({sc::Sphere{1.0}}, far_apart(3), mobility, solver(fail_whole_step),
                          brownian_options(dt, 1.3, 99));
    substeps = stepper.step().substeps;
    return stepper.poses();
  };
  int whole = 0, halved = 0;
  const std::vector<sc::Pose> a = first_step(false, whole);
  const std::vector<sc::Pose> b = first_step(true, halved);
  EXPECT_EQ(whole, 1);
  EXPECT_EQ(halved, 2);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_GT((a[i].x - far_apart(3)[i].x).norm(), 1e-3);  // it moved
    EXPECT_LT((a[i].x - b[i].x).norm(), 1e-13) << "body " << i;
  }
}

// Hard spheres at packing 0.3 in a periodic box: every step ends with every gap >= d_hat (up
// to the solver's margin), and the collision forces only push.
TEST(BrownianStepping, HardSpheresInAPeriodicBoxStayApart) {
  const std::size_t n = 60;
  const sc::SpherePacking packing = sc::dense_packing(n, 0.3, 5);
  auto mobility = sc::FreeDrainingMobility(sc::sphere_mobility(sc::Sphere{1.0}, 1.0), n, 3);
  sc::TimeStepperOptions o = brownian_options(2e-3, 1.0, 3);
  o.d_hat = 1e-3;
  o.box = sc::PeriodicBox{sc::Vec3::Constant(packing.side)};
  SphereStepper stepper({sc::Sphere{1.0}}, packing.poses, mobility, o);
  std::size_t pushed = 0;
  for (int k = 0; k < 200; ++k) {
    const sc::StepDiagnostics d = stepper.step();
    EXPECT_GE(d.min_distance_ratio, 1.0 - 1e-4) << "step " << k;
    EXPECT_GE(d.lambda_sum, 0.0);
    pushed += d.active_pairs;
  }
  EXPECT_GT(pushed, 0u);  // collisions happened
}

// Brownian rods L/D = 5 (300 at phi 0.02, Yan's free-draining mobility, d_hat = 1e-3 D,
// dt = 1e-3 / D_R, each rod end turning ~0.1 rad per step), with sub-stepping off: every step
// must hold on its own. Before interior contacts this failed at step 5, a carried pair whose
// end gap held overlapping on the way (docs/results.md, Brownian rods).
TEST(BrownianStepping, RodsHoldEveryStepWithoutSubSteps) {
  const std::size_t n = 300;
  const sc::Spherocylinder rod{5.0, 0.5};
  const sc::Mat6 body = sc::spherocylinder_mobility(rod, 1.0);
  const double volume = std::numbers::pi * (0.25 * 5.0 + 1.0 / 6.0);
  const double side = std::cbrt(static_cast<double>(n) * volume / 0.02);
  auto mobility = sc::FreeDrainingMobility(body, n, 6);
  sc::TimeStepperOptions o = brownian_options(1e-3 / body(3, 3), 1.0, 1);
  o.d_hat = 1e-3;
  o.box = sc::PeriodicBox{sc::Vec3::Constant(side)};
  o.max_substep_halvings = 0;
  sc::TimeStepper<sc::Spherocylinder, sc::FreeDrainingMobility> stepper(
      {rod}, sc::periodic_random_placement(rod, n, side, o.d_hat, 1), mobility, o);
  std::size_t pushed = 0, carried = 0;
  for (int k = 0; k < 120; ++k) {
    const sc::StepDiagnostics d = stepper.step();
    EXPECT_GE(d.min_distance_ratio, 1.0 - 1e-3) << "step " << k;
    pushed += d.active_pairs;
    carried += d.carried_pairs;
  }
  EXPECT_GT(pushed, 0u);
  EXPECT_GT(carried, 0u);  // pairs that passed each other in the trial step were held
}

TEST(BrownianStepping, RejectsBadInputNamingTheField) {
  auto mobility = sc::FreeDrainingMobility(sc::sphere_mobility(sc::Sphere{1.0}, 1.0), 2, 3);
  test_support::expect_rejects(
      [&] { SphereStepper({sc::Sphere{1.0}}, far_apart(2), mobility, brownian_options(0.01, -1.0, 1)); }, "brownian.kT");
  sc::TimeStepperOptions o = brownian_options(0.01, 1.0, 1);
  o.brownian->rfd.delta = 0.0;
  test_support::expect_rejects([&] { SphereStepper({sc::Sphere{1.0}}, far_apart(2), mobility, o); },
                               "RfdOptions.delta");
  // A box too small for the minimum image (a unit sphere needs sides >= 2 (2 + d_hat)).
  sc::TimeStepperOptions small_box = brownian_options(0.01, 1.0, 1);
  small_box.box = sc::PeriodicBox{sc::Vec3(10.0, 10.0, 3.9)};
  const std::vector<sc::Pose> two = {{sc::Vec3(1, 1, 1), sc::Quat::Identity()}, {sc::Vec3(6, 6, 1), sc::Quat::Identity()}};
  test_support::expect_rejects([&] { SphereStepper({sc::Sphere{1.0}}, two, mobility, small_box); }, "box.lengths");
  small_box.box = sc::PeriodicBox{sc::Vec3(10.0, 10.0, 4.02)};
  EXPECT_NO_THROW(SphereStepper({sc::Sphere{1.0}}, two, mobility, small_box));
  // An overlapping start.
  const std::vector<sc::Pose> overlapping = {{sc::Vec3(0, 0, 0), sc::Quat::Identity()},
                                             {sc::Vec3(1.5, 0, 0), sc::Quat::Identity()}};
  test_support::expect_rejects(
      [&] { SphereStepper({sc::Sphere{1.0}}, overlapping, mobility, brownian_options(0.01, 1.0, 1)); }, "poses");
}

}  // namespace

}  // namespace brownian_stepping_tests
