// No tunnelling: contact over the whole step (geometry/swept_distance.hpp,
// contact/continuous_detection.hpp, the carried contacts and the interior check of
// contact/contact_step.hpp, the time stepper's sub-steps), and a flagged set that depends on
// relative motion only.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <numbers>
#include <random>
#include <optional>
#include <set>
#include <span>
#include <utility>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/contact/continuous_detection.hpp"
#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/dynamics/time_stepper.hpp"
#include "stokescontact/geometry/swept_distance.hpp"
#include "stokescontact/mobility/boomerang_blobs.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/mobility/single_body_mobility.hpp"
#include "stokescontact/scenes/periodic_placement.hpp"
#include "stokescontact/scenes/random.hpp"
#include "stokescontact/scenes/sphere_packing.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace continuous_detection_tests {

namespace sc = stokescontact;

namespace {

constexpr double kDHat = 0.01;
constexpr double kMargin = 1e-3;  // ContactStepOptions' default separation margin

sc::Quat turn(double angle, const sc::Vec3& axis) { return sc::Quat(Eigen::AngleAxisd(angle, axis.normalized())); }

// Brute force: d(t) at n + 1 equally spaced times.
template <sc::Shape A, sc::Shape B>
std::vector<double> sampled(const A& a, const sc::Pose& pa, const sc::RigidVelocity& va, const B& b, const sc::Pose& pb,
                            const sc::RigidVelocity& vb, double T, int n) {
  std::vector<double> d;
  for (int k = 0; k <= n; ++k) {
    const double t = T * k / n;
    d.push_back(sc::closest_points(a, sc::advance(pa, va.u, va.omega, t), b, sc::advance(pb, vb.u, vb.omega, t)).distance);
  }
  return d;
}

// Two crossing rods, one spinning and drifting: the swept queries against dense sampling.
TEST(SweptDistance, RotatingRodsAgreeWithDenseSampling) {
  const sc::Spherocylinder rod{2.0, 0.1};
  sc::Rng rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const sc::Pose pa{sc::Vec3::Zero(), sc::random_rotation(rng)};
    const sc::Pose pb{sc::Vec3(0.0, 0.0, 1.0) + 0.3 * sc::random_unit_vector(rng), sc::random_rotation(rng)};
    if (sc::closest_points(rod, pa, rod, pb).distance < 0.05) continue;
    const sc::RigidVelocity va{sc::Vec3::Zero(), 3.0 * sc::random_unit_vector(rng)};
    const sc::RigidVelocity vb{sc::Vec3(0.0, 0.0, -1.5) + 0.5 * sc::random_unit_vector(rng), 2.0 * sc::random_unit_vector(rng)};
    const double T = 1.0;
    const std::vector<double> d = sampled(rod, pa, va, rod, pb, vb, T, 20000);
    const double brute_min = *std::min_element(d.begin(), d.end());
    const sc::SweptDistance m = sc::swept_minimum(rod, pa, va, rod, pb, vb, T, 1e-4, 2000);
    EXPECT_LE(m.lower_bound, brute_min + 1e-12);
    EXPECT_NEAR(m.points.distance, brute_min, 2e-4);  // sampling is ~1e-4 fine in time
    for (const double threshold : {0.0, 0.05, 0.2}) {
      const sc::SweptDistance f = sc::first_time_below(rod, pa, va, rod, pb, vb, T, threshold, 1e-6);
      const auto first = std::find_if(d.begin(), d.end(), [&](double x) { return x <= threshold; });
      EXPECT_EQ(f.below, first != d.end() || brute_min <= threshold + 1e-6) << "threshold " << threshold;
      if (f.below) {
        EXPECT_LE(f.points.distance, threshold + 1e-6);
        // Never after the sampled first crossing, never before the true one (d > threshold before).
        if (first != d.end()) {
          EXPECT_LE(f.time, T * static_cast<double>(first - d.begin()) / 20000 + 1e-12);
        }
        for (int k = 0; k * T / 20000 < f.time - 1e-9; ++k) ASSERT_GT(d[static_cast<std::size_t>(k)], threshold);
      }
    }
  }
}

