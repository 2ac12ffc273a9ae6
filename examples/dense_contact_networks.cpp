// Contact steps on dense contact networks, every solver side by side: the cost against the
// number of pushed pairs, where the working set is one connected cluster.
//
//   dense_contact_networks [--part ball,jammed] [--spheres 1000] [--steps 300] [--phi 0.45,0.5,0.55,0.6]
//                          [--solvers default,lcp-newton,lcp-bbpgd,lcp-apgd] [--cost blocks,matrix-free]
//                          [--output FILE]
//
// Each part runs once per cost mode (contact_step.hpp: blocks forms M D from the free-draining
// bodies' blocks, matrix-free applies M).
// ball: N unit spheres (random sequential addition, phi 0.3, seed 1) driven towards their
//   centroid by |f| = 20, free draining, dt = d_hat = 0.01, forward Euler with the default
//   solver for --steps steps: the network grows as the ball compacts. Per step: pushed pairs,
//   applications, wall time of the contact step. Summary: per band of pushed pairs, the median
//   time, and time / pushed pairs (flat when the cost is linear in the contacts).
// jammed: N spheres compressed to each packing fraction (dense_packing, seed 1, smallest gaps
//   ~1e-3), random forces |f| = 100, free draining, dt = 0.01, d_hat = 1e-4: one contact step
//   per solver; pushed pairs, applications, wall time, min d / d_hat after, complementarity.
//   An LCP sequence's name with "-polished" (lcp-bbpgd-polished, ...) runs it on to the
//   default solver's own end, Broms eq. 29 at d >= d_hat (LcpSequenceOptions::tol and margin
//   set to the DefectCorrectionOptions defaults): a complementary baseline, where the plain
//   sequence stops at its first separated iterate.
// One JSON object per line (to --output if given, else stdout) and a readable summary.
#include <stokescontact/contact/solvers/contact_solver.hpp>
#include <stokescontact/io/json.hpp>
#include <stokescontact/mobility/free_draining.hpp>
#include <stokescontact/scenes/random.hpp>
#include <stokescontact/scenes/sphere_packing.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "common/cli.hpp"

namespace sc = stokescontact;
namespace ex = examples;

