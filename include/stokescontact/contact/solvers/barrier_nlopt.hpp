#pragma once
// The barrier method of Broms & Tornberg (eq. 15) with NLopt:
//     min_{lambda >= 0} sum_k lambda_k   s.t.   E(lambda) = sum_k b(d_k(Q(lambda))) = 0,
// b of eq. 10 with eps_reg = d_try by default (Remark 4; Sec. 2.3, the paper's choice; eps_cap = 1e-2
// (d_hat + eps_reg) keeps b finite for overlaps), Q(lambda) = Q_t + dt Psi (U + M D lambda).
// Since b >= 0, E = 0 is posed as the inequality E <= 0 (the same feasible set; MMA accepts
// only inequalities).
//
// Gradient by the chain rule: dE/dlambda = sum_k b'(d_k) dd_k/dlambda, and to first order in
// dt (the exponential map's rotation taken as its linearisation dt omega) dd_k/dlambda =
// dt D_k^T M D with D_k the contact matrix of the flagged pairs at Q(lambda), so
//     grad E = dt (M D)^T D_k b'(d)   (M symmetric: dt D^T M (D_k b')),
// one mobility application in matrix_free mode, free once M D is formed; none where every
// b' = 0. Each barrier-energy evaluation costs one application for M D lambda (matrix_free).
//
// Objective (eq. 14-15, Sec. 3.1.2): sum_k lambda_k by default, or the dissipation
// lambda^T D^T M D lambda = (D lambda) . (M D lambda), gradient 2 D^T (M D lambda). Both come
// from the evaluation at lambda that the constraint needs too (cached): no extra application.
//
// Variables are scaled, lambda = s x with s = d_try / (dt c), c = v^T D^T M D v / v^T v for
// v = 1 (one application, or free once formed), so x is O(1) for a typical correction.
//
// Stopping rule eq. 29, applied to successive barrier-energy evaluations: stop at the first
// evaluation with max_k |lambda_k - lambda_k^prev| < TOL ||lambda||_inf whose flagged pairs all
// satisfy d >= d_hat (1 - separation_margin). NLopt's own limits (max evaluations, xtol) back
// it up; the cheapest separated point seen is returned when NLopt stops first.
// Iterations reported: barrier-energy evaluations (NLopt does not expose its iterations).
//
// BarrierConstraint::working_set poses the same eq. 15 pair by pair on the default solver's
// working-set model instead (barrier_working_set.hpp): NLopt's evaluations then cost no
// mobility application, and the result separates to d_hat (1 + margin), measured.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlopt.hpp>

#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/contact/solvers/barrier_working_set.hpp"

namespace stokescontact {

// SLSQP (gradient, the default), MMA (gradient, CCSA), COBYLA (derivative-free: fine for a
// handful of pairs, but in our tests it needs more than 1000 evaluations from Nc ~ 20 on).
enum class BarrierOptimizer { slsqp, cobyla, mma };

// The norm of lambda that eq. 15 minimises (eq. 14).
enum class BarrierObjective { lambda_sum, dissipation };

// How eq. 15's constraint E(lambda) = 0 reaches NLopt: as the paper's scalar barrier energy of
// the flagged pairs, evaluated at every iterate (one mobility application each), or as its
// per-pair form d_k >= d_hat on the working-set model, corrected by the true distances
// (barrier_working_set.hpp; the default solver's applications).
enum class BarrierConstraint { energy, working_set };

struct BarrierNloptOptions {
  BarrierOptimizer optimizer = BarrierOptimizer::slsqp;
  BarrierObjective objective = BarrierObjective::lambda_sum;
  BarrierConstraint constraint = BarrierConstraint::energy;
  double tol = 1e-2;                 // eq. 29 (working_set: on successive corrections)
  double eps_reg = -1.0;             // < 0: d_try (Remark 4, Sec. 2.3); energy only
  int max_evaluations = 1000;        // NLopt evaluations per round (energy: barrier energies,
                                     // each an application) or per model problem (working_set)
  double cap_fraction = 1e-2;        // eps_cap = cap_fraction (d_hat + eps_reg); energy only

