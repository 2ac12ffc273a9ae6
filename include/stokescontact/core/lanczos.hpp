#pragma once
// Lanczos approximation of A^(1/2) b for a symmetric positive definite A given only as a
// callable v -> A v (Ando, Chow, Saad & Skolnick, J. Chem. Phys. 137, 064106 (2012); Chow &
// Saad, SIAM J. Sci. Comput. 36, A588 (2014)). k Lanczos steps on A from v_1 = b / |b| give
// A V_k = V_k T_k + beta_k v_{k+1} e_k^T with T_k tridiagonal, and
//   y_k = |b| V_k T_k^(1/2) e_1  ~  A^(1/2) b,
// T_k^(1/2) e_1 = Q sqrt(Lambda) Q^T e_1 from the eigendecomposition T_k = Q Lambda Q^T.
// The iteration stops when successive iterates agree, |y_k - y_{k-1}| <= tolerance |y_k|
// (the test of Ando et al.), when the Krylov space is invariant (beta_k ~ 0: y_k is then
// exact), or after max_iterations applications of A.
//
// Each new Lanczos vector is orthogonalised against all earlier ones (two classical
// Gram-Schmidt passes, "twice is enough"), so V_k stays orthonormal to rounding. That costs
// O(n k) per step and n k doubles of memory, small next to the operators this serves (an RPY
// sum is O(N^2) per application), and makes |y_k - y_{k-1}| = |b| |s_k - (s_{k-1}, 0)| with
// s_k = T_k^(1/2) e_1: the stopping test needs only the small vectors.
//
// A must be symmetric positive definite: a Ritz value (eigenvalue of T_k) below zero proves it
// is not, and the routine stops with status not_positive_definite.
#include <algorithm>
#include <cmath>
#include <concepts>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

// The tolerance bounds the change between successive iterates, not the error: with the error
// shrinking by a factor rho per step the error is about change rho / (1 - rho), measured at
// 0.4-4 times the tolerance for condition numbers 10-1e4. The default suits sampling: a
// Brownian increment whose amplitude is off by ~1e-4 is far below the statistical error of any
// observable, and costs 19-24 applications for 500 RPY spheres at packing 0.12-0.4 (36-41 at
// 1e-6, 42-57 at 1e-8; condition numbers 170-440).
struct LanczosOptions {
  double tolerance = 1e-4;   // stop when |y_k - y_{k-1}| <= tolerance |y_k|
  int max_iterations = 100;  // Krylov dimension k = applications of A; memory n (k + 1) doubles

  void validate() const {
    require_positive(tolerance, "LanczosOptions.tolerance");
    if (max_iterations < 1)
      fail_argument("LanczosOptions.max_iterations", "must be >= 1, got " + std::to_string(max_iterations));
  }
};

enum class LanczosStatus {
  converged,              // successive iterates agree to the tolerance, or the space is invariant
  max_iterations,         // the last iterate is returned, relative_change says how settled it was
  not_positive_definite,  // a Ritz value < 0: the iterate before it is returned
};

struct LanczosResult {
  VecX value;                      // y_k ~ A^(1/2) b
  int iterations = 0;              // Lanczos steps = applications of A
  double relative_change = 0.0;    // |y_k - y_{k-1}| / |y_k| of the last step (0 when b = 0)
  LanczosStatus status = LanczosStatus::converged;

  bool converged() const { return status == LanczosStatus::converged; }
};

namespace detail {

// A v, checked for size and finiteness (the caller's operator is user code).
template <typename F>
VecX lanczos_apply(F& f, const VecX& v) {
  VecX out = f(v);
  if (out.size() != v.size())
    fail_argument("operator", "returned a vector of size " + std::to_string(out.size()) + ", expected " +
                                  std::to_string(v.size()));
  if (!out.allFinite()) fail_argument("operator", "returned non-finite values");
  return out;
}

}  // namespace detail

// A^(1/2) b by Lanczos (Ando et al. 2012; Chow & Saad 2014, f(A) b with f = sqrt). b = 0
// returns 0 at once. Throws std::invalid_argument for bad options, non-finite b, or an operator
// that returns a wrong size or non-finite values; non-convergence is a status, not an exception.
template <typename Operator>
  requires std::invocable<Operator&, const VecX&>
LanczosResult lanczos_sqrt(Operator&& A, const VecX& b, const LanczosOptions& options = {}) {
  options.validate();
  require_finite(b, "b");
  const Eigen::Index n = b.size();
  LanczosResult result;
  result.value = VecX::Zero(n);
  const double b_norm = b.norm();
  if (b_norm == 0.0) return result;

  // beta_k below this fraction of |A v_k| means A v_k lies in span(V_k): the space is invariant.
  constexpr double kInvariantTolerance = 1e-12;
  // Ritz values down to this fraction of the largest below zero are rounding of a semidefinite A.
  constexpr double kNegativeRitzTolerance = 1e-12;

  std::vector<VecX> V{b / b_norm};  // Lanczos vectors v_1 .. v_k (and v_{k+1} while iterating)
  VecX alpha(0), beta(0);           // diagonal and off-diagonal of T_k
  VecX s, s_previous;               // T_k^(1/2) e_1 and T_{k-1}^(1/2) e_1
  Eigen::SelfAdjointEigenSolver<MatX> eigen;
  for (;;) {
    const Eigen::Index k = result.iterations + 1;  // Krylov dimension after this step
    if (result.iterations == options.max_iterations) {
      result.status = LanczosStatus::max_iterations;
      break;
    }
    VecX w = detail::lanczos_apply(A, V.back());
    ++result.iterations;
    const double w_norm = w.norm();
    alpha.conservativeResize(k);
    alpha(k - 1) = V.back().dot(w);
    // Three-term recurrence, then full reorthogonalisation (twice is enough).
    w -= alpha(k - 1) * V.back();
    if (k > 1) w -= beta(k - 2) * V[static_cast<std::size_t>(k - 2)];
    for (int pass = 0; pass < 2; ++pass)
      for (const VecX& v : V) w -= v.dot(w) * v;
    const double beta_k = w.norm();

    eigen.computeFromTridiagonal(alpha, beta, Eigen::ComputeEigenvectors);
    const VecX& ritz = eigen.eigenvalues();  // ascending
    const double largest = ritz(k - 1);
    if (!(largest > 0.0) || ritz(0) < -kNegativeRitzTolerance * largest) {
      result.status = LanczosStatus::not_positive_definite;
      break;  // value from s_previous (the last iterate built on a positive T)
    }
    const MatX& Q = eigen.eigenvectors();
    s = Q * ritz.cwiseMax(0.0).cwiseSqrt().cwiseProduct(Q.row(0).transpose()).eval();
    VecX difference = s;
    difference.head(k - 1) -= s_previous;
    result.relative_change = difference.norm() / s.norm();
    s_previous = s;

    const bool invariant = beta_k <= kInvariantTolerance * w_norm || k == n;
    if (invariant || result.relative_change <= options.tolerance) {
      result.status = LanczosStatus::converged;
      break;
    }
    beta.conservativeResize(k);
    beta(k - 1) = beta_k;
    V.push_back(w / beta_k);
  }
  // y = |b| V_k s_k, from the last iterate with a positive T.
  for (Eigen::Index j = 0; j < s_previous.size(); ++j)
    result.value += (b_norm * s_previous(j)) * V[static_cast<std::size_t>(j)];
  return result;
}

}  // namespace stokescontact
