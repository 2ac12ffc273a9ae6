// Broms & Tornberg Fig. 7 (Sec. 3.2.2): chains of 40 rods (L_rod = 0.5 end to end, R_rod =
// L_rod / 20), one contact step each. Per chain a unit vector t and a rotation (theta, phi)
// are drawn from the first orthant; the first rod sits at the origin along z, and rod k + 1 is
// rod k rotated by (theta, phi) (body frame: R_z(phi) R_y(theta)) and shifted by beta(d_hat) t
// in rod k's frame, beta the largest shift at which the pair's gap d^P is d_hat (bisection);
// chains where a non-consecutive pair comes closer than d_hat are redrawn. Every rod but the
// last is pushed towards the next rod's centre with |f| = 2 d_hat^(1/3); dt = 0.05; U = M f
// (one application, not counted); then one contact step.
//
//   fig7_rod_chains [--chains 100] [--rods 40] [--seed 1] [--d-hat 1e-4,3e-4,...,1e-1]
//                   [--solver NAME] [--mobility free-draining|multiblob] [--blobs-per-ring 8]
//                   [--multiblob-solver matrix-free|dense|adaptive|automatic]
//                   [--directions particle|surface|line|overlap-ends] [--cost automatic|blocks|formed|matrix-free]
//                   [--output FILE] [--scene FILE]
//   fig7_rod_chains --resolution [--rings 4,6,8,12,16] [--reference-ring 24] [--output FILE]
//
// --cost: the contact step's cost mode (ContactStepOptions::cost; automatic takes blocks for
// free-draining rods: no mobility application); matrix-free counts applications as the
// speed-versus-error table does.
// --scene FILE writes the first chain at the first d_hat as a scene file for stokescontact-run
// (its poses, the pushes as per-body forces, one step; docs/scenes.md) and runs nothing else:
// examples/scenes/rod_chain.json is `fig7_rod_chains --d-hat 1e-2 --scene FILE`.
//
// --resolution: the single-body mobility of the multiblob rod grids (mobility/rod_blobs.hpp,
// viscosity 1) per number of blobs per ring (--rings), for Fig. 7's rod and Fig. 8's (L_rod =
// 2, R_rod = 0.5), against the grid of --reference-ring blobs per ring taken as the converged
// value (examples/common/blob_resolution.hpp: relative errors of the translation, rotation and
// coupling blocks and of the whole matrix); for Fig. 7's rod also the grid's parallel,
// perpendicular and rotational mobility over Yan et al.'s slender-body theory (eq. 45-50),
// the independent value for long rods. One JSON object per grid; nothing else runs.
//
// Per chain one JSON object with, per consecutive pair, d at the trial step Q* (no contact
// forces) and after, and per flagged pair lambda / |f| (the net contact force over the push);
// then a table per d_hat: chains with min d >= d_hat (to 1e-9), >= d_hat (1 - separation
// margin 1e-3), and reported as failed separation; d(lambda) against d_hat (Fig. 7b), (d - d_hat) / d_hat before and
// after (Fig. 7c: min, 10th, 50th, 90th percentile, max), lambda / |f| (Fig. 7d). The paper
// does not list its d_hat values; the default covers 1e-4 to 1e-1 in half decades.
#include <stokescontact/contact/contact_pairs.hpp>
#include <stokescontact/contact/solvers/contact_solver.hpp>
#include <stokescontact/core/rigid_motion.hpp>
#include <stokescontact/io/json.hpp>
#include <stokescontact/mobility/rod_blobs.hpp>
#include <stokescontact/mobility/single_body_mobility.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "common/blob_resolution.hpp"
#include "common/cli.hpp"
#include "common/rod_experiment.hpp"

namespace sc = stokescontact;
namespace ex = examples;