  void validate() const {
    require_positive(tol, "BarrierNloptOptions.tol");
    require_finite(eps_reg, "BarrierNloptOptions.eps_reg");
    if (max_evaluations < 1)
      fail_argument("BarrierNloptOptions.max_evaluations", "must be >= 1, got " + std::to_string(max_evaluations));
    if (!(cap_fraction > 0.0 && cap_fraction < 1.0))
      fail_argument("BarrierNloptOptions.cap_fraction", "must lie in (0, 1), got " + std::to_string(cap_fraction));
    // MMA took more than 7 minutes for one step of 100 spheres at 55% (about 250 flagged pairs)
    // on the working set's model problems, where SLSQP takes a second; COBYLA has no gradients.
    if (constraint == BarrierConstraint::working_set && optimizer != BarrierOptimizer::slsqp)
      fail_argument("BarrierNloptOptions.optimizer", "the working-set constraint needs SLSQP");
  }
};

namespace detail {

inline nlopt::algorithm nlopt_algorithm(BarrierOptimizer o) {
  switch (o) {
    case BarrierOptimizer::slsqp: return nlopt::LD_SLSQP;
    case BarrierOptimizer::cobyla: return nlopt::LN_COBYLA;
    case BarrierOptimizer::mma: return nlopt::LD_MMA;
  }
  return nlopt::LD_SLSQP;
}

// The state NLopt's callbacks share for one round.
template <Shape S, MobilityOperator M>
struct BarrierRound {
  BarrierRound(ContactStep<S, M>& s, const BarrierNloptOptions& o) : step(s), options(o) {}

  ContactStep<S, M>& step;
  const BarrierNloptOptions& options;
  nlopt::opt* opt = nullptr;
  BarrierParameters barrier;
  double scale = 1.0;    // lambda = scale x
  double curvature = 1.0;  // 1^T D^T M D 1 / Nc
  double energy_scale = 1.0;
  int evaluations = 0;
  std::optional<VecX> previous;  // lambda at the previous evaluation
  std::optional<VecX> stopped_at;  // where eq. 29 stopped the optimiser
  std::optional<VecX> best;        // cheapest separated lambda seen
  double best_sum = std::numeric_limits<double>::infinity();

  // E(lambda) / energy_scale and its gradient in x; applies eq. 29.
  double constraint(const std::vector<double>& x, std::vector<double>& grad) {
    const VecX lambda = scale * Eigen::Map<const VecX>(x.data(), static_cast<Eigen::Index>(x.size()));
    const ContactEvaluation& e = step.evaluate(lambda);
    ++evaluations;
    double energy = 0.0;
    VecX slope(e.distances.size());
    for (Eigen::Index k = 0; k < slope.size(); ++k) {
      const BarrierValue b = stokescontact::barrier(BarrierFunction::b, e.distances(k), barrier);
      energy += b.value;
      slope(k) = b.first;
    }
    if (!grad.empty()) {
      const VecX Dk_slope = step.contact_matrix_at(e) * slope;
      const VecX g = (scale * step.problem().dt / energy_scale) * step.MD_transpose_times(Dk_slope);
      Eigen::Map<VecX>(grad.data(), g.size()) = g;
    }
    const bool separated = step.all_separated(e);
    if (separated && lambda.sum() < best_sum) {
      best_sum = lambda.sum();
      best = lambda;
    }
    const double lambda_inf = lambda.size() == 0 ? 0.0 : lambda.cwiseAbs().maxCoeff();
    if (separated && previous && (lambda - *previous).cwiseAbs().maxCoeff() < options.tol * lambda_inf) {
      stopped_at = lambda;  // eq. 29
      opt->force_stop();
    }
    previous = lambda;
    return energy / energy_scale;
  }

  // sum x_k, or the dissipation in units of scale^2 c (c the curvature along 1, so both are
  // O(Nc) for x = 1).
  double objective(const std::vector<double>& x, std::vector<double>& grad) {
    const Eigen::Map<const VecX> xs(x.data(), static_cast<Eigen::Index>(x.size()));
    if (options.objective == BarrierObjective::lambda_sum) {
      if (!grad.empty()) std::fill(grad.begin(), grad.end(), 1.0);
      return xs.sum();
    }
    const ContactEvaluation& e = step.evaluate(scale * xs);
    const VecX D_lambda = step.D() * e.lambda;
    const double unit = scale * scale * curvature;
    if (!grad.empty()) {
      const VecX g = step.D_transpose_times(e.MD_lambda, 2.0 * scale / unit);
      Eigen::Map<VecX>(grad.data(), g.size()) = g;
    }
    return D_lambda.dot(e.MD_lambda) / unit;
  }

  static double objective_callback(const std::vector<double>& x, std::vector<double>& grad, void* data) {
    return static_cast<BarrierRound*>(data)->objective(x, grad);
  }

