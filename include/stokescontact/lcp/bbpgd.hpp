#pragma once
// Barzilai-Borwein projected gradient descent for the LCP as the CQP min_{gamma >= 0}
// 1/2 gamma^T A gamma + b^T gamma (Yan et al. eq. 42, Appendix B Alg. 1; Dai & Fletcher 2005),
// with the BB1 and BB2 step sizes alternating:
//     gamma_k = max(0, gamma_{k-1} - alpha_{k-1} g_{k-1}),  g_k = A gamma_k + b,
//     s = gamma_k - gamma_{k-1}, y = g_k - g_{k-1} (= A s, free),
//     alpha_k = s^T s / s^T y (BB1, odd k) or s^T y / y^T y (BB2, even k).
//
// Cost: one application of A per step (g_k); plus one for the first step size, the Cauchy step
// along the projected gradient p0 = min(gamma0, g0); the first step is free whenever it moves
// exactly along -p0, which it always does from a cold start (g_1 = g_0 - alpha_0 A p0); plus
// one for w0 = A gamma0 + b under a nonzero warm start. So a cold start that converges after k
// steps costs k applications.
//
// Differences from Alg. 1: the first step size is taken along p0 rather than along g0 (g0 is
// dominated by the large entries of pairs that stay apart); BB1 and BB2 alternate (Alg. 1 uses
// BB1 and notes BB2 works as well); a step with s^T y <= 0 (s in the null space of a PSD A)
// keeps the previous size; the stopping rule is that of lcp.hpp; when the method does not
// converge the best iterate is returned (BB steps are not monotone).
#include <type_traits>
#include <utility>

#include "stokescontact/lcp/lcp.hpp"

namespace stokescontact {

template <LcpMatrixOperator ApplyA>
LcpResult solve_lcp_bbpgd(ApplyA&& apply_A, const VecX& b, const LcpOptions& options = {},
                          const VecX* warm_start = nullptr) {
  detail::LcpSolve<std::remove_reference_t<ApplyA>> solve(apply_A, b, options, warm_start);
  VecX gamma = solve.gamma0, g = solve.w0;  // g = grad f = A gamma + b = w
  if (solve.converged(gamma, g)) return solve.finish(std::move(gamma), std::move(g), 0);

  const VecX p = detail::minimum_map(gamma, g);  // projected gradient p0 = H(gamma0)
  const VecX Ap = solve.A(p);
  const double curvature = detail::curvature_estimate(solve.A, p, Ap);
  if (!(curvature > 0.0)) return solve.finish(std::move(gamma), std::move(g), 0);  // A = 0: no scale
  double alpha = 1.0 / curvature;

  detail::BestLcpIterate best;
  best.offer(gamma, g, solve.residual(gamma, g));
  for (int k = 1; k <= options.max_iterations; ++k) {
    VecX gamma_next = detail::project_nonnegative(gamma - alpha * g);  // descent + projection steps
    const bool along_p = k == 1 && gamma_next == VecX(gamma - alpha * p);
    VecX g_next = along_p ? VecX(g - alpha * Ap) : VecX(solve.A(gamma_next) + b);
    const double r = solve.residual(gamma_next, g_next);
    if (r <= options.tolerance) return solve.finish(std::move(gamma_next), std::move(g_next), k);
    best.offer(gamma_next, g_next, r);

    const VecX s = gamma_next - gamma;  // s_{k-1}
    const VecX y = g_next - g;          // y_{k-1} = A s_{k-1}
    const double sy = s.dot(y);
    if (sy > 0.0) alpha = k % 2 == 1 ? s.squaredNorm() / sy : sy / y.squaredNorm();  // BB1 / BB2
    gamma = std::move(gamma_next);
    g = std::move(g_next);
  }
  return solve.finish(std::move(best.gamma), std::move(best.w), options.max_iterations);
}

}  // namespace stokescontact