namespace dense_contact_networks {

constexpr const char* kUsage =
    "usage: dense_contact_networks [--part ball,jammed] [--spheres 1000] [--steps 300] [--phi 0.45,0.5,0.55,0.6]\n"
    "                              [--solvers default,lcp-newton,lcp-bbpgd,lcp-apgd] [--cost blocks,matrix-free]\n"
    "                              [--output FILE]\n";

const std::vector<sc::Sphere> kShapes{sc::Sphere{1.0}};

sc::VecX stacked(const std::vector<sc::Vec3>& f) {
  sc::VecX F(3 * static_cast<Eigen::Index>(f.size()));
  for (std::size_t k = 0; k < f.size(); ++k) F.segment<3>(3 * static_cast<Eigen::Index>(k)) = f[k];
  return F;
}

std::size_t pushed_pairs(const sc::ContactStepResult& r) {
  return static_cast<std::size_t>((r.lambda.array() > 0.0).count());
}

std::string record(const char* part, const std::string& solver, const sc::ContactStepResult& r) {
  return std::string("{\"part\": \"") + part + "\", \"solver\": \"" + solver + "\", \"cost\": \"" +
         sc::mobility_cost_name(r.cost) + "\", \"flagged_pairs\": " +
         std::to_string(r.flagged_pairs) + ", \"pushed_pairs\": " + std::to_string(pushed_pairs(r)) +
         ", \"mobility_applications\": " + std::to_string(r.mobility_applications) + ", \"iterations\": " +
         std::to_string(r.iterations) + ", \"wall_time_s\": " + sc::json_number(r.wall_time_s) +
         ", \"min_d_over_d_hat_after\": " + sc::json_number(r.min_distance_ratio) +
         ", \"complementarity_residual\": " + sc::json_number(r.complementarity_residual) + ", \"lambda_sum\": " +
         sc::json_number(r.lambda_sum) + ", \"status\": \"" + std::string(sc::to_string(r.status)) + "\"" +
         ", \"message\": " + sc::json_quoted(r.message);
}

bool ball(ex::JsonLines& sink, std::size_t n, int steps, sc::MobilityCost mode) {
  const double dt = 0.01, d_hat = 0.01, force = 20.0;
  std::vector<sc::Pose> poses = sc::random_sequential_addition(n, 0.3, 1).poses;
  sc::FreeDrainingMobility mobility(sc::sphere_mobility(kShapes[0], 1.0), n, 3);
  sc::ContactStepOptions options;
  options.cost = mode;
  std::vector<std::pair<std::size_t, double>> cost;  // (pushed pairs, wall time)
  bool ok = true;
  for (int step = 0; step < steps; ++step) {
    sc::Vec3 centre = sc::Vec3::Zero();
    for (const sc::Pose& p : poses) centre += p.x / static_cast<double>(n);
    std::vector<sc::Vec3> f;
    for (const sc::Pose& p : poses) f.push_back(-force * (p.x - centre).normalized());
    mobility.set_configuration(poses);
    const sc::VecX U = mobility.apply(stacked(f));
    const sc::ContactStepProblem<sc::Sphere> problem{kShapes, poses, U, dt, d_hat};
    const sc::ContactStepResult r = sc::solve_contact_step(problem, mobility, options);
    sink.line(record("ball", "default", r) + ", \"step\": " + std::to_string(step) + "}");
    cost.emplace_back(pushed_pairs(r), r.wall_time_s);
    if (r.status != sc::ContactStepStatus::converged) {
      std::printf("ERROR: ball step %d: %s\n", step, r.message.c_str());
      ok = false;
      break;
    }
    poses = r.poses;
  }
  std::printf("\nBall: %zu spheres driven inward, |f| = %g, free draining, dt = d_hat = %g, default solver, %s\n"
              "%17s | %5s | %12s | %16s\n",
              n, force, dt, sc::mobility_cost_name(mode), "pushed pairs", "steps", "median time", "time / pushed");
  std::sort(cost.begin(), cost.end());
  const std::size_t largest = cost.empty() ? 0 : cost.back().first;
  const std::size_t band = std::max<std::size_t>(1, (largest + 5) / 6);
  for (std::size_t lo = 0; lo <= largest; lo += band) {
    std::vector<double> t, per;
    for (const auto& [pushed, seconds] : cost)
      if (pushed >= lo && pushed < lo + band && pushed > 0) {
        t.push_back(seconds);
        per.push_back(seconds / static_cast<double>(pushed));
      }
    if (!t.empty())
      std::printf("%7zu - %7zu | %5zu | %11.4fs | %13.2f us\n", lo, lo + band - 1, t.size(), ex::median(t),
                  1e6 * ex::median(per));
  }
  return ok;
}

constexpr std::string_view kPolished = "-polished";

// The solver `name` names: the library's (contact_solver_from_name), or an LCP sequence's name
// with kPolished, the sequence taken to complementarity.
sc::ContactSolver solver_named(const std::string& name) {
  if (!name.ends_with(kPolished)) return sc::contact_solver_from_name(name);
  sc::ContactSolver solver = sc::contact_solver_from_name(name.substr(0, name.size() - kPolished.size()));
  auto* sequence = std::get_if<sc::LcpSequenceOptions>(&solver);
  if (!sequence) throw std::invalid_argument("--solvers: '" + name + "': only an LCP sequence (lcp-*) can be polished");
  sequence->tol = sc::DefectCorrectionOptions{}.tol;
  sequence->margin = sc::DefectCorrectionOptions{}.margin;
  return solver;
}

bool jammed(ex::JsonLines& sink, std::size_t n, const std::vector<double>& phis, const std::vector<std::string>& solvers,
            sc::MobilityCost mode) {
  const double dt = 0.01, d_hat = 1e-4, force = 100.0;
  std::printf("\nJammed packings: %zu spheres, |f| = %g, free draining, dt = %g, d_hat = %g, %s\n"
              "%6s %6s | %-18s | %7s %7s | %6s %5s | %10s | %12s | %9s | %s\n",
              n, force, dt, d_hat, sc::mobility_cost_name(mode), "phi", "gap", "solver", "Nc", "pushed", "apps", "its", "wall", "min d/d_hat",
              "compl.", "status");
  bool ok = true;
  for (const double phi : phis) {
    const sc::SpherePacking packing = sc::dense_packing(n, phi, 1);
    sc::Rng rng(1);
    const sc::VecX F = stacked(sc::random_forces(n, force, rng));
    for (const std::string& name : solvers) {
      sc::FreeDrainingMobility mobility(sc::sphere_mobility(kShapes[0], 1.0), n, 3);
      mobility.set_configuration(packing.poses);
      const sc::VecX U = mobility.apply(F);
      const sc::ContactStepProblem<sc::Sphere> problem{kShapes, packing.poses, U, dt, d_hat};
      sc::ContactStepOptions options;
      options.cost = mode;
      const sc::ContactStepResult r =
          sc::solve_contact_step(problem, mobility, options, solver_named(name));
      sink.line(record("jammed", name, r) + ", \"phi\": " + sc::json_number(packing.phi) + ", \"min_gap\": " +
                sc::json_number(packing.min_gap) + "}");
      std::printf("%6.3f %6.0e | %-18s | %7zu %7zu | %6zu %5d | %9.3fs | %12.6f | %9.2e | %s\n", packing.phi,
                  packing.min_gap, name.c_str(), r.flagged_pairs, pushed_pairs(r), r.mobility_applications,
                  r.iterations, r.wall_time_s, r.min_distance_ratio, r.complementarity_residual,
                  std::string(sc::to_string(r.status)).c_str());
      std::fflush(stdout);
      if (r.status == sc::ContactStepStatus::failed_separation) {
        std::printf("ERROR: phi %.3f, %s: %s\n", packing.phi, name.c_str(), r.message.c_str());
        ok = false;
      }
    }
  }
  return ok;
}

struct Options {
  std::vector<std::string> parts;
  std::size_t spheres = 1000;
  int steps = 300;
  std::vector<double> phis;
  std::vector<std::string> solvers;
  std::vector<sc::MobilityCost> costs;
  std::string output;
};

Options parse(int argc, char** argv) {
  ex::Arguments args(argc, argv);
  Options o;
  o.parts = args.list("--part", {"ball", "jammed"});
  for (const std::string& part : o.parts)
    if (part != "ball" && part != "jammed")
      throw std::invalid_argument("--part: unknown part '" + part + "' (known: ball, jammed)");
  o.spheres = static_cast<std::size_t>(args.integer("--spheres", 1000, 2));
  o.steps = static_cast<int>(args.integer("--steps", 300, 1));
  o.phis = args.numbers("--phi", {0.45, 0.5, 0.55, 0.6}, 0.0);
  o.solvers = args.list("--solvers", {"default", "lcp-newton", "lcp-bbpgd", "lcp-apgd"});
  for (const std::string& s : o.solvers) solver_named(s);
  for (const std::string& c : args.list("--cost", {"blocks", "matrix-free"}))
    o.costs.push_back(sc::mobility_cost_from_name(c, "--cost"));
  o.output = args.text("--output", "");
  args.reject_unknown();
  return o;
}

// 0 when no step failed, 1 otherwise ("ERROR" lines say where).
int run(const Options& o) {
  ex::JsonLines sink(o.output);
  bool ok = true;
  for (const std::string& part : o.parts)
    for (const sc::MobilityCost cost : o.costs)
      ok = (part == "ball" ? ball(sink, o.spheres, o.steps, cost) : jammed(sink, o.spheres, o.phis, o.solvers, cost)) && ok;
  return ok ? 0 : 1;
}

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  Options o;
  return ex::driver_main("dense_contact_networks", kUsage, [&] { o = parse(argc, argv); }, [&] { return run(o); });
}

}  // namespace dense_contact_networks
