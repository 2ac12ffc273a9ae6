#pragma once
// One contact step on a scene of forced unit spheres, Broms & Tornberg Sec. 3.1.1: what the
// sphere drivers share. A scene is a contact-free packing (scenes/sphere_packing.hpp) with
// d_hat = its minimum gap and forces of random direction, |f_i| = 100. The unconstrained
// velocities U = M f cost one mobility application, not counted in the contact step; the step
// itself (dt = 0.01, d^P, d_try of eq. 31 times a multiplier) is run by a contact solver
// chosen by value (contact_solver_from_name) and summarised in a StepRecord.
#include <stokescontact/contact/continuous_detection.hpp>
#include <stokescontact/contact/contact_pairs.hpp>
#include <stokescontact/contact/solvers/contact_solver.hpp>
#include <stokescontact/geometry/swept_distance.hpp>
#include <stokescontact/io/json.hpp>
#include <stokescontact/mobility/free_draining.hpp>
#include <stokescontact/mobility/multiblob_mobility.hpp>
#include <stokescontact/mobility/rpy_mobility.hpp>
#include <stokescontact/mobility/sphere_shell.hpp>
#include <stokescontact/scenes/random.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "stokescontact/scenes/sphere_packing.hpp"

namespace examples {

namespace sc = stokescontact;

inline constexpr double kForceMagnitude = 100.0;  // |f_i|, Sec. 3.1.1
inline constexpr double kTimeStep = 0.01;         // dt, Sec. 3.1.1
// A configuration "respects d_hat" when min d / d_hat >= kRespectsDHat (roundoff allowed).
inline constexpr double kRespectsDHat = 1.0 - 1e-9;
// A pair is active when lambda_k > kActiveFraction max lambda.
inline constexpr double kActiveFraction = 1e-12;

// ---------------------------------------------------------------------------------------
// Mobility models of the sphere scenes.

enum class MobilityModel { multiblob, rpy, free_draining };

inline MobilityModel parse_mobility(const std::string& name) {
  if (name == "multiblob") return MobilityModel::multiblob;
  if (name == "rpy") return MobilityModel::rpy;
  if (name == "free-draining") return MobilityModel::free_draining;
  throw std::invalid_argument("unknown mobility '" + name + "' (known: multiblob, rpy, free-draining)");
}

inline const char* mobility_name(MobilityModel m) {
  switch (m) {
    case MobilityModel::multiblob: return "multiblob";
    case MobilityModel::rpy: return "rpy";
    case MobilityModel::free_draining: return "free-draining";
  }
  return "?";
}

using SphereMobility = std::variant<sc::MultiblobMobility, sc::RpyMobility, sc::FreeDrainingMobility>;

// Unit spheres in viscosity 1. multiblob: the paper's 12-blob icosahedral shell (hydrodynamic
// radius 1), matrix-free GMRES, 6 dofs per body; rpy and free-draining: translation only.
inline SphereMobility make_mobility(MobilityModel model, std::size_t n) {
  switch (model) {
    case MobilityModel::multiblob: {
      sc::MultiblobOptions options;
      options.solver = sc::MultiblobSolver::matrix_free;
      return SphereMobility(std::in_place_type<sc::MultiblobMobility>, sc::sphere_shell(12, 1.0), n, options);
    }
    case MobilityModel::rpy:
      return SphereMobility(std::in_place_type<sc::RpyMobility>, n, sc::RpyParameters{1.0, 1.0}, 3);
    case MobilityModel::free_draining:
      return SphereMobility(std::in_place_type<sc::FreeDrainingMobility>, sc::sphere_mobility(sc::Sphere{1.0}, 1.0),
                            n, 3);
  }
  throw std::invalid_argument("unknown mobility model");
}

// ---------------------------------------------------------------------------------------
// Scenes.

enum class PackingKind { random_sequential, dense };

struct SceneSpec {
  std::string name;  // for the output
  PackingKind packing = PackingKind::random_sequential;
  std::size_t spheres = 500;
  double phi = 0.24;  // target packing fraction
};

struct SphereScene {
  std::uint64_t seed = 0;
  sc::SpherePacking packing;
  std::vector<sc::Vec3> forces;
  double d_hat = 0.0;  // the minimum gap (Sec. 3.1.1)
};

// A reproducible scene from (seed, phi): the packing and the forces from one stream.
inline SphereScene make_scene(const SceneSpec& spec, std::uint64_t seed) {
  std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                         static_cast<std::uint32_t>(spec.phi * 1e6), static_cast<std::uint32_t>(spec.packing)};
  std::mt19937_64 rng(sequence);
  SphereScene s;
  s.seed = seed;
  s.packing = spec.packing == PackingKind::dense ? sc::dense_packing(spec.spheres, spec.phi, rng())
                                                 : sc::random_sequential_addition(spec.spheres, spec.phi, rng());
  s.forces = sc::random_forces(spec.spheres, kForceMagnitude, rng);
  s.d_hat = s.packing.min_gap;
  return s;
}

