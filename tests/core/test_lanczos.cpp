#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "common/test_support.hpp"
#include "stokescontact/core/lanczos.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace lanczos_tests {

namespace sc = stokescontact;

namespace {

using test_support::expect_rejects;

// A = Q diag(lambda) Q^T and, independently of any eigensolver, A^(1/2) = Q diag(sqrt lambda) Q^T.
struct KnownSpectrum {
  sc::MatX a, sqrt_a;
};

KnownSpectrum with_eigenvalues(const sc::VecX& lambda, unsigned seed) {
  const Eigen::HouseholderQR<sc::MatX> qr(test_support::random_matrix(lambda.size(), seed));
  const sc::MatX q = qr.householderQ();
  return {q * lambda.asDiagonal() * q.transpose(), q * lambda.cwiseSqrt().asDiagonal() * q.transpose()};
}

// Eigenvalues spread log-uniformly over [1, condition].
sc::VecX log_spaced(Eigen::Index n, double condition) {
  sc::VecX lambda(n);
  for (Eigen::Index i = 0; i < n; ++i)
    lambda(i) = std::pow(condition, static_cast<double>(i) / static_cast<double>(n - 1));
  return lambda;
}

// The operator as Lanczos sees it, counting its applications.
struct CountingOperator {
  const sc::MatX* a;
  int* applications;
  sc::VecX operator()(const sc::VecX& v) const {
    ++*applications;
    return *a * v;
  }
};

}  // namespace

// The tolerance bounds the change between successive iterates, not the error: with the error
// shrinking by a factor rho per step, error ~ change rho / (1 - rho). Here (condition 100)
// rho ~ 0.65, so the error is about twice the change; three times the tolerance bounds it.
TEST(LanczosSqrt, MatchesSquareRootOfKnownSpectrumToTolerance) {
  const Eigen::Index n = 80;
  const KnownSpectrum m = with_eigenvalues(log_spaced(n, 100.0), 11);
  const sc::VecX b = test_support::random_matrix(n, 12).col(0);
  const sc::VecX exact = m.sqrt_a * b;
  for (const double tolerance : {1e-4, 1e-8, 1e-12}) {
    int applications = 0;
    const auto result = sc::lanczos_sqrt(CountingOperator{&m.a, &applications}, b, {tolerance, 200});
    SCOPED_TRACE(tolerance);
    ASSERT_TRUE(result.converged());
    EXPECT_LE(result.relative_change, tolerance);
    EXPECT_EQ(result.iterations, applications);  // one application per step, nothing else
    EXPECT_LE((result.value - exact).norm() / exact.norm(), 3.0 * tolerance);
    EXPECT_LT(result.iterations, n);  // converged well before the Krylov space is full
  }
}

TEST(LanczosSqrt, TighterToleranceTakesMoreSteps) {
  const Eigen::Index n = 60;
  const KnownSpectrum m = with_eigenvalues(log_spaced(n, 1e3), 13);
  const sc::VecX b = test_support::random_matrix(n, 14).col(0);
  const auto op = [&](const sc::VecX& v) { return sc::VecX(m.a * v); };
  const auto loose = sc::lanczos_sqrt(op, b, {1e-3, 200});
  const auto tight = sc::lanczos_sqrt(op, b, {1e-10, 200});
  ASSERT_TRUE(loose.converged() && tight.converged());
  EXPECT_LT(loose.iterations, tight.iterations);
}

TEST(LanczosSqrt, EigenvectorStartIsExactAfterOneStep) {
  const Eigen::Index n = 20;
  sc::VecX lambda = log_spaced(n, 50.0);
  const Eigen::HouseholderQR<sc::MatX> qr(test_support::random_matrix(n, 15));
  const sc::MatX q = qr.householderQ();
  const sc::MatX a = q * lambda.asDiagonal() * q.transpose();
  const sc::VecX b = 3.0 * q.col(7);  // A b = lambda_7 b: the Krylov space is span(b)
  const auto result = sc::lanczos_sqrt([&](const sc::VecX& v) { return sc::VecX(a * v); }, b);
  ASSERT_TRUE(result.converged());
  EXPECT_EQ(result.iterations, 1);
  EXPECT_LT((result.value - std::sqrt(lambda(7)) * b).norm(), 1e-12 * b.norm());
}

