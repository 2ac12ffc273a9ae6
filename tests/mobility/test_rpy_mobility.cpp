#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "stokescontact/mobility/rpy_mobility.hpp"
#include "mobility/mobility_checks.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace rpy_mobility_tests {

namespace sc = stokescontact;

static_assert(sc::MobilityOperator<sc::RpyMobility>);
static_assert(sc::DenseMobilityOperator<sc::RpyMobility>);

namespace {

using mobility_checks::min_eigenvalue;
using sc::random_poses;
using sc::random_rotation;
using mobility_checks::random_vector;

constexpr double kPi = std::numbers::pi;
constexpr unsigned kSeed = 31337;

// Smallest pair distance of a configuration (to report how much it overlaps).
double min_distance(const std::vector<sc::Pose>& poses) {
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (std::size_t j = i + 1; j < poses.size(); ++j) d = std::min(d, (poses[i].x - poses[j].x).norm());
  return d;
}

// All five scalar coefficients of a pair, in their units (mu_t, mu_rt, mu_r).
std::array<double, 5> pair_coefficients(double r, double a) {
  const sc::RpyCoefficients t = sc::rpy_translation_coefficients(r, a);
  const sc::RpyRotationCoefficients q = sc::rpy_rotation_coefficients(r, a);
  return {t.f, t.g, q.w, q.f_r, q.g_r};
}

// (1/2) curl of the velocity field x -> M(x - x_j) v, at x - x_j = r, by central differences.
template <typename Block>
sc::Mat3 half_curl(Block block, const sc::Vec3& r, double h) {
  sc::Mat3 out;
  for (int c = 0; c < 3; ++c) {
    const sc::Vec3 v = sc::Vec3::Unit(c);
    sc::Mat3 grad;  // grad(k, l) = d u_k / d x_l
    for (int l = 0; l < 3; ++l) {
      const sc::Vec3 e = h * sc::Vec3::Unit(l);
      grad.col(l) = (block(r + e) * v - block(r - e) * v) / (2.0 * h);
    }
    out.col(c) = 0.5 * sc::Vec3(grad(2, 1) - grad(1, 2), grad(0, 2) - grad(2, 0), grad(1, 0) - grad(0, 1));
  }
  return out;
}

}  // namespace

// Wajnryb et al.: both branches agree at r = 2a in value and first derivative.
TEST(RpyPairBlocks, BranchesAreContinuousAtTwoRadii) {
  const double a = 0.8, r0 = 2.0 * a, h = 1e-6 * a;
  const auto at = pair_coefficients(r0, a);                   // near branch (r <= 2a)
  const auto above = pair_coefficients(r0 * (1 + 1e-15), a);  // far branch
  const auto left = pair_coefficients(r0 - h, a), right = pair_coefficients(r0 + h, a);
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_NEAR(at[k], above[k], 1e-14) << "coefficient " << k;
    const double d_near = (at[k] - left[k]) / h, d_far = (right[k] - at[k]) / h;
    EXPECT_NEAR(d_near, d_far, 1e-5 / a) << "derivative of coefficient " << k;
  }
}

// At r -> 0 the pair blocks become the self mobilities.
TEST(RpyPairBlocks, CoincidentLimitIsSelfMobility) {
  const double a = 1.3, eta = 0.7;
  const sc::Vec3 r(1e-9, -2e-9, 0.5e-9);
  EXPECT_LT((sc::rpy_translation(r, a, eta) - sc::stokes_mobility(a, eta) * sc::Mat3::Identity()).norm(),
            1e-8 * sc::stokes_mobility(a, eta));
  EXPECT_LT(sc::rpy_rotation_translation(r, a, eta).norm(), 1e-8 * sc::rotation_translation_mobility(a, eta));
  EXPECT_LT((sc::rpy_rotation_rotation(r, a, eta) - sc::rotation_mobility(a, eta) * sc::Mat3::Identity()).norm(),
            1e-8 * sc::rotation_mobility(a, eta));
}

