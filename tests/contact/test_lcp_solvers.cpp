#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Sparse>

#include "stokescontact/lcp/lcp.hpp"
#include "stokescontact/lcp/apgd.hpp"
#include "stokescontact/lcp/bbpgd.hpp"
#include "stokescontact/lcp/minimum_map_newton.hpp"
#include "stokescontact/lcp/model_started_newton.hpp"
#include "stokescontact/contact/solvers/defect_correction.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace lcp_solvers_tests {

namespace sc = stokescontact;

namespace {

using SparseMat = Eigen::SparseMatrix<double>;

enum class Solver { kBbpgd, kApgd, kMinimumMapNewton };

std::string solver_name(Solver s) {
  switch (s) {
    case Solver::kBbpgd: return "Bbpgd";
    case Solver::kApgd: return "Apgd";
    case Solver::kMinimumMapNewton: return "MinimumMapNewton";
  }
  return "?";
}

template <typename ApplyA>
sc::LcpResult run_solver(Solver s, ApplyA&& A, const sc::VecX& b, const sc::LcpOptions& options,
                         const sc::VecX* warm_start = nullptr) {
  switch (s) {
    case Solver::kBbpgd: return sc::solve_lcp_bbpgd(A, b, options, warm_start);
    case Solver::kApgd: return sc::solve_lcp_apgd(A, b, options, warm_start);
    case Solver::kMinimumMapNewton: return sc::solve_lcp_minimum_map_newton(A, b, options, warm_start);
  }
  throw std::logic_error("unknown solver");
}

// A as a callable that counts its own calls, to check the solvers' accounting.
template <typename Matrix>
struct CountingOperator {
  const Matrix& A;
  std::size_t calls = 0;
  sc::VecX operator()(const sc::VecX& x) {
    ++calls;
    return A * x;
  }
};

sc::MatX random_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  sc::MatX m(rows, cols);
  for (Eigen::Index j = 0; j < cols; ++j)
    for (Eigen::Index i = 0; i < rows; ++i) m(i, j) = g(rng);
  return m;
}

sc::VecX random_vector(Eigen::Index n, std::mt19937_64& rng) { return random_matrix(n, 1, rng).col(0); }

// Symmetric positive definite with eigenvalues log-spaced in [1, cond], random eigenvectors.
sc::MatX random_spd(Eigen::Index n, double cond, std::mt19937_64& rng) {
  const Eigen::HouseholderQR<sc::MatX> qr(random_matrix(n, n, rng));
  const sc::MatX q = qr.householderQ();
  sc::VecX eig(n);
  for (Eigen::Index i = 0; i < n; ++i)
    eig(i) = n == 1 ? 1.0 : std::pow(cond, static_cast<double>(i) / static_cast<double>(n - 1));
  return q * eig.asDiagonal() * q.transpose();
}

// The exact solution by enumeration (independent of the solvers): for each of the 2^n sets S
// of positive gamma, solve A_SS gamma_S = -b_S and keep the candidate with the smallest
// violation of gamma >= 0, w >= 0. Unique for A SPD.
struct ExactLcp {
  sc::VecX gamma, w;
  double violation = std::numeric_limits<double>::infinity();
};

ExactLcp enumerate_lcp(const sc::MatX& A, const sc::VecX& b) {
  const Eigen::Index n = b.size();
  ExactLcp best;
  for (unsigned mask = 0; mask < (1u << n); ++mask) {
    std::vector<Eigen::Index> s;
    for (Eigen::Index i = 0; i < n; ++i)
      if (mask & (1u << i)) s.push_back(i);
    const auto m = static_cast<Eigen::Index>(s.size());
    sc::MatX Ass(m, m);
    sc::VecX bs(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      bs(i) = b(s[i]);
      for (Eigen::Index j = 0; j < m; ++j) Ass(i, j) = A(s[i], s[j]);
    }
    sc::VecX gamma = sc::VecX::Zero(n);
    if (m > 0) {
      const sc::VecX gs = Ass.ldlt().solve(-bs);
      for (Eigen::Index i = 0; i < m; ++i) gamma(s[i]) = gs(i);
    }
    const sc::VecX w = A * gamma + b;
    const double violation = std::max(-gamma.minCoeff(), -w.minCoeff());
    if (violation < best.violation) best = {gamma, w, violation};
  }
  return best;
}

// What every result must satisfy: gamma >= 0, w = A gamma + b, the residual it reports is the
// one recomputed here, converged agrees with the tolerance, and the applications it reports are
// the calls the operator saw.
void expect_honest(const sc::LcpResult& r, const sc::MatX& A, const sc::VecX& b, const sc::LcpOptions& options,
                   std::size_t calls) {
  ASSERT_EQ(r.gamma.size(), b.size());
  ASSERT_EQ(r.w.size(), b.size());
  if (b.size() == 0) return;
  EXPECT_GE(r.gamma.minCoeff(), 0.0);
  const sc::VecX w = A * r.gamma + b;
  const double scale = b.cwiseAbs().maxCoeff();
  EXPECT_LE((r.w - w).cwiseAbs().maxCoeff(), 1e-12 * std::max(scale, (A * r.gamma).cwiseAbs().maxCoeff()));
  const double residual = scale == 0.0 ? 0.0 : sc::lcp_residual(r.gamma, w) / scale;
  EXPECT_NEAR(r.residual, residual, 1e-12 + 1e-6 * residual);
  EXPECT_EQ(r.converged, r.residual <= options.tolerance);
  EXPECT_EQ(r.operator_applications, calls);
}

