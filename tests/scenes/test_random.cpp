#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "stokescontact/scenes/random.hpp"
#include "common/test_support.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace random_tests {

namespace sc = stokescontact;

namespace {

using test_support::expect_rejects;

constexpr double kPi = std::numbers::pi;
constexpr std::size_t kSamples = 20000;

// Kolmogorov-Smirnov distance between the samples and a continuous CDF.
template <typename Cdf>
double ks_distance(std::vector<double> samples, Cdf cdf) {
  std::sort(samples.begin(), samples.end());
  const double n = static_cast<double>(samples.size());
  double d = 0.0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const double f = cdf(samples[k]);
    d = std::max({d, f - static_cast<double>(k) / n, static_cast<double>(k + 1) / n - f});
  }
  return d;
}

// A loose KS bound: exceeded with probability ~1e-3 by a correct sampler (the seeds are fixed).
double ks_bound(std::size_t n) { return 1.95 / std::sqrt(static_cast<double>(n)); }

// The mean of n unit vectors uniform on the sphere: each component has standard deviation
// 1 / sqrt(3 n); the bound is 5 of them.
double mean_bound(std::size_t n) { return 5.0 / std::sqrt(3.0 * static_cast<double>(n)); }

}  // namespace

TEST(Uniform, StaysInItsIntervalAndIsReproducibleFromTheSeed) {
  const std::uint64_t seed = 101;
  SCOPED_TRACE("seed " + std::to_string(seed));
  sc::Rng rng(seed), again(seed);
  double mean = 0.0;
  for (std::size_t k = 0; k < kSamples; ++k) {
    const double u = sc::uniform(rng, -2.0, 3.0);
    ASSERT_GE(u, -2.0);
    ASSERT_LT(u, 3.0);
    ASSERT_EQ(u, sc::uniform(again, -2.0, 3.0));
    mean += u / static_cast<double>(kSamples);
  }
  EXPECT_NEAR(mean, 0.5, 5.0 * 5.0 / std::sqrt(12.0 * static_cast<double>(kSamples)));
  EXPECT_EQ(sc::uniform(rng, 1.5, 1.5), 1.5);
  const sc::Vec3 v = sc::uniform_vector(rng, 4.0, 5.0);
  EXPECT_TRUE((v.array() >= 4.0).all() && (v.array() < 5.0).all()) << v.transpose();
}

