// Scene files (apps/scene/): every bad input stops before any work with its key path named;
// the automatic model follows the two-sphere error table; a small run writes complete outputs
// and never half-overwrites an earlier run.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include <unistd.h>

#include "scene/model_choice.hpp"
#include "scene/scene_run.hpp"
#include "scene/scene_spec.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace scene_file_tests {

namespace sc = stokescontact;
namespace apps = stokescontact::apps;
using nlohmann::json;

namespace {

// Two unit spheres 2.5 apart along x, pushed together by +-10 for 10 steps of 0.01.
json two_spheres() {
  return json::parse(R"({
    "name": "two_spheres",
    "shape": {"type": "sphere", "radius": 1.0},
    "bodies": {"poses": [{"position": [0, 0, 0]}, {"position": [2.5, 0, 0]}]},
    "forces": {"type": "per_body", "force": [[10, 0, 0], [-10, 0, 0]]},
    "mobility": {"model": "free-draining"},
    "contact": {"d_hat": 0.05},
    "time": {"dt": 0.01, "steps": 10}
  })");
}

// read_scene on `scene` must throw a SceneError whose message starts with `path: `.
void expect_error(const json& scene, const std::string& path, const std::string& words = "") {
  try {
    (void)apps::read_scene(scene);
    ADD_FAILURE() << "accepted; expected an error at " << path;
  } catch (const apps::SceneError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_NE(what.find(words), std::string::npos) << what;
  }
}

std::filesystem::path scratch(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("stokescontact_scene_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::filesystem::path write_scene(const std::filesystem::path& dir, const json& scene) {
  const std::filesystem::path file = dir / "scene.json";
  std::ofstream(file) << scene.dump(2);
  return file;
}

apps::RunSummary run(const std::filesystem::path& scene, const std::filesystem::path& output, bool replace = false) {
  apps::RunOptions o;
  o.scene = scene;
  o.output = output;
  o.replace = replace;
  o.progress = false;
  std::ostringstream out;
  return apps::run_scene(o, out);
}

}  // namespace

TEST(SceneFile, ReadsAValidScene) {
  const apps::SceneSpec s = apps::read_scene(two_spheres());
  EXPECT_EQ(s.name, "two_spheres");
  EXPECT_TRUE(std::holds_alternative<sc::Sphere>(s.shape));
  ASSERT_TRUE(std::holds_alternative<std::vector<sc::Pose>>(s.bodies));
  EXPECT_EQ(std::get<std::vector<sc::Pose>>(s.bodies).size(), 2u);
  EXPECT_EQ(s.steps, 10);
  EXPECT_EQ(s.contact.d_hat, 0.05);
}

TEST(SceneFile, EndTimeRoundsToWholeSteps) {
  json j = two_spheres();
  j["time"] = {{"dt", 0.02}, {"end", 9.0}};
  EXPECT_EQ(apps::read_scene(j).steps, 450);
}

TEST(SceneFile, CorrectionTurnBoundIsRead) {
  json j = two_spheres();
  EXPECT_EQ(apps::read_scene(j).contact.step.max_correction_turn, sc::ContactStepOptions{}.max_correction_turn);
  j["contact"]["max_correction_turn"] = 0.25;
  EXPECT_EQ(apps::read_scene(j).contact.step.max_correction_turn, 0.25);
  j["contact"]["max_correction_turn"] = 0.0;
  expect_error(j, "contact.max_correction_turn", "must be > 0");
}

TEST(SceneFile, BroadPhaseSkinIsRead) {
  json j = two_spheres();
  EXPECT_LT(apps::read_scene(j).contact.step.broad_phase_skin, 0.0);  // automatic
  j["contact"]["broad_phase_skin"] = 0.0;
  EXPECT_EQ(apps::read_scene(j).contact.step.broad_phase_skin, 0.0);
  j["contact"]["broad_phase_skin"] = 0.5;
  EXPECT_EQ(apps::read_scene(j).contact.step.broad_phase_skin, 0.5);
  j["contact"]["broad_phase_skin"] = -0.5;
  expect_error(j, "contact.broad_phase_skin", "must be >= 0");
}

