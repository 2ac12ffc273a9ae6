#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/SparseCore>

#include "stokescontact/mobility/free_draining.hpp"
#include "mobility/mobility_checks.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace free_draining_tests {

namespace sc = stokescontact;

static_assert(sc::MobilityOperator<sc::FreeDrainingMobility>);
static_assert(sc::DenseMobilityOperator<sc::FreeDrainingMobility>);

namespace {

using mobility_checks::min_eigenvalue;
using sc::random_poses;
using sc::random_rotation;
using mobility_checks::random_vector;

constexpr double kPi = std::numbers::pi;
constexpr unsigned kSeed = 20240611;

// An SPD 6x6 with translation-rotation coupling, as a multiblob model of an irregular body gives.
sc::Mat6 random_body_mobility(sc::Rng& rng) {
  const sc::VecX a = random_vector(36, rng);
  const sc::Mat6 A = Eigen::Map<const sc::Mat6>(a.data());
  return A * A.transpose() + 0.5 * sc::Mat6::Identity();
}

// Three shapes: a sphere, a slender rod, an irregular body with coupling.
sc::FreeDrainingMobility mixed_scene(std::size_t bodies, int dofs, sc::Rng& rng) {
  std::vector<sc::Mat6> shapes{sc::sphere_mobility({0.7}, 1.3), sc::spherocylinder_mobility({4.0, 0.5}, 1.3),
                               random_body_mobility(rng)};
  std::vector<std::size_t> shape_of_body(bodies);
  for (std::size_t i = 0; i < bodies; ++i) shape_of_body[i] = i % 3;
  return sc::FreeDrainingMobility(shapes, shape_of_body, dofs);
}

}  // namespace

TEST(SingleBodyMobility, SphereIsStokesEinstein) {
  const double a = 0.37, eta = 2.9;
  const sc::Mat6 n = sc::sphere_mobility({a}, eta);
  for (int k = 0; k < 3; ++k) {
    EXPECT_DOUBLE_EQ(n(k, k) * 6.0 * kPi * eta * a, 1.0);
    EXPECT_DOUBLE_EQ(n(k + 3, k + 3) * 8.0 * kPi * eta * a * a * a, 1.0);
  }
  EXPECT_EQ((n - sc::Mat6(n.diagonal().asDiagonal())).cwiseAbs().maxCoeff(), 0.0);
}

