// Broms & Tornberg Fig. 4 (Sec. 3.1.1) and Table 1 (Sec. 3.1.2): one contact step on random
// suspensions of 500 unit spheres in a cube, packing fractions 24% and 12%, 200 configurations
// each. Per configuration: d_hat = the minimum gap, forces of random direction with
// |f_i| = 100, U = M f (one application, not counted), one contact step with dt = 0.01.
//
//   fig4_spheres [--configs 200] [--seed 1] [--phi 0.24,0.12] [--spheres 500]
//                [--solver NAME] [--mobility multiblob|rpy|free-draining]
//                [--d-try-multiplier 1] [--d-try-rule absolute|relative] [--tol TOL] [--dt 0.01]
//                [--cost formed|matrix-free]
//                [--separation-margin 1e-3] [--end-of-step] [--pairs] [--output FILE] [--table1]
//                [--objective sum|dissipation] [--substep-halvings K]
//
// Prints one JSON object per configuration (to --output if given, else stdout), then a
// summary table per phi. --tol sets the eq. 29 TOL of the barrier and default solvers (without
// it each keeps its own: barrier 1e-2, the paper's). --pairs adds per-pair distances and
// forces (Fig. 4c, 4e, 5). --d-try-rule: absolute is the paper's eq. 31 (the default here, as
// the paper's figures use it), relative the library's default (per pair, Galilean invariant).
// --end-of-step: the paper's check at the end of the step only (ContactStepOptions::
// whole_step off). Every record says how many pairs overlap inside the step along the
// returned motion (interior_overlaps) and how deep (interior_min_d_over_d_hat).
// --table1: the Sec. 3.1.2 sweep d_try x {1, 1.1, 1.2}, TOL in {1e-2, 5e-3, 5e-6} on the
// first --phi (default 0.24), solver default barrier-slsqp (the paper's), contact forces
// compared with the reference (d_try x 1, TOL 5e-6). With it, each configuration also writes an
// "extra_pairs" record: lambda / |f| of the pairs flagged at d_try x 1.1 and x 1.2 but not at
// x 1, at TOL 5e-6 (Fig. 5b with the lambda sum, Fig. 6 with --objective dissipation).
// --objective: eq. 14's norm for the barrier solvers, sum of lambda (the default) or the
// dissipation lambda^T D^T M D lambda.
// --substep-halvings K: instead of one contact step, one TimeStepper step of --dt from each
// configuration under its forces (U = M f at every sub-step's start), halved up to K times
// where a contact step fails (TimeStepperOptions::max_substep_halvings; a step too crowded to
// solve is refused at once, ContactStepOptions::max_flagged_pairs_per_body): per
// configuration the sub-steps taken, the status, min d / d_hat over all pairs at the end
// (brute force), the applications and the wall time of the whole step.
#include <stokescontact/contact/solvers/contact_solver.hpp>
#include <stokescontact/dynamics/time_stepper.hpp>
#include <stokescontact/io/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/cli.hpp"
#include "common/sphere_experiment.hpp"

namespace sc = stokescontact;
namespace ex = examples;