#if defined(__GLIBCXX__)
// The reason for the explicit formula: libstdc++'s std::uniform_real_distribution gives the
// same numbers on this engine, so scenes drawn with it before (the examples' packings) are
// unchanged, and other standard libraries give them too.
TEST(Uniform, EqualsLibstdcxxUniformRealDistribution) {
  for (const std::uint64_t seed : {1u, 2u, 2024u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    sc::Rng ours(seed), theirs(seed);
    for (std::size_t k = 0; k < kSamples; ++k) {
      const double lo = k % 2 ? 0.0 : -3.25, hi = k % 3 ? 17.5 : 1.0;
      ASSERT_EQ(sc::uniform(ours, lo, hi), std::uniform_real_distribution<double>(lo, hi)(theirs)) << "draw " << k;
    }
  }
}
#endif

TEST(RandomUnitVector, IsUnitAndUniformOnTheSphere) {
  const std::uint64_t seed = 202;
  SCOPED_TRACE("seed " + std::to_string(seed));
  sc::Rng rng(seed);
  sc::Vec3 mean = sc::Vec3::Zero();
  std::vector<double> z(kSamples);
  for (double& zk : z) {
    const sc::Vec3 v = sc::random_unit_vector(rng);
    ASSERT_NEAR(v.norm(), 1.0, 1e-15);
    mean += v / static_cast<double>(kSamples);
    zk = v.z();
  }
  EXPECT_LT(mean.norm(), mean_bound(kSamples)) << mean.transpose();
  // Archimedes: one coordinate of a uniform point on the sphere is uniform on [-1, 1].
  EXPECT_LT(ks_distance(z, [](double t) { return 0.5 * (t + 1.0); }), ks_bound(kSamples));
}

TEST(RandomRotation, IsAUnitQuaternion) {
  sc::Rng rng(303);
  for (int k = 0; k < 1000; ++k) {
    const sc::Quat q = sc::random_rotation(rng);
    ASSERT_LE(std::abs(q.norm() - 1.0), sc::kUnitQuaternionTolerance) << "seed 303, draw " << k;
    ASSERT_NO_THROW(sc::require_unit(q, "q"));
  }
}

// Haar measure on SO(3): R e_z is uniform on the sphere (mean ~0), and the rotation angle
// theta has density (1 - cos theta) / pi on [0, pi], CDF (theta - sin theta) / pi.
TEST(RandomRotation, IsUniformlyDistributed) {
  const std::uint64_t seed = 404;
  SCOPED_TRACE("seed " + std::to_string(seed));
  sc::Rng rng(seed);
  sc::Vec3 mean_axis = sc::Vec3::Zero();
  sc::Mat3 mean_matrix = sc::Mat3::Zero();
  std::vector<double> angle(kSamples);
  for (double& theta : angle) {
    const sc::Quat q = sc::random_rotation(rng);
    mean_axis += q * sc::Vec3::UnitZ() / static_cast<double>(kSamples);
    mean_matrix += q.toRotationMatrix() / static_cast<double>(kSamples);
    theta = 2.0 * std::acos(std::min(1.0, std::abs(q.w())));
  }
  EXPECT_LT(mean_axis.norm(), mean_bound(kSamples)) << mean_axis.transpose();
  EXPECT_LT(mean_matrix.cwiseAbs().maxCoeff(), 5.0 / std::sqrt(3.0 * static_cast<double>(kSamples)));
  const auto haar_cdf = [](double t) { return (t - std::sin(t)) / kPi; };
  EXPECT_LT(ks_distance(angle, haar_cdf), ks_bound(kSamples));
  // The bound has teeth: angles uniform on [0, pi] (a common mistake) are far off.
  std::vector<double> wrong(kSamples);
  for (double& t : wrong) t = sc::uniform(rng, 0.0, kPi);
  EXPECT_GT(ks_distance(wrong, haar_cdf), 10.0 * ks_bound(kSamples));
}

TEST(RandomPoses, DrawACentreThenARotationPerPose) {
  const std::uint64_t seed = 505;
  SCOPED_TRACE("seed " + std::to_string(seed));
  sc::Rng rng(seed), replay(seed);
  const std::vector<sc::Pose> poses = sc::random_poses(50, -1.0, 4.0, rng);
  ASSERT_EQ(poses.size(), 50u);
  for (const sc::Pose& p : poses) {
    EXPECT_TRUE((p.x.array() >= -1.0).all() && (p.x.array() < 4.0).all()) << p.x.transpose();
    EXPECT_EQ(p.x, sc::uniform_vector(replay, -1.0, 4.0));
    EXPECT_EQ(p.q.coeffs(), sc::random_rotation(replay).coeffs());
  }
  EXPECT_NO_THROW(sc::validate(poses));
  EXPECT_TRUE(sc::random_poses(0, 0.0, 1.0, rng).empty());
}

TEST(RandomForces, HaveTheGivenMagnitudeAndUniformDirections) {
  const std::uint64_t seed = 606;
  SCOPED_TRACE("seed " + std::to_string(seed));
  sc::Rng rng(seed);
  const std::vector<sc::Vec3> f = sc::random_forces(kSamples, 100.0, rng);
  ASSERT_EQ(f.size(), kSamples);
  sc::Vec3 mean = sc::Vec3::Zero();
  for (const sc::Vec3& v : f) {
    ASSERT_NEAR(v.norm(), 100.0, 1e-12);
    mean += v / (100.0 * static_cast<double>(kSamples));
  }
  EXPECT_LT(mean.norm(), mean_bound(kSamples)) << mean.transpose();
  for (const sc::Vec3& v : sc::random_forces(3, 0.0, rng)) EXPECT_EQ(v, sc::Vec3::Zero());
}

TEST(Random, RejectsBadInputNamingTheField) {
  sc::Rng rng(1);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  expect_rejects([&] { sc::uniform(rng, 1.0, 0.0); }, "hi");
  expect_rejects([&] { sc::uniform(rng, nan, 1.0); }, "lo");
  expect_rejects([&] { sc::uniform(rng, 0.0, inf); }, "hi");
  expect_rejects([&] { sc::uniform_vector(rng, 2.0, -2.0); }, "hi");
  expect_rejects([&] { sc::random_poses(3, -inf, 1.0, rng); }, "lo");
  expect_rejects([&] { sc::random_poses(3, 1.0, 0.5, rng); }, "hi");
  expect_rejects([&] { sc::random_forces(3, -1.0, rng); }, "magnitude");
  expect_rejects([&] { sc::random_forces(3, nan, rng); }, "magnitude");
}

}  // namespace random_tests
