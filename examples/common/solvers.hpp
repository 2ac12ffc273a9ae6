#pragma once
// The contact solvers by name, shared by the experiment drivers. Every solver sits behind the
// one interface of contact_step.hpp; a registry entry is the name and what configures it:
//   barrier-slsqp, barrier-mma, barrier-cobyla  the barrier method, eq. 15 (NLopt)
//   lcp-bbpgd, lcp-apgd, lcp-newton             the NCP as a sequence of LCPs (eq. 26-27)
//   default                                     the library's default solver
// solve() runs an entry on one contact step; an optional TOL (the eq. 29 stopping rule)
// replaces the solver's own where it has one (barrier, default); the LCP solvers have none.
#include <stokescontact/contact/solvers/barrier_nlopt.hpp>
#include <stokescontact/contact/solvers/defect_correction.hpp>
#include <stokescontact/contact/solvers/lcp_sequence.hpp>

#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace examples {

namespace sc = stokescontact;

struct DefaultSolver {};  // solve_contact_step_defect_correction with its own options

struct SolverEntry {
  std::string name;
  std::variant<sc::BarrierOptimizer, sc::InnerLcpSolver, DefaultSolver> kind;
};

inline const std::vector<SolverEntry>& solver_registry() {
  static const std::vector<SolverEntry> registry{
      {"default", DefaultSolver{}},
      {"barrier-slsqp", sc::BarrierOptimizer::slsqp},
      {"barrier-mma", sc::BarrierOptimizer::mma},
      {"barrier-cobyla", sc::BarrierOptimizer::cobyla},
      {"lcp-bbpgd", sc::InnerLcpSolver::bbpgd},
      {"lcp-apgd", sc::InnerLcpSolver::apgd},
      {"lcp-newton", sc::InnerLcpSolver::minimum_map_newton},
  };
  return registry;
}

inline constexpr const char* kDefaultSolverName = "default";

inline std::string solver_names() {
  std::string names;
  for (const SolverEntry& e : solver_registry()) names += (names.empty() ? "" : ", ") + e.name;
  return names;
}

// The entry called `name`; std::invalid_argument listing the names otherwise.
inline const SolverEntry& find_solver(const std::string& name) {
  for (const SolverEntry& e : solver_registry())
    if (e.name == name) return e;
  throw std::invalid_argument("unknown solver '" + name + "' (known: " + solver_names() + ")");
}

inline bool has_tol(const SolverEntry& e) { return !std::holds_alternative<sc::InnerLcpSolver>(e.kind); }

template <sc::Shape S, sc::MobilityOperator M>
sc::ContactStepResult solve(const SolverEntry& entry, const sc::ContactStepProblem<S>& problem, M& mobility,
                            const sc::ContactStepOptions& options, std::optional<double> tol = {}) {
  return std::visit(
      [&](auto kind) {
        using Kind = decltype(kind);
        if constexpr (std::is_same_v<Kind, sc::BarrierOptimizer>) {
          sc::BarrierNloptOptions barrier;
          barrier.optimizer = kind;
          if (tol) barrier.tol = *tol;
          return sc::solve_contact_step_barrier(problem, mobility, options, barrier);
        } else if constexpr (std::is_same_v<Kind, sc::InnerLcpSolver>) {
          sc::LcpSequenceOptions sequence;
          sequence.inner = kind;
          return sc::solve_contact_step_lcp_sequence(problem, mobility, options, sequence);
        } else {
          sc::DefectCorrectionOptions solver;
          if (tol) solver.tol = *tol;
          return sc::solve_contact_step_defect_correction(problem, mobility, options, solver);
        }
      },
      entry.kind);
}

}  // namespace examples