namespace fig7_rod_chains {

constexpr const char* kUsage =
    "usage: fig7_rod_chains [--chains 100] [--rods 40] [--seed 1] [--d-hat LIST] [--solver NAME]\n"
    "                       [--mobility free-draining|multiblob] [--blobs-per-ring 8]\n"
    "                       [--multiblob-solver matrix-free|dense|adaptive|automatic]\n"
    "                       [--directions particle|surface|line|overlap-ends] [--cost automatic|blocks|formed|matrix-free]\n"
    "                       [--output FILE] [--scene FILE]\n"
    "       fig7_rod_chains --resolution [--rings 4,6,8,12,16] [--reference-ring 24] [--output FILE]\n";

constexpr double kLRod = 0.5, kRRod = kLRod / 20.0, kDt = 0.05;  // Sec. 3.2.2

struct Options {
  int chains = 100;
  int rods = 40;
  std::uint64_t seed = 1;
  std::vector<double> d_hats;
  sc::ContactSolver solver;
  ex::RodMobilityModel mobility = ex::RodMobilityModel::free_draining;
  int blobs_per_ring = 8;
  sc::MultiblobSolver multiblob_solver = sc::MultiblobSolver::matrix_free;
  ex::RodDirections directions = ex::RodDirections::particle;
  sc::MobilityCost cost = sc::MobilityCost::automatic;
  std::string output;
  std::string scene;
  bool resolution = false;
  std::vector<double> rings;
  int reference_ring = 24;
};

Options parse(int argc, char** argv) {
  ex::Arguments args(argc, argv);
  Options o;
  o.chains = static_cast<int>(args.integer("--chains", 100, 1));
  o.rods = static_cast<int>(args.integer("--rods", 40, 2));
  o.seed = static_cast<std::uint64_t>(args.integer("--seed", 1, 0));
  o.d_hats = args.numbers("--d-hat", {1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1}, 1e-12);
  o.solver = sc::contact_solver_from_name(args.text("--solver", "default"));
  o.mobility = ex::parse_rod_mobility(args.text("--mobility", "free-draining"));
  o.blobs_per_ring = static_cast<int>(args.integer("--blobs-per-ring", 8, 3));
  o.multiblob_solver =
      sc::multiblob_solver_from_name(args.text("--multiblob-solver", "matrix-free"), "--multiblob-solver");
  o.directions = ex::parse_directions(args.text("--directions", "particle"));
  o.cost = sc::mobility_cost_from_name(args.text("--cost", "automatic"), "--cost");
  o.output = args.text("--output", "");
  o.scene = args.text("--scene", "");
  o.resolution = args.flag("--resolution");
  o.rings = args.numbers("--rings", {4, 6, 8, 12, 16}, 3.0);
  for (const double rings : o.rings)
    if (rings != std::floor(rings)) throw std::invalid_argument("--rings takes whole numbers of blobs per ring");
  o.reference_ring = static_cast<int>(args.integer("--reference-ring", 24, 3));
  args.reject_unknown();
  return o;
}

struct Chain {
  std::vector<sc::Pose> poses;
  double beta = 0.0;
  int redraws = 0;
};

// The gap of rod 0 (origin, along z) and rod 1 (rotated by q, at beta t).
double pair_gap(const sc::Spherocylinder& rod, const sc::Quat& q, const sc::Vec3& t, double beta) {
  return sc::closest_points(rod, sc::Pose{sc::Vec3::Zero(), sc::Quat::Identity()}, rod, sc::Pose{beta * t, q}).distance;
}

// The largest beta with gap d_hat: from beta = L_rod + d_hat (gap >= d_hat: the bounding balls
// of radius L_rod / 2 are d_hat apart) down to the first beta with a smaller gap, then bisection.
double shift_for_gap(const sc::Spherocylinder& rod, const sc::Quat& q, const sc::Vec3& t, double d_hat) {
  double hi = kLRod + d_hat, lo = hi;
  const int scan = 2000;
  for (int k = 1; k <= scan; ++k) {
    lo = hi * (1.0 - static_cast<double>(k) / scan);
    if (pair_gap(rod, q, t, lo) < d_hat) break;
  }
  double upper = lo + hi / scan;  // gap >= d_hat here
  for (int it = 0; it < 200 && upper - lo > 1e-15 * upper; ++it) {
    const double mid = 0.5 * (lo + upper);
    (pair_gap(rod, q, t, mid) < d_hat ? lo : upper) = mid;
  }
  return upper;
}

Chain make_chain(const sc::Spherocylinder& rod, int rods, double d_hat, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> angle(0.0, 0.5 * std::numbers::pi);
  std::normal_distribution<double> normal;
  Chain c;
  for (;; ++c.redraws) {
    const sc::Vec3 t = sc::Vec3(std::abs(normal(rng)), std::abs(normal(rng)), std::abs(normal(rng))).normalized();
    const double theta = angle(rng), phi = angle(rng);
    const sc::Quat step =
        sc::Quat(Eigen::AngleAxisd(phi, sc::Vec3::UnitZ())) * sc::Quat(Eigen::AngleAxisd(theta, sc::Vec3::UnitY()));
    c.beta = shift_for_gap(rod, step, t, d_hat);
    c.poses.assign(1, sc::Pose{sc::Vec3::Zero(), sc::Quat::Identity()});
    for (int k = 1; k < rods; ++k) {
      const sc::Pose& prev = c.poses.back();
      c.poses.push_back({prev.x + c.beta * (prev.q * t), (prev.q * step).normalized()});
    }
    // Non-consecutive pairs no closer than d_hat, else redraw.
    bool ok = true;
    for (const sc::ContactPair& p : sc::find_contact_pairs(rod, std::span<const sc::Pose>(c.poses), d_hat))
      if (p.j - p.i > 1 && p.points.distance < d_hat * (1.0 - 1e-9)) ok = false;
    if (ok) return c;
  }
}

struct Stats {
  std::vector<double> after, rel_before, rel_after, force;
  int chains_respecting = 0, chains_within_margin = 0, failed = 0, chains = 0, redraws = 0;
  std::vector<double> d_try;
};

std::string quantiles(const std::vector<double>& v) {
  std::vector<double> s = v;
  std::sort(s.begin(), s.end());
  const auto q = [&](double f) { return s[static_cast<std::size_t>(std::lround(f * static_cast<double>(s.size() - 1)))]; };
  char buf[160];
  std::snprintf(buf, sizeof buf, "%10.3g %10.3g %10.3g %10.3g %10.3g", s.front(), q(0.1), q(0.5), q(0.9), s.back());
  return buf;
}

template <sc::Shape S, sc::MobilityOperator M>
void run_d_hat(const Options& o, const S& rod, double d_hat, M& mobility, ex::JsonLines& sink, Stats& st) {
  const double f = 2.0 * std::cbrt(d_hat);  // |f_i| = 2 d_hat^(1/3)
  for (int chain = 0; chain < o.chains; ++chain) {
    std::mt19937_64 rng(o.seed + 1000003ULL * static_cast<std::uint64_t>(chain));
    const Chain c = make_chain(rod, o.rods, d_hat, rng);
    st.redraws += c.redraws;
    sc::VecX F = sc::VecX::Zero(6 * o.rods);
    for (int k = 0; k + 1 < o.rods; ++k)
      F.segment<3>(6 * k) = f * (c.poses[static_cast<std::size_t>(k + 1)].x - c.poses[static_cast<std::size_t>(k)].x).normalized();
    mobility.set_configuration(std::span<const sc::Pose>(c.poses));
    const sc::VecX U = mobility.apply(F);
    const std::vector<S> shapes{rod};
    const sc::ContactStepProblem<S> problem{shapes, c.poses, U, kDt, d_hat, 0.0, 1.0, {}};
    sc::ContactStepOptions options;
    options.directions = ex::contact_directions(o.directions);
    options.cost = o.cost;
    const sc::ContactStepResult r = sc::solve_contact_step(problem, mobility, options, o.solver);
    const std::vector<sc::Pose> trial = sc::advance_all(std::span<const sc::Pose>(c.poses), U, 6, kDt);  // Q*, eq. 16
    std::vector<double> before, after, force;
    for (int k = 0; k + 1 < o.rods; ++k) {
      const auto a = static_cast<std::size_t>(k), b = a + 1;
      before.push_back(sc::closest_points(rod, trial[a], rod, trial[b]).distance);
      after.push_back(sc::closest_points(rod, r.poses[a], rod, r.poses[b]).distance);
      st.after.push_back(after.back());
      st.rel_before.push_back((before.back() - d_hat) / d_hat);
      st.rel_after.push_back((after.back() - d_hat) / d_hat);
    }
    for (Eigen::Index k = 0; k < r.lambda.size(); ++k) {
      if (!(r.lambda(k) > 0.0)) continue;  // the pairs that pushed
      force.push_back(r.lambda(k) / f);
      st.force.push_back(force.back());
    }
    st.d_try.push_back(r.d_try);
    ++st.chains;
    st.chains_respecting += r.min_distance_ratio >= 1.0 - 1e-9;
    st.chains_within_margin += r.min_distance_ratio >= 1.0 - options.separation_margin;
    st.failed += r.status == sc::ContactStepStatus::failed_separation;
    char progress[200];
    std::snprintf(progress, sizeof progress, "d_hat %.0e chain %3d: beta %.6f Nc %3zu min d/d_hat %.6f apps %4zu %s",
                  d_hat, chain, c.beta, r.flagged_pairs, r.min_distance_ratio, r.mobility_applications,
                  std::string(sc::to_string(r.status)).c_str());
    sink.line("{\"record\": \"chain\", \"d_hat\": " + sc::json_number(d_hat) + ", \"chain\": " + std::to_string(chain) +
                  ", \"rods\": " + std::to_string(o.rods) + ", \"solver\": \"" + sc::contact_solver_name(o.solver) +
                  "\", \"mobility\": \"" + ex::rod_mobility_name(o.mobility) + "\", \"directions\": \"" +
                  ex::directions_name(o.directions) + "\", \"cost\": \"" + sc::mobility_cost_name(r.cost) +
                  "\", \"beta\": " + sc::json_number(c.beta) +
                  ", \"redraws\": " + std::to_string(c.redraws) + ", \"f\": " + sc::json_number(f) +
                  ", \"d_try\": " + sc::json_number(r.d_try) + ", \"nc\": " + std::to_string(r.flagged_pairs) +
                  ", \"mobility_applications\": " + std::to_string(r.mobility_applications) +
                  ", \"min_d_over_d_hat\": " + sc::json_number(r.min_distance_ratio) +
                  ", \"lambda_sum\": " + sc::json_number(r.lambda_sum) +
                  ", \"max_correction_turn\": " + sc::json_number(r.max_correction_turn) + ", \"wall_time_s\": " +
                  sc::json_number(r.wall_time_s) + ", \"status\": \"" +
                  std::string(sc::to_string(r.status)) + "\", \"d_before\": " + sc::json_array(before) +
                  ", \"d_after\": " + sc::json_array(after) + ", \"lambda_over_f\": " + sc::json_array(force) + "}",
              progress);
  }
}

// The first chain at d_hat as a scene file: its poses, the pushes as per-body forces, one step.
void write_scene(const Options& o, double d_hat) {
  const sc::Spherocylinder rod = ex::paper_rod(kLRod, kRRod);
  std::mt19937_64 rng(o.seed);
  const Chain c = make_chain(rod, o.rods, d_hat, rng);
  const double f = 2.0 * std::cbrt(d_hat);
  std::string poses, forces;
  for (int k = 0; k < o.rods; ++k) {
    const sc::Pose& p = c.poses[static_cast<std::size_t>(k)];
    const sc::Vec3 push = k + 1 < o.rods ? sc::Vec3(f * (c.poses[static_cast<std::size_t>(k + 1)].x - p.x).normalized())
                                         : sc::Vec3::Zero();
    const double q[4] = {p.q.w(), p.q.x(), p.q.y(), p.q.z()};
    poses += std::string(k ? ",\n      " : "") + "{\"position\": " + sc::json_array(p.x) +
             ", \"orientation\": " + sc::json_array(std::span<const double>(q, 4)) + "}";
    forces += std::string(k ? ",\n      " : "") + sc::json_array(push);
  }
  std::FILE* out = std::fopen(o.scene.c_str(), "w");
  if (!out) throw std::runtime_error("cannot write " + o.scene);
  std::fprintf(out,
               "{\n  \"name\": \"rod_chain\",\n  \"description\": \"Broms & Tornberg Fig. 7: a chain of %d rods "
               "(L_rod = 0.5, R_rod = L_rod / 20), consecutive gaps d_hat = %g, each rod pushed towards the next with "
               "|f| = 2 d_hat^(1/3); one step of dt 0.05 (fig7_rod_chains --seed %llu --d-hat %g --scene FILE)\",\n"
               "  \"shape\": {\"type\": \"spherocylinder\", \"length\": %s, \"radius\": %s},\n"
               "  \"bodies\": {\"poses\": [\n      %s]},\n"
               "  \"forces\": {\"type\": \"per_body\", \"force\": [\n      %s]},\n"
               "  \"mobility\": {\"model\": \"free-draining\"},\n"
               "  \"contact\": {\"d_hat\": %s},\n  \"time\": {\"dt\": %s, \"steps\": 1}\n}\n",
               o.rods, d_hat, static_cast<unsigned long long>(o.seed), d_hat, sc::json_number(rod.length).c_str(),
               sc::json_number(rod.radius).c_str(), poses.c_str(), forces.c_str(), sc::json_number(d_hat).c_str(),
               sc::json_number(kDt).c_str());
  std::fclose(out);
  std::printf("fig7_rod_chains: chain of %d rods at d_hat %g -> %s\n", o.rods, d_hat, o.scene.c_str());
}

template <sc::MobilityOperator M>
void run_all(const Options& o, M& mobility) {
  ex::JsonLines sink(o.output);
  const sc::Spherocylinder rod = ex::paper_rod(kLRod, kRRod);
  std::vector<std::pair<double, Stats>> rows;
  for (const double d_hat : o.d_hats) {
    Stats st;
    if (o.directions == ex::RodDirections::line)
      run_d_hat(o, ex::line_contact_rod(rod, 2.0 * kRRod, 0.05), d_hat, mobility, sink, st);
    else
      run_d_hat(o, rod, d_hat, mobility, sink, st);
    rows.emplace_back(d_hat, std::move(st));
  }
  std::printf("\nFig. 7: %d chains of %d rods per d_hat, %s mobility, solver %s, %s directions\n", o.chains, o.rods,
              ex::rod_mobility_name(o.mobility), sc::contact_solver_name(o.solver).c_str(),
              ex::directions_name(o.directions));
  std::printf("%8s %9s %8s %8s %6s | %-54s | %-54s | %-54s\n", "d_hat", "med d_try", "d>=d_hat", "margin", "failed",
              "(d-d_hat)/d_hat before: min p10 p50 p90 max", "after: min p10 p50 p90 max",
              "lambda/|f|: min p10 p50 p90 max");
  for (const auto& [d_hat, st] : rows) {
    std::printf("%8.0e %9.3g %3d/%-4d %3d/%-4d %6d | %s | %s | %s\n", d_hat, ex::median(st.d_try), st.chains_respecting,
                st.chains, st.chains_within_margin, st.chains, st.failed,
                quantiles(st.rel_before).c_str(), quantiles(st.rel_after).c_str(),
                st.force.empty() ? "-" : quantiles(st.force).c_str());
    sink.line("{\"record\": \"summary\", \"d_hat\": " + sc::json_number(d_hat) + ", \"chains\": " +
                  std::to_string(st.chains) + ", \"chains_respecting_d_hat\": " + std::to_string(st.chains_respecting) +
                  ", \"chains_within_margin\": " + std::to_string(st.chains_within_margin) +
                  ", \"failed_separation\": " + std::to_string(st.failed) +
                  ", \"redraws\": " + std::to_string(st.redraws) + ", \"median_d_try\": " +
                  sc::json_number(ex::median(st.d_try)) + ", \"min_d_after\": " + sc::json_number(ex::minimum(st.after)) +
                  ", \"min_rel_after\": " + sc::json_number(ex::minimum(st.rel_after)) + ", \"max_rel_after\": " +
                  sc::json_number(ex::maximum(st.rel_after)) + ", \"max_lambda_over_f\": " +
                  sc::json_number(ex::maximum(st.force)) + "}",
              "");
  }
}

// The rod grids per blobs per ring against the finest (see the top).
void run_resolution(const Options& o) {
  ex::JsonLines sink(o.output);
  const auto grid_of = [](const sc::Spherocylinder& rod, int blobs_per_ring) {
    sc::RodBlobResolution resolution;
    resolution.blobs_per_ring = blobs_per_ring;
    return sc::rod_blob_model(rod, resolution);
  };
  const struct {
    const char* name;
    sc::Spherocylinder rod;
  } rods[] = {{"fig7 rod", ex::paper_rod(kLRod, kRRod)}, {"fig8 rod", ex::paper_rod(2.0, 0.5)}};
  for (const auto& r : rods) {
    const sc::BlobModel reference = grid_of(r.rod, o.reference_ring);
    const sc::Mat6 ref = sc::single_body_mobility(reference, 1.0);
    std::printf("%s (Spherocylinder{%g, %g}): reference %d blobs per ring, %lld blobs\n", r.name, r.rod.length,
                r.rod.radius, o.reference_ring, static_cast<long long>(reference.positions.cols()));
    const bool slender = r.rod.length >= 4.0 * r.rod.radius;  // Yan's theory is for long rods only
    const sc::Mat6 sbt = slender ? sc::spherocylinder_mobility(r.rod, 1.0) : sc::Mat6::Identity();
    for (const double rings : o.rings) {
      const sc::BlobModel grid = grid_of(r.rod, static_cast<int>(rings));
      const sc::Mat6 M = sc::single_body_mobility(grid, 1.0);
      std::string row = ex::resolution_row(r.name, static_cast<std::size_t>(grid.positions.cols()), "blobs_per_ring",
                                           rings, M, ref, sc::bounding_radius(r.rod));
      if (slender) {  // the rod's axis is body z: parallel (2, 2), perpendicular (0, 0), rotation (3, 3)
        row.pop_back();
        row += ", \"parallel_over_sbt\": " + sc::json_number(M(2, 2) / sbt(2, 2)) +
               ", \"perpendicular_over_sbt\": " + sc::json_number(M(0, 0) / sbt(0, 0)) +
               ", \"rotation_over_sbt\": " + sc::json_number(M(3, 3) / sbt(3, 3)) + "}";
      }
      sink.line(row);
    }
  }
}

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  Options o;
  return ex::driver_main(
      "fig7_rod_chains", kUsage, [&] { o = parse(argc, argv); },
      [&] {
        if (!o.scene.empty()) {
          write_scene(o, o.d_hats.front());
          return;
        }
        if (o.resolution) {
          run_resolution(o);
          return;
        }
        ex::RodMobility mobility = ex::make_rod_mobility(o.mobility, ex::paper_rod(kLRod, kRRod),
                                                          static_cast<std::size_t>(o.rods), o.blobs_per_ring,
                                                          o.multiblob_solver);
        std::visit([&](auto& m) { run_all(o, m); }, mobility);
      });
}

}  // namespace fig7_rod_chains
