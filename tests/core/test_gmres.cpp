#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "common/test_support.hpp"
#include "stokescontact/core/gmres.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace gmres_tests {

namespace sc = stokescontact;

namespace {

sc::VecX random_vector(Eigen::Index n, unsigned seed) { return test_support::random_matrix(n, seed).col(0); }

// A with prescribed singular values: U diag(s) V^T from two random orthogonal factors.
sc::MatX with_singular_values(const sc::VecX& s, unsigned seed) {
  const Eigen::Index n = s.size();
  const Eigen::HouseholderQR<sc::MatX> qu(test_support::random_matrix(n, seed)), qv(test_support::random_matrix(n, seed + 1));
  const sc::MatX u = qu.householderQ(), v = qv.householderQ();
  return u * s.asDiagonal() * v.transpose();
}

double relative_residual(const sc::MatX& a, const sc::VecX& x, const sc::VecX& b) {
  return (b - a * x).norm() / b.norm();
}

}  // namespace

TEST(Gmres, SolvesSpdSystemLikeDenseCholesky) {
  const Eigen::Index n = 60;
  const sc::MatX r = test_support::random_matrix(n, 3);
  const sc::MatX a = r * r.transpose() + n * sc::MatX::Identity(n, n);
  const sc::VecX b = random_vector(n, 4);
  const sc::VecX exact = a.llt().solve(b);
  const auto result = sc::gmres([&](const sc::VecX& v) { return sc::VecX(a * v); }, b, {1e-12, 200, 30});
  ASSERT_TRUE(result.converged);
  EXPECT_LE(result.relative_residual, 1e-12);
  EXPECT_LE(relative_residual(a, result.x, b), 1e-12);
  EXPECT_LT((result.x - exact).norm() / exact.norm(), 1e-11);
  EXPECT_LE(result.iterations, 60);
}

TEST(Gmres, SolvesNonSymmetricSystemLikeDenseLu) {
  const Eigen::Index n = 80;
  const sc::MatX a = 3.0 * std::sqrt(static_cast<double>(n)) * sc::MatX::Identity(n, n) + test_support::random_matrix(n, 5);
  const sc::VecX b = random_vector(n, 6);
  const sc::VecX exact = a.partialPivLu().solve(b);
  const auto result = sc::gmres([&](const sc::VecX& v) { return sc::VecX(a * v); }, b, {1e-11, 400, 20});
  ASSERT_TRUE(result.converged) << result.relative_residual;
  EXPECT_LE(relative_residual(a, result.x, b), 1e-11);
  EXPECT_LT((result.x - exact).norm() / exact.norm(), 1e-10);
}

TEST(Gmres, RightPreconditionerCutsIterationsAndKeepsTrueResidual) {
  // Badly scaled columns: right Jacobi (the inverse diagonal) undoes the scaling.
  const Eigen::Index n = 100;
  sc::VecX d(n);
  for (Eigen::Index i = 0; i < n; ++i) d(i) = std::pow(10.0, 4.0 * static_cast<double>(i) / (n - 1));
  const sc::MatX a = (sc::MatX::Identity(n, n) + 0.3 / std::sqrt(n) * test_support::random_matrix(n, 7)) * d.asDiagonal();
  const sc::VecX b = random_vector(n, 8);
  const sc::VecX exact = a.partialPivLu().solve(b);
  const sc::VecX inv_diag = a.diagonal().cwiseInverse();
  const auto op = [&](const sc::VecX& v) { return sc::VecX(a * v); };
  const sc::GmresOptions options{1e-10, 1000, 40};
  const auto plain = sc::gmres(op, b, options);
  const auto jacobi = sc::gmres(op, b, [&](const sc::VecX& v) { return sc::VecX(inv_diag.cwiseProduct(v)); }, options);
  ASSERT_TRUE(jacobi.converged);
  EXPECT_LT(jacobi.iterations, plain.iterations / 3) << plain.iterations;
  // Right preconditioning: the reported residual is that of the original system.
  EXPECT_NEAR(jacobi.relative_residual, relative_residual(a, jacobi.x, b), 1e-14);
  EXPECT_LE(jacobi.relative_residual, 1e-10);
  EXPECT_LT((jacobi.x - exact).norm() / exact.norm(), 1e-8);
}