// Forces stacked for a model with `dofs` per body (zero torques for 6).
inline sc::VecX stacked_forces(const std::vector<sc::Vec3>& forces, int dofs) {
  sc::VecX F = sc::VecX::Zero(static_cast<Eigen::Index>(forces.size()) * dofs);
  for (std::size_t i = 0; i < forces.size(); ++i) F.segment<3>(static_cast<Eigen::Index>(i) * dofs) = forces[i];
  return F;
}

// U = M f at Q_t: one application, the caller's (not counted in the contact step).
template <sc::MobilityOperator M>
sc::VecX unconstrained_velocities(M& mobility, const SphereScene& scene) {
  mobility.set_configuration(scene.packing.poses);
  return mobility.apply(stacked_forces(scene.forces, mobility.dofs_per_body()));
}

// ---------------------------------------------------------------------------------------
// One contact step and its numbers.

struct StepSettings {
  double dt = kTimeStep;          // the paper's 0.01; larger for the large-step runs
  double d_try_multiplier = 1.0;  // Sec. 3.1.2: 1, 1.1, 1.2
  // The paper's eq. 31 (one threshold from the fastest sphere), as its figures and tables
  // use; relative: the library's default, one threshold per pair from its relative motion.
  sc::DTryRule d_try_rule = sc::DTryRule::absolute;
  std::optional<double> tol;      // eq. 29 TOL for solvers that have one; none: the solver's own
  sc::ContactStepOptions options;  // cost mode, separation margin
  bool pair_details = false;       // keep per-pair distances and forces (Fig. 4c, 4e, 5)
};

struct StepRecord {
  double d_hat = 0.0, d_try = 0.0;
  std::size_t flagged = 0;            // Nc (pairs added by the guarantee loop included)
  std::size_t active = 0;             // lambda_k > kActiveFraction max lambda
  std::size_t violating_trial = 0;    // flagged pairs with d < d_hat at the trial step Q*
  double min_ratio_trial = 0.0;       // min d / d_hat over all pairs at Q*
  double min_ratio_after = 0.0;       // ... at Q(lambda)
  // Along the returned motion Q_t + t' Psi V, t' in [0, dt]: pairs that overlap inside the
  // step, and the smallest d / d_hat among them (NaN when none).
  std::size_t interior_overlaps = 0;
  double interior_min_ratio = std::numeric_limits<double>::quiet_NaN();
  int iterations = 0;
  std::size_t applications = 0;
  double wall_time_s = 0.0;
  double lambda_sum = 0.0;
  double lambda_max_over_f = 0.0;     // max lambda / |f_i|
  std::string status, message;
  sc::VecX sphere_forces;             // D lambda, the force part only: 3 per sphere
  // With pair_details: per flagged pair, its bodies (i < j), d at Q* / d_try, d at Q(lambda) /
  // d_hat, lambda / |f|.
  bool has_pair_details = false;
  std::vector<std::pair<Eigen::Index, Eigen::Index>> pair_bodies;
  std::vector<double> pair_trial_over_d_try, pair_after_over_d_hat, pair_lambda_over_f;
};

namespace detail {

inline sc::VecX force_part(const sc::VecX& contact_forces, int dofs) {
  const Eigen::Index n = contact_forces.size() / dofs;
  sc::VecX f(3 * n);
  for (Eigen::Index b = 0; b < n; ++b) f.segment<3>(3 * b) = contact_forces.segment<3>(b * dofs);
  return f;
}

inline void keep_pair_details(const sc::ContactStepResult& r, StepRecord& out) {
  const sc::Sphere sphere{1.0};
  out.has_pair_details = true;
  for (std::size_t k = 0; k < r.pairs.size(); ++k) {
    const sc::ContactPair& p = r.pairs[k];
    const double after = sc::closest_points(sphere, r.poses[static_cast<std::size_t>(p.i)], sphere,
                                            r.poses[static_cast<std::size_t>(p.j)]).distance;
    out.pair_bodies.emplace_back(std::min(p.i, p.j), std::max(p.i, p.j));
    out.pair_trial_over_d_try.push_back(p.points.distance / out.d_try);
    out.pair_after_over_d_hat.push_back(after / out.d_hat);
    out.pair_lambda_over_f.push_back(r.lambda(static_cast<Eigen::Index>(k)) / kForceMagnitude);
  }
}

}  // namespace detail