// Sign conventions of the far branches: a sphere turns with the fluid, omega = (1/2) curl u
// (Faxen), for the flow of a force (giving M_rt) and of a torque (u = M_rt tau, giving M_rr).
TEST(RpyPairBlocks, FarRotationBlocksAreHalfCurlOfTheFlow) {
  const double a = 0.5, eta = 1.7;
  sc::Rng rng(kSeed);
  for (int trial = 0; trial < 5; ++trial) {
    sc::Vec3 r = random_vector(3, rng);
    r *= (2.5 + trial) * a / r.norm();
    const auto tt = [&](const sc::Vec3& x) { return sc::rpy_translation(x, a, eta); };
    const auto rt = [&](const sc::Vec3& x) { return sc::rpy_rotation_translation(x, a, eta); };
    const double h = 1e-4 * a;
    EXPECT_LT((half_curl(tt, r, h) - rt(r)).norm(), 1e-7 * rt(r).norm()) << "seed " << kSeed;
    const sc::Mat3 rr = sc::rpy_rotation_rotation(r, a, eta);
    EXPECT_LT((half_curl(rt, r, h) - rr).norm(), 1e-7 * rr.norm()) << "seed " << kSeed;
  }
}

TEST(RpyMobility, SingleSphereIsStokesEinstein) {
  const double a = 0.9, eta = 1.4;
  sc::RpyMobility m(1, {eta, a}, 6);
  m.set_configuration(std::vector<sc::Pose>(1));
  const sc::VecX U = m.apply(sc::VecX::Ones(6));
  EXPECT_NEAR(U(0) * 6.0 * kPi * eta * a, 1.0, 1e-15);
  EXPECT_NEAR(U(4) * 8.0 * kPi * eta * a * a * a, 1.0, 1e-15);
}

// Random configurations with many overlaps: M stays SPD (Wajnryb et al.'s point).
TEST(RpyMobility, DenseMatrixIsSymmetricPositiveDefiniteWithOverlaps) {
  sc::Rng rng(kSeed + 1);
  for (int dofs : {3, 6}) {
    for (double box : {3.0, 8.0}) {  // 40 unit spheres in a box of side 3: heavy overlap
      sc::RpyMobility m(40, {1.0, 1.0}, dofs);
      const std::vector<sc::Pose> poses = random_poses(40, 0.0, box, rng);
      m.set_configuration(poses);
      const sc::MatX M = m.dense_matrix();
      const std::string info = "seed " + std::to_string(kSeed + 1) + ", dofs " + std::to_string(dofs) +
                               ", min distance " + std::to_string(min_distance(poses));
      EXPECT_LT((M - M.transpose()).cwiseAbs().maxCoeff(), 1e-15) << info;
      EXPECT_EQ(Eigen::LLT<sc::MatX>(M).info(), Eigen::Success) << info;
      EXPECT_GT(min_eigenvalue(M), 0.0) << info;
    }
  }
}

TEST(RpyMobility, ApplyEqualsDenseMatrixAndCountsApplications) {
  sc::Rng rng(kSeed + 2);
  for (int dofs : {3, 6}) {
    SCOPED_TRACE("seed " + std::to_string(kSeed + 2) + ", dofs " + std::to_string(dofs));
    // 300 spheres: two target blocks, the second partial; overlapping and distant pairs.
    sc::RpyMobility m(300, {0.8, 0.5}, dofs);
    m.set_configuration(random_poses(300, 0.0, 8.0, rng));
    mobility_checks::expect_apply_matches_dense(m, rng, 1e-13);
  }
}

TEST(RpyMobility, RigidMotionOfSceneRotatesMobility) {
  sc::Rng rng(kSeed + 3);
  for (int dofs : {3, 6}) {
    sc::RpyMobility m(20, {1.0, 1.0}, dofs);
    std::vector<sc::Pose> poses = random_poses(20, 0.0, 5.0, rng);
    m.set_configuration(poses);
    const sc::MatX M = m.dense_matrix();
    const sc::Quat q = random_rotation(rng);
    for (sc::Pose& p : poses) {
      p.x = q * p.x + sc::Vec3(-4.0, 1.0, 7.0);
      p.q = q * p.q;
    }
    m.set_configuration(poses);
    sc::MatX Q = sc::MatX::Zero(m.size(), m.size());
    for (Eigen::Index k = 0; k < m.size() / 3; ++k) Q.block<3, 3>(3 * k, 3 * k) = q.toRotationMatrix();
    EXPECT_LT((m.dense_matrix() - Q * M * Q.transpose()).cwiseAbs().maxCoeff(), 1e-13 * M.cwiseAbs().maxCoeff())
        << "seed " << kSeed + 3;
    const sc::VecX F = random_vector(m.size(), rng);
    EXPECT_LT((m.apply(Q * F) - Q * (M * F)).cwiseAbs().maxCoeff(), 1e-13 * (M * F).cwiseAbs().maxCoeff());
  }
}

