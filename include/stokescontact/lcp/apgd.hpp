#pragma once
// Accelerated projected gradient descent for the LCP as the CQP min_{gamma >= 0}
// 1/2 gamma^T A gamma + b^T gamma (Yan et al. eq. 42): Nesterov's method with a backtracked
// Lipschitz estimate L, adaptive growth of the step 1/L and gradient restart, after Mazhar,
// Heyn, Negrut & Tasora, ACM TOG 34(3) 2015, Alg. "APGD" (restart: O'Donoghue & Candes 2015).
//
// Per step k, from the extrapolated point y_k:
//   gamma_{k+1} = max(0, y_k - (A y_k + b) / L),  doubling L until the sufficient decrease
//   f(gamma_{k+1}) <= f(y_k) + grad f(y_k).(gamma_{k+1} - y_k) + L/2 |gamma_{k+1} - y_k|^2,
//   which for the quadratic f reads d^T A d <= L d^T d with d = gamma_{k+1} - y_k;
//   theta_{k+1} = theta_k (sqrt(theta_k^2 + 4) - theta_k) / 2,
//   beta_{k+1} = theta_k (1 - theta_k) / (theta_k^2 + theta_{k+1}),
//   y_{k+1} = gamma_{k+1} + beta_{k+1} (gamma_{k+1} - gamma_k), or y_{k+1} = gamma_{k+1},
//   theta_{k+1} = 1 when grad f(y_k).(gamma_{k+1} - gamma_k) > 0 (restart); then L *= 0.9.
//
// Cost: one application of A per trial point gamma_{k+1} (so one per step plus one per
// doubling of L); A y_{k+1} follows from A gamma_{k+1} and A gamma_k by linearity. Plus one
// for L0, plus one for w0 = A gamma0 + b under a nonzero warm start.
// Differences from Mazhar et al.: L0 is the curvature along the projected gradient
// p0 = min(gamma0, w0) instead of along gamma0 - 1; the residual and stopping rule are those
// of lcp.hpp; the best iterate is returned when the method does not converge (as they do).
#include <cmath>
#include <type_traits>
#include <utility>

#include "stokescontact/lcp/lcp.hpp"

namespace stokescontact {

template <LcpMatrixOperator ApplyA>
LcpResult solve_lcp_apgd(ApplyA&& apply_A, const VecX& b, const LcpOptions& options = {},
                         const VecX* warm_start = nullptr) {
  detail::LcpSolve<std::remove_reference_t<ApplyA>> solve(apply_A, b, options, warm_start);
  VecX gamma = solve.gamma0, w = solve.w0;
  if (solve.converged(gamma, w)) return solve.finish(std::move(gamma), std::move(w), 0);

  const VecX p = detail::minimum_map(gamma, w);
  double L = detail::curvature_estimate(solve.A, p, solve.A(p));  // Lipschitz estimate L0
  if (!(L > 0.0)) return solve.finish(std::move(gamma), std::move(w), 0);  // A = 0: no scale
  constexpr double kGrowth = 2.0, kShrink = 0.9;

  detail::BestLcpIterate best;
  best.offer(gamma, w, solve.residual(gamma, w));
  VecX A_gamma = w - b;  // A gamma_k (exactly 0 from a cold start)
  VecX y = gamma, A_y = A_gamma;
  double theta = 1.0;
  for (int k = 1; k <= options.max_iterations; ++k) {
    const VecX grad = A_y + b;  // grad f(y_k)
    VecX next, A_next;
    for (int t = 0;; ++t) {  // backtracking on L
      next = detail::project_nonnegative(y - grad / L);
      A_next = solve.A(next);
      const VecX d = next - y;
      if (d.dot(A_next - A_y) <= L * d.squaredNorm() || t + 1 >= options.max_line_search_steps) break;
      L *= kGrowth;
    }
    VecX w_next = A_next + b;
    const double r = solve.residual(next, w_next);
    if (r <= options.tolerance) return solve.finish(std::move(next), std::move(w_next), k);
    best.offer(next, w_next, r);

    const double theta_next = 0.5 * theta * (std::sqrt(theta * theta + 4.0) - theta);
    const double beta = theta * (1.0 - theta) / (theta * theta + theta_next);
    if (grad.dot(next - gamma) > 0.0) {  // gradient restart
      y = next;
      A_y = A_next;
      theta = 1.0;
    } else {
      y = next + beta * (next - gamma);
      A_y = A_next + beta * (A_next - A_gamma);
      theta = theta_next;
    }
    gamma = std::move(next);
    A_gamma = std::move(A_next);
    L *= kShrink;
  }
  return solve.finish(std::move(best.gamma), std::move(best.w), options.max_iterations);
}

}  // namespace stokescontact
