// Speed versus error of every contact solver the library names (contact_solver_names) on the
// same sphere scenes: the Fig. 4 suspensions (Broms & Tornberg Sec. 3.1.1; 500 unit spheres,
// phi 0.24 and 0.12, random sequential addition) and a near-jammed packing (phi ~0.55, 200
// spheres by default, by compression with overlap relaxation; scenes/sphere_packing.hpp). Same step
// as Fig. 4: d_hat = the minimum gap, |f_i| = 100, dt = 0.01, U = M f not counted.
//
//   speed_vs_error [--configs 20] [--seed 1] [--scenes fig4-0.24,fig4-0.12,jammed-0.55]
//                  [--spheres 500] [--jammed-spheres 200] [--mobility rpy|multiblob|free-draining]
//                  [--cost both|formed|matrix-free] [--solvers except-cobyla|all|NAME,...] [--tol TOL]
//                  [--separation-margin 1e-3] [--output FILE]
//
// Errors of one solve, per configuration:
//   shortfall = max(0, 1 - min d / d_hat)  over all pairs after the step (0: d_hat respected);
//   excess    = sum lambda / best - 1, best = the smallest sum lambda among this
//               configuration's solves (every solver and cost mode) with min d / d_hat >=
//               1 - 1e-9; null when no solve qualifies, or when best = 0 < sum lambda.
// One JSON object per (scene, config, solver, cost) (to --output, else stdout), then a summary
// per scene and solver. scripts/plot_speed_vs_error.py plots the JSON.
#include <stokescontact/contact/solvers/contact_solver.hpp>
#include <stokescontact/io/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "common/cli.hpp"
#include "common/sphere_experiment.hpp"

namespace sc = stokescontact;
namespace ex = examples;