template <sc::MobilityOperator M>
StepRecord run_step(const sc::ContactSolver& solver, const SphereScene& scene, M& mobility, const sc::VecX& U,
                    const StepSettings& settings) {
  const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  const sc::ContactStepProblem<sc::Sphere> problem{shapes, scene.packing.poses, U, settings.dt, scene.d_hat,
                                                   0.0,    settings.d_try_multiplier, {}, settings.d_try_rule};
  // TOL replaces the solver's own where it has one (default, barrier); the LCP sequence keeps
  // stopping at its first separated iterate.
  sc::ContactSolver chosen = solver;
  if (settings.tol && sc::stopping_tolerance(chosen)) sc::set_stopping_tolerance(chosen, *settings.tol);
  const sc::ContactStepResult r = sc::solve_contact_step(problem, mobility, settings.options, chosen);
  const int dofs = mobility.dofs_per_body();
  StepRecord out;
  out.d_hat = scene.d_hat;
  out.d_try = r.d_try;
  out.flagged = r.flagged_pairs;
  for (Eigen::Index k = 0; k < r.lambda.size(); ++k) {
    if (r.lambda(k) > kActiveFraction * r.lambda_max) ++out.active;
    if (r.pairs[static_cast<std::size_t>(k)].points.distance < scene.d_hat) ++out.violating_trial;
  }
  const std::vector<sc::Pose> trial = sc::advance_all(scene.packing.poses, U, dofs, settings.dt);  // Q*, eq. 16
  out.min_ratio_trial =
      sc::minimum_pair_distance(sc::Sphere{1.0}, std::span<const sc::Pose>(trial)).distance / scene.d_hat;
  out.min_ratio_after = r.min_distance_ratio;
  const sc::Sphere sphere{1.0};
  const auto inside = sc::trajectory_crossings(std::span<const sc::Sphere>(shapes), std::span<const sc::Pose>(scene.packing.poses),
                                               r.velocities, dofs, settings.dt, 0.0, 1e-12 * scene.d_hat);
  out.interior_overlaps = inside.size();
  for (const sc::TrajectoryCrossing& c : inside) {
    const auto i = static_cast<std::size_t>(c.i), j = static_cast<std::size_t>(c.j);
    const double lowest = sc::swept_minimum(sphere, scene.packing.poses[i], sc::rigid_velocity(r.velocities, i, dofs), sphere,
                                            scene.packing.poses[j], sc::rigid_velocity(r.velocities, j, dofs), settings.dt,
                                            1e-12 * scene.d_hat)
                              .points.distance / scene.d_hat;
    out.interior_min_ratio = std::isnan(out.interior_min_ratio) ? lowest : std::min(out.interior_min_ratio, lowest);
  }
  out.iterations = r.iterations;
  out.applications = r.mobility_applications;
  out.wall_time_s = r.wall_time_s;
  out.lambda_sum = r.lambda_sum;
  out.lambda_max_over_f = r.lambda_max / kForceMagnitude;
  out.status = sc::to_string(r.status);
  out.message = r.message;
  out.sphere_forces = detail::force_part(r.contact_forces, dofs);
  if (settings.pair_details) detail::keep_pair_details(r, out);
  return out;
}

// ---------------------------------------------------------------------------------------
// JSON.

// The record's fields as `"key": value, ...` (no braces), for a driver's JSON object.
inline std::string json_fields(const StepRecord& r) {
  std::ostringstream os;
  os << "\"d_hat\": " << sc::json_number(r.d_hat) << ", \"d_try\": " << sc::json_number(r.d_try)
     << ", \"nc\": " << r.flagged << ", \"active_pairs\": " << r.active
     << ", \"violating_pairs_trial\": " << r.violating_trial
     << ", \"min_d_over_d_hat_trial\": " << sc::json_number(r.min_ratio_trial)
     << ", \"min_d_over_d_hat_after\": " << sc::json_number(r.min_ratio_after)
     << ", \"interior_overlaps\": " << r.interior_overlaps
     << ", \"interior_min_d_over_d_hat\": " << sc::json_number(r.interior_min_ratio) << ", \"iterations\": " << r.iterations
     << ", \"mobility_applications\": " << r.applications << ", \"wall_time_s\": " << sc::json_number(r.wall_time_s)
     << ", \"lambda_sum\": " << sc::json_number(r.lambda_sum)
     << ", \"lambda_max_over_f\": " << sc::json_number(r.lambda_max_over_f)
     << ", \"status\": " << sc::json_quoted(r.status) << ", \"message\": " << sc::json_quoted(r.message);
  if (r.has_pair_details)
    os << ", \"pair_d_trial_over_d_try\": " << sc::json_array(r.pair_trial_over_d_try)
       << ", \"pair_d_after_over_d_hat\": " << sc::json_array(r.pair_after_over_d_hat)
       << ", \"pair_lambda_over_f\": " << sc::json_array(r.pair_lambda_over_f);
  return os.str();
}

}  // namespace examples