class LcpSolverTest : public testing::TestWithParam<Solver> {
 protected:
  // Solves with A behind a counting callable and checks the result is honest.
  sc::LcpResult solve(const sc::MatX& A, const sc::VecX& b, const sc::LcpOptions& options = {},
                      const sc::VecX* warm_start = nullptr) {
    CountingOperator<sc::MatX> op{A};
    sc::LcpResult r = run_solver(GetParam(), op, b, options, warm_start);
    expect_honest(r, A, b, options, op.calls);
    return r;
  }
};

// gamma and w against the exact solution, relative to the solution's scale.
void expect_matches(const sc::LcpResult& r, const ExactLcp& exact, double tol) {
  const double g_scale = std::max(1.0, exact.gamma.cwiseAbs().maxCoeff());
  const double w_scale = std::max(1.0, exact.w.cwiseAbs().maxCoeff());
  EXPECT_LE((r.gamma - exact.gamma).cwiseAbs().maxCoeff(), tol * g_scale) << "gamma " << r.gamma.transpose()
                                                                           << "\nexact " << exact.gamma.transpose();
  EXPECT_LE((r.w - exact.w).cwiseAbs().maxCoeff(), tol * w_scale) << "w " << r.w.transpose() << "\nexact "
                                                                   << exact.w.transpose();
}

// b with a known solution: gamma* > 0 on `contact`, w* > 0 elsewhere, b = w* - A gamma*;
// indices in `degenerate` get gamma* = w* = 0.
sc::VecX b_with_solution(const sc::MatX& A, std::mt19937_64& rng, double contact_fraction,
                         const std::set<Eigen::Index>& degenerate, sc::VecX& gamma, sc::VecX& w) {
  const Eigen::Index n = A.rows();
  std::uniform_real_distribution<double> u(0.0, 1.0);
  gamma = sc::VecX::Zero(n);
  w = sc::VecX::Zero(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (degenerate.contains(i)) continue;
    (u(rng) < contact_fraction ? gamma(i) : w(i)) = 0.5 + u(rng);
  }
  return w - A * gamma;
}

}  // namespace

TEST(LcpResidual, IsTheMaxNormOfTheMinimumMap) {
  sc::VecX gamma(3), w(3);
  gamma << 1.0, 0.0, 3.0;
  w << 0.0, -2.0, 1.5;
  EXPECT_DOUBLE_EQ(sc::lcp_residual(gamma, w), 2.0);  // min = (0, -2, 1.5)
  EXPECT_EQ(sc::lcp_residual(sc::VecX(), sc::VecX()), 0.0);
  EXPECT_THROW(sc::lcp_residual(gamma, sc::VecX(2)), std::invalid_argument);
}

TEST_P(LcpSolverTest, AgreesWithEnumerationOnRandomSmallProblems) {
  const sc::LcpOptions options{.tolerance = 1e-10};
  for (unsigned seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    const Eigen::Index n = 1 + static_cast<Eigen::Index>(seed % 10);
    const sc::MatX A = random_spd(n, 100.0, rng);
    const sc::VecX b = random_vector(n, rng);
    const ExactLcp exact = enumerate_lcp(A, b);
    ASSERT_LE(exact.violation, 1e-12);
    const sc::LcpResult r = solve(A, b, options);
    ASSERT_TRUE(r.converged) << r.residual;
    expect_matches(r, exact, 1e-7);
  }
}

TEST_P(LcpSolverTest, OneContactMatchesTheClosedForm) {
  const sc::MatX A = sc::MatX::Constant(1, 1, 2.5);
  for (const double b0 : {-3.0, -1e-9, 0.0, 4.0, 1e12}) {
    SCOPED_TRACE("b = " + std::to_string(b0));
    const sc::VecX b = sc::VecX::Constant(1, b0);
    const sc::LcpResult r = solve(A, b);
    ASSERT_TRUE(r.converged);
    EXPECT_NEAR(r.gamma(0), std::max(0.0, -b0 / 2.5), 1e-12 * std::abs(b0));  // gamma = max(0, -b/a)
  }
}

