// Contact steps in a periodic box (ContactStepProblem.box): pairs touching across the boundary
// are flagged through their minimum image and pushed apart exactly as the same pair in the
// middle of the box in open space.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/contact/solvers/barrier_nlopt.hpp"
#include "stokescontact/contact/solvers/defect_correction.hpp"
#include "stokescontact/contact/solvers/lcp_sequence.hpp"
#include "stokescontact/geometry/closest_points.hpp"
#include "stokescontact/mobility/free_draining.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace contact_step_periodic_tests {

namespace sc = stokescontact;

namespace {

using test_support::random_unit_vector;
using test_support::uniform_vector;

constexpr double kMargin = 1e-3;  // ContactStepOptions::separation_margin
constexpr double kL = 10.0;       // box side

enum class Solver { kLcpSequence, kBarrierSlsqp, kDefault };
const std::vector<Solver> kSolvers = {Solver::kLcpSequence, Solver::kBarrierSlsqp, Solver::kDefault};
std::string name(Solver s) {
  return s == Solver::kLcpSequence ? "lcp_sequence" : s == Solver::kBarrierSlsqp ? "barrier_slsqp" : "default";
}

template <sc::Shape S>
sc::ContactStepResult solve(Solver s, const sc::ContactStepProblem<S>& p, sc::FreeDrainingMobility& m) {
  switch (s) {
    case Solver::kLcpSequence: return sc::solve_contact_step_lcp_sequence(p, m);
    case Solver::kBarrierSlsqp: return sc::solve_contact_step_barrier(p, m);
    case Solver::kDefault: return sc::solve_contact_step_defect_correction(p, m);
  }
  return {};
}

// Smallest d^P over all pairs and all 27 neighbouring images: no minimum-image code involved.
template <sc::Shape S>
double min_distance_over_images(const S& shape, const std::vector<sc::Pose>& poses, double L) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (std::size_t j = i + 1; j < poses.size(); ++j)
      for (int a = -1; a <= 1; ++a)
        for (int b = -1; b <= 1; ++b)
          for (int c = -1; c <= 1; ++c) {
            // Positions may have left [0, L) by a step: bring j near i first.
            sc::Vec3 d = poses[j].x - poses[i].x;
            for (int k = 0; k < 3; ++k) d[k] -= L * std::round(d[k] / L);
            const sc::Pose image{poses[i].x + d + L * sc::Vec3(a, b, c), poses[j].q};
            best = std::min(best, sc::closest_points(shape, poses[i], shape, image).distance);
          }
  return best;
}

// Two bodies of one shape: b sits across the boundary from a; `shift` moves a into the middle,
// `lattice` is the box vector that brings b next to a.
template <sc::Shape S>
struct PairCase {
  std::string label;
  S shape;
  int dofs;
  sc::Pose a, b;
  sc::VecX U;
  sc::Vec3 lattice;  // image of b next to a: b.x + lattice
  sc::Vec3 shift;    // a.x + shift lies mid-box
};