// Spheres: the closed form, against the same brute force.
TEST(SweptDistance, SpheresHaveTheClosedFormNearestApproach) {
  const sc::Sphere s{1.0};
  const sc::Pose pa{sc::Vec3::Zero(), sc::Quat::Identity()}, pb{sc::Vec3(3.0, 0.5, 0.0), sc::Quat::Identity()};
  const sc::RigidVelocity va{sc::Vec3(2.0, 0.0, 0.0)}, vb{sc::Vec3(-2.0, 0.0, 0.0)};
  const sc::SweptDistance m = sc::swept_minimum(s, pa, va, s, pb, vb, 2.0, 1e-9);
  EXPECT_NEAR(m.time, 0.75, 1e-15);
  EXPECT_NEAR(m.points.distance, 0.5 - 2.0, 1e-15);
  // |(3 - 4t, 0.5)| = 2 first at t = (3 - sqrt(3.75)) / 4.
  const sc::SweptDistance f = sc::first_time_below(s, pa, va, s, pb, vb, 2.0, 0.0, 1e-12);
  EXPECT_TRUE(f.below);
  EXPECT_NEAR(f.time, (3.0 - std::sqrt(3.75)) / 4.0, 1e-14);
  EXPECT_FALSE(sc::first_time_below(s, pa, va, s, pb, vb, 0.1, 0.0, 1e-12).below);
}

// trajectory_crossings within a CrossingScope finds what the whole check finds, when the
// unscoped pairs are those the trial step did not flag (DTryRule::relative) and the scope's
// moved bodies are those whose velocity differs from the trial one: the contact step's
// guarantee after a correction. Spheres in open space (with a few bodies fast enough for
// the broad phase's all-against-one path) and rods turning in a periodic box; trial motions
// that pass pairs through each other and corrections that do, so that both the flagged pairs
// of unmoved bodies and the moved bodies' pairs cross. Crossings compared field by field.
template <sc::Shape S>
void expect_scoped_crossings_are_all(std::span<const S> shapes, std::span<const sc::Pose> poses, const sc::VecX& U,
                                     int dofs, double dt, const std::optional<sc::PeriodicBox>& box, sc::Rng& rng) {
  const std::vector<sc::Pose> trial = sc::advance_all(poses, U, dofs, dt);
  const sc::RelativePairs flagged = sc::find_pairs_relative(shapes, std::span<const sc::Pose>(trial), U, dofs, dt,
                                                            kDHat, 1.0, box);
  std::vector<sc::BodyPair> flagged_pairs;
  for (const sc::ContactPair& p : flagged.pairs) flagged_pairs.push_back({p.i, p.j});
  for (const double fraction : {0.0, 0.1, 0.5}) {
    sc::VecX V = U;
    std::vector<char> moved(poses.size(), 0);
    for (std::size_t b = 0; b < poses.size(); ++b) {
      if (std::uniform_real_distribution<double>(0.0, 1.0)(rng) >= fraction) continue;
      moved[b] = 1;
      V.segment<3>(static_cast<Eigen::Index>(b) * dofs) += (1.5 / dt) * sc::random_unit_vector(rng);
      if (dofs == 6) V.segment<3>(static_cast<Eigen::Index>(b) * dofs + 3) += (1.0 / dt) * sc::random_unit_vector(rng);
    }
    const sc::CrossingScope scope{moved, flagged_pairs};
    for (const double threshold : {-kMargin * kDHat, 0.5 * kDHat}) {
      SCOPED_TRACE("moved fraction " + std::to_string(fraction) + ", threshold " + std::to_string(threshold));
      const std::vector<sc::TrajectoryCrossing> all =
          sc::trajectory_crossings(shapes, poses, V, dofs, dt, threshold, 1e-4 * kDHat, box);
      sc::CellList cells;
      const std::vector<sc::TrajectoryCrossing> scoped =
          sc::trajectory_crossings(shapes, poses, V, dofs, dt, threshold, 1e-4 * kDHat, box, &cells, &scope);
      ASSERT_GT(all.size(), 0u);
      ASSERT_EQ(scoped.size(), all.size());
      bool unmoved_crossing = false;
      for (std::size_t k = 0; k < all.size(); ++k) {
        EXPECT_EQ(scoped[k].i, all[k].i);
        EXPECT_EQ(scoped[k].j, all[k].j);
        EXPECT_TRUE(scoped[k].image_shift == all[k].image_shift);
        EXPECT_EQ(scoped[k].first.time, all[k].first.time);
        EXPECT_EQ(scoped[k].first.points.distance, all[k].first.points.distance);
        unmoved_crossing |= !moved[static_cast<std::size_t>(all[k].i)] && !moved[static_cast<std::size_t>(all[k].j)];
      }
      EXPECT_TRUE(unmoved_crossing) << "the trial motion must pass some pair through";
    }
  }
}

