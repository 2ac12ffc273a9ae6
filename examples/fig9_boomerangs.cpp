// Broms & Tornberg Fig. 9 (Sec. 3.3.2): one contact step on random suspensions of 40
// boomerangs in a cube of side 12. Each configuration: the boomerangs are placed one at a time,
// a uniform centre in [0, 12)^3 and a uniform rotation, rejected unless every gap to those
// already placed exceeds 1e-2; d_hat = the minimum gap; each body gets a force and torque
// (F, T) drawn uniformly from the sphere |(F, T)| = 100 in R^6 (the paper's "forces and
// torques randomly sampled from a sphere with ||F_ext|| = 100"); U = M F_ext (one
// application, not counted); one contact step with dt = 0.01 and d^S directions (eq. 22-23).
//
//   fig9_boomerangs [--configs 200] [--seed 1] [--boomerangs 40] [--side 12] [--min-gap 1e-2]
//                   [--solver NAME] [--mobility free-draining|multiblob] [--blob-model curve|surface]
//                   [--multiblob-solver matrix-free|dense|adaptive|automatic]
//                   [--blob-spacing H] [--cost formed|matrix-free|blocks|automatic] [--directions surface|particle] [--output FILE]
//   fig9_boomerangs --resolution [--spacings 0.5,0.35,0.25,0.18,0.125] [--reference-spacing 0.09]
//
// Prints one JSON object per configuration (to --output if given, else stdout), then a summary.
// Per configuration: d_hat, d_try, min d over all pairs after / d_hat (9b), the flagged pairs'
// d^P at the trial step and after the correction (9c), status, mobility applications, wall time,
// the solver's message.
// Mobility: free-draining = each body alone, its 6x6 mobility from the boomerang's curve blobs
// (--blob-model curve: boomerang_curve_blobs, --blob-spacing default the tube radius; surface:
// boomerang_surface_blobs at --blob-spacing, default 0.25); multiblob = the same blobs coupled
// by RPY (the paper's rigid multiblob method), matrix-free GMRES unless --multiblob-solver
// says dense (one factorisation per configuration), adaptive or automatic (MultiblobOptions).
// --resolution: the single-body mobility of the boomerang's blob grids (the curve chain, the
// surface grids at --spacings) against a finer surface grid (--reference-spacing) taken as
// the converged value: relative errors of the translation, rotation and coupling blocks
// (Frobenius norms) and of the whole 6x6 matrix in the units where its blocks are comparable.
#include <stokescontact/contact/contact_pairs.hpp>
#include <stokescontact/contact/solvers/contact_solver.hpp>
#include <stokescontact/io/json.hpp>
#include <stokescontact/mobility/boomerang_blobs.hpp>
#include <stokescontact/mobility/free_draining.hpp>
#include <stokescontact/mobility/multiblob_mobility.hpp>
#include <stokescontact/mobility/single_body_mobility.hpp>
#include <stokescontact/scenes/random.hpp>

#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "common/blob_resolution.hpp"
#include "common/cli.hpp"

namespace sc = stokescontact;
namespace ex = examples;