template <sc::Shape S>
void check_pair_across_the_boundary(const PairCase<S>& c) {
  const double dt = 0.01, d_hat = 0.01;
  const std::vector<S> shapes{c.shape};
  const sc::Mat6 n = [&] {
    if constexpr (std::is_same_v<S, sc::Sphere>) return sc::sphere_mobility(c.shape, 1.0);
    else return sc::spherocylinder_mobility(c.shape, 1.0);
  }();
  const std::vector<sc::Pose> periodic_poses = {c.a, c.b};
  const std::vector<sc::Pose> middle_poses = {{c.a.x + c.shift, c.a.q}, {c.b.x + c.lattice + c.shift, c.b.q}};
  const sc::PeriodicBox box{sc::Vec3::Constant(kL)};

  // Without the box the two bodies are far apart: nothing to do.
  {
    sc::FreeDrainingMobility m(n, 2, c.dofs);
    const sc::ContactStepResult open = sc::solve_contact_step_lcp_sequence(
        sc::ContactStepProblem<S>{shapes, periodic_poses, c.U, dt, d_hat, 0.0, 1.0, {}}, m);
    EXPECT_EQ(open.flagged_pairs, 0u);
  }
  for (const Solver solver : kSolvers) {
    SCOPED_TRACE(c.label + " " + name(solver));
    sc::FreeDrainingMobility m_periodic(n, 2, c.dofs), m_middle(n, 2, c.dofs);
    const sc::ContactStepResult r =
        solve(solver, sc::ContactStepProblem<S>{shapes, periodic_poses, c.U, dt, d_hat, 0.0, 1.0, box}, m_periodic);
    const sc::ContactStepResult ref =
        solve(solver, sc::ContactStepProblem<S>{shapes, middle_poses, c.U, dt, d_hat, 0.0, 1.0, {}}, m_middle);
    ASSERT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
    ASSERT_EQ(ref.status, sc::ContactStepStatus::converged) << ref.message;
    ASSERT_EQ(r.flagged_pairs, 1u);
    ASSERT_EQ(ref.flagged_pairs, 1u);
    EXPECT_LE((r.pairs[0].image_shift - c.lattice).norm(), 0.0);
    ASSERT_GT(r.lambda(0), 0.0);  // pushed apart

    // Separated over all pairs and images, and the result's own measure agrees.
    const double d_min = min_distance_over_images(c.shape, r.poses, kL);
    EXPECT_GE(d_min, d_hat * (1.0 - kMargin));
    EXPECT_NEAR(r.min_distance_ratio, d_min / d_hat, 1e-9);

    // Newton's third law, and a is pushed away from b's image.
    const sc::Vec3 f_a = r.contact_forces.segment<3>(0), f_b = r.contact_forces.segment<3>(c.dofs);
    EXPECT_LE((f_a + f_b).norm(), 1e-14 * r.lambda_sum);
    EXPECT_GT(f_a.dot(c.a.x - (c.b.x + c.lattice)), 0.0);

    // The same step as in the middle of the box, without periodicity.
    EXPECT_NEAR(r.lambda(0), ref.lambda(0), 1e-12 * ref.lambda(0));
    EXPECT_LE((r.contact_forces - ref.contact_forces).norm(), 1e-12 * ref.lambda_sum);
    EXPECT_LE((r.velocities - ref.velocities).norm(), 1e-12 * ref.velocities.norm());
    EXPECT_LE((r.poses[0].x + c.shift - ref.poses[0].x).norm(), 1e-12);
    EXPECT_LE((r.poses[1].x + c.lattice + c.shift - ref.poses[1].x).norm(), 1e-12);
    for (std::size_t k = 0; k < 2; ++k) EXPECT_LE((r.poses[k].rotation() - ref.poses[k].rotation()).norm(), 1e-12);
    EXPECT_NEAR(r.min_distance_ratio, ref.min_distance_ratio, 1e-9);
    EXPECT_EQ(r.iterations, ref.iterations);
    EXPECT_EQ(r.mobility_applications, ref.mobility_applications);
  }
}

sc::VecX stacked(const std::vector<sc::Vec3>& parts) {
  sc::VecX U(3 * static_cast<Eigen::Index>(parts.size()));
  for (std::size_t k = 0; k < parts.size(); ++k) U.segment<3>(3 * static_cast<Eigen::Index>(k)) = parts[k];
  return U;
}

TEST(ContactStepPeriodic, SpheresTouchingAcrossAFaceArePushedApartAsInOpenSpace) {
  // a at x = 1.02, b at x = L - 1.03: gap 0.05 through the face x = 0, closing at speed 20.
  check_pair_across_the_boundary(PairCase<sc::Sphere>{
      "face x", sc::Sphere{1.0}, 3, {sc::Vec3(1.02, 5.0, 5.0), sc::Quat::Identity()},
      {sc::Vec3(kL - 1.03, 5.1, 4.9), sc::Quat::Identity()}, stacked({sc::Vec3(-10, 0, 0), sc::Vec3(10, 0.5, 0)}),
      sc::Vec3(-kL, 0, 0), sc::Vec3(kL / 2, 0, 0)});
  // Across the face z = L.
  check_pair_across_the_boundary(PairCase<sc::Sphere>{
      "face z", sc::Sphere{1.0}, 3, {sc::Vec3(4.0, 6.0, kL - 1.01), sc::Quat::Identity()},
      {sc::Vec3(4.0, 6.0, 1.02), sc::Quat::Identity()}, stacked({sc::Vec3(0, 0, 8), sc::Vec3(0, 0, -8)}),
      sc::Vec3(0, 0, kL), sc::Vec3(0, 0, -kL / 2)});
}

TEST(ContactStepPeriodic, SpheresTouchingAcrossACornerEdgeArePushedApartAsInOpenSpace) {
  // |(0.75, 0.75) - (-0.70, -0.70)| = 1.45 sqrt 2 = 2.0506: gap 0.0506 across the edge x = y = 0.
  check_pair_across_the_boundary(PairCase<sc::Sphere>{
      "edge xy", sc::Sphere{1.0}, 3, {sc::Vec3(0.75, 0.75, 5.0), sc::Quat::Identity()},
      {sc::Vec3(kL - 0.70, kL - 0.70, 5.0), sc::Quat::Identity()}, stacked({sc::Vec3(-7, -7, 0), sc::Vec3(7, 7, 0)}),
      sc::Vec3(-kL, -kL, 0), sc::Vec3(kL / 2, kL / 2, 0)});
}

