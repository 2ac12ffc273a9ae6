// The equation of state of Brownian hard spheres (Yan, Zhang & Shelley 2019 Sec. II-IV, the
// L/D = 0 line of their Fig. 3): N unit spheres (a = 1) in a periodic cube at packing fraction
// phi, free draining with D0 = kT / (6 pi mu a) = 1 (mu = 1 / (6 pi), kT = 1; time in a^2 / D0),
// no forces: each step's U is the Brownian velocity alone (TimeStepper with
// TimeStepperOptions::brownian), and the contact step holds every gap at >= d_hat, so the
// spheres are hard spheres of diameter sigma = 2a + d_hat.
//
//   brownian_hard_spheres [--phi 0.05,0.15,0.25,0.35,0.45] [--n 500] [--dt 1e-4]
//                         [--d-hat 1e-3] [--equilibrate 1] [--average 4] [--solver default]
//                         [--seed 1] [--tolerance 0] [--output FILE]
//
// Per (phi, dt, solver), from the same start (dense_packing of the seed, gaps >= ~1.9 d_hat):
// `equilibrate` time units unrecorded, then `average` time units in which every step gives one
// sample of the compressibility factor (collision_stress.hpp, eq. 16, 51-52)
//     Z_step = 1 + sum over the step's contact sub-steps (h / dt) tr(sigma^col) / (3 N kT),
// averaged with its error bar by block averaging (core/block_average.hpp: the plateau of the
// blocked standard error, Flyvbjerg & Petersen 1989). The reference is Carnahan-Starling,
//     Z_CS(eta) = (1 + eta + eta^2 - eta^3) / (1 - eta)^3,
// at the hard-sphere packing fraction eta = phi (sigma / 2a)^3. The mean per step of contact
// pairs with lambda > 0, mobility applications and solver iterations, and the wall time, are
// reported as the cost.
// The discrete step misses the collisions a Brownian path makes between the ends of a step, so Z
// is low by an amount that shrinks like sqrt(dt) (measured: docs/results.md "Brownian hard
// spheres"). Given several --dt, a row "dt -> 0" per (phi, solver) extrapolates: the weighted
// (1 / error^2) least-squares line Z = Z_0 + c sqrt(dt), with Z_0's error bar from the fit's
// covariance. --tolerance > 0: ERROR when |Z - Z_CS| > tolerance Z_CS + 3 error bars.
// A step that fails (TimeStepper throws after its sub-steps) is an ERROR and ends that run.
// One JSON object per line (to --output if given, else stdout) and a readable summary.
#include <stokescontact/dynamics/time_stepper.hpp>
#include <stokescontact/io/json.hpp>
#include <stokescontact/mobility/free_draining.hpp>
#include <stokescontact/scenes/sphere_packing.hpp>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/brownian_pressure.hpp"
#include "common/cli.hpp"

namespace sc = stokescontact;
namespace ex = examples;

