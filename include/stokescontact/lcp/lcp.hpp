#pragma once
// The linear complementarity problem of a contact step (Yan et al. eq. 39-41):
//     find gamma with  0 <= gamma  _|_  w = A gamma + b >= 0,   A = D^T M D (symmetric PSD),
// equivalently the convex quadratic programme min_{gamma >= 0} 1/2 gamma^T A gamma + b^T gamma
// (Yan eq. 42). A is matrix-free: a callable VecX -> VecX (one call = one mobility application in
// the caller's accounting), or any Eigen matrix with A * x (each product is still counted).
//
// Residual and stopping rule, shared by every solver. The minimum map H = min(gamma, w)
// (Yan eq. 44, Lu eq. 62) vanishes exactly at a solution; we use its max norm, relative to
// ||b||_inf so that the test is invariant under b -> c b (which scales gamma and w alike):
//     residual = ||min(gamma, A gamma + b)||_inf / ||b||_inf,  converged <=> residual <= tolerance.
// (Yan uses the absolute 2-norm with eps = 1e-5.) H compares gamma with w as they stand, so for
// A far from unit scale the gamma-part weighs like 1/|A|; callers who care rescale gamma.
//
// Costs common to all solvers: a cold start (gamma0 = 0) has w0 = b for free, so b >= 0 returns
// gamma = 0 after 0 iterations and 0 applications, as do Nc = 0 and b = 0; a nonzero warm start
// costs one application for w0 (and returns after 0 iterations if it already solves the LCP);
// each solver then spends one application on a curvature estimate along p0 = min(gamma0, w0).
//
// Shared by the solvers: options and result, the counted and checked operator, the start
// (validation, trivial problems, warm start), the curvature estimate for first steps.
#include <concepts>
#include <cstddef>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

struct LcpOptions {
  double tolerance = 1e-8;    // converged when ||min(gamma, w)||_inf <= tolerance ||b||_inf
  int max_iterations = 1000;  // gradient steps (BBPGD, APGD) or Newton steps
  // Minimum-map Newton only.
  int gmres_restart = 50;          // Krylov dimension of one GMRES cycle
  int gmres_max_iterations = 500;  // Arnoldi steps per Newton direction
  double forcing_max = 0.1;        // GMRES relative tolerance eta_k <= forcing_max (inexact Newton)
  double regularization = 1e-2;    // proximal term mu_k = regularization c |H_k| / |H_0| (0: none)
  // With a sparse preconditioner: Arnoldi steps a Newton direction takes before its block is
  // factorised (0: at once, where a product with A costs a mobility application and a sparse
  // factorisation is cheaper than a few of them). After the first direction of a solve that
  // needed the factorisation, the later ones factorise at once (minimum_map_newton.hpp).
  int gmres_unpreconditioned_steps = 50;
  // Newton: Armijo halvings per line search; APGD: doublings of L per step.
  int max_line_search_steps = 40;
  // Minimum-map Newton only: it gives up when its best merit has not halved over this many
  // Newton steps (0: never). An LCP whose matrix is not a P-matrix (a secant-corrected
  // working-set model is not symmetric) can have no solution, and Newton then crawls on to
  // max_iterations (dense Brownian rods: 1000 steps of 40 GMRES products each, see
  // minimum_map_newton.hpp).
  int stall_window = 50;

  void validate() const {
    require_positive(tolerance, "LcpOptions.tolerance");
    const auto at_least_one = [](int v, const char* field) {
      if (v < 1) fail_argument(field, "must be >= 1, got " + std::to_string(v));
    };
    at_least_one(max_iterations, "LcpOptions.max_iterations");
    at_least_one(gmres_restart, "LcpOptions.gmres_restart");
    at_least_one(gmres_max_iterations, "LcpOptions.gmres_max_iterations");
    at_least_one(max_line_search_steps, "LcpOptions.max_line_search_steps");
    if (stall_window < 0) fail_argument("LcpOptions.stall_window", "must be >= 0, got " + std::to_string(stall_window));
    require_non_negative(regularization, "LcpOptions.regularization");
    if (gmres_unpreconditioned_steps < 0)
      fail_argument("LcpOptions.gmres_unpreconditioned_steps",
                    "must be >= 0, got " + std::to_string(gmres_unpreconditioned_steps));
    require_positive(forcing_max, "LcpOptions.forcing_max");
    if (!(forcing_max < 1.0)) fail_argument("LcpOptions.forcing_max", "must be < 1, got " + std::to_string(forcing_max));
  }
};

