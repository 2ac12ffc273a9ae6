// The cost of one contact step as the suspension grows: N unit spheres placed by random
// sequential addition at packing fraction phi (seed N), forces of random direction with
// |f| = 100, free-draining mobility, dt = d_hat = 0.01 (the pushed pairs are those the trial
// step brings below d_hat).
//
//   contact_step_scaling [--sizes 1000,10000,100000] [--phi 0.3] [--cost blocks,matrix-free,formed]
//                        [--formed-max 10000] [--solver default] [--max-memory-mb 0]
//                        [--repeat 3] [--late-end-check] [--output FILE]
//
// Per N and cost mode: the unconstrained step (M at Q_t, U = M f and Q* = Q_t + dt U), the
// contact step (detection, solve and the whole-step guarantee), flagged and pushed pairs,
// mobility applications, solver iterations, status, min d / d_hat after, sphere-steps per
// second of the contact step, its time by phase (ContactStepResult::phase_times: medians over
// the repeats, phase by phase), its broad-phase queries (and how many kept candidates
// answered) and the process's peak resident memory so far (sizes run in the
// order given). Formed mode runs only up to --formed-max bodies: it forms one column of M D per
// working-set pair, O(N) each. blocks (the library's automatic choice for free draining) forms
// M D sparsely from the bodies' blocks: no application. --max-memory-mb > 0: ERROR when the
// peak exceeds it.
// Times: each step is run --repeat times from the same Q_t and the median is reported, as a
// simulation's steps after its first meet a warm heap; the first contact step's time (the
// process touching its memory for the first time: page faults) is reported as well. The
// repeats must give the same forces (ERROR otherwise).
// --late-end-check: the default solver checks the end only after a round has converged
// (DefectCorrectionOptions::early_end_check off), to compare with the library's default.
// One JSON object per line (to --output if given, else stdout) and a readable summary.
#include <stokescontact/contact/solvers/contact_solver.hpp>
#include <stokescontact/io/json.hpp>
#include <stokescontact/mobility/free_draining.hpp>
#include <stokescontact/scenes/random.hpp>
#include <stokescontact/scenes/sphere_packing.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "common/cli.hpp"

namespace sc = stokescontact;
namespace ex = examples;

namespace contact_step_scaling {

constexpr const char* kUsage =
    "usage: contact_step_scaling [--sizes 1000,10000,100000] [--phi 0.3] [--cost blocks,matrix-free,formed]\n"
    "                            [--formed-max 10000] [--solver default] [--max-memory-mb 0] [--repeat 3]\n"
    "                            [--late-end-check] [--output FILE]\n";

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The process's peak resident set (VmHWM) in MiB; 0 where /proc does not say.
double peak_memory_mb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0.0;
}

sc::MobilityCost cost_from_name(const std::string& name) { return sc::mobility_cost_from_name(name, "--cost"); }