namespace speed_vs_error {

constexpr const char* kUsage =
    "usage: speed_vs_error [--configs 20] [--seed 1] [--scenes fig4-0.24,fig4-0.12,jammed-0.55]\n"
    "                      [--spheres 500] [--jammed-spheres 200] [--mobility rpy|multiblob|free-draining]\n"
    "                      [--cost both|formed|matrix-free] [--solvers except-cobyla|all|NAME,...] [--tol TOL]\n"
    "                      [--separation-margin 1e-3] [--output FILE]\n";

struct Options {
  int configs = 20;
  std::uint64_t seed = 1;
  std::vector<ex::SceneSpec> scenes;
  ex::MobilityModel mobility = ex::MobilityModel::rpy;
  std::vector<sc::MobilityCost> costs;
  std::vector<sc::ContactSolver> solvers;
  ex::StepSettings step;
  std::string output;
};

// "fig4-PHI" (random sequential addition) or "jammed-PHI" (dense packing).
ex::SceneSpec parse_scene(const std::string& name, std::size_t spheres, std::size_t jammed_spheres) {
  const std::size_t dash = name.find('-');
  const std::string kind = name.substr(0, dash);
  ex::SceneSpec spec{name, ex::PackingKind::random_sequential, spheres, 0.0};
  if (kind == "jammed") {
    spec.packing = ex::PackingKind::dense;
    spec.spheres = jammed_spheres;
  } else if (kind != "fig4") {
    throw std::invalid_argument("--scenes: '" + name + "' is not fig4-PHI or jammed-PHI");
  }
  std::size_t used = 0;
  try {
    spec.phi = std::stod(name.substr(dash + 1), &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (dash == std::string::npos || used == 0 || used != name.size() - dash - 1 || !(spec.phi > 0.0))
    throw std::invalid_argument("--scenes: '" + name + "' needs a packing fraction, e.g. " + kind + "-0.24");
  return spec;
}

std::vector<sc::MobilityCost> parse_costs(const std::string& name) {
  if (name == "both") return {sc::MobilityCost::formed, sc::MobilityCost::matrix_free};
  return {sc::mobility_cost_from_name(name, "--cost (or both)")};
}

const char* cost_name(sc::MobilityCost c) { return sc::mobility_cost_name(c); }

Options parse(int argc, char** argv) {
  ex::Arguments args(argc, argv);
  Options o;
  o.configs = static_cast<int>(args.integer("--configs", 20, 1));
  o.seed = static_cast<std::uint64_t>(args.integer("--seed", 1, 0));
  const auto spheres = static_cast<std::size_t>(args.integer("--spheres", 500, 2));
  const auto jammed = static_cast<std::size_t>(args.integer("--jammed-spheres", 200, 2));
  for (const std::string& s : args.list("--scenes", {"fig4-0.24", "fig4-0.12", "jammed-0.55"}))
    o.scenes.push_back(parse_scene(s, spheres, jammed));
  o.mobility = ex::parse_mobility(args.text("--mobility", "rpy"));
  o.costs = parse_costs(args.text("--cost", "both"));
  // Default: every solver but the COBYLA ones; COBYLA is derivative free and needs hours (and fails to
  // separate) at Nc ~ 200-1000: 20-80 s per step, 1000 evaluations, at Nc ~ 200 in our runs.
  const std::vector<std::string> names = args.list("--solvers", {"except-cobyla"});
  const bool all = names == std::vector<std::string>{"all"};
  const bool except_cobyla = names == std::vector<std::string>{"except-cobyla"};
  for (const std::string& n : all || except_cobyla ? sc::contact_solver_names() : names)
    if (!(except_cobyla && n.find("cobyla") != std::string::npos)) o.solvers.push_back(sc::contact_solver_from_name(n));
  o.step.tol = args.positive("--tol");
  o.step.options.separation_margin = args.number("--separation-margin", o.step.options.separation_margin, 0.0);
  o.step.options.validate();
  o.output = args.text("--output", "");
  args.reject_unknown();
  return o;
}

// One solve of one configuration.
struct Solve {
  std::size_t solver;  // index into Options::solvers
  sc::MobilityCost cost;
  ex::StepRecord record;
  double shortfall = 0.0;
  double excess = std::numeric_limits<double>::quiet_NaN();  // NaN: undefined (null in JSON)
};

// Fills shortfall and excess (see the top) for the solves of one configuration.
void score(std::vector<Solve>& solves) {
  double best = std::numeric_limits<double>::infinity();
  for (Solve& s : solves) {
    s.shortfall = std::max(0.0, 1.0 - s.record.min_ratio_after);
    if (s.record.min_ratio_after >= ex::kRespectsDHat) best = std::min(best, s.record.lambda_sum);
  }
  if (!std::isfinite(best)) return;
  for (Solve& s : solves) {
    if (best > 0.0) s.excess = s.record.lambda_sum / best - 1.0;
    else if (s.record.lambda_sum == 0.0) s.excess = 0.0;
  }
}

struct Summary {
  std::vector<double> wall, applications, shortfall, excess;
  int not_converged = 0;

  void add(const Solve& s) {
    wall.push_back(s.record.wall_time_s);
    applications.push_back(static_cast<double>(s.record.applications));
    shortfall.push_back(s.shortfall);
    if (std::isfinite(s.excess)) excess.push_back(s.excess);
    not_converged += s.record.status != "converged";
  }
};

using SummaryKey = std::tuple<std::size_t, std::size_t, int>;  // scene, solver, cost (in option order)

void print_summary(const Options& o, const std::map<SummaryKey, Summary>& summaries) {
  std::printf("\nSpeed vs error: %s mobility, %d configs per scene; shortfall = max(0, 1 - min d/d_hat), "
              "excess = sum lambda / best separated - 1\n",
              ex::mobility_name(o.mobility), o.configs);
  std::printf("%-12s %-15s %-11s | %9s %8s | %10s | %10s %10s | %s\n", "scene", "solver", "cost", "med wall",
              "med apps", "worst shrt", "med excess", "max excess", "not conv.");
  for (const auto& [key, s] : summaries) {
    const auto [scene, solver, cost] = key;
    std::printf("%-12s %-15s %-11s | %8.4fs %8.0f | %10.2e | %10.2e %10.2e | %d\n", o.scenes[scene].name.c_str(),
                sc::contact_solver_name(o.solvers[solver]).c_str(), cost_name(o.costs[static_cast<std::size_t>(cost)]),
                ex::median(s.wall), ex::median(s.applications), ex::maximum(s.shortfall), ex::median(s.excess),
                ex::maximum(s.excess), s.not_converged);
  }
}

std::string solve_json(const Options& o, const ex::SceneSpec& spec, const ex::SphereScene& scene, int config,
                       const Solve& s) {
  return "{\"scene\": \"" + spec.name + "\", \"spheres\": " + std::to_string(spec.spheres) +
         ", \"phi\": " + sc::json_number(spec.phi) + ", \"phi_reached\": " + sc::json_number(scene.packing.phi) +
         ", \"config\": " + std::to_string(config) + ", \"seed\": " + std::to_string(scene.seed) +
         ", \"mobility\": \"" + ex::mobility_name(o.mobility) +
         "\", \"solver\": \"" + sc::contact_solver_name(o.solvers[s.solver]) + "\", \"cost\": \"" + cost_name(s.cost) +
         "\", \"shortfall\": " + sc::json_number(s.shortfall) +
         ", \"excess\": " + sc::json_number(s.excess) + ", " + ex::json_fields(s.record) + "}";
}

template <sc::MobilityOperator M>
std::vector<Solve> solve_all(const Options& o, const ex::SphereScene& scene, M& mobility) {
  const sc::VecX U = ex::unconstrained_velocities(mobility, scene);
  std::vector<Solve> solves;
  for (std::size_t solver = 0; solver < o.solvers.size(); ++solver)
    for (const sc::MobilityCost cost : o.costs) {
      ex::StepSettings settings = o.step;
      settings.options.cost = cost;
      solves.push_back({solver, cost, ex::run_step(o.solvers[solver], scene, mobility, U, settings)});
    }
  score(solves);
  return solves;
}

void run(const Options& o) {
  ex::JsonLines sink(o.output);
  std::map<SummaryKey, Summary> summaries;
  for (std::size_t k = 0; k < o.scenes.size(); ++k) {
    const ex::SceneSpec& spec = o.scenes[k];
    ex::SphereMobility mobility = ex::make_mobility(o.mobility, spec.spheres);
    for (int c = 0; c < o.configs; ++c) {
      const ex::SphereScene scene = ex::make_scene(spec, o.seed + static_cast<std::uint64_t>(c));
      const std::vector<Solve> solves = std::visit([&](auto& m) { return solve_all(o, scene, m); }, mobility);
      for (const Solve& s : solves) {
        const int cost = static_cast<int>(std::find(o.costs.begin(), o.costs.end(), s.cost) - o.costs.begin());
        summaries[{k, s.solver, cost}].add(s);
        sink.line(solve_json(o, spec, scene, c, s));
      }
      if (sink.to_file())
        std::printf("%s config %d: phi %.4f, d_hat %.3g, Nc %zu\n", spec.name.c_str(), c, scene.packing.phi,
                    scene.d_hat, solves.front().record.flagged);
      std::fflush(stdout);
    }
  }
  print_summary(o, summaries);
}

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  Options o;
  return ex::driver_main("speed_vs_error", kUsage, [&] { o = parse(argc, argv); }, [&] { run(o); });
}

}  // namespace speed_vs_error