namespace fig4_spheres {

constexpr const char* kUsage =
    "usage: fig4_spheres [--configs 200] [--seed 1] [--phi 0.24,0.12] [--spheres 500] [--solver NAME]\n"
    "                    [--mobility multiblob|rpy|free-draining] [--d-try-multiplier 1] [--dt 0.01]\n"
    "                    [--d-try-rule absolute|relative] [--tol TOL]\n"
    "                    [--cost formed|matrix-free] [--separation-margin 1e-3] [--end-of-step] [--pairs]\n"
    "                    [--output FILE]\n"
    "                    [--table1] [--objective sum|dissipation] [--substep-halvings K]\n";

struct Options {
  int configs = 200;
  std::uint64_t seed = 1;
  std::vector<double> phis;
  std::size_t spheres = 500;
  sc::ContactSolver solver;
  ex::MobilityModel mobility = ex::MobilityModel::multiblob;
  ex::StepSettings step;
  std::string output;
  bool table1 = false;
  int substep_halvings = -1;  // >= 0: one TimeStepper step per configuration, halved up to this often
};

sc::MobilityCost parse_cost(const std::string& name) { return sc::mobility_cost_from_name(name, "--cost"); }

Options parse(int argc, char** argv) {
  ex::Arguments args(argc, argv);
  Options o;
  o.table1 = args.flag("--table1");
  o.configs = static_cast<int>(args.integer("--configs", 200, 1));
  o.seed = static_cast<std::uint64_t>(args.integer("--seed", 1, 0));
  o.phis = args.numbers("--phi", o.table1 ? std::vector<double>{0.24} : std::vector<double>{0.24, 0.12}, 1e-6);
  o.spheres = static_cast<std::size_t>(args.integer("--spheres", 500, 2));
  // Fig. 4 uses the default solver; Table 1 is about the barrier method's TOL (eq. 29).
  o.solver = sc::contact_solver_from_name(args.text("--solver", o.table1 ? "barrier-slsqp" : "default"));
  const std::string objective = args.text("--objective", "sum");
  if (objective != "sum" && objective != "dissipation")
    throw std::invalid_argument("--objective must be sum or dissipation, got '" + objective + "'");
  if (objective == "dissipation") {
    auto* barrier = std::get_if<sc::BarrierNloptOptions>(&o.solver);
    if (!barrier)
      throw std::invalid_argument("--objective dissipation needs a barrier solver, got '" +
                                  sc::contact_solver_name(o.solver) + "'");
    barrier->objective = sc::BarrierObjective::dissipation;
  }
  o.mobility = ex::parse_mobility(args.text("--mobility", "multiblob"));
  o.step.dt = args.number("--dt", ex::kTimeStep, 0.0);
  sc::require_positive(o.step.dt, "--dt");
  o.step.d_try_multiplier = args.number("--d-try-multiplier", 1.0, 1.0);
  const std::string rule = args.text("--d-try-rule", "absolute");
  if (rule != "absolute" && rule != "relative")
    throw std::invalid_argument("--d-try-rule must be absolute or relative, got '" + rule + "'");
  o.step.d_try_rule = rule == "relative" ? sc::DTryRule::relative : sc::DTryRule::absolute;
  // TOL (eq. 29) replaces the solver's own when given (barrier: 1e-2, the paper's).
  o.step.tol = args.positive("--tol");
  o.step.options.cost = parse_cost(args.text("--cost", "matrix-free"));
  o.step.options.separation_margin = args.number("--separation-margin", o.step.options.separation_margin, 0.0);
  o.step.options.whole_step = !args.flag("--end-of-step");
  o.step.options.validate();
  o.step.pair_details = args.flag("--pairs");
  o.output = args.text("--output", "");
  o.substep_halvings = static_cast<int>(args.integer("--substep-halvings", -1, -1));
  if (o.substep_halvings > 30) throw std::invalid_argument("--substep-halvings must lie in [0, 30]");
  if (o.substep_halvings >= 0 && (o.table1 || o.step.pair_details || o.step.tol))
    throw std::invalid_argument("--substep-halvings takes one stepper step per configuration: not with --table1, --pairs or --tol");
  args.reject_unknown();
  return o;
}

const char* cost_name(const Options& o) {
  return sc::mobility_cost_name(o.step.options.cost);
}

ex::SceneSpec fig4_scene(const Options& o, double phi) {
  return {"fig4", ex::PackingKind::random_sequential, o.spheres, phi};
}

std::string step_json(const Options& o, const ex::SphereScene& scene, double phi, int config,
                      const std::string& extra, const ex::StepRecord& r) {
  return "{\"record\": \"step\", \"seed\": " + std::to_string(scene.seed) + ", \"config\": " + std::to_string(config) +
         ", \"phi\": " + sc::json_number(phi) + ", \"phi_reached\": " + sc::json_number(scene.packing.phi) +
         ", \"spheres\": " + std::to_string(o.spheres) + ", \"mobility\": \"" + ex::mobility_name(o.mobility) +
         "\", \"solver\": \"" + sc::contact_solver_name(o.solver) + "\", \"cost\": \"" + cost_name(o) + "\", \"dt\": " +
         sc::json_number(o.step.dt) +
         extra + ", " + ex::json_fields(r) + "}";
}

std::string progress(const ex::StepRecord& r, double phi, int config) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "phi %.2f config %3d: Nc %4zu active %3zu min d/d_hat %.6f apps %4zu %8.3f s %s",
                phi, config, r.flagged, r.active, r.min_ratio_after, r.applications, r.wall_time_s, r.status.c_str());
  return buf;
}

