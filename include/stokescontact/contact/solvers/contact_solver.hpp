#pragma once
// Choosing a contact solver by value, and `solve_contact_step`, the name users call.
//
// A `ContactSolver` is the options struct of one of the library's solvers; which alternative
// it holds says which solver runs:
//   DefectCorrectionOptions   the default: Broms eq. 27 by defect correction (defect_correction.hpp);
//                             a step it fails is solved again: a far root (a turn above
//                             ContactStepOptions::max_correction_turn) by barrier-working-set
//                             where NLopt is there and the step has at most
//                             far_root_fallback_max_pairs flagged pairs, then any failure by the LCP sequence
//                             (solve_failed_step_again)
//   LcpSequenceOptions        the NCP as a sequence of LCPs (Lu et al. Alg. 1; lcp_sequence.hpp)
//   BarrierNloptOptions       the barrier method, Broms eq. 15 with NLopt (barrier_nlopt.hpp); only
//                             where the library was configured with NLopt
//                             (STOKESCONTACT_HAS_NLOPT)
// Every solver returns the same ContactStepResult. Drivers and scene files name a solver by a
// string (contact_solver_from_name): "default", "lcp-bbpgd", "lcp-apgd", "lcp-newton",
// "barrier-slsqp", "barrier-mma", "barrier-cobyla" (the paper's scalar constraint), and
// "barrier-working-set" (eq. 15 pair by pair on the working-set model with SLSQP, TOL 1e-4 as
// the default solver's).
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "stokescontact/contact/solvers/defect_correction.hpp"
#include "stokescontact/contact/solvers/lcp_sequence.hpp"
#if STOKESCONTACT_HAS_NLOPT
#include "stokescontact/contact/solvers/barrier_nlopt.hpp"
#endif

