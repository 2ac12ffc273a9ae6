#pragma once
// The collision pressure of a Brownian suspension as a time average, shared by the Brownian
// drivers (brownian_hard_spheres, brownian_rods): a TimeStepper with Brownian motion runs
// `equilibrate` steps unrecorded, then `average` steps, each giving one sample of
//     Z_step = 1 + sum over the step's contact sub-steps (h / dt) tr(sigma^col) / (3 N kT)
// (Yan et al. eq. 16, 51-52; dynamics/collision_stress.hpp), block averaged for its error bar
// (core/block_average.hpp). Also per step: pushed pairs (lambda > 0), mobility applications,
// solver iterations and sub-steps, the smallest d / d_hat, the largest correction turn, the
// sub-steps the default solver failed and another solved again (contact_solver.hpp), and an optional extra observable
// per step (e.g. a nematic order parameter) averaged the same way. A step that throws ends
// the run; its message is kept and the averages cover the steps before it.
#include <stokescontact/stokescontact.hpp>

#include <algorithm>
#include <chrono>
#include <functional>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>

namespace examples {

namespace sc = stokescontact;

struct BrownianPressureRun {
  sc::BlockAverageResult z;      // Z = P / (n kT), one sample per averaged step
  sc::BlockAverageResult extra;  // the extra observable (empty without one)
  double pushed_per_step = 0.0, applications_per_step = 0.0, iterations_per_step = 0.0, substeps_per_step = 0.0;
  double min_distance_ratio = std::numeric_limits<double>::quiet_NaN();  // NaN until a step is averaged
  double max_correction_turn = 0.0;  // the largest turn a contact correction gave a body, averaged steps
  long fallbacks = 0;                // contact sub-steps another solver solved again, all steps run
  double wall_s = 0.0;
  long steps = 0;  // averaged steps completed
  std::string failure;

  bool measured() const { return steps >= 2; }
};

template <sc::Shape S, sc::MobilityOperator M>
BrownianPressureRun measure_brownian_pressure(sc::TimeStepper<S, M>& stepper, double kT, long equilibrate_steps,
                                              long average_steps,
                                              const std::function<double(std::span<const sc::Pose>)>& extra = {}) {
  const double dt = stepper.options().dt;
  const double bodies = static_cast<double>(stepper.poses().size());
  double step_pressure = 0.0;  // sum of (h / dt) tr(sigma^col) / 3 over the step's sub-steps
  stepper.add_contact_observer([&](const sc::ContactStepProblem<S>& problem, const sc::ContactStepResult& result) {
    if (result.lambda.size() > 0) step_pressure += problem.dt / dt * sc::contact_step_stress(problem, result).trace() / 3.0;
  });
  BrownianPressureRun r;
  sc::BlockAverage z, x;
  const auto start = std::chrono::steady_clock::now();
  try {
    for (long k = 0; k < equilibrate_steps + average_steps; ++k) {
      step_pressure = 0.0;
      const sc::StepDiagnostics d = stepper.step();
      r.fallbacks += static_cast<long>(d.fallbacks);
      if (k < equilibrate_steps) continue;
      z.add(1.0 + step_pressure / (bodies * kT));
      if (extra) x.add(extra(std::span<const sc::Pose>(stepper.poses())));
      r.pushed_per_step += static_cast<double>(d.active_pairs);
      r.applications_per_step += static_cast<double>(d.mobility_applications);
      r.iterations_per_step += static_cast<double>(d.iterations);
      r.substeps_per_step += static_cast<double>(d.substeps);
      r.max_correction_turn = std::max(r.max_correction_turn, d.max_correction_turn);
      if (!(r.min_distance_ratio <= d.min_distance_ratio)) r.min_distance_ratio = d.min_distance_ratio;
      ++r.steps;
    }
  } catch (const std::runtime_error& e) {
    r.failure = e.what();
  }
  stepper.clear_contact_observers();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (r.measured()) {
    r.z = z.result();
    if (extra) r.extra = x.result();
  }
  const double steps = static_cast<double>(std::max(1L, r.steps));
  r.pushed_per_step /= steps;
  r.applications_per_step /= steps;
  r.iterations_per_step /= steps;
  r.substeps_per_step /= steps;
  return r;
}

}  // namespace examples