TEST(NoTunnelling, ScopedCrossingsAreEveryCrossingAfterACorrection) {
  sc::Rng rng(41);
  {
    const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
    const std::vector<sc::Pose> poses = sc::random_sequential_addition(800, 0.3, 41).poses;
    const double dt = 0.01;
    sc::VecX U(3 * static_cast<Eigen::Index>(poses.size()));
    for (std::size_t b = 0; b < poses.size(); ++b)  // up to 1.5 radii per step, three bodies 6
      U.segment<3>(3 * static_cast<Eigen::Index>(b)) = ((b % 300 == 0 ? 6.0 : 1.5) / dt) * sc::random_unit_vector(rng);
    expect_scoped_crossings_are_all(std::span<const sc::Sphere>(shapes), std::span<const sc::Pose>(poses), U, 3, dt,
                                    std::nullopt, rng);
  }
  {
    const sc::Spherocylinder rod{1.0, 0.2};
    const double side = 12.0;
    const std::vector<sc::Pose> poses = sc::periodic_random_placement(rod, 150, side, 0.01, 42);
    const double dt = 0.01;
    sc::VecX U(6 * static_cast<Eigen::Index>(poses.size()));
    for (std::size_t b = 0; b < poses.size(); ++b) {
      U.segment<3>(6 * static_cast<Eigen::Index>(b)) = (0.5 / dt) * sc::random_unit_vector(rng);
      U.segment<3>(6 * static_cast<Eigen::Index>(b) + 3) = (0.8 / dt) * sc::random_unit_vector(rng);
    }
    const std::vector<sc::Spherocylinder> shapes{rod};
    expect_scoped_crossings_are_all(std::span<const sc::Spherocylinder>(shapes), std::span<const sc::Pose>(poses), U, 6,
                                    dt, sc::PeriodicBox{sc::Vec3::Constant(side)}, rng);
  }
}

struct HeadOn {
  std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  std::vector<sc::Pose> poses{{sc::Vec3(0, 0, 0), sc::Quat::Identity()}, {sc::Vec3(2.2, 0, 0), sc::Quat::Identity()}};
  sc::VecX U = (sc::VecX(6) << 10, 0, 0, -10, 0, 0).finished();
};

