#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "stokescontact/core/pose.hpp"
#include "common/test_support.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace pose_tests {

namespace sc = stokescontact;

namespace {

using test_support::expect_rejects;

}  // namespace

TEST(Pose, BodyAndWorldMapsAreInverse) {
  const sc::Pose pose{sc::Vec3(1.0, -2.0, 0.5),
                      sc::Quat(Eigen::AngleAxisd(0.7, sc::Vec3(1, 2, 3).normalized()))};
  const sc::Vec3 p(0.3, 0.4, -1.2);
  EXPECT_LT((pose.to_body(pose.to_world(p)) - p).norm(), 1e-15);
  // Independent value: x + R p with R from Eigen's angle-axis matrix.
  const sc::Mat3 r = Eigen::AngleAxisd(0.7, sc::Vec3(1, 2, 3).normalized()).toRotationMatrix();
  EXPECT_LT((pose.to_world(p) - (pose.x + r * p)).norm(), 1e-15);
}

TEST(Pose, RejectsNonFiniteCentre) {
  sc::Pose pose;
  pose.x.y() = std::numeric_limits<double>::quiet_NaN();
  expect_rejects([&] { sc::validate(pose); }, "pose.x");
  pose.x.y() = std::numeric_limits<double>::infinity();
  expect_rejects([&] { sc::validate(pose, "pose_a"); }, "pose_a.x");
}

TEST(Pose, RejectsNonUnitQuaternion) {
  sc::Pose pose;
  pose.q = sc::Quat(1.0 + 1e-8, 0.0, 0.0, 0.0);
  expect_rejects([&] { sc::validate(pose); }, "pose.q");
  pose.q = sc::Quat(0.0, 0.0, 0.0, 0.0);
  expect_rejects([&] { sc::validate(pose); }, "pose.q");
  pose.q = sc::Quat(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0, 0.0);
  expect_rejects([&] { sc::validate(pose); }, "pose.q");
}

TEST(Pose, AcceptsQuaternionWithinTolerance) {
  sc::Pose pose;
  pose.q = sc::Quat(1.0 + 0.5 * sc::kUnitQuaternionTolerance, 0.0, 0.0, 0.0);
  EXPECT_NO_THROW(sc::validate(pose));
}

}  // namespace pose_tests
