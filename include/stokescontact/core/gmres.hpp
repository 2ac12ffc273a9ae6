#pragma once
// Restarted GMRES with right preconditioning (Saad & Schultz 1986; Saad, "Iterative
// Methods for Sparse Linear Systems", Alg. 9.5): solve A P y = b, x = P y, so that the
// residual GMRES minimises is the true residual b - A x, whatever the preconditioner P.
// Arnoldi uses modified Gram-Schmidt with one reorthogonalisation pass when a vector loses
// more than ~30% of its norm ("twice is enough", Giraud et al. 2005); the small least-
// squares problem is kept triangular by Givens rotations.
//
// A and P are callables VecX -> VecX. Each restart cycle ends with one extra application of
// A to form the true residual, so a cycle never reports convergence on the Arnoldi estimate
// alone; `relative_residual` is that true |b - A x| / |b|.
#include <algorithm>
#include <cmath>
#include <concepts>
#include <string>
#include <utility>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

struct GmresOptions {
  double tolerance = 1e-10;  // stop when |b - A x| <= tolerance |b|
  int max_iterations = 500;  // Arnoldi steps (applications of A P) over all cycles
  int restart = 50;          // Krylov dimension of one cycle

  void validate() const {
    require_positive(tolerance, "GmresOptions.tolerance");
    if (max_iterations < 0)
      fail_argument("GmresOptions.max_iterations", "must be >= 0, got " + std::to_string(max_iterations));
    if (restart < 1) fail_argument("GmresOptions.restart", "must be >= 1, got " + std::to_string(restart));
  }
};

struct GmresResult {
  VecX x;                            // the approximate solution
  int iterations = 0;                // Arnoldi steps taken (one A and one P application each)
  int operator_applications = 0;     // all applications of A, residual checks included
  double relative_residual = 0.0;    // true |b - A x| / |b| at return (0 when b = 0)
  bool converged = false;            // relative_residual <= tolerance
};

// The identity preconditioner.
struct IdentityPreconditioner {
  const VecX& operator()(const VecX& v) const { return v; }
};

namespace detail {

template <typename F>
VecX checked_call(F& f, const VecX& v, Eigen::Index n, const char* name) {
  VecX out = f(v);
  if (out.size() != n)
    fail_argument(name, "returned a vector of size " + std::to_string(out.size()) + ", expected " +
                            std::to_string(n));
  if (!out.allFinite()) fail_argument(name, "returned non-finite values");
  return out;
}

// c, s with [c s; -s c] [a; b] = [r; 0].
inline void givens(double a, double b, double& c, double& s) {
  if (b == 0.0) {
    c = 1.0;
    s = 0.0;
    return;
  }
  const double r = std::hypot(a, b);
  c = a / r;
  s = b / r;
}

}  // namespace detail

// x0, when given, is the starting guess. b = 0 returns x = 0 at once (the exact solution).
// Throws std::invalid_argument for bad options, non-finite b or x0, mismatched sizes, or an
// operator/preconditioner that returns a wrong size or non-finite values.
template <typename Operator, typename Preconditioner>
  requires std::invocable<Operator&, const VecX&> && std::invocable<Preconditioner&, const VecX&>
