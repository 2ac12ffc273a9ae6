#pragma once
// A time step's diagnostics (dynamics/step_diagnostics.hpp) as one line of JSON, e.g. for a
// JSON-lines log written by a step observer:
//   stepper.add_step_observer([&out](const StepDiagnostics& d, std::span<const Pose>) {
//     out << to_json(d) << '\n';
//   });
#include <string>

#include "stokescontact/dynamics/step_diagnostics.hpp"
#include "stokescontact/io/json.hpp"

namespace stokescontact {

// One JSON object, no newline; min_distance_ratio is null when infinite (fewer than 2 bodies).
inline std::string to_json(const StepDiagnostics& d) {
  return "{\"step\": " + std::to_string(d.step) + ", \"time\": " + json_number(d.time) +
         ", \"flagged_pairs\": " + std::to_string(d.flagged_pairs) +
         ", \"active_pairs\": " + std::to_string(d.active_pairs) +
         ", \"carried_pairs\": " + std::to_string(d.carried_pairs) +
         ", \"substeps\": " + std::to_string(d.substeps) +
         ", \"min_distance_ratio\": " + json_number(d.min_distance_ratio) +
         ", \"status\": " + json_quoted(to_string(d.status)) + ", \"message\": " + json_quoted(d.message) +
         ", \"iterations\": " + std::to_string(d.iterations) +
         ", \"unconstrained_applications\": " + std::to_string(d.unconstrained_applications) +
         ", \"mobility_applications\": " + std::to_string(d.mobility_applications) +
         ", \"wall_time_s\": " + json_number(d.wall_time_s) + ", \"lambda_sum\": " + json_number(d.lambda_sum) +
         ", \"lambda_max\": " + json_number(d.lambda_max) +
         ", \"max_correction_turn\": " + json_number(d.max_correction_turn) +
         ", \"fallbacks\": " + std::to_string(d.fallbacks) + "}";
}

}  // namespace stokescontact
