#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/dynamics/background_flow.hpp"
#include "stokescontact/dynamics/time_stepper.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/scenes/random.hpp"
#include "stokescontact/scenes/sphere_packing.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace time_stepper_tests {

namespace sc = stokescontact;

namespace {

using test_support::expect_rejects;
using test_support::random_rotation;
using test_support::random_unit_vector;
using test_support::uniform;
using test_support::uniform_vector;

using SphereStepper = sc::TimeStepper<sc::Sphere, sc::FreeDrainingMobility>;
using CustomSphereSolver = SphereStepper::CustomContactSolver;

// Unit spheres in viscosity 1: translational mobility mu = 1 / (6 pi).
constexpr double kMu = 1.0 / (6.0 * std::numbers::pi);
constexpr double kMargin = 1e-3;  // ContactStepOptions::separation_margin

// The library's solvers by value, each with its default options.
const sc::ContactSolver kLcpSequence = sc::LcpSequenceOptions{};  // "lcp-newton"
const sc::ContactSolver kBarrierSlsqp = sc::BarrierNloptOptions{};  // "barrier-slsqp"
const sc::ContactSolver kDefault = sc::DefectCorrectionOptions{};  // "default"
constexpr double kDefaultMargin = 1e-4;  // DefectCorrectionOptions::margin

sc::FreeDrainingMobility sphere_mobility(std::size_t n, int dofs) {
  return sc::FreeDrainingMobility(sc::sphere_mobility(sc::Sphere{1.0}, 1.0), n, dofs);
}

sc::TimeStepperOptions options(double dt, double d_hat) {
  sc::TimeStepperOptions o;
  o.dt = dt;
  o.d_hat = d_hat;
  return o;
}

// Smallest surface distance between unit spheres by brute force, minimum image in a cubic box of side L (0: open).
double brute_force_min_distance(const std::vector<sc::Pose>& poses, double L = 0.0) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (std::size_t j = i + 1; j < poses.size(); ++j) {
      sc::Vec3 d = poses[j].x - poses[i].x;
      if (L > 0.0)
        for (int k = 0; k < 3; ++k) d[k] -= L * std::round(d[k] / L);
      best = std::min(best, d.norm() - 2.0);
    }
  return best;
}

// Forward Euler in shear by hand: x += dt rate y; rotation by -rate dt / 2 about z per step.
TEST(TimeStepper, FreeBodiesInShearMoveExactlyWithTheFlow) {
  const double rate = 0.8, dt = 0.05;
  const int steps = 40;
  test_support::Rng rng(21);
  const std::vector<sc::Pose> start = {{sc::Vec3(0.2, 1.5, 0.1), random_rotation(rng)},
                                       {sc::Vec3(3.0, -2.0, 10.0), random_rotation(rng)}};
  for (const int dofs : {3, 6}) {
    SCOPED_TRACE(dofs);
    auto mobility = sphere_mobility(2, dofs);
    sc::TimeStepperOptions o = options(dt, 0.01);
    o.background_flow = sc::LinearBackgroundFlow::shear(rate);
    SphereStepper stepper({sc::Sphere{1.0}}, start, mobility, kLcpSequence, o);
    std::vector<sc::Vec3> x = {start[0].x, start[1].x};
    for (int n = 1; n <= steps; ++n) {
      const sc::StepDiagnostics& d = stepper.step();
      EXPECT_EQ(d.step, n);
      EXPECT_DOUBLE_EQ(d.time, n * dt);
      EXPECT_EQ(d.flagged_pairs, 0u);
      EXPECT_EQ(d.mobility_applications, 0u);  // F_ext = 0: no mobility solve at all
      for (std::size_t b = 0; b < 2; ++b) {
        x[b].x() += dt * rate * x[b].y();
        EXPECT_LE((stepper.poses()[b].x - x[b]).norm(), 1e-12) << "step " << n << " body " << b;
        const sc::Mat3 expected =
            dofs == 6 ? sc::Mat3(Eigen::AngleAxisd(-0.5 * rate * n * dt, sc::Vec3::UnitZ()) * start[b].q)
                      : start[b].rotation();
        EXPECT_LE((stepper.poses()[b].rotation() - expected).norm(), 1e-12) << "step " << n << " body " << b;
      }
    }
    // Closed form of the recursion: y is constant, so x_n = x_0 + n dt rate y_0.
    for (std::size_t b = 0; b < 2; ++b)
      EXPECT_NEAR(stepper.poses()[b].x.x(), start[b].x.x() + steps * dt * rate * start[b].x.y(), 1e-12);
    EXPECT_EQ(mobility.applications(), 0u);
  }
}