// A = D^T D with more contacts (8) than degrees of freedom (4): gamma is not unique, w is.
TEST_P(LcpSolverTest, RankDeficientAGivesTheUniqueW) {
  // Seed 4's active block is nearly singular: BBPGD needs ~5e4 steps there, APGD ~1e3.
  const sc::LcpOptions options{.tolerance = 1e-10, .max_iterations = 100000};
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    const sc::MatX D = random_matrix(4, 8, rng);
    const sc::MatX A = D.transpose() * D;
    sc::VecX gamma_star, w_star;
    const sc::VecX b = b_with_solution(A, rng, 0.5, {}, gamma_star, w_star);
    const sc::LcpResult r = solve(A, b, options);
    std::printf("  [%s] rank 4, Nc 8, seed %u: %d iterations, %zu applications\n", solver_name(GetParam()).c_str(),
                seed, r.iterations, r.operator_applications);
    ASSERT_TRUE(r.converged) << r.residual;
    const double scale = b.cwiseAbs().maxCoeff();
    EXPECT_LE((r.w - w_star).cwiseAbs().maxCoeff(), 1e-7 * scale) << r.w.transpose() << "\n" << w_star.transpose();
    EXPECT_LE(std::abs(r.gamma.dot(r.w)), 1e-7 * scale * std::max(1.0, r.gamma.cwiseAbs().maxCoeff()));
  }
}

// cond(A) = 1e8 (eigenvalues in [1e-8, 1]). Every solver either converges, with w close to w*
// and gamma within about cond(A) times the tolerance of gamma*, or says it did not (the
// assertions in expect_honest): never a wrong answer reported as right. Newton must converge.
TEST_P(LcpSolverTest, IllConditionedAIsSolvedOrReportedUnconverged) {
  const double cond = 1e8;
  const sc::LcpOptions options{.tolerance = 1e-8, .max_iterations = 20000};
  for (unsigned seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(100 + seed);
    const sc::MatX A = random_spd(8, cond, rng) / cond;
    sc::VecX gamma_star, w_star;
    const sc::VecX b = b_with_solution(A, rng, 0.5, {}, gamma_star, w_star);
    const sc::LcpResult r = solve(A, b, options);
    std::printf("  [%s] cond 1e8 seed %u: converged %d, %d iterations, %zu applications, residual %.2e\n",
                solver_name(GetParam()).c_str(), seed, r.converged, r.iterations, r.operator_applications,
                r.residual);
    if (GetParam() == Solver::kMinimumMapNewton) {
      ASSERT_TRUE(r.converged) << r.residual;
    }
    if (r.converged) {
      EXPECT_LE((r.w - w_star).cwiseAbs().maxCoeff(), 1e-6 * std::max(1.0, w_star.cwiseAbs().maxCoeff()));
      EXPECT_LE((r.gamma - gamma_star).cwiseAbs().maxCoeff(),
                cond * options.tolerance * std::max(1.0, gamma_star.cwiseAbs().maxCoeff()));
    } else {
      EXPECT_GT(r.residual, options.tolerance);
    }
  }
}

// b_i = 0 with gamma*_i = w*_i = 0: the strictly complementary part is absent at those pairs.
TEST_P(LcpSolverTest, DegenerateComplementarityIsSolved) {
  const sc::LcpOptions options{.tolerance = 1e-10};
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(200 + seed);
    const sc::MatX A = random_spd(9, 50.0, rng);
    sc::VecX gamma_star, w_star;
    const sc::VecX b = b_with_solution(A, rng, 0.5, {0, 3, 7}, gamma_star, w_star);
    const sc::LcpResult r = solve(A, b, options);
    ASSERT_TRUE(r.converged) << r.residual;
    expect_matches(r, {gamma_star, w_star, 0.0}, 1e-7);
  }
  // The smallest case: b = (0, -1) with a coupling that makes pair 0 exactly degenerate.
  sc::MatX A(2, 2);
  A << 2.0, 1.0, 1.0, 1.0;
  const sc::VecX b = (sc::VecX(2) << 1.0, -1.0).finished();  // gamma* = (0, 1), w* = (0, 0)
  const sc::LcpResult r = solve(A, b, options);
  ASSERT_TRUE(r.converged);
  EXPECT_NEAR(r.gamma(0), 0.0, 1e-9);
  EXPECT_NEAR(r.gamma(1), 1.0, 1e-9);
}

// b >= 0: gamma = 0 is the solution and w0 = b comes free from the cold start, so every solver
// returns after 0 iterations and 0 applications.
TEST_P(LcpSolverTest, AllConstraintsInactiveCostNothing) {
  std::mt19937_64 rng(7);
  const sc::MatX A = random_spd(6, 10.0, rng);
  const sc::VecX b = (sc::VecX(6) << 0.5, 0.0, 2.0, 1e-3, 7.0, 0.0).finished();
  const sc::LcpResult r = solve(A, b);
  ASSERT_TRUE(r.converged);
  EXPECT_TRUE(r.gamma.isZero(0.0));
  EXPECT_EQ(r.iterations, 0);
  EXPECT_EQ(r.operator_applications, 0u);
}

// From its own solution (one application for w0) or from the exact one, 0 or 1 steps.
TEST_P(LcpSolverTest, WarmStartFromTheSolutionConvergesAtOnce) {
  const sc::LcpOptions options{.tolerance = 1e-9};
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(300 + seed);
    const sc::MatX A = random_spd(10, 100.0, rng);
    const sc::VecX b = random_vector(10, rng);
    const sc::LcpResult cold = solve(A, b, options);
    ASSERT_TRUE(cold.converged);
    const sc::LcpResult warm = solve(A, b, options, &cold.gamma);
    ASSERT_TRUE(warm.converged);
    EXPECT_EQ(warm.iterations, 0);
    EXPECT_EQ(warm.operator_applications, 1u);  // w0 = A gamma0 + b
    const ExactLcp exact = enumerate_lcp(A, b);
    const sc::LcpResult from_exact = solve(A, b, options, &exact.gamma);
    ASSERT_TRUE(from_exact.converged);
    EXPECT_LE(from_exact.iterations, 1);
  }
}

