// Brownian and self-propelled spherocylinders in the dilute limit (Yan, Zhang & Shelley 2019
// Sec. IV-V.A, Fig. 6): N rods of diameter D = 1 and cylinder length L = aspect D in a
// periodic cube at packing fraction phi, free draining with Yan's slender-body mobility
// (eq. 45-50, mobility/free_draining.hpp spherocylinder_mobility; viscosity 1, kT = 1), each
// rod propelled at speed U0 along its axis n (a force U0 zeta_par n, so that M F = U0 n), the
// default contact solver holding every gap at >= d_hat each step.
//
//   brownian_rods [--aspect 5] [--phi 0.02] [--n 1000] [--u0 0,1,2,4] [--dt 1e-3] [--d-hat 1e-2]
//                 [--equilibrate 0.5] [--average 2] [--solver default] [--seed 1] [--tolerance 0]
//                 [--output FILE]
//
// --u0 is given as U0 / (L D_R), the paper's Fig. 6 axis (D_R = kT / zeta_r, eq. 49); --dt,
// --equilibrate and --average are in rotational times 1 / D_R. Start: periodic_random_placement
// of the seed (every gap > d_hat). Per U0, the collision pressure is reported as Yan's
//     Pi^col / (B2 n kT) = (Z - 1) / (B2 n),   B2 = pi (2 D'^3 / 3 + L D'^2 + L^2 D' / 4),
// (eq. 53-55; B2 of hard spherocylinders, exact, Onsager 1949) with the hard-core diameter
// D' = D + d_hat that the contact step holds (phi and n count the rods of diameter D), with
// the error bar of Z's block
// average, and the nematic order parameter S (largest eigenvalue of <3 n n^T - I> / 2) as a
// check that the suspension stays isotropic (S ~ 1 / sqrt(N) there). In the dilute limit and at
// U0 = 0 the ratio tends to 1 + (B3 / B2^2) (B2 n) + (B4 / B2^3) (B2 n)^2 + ...; the driver
// prints that truncated series with B3 / B2^2 and B4 / B2^3 for L / D = 5 (the only aspect it
// has them for) from Monte Carlo virial coefficients (see docs/results.md for the source).
// --tolerance > 0: ERROR when the U0 = 0 ratio is not within tolerance (relative) plus 3 error
// bars of that series.
// One JSON object per line (to --output if given, else stdout) and a readable summary.
#include <stokescontact/stokescontact.hpp>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/brownian_pressure.hpp"
#include "common/cli.hpp"

namespace sc = stokescontact;
namespace ex = examples;