TEST(Gmres, IllConditionedSystemReachesTheToleranceAndTheForwardErrorBound) {
  // cond(A) = 1e10: GMRES must still drive the true residual below the tolerance, and the
  // forward error then obeys |x - x*| / |x*| <= cond * residual.
  const Eigen::Index n = 50;
  sc::VecX s(n);
  for (Eigen::Index i = 0; i < n; ++i) s(i) = std::pow(10.0, -10.0 * static_cast<double>(i) / (n - 1));
  const sc::MatX a = with_singular_values(s, 9);
  const sc::VecX x_true = random_vector(n, 10);
  const sc::VecX b = a * x_true;
  const auto result = sc::gmres([&](const sc::VecX& v) { return sc::VecX(a * v); }, b, {1e-9, 500, 50});
  ASSERT_TRUE(result.converged) << result.relative_residual;
  EXPECT_LE(relative_residual(a, result.x, b), 1e-9);
  const sc::VecX dense = a.partialPivLu().solve(b);
  const double cond = 1e10;
  EXPECT_LE((result.x - dense).norm() / dense.norm(), cond * 2e-9);
}

TEST(Gmres, RestartingStillConvergesOnAnSpdSystem) {
  const Eigen::Index n = 120;
  sc::VecX s(n);
  for (Eigen::Index i = 0; i < n; ++i) s(i) = 1.0 + 99.0 * static_cast<double>(i) / (n - 1);
  const Eigen::HouseholderQR<sc::MatX> q(test_support::random_matrix(n, 11));
  const sc::MatX u = q.householderQ();
  const sc::MatX a = u * s.asDiagonal() * u.transpose();
  const sc::VecX b = random_vector(n, 12);
  const auto result = sc::gmres([&](const sc::VecX& v) { return sc::VecX(a * v); }, b, {1e-10, 2000, 5});
  ASSERT_TRUE(result.converged);
  EXPECT_GT(result.iterations, 5);  // needed several cycles
  EXPECT_LE(relative_residual(a, result.x, b), 1e-10);
}

TEST(Gmres, StagnationIsReportedNotHidden) {
  // The cyclic shift: GMRES makes no progress before the n-th step (Nachtigal, Reddy &
  // Trefethen 1992), so GMRES(restart < n) stagnates at residual 1.
  const Eigen::Index n = 20;
  sc::MatX shift = sc::MatX::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) shift((i + 1) % n, i) = 1.0;
  const sc::VecX b = sc::VecX::Unit(n, 0);
  const auto op = [&](const sc::VecX& v) { return sc::VecX(shift * v); };
  const auto stuck = sc::gmres(op, b, {1e-10, 500, 10});
  EXPECT_FALSE(stuck.converged);
  EXPECT_NEAR(stuck.relative_residual, 1.0, 1e-12);
  EXPECT_LE(stuck.iterations, 500);
  const auto full = sc::gmres(op, b, {1e-10, 500, 20});  // one full cycle solves it
  EXPECT_TRUE(full.converged);
  EXPECT_LE(relative_residual(shift, full.x, b), 1e-10);
}

// Singular A, b with a part outside its range: no x solves it. GMRES must report that and
// never return an iterate worse than its start (a tiny pivot on the near-null direction
// would otherwise blow the update up).
TEST(Gmres, InconsistentSingularSystemNeverEndsWorseThanItStarts) {
  // A full Krylov space (restart >= n) reaches the null direction: where the old update
  // rule went wrong (true residuals up to 100 times the start's).
  for (unsigned seed = 1; seed <= 30; ++seed) {
    sc::VecX s = sc::VecX::LinSpaced(12, 1.0, 3.0);
    s(0) = 0.0;
    s(1) = seed % 3 == 0 ? 0.0 : (seed % 3 == 1 ? 1e-12 : 1e-9);  // numerically singular too
    const sc::MatX a = with_singular_values(s, 100 + seed);
    const sc::VecX b = random_vector(12, 200 + seed);
    const auto op = [&](const sc::VecX& v) { return sc::VecX(a * v); };
    const auto r = sc::gmres(op, b, {1e-12, 200, 12});
    EXPECT_FALSE(r.converged) << "seed " << seed;
    EXPECT_LE(r.relative_residual, 1.0) << "seed " << seed;
    EXPECT_NEAR(r.relative_residual, relative_residual(a, r.x, b), 1e-12) << "seed " << seed;
  }
}