// U = U_bg + M F: a sphere in shear under a constant force, integrated by hand.
TEST(TimeStepper, ForcesAndBackgroundFlowAdd) {
  const double rate = -1.3, dt = 0.02;
  const sc::Vec3 f(2.0, -3.0, 0.5);
  auto mobility = sphere_mobility(1, 6);
  sc::TimeStepperOptions o = options(dt, 0.01);
  o.background_flow = sc::LinearBackgroundFlow::shear(rate);
  SphereStepper stepper({sc::Sphere{1.0}}, {sc::Pose{sc::Vec3(1, 2, 3), sc::Quat::Identity()}}, mobility,
                        kLcpSequence, o);
  sc::VecX F = sc::VecX::Zero(6);
  F.head<3>() = f;
  F(5) = 4.0;  // torque about z
  stepper.set_external_forces(F);
  sc::Vec3 x(1, 2, 3);
  const double omega_z = -0.5 * rate + 4.0 / (8.0 * std::numbers::pi);
  for (int n = 1; n <= 25; ++n) {
    const sc::StepDiagnostics& d = stepper.step();
    EXPECT_EQ(d.unconstrained_applications, 1u);
    EXPECT_EQ(d.mobility_applications, 1u);
    x += dt * (sc::Vec3(rate * x.y(), 0, 0) + kMu * f);
    EXPECT_LE((stepper.poses()[0].x - x).norm(), 1e-12) << "step " << n;
    const sc::Mat3 expected(Eigen::AngleAxisd(omega_z * n * dt, sc::Vec3::UnitZ()));
    EXPECT_LE((stepper.poses()[0].rotation() - expected).norm(), 1e-12) << "step " << n;
    EXPECT_TRUE(std::isinf(d.min_distance_ratio));  // one body: no pairs
  }
  EXPECT_EQ(mobility.applications(), 25u);
}

// Two spheres pushed together by f = 6 pi (speed 1 each): they close the gap, then sit at
// d_hat, the contact force balancing f (lambda = f once they rest there).
TEST(TimeStepper, TwoSpheresDrivenHeadOnSettleAtDHat) {
  const double dt = 0.01, d_hat = 0.01, f = 1.0 / kMu;
  const std::vector<std::pair<std::string, sc::ContactSolver>> solvers = {
      {"lcp_sequence", kLcpSequence}, {"barrier_slsqp", kBarrierSlsqp}, {"default", kDefault}};
  for (const auto& [name, solver] : solvers) {
    SCOPED_TRACE(name);
    auto mobility = sphere_mobility(2, 3);
    SphereStepper stepper({sc::Sphere{1.0}},
                          {sc::Pose{sc::Vec3(0, 0, 0), sc::Quat::Identity()},
                           sc::Pose{sc::Vec3(2.5, 0, 0), sc::Quat::Identity()}},
                          mobility, solver, options(dt, d_hat));
    sc::VecX F(6);
    F << f, 0, 0, -f, 0, 0;
    stepper.set_external_forces(F);
    int contact_steps = 0;
    for (int n = 1; n <= 80; ++n) {
      const sc::StepDiagnostics& diag = stepper.step();
      const std::vector<sc::Pose>& p = stepper.poses();
      const double d = (p[1].x - p[0].x).norm() - 2.0;
      ASSERT_GE(d, d_hat * (1.0 - kMargin)) << "step " << n;
      EXPECT_NEAR(diag.min_distance_ratio, d / d_hat, 1e-9) << "step " << n;
      EXPECT_NEAR(p[0].x.x() + p[1].x.x(), 2.5, 1e-12) << "step " << n;  // equal and opposite forces
      EXPECT_EQ(p[0].x.tail<2>().norm() + p[1].x.tail<2>().norm(), 0.0);
      contact_steps += diag.active_pairs > 0 ? 1 : 0;
    }
    // The gap 0.5 closes at relative speed 2 in 25 steps; contact from then on.
    EXPECT_GE(contact_steps, 50);
    const std::vector<sc::Pose>& p = stepper.poses();
    const double d = (p[1].x - p[0].x).norm() - 2.0;
    const sc::StepDiagnostics& last = stepper.diagnostics().back();
    std::printf("[head-on %s] final d / d_hat = %.12f, lambda / f = %.12f, contact steps %d\n", name.c_str(),
                d / d_hat, last.lambda_max / f, contact_steps);
    if (name == "lcp_sequence") {
      EXPECT_NEAR(d, d_hat, 1e-9 * d_hat);
      EXPECT_NEAR(last.lambda_max, f, 1e-6 * f);
    } else if (name == "default") {  // held at d_hat (1 + margin)
      EXPECT_NEAR(d, d_hat * (1.0 + kDefaultMargin), 1e-9 * d_hat);
      EXPECT_NEAR(last.lambda_max, f, 1e-6 * f);
    } else {  // the barrier stops by eq. 29 (TOL = 1e-2) within the separation margin
      EXPECT_NEAR(d, d_hat, 2e-3 * d_hat);
      EXPECT_NEAR(last.lambda_max, f, 1e-3 * f);
    }
  }
}

// A custom contact solver: the LCP sequence, counting its mobility applications.
struct CountingSolver {
  std::size_t* last_contact_applications;
  sc::ContactStepResult operator()(const sc::ContactStepProblem<sc::Sphere>& p, sc::FreeDrainingMobility& m,
                                   const sc::ContactStepOptions& options) const {
    sc::ContactStepResult r = sc::solve_contact_step(p, m, options, kLcpSequence);
    *last_contact_applications = r.mobility_applications;
    return r;
  }
};

