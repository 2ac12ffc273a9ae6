#pragma once
// What one time step did (dynamics/time_stepper.hpp): the numbers the papers report per step.
// io/diagnostics_json.hpp writes it as one line of JSON.
#include <cstddef>
#include <string>

#include "stokescontact/contact/contact_step.hpp"

namespace stokescontact {

struct StepDiagnostics {
  long step = 0;                       // 1 for the first step
  double time = 0.0;                   // t + dt, the time reached
  std::size_t flagged_pairs = 0;       // Nc at the trial step (and pairs the guarantee loop added);
                                       // pair counts are the largest over sub-steps, work adds up
  std::size_t active_pairs = 0;        // pairs with lambda > 0
  std::size_t carried_pairs = 0;       // flagged pairs constrained where they first came within d_hat
                                       // (they passed or swept past each other in the trial step)
  std::size_t substeps = 1;            // contact steps the step took (> 1: it was sub-stepped)
  double min_distance_ratio = 0.0;     // min d^P over all pairs of Q_{t+dt} / d_hat (inf: < 2 bodies)
  ContactStepStatus status = ContactStepStatus::converged;
  std::string message;                 // the solver's message (empty when it has nothing to say)
  int iterations = 0;                  // the contact solver's iterations
  std::size_t unconstrained_applications = 0;  // 1 for M F_ext, 0 when F_ext = 0
  std::size_t mobility_applications = 0;       // all of the step: the one for U plus the contact step's
  double wall_time_s = 0.0;            // the whole step
  double lambda_sum = 0.0;
  double lambda_max = 0.0;
  double max_correction_turn = 0.0;    // the largest turn the contact correction gave a body, radians
  std::size_t fallbacks = 0;           // contact sub-steps the default solver failed and another
                                       // solver solved again (ContactStepResult::fallback)
};

}  // namespace stokescontact