// The translation-only model is the translation block of the full one.
TEST(RpyMobility, ThreeDofModelIsTranslationBlockOfSixDofModel) {
  sc::Rng rng(kSeed + 4);
  const std::vector<sc::Pose> poses = random_poses(60, 0.0, 4.0, rng);
  sc::RpyMobility m3(60, {1.0, 0.7}, 3), m6(60, {1.0, 0.7}, 6);
  m3.set_configuration(poses);
  m6.set_configuration(poses);
  const sc::MatX M3 = m3.dense_matrix(), M6 = m6.dense_matrix();
  for (Eigen::Index i = 0; i < 60; ++i)
    for (Eigen::Index j = 0; j < 60; ++j)
      EXPECT_EQ((M3.block<3, 3>(3 * i, 3 * j) - M6.block<3, 3>(6 * i, 6 * j)).cwiseAbs().maxCoeff(), 0.0);
  const sc::VecX f = random_vector(180, rng);
  sc::VecX F = sc::VecX::Zero(360);
  for (Eigen::Index i = 0; i < 60; ++i) F.segment<3>(6 * i) = f.segment<3>(3 * i);
  const sc::VecX U3 = m3.apply(f), U6 = m6.apply(F);
  for (Eigen::Index i = 0; i < 60; ++i)
    EXPECT_LT((U3.segment<3>(3 * i) - U6.segment<3>(6 * i)).norm(), 1e-14 * U3.cwiseAbs().maxCoeff());
}

#ifdef _OPENMP
// Each target sums its sources in one order, whatever the number of threads.
TEST(RpyMobility, ApplyDoesNotDependOnThreadCount) {
  sc::Rng rng(kSeed + 5);
  sc::RpyMobility m(1000, {1.0, 1.0}, 6);  // 8 blocks: the sum runs in parallel
  m.set_configuration(random_poses(1000, 0.0, 14.0, rng));
  const sc::VecX F = random_vector(m.size(), rng);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const sc::VecX serial = m.apply(F);
  omp_set_num_threads(std::max(2, threads));
  const sc::VecX parallel = m.apply(F);
  omp_set_num_threads(threads);
  EXPECT_EQ((serial - parallel).cwiseAbs().maxCoeff(), 0.0);
}
#endif

TEST(RpyMobility, RefusesBadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto message = [](auto&& make) {
    try {
      make();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_NE(message([] { sc::RpyMobility(3, {1.0, 0.0}); }).find("radius"), std::string::npos);
  EXPECT_NE(message([] { sc::RpyMobility(3, {-1.0, 1.0}); }).find("viscosity"), std::string::npos);
  EXPECT_NE(message([&] { sc::RpyMobility(3, {1.0, nan}); }).find("radius"), std::string::npos);
  EXPECT_THROW(sc::RpyMobility(3, {1.0, 1.0}, 4), std::invalid_argument);
  EXPECT_THROW(sc::RpyMobility(0, {1.0, 1.0}), std::invalid_argument);

  sc::RpyMobility m(2, {1.0, 1.0}, 6);
  EXPECT_THROW(m.apply(sc::VecX::Zero(12)), std::logic_error);
  std::vector<sc::Pose> poses(2);
  poses[1].x = sc::Vec3(0.5, 0.0, 0.0);  // overlapping is allowed
  EXPECT_NO_THROW(m.set_configuration(poses));
  EXPECT_THROW(m.set_configuration(std::vector<sc::Pose>(3)), std::invalid_argument);
  poses[0].x.z() = nan;
  EXPECT_NE(message([&] { m.set_configuration(poses); }).find("poses[0].x"), std::string::npos);
  EXPECT_THROW(m.apply(sc::VecX::Zero(6)), std::invalid_argument);
  sc::VecX F = sc::VecX::Zero(12);
  F(7) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(m.apply(F), std::invalid_argument);
  EXPECT_EQ(m.applications(), 0u);
}

}  // namespace rpy_mobility_tests
