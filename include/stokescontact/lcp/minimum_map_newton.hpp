#pragma once
// Minimum-map Newton for the LCP (Lu, Rahimian & Zorin 2017, Sec. 3.3, Alg. 2), matrix-free.
// The minimum map H(lambda) = min(lambda, y), y = A lambda + b (eq. 62), is driven to zero by
// Newton steps on its B-derivative J = P_A A + P_F, with (Alg. 2 lines 5-6)
//     set A = {i : y_i < c lambda_i}   (rows of A: the contact holds, y_i -> 0),
//     set F = {i : y_i >= c lambda_i}  (identity rows: the pair separates, lambda_i -> 0).
// (Names as in Lu et al.; with gamma = lambda and w = y, F is where c gamma_i <= w_i.)
// c > 0 is the curvature of A along the first projected gradient (lcp.hpp), so that the
// comparison and the merit below weigh lambda and y / c in the same units; Alg. 2 has c = 1.
// Line 7, J d = -H, reduces to
//     d_F = -lambda_F,    A_AA d_A = -y_A - A_AF d_F,
// whose second half we solve as (A_AA + mu_k I) d_A = -y_A - A_AF d_F by GMRES (core/gmres.hpp)
// on the principal block, one application of A per Arnoldi step. A caller that holds a sparse
// matrix P close to A (a working-set model's probed part, of which A is a low-rank
// correction; or A itself) passes it: GMRES is then right-preconditioned by a sparse Cholesky
// factorisation (Eigen's SimplicialLDLT) of P_AA + mu_k I, so that a large connected cluster,
// whose A conditions like a graph Laplacian, costs a few Arnoldi steps per direction instead
// of hundreds. A non-symmetric P (A itself, where A is a sparse Jacobian far from symmetric) is
// factorised by sparse LU instead. A direction first gets
// LcpOptions::gmres_unpreconditioned_steps (50) Arnoldi steps without it (a well-conditioned
// block, e.g. a model lifted by a diagonal shift, converges in those, and a factorisation would
// cost more than it saves); only then is P_AA + mu_k I factorised, and GMRES goes on from where
// it stopped. Once one direction of a solve has needed the factorisation, the solve's later
// directions with a new set A factorise at once: their blocks are the same problem's, and 50
// more unpreconditioned steps on each made the default solver's corrections on dense Brownian
// rods 1.15-1.45x slower (docs/results.md, "The working-set LCP's factorisations"). The
// factorisation is kept while the set A stays the same (mu_k changes, but a preconditioner
// need not be exact: GMRES's residual is the true one). Where a symmetric P's block is not
// positive definite, or a non-symmetric one's is singular, GMRES runs unpreconditioned. The proximal term
// mu_k = regularization c |H_k| / |H_0| (Levenberg-Marquardt style) keeps the block solvable
// when more contacts are active than A has rank, and vanishes as H -> 0. GMRES stops at the
// inexact-Newton tolerance eta_k = min(eta_cap, |H_k| / |H_0|), no tighter than the stopping
// rule needs; eta_cap starts at forcing_max and is cut a hundredfold after every damped step.
// Line 8: Armijo backtracking on the merit psi = 1/2 |min(lambda, y / c)|^2 along lambda + tau d.
// When d is not a descent direction for psi (GMRES too inexact, singular A_AA) or no step along
// it is accepted, a steepest-descent step on psi, d = -J^T H, is taken instead; when that fails
// too the solver stops and says so. It stops as well when its least merit has not halved over
// LcpOptions::stall_window Newton steps (50): a working-set model corrected by secants is not
// symmetric, need not be a P-matrix, and its LCP can have no solution; Newton then crawled on to
// max_iterations (1000 steps, each of ~40 GMRES products, on 600-760 pairs of dense Brownian
// rods at eta 0.45), where every LCP that converged on those rods, on Fig. 4 and on the dense
// contact networks had halved its merit within 50 steps but one (docs/results.md).
//
// Differences from Alg. 2, each measured on the tests' problems: the scale c (with c = 1 Newton
// stalled where A is far from unit scale); the proximal term (without it 12 of 79 problems with
// rank-deficient or cond 1e6-1e8 blocks did not converge, with it none); the line search does not
// project lambda(tau) onto lambda >= 0 (projected trials cost one application each and stalled
// on cond 1e4-1e6 problems): lambda is projected once the stopping rule is met, and convergence
// is then confirmed on the true w.
//
// Cost per Newton step: the GMRES applications (Arnoldi steps plus one true-residual check per
// cycle), plus one for A_AF lambda_F when lambda_F != 0 (after a damped step). A d itself is
// free: GMRES's last product is A at its returned x, which is kept; line-search trials update
// y by linearity. Plus one for c, plus one to confirm convergence on the true w = A gamma + b
// (the returned w is always exact), plus one for w0 under a nonzero warm start.
#include <algorithm>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>