// Random forces each step (a field of (t, Q_t)), the cluster also pulled to its centre so that
// it jams: the minimum distance, by brute force, stays >= d_hat (1 - margin) after every step.
// Mobility applications per step: 1 for U plus the contact step's, as the mobility counted them.
void run_random_sphere_scene(std::uint64_t seed, std::optional<double> box_side) {
  SCOPED_TRACE("seed " + std::to_string(seed) + (box_side ? " periodic" : " open"));
  test_support::Rng rng(seed);
  const int side = 3;
  const double spacing = 2.3, dt = 0.02, d_hat = 0.02;
  std::vector<sc::Pose> poses;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      for (int k = 0; k < side; ++k)
        poses.push_back({sc::Vec3(1.2 + spacing * i, 1.2 + spacing * j, 1.2 + spacing * k) + uniform_vector(rng, -0.1, 0.1),
                         sc::Quat::Identity()});
  const auto n = static_cast<Eigen::Index>(poses.size());
  auto mobility = sphere_mobility(poses.size(), 3);
  std::size_t contact_applications = 0;
  sc::TimeStepperOptions o = options(dt, d_hat);
  if (box_side) o.box = sc::PeriodicBox{sc::Vec3::Constant(*box_side)};
  SphereStepper stepper({sc::Sphere{1.0}}, poses, mobility, CountingSolver{&contact_applications}, o);
  test_support::Rng force_rng(seed + 1);
  const bool periodic = box_side.has_value();
  stepper.set_external_force_field([&force_rng, n, periodic](double, std::span<const sc::Pose> q) {
    sc::Vec3 centre = sc::Vec3::Zero();
    for (const sc::Pose& p : q) centre += p.x / static_cast<double>(q.size());
    sc::VecX F(3 * n);
    for (Eigen::Index b = 0; b < n; ++b) {
      const sc::Vec3 pull = periodic ? sc::Vec3(3.0, 0, 0) : sc::Vec3(centre - q[static_cast<std::size_t>(b)].x);
      F.segment<3>(3 * b) = (2.0 * random_unit_vector(force_rng) + pull) / kMu;
    }
    return F;
  });
  std::size_t active = 0, wrapped = 0;
  for (int step = 1; step <= 50; ++step) {
    const std::vector<sc::Pose> before = stepper.poses();
    const std::size_t applications_before = mobility.applications();
    const sc::StepDiagnostics& d = stepper.step();
    const double d_min = brute_force_min_distance(stepper.poses(), box_side.value_or(0.0));
    ASSERT_GE(d_min, d_hat * (1.0 - kMargin)) << "step " << step;
    EXPECT_NEAR(d.min_distance_ratio, d_min / d_hat, 1e-9 * std::max(1.0, d_min / d_hat)) << "step " << step;
    EXPECT_EQ(d.status, sc::ContactStepStatus::converged) << d.message;
    EXPECT_EQ(d.unconstrained_applications, 1u);
    EXPECT_EQ(d.mobility_applications, 1u + contact_applications) << "step " << step;
    EXPECT_EQ(d.mobility_applications, mobility.applications() - applications_before) << "step " << step;
    EXPECT_LE(d.active_pairs, d.flagged_pairs);
    active += d.active_pairs;
    if (box_side)
      for (std::size_t b = 0; b < before.size(); ++b) {
        const sc::Vec3& x = stepper.poses()[b].x;
        EXPECT_TRUE((x.array() >= 0.0).all() && (x.array() < *box_side).all()) << "body " << b;
        wrapped += (x - before[b].x).cwiseAbs().maxCoeff() > 0.5 * *box_side ? 1 : 0;
      }
  }
  EXPECT_GT(active, 20u);  // the scene did jam: the test exercised contacts
  if (box_side) {
    EXPECT_GT(wrapped, 0u);  // and bodies crossed the box
  }
  std::printf("[random spheres seed %llu %s] active contacts over 50 steps: %zu, wraps %zu\n",
              static_cast<unsigned long long>(seed), box_side ? "periodic" : "open", active, wrapped);
}

TEST(TimeStepper, ManySpheresWithRandomForcesNeverOverlap) {
  for (const std::uint64_t seed : {101u, 202u}) run_random_sphere_scene(seed, std::nullopt);
}

TEST(TimeStepper, ManySpheresInAPeriodicBoxNeverOverlapAndStayWrapped) {
  run_random_sphere_scene(303u, 7.0);
}

