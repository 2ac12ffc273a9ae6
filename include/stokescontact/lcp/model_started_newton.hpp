#pragma once
// Minimum-map Newton (minimum_map_newton.hpp) on an LCP whose products with A are costly (a
// mobility application each, matrix-free), given a sparse symmetric positive definite matrix P
// close to A (a probed Delassus model, delassus_probing.hpp): Newton starts from BBPGD's first
// iterate within 1e-3 on the LCP of P (bbpgd.hpp; one sparse product per BB step, no product
// with A), and P's principal blocks precondition its GMRES.
//
// Why the start: from the previous iterate alone, Newton crawls where many pairs change sides
// at once (a jammed packing's guarantee round: 26 Newton steps at tau down to 1/256, the
// active set shrinking by one pair per step; 3-5 steps from BBPGD's start, docs/results.md).
// The start only has to sort the pairs into pushed and free; Newton's own stopping rule, on
// the true w = A gamma + b, decides convergence, so P's error costs steps, never accuracy.
#include <Eigen/Sparse>

#include "stokescontact/lcp/bbpgd.hpp"
#include "stokescontact/lcp/minimum_map_newton.hpp"

namespace stokescontact {

inline constexpr LcpOptions kGradientStart{1e-3, 200};  // BBPGD's start for minimum-map Newton

// 0 <= gamma _|_ A gamma + b >= 0 from `warm` (b_P: the same LCP's b for P, so that
// P gamma + b_P ~ A gamma + b near warm). `lu_preconditioner`, when given, a non-symmetric sparse
// matrix closer to A than P (A itself, where A is sparse), preconditions GMRES in P's place,
// factorised by sparse LU.
template <LcpMatrixOperator ApplyA>
LcpResult solve_lcp_newton_from_model(ApplyA&& A, const VecX& b, const Eigen::SparseMatrix<double>& P,
                                      const VecX& b_P, const LcpOptions& options, const VecX& warm,
                                      const Eigen::SparseMatrix<double>* lu_preconditioner = nullptr) {
  const VecX start = solve_lcp_bbpgd(P, b_P, kGradientStart, &warm).gamma;
  if (lu_preconditioner != nullptr)
    return solve_lcp_minimum_map_newton(A, b, options, &start, lu_preconditioner, false);
  return solve_lcp_minimum_map_newton(A, b, options, &start, &P);
}

}  // namespace stokescontact