// ---------------------------------------------------------------------------------------
// Fig. 4

struct PhiSummary {
  std::vector<double> min_after, applications, wall, nc;
  int respects = 0;  // configs with min d >= d_hat (1 - 1e-9)
  int converged = 0;    // configs whose step reported `converged`
  int overlapping = 0;  // configs with a pair overlapping inside the step
  double deepest = 0.0;  // the smallest interior d / d_hat among them

  void add(const ex::StepRecord& r) {
    min_after.push_back(r.min_ratio_after);
    applications.push_back(static_cast<double>(r.applications));
    wall.push_back(r.wall_time_s);
    nc.push_back(static_cast<double>(r.flagged));
    respects += r.min_ratio_after >= ex::kRespectsDHat;
    converged += r.status == "converged";
    if (r.interior_overlaps > 0) {
      ++overlapping;
      deepest = std::min(deepest, r.interior_min_ratio);
    }
  }
};

void print_fig4_summary(const Options& o, const std::vector<std::pair<double, PhiSummary>>& rows) {
  std::printf("\nFig. 4: %zu spheres, %s mobility, solver %s, cost %s, dt %g, d_try x %g (%s), TOL %s, %s\n", o.spheres,
              ex::mobility_name(o.mobility), sc::contact_solver_name(o.solver).c_str(), cost_name(o), o.step.dt,
              o.step.d_try_multiplier, o.step.d_try_rule == sc::DTryRule::relative ? "per pair" : "eq. 31",
              o.step.tol ? sc::json_number(*o.step.tol).c_str() : "the solver's own",
              o.step.options.whole_step ? "whole step" : "end of step only");
  std::printf("%5s %7s | %-29s | %9s | %-13s | %9s | %7s | %s\n", "phi", "configs", "min d/d_hat after (min med max)",
              "d>=d_hat", "apps (med max)", "med wall", "med Nc",
              "overlap inside the step (configs, deepest d/d_hat) | converged");
  for (const auto& [phi, s] : rows)
    std::printf("%5.2f %7zu | %9.6f %9.6f %9.6f | %8.1f%% | %6.0f %6.0f | %8.3fs | %7.0f | %d, %.3g | %d\n", phi,
                s.min_after.size(), ex::minimum(s.min_after), ex::median(s.min_after), ex::maximum(s.min_after),
                100.0 * s.respects / static_cast<double>(s.min_after.size()), ex::median(s.applications),
                ex::maximum(s.applications), ex::median(s.wall), ex::median(s.nc), s.overlapping, s.deepest,
                s.converged);
}

