#pragma once
// The collision pressure of a Brownian suspension as a time average, shared by the Brownian
// drivers (brownian_hard_spheres, brownian_rods): a TimeStepper with Brownian motion runs
// `equilibrate` steps unrecorded, then `average` steps, each giving one sample of
//     Z_step = 1 + sum over the step's contact sub-steps (h / dt) tr(sigma^col) / (3 N kT)
// (Yan et al. eq. 16, 51-52; dynamics/collision_stress.hpp), block averaged for its error bar
// (core/block_average.hpp), and the mean collision stress tensor per body, sum (h / dt)
// sigma^col / (N kT) (its trace / 3 is Z - 1). Also per step: pushed pairs (lambda > 0),
// mobility applications, solver iterations and sub-steps, the smallest d / d_hat, the largest
// correction turn, the sub-steps the default solver failed and another solved again
// (contact_solver.hpp), and an optional extra observable per step (e.g. a nematic order
// parameter) averaged the same way. A step that throws ends the run; its message is kept and
// the averages cover the steps before it.
// The discrete step misses the collisions a Brownian path makes between the ends of a step, so
// Z is low by an amount that shrinks like sqrt(dt) (docs/results.md, "Brownian hard spheres");
// extrapolate_to_zero_step fits Z = Z_0 + c sqrt(dt) through several step sizes.
#include <stokescontact/core/block_average.hpp>
#include <stokescontact/dynamics/collision_stress.hpp>
#include <stokescontact/dynamics/time_stepper.hpp>

#include <algorithm>
#include <chrono>
#include <functional>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace examples {

namespace sc = stokescontact;

struct BrownianPressureRun {
  sc::BlockAverageResult z;      // Z = P / (n kT), one sample per averaged step
  sc::BlockAverageResult extra;  // the extra observable (empty without one)
  sc::Mat3 collision_stress = sc::Mat3::Zero();  // mean per averaged step of sum (h / dt) sigma^col / (N kT)
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
  sc::Mat3 step_stress = sc::Mat3::Zero();  // sum of (h / dt) sigma^col over the step's sub-steps
  stepper.add_contact_observer([&](const sc::ContactStepProblem<S>& problem, const sc::ContactStepResult& result) {
    if (result.lambda.size() > 0) step_stress += problem.dt / dt * sc::contact_step_stress(problem, result);
  });
  BrownianPressureRun r;
  sc::BlockAverage z, x;
  const auto start = std::chrono::steady_clock::now();
  try {
    for (long k = 0; k < equilibrate_steps + average_steps; ++k) {
      step_stress.setZero();
      const sc::StepDiagnostics d = stepper.step();
      r.fallbacks += static_cast<long>(d.fallbacks);
      if (k < equilibrate_steps) continue;
      z.add(1.0 + step_stress.trace() / (3.0 * bodies * kT));
      r.collision_stress += step_stress / (bodies * kT);
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
  r.collision_stress /= steps;
  return r;
}

// Z measured at one step size: sqrt(dt), the mean and its error bar.
struct ZAtStep {
  double sqrt_dt = 0.0, z = 0.0, error = 0.0;
};

struct Extrapolated {
  double z = 0.0, error = 0.0, slope = 0.0;
};

// Weighted least squares Z = z + slope sqrt(dt), weights 1 / error^2 (equal weights if an
// error bar is 0); the error of z from the inverse normal matrix.
inline Extrapolated extrapolate_to_zero_step(const std::vector<ZAtStep>& points) {
  bool all_errors = true;
  for (const ZAtStep& p : points) all_errors = all_errors && p.error > 0.0;
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  for (const ZAtStep& p : points) {
    const double w = all_errors ? 1.0 / (p.error * p.error) : 1.0;
    const Eigen::Vector2d row(1.0, p.sqrt_dt);
    normal += w * row * row.transpose();
    rhs += w * p.z * row;
  }
  const Eigen::Matrix2d covariance = normal.inverse();
  const Eigen::Vector2d fit = covariance * rhs;
  return {fit(0), all_errors ? std::sqrt(covariance(0, 0)) : 0.0, fit(1)};
}

}  // namespace examples
