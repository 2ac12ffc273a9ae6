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

// is_valid checks |q|^2 against the squared bounds (no square root): the same answer as
// | |q| - 1 | <= kUnitQuaternionTolerance away from the boundary, on either side, for every
// direction of q; false for a NaN or infinite coefficient of q or x.
TEST(Pose, IsValidIsTheUnitToleranceWithoutASquareRoot) {
  const double tol = sc::kUnitQuaternionTolerance;
  const sc::Quat axis = sc::Quat(0.5, -0.5, 0.5, 0.5);
  for (const double offset : {-3.0, -1.01, -0.99, -0.5, 0.0, 0.5, 0.99, 1.01, 3.0}) {
    sc::Pose pose;
    pose.q.coeffs() = (1.0 + offset * tol) * axis.coeffs();
    EXPECT_EQ(sc::is_valid(pose), std::abs(pose.q.norm() - 1.0) <= tol) << "offset " << offset;
    EXPECT_EQ(sc::is_valid(pose), std::abs(offset) < 1.0) << "offset " << offset;
  }
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  for (const double bad : {inf, -inf, nan})
    for (int k = 0; k < 4; ++k) {
      sc::Pose pose;
      pose.q.coeffs()(k) = bad;
      EXPECT_FALSE(sc::is_valid(pose)) << "q coefficient " << k << " = " << bad;
      if (k < 3) {
        sc::Pose at;
        at.x(k) = bad;
        EXPECT_FALSE(sc::is_valid(at)) << "x(" << k << ") = " << bad;
      }
    }
  EXPECT_TRUE(sc::is_valid(sc::Pose{sc::Vec3(1e300, -1e300, 1e4), axis}));
}

}  // namespace pose_tests