struct LcpResult {
  VecX gamma;                             // the solution estimate, gamma >= 0 always
  VecX w;                                 // A gamma + b at the returned gamma
  int iterations = 0;                     // gradient or Newton steps taken
  std::size_t operator_applications = 0;  // every application of A, inner GMRES ones included
  double residual = 0.0;                  // ||min(gamma, w)||_inf / ||b||_inf (0 when b = 0)
  bool converged = false;                 // residual <= tolerance
  int preconditioner_factorisations = 0;  // sparse factorisations of a preconditioner (Newton)
};

// ||min(gamma, w)||_inf: the max norm of the minimum map (Yan eq. 44, Lu eq. 62); 0 when empty.
inline double lcp_residual(const VecX& gamma, const VecX& w) {
  if (gamma.size() != w.size())
    fail_argument("w", "has size " + std::to_string(w.size()) + ", gamma has " + std::to_string(gamma.size()));
  return gamma.size() == 0 ? 0.0 : gamma.cwiseMin(w).cwiseAbs().maxCoeff();
}

namespace detail {
template <typename A>
inline constexpr bool is_eigen_matrix = std::is_base_of_v<Eigen::EigenBase<std::remove_cvref_t<A>>, std::remove_cvref_t<A>>;
}  // namespace detail

// What the solvers accept as A: a square Eigen matrix (dense or sparse), or a callable VecX -> VecX.
template <typename A>
concept LcpMatrixOperator =
    detail::is_eigen_matrix<A> ||
    (std::invocable<A&, const VecX&> && std::convertible_to<std::invoke_result_t<A&, const VecX&>, VecX>);

namespace detail {

// The minimum map H(gamma) = min(gamma, w) (Yan eq. 44, Lu eq. 62).
inline VecX minimum_map(const VecX& gamma, const VecX& w) { return gamma.cwiseMin(w); }

// Projection onto the feasible set gamma >= 0.
inline VecX project_nonnegative(const VecX& gamma) { return gamma.cwiseMax(0.0); }

// A as the solvers see it: every call is counted and checked (size, finiteness).
template <typename ApplyA>
class CountedLcpOperator {
 public:
  CountedLcpOperator(ApplyA& a, Eigen::Index n) : a_(a), n_(n) {
    if constexpr (is_eigen_matrix<ApplyA>) {
      if (a.rows() != n || a.cols() != n)
        fail_argument("A", "is " + std::to_string(a.rows()) + " x " + std::to_string(a.cols()) + ", b has size " +
                               std::to_string(n));
    }
  }

  VecX operator()(const VecX& x) {
    ++applications_;
    VecX out;
    if constexpr (is_eigen_matrix<ApplyA>)
      out = a_ * x;
    else
      out = a_(x);
    if (out.size() != n_)
      fail_argument("A", "returned a vector of size " + std::to_string(out.size()) + ", expected " + std::to_string(n_));
    if (!out.allFinite()) fail_argument("A", "returned non-finite values");
    return out;
  }

  std::size_t applications() const { return applications_; }