  static double constraint_callback(const std::vector<double>& x, std::vector<double>& grad, void* data) {
    return static_cast<BarrierRound*>(data)->constraint(x, grad);
  }
};

template <Shape S, MobilityOperator M>
ContactSolveOutcome solve_barrier_round(ContactStep<S, M>& step, const VecX& warm, const BarrierNloptOptions& options) {
  ContactSolveOutcome out;
  out.lambda = warm;
  const Eigen::Index nc = step.nc();
  if (nc == 0 || step.all_separated(step.evaluate(warm))) {
    out.converged = true;
    return out;
  }
  const double d_hat = step.problem().d_hat, dt = step.problem().dt;
  BarrierRound<S, M> round(step, options);
  round.barrier = barrier_parameters(d_hat, options.eps_reg < 0.0 ? step.d_try() : options.eps_reg,
                                     options.cap_fraction);
  const VecX ones = VecX::Ones(nc);
  const double c = VecX(step.D() * ones).dot(step.MD_times(ones)) / static_cast<double>(nc);
  round.scale = c > 0.0 ? step.d_try() / (dt * c) : 1.0;
  round.curvature = c > 0.0 ? c : 1.0;
  round.energy_scale = d_hat * d_hat;

  nlopt::opt opt(nlopt_algorithm(options.optimizer), static_cast<unsigned>(nc));
  round.opt = &opt;
  opt.set_min_objective(&BarrierRound<S, M>::objective_callback, &round);
  opt.add_inequality_constraint(&BarrierRound<S, M>::constraint_callback, &round, 0.0);  // E <= 0, eq. 15
  opt.set_lower_bounds(0.0);
  opt.set_maxeval(options.max_evaluations);
  opt.set_xtol_rel(1e-12);
  opt.set_initial_step(1.0);
  std::vector<double> x(static_cast<std::size_t>(nc));
  for (Eigen::Index k = 0; k < nc; ++k) x[static_cast<std::size_t>(k)] = warm(k) / round.scale;
  double f = 0.0;
  std::string stop;
  try {
    const nlopt::result res = opt.optimize(x, f);
    stop = "NLopt result " + std::to_string(static_cast<int>(res));
  } catch (const nlopt::forced_stop&) {
    stop = "eq. 29";
  } catch (const std::exception& ex) {  // roundoff_limited, failure
    stop = std::string("NLopt stopped: ") + ex.what();
  }
  out.iterations = round.evaluations;
  if (round.stopped_at) {
    out.lambda = *round.stopped_at;
    out.converged = true;
    return out;
  }
  const VecX final_lambda = round.scale * Eigen::Map<const VecX>(x.data(), nc);
  out.lambda = round.best ? *round.best : final_lambda.cwiseMax(0.0);
  out.converged = round.best.has_value();
  out.message = "barrier (" + stop + ") after " + std::to_string(round.evaluations) + " evaluations" +
                (round.best ? ", cheapest separated point returned" : ", no separated point found");
  return out;
}

}  // namespace detail

template <Shape S, MobilityOperator M>
ContactStepResult solve_contact_step_barrier(const ContactStepProblem<S>& problem, M& mobility,
                                             const ContactStepOptions& options = {},
                                             const BarrierNloptOptions& barrier = {}) {
  barrier.validate();
  if (barrier.constraint == BarrierConstraint::working_set) {
    DefectCorrectionOptions corrections;
    corrections.tol = barrier.tol;
    corrections.lcp_forcing = 0.0;  // every LCP to 1e-12: its answer starts SLSQP, whose dense solve is the cost
    corrections.bbpgd_on_exact_model = false;  // eq. 15 is not an LCP: the Jacobian at the iterate serves it
    const detail::WorkingSetBarrier subproblem{detail::nlopt_algorithm(barrier.optimizer),
                                               barrier.objective == BarrierObjective::dissipation,
                                               barrier.max_evaluations, corrections.lcp};
    return run_contact_step(problem, mobility, options, [&](ContactStep<S, M>& step, const VecX& warm) {
      subproblem.complementarity_corrections = 0;
      ContactSolveOutcome out = detail::solve_defect_correction_round(step, warm, corrections, subproblem);
      if (subproblem.complementarity_corrections > 0)
        out.message += (out.message.empty() ? "" : "; ") + std::string(subproblem.name) + ": the smallest sum did not settle in " +
                       std::to_string(subproblem.smallest_sum_corrections) + " corrections, the last " +
                       std::to_string(subproblem.complementarity_corrections) + " solved the LCP (complementarity)";
      if (out.converged) return out;
      // The default solver's round from the same warm start: complementarity, separated. (The
      // round may have added pairs: DefectCorrectionOptions::early_end_check.)
      ContactSolveOutcome lcp = detail::solve_defect_correction_round(step, detail::padded(warm, step.nc()), corrections,
                                                                      detail::WorkingSetLcp{corrections.lcp, subproblem.name});
      lcp.iterations += out.iterations;
      lcp.message = std::string(subproblem.name) + ": the smallest sum was not reached (" + out.message +
                    "), solved again to complementarity" + (lcp.message.empty() ? "" : ": " + lcp.message);
      return lcp;
    });
  }
  return run_contact_step(problem, mobility, options, [&barrier](ContactStep<S, M>& step, const VecX& warm) {
    return detail::solve_barrier_round(step, warm, barrier);
  });
}

}  // namespace stokescontact
