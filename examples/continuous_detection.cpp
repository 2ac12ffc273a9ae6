// Contact over the whole step (contact/continuous_detection.hpp, contact/contact_step.hpp):
// the tunnelling cases, the Galilean-invariance check and the cost of detection.
//
//   continuous_detection [--part tunnelling,galilean,overhead] [--sizes 1000,10000,100000]
//                        [--repeats 3] [--output FILE]
//
// tunnelling: each case once with the paper's end-of-step check (whole_step off, eq. 31 d_try)
//   and once with the library's defaults; "passed" = a pair's order along its approach
//   reversed (the bodies went through each other), or an overlap anywhere on the returned
//   motion (conservative advancement along Q_t + t' Psi V).
// galilean: 1000 spheres (random sequential addition, phi 0.2) in simple shear u = y e_x,
//   the suspension centred at y = 0, 1e3, 1e4; flagged pairs and time of one contact step
//   (free draining, default solver) for both d_try rules.
// overhead: N spheres on a jittered cubic lattice (phi 0.3), random forces |f| = 100, free
//   draining, dt = d_hat = 0.01: the unconstrained step (U = M f and Q*), the end-of-step
//   detection of the paper (eq. 31) and the relative detection, the interior check on U, and
//   whole contact steps with whole_step on and off (median of --repeats); the extra time of
//   whole_step over the free-draining unconstrained step and, for N <= 1e4, over one RPY
//   application (the unconstrained step with hydrodynamics).
// One JSON object per line (to --output if given, else stdout) and a readable summary on stdout.
#include <stokescontact/contact/contact_pairs.hpp>
#include <stokescontact/contact/continuous_detection.hpp>
#include <stokescontact/contact/d_try.hpp>
#include <stokescontact/dynamics/time_stepper.hpp>
#include <stokescontact/io/json.hpp>
#include <stokescontact/mobility/boomerang_blobs.hpp>
#include <stokescontact/mobility/free_draining.hpp>
#include <stokescontact/mobility/rpy_mobility.hpp>
#include <stokescontact/mobility/single_body_mobility.hpp>
#include <stokescontact/scenes/random.hpp>
#include <stokescontact/scenes/sphere_packing.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "common/cli.hpp"

namespace sc = stokescontact;
namespace ex = examples;

