// Broms & Tornberg Fig. 8 and Table 2 (Sec. 3.2.3): a 2D grid of 30 rods (L_rod = 2 end to
// end, R_rod = L_rod / 4) along z in the yz plane, in the biaxial compression flow of eq. 32
// (E = diag(1, -1/2, -1/2)), forward Euler with a contact step per time step, to T_end = 9,
// for d_hat in {0.01, 0.1} R_rod and dt in {0.02, 0.01, 0.005}.
//
//   fig8_biaxial [--d-hat 0.01,0.1] [--dt 0.02,0.01,0.005] [--t-end 9] [--t-s 4.36]
//                [--rows 5] [--columns 6] [--spacing-y 1.5] [--spacing-z 3]
//                [--solver NAME] [--mobility free-draining|multiblob] [--blobs-per-ring 8]
//                [--multiblob-solver matrix-free|dense|adaptive|automatic]
//                [--directions particle|surface|line|overlap-ends] [--node-spacing 0] [--line-width 1]
//                [--line-angle 0.05] [--cost formed|matrix-free|blocks|automatic] [--max-steps N] [--tilt 0]
//                [--max-iterations N] [--max-correction-turn 0.5] [--overlap-ends-min-overlap 0.1]
//                [--output FILE]
//
// --d-hat is in units of R_rod. --directions: the paper's d^P ("particle", eq. 20-21) and d^S
// ("surface", eq. 22-23, node spacing R_rod / 2 unless --node-spacing), or "line": d^P
// constrained with the force of near-parallel pairs spread over their overlap
// (geometry/line_contact.hpp; --line-width, default 2 R_rod, and --line-angle in rad). The grid: `columns` rods along y at centre spacing
// spacing-y, `rows` along z at spacing-z, centred on the flow's stagnation point; the paper
// shows the grid (Fig. 8a-b) without its spacings, and the defaults (gaps of half the rod's
// extent both ways: 0.5 = R_rod side by side, 1 = L_rod / 2 tip to tip) are ours.
// Per step one JSON object: whether the contact algorithm was triggered (the trial step
// Q* = Q_t + dt U_bg violates d_hat, the paper's count in Table 2), Nc and active pairs,
// mobility applications, wall time, the order parameter S (eq. 33), max |x_i| (the rods
// start at x = 0; eq. 32 keeps them there by symmetry), the largest rotation of a rod, min d /
// d_hat. Then one summary object per (d_hat, dt) and a table next to the paper's Table 2.
// --max-steps stops each run early (a measured partial run of an expensive model). --tilt
// turns rod k by (-1)^k (k + 1) / N times the given angle about x at t = 0: a perturbation of
// the symmetric start, to see whether the contacts restore or amplify it.
// --max-correction-turn: ContactStepOptions::max_correction_turn in radians (a step whose
// correction turns a rod further is refused and sub-stepped; a large value lifts the guard).
// --overlap-ends-min-overlap: ContactStepOptions::overlap_ends_min_overlap, in units of R_rod
// (near-parallel pairs overlapping less are held at their closest points).
#include <stokescontact/contact/contact_pairs.hpp>
#include <stokescontact/core/rigid_motion.hpp>
#include <stokescontact/dynamics/nematic_order.hpp>
#include <stokescontact/dynamics/time_stepper.hpp>
#include <stokescontact/io/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "common/cli.hpp"
#include "common/rod_experiment.hpp"

namespace sc = stokescontact;
namespace ex = examples;

