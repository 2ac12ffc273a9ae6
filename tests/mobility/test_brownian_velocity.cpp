#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/mobility/brownian_velocity.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/mobility/rpy_mobility.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace brownian_velocity_tests {

namespace sc = stokescontact;

// The Brownian slot: free-draining offers an exact square root and divergence, RPY only its
// (zero) divergence (it gets the Lanczos square root); both stay plain MobilityOperators.
static_assert(sc::SquareRootMobility<sc::FreeDrainingMobility>);
static_assert(sc::ExactDivergenceMobility<sc::FreeDrainingMobility>);
static_assert(sc::DenseMobilityOperator<sc::FreeDrainingMobility>);
static_assert(!sc::SquareRootMobility<sc::RpyMobility>);
static_assert(sc::ExactDivergenceMobility<sc::RpyMobility>);
static_assert(sc::DenseMobilityOperator<sc::RpyMobility>);

namespace {

using test_support::expect_rejects;
using test_support::Rng;

constexpr double kPi = std::numbers::pi;

// An SPD 6x6 with translation-rotation coupling (not symmetric), as an irregular body has.
sc::Mat6 coupled_body_mobility(Rng& rng) {
  sc::Mat6 a;
  for (auto& x : a.reshaped()) x = test_support::uniform(rng, -1.0, 1.0);
  return a * a.transpose() + 0.3 * sc::Mat6::Identity();
}

// Bodies cycling through a sphere, a slender rod and a coupled irregular body.
sc::FreeDrainingMobility mixed_free_draining(std::size_t bodies, int dofs, Rng& rng) {
  std::vector<sc::Mat6> shapes{sc::sphere_mobility({0.7}, 1.3), sc::spherocylinder_mobility({4.0, 0.5}, 1.3),
                               coupled_body_mobility(rng)};
  std::vector<std::size_t> shape_of_body(bodies);
  for (std::size_t i = 0; i < bodies; ++i) shape_of_body[i] = i % 3;
  return sc::FreeDrainingMobility(shapes, shape_of_body, dofs);
}

// Columns B e_j of the model's square root.
template <typename M>
sc::MatX sqrt_matrix(M& model) {
  sc::MatX b(model.size(), model.size());
  for (Eigen::Index j = 0; j < model.size(); ++j) b.col(j) = model.apply_sqrt(sc::VecX::Unit(model.size(), j));
  return b;
}

// The symmetric square root of an SPD matrix from its eigendecomposition (the reference).
sc::MatX dense_sqrt(const sc::MatX& m) {
  const Eigen::SelfAdjointEigenSolver<sc::MatX> eigen(m);
  return eigen.eigenvectors() * eigen.eigenvalues().cwiseSqrt().asDiagonal() * eigen.eigenvectors().transpose();
}

// Sample covariance (1/n) sum U U^T of n draws of U^B against 2 kT M / dt, entry by entry within
// five standard errors: for a Gaussian, var(U_i U_j) = S_ii S_jj + S_ij^2 with S = 2 kT M / dt;
// the sample mean within five standard errors of 0.
template <typename M>
void expect_covariance(M& model, double kT, double dt, int samples, std::uint64_t seed,
                       const sc::LanczosOptions& options = {}) {
  SCOPED_TRACE("seed " + std::to_string(seed) + ", samples " + std::to_string(samples));
  const sc::MatX S = 2.0 * kT / dt * model.dense_matrix();
  sc::GaussianStream rng(seed);
  const Eigen::Index n = model.size();
  sc::MatX covariance = sc::MatX::Zero(n, n);
  sc::VecX mean = sc::VecX::Zero(n);
  for (int k = 0; k < samples; ++k) {
    const sc::VecX u = sc::brownian_velocity(model, kT, dt, rng, options).value;
    covariance.selfadjointView<Eigen::Lower>().rankUpdate(u);
    mean += u;
  }
  covariance = covariance.selfadjointView<Eigen::Lower>();
  covariance /= samples;
  mean /= samples;
  const double root_n = std::sqrt(static_cast<double>(samples));
  for (Eigen::Index i = 0; i < n; ++i) {
    EXPECT_LT(std::abs(mean(i)), 5.0 * std::sqrt(S(i, i)) / root_n) << "mean " << i;
    for (Eigen::Index j = 0; j <= i; ++j)
      EXPECT_LT(std::abs(covariance(i, j) - S(i, j)), 5.0 * std::sqrt(S(i, i) * S(j, j) + S(i, j) * S(i, j)) / root_n)
          << "entry (" << i << ", " << j << "): " << covariance(i, j) << " vs " << S(i, j);
  }
}

}  // namespace