// Rods in the yz plane squeezed by biaxial compression (the setting of Broms & Tornberg Sec.
// 3.2.3, eq. 32), 6 dofs: no overlap at any step, contacts did occur, and no rod turns (the
// rods lie along a principal axis of the pure strain, and parallel neighbours meet at the
// middle of their overlap; the barrier's rods only to 1e-4 rad). Before parallel segments met at their overlap's middle, the LCP
// sequence stopped at step 18 with min d / d_hat = 0.949 and the stepper threw.
TEST(TimeStepper, RodsInBiaxialCompressionNeverOverlap) {
  using RodStepper = sc::TimeStepper<sc::Spherocylinder, sc::FreeDrainingMobility>;
  const sc::Spherocylinder rod{2.0, 0.5};
  std::vector<sc::Pose> poses;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 2; ++k) poses.push_back({sc::Vec3(0.0, 1.1 * (i - 1), 3.1 * k - 1.55), sc::Quat::Identity()});
  const std::vector<std::pair<std::string, sc::ContactSolver>> solvers = {
      {"barrier_slsqp", kBarrierSlsqp}, {"default", kDefault}, {"lcp_sequence", kLcpSequence}};
  for (const auto& [name, solver] : solvers) {
    SCOPED_TRACE(name);
    sc::FreeDrainingMobility mobility(sc::spherocylinder_mobility(rod, 1.0), poses.size(), 6);
    sc::TimeStepperOptions o = options(0.01, 0.01);
    o.background_flow = sc::LinearBackgroundFlow::biaxial_compression(1.0);
    // The barrier with the paper's d_try (eq. 30): with the per-pair rule its eps_reg = d_try
    // is smaller here and SLSQP flung the rods apart at step 19 (lambda_sum 3e12, reported
    // converged), a defect of the barrier solver recorded in docs/results.md.
    if (name == "barrier_slsqp") o.d_try_rule = sc::DTryRule::absolute;
    // And in formed mode: SLSQP breaks the symmetry from rounding, and how far depends on how
    // M D lambda is summed. Measured over these 60 steps, the largest turn is 2.6e-5 rad formed,
    // 0.020 rad with blocks (the default for free draining) and 0.27 rad matrix-free.
    if (name == "barrier_slsqp") o.contact_step.cost = sc::MobilityCost::formed;
    RodStepper stepper({rod}, poses, mobility, solver, o);
    std::size_t active = 0;
    for (int step = 1; step <= 60; ++step) {
      const sc::StepDiagnostics& d = stepper.step();
      const double d_min = sc::minimum_pair_distance(rod, std::span<const sc::Pose>(stepper.poses())).distance;
      ASSERT_GE(d_min, 0.01 * (name == "default" ? 1.0 - 1e-9 : 1.0 - kMargin)) << "step " << step;
      EXPECT_EQ(d.unconstrained_applications, 0u);
      active += d.active_pairs;
    }
    EXPECT_GT(active, 0u);
    // The barrier's SLSQP ends each step at slightly unequal forces on alike pairs: its rods
    // turn by up to 2.6e-5 rad over the 60 steps (measured); the complementarity solvers'
    // forces are symmetric and their rods do not turn.
    const double max_turn = name == "barrier_slsqp" ? 1e-4 : 1e-9;
    for (const sc::Pose& p : stepper.poses())
      EXPECT_LT(p.q.angularDistance(sc::Quat::Identity()), max_turn) << "a rod turned";
  }
}

// 50 steps of Broms & Tornberg's biaxial compression (Sec. 3.2.3, eq. 32, Table 2) on 6 of the
// 30 rods: L_rod = 2 end to end, R_rod = 0.5 (centre segment 1), 3 columns at y spacing 1.5
// and 2 rows at z spacing 3 (gaps R_rod side by side and L_rod / 2 tip to tip, the layout of
// examples/fig8_biaxial.cpp), d_hat = 0.01 R_rod, dt = 0.02, free draining. Before any contact
// forward Euler gives y_n = y_0 (1 - dt/2)^n, so the trial step of step n closes the side gap
// to 1.5 (0.99)^n - 1, below d_hat first for n = 40 (ln(1.005/1.5)/ln(0.99) = 39.9), and the
// tip gap to 3 (0.99)^n - 2, first for n = 41 (40.1). From then on the flow presses every step:
// contacts are active at steps 40..50, 11 steps (the paper's count starts at its step 41 too:
// 410 of 450). The rods are exactly parallel, every contact a line contact at the middle of
// the overlap or tip to tip along the axis: no rod may leave x = 0 or turn, and the mirror
// pair (y = -1.5, +1.5) stays mirrored.
TEST(TimeStepper, BiaxialRodGridKeepsItsSymmetryAndContactCounts) {
  using RodStepper = sc::TimeStepper<sc::Spherocylinder, sc::FreeDrainingMobility>;
  const sc::Spherocylinder rod{1.0, 0.5};
  const double d_hat = 0.01 * rod.radius;
  std::vector<sc::Pose> poses;
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 3; ++col)
      poses.push_back({sc::Vec3(0.0, 1.5 * (col - 1), 3.0 * (row - 0.5)), sc::Quat::Identity()});
  for (const auto& [name, solver] : std::vector<std::pair<std::string, sc::ContactSolver>>{{"default", kDefault},
                                                                                        {"lcp_sequence", kLcpSequence}}) {
    SCOPED_TRACE(name);
    sc::FreeDrainingMobility mobility(sc::spherocylinder_mobility(rod, 1.0), poses.size(), 6);
    sc::TimeStepperOptions o = options(0.02, d_hat);
    o.background_flow = sc::LinearBackgroundFlow::biaxial_compression(1.0);
    RodStepper stepper({rod}, poses, mobility, solver, o);
    std::vector<long> active_steps;
    for (int step = 1; step <= 50; ++step) {
      const sc::StepDiagnostics& d = stepper.step();
      ASSERT_GE(d.min_distance_ratio, 1.0 - kMargin) << "step " << step;
      if (d.active_pairs > 0) active_steps.push_back(d.step);
      for (const sc::Pose& p : stepper.poses()) {
        EXPECT_EQ(p.x.x(), 0.0) << "step " << step;
        EXPECT_LT(p.q.angularDistance(sc::Quat::Identity()), 1e-12) << "step " << step;
      }
      const std::vector<sc::Pose>& q = stepper.poses();
      for (const std::size_t row : {0u, 3u}) {
        EXPECT_NEAR(q[row].x.y(), -q[row + 2].x.y(), 1e-12) << "step " << step;
        EXPECT_NEAR(q[row].x.z(), q[row + 2].x.z(), 1e-12) << "step " << step;
      }
    }
    ASSERT_FALSE(active_steps.empty());
    EXPECT_EQ(active_steps.front(), 40);
    EXPECT_EQ(active_steps.size(), 11u);
  }
}