namespace fig9_boomerangs {

constexpr const char* kUsage =
    "usage: fig9_boomerangs [--configs 200] [--seed 1] [--boomerangs 40] [--side 12] [--min-gap 1e-2]\n"
    "                       [--solver NAME] [--mobility free-draining|multiblob] [--blob-model curve|surface]\n"
    "                       [--multiblob-solver matrix-free|dense|adaptive|automatic]\n"
    "                       [--blob-spacing H] [--cost formed|matrix-free|blocks|automatic] [--directions surface|particle] [--output FILE]\n"
    "       fig9_boomerangs --resolution [--spacings 0.5,0.35,0.25,0.18,0.125] [--reference-spacing 0.09]\n";

constexpr double kTimeStep = 0.01;
constexpr double kForceMagnitude = 100.0;

struct Options {
  int configs = 200;
  std::uint64_t seed = 1;
  std::size_t boomerangs = 40;
  double side = 12.0;
  double min_gap = 1e-2;
  sc::ContactSolver solver;
  std::string mobility = "free-draining";
  std::string blob_model = "curve";
  sc::MultiblobSolver multiblob_solver = sc::MultiblobSolver::matrix_free;
  double blob_spacing = 0.0;
  sc::ContactStepOptions step;
  std::string output;
  bool resolution = false;
  std::vector<double> spacings;
  double reference_spacing = 0.09;
};

Options parse(int argc, char** argv) {
  ex::Arguments args(argc, argv);
  Options o;
  o.configs = static_cast<int>(args.integer("--configs", 200, 1));
  o.seed = static_cast<std::uint64_t>(args.integer("--seed", 1, 0));
  o.boomerangs = static_cast<std::size_t>(args.integer("--boomerangs", 40, 2));
  o.side = args.number("--side", 12.0, 1e-6);
  o.min_gap = args.number("--min-gap", 1e-2, 1e-12);
  o.solver = sc::contact_solver_from_name(args.text("--solver", "default"));
  o.mobility = args.text("--mobility", "free-draining");
  if (o.mobility != "free-draining" && o.mobility != "multiblob")
    throw std::invalid_argument("--mobility must be free-draining or multiblob, got '" + o.mobility + "'");
  o.blob_model = args.text("--blob-model", "curve");
  if (o.blob_model != "curve" && o.blob_model != "surface")
    throw std::invalid_argument("--blob-model must be curve or surface, got '" + o.blob_model + "'");
  o.multiblob_solver =
      sc::multiblob_solver_from_name(args.text("--multiblob-solver", "matrix-free"), "--multiblob-solver");
  o.blob_spacing = args.number("--blob-spacing", o.blob_model == "surface" ? 0.25 : 0.0, 0.0);
  o.step.cost = sc::mobility_cost_from_name(args.text("--cost", "matrix-free"), "--cost");
  const std::string directions = args.text("--directions", "surface");
  if (directions != "surface" && directions != "particle")
    throw std::invalid_argument("--directions must be surface or particle, got '" + directions + "'");
  o.step.directions = directions == "surface" ? sc::ContactDirections::surface : sc::ContactDirections::particle;
  o.output = args.text("--output", "");
  o.resolution = args.flag("--resolution");
  o.spacings = args.numbers("--spacings", {0.5, 0.35, 0.25, 0.18, 0.125}, 1e-3);
  o.reference_spacing = args.number("--reference-spacing", 0.09, 1e-3);
  args.reject_unknown();
  return o;
}

// The paper's placement: one at a time, rejected unless every gap exceeds min_gap.
std::vector<sc::Pose> place(const Options& o, const sc::Boomerang& b, sc::Rng& rng) {
  std::vector<sc::Pose> poses;
  while (poses.size() < o.boomerangs) {
    sc::Pose p;
    p.x = sc::uniform_vector(rng, 0.0, o.side);
    p.q = sc::random_rotation(rng);
    bool ok = true;
    for (const sc::Pose& q : poses) {
      if ((p.x - q.x).norm() > 2.0 * sc::bounding_radius(b) + o.min_gap) continue;
      if (!(sc::closest_points(b, p, b, q).distance > o.min_gap)) {
        ok = false;
        break;
      }
    }
    if (ok) poses.push_back(p);
  }
  return poses;
}

// (F, T) uniform on the sphere of radius 100 in R^6: a normalised 6D standard Gaussian.
sc::VecX random_wrenches(std::size_t n, sc::Rng& rng) {
  std::normal_distribution<double> g;
  sc::VecX F(6 * static_cast<Eigen::Index>(n));
  for (Eigen::Index b = 0; b < static_cast<Eigen::Index>(n); ++b) {
    sc::Vec6 w;
    do {
      for (int k = 0; k < 6; ++k) w(k) = g(rng);
    } while (w.norm() < 1e-12);
    F.segment<6>(6 * b) = kForceMagnitude * w.normalized();
  }
  return F;
}

sc::BlobModel blob_model(const Options& o, const sc::Boomerang& b) {
  return o.blob_model == "surface" ? sc::boomerang_surface_blobs(b, o.blob_spacing)
                                   : sc::boomerang_curve_blobs(b, o.blob_spacing);
}

using BoomerangMobility = std::variant<sc::FreeDrainingMobility, sc::MultiblobMobility>;

BoomerangMobility make_mobility(const Options& o, const sc::Boomerang& b) {
  const sc::BlobModel blobs = blob_model(o, b);
  if (o.mobility == "multiblob") {
    sc::MultiblobOptions options;
    options.solver = o.multiblob_solver;
    return BoomerangMobility(std::in_place_type<sc::MultiblobMobility>, blobs, o.boomerangs, options);
  }
  return BoomerangMobility(std::in_place_type<sc::FreeDrainingMobility>, sc::single_body_mobility(blobs, 1.0),
                           o.boomerangs, 6);
}

struct Summary {
  std::vector<double> min_after, applications, wall, nc;
  int respects = 0, converged = 0;
};

template <sc::MobilityOperator M>
void run(const Options& o, M& mobility) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  const std::vector<sc::Boomerang> shapes{b};
  ex::JsonLines sink(o.output);
  const auto mobility_blobs = static_cast<std::size_t>(blob_model(o, b).positions.cols());
  Summary s;
  for (int c = 0; c < o.configs; ++c) {
    const std::uint64_t seed = o.seed + static_cast<std::uint64_t>(c);
    sc::Rng rng(seed);
    const std::vector<sc::Pose> poses = place(o, b, rng);
    const double d_hat = sc::minimum_pair_distance(b, std::span<const sc::Pose>(poses)).distance;
    const sc::VecX F = random_wrenches(o.boomerangs, rng);
    mobility.set_configuration(poses);
    const sc::VecX U = mobility.apply(F);
    const sc::ContactStepProblem<sc::Boomerang> problem{shapes, poses, U, kTimeStep, d_hat, 0.0, 1.0, {}};
    const sc::ContactStepResult r = sc::solve_contact_step(problem, mobility, o.step, o.solver);
    // The flagged pairs' d^P at the trial step Q* (as flagged) and at Q(lambda).
    std::vector<double> before, after;
    for (const sc::ContactPair& p : r.pairs) {
      before.push_back(p.points.distance);
      after.push_back(sc::closest_points(b, r.poses[static_cast<std::size_t>(p.i)], b,
                                         r.poses[static_cast<std::size_t>(p.j)])
                          .distance);
    }
    const std::string json =
        "{\"record\": \"step\", \"seed\": " + std::to_string(seed) + ", \"config\": " + std::to_string(c) +
        ", \"boomerangs\": " + std::to_string(o.boomerangs) + ", \"side\": " + sc::json_number(o.side) +
        ", \"mobility\": \"" + o.mobility + "\", \"blob_model\": \"" + o.blob_model +
        "\", \"blobs_per_body\": " + std::to_string(mobility_blobs) + ", \"solver\": \"" + sc::contact_solver_name(o.solver) +
        "\", \"cost\": \"" + sc::mobility_cost_name(r.cost) + "\", \"directions\": \"" + (o.step.directions == sc::ContactDirections::surface ? "surface" : "particle") +
        "\", \"d_hat\": " + sc::json_number(d_hat) + ", \"d_try\": " + sc::json_number(r.d_try) +
        ", \"flagged\": " + std::to_string(r.flagged_pairs) + ", \"min_d_over_d_hat_after\": " +
        sc::json_number(r.min_distance_ratio) + ", \"pair_d_before\": " + sc::json_array(std::span<const double>(before)) +
        ", \"pair_d_after\": " + sc::json_array(std::span<const double>(after)) + ", \"status\": \"" +
        std::string(sc::to_string(r.status)) + "\", \"applications\": " + std::to_string(r.mobility_applications) +
        ", \"iterations\": " + std::to_string(r.iterations) + ", \"lambda_sum\": " + sc::json_number(r.lambda_sum) +
        ", \"max_correction_turn\": " + sc::json_number(r.max_correction_turn) + ", \"wall_time_s\": " + sc::json_number(r.wall_time_s) + ", \"message\": " + sc::json_quoted(r.message) + "}";
    char progress[200];
    std::snprintf(progress, sizeof progress, "config %3d: d_hat %.3e Nc %3zu min d/d_hat %.6f apps %3zu %7.3f s %s", c,
                  d_hat, r.flagged_pairs, r.min_distance_ratio, r.mobility_applications, r.wall_time_s,
                  std::string(sc::to_string(r.status)).c_str());
    sink.line(json, progress);
    s.min_after.push_back(r.min_distance_ratio);
    s.applications.push_back(static_cast<double>(r.mobility_applications));
    s.wall.push_back(r.wall_time_s);
    s.nc.push_back(static_cast<double>(r.flagged_pairs));
    s.respects += r.min_distance_ratio >= 1.0 - 1e-9;
    s.converged += r.status == sc::ContactStepStatus::converged;
  }
  std::printf("\nFig. 9: %zu boomerangs, side %g, %s mobility (%s blobs, %zu per body), solver %s, %s directions\n",
              o.boomerangs, o.side, o.mobility.c_str(), o.blob_model.c_str(), mobility_blobs,
              sc::contact_solver_name(o.solver).c_str(),
              o.step.directions == sc::ContactDirections::surface ? "surface" : "particle");
  std::printf("%7s | %-29s | %9s | %9s | %-13s | %9s | %6s\n", "configs", "min d/d_hat after (min med max)",
              "d>=d_hat", "converged", "apps (med max)", "med wall", "med Nc");
  std::printf("%7zu | %9.6f %9.6f %9.6f | %8.1f%% | %8.1f%% | %6.0f %6.0f | %8.3fs | %6.0f\n", s.min_after.size(),
              ex::minimum(s.min_after), ex::median(s.min_after), ex::maximum(s.min_after),
              100.0 * s.respects / static_cast<double>(s.min_after.size()),
              100.0 * s.converged / static_cast<double>(s.min_after.size()), ex::median(s.applications),
              ex::maximum(s.applications), ex::median(s.wall), ex::median(s.nc));
}

