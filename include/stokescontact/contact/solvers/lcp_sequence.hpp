#pragma once
// The contact step as a sequence of LCPs (Lu et al. Alg. 1; Broms & Tornberg eq. 25-27 with d^P).
//
// The nonlinear complementarity problem (Broms eq. 27)
//     0 <= lambda  _|_  d(lambda) - d_hat >= 0,   d(lambda) = d^P(Q(lambda)),
// is linearised about the current iterate lambda_k, where the distances d_k = d(lambda_k) are
// exact. With Q(lambda) = Q_t + dt Psi (U + M D lambda), to first order in dt,
//     d(lambda) ~ d_k + dt D_k^T M D (lambda - lambda_k),
// D_k being the contact matrix of the flagged pairs at Q(lambda_k) (D_k^T U = rate of change
// of d). We replace D_k^T by D^T (D at Q*, exact at k = 0, where Q(0) = Q*), which keeps
//     A = dt D^T M D   symmetric positive semi-definite
// so the CQP solvers (BBPGD, APGD) apply, and solve for the total lambda
//     0 <= lambda  _|_  A lambda + b_k >= 0,   b_k = d_k - d_hat - A lambda_k,
// warm-started at lambda_k (A lambda_k = dt D^T (M D lambda_k) is free: Q(lambda_k) needed
// M D lambda_k). Then lambda_{k+1} is re-measured at Q(lambda_{k+1}) and the loop repeats until
// every flagged pair has d >= d_hat (1 - separation_margin). A fixed point solves Broms eq. 27
// exactly, whatever the Jacobian approximation, since b_k uses the true distances. For spheres
// without torques one LCP suffices: a centre distance is convex in the displacements, so the
// linear model never overestimates d.
//
// Cost per outer iteration: the LCP's applications of A (one mobility application each in
// matrix_free mode, free once M D is formed) plus one for M D lambda_{k+1} (matrix_free).
// Iterations reported: outer LCPs solved.
#include <algorithm>
#include <limits>
#include <string>
#include <utility>

#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/lcp/apgd.hpp"
#include "stokescontact/lcp/bbpgd.hpp"
#include "stokescontact/lcp/minimum_map_newton.hpp"
#include "stokescontact/lcp/model_started_newton.hpp"

namespace stokescontact {

enum class InnerLcpSolver { bbpgd, apgd, minimum_map_newton };

struct LcpSequenceOptions {
  InnerLcpSolver inner = InnerLcpSolver::minimum_map_newton;
  LcpOptions lcp{1e-8};  // each LCP's stopping rule (lcp.hpp)
  int max_iterations = 20;  // LCPs per round
  // By default the sequence stops at its first separated iterate, which for spheres is the
  // first LCP, whose linear model underestimates the distances: pushed pairs may end above
  // d_hat (forces a few per cent too large in dense packings). With tol > 0 it goes on until
  // an LCP changes lambda by less than tol ||lambda||_inf (Broms eq. 29), aiming at d_hat (1 +
  // margin) and then requiring d >= d_hat itself.
  double tol = 0.0;
  double margin = 0.0;
  // Inexact LCPs, a forcing term as in inexact Newton (Eisenstat & Walker 1996): from the
  // second LCP of a round on, an LCP is solved only until its residual is below `forcing`
  // times the round's shortfall v_k = d_hat (1 + margin) - min d_k (both in distance units:
  // LcpOptions::tolerance, relative to ||b_k||_inf, becomes max(lcp.tolerance,
  // min(kForcingCap, forcing v_k / ||b_k||_inf))). The sequence still stops on the true
  // distances, so what it guarantees is unchanged; an iterate far from separation is not
  // solved to 1e-8 only to be re-linearised. The first LCP (the only one for spheres) and every
  // LCP of a polishing sequence (tol > 0, aiming at complementarity) are solved to
  // lcp.tolerance. 0: every LCP to lcp.tolerance. (400 Brownian rods at eta 0.44, 40 steps:
  // 1.3-1.6x less time for lcp-newton, lcp-apgd and lcp-bbpgd at the same LCP count, S after
  // them the same to 4 digits; matrix-free, 3.75x fewer applications of A; docs/results.md,
  // "Inexact LCPs in the sequence".)
  double forcing = 0.01;
  static constexpr double kForcingCap = 1e-2;  // never looser than 1% of ||b_k||_inf

