// slab_order_profile and orientational_correlation (dynamics/order_structure.hpp): exact values
// of axis mixtures, the identity that ties g2 over every pair to the order tensor, invariance
// under a shift of the frame and a common rotation, and clear errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/dynamics/nematic_order.hpp"
#include "stokescontact/dynamics/order_structure.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace order_structure_tests {

namespace sc = stokescontact;

namespace {

using sc::Pose;
using sc::Quat;
using sc::Vec3;
using test_support::expect_rejects;
using test_support::random_rotation;
using test_support::random_unit_vector;
using test_support::Rng;
using test_support::uniform;

Pose rod_along(const Vec3& axis, const Vec3& x, double spin = 0.0) {
  return {x, Quat::FromTwoVectors(Vec3::UnitZ(), axis) * Quat(Eigen::AngleAxisd(spin, Vec3::UnitZ()))};
}

// Three quarters of the box (x < 6 of 8) holds rods along z, the last quarter rods along x:
// across x the four slabs have P2(z . u) = 1, 1, 1, -1/2 exactly; Q = diag(-1/8, -1/2, 5/8),
// so the director is z and S = 5/8. Centres given outside the box (shifted by whole periods)
// fall in the same slabs.
TEST(OrderStructure, SlabProfileOfARegionOfCrossedRods) {
  const sc::PeriodicBox box{Vec3(8.0, 5.0, 7.0)};
  Rng rng(3);
  std::vector<Pose> poses;
  for (int slab = 0; slab < 4; ++slab)
    for (int r = 0; r < 6; ++r) {
      const Vec3 x(2.0 * slab + 0.1 + 1.8 * r / 5.0 + 8.0 * ((r % 3) - 1), 5.0 * uniform(rng, 0.0, 1.0) - 5.0 * r,
                   7.0 * uniform(rng, 0.0, 1.0));
      poses.push_back(rod_along(slab < 3 ? Vec3::UnitZ() : Vec3::UnitX(), x, 0.3 * r));
    }
  const sc::NematicOrder order = sc::nematic_order(poses);
  EXPECT_NEAR(order.S, 0.625, 1e-14);
  EXPECT_NEAR(std::abs(order.director.z()), 1.0, 1e-14);
  const sc::SlabOrderProfile across_x = sc::slab_order_profile(poses, box, order.director, 0, 4);
  const std::vector<double> expected{1.0, 1.0, 1.0, -0.5};
  for (std::size_t s = 0; s < 4; ++s) {
    EXPECT_NEAR(across_x.order[s], expected[s], 1e-14) << "slab " << s;
    EXPECT_EQ(across_x.rods[s], 6u);
  }
  // Across y every slab mixes the two kinds; the rods' mean over the slabs is e^T Q e with e the
  // director (order_along), whatever the split.
  const sc::SlabOrderProfile across_y = sc::slab_order_profile(poses, box, 3.0 * order.director, 1, 3);
  double total = 0.0;
  std::size_t rods = 0;
  for (std::size_t s = 0; s < 3; ++s) {
    if (across_y.rods[s] > 0) total += across_y.order[s] * static_cast<double>(across_y.rods[s]);
    rods += across_y.rods[s];
  }
  EXPECT_EQ(rods, poses.size());
  EXPECT_NEAR(total / static_cast<double>(rods), sc::order_along(poses, order.director), 1e-14);
  // More slabs than rods' rows: empty slabs are NaN.
  const sc::SlabOrderProfile fine = sc::slab_order_profile(poses, box, order.director, 0, 64);
  std::size_t empty = 0;
  for (std::size_t s = 0; s < fine.order.size(); ++s)
    if (fine.rods[s] == 0) {
      EXPECT_TRUE(std::isnan(fine.order[s]));
      ++empty;
    }
  EXPECT_GT(empty, 0u);
}

// Over one shell holding every pair, g2 is fixed by the order tensor alone:
//   sum_{i,j} P2(u_i . u_j) = (2 N^2 / 3) tr Q^2,  so  mean over i < j = ((2 N^2 / 3) tr Q^2 - N) / (N (N - 1)).
// Rods drawn about an axis (a uniaxial sample) and an isotropic sample; then the same rods
// rotated together and their centres shifted by (1e4, -3e3, 7): the same shells, the same g2.
TEST(OrderStructure, CorrelationOverEveryPairIsTheOrderTensorsSquare) {
  const sc::PeriodicBox box{Vec3(10.0, 12.0, 9.0)};
  Rng rng(11);
  for (const double spread : {0.4, 100.0}) {
    std::vector<Pose> poses;
    for (int i = 0; i < 300; ++i) {
      const Vec3 axis = (Vec3::UnitZ() + spread * random_unit_vector(rng)).normalized();
      poses.push_back(rod_along(axis, Vec3(uniform(rng, 0.0, 10.0), uniform(rng, 0.0, 12.0), uniform(rng, 0.0, 9.0)), i));
    }
    const double n = static_cast<double>(poses.size());
    const sc::Mat3 q = sc::order_tensor(poses);
    const double expected = ((2.0 * n * n / 3.0) * (q * q).trace() - n) / (n * (n - 1.0));
    const std::vector<double> all{0.0, 100.0};
    const sc::OrientationalCorrelation g = sc::orientational_correlation(poses, box, all);
    EXPECT_EQ(g.pairs[0], poses.size() * (poses.size() - 1) / 2);
    EXPECT_NEAR(g.g2[0], expected, 1e-13) << "spread " << spread;
    if (spread < 1.0) EXPECT_GT(g.g2[0], 0.3);          // ordered: about S^2
    else EXPECT_LT(std::abs(g.g2[0]), 0.05);           // isotropic: about 0

    const std::vector<double> shells{0.0, 1.5, 3.0, 4.5, 6.0, 8.0};
    const sc::OrientationalCorrelation before = sc::orientational_correlation(poses, box, shells);
    const Quat turn = random_rotation(rng);
    std::vector<Pose> moved = poses;
    for (Pose& p : moved) {
      p.q = turn * p.q;
      p.x += Vec3(1e4, -3e3, 7.0);
    }
    const sc::OrientationalCorrelation after = sc::orientational_correlation(moved, box, shells);
    for (std::size_t s = 0; s + 1 < shells.size(); ++s) {
      EXPECT_EQ(after.pairs[s], before.pairs[s]) << "shell " << s;
      EXPECT_NEAR(after.g2[s], before.g2[s], 1e-12) << "shell " << s;
    }
  }
}

// Two rods 1 apart across the periodic face (x = 0.3 and x = 9.3 in a box of 10), crossed at
// right angles: one pair in the shell (0.5, 1.5], P2(0) = -1/2; no pair elsewhere (NaN).
TEST(OrderStructure, CorrelationUsesTheNearestImage) {
  const sc::PeriodicBox box{Vec3(10.0, 10.0, 10.0)};
  const std::vector<Pose> poses{rod_along(Vec3::UnitZ(), Vec3(0.3, 5.0, 5.0)), rod_along(Vec3::UnitY(), Vec3(9.3, 5.0, 5.0))};
  const std::vector<double> shells{0.0, 0.5, 1.5, 5.0};
  const sc::OrientationalCorrelation g = sc::orientational_correlation(poses, box, shells);
  EXPECT_TRUE(std::isnan(g.g2[0]));
  EXPECT_NEAR(g.g2[1], -0.5, 1e-15);
  EXPECT_EQ(g.pairs[1], 1u);
  EXPECT_EQ(g.pairs[2], 0u);
}

TEST(OrderStructure, RejectsBadInputNamingTheField) {
  const sc::PeriodicBox box{Vec3(10.0, 10.0, 10.0)};
  const std::vector<Pose> poses{rod_along(Vec3::UnitZ(), Vec3(1.0, 1.0, 1.0)), rod_along(Vec3::UnitX(), Vec3(4.0, 1.0, 1.0))};
  const std::vector<double> shells{0.0, 2.0};
  expect_rejects([&] { sc::slab_order_profile(std::vector<Pose>{}, box, Vec3::UnitZ(), 0, 4); }, "poses");
  expect_rejects([&] { sc::slab_order_profile(poses, sc::PeriodicBox{Vec3(10.0, 0.0, 10.0)}, Vec3::UnitZ(), 0, 4); },
                 "box.lengths[1]");
  expect_rejects([&] { sc::slab_order_profile(poses, box, Vec3::Zero(), 0, 4); }, "director");
  expect_rejects([&] { sc::slab_order_profile(poses, box, Vec3::UnitZ(), 3, 4); }, "axis");
  expect_rejects([&] { sc::slab_order_profile(poses, box, Vec3::UnitZ(), 0, 0); }, "slabs");
  std::vector<Pose> bad = poses;
  bad[1].x.y() = std::nan("");
  expect_rejects([&] { sc::slab_order_profile(bad, box, Vec3::UnitZ(), 0, 4); }, "poses[1].x");
  expect_rejects([&] { sc::orientational_correlation(poses, box, std::vector<double>{1.0}); }, "edges");
  expect_rejects([&] { sc::orientational_correlation(poses, box, std::vector<double>{0.0, 2.0, 2.0}); }, "edges");
  expect_rejects([&] { sc::orientational_correlation(poses, box, std::vector<double>{-1.0, 2.0}); }, "edges[0]");
  expect_rejects([&] { sc::orientational_correlation(poses, sc::PeriodicBox{Vec3(10.0, 10.0, -1.0)}, shells); },
                 "box.lengths[2]");
}

}  // namespace

}  // namespace order_structure_tests
