// The scene runner's work (scene_run.hpp): one translation unit, so the time stepper is
// instantiated once per shape and model for the runner and its tests together.
#include "scene/scene_run.hpp"

#include <unistd.h>

#include <stokescontact/core/block_average.hpp>
#include <stokescontact/dynamics/collision_stress.hpp>
#include <stokescontact/dynamics/time_stepper.hpp>
#include <stokescontact/io/diagnostics_json.hpp>
#include <stokescontact/io/vtk_polydata.hpp>
#include <stokescontact/mobility/boomerang_blobs.hpp>
#include <stokescontact/mobility/free_draining.hpp>
#include <stokescontact/mobility/multiblob_mobility.hpp>
#include <stokescontact/mobility/rod_blobs.hpp>
#include <stokescontact/mobility/rpy_mobility.hpp>
#include <stokescontact/mobility/single_body_mobility.hpp>
#include <stokescontact/mobility/sphere_shell.hpp>

#include "scene/model_choice.hpp"
#include "scene/output_directory.hpp"
#include "scene/progress.hpp"
#include "scene/scene_bodies.hpp"

namespace stokescontact::apps {

namespace detail {

inline nlohmann::json load_scene_json(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw SceneError("scene file", "cannot open '" + file.string() + "'");
  try {
    return nlohmann::json::parse(in, nullptr, true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::parse_error& e) {
    throw SceneError("scene file", "'" + file.string() + "' is not valid JSON: " + e.what());
  }
}

inline std::string describe(const Sphere& s) { return "sphere (radius " + JsonReader::format(s.radius) + ")"; }
inline std::string describe(const Spherocylinder& s) {
  return "spherocylinder (length " + JsonReader::format(s.length) + ", radius " + JsonReader::format(s.radius) + ")";
}
inline std::string describe(const LineContactRod& s) { return describe(static_cast<const Spherocylinder&>(s)) + ", line contacts"; }
inline std::string describe(const Boomerang& b) {
  return "boomerang (arms " + JsonReader::format(b.arm_length) + ", radius " + JsonReader::format(b.radius) +
         ", bend radius " + JsonReader::format(b.bend_radius) + ")";
}

inline std::string model_name(const ModelChoice& c) {
  switch (c.model) {
    case MobilityModel::free_draining: return "free-draining";
    case MobilityModel::rpy: return "rpy";
    case MobilityModel::multiblob: return "multiblob";
    case MobilityModel::automatic: break;
  }
  return "automatic";
}

using SceneMobility = std::variant<FreeDrainingMobility, RpyMobility, MultiblobMobility>;

// The chosen model for `bodies` bodies of `shape` (viscosity and resolution from the scene).
template <Shape S>
SceneMobility make_mobility(const ModelChoice& c, const MobilitySpec& m, const S& shape, std::size_t bodies) {
  MultiblobOptions multiblob;
  multiblob.viscosity = m.viscosity;
  if constexpr (std::is_same_v<S, Sphere>) {
    if (c.model == MobilityModel::rpy)
      return SceneMobility(std::in_place_type<RpyMobility>, bodies, RpyParameters{shape.radius, m.viscosity},
                           c.dofs_per_body);
    if (c.model == MobilityModel::multiblob)
      return SceneMobility(std::in_place_type<MultiblobMobility>, sphere_shell(c.shell_blobs, shape.radius), bodies,
                           multiblob);
    return SceneMobility(std::in_place_type<FreeDrainingMobility>, sphere_mobility(shape, m.viscosity), bodies,
                         c.dofs_per_body);
  } else if constexpr (std::is_base_of_v<Spherocylinder, S>) {
    const Spherocylinder& rod = shape;
    if (c.model == MobilityModel::multiblob) {
      RodBlobResolution resolution;
      resolution.blobs_per_ring = m.blobs_per_ring;
      return SceneMobility(std::in_place_type<MultiblobMobility>, rod_blob_model(rod, resolution), bodies, multiblob);
    }
    return SceneMobility(std::in_place_type<FreeDrainingMobility>, spherocylinder_mobility(rod, m.viscosity), bodies, 6);
  } else {
    const BlobModel blobs = boomerang_curve_blobs(shape, m.blob_spacing);
    if (c.model == MobilityModel::multiblob)
      return SceneMobility(std::in_place_type<MultiblobMobility>, blobs, bodies, multiblob);
    return SceneMobility(std::in_place_type<FreeDrainingMobility>, single_body_mobility(blobs, m.viscosity), bodies, 6);
  }
}

inline ContactSolver scene_solver(const ContactSpec& c) {
  ContactSolver solver = contact_solver_from_name(c.solver);
  if (c.max_iterations)
    std::visit(
        [&](auto& s) {
          if constexpr (requires { s.max_iterations; }) s.max_iterations = *c.max_iterations;
        },
        solver);
  return solver;
}

inline std::size_t median(std::vector<std::size_t> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Steps the scene with mobility M, writing into `dir` (already open).
template <Shape S, MobilityOperator M>
void step_scene(const SceneSpec& spec, const S& shape, std::vector<Pose> poses, double d_hat, M& mobility,
                const std::filesystem::path& dir, long long steps, bool progress_on, RunSummary& summary) {
  TimeStepperOptions o;
  o.dt = spec.dt;
  o.d_hat = d_hat;
  o.d_try = spec.contact.d_try;
  o.d_try_multiplier = spec.contact.d_try_multiplier;
  o.d_try_rule = spec.contact.d_try_rule;
  o.max_substep_halvings = spec.contact.max_substep_halvings;
  if (spec.box) o.box = PeriodicBox{*spec.box};
  if (spec.velocity_gradient) o.background_flow = LinearBackgroundFlow(*spec.velocity_gradient);
  o.contact_step = spec.contact.step;
  TimeStepper<S, M> stepper(std::vector<S>{shape}, std::move(poses), mobility, scene_solver(spec.contact), o);
  const VecX F = stacked_forces(spec.forces, stepper.poses().size(), mobility.dofs_per_body());
  if (!F.isZero(0.0)) stepper.set_external_forces(F);

  std::ofstream steps_out(dir / "steps.jsonl");
  std::optional<VtkSeriesWriter> vtk;
  BodyMeshOptions mesh;
  mesh.ring_points = spec.output.ring_points;
  if (spec.output.vtk) {
    vtk.emplace(dir, "bodies", mesh);
    vtk->write_frame(stepper.time(), shape, std::span<const Pose>(stepper.poses()));
  }
  std::vector<std::size_t> applications;
  // The collision stress of each step (Yan eq. 16 summed over its pairs; sub-steps of length
  // h weighted h / dt), one line of stress.jsonl per step, block-averaged over the run.
  std::ofstream stress_out(dir / "stress.jsonl");
  Mat3 step_stress = Mat3::Zero();
  BlockAverage stress_average, pressure_average;
  stepper.add_contact_observer([&](const ContactStepProblem<S>& p, const ContactStepResult& r) {
    step_stress += (p.dt / spec.dt) * contact_step_stress(p, r);
    const std::string cost = mobility_cost_name(r.cost);
    if (("," + summary.contact_cost + ",").find("," + cost + ",") == std::string::npos)
      summary.contact_cost += (summary.contact_cost.empty() ? "" : ",") + cost;
  });
  Progress progress(steps, progress_on);
  stepper.add_step_observer([&](const StepDiagnostics& d, std::span<const Pose> q) {
    steps_out << to_json(d) << '\n';
    const Mat3 row_major = step_stress.transpose();
    stress_out << "{\"step\": " << d.step << ", \"time\": " << json_number(d.time)
               << ", \"collision_stress\": " << json_array(std::span<const double>(row_major.data(), 9))
               << ", \"collision_pressure\": " << json_number(collision_pressure(step_stress)) << "}\n";
    stress_average.add_tensor(step_stress);
    pressure_average.add(collision_pressure(step_stress));
    step_stress.setZero();
    applications.push_back(d.mobility_applications);
    if (d.active_pairs > 0) ++summary.contact_steps;
    if (d.substeps > 1) ++summary.substepped_steps;
    if (d.min_distance_ratio < summary.min_distance_ratio) {
      summary.min_distance_ratio = d.min_distance_ratio;
      summary.min_distance_step = d.step;
    }
    if (vtk && (d.step % spec.output.vtk_every == 0 || d.step == steps))
      vtk->write_frame(d.time, shape, q);
  });
  const auto start = std::chrono::steady_clock::now();
  try {
    for (long long k = 0; k < steps; ++k) {
      stepper.step();
      progress.update(k + 1);
    }
  } catch (const std::runtime_error& e) {
    summary.status = "failed";
    summary.message = e.what();
    if (vtk && stepper.steps_taken() % spec.output.vtk_every != 0)  // the last good state
      vtk->write_frame(stepper.time(), shape, std::span<const Pose>(stepper.poses()));
  }
  progress.finish();
  summary.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.steps_done = stepper.steps_taken();
  summary.time = stepper.time();
  summary.frames = vtk ? static_cast<long long>(vtk->frames()) : 0;
  if (summary.steps_done >= 2) {
    const BlockAverageResult stress = stress_average.result(), pressure = pressure_average.result();
    const Mat3 mean = Eigen::Map<const Mat3>(stress.mean.data());
    const Mat3 error = Eigen::Map<const Mat3>(stress.std_error.data());
    summary.collision_stress_mean = mean;
    summary.collision_stress_error = error;
    summary.collision_pressure_mean = pressure.mean(0);
    summary.collision_pressure_error = pressure.std_error(0);
    summary.collision_pressure_error_converged = pressure.all_converged();
  }
  summary.applications_median = median(applications);
  for (std::size_t a : applications) {
    summary.applications_total += a;
    summary.applications_max = std::max(summary.applications_max, a);
  }
}

inline double contact_radius(const Sphere& s) { return s.radius; }
inline double contact_radius(const Spherocylinder& s) { return s.radius; }
inline double contact_radius(const Boomerang& b) { return b.radius; }

template <Shape S>
RunSummary run_shape(const SceneSpec& spec, const nlohmann::json& document, const S& shape, const RunOptions& run,
                     std::ostream& out) {
  RunSummary summary;
  summary.scene = spec.name;
  summary.shape = describe(shape);
  std::vector<Pose> poses = scene_poses(spec, shape);
  const double min_gap = check_start(spec, shape, std::span<const Pose>(poses));
  double d_hat = spec.contact.d_hat;
  if (spec.contact.d_hat_is_minimum_gap) {
    if (!std::isfinite(min_gap)) throw SceneError("contact.d_hat", "'minimum_gap' needs at least two bodies");
    d_hat = min_gap;
  }
  if (spec.contact.d_try > 0.0 && spec.contact.d_try < d_hat)
    throw SceneError("contact.d_try", "must be 0 (the d_try rule) or >= d_hat = " + JsonReader::format(d_hat));
  const ModelChoice choice = choose_model(spec, d_hat / contact_radius(shape));
  const bool default_output = run.output.empty();
  OutputDirectory output(default_output ? std::filesystem::path("out") / spec.name : run.output, run.replace,
                         /*create_parent=*/default_output);
  SceneMobility mobility = make_mobility(choice, spec.mobility, shape, poses.size());

  summary.bodies = poses.size();
  summary.model = model_name(choice) + (choice.model == MobilityModel::multiblob && std::is_same_v<S, Sphere>
                                            ? " (shell of " + std::to_string(choice.shell_blobs) + " blobs)"
                                            : "");
  summary.model_reason = choice.reason;
  summary.dofs_per_body = choice.dofs_per_body;
  summary.d_hat = d_hat;
  summary.dt = spec.dt;
  summary.steps_requested = spec.steps;
  const long long steps = run.max_steps ? std::min(*run.max_steps, spec.steps) : spec.steps;
  out << "scene      " << spec.name << (spec.description.empty() ? "" : ": " + spec.description) << '\n'
      << "bodies     " << poses.size() << " x " << summary.shape << '\n'
      << "model      " << summary.model << ", " << choice.dofs_per_body << " dofs per body\n"
      << "           (" << choice.reason << ")\n"
      << "contact    d_hat " << JsonReader::format(d_hat) << ", solver " << spec.contact.solver << ", dt "
      << JsonReader::format(spec.dt) << ", " << steps << " steps" << (steps < spec.steps ? " (of " + std::to_string(spec.steps) + ", --max-steps)" : "")
      << '\n';

  const std::filesystem::path& dir = output.open();
  {
    std::ofstream scene_copy(dir / "scene.json");
    scene_copy << document.dump(2) << '\n';
  }
  std::visit(
      [&](auto& m) {
        using Model = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<Model, RpyMobility> && !std::is_same_v<S, Sphere>)
          throw SceneError("mobility.model", "'rpy' is for spheres only");
        else
          step_scene(spec, shape, std::move(poses), d_hat, m, dir, steps,
                     run.progress.value_or(isatty(fileno(stderr)) != 0), summary);
      },
      mobility);
  {
    std::ofstream s(dir / "summary.json");
    s << summary.json() << '\n';
  }
  summary.output = output.commit();
  return summary;
}

}  // namespace detail

void print_summary(const RunSummary& s, std::ostream& out) {
  char line[256];
  out << "status     " << s.status << (s.message.empty() ? "" : ": " + s.message) << '\n';
  std::snprintf(line, sizeof line, "steps      %lld of %lld (t = %.6g), %lld with contact forces, %lld sub-stepped\n",
                s.steps_done, s.steps_requested, s.time, s.contact_steps, s.substepped_steps);
  out << line;
  std::snprintf(line, sizeof line, "min d/d_hat %.6f (step %lld)\n", s.min_distance_ratio, s.min_distance_step);
  out << line;
  std::snprintf(line, sizeof line, "mobility   %zu applications in all, per step median %zu, max %zu%s%s%s\n",
                s.applications_total, s.applications_median, s.applications_max,
                s.contact_cost.empty() ? "" : " (contact cost mode: ", s.contact_cost.c_str(),
                s.contact_cost.empty() ? "" : ")");
  out << line;
  if (s.steps_done >= 2) {
    std::snprintf(line, sizeof line, "collisions pressure %.6g +- %.2g (time average of Yan eq. 16 summed over pairs, "
                  "block-averaged error%s)\n", s.collision_pressure_mean, s.collision_pressure_error,
                  s.collision_pressure_error_converged ? "" : ", not converged: run longer");
    out << line;
  }
  std::snprintf(line, sizeof line, "wall time  %.3g s (%.3g ms per step)\n", s.wall_time_s,
                s.steps_done > 0 ? 1e3 * s.wall_time_s / static_cast<double>(s.steps_done) : 0.0);
  out << line;
  out << "outputs    " << s.output.string() << "/{summary.json, steps.jsonl, stress.jsonl, scene.json"
      << (s.frames > 0 ? ", bodies.pvd (" + std::to_string(s.frames) + " frames)" : std::string()) << "}\n";
}

RunSummary run_scene(const RunOptions& run, std::ostream& out) {
  const nlohmann::json document = detail::load_scene_json(run.scene);
  const SceneSpec spec = read_scene(document, run.scene.stem().string());
  return std::visit(
      [&](const auto& shape) -> RunSummary {
        using S = std::decay_t<decltype(shape)>;
        if constexpr (std::is_same_v<S, Spherocylinder>) {
          if (spec.contact.line_contact) {
            LineContactRod rod{shape, spec.contact.line};
            validate(rod);
            return detail::run_shape(spec, document, rod, run, out);
          }
        }
        return detail::run_shape(spec, document, shape, run, out);
      },
      spec.shape);
}

}  // namespace stokescontact::apps