namespace stokescontact {

using ContactSolver = std::variant<DefectCorrectionOptions, LcpSequenceOptions
#if STOKESCONTACT_HAS_NLOPT
                                   ,
                                   BarrierNloptOptions
#endif
                                   >;

namespace detail {

struct NamedContactSolver {
  std::string_view name;
  ContactSolver (*make)();
};

template <InnerLcpSolver Inner>
ContactSolver lcp_sequence_with() {
  LcpSequenceOptions o;
  o.inner = Inner;
  return o;
}

#if STOKESCONTACT_HAS_NLOPT
template <BarrierOptimizer Optimizer>
ContactSolver barrier_with() {
  BarrierNloptOptions o;
  o.optimizer = Optimizer;
  return o;
}

inline ContactSolver barrier_working_set() {
  BarrierNloptOptions o;
  o.constraint = BarrierConstraint::working_set;
  o.tol = DefectCorrectionOptions{}.tol;
  return o;
}
#endif

inline constexpr std::array kNamedContactSolvers{
    NamedContactSolver{"default", [] { return ContactSolver{DefectCorrectionOptions{}}; }},
    NamedContactSolver{"lcp-bbpgd", &lcp_sequence_with<InnerLcpSolver::bbpgd>},
    NamedContactSolver{"lcp-apgd", &lcp_sequence_with<InnerLcpSolver::apgd>},
    NamedContactSolver{"lcp-newton", &lcp_sequence_with<InnerLcpSolver::minimum_map_newton>},
#if STOKESCONTACT_HAS_NLOPT
    NamedContactSolver{"barrier-slsqp", &barrier_with<BarrierOptimizer::slsqp>},
    NamedContactSolver{"barrier-mma", &barrier_with<BarrierOptimizer::mma>},
    NamedContactSolver{"barrier-cobyla", &barrier_with<BarrierOptimizer::cobyla>},
    NamedContactSolver{"barrier-working-set", &barrier_working_set},
#endif
};

}  // namespace detail

// The names contact_solver_from_name knows, in a fixed order ("default" first).
inline std::vector<std::string> contact_solver_names() {
  std::vector<std::string> names;
  for (const detail::NamedContactSolver& s : detail::kNamedContactSolvers) names.emplace_back(s.name);
  return names;
}

// The solver called `name` with its default options; std::invalid_argument listing the known
// names otherwise (a barrier name in a build without NLopt says so).
inline ContactSolver contact_solver_from_name(std::string_view name) {
  for (const detail::NamedContactSolver& s : detail::kNamedContactSolvers)
    if (s.name == name) return s.make();
  std::string known;
  for (const std::string& n : contact_solver_names()) known += (known.empty() ? "" : ", ") + n;
  std::string why = "unknown solver '" + std::string(name) + "' (known: " + known + ")";
#if !STOKESCONTACT_HAS_NLOPT
  if (name.starts_with("barrier-")) why += "; the barrier solvers need the library built with NLopt";
#endif
  fail_argument("solver", why);
}

// The name of a solver value, as contact_solver_from_name reads it.
inline std::string contact_solver_name(const ContactSolver& solver) {
  return std::visit(
      [](const auto& o) -> std::string {
        using O = std::decay_t<decltype(o)>;
        if constexpr (std::is_same_v<O, DefectCorrectionOptions>) {
          return "default";
        } else if constexpr (std::is_same_v<O, LcpSequenceOptions>) {
          switch (o.inner) {
            case InnerLcpSolver::bbpgd: return "lcp-bbpgd";
            case InnerLcpSolver::apgd: return "lcp-apgd";
            case InnerLcpSolver::minimum_map_newton: return "lcp-newton";
          }
          return "lcp";
        }
#if STOKESCONTACT_HAS_NLOPT
        else {
          if (o.constraint == BarrierConstraint::working_set) return "barrier-working-set";  // SLSQP (validate)
          switch (o.optimizer) {
            case BarrierOptimizer::slsqp: return "barrier-slsqp";
            case BarrierOptimizer::mma: return "barrier-mma";
            case BarrierOptimizer::cobyla: return "barrier-cobyla";
          }
          return "barrier";
        }
#endif
      },
      solver);
}

// The Broms eq. 29 stopping tolerance TOL of a solver that has one (default, barrier); the LCP
// sequence's own stops at its first separated iterate by default (tol = 0), so it reports none.
inline std::optional<double> stopping_tolerance(const ContactSolver& solver) {
  return std::visit(
      [](const auto& o) -> std::optional<double> {
        if constexpr (std::is_same_v<std::decay_t<decltype(o)>, LcpSequenceOptions>)
          return o.tol > 0.0 ? std::optional<double>(o.tol) : std::nullopt;
        else
          return o.tol;
      },
      solver);
}

// Sets TOL (Broms eq. 29) on any solver: the LCP sequence then iterates to it as well.
inline void set_stopping_tolerance(ContactSolver& solver, double tol) {
  require_positive(tol, "tol");
  std::visit([tol](auto& o) { o.tol = tol; }, solver);
}

namespace detail {

// A message without its trailing separator.
inline std::string trimmed(std::string message) {
  while (!message.empty() && (message.back() == ';' || message.back() == ' ')) message.pop_back();
  return message;
}

// A step the default solver failed (failed_separation; not one refused before its solve,
// ContactStepResult::refused, which every solver would refuse alike) solved again by other
// solvers, in order, the first answer that does not fail kept (DefectCorrectionOptions::far_root_fallback,
// lcp_sequence_fallback):
//  - a far root (a correction turning a body by more than ContactStepOptions::
//    max_correction_turn) by eq. 15 on the working set (barrier-working-set, the same
//    corrections and TOL; with NLopt). Eq. 13 is linear in the rotation, so a pair of crossing
//    rods can have a near root and one far along the force that turns a rod by radians; the
//    defect correction, which follows complementarity from the LCP of its model, can end at
//    the far one, where the smallest sum of lambda finds the near one
//    (tests/contact/test_crossing_rods.cpp);
//  - any failure by the LCP sequence (lcp-newton: exact products, no probing, no ray search),
//    whose LCPs hold contact networks where the corrections stall.
// Each solve starts afresh (its probes cost again). The result counts the applications,
// iterations, wall time (and its phases) and broad-phase queries of every solve; its `fallback` names the solver
// whose answer it is (empty: every fallback failed too, and the default solver's failure is
// returned, with theirs in its message).
template <Shape S, MobilityOperator M>
ContactStepResult solve_failed_step_again(const ContactStepProblem<S>& problem, M& mobility,
                                          const ContactStepOptions& options, const DefectCorrectionOptions& solver,
                                          ContactStepResult failed) {
  std::size_t applications = failed.mobility_applications;
  int iterations = failed.iterations;
  double wall_time_s = failed.wall_time_s;
  ContactStepPhaseTimes phase_times = failed.phase_times;
  int queries = failed.broad_phase_queries, reused = failed.broad_phase_reused;
  std::string tried;
  const auto attempt = [&](std::string_view name, ContactStepResult again) -> std::optional<ContactStepResult> {
    applications += again.mobility_applications;
    iterations += again.iterations;
    wall_time_s += again.wall_time_s;
    phase_times += again.phase_times;
    queries += again.broad_phase_queries;
    reused += again.broad_phase_reused;
    if (again.status == ContactStepStatus::failed_separation) {
      tried += "; " + std::string(name) + ", tried on this step: " + trimmed(again.message);
      return std::nullopt;
    }
    again.mobility_applications = applications;
    again.iterations = iterations;
    again.wall_time_s = wall_time_s;
    again.phase_times = phase_times;
    again.broad_phase_queries = queries;
    again.broad_phase_reused = reused;
    again.fallback = name;
    again.message = "solved again by " + std::string(name) + " after the default solver's " + trimmed(failed.message) +
                    (again.message.empty() ? std::string() : "; " + std::string(name) + ": " + again.message);
    return again;
  };
#if STOKESCONTACT_HAS_NLOPT
  if (solver.far_root_fallback && failed.max_correction_turn > options.max_correction_turn &&
      failed.flagged_pairs <= solver.far_root_fallback_max_pairs) {
    BarrierNloptOptions working_set;
    working_set.constraint = BarrierConstraint::working_set;
    working_set.tol = solver.tol;
    if (auto r = attempt("barrier-working-set", solve_contact_step_barrier(problem, mobility, options, working_set)))
      return std::move(*r);
  }
#endif
  if (solver.lcp_sequence_fallback) {
    LcpSequenceOptions sequence;
    sequence.inner = InnerLcpSolver::minimum_map_newton;
    if (auto r = attempt("lcp-newton", solve_contact_step_lcp_sequence(problem, mobility, options, sequence)))
      return std::move(*r);
  }
  failed.mobility_applications = applications;
  failed.iterations = iterations;
  failed.wall_time_s = wall_time_s;
  failed.phase_times = phase_times;
  failed.message = trimmed(failed.message) + tried;
  return failed;
}

}  // namespace detail

// One contact step by the chosen solver (by default the defect-correction solver). Bad input
// throws std::invalid_argument naming the field before anything changes.
template <Shape S, MobilityOperator M>
ContactStepResult solve_contact_step(const ContactStepProblem<S>& problem, M& mobility,
                                     const ContactStepOptions& options = {},
                                     const ContactSolver& solver = DefectCorrectionOptions{}) {
  return std::visit(
      [&](const auto& o) {
        using O = std::decay_t<decltype(o)>;
        if constexpr (std::is_same_v<O, DefectCorrectionOptions>) {
          ContactStepResult r = solve_contact_step_defect_correction(problem, mobility, options, o);
          if (r.status == ContactStepStatus::failed_separation && !r.refused && (o.far_root_fallback || o.lcp_sequence_fallback))
            return detail::solve_failed_step_again(problem, mobility, options, o, std::move(r));
          return r;
        } else if constexpr (std::is_same_v<O, LcpSequenceOptions>)
          return solve_contact_step_lcp_sequence(problem, mobility, options, o);
#if STOKESCONTACT_HAS_NLOPT
        else
          return solve_contact_step_barrier(problem, mobility, options, o);
#endif
      },
      solver);
}

}  // namespace stokescontact