TEST(ContactStepPeriodic, RodsTouchingAcrossAFaceArePushedApartAsInOpenSpace) {
  // Crossed rods (a along x, b along y), axes 1.05 apart through the face z = 0: gap 0.05.
  const sc::Spherocylinder rod{2.0, 0.5};
  sc::VecX U(12);
  U << 0.3, 0, -6, 0.5, -1.0, 0.2, 0, -0.2, 6, 0.0, 0.8, -0.4;
  check_pair_across_the_boundary(PairCase<sc::Spherocylinder>{
      "rods face z", rod, 6,
      {sc::Vec3(5.0, 5.0, 0.6), sc::Quat(Eigen::AngleAxisd(std::numbers::pi / 2, sc::Vec3::UnitY()))},
      {sc::Vec3(5.3, 5.2, kL - 0.45), sc::Quat(Eigen::AngleAxisd(std::numbers::pi / 2, sc::Vec3::UnitX()))}, U,
      sc::Vec3(0, 0, -kL), sc::Vec3(0, 0, kL / 2)});
}

// A random periodic scene: every pair, all images, ends at d >= d_hat (1 - margin).
TEST(ContactStepPeriodic, RandomSpheresInABoxEndSeparated) {
  const double L = 12.0, dt = 0.02, d_hat = 0.02;
  for (const std::uint64_t seed : {7u, 8u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    test_support::Rng rng(seed);
    std::vector<sc::Pose> poses;
    for (int attempt = 0; poses.size() < 60; ++attempt) {
      ASSERT_LT(attempt, 100000) << "jammed";
      const sc::Vec3 x = uniform_vector(rng, 0.0, L);
      bool free = true;
      for (const sc::Pose& p : poses) {
        sc::Vec3 d = x - p.x;
        for (int k = 0; k < 3; ++k) d[k] -= L * std::round(d[k] / L);
        free = free && d.norm() > 2.05;
      }
      if (free) poses.push_back({x, sc::Quat::Identity()});
    }
    sc::VecX U(3 * static_cast<Eigen::Index>(poses.size()));
    for (Eigen::Index b = 0; b < U.size(); b += 3) U.segment<3>(b) = 5.0 * random_unit_vector(rng);
    const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
    const sc::ContactStepProblem<sc::Sphere> problem{shapes, poses, U, dt, d_hat, 0.0, 1.0,
                                                     sc::PeriodicBox{sc::Vec3::Constant(L)}};
    const double before = min_distance_over_images(sc::Sphere{1.0}, poses, L);
    for (const Solver solver : kSolvers) {
      SCOPED_TRACE(name(solver));
      sc::FreeDrainingMobility m(sc::sphere_mobility(shapes[0], 1.0), poses.size(), 3);
      const sc::ContactStepResult r = solve(solver, problem, m);
      EXPECT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
      EXPECT_GT(r.lambda_max, 0.0);
      const double d_min = min_distance_over_images(sc::Sphere{1.0}, r.poses, L);
      EXPECT_GE(d_min, d_hat * (1.0 - kMargin)) << "before the step: " << before;
      EXPECT_NEAR(r.min_distance_ratio, d_min / d_hat, 1e-9 * std::max(1.0, d_min / d_hat));
      sc::Vec3 total = sc::Vec3::Zero();
      for (Eigen::Index b = 0; b < r.contact_forces.size(); b += 3) total += r.contact_forces.segment<3>(b);
      EXPECT_LE(total.norm(), 1e-13 * std::max(1.0, r.lambda_sum));
    }
  }
}

// Contact forces that fling a body farther than the box allows (a solver's runaway lambda):
// the step reports failed separation naming the body, instead of throwing from the whole-step
// check's broad phase, so that a time stepper can sub-step it.
TEST(ContactStepPeriodic, AForceThatFlingsABodyBeyondTheBoxIsAFailedStepNotAThrow) {
  const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  const std::vector<sc::Pose> poses = {{sc::Vec3(5.0, 5.0, 5.0), sc::Quat::Identity()},
                                       {sc::Vec3(7.005, 5.0, 5.0), sc::Quat::Identity()}};
  sc::VecX U = sc::VecX::Zero(6);
  U(0) = 1.0;  // body 0 approaches body 1
  const sc::ContactStepProblem<sc::Sphere> problem{shapes, poses, U, 0.01, 0.01, 0.0, 1.0,
                                                   sc::PeriodicBox{sc::Vec3::Constant(kL)}};
  sc::FreeDrainingMobility mobility(sc::sphere_mobility(shapes[0], 1.0), 2, 3);
  const sc::ContactStepOptions options;  // whole-step guarantee on
  // A solver core that returns a force moving the bodies apart by about 1e3 box sides.
  const auto runaway = [](sc::ContactStep<sc::Sphere, sc::FreeDrainingMobility>& step, const sc::VecX&) {
    sc::ContactSolveOutcome out;
    out.lambda = sc::VecX::Constant(step.nc(), 1e7);
    out.converged = true;
    return out;
  };
  sc::ContactStepResult r;
  ASSERT_NO_THROW(r = sc::run_contact_step(problem, mobility, options, runaway));
  EXPECT_EQ(r.status, sc::ContactStepStatus::failed_separation);
  EXPECT_NE(r.message.find("moves too far in the step for the box"), std::string::npos) << r.message;
}

}  // namespace

}  // namespace contact_step_periodic_tests