#include "stokescontact/lcp/lcp.hpp"
#include "stokescontact/core/gmres.hpp"

namespace stokescontact {
namespace detail {

// lambda, y = A lambda + b, and whether y came from a true application (not a linear update).
struct MinimumMapState {
  VecX lambda, y;
  bool y_exact = true;
};

// min(lambda, y / c): the minimum map with y in the units of lambda.
inline VecX scaled_minimum_map(const VecX& lambda, const VecX& y, double c) { return lambda.cwiseMin(y / c); }

// A search direction d with A d, and the directional derivative of psi along it.
struct MinimumMapDirection {
  VecX d, Ad;
  double slope = 0.0;
};

// J d = (A d / c on the set A, d on the set F).
inline VecX jacobian_times(const std::vector<Eigen::Index>& active, const VecX& d, const VecX& Ad, double c) {
  VecX Jd = d;
  for (const Eigen::Index i : active) Jd(i) = Ad(i) / c;
  return Jd;
}

// P_AA + shift I: the principal block of a sparse matrix on the rows and columns `active`.
inline Eigen::SparseMatrix<double> shifted_principal_block(const Eigen::SparseMatrix<double>& P,
                                                           const std::vector<Eigen::Index>& active, double shift) {
  std::vector<Eigen::Index> position(static_cast<std::size_t>(P.rows()), -1);
  for (std::size_t j = 0; j < active.size(); ++j)
    position[static_cast<std::size_t>(active[j])] = static_cast<Eigen::Index>(j);
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t j = 0; j < active.size(); ++j) {
    entries.emplace_back(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(j), shift);
    for (Eigen::SparseMatrix<double>::InnerIterator it(P, active[j]); it; ++it)
      if (const Eigen::Index r = position[static_cast<std::size_t>(it.row())]; r >= 0)
        entries.emplace_back(r, static_cast<Eigen::Index>(j), it.value());
  }
  const auto m = static_cast<Eigen::Index>(active.size());
  Eigen::SparseMatrix<double> block(m, m);
  block.setFromTriplets(entries.begin(), entries.end());
  return block;
}

// (P_AA + mu I)^-1 for Newton's GMRES, factorised again only when the set A changes: by LDLT
// where P is symmetric, by sparse LU (Eigen's SparseLU, COLAMD ordering) where it is not.
class ActiveBlockPreconditioner {
 public:
  ActiveBlockPreconditioner(const Eigen::SparseMatrix<double>* P, bool symmetric) : P_(P), symmetric_(symmetric) {}

  bool available() const { return P_ != nullptr; }
  // Whether it is already that of `active`.
  bool factorised_for(const std::vector<Eigen::Index>& active) const {
    return factorisations_ > 0 && active == active_;
  }
  // Whether a direction of this solve has needed the factorisation (of any set A).
  bool factorised_before() const { return factorisations_ > 0; }
  int factorisations() const { return factorisations_; }