// The same 6-rod grid with every rod turned about x by up to 1e-6 rad (alternating signs),
// the perturbation that rounding gives the 30-rod grid. Held at their closest points (d^P)
// the tilted pairs get their force at an end of the overlap; held at both overlap ends
// (ContactDirections::overlap_ends) each pair's tilt is what brings both ends to d_hat. Per
// step: no pair below d_hat (1 - margin). Measured with the default solver: d^P fails
// separation at the first contact step (step 40: pairs overlap inside the step); overlap ends
// run all 50 steps (11 with contact) and the largest turn grows from 1e-6 to 2e-6 rad.
TEST(TimeStepper, TiltedBiaxialRodGridWithOverlapEnds) {
  using RodStepper = sc::TimeStepper<sc::Spherocylinder, sc::FreeDrainingMobility>;
  const sc::Spherocylinder rod{1.0, 0.5};
  const double d_hat = 0.01 * rod.radius, tilt = 1e-6;
  std::vector<sc::Pose> poses;
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 3; ++col) {
      const int k = 3 * row + col;
      poses.push_back({sc::Vec3(0.0, 1.5 * (col - 1), 3.0 * (row - 0.5)),
                       sc::Quat(Eigen::AngleAxisd((k % 2 == 0 ? 1.0 : -1.0) * tilt * (k + 1) / 6.0, sc::Vec3::UnitX()))});
    }
  for (const sc::ContactDirections directions : {sc::ContactDirections::particle, sc::ContactDirections::overlap_ends}) {
    const bool ends = directions == sc::ContactDirections::overlap_ends;
    SCOPED_TRACE(ends ? "overlap ends" : "d^P");
    sc::FreeDrainingMobility mobility(sc::spherocylinder_mobility(rod, 1.0), poses.size(), 6);
    sc::TimeStepperOptions o = options(0.02, d_hat);
    o.background_flow = sc::LinearBackgroundFlow::biaxial_compression(1.0);
    o.contact_step.directions = directions;
    RodStepper stepper({rod}, poses, mobility, kDefault, o);
    double max_turn = 0.0;
    int steps = 0;
    try {
      for (int step = 1; step <= 50; ++step, ++steps) {
        const sc::StepDiagnostics& d = stepper.step();
        ASSERT_GE(d.min_distance_ratio, 1.0 - kMargin) << "step " << step;
        for (const sc::Pose& p : stepper.poses()) max_turn = std::max(max_turn, p.q.angularDistance(sc::Quat::Identity()));
      }
    } catch (const std::runtime_error& e) {
      std::printf("[tilted grid] %s: stopped after %d steps: %s\n", ends ? "overlap ends" : "d^P", steps, e.what());
      if (ends) ADD_FAILURE() << e.what();
    }
    std::printf("[tilted grid] %s: %d steps, largest turn %.3g rad\n", ends ? "overlap ends" : "d^P", steps, max_turn);
    if (ends) {
      EXPECT_EQ(steps, 50);
      EXPECT_LT(max_turn, 1e-5);
    }
  }
}