TEST(Gmres, IterationLimitIsHonoured) {
  const Eigen::Index n = 100;
  sc::VecX s(n);
  for (Eigen::Index i = 0; i < n; ++i) s(i) = 1.0 + static_cast<double>(i * i);
  const sc::MatX a = s.asDiagonal();
  const sc::VecX b = sc::VecX::Ones(n);
  const auto result = sc::gmres([&](const sc::VecX& v) { return sc::VecX(a * v); }, b, {1e-14, 7, 50});
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.iterations, 7);
  EXPECT_NEAR(result.relative_residual, relative_residual(a, result.x, b), 1e-14);
  const auto none = sc::gmres([&](const sc::VecX& v) { return sc::VecX(a * v); }, b, {1e-14, 0, 50});
  EXPECT_EQ(none.iterations, 0);
  EXPECT_FALSE(none.converged);
  EXPECT_EQ(none.x, sc::VecX::Zero(n));
}

TEST(Gmres, ExactInitialGuessAndZeroRightHandSide) {
  const Eigen::Index n = 10;
  const sc::MatX a = sc::MatX::Identity(n, n) + 0.1 * test_support::random_matrix(n, 13);
  const auto op = [&](const sc::VecX& v) { return sc::VecX(a * v); };
  const sc::VecX x = random_vector(n, 14);
  const sc::VecX b = a * x;
  const auto warm = sc::gmres(op, b, sc::IdentityPreconditioner{}, {1e-10, 100, 10}, &x);
  EXPECT_TRUE(warm.converged);
  EXPECT_EQ(warm.iterations, 0);
  EXPECT_EQ(warm.operator_applications, 1);  // the check of the initial residual
  const sc::VecX x0 = random_vector(n, 15);
  const auto zero = sc::gmres(op, sc::VecX::Zero(n), sc::IdentityPreconditioner{}, {}, &x0);
  EXPECT_TRUE(zero.converged);
  EXPECT_EQ(zero.x, sc::VecX::Zero(n));
  EXPECT_EQ(zero.relative_residual, 0.0);
}

TEST(Gmres, HappyBreakdownOnALowDimensionalKrylovSpace) {
  // b lies in a 3-dimensional invariant subspace: three steps give the exact solution.
  const Eigen::Index n = 30;
  sc::VecX d = sc::VecX::Ones(n);
  d.head(3) << 2.0, 3.0, 5.0;
  const sc::MatX a = d.asDiagonal();
  sc::VecX b = sc::VecX::Zero(n);
  b.head(3) << 1.0, 1.0, 1.0;
  const auto result = sc::gmres([&](const sc::VecX& v) { return sc::VecX(a * v); }, b, {1e-14, 100, 50});
  EXPECT_TRUE(result.converged);
  EXPECT_EQ(result.iterations, 3);
  EXPECT_NEAR(result.x(2), 0.2, 1e-15);
}

TEST(Gmres, RejectsBadInput) {
  const sc::MatX a = sc::MatX::Identity(4, 4);
  const auto op = [&](const sc::VecX& v) { return sc::VecX(a * v); };
  const sc::VecX b = sc::VecX::Ones(4);
  EXPECT_THROW(sc::gmres(op, b, {0.0, 10, 5}), std::invalid_argument);
  EXPECT_THROW(sc::gmres(op, b, {-1e-8, 10, 5}), std::invalid_argument);
  EXPECT_THROW(sc::gmres(op, b, {1e-8, -1, 5}), std::invalid_argument);
  EXPECT_THROW(sc::gmres(op, b, {1e-8, 10, 0}), std::invalid_argument);
  sc::VecX bad = b;
  bad(2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(sc::gmres(op, bad), std::invalid_argument);
  const sc::VecX short_x0 = sc::VecX::Zero(3);
  EXPECT_THROW(sc::gmres(op, b, sc::IdentityPreconditioner{}, {}, &short_x0), std::invalid_argument);
  EXPECT_THROW(sc::gmres(op, b, sc::IdentityPreconditioner{}, {}, &bad), std::invalid_argument);
  const auto wrong_size = [](const sc::VecX&) { return sc::VecX(sc::VecX::Ones(3)); };
  EXPECT_THROW(sc::gmres(wrong_size, b), std::invalid_argument);
  const auto blows_up = [](const sc::VecX& v) { return sc::VecX(v / 0.0); };
  EXPECT_THROW(sc::gmres(blows_up, b), std::invalid_argument);
  EXPECT_THROW(sc::gmres(op, b, blows_up), std::invalid_argument);
  try {
    sc::gmres(op, b, {1e-8, 10, 0});
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("GmresOptions.restart"), std::string::npos) << e.what();
  }
}

}  // namespace gmres_tests