// Yan et al. eq. 47-50 at L = 5, D = 1 (b = 2 ln 10 - 1), axis along body z.
TEST(SingleBodyMobility, SpherocylinderFollowsYanSlenderBody) {
  const double L = 5.0, R = 0.5, mu = 0.8;
  const double b = -(1.0 + 2.0 * std::log(2.0 * R / (2.0 * L)));
  EXPECT_NEAR(b, 2.0 * std::log(10.0) - 1.0, 1e-14);
  const sc::Mat6 n = sc::spherocylinder_mobility({L, R}, mu);
  const double perp = (b + 2.0) / (8.0 * kPi * L * mu), par = 2.0 * b / (8.0 * kPi * L * mu);
  const double rot = 3.0 * (b + 2.0) / (2.0 * kPi * L * L * L * mu);
  sc::Vec6 expected;
  expected << perp, perp, par, rot, rot, rot;
  EXPECT_LT((n.diagonal() - expected).cwiseAbs().maxCoeff(), 1e-15 * expected.maxCoeff());
  EXPECT_EQ((n - sc::Mat6(n.diagonal().asDiagonal())).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(par, perp);  // a slender rod slides along its axis more easily (b > 2 here)
}

TEST(SingleBodyMobility, SpherocylinderRefusesStubbyRods) {
  // b > 0 needs L / D > exp(1/2) / 2 = 0.8244.
  EXPECT_NO_THROW(sc::spherocylinder_mobility({0.83, 0.5}, 1.0));
  for (double L : {0.0, 0.5, 0.82}) {
    try {
      sc::spherocylinder_mobility({L, 0.5}, 1.0);
      ADD_FAILURE() << "L = " << L << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("Spherocylinder.length"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(sc::spherocylinder_mobility({2.0, 0.5}, 0.0), std::invalid_argument);
  EXPECT_THROW(sc::sphere_mobility({-1.0}, 1.0), std::invalid_argument);
}

TEST(FreeDrainingMobility, SphereSceneIsStokesEinsteinInBothModels) {
  const double a = 1.1, eta = 0.6;
  sc::Rng rng(kSeed);
  const std::vector<sc::Pose> poses = random_poses(50, 0.0, 10.0, rng);
  for (int dofs : {3, 6}) {
    sc::FreeDrainingMobility m(sc::sphere_mobility({a}, eta), poses.size(), dofs);
    m.set_configuration(poses);
    const sc::VecX F = random_vector(m.size(), rng);
    const sc::VecX U = m.apply(F);
    for (Eigen::Index i = 0; i < 50; ++i) {
      EXPECT_LT((U.segment<3>(dofs * i) * 6.0 * kPi * eta * a - F.segment<3>(dofs * i)).norm(), 1e-14);
      if (dofs == 6) {
        EXPECT_LT((U.segment<3>(6 * i + 3) * 8.0 * kPi * eta * a * a * a - F.segment<3>(6 * i + 3)).norm(), 1e-14);
      }
    }
  }
}

TEST(FreeDrainingMobility, RodBlockIsRotatedWithItsPose) {
  const sc::Mat6 n = sc::spherocylinder_mobility({4.0, 0.5}, 1.0);
  sc::FreeDrainingMobility m(n, 1);
  sc::Pose p;
  p.q = sc::Quat::FromTwoVectors(sc::Vec3::UnitZ(), sc::Vec3::UnitX());  // rod axis along world x
  m.set_configuration(std::vector<sc::Pose>{p});
  const sc::MatX M = m.dense_matrix();
  EXPECT_NEAR(M(0, 0), n(2, 2), 1e-15);  // parallel mobility now along x
  EXPECT_NEAR(M(1, 1), n(0, 0), 1e-15);
  EXPECT_NEAR(M(2, 2), n(0, 0), 1e-15);
}

TEST(FreeDrainingMobility, DenseMatrixIsSymmetricPositiveDefinite) {
  sc::Rng rng(kSeed);
  for (int dofs : {3, 6}) {
    sc::FreeDrainingMobility m = mixed_scene(30, dofs, rng);
    m.set_configuration(random_poses(30, 0.0, 5.0, rng));
    const sc::MatX M = m.dense_matrix();
    EXPECT_LT((M - M.transpose()).cwiseAbs().maxCoeff(), 1e-15 * M.cwiseAbs().maxCoeff()) << "seed " << kSeed;
    EXPECT_EQ(Eigen::LLT<sc::MatX>(M).info(), Eigen::Success) << "seed " << kSeed;
    EXPECT_GT(min_eigenvalue(M), 0.0) << "seed " << kSeed;
  }
}

TEST(FreeDrainingMobility, ApplyEqualsDenseMatrixAndCountsApplications) {
  sc::Rng rng(kSeed + 1);
  for (int dofs : {3, 6}) {
    SCOPED_TRACE("seed " + std::to_string(kSeed + 1) + ", dofs " + std::to_string(dofs));
    sc::FreeDrainingMobility m = mixed_scene(40, dofs, rng);
    m.set_configuration(random_poses(40, 0.0, 5.0, rng));
    mobility_checks::expect_apply_matches_dense(m, rng, 1e-13);
  }
}

// The sparse form (BlockDiagonalMobility, the contact step's blocks mode): the same products
// as apply, body blocks only, and no application counted.
TEST(FreeDrainingMobility, BlockDiagonalMatchesApplyWithoutApplications) {
  static_assert(sc::BlockDiagonalMobility<sc::FreeDrainingMobility>);
  sc::Rng rng(kSeed + 2);
  for (int dofs : {3, 6}) {
    SCOPED_TRACE("seed " + std::to_string(kSeed + 2) + ", dofs " + std::to_string(dofs));
    sc::FreeDrainingMobility m = mixed_scene(40, dofs, rng);
    m.set_configuration(random_poses(40, 0.0, 5.0, rng));
    const Eigen::SparseMatrix<double> M = m.block_diagonal();
    EXPECT_EQ(m.applications(), 0u);
    ASSERT_EQ(M.rows(), m.size());
    ASSERT_EQ(M.cols(), m.size());
    EXPECT_LE(M.nonZeros(), 40 * dofs * dofs);
    for (int k = 0; k < M.outerSize(); ++k)
      for (Eigen::SparseMatrix<double>::InnerIterator it(M, k); it; ++it)
        EXPECT_EQ(it.row() / dofs, it.col() / dofs) << "entry (" << it.row() << ", " << it.col() << ") off the body blocks";
    for (int trial = 0; trial < 3; ++trial) {
      const sc::VecX F = random_vector(m.size(), rng);
      const sc::VecX U = m.apply(F);
      EXPECT_LE((sc::VecX(M * F) - U).norm(), 1e-13 * U.norm());
    }
  }
}

// Rotating and shifting the whole scene rotates every block: M' = Q M Q^T.
TEST(FreeDrainingMobility, RigidMotionOfSceneRotatesMobility) {
  sc::Rng rng(kSeed + 2);
  for (int dofs : {3, 6}) {
    sc::FreeDrainingMobility m = mixed_scene(12, dofs, rng);
    std::vector<sc::Pose> poses = random_poses(12, 0.0, 5.0, rng);
    m.set_configuration(poses);
    const sc::MatX M = m.dense_matrix();
    const sc::Quat q = random_rotation(rng);
    const sc::Vec3 shift(3.0, -1.0, 2.0);
    for (sc::Pose& p : poses) {
      p.x = q * p.x + shift;
      p.q = q * p.q;
    }
    m.set_configuration(poses);
    sc::MatX Q = sc::MatX::Zero(m.size(), m.size());
    for (Eigen::Index k = 0; k < m.size() / 3; ++k) Q.block<3, 3>(3 * k, 3 * k) = q.toRotationMatrix();
    EXPECT_LT((m.dense_matrix() - Q * M * Q.transpose()).cwiseAbs().maxCoeff(), 1e-14 * M.cwiseAbs().maxCoeff())
        << "seed " << kSeed + 2;
  }
}

// The translation-only model is the translation block of the full one (exact when torque-free).
TEST(FreeDrainingMobility, ThreeDofModelIsTranslationBlockOfSixDofModel) {
  sc::Rng rng(kSeed + 3);
  const std::vector<sc::Pose> poses = random_poses(9, 0.0, 5.0, rng);
  sc::Rng shapes_rng(7);
  sc::FreeDrainingMobility m3 = mixed_scene(9, 3, shapes_rng);
  shapes_rng.seed(7);
  sc::FreeDrainingMobility m6 = mixed_scene(9, 6, shapes_rng);
  m3.set_configuration(poses);
  m6.set_configuration(poses);
  const sc::MatX M3 = m3.dense_matrix(), M6 = m6.dense_matrix();
  for (Eigen::Index i = 0; i < 9; ++i)
    for (Eigen::Index j = 0; j < 9; ++j)
      EXPECT_EQ((M3.block<3, 3>(3 * i, 3 * j) - M6.block<3, 3>(6 * i, 6 * j)).cwiseAbs().maxCoeff(), 0.0);
}

TEST(FreeDrainingMobility, ManyIdenticalBodiesShareOneMatrix) {
  const std::size_t n = 100000;
  sc::FreeDrainingMobility m(sc::sphere_mobility({1.0}, 1.0), n, 3);
  EXPECT_EQ(m.size(), static_cast<Eigen::Index>(3 * n));
  std::vector<sc::Pose> poses(n);
  for (std::size_t i = 0; i < n; ++i) poses[i].x = sc::Vec3(static_cast<double>(i), 0.0, 0.0);
  m.set_configuration(poses);
  const sc::VecX F = sc::VecX::Ones(m.size());
  EXPECT_LT((m.apply(F) * 6.0 * kPi - F).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(FreeDrainingMobility, RefusesBadInput) {
  const sc::Mat6 good = sc::sphere_mobility({1.0}, 1.0);
  sc::Mat6 asymmetric = good;
  asymmetric(0, 1) = 1e-3;
  sc::Mat6 indefinite = good;
  indefinite(2, 2) = -1.0;
  sc::Mat6 nan = good;
  nan(4, 4) = std::numeric_limits<double>::quiet_NaN();
  for (const sc::Mat6& bad : {asymmetric, indefinite, nan})
    EXPECT_THROW(sc::FreeDrainingMobility(std::vector<sc::Mat6>{good, bad}, std::vector<std::size_t>{0, 1}),
                 std::invalid_argument);
  EXPECT_THROW(sc::FreeDrainingMobility(good, 3, 4), std::invalid_argument);
  EXPECT_THROW(sc::FreeDrainingMobility(good, 0), std::invalid_argument);
  EXPECT_THROW(sc::FreeDrainingMobility(std::vector<sc::Mat6>{good}, std::vector<std::size_t>{0, 1}),
               std::invalid_argument);

  sc::FreeDrainingMobility m(sc::spherocylinder_mobility({3.0, 0.5}, 1.0), 2);
  EXPECT_THROW(m.apply(sc::VecX::Zero(12)), std::logic_error);  // no configuration yet
  std::vector<sc::Pose> poses(2);
  EXPECT_THROW(m.set_configuration(std::vector<sc::Pose>(3)), std::invalid_argument);
  poses[1].x.y() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(m.set_configuration(poses), std::invalid_argument);
  poses[1].x.y() = 0.0;
  poses[1].q.coeffs() *= 1.1;
  EXPECT_THROW(m.set_configuration(poses), std::invalid_argument);
  poses[1].q.normalize();
  m.set_configuration(poses);
  EXPECT_THROW(m.apply(sc::VecX::Zero(11)), std::invalid_argument);
  sc::VecX F = sc::VecX::Zero(12);
  F(5) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(m.apply(F), std::invalid_argument);
  EXPECT_EQ(m.applications(), 0u);
}

}  // namespace free_draining_tests