void run_resolution(const Options& o) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  const double ell = sc::bounding_radius(b);
  ex::JsonLines sink(o.output);
  const sc::BlobModel reference = sc::boomerang_surface_blobs(b, o.reference_spacing);
  const sc::Mat6 ref = sc::single_body_mobility(reference, 1.0);
  std::printf("reference: surface blobs at h = %g (%lld blobs); errors relative to it\n", o.reference_spacing,
              static_cast<long long>(reference.positions.cols()));
  const sc::BlobModel curve = sc::boomerang_curve_blobs(b, o.blob_spacing);
  sink.line(ex::resolution_row("curve", static_cast<std::size_t>(curve.positions.cols()), "spacing",
                               o.blob_spacing > 0.0 ? o.blob_spacing : b.radius, sc::single_body_mobility(curve, 1.0),
                               ref, ell));
  for (const double h : o.spacings) {
    const sc::BlobModel surface = sc::boomerang_surface_blobs(b, h);
    sink.line(ex::resolution_row("surface", static_cast<std::size_t>(surface.positions.cols()), "spacing", h,
                                 sc::single_body_mobility(surface, 1.0), ref, ell));
  }
}

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    if (o.resolution) {
      run_resolution(o);
      return 0;
    }
    BoomerangMobility mobility = make_mobility(o, sc::broms_tornberg_boomerang());
    std::visit([&](auto& m) { run(o, m); }, mobility);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fig9_boomerangs: %s\n%s", e.what(), kUsage);
    return 2;
  }
}

}  // namespace fig9_boomerangs