// A step whose contact solve fails separation throws and leaves Q_t. A at 0 rushes into B
// at 2.5; B, pushed by the contact, hits C at 4.6, a pair the trial step does not flag
// (B is at rest there, 0.1 > d_try away). Without guarantee rounds the solve must fail.
TEST(TimeStepper, FailedSeparationIsSurfacedAndTheStateKept) {
  const std::vector<sc::Pose> start = {{sc::Vec3(0, 0, 0), sc::Quat::Identity()},
                                       {sc::Vec3(2.5, 0, 0), sc::Quat::Identity()},
                                       {sc::Vec3(4.6, 0, 0), sc::Quat::Identity()}};
  sc::TimeStepperOptions o = options(0.1, 0.01);
  o.d_try = 0.015;
  sc::VecX F = sc::VecX::Zero(9);
  F(0) = 10.0 / kMu;
  sc::TimeStepperOptions no_guarantee = o;
  no_guarantee.contact_step.max_guarantee_rounds = 0;
  auto mobility = sphere_mobility(3, 3);
  SphereStepper stepper({sc::Sphere{1.0}}, start, mobility, kLcpSequence, no_guarantee);
  stepper.set_external_forces(F);
  int observed = 0;
  stepper.add_step_observer([&observed](const sc::StepDiagnostics&, std::span<const sc::Pose>) { ++observed; });
  try {
    stepper.step();
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("failed separation"), std::string::npos) << e.what();
  }
  EXPECT_EQ(stepper.time(), 0.0);
  EXPECT_EQ(stepper.steps_taken(), 0);
  EXPECT_TRUE(stepper.diagnostics().empty());
  EXPECT_EQ(observed, 0);  // observers see committed steps only
  for (std::size_t b = 0; b < 3; ++b) EXPECT_EQ(stepper.poses()[b].x, start[b].x);
  // The same step with the guarantee loop adds the B-C pair and succeeds.
  auto mobility2 = sphere_mobility(3, 3);
  SphereStepper guarded({sc::Sphere{1.0}}, start, mobility2, kLcpSequence, o);
  guarded.set_external_forces(F);
  const sc::StepDiagnostics& d = guarded.step();
  EXPECT_EQ(d.flagged_pairs, 2u);
  EXPECT_GE(brute_force_min_distance(guarded.poses()), 0.01 * (1.0 - kMargin));
}

// Observers run after every committed step, in the order added, with that step's diagnostics
// and Q_{t+dt} as the stepper holds it (centres wrapped into the box). Two spheres pushed
// along x against each other and across a periodic box: contacts and wraps both happen.
TEST(TimeStepper, ObserversSeeEveryStepWithTheCommittedPoses) {
  const double L = 8.0, d_hat = 0.01;
  sc::TimeStepperOptions o = options(0.05, d_hat);
  o.box = sc::PeriodicBox{sc::Vec3::Constant(L)};
  auto mobility = sphere_mobility(2, 3);
  SphereStepper stepper({sc::Sphere{1.0}},
                        {sc::Pose{sc::Vec3(4.0, 4.0, 4.0), sc::Quat::Identity()},
                         sc::Pose{sc::Vec3(6.5, 4.0, 4.0), sc::Quat::Identity()}},
                        mobility, o);
  sc::VecX F(6);
  F << 3.0 / kMu, 0, 0, 1.0 / kMu, 0, 0;  // the first catches up with the second: both go on at speed 2
  stepper.set_external_forces(F);
  struct Seen {
    int observer;
    long step;
    double time;
    std::vector<sc::Pose> poses;
  };
  std::vector<Seen> seen;
  for (const int id : {1, 2})
    stepper.add_step_observer([&stepper, &seen, id](const sc::StepDiagnostics& d, std::span<const sc::Pose> q) {
      // Called with the stepper's own state, already committed.
      EXPECT_EQ(&d, &stepper.diagnostics().back());
      EXPECT_EQ(d.step, stepper.steps_taken());
      EXPECT_EQ(d.time, stepper.time());
      EXPECT_EQ(q.data(), stepper.poses().data());
      EXPECT_EQ(q.size(), 2u);
      seen.push_back({id, d.step, d.time, std::vector<sc::Pose>(q.begin(), q.end())});
    });
  const int steps = 40;
  std::vector<std::vector<sc::Pose>> committed;
  std::size_t active = 0, wrapped = 0;
  for (int n = 1; n <= steps; ++n) {
    const sc::Vec3 before = stepper.poses()[1].x;
    active += stepper.step().active_pairs;
    committed.push_back(stepper.poses());
    wrapped += (stepper.poses()[1].x - before).norm() > 0.5 * L ? 1 : 0;
  }
  ASSERT_EQ(seen.size(), 2u * steps);
  for (int n = 1; n <= steps; ++n)
    for (int id : {1, 2}) {
      const Seen& s = seen[static_cast<std::size_t>(2 * (n - 1) + id - 1)];
      EXPECT_EQ(s.observer, id) << "step " << n;  // in the order added
      EXPECT_EQ(s.step, n);
      EXPECT_DOUBLE_EQ(s.time, n * o.dt);
      for (std::size_t b = 0; b < 2; ++b) {
        const sc::Pose& p = committed[static_cast<std::size_t>(n - 1)][b];
        EXPECT_EQ(s.poses[b].x, p.x) << "step " << n << " body " << b;
        EXPECT_EQ(s.poses[b].q.coeffs(), p.q.coeffs()) << "step " << n << " body " << b;
        EXPECT_TRUE((p.x.array() >= 0.0).all() && (p.x.array() < L).all()) << "step " << n << " body " << b;
      }
    }
  EXPECT_GT(active, 0u);   // the spheres did touch
  EXPECT_GT(wrapped, 0u);  // and crossed the box
  EXPECT_GE(brute_force_min_distance(stepper.poses(), L), d_hat * (1.0 - kMargin));
  // Cleared observers see nothing more.
  stepper.clear_step_observers();
  stepper.step();
  EXPECT_EQ(seen.size(), 2u * steps);
}

