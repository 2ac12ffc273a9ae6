#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/d_try.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace d_try_tests {

namespace sc = stokescontact;
using test_support::expect_rejects;
using sc::Pose;
using sc::Vec3;
using sc::VecX;

// eq. 31: d_hat + dt max |u_i|, rotations ignored, times the multiplier.
TEST(DTry, SpheresFollowEquation31) {
  VecX u3(6);
  u3 << 3, 4, 0, 0, 0, 1;
  EXPECT_DOUBLE_EQ(sc::d_try_spheres(0.1, 0.01, u3, 3), 0.1 + 0.01 * 5.0);
  EXPECT_DOUBLE_EQ(sc::d_try_spheres(0.1, 0.01, u3, 3, 1.2), 1.2 * (0.1 + 0.01 * 5.0));
  VecX u6(12);
  u6 << 3, 4, 0, 100, 0, 0, 0, 0, 1, 0, -50, 0;
  EXPECT_DOUBLE_EQ(sc::d_try_spheres(0.1, 0.01, u6, 6), 0.15);
  // The general rule gives the same for spheres: a sphere's centre curve is its centre.
  const std::vector<Pose> poses = {Pose{}, {Vec3(3, 0, 0), sc::Quat::Identity()}};
  EXPECT_DOUBLE_EQ(sc::d_try_tip_velocity(0.1, 0.01, sc::Sphere{0.7}, poses, u6), 0.15);
}

// eq. 30 for a rod along z (centre segment length L = 2): u = (1, 0, 0), omega = (0, 1, 0)
// moves the tip +z at u + (L/2) omega x e_z = (2, 0, 0) and the tip -z at rest. (The
// printed expression u + (L/2) v x omega gives the tip at rest, 0, here; we take the faster.)
TEST(DTry, RodTakesFasterTip) {
  const sc::Spherocylinder rod{2.0, 0.4};
  const std::vector<Pose> upright = {Pose{}};
  VecX u(6);
  u << 1, 0, 0, 0, 1, 0;
  EXPECT_DOUBLE_EQ(sc::d_try_tip_velocity(0.1, 0.01, rod, upright, u), 0.1 + 0.01 * 2.0);
  // Rotated: tips at x +- R e_z; the faster of u +- omega x (R e_z).
  std::mt19937_64 rng(201);
  for (int trial = 0; trial < 20; ++trial) {
    const std::vector<Pose> poses = test_support::random_poses(3, -5.0, 5.0, rng);
    const VecX vel = VecX::NullaryExpr(18, [&] { return test_support::uniform(rng, -2, 2); });
    double fastest = 0.0;
    for (int k = 0; k < 3; ++k) {
      const Vec3 arm = poses[static_cast<std::size_t>(k)].q * Vec3(0, 0, 1.0);
      const Vec3 v = vel.segment<3>(6 * k), w = vel.segment<3>(6 * k + 3);
      fastest = std::max({fastest, (v + w.cross(arm)).norm(), (v - w.cross(arm)).norm()});
    }
    EXPECT_NEAR(sc::d_try_tip_velocity(0.05, 0.02, rod, poses, vel, 1.1), 1.1 * (0.05 + 0.02 * fastest), 1e-15);
  }
}

// Boomerangs: at least the fastest of densely sampled centre-curve points, at most that plus
// |omega| (sqrt 2 - 1) R_b, the farthest the bend's enclosing corner lies from the bend.
TEST(DTry, BoomerangBoundsEveryCentreCurvePoint) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  const auto curve = sc::centre_curve(b);
  std::vector<Vec3> samples;
  for (const auto& s : curve.segments)
    for (int i = 0; i <= 200; ++i) samples.push_back(s.point(i / 200.0));
  for (const auto& a : curve.arcs)
    for (int i = 0; i <= 200; ++i) samples.push_back(a.point(a.angle * i / 200.0));
  std::mt19937_64 rng(202);
  for (int trial = 0; trial < 50; ++trial) {
    const std::vector<Pose> poses = test_support::random_poses(1, -5.0, 5.0, rng);
    const VecX vel = VecX::NullaryExpr(6, [&] { return test_support::uniform(rng, -2, 2); });
    const Vec3 v = vel.head<3>(), w = vel.tail<3>();
    double sampled = 0.0;
    for (const Vec3& r : samples) sampled = std::max(sampled, (v + w.cross(poses[0].q * r)).norm());
    const double speed = (sc::d_try_tip_velocity(0.05, 1.0, b, poses, vel) - 0.05) / 1.0;
    EXPECT_GE(speed, sampled - 1e-12) << "trial " << trial;
    EXPECT_LE(speed, sampled + w.norm() * (std::sqrt(2.0) - 1.0) * b.bend_radius + 1e-12) << "trial " << trial;
  }
}

TEST(DTry, RejectsBadInput) {
  VecX u(6);
  u << 1, 0, 0, 0, 1, 0;
  const std::vector<Pose> one = {Pose{}};
  const sc::Spherocylinder rod{2.0, 0.4};
  expect_rejects([&] { sc::d_try_spheres(0.1, 0.01, u, 3, 0.9); }, "multiplier");
  expect_rejects([&] { sc::d_try_spheres(0.1, 0.0, u, 3); }, "dt");
  expect_rejects([&] { sc::d_try_spheres(-0.1, 0.01, u, 3); }, "d_hat");
  expect_rejects([&] { sc::d_try_spheres(0.1, 0.01, u, 4); }, "dofs_per_body");
  expect_rejects([&] { sc::d_try_spheres(0.1, 0.01, VecX::Ones(5), 3); }, "U");
  expect_rejects([&] { sc::d_try_tip_velocity(0.1, 0.01, rod, one, VecX::Ones(12)); }, "U");
  VecX bad = u;
  bad[2] = std::nan("");
  expect_rejects([&] { sc::d_try_tip_velocity(0.1, 0.01, rod, one, bad); }, "U");
  expect_rejects([&] { sc::d_try_tip_velocity(0.1, 0.01, sc::Spherocylinder{-1.0, 0.4}, one, u); },
                 "Spherocylinder.length");
}

}  // namespace d_try_tests
