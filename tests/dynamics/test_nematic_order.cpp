#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/dynamics/collision_stress.hpp"
#include "stokescontact/dynamics/nematic_order.hpp"
#include "stokescontact/geometry/shapes.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace nematic_order_tests {

namespace sc = stokescontact;

namespace {

using sc::Mat3;
using sc::Pose;
using sc::Quat;
using sc::Vec3;
using test_support::expect_rejects;
using test_support::random_rotation;
using test_support::random_unit_vector;
using test_support::Rng;

// A rod whose axis (body z) is `axis`, spun about it by `spin`.
Pose rod_along(const Vec3& axis, double spin, const Vec3& x = Vec3::Zero()) {
  return {x, Quat::FromTwoVectors(Vec3::UnitZ(), axis) * Quat(Eigen::AngleAxisd(spin, Vec3::UnitZ()))};
}

TEST(NematicOrder, RodsAlongOneAxisHaveOrderOneAndThatDirector) {
  Rng rng(7);
  const Vec3 a = random_unit_vector(rng);
  std::vector<Pose> poses;
  for (int i = 0; i < 50; ++i) poses.push_back(rod_along(i % 2 ? a : Vec3(-a), 0.37 * i));  // head or tail
  const sc::NematicOrder order = sc::nematic_order(poses);
  EXPECT_NEAR(order.S, 1.0, 1e-14);
  EXPECT_NEAR(std::abs(order.director.dot(a)), 1.0, 1e-14);
  EXPECT_NEAR(sc::order_along(poses, a), 1.0, 1e-14);
  EXPECT_NEAR(sc::order_along(poses, 3.0 * a), 1.0, 1e-14);  // the axis is normalised
  EXPECT_NEAR(sc::order_along(poses, a.unitOrthogonal()), -0.5, 1e-14);
}

// Exact values: equal numbers along x, y, z give Q = 0; half along z and half along x give
// Q = diag(1/4, -1/2, 1/4) (S = 1/4, the director anywhere in the xz plane, y the unique axis).
TEST(NematicOrder, ExactTensorsOfAxisMixtures) {
  const std::vector<Pose> cube{rod_along(Vec3::UnitX(), 0.1), rod_along(Vec3::UnitY(), 0.2),
                               rod_along(Vec3::UnitZ(), 0.3)};
  EXPECT_LT(sc::order_tensor(cube).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_NEAR(sc::nematic_order(cube).S, 0.0, 1e-15);

  const std::vector<Pose> xz{rod_along(Vec3::UnitZ(), 0.0), rod_along(Vec3::UnitX(), 1.0)};
  const Mat3 q = sc::order_tensor(xz);
  EXPECT_LT((q - Vec3(0.25, -0.5, 0.25).asDiagonal().toDenseMatrix()).cwiseAbs().maxCoeff(), 1e-15);
  const sc::NematicOrder order = sc::nematic_order(xz);
  EXPECT_NEAR(order.S, 0.25, 1e-15);
  EXPECT_NEAR(order.director.y(), 0.0, 1e-14);
  EXPECT_NEAR(sc::order_along(xz, Vec3::UnitZ()), 0.25, 1e-15);  // eq. 33 against e_z
}

// Uniformly random orientations: Q's entries have mean 0 and a diagonal entry's standard
// deviation is sqrt(9/4 (1/5 - 1/9)) / sqrt(N) = sqrt(1/5) / sqrt(N) (u_z^2 has mean 1/3 and
// second moment 1/5), so S is a few of those; Q stays traceless to rounding.
TEST(NematicOrder, IsotropicOrientationsHaveOrderOfOneOverSqrtN) {
  Rng rng(11);
  const std::size_t n = 20000;
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < n; ++i) poses.push_back({Vec3::Zero(), random_rotation(rng)});
  const Mat3 q = sc::order_tensor(poses);
  EXPECT_NEAR(q.trace(), 0.0, 1e-13);
  EXPECT_LT((q - q.transpose()).cwiseAbs().maxCoeff(), 1e-15);
  const double sigma = std::sqrt(0.2 / static_cast<double>(n));
  const double s = sc::nematic_order(poses).S;
  EXPECT_GT(s, 0.0);
  EXPECT_LT(s, 6.0 * sigma) << "sigma " << sigma;
}

// Yan Sec. IV.B's anisotropy from the collision stress of eq. 16 (dynamics/collision_stress.hpp)
// for rods aligned along the director: a tip-to-tip push carries stress only along it (along =
// |r1 - r2| |F|, across = 0) and a side-by-side push at the middle of the overlap only across it
// (along = 0, across = |r1 - r2| |F| / 2). The same configurations turned by a random rotation,
// with the director taken from nematic_order, give the same numbers.
TEST(NematicOrder, CollisionStressOfAlignedRodsSplitsAlongAndAcrossTheDirector) {
  const sc::Spherocylinder rod{4.0, 0.5};
  const double tip = 0.5 * rod.length + rod.radius;  // centre to tip
  const double f = 40.0;
  Rng rng(3);
  for (int trial = 0; trial < 6; ++trial) {
    const Quat turn = trial == 0 ? Quat::Identity() : random_rotation(rng);
    const Vec3 shift = trial == 0 ? Vec3::Zero() : Vec3(1e4, -2e3, 5e3);
    const auto place = [&](const Vec3& x) { return Pose{turn * x + shift, turn}; };
    const Vec3 z = turn * Vec3::UnitZ(), x = turn * Vec3::UnitX();

    // Tip to tip: centres 2 tip + gap apart along z, a repulsion: +f z on the upper rod 1.
    const double tip_gap = 0.01, separation = 2.0 * tip + tip_gap;
    const Pose upper = place(Vec3(0, 0, separation)), lower = place(Vec3::Zero());
    const std::vector<Pose> column{upper, lower};
    const Vec3 n = sc::nematic_order(column).director;
    const Mat3 column_stress =
        sc::collision_stress(rod, upper, upper.x - tip * z, rod, lower, lower.x + tip * z, Vec3(f * z));
    const sc::DirectionalPressure tip_split = sc::pressure_along_and_across(column_stress, n);
    EXPECT_NEAR(tip_split.along, separation * f, 1e-12 * separation * f) << "trial " << trial;
    EXPECT_NEAR(tip_split.across, 0.0, 1e-12 * separation * f) << "trial " << trial;

    // Side by side: centres 2 R + gap apart along x, +f x on rod 1 at the overlap's middle.
    const double side = 2.0 * rod.radius + 0.01;
    const Pose right = place(Vec3(side, 0, 0)), left = place(Vec3::Zero());
    const Mat3 pair = sc::collision_stress(rod, right, right.x - rod.radius * x, rod, left, left.x + rod.radius * x,
                                           Vec3(f * x));
    const sc::DirectionalPressure side_split = sc::pressure_along_and_across(pair, n);
    EXPECT_NEAR(side_split.along, 0.0, 1e-12 * side * f) << "trial " << trial;
    EXPECT_NEAR(side_split.across, 0.5 * side * f, 1e-12 * side * f) << "trial " << trial;
    EXPECT_NEAR(side_split.along + 2.0 * side_split.across, pair.trace(), 1e-12 * side * f);
  }
}

// Yan's sigma_max / sigma_min: aligned rods pushed tip to tip along z (f_z), side by side along x
// (f_x) and along y (f_y) at the middles of their overlaps give, summed, the diagonal stress
// (sep_x f_x, sep_y f_y, sep_z f_z) in the rods' frame, so the ratio is the largest over the
// smallest of those products, in any frame; without the push along y it is unbounded.
TEST(NematicOrder, StressAnisotropyIsTheRatioOfTheExtremeEigenvalues) {
  const sc::Spherocylinder rod{4.0, 0.5};
  const double tip = 0.5 * rod.length + rod.radius, side = 2.0 * rod.radius + 0.01, column = 2.0 * tip + 0.01;
  const double fx = 30.0, fy = 10.0, fz = 20.0;
  Rng rng(5);
  for (int trial = 0; trial < 4; ++trial) {
    const Quat turn = trial == 0 ? Quat::Identity() : random_rotation(rng);
    const auto place = [&](const Vec3& x) { return Pose{turn * x, turn}; };
    const Vec3 ex = turn * Vec3::UnitX(), ey = turn * Vec3::UnitY(), ez = turn * Vec3::UnitZ();
    const Pose origin = place(Vec3::Zero()), right = place(side * Vec3::UnitX()), front = place(side * Vec3::UnitY()),
               upper = place(column * Vec3::UnitZ());
    const Mat3 x_push = sc::collision_stress(rod, right, right.x - rod.radius * ex, rod, origin,
                                             origin.x + rod.radius * ex, Vec3(fx * ex));
    const Mat3 y_push = sc::collision_stress(rod, front, front.x - rod.radius * ey, rod, origin,
                                             origin.x + rod.radius * ey, Vec3(fy * ey));
    const Mat3 z_push = sc::collision_stress(rod, upper, upper.x - tip * ez, rod, origin, origin.x + tip * ez,
                                             Vec3(fz * ez));
    const double products[] = {side * fx, side * fy, column * fz};
    const double expected = *std::max_element(products, products + 3) / *std::min_element(products, products + 3);
    EXPECT_NEAR(sc::stress_anisotropy(x_push + y_push + z_push), expected, 1e-12 * expected) << "trial " << trial;
    EXPECT_TRUE(std::isinf(sc::stress_anisotropy(x_push + z_push))) << "trial " << trial;
  }
  EXPECT_DOUBLE_EQ(sc::stress_anisotropy(2.0 * Mat3::Identity()), 1.0);
}

TEST(NematicOrder, RejectsEmptyInputAndZeroAxes) {
  const std::vector<Pose> none;
  expect_rejects([&] { sc::order_tensor(none); }, "poses");
  const std::vector<Pose> one{rod_along(Vec3::UnitZ(), 0.0)};
  expect_rejects([&] { sc::order_along(one, Vec3::Zero()); }, "axis");
  expect_rejects([&] { sc::pressure_along_and_across(Mat3::Identity(), Vec3::Zero()); }, "director");
  expect_rejects([&] { sc::pressure_along_and_across(Mat3::Identity(), Vec3(NAN, 0, 0)); }, "director");
  expect_rejects([&] { sc::stress_anisotropy(Mat3::Constant(NAN)); }, "sigma");
}

}  // namespace

}  // namespace nematic_order_tests