// The case: x = 0 and 2.2 at +-10, d_hat = 0.01. Before: at dt = 0.3 converged with no
// force, the spheres at 3.0 and -0.8 (passed through); at dt >= 0.5 not even flagged.
// Also in a frame shifted by 1e4 and carried along at 1e3 in all three directions.
TEST(NoTunnelling, HeadOnSpheresNeverPassAtAnyStep) {
  for (const double frame : {0.0, 1e4})
  for (double dt = 0.01; dt <= 10.0 + 1e-9; dt *= std::pow(10.0, 0.125)) {
    SCOPED_TRACE("dt " + std::to_string(dt) + " frame " + std::to_string(frame));
    HeadOn s;
    for (sc::Pose& p : s.poses) p.x += sc::Vec3::Constant(frame);
    for (Eigen::Index k = 0; k < 6; ++k) s.U(k) += 0.1 * frame;
    sc::FreeDrainingMobility m(sc::sphere_mobility(s.shapes[0], 1.0), 2, 3);
    const sc::ContactStepProblem<sc::Sphere> p{s.shapes, s.poses, s.U, dt, kDHat};
    for (const sc::ContactSolver& solver : {sc::ContactSolver{}, sc::contact_solver_from_name("lcp-newton")}) {
      const sc::ContactStepResult r = sc::solve_contact_step(p, m, {}, solver);
      EXPECT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
      const double gap = r.poses[1].x.x() - r.poses[0].x.x() - 2.0;
      EXPECT_GE(gap, kDHat * (1.0 - kMargin));  // on the side they started, d_hat apart
      EXPECT_LE(gap, 0.2 + 1e-9);               // and no farther than they started
      EXPECT_TRUE(sc::trajectory_crossings(std::span<const sc::Sphere>(s.shapes), std::span<const sc::Pose>(s.poses),
                                           r.velocities, 3, dt, 0.0, 1e-9)
                      .empty());
      if (dt * 20.0 > 4.2) {
        EXPECT_EQ(r.carried_pairs, 1u);  // the trial step passed through
      }
    }
  }
}

// A thin rod (R = L/20, Fig. 7's) falls across another at right angles at 10-1000 radii per
// step: it must stop above it.
TEST(NoTunnelling, ThinRodsCrossingAtRightAnglesStopAbove) {
  const sc::Spherocylinder rod{0.5, 0.025};
  const std::vector<sc::Spherocylinder> shapes{rod};
  const double dt = 0.05;
  for (const double radii_per_step : {10.0, 100.0, 1000.0}) {
    SCOPED_TRACE(radii_per_step);
    const std::vector<sc::Pose> poses{
        {sc::Vec3::Zero(), turn(0.5 * std::numbers::pi, sc::Vec3::UnitY())},                      // along x
        {sc::Vec3(0.0, 0.0, 2.0 * rod.radius + 0.05), turn(0.5 * std::numbers::pi, sc::Vec3::UnitX())}};  // along y
    sc::VecX U = sc::VecX::Zero(12);
    U(8) = -radii_per_step * rod.radius / dt;
    sc::FreeDrainingMobility m(sc::spherocylinder_mobility(rod, 1.0), 2, 6);
    const sc::ContactStepProblem<sc::Spherocylinder> p{shapes, poses, U, dt, kDHat};
    const sc::ContactStepResult r = sc::solve_contact_step(p, m);
    EXPECT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
    EXPECT_GE(r.poses[1].x.z() - r.poses[0].x.z(), 2.0 * rod.radius + kDHat * (1.0 - kMargin));
    EXPECT_GE(r.min_distance_ratio, 1.0 - kMargin);
    EXPECT_TRUE(sc::trajectory_crossings(std::span<const sc::Spherocylinder>(shapes), std::span<const sc::Pose>(poses),
                                         r.velocities, 6, dt, 0.0, 1e-9)
                    .empty());
    // The rods stay crossed at right angles: held by a force through both centres.
    EXPECT_LT(r.poses[1].q.angularDistance(poses[1].q), 1e-9);
  }
}