  // Makes the preconditioner that of `active` (mu: the shift when it must be factorised).
  void update(const std::vector<Eigen::Index>& active, double mu) {
    if (P_ == nullptr || factorised_for(active)) return;
    active_ = active;
    ++factorisations_;
    factor_.reset();
    lu_.reset();
    Eigen::SparseMatrix<double> block = shifted_principal_block(*P_, active, mu);
    if (symmetric_) {
      factor_.emplace(block);
      // LDLT also factorises indefinite blocks: only a positive diagonal makes it a preconditioner
      // of the positive definite A_AA + mu I that GMRES solves.
      if (factor_->info() != Eigen::Success || !(factor_->vectorD().minCoeff() > 0.0)) factor_.reset();
    } else {
      block.makeCompressed();
      lu_.emplace(block);  // a singular block: no preconditioner
      if (lu_->info() != Eigen::Success) lu_.reset();
    }
  }

  VecX operator()(const VecX& v) const {
    if (factor_) return factor_->solve(v);
    if (lu_) return lu_->solve(v);
    return v;
  }

 private:
  const Eigen::SparseMatrix<double>* P_;
  bool symmetric_;
  std::vector<Eigen::Index> active_;
  int factorisations_ = 0;
  std::optional<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>> factor_;
  std::optional<Eigen::SparseLU<Eigen::SparseMatrix<double>>> lu_;
};

// Alg. 2 line 7 on the reduced system: d_F = -lambda_F, (A_AA + mu I) d_A = -y_A - A_AF d_F by
// GMRES, right-preconditioned by `preconditioner` (made that of the set A here).
template <typename Op>
MinimumMapDirection newton_direction(Op& A, const MinimumMapState& s, const VecX& H,
                                     const std::vector<Eigen::Index>& active, double c, double mu, double eta,
                                     double threshold, const LcpOptions& options,
                                     ActiveBlockPreconditioner& preconditioner) {
  const Eigen::Index n = s.lambda.size();
  const auto m = static_cast<Eigen::Index>(active.size());
  MinimumMapDirection dir{VecX::Zero(n), VecX::Zero(n), 0.0};
  VecX lambda_F = s.lambda;
  for (const Eigen::Index i : active) lambda_F(i) = 0.0;
  if (!lambda_F.isZero(0.0)) {
    dir.d = -lambda_F;
    dir.Ad = -A(lambda_F);  // A P_F d
  }
  if (m > 0) {
    VecX rhs(m);
    for (Eigen::Index j = 0; j < m; ++j) rhs(j) = -s.y(active[j]) - dir.Ad(active[j]);
    VecX last_x, last_Ax;  // the last product A P_A x that GMRES asked for
    const auto A_AA = [&](const VecX& x) {
      VecX full = VecX::Zero(n);
      for (Eigen::Index j = 0; j < m; ++j) full(active[j]) = x(j);
      last_Ax = A(full);
      last_x = x;
      VecX out(m);
      for (Eigen::Index j = 0; j < m; ++j) out(j) = last_Ax(active[j]) + mu * x(j);  // (A_AA + mu I) x
      return out;
    };
    // No tighter than needed: a GMRES residual of threshold / 2 already meets the stopping rule.
    const double eta_floor = 0.5 * threshold / std::max(rhs.norm(), 1e-300);
    const GmresOptions gmres_options{std::min(options.forcing_max, std::max(eta, eta_floor)),
                                     options.gmres_max_iterations, options.gmres_restart};
    GmresResult solved;
    if (preconditioner.available() && !preconditioner.factorised_for(active)) {
      GmresOptions quick = gmres_options;
      quick.max_iterations = preconditioner.factorised_before()
                                 ? 0
                                 : std::min(quick.max_iterations, options.gmres_unpreconditioned_steps);
      if (quick.max_iterations == 0) {
        preconditioner.update(active, mu);
        solved = gmres(A_AA, rhs, preconditioner, gmres_options);
      } else if (solved = gmres(A_AA, rhs, quick); !solved.converged) {
        preconditioner.update(active, mu);
        const VecX start = solved.x;
        solved = gmres(A_AA, rhs, preconditioner, gmres_options, &start);
      }
    } else {
      solved = gmres(A_AA, rhs, preconditioner, gmres_options);
    }
    VecX full = VecX::Zero(n);
    for (Eigen::Index j = 0; j < m; ++j) full(active[j]) = solved.x(j);
    if (last_x.size() == m && last_x == solved.x)
      dir.Ad += last_Ax;  // GMRES's true-residual check was A at x: reuse it
    else if (!solved.x.isZero(0.0))
      dir.Ad += A(full);
    dir.d += full;
  }
  dir.slope = H.dot(jacobian_times(active, dir.d, dir.Ad, c));
  return dir;
}

// Steepest descent on psi: d = -J^T H = -(A P_A H / c + P_F H), with the first step from the
// linear model, tau0 = -H^T J d / |J d|^2 (two applications).
template <typename Op>
MinimumMapDirection merit_gradient_direction(Op& A, const VecX& H, const std::vector<Eigen::Index>& active, double c,
                                             double& tau0) {
  const Eigen::Index n = H.size();
  VecX H_A = VecX::Zero(n), grad = H;
  for (const Eigen::Index i : active) {
    H_A(i) = H(i);
    grad(i) = 0.0;
  }
  if (!H_A.isZero(0.0)) grad += A(H_A) / c;
  MinimumMapDirection dir{-grad, VecX::Zero(n), 0.0};
  if (!grad.isZero(0.0)) dir.Ad = A(dir.d);
  const VecX Jd = jacobian_times(active, dir.d, dir.Ad, c);
  dir.slope = H.dot(Jd);
  tau0 = Jd.squaredNorm() > 0.0 ? -dir.slope / Jd.squaredNorm() : 0.0;
  return dir;
}

// Alg. 2 line 8: Armijo backtracking on psi along lambda + tau d, halving tau from tau0; y
// follows by linearity, so trials are free. Updates s and returns the accepted tau, 0 if none.
inline double armijo_step(MinimumMapState& s, const MinimumMapDirection& dir, double psi, double c, double tau0,
                          int max_steps) {
  constexpr double kArmijo = 1e-4;
  double tau = tau0;
  for (int t = 0; t < max_steps; ++t, tau *= 0.5) {
    VecX lambda = s.lambda + tau * dir.d;
    VecX y = s.y + tau * dir.Ad;
    if (0.5 * scaled_minimum_map(lambda, y, c).squaredNorm() <= psi + kArmijo * tau * dir.slope) {
      s.lambda = std::move(lambda);
      s.y = std::move(y);
      s.y_exact = false;
      return tau;
    }
  }
  return 0.0;
}

// Whether the least merit has not halved over the last `window` Newton steps (best_psi[k]: the
// least psi up to step k; window 0: never).
inline bool stalled(const std::vector<double>& best_psi, int window) {
  const auto w = static_cast<std::size_t>(window);
  return window > 0 && best_psi.size() > w && best_psi.back() > 0.5 * best_psi[best_psi.size() - 1 - w];
}

}  // namespace detail