namespace continuous_detection {

constexpr const char* kUsage =
    "usage: continuous_detection [--part tunnelling,galilean,overhead] [--sizes 1000,10000,100000]\n"
    "                            [--repeats 3] [--output FILE]\n";

constexpr double kDHat = 0.01;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Median wall time of `repeats` calls.
double median_time(int repeats, const std::function<void()>& f) {
  std::vector<double> t;
  for (int k = 0; k < repeats; ++k) {
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(seconds_since(start));
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

sc::Quat turn(double angle, const sc::Vec3& axis) { return sc::Quat(Eigen::AngleAxisd(angle, axis.normalized())); }

struct Mode {
  const char* name;
  sc::DTryRule rule;
  bool whole_step;
};
constexpr Mode kModes[] = {{"end_of_step_eq31", sc::DTryRule::absolute, false}, {"whole_step", sc::DTryRule::relative, true}};

// One contact step of a two-body case in both modes: did the pair pass or overlap on the way?
template <sc::Shape S>
void tunnelling_case(ex::JsonLines& sink, const std::string& name, const std::vector<S>& shapes,
                     const std::vector<sc::Pose>& poses, const sc::VecX& U, double dt, const sc::Mat6& body_mobility,
                     int dofs, const sc::Vec3& approach) {
  for (const Mode& mode : kModes) {
    sc::FreeDrainingMobility m(body_mobility, poses.size(), dofs);
    sc::ContactStepProblem<S> p{shapes, poses, U, dt, kDHat};
    p.d_try_rule = mode.rule;
    sc::ContactStepOptions options;
    options.whole_step = mode.whole_step;
    const sc::ContactStepResult r = sc::solve_contact_step(p, m, options);
    const bool reversed = (r.poses[1].x - r.poses[0].x).dot(approach) < 0.0;
    const auto overlaps = sc::trajectory_crossings(std::span<const S>(shapes), std::span<const sc::Pose>(poses),
                                                   r.velocities, dofs, dt, 0.0, 1e-9);
    const bool passed = reversed || !overlaps.empty();
    sink.line("{\"part\": \"tunnelling\", \"case\": " + sc::json_quoted(name) + ", \"mode\": " +
              sc::json_quoted(mode.name) + ", \"dt\": " + sc::json_number(dt) + ", \"status\": " +
              sc::json_quoted(sc::to_string(r.status)) + ", \"flagged\": " + std::to_string(r.flagged_pairs) +
              ", \"carried\": " + std::to_string(r.carried_pairs) + ", \"applications\": " +
              std::to_string(r.mobility_applications) + ", \"min_d_over_d_hat\": " +
              sc::json_number(r.min_distance_ratio) + ", \"passed_through\": " + (passed ? "true" : "false") + "}");
    std::printf("%-34s %-17s dt %-6g %-17s flagged %zu carried %zu apps %2zu  %s\n", name.c_str(), mode.name,
                 dt, std::string(sc::to_string(r.status)).c_str(), r.flagged_pairs, r.carried_pairs,
                 r.mobility_applications,
                 !passed ? "held"
                 : r.status == sc::ContactStepStatus::failed_separation ? "cannot hold it in one step: reported"
                                                                         : "PASSED THROUGH, unreported");
  }
}

void tunnelling(ex::JsonLines& sink) {
  std::printf("\nTunnelling: one contact step, free draining\n");
  {  // Head-on unit spheres at x = 0 and 2.2, +-10.
    const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
    const std::vector<sc::Pose> poses{{sc::Vec3::Zero(), sc::Quat::Identity()}, {sc::Vec3(2.2, 0, 0), sc::Quat::Identity()}};
    const sc::VecX U = (sc::VecX(6) << 10, 0, 0, -10, 0, 0).finished();
    for (const double dt : {0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0})
      tunnelling_case(sink, "head-on spheres, +-10", shapes, poses, U, dt, sc::sphere_mobility(shapes[0], 1.0), 3,
                      sc::Vec3::UnitX());
  }
  {  // A thin rod (R = L/20) falling across another at right angles.
    const sc::Spherocylinder rod{0.5, 0.025};
    const std::vector<sc::Spherocylinder> shapes{rod};
    const std::vector<sc::Pose> poses{{sc::Vec3::Zero(), turn(0.5 * std::numbers::pi, sc::Vec3::UnitY())},
                                      {sc::Vec3(0, 0, 2.0 * rod.radius + 0.05), turn(0.5 * std::numbers::pi, sc::Vec3::UnitX())}};
    const double dt = 0.05;
    for (const double radii : {10.0, 100.0, 1000.0}) {
      sc::VecX U = sc::VecX::Zero(12);
      U(8) = -radii * rod.radius / dt;
      tunnelling_case(sink, "crossing rods, " + std::to_string(static_cast<int>(radii)) + " radii/step", shapes, poses,
                      U, dt, sc::spherocylinder_mobility(rod, 1.0), 6, sc::Vec3::UnitZ());
    }
  }
  {  // A boomerang spinning a full turn in one step beside another: its arms sweep through it.
    const sc::Boomerang b;
    const std::vector<sc::Boomerang> shapes{b};
    const std::vector<sc::Pose> poses{{sc::Vec3::Zero(), sc::Quat::Identity()},
                                      {sc::Vec3(-2.0, 0.0, -2.0), turn(std::numbers::pi, sc::Vec3::UnitY())}};
    const double dt = 0.01;
    sc::VecX U = sc::VecX::Zero(12);
    U(10) = 2.0 * std::numbers::pi / dt;
    const sc::Mat6 body = sc::single_body_mobility(sc::boomerang_curve_blobs(b), 1.0);
    tunnelling_case(sink, "boomerang spinning through another", shapes, poses, U, dt, body, 6, sc::Vec3(-1, 0, -1));
    // The same spin from a torque, through the time stepper and its default sub-steps.
    sc::FreeDrainingMobility m(body, 2, 6);
    sc::VecX F = sc::VecX::Zero(12);
    F.segment<6>(6) = body.ldlt().solve(U.segment<6>(6));
    sc::TimeStepperOptions o;
    o.dt = dt;
    o.d_hat = kDHat;
    sc::TimeStepper<sc::Boomerang, sc::FreeDrainingMobility> stepper(shapes, poses, m, o);
    stepper.set_external_forces(F);
    const sc::StepDiagnostics d = stepper.step();
    sink.line("{\"part\": \"tunnelling\", \"case\": \"boomerang spinning through another\", \"mode\": "
              "\"time_stepper\", \"dt\": " + sc::json_number(dt) + ", \"substeps\": " + std::to_string(d.substeps) +
              ", \"applications\": " + std::to_string(d.mobility_applications) + ", \"min_d_over_d_hat\": " +
              sc::json_number(d.min_distance_ratio) + "}");
    std::printf("%-34s %-17s dt %-6g %-17s substeps %zu apps %2zu min d/d_hat %.6f  held\n",
                 "boomerang spinning through another", "time_stepper", dt, std::string(sc::to_string(d.status)).c_str(),
                 d.substeps, d.mobility_applications, d.min_distance_ratio);
  }
}

std::vector<sc::Pose> shifted_poses(const std::vector<sc::Pose>& poses, const sc::Vec3& shift) {
  std::vector<sc::Pose> out = poses;
  for (sc::Pose& p : out) p.x += shift;
  return out;
}

void galilean(ex::JsonLines& sink, int repeats) {
  std::printf("\nGalilean invariance: 1000 spheres in simple shear u = y e_x, dt 0.01, d_hat 0.01\n");
  const sc::SpherePacking packing = sc::random_sequential_addition(1000, 0.2, 5);
  const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  const double dt = 0.01;
  for (const Mode& mode : kModes) {
    std::set<std::pair<Eigen::Index, Eigen::Index>> reference;
    for (const double centre : {0.0, 1e3, 1e4}) {
      const std::vector<sc::Pose> poses = shifted_poses(packing.poses, sc::Vec3(0, centre - 0.5 * packing.side, 0));
      sc::VecX U(3000);
      for (std::size_t k = 0; k < poses.size(); ++k)
        U.segment<3>(3 * static_cast<Eigen::Index>(k)) = sc::Vec3(poses[k].x.y(), 0, 0);
      sc::FreeDrainingMobility m(sc::sphere_mobility(shapes[0], 1.0), poses.size(), 3);
      sc::ContactStepProblem<sc::Sphere> p{shapes, poses, U, dt, kDHat};
      p.d_try_rule = mode.rule;
      sc::ContactStepOptions options;
      options.whole_step = mode.whole_step;
      sc::ContactStepResult r;
      const double t = median_time(repeats, [&] { r = sc::solve_contact_step(p, m, options); });
      std::set<std::pair<Eigen::Index, Eigen::Index>> flagged;
      for (const sc::ContactPair& pair : r.pairs) flagged.insert({pair.i, pair.j});
      if (centre == 0.0) reference = flagged;
      sink.line("{\"part\": \"galilean\", \"mode\": " + sc::json_quoted(mode.name) + ", \"centre_y\": " +
                sc::json_number(centre) + ", \"flagged\": " + std::to_string(flagged.size()) +
                ", \"same_as_centre_0\": " + (flagged == reference ? "true" : "false") +
                ", \"step_s\": " + sc::json_number(t) + "}");
      std::printf("%-17s centre y %-6g flagged %7zu  same set as at 0: %-3s  step %.4f s\n", mode.name, centre,
                   flagged.size(), flagged == reference ? "yes" : "no", t);
    }
  }
}

// N unit spheres on a cubic lattice at packing fraction phi, each jittered by up to 0.15.
std::vector<sc::Pose> jittered_lattice(std::size_t n, double phi, sc::Rng& rng) {
  const double spacing = std::cbrt(4.0 / 3.0 * std::numbers::pi / phi);
  const auto side = static_cast<std::size_t>(std::ceil(std::cbrt(static_cast<double>(n))));
  std::vector<sc::Pose> poses;
  for (std::size_t k = 0; k < n; ++k) {
    const sc::Vec3 cell(static_cast<double>(k % side), static_cast<double>(k / side % side),
                        static_cast<double>(k / (side * side)));
    poses.push_back({spacing * cell + sc::uniform_vector(rng, -0.15, 0.15), sc::Quat::Identity()});
  }
  return poses;
}

void overhead(ex::JsonLines& sink, const std::vector<std::size_t>& sizes, int repeats) {
  std::printf("\nDetection cost: jittered lattice phi 0.3, |f| = 100, free draining, dt = d_hat = 0.01 (median of %d)\n"
               "%8s | %10s | %10s %10s %10s | %10s %10s | %6s %6s | %10s %6s\n",
               repeats, "N", "U and Q*", "eq31 pairs", "rel pairs", "interior", "step end", "step whole", "Nc", "extra",
               "RPY apply", "extra");
  const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  const double dt = 0.01;
  for (const std::size_t n : sizes) {
    sc::Rng rng(n);
    const std::vector<sc::Pose> poses = jittered_lattice(n, 0.3, rng);
    const std::vector<sc::Vec3> f = sc::random_forces(n, 100.0, rng);
    sc::VecX F(3 * static_cast<Eigen::Index>(n));
    for (std::size_t k = 0; k < n; ++k) F.segment<3>(3 * static_cast<Eigen::Index>(k)) = f[k];
    sc::FreeDrainingMobility m(sc::sphere_mobility(shapes[0], 1.0), n, 3);
    const std::span<const sc::Sphere> sh(shapes);
    const std::span<const sc::Pose> q(poses);
    sc::VecX U;
    std::vector<sc::Pose> trial;
    const double t_free = median_time(repeats, [&] {
      m.set_configuration(poses);
      U = m.apply(F);
      trial = sc::advance_all(poses, U, 3, dt);
    });
    std::size_t nc_eq31 = 0, nc_rel = 0;
    const double t_eq31 = median_time(repeats, [&] {
      nc_eq31 = sc::find_contact_pairs(sh, std::span<const sc::Pose>(trial), sc::d_try_spheres(kDHat, dt, U, 3)).size();
    });
    const double t_rel = median_time(repeats, [&] {
      nc_rel = sc::find_pairs_relative(sh, std::span<const sc::Pose>(trial), U, 3, dt, kDHat, 1.0).pairs.size();
    });
    const double t_interior =
        median_time(repeats, [&] { sc::trajectory_crossings(sh, q, U, 3, dt, -1e-3 * kDHat, 5e-4 * kDHat); });
    double t_step[2] = {0.0, 0.0};
    std::size_t nc_step = 0;
    for (int k = 0; k < 2; ++k) {
      sc::ContactStepProblem<sc::Sphere> p{sh, q, U, dt, kDHat};
      p.d_try_rule = kModes[k].rule;
      sc::ContactStepOptions options;
      options.whole_step = kModes[k].whole_step;
      options.cost = sc::MobilityCost::matrix_free;
      t_step[k] = median_time(repeats, [&] { nc_step = sc::solve_contact_step(p, m, options).flagged_pairs; });
    }
    const double extra = (t_step[1] - t_step[0]) / t_free;
    // With hydrodynamics: one RPY application (the unconstrained step of the Fig. 4 scenes).
    double t_rpy = 0.0;
    if (n <= 10000) {
      sc::RpyMobility rpy(n, sc::RpyParameters{1.0, 1.0}, 3);
      t_rpy = median_time(repeats, [&] {
        rpy.set_configuration(poses);
        U = rpy.apply(F);
      });
    }
    sink.line("{\"part\": \"overhead\", \"N\": " + std::to_string(n) + ", \"unconstrained_s\": " +
              sc::json_number(t_free) + ", \"detect_eq31_s\": " + sc::json_number(t_eq31) + ", \"flagged_eq31\": " +
              std::to_string(nc_eq31) + ", \"detect_relative_s\": " + sc::json_number(t_rel) +
              ", \"flagged_relative\": " + std::to_string(nc_rel) + ", \"interior_check_s\": " +
              sc::json_number(t_interior) + ", \"step_end_of_step_s\": " + sc::json_number(t_step[0]) +
              ", \"step_whole_step_s\": " + sc::json_number(t_step[1]) + ", \"extra_over_unconstrained\": " +
              sc::json_number(extra) + ", \"rpy_apply_s\": " + (t_rpy > 0.0 ? sc::json_number(t_rpy) : "null") + "}");
    std::printf("%8zu | %9.4fs | %9.4fs %9.4fs %9.4fs | %9.4fs %9.4fs | %6zu %5.0f%% | %9.4fs %5.1f%%\n", n,
                 t_free, t_eq31, t_rel, t_interior, t_step[0], t_step[1], nc_step, 100.0 * extra, t_rpy,
                 t_rpy > 0.0 ? 100.0 * (t_step[1] - t_step[0]) / t_rpy : 0.0);
  }
}

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  try {
    ex::Arguments args(argc, argv);
    const std::vector<std::string> parts = args.list("--part", {"tunnelling", "galilean", "overhead"});
    std::vector<std::size_t> sizes;
    for (const std::string& s : args.list("--sizes", {"1000", "10000", "100000"})) {
      const long long v = std::stoll(s);
      if (v < 2) throw std::invalid_argument("--sizes: each must be >= 2, got " + s);
      sizes.push_back(static_cast<std::size_t>(v));
    }
    const int repeats = static_cast<int>(args.integer("--repeats", 3, 1));
    ex::JsonLines sink(args.text("--output", ""));
    args.reject_unknown();
    for (const std::string& part : parts) {
      if (part == "tunnelling") tunnelling(sink);
      else if (part == "galilean") galilean(sink, repeats);
      else if (part == "overhead") overhead(sink, sizes, repeats);
      else throw std::invalid_argument("--part: unknown part '" + part + "'");
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "error: %s\n%s", e.what(), kUsage);
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace continuous_detection
