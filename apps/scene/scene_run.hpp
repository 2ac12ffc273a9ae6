#pragma once
// One scene run, start to end: read the file, place the bodies, choose the model, check the
// output directory, then step (dynamics/time_stepper.hpp) and write
//   <output>/scene.json     the scene as read,
//   <output>/steps.jsonl    one line of StepDiagnostics per step (io/diagnostics_json.hpp),
//   <output>/bodies.pvd     the VTK series of the bodies' true shapes (bodies_NNNNNN.vtp),
//   <output>/summary.json   the run's summary, also printed.
// Every check runs before the first step and before anything is written. The work is compiled
// once, in scene_run.cpp (the stokescontact_scene library), for the runner and its tests.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include <stokescontact/io/json.hpp>

#include "scene/json_reader.hpp"

namespace stokescontact::apps {

struct RunOptions {
  std::filesystem::path scene;
  std::filesystem::path output;           // empty: out/<scene name>
  bool replace = false;
  std::optional<long long> max_steps;     // stop early (short runs of a long scene)
  std::optional<bool> progress;           // none: when stderr is a terminal
};

// What the runner prints and writes as summary.json.
struct RunSummary {
  std::string scene, shape, model, model_reason, status = "finished", message;
  std::size_t bodies = 0;
  int dofs_per_body = 0;
  double d_hat = 0.0, dt = 0.0, time = 0.0;
  long long steps_requested = 0, steps_done = 0, contact_steps = 0, substepped_steps = 0, frames = 0;
  double min_distance_ratio = std::numeric_limits<double>::infinity();
  long long min_distance_step = 0;
  std::size_t applications_total = 0, applications_median = 0, applications_max = 0;
  // The contact steps' cost modes (ContactStepResult::cost, automatic resolved), comma-separated
  // in the order first used; empty before any contact step.
  std::string contact_cost;
  double wall_time_s = 0.0;
  // The collision stress per step (Yan eq. 16 summed over the step's pairs: force x length,
  // not divided by a volume), averaged over the run with block-averaging error bars
  // (core/block_average.hpp); NaN with fewer than 2 steps.
  Mat3 collision_stress_mean = Mat3::Constant(std::numeric_limits<double>::quiet_NaN());
  Mat3 collision_stress_error = Mat3::Constant(std::numeric_limits<double>::quiet_NaN());
  double collision_pressure_mean = std::numeric_limits<double>::quiet_NaN();
  double collision_pressure_error = std::numeric_limits<double>::quiet_NaN();
  bool collision_pressure_error_converged = false;
  std::filesystem::path output;

  std::string json() const {
    return "{\"scene\": " + json_quoted(scene) + ", \"shape\": " + json_quoted(shape) +
           ", \"bodies\": " + std::to_string(bodies) + ", \"model\": " + json_quoted(model) +
           ", \"model_reason\": " + json_quoted(model_reason) + ", \"dofs_per_body\": " + std::to_string(dofs_per_body) +
           ", \"d_hat\": " + json_number(d_hat) + ", \"dt\": " + json_number(dt) +
           ", \"steps_requested\": " + std::to_string(steps_requested) + ", \"steps_done\": " + std::to_string(steps_done) +
           ", \"time\": " + json_number(time) + ", \"status\": " + json_quoted(status) +
           ", \"message\": " + json_quoted(message) + ", \"contact_steps\": " + std::to_string(contact_steps) +
           ", \"substepped_steps\": " + std::to_string(substepped_steps) +
           ", \"min_distance_ratio\": " + json_number(min_distance_ratio) +
           ", \"min_distance_step\": " + std::to_string(min_distance_step) +
           ", \"applications_total\": " + std::to_string(applications_total) +
           ", \"applications_median\": " + std::to_string(applications_median) +
           ", \"applications_max\": " + std::to_string(applications_max) +
           ", \"contact_cost\": " + json_quoted(contact_cost) + ", \"wall_time_s\": " + json_number(wall_time_s) +
           ", \"frames\": " + std::to_string(frames) + ", \"collision_stress_mean\": " + row_major(collision_stress_mean) +
           ", \"collision_stress_error\": " + row_major(collision_stress_error) +
           ", \"collision_pressure_mean\": " + json_number(collision_pressure_mean) +
           ", \"collision_pressure_error\": " + json_number(collision_pressure_error) +
           ", \"collision_pressure_error_converged\": " + (collision_pressure_error_converged ? "true" : "false") + "}";
  }

 private:
  static std::string row_major(const Mat3& m) {
    const Mat3 t = m.transpose();
    return json_array(std::span<const double>(t.data(), 9));
  }
};

// The summary as the runner prints it.
void print_summary(const RunSummary& s, std::ostream& out);

// Reads, checks, runs and writes; returns the summary (status "failed" when a step could not
// be held). Throws SceneError for a scene that cannot run, before anything is written.
RunSummary run_scene(const RunOptions& run, std::ostream& out);

}  // namespace stokescontact::apps
