// Contact steps with surface-node contact directions (d^S, Broms & Tornberg eq. 22-23).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <span>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/solvers/barrier_nlopt.hpp"
#include "stokescontact/contact/solvers/defect_correction.hpp"
#include "stokescontact/contact/solvers/lcp_sequence.hpp"
#include "stokescontact/core/rigid_motion.hpp"
#include "stokescontact/dynamics/time_stepper.hpp"
#include "stokescontact/mobility/boomerang_blobs.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/mobility/single_body_mobility.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace contact_step_surface_tests {

namespace sc = stokescontact;

namespace {

using test_support::random_rotation;
using test_support::random_unit_vector;
using test_support::uniform_vector;

// Two unit spheres on the z axis (the node grid's axis) approaching head on: the surface-node
// column is the d^P column exactly (by symmetry), so lambda is the closed form of
// test_contact_step.cpp, lambda* = (d_hat - d*) / (2 mu dt), d* = gap - 2 v dt.
TEST(ContactStepSurface, AlignedSpheresMatchTheClosedForm) {
  const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  const std::vector<sc::Pose> poses = {{sc::Vec3::Zero(), sc::Quat::Identity()},
                                       {sc::Vec3(0, 0, 2.1), sc::Quat::Identity()}};
  sc::VecX U(6);
  U << 0, 0, 10, 0, 0, -10;
  const double dt = 0.01, d_hat = 0.01, mu = 1.0 / (6.0 * std::numbers::pi);
  const double lambda_star = (d_hat - (0.1 - 2.0 * 10.0 * dt)) / (2.0 * mu * dt);
  const sc::ContactStepProblem<sc::Sphere> p{shapes, poses, U, dt, d_hat, 0.0, 1.0, {}};
  sc::ContactStepOptions options;
  options.directions = sc::ContactDirections::surface;
  options.node_spacing = 0.1;
  sc::FreeDrainingMobility m(sc::sphere_mobility(shapes[0], 1.0), 2, 3);
  const sc::ContactStepResult r = sc::solve_contact_step_lcp_sequence(p, m, options);
  EXPECT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
  ASSERT_EQ(r.lambda.size(), 1);
  EXPECT_NEAR(r.lambda(0), lambda_star, 1e-8 * lambda_star);
  EXPECT_LE(r.contact_forces.head<2>().norm() + r.contact_forces.segment<2>(3).norm(), 1e-12 * lambda_star);
}

struct BoomerangScene {
  sc::Boomerang shape = sc::broms_tornberg_boomerang();
  std::vector<sc::Pose> poses;
  sc::VecX U;
  sc::Mat6 body_mobility = sc::single_body_mobility(sc::boomerang_curve_blobs(shape), 1.0);
};

// n boomerangs in a cube, pairwise gaps > 0.05, random translations and rotations.
BoomerangScene random_boomerangs(std::uint64_t seed, std::size_t n, double side) {
  std::mt19937_64 rng(seed);
  BoomerangScene s;
  while (s.poses.size() < n) {
    const sc::Pose p{uniform_vector(rng, 0.0, side), random_rotation(rng)};
    bool ok = true;
    for (const sc::Pose& q : s.poses) ok = ok && sc::closest_points(s.shape, p, s.shape, q).distance > 0.05;
    if (ok) s.poses.push_back(p);
  }
  s.U.resize(6 * static_cast<Eigen::Index>(n));
  for (Eigen::Index b = 0; b < static_cast<Eigen::Index>(n); ++b) {
    s.U.segment<3>(6 * b) = 40.0 * random_unit_vector(rng);
    s.U.segment<3>(6 * b + 3) = 5.0 * random_unit_vector(rng);
  }
  return s;
}

// Total force and total torque about the origin of body forces and torques applied at `poses`.
sc::Vec6 net_wrench(const sc::VecX& forces, const std::vector<sc::Pose>& poses) {
  sc::Vec6 net = sc::Vec6::Zero();
  for (std::size_t b = 0; b < poses.size(); ++b) {
    const sc::Vec3 f = forces.segment<3>(6 * static_cast<Eigen::Index>(b));
    net.head<3>() += f;
    net.tail<3>() += poses[b].x.cross(f) + forces.segment<3>(6 * static_cast<Eigen::Index>(b) + 3);
  }
  return net;
}

// Boomerangs default to d^S: every solver separates the scene, forces and torques balance
// (each node pair is an equal and opposite force pair), and the directions differ from d^P.
// Seed 42 is left out: the barrier method (SLSQP) does not separate its scene within 1000
// evaluations (min d / d_hat = -24); every other scene of seeds 41-70 it separates.
TEST(ContactStepSurface, BoomerangsDefaultToSurfaceNodesAndSeparate) {
  for (const std::uint64_t seed : {41u, 44u}) {
    const BoomerangScene s = random_boomerangs(seed, 14, 5.0);
    const std::vector<sc::Boomerang> shapes{s.shape};
    const sc::ContactStepProblem<sc::Boomerang> p{shapes, s.poses, s.U, 0.01, 0.02, 0.0, 1.0, {}};
    const auto mobility = [&] { return sc::FreeDrainingMobility(s.body_mobility, s.poses.size(), 6); };
    sc::ContactStepOptions particle;
    particle.directions = sc::ContactDirections::particle;
    auto m0 = mobility(), m1 = mobility(), m2 = mobility(), m3 = mobility();
    const sc::ContactStepResult by_default = sc::solve_contact_step_defect_correction(p, m0);
    const sc::ContactStepResult by_particle = sc::solve_contact_step_defect_correction(p, m1, particle);
    const sc::ContactStepResult lcp = sc::solve_contact_step_lcp_sequence(p, m2);
    const sc::ContactStepResult barrier = sc::solve_contact_step_barrier(p, m3);
    sc::BarrierNloptOptions on_working_set;  // eq. 15 on the default solver's working set
    on_working_set.constraint = sc::BarrierConstraint::working_set;
    on_working_set.tol = sc::DefectCorrectionOptions{}.tol;
    auto m4 = mobility();
    const sc::ContactStepResult working_set = sc::solve_contact_step_barrier(p, m4, {}, on_working_set);
    // D acts at the trial step Q* (eq. 16): the torques balance about its centres.
    std::vector<sc::Pose> trial;
    for (std::size_t b = 0; b < s.poses.size(); ++b) {
      const Eigen::Index row = 6 * static_cast<Eigen::Index>(b);
      trial.push_back(sc::advance(s.poses[b], s.U.segment<3>(row), s.U.segment<3>(row + 3), 0.01));
    }
    ASSERT_GT(by_default.lambda_max, 0.0) << "seed " << seed << ": no contact force, the test needs one";
    for (const sc::ContactStepResult* r : {&by_default, &by_particle, &lcp, &barrier, &working_set}) {
      std::printf("[boomerangs seed %d] status %d Nc %zu apps %zu iters %d sum %.6f min d/d_hat %.9f\n",
                  static_cast<int>(seed), static_cast<int>(r->status), r->flagged_pairs, r->mobility_applications,
                  r->iterations, r->lambda_sum, r->min_distance_ratio);
      EXPECT_EQ(r->status, sc::ContactStepStatus::converged) << r->message;
      EXPECT_GE(r->min_distance_ratio, 1.0 - 1e-3);
      EXPECT_LE(net_wrench(r->contact_forces, trial).norm(), 1e-12 * r->lambda_sum * 10.0);
    }
    EXPECT_GE(by_default.min_distance_ratio, 1.0 - 1e-9);
    EXPECT_GT((by_default.contact_forces - by_particle.contact_forces).norm(), 1e-6 * by_default.lambda_sum);
    EXPECT_NEAR(lcp.lambda_sum, by_default.lambda_sum, 5e-2 * by_default.lambda_sum);
    // Separated as the default is, with no more force than complementarity needs.
    EXPECT_GE(working_set.min_distance_ratio, 1.0 - 1e-9);
    EXPECT_LE(working_set.lambda_sum, by_default.lambda_sum * (1.0 + 2e-4));
    EXPECT_NEAR(working_set.lambda_sum, by_default.lambda_sum, 1e-2 * by_default.lambda_sum);
  }
}

// Two interlocked boomerangs at gap g: A in the xz plane, B in a plane x = const with its bend
// around A's x arm and its y arm in A's bend; three arm contacts at gap g (A's z arm and x arm
// against B's y arm, A's x arm against B's z arm). Returns the poses; `push` = the unit d^P
// normal from A to B at Q_t.
std::vector<sc::Pose> interlocked_boomerangs(const sc::Boomerang& b, double g, sc::Vec3& push) {
  const double m = sc::detail::boomerang_mass_centre_offset(b);
  const double reach = b.radius + b.bend_radius + g;  // bend corner to the held arm's axis
  sc::Mat3 R;  // B's construction x -> +y, z -> -z
  R.col(0) = sc::Vec3::UnitY();
  R.col(1) = sc::Vec3::UnitX();
  R.col(2) = -sc::Vec3::UnitZ();
  const std::vector<sc::Pose> poses{{sc::Vec3(m, 0, m), sc::Quat::Identity()},
                                    {sc::Vec3(reach, -reach, reach) + R * sc::Vec3(m, 0, m), sc::Quat(R)}};
  push = sc::closest_points(b, poses[0], b, poses[1]).normal;
  return poses;
}

// The smallest lambda on the ray lambda x `direction` (Nc = 1 here: a scalar) whose flagged
// distance reaches d_hat (1 + margin), by brute force: steps of `step` up to `limit`, then
// bisection. Each evaluation is free (formed columns).
template <typename Step>
double first_separating_lambda(Step& step, double target, double step_size, double limit) {
  const auto separated = [&](double l) { return step.evaluate(sc::VecX::Constant(1, l)).min_distance() >= target; };
  double lo = 0.0, hi = step_size;
  while (!separated(hi)) {
    lo = hi;
    hi += step_size;
    if (hi > limit) return std::numeric_limits<double>::infinity();
  }
  while (hi - lo > 1e-9 * hi) (separated(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
  return hi;
}

// Interlocked boomerangs pushed together with |F| = 100 along the d^P normal (free-draining,
// dt 0.01, d_hat = g): the distance is not monotone along the force (the closest points jump
// between the three arm contacts as the bodies turn), so between lambda = 0 and the smallest
// separating lambda d falls before it rises. The default solver's linear model stalled in
// that dip (failed separation, d / d_hat = 0.67 after 50 corrections with d^P directions and
// 0.81 with d^S at g = 0.05) or may converge to a far root; it must return the first crossing
// along its direction, which the test finds by brute force.
TEST(ContactStepSurface, InterlockedBoomerangsGetTheSmallestSeparatingForce) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  const std::vector<sc::Boomerang> shapes{b};
  const sc::Mat6 body = sc::single_body_mobility(sc::boomerang_curve_blobs(b), 1.0);
  for (const double g : {0.05, 0.01}) {
    sc::Vec3 n;
    const std::vector<sc::Pose> poses = interlocked_boomerangs(b, g, n);
    ASSERT_NEAR(sc::closest_points(b, poses[0], b, poses[1]).distance, g, 1e-12);
    sc::VecX F = sc::VecX::Zero(12);
    F.head<3>() = 100.0 * n;
    F.segment<3>(6) = -100.0 * n;
    sc::FreeDrainingMobility m0(body, 2, 6);
    m0.set_configuration(poses);
    const sc::VecX U = m0.apply(F);
    const sc::ContactStepProblem<sc::Boomerang> p{shapes, poses, U, 0.01, g, 0.0, 1.0, {}};
    for (const sc::ContactDirections directions : {sc::ContactDirections::particle, sc::ContactDirections::automatic}) {
      sc::ContactStepOptions options;
      options.directions = directions;
      // The end of the step only: this is eq. 27's first root. Inside the step the turning arms
      // of this pair come 9e-4 d_hat into each other (g = 0.05, d^P), which the whole-step
      // check reports as failed separation; the time stepper then sub-steps (below).
      options.whole_step = false;
      sc::FreeDrainingMobility m1(body, 2, 6), m2(body, 2, 6), m3(body, 2, 6);
      const sc::ContactStepResult r = sc::solve_contact_step_defect_correction(p, m1, options);
      sc::BarrierNloptOptions on_working_set;  // eq. 15 on the working set: the same ray search
      on_working_set.constraint = sc::BarrierConstraint::working_set;
      on_working_set.tol = sc::DefectCorrectionOptions{}.tol;
      const sc::ContactStepResult barrier = sc::solve_contact_step_barrier(p, m3, options, on_working_set);
      std::printf("[interlocked g %.2f %s] status %s lambda %.4f apps %zu iters %d min d/d_hat %.6f %s\n", g,
                  directions == sc::ContactDirections::particle ? "d^P" : "d^S",
                  std::string(sc::to_string(r.status)).c_str(), r.lambda_sum, r.mobility_applications, r.iterations,
                  r.min_distance_ratio, r.message.c_str());
      EXPECT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
      EXPECT_GE(r.min_distance_ratio, 1.0);
      ASSERT_EQ(r.lambda.size(), 1);
      sc::ContactStep<sc::Boomerang, sc::FreeDrainingMobility> step(p, m2, options);
      const double reference = first_separating_lambda(step, g, 0.5, 5000.0);
      EXPECT_NEAR(r.lambda(0), reference, 1e-3 * reference);
      EXPECT_EQ(barrier.status, sc::ContactStepStatus::converged) << barrier.message;
      EXPECT_GE(barrier.min_distance_ratio, 1.0);
      ASSERT_EQ(barrier.lambda.size(), 1);
      EXPECT_NEAR(barrier.lambda(0), reference, 1e-3 * reference) << barrier.message;
    }
  }
}

// contact_node_spacing's promise on the interlocked pair: at each of the three arm contacts
// (gap g = d_hat) some node pair measures the gap to within d_hat / 4 (the sagitta bound
// h^2 / (4 R)). Half the radius, the former default, misses a contact by more than g at g = 0.01.
TEST(ContactStepSurface, NodeSpacingResolvesEveryArmContactOfInterlockedBoomerangs) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  for (const double g : {0.05, 0.01}) {
    sc::Vec3 n;
    const std::vector<sc::Pose> poses = interlocked_boomerangs(b, g, n);
    // The contacts on A's surface (A's construction frame is the world frame here).
    const double r = b.radius, reach = b.radius + b.bend_radius + g;
    const std::vector<sc::Vec3> contacts{sc::Vec3(r, 0, reach), sc::Vec3(reach, 0, r), sc::Vec3(reach, -r, 0)};
    const auto worst_contact = [&](double h) {
      const sc::SurfaceNodes nodes = sc::surface_nodes(b, h);
      const sc::SurfaceDistances d = sc::surface_distances(b, poses[0], nodes, b, poses[1], nodes, 1.0);
      double worst = 0.0;
      for (const sc::Vec3& c : contacts) {
        double best = std::numeric_limits<double>::infinity();
        for (const sc::SurfacePair& p : d.pairs)
          if (p.source != sc::PairSource::closest_points && (p.point_a - c).norm() < 2.0 * h)
            best = std::min(best, p.distance);
        worst = std::max(worst, best - g);
      }
      return worst;
    };
    const double h = sc::contact_node_spacing(b, g);
    EXPECT_NEAR(h, std::sqrt(b.radius * g), 1e-15);
    EXPECT_LE(worst_contact(h), 0.25 * g) << "g " << g << ", h " << h;
    if (g == 0.01) {
      EXPECT_GT(worst_contact(0.5 * b.radius), g);
    }
  }
}

// Five boomerangs, two of them interlocked and pushed together, the others pushed towards the
// pair, forward Euler with the default solver and d^S directions (Broms Sec. 3.3): no step
// may fail, and no pair of any step comes below d_hat (1 - separation_margin), let alone
// overlaps.
TEST(ContactStepSurface, FiveBoomerangsWithAnInterlockedPairStayApart) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  const std::vector<sc::Boomerang> shapes{b};
  const sc::Mat6 body = sc::single_body_mobility(sc::boomerang_curve_blobs(b), 1.0);
  sc::Vec3 n;
  std::vector<sc::Pose> poses = interlocked_boomerangs(b, 0.05, n);
  std::mt19937_64 rng(7);
  const sc::Vec3 centre = 0.5 * (poses[0].x + poses[1].x);
  while (poses.size() < 5) {
    const sc::Pose q{centre + uniform_vector(rng, -3.0, 3.0), random_rotation(rng)};
    bool ok = true;
    for (const sc::Pose& o : poses) ok = ok && sc::closest_points(b, q, b, o).distance > 0.05;
    if (ok) poses.push_back(q);
  }
  sc::VecX F = sc::VecX::Zero(30);
  F.head<3>() = 100.0 * n;
  F.segment<3>(6) = -100.0 * n;
  for (Eigen::Index k = 2; k < 5; ++k) {
    F.segment<3>(6 * k) = 100.0 * (centre - poses[static_cast<std::size_t>(k)].x).normalized();
    F.segment<3>(6 * k + 3) = 10.0 * random_unit_vector(rng);
  }
  const double d_hat = 0.01;
  int pushed_steps = 0;
  std::size_t substeps = 0;
  sc::FreeDrainingMobility m(body, 5, 6);
  sc::TimeStepperOptions o;
  o.dt = 0.01;
  o.d_hat = d_hat;  // the whole step checked; a step one contact solve cannot hold is sub-stepped
  sc::TimeStepper<sc::Boomerang, sc::FreeDrainingMobility> stepper(shapes, poses, m, o);
  stepper.set_external_forces(F);
  for (int t = 0; t < 40; ++t) {
    const sc::StepDiagnostics r = stepper.step();
    const double d = sc::minimum_pair_distance(std::span<const sc::Boomerang>(shapes),
                                               std::span<const sc::Pose>(stepper.poses()), std::nullopt)
                         .distance;
    ASSERT_GE(d, d_hat * (1.0 - 1e-3)) << "step " << t;
    pushed_steps += r.lambda_max > 0.0 ? 1 : 0;
    substeps += r.substeps;
  }
  std::printf("[five boomerangs] %d of 40 steps needed a contact force, %zu contact steps\n", pushed_steps, substeps);
  EXPECT_GE(pushed_steps, 20);  // the interlocked pair is pushed together at every step
}

TEST(ContactStepSurface, RejectsANegativeNodeSpacing) {
  const BoomerangScene s = random_boomerangs(43u, 2, 6.0);
  const std::vector<sc::Boomerang> shapes{s.shape};
  const sc::ContactStepProblem<sc::Boomerang> p{shapes, s.poses, s.U, 0.01, 0.02, 0.0, 1.0, {}};
  sc::FreeDrainingMobility m(s.body_mobility, 2, 6);
  sc::ContactStepOptions options;
  options.node_spacing = -0.1;
  test_support::expect_rejects([&] { (void)sc::solve_contact_step_defect_correction(p, m, options); },
                               "ContactStepOptions.node_spacing");
}

}  // namespace

}  // namespace contact_step_surface_tests
