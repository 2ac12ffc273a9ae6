// Brownian and self-propelled spherocylinders (Yan, Zhang & Shelley 2019 Sec. IV-V.A, Fig.
// 3-6): N rods of diameter D = 1 and cylinder length L = aspect D in a
// periodic cube at packing fraction phi, free draining with Yan's slender-body mobility
// (eq. 45-50, mobility/free_draining.hpp spherocylinder_mobility; viscosity 1, kT = 1), each
// rod propelled at speed U0 along its axis n (a force U0 zeta_par n, so that M F = U0 n), the
// default contact solver holding every gap at >= d_hat each step.
//
//   brownian_rods [--aspect 5] [--phi 0.02 | --eta ETA] [--n 1000] [--box-aspect 1] [--u0 0,1,2,4] [--dt 1e-3]
//                 [--d-hat 1e-2] [--equilibrate 0.5] [--average 2] [--solver default] [--seed 1]
//                 [--directions particle|surface|overlap-ends] [--overlap-ends-min-overlap 0.1]
//                 [--overlap-ends-angle 0.1] [--start random|aligned|compressed] [--melt 0]
//                 [--compress-from 0.25] [--compress-rate 5e-4] [--compress-steps 5]
//                 [--melt-dt 1e-3] [--progress 0] [--max-substep-halvings 4] [--tolerance 0]
//                 [--separation-margin 1e-3] [--save-state FILE] [--save-every 1000]
//                 [--load-state FILE] [--output FILE]
//
// --u0 is given as U0 / (L D_R), the paper's Fig. 6 axis (D_R = kT / zeta_r, eq. 49); --dt,
// --equilibrate, --average, --melt and --melt-dt are in rotational times 1 / D_R. --eta gives
// the packing fraction of the hard core D + d_hat instead of phi (that of diameter D).
// The box: a cube, or with --box-aspect A > 1 a box A times as long along z as across (Lx = Ly,
// Lz = A Lx; Yan et al.'s aligned runs used 72 D x 15 D x 15 D for 2000 rods, A = 4.8), with
// --start aligned (the rods along the long side) or --load-state of such a box.
// Start: --start random, periodic_random_placement of the seed (every gap > d_hat; phi < 0.3);
// --start aligned, periodic_aligned_columns (every rod along z, Yan et al. Sec. IV.B's aligned
// start, for dense suspensions); --start compressed, an isotropic dense start: random placement
// at the hard-core packing --compress-from (< 0.3), then the centres and the box rescaled
// towards --eta by a factor of at least 1 - --compress-rate at a time, each rescaling followed
// by --compress-steps Brownian steps at --melt-dt (a rescaling that would bring a pair below
// d_hat / 2 is undone and the rate halved; it never overlaps a pair, and the steps push the
// pairs it brought below d_hat back out); then --melt time units of Brownian motion at --melt-dt
// without propulsion, unrecorded, whose end is the start of every run (the summary prints its
// nematic order; --progress K writes every K-th melt step's diagnostics and the nematic order S
// after it to stderr as JSON).
// Continuing a run (io/checkpoint.hpp): --save-state FILE writes the melt's state (time, box,
// poses, the Brownian stream) every --save-every melt steps and at the melt's end (without a
// melt: the start); --load-state FILE starts from such a file instead of --start (same --n
// and --aspect), and its melt goes on with the saved stream, so `--melt 2 --save-state s` then
// `--load-state s --melt 3` takes the same steps as `--melt 5`. A file saved at another
// packing is brought to --eta first: a denser one expanded in one affine rescaling of the
// centres and the box (rescale_centres, scenes/periodic_placement.hpp: no gap between
// spherocylinders shortens), a more dilute one compressed as --start compressed does (steps
// of --compress-rate, --compress-steps Brownian steps each); the expansion and compression
// runs of a hysteresis loop across the isotropic-nematic transition (the clock goes on from
// the file's time; the compression's steps, as those of --start compressed, are not counted).
// One Brownian stream runs through the whole program (the compression's steppers, the melt,
// then each measured run from the melt's end): no phase draws the seed's first variates again.
// Every (U0, dt) runs from that start; given several --dt, a row "dt -> 0" per U0
// extrapolates Z = Z_0 + c sqrt(dt) (brownian_pressure.hpp). --directions: the contact
// directions (overlap-ends holds near-parallel rods at both ends of their overlap, when it is
// at least --overlap-ends-min-overlap times the radius: ContactStepOptions::overlap_ends_min_overlap,
// and their axes meet at less than --overlap-ends-angle radians: overlap_ends_angle);
// --max-substep-halvings: TimeStepperOptions::max_substep_halvings (0: a step the solver
// fails ends the run at once, with the solver's message); --separation-margin:
// ContactStepOptions::separation_margin, a step is committed when every gap is at least
// d_hat (1 - margin) (Yan et al. accept the gap their linearised LCP leaves; a margin of
// 0.1-0.5 lets the LCP solvers step dense suspensions, at a hard core between D + d_hat (1 -
// margin) and D + d_hat). Per run, the collision pressure is
// reported as Yan's
//     Pi^col / (B2 n kT) = (Z - 1) / (B2 n),   B2 = pi (2 D'^3 / 3 + L D'^2 + L^2 D' / 4),
// (eq. 53-55; B2 of hard spherocylinders, exact, Onsager 1949) with the hard-core diameter
// D' = D + d_hat that the contact step holds (phi and n count the rods of diameter D), with
// the error bar of Z's block average, and the nematic order parameter S (largest eigenvalue
// of <3 n n^T - I> / 2), which is ~ 1 / sqrt(N) in an isotropic suspension. In the dilute limit and at
// U0 = 0 the ratio tends to 1 + (B3 / B2^2) (B2 n) + (B4 / B2^3) (B2 n)^2 + ...; the driver
// prints that truncated series with B3 / B2^2 and B4 / B2^3 for L / D = 5 (the only aspect it
// has them for) from Monte Carlo virial coefficients (see docs/results.md for the source).
// Dense suspensions of L / D = 5 at U0 = 0 are compared with the isotropic Monte Carlo
// equation of state of McGrother, Williamson & Jackson, J. Chem. Phys. 104, 6755 (1996),
// Table V (Z = P v / (eta kT) at their packing fractions eta, printed where the hard-core eta
// is within 5e-4 of one). Also per run: the collision stress along the nematic director n of
// the run's last step and across it, Z_par = 1 + n . Sigma^col n / (N kT) and Z_perp (the
// mean of the other two directions; Z = (Z_par + 2 Z_perp) / 3), the stress anisotropy of Yan
// et al. Sec. IV.B.
// --tolerance > 0: ERROR when the U0 = 0 ratio is not within tolerance (relative) plus 3 error
// bars of that series.
// One JSON object per line (to --output if given, else stdout) and a readable summary.
#include <stokescontact/dynamics/nematic_order.hpp>
#include <stokescontact/dynamics/time_stepper.hpp>
#include <stokescontact/io/checkpoint.hpp>
#include <stokescontact/io/diagnostics_json.hpp>
#include <stokescontact/io/json.hpp>
#include <stokescontact/mobility/free_draining.hpp>
#include <stokescontact/scenes/periodic_placement.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/brownian_pressure.hpp"
#include "common/cli.hpp"
#include "common/rod_experiment.hpp"