// A given as a dense or sparse matrix: same answer as the callable, products still counted.
TEST_P(LcpSolverTest, AcceptsDenseAndSparseMatrices) {
  std::mt19937_64 rng(11);
  const sc::MatX A = random_spd(7, 20.0, rng);
  const sc::VecX b = random_vector(7, rng);
  const sc::LcpResult callable = solve(A, b);
  const sc::LcpResult dense = run_solver(GetParam(), A, b, {});
  const SparseMat sparse = A.sparseView();
  const sc::LcpResult from_sparse = run_solver(GetParam(), sparse, b, {});
  EXPECT_EQ(dense.operator_applications, callable.operator_applications);
  EXPECT_EQ(from_sparse.operator_applications, callable.operator_applications);
  EXPECT_LE((dense.gamma - callable.gamma).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LE((from_sparse.gamma - callable.gamma).cwiseAbs().maxCoeff(), 1e-10);
}

// Stopped early, a solver says it did not converge, with the residual it reached.
TEST_P(LcpSolverTest, NonConvergenceIsReportedWithItsResidual) {
  std::mt19937_64 rng(13);
  const sc::MatX A = random_spd(10, 1e4, rng);
  sc::VecX gamma_star, w_star;
  const sc::VecX b = b_with_solution(A, rng, 0.6, {}, gamma_star, w_star);
  const sc::LcpOptions options{.tolerance = 1e-12, .max_iterations = 1};
  const sc::LcpResult r = solve(A, b, options);
  EXPECT_FALSE(r.converged);
  EXPECT_GT(r.residual, options.tolerance);
  EXPECT_EQ(r.iterations, 1);
}

// PSD A with no solution: A = [1 -1; -1 1], b = (-1, -1) gives w_1 + w_2 = -2 for every gamma;
// A = 0 with b_0 < 0; A = diag(1, 0) with b_2 < 0. Every solver stops within its budget and
// says it did not converge.
TEST_P(LcpSolverTest, InfeasibleProblemIsReportedUnconverged) {
  sc::MatX A(2, 2);
  A << 1.0, -1.0, -1.0, 1.0;
  const sc::VecX b = -sc::VecX::Ones(2);
  const sc::LcpOptions options{.max_iterations = 200};
  const sc::LcpResult r = solve(A, b, options);
  EXPECT_FALSE(r.converged);
  EXPECT_GE(r.residual, 1.0 - 1e-12);  // some w_i <= -1, so |min(gamma, w)|_inf >= 1
  const sc::LcpResult zero = solve(sc::MatX::Zero(3, 3), (sc::VecX(3) << -1.0, 2.0, 0.0).finished(), options);
  EXPECT_FALSE(zero.converged);
  EXPECT_DOUBLE_EQ(zero.residual, 0.5);
  // p0 = (0, -1) lies in the null space of A = diag(1, 0): the first step size comes from the
  // power-iteration fallback; w_2 = -1 whatever gamma is.
  const sc::MatX singular = (sc::VecX(2) << 1.0, 0.0).finished().asDiagonal();
  const sc::LcpResult null_start = solve(singular, (sc::VecX(2) << 1.0, -1.0).finished(), options);
  EXPECT_FALSE(null_start.converged);
  EXPECT_GE(null_start.residual, 1.0 - 1e-12);
}

// The same kind of problem for minimum-map Newton's stall window: A = [1 -1; -1 1] with
// b = (-1, -2) has no solution (w_1 + w_2 = -3), c = 1/5 > 0 so Newton runs, and its merit
// stops falling. Without the window it takes every one of its 1000 steps; with the default
// window of 50 it stops within the window (plus the step it decides on) at the same residual
// to 1e-9 (0.75).
TEST(LcpSolvers, NewtonStopsWhenItsMeritStopsFalling) {
  sc::MatX A(2, 2);
  A << 1.0, -1.0, -1.0, 1.0;
  const sc::VecX b = (sc::VecX(2) << -1.0, -2.0).finished();
  const sc::LcpOptions without{.stall_window = 0};
  const sc::LcpResult crawled = sc::solve_lcp_minimum_map_newton(A, b, without);
  EXPECT_FALSE(crawled.converged);
  EXPECT_EQ(crawled.iterations, without.max_iterations);
  const sc::LcpOptions with{};
  ASSERT_EQ(with.stall_window, 50);
  const sc::LcpResult stopped = sc::solve_lcp_minimum_map_newton(A, b, with);
  EXPECT_FALSE(stopped.converged);
  EXPECT_LE(stopped.iterations, with.stall_window + 2);
  EXPECT_GE(stopped.iterations, with.stall_window);
  EXPECT_NEAR(stopped.residual, crawled.residual, 1e-6);  // 0.75: the least |min(gamma, w)|_inf
  EXPECT_LT(stopped.operator_applications, crawled.operator_applications / 10);
}

TEST_P(LcpSolverTest, EmptyAndZeroProblemsAreSolvedForFree) {
  const sc::LcpResult empty = solve(sc::MatX(0, 0), sc::VecX());
  EXPECT_TRUE(empty.converged);
  EXPECT_EQ(empty.gamma.size(), 0);
  EXPECT_EQ(empty.operator_applications, 0u);
  // b = 0: gamma = 0, w = 0 solves it whatever A and the warm start are.
  std::mt19937_64 rng(17);
  const sc::MatX A = random_spd(4, 10.0, rng);
  const sc::VecX warm = sc::VecX::Constant(4, 3.0);
  const sc::LcpResult zero = solve(A, sc::VecX::Zero(4), {}, &warm);
  EXPECT_TRUE(zero.converged);
  EXPECT_TRUE(zero.gamma.isZero(0.0));
  EXPECT_EQ(zero.operator_applications, 0u);
}

TEST_P(LcpSolverTest, RejectsBadInputNamingTheField) {
  std::mt19937_64 rng(19);
  const sc::MatX A = random_spd(3, 10.0, rng);
  const sc::VecX b = random_vector(3, rng);
  const auto message = [&](auto&& call) -> std::string {
    try {
      call();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no exception";
  };
  const auto field_of = [&](const sc::VecX& bb, const sc::LcpOptions& o, const sc::VecX* warm) {
    return message([&] { run_solver(GetParam(), A, bb, o, warm); });
  };
  sc::VecX bad_b = b;
  bad_b(1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(field_of(bad_b, {}, nullptr).rfind("b:", 0), 0u);
  bad_b(1) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(field_of(bad_b, {}, nullptr).rfind("b:", 0), 0u);
  EXPECT_EQ(field_of(sc::VecX::Ones(4), {}, nullptr).rfind("A:", 0), 0u);  // 3x3 A, 4 contacts
  const sc::VecX short_warm = sc::VecX::Ones(2);
  EXPECT_EQ(field_of(b, {}, &short_warm).rfind("warm_start:", 0), 0u);
  sc::VecX nan_warm = sc::VecX::Ones(3);
  nan_warm(0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(field_of(b, {}, &nan_warm).rfind("warm_start:", 0), 0u);
  EXPECT_EQ(field_of(b, {.tolerance = 0.0}, nullptr).rfind("LcpOptions.tolerance:", 0), 0u);
  EXPECT_EQ(field_of(b, {.tolerance = -1e-8}, nullptr).rfind("LcpOptions.tolerance:", 0), 0u);
  EXPECT_EQ(field_of(b, {.max_iterations = 0}, nullptr).rfind("LcpOptions.max_iterations:", 0), 0u);
  EXPECT_EQ(field_of(b, {.max_iterations = -3}, nullptr).rfind("LcpOptions.max_iterations:", 0), 0u);
  EXPECT_EQ(field_of(b, {.stall_window = -1}, nullptr).rfind("LcpOptions.stall_window:", 0), 0u);
  // A callable that returns the wrong size or non-finite values.
  const sc::VecX negative_b = -sc::VecX::Ones(3);
  const auto wrong_size = [](const sc::VecX&) { return sc::VecX::Zero(2).eval(); };
  EXPECT_EQ(message([&] { run_solver(GetParam(), wrong_size, negative_b, {}); }).rfind("A:", 0), 0u);
  const auto not_finite = [](const sc::VecX& x) {
    return sc::VecX::Constant(x.size(), std::numeric_limits<double>::quiet_NaN()).eval();
  };
  EXPECT_EQ(message([&] { run_solver(GetParam(), not_finite, negative_b, {}); }).rfind("A:", 0), 0u);
}

INSTANTIATE_TEST_SUITE_P(LcpSolvers, LcpSolverTest,
                         testing::Values(Solver::kBbpgd, Solver::kApgd, Solver::kMinimumMapNewton),
                         [](const testing::TestParamInfo<Solver>& info) { return solver_name(info.param); });

namespace {

// D with 6 dofs per body, bodies on a ring, each contact between body i and one of i+1..i+3
// (distinct pairs), random force and torque entries on both bodies.
SparseMat random_contact_matrix(Eigen::Index bodies, Eigen::Index contacts, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_int_distribution<Eigen::Index> body(0, bodies - 1), offset(1, 3);
  std::set<std::pair<Eigen::Index, Eigen::Index>> pairs;
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index c = 0; c < contacts;) {
    const Eigen::Index i = body(rng), j = (i + offset(rng)) % bodies;
    if (!pairs.insert({std::min(i, j), std::max(i, j)}).second) continue;
    for (const Eigen::Index k : {i, j})
      for (int r = 0; r < 6; ++r) entries.emplace_back(6 * k + r, c, g(rng));
    ++c;
  }
  SparseMat D(6 * bodies, contacts);
  D.setFromTriplets(entries.begin(), entries.end());
  return D;
}

}  // namespace

// Nc = 2000 contacts among 1000 bodies, A = D^T D sparse SPD, b = D^T u + gaps: the three
// solvers agree; their iterations and applications are printed for comparison.
TEST(LcpSolvers, LargeSparseProblemAllThreeAgree) {
  const unsigned seed = 23;
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937_64 rng(seed);
  const SparseMat D = random_contact_matrix(1000, 2000, rng);
  const SparseMat A = SparseMat(D.transpose() * D);
  std::uniform_real_distribution<double> gap(0.0, 2.0);
  sc::VecX b = D.transpose() * random_vector(D.rows(), rng);
  for (Eigen::Index i = 0; i < b.size(); ++i) b(i) += gap(rng);
  const sc::LcpOptions options{.tolerance = 1e-8, .max_iterations = 5000};
  std::vector<sc::LcpResult> results;
  for (const Solver s : {Solver::kBbpgd, Solver::kApgd, Solver::kMinimumMapNewton}) {
    CountingOperator<SparseMat> op{A};
    results.push_back(run_solver(s, op, b, options));
    const sc::LcpResult& r = results.back();
    EXPECT_EQ(r.operator_applications, op.calls);
    EXPECT_TRUE(r.converged) << solver_name(s) << " residual " << r.residual;
    EXPECT_GE(r.gamma.minCoeff(), 0.0);
    std::printf("  Nc 2000 %-16s: %5d iterations %6zu applications, residual %.2e, %ld contacts active\n",
                solver_name(s).c_str(), r.iterations, r.operator_applications, r.residual,
                static_cast<long>((r.gamma.array() > 0.0).count()));
  }
  const double w_scale = b.cwiseAbs().maxCoeff();
  for (std::size_t k = 1; k < results.size(); ++k) {
    EXPECT_LE((results[k].w - results[0].w).cwiseAbs().maxCoeff(), 1e-6 * w_scale);
    EXPECT_LE((results[k].gamma - results[0].gamma).cwiseAbs().maxCoeff(),
              1e-5 * std::max(1.0, results[0].gamma.cwiseAbs().maxCoeff()));
  }
}

// A jammed cluster: 3000 unit spheres on a 30 x 100 square lattice (x, y) touching their
// neighbours, free draining with M = I, every pair pushed together by a force towards the
// lattice's centre line: A = D^T D is the edge Laplacian of the lattice (condition ~1e4, as
// the Delassus matrix of one large connected cluster), b < 0 on most pairs.
struct LatticeCluster {
  SparseMat A;
  sc::VecX b;
  LatticeCluster() {
    constexpr Eigen::Index nx = 30, ny = 100;
    const auto body = [&](Eigen::Index x, Eigen::Index y) { return x + nx * y; };
    std::vector<Eigen::Triplet<double>> entries;
    std::vector<double> push;
    Eigen::Index c = 0;
    for (Eigen::Index y = 0; y < ny; ++y)
      for (Eigen::Index x = 0; x < nx; ++x)
        for (const auto& [dx, dy] : {std::pair<Eigen::Index, Eigen::Index>{1, 0}, {0, 1}}) {
          if (x + dx >= nx || y + dy >= ny) continue;
          const Eigen::Index i = body(x, y), j = body(x + dx, y + dy), axis = dx == 1 ? 0 : 1;
          entries.emplace_back(3 * j + axis, c, 1.0);  // the normal from i to j, on j; minus it on i
          entries.emplace_back(3 * i + axis, c, -1.0);
          // closing velocity: pairs across the centre line y = ny / 2 are pushed hardest
          push.push_back(dy == 1 ? -1.0 - 0.01 * static_cast<double>(std::min(y, ny - 1 - y)) : 0.5);
          ++c;
        }
    SparseMat D(3 * nx * ny, c);
    D.setFromTriplets(entries.begin(), entries.end());
    A = SparseMat(D.transpose() * D);
    b = Eigen::Map<const sc::VecX>(push.data(), c);
  }
};

// Minimum-map Newton with the sparse matrix itself as its preconditioner (what the default
// solver's working set passes: its sparse model) takes at most a third of the applications of
// A that unpreconditioned GMRES takes (measured: 160 against 621, the first 50 Arnoldi steps
// of each direction being unpreconditioned), for the same solution; an indefinite preconditioner is not used
// (the same solution at the unpreconditioned cost); one of the wrong size is rejected by name.
TEST(LcpSolvers, PreconditionedNewtonSolvesALargeClusterInFewApplications) {
  const LatticeCluster lattice;
  const SparseMat& A = lattice.A;
  const sc::VecX& b = lattice.b;
  const Eigen::Index c = b.size();
  const sc::LcpOptions options{.tolerance = 1e-8, .max_iterations = 200};
  const sc::LcpResult plain = sc::solve_lcp_minimum_map_newton(A, b, options);
  const sc::LcpResult preconditioned = sc::solve_lcp_minimum_map_newton(A, b, options, nullptr, &A);
  ASSERT_TRUE(plain.converged) << plain.residual;
  ASSERT_TRUE(preconditioned.converged) << preconditioned.residual;
  std::printf("  lattice cluster, %ld pairs, %ld active: %zu applications unpreconditioned, %zu preconditioned\n",
              static_cast<long>(c), static_cast<long>((preconditioned.gamma.array() > 0.0).count()),
              plain.operator_applications, preconditioned.operator_applications);
  EXPECT_GT((preconditioned.gamma.array() > 0.0).count(), c / 3);
  EXPECT_LE(3 * preconditioned.operator_applications, plain.operator_applications);
  const double scale = std::max(1.0, plain.gamma.cwiseAbs().maxCoeff());
  EXPECT_LE((preconditioned.gamma - plain.gamma).cwiseAbs().maxCoeff(), 1e-6 * scale);

  const SparseMat indefinite = SparseMat(-A);
  const sc::LcpResult unused = sc::solve_lcp_minimum_map_newton(A, b, options, nullptr, &indefinite);
  ASSERT_TRUE(unused.converged) << unused.residual;
  EXPECT_GT(3 * unused.operator_applications, plain.operator_applications);
  EXPECT_LE((unused.gamma - plain.gamma).cwiseAbs().maxCoeff(), 1e-6 * scale);

  const SparseMat wrong(c + 1, c + 1);
  try {
    sc::solve_lcp_minimum_map_newton(A, b, options, nullptr, &wrong);
    ADD_FAILURE() << "a wrong-size preconditioner was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("preconditioner"), std::string::npos) << e.what();
  }
}

// Once a direction of a solve has needed the factorisation, Newton's later directions with a
// new set A factorise at once (minimum_map_newton.hpp). The lattice cluster from lambda = 10 on
// every pair (most of them must let go, so the set A changes): 3 factorisations and 171
// applications of A; with 50 unpreconditioned steps before each factorisation, 275 (measured
// with the rule removed); factorising from the first Arnoldi step, 51. Unpreconditioned, it
// reports no factorisation.
TEST(LcpSolvers, NewtonFactorisesAtOnceAfterTheFirstDirectionThatNeedsIt) {
  const LatticeCluster lattice;
  const SparseMat& A = lattice.A;
  const sc::VecX& b = lattice.b;
  const sc::VecX pushed = sc::VecX::Constant(b.size(), 10.0);
  sc::LcpOptions options{.tolerance = 1e-8, .max_iterations = 200};
  const sc::LcpResult learnt = sc::solve_lcp_minimum_map_newton(A, b, options, &pushed, &A);
  const sc::LcpResult plain = sc::solve_lcp_minimum_map_newton(A, b, options, &pushed);
  options.gmres_unpreconditioned_steps = 0;
  const sc::LcpResult at_once = sc::solve_lcp_minimum_map_newton(A, b, options, &pushed, &A);
  for (const sc::LcpResult* r : {&learnt, &plain, &at_once}) ASSERT_TRUE(r->converged) << r->residual;
  std::printf("  lattice cluster from lambda = 10: %zu applications (%d factorisations) with 50 unpreconditioned "
              "steps first, %zu (%d) factorising at once\n",
              learnt.operator_applications, learnt.preconditioner_factorisations, at_once.operator_applications,
              at_once.preconditioner_factorisations);
  EXPECT_GE(learnt.preconditioner_factorisations, 2);
  EXPECT_LE(learnt.operator_applications, 220u);
  EXPECT_EQ(plain.preconditioner_factorisations, 0);
  const double scale = std::max(1.0, plain.gamma.cwiseAbs().maxCoeff());
  EXPECT_LE((learnt.gamma - plain.gamma).cwiseAbs().maxCoeff(), 1e-6 * scale);
}

// A non-symmetric sparse A (the lattice cluster's Laplacian with a skew coupling between
// neighbouring pairs, as the Jacobian of turning rods departs from the model at Q*):
// preconditioned by the sparse LU of its own active blocks, Newton takes fewer applications
// than preconditioned by LDLT of the symmetric cluster (the model at Q*), for the same
// solution. IterateJacobianModel asks for that LU only where A departs from its base by more
// than kLuDeparture.
TEST(LcpSolvers, NewtonPreconditionedByTheLuOfANonSymmetricMatrix) {
  const LatticeCluster lattice;
  const SparseMat& P = lattice.A;
  const sc::VecX& b = lattice.b;
  SparseMat skew(P.rows(), P.cols());
  {
    std::vector<Eigen::Triplet<double>> entries;
    for (Eigen::Index c = 0; c < P.outerSize(); ++c)
      for (SparseMat::InnerIterator it(P, c); it; ++it)
        if (it.row() < c) {  // +0.4 above the diagonal, -0.4 below, on P's pattern
          entries.emplace_back(it.row(), c, 0.4);
          entries.emplace_back(c, it.row(), -0.4);
        }
    skew.setFromTriplets(entries.begin(), entries.end());
  }
  const SparseMat A = P + skew;
  const sc::LcpOptions options{.tolerance = 1e-8, .max_iterations = 200};
  const sc::LcpResult by_model = sc::solve_lcp_minimum_map_newton(A, b, options, nullptr, &P);
  const sc::LcpResult by_lu = sc::solve_lcp_minimum_map_newton(A, b, options, nullptr, &A, false);
  ASSERT_TRUE(by_model.converged) << by_model.residual;
  ASSERT_TRUE(by_lu.converged) << by_lu.residual;
  std::printf("  skewed lattice cluster: %zu applications preconditioned by LDLT of the symmetric part, %zu by the "
              "LU of A\n",
              by_model.operator_applications, by_lu.operator_applications);
  EXPECT_LT(2 * by_lu.operator_applications, by_model.operator_applications);
  EXPECT_GE(by_lu.preconditioner_factorisations, 1);
  const double scale = std::max(1.0, by_model.gamma.cwiseAbs().maxCoeff());
  EXPECT_LE((by_lu.gamma - by_model.gamma).cwiseAbs().maxCoeff(), 1e-6 * scale);

  const sc::detail::IterateJacobianModel far{P, A};
  EXPECT_EQ(far.lu_preconditioner(), &far.A);
  const sc::detail::IterateJacobianModel near{P, SparseMat(P + 0.01 * skew)};
  EXPECT_EQ(near.lu_preconditioner(), nullptr);
}

// The default solver's working-set LCP learns the same across a round's corrections: after a
// correction's Newton needed its factorisation, the next ones factorise at once
// (defect_correction.hpp, WorkingSetLcp); a block that converges unpreconditioned does not
// teach it that.
TEST(LcpSolvers, WorkingSetLcpFactorisesAtOnceAfterACorrectionThatNeededIt) {
  const LatticeCluster lattice;
  const Eigen::Index c = lattice.b.size();
  std::vector<Eigen::Index> W(static_cast<std::size_t>(c));
  for (Eigen::Index k = 0; k < c; ++k) W[static_cast<std::size_t>(k)] = k;
  const sc::VecX zero = sc::VecX::Zero(c);
  const sc::detail::WorkingSetLcp lcp{sc::LcpOptions{.tolerance = 1e-8, .max_iterations = 200}};
  // d - target = b with lambda = 0: the lattice's LCP
  ASSERT_TRUE(lcp(lattice.A, W, zero, sc::VecX(lattice.b + sc::VecX::Ones(c)), 1.0, {}).has_value());
  EXPECT_TRUE(lcp.factorise_at_once);

  const sc::MatX dense = (sc::MatX(3, 3) << 2.0, 0.5, 0.0, 0.5, 2.0, 0.5, 0.0, 0.5, 2.0).finished();
  const SparseMat small = dense.sparseView();
  const std::vector<Eigen::Index> three{0, 1, 2};
  const sc::detail::WorkingSetLcp easy{sc::LcpOptions{1e-12}};
  ASSERT_TRUE(easy(small, three, sc::VecX::Zero(3), sc::VecX::Zero(3), 1.0, {}).has_value());
  EXPECT_FALSE(easy.factorise_at_once);
}

// The lattice cluster as the LCP sequence solves it when the default solver hands it a round
// (model_started_newton.hpp): Newton from BBPGD's start on a sparse model P close to A (A with
// its off-diagonal entries scaled by 0.9, as a probed model misses part of the coupling) and
// preconditioned by P from the first Arnoldi step. The same solution as Newton alone, in fewer
// applications of A than Newton preconditioned by P after 50 unpreconditioned steps.
TEST(LcpSolvers, NewtonFromAModelsStartSolvesTheClusterInFewerApplications) {
  const LatticeCluster lattice;
  const SparseMat& A = lattice.A;
  const sc::VecX& b = lattice.b;
  SparseMat P = 0.9 * A;
  P.diagonal() = A.diagonal();
  const sc::VecX zero = sc::VecX::Zero(b.size());
  sc::LcpOptions options{.tolerance = 1e-8, .max_iterations = 200};
  const sc::LcpResult plain = sc::solve_lcp_minimum_map_newton(A, b, options);
  const sc::LcpResult later = sc::solve_lcp_minimum_map_newton(A, b, options, &zero, &P);
  options.gmres_unpreconditioned_steps = 0;
  const sc::LcpResult started = sc::solve_lcp_newton_from_model(A, b, P, b, options, zero);
  for (const sc::LcpResult* r : {&plain, &later, &started}) ASSERT_TRUE(r->converged) << r->residual;
  std::printf("  lattice cluster: %zu applications unpreconditioned, %zu preconditioned after 50 steps, %zu from the "
              "model's start\n",
              plain.operator_applications, later.operator_applications, started.operator_applications);
  EXPECT_LT(started.operator_applications, later.operator_applications);
  const double scale = std::max(1.0, plain.gamma.cwiseAbs().maxCoeff());
  EXPECT_LE((started.gamma - plain.gamma).cwiseAbs().maxCoeff(), 1e-6 * scale);
  EXPECT_LE((later.gamma - plain.gamma).cwiseAbs().maxCoeff(), 1e-6 * scale);

  options.gmres_unpreconditioned_steps = -1;
  try {
    options.validate();
    ADD_FAILURE() << "a negative gmres_unpreconditioned_steps was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("gmres_unpreconditioned_steps"), std::string::npos) << e.what();
  }
}

}  // namespace lcp_solvers_tests