// --substep-halvings: one TimeStepper step per configuration (see the top).
template <sc::MobilityOperator M>
void run_stepper(const Options& o, M& mobility) {
  ex::JsonLines sink(o.output);
  std::printf("One stepper step of dt %g per configuration: %zu spheres, %s mobility, solver %s, cost %s, up to %d "
              "halvings\n%5s %6s | %8s %9s | %12s | %6s | %9s | %s\n",
              o.step.dt, o.spheres, ex::mobility_name(o.mobility), sc::contact_solver_name(o.solver).c_str(),
              cost_name(o), o.substep_halvings, "phi", "config", "substeps", "flagged", "min d/d_hat", "apps",
              "wall", "status");
  for (const double phi : o.phis)
    for (int c = 0; c < o.configs; ++c) {
      const ex::SphereScene scene = ex::make_scene(fig4_scene(o, phi), o.seed + static_cast<std::uint64_t>(c));
      sc::TimeStepperOptions options;
      options.dt = o.step.dt;
      options.d_hat = scene.d_hat;
      options.d_try_multiplier = o.step.d_try_multiplier;
      options.d_try_rule = o.step.d_try_rule;
      options.max_substep_halvings = o.substep_halvings;
      options.contact_step = o.step.options;
      sc::TimeStepper<sc::Sphere, M> stepper({sc::Sphere{1.0}}, scene.packing.poses, mobility, o.solver, options);
      stepper.set_external_forces(ex::stacked_forces(scene.forces, mobility.dofs_per_body()));
      std::string status, message;
      sc::StepDiagnostics d;
      const auto start = std::chrono::steady_clock::now();
      try {
        d = stepper.step();
        status = sc::to_string(d.status);
        message = d.message;
      } catch (const std::runtime_error& e) {  // every halving failed: the stepper keeps Q_t
        status = "failed_separation";
        message = e.what();
      }
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double min_ratio =
          sc::minimum_pair_distance(sc::Sphere{1.0}, std::span<const sc::Pose>(stepper.poses())).distance / scene.d_hat;
      sink.line("{\"record\": \"stepper\", \"seed\": " + std::to_string(scene.seed) + ", \"config\": " + std::to_string(c) +
                    ", \"phi\": " + sc::json_number(phi) + ", \"spheres\": " + std::to_string(o.spheres) +
                    ", \"mobility\": \"" + ex::mobility_name(o.mobility) + "\", \"solver\": \"" +
                    sc::contact_solver_name(o.solver) + "\", \"cost\": \"" + cost_name(o) + "\", \"dt\": " +
                    sc::json_number(o.step.dt) + ", \"max_substep_halvings\": " + std::to_string(o.substep_halvings) +
                    ", \"substeps\": " + std::to_string(d.substeps) + ", \"flagged_pairs\": " +
                    std::to_string(d.flagged_pairs) + ", \"min_d_over_d_hat_after\": " + sc::json_number(min_ratio) +
                    ", \"mobility_applications\": " + std::to_string(d.mobility_applications) +
                    ", \"iterations\": " + std::to_string(d.iterations) + ", \"wall_time_s\": " +
                    sc::json_number(wall) + ", \"status\": \"" + status + "\", \"message\": " +
                    sc::json_quoted(message) + "}");
      std::printf("%5.2f %6d | %8zu %9zu | %12.6f | %6zu | %8.2fs | %s\n", phi, c, d.substeps, d.flagged_pairs,
                  min_ratio, d.mobility_applications, wall, status.c_str());
      std::fflush(stdout);
    }
}

template <sc::MobilityOperator M>
void run_fig4(const Options& o, M& mobility) {
  ex::JsonLines sink(o.output);
  std::vector<std::pair<double, PhiSummary>> rows;
  for (const double phi : o.phis) {
    PhiSummary summary;
    for (int c = 0; c < o.configs; ++c) {
      const ex::SphereScene scene = ex::make_scene(fig4_scene(o, phi), o.seed + static_cast<std::uint64_t>(c));
      const sc::VecX U = ex::unconstrained_velocities(mobility, scene);
      const ex::StepRecord r = ex::run_step(o.solver, scene, mobility, U, o.step);
      sink.line(step_json(o, scene, phi, c, "", r), progress(r, phi, c));
      summary.add(r);
    }
    rows.emplace_back(phi, std::move(summary));
  }
  print_fig4_summary(o, rows);
}