namespace brownian_hard_spheres {

constexpr const char* kUsage =
    "usage: brownian_hard_spheres [--phi 0.05,0.15,0.25,0.35,0.45] [--n 500] [--dt 1e-4] [--d-hat 1e-3]\n"
    "                             [--equilibrate 1] [--average 4] [--solver default] [--seed 1]\n"
    "                             [--tolerance 0] [--output FILE]\n";

// Carnahan & Starling, J. Chem. Phys. 51, 635 (1969): Z of hard spheres at packing fraction eta.
double carnahan_starling(double eta) {
  return (1.0 + eta + eta * eta - eta * eta * eta) / ((1.0 - eta) * (1.0 - eta) * (1.0 - eta));
}

struct Options {
  std::vector<double> phis;
  std::size_t n = 500;
  std::vector<double> dts;
  double d_hat = 1e-3;
  double equilibrate = 1.0;
  double average = 4.0;
  std::vector<std::string> solvers;
  std::uint64_t seed = 1;
  double tolerance = 0.0;
  std::string output;
};

Options parse(int argc, char** argv) {
  ex::Arguments args(argc, argv);
  Options o;
  o.phis = args.numbers("--phi", {0.05, 0.15, 0.25, 0.35, 0.45}, 0.0);
  for (double phi : o.phis)
    if (!(phi > 0.0 && phi < 0.55)) throw std::invalid_argument("--phi: each must lie in (0, 0.55), got " + std::to_string(phi));
  o.n = static_cast<std::size_t>(args.integer("--n", 500, 2));
  o.dts = args.numbers("--dt", {1e-4}, 0.0);
  for (double dt : o.dts)
    if (!(dt > 0.0)) throw std::invalid_argument("--dt: each must be > 0, got " + std::to_string(dt));
  o.d_hat = args.number("--d-hat", 1e-3, 0.0);
  if (!(o.d_hat > 0.0)) throw std::invalid_argument("--d-hat must be > 0");
  o.equilibrate = args.number("--equilibrate", 1.0, 0.0);
  o.average = args.number("--average", 4.0, 0.0);
  if (!(o.average > 0.0)) throw std::invalid_argument("--average must be > 0");
  o.solvers = args.list("--solver", {"default"});
  for (const std::string& s : o.solvers) sc::contact_solver_from_name(s);
  o.seed = static_cast<std::uint64_t>(args.integer("--seed", 1, 0));
  o.tolerance = args.number("--tolerance", 0.0, 0.0);
  o.output = args.text("--output", "");
  args.reject_unknown();
  return o;
}

bool within_tolerance(const Options& o, double phi, double dt, const std::string& solver, double z, double error,
                      double z_cs) {
  if (std::abs(z - z_cs) <= o.tolerance * z_cs + 3.0 * error) return true;
  std::printf("ERROR: phi %g, dt %g, %s: Z = %g +- %g is not within %g of Carnahan-Starling %g\n", phi, dt,
              solver.c_str(), z, error, o.tolerance, z_cs);
  return false;
}

// One (phi, dt, solver) run from the seed's packing; eta is the hard-sphere packing fraction.
ex::BrownianPressureRun run_one(const Options& o, double phi, double dt, const std::string& solver_name) {
  constexpr double kT = 1.0, radius = 1.0;
  const double viscosity = 1.0 / (6.0 * std::numbers::pi);  // D0 = kT / (6 pi mu a) = 1
  sc::DensePackingOptions packing_options;
  packing_options.phi_start = std::min(packing_options.phi_start, phi);
  packing_options.skin = std::max(packing_options.skin, o.d_hat);
  const sc::SpherePacking packing = sc::dense_packing(o.n, phi, o.seed, radius, packing_options);
  if (std::abs(packing.phi - phi) > 1e-9 * phi)
    throw std::runtime_error("dense_packing reached phi " + std::to_string(packing.phi) + ", not " +
                             std::to_string(phi));
  const std::vector<sc::Sphere> shapes{sc::Sphere{radius}};
  sc::FreeDrainingMobility mobility(sc::sphere_mobility(shapes[0], viscosity), o.n, 3);
  sc::TimeStepperOptions options;
  options.dt = dt;
  options.d_hat = o.d_hat;
  options.box = sc::PeriodicBox{sc::Vec3::Constant(packing.side)};
  options.brownian.emplace();
  options.brownian->kT = kT;
  options.brownian->seed = o.seed;
  sc::TimeStepper<sc::Sphere, sc::FreeDrainingMobility> stepper(shapes, packing.poses, mobility,
                                                                 sc::contact_solver_from_name(solver_name), options);
  return ex::measure_brownian_pressure(stepper, kT, std::lround(o.equilibrate / dt),
                                       std::max(2L, std::lround(o.average / dt)));
}

int run(const Options& o) {
  ex::JsonLines sink(o.output);
  std::printf("Brownian hard spheres: N = %zu unit spheres, periodic cube, free draining, D0 = kT = 1, d_hat = %g\n"
              "equilibrate %g, average %g (time units a^2/D0); Z against Carnahan-Starling at eta = phi (1 + d_hat/2)^3\n"
              "%5s %8s %8s %-12s | %8s %8s %8s | %7s %7s | %7s %6s %6s | %9s | %8s\n",
              o.n, o.d_hat, o.equilibrate, o.average, "phi", "eta", "dt", "solver", "Z", "+-", "Z_CS", "dev %",
              "dev/se", "pushed", "apps", "its", "min d/dh", "wall s");
  bool ok = true;
  for (const double phi : o.phis)
    for (const std::string& solver : o.solvers) {
      std::vector<ex::ZAtStep> measured_z;
      for (const double dt : o.dts) {
        const ex::BrownianPressureRun r = run_one(o, phi, dt, solver);
        const double eta = phi * std::pow(1.0 + 0.5 * o.d_hat, 3);  // diameter 2a + d_hat, a = 1
        const double z_cs = carnahan_starling(eta);
        const bool measured = r.measured();
        const double z_mean = measured ? r.z.mean(0) : 0.0, z_error = measured ? r.z.std_error(0) : 0.0;
        const double deviation = z_mean / z_cs - 1.0;
        const bool error_converged = measured && r.z.all_converged();
        sink.line("{\"N\": " + std::to_string(o.n) + ", \"phi\": " + sc::json_number(phi) + ", \"eta\": " +
                  sc::json_number(eta) + ", \"dt\": " + sc::json_number(dt) + ", \"d_hat\": " +
                  sc::json_number(o.d_hat) + ", \"solver\": \"" + solver + "\", \"seed\": " + std::to_string(o.seed) +
                  ", \"equilibrate\": " + sc::json_number(o.equilibrate) + ", \"average\": " +
                  sc::json_number(o.average) + ", \"steps_averaged\": " + std::to_string(r.steps) +
                  ", \"Z\": " + sc::json_number(z_mean) + ", \"Z_error\": " + sc::json_number(z_error) +
                  ", \"Z_error_converged\": " + (error_converged ? "true" : "false") + ", \"Z_CS\": " +
                  sc::json_number(z_cs) + ", \"pushed_per_step\": " + sc::json_number(r.pushed_per_step) +
                  ", \"applications_per_step\": " + sc::json_number(r.applications_per_step) +
                  ", \"iterations_per_step\": " + sc::json_number(r.iterations_per_step) +
                  ", \"substeps_per_step\": " + sc::json_number(r.substeps_per_step) +
                  ", \"min_d_over_d_hat\": " + sc::json_number(r.min_distance_ratio) + ", \"wall_s\": " +
                  sc::json_number(r.wall_s) + ", \"failure\": " + sc::json_quoted(r.failure) + "}");
        std::printf("%5.3f %8.5f %8.1e %-12s | %8.4f %8.4f %8.4f | %+7.2f %7.1f | %7.2f %6.2f %6.1f | %9.6f | %8.1f%s\n",
                    phi, eta, dt, solver.c_str(), z_mean, z_error, z_cs, 100.0 * deviation,
                    z_error > 0.0 ? (z_mean - z_cs) / z_error : 0.0, r.pushed_per_step, r.applications_per_step,
                    r.iterations_per_step, r.min_distance_ratio, r.wall_s, error_converged ? "" : "  (error bar not converged)");
        std::fflush(stdout);
        if (!r.failure.empty()) {
          std::printf("ERROR: phi %g, dt %g, %s: %s\n", phi, dt, solver.c_str(), r.failure.c_str());
          ok = false;
          continue;
        }
        if (o.dts.size() == 1 && o.tolerance > 0.0) ok = within_tolerance(o, phi, dt, solver, z_mean, z_error, z_cs) && ok;
        measured_z.push_back({std::sqrt(dt), z_mean, z_error});
      }
      if (o.dts.size() < 2 || measured_z.size() != o.dts.size()) continue;
      const double z_cs = carnahan_starling(phi * std::pow(1.0 + 0.5 * o.d_hat, 3));  // as above
      const ex::Extrapolated z0 = ex::extrapolate_to_zero_step(measured_z);
      sink.line("{\"N\": " + std::to_string(o.n) + ", \"phi\": " + sc::json_number(phi) + ", \"dt\": 0, \"extrapolated\": true" +
                ", \"solver\": \"" + solver + "\", \"Z\": " + sc::json_number(z0.z) + ", \"Z_error\": " +
                sc::json_number(z0.error) + ", \"slope_sqrt_dt\": " + sc::json_number(z0.slope) + ", \"Z_CS\": " +
                sc::json_number(z_cs) + "}");
      std::printf("%5.3f %8s %8s %-12s | %8.4f %8.4f %8.4f | %+7.2f %7.1f | slope in sqrt(dt) %.3g\n", phi, "",
                  "dt -> 0", solver.c_str(), z0.z, z0.error, z_cs, 100.0 * (z0.z / z_cs - 1.0),
                  z0.error > 0.0 ? (z0.z - z_cs) / z0.error : 0.0, z0.slope);
      if (o.tolerance > 0.0) ok = within_tolerance(o, phi, 0.0, solver, z0.z, z0.error, z_cs) && ok;
    }
  return ok ? 0 : 1;
}

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  Options o;
  return ex::driver_main("brownian_hard_spheres", kUsage, [&] { o = parse(argc, argv); }, [&] { return run(o); });
}

}  // namespace brownian_hard_spheres