 private:
  ApplyA& a_;
  Eigen::Index n_;
  std::size_t applications_ = 0;
};

// One solve's bookkeeping: the problem, the stopping threshold, and the result it ends with.
template <typename ApplyA>
class LcpSolve {
 public:
  // Validates the input (std::invalid_argument naming the field) and sets the start gamma0 =
  // max(warm_start, 0) with w0 = A gamma0 + b, free when gamma0 = 0.
  LcpSolve(ApplyA& a, const VecX& b, const LcpOptions& options, const VecX* warm_start)
      : A(a, b.size()), b(b), options(options) {
    options.validate();
    require_finite(b, "b");
    const Eigen::Index n = b.size();
    gamma0 = VecX::Zero(n);
    if (warm_start != nullptr) {
      if (warm_start->size() != n)
        fail_argument("warm_start", "has size " + std::to_string(warm_start->size()) + ", b has " + std::to_string(n));
      require_finite(*warm_start, "warm_start");
      gamma0 = project_nonnegative(*warm_start);
    }
    b_scale = n == 0 ? 0.0 : b.cwiseAbs().maxCoeff();
    // Nc = 0 or b = 0: gamma = 0 solves the LCP exactly (w = 0), whatever A is.
    trivial = b_scale == 0.0;
    if (trivial) {
      gamma0.setZero();
      w0 = VecX::Zero(n);
    } else {
      w0 = gamma0.isZero(0.0) ? b : VecX(A(gamma0) + b);
    }
  }

  // The relative residual of the stopping rule.
  double residual(const VecX& gamma, const VecX& w) const {
    return trivial ? 0.0 : lcp_residual(gamma, w) / b_scale;
  }
  bool converged(const VecX& gamma, const VecX& w) const { return residual(gamma, w) <= options.tolerance; }

  // The stopping test where w may come from linear updates (w_exact false): convergence is
  // confirmed on the true w = A gamma + b (one application), which then replaces w.
  bool confirmed_converged(const VecX& gamma, VecX& w, bool& w_exact) {
    if (!converged(gamma, w)) return false;
    if (w_exact) return true;
    w = A(gamma) + b;
    w_exact = true;
    return converged(gamma, w);
  }

  // The result at gamma; a w from linear updates is replaced by the true one (one application).
  LcpResult finish(VecX gamma, VecX w, int iterations, bool w_exact = true) {
    if (!w_exact) w = A(gamma) + b;
    LcpResult r;
    r.residual = residual(gamma, w);
    r.converged = r.residual <= options.tolerance;
    r.gamma = std::move(gamma);
    r.w = std::move(w);
    r.iterations = iterations;
    r.operator_applications = A.applications();
    return r;
  }

  CountedLcpOperator<ApplyA> A;
  const VecX& b;
  const LcpOptions& options;
  VecX gamma0, w0;
  double b_scale = 0.0;
  bool trivial = false;
};

// The best iterate seen, returned by the first-order methods when they do not converge (they are
// not monotone; Mazhar et al. return the best iterate too).
struct BestLcpIterate {
  VecX gamma, w;
  double residual = std::numeric_limits<double>::infinity();

  void offer(const VecX& g, const VecX& w_at_g, double r) {
    if (r < residual) {
      gamma = g;
      w = w_at_g;
      residual = r;
    }
  }
};

// The curvature v^T A v / v^T v of the CQP along v != 0, given Av, for a first step size.
// Where v is a null direction of A (possible for PSD A) the largest eigenvalue is estimated by
// power iteration from a fixed vector instead (counted). Returns 0 when A vanishes on all it saw.
template <typename Op>
double curvature_estimate(Op& A, const VecX& v, const VecX& Av) {
  const double rayleigh = v.dot(Av) / v.squaredNorm();
  if (rayleigh > 0.0) return rayleigh;
  constexpr int kPowerSteps = 10;
  VecX x = VecX::LinSpaced(v.size(), 1.0, 2.0).normalized();  // fixed and positive
  double lambda = 0.0;
  for (int k = 0; k < kPowerSteps; ++k) {
    const VecX Ax = A(x);
    lambda = Ax.norm();
    if (!(lambda > 0.0)) return 0.0;
    x = Ax / lambda;
  }
  return lambda;
}

}  // namespace detail
}  // namespace stokescontact