// The three ways to give a solver run the same step: no solver (the default), the default by
// value, and a custom callable around it, which gets TimeStepperOptions::contact_step.
TEST(TimeStepper, TheSolverIsTheDefaultUnlessGiven) {
  const std::vector<sc::Pose> start = {{sc::Vec3(0, 0, 0), sc::Quat::Identity()},
                                       {sc::Vec3(2.1, 0.3, 0), sc::Quat::Identity()},
                                       {sc::Vec3(4.2, 0, 0.2), sc::Quat::Identity()}};
  sc::VecX F = sc::VecX::Zero(9);
  F(0) = 20.0 / kMu;
  F(6) = -20.0 / kMu;
  sc::TimeStepperOptions o = options(0.01, 0.01);
  o.contact_step.cost = sc::MobilityCost::matrix_free;
  auto m1 = sphere_mobility(3, 3), m2 = sphere_mobility(3, 3), m3 = sphere_mobility(3, 3);
  SphereStepper implicit({sc::Sphere{1.0}}, start, m1, o);
  SphereStepper by_value({sc::Sphere{1.0}}, start, m2, sc::contact_solver_from_name("default"), o);
  int calls = 0;
  const CustomSphereSolver around_default = [&calls](const sc::ContactStepProblem<sc::Sphere>& p,
                                                     sc::FreeDrainingMobility& m, const sc::ContactStepOptions& c) {
    ++calls;
    EXPECT_EQ(c.cost, sc::MobilityCost::matrix_free);
    return sc::solve_contact_step_defect_correction(p, m, c);
  };
  SphereStepper custom({sc::Sphere{1.0}}, start, m3, around_default, o);
  std::size_t active = 0;
  for (SphereStepper* s : {&implicit, &by_value, &custom}) {
    s->set_external_forces(F);
    s->run(10);
  }
  for (const sc::StepDiagnostics& d : implicit.diagnostics()) active += d.active_pairs;
  EXPECT_GT(active, 0u);
  EXPECT_EQ(calls, 10);
  for (std::size_t b = 0; b < 3; ++b) {
    EXPECT_EQ(by_value.poses()[b].x, implicit.poses()[b].x) << "body " << b;
    EXPECT_EQ(custom.poses()[b].x, implicit.poses()[b].x) << "body " << b;
  }
  EXPECT_EQ(m1.applications(), m2.applications());
  EXPECT_EQ(m1.applications(), m3.applications());
}

