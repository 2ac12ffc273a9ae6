#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/core/rigid_motion.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace rigid_motion_tests {

namespace sc = stokescontact;

TEST(RigidMotion, QuaternionExpMatchesAngleAxis) {
  std::mt19937 rng(12);
  std::normal_distribution<double> n(0.0, 1.0);
  for (double scale : {1e-12, 1e-6, 1e-4, 0.3, 2.0, 7.0}) {
    const sc::Vec3 theta = scale * sc::Vec3(n(rng), n(rng), n(rng));
    // exp([0, theta]) is the rotation by 2 |theta| about theta / |theta|.
    const sc::Quat expected(Eigen::AngleAxisd(2.0 * theta.norm(), theta.normalized()));
    const sc::Quat e = sc::quaternion_exp(theta);
    EXPECT_LT((e.toRotationMatrix() - expected.toRotationMatrix()).norm(), 1e-15) << scale;
    EXPECT_NEAR(e.norm(), 1.0, 1e-15);
  }
}

TEST(RigidMotion, PsiMatchesQuaternionProduct) {
  const sc::Quat q(Eigen::AngleAxisd(1.1, sc::Vec3(0.2, -1, 0.4).normalized()));
  const sc::Vec3 u(0.1, 0.2, 0.3), omega(-0.7, 0.5, 1.3);
  sc::Vec6 velocity;
  velocity << u, omega;
  const sc::Vec7 rate = sc::psi_matrix(q) * velocity;
  // dq/dt = (1/2) [0, omega] q, computed with Eigen's quaternion product.
  const sc::Quat omega_q(0.0, omega.x(), omega.y(), omega.z());
  const sc::Quat dq = omega_q * q;
  EXPECT_LT((rate.head<3>() - u).norm(), 1e-15);
  EXPECT_NEAR(rate(3), 0.5 * dq.w(), 1e-15);
  EXPECT_LT((rate.tail<3>() - 0.5 * dq.vec()).norm(), 1e-15);
}

TEST(RigidMotion, AdvanceIsFirstOrderConsistentWithPsi) {
  const sc::Pose pose{sc::Vec3(1, 2, 3), sc::Quat(Eigen::AngleAxisd(0.4, sc::Vec3::UnitY()))};
  const sc::Vec3 u(0.3, -0.1, 0.2), omega(0.9, 0.1, -0.4);
  sc::Vec6 velocity;
  velocity << u, omega;
  const sc::Vec7 rate = sc::psi_matrix(pose.q) * velocity;
  const double dt = 1e-6;
  const sc::Pose next = sc::advance(pose, u, omega, dt);
  EXPECT_LT(((next.x - pose.x) / dt - rate.head<3>()).norm(), 1e-9);
  EXPECT_NEAR((next.q.w() - pose.q.w()) / dt, rate(3), 1e-6);
  EXPECT_LT(((next.q.vec() - pose.q.vec()) / dt - rate.tail<3>()).norm(), 1e-6);
}

// Without rotation (omega = 0 exactly, e.g. a sphere model with 3 dofs per body) the
// orientation is kept bit for bit; a tiny nonzero rotation takes the general path, still unit.
TEST(RigidMotion, AdvanceWithoutRotationKeepsTheOrientation) {
  const sc::Pose pose{sc::Vec3(1, 2, 3), sc::Quat(Eigen::AngleAxisd(0.4, sc::Vec3(1, 2, 2).normalized()))};
  const sc::Pose next = sc::advance(pose, sc::Vec3(0.5, 0, 0), sc::Vec3::Zero(), 0.1);
  EXPECT_EQ(next.q.coeffs(), pose.q.coeffs());
  EXPECT_EQ(next.x, sc::Vec3(1.05, 2, 3));
  const sc::Pose turned = sc::advance(pose, sc::Vec3::Zero(), sc::Vec3(0, 0, 1e-300), 1.0);
  EXPECT_NEAR(turned.q.angularDistance(pose.q), 0.0, 1e-15);
  EXPECT_NEAR(turned.q.norm(), 1.0, 1e-15);
}

TEST(RigidMotion, ConstantRotationIsExactOverManySteps) {
  const sc::Vec3 omega = sc::Vec3(0.3, -0.2, 1.0);
  const double dt = 1e-3;
  const int steps = 10000;
  sc::Pose pose;
  for (int k = 0; k < steps; ++k) pose = sc::advance(pose, sc::Vec3::Zero(), omega, dt);
  const Eigen::AngleAxisd expected(omega.norm() * dt * steps, omega.normalized());
  EXPECT_LT((pose.rotation() - expected.toRotationMatrix()).norm(), 1e-11);
}

