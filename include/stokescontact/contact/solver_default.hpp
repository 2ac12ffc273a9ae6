#pragma once
// Deprecated path, kept for one release (0.2): moved to <stokescontact/contact/solvers/defect_correction.hpp>.
#include "stokescontact/contact/solvers/defect_correction.hpp"

namespace stokescontact {

// Deprecated names, kept for one release (0.2): the default solver is named after its method.
using DefaultSolverOptions [[deprecated("use DefectCorrectionOptions")]] = DefectCorrectionOptions;

template <Shape S, MobilityOperator M>
[[deprecated("use solve_contact_step (the default) or solve_contact_step_defect_correction")]]
ContactStepResult solve_contact_step_default(const ContactStepProblem<S>& problem, M& mobility,
                                             const ContactStepOptions& options = {},
                                             const DefectCorrectionOptions& solver = {}) {
  return solve_contact_step_defect_correction(problem, mobility, options, solver);
}

}  // namespace stokescontact