namespace {

constexpr const char* kUsage =
    "usage: brownian_rods [--aspect 5] [--phi 0.02] [--n 1000] [--u0 0,1,2,4] [--dt 1e-3] [--d-hat 1e-2]\n"
    "                     [--equilibrate 0.5] [--average 2] [--solver default] [--seed 1] [--tolerance 0]\n"
    "                     [--output FILE]\n";

struct Options {
  double aspect = 5.0;
  double phi = 0.02;
  std::size_t n = 1000;
  std::vector<double> u0;
  double dt = 1e-3, d_hat = 1e-2, equilibrate = 0.5, average = 2.0;
  std::string solver = "default";
  std::uint64_t seed = 1;
  double tolerance = 0.0;
  std::string output;
};

Options parse(int argc, char** argv) {
  ex::Arguments args(argc, argv);
  Options o;
  o.aspect = args.number("--aspect", 5.0, 0.0);
  if (!(o.aspect > 0.0)) throw std::invalid_argument("--aspect must be > 0");
  o.phi = args.number("--phi", 0.02, 0.0);
  if (!(o.phi > 0.0 && o.phi < 0.3)) throw std::invalid_argument("--phi must lie in (0, 0.3)");
  o.n = static_cast<std::size_t>(args.integer("--n", 1000, 2));
  o.u0 = args.numbers("--u0", {0.0, 1.0, 2.0, 4.0}, 0.0);
  o.dt = args.number("--dt", 1e-3, 0.0);
  o.d_hat = args.number("--d-hat", 1e-2, 0.0);
  o.equilibrate = args.number("--equilibrate", 0.5, 0.0);
  o.average = args.number("--average", 2.0, 0.0);
  for (const double* v : {&o.dt, &o.d_hat, &o.average})
    if (!(*v > 0.0)) throw std::invalid_argument("--dt, --d-hat and --average must be > 0");
  o.solver = args.text("--solver", "default");
  sc::contact_solver_from_name(o.solver);
  o.seed = static_cast<std::uint64_t>(args.integer("--seed", 1, 0));
  o.tolerance = args.number("--tolerance", 0.0, 0.0);
  o.output = args.text("--output", "");
  args.reject_unknown();
  return o;
}

// Nematic order parameter: the largest eigenvalue of Q = <3 n n^T - I> / 2 over the rods.
double nematic_order(std::span<const sc::Pose> poses) {
  sc::Mat3 q = sc::Mat3::Zero();
  for (const sc::Pose& p : poses) {
    const sc::Vec3 n = p.rotation().col(2);  // the rod axis, body z
    q += 1.5 * n * n.transpose() - 0.5 * sc::Mat3::Identity();
  }
  q /= static_cast<double>(poses.size());
  return Eigen::SelfAdjointEigenSolver<sc::Mat3>(q).eigenvalues().maxCoeff();
}

// Truncated virial series of (Z - 1) / (B2 n) at U0 = 0 for L / D = 5 (docs/results.md names
// the source of B3 / B2^2 = 0.41946 and B4 / B2^3 = 0.05275); none for other aspects.
std::optional<double> virial_ratio(double aspect, double b2n) {
  if (std::abs(aspect - 5.0) > 1e-12) return std::nullopt;
  return 1.0 + 0.41946 * b2n + 0.05275 * b2n * b2n;
}

int run(const Options& o) {
  constexpr double kT = 1.0, viscosity = 1.0, D = 1.0;
  const double L = o.aspect * D;
  const sc::Spherocylinder rod{L, 0.5 * D};
  const sc::Mat6 body_mobility = sc::spherocylinder_mobility(rod, viscosity);
  const double D_R = kT * body_mobility(3, 3);  // 1 / zeta_r (eq. 49)
  const double m_par = body_mobility(2, 2);     // 1 / zeta_par (eq. 47), axis = body z
  const double v0 = std::numbers::pi * (0.25 * L * D * D + D * D * D / 6.0);
  const double Dh = D + o.d_hat;  // the hard core the contact step holds
  const double b2 = std::numbers::pi * (2.0 * Dh * Dh * Dh / 3.0 + L * Dh * Dh + 0.25 * L * L * Dh);
  const double side = std::cbrt(static_cast<double>(o.n) * v0 / o.phi);
  const double number_density = static_cast<double>(o.n) / (side * side * side);
  const double b2n = b2 * number_density;
  const std::optional<double> reference = virial_ratio(o.aspect, b2n);
  const double dt = o.dt / D_R;
  ex::JsonLines sink(o.output);
  std::printf("Brownian rods: N = %zu spherocylinders L/D = %g in a periodic cube of side %.4g, phi %g, B2 n = %.5f,\n"
              "free draining (Yan eq. 45-50), D_R = %.5g, dt = %g / D_R, equilibrate %g, average %g (1 / D_R), "
              "d_hat %g, solver %s\n"
              "%9s | %8s %8s | %9s | %7s %6s %6s | %9s | %7s | %8s\n",
              o.n, o.aspect, side, o.phi, b2n, D_R, o.dt, o.equilibrate, o.average, o.d_hat, o.solver.c_str(),
              "U0/(L DR)", "ratio", "+-", "series", "pushed", "apps", "its", "min d/dh", "S", "wall s");
  const std::vector<sc::Pose> start = sc::periodic_random_placement(rod, o.n, side, o.d_hat, o.seed);
  bool ok = true;
  for (const double u0_scaled : o.u0) {
    const double u0 = u0_scaled * L * D_R;
    sc::FreeDrainingMobility mobility(body_mobility, o.n, 6);
    sc::TimeStepperOptions options;
    options.dt = dt;
    options.d_hat = o.d_hat;
    options.box = sc::PeriodicBox{sc::Vec3::Constant(side)};
    options.brownian.emplace();
    options.brownian->kT = kT;
    options.brownian->seed = o.seed;
    sc::TimeStepper<sc::Spherocylinder, sc::FreeDrainingMobility> stepper({rod}, start, mobility,
                                                                          sc::contact_solver_from_name(o.solver), options);
    if (u0 > 0.0)  // self-propulsion: M F = U0 n for the force U0 zeta_par n (no torque)
      stepper.set_external_force_field([u0, m_par](double, std::span<const sc::Pose> poses) {
        sc::VecX F = sc::VecX::Zero(6 * static_cast<Eigen::Index>(poses.size()));
        for (std::size_t i = 0; i < poses.size(); ++i)
          F.segment<3>(6 * static_cast<Eigen::Index>(i)) = (u0 / m_par) * poses[i].rotation().col(2);
        return F;
      });
    const ex::BrownianPressureRun r =
        ex::measure_brownian_pressure(stepper, kT, std::lround(o.equilibrate / o.dt),
                                      std::max(2L, std::lround(o.average / o.dt)), nematic_order);
    const double ratio = r.measured() ? (r.z.mean(0) - 1.0) / b2n : 0.0;
    const double error = r.measured() ? r.z.std_error(0) / b2n : 0.0;
    const double order = r.measured() ? r.extra.mean(0) : 0.0;
    const bool converged = r.measured() && r.z.all_converged();
    sink.line("{\"N\": " + std::to_string(o.n) + ", \"aspect\": " + sc::json_number(o.aspect) + ", \"phi\": " +
              sc::json_number(o.phi) + ", \"u0_over_L_DR\": " + sc::json_number(u0_scaled) + ", \"u0\": " +
              sc::json_number(u0) + ", \"D_R\": " + sc::json_number(D_R) + ", \"dt_D_R\": " + sc::json_number(o.dt) +
              ", \"d_hat\": " + sc::json_number(o.d_hat) + ", \"solver\": \"" + o.solver + "\", \"seed\": " +
              std::to_string(o.seed) + ", \"steps_averaged\": " + std::to_string(r.steps) + ", \"B2n\": " +
              sc::json_number(b2n) + ", \"Z\": " + sc::json_number(r.measured() ? r.z.mean(0) : 0.0) +
              ", \"Z_error\": " + sc::json_number(r.measured() ? r.z.std_error(0) : 0.0) +
              ", \"pressure_ratio\": " + sc::json_number(ratio) + ", \"pressure_ratio_error\": " +
              sc::json_number(error) + ", \"error_converged\": " + (converged ? "true" : "false") +
              ", \"virial_series\": " + (reference && u0 == 0.0 ? sc::json_number(*reference) : "null") +
              ", \"nematic_order\": " + sc::json_number(order) + ", \"pushed_per_step\": " +
              sc::json_number(r.pushed_per_step) + ", \"applications_per_step\": " +
              sc::json_number(r.applications_per_step) + ", \"iterations_per_step\": " +
              sc::json_number(r.iterations_per_step) + ", \"substeps_per_step\": " +
              sc::json_number(r.substeps_per_step) + ", \"min_d_over_d_hat\": " +
              sc::json_number(r.min_distance_ratio) + ", \"max_correction_turn\": " +
              sc::json_number(r.max_correction_turn) + ", \"fallbacks\": " +
              std::to_string(r.fallbacks) + ", \"wall_s\": " + sc::json_number(r.wall_s) +
              ", \"failure\": " + sc::json_quoted(r.failure) + "}");
    const std::string series = reference && u0 == 0.0 ? std::to_string(*reference).substr(0, 7) : "-";
    std::printf("%9.3g | %8.4f %8.4f | %9s | %7.2f %6.2f %6.2f | %9.6f | %7.4f | %8.1f%s\n", u0_scaled, ratio, error,
                series.c_str(), r.pushed_per_step, r.applications_per_step, r.iterations_per_step,
                r.min_distance_ratio, order, r.wall_s, converged ? "" : "  (error bar not converged)");
    if (r.fallbacks > 0)
      std::printf("          %ld contact sub-step(s) failed by the solver and solved again by another; largest "
                  "correction turn %.3g rad\n",
                  r.fallbacks, r.max_correction_turn);
    std::fflush(stdout);
    if (!r.failure.empty()) {
      std::printf("ERROR: U0 / (L D_R) = %g: %s\n", u0_scaled, r.failure.c_str());
      ok = false;
    } else if (o.tolerance > 0.0 && reference && u0 == 0.0 &&
               std::abs(ratio - *reference) > o.tolerance * *reference + 3.0 * error) {
      std::printf("ERROR: U0 = 0: Pi^col / (B2 n kT) = %g +- %g is not within %g of the virial series %g\n", ratio,
                  error, o.tolerance, *reference);
      ok = false;
    }
  }
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  return ex::driver_main("brownian_rods", kUsage, [&] { o = parse(argc, argv); }, [&] { return run(o); });
}