// B B^T = M: spheres, rotated rods and coupled bodies, all six dofs or the translations alone.
TEST(FreeDrainingSqrt, SquaresToTheMobilityBlockByBlock) {
  for (const int dofs : {6, 3}) {
    SCOPED_TRACE(dofs);
    Rng rng(7);
    sc::FreeDrainingMobility model = mixed_free_draining(9, dofs, rng);
    const std::vector<sc::Pose> poses = sc::random_poses(9, 0.0, 10.0, rng);
    model.set_configuration(poses);
    model.reset_applications();
    const sc::MatX B = sqrt_matrix(model);
    EXPECT_EQ(model.applications(), static_cast<std::size_t>(model.size()));  // one per apply_sqrt
    const sc::MatX M = model.dense_matrix();
    EXPECT_LT((B * B.transpose() - M).cwiseAbs().maxCoeff(), 1e-13 * M.cwiseAbs().maxCoeff());
    // Block diagonal: body i's increment comes from its own W_i only.
    for (Eigen::Index i = 0; i < 9; ++i)
      for (Eigen::Index j = 0; j < 9; ++j)
        if (i != j) {
          EXPECT_EQ(B.block(dofs * i, dofs * j, dofs, dofs).cwiseAbs().maxCoeff(), 0.0);
        }
  }
}

TEST(FreeDrainingSqrt, TranslatingSphereIsTheScalarStokesEinsteinRoot) {
  const double a = 0.4, eta = 2.5;
  sc::FreeDrainingMobility model(sc::sphere_mobility({a}, eta), 5, 3);
  Rng rng(8);
  model.set_configuration(sc::random_poses(5, 0.0, 4.0, rng));
  sc::GaussianStream w(9);
  const sc::VecX W = w.vector(15);
  const sc::VecX expected = std::sqrt(1.0 / (6.0 * kPi * eta * a)) * W;
  EXPECT_LT((model.apply_sqrt(W) - expected).cwiseAbs().maxCoeff(), 1e-15 * expected.cwiseAbs().maxCoeff());
}

TEST(FreeDrainingSqrt, RejectsBadInput) {
  sc::FreeDrainingMobility model(sc::sphere_mobility({1.0}, 1.0), 2, 6);
  EXPECT_THROW(model.apply_sqrt(sc::VecX::Zero(12)), std::logic_error);  // not configured
  model.set_configuration(std::vector<sc::Pose>(2));
  expect_rejects([&] { model.apply_sqrt(sc::VecX::Zero(11)); }, "W");
  sc::VecX bad = sc::VecX::Zero(12);
  bad(4) = std::numeric_limits<double>::quiet_NaN();
  expect_rejects([&] { model.apply_sqrt(bad); }, "W");
}

// The Lanczos fallback against the dense symmetric root of RPY spheres (overlaps allowed), with
// the cost counted by the model: one application per Lanczos step.
TEST(MobilitySqrt, LanczosMatchesDenseRootOfRpySpheres) {
  for (const int dofs : {3, 6}) {
    Rng rng(21);
    sc::RpyMobility model(40, {1.0, 1.0}, dofs);
    model.set_configuration(sc::random_poses(40, 0.0, 10.0, rng));  // packing ~0.17
    const sc::MatX root = dense_sqrt(model.dense_matrix());
    sc::GaussianStream w(22);
    const sc::VecX W = w.vector(model.size());
    const sc::VecX exact = root * W;
    for (const double tolerance : {1e-4, 1e-8}) {
      SCOPED_TRACE("dofs " + std::to_string(dofs) + ", tolerance " + std::to_string(tolerance));
      model.reset_applications();
      const sc::MobilitySqrtProduct product = sc::mobility_sqrt(model, W, {tolerance, 200});
      EXPECT_FALSE(product.exact);
      EXPECT_EQ(model.applications(), static_cast<std::size_t>(product.lanczos_iterations));
      EXPECT_LE(product.lanczos_relative_change, tolerance);
      // Error ~ change rho / (1 - rho) (core/lanczos.hpp): within three times the tolerance.
      EXPECT_LE((product.value - exact).norm() / exact.norm(), 3.0 * tolerance);
      EXPECT_LT(product.lanczos_iterations, 60);
    }
  }
}

TEST(MobilitySqrt, ExactModelsSkipLanczos) {
  Rng rng(23);
  sc::FreeDrainingMobility model = mixed_free_draining(4, 6, rng);
  model.set_configuration(sc::random_poses(4, 0.0, 5.0, rng));
  sc::GaussianStream w(24);
  const sc::VecX W = w.vector(24);
  model.reset_applications();
  const sc::MobilitySqrtProduct product = sc::mobility_sqrt(model, W);
  EXPECT_TRUE(product.exact);
  EXPECT_EQ(product.lanczos_iterations, 0);
  EXPECT_EQ(model.applications(), 1u);
  EXPECT_EQ(product.value, model.apply_sqrt(W));
}