TEST(SceneFile, MaxFlaggedPairsPerBodyIsRead) {
  json j = two_spheres();
  EXPECT_EQ(apps::read_scene(j).contact.step.max_flagged_pairs_per_body, sc::ContactStepOptions{}.max_flagged_pairs_per_body);
  j["contact"]["max_flagged_pairs_per_body"] = 0.0;  // never refused
  EXPECT_EQ(apps::read_scene(j).contact.step.max_flagged_pairs_per_body, 0.0);
  j["contact"]["max_flagged_pairs_per_body"] = 4.5;
  EXPECT_EQ(apps::read_scene(j).contact.step.max_flagged_pairs_per_body, 4.5);
  j["contact"]["max_flagged_pairs_per_body"] = -1.0;
  expect_error(j, "contact.max_flagged_pairs_per_body", "must be >= 0");
}

TEST(SceneFile, BadInputNamesTheKeyPath) {
  json j = two_spheres();
  j["shape"]["radius"] = -1;
  expect_error(j, "shape.radius", "must be > 0, got -1");

  j = two_spheres();
  j["bodies"]["poses"][1]["position"] = {1, 2};
  expect_error(j, "bodies.poses[1].position", "3 numbers");

  j = two_spheres();
  j["bodies"]["poses"][0]["orientation"] = {2, 0, 0, 0};
  expect_error(j, "bodies.poses[0].orientation", "unit length");

  j = two_spheres();
  j["contact"]["dhat"] = 0.1;
  expect_error(j, "contact.dhat", "unknown key");

  j = two_spheres();
  j["time"]["dt"] = "0.01";
  expect_error(j, "time.dt", "must be a number, got a string");

  j = two_spheres();
  j["contact"]["d_try"] = 0.01;
  expect_error(j, "contact.d_try", ">= contact.d_hat");

  j = two_spheres();
  j["contact"]["solver"] = "newton";
  expect_error(j, "contact.solver", "unknown solver 'newton'");

  j = two_spheres();
  j["mobility"]["model"] = "stokesian";
  expect_error(j, "mobility.model", "unknown value 'stokesian'");

  j = two_spheres();
  j["time"]["end"] = 1.0;
  expect_error(j, "time", "exactly one of steps, end");

  j = two_spheres();
  j.erase("contact");
  expect_error(j, "contact", "is required");

  j = two_spheres();
  j["temperature"] = 1.0;
  expect_error(j, "temperature", "Brownian");

  j = two_spheres();
  j["box"] = {10, 10, 10};
  j["flow"] = {{"shear", 1.0}};
  expect_error(j, "box", "background flow");

  j = two_spheres();
  j["flow"] = {{"velocity_gradient", {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}};
  expect_error(j, "flow.velocity_gradient", "traceless");

  j = two_spheres();
  j["contact"]["directions"] = "line";
  expect_error(j, "contact.directions", "spherocylinders only");
  j["contact"]["directions"] = "overlap-ends";
  expect_error(j, "contact.directions", "spherocylinders only");
}

TEST(SceneFile, OneShapeTypePerSceneSaysSo) {
  json j = two_spheres();
  j["shapes"] = json::array({{{"type", "sphere"}, {"radius", 1}}, {{"type", "boomerang"}}});
  expect_error(j, "shapes", "one shape type");
  j = two_spheres();
  j["shape"]["type"] = "cube";
  expect_error(j, "shape.type", "known: sphere, spherocylinder, boomerang");
  j = two_spheres();
  j["bodies"] = {{"dense_packing", {{"count", 10}, {"packing_fraction", 0.3}}}};
  j["shape"] = {{"type", "boomerang"}};
  expect_error(j, "bodies.dense_packing", "spheres only");
}

TEST(SceneFile, AutomaticModelIsTheCheapestThatMeetsTheAccuracy) {
  json j = two_spheres();
  j["mobility"] = {{"model", "automatic"}, {"accuracy", 0.05}};
  apps::SceneSpec s = apps::read_scene(j);
  // Table row at gap 1 R: rpy 0.0387 <= 0.05.
  apps::ModelChoice c = apps::choose_model(s, 1.0);
  EXPECT_EQ(c.model, apps::MobilityModel::rpy);
  EXPECT_EQ(c.dofs_per_body, 3);
  // At gap 0.05 R (read at 0.1): rpy 0.164, shell12 0.0543, shell42 0.0215.
  c = apps::choose_model(s, 0.05);
  EXPECT_EQ(c.model, apps::MobilityModel::multiblob);
  EXPECT_EQ(c.shell_blobs, 42);
  EXPECT_EQ(c.dofs_per_body, 6);
  EXPECT_NE(c.reason.find("shell42"), std::string::npos) << c.reason;
  // Unreachable accuracy: the best has 0.00196 at gap 0.1.
  j["mobility"]["accuracy"] = 1e-3;
  s = apps::read_scene(j);
  EXPECT_THROW((void)apps::choose_model(s, 0.05), apps::SceneError);
  // No hydrodynamic interactions: free-draining, and spheres without torques keep 3 dofs.
  j["mobility"] = {{"hydrodynamic_interactions", false}};
  c = apps::choose_model(apps::read_scene(j), 0.05);
  EXPECT_EQ(c.model, apps::MobilityModel::free_draining);
  EXPECT_EQ(c.dofs_per_body, 3);
  // A torque on a sphere needs its rotation: 6 dofs.
  j["forces"] = {{"type", "constant"}, {"torque", {0, 0, 1}}};
  EXPECT_EQ(apps::choose_model(apps::read_scene(j), 0.05).dofs_per_body, 6);
}

TEST(SceneRun, TwoSpheresAreHeldAtDHatAndEveryOutputIsWritten) {
  const std::filesystem::path dir = scratch("two_spheres");
  const apps::RunSummary s = run(write_scene(dir, two_spheres()), dir / "out");
  EXPECT_EQ(s.status, "finished") << s.message;
  EXPECT_EQ(s.steps_done, 10);
  EXPECT_EQ(s.dofs_per_body, 3);
  EXPECT_GE(s.min_distance_ratio, 1.0 - 1e-3);
  // Free-draining unit spheres close at 2 x 10 / (6 pi) = 1.06 per unit time: the gap of 0.5
  // reaches d_hat after about 0.42, so the last contact-free step is step 42 at most: all 10
  // steps are free of contact. Run longer to make them touch.
  EXPECT_EQ(s.contact_steps, 0);
  for (const char* f : {"summary.json", "steps.jsonl", "scene.json", "bodies.pvd", "bodies_000010.vtp"})
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / f)) << f;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.partial"));
  std::ifstream steps(dir / "out" / "steps.jsonl");
  int lines = 0;
  for (std::string line; std::getline(steps, line);) {
    EXPECT_TRUE(json::accept(line)) << line;
    ++lines;
  }
  EXPECT_EQ(lines, 10);
  const json summary = json::parse(std::ifstream(dir / "out" / "summary.json"));
  EXPECT_EQ(summary["steps_done"], 10);
  std::filesystem::remove_all(dir);
}