GmresResult gmres(Operator&& A, const VecX& b, Preconditioner&& P, const GmresOptions& options = {},
                  const VecX* x0 = nullptr) {
  options.validate();
  require_finite(b, "b");
  const Eigen::Index n = b.size();
  GmresResult result;
  result.x = VecX::Zero(n);
  if (x0 != nullptr) {
    if (x0->size() != n)
      fail_argument("x0", "has size " + std::to_string(x0->size()) + ", b has " + std::to_string(n));
    require_finite(*x0, "x0");
    result.x = *x0;
  }
  const double b_norm = b.norm();
  if (b_norm == 0.0) {
    result.x.setZero();
    result.converged = true;
    return result;
  }
  const double target = options.tolerance * b_norm;
  const int m = options.restart;

  MatX V(n, m + 1);          // Arnoldi basis
  MatX H = MatX::Zero(m + 1, m);  // Hessenberg matrix, rotated to upper triangular
  VecX cs(m), sn(m), g(m + 1);

  VecX r = x0 != nullptr ? VecX(b - detail::checked_call(A, result.x, n, "operator")) : b;
  if (x0 != nullptr) ++result.operator_applications;
  double r_norm = r.norm();

  while (r_norm > target && result.iterations < options.max_iterations) {
    V.col(0) = r / r_norm;
    g.setZero();
    g(0) = r_norm;
    H.setZero();
    int k = 0;  // columns built in this cycle
    while (k < m && result.iterations < options.max_iterations) {
      VecX w = detail::checked_call(A, detail::checked_call(P, V.col(k), n, "preconditioner"), n,
                                    "operator");
      ++result.operator_applications;
      ++result.iterations;
      const double w_norm0 = w.norm();
      for (int pass = 0; pass < 2; ++pass) {  // modified Gram-Schmidt, repeated if needed
        const double before = w.norm();
        for (int i = 0; i <= k; ++i) {
          const double h = V.col(i).dot(w);
          H(i, k) += h;
          w -= h * V.col(i);
        }
        if (w.norm() > 0.7 * before) break;
      }
      const double h_next = w.norm();
      H(k + 1, k) = h_next;
      // Happy breakdown: the Krylov space is invariant, the solution lies in it.
      const bool breakdown = h_next <= 1e-14 * w_norm0;
      if (!breakdown) V.col(k + 1) = w / h_next;
      for (int i = 0; i < k; ++i) {  // apply the earlier rotations to the new column
        const double t = cs(i) * H(i, k) + sn(i) * H(i + 1, k);
        H(i + 1, k) = -sn(i) * H(i, k) + cs(i) * H(i + 1, k);
        H(i, k) = t;
      }
      detail::givens(H(k, k), H(k + 1, k), cs(k), sn(k));
      H(k, k) = cs(k) * H(k, k) + sn(k) * H(k + 1, k);
      H(k + 1, k) = 0.0;
      g(k + 1) = -sn(k) * g(k);
      g(k) = cs(k) * g(k);
      ++k;
      if (breakdown || std::abs(g(k)) <= target) break;
    }
    // y = H^-1 g on the triangle; a zero pivot (singular A) contributes nothing.
    VecX y = VecX::Zero(k);
    for (int i = k - 1; i >= 0; --i) {
      double s = g(i) - H.row(i).segment(i + 1, k - i - 1).dot(y.segment(i + 1, k - i - 1));
      y(i) = H(i, i) != 0.0 ? s / H(i, i) : 0.0;
    }
    const VecX x_cycle_start = result.x;
    result.x += detail::checked_call(P, VecX(V.leftCols(k) * y), n, "preconditioner");
    VecX r_new = b - detail::checked_call(A, result.x, n, "operator");
    ++result.operator_applications;
    // No progress over a whole cycle (singular or stagnating system): keep the better
    // iterate, whose residual is known, and stop honestly. On a singular system with an
    // inconsistent right-hand side a tiny pivot can make the update far worse than none.
    if (!(r_new.norm() < r_norm)) {
      result.x = x_cycle_start;
      break;
    }
    r = std::move(r_new);
    r_norm = r.norm();
  }
  result.relative_residual = r_norm / b_norm;
  result.converged = r_norm <= target;
  return result;
}

// Unpreconditioned GMRES.
template <typename Operator>
  requires std::invocable<Operator&, const VecX&>
GmresResult gmres(Operator&& A, const VecX& b, const GmresOptions& options = {}, const VecX* x0 = nullptr) {
  return gmres(std::forward<Operator>(A), b, IdentityPreconditioner{}, options, x0);
}

}  // namespace stokescontact