// ---------------------------------------------------------------------------------------
// Table 1 (Sec. 3.1.2): contact forces per sphere against the reference (d_try x 1, TOL 5e-6).
//   msd:          mean over all force components (3 per sphere, every sphere of every
//                 configuration) of (f - f_ref)^2; msd_over_f2 divides it by |f_i|^2 = 100^2.
//   max_rel_diff: max |f - f_ref| / max |f_ref|, both maxima over all those components
//                 (one ratio for the whole sweep, not a maximum of per-configuration ratios).

constexpr std::array<double, 3> kMultipliers{1.0, 1.1, 1.2};
constexpr std::array<double, 3> kTols{1e-2, 5e-3, 5e-6};

struct ForceDeviation {
  double squared_sum = 0.0, components = 0.0, max_diff = 0.0, max_ref = 0.0;
  std::vector<double> applications, nc;
  double min_after = std::numeric_limits<double>::infinity();

  void add(const ex::StepRecord& r, const sc::VecX& reference) {
    const sc::VecX diff = r.sphere_forces - reference;
    squared_sum += diff.squaredNorm();
    components += static_cast<double>(diff.size());
    max_diff = std::max(max_diff, diff.cwiseAbs().maxCoeff());
    max_ref = std::max(max_ref, reference.cwiseAbs().maxCoeff());
    applications.push_back(static_cast<double>(r.applications));
    nc.push_back(static_cast<double>(r.flagged));
    min_after = std::min(min_after, r.min_ratio_after);
  }
  double msd() const { return squared_sum / components; }
  double max_rel_diff() const { return max_ref > 0.0 ? max_diff / max_ref : 0.0; }
};

// eq. 14's norm of a barrier solver ("sum" for every other solver: they minimise no norm).
const char* objective_name(const sc::ContactSolver& solver) {
  const auto* barrier = std::get_if<sc::BarrierNloptOptions>(&solver);
  return barrier && barrier->objective == sc::BarrierObjective::dissipation ? "dissipation" : "sum";
}

void print_table1(const Options& o, const std::map<std::pair<int, int>, ForceDeviation>& dev, ex::JsonLines& sink) {
  std::printf("\nTable 1: %zu spheres, phi %.2f, %d configs, %s mobility, solver %s, objective %s; reference d_try x 1, "
              "TOL 5e-6\n",
              o.spheres, o.phis.front(), o.configs, ex::mobility_name(o.mobility),
              sc::contact_solver_name(o.solver).c_str(), objective_name(o.solver));
  std::printf("%-9s %-8s | %11s %11s | %12s | %9s %9s | %s\n", "d_try", "TOL", "msd", "msd/|f|^2", "max rel diff",
              "med apps", "med Nc", "min d/d_hat after");
  for (const auto& [key, d] : dev) {
    const double mult = kMultipliers[static_cast<std::size_t>(key.first)];
    const double tol = kTols[static_cast<std::size_t>(key.second)];
    std::printf("x %-7.1f %-8.0e | %11.3e %11.3e | %12.3g | %9.0f %9.0f | %.6f\n", mult, tol, d.msd(),
                d.msd() / (ex::kForceMagnitude * ex::kForceMagnitude), d.max_rel_diff(), ex::median(d.applications),
                ex::median(d.nc), d.min_after);
  }
  for (const auto& [key, d] : dev) {
    const double mult = kMultipliers[static_cast<std::size_t>(key.first)];
    const double tol = kTols[static_cast<std::size_t>(key.second)];
    sink.line("{\"record\": \"table1\", \"d_try_multiplier\": " + sc::json_number(mult) +
                  ", \"tol\": " + sc::json_number(tol) + ", \"configs\": " + std::to_string(o.configs) +
                  ", \"msd\": " + sc::json_number(d.msd()) +
                  ", \"msd_over_f2\": " + sc::json_number(d.msd() / (ex::kForceMagnitude * ex::kForceMagnitude)) +
                  ", \"max_rel_diff\": " + sc::json_number(d.max_rel_diff()) +
                  ", \"median_applications\": " + sc::json_number(ex::median(d.applications)) +
                  ", \"median_nc\": " + sc::json_number(ex::median(d.nc)) +
                  ", \"min_d_over_d_hat_after\": " + sc::json_number(d.min_after) + "}",
              "");
  }
}