TEST(TimeStepper, RejectsBadInputBeforeChangingAnything) {
  const std::vector<sc::Sphere> shape = {sc::Sphere{1.0}};
  const std::vector<sc::Pose> two = {{sc::Vec3(0, 0, 0), sc::Quat::Identity()},
                                     {sc::Vec3(3, 0, 0), sc::Quat::Identity()}};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto mobility = sphere_mobility(2, 3);
  auto make = [&](const sc::TimeStepperOptions& o) { SphereStepper s(shape, two, mobility, kLcpSequence, o); };
  for (const double dt : {0.0, -1.0, nan}) {
    sc::TimeStepperOptions o = options(dt, 0.01);
    expect_rejects([&] { make(o); }, "dt");
  }
  for (const double d_hat : {0.0, -0.1, nan}) {
    sc::TimeStepperOptions o = options(0.01, d_hat);
    expect_rejects([&] { make(o); }, "d_hat");
  }
  {
    sc::TimeStepperOptions o = options(0.01, 0.01);
    o.d_try = 0.005;
    expect_rejects([&] { make(o); }, "d_try");
    o.d_try = 0.0;
    o.d_try_multiplier = 0.5;
    expect_rejects([&] { make(o); }, "d_try_multiplier");
    o.d_try_multiplier = 1.0;
    o.box = sc::PeriodicBox{sc::Vec3(20, 20, 0)};
    expect_rejects([&] { make(o); }, "box.lengths");
    o.box = sc::PeriodicBox{sc::Vec3::Constant(20)};
    o.background_flow = sc::LinearBackgroundFlow::shear(1.0);
    expect_rejects([&] { make(o); }, "background_flow");
  }
  const sc::TimeStepperOptions good = options(0.01, 0.01);
  expect_rejects([&] { SphereStepper s(shape, two, mobility, CustomSphereSolver{}, good); }, "contact_solver");
  {
    sc::DefectCorrectionOptions bad_solver;
    bad_solver.tol = 0.0;
    expect_rejects([&] { SphereStepper s(shape, two, mobility, bad_solver, good); }, "DefectCorrectionOptions.tol");
    sc::TimeStepperOptions o = good;
    o.contact_step.separation_margin = 1.0;
    expect_rejects([&] { SphereStepper s(shape, two, mobility, o); }, "ContactStepOptions.separation_margin");
  }
  expect_rejects([&] { SphereStepper s(shape, two, mobility, kLcpSequence, good, nan); }, "t0");
  {
    auto wrong = sphere_mobility(3, 3);
    expect_rejects([&] { SphereStepper s(shape, two, wrong, kLcpSequence, good); }, "mobility");
  }
  expect_rejects([&] { SphereStepper s({sc::Sphere{1.0}, sc::Sphere{1.0}, sc::Sphere{1.0}}, two, mobility,
                                       kLcpSequence, good); },
                 "shapes");
  expect_rejects([&] { SphereStepper s(shape, {two[0], sc::Pose{sc::Vec3(1.5, 0, 0), sc::Quat::Identity()}},
                                       mobility, kLcpSequence, good); },
                 "poses");

  // Forces: rejected at set time, the previous forces kept.
  SphereStepper stepper(shape, two, mobility, kLcpSequence, good);
  SphereStepper twin(shape, two, mobility, kLcpSequence, good);
  sc::VecX F(6);
  F << 1, 2, 3, -1, 0, 0.5;
  stepper.set_external_forces(F);
  twin.set_external_forces(F);
  sc::VecX bad = F;
  bad(4) = nan;
  expect_rejects([&] { stepper.set_external_forces(bad); }, "external_forces");
  expect_rejects([&] { stepper.set_external_forces(sc::VecX::Ones(5)); }, "external_forces");
  expect_rejects([&] { stepper.set_external_force_field(sc::ExternalForceField{}); }, "external_forces");
  expect_rejects([&] { stepper.run(-1); }, "steps");
  expect_rejects([&] { stepper.add_step_observer(sc::StepObserver{}); }, "step_observer");
  stepper.step();
  twin.step();
  for (std::size_t b = 0; b < 2; ++b) EXPECT_EQ(stepper.poses()[b].x, twin.poses()[b].x);

  // A force field that returns bad forces is caught at the step, before anything moves.
  for (const sc::VecX& returned : {sc::VecX(sc::VecX::Ones(7)), bad}) {
    stepper.set_external_force_field([returned](double, std::span<const sc::Pose>) { return returned; });
    const std::vector<sc::Pose> before = stepper.poses();
    const double t = stepper.time();
    const std::size_t applications = mobility.applications();
    expect_rejects([&] { stepper.step(); }, "external_forces");
    EXPECT_EQ(stepper.time(), t);
    EXPECT_EQ(stepper.diagnostics().size(), 1u);
    EXPECT_EQ(mobility.applications(), applications);
    for (std::size_t b = 0; b < 2; ++b) EXPECT_EQ(stepper.poses()[b].x, before[b].x);
  }
}

// The careless step of ContactStep.RefusesACrowdedStepBeforeItsSolve (200 spheres at packing
// 0.3, |f| = 100, dt = 1: about 5 radii of motion) through the stepper: the refused interval
// is halved at once, without a solve, and its halves (here dt / 2 each) are solved; the step
// is committed with every gap held and every sub-step converged.
TEST(TimeStepper, TakesACarelessStepInSubSteps) {
  const std::size_t n = 200;
  const sc::SpherePacking packing = sc::random_sequential_addition(n, 0.3, 5);
  sc::Rng rng(5);
  const std::vector<sc::Vec3> f = sc::random_forces(n, 100.0, rng);
  sc::VecX F(3 * static_cast<Eigen::Index>(n));
  for (std::size_t k = 0; k < n; ++k) F.segment<3>(3 * static_cast<Eigen::Index>(k)) = f[k];
  auto mobility = sphere_mobility(n, 3);
  sc::TimeStepperOptions o = options(1.0, 0.01);
  o.max_substep_halvings = 8;
  SphereStepper stepper({sc::Sphere{1.0}}, packing.poses, mobility, kDefault, o);
  stepper.set_external_forces(F);
  const sc::StepDiagnostics& d = stepper.step();
  EXPECT_GE(d.substeps, 2);
  EXPECT_EQ(d.status, sc::ContactStepStatus::converged) << d.message;
  EXPECT_GE(brute_force_min_distance(stepper.poses()), 0.01 * (1.0 - kMargin));
  EXPECT_GE(d.min_distance_ratio, 1.0 - kMargin);  // the least over the sub-steps' ends
  double moved = 0.0;
  for (std::size_t k = 0; k < n; ++k) moved = std::max(moved, (stepper.poses()[k].x - packing.poses[k].x).norm());
  EXPECT_GT(moved, 2.0);  // the bodies did move several radii
}

}  // namespace

}  // namespace time_stepper_tests
