#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <random>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/dynamics/background_flow.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace background_flow_tests {

namespace sc = stokescontact;

namespace {

using test_support::expect_rejects;
using test_support::random_poses;
using test_support::uniform;
using test_support::uniform_vector;

// Half the curl of u by central differences (exact for a linear u up to rounding).
sc::Vec3 half_curl_by_differences(const sc::LinearBackgroundFlow& flow, const sc::Vec3& x) {
  const double h = 0.5;
  sc::Mat3 grad;  // grad(i, j) = d u_i / d x_j
  for (int j = 0; j < 3; ++j) {
    const sc::Vec3 e = h * sc::Vec3::Unit(j);
    grad.col(j) = (flow.velocity(x + e) - flow.velocity(x - e)) / (2 * h);
  }
  return 0.5 * sc::Vec3(grad(2, 1) - grad(1, 2), grad(0, 2) - grad(2, 0), grad(1, 0) - grad(0, 1));
}

TEST(BackgroundFlow, ShearMovesWithRateTimesYAndSpinsWithMinusHalfRateAboutZ) {
  const double rate = 2.5;
  const sc::LinearBackgroundFlow flow = sc::LinearBackgroundFlow::shear(rate);
  test_support::Rng rng(11);
  const std::vector<sc::Pose> poses = random_poses(7, -5.0, 5.0, rng);
  EXPECT_EQ(flow.angular_velocity(), sc::Vec3(0, 0, -0.5 * rate));
  for (const int dofs : {3, 6}) {
    SCOPED_TRACE(dofs);
    const sc::VecX U = flow.body_velocities(poses, dofs);
    ASSERT_EQ(U.size(), 7 * dofs);
    for (std::size_t b = 0; b < poses.size(); ++b) {
      const Eigen::Index row = static_cast<Eigen::Index>(b) * dofs;
      EXPECT_EQ(U(row + 0), rate * poses[b].x.y());
      EXPECT_EQ(U(row + 1), 0.0);
      EXPECT_EQ(U(row + 2), 0.0);
      if (dofs == 6) {
        EXPECT_EQ(U(row + 3), 0.0);
        EXPECT_EQ(U(row + 4), 0.0);
        EXPECT_EQ(U(row + 5), -0.5 * rate);
      }
    }
  }
}

// Broms & Tornberg eq. 32: E = diag(rate, -rate/2, -rate/2).
TEST(BackgroundFlow, BiaxialCompressionIsTracelessIrrotationalAndMatchesEq32) {
  const double rate = 1.7;
  const sc::LinearBackgroundFlow flow = sc::LinearBackgroundFlow::biaxial_compression(rate);
  EXPECT_EQ(flow.velocity_gradient().trace(), 0.0);
  EXPECT_EQ(flow.angular_velocity(), sc::Vec3::Zero());
  test_support::Rng rng(12);
  const std::vector<sc::Pose> poses = random_poses(5, -5.0, 5.0, rng);
  const sc::VecX U = flow.body_velocities(poses, 6);
  for (std::size_t b = 0; b < poses.size(); ++b) {
    const sc::Vec3& x = poses[b].x;
    const auto row = static_cast<Eigen::Index>(6 * b);
    EXPECT_DOUBLE_EQ(U(row + 0), rate * x.x());
    EXPECT_DOUBLE_EQ(U(row + 1), -0.5 * rate * x.y());
    EXPECT_DOUBLE_EQ(U(row + 2), -0.5 * rate * x.z());
    EXPECT_EQ(U.segment<3>(row + 3), sc::Vec3::Zero());
  }
  // Compresses along y and z, extends along x.
  EXPECT_LT(flow.velocity(sc::Vec3(0, 1, 0)).y(), 0.0);
  EXPECT_LT(flow.velocity(sc::Vec3(0, 0, 1)).z(), 0.0);
  EXPECT_GT(flow.velocity(sc::Vec3(1, 0, 0)).x(), 0.0);
}

// A rigid rotation u = w x x has angular velocity w; a random traceless E spins with half its curl.
TEST(BackgroundFlow, AngularVelocityIsHalfTheVorticity) {
  const sc::Vec3 w(0.3, -1.1, 0.7);
  sc::Mat3 cross;
  cross << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  EXPECT_LE((sc::LinearBackgroundFlow(cross).angular_velocity() - w).norm(), 1e-15);
  test_support::Rng rng(13);
  for (int trial = 0; trial < 20; ++trial) {
    sc::Mat3 E;
    for (int k = 0; k < 9; ++k) E(k % 3, k / 3) = uniform(rng, -2, 2);
    E(2, 2) = -E(0, 0) - E(1, 1);
    const sc::LinearBackgroundFlow flow(E);
    const sc::Vec3 x = uniform_vector(rng, -3, 3);
    EXPECT_LE((flow.angular_velocity() - half_curl_by_differences(flow, x)).norm(), 1e-13) << "trial " << trial;
    EXPECT_LE((flow.velocity(x) - E * x).norm(), 0.0);
  }
}

TEST(BackgroundFlow, CompressibleFlowsOnlyWhenAskedFor) {
  const sc::Mat3 E = sc::Mat3::Identity();
  expect_rejects([&] { sc::LinearBackgroundFlow f(E); }, "E");
  const sc::LinearBackgroundFlow f(E, sc::Incompressibility::not_required);
  EXPECT_EQ(f.velocity(sc::Vec3(1, 2, 3)), sc::Vec3(1, 2, 3));
  // A trace at rounding level relative to |E| passes.
  sc::Mat3 nearly = sc::LinearBackgroundFlow::biaxial_compression(1e6).velocity_gradient();
  nearly(0, 0) += 1e-7;
  EXPECT_NO_THROW(sc::LinearBackgroundFlow{nearly});
  nearly(0, 0) += 1e-3;
  expect_rejects([&] { sc::LinearBackgroundFlow g(nearly); }, "E");
}

TEST(BackgroundFlow, RejectsBadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  sc::Mat3 E = sc::Mat3::Zero();
  E(1, 2) = std::numeric_limits<double>::infinity();
  expect_rejects([&] { sc::LinearBackgroundFlow f(E, sc::Incompressibility::not_required); }, "E");
  expect_rejects([&] { (void)sc::LinearBackgroundFlow::shear(nan); }, "rate");
  expect_rejects([&] { (void)sc::LinearBackgroundFlow::biaxial_compression(nan); }, "rate");
  const sc::LinearBackgroundFlow flow = sc::LinearBackgroundFlow::shear(1.0);
  std::vector<sc::Pose> poses(2);
  expect_rejects([&] { (void)flow.body_velocities(poses, 4); }, "dofs_per_body");
  poses[1].x.y() = nan;
  expect_rejects([&] { (void)flow.body_velocities(poses, 6); }, "poses[1].x");
}

}  // namespace

}  // namespace background_flow_tests