// Fig. 5b / 6: lambda / |f| of the pairs `wider` flags that `reference` (d_try x 1) does not.
std::vector<double> extra_pair_forces(const ex::StepRecord& reference, const ex::StepRecord& wider) {
  std::vector<std::pair<Eigen::Index, Eigen::Index>> known = reference.pair_bodies;
  std::sort(known.begin(), known.end());
  std::vector<double> extra;
  for (std::size_t k = 0; k < wider.pair_bodies.size(); ++k)
    if (!std::binary_search(known.begin(), known.end(), wider.pair_bodies[k]))
      extra.push_back(wider.pair_lambda_over_f[k]);
  return extra;
}

template <sc::MobilityOperator M>
void run_table1(const Options& o, M& mobility) {
  if (!sc::stopping_tolerance(o.solver))
    std::fprintf(stderr, "note: %s has no TOL (eq. 29); only d_try varies\n",
                 sc::contact_solver_name(o.solver).c_str());
  const double phi = o.phis.front();
  ex::JsonLines sink(o.output);
  std::map<std::pair<int, int>, ForceDeviation> deviations;
  for (int c = 0; c < o.configs; ++c) {
    const ex::SphereScene scene = ex::make_scene(fig4_scene(o, phi), o.seed + static_cast<std::uint64_t>(c));
    const sc::VecX U = ex::unconstrained_velocities(mobility, scene);
    std::optional<ex::StepRecord> reference;  // (x 1, 5e-6): the first combination run
    for (const int t : {2, 0, 1})
      for (int m = 0; m < 3; ++m) {
        ex::StepSettings settings = o.step;
        settings.pair_details = true;
        settings.d_try_multiplier = kMultipliers[static_cast<std::size_t>(m)];
        settings.tol = kTols[static_cast<std::size_t>(t)];
        ex::StepRecord r = ex::run_step(o.solver, scene, mobility, U, settings);
        if (!reference) {
          reference = r;
        } else if (t == 2) {
          sink.line("{\"record\": \"extra_pairs\", \"config\": " + std::to_string(c) +
                        ", \"d_try_multiplier\": " + sc::json_number(settings.d_try_multiplier) +
                        ", \"tol\": " + sc::json_number(*settings.tol) + ", \"objective\": \"" +
                        objective_name(o.solver) + "\", \"lambda_over_f\": " +
                        sc::json_array(extra_pair_forces(*reference, r)) + "}",
                    "");
        }
        deviations[{m, t}].add(r, reference->sphere_forces);
        r.has_pair_details = o.step.pair_details;  // kept for the extra pairs; written with --pairs
        const std::string extra = ", \"d_try_multiplier\": " + sc::json_number(settings.d_try_multiplier) +
                                  ", \"tol\": " + sc::json_number(*settings.tol);
        char label[64];
        std::snprintf(label, sizeof label, "  (d_try x %g, TOL %g)", settings.d_try_multiplier, *settings.tol);
        sink.line(step_json(o, scene, phi, c, extra, r), progress(r, phi, c) + label);
      }
  }
  deviations.erase({0, 2});  // the reference itself
  print_table1(o, deviations, sink);
}

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  Options o;
  return ex::driver_main(
      "fig4_spheres", kUsage, [&] { o = parse(argc, argv); },
      [&] {
        ex::SphereMobility mobility = ex::make_mobility(o.mobility, o.spheres);
        std::visit([&](auto& m) { o.table1 ? run_table1(o, m) : o.substep_halvings >= 0 ? run_stepper(o, m) : run_fig4(o, m); },
                   mobility);
      });
}

}  // namespace fig4_spheres