TEST(SceneRun, ContactHoldsTheGapOverALongRun) {
  const std::filesystem::path dir = scratch("contact");
  json j = two_spheres();
  j["time"]["steps"] = 100;
  const apps::RunSummary s = run(write_scene(dir, j), dir / "out");
  EXPECT_EQ(s.status, "finished") << s.message;
  EXPECT_GT(s.contact_steps, 40);
  EXPECT_GE(s.min_distance_ratio, 1.0 - 1e-3);
  EXPECT_LE(s.min_distance_ratio, 1.0 + 1e-2);  // pushed together: held at d_hat
  // The last step's collision stress (stress.jsonl) by hand: body 1 gets -lambda e_x from the
  // contact, and D is built at the trial step, whose centre distance is the start's 2 + d_hat
  // (held to the solver's 1e-4) less dt times the closing speed 2 x 10 / (6 pi), so Yan's
  // eq. 19 gives sigma_xx = lambda (2 + d_hat - dt 20 / (6 pi)), every other entry 0.
  std::string line, last_step, last_stress;
  for (std::ifstream in(dir / "out" / "steps.jsonl"); std::getline(in, line);) last_step = line;
  for (std::ifstream in(dir / "out" / "stress.jsonl"); std::getline(in, line);) last_stress = line;
  const double lambda = json::parse(last_step)["lambda_sum"];
  const json stress = json::parse(last_stress);
  EXPECT_NEAR(lambda, 10.0, 1e-3);
  const double expected = lambda * (2.0 + 0.05 - 0.01 * 20.0 / (6.0 * std::numbers::pi));
  EXPECT_NEAR(stress["collision_stress"][0].get<double>(), expected, 1e-4 * expected);
  for (int k = 1; k < 9; ++k) EXPECT_EQ(stress["collision_stress"][k].get<double>(), 0.0) << k;
  EXPECT_NEAR(stress["collision_pressure"].get<double>(), expected / 3.0, 1e-4 * expected);
  EXPECT_GT(s.collision_pressure_mean, 0.0);
  EXPECT_GT(s.collision_pressure_error, 0.0);
  std::filesystem::remove_all(dir);
}