namespace fig8_biaxial {

constexpr const char* kUsage =
    "usage: fig8_biaxial [--d-hat 0.01,0.1] [--dt 0.02,0.01,0.005] [--t-end 9] [--t-s 4.36] [--rows 5]\n"
    "                    [--columns 6] [--spacing-y 1.5] [--spacing-z 3] [--solver NAME]\n"
    "                    [--mobility free-draining|multiblob] [--blobs-per-ring 8]\n"
    "                    [--multiblob-solver matrix-free|dense|adaptive|automatic]\n"
    "                    [--directions particle|surface|line|overlap-ends] [--node-spacing 0] [--line-width 1]\n"
    "                    [--line-angle 0.05] [--cost formed|matrix-free|blocks|automatic] [--max-steps N] [--tilt 0]\n"
    "                    [--max-iterations N] [--max-correction-turn 0.5] [--overlap-ends-min-overlap 0.1]\n"
    "                    [--output FILE]\n";

constexpr double kLRod = 2.0, kRRod = kLRod / 4.0;  // Sec. 3.2.3

struct Options {
  std::vector<double> d_hat_fractions, dts;
  double t_end = 9.0, t_s = 4.36;
  int rows = 5, columns = 6;
  double spacing_y = 1.5, spacing_z = 3.0;
  sc::ContactSolver solver;
  ex::RodMobilityModel mobility = ex::RodMobilityModel::free_draining;
  int blobs_per_ring = 8;
  sc::MultiblobSolver multiblob_solver = sc::MultiblobSolver::matrix_free;
  ex::RodDirections directions = ex::RodDirections::particle;
  double line_width = 2.0 * kRRod, line_angle = 0.05;
  sc::ContactStepOptions step;
  long max_steps = 0;  // 0: to T_end
  double tilt = 0.0;
  std::string output;
};

Options parse(int argc, char** argv) {
  ex::Arguments args(argc, argv);
  Options o;
  o.d_hat_fractions = args.numbers("--d-hat", {0.01, 0.1}, 1e-12);
  o.dts = args.numbers("--dt", {0.02, 0.01, 0.005}, 1e-9);
  o.t_end = args.number("--t-end", 9.0, 0.0);
  o.t_s = args.number("--t-s", 4.36, 0.0);
  o.rows = static_cast<int>(args.integer("--rows", 5, 1));
  o.columns = static_cast<int>(args.integer("--columns", 6, 1));
  o.spacing_y = args.number("--spacing-y", 1.5, 2.0 * kRRod);
  o.spacing_z = args.number("--spacing-z", 3.0, kLRod);
  o.solver = sc::contact_solver_from_name(args.text("--solver", "default"));
  o.mobility = ex::parse_rod_mobility(args.text("--mobility", "free-draining"));
  o.blobs_per_ring = static_cast<int>(args.integer("--blobs-per-ring", 8, 3));
  o.multiblob_solver =
      sc::multiblob_solver_from_name(args.text("--multiblob-solver", "matrix-free"), "--multiblob-solver");
  o.directions = ex::parse_directions(args.text("--directions", "particle"));
  o.step.directions = ex::contact_directions(o.directions);
  o.line_width = args.number("--line-width", 2.0 * kRRod, 1e-12);
  o.line_angle = args.number("--line-angle", 0.05, 1e-12);
  o.step.node_spacing = args.number("--node-spacing", 0.0, 0.0);
  o.step.cost = sc::mobility_cost_from_name(args.text("--cost", "formed"), "--cost");
  o.max_steps = static_cast<long>(args.integer("--max-steps", 0, 0));
  o.tilt = args.number("--tilt", 0.0);
  o.step.max_correction_turn = args.number("--max-correction-turn", o.step.max_correction_turn, 1e-12);
  o.step.overlap_ends_min_overlap =
      args.number("--overlap-ends-min-overlap", o.step.overlap_ends_min_overlap, 1e-12);
  // The solver's iteration limit per round (LCPs of the LCP sequence, corrections of the
  // default solver); without it each keeps its own (20, 50).
  if (const auto limit = args.positive("--max-iterations")) {
    std::visit(
        [&](auto& solver) {
          if constexpr (requires { solver.max_iterations; }) solver.max_iterations = static_cast<int>(*limit);
        },
        o.solver);
  }
  o.output = args.text("--output", "");
  args.reject_unknown();
  if (o.rows * o.columns < 2) throw std::invalid_argument("--rows x --columns must be >= 2");
  return o;
}

// The grid in the yz plane, every rod along z (body z = lab z).
std::vector<sc::Pose> grid(const Options& o) {
  std::vector<sc::Pose> poses;
  const int n = o.rows * o.columns;
  for (int r = 0; r < o.rows; ++r)
    for (int c = 0; c < o.columns; ++c) {
      const int k = static_cast<int>(poses.size());
      const double angle = o.tilt * (k % 2 == 0 ? 1.0 : -1.0) * (k + 1) / n;
      poses.push_back({sc::Vec3(0.0, o.spacing_y * (c - 0.5 * (o.columns - 1)), o.spacing_z * (r - 0.5 * (o.rows - 1))),
                       angle == 0.0 ? sc::Quat::Identity() : sc::Quat(Eigen::AngleAxisd(angle, sc::Vec3::UnitX()))});
    }
  return poses;
}

// Table 2 of the paper: contact steps to T_end (and to T_S) for d_hat = 0.01 R_rod and
// 0.1 R_rod, and the total steps, at dt = 0.02, 0.01, 0.005.
struct PaperRow {
  double dt;
  int contact_001, contact_01, total;
  int contact_001_ts, contact_01_ts, total_ts;
};
constexpr std::array<PaperRow, 3> kTable2{{{0.02, 410, 412, 450, 178, 180, 218},
                                           {0.01, 819, 824, 900, 357, 362, 436},
                                           {0.005, 1639, 1647, 1800, 715, 723, 872}}};

int paper_count(double dt, double fraction, bool to_t_s) {
  for (const PaperRow& r : kTable2)
    if (std::abs(r.dt - dt) < 1e-12) {
      if (std::abs(fraction - 0.01) < 1e-12) return to_t_s ? r.contact_001_ts : r.contact_001;
      if (std::abs(fraction - 0.1) < 1e-12) return to_t_s ? r.contact_01_ts : r.contact_01;
    }
  return -1;
}

struct RunSummary {
  double d_hat_fraction = 0.0, dt = 0.0;
  long steps = 0, triggered = 0, triggered_ts = 0, flagged = 0, steps_ts = 0;
  long overlaps = 0;        // steps ending with some d^P < 0
  long below_d_hat = 0;     // steps ending with some d^P < d_hat (1 - separation margin)
  double min_ratio = std::numeric_limits<double>::infinity();
  double max_x = 0.0, min_s = 1.0, max_turn = 0.0;
  double s_at_t_s = 1.0;
  std::size_t applications = 0;
  double wall = 0.0;
  std::string error;  // a step that threw
  std::string multiblob_path;  // multiblob rods: "dense", "matrix-free" or "adaptive"
};

template <sc::Shape S, sc::MobilityOperator M>
RunSummary run(const Options& o, const S& rod, double fraction, double dt, M& mobility, ex::JsonLines& sink) {
  const double d_hat = fraction * kRRod;
  const std::vector<sc::Pose> start = grid(o);
  sc::TimeStepperOptions options;
  options.dt = dt;
  options.d_hat = d_hat;
  options.background_flow = sc::LinearBackgroundFlow::biaxial_compression(1.0);  // eq. 32, gamma-dot = 1
  options.contact_step = o.step;
  sc::TimeStepper<S, M> stepper({rod}, start, mobility, o.solver, options);
  RunSummary s;
  s.multiblob_path = ex::multiblob_path(mobility);
  s.d_hat_fraction = fraction;
  s.dt = dt;
  long n_steps = std::lround(o.t_end / dt);
  if (o.max_steps > 0) n_steps = std::min(n_steps, o.max_steps);
  const auto begin = std::chrono::steady_clock::now();
  for (long n = 1; n <= n_steps; ++n) {
    // The paper's trigger: the trial step Q* = Q_t + dt U_bg (forward Euler, no forces) violates d_hat.
    const std::span<const sc::Pose> q_t(stepper.poses());
    const sc::VecX U = options.background_flow->body_velocities(q_t, 6);
    const std::vector<sc::Pose> trial = sc::advance_all(q_t, U, 6, dt);
    const bool triggered = sc::minimum_pair_distance(rod, std::span<const sc::Pose>(trial)).distance < d_hat;
    sc::StepDiagnostics d;
    try {
      d = stepper.step();
    } catch (const std::exception& e) {
      s.error = e.what();
      break;
    }
    const std::span<const sc::Pose> q(stepper.poses());
    const double order = sc::order_along(q, sc::Vec3::UnitZ());  // eq. 33
    double max_x = 0.0, max_turn = 0.0;
    for (const sc::Pose& p : q) {
      max_x = std::max(max_x, std::abs(p.x.x()));
      max_turn = std::max(max_turn, p.q.angularDistance(sc::Quat::Identity()));
    }
    const bool before_t_s = d.time <= o.t_s + 1e-9;
    ++s.steps;
    s.steps_ts += before_t_s;
    s.triggered += triggered;
    s.triggered_ts += triggered && before_t_s;
    s.flagged += d.flagged_pairs > 0;
    s.overlaps += d.min_distance_ratio < 0.0;
    s.below_d_hat += d.min_distance_ratio < 1.0 - o.step.separation_margin;
    s.min_ratio = std::min(s.min_ratio, d.min_distance_ratio);
    s.max_x = std::max(s.max_x, max_x);
    s.max_turn = std::max(s.max_turn, max_turn);
    s.min_s = std::min(s.min_s, order);
    if (before_t_s) s.s_at_t_s = order;
    s.applications += d.mobility_applications;
    sink.line("{\"record\": \"step\", \"d_hat_over_R\": " + sc::json_number(fraction) + ", \"dt\": " +
                  sc::json_number(dt) + ", \"step\": " + std::to_string(d.step) + ", \"t\": " + sc::json_number(d.time) +
                  ", \"triggered\": " + (triggered ? "true" : "false") + ", \"nc\": " +
                  std::to_string(d.flagged_pairs) + ", \"active_pairs\": " + std::to_string(d.active_pairs) +
                  ", \"mobility_applications\": " + std::to_string(d.mobility_applications) +
                  ", \"wall_time_s\": " + sc::json_number(d.wall_time_s) + ", \"S\": " + sc::json_number(order) +
                  ", \"max_abs_x\": " + sc::json_number(max_x) + ", \"max_turn\": " + sc::json_number(max_turn) +
                  ", \"max_correction_turn\": " + sc::json_number(d.max_correction_turn) +
                  ", \"substeps\": " + std::to_string(d.substeps) + ", \"fallbacks\": " + std::to_string(d.fallbacks) +
                  ", \"min_d_over_d_hat\": " + sc::json_number(d.min_distance_ratio) + ", \"status\": \"" +
                  std::string(sc::to_string(d.status)) + "\"}");
  }
  s.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return s;
}

std::string summary_json(const Options& o, const RunSummary& s) {
  return "{\"record\": \"summary\", \"rods\": " + std::to_string(o.rows * o.columns) + ", \"mobility\": \"" +
         ex::rod_mobility_name(o.mobility) + "\", \"multiblob_path\": \"" + s.multiblob_path +
         "\", \"solver\": \"" + sc::contact_solver_name(o.solver) +
         "\", \"directions\": \"" + ex::directions_name(o.directions) +
         "\", \"max_correction_turn_bound\": " + sc::json_number(o.step.max_correction_turn) +
         ", \"overlap_ends_min_overlap\": " + sc::json_number(o.step.overlap_ends_min_overlap) + ", \"d_hat_over_R\": " +
         sc::json_number(s.d_hat_fraction) + ", \"dt\": " + sc::json_number(s.dt) +
         ", \"steps\": " + std::to_string(s.steps) + ", \"triggered\": " + std::to_string(s.triggered) +
         ", \"paper_triggered\": " + std::to_string(paper_count(s.dt, s.d_hat_fraction, false)) +
         ", \"steps_to_t_s\": " + std::to_string(s.steps_ts) + ", \"triggered_to_t_s\": " +
         std::to_string(s.triggered_ts) + ", \"paper_triggered_to_t_s\": " +
         std::to_string(paper_count(s.dt, s.d_hat_fraction, true)) + ", \"flagged_steps\": " +
         std::to_string(s.flagged) + ", \"overlap_steps\": " + std::to_string(s.overlaps) +
         ", \"below_d_hat_steps\": " + std::to_string(s.below_d_hat) + ", \"min_d_over_d_hat\": " +
         sc::json_number(s.min_ratio) + ", \"max_abs_x\": " + sc::json_number(s.max_x) + ", \"max_turn\": " +
         sc::json_number(s.max_turn) + ", \"min_S\": " + sc::json_number(s.min_s) + ", \"S_at_t_s\": " +
         sc::json_number(s.s_at_t_s) + ", \"mobility_applications\": " + std::to_string(s.applications) +
         ", \"wall_time_s\": " + sc::json_number(s.wall) + ", \"error\": " + sc::json_quoted(s.error) + "}";
}

template <sc::MobilityOperator M>
void run_all(const Options& o, M& mobility) {
  ex::JsonLines sink(o.output);
  std::vector<RunSummary> rows;
  for (const double fraction : o.d_hat_fractions)
    for (const double dt : o.dts) {
      const sc::Spherocylinder rod = ex::paper_rod(kLRod, kRRod);
      if (o.directions == ex::RodDirections::line)
        rows.push_back(run(o, ex::line_contact_rod(rod, o.line_width, o.line_angle), fraction, dt, mobility, sink));
      else
        rows.push_back(run(o, rod, fraction, dt, mobility, sink));
      sink.line(summary_json(o, rows.back()), summary_json(o, rows.back()));
    }
  std::printf("\nTable 2: %d rods, %s mobility, solver %s, %s directions (paper's counts in brackets)\n",
              o.rows * o.columns, ex::rod_mobility_name(o.mobility), sc::contact_solver_name(o.solver).c_str(),
              ex::directions_name(o.directions));
  std::printf("%8s %6s | %6s | %-13s | %-13s | %8s | %11s | %9s | %9s | %9s | %7s | %8s\n", "d_hat/R", "dt", "steps",
              "triggered", "to T_S", "overlaps", "min d/d_hat", "max |x|", "max turn", "min S", "apps", "wall s");
  for (const RunSummary& s : rows)
    std::printf("%8.2f %6.3f | %6ld | %5ld (%5d) | %5ld (%5d) | %8ld | %11.6f | %9.2e | %9.2e | %9.6f | %7zu | %8.1f%s\n",
                s.d_hat_fraction, s.dt, s.steps, s.triggered, paper_count(s.dt, s.d_hat_fraction, false), s.triggered_ts,
                paper_count(s.dt, s.d_hat_fraction, true), s.overlaps, s.min_ratio, s.max_x, s.max_turn, s.min_s,
                s.applications, s.wall, s.error.empty() ? "" : (" ERROR: " + s.error).c_str());
}

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  Options o;
  return ex::driver_main(
      "fig8_biaxial", kUsage, [&] { o = parse(argc, argv); },
      [&] {
        const sc::Spherocylinder rod = ex::paper_rod(kLRod, kRRod);
        ex::RodMobility mobility =
            ex::make_rod_mobility(o.mobility, rod, static_cast<std::size_t>(o.rows * o.columns), o.blobs_per_ring,
                                  o.multiblob_solver);
        std::visit([&](auto& m) { run_all(o, m); }, mobility);
      });
}

}  // namespace fig8_biaxial