struct Options {
  std::vector<std::size_t> sizes;
  double phi = 0.3;
  std::vector<std::string> costs;
  std::size_t formed_max = 10000;
  std::string solver_name = "default";
  double max_memory_mb = 0.0;
  int repeat = 3;
  bool late_end_check = false;
  std::string output;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 == 1 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

Options parse(int argc, char** argv) {
  ex::Arguments args(argc, argv);
  Options o;
  for (const std::string& s : args.list("--sizes", {"1000", "10000", "100000"})) {
    const long long v = std::stoll(s);
    if (v < 2) throw std::invalid_argument("--sizes: each must be >= 2, got " + s);
    o.sizes.push_back(static_cast<std::size_t>(v));
  }
  o.phi = args.number("--phi", 0.3, 0.0);
  o.costs = args.list("--cost", {"blocks", "matrix-free", "formed"});
  for (const std::string& c : o.costs) cost_from_name(c);
  o.formed_max = static_cast<std::size_t>(args.integer("--formed-max", 10000, 2));
  o.solver_name = args.text("--solver", "default");
  sc::contact_solver_from_name(o.solver_name);
  o.max_memory_mb = args.number("--max-memory-mb", 0.0, 0.0);
  o.repeat = static_cast<int>(args.integer("--repeat", 3, 1));
  o.late_end_check = args.flag("--late-end-check");
  if (o.late_end_check && !std::holds_alternative<sc::DefectCorrectionOptions>(sc::contact_solver_from_name(o.solver_name)))
    throw std::invalid_argument("--late-end-check: only the default solver checks the end early, not " + o.solver_name);
  o.output = args.text("--output", "");
  args.reject_unknown();
  return o;
}

// 0 when every step converged within the memory bound, 1 otherwise ("ERROR" lines say why).
int run(const Options& o) {
  sc::ContactSolver solver = sc::contact_solver_from_name(o.solver_name);
  if (o.late_end_check) std::get<sc::DefectCorrectionOptions>(solver).early_end_check = false;
  ex::JsonLines sink(o.output);
  const double dt = 0.01, d_hat = 0.01, force = 100.0;
  std::printf("Contact step scaling: spheres at phi %g, |f| = %g, free draining, dt = d_hat = %g, solver %s,\n"
              "median of %d repeats (first: the first contact step of each)\n"
              "%9s %11s | %10s | %10s %10s %6s | %7s %7s | %5s %4s | %9s | %10s | %8s | %s\n",
              o.phi, force, dt, o.solver_name.c_str(), o.repeat, "N", "cost", "unconstr.", "contact", "first", "ratio",
              "Nc", "pushed",
              "apps", "its", "min d/dh", "sphere-st/s", "peak MB", "status");
  const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  bool ok = true;
  for (const std::size_t n : o.sizes) {
    const sc::SpherePacking packing = sc::random_sequential_addition(n, o.phi, n);
    sc::Rng rng(n);
    const std::vector<sc::Vec3> f = sc::random_forces(n, force, rng);
    sc::VecX F(3 * static_cast<Eigen::Index>(n));
    for (std::size_t k = 0; k < n; ++k) F.segment<3>(3 * static_cast<Eigen::Index>(k)) = f[k];
    for (const std::string& cost_name : o.costs) {
      const sc::MobilityCost cost = cost_from_name(cost_name);
      if (cost == sc::MobilityCost::formed && n > o.formed_max) continue;
      sc::FreeDrainingMobility mobility(sc::sphere_mobility(shapes[0], 1.0), n, 3);
      sc::VecX U;
      std::vector<double> unconstrained_times, contact_times;
      std::vector<sc::ContactStepPhaseTimes> phases;
      for (int k = 0; k < o.repeat; ++k) {
        const auto start = std::chrono::steady_clock::now();
        mobility.set_configuration(packing.poses);
        U = mobility.apply(F);
        const std::vector<sc::Pose> trial = sc::advance_all(packing.poses, U, 3, dt);
        unconstrained_times.push_back(seconds_since(start));
      }
      const sc::ContactStepProblem<sc::Sphere> problem{shapes, packing.poses, U, dt, d_hat};
      sc::ContactStepOptions options;
      options.cost = cost;
      sc::ContactStepResult r;
      for (int k = 0; k < o.repeat; ++k) {
        const auto start = std::chrono::steady_clock::now();
        sc::ContactStepResult again = sc::solve_contact_step(problem, mobility, options, solver);
        contact_times.push_back(seconds_since(start));
        phases.push_back(again.phase_times);
        if (k > 0 && (again.lambda != r.lambda || again.status != r.status)) {
          std::printf("ERROR: N = %zu, %s: repeat %d of the same step gave other forces\n", n, cost_name.c_str(), k);
          ok = false;
        }
        r = std::move(again);
      }
      const double unconstrained_s = median(unconstrained_times), contact_s = median(contact_times);
      const auto phase_median = [&phases](double sc::ContactStepPhaseTimes::*phase) {
        std::vector<double> v;
        for (const sc::ContactStepPhaseTimes& p : phases) v.push_back(p.*phase);
        return median(v);
      };
      const double setup_s = phase_median(&sc::ContactStepPhaseTimes::setup_s),
                   solve_s = phase_median(&sc::ContactStepPhaseTimes::solve_s),
                   end_s = phase_median(&sc::ContactStepPhaseTimes::end_check_s),
                   interior_s = phase_median(&sc::ContactStepPhaseTimes::interior_check_s),
                   add_s = phase_median(&sc::ContactStepPhaseTimes::add_pairs_s),
                   finish_s = phase_median(&sc::ContactStepPhaseTimes::finish_s);
      const auto pushed = static_cast<std::size_t>((r.lambda.array() > 0.0).count());
      const double memory = peak_memory_mb();
      const double rate = static_cast<double>(n) / contact_s;
      sink.line("{\"N\": " + std::to_string(n) + ", \"phi\": " + sc::json_number(o.phi) + ", \"cost\": \"" +
                sc::mobility_cost_name(r.cost) + "\", \"solver\": \"" + o.solver_name + "\", \"unconstrained_s\": " +
                sc::json_number(unconstrained_s) + ", \"contact_step_s\": " + sc::json_number(contact_s) +
                ", \"first_contact_step_s\": " + sc::json_number(contact_times.front()) +
                ", \"repeats\": " + std::to_string(o.repeat) + ", \"early_end_check\": " +
                (o.late_end_check ? "false" : "true") +
                ", \"flagged_pairs\": " + std::to_string(r.flagged_pairs) + ", \"pushed_pairs\": " +
                std::to_string(pushed) + ", \"mobility_applications\": " + std::to_string(r.mobility_applications) +
                ", \"iterations\": " + std::to_string(r.iterations) + ", \"guarantee_rounds\": " +
                std::to_string(r.guarantee_rounds) + ", \"min_d_over_d_hat_after\": " +
                sc::json_number(r.min_distance_ratio) + ", \"status\": \"" + std::string(sc::to_string(r.status)) +
                "\", \"sphere_steps_per_s\": " + sc::json_number(rate) + ", \"peak_memory_mb\": " +
                sc::json_number(memory) + ", \"phases_s\": {\"setup\": " + sc::json_number(setup_s) +
                ", \"solve\": " + sc::json_number(solve_s) + ", \"end_check\": " + sc::json_number(end_s) +
                ", \"interior_check\": " + sc::json_number(interior_s) + ", \"add_pairs\": " +
                sc::json_number(add_s) + ", \"finish\": " + sc::json_number(finish_s) +
                "}, \"broad_phase_queries\": " + std::to_string(r.broad_phase_queries) +
                ", \"broad_phase_reused\": " + std::to_string(r.broad_phase_reused) + "}");
      std::printf("%9zu %11s | %9.4fs | %9.4fs %9.4fs %6.0f | %7zu %7zu | %5zu %4d | %9.6f | %10.3g | %8.0f | %s\n", n,
                  cost_name.c_str(), unconstrained_s, contact_s, contact_times.front(), contact_s / unconstrained_s,
                  r.flagged_pairs, pushed,
                  r.mobility_applications, r.iterations, r.min_distance_ratio, rate, memory,
                  std::string(sc::to_string(r.status)).c_str());
      std::printf("%21s   phases (medians): setup %.4fs, solve %.4fs, end check %.4fs, interior check %.4fs, "
                  "added pairs %.4fs, result %.4fs; broad-phase queries %d (%d from kept candidates)\n",
                  "", setup_s, solve_s, end_s, interior_s, add_s, finish_s, r.broad_phase_queries, r.broad_phase_reused);
      std::fflush(stdout);
      if (r.status != sc::ContactStepStatus::converged) {
        std::printf("ERROR: N = %zu, %s: %s\n", n, cost_name.c_str(), r.message.c_str());
        ok = false;
      }
      if (o.max_memory_mb > 0.0 && memory > o.max_memory_mb) {
        std::printf("ERROR: N = %zu: peak memory %.0f MB above --max-memory-mb %.0f\n", n, memory, o.max_memory_mb);
        ok = false;
      }
    }
  }
  return ok ? 0 : 1;
}

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  Options o;
  return ex::driver_main("contact_step_scaling", kUsage, [&] { o = parse(argc, argv); }, [&] { return run(o); });
}

}  // namespace contact_step_scaling