// A rod turning about its centre: its tip sweeps an arc whose middle dips 0.05 into a rod
// lying across it, while at both ends of the step the tip is 0.039 clear (2 (1 - cos 0.3)
// above the dip). The carried contact bounds the gap of the material points at the end of
// the step, which the arc passes; the pair still overlaps inside the step, and an interior
// contact holds it at the time it comes closest. Every solver: no overlap anywhere along
// the corrected motion (dense sampling), and the force a fraction of what a stop would need.
TEST(NoTunnelling, RodTipSweepingAnArcThroughAnotherIsHeldInside) {
  const sc::Spherocylinder rod{4.0, 0.5};
  const std::vector<sc::Spherocylinder> shapes{rod};
  const double dt = 0.01, sweep = 0.6;  // radians turned in the step, about y
  const double dip = 0.05;              // how far the tip's arc reaches into the lower rod
  const double height = 0.5 * rod.length + 2.0 * rod.radius - dip;
  // Rod 0 along y at the origin; rod 1 hangs along -z from (0, 0, height), turned back by
  // sweep / 2 about y so that the step's turn takes its tip from x = -0.59 to x = +0.59.
  const std::vector<sc::Pose> poses{{sc::Vec3::Zero(), turn(0.5 * std::numbers::pi, sc::Vec3::UnitX())},
                                    {sc::Vec3(0.0, 0.0, height), turn(-0.5 * sweep, sc::Vec3::UnitY())}};
  sc::VecX U = sc::VecX::Zero(12);
  U(10) = sweep / dt;  // omega_y of rod 1
  const auto span_shapes = std::span<const sc::Spherocylinder>(shapes);
  const auto span_poses = std::span<const sc::Pose>(poses);
  ASSERT_GT(sc::minimum_pair_distance(span_shapes, span_poses).distance, 0.03);
  const std::vector<sc::Pose> trial = sc::advance_all(span_poses, U, 6, dt);
  ASSERT_GT(sc::minimum_pair_distance(span_shapes, std::span<const sc::Pose>(trial)).distance, 0.03);
  const sc::RigidVelocity still{}, turning{sc::Vec3::Zero(), U.segment<3>(9)};
  ASSERT_LT(sc::swept_minimum(rod, poses[0], still, rod, poses[1], turning, dt, 1e-9).points.distance, -0.049);
  sc::FreeDrainingMobility m(sc::spherocylinder_mobility(rod, 1.0), 2, 6);
  const sc::ContactStepProblem<sc::Spherocylinder> p{shapes, poses, U, dt, kDHat};
  for (const char* name : {"default", "lcp-newton", "lcp-bbpgd"}) {
    SCOPED_TRACE(name);
    const sc::ContactStepResult r = sc::solve_contact_step(p, m, {}, sc::contact_solver_from_name(name));
    ASSERT_NE(r.status, sc::ContactStepStatus::failed_separation) << r.message;
    EXPECT_GE(r.carried_pairs, 1u);
    EXPECT_GE(r.min_distance_ratio, 1.0 - kMargin);
    const sc::RigidVelocity v0{r.velocities.segment<3>(0), r.velocities.segment<3>(3)};
    const sc::RigidVelocity v1{r.velocities.segment<3>(6), r.velocities.segment<3>(9)};
    const std::vector<double> d = sampled(rod, poses[0], v0, rod, poses[1], v1, dt, 4000);
    EXPECT_GE(*std::min_element(d.begin(), d.end()), -kMargin * kDHat);
    // Lifting the tip by the dip over half the step takes a velocity of ~dip / (dt / 2); a
    // contact force that stopped the turn instead would be far larger (the turn is 60 rad/s).
    EXPECT_LT((r.velocities.segment<3>(9) - U.segment<3>(9)).norm(), 0.5 * sweep / dt);
  }
}