TEST(SceneRun, BadScenesStopBeforeAnythingIsWritten) {
  const std::filesystem::path dir = scratch("bad");
  json j = two_spheres();
  j["bodies"]["poses"][1]["position"] = {1.5, 0, 0};  // overlapping start
  try {
    (void)run(write_scene(dir, j), dir / "out");
    ADD_FAILURE() << "an overlapping start ran";
  } catch (const apps::SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("bodies: bodies 0 and 1 overlap", 0), 0u) << e.what();
  }
  j = two_spheres();
  j["box"] = {2.0, 10, 10};  // smaller than a body plus its gaps
  try {
    (void)run(write_scene(dir, j), dir / "out");
    ADD_FAILURE() << "a box smaller than a body ran";
  } catch (const apps::SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("box: is smaller than a body", 0), 0u) << e.what();
  }
  j = two_spheres();
  j["mobility"] = {{"model", "rpy"}};
  j["shape"] = {{"type", "spherocylinder"}, {"length", 1.0}, {"radius", 0.2}};
  try {
    (void)run(write_scene(dir, j), dir / "out");
    ADD_FAILURE() << "rpy ran for rods";
  } catch (const apps::SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("mobility.model: ", 0), 0u) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out.partial"));
  std::filesystem::remove_all(dir);
}

TEST(SceneRun, AnEarlierRunIsRefusedOrReplacedWhole) {
  const std::filesystem::path dir = scratch("replace");
  const std::filesystem::path scene = write_scene(dir, two_spheres());
  (void)run(scene, dir / "out");
  std::ofstream(dir / "out" / "mark") << "first run";
  try {
    (void)run(scene, dir / "out");
    ADD_FAILURE() << "overwrote an earlier run";
  } catch (const apps::SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--output: ", 0), 0u) << e.what();
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "mark"));
  const apps::RunSummary s = run(scene, dir / "out", /*replace=*/true);
  EXPECT_EQ(s.status, "finished");
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "mark"));  // the old run is gone whole
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "summary.json"));
  std::filesystem::remove_all(dir);
}

TEST(SceneRun, DefaultOutputIsOutSlashNameMadeWhenMissing) {
  const std::filesystem::path dir = scratch("default_output");
  const std::filesystem::path scene = write_scene(dir, two_spheres());
  const std::filesystem::path cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  apps::RunSummary s;
  EXPECT_NO_THROW(s = run(scene, ""));
  std::filesystem::current_path(cwd);
  EXPECT_EQ(s.status, "finished");
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "two_spheres" / "summary.json"));
  std::filesystem::remove_all(dir);
}

}  // namespace scene_file_tests
