// A time step's diagnostics as JSON (io/diagnostics_json.hpp): every field in its place, strings
// escaped, infinities null; and a JSON-lines log written by a step observer, one object per step.
#include <gtest/gtest.h>

#include <limits>
#include <numbers>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "stokescontact/dynamics/time_stepper.hpp"
#include "stokescontact/io/diagnostics_json.hpp"
#include "stokescontact/mobility/free_draining.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace diagnostics_json_tests {

namespace sc = stokescontact;

namespace {

TEST(DiagnosticsJson, EveryFieldInItsPlace) {
  sc::StepDiagnostics d;
  d.step = 12;
  d.time = 0.25;
  d.flagged_pairs = 7;
  d.active_pairs = 3;
  d.carried_pairs = 1;
  d.substeps = 2;
  d.min_distance_ratio = 1.0001;
  d.status = sc::ContactStepStatus::not_converged;
  d.message = "stopped after 50 corrections";
  d.iterations = 50;
  d.unconstrained_applications = 1;
  d.mobility_applications = 9;
  d.wall_time_s = 0.5;
  d.lambda_sum = 12.5;
  d.lambda_max = 4.0;
  d.max_correction_turn = 0.125;
  d.fallbacks = 1;
  EXPECT_EQ(sc::to_json(d),
            R"({"step": 12, "time": 0.25, "flagged_pairs": 7, "active_pairs": 3, "carried_pairs": 1, "substeps": 2, )"
            R"("min_distance_ratio": 1.0001, )"
            R"("status": "not_converged", "message": "stopped after 50 corrections", "iterations": 50, )"
            R"("unconstrained_applications": 1, "mobility_applications": 9, "wall_time_s": 0.5, )"
            R"("lambda_sum": 12.5, "lambda_max": 4, "max_correction_turn": 0.125, )"
            R"("fallbacks": 1})");
}

TEST(DiagnosticsJson, StatusNamesAreTheContactStepsOwn) {
  for (const sc::ContactStepStatus s : {sc::ContactStepStatus::converged, sc::ContactStepStatus::not_converged,
                                        sc::ContactStepStatus::failed_separation}) {
    sc::StepDiagnostics d;
    d.status = s;
    const std::string field = "\"status\": \"" + std::string(sc::to_string(s)) + "\"";
    EXPECT_NE(sc::to_json(d).find(field), std::string::npos) << sc::to_json(d);
  }
  EXPECT_EQ(sc::to_string(sc::ContactStepStatus::failed_separation), "failed_separation");
}

// Strings are escaped (the line stays one line); infinities and NaN become null.
TEST(DiagnosticsJson, StringsAreEscapedAndInfinitiesAreNull) {
  sc::StepDiagnostics d;
  d.message = "a \"quoted\"\nline\twith \\ and \x01";
  d.min_distance_ratio = std::numeric_limits<double>::infinity();  // fewer than 2 bodies
  d.lambda_sum = std::numeric_limits<double>::quiet_NaN();
  const std::string json = sc::to_json(d);
  EXPECT_NE(json.find(R"("message": "a \"quoted\"\u000aline\u0009with \\ and \u0001")"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("min_distance_ratio": null)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("lambda_sum": null)"), std::string::npos) << json;
  EXPECT_EQ(json.find('\n'), std::string::npos);
}

// A JSON-lines log through a step observer: one object per committed step, equal to to_json of
// the stepper's own diagnostics.
TEST(DiagnosticsJson, OneObjectPerLineThroughAStepObserver) {
  constexpr double kMu = 1.0 / (6.0 * std::numbers::pi);
  sc::FreeDrainingMobility mobility(sc::sphere_mobility(sc::Sphere{1.0}, 1.0), 2, 3);
  sc::TimeStepperOptions o;
  o.dt = 0.01;
  o.d_hat = 0.01;
  sc::TimeStepper<sc::Sphere, sc::FreeDrainingMobility> stepper(
      {sc::Sphere{1.0}},
      {sc::Pose{sc::Vec3(0, 0, 0), sc::Quat::Identity()}, sc::Pose{sc::Vec3(2.02, 0, 0), sc::Quat::Identity()}},
      mobility, sc::LcpSequenceOptions{}, o);
  sc::VecX F(6);
  F << 1.0 / kMu, 0, 0, -1.0 / kMu, 0, 0;
  stepper.set_external_forces(F);
  std::ostringstream out;
  stepper.add_step_observer(
      [&out](const sc::StepDiagnostics& d, std::span<const sc::Pose>) { out << sc::to_json(d) << '\n'; });
  stepper.run(3);
  std::istringstream lines(out.str());
  std::string line;
  int k = 0;
  while (std::getline(lines, line)) {
    const sc::StepDiagnostics& d = stepper.diagnostics()[static_cast<std::size_t>(k)];
    ++k;
    EXPECT_EQ(line.front(), '{');
    EXPECT_EQ(line.back(), '}');
    EXPECT_EQ(line, sc::to_json(d));
    for (const std::string& field :
         {"\"step\": " + std::to_string(k), "\"time\": " + sc::json_number(d.time),
          "\"min_distance_ratio\": " + sc::json_number(d.min_distance_ratio), std::string("\"status\": \"converged\""),
          "\"mobility_applications\": " + std::to_string(d.mobility_applications),
          "\"flagged_pairs\": " + std::to_string(d.flagged_pairs), "\"lambda_sum\": " + sc::json_number(d.lambda_sum)})
      EXPECT_NE(line.find(field), std::string::npos) << field << " not in " << line;
  }
  EXPECT_EQ(k, 3);
  EXPECT_GT(stepper.diagnostics()[0].active_pairs, 0u);
}

}  // namespace

}  // namespace diagnostics_json_tests