TEST(LanczosSqrt, FullKrylovSpaceIsExact) {
  // Tolerance below rounding: the run ends when the space is all of R^n, y_n = A^(1/2) b.
  const Eigen::Index n = 6;
  const KnownSpectrum m = with_eigenvalues(log_spaced(n, 10.0), 16);
  const sc::VecX b = test_support::random_matrix(n, 17).col(0);
  const auto result = sc::lanczos_sqrt([&](const sc::VecX& v) { return sc::VecX(m.a * v); }, b, {1e-300, 50});
  ASSERT_TRUE(result.converged());
  EXPECT_LE(result.iterations, n);
  EXPECT_LT((result.value - m.sqrt_a * b).norm(), 1e-12 * b.norm());
}

TEST(LanczosSqrt, ZeroVectorCostsNothing) {
  int applications = 0;
  const sc::MatX a = sc::MatX::Identity(4, 4);
  const auto result = sc::lanczos_sqrt(CountingOperator{&a, &applications}, sc::VecX::Zero(4));
  EXPECT_TRUE(result.converged());
  EXPECT_EQ(result.iterations, 0);
  EXPECT_EQ(applications, 0);
  EXPECT_EQ(result.value, sc::VecX::Zero(4));
}

TEST(LanczosSqrt, ReportsMaxIterationsWithTheLastIterate) {
  const Eigen::Index n = 60;
  const KnownSpectrum m = with_eigenvalues(log_spaced(n, 1e4), 18);
  const sc::VecX b = test_support::random_matrix(n, 19).col(0);
  int applications = 0;
  const auto result = sc::lanczos_sqrt(CountingOperator{&m.a, &applications}, b, {1e-12, 3});
  EXPECT_EQ(result.status, sc::LanczosStatus::max_iterations);
  EXPECT_FALSE(result.converged());
  EXPECT_EQ(result.iterations, 3);
  EXPECT_EQ(applications, 3);
  EXPECT_GT(result.relative_change, 1e-12);
  // A rough but honest approximation: within tens of percent after three steps.
  const sc::VecX exact = m.sqrt_a * b;
  EXPECT_LT((result.value - exact).norm() / exact.norm(), 0.5);
}

TEST(LanczosSqrt, ReportsAnIndefiniteOperator) {
  sc::VecX d(5);
  d << 1.0, 2.0, -3.0, 4.0, 5.0;
  const sc::MatX a = d.asDiagonal();
  const auto result = sc::lanczos_sqrt([&](const sc::VecX& v) { return sc::VecX(a * v); }, sc::VecX::Ones(5),
                                       {1e-12, 10});
  EXPECT_EQ(result.status, sc::LanczosStatus::not_positive_definite);
  EXPECT_TRUE(result.value.allFinite());
}

TEST(LanczosSqrt, RejectsBadInput) {
  const sc::MatX a = sc::MatX::Identity(3, 3);
  const auto op = [&](const sc::VecX& v) { return sc::VecX(a * v); };
  const sc::VecX b = sc::VecX::Ones(3);
  expect_rejects([&] { sc::lanczos_sqrt(op, b, {0.0, 10}); }, "LanczosOptions.tolerance");
  expect_rejects([&] { sc::lanczos_sqrt(op, b, {std::numeric_limits<double>::quiet_NaN(), 10}); },
                 "LanczosOptions.tolerance");
  expect_rejects([&] { sc::lanczos_sqrt(op, b, {1e-6, 0}); }, "LanczosOptions.max_iterations");
  sc::VecX bad = b;
  bad(1) = std::numeric_limits<double>::infinity();
  expect_rejects([&] { sc::lanczos_sqrt(op, bad); }, "b");
  expect_rejects([&] { sc::lanczos_sqrt([](const sc::VecX&) { return sc::VecX::Ones(2); }, b); }, "operator");
  expect_rejects(
      [&] {
        sc::lanczos_sqrt([](const sc::VecX& v) { return sc::VecX(v * std::numeric_limits<double>::quiet_NaN()); }, b);
      },
      "operator");
}

}  // namespace lanczos_tests