namespace sc = stokescontact;
namespace ex = examples;

namespace brownian_rods {

constexpr const char* kUsage =
    "usage: brownian_rods [--aspect 5] [--phi 0.02 | --eta ETA] [--n 1000] [--box-aspect 1] [--u0 0,1,2,4] [--dt 1e-3]\n"
    "                     [--d-hat 1e-2] [--equilibrate 0.5] [--average 2] [--solver default] [--seed 1]\n"
    "                     [--directions particle|surface|overlap-ends] [--overlap-ends-min-overlap 0.1]\n"
    "                     [--overlap-ends-angle 0.1]\n"
    "                     [--start random|aligned|compressed] [--melt 0]\n"
    "                     [--compress-from 0.25] [--compress-rate 5e-4] [--compress-steps 5]\n"
    "                     [--melt-dt 1e-3] [--progress 0] [--max-substep-halvings 4] [--tolerance 0]\n"
    "                     [--separation-margin 1e-3] [--save-state FILE] [--save-every 1000]\n"
    "                     [--load-state FILE] [--output FILE]\n";

struct Options {
  double aspect = 5.0;
  double box_aspect = 1.0;  // Lz / Lx of the box, Lx = Ly
  double phi = 0.02;
  std::optional<double> eta;  // of the hard core D + d_hat; sets phi when given
  std::size_t n = 1000;
  std::vector<double> u0, dts;
  double d_hat = 1e-2, equilibrate = 0.5, average = 2.0;
  std::string start = "random";
  double melt = 0.0, melt_dt = 1e-3;
  double compress_from = 0.25, compress_rate = 5e-4;  // --start compressed
  long compress_steps = 5;
  long progress = 0;  // melt steps between diagnostics lines on stderr (0: none)
  int halvings = 4;   // TimeStepperOptions::max_substep_halvings
  std::string solver = "default";
  ex::RodDirections directions = ex::RodDirections::particle;
  double min_overlap = sc::ContactStepOptions{}.overlap_ends_min_overlap;
  double ends_angle = sc::ContactStepOptions{}.overlap_ends_angle;
  double separation_margin = sc::ContactStepOptions{}.separation_margin;
  std::uint64_t seed = 1;
  double tolerance = 0.0;
  std::string save_state, load_state;  // checkpoint files (empty: none)
  long save_every = 1000;              // melt steps between checkpoints
  std::string output;
};

Options parse(int argc, char** argv) {
  ex::Arguments args(argc, argv);
  Options o;
  o.aspect = args.number("--aspect", 5.0, 0.0);
  if (!(o.aspect > 0.0)) throw std::invalid_argument("--aspect must be > 0");
  o.eta = args.positive("--eta");
  if (o.eta && args.text("--phi", "") != "") throw std::invalid_argument("give --phi or --eta, not both");
  o.phi = args.number("--phi", 0.02, 0.0);
  o.n = static_cast<std::size_t>(args.integer("--n", 1000, 2));
  o.u0 = args.numbers("--u0", {0.0, 1.0, 2.0, 4.0}, 0.0);
  o.dts = args.numbers("--dt", {1e-3}, 0.0);
  o.d_hat = args.number("--d-hat", 1e-2, 0.0);
  o.equilibrate = args.number("--equilibrate", 0.5, 0.0);
  o.average = args.number("--average", 2.0, 0.0);
  for (const double* v : {&o.d_hat, &o.average})
    if (!(*v > 0.0)) throw std::invalid_argument("--d-hat and --average must be > 0");
  for (const double dt : o.dts)
    if (!(dt > 0.0)) throw std::invalid_argument("--dt must be > 0");
  o.directions = ex::parse_directions(args.text("--directions", "particle"));
  if (o.directions == ex::RodDirections::line)
    throw std::invalid_argument("--directions line needs line-contact rods; use particle, surface or overlap-ends");
  o.min_overlap = args.number("--overlap-ends-min-overlap", o.min_overlap, 1e-12);
  o.ends_angle = args.number("--overlap-ends-angle", o.ends_angle, 1e-12);
  o.separation_margin = args.number("--separation-margin", o.separation_margin, 0.0);
  if (!(o.separation_margin < 1.0)) throw std::invalid_argument("--separation-margin must lie in [0, 1)");
  o.load_state = args.text("--load-state", "");
  if (!o.load_state.empty() && args.text("--start", "") != "")
    throw std::invalid_argument("give --start or --load-state, not both");
  o.save_state = args.text("--save-state", "");
  o.save_every = static_cast<long>(args.integer("--save-every", o.save_every, 1));
  o.start = args.text("--start", "random");
  if (o.start != "random" && o.start != "aligned" && o.start != "compressed")
    throw std::invalid_argument("--start must be random, aligned or compressed, got '" + o.start + "'");
  if (!o.load_state.empty()) o.start = "checkpoint";
  o.box_aspect = args.number("--box-aspect", o.box_aspect, 0.0);
  if (!(o.box_aspect >= 1.0)) throw std::invalid_argument("--box-aspect must be >= 1");
  if (o.box_aspect != 1.0 && (o.start == "random" || o.start == "compressed"))
    throw std::invalid_argument("--box-aspect other than 1 needs --start aligned or --load-state (random and compressed starts fill a cube)");
  o.compress_from = args.number("--compress-from", o.compress_from, 0.0);
  o.compress_rate = args.number("--compress-rate", o.compress_rate, 0.0);
  o.compress_steps = static_cast<long>(args.integer("--compress-steps", o.compress_steps, 0));
  if (o.start == "compressed") {
    if (!o.eta) throw std::invalid_argument("--start compressed needs --eta (the packing it compresses to)");
    if (!(o.compress_from > 0.0 && o.compress_from < *o.eta))
      throw std::invalid_argument("--compress-from must lie in (0, --eta)");
  }
  if (!(o.compress_rate > 0.0 && o.compress_rate < 0.1))  // also for a --load-state at a lower packing
    throw std::invalid_argument("--compress-rate must lie in (0, 0.1)");
  o.melt = args.number("--melt", 0.0, 0.0);
  o.melt_dt = args.number("--melt-dt", 1e-3, 0.0);
  if (!(o.melt_dt > 0.0)) throw std::invalid_argument("--melt-dt must be > 0");
  o.progress = static_cast<long>(args.integer("--progress", 0, 0));
  o.halvings = static_cast<int>(args.integer("--max-substep-halvings", 4, 0));
  o.solver = args.text("--solver", "default");
  sc::contact_solver_from_name(o.solver);
  o.seed = static_cast<std::uint64_t>(args.integer("--seed", 1, 0));
  o.tolerance = args.number("--tolerance", 0.0, 0.0);
  o.output = args.text("--output", "");
  args.reject_unknown();
  return o;
}

// The nematic order parameter S (dynamics/nematic_order.hpp), as an observable of the run.
double order_parameter(std::span<const sc::Pose> poses) { return sc::nematic_order(poses).S; }

// Truncated virial series of (Z - 1) / (B2 n) at U0 = 0 for L / D = 5 (docs/results.md names
// the source of B3 / B2^2 = 0.41946 and B4 / B2^3 = 0.05275); none for other aspects.
std::optional<double> virial_ratio(double aspect, double b2n) {
  if (std::abs(aspect - 5.0) > 1e-12) return std::nullopt;
  return 1.0 + 0.41946 * b2n + 0.05275 * b2n * b2n;
}

// McGrother, Williamson & Jackson, J. Chem. Phys. 104, 6755 (1996), Table V, L / D = 5: the
// isotropic branch (nematic order <= 0.17) of their NPT Monte Carlo, P v / kT at packing
// fraction eta (v the rod's volume), as reproduced in the public repository
// Allen-Tildesley/examples (python_examples/GUIDE.md). Z = P v / (eta kT).
struct MonteCarloPoint {
  double eta, pv;
};
constexpr MonteCarloPoint kMcGrother[] = {{0.310, 2.53}, {0.352, 3.63}, {0.397, 4.89}, {0.400, 5.05}};

std::optional<double> mcgrother_z(double aspect, double eta) {
  if (std::abs(aspect - 5.0) > 1e-12) return std::nullopt;
  for (const MonteCarloPoint& p : kMcGrother)
    if (std::abs(eta - p.eta) <= 5e-4) return p.pv / p.eta;
  return std::nullopt;
}

struct System {
  sc::Spherocylinder rod;
  sc::Mat6 body_mobility;
  double D_R = 0.0, m_par = 0.0;
  sc::Vec3 lengths = sc::Vec3::Zero();  // the periodic box
};

using RodStepper = sc::TimeStepper<sc::Spherocylinder, sc::FreeDrainingMobility>;

// A Brownian stepper from `start` at time t0 with step dt_D_R / D_R, drawing from `noise` on
// (the program's one stream), each rod propelled at u0 along its axis.
std::unique_ptr<RodStepper> make_stepper(const Options& o, const System& s, const std::vector<sc::Pose>& start,
                                         double dt_D_R, double u0, sc::FreeDrainingMobility& mobility,
                                         const sc::GaussianStream& noise, double t0 = 0.0) {
  sc::TimeStepperOptions options;
  options.dt = dt_D_R / s.D_R;
  options.d_hat = o.d_hat;
  options.box = sc::PeriodicBox{s.lengths};
  options.contact_step.directions = ex::contact_directions(o.directions);
  options.contact_step.overlap_ends_min_overlap = o.min_overlap;
  options.contact_step.overlap_ends_angle = o.ends_angle;
  options.contact_step.separation_margin = o.separation_margin;
  options.max_substep_halvings = o.halvings;
  options.brownian.emplace();
  options.brownian->kT = 1.0;
  options.brownian->seed = o.seed;
  auto stepper = std::make_unique<RodStepper>(std::vector<sc::Spherocylinder>{s.rod}, start, mobility,
                                              sc::contact_solver_from_name(o.solver), options, t0);
  stepper->set_noise(noise);
  if (u0 > 0.0)  // self-propulsion: M F = U0 n for the force U0 zeta_par n (no torque)
    stepper->set_external_force_field([u0, m_par = s.m_par](double, std::span<const sc::Pose> poses) {
      sc::VecX F = sc::VecX::Zero(6 * static_cast<Eigen::Index>(poses.size()));
      for (std::size_t i = 0; i < poses.size(); ++i)
        F.segment<3>(6 * static_cast<Eigen::Index>(i)) = (u0 / m_par) * poses[i].rotation().col(2);
      return F;
    });
  return stepper;
}

// --start compressed (see the top): `poses` in the box s.lengths, compressed to the box
// `to_lengths` of the same shape in place, its steps drawing from `noise` on. Prints what it took.
void compress(const Options& o, System s, std::vector<sc::Pose>& poses, const sc::Vec3& to_lengths,
              sc::GaussianStream& noise) {
  const auto t0 = std::chrono::steady_clock::now();
  double rate = o.compress_rate;
  long rescalings = 0, halvings = 0;
  while (s.lengths.x() > to_lengths.x()) {
    const double factor = std::max(to_lengths.x() / s.lengths.x(), 1.0 - rate);
    std::vector<sc::Pose> scaled = poses;
    sc::rescale_centres(scaled, factor);
    const sc::PeriodicBox box{s.lengths * factor};
    if (sc::minimum_pair_distance(s.rod, std::span<const sc::Pose>(scaled), box).distance < 0.5 * o.d_hat) {
      rate *= 0.5;
      ++halvings;
      if (rate < 1e-12) throw std::runtime_error("--start compressed: no rescaling keeps every gap above d_hat / 2");
      continue;
    }
    poses = std::move(scaled);
    s.lengths *= factor;
    ++rescalings;
    sc::FreeDrainingMobility mobility(s.body_mobility, o.n, 6);
    const std::unique_ptr<RodStepper> stepper = make_stepper(o, s, poses, o.melt_dt, 0.0, mobility, noise);
    for (long k = 0; k < o.compress_steps; ++k) stepper->step();
    poses = stepper->poses();
    noise = stepper->noise();
  }
  std::printf("compression: %ld rescalings (the rate halved %ld times), %ld Brownian steps, nematic order %.4f, %.1f s\n",
              rescalings, halvings, rescalings * o.compress_steps, order_parameter(poses),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

int run(const Options& o) {
  constexpr double kT = 1.0, viscosity = 1.0, D = 1.0;
  const double L = o.aspect * D;
  System s{sc::Spherocylinder{L, 0.5 * D}, {}, 0.0, 0.0, sc::Vec3::Zero()};
  s.body_mobility = sc::spherocylinder_mobility(s.rod, viscosity);
  s.D_R = kT * s.body_mobility(3, 3);  // 1 / zeta_r (eq. 49)
  s.m_par = s.body_mobility(2, 2);     // 1 / zeta_par (eq. 47), axis = body z
  const auto rod_volume = [L](double d) { return std::numbers::pi * (0.25 * L * d * d + d * d * d / 6.0); };
  const double Dh = D + o.d_hat;  // the hard core the contact step holds
  const double phi = o.eta ? *o.eta * rod_volume(D) / rod_volume(Dh) : o.phi;
  if (!(phi > 0.0 && phi < (o.start == "random" ? 0.3 : 0.74)))
    throw std::invalid_argument(std::string(o.eta ? "--eta gives phi = " : "--phi = ") + std::to_string(phi) +
                                (o.start == "random" ? ": phi must lie in (0, 0.3) with --start random (denser: --start aligned)"
                                                     : ": phi must lie in (0, 0.74)"));
  const double side = std::cbrt(static_cast<double>(o.n) * rod_volume(D) / phi / o.box_aspect);
  s.lengths = sc::Vec3(side, side, o.box_aspect * side);
  const double number_density = static_cast<double>(o.n) / (s.lengths.x() * s.lengths.y() * s.lengths.z());
  const double eta = number_density * rod_volume(Dh);
  const double b2 = std::numbers::pi * (2.0 * Dh * Dh * Dh / 3.0 + L * Dh * Dh + 0.25 * L * L * Dh);
  const double b2n = b2 * number_density;
  const std::optional<double> reference = virial_ratio(o.aspect, b2n);
  const std::optional<double> monte_carlo = mcgrother_z(o.aspect, eta);
  ex::JsonLines sink(o.output);
  std::vector<sc::Pose> start;
  sc::GaussianStream noise(o.seed);
  double start_time = 0.0;
  if (o.start == "checkpoint") {
    const sc::Checkpoint c = sc::load_checkpoint(o.load_state);
    if (c.poses.size() != o.n)
      throw std::invalid_argument("--load-state " + o.load_state + " holds " + std::to_string(c.poses.size()) +
                                  " rods, --n is " + std::to_string(o.n));
    if (!c.box || std::abs(c.box->lengths.y() - c.box->lengths.x()) > 1e-12 * c.box->lengths.x() ||
        std::abs(c.box->lengths.z() - o.box_aspect * c.box->lengths.x()) > 1e-12 * c.box->lengths.z())
      throw std::invalid_argument("--load-state " + o.load_state + ": its box is not Lx = Ly, Lz = --box-aspect Lx = " +
                                  std::to_string(o.box_aspect) + " Lx");
    if (!c.noise) throw std::invalid_argument("--load-state " + o.load_state + " holds no Brownian stream");
    start = c.poses;
    noise = *c.noise;
    start_time = c.time;
    const double saved_side = c.box->lengths.x(), side_now = s.lengths.x();
    if (saved_side < side_now * (1.0 - 1e-12)) {  // a denser state: expanded at once, no gap shortens
      sc::rescale_centres(start, side_now / saved_side);
      std::printf("expansion: side %.6g -> %.6g (eta %.4f -> %.4f) in one rescaling, every gap kept or widened\n",
                  saved_side, side_now, eta * std::pow(side_now / saved_side, 3), eta);
    } else if (saved_side > side_now * (1.0 + 1e-12)) {  // a more dilute state: compressed as --start compressed
      System from = s;
      from.lengths = c.box->lengths;
      std::printf("compression from eta %.4f:\n", eta * std::pow(side_now / saved_side, 3));
      compress(o, from, start, s.lengths, noise);
    }
  } else if (o.start == "aligned") {
    start = sc::periodic_aligned_columns(s.rod, o.n, sc::PeriodicBox{s.lengths}, o.d_hat, o.seed);
  } else if (o.start == "random") {
    start = sc::periodic_random_placement(s.rod, o.n, s.lengths.x(), o.d_hat, o.seed);
  } else {  // compressed: placed at the hard-core packing compress_from, then compressed
    const double phi_from = o.compress_from * rod_volume(D) / rod_volume(Dh);
    if (!(phi_from < 0.3)) throw std::invalid_argument("--compress-from gives phi = " + std::to_string(phi_from) + ", must be < 0.3");
    System from = s;
    from.lengths = sc::Vec3::Constant(std::cbrt(static_cast<double>(o.n) * rod_volume(D) / phi_from));
    start = sc::periodic_random_placement(s.rod, o.n, from.lengths.x(), o.d_hat, o.seed);
    compress(o, from, start, s.lengths, noise);
  }
  std::printf("Brownian rods: N = %zu spherocylinders L/D = %g in a periodic box %.4g x %.4g x %.4g, phi %g (hard core %.4g), "
              "B2 n = %.5f,\nfree draining (Yan eq. 45-50), D_R = %.5g, equilibrate %g, average %g (1 / D_R), d_hat %g, "
              "solver %s, %s directions, start %s\n",
              o.n, o.aspect, s.lengths.x(), s.lengths.y(), s.lengths.z(), phi, eta, b2n, s.D_R, o.equilibrate, o.average, o.d_hat, o.solver.c_str(),
              ex::directions_name(o.directions), o.start.c_str());
  double start_order = order_parameter(start);
  const auto save_state = [&](const std::vector<sc::Pose>& poses, const sc::GaussianStream& stream, double time) {
    if (!o.save_state.empty())
      sc::save_checkpoint(o.save_state, sc::Checkpoint{time, sc::PeriodicBox{s.lengths}, poses, stream});
  };
  if (o.melt > 0.0) {
    sc::FreeDrainingMobility mobility(s.body_mobility, o.n, 6);
    const std::unique_ptr<RodStepper> melter = make_stepper(o, s, start, o.melt_dt, 0.0, mobility, noise, start_time);
    const long steps = std::lround(o.melt / o.melt_dt);
    const auto t0 = std::chrono::steady_clock::now();
    for (long k = 0; k < steps; ++k) {
      const sc::StepDiagnostics d = melter->step();
      if (o.progress > 0 && (k + 1) % o.progress == 0)  // the step's diagnostics and the order it leaves
        std::fprintf(stderr, "melt {\"nematic_order\": %s, %s\n", sc::json_number(order_parameter(melter->poses())).c_str(),
                     sc::to_json(d).c_str() + 1);
      if ((k + 1) % o.save_every == 0 || k + 1 == steps) save_state(melter->poses(), melter->noise(), melter->time());
    }
    start = melter->poses();
    noise = melter->noise();
    std::printf("melt: %ld steps at dt %g / D_R, nematic order %.4f -> %.4f, t D_R %.6g -> %.6g, %.1f s\n", steps,
                o.melt_dt, start_order, order_parameter(start), start_time * s.D_R, melter->time() * s.D_R,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    start_order = order_parameter(start);
  }
  if (!(o.melt > 0.0)) save_state(start, noise, start_time);
  if (monte_carlo) std::printf("McGrother et al. 1996 (Monte Carlo, isotropic) at eta %.3f: Z = %.4f\n", eta, *monte_carlo);
  std::printf("%9s %8s | %8s %8s | %8s %8s | %9s | %7s %6s %6s | %9s | %7s | %8s\n", "U0/(L DR)", "dt D_R", "ratio",
              "+-", "Z", "+-", "series", "pushed", "apps", "its", "min d/dh", "S", "wall s");
  bool ok = true;
  for (const double u0_scaled : o.u0) {
    const double u0 = u0_scaled * L * s.D_R;
    std::vector<ex::ZAtStep> measured_z;
    for (const double dt_D_R : o.dts) {
      sc::FreeDrainingMobility mobility(s.body_mobility, o.n, 6);
      const std::unique_ptr<RodStepper> stepper = make_stepper(o, s, start, dt_D_R, u0, mobility, noise);
      const ex::BrownianPressureRun r =
          ex::measure_brownian_pressure(*stepper, kT, std::lround(o.equilibrate / dt_D_R),
                                        std::max(2L, std::lround(o.average / dt_D_R)), order_parameter);
      const double z = r.measured() ? r.z.mean(0) : 0.0, z_error = r.measured() ? r.z.std_error(0) : 0.0;
      const double ratio = r.measured() ? (z - 1.0) / b2n : 0.0;
      const double error = z_error / b2n;
      const double order = r.measured() ? r.extra.mean(0) : 0.0;
      const bool converged = r.measured() && r.z.all_converged();
      const sc::DirectionalPressure split =
          sc::pressure_along_and_across(r.collision_stress, sc::nematic_order(stepper->poses()).director);
      const double z_par = 1.0 + split.along, z_perp = 1.0 + split.across;
      const double anisotropy = sc::stress_anisotropy(r.collision_stress);  // Yan Fig. 5
      const bool series = reference && u0 == 0.0;
      const bool mc = monte_carlo && u0 == 0.0;
      sink.line("{\"N\": " + std::to_string(o.n) + ", \"aspect\": " + sc::json_number(o.aspect) + ", \"phi\": " +
                sc::json_number(phi) + ", \"eta\": " + sc::json_number(eta) + ", \"start\": \"" + o.start + "\", \"compress_from\": " +
                (o.start == "compressed" ? sc::json_number(o.compress_from) : std::string("null")) +
                ", \"melt\": " + sc::json_number(o.melt) + ", \"start_nematic_order\": " +
                sc::json_number(start_order) + ", \"u0_over_L_DR\": " + sc::json_number(u0_scaled) +
                ", \"u0\": " + sc::json_number(u0) + ", \"D_R\": " + sc::json_number(s.D_R) + ", \"dt_D_R\": " +
                sc::json_number(dt_D_R) + ", \"d_hat\": " + sc::json_number(o.d_hat) + ", \"solver\": \"" +
                o.solver + "\", \"directions\": \"" + ex::directions_name(o.directions) +
                "\", \"overlap_ends_min_overlap\": " + sc::json_number(o.min_overlap) +
                ", \"overlap_ends_angle\": " + sc::json_number(o.ends_angle) + ", \"separation_margin\": " +
                sc::json_number(o.separation_margin) + ", \"seed\": " +
                std::to_string(o.seed) + ", \"steps_averaged\": " +
                std::to_string(r.steps) + ", \"B2n\": " + sc::json_number(b2n) + ", \"Z\": " + sc::json_number(z) +
                ", \"Z_error\": " + sc::json_number(z_error) + ", \"pressure_ratio\": " + sc::json_number(ratio) +
                ", \"pressure_ratio_error\": " + sc::json_number(error) + ", \"error_converged\": " +
                (converged ? "true" : "false") + ", \"virial_series\": " +
                (series ? sc::json_number(*reference) : "null") + ", \"mcgrother_Z\": " +
                (mc ? sc::json_number(*monte_carlo) : "null") + ", \"Z_parallel\": " + sc::json_number(z_par) +
                ", \"Z_perpendicular\": " + sc::json_number(z_perp) + ", \"stress_anisotropy\": " +
                sc::json_number(anisotropy) + ", \"nematic_order\": " +
                sc::json_number(order) + ", \"pushed_per_step\": " + sc::json_number(r.pushed_per_step) +
                ", \"applications_per_step\": " + sc::json_number(r.applications_per_step) +
                ", \"iterations_per_step\": " + sc::json_number(r.iterations_per_step) +
                ", \"substeps_per_step\": " + sc::json_number(r.substeps_per_step) + ", \"min_d_over_d_hat\": " +
                sc::json_number(r.min_distance_ratio) + ", \"max_correction_turn\": " +
                sc::json_number(r.max_correction_turn) + ", \"fallbacks\": " + std::to_string(r.fallbacks) +
                ", \"wall_s\": " + sc::json_number(r.wall_s) + ", \"failure\": " + sc::json_quoted(r.failure) + "}");
      const std::string series_text = series ? std::to_string(*reference).substr(0, 7) : "-";
      std::printf("%9.3g %8.2g | %8.4f %8.4f | %8.4f %8.4f | %9s | %7.2f %6.2f %6.2f | %9.6f | %7.4f | %8.1f%s\n",
                  u0_scaled, dt_D_R, ratio, error, z, z_error, series_text.c_str(), r.pushed_per_step,
                  r.applications_per_step, r.iterations_per_step, r.min_distance_ratio, order, r.wall_s,
                  converged ? "" : "  (error bar not converged)");
      std::printf("          collision stress along the director %.4f, across %.4f (units n kT); sigma_max / sigma_min %.4f\n",
                  z_par, z_perp, anisotropy);
      if (r.fallbacks > 0)
        std::printf("          %ld contact sub-step(s) failed by the solver and solved again by another; largest "
                    "correction turn %.3g rad\n",
                    r.fallbacks, r.max_correction_turn);
      std::fflush(stdout);
      if (!r.failure.empty()) {
        std::printf("ERROR: U0 / (L D_R) = %g, dt %g / D_R: %s\n", u0_scaled, dt_D_R, r.failure.c_str());
        ok = false;
        continue;
      }
      measured_z.push_back({std::sqrt(dt_D_R), z, z_error});
      if (o.tolerance > 0.0 && series && std::abs(ratio - *reference) > o.tolerance * *reference + 3.0 * error) {
        std::printf("ERROR: U0 = 0: Pi^col / (B2 n kT) = %g +- %g is not within %g of the virial series %g\n", ratio,
                    error, o.tolerance, *reference);
        ok = false;
      }
    }
    if (o.dts.size() < 2 || measured_z.size() != o.dts.size()) continue;
    const ex::Extrapolated z0 = ex::extrapolate_to_zero_step(measured_z);
    const bool mc = monte_carlo && u0 == 0.0;
    sink.line("{\"N\": " + std::to_string(o.n) + ", \"aspect\": " + sc::json_number(o.aspect) + ", \"eta\": " +
              sc::json_number(eta) + ", \"u0_over_L_DR\": " + sc::json_number(u0_scaled) +
              ", \"dt_D_R\": 0, \"extrapolated\": true, \"solver\": \"" + o.solver + "\", \"Z\": " +
              sc::json_number(z0.z) + ", \"Z_error\": " + sc::json_number(z0.error) + ", \"slope_sqrt_dt\": " +
              sc::json_number(z0.slope) + ", \"pressure_ratio\": " + sc::json_number((z0.z - 1.0) / b2n) +
              ", \"pressure_ratio_error\": " + sc::json_number(z0.error / b2n) + ", \"mcgrother_Z\": " +
              (mc ? sc::json_number(*monte_carlo) : "null") + "}");
    std::printf("%9.3g %8s | %8.4f %8.4f | %8.4f %8.4f | slope in sqrt(dt D_R) %.3g%s\n", u0_scaled, "dt -> 0",
                (z0.z - 1.0) / b2n, z0.error / b2n, z0.z, z0.error, z0.slope,
                mc ? (", against McGrother " + std::to_string(*monte_carlo).substr(0, 6) + ": " +
                      std::to_string(100.0 * (z0.z / *monte_carlo - 1.0)).substr(0, 5) + "%")
                         .c_str()
                   : "");
  }
  return ok ? 0 : 1;
}

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  Options o;
  return ex::driver_main("brownian_rods", kUsage, [&] { o = parse(argc, argv); }, [&] { return run(o); });
}

}  // namespace brownian_rods