// A boomerang spins a full turn in one step beside another (0.54 apart at the start and the
// end): along the unconstrained motion its arms sweep through the other. The step holds it
// (interior contacts where the arms pass); never an overlap inside the step it returns.
TEST(NoTunnelling, BoomerangArmSweepingThroughAnotherIsHeld) {
  const sc::Boomerang b;
  const std::vector<sc::Boomerang> shapes{b};
  const std::vector<sc::Pose> poses{{sc::Vec3::Zero(), sc::Quat::Identity()},
                                    {sc::Vec3(-2.0, 0.0, -2.0), turn(std::numbers::pi, sc::Vec3::UnitY())}};
  ASSERT_GT(sc::minimum_pair_distance(std::span<const sc::Boomerang>(shapes), std::span<const sc::Pose>(poses)).distance,
            0.5);
  sc::VecX U = sc::VecX::Zero(12);
  U.segment<3>(9) = sc::Vec3(0.0, 2.0 * std::numbers::pi / 0.01, 0.0);  // a full turn in one step of 0.01
  const double dt = 0.01;
  sc::FreeDrainingMobility m(sc::single_body_mobility(sc::boomerang_curve_blobs(b), 1.0), 2, 6);
  // Along the unconstrained motion the arm does pass through A.
  ASSERT_FALSE(sc::trajectory_crossings(std::span<const sc::Boomerang>(shapes), std::span<const sc::Pose>(poses), U, 6,
                                        dt, 0.0, 1e-9)
                   .empty());
  const sc::ContactStepProblem<sc::Boomerang> p{shapes, poses, U, dt, kDHat};
  const sc::ContactStepResult r = sc::solve_contact_step(p, m);
  std::printf("[boomerang sweep] status %s carried %zu flagged %zu apps %zu min d/d_hat %.6f\n",
              std::string(sc::to_string(r.status)).c_str(), r.carried_pairs, r.flagged_pairs, r.mobility_applications,
              r.min_distance_ratio);
  ASSERT_NE(r.status, sc::ContactStepStatus::failed_separation) << r.message;
  EXPECT_TRUE(sc::trajectory_crossings(std::span<const sc::Boomerang>(shapes), std::span<const sc::Pose>(poses),
                                       r.velocities, 6, dt, -kMargin * kDHat, 1e-9)
                  .empty());
  EXPECT_GE(r.min_distance_ratio, 1.0 - kMargin);
}

// Sub-stepping: the spinning boomerang of the previous test, now driven by a torque through
// the time stepper, with the guarantee rounds switched off (the step holds only what its
// trial motion flags; the previous test's step needs its interior contacts). One step cannot
// hold it (the end state alone is clear); with sub-steps each piece turns a fraction of the
// way and is held.
TEST(NoTunnelling, TimeStepperSubStepsWhatOneStepCannotHold) {
  const sc::Boomerang b;
  const std::vector<sc::Pose> poses{{sc::Vec3::Zero(), sc::Quat::Identity()},
                                    {sc::Vec3(-2.0, 0.0, -2.0), turn(std::numbers::pi, sc::Vec3::UnitY())}};
  const sc::Mat6 body = sc::single_body_mobility(sc::boomerang_curve_blobs(b), 1.0);
  sc::FreeDrainingMobility m(body, 2, 6);
  sc::VecX F = sc::VecX::Zero(12);  // the wrench that spins B a full turn per step about y
  const sc::Vec6 spin = (sc::Vec6() << 0, 0, 0, 0, 2.0 * std::numbers::pi / 0.01, 0).finished();
  m.set_configuration(poses);
  {
    sc::VecX unit = sc::VecX::Zero(12);
    sc::Mat6 M_b;
    for (int c = 0; c < 6; ++c) {
      unit.setZero();
      unit(6 + c) = 1.0;
      M_b.col(c) = m.apply(unit).segment<6>(6);
    }
    F.segment<6>(6) = M_b.ldlt().solve(spin);
  }
  sc::TimeStepperOptions o;
  o.dt = 0.01;
  o.d_hat = kDHat;
  o.max_substep_halvings = 0;
  o.contact_step.max_guarantee_rounds = 0;
  {
    sc::TimeStepper<sc::Boomerang, sc::FreeDrainingMobility> stepper({b}, poses, m, o);
    stepper.set_external_forces(F);
    EXPECT_THROW(stepper.step(), std::runtime_error);
    EXPECT_EQ(stepper.steps_taken(), 0);
  }
  o.max_substep_halvings = 6;
  sc::TimeStepper<sc::Boomerang, sc::FreeDrainingMobility> stepper({b}, poses, m, o);
  stepper.set_external_forces(F);
  const sc::StepDiagnostics d = stepper.step();
  std::printf("[boomerang sweep, stepper] substeps %zu applications %zu min d/d_hat %.6f\n", d.substeps,
              d.mobility_applications, d.min_distance_ratio);
  EXPECT_GT(d.substeps, 1u);
  EXPECT_NEAR(stepper.time(), 0.01, 1e-15);
  EXPECT_GE(d.min_distance_ratio, 1.0 - kMargin);
}