TEST(RigidMotion, QuaternionStaysUnitOverAMillionSteps) {
  std::mt19937 rng(2023);
  std::normal_distribution<double> n(0.0, 5.0);
  sc::Pose pose{sc::Vec3::Zero(), sc::Quat(Eigen::AngleAxisd(0.3, sc::Vec3::UnitX()))};
  double worst = 0.0;
  for (int k = 0; k < 1000000; ++k) {
    pose = sc::advance(pose, sc::Vec3::Zero(), sc::Vec3(n(rng), n(rng), n(rng)), 0.01);
    worst = std::max(worst, std::abs(pose.q.norm() - 1.0));
  }
  EXPECT_LT(worst, 4e-16) << "seed 2023";
  EXPECT_NO_THROW(sc::validate(pose));
}

TEST(RigidMotion, AdvanceRejectsBadInput) {
  const sc::Pose pose;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(sc::advance(pose, sc::Vec3(nan, 0, 0), sc::Vec3::Zero(), 0.1), std::invalid_argument);
  EXPECT_THROW(sc::advance(pose, sc::Vec3::Zero(), sc::Vec3(0, nan, 0), 0.1), std::invalid_argument);
  EXPECT_THROW(sc::advance(pose, sc::Vec3::Zero(), sc::Vec3::Zero(), nan), std::invalid_argument);
  sc::Pose bad;
  bad.q = sc::Quat(2.0, 0, 0, 0);
  EXPECT_THROW(sc::advance(bad, sc::Vec3::Zero(), sc::Vec3::Zero(), 0.1), std::invalid_argument);
}

// advance_all is advance body by body: (u) per body for 3 dofs (orientation kept), (u, omega) for 6.
TEST(RigidMotion, AdvanceAllAdvancesEveryBody) {
  const std::vector<sc::Pose> poses = {{sc::Vec3(1, 2, 3), sc::Quat(Eigen::AngleAxisd(0.4, sc::Vec3::UnitY()))},
                                       {sc::Vec3(-1, 0, 5), sc::Quat(Eigen::AngleAxisd(1.2, sc::Vec3::UnitX()))}};
  const double dt = 0.03;
  sc::VecX U6(12);
  U6 << 0.1, 0.2, 0.3, -0.7, 0.5, 1.3, 2.0, -1.0, 0.5, 0.0, 3.0, -0.2;
  const std::vector<sc::Pose> six = sc::advance_all(poses, U6, 6, dt);
  sc::VecX U3(6);
  U3 << 0.1, 0.2, 0.3, 2.0, -1.0, 0.5;
  const std::vector<sc::Pose> three = sc::advance_all(poses, U3, 3, dt);
  ASSERT_EQ(six.size(), 2u);
  ASSERT_EQ(three.size(), 2u);
  for (std::size_t b = 0; b < 2; ++b) {
    const auto i = static_cast<Eigen::Index>(b);
    const sc::Pose p6 = sc::advance(poses[b], U6.segment<3>(6 * i), U6.segment<3>(6 * i + 3), dt);
    EXPECT_EQ(six[b].x, p6.x);
    EXPECT_EQ(six[b].q.coeffs(), p6.q.coeffs());
    const sc::Pose p3 = sc::advance(poses[b], U3.segment<3>(3 * i), sc::Vec3::Zero(), dt);
    EXPECT_EQ(three[b].x, p3.x);
    EXPECT_EQ(three[b].q.coeffs(), p3.q.coeffs());
  }
}

TEST(RigidMotion, AdvanceAllRejectsBadInput) {
  using test_support::expect_rejects;
  const std::vector<sc::Pose> poses(2);
  expect_rejects([&] { (void)sc::advance_all(poses, sc::VecX::Zero(8), 4, 0.1); }, "dofs_per_body");
  expect_rejects([&] { (void)sc::advance_all(poses, sc::VecX::Zero(7), 3, 0.1); }, "velocities");
  expect_rejects([&] { (void)sc::advance_all(poses, sc::VecX::Zero(6), 6, 0.1); }, "velocities");
  EXPECT_THROW((void)sc::advance_all(poses, sc::VecX::Constant(6, std::nan("")), 3, 0.1), std::invalid_argument);
}

}  // namespace rigid_motion_tests