  void validate() const {
    lcp.validate();
    if (max_iterations < 1)
      fail_argument("LcpSequenceOptions.max_iterations", "must be >= 1, got " + std::to_string(max_iterations));
    require_non_negative(tol, "LcpSequenceOptions.tol");
    require_non_negative(margin, "LcpSequenceOptions.margin");
    if (!(forcing >= 0.0 && forcing < 1.0))
      fail_argument("LcpSequenceOptions.forcing", "must lie in [0, 1), got " + std::to_string(forcing));
  }
};

namespace detail {

template <typename ApplyA>
LcpResult solve_inner_lcp(InnerLcpSolver solver, ApplyA& A, const VecX& b, const LcpOptions& options,
                          const VecX& warm_start) {
  switch (solver) {
    case InnerLcpSolver::bbpgd: return solve_lcp_bbpgd(A, b, options, &warm_start);
    case InnerLcpSolver::apgd: return solve_lcp_apgd(A, b, options, &warm_start);
    case InnerLcpSolver::minimum_map_newton: return solve_lcp_minimum_map_newton(A, b, options, &warm_start);
  }
  return {};
}

// The stopping rule of the `lcp`-th LCP of a round (1-based) whose shortfall is `shortfall`
// and right-hand side b (LcpSequenceOptions::forcing).
inline LcpOptions inexact_lcp_options(const LcpSequenceOptions& options, int lcp, double shortfall, const VecX& b) {
  LcpOptions out = options.lcp;
  const double scale = b.lpNorm<Eigen::Infinity>();
  if (lcp > 1 && options.tol == 0.0 && options.forcing > 0.0 && shortfall > 0.0 && scale > 0.0)
    out.tolerance = std::max(out.tolerance, std::min(LcpSequenceOptions::kForcingCap, options.forcing * shortfall / scale));
  return out;
}

// One round of the sequence, from lambda_0 = warm_start. `model`, when given: a sparse
// symmetric positive definite matrix close to A on all flagged pairs (the default solver's
// probed model, when it hands a round over); minimum-map Newton then starts each LCP from
// BBPGD on the model and is preconditioned by it (model_started_newton.hpp), which costs no
// application of A. The other inner solvers do not use it.
template <Shape S, MobilityOperator M>
ContactSolveOutcome solve_lcp_sequence_round(ContactStep<S, M>& step, VecX lambda, const LcpSequenceOptions& options,
                                             const Eigen::SparseMatrix<double>* model = nullptr) {
  ContactSolveOutcome out;
  const double d_hat = step.problem().d_hat, target = d_hat * (1.0 + options.margin);
  const bool polish = options.tol > 0.0;
  auto A = [&step](const VecX& x) { return step.A_times(x); };
  double change = std::numeric_limits<double>::infinity();
  for (;;) {
    const ContactEvaluation& e = step.evaluate(lambda);
    const bool separated = polish ? e.min_distance() >= d_hat : step.all_separated(e);
    if (separated && (!polish || change <= options.tol * lambda.lpNorm<Eigen::Infinity>())) {
      out.converged = true;
      break;
    }
    if (out.iterations == options.max_iterations) {
      out.message = "LCP sequence: " + std::to_string(out.iterations) + " LCPs, min flagged d / d_hat = " +
                    std::to_string(e.min_distance() / d_hat);
      break;
    }
    ++out.iterations;
    const VecX A_lambda = step.D_transpose_times(e.MD_lambda, step.problem().dt);
    const VecX b = e.distances - VecX::Constant(step.nc(), target) - A_lambda;
    const LcpOptions lcp_options = inexact_lcp_options(options, out.iterations, target - e.min_distance(), b);
    LcpResult lcp =
        model && options.inner == InnerLcpSolver::minimum_map_newton
            ? solve_lcp_newton_from_model(A, b, *model, VecX(e.distances - VecX::Constant(step.nc(), target) - *model * lambda),
                                          lcp_options, lambda)
            : solve_inner_lcp(options.inner, A, b, lcp_options, lambda);
    if (lcp.gamma == lambda) {  // the LCP has nothing left to change: stalled
      out.message = "LCP sequence stalled after " + std::to_string(out.iterations) + " LCPs, min flagged d / d_hat = " +
                    std::to_string(e.min_distance() / d_hat);
      break;
    }
    change = (lcp.gamma - lambda).lpNorm<Eigen::Infinity>();
    lambda = std::move(lcp.gamma);
  }
  out.lambda = std::move(lambda);
  return out;
}

}  // namespace detail

template <Shape S, MobilityOperator M>
ContactStepResult solve_contact_step_lcp_sequence(const ContactStepProblem<S>& problem, M& mobility,
                                                  const ContactStepOptions& options = {},
                                                  const LcpSequenceOptions& sequence = {}) {
  sequence.validate();
  return run_contact_step(problem, mobility, options, [&sequence](ContactStep<S, M>& step, const VecX& warm) {
    return detail::solve_lcp_sequence_round(step, warm, sequence);
  });
}

}  // namespace stokescontact