// 1000 spheres in one simple shear u = rate y e_x, the suspension centred at y = 0, 1e3 and 1e4:
// the same relative motion, so the same flagged pairs (the issue measured 382, 129 492 and all
// 499 500 with eq. 31).
TEST(GalileanInvariance, ShearedSuspensionFlagsTheSamePairsWhereverItIs) {
  const sc::SpherePacking packing = sc::random_sequential_addition(1000, 0.2, 5);
  const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  const double rate = 1.0, dt = 0.01;
  std::set<std::pair<Eigen::Index, Eigen::Index>> reference;
  std::size_t absolute_far = 0;
  for (const double centre : {0.0, 1e3, 1e4}) {
    std::vector<sc::Pose> poses = packing.poses;
    sc::VecX U(3000);
    for (std::size_t k = 0; k < poses.size(); ++k) {
      poses[k].x.y() += centre - 0.5 * packing.side;
      U.segment<3>(3 * static_cast<Eigen::Index>(k)) = sc::Vec3(rate * poses[k].x.y(), 0, 0);
    }
    const std::vector<sc::Pose> trial = sc::advance_all(poses, U, 3, dt);
    const sc::RelativePairs found = sc::find_pairs_relative(std::span<const sc::Sphere>(shapes),
                                                            std::span<const sc::Pose>(trial), U, 3, dt, kDHat, 1.0);
    std::set<std::pair<Eigen::Index, Eigen::Index>> flagged;
    for (const sc::ContactPair& p : found.pairs) flagged.insert({p.i, p.j});
    if (centre == 0.0) reference = flagged;
    EXPECT_EQ(flagged, reference) << "centre " << centre;
    std::printf("[shear] centre %g: %zu flagged (relative)\n", centre, flagged.size());
    if (centre == 1e4)
      absolute_far = sc::find_contact_pairs(std::span<const sc::Sphere>(shapes), std::span<const sc::Pose>(trial),
                                            sc::d_try_spheres(kDHat, dt, U, 3))
                         .size();
  }
  EXPECT_GT(reference.size(), 0u);
  EXPECT_GT(absolute_far, 100 * reference.size());  // eq. 31 there: nearly every pair
}

// The per-pair rule against brute force over all pairs, with one body 1000 times faster than
// the rest (it is tested against every body rather than coarsening the cell list).
TEST(GalileanInvariance, RelativeFlagsMatchBruteForceWithAFastBody) {
  const sc::SpherePacking packing = sc::random_sequential_addition(300, 0.2, 9);
  const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  sc::Rng rng(3);
  sc::VecX U(900);
  for (Eigen::Index k = 0; k < 300; ++k) U.segment<3>(3 * k) = 2.0 * sc::random_unit_vector(rng);
  U.segment<3>(0) = sc::Vec3(2000.0, 0.0, 0.0);
  const double dt = 0.01;
  const std::vector<sc::Pose> trial = sc::advance_all(packing.poses, U, 3, dt);
  const sc::RelativePairs found =
      sc::find_pairs_relative(std::span<const sc::Sphere>(shapes), std::span<const sc::Pose>(trial), U, 3, dt, kDHat, 1.1);
  std::set<std::pair<Eigen::Index, Eigen::Index>> flagged, brute;
  for (const sc::ContactPair& p : found.pairs) flagged.insert({p.i, p.j});
  std::size_t with_fast = 0;
  for (Eigen::Index i = 0; i < 300; ++i)
    for (Eigen::Index j = i + 1; j < 300; ++j) {
      const double d = (trial[static_cast<std::size_t>(j)].x - trial[static_cast<std::size_t>(i)].x).norm() - 2.0;
      const double d_try = 1.1 * (kDHat + dt * (U.segment<3>(3 * i) - U.segment<3>(3 * j)).norm());
      if (d <= d_try) {
        brute.insert({i, j});
        with_fast += i == 0 ? 1 : 0;
      }
    }
  EXPECT_EQ(flagged, brute);
  EXPECT_GT(with_fast, 0u);  // the fast body's sweep does reach others
}

}  // namespace

}  // namespace continuous_detection_tests