// `preconditioner`, when given: a sparse matrix close to A (same size), whose principal blocks
// precondition the Newton directions' GMRES (see the top of this file); symmetric, or not
// (`preconditioner_symmetric` false: factorised by sparse LU, e.g. A itself where A is a
// non-symmetric sparse matrix).
template <LcpMatrixOperator ApplyA>
LcpResult solve_lcp_minimum_map_newton(ApplyA&& apply_A, const VecX& b, const LcpOptions& options = {},
                                       const VecX* warm_start = nullptr,
                                       const Eigen::SparseMatrix<double>* preconditioner = nullptr,
                                       bool preconditioner_symmetric = true) {
  detail::LcpSolve<std::remove_reference_t<ApplyA>> solve(apply_A, b, options, warm_start);
  if (preconditioner != nullptr && (preconditioner->rows() != b.size() || preconditioner->cols() != b.size()))
    fail_argument("preconditioner", "is " + std::to_string(preconditioner->rows()) + " x " +
                                        std::to_string(preconditioner->cols()) + ", b has size " +
                                        std::to_string(b.size()));
  auto& A = solve.A;
  detail::MinimumMapState s{solve.gamma0, solve.w0, true};
  if (solve.converged(s.lambda, s.y)) return solve.finish(std::move(s.lambda), std::move(s.y), 0);
  // Back onto lambda >= 0 (iterates may leave it: the line search does not project).
  const auto project = [&s] {
    if (s.lambda.minCoeff() < 0.0) {
      s.lambda = detail::project_nonnegative(s.lambda);
      s.y_exact = false;
    }
  };

  const VecX p = detail::minimum_map(s.lambda, s.y);
  const double c = detail::curvature_estimate(A, p, A(p));
  if (!(c > 0.0)) return solve.finish(std::move(s.lambda), std::move(s.y), 0);  // A = 0: no scale
  const double threshold = options.tolerance * solve.b_scale;  // on ||min(gamma, w)||_inf
  const double H0_norm = detail::scaled_minimum_map(s.lambda, s.y, c).norm();
  double eta_cap = options.forcing_max;
  detail::ActiveBlockPreconditioner block_preconditioner(preconditioner, preconditioner_symmetric);
  const auto finish = [&](int iterations) {
    LcpResult out = solve.finish(std::move(s.lambda), std::move(s.y), iterations, s.y_exact);
    out.preconditioner_factorisations = block_preconditioner.factorisations();
    return out;
  };
  std::vector<double> best_psi;  // the least merit up to each Newton step, for the stall window
  int k = 0;
  for (;;) {
    if (solve.converged(s.lambda, s.y)) {
      project();
      if (solve.confirmed_converged(s.lambda, s.y, s.y_exact)) return finish(k);
    }
    if (k == options.max_iterations) break;
    ++k;
    const VecX H = detail::scaled_minimum_map(s.lambda, s.y, c);
    const double psi = 0.5 * H.squaredNorm();
    best_psi.push_back(best_psi.empty() ? psi : std::min(psi, best_psi.back()));
    if (detail::stalled(best_psi, options.stall_window)) break;
    std::vector<Eigen::Index> active;  // Alg. 2 line 5: {i : y_i < c lambda_i}
    for (Eigen::Index i = 0; i < H.size(); ++i)
      if (s.y(i) < c * s.lambda(i)) active.push_back(i);

    const double eta = std::min(eta_cap, H.norm() / H0_norm);  // inexact-Newton forcing term
    const double mu = options.regularization * c * H.norm() / H0_norm;  // proximal term, -> 0 with H
    const detail::MinimumMapDirection newton =
        detail::newton_direction(A, s, H, active, c, mu, eta, threshold, options, block_preconditioner);
    const double tau =
        newton.slope < 0.0 ? detail::armijo_step(s, newton, psi, c, 1.0, options.max_line_search_steps) : 0.0;
    if (tau < 1.0) eta_cap *= 0.01;  // a damped step: ask for more accurate directions
    if (tau > 0.0) continue;
    double tau0 = 0.0;
    const detail::MinimumMapDirection descent = detail::merit_gradient_direction(A, H, active, c, tau0);
    if (!(descent.slope < 0.0 && tau0 > 0.0 &&
          detail::armijo_step(s, descent, psi, c, tau0, options.max_line_search_steps) > 0.0))
      break;  // stalled: no step decreases psi
  }
  project();
  return finish(k);
}

}  // namespace stokescontact