TEST(MobilitySqrt, UnconvergedLanczosThrowsAfterCountedApplications) {
  Rng rng(25);
  sc::RpyMobility model(30, {1.0, 1.0}, 3);
  model.set_configuration(sc::random_poses(30, 0.0, 8.0, rng));
  sc::GaussianStream w(26);
  model.reset_applications();
  EXPECT_THROW(sc::mobility_sqrt(model, w.vector(90), {1e-10, 3}), std::runtime_error);
  EXPECT_EQ(model.applications(), 3u);
}

// U^B = sqrt(2 kT / dt) M^(1/2) W on both paths, and the stream overload draws W in order.
TEST(BrownianVelocity, IsScaledSquareRootOfTheGivenNoise) {
  const double kT = 0.7, dt = 0.01;
  Rng rng(27);
  sc::FreeDrainingMobility free_draining = mixed_free_draining(3, 6, rng);
  free_draining.set_configuration(sc::random_poses(3, 0.0, 5.0, rng));
  sc::RpyMobility rpy(6, {1.0, 1.0}, 3);
  rpy.set_configuration(sc::random_poses(6, 0.0, 5.0, rng));
  const auto check = [&](auto& model) {
    sc::GaussianStream stream(28), copy(28);
    const sc::VecX W = copy.vector(model.size());
    const sc::VecX root = sc::mobility_sqrt(model, W, {1e-10, 100}).value;
    const sc::VecX u = sc::brownian_velocity(model, kT, dt, stream, {1e-10, 100}).value;
    EXPECT_LT((u - std::sqrt(2.0 * kT / dt) * root).norm(), 1e-14 * u.norm());
    EXPECT_EQ(stream(), copy());  // exactly size() variates drawn
  };
  check(free_draining);
  check(rpy);
}

TEST(BrownianVelocity, CovarianceIsTwoKtMobilityOverDtExactRoot) {
  Rng rng(29);
  sc::FreeDrainingMobility model = mixed_free_draining(3, 6, rng);  // sphere, rod, coupled body
  model.set_configuration(sc::random_poses(3, 0.0, 5.0, rng));
  expect_covariance(model, 1.7, 0.05, 20000, 30);
}

TEST(BrownianVelocity, CovarianceIsTwoKtMobilityOverDtLanczos) {
  Rng rng(31);
  sc::RpyMobility model(4, {1.0, 1.0}, 3);
  model.set_configuration(sc::random_poses(4, 0.0, 3.0, rng));  // close and overlapping spheres
  expect_covariance(model, 1.7, 0.05, 10000, 32, {1e-8, 100});
}

TEST(BrownianVelocity, ZeroTemperatureCostsNothing) {
  sc::RpyMobility model(5, {1.0, 1.0}, 6);
  Rng rng(33);
  model.set_configuration(sc::random_poses(5, 0.0, 5.0, rng));
  model.reset_applications();
  sc::GaussianStream stream(34), fresh(34);
  const sc::MobilitySqrtProduct u = sc::brownian_velocity(model, 0.0, 0.1, stream);
  EXPECT_EQ(u.value, sc::VecX::Zero(30));
  EXPECT_EQ(model.applications(), 0u);
  EXPECT_EQ(stream(), fresh());  // nothing drawn
}

TEST(BrownianVelocity, RejectsBadInputNamingTheField) {
  sc::FreeDrainingMobility model(sc::sphere_mobility({1.0}, 1.0), 2, 3);
  model.set_configuration(std::vector<sc::Pose>(2));
  sc::GaussianStream rng(35);
  const sc::VecX W = sc::VecX::Ones(6);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect_rejects([&] { sc::brownian_velocity(model, -1.0, 0.1, W); }, "kT");
  expect_rejects([&] { sc::brownian_velocity(model, nan, 0.1, rng); }, "kT");
  expect_rejects([&] { sc::brownian_velocity(model, 1.0, 0.0, W); }, "dt");
  expect_rejects([&] { sc::brownian_velocity(model, 1.0, std::numeric_limits<double>::infinity(), rng); }, "dt");
  expect_rejects([&] { sc::brownian_velocity(model, 1.0, 0.1, sc::VecX::Ones(5)); }, "W");
  sc::VecX bad = W;
  bad(2) = nan;
  expect_rejects([&] { sc::brownian_velocity(model, 1.0, 0.1, bad); }, "W");
  expect_rejects([&] { sc::brownian_velocity(model, 1.0, 0.1, W, {-1.0, 10}); }, "LanczosOptions.tolerance");
  expect_rejects([&] { sc::mobility_sqrt(model, sc::VecX::Ones(7)); }, "W");
}

}  // namespace brownian_velocity_tests
