#pragma once
// One contact step (Broms & Tornberg Sec. 2): the problem, options and result shared by
// every contact solver, and the machinery they share.
//
// Given a contact-free configuration Q_t and the unconstrained velocities U (the caller's
// mobility solve, not counted here), the trial step Q* = Q_t + dt Psi U (eq. 16) flags the
// Nc pairs with d^P <= d_try (by default one threshold per pair from its relative motion,
// contact/continuous_detection.hpp; eq. 30/31 on request) and builds the contact matrix D at Q*: from the
// closest points (d^P, eq. 20-21) or from the surface-node pairs within d_try (d^S, eq.
// 22-23; by default for boomerangs, whose non-convex contacts may touch at several places).
// The constraint is on d^P in both cases (d^S >= d^P for every node pair, Sec. 3.2.1, which
// prints the inequality reversed; so d^P >= d_hat is the stricter); d^S only spreads each
// contact's force over its node pairs.
// A solver then looks for contact magnitudes lambda >= 0 so that the corrected configuration
//     Q(lambda) = Q_t + dt Psi (U + M D lambda)        (eq. 13, M at Q_t)
// keeps every pair at d >= d_hat. Three cost modes for M D lambda:
//   formed:      each column of M D is computed once, on first need (one application each:
//                M D lambda needs the columns with lambda_k != 0, (M D)^T v all Nc of them);
//                every product is then free; each column is held densely (N dofs);
//   matrix_free: one application per distinct M D lambda and per D^T M v;
//   blocks:      M D formed once, exactly and sparsely, from a block-diagonal model's blocks
//                (BlockDiagonalMobility: free draining); no application at all, O(N + Nc)
//                time and memory.
// automatic (the default) takes blocks where the model offers them; otherwise formed for a
// step with few flagged pairs (ContactStepOptions::automatic_formed_max_pairs: formed pays
// one application per working-set pair, while the default solver matrix-free needs a median
// of 4-6 on the Fig. 4 scenes, whatever their size) and matrix_free beyond, where formed
// would pay hundreds of applications and hold a dense column per pair.
// ContactStepResult::cost says which was used. lambda = 0 costs nothing in every mode, so a step
// without contacts costs 0 applications.
//
// Pairs that pass through each other (or sweep past) in the trial step. A flagged pair whose
// distance along the trial motion has its minimum inside the step, below min(d*, d_hat), ends
// on the wrong side (or elsewhere) at Q*, so its closest points there point the wrong way.
// Such a pair is constrained where it first comes within d_hat, at t_c: its contact is the
// pair of centre-curve points closest at Q(t_c), carried with the bodies (material points),
// with the normal n_c of that moment held fixed, and its distance at a configuration is the
// gap of those points along n_c less the radii (< 0 once they have passed each other). Its
// column of D is the gradient of that gap at Q*, consistent with the distance.
//
// The guarantee (run_contact_step) covers the whole step. After a solve:
//   end:      every pair of Q(lambda) has d >= d_hat (1 - separation_margin); a pair that was
//             not flagged and is closer is added (its column from its closest points at Q*);
//   interior: along the corrected motion Q_t + t' Psi (U + M D lambda), t' in [0, dt], no
//             pair overlaps: d(t') >= -separation_margin d_hat (conservative advancement,
//             exact for spheres). A pair that does is added as a carried contact, from where
//             it first comes within d_hat on the corrected motion. A carried pair that still
//             overlaps (its end gap holds, but a turning body's arc passes through the other
//             on the way) gets an interior contact: its closest points where it comes closest
//             on the corrected motion, t_c, carried, with that normal, and the constraint on
//             their gap at t_c itself, d(Q_t + t_c Psi (U + M D lambda)) >= d_hat / 2, whose
//             column is t_c / dt times the gap's gradient there (only t_c of the correction
//             acts before t_c; the space-time constraint of Lu, Rahimian & Zorin 2017 at one
//             time). Its distance is reported as that gap plus d_hat / 2, so every solver
//             holds it at d_hat like any other pair.
// The interior bound is no overlap, not d_hat: d_hat is the margin the next step's
// linearisation needs at its start, while inside a step only overlap is unphysical; a
// rotating body held at d_hat at the end may come closer inside without touching. The step
// is then re-solved, warm-started. One that still violates either reports failed_separation
// with the numbers, never silently (the time stepper then sub-steps by default). So does a
// step whose correction turns a body by more than ContactStepOptions::max_correction_turn:
// eq. 13 is linear in the rotation, and a crossing pair of rods can have a far root (lambda
// thousands of times the push, a turn of radians) whose end gaps all hold. And so does, at
// once, a round whose solver did not converge and left one of its own flagged pairs
// overlapping: the next round's problem would only add constraints.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Sparse>

#include "stokescontact/contact/barrier.hpp"
#include "stokescontact/contact/contact_matrix.hpp"
#include "stokescontact/contact/contact_pairs.hpp"
#include "stokescontact/contact/continuous_detection.hpp"
#include "stokescontact/contact/d_try.hpp"
#include "stokescontact/contact/surface_contacts.hpp"
#include "stokescontact/core/parallel_for.hpp"
#include "stokescontact/core/sparse_transpose_product.hpp"
#include "stokescontact/core/rigid_motion.hpp"
#include "stokescontact/mobility/mobility_operator.hpp"

namespace stokescontact {

// The step to correct. Spans and U are referenced, not copied: they must outlive the solve.
template <Shape S>
struct ContactStepProblem {
  std::span<const S> shapes;         // one per body, or one shared
  std::span<const Pose> poses;       // Q_t, contact free (every d^P >= 0)
  const VecX& U;                     // unconstrained velocities, N * mobility.dofs_per_body()
  double dt = 0.0;                   // > 0
  double d_hat = 0.0;                // > 0, the smallest distance allowed at t + dt
  double d_try = 0.0;                // 0: eq. 31 (dofs 3) or eq. 30 (dofs 6) times the multiplier;
                                     // > 0: used as given (>= d_hat), the multiplier ignored
  double d_try_multiplier = 1.0;     // >= 1
  std::optional<PeriodicBox> box = std::nullopt;  // periodic box, none for open space
  DTryRule d_try_rule = DTryRule::relative;        // when d_try = 0: per pair (relative) or eq. 30/31
};

enum class MobilityCost { automatic, formed, matrix_free, blocks };

inline const char* mobility_cost_name(MobilityCost cost) {
  switch (cost) {
    case MobilityCost::automatic: return "automatic";
    case MobilityCost::formed: return "formed";
    case MobilityCost::matrix_free: return "matrix-free";
    case MobilityCost::blocks: return "blocks";
  }
  return "unknown";
}

// The mode a driver or scene file names (mobility_cost_name's words); `field` names the input.
inline MobilityCost mobility_cost_from_name(std::string_view name, std::string_view field) {
  for (MobilityCost c : {MobilityCost::automatic, MobilityCost::formed, MobilityCost::matrix_free, MobilityCost::blocks})
    if (name == mobility_cost_name(c)) return c;
  fail_argument(field, "unknown cost mode '" + std::string(name) + "' (known: automatic, formed, matrix-free, blocks)");
}

// Where contact forces act: the closest points (eq. 21) or the surface-node pairs (eq. 23);
// automatic: surface for non-convex shapes (boomerangs), particle for convex ones.
// overlap_ends (Spherocylinder scenes): the closest points, and near-parallel rods held at
// both ends of their overlap, two constraints per pair (geometry/overlap_ends.hpp).
enum class ContactDirections { automatic, particle, surface, overlap_ends };

struct ContactStepOptions {
  MobilityCost cost = MobilityCost::automatic;
  // automatic without blocks: formed up to this many flagged pairs, matrix_free beyond.
  std::size_t automatic_formed_max_pairs = 8;
  // A pair is separated when d >= d_hat (1 - separation_margin).
  double separation_margin = 1e-3;
  // Re-solves after adding pairs the trial step missed (the guarantee loop).
  int max_guarantee_rounds = 3;
  ContactDirections directions = ContactDirections::automatic;
  // The guarantee over the whole step (carried contacts, the interior check); false: the
  // paper's check at the end of the step only, where bodies may pass through each other.
  bool whole_step = true;
  // Surface-node spacing h for eq. 23; 0: contact_node_spacing(shape, d_hat).
  double node_spacing = 0.0;
  SurfaceWeights surface_weights;
  // overlap_ends: pairs of rods whose centre lines meet below this angle (radians) are held
  // at both ends of their overlap when it is at least overlap_ends_min_overlap times the
  // smaller radius long; a shorter overlap keeps the closest points, whose jump across it
  // moves the force by at most that length. A pair held at one end of its overlap misses the
  // other end's gap by the step's turn times the overlap (the staggered rows of the Fig. 8
  // grid, overlap 0.97 R, stopped every solver with a minimum of 1 R: docs/results.md).
  double overlap_ends_angle = 0.1;
  double overlap_ends_min_overlap = 0.1;
  // The largest turn dt |omega_c| the contact correction M D lambda may give a body in one
  // step, in radians. Eq. 13 is linear in the rotation, so a correction turning a body by
  // radians to hold a gap of d_hat is a root of the linearised problem, not a motion: a step
  // that needs more reports failed_separation (the stepper then sub-steps). Bodies without
  // rotational degrees of freedom (spheres) never turn.
  double max_correction_turn = 0.5;
  // A step whose flagged body pairs outnumber this many per body is refused before its solve
  // (failed_separation, saying how many; the stepper then sub-steps): the trial motions carry
  // the bodies through many neighbours each (equal spheres touch at most 12, 6 pairs per body;
  // the dense suspensions of docs/results.md flag 1-7), where one linearised step cannot order
  // the collisions, and the solve of tens of thousands of such pairs costs tens of seconds (500
  // spheres at 100x the Fig. 4 step: 31098 pairs, 51 s, failed). 0: never refused.
  double max_flagged_pairs_per_body = 16.0;
  // The skin of the candidates the step's broad-phase queries share (CellList::keep_candidates):
  // negative, automatic (ContactStep::candidate_skin); 0, every query collects afresh. It sets
  // the cost of the queries, never their answer.
  double broad_phase_skin = -1.0;

  void validate() const {
    if (!(separation_margin >= 0.0 && separation_margin < 1.0))
      fail_argument("ContactStepOptions.separation_margin",
                    "must lie in [0, 1), got " + std::to_string(separation_margin));
    if (max_guarantee_rounds < 0)
      fail_argument("ContactStepOptions.max_guarantee_rounds",
                    "must be >= 0, got " + std::to_string(max_guarantee_rounds));
    require_non_negative(node_spacing, "ContactStepOptions.node_spacing");
    if (!(overlap_ends_angle > 0.0 && overlap_ends_angle <= 0.5 * std::numbers::pi))
      fail_argument("ContactStepOptions.overlap_ends_angle",
                    "must lie in (0, pi/2], got " + std::to_string(overlap_ends_angle));
    if (!(overlap_ends_min_overlap > 0.0 && std::isfinite(overlap_ends_min_overlap)))
      fail_argument("ContactStepOptions.overlap_ends_min_overlap",
                    "must be positive and finite, got " + std::to_string(overlap_ends_min_overlap));
    require_finite(broad_phase_skin, "ContactStepOptions.broad_phase_skin");
    if (!(max_correction_turn > 0.0))
      fail_argument("ContactStepOptions.max_correction_turn",
                    "must be > 0 radians, got " + std::to_string(max_correction_turn));
    require_non_negative(max_flagged_pairs_per_body, "ContactStepOptions.max_flagged_pairs_per_body");
  }

  // Whether a scene of shape S uses d^S for its contact directions.
  template <Shape S>
  bool surface_directions() const {
    return directions == ContactDirections::surface || (directions == ContactDirections::automatic && !S::convex);
  }
};

enum class ContactStepStatus { converged, not_converged, failed_separation };

// The status as the drivers' and the stepper's JSON write it: "converged", ...
constexpr std::string_view to_string(ContactStepStatus status) {
  switch (status) {
    case ContactStepStatus::converged: return "converged";
    case ContactStepStatus::not_converged: return "not_converged";
    case ContactStepStatus::failed_separation: return "failed_separation";
  }
  return "unknown";
}

// Where a contact step's wall time went, phase by phase of run_contact_step (seconds). The
// phases follow one another, so they add up to wall_time_s (to rounding).
struct ContactStepPhaseTimes {
  double setup_s = 0.0;           // ContactStep: Q_t's check, detection at Q*, D's columns, M D
  double solve_s = 0.0;           // the solver's rounds (the default solver's early end check is in it)
  double end_check_s = 0.0;       // Q(lambda) and the query for pairs below d_hat at the end
  double interior_check_s = 0.0;  // trajectory_crossings along the corrected motion (whole_step)
  double add_pairs_s = 0.0;       // guarantee rounds: the missed pairs' columns and measurements
  double finish_s = 0.0;          // the result: forces, velocities, min d^P, energies, residuals

  double total() const { return setup_s + solve_s + end_check_s + interior_check_s + add_pairs_s + finish_s; }
  ContactStepPhaseTimes& operator+=(const ContactStepPhaseTimes& o) {
    setup_s += o.setup_s;
    solve_s += o.solve_s;
    end_check_s += o.end_check_s;
    interior_check_s += o.interior_check_s;
    add_pairs_s += o.add_pairs_s;
    finish_s += o.finish_s;
    return *this;
  }
};

// The same result for every solver.
struct ContactStepResult {
  ContactStepStatus status = ContactStepStatus::converged;
  std::string message;                  // what happened, with the numbers when not converged
  VecX lambda;                          // contact magnitudes, one per flagged pair, >= 0
  std::vector<ContactPair> pairs;       // the flagged pairs at Q* (missed ones appended)
  VecX contact_forces;                  // D lambda: forces (and torques) per body
  // The columns of D at Q*, one per pair (D = assemble_contact_matrix(columns, N, dofs)):
  // where each pair's force acts, for the collision stress (dynamics/collision_stress.hpp).
  std::vector<ContactColumn> columns;
  VecX velocities;                      // U + M D lambda
  std::vector<Pose> poses;              // Q(lambda), the new configuration
  int iterations = 0;                   // solver iterations over all rounds (see each solver)
  std::size_t mobility_applications = 0;
  MobilityCost cost = MobilityCost::formed;  // the cost mode used (automatic resolved)
  double wall_time_s = 0.0;
  ContactStepPhaseTimes phase_times;    // wall_time_s by phase
  // Broad-phase queries of the step over all bodies (detection, end and whole-step checks),
  // and how many the candidates kept within ContactStepOptions::broad_phase_skin answered.
  int broad_phase_queries = 0;
  int broad_phase_reused = 0;
  double d_try = 0.0;                   // the threshold used
  double min_distance_ratio = 0.0;      // min d^P over all pairs of Q(lambda) / d_hat (inf: < 2 bodies)
  double barrier_energy = 0.0;          // sum b(d_k) over flagged pairs at Q(lambda), eq. 10 with eps_reg = d_try
  // max_k min(lambda_k / max lambda, (d_k - d_hat)_+ / d_hat): 0 when every pushed pair sits at d_hat.
  double complementarity_residual = 0.0;
  double lambda_sum = 0.0;
  double lambda_max = 0.0;
  std::size_t flagged_pairs = 0;        // Nc
  std::size_t carried_pairs = 0;        // of them, constrained where they first came within d_hat
  int guarantee_rounds = 0;             // re-solves after adding missed pairs
  double max_correction_turn = 0.0;     // max over bodies of dt |omega| of M D lambda, radians
  Eigen::Index max_correction_turn_body = -1;  // the body that turns most (-1: none turns)
  // The solver whose answer this is when the default solver failed the step and another one
  // solved it again ("barrier-working-set", "lcp-newton"; solve_contact_step); empty otherwise.
  // The work counted above is that of every solve.
  std::string fallback;
  // failed_separation before any solve: more flagged body pairs per body than
  // ContactStepOptions::max_flagged_pairs_per_body. Every solver would refuse the same step,
  // so no fallback is tried; a smaller step is the remedy.
  bool refused = false;
};

// What a solver's core returns for one round: lambda and its own convergence.
struct ContactSolveOutcome {
  VecX lambda;
  int iterations = 0;
  bool converged = false;
  std::string message;
};

// A pair constrained where it first came within d_hat (see the top of this file): its
// centre-curve points in each body's frame (body j: its image), carried with the bodies,
// and the normal of that moment, fixed.
// An interior contact (interior = true) is held at its own time t_c inside the step instead
// of at the end: the pair's gap at Q_t + t_c Psi (U + M D lambda), where it came closest on a
// corrected motion that still overlapped there (see the top of this file).
struct CarriedContact {
  Vec3 curve_point_i = Vec3::Zero();
  Vec3 curve_point_j = Vec3::Zero();
  Vec3 normal = Vec3::UnitX();
  double radius_i = 0.0;
  double radius_j = 0.0;
  double time = 0.0;  // t_c in [0, dt]
  bool interior = false;
};

// The carried contact of bodies i, j at their poses (pose_j of j's image): points, fixed
// normal and their gap along it, d = n . (c_j - c_i) - r_i - r_j.
inline ContactPair carried_pair(const CarriedContact& c, Eigen::Index i, Eigen::Index j, const Vec3& image_shift,
                                const Pose& pose_i, const Pose& pose_j) {
  const Vec3 ci = pose_i.to_world(c.curve_point_i);
  const Vec3 cj = pose_j.to_world(c.curve_point_j);
  ContactPair p{i, j, image_shift, {}, std::nullopt, std::nullopt};
  p.points.distance = c.normal.dot(cj - ci) - c.radius_i - c.radius_j;
  p.points.normal = c.normal;
  p.points.curve_point_a = ci;
  p.points.curve_point_b = cj;
  // Both forces at the middle of the carried points: torques balance (at the contact time the
  // points lie along the normal and this is the gap's exact gradient).
  p.points.point_a = p.points.point_b = 0.5 * (ci + cj);
  return p;
}

// The same at a configuration of all bodies.
inline ContactPair carried_pair(const CarriedContact& c, Eigen::Index i, Eigen::Index j, const Vec3& image_shift,
                                std::span<const Pose> poses) {
  return carried_pair(c, i, j, image_shift, poses[static_cast<std::size_t>(i)],
                      shifted(poses[static_cast<std::size_t>(j)], image_shift));
}

// Q(lambda) with its flagged-pair distances and closest points.
struct ContactEvaluation {
  VecX lambda;
  VecX MD_lambda;  // M D lambda
  std::vector<Pose> poses;
  std::vector<ContactPair> pairs;  // the flagged pairs re-measured at Q(lambda)
  VecX distances;

  double min_distance() const {
    return distances.size() == 0 ? std::numeric_limits<double>::infinity() : distances.minCoeff();
  }
};

// The shared machinery of one step: Q*, flagged pairs, D, M D lambda, Q(lambda), distances.
template <Shape S, MobilityOperator M>
class ContactStep {
 public:
  // Validates everything (std::invalid_argument naming the field) before touching `mobility`.
  ContactStep(const ContactStepProblem<S>& problem, M& mobility, const ContactStepOptions& options)
      : problem_(problem), mobility_(mobility), options_(options) {
    options.validate();
    validate_scene(problem.shapes, problem.poses);
    require_positive(problem.dt, "dt");
    require_positive(problem.d_hat, "d_hat");
    dofs_ = mobility.dofs_per_body();
    cost_ = options.cost;
    if (cost_ == MobilityCost::automatic && BlockDiagonalMobility<M>) cost_ = MobilityCost::blocks;
    if (cost_ == MobilityCost::blocks && !BlockDiagonalMobility<M>)
      fail_argument("ContactStepOptions.cost", "blocks needs a block-diagonal mobility (BlockDiagonalMobility, "
                                               "e.g. FreeDrainingMobility); use formed or matrix_free");
    detail::require_velocities(problem.U, problem.poses.size(), dofs_);
    if (mobility.size() != static_cast<Eigen::Index>(problem.poses.size()) * dofs_)
      fail_argument("mobility", "has size " + std::to_string(mobility.size()) + ", expected " +
                                    std::to_string(problem.poses.size() * static_cast<std::size_t>(dofs_)));
    if (problem.box) require_finite(problem.box->lengths, "box.lengths");
    require_finite(problem.d_try_multiplier, "d_try_multiplier");
    if (!(problem.d_try_multiplier >= 1.0))
      fail_argument("d_try_multiplier", "must be >= 1, got " + std::to_string(problem.d_try_multiplier));
    d_try_ = problem.d_try;
    if (d_try_ != 0.0) {
      require_positive(d_try_, "d_try");
      if (!(d_try_ >= problem.d_hat))
        fail_argument("d_try", "must be >= d_hat = " + std::to_string(problem.d_hat) + ", got " +
                                   std::to_string(d_try_));
    }
    if (options.directions == ContactDirections::overlap_ends && !std::is_same_v<S, Spherocylinder>)
      fail_argument("ContactStepOptions.directions", "overlap_ends holds pairs of rods: it needs a Spherocylinder scene");
    if (options.surface_directions<S>()) {
      for (const S& shape : problem.shapes)
        nodes_.push_back(surface_nodes(shape, options.node_spacing > 0.0 ? options.node_spacing : contact_node_spacing(shape, problem.d_hat)));
    }
    cells_.keep_candidates(options.broad_phase_skin < 0.0 ? candidate_skin(problem) : options.broad_phase_skin);
    trial_ = advance_all(problem.poses, problem.U, dofs_, problem.dt);  // Q*, eq. 16
    scratch_poses_ = trial_;
    const std::span<const Pose> trial(trial_);
    if (d_try_ == 0.0 && problem.d_try_rule == DTryRule::relative) {
      RelativePairs found = find_pairs_relative(problem.shapes, trial, problem.U, dofs_, problem.dt, problem.d_hat,
                                                problem.d_try_multiplier, problem.box, &cells_);
      pairs_ = std::move(found.pairs);
      // Every pair within d_hat at Q_t is flagged (a pair that comes within d_hat at any time of
      // the trial step is: continuous_detection.hpp), so Q_t is contact free when the flagged
      // pairs are there: O(Nc) distances instead of a broad phase over all N bodies at Q_t
      // (6% of a step of 1e5 free-draining spheres).
      // (Their distances only: at 1e6 spheres 3.1e5 pairs held whole, 320 bytes each, were 100 MB.)
      std::vector<double> at_start(pairs_.size());
      parallel_for(nc(), [&](std::ptrdiff_t k) {
        const ContactPair& p = pairs_[static_cast<std::size_t>(k)];
        at_start[static_cast<std::size_t>(k)] =
            detail::contact_pair(problem.shapes, problem.poses, p.i, p.j, problem.box).points.distance;
      });
      require_contact_free(pairs_, at_start);
      unflagged_stay_clear_ = true;
      // One value where one is needed (the barrier's eps_reg, the d^S node threshold): the largest.
      d_try_ = problem.d_try_multiplier * problem.d_hat;
      for (double d : found.d_try) d_try_ = std::max(d_try_, d);
    } else {
      if (d_try_ == 0.0)
        d_try_ = dofs_ == 3 ? d_try_spheres(problem.d_hat, problem.dt, problem.U, 3, problem.d_try_multiplier)
                            : d_try_tip_velocity(problem.d_hat, problem.dt, problem.shapes, problem.poses, problem.U,
                                                 problem.d_try_multiplier);
      // Contact free: no pair with d^P < 0 among those with d^P <= 0 at Q_t (a narrow broad phase).
      const std::vector<ContactPair> touching = find_contact_pairs(problem.shapes, problem.poses, 0.0, problem.box, &cells_);
      std::vector<double> at_start(touching.size());
      for (std::size_t k = 0; k < touching.size(); ++k) at_start[k] = touching[k].points.distance;
      require_contact_free(touching, at_start);
      pairs_ = find_contact_pairs(problem.shapes, trial, d_try_, problem.box, &cells_);
    }
    if (cost_ == MobilityCost::automatic)
      cost_ = pairs_.size() <= options.automatic_formed_max_pairs ? MobilityCost::formed : MobilityCost::matrix_free;
    carried_.assign(pairs_.size(), std::nullopt);
    if (options.whole_step)
      parallel_for(nc(), [&](std::ptrdiff_t k) { carry_if_passing(static_cast<std::size_t>(k)); });  // pair k only
    split_overlap_ends_from(0);
    rebuild();
    // Everything checked: only now touch the mobility.
    start_applications_ = mobility.applications();
    mobility.set_configuration(problem.poses);  // M at Q_t (eq. 13)
    if constexpr (BlockDiagonalMobility<M>)
      if (cost_ == MobilityCost::blocks) {
        M_blocks_ = mobility.block_diagonal();
        append_block_diagonal_product(MD_, M_blocks_, D_, trial_.size());
      }
  }

  // The skin of the candidates the step's broad-phase queries share (detection, the early and
  // final end checks, the whole-step check: CellList::keep_candidates): 2 d_hat plus the
  // trial motion relative to the mean, dt times the root mean square of |u_k - u_mean|, room
  // for corrections that move two bodies back by half their trial motion each; at most the
  // largest bounding radius. Not the fastest body's motion: one body flung across the scene
  // would widen every cell and make every pair a candidate. A query whose bodies moved farther
  // collects afresh (and keeps its own candidates): the skin sets the cost, never the answer.
  // (At 1e5 spheres, |f| = 100, dt = d_hat = 0.01, the later queries needed 0.032-0.033 of the
  // skin's 0.073; a skin of 0.116 gave detection's query 1.2x the profile's samples:
  // docs/results.md, "The step's queries share one broad phase".)
  double candidate_skin(const ContactStepProblem<S>& problem) const {
    const std::size_t n = problem.poses.size();
    const Vec3 mean = detail::mean_velocity(problem.U, n, dofs_);
    double squares = 0.0, largest_radius = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      squares += (rigid_velocity(problem.U, k, dofs_).u - mean).squaredNorm();
      largest_radius = std::max(largest_radius, bounding_radius(shape_of(problem.shapes, k)));
    }
    const double rms = n == 0 ? 0.0 : std::sqrt(squares / static_cast<double>(n));
    return std::min(2.0 * problem.d_hat + problem.dt * rms, largest_radius);
  }

  // Adds pairs (i < j) not yet flagged, measured at Q*; returns how many were new. A pair
  // held at its overlap ends only (overlap_ends) gains its closest points: it ended too
  // close between them.
  std::size_t add_pairs(std::span<const ContactPair> found) {
    using Key = std::pair<Eigen::Index, Eigen::Index>;
    std::vector<Key> known, ends_only;  // sorted: Nc keys without a node each
    known.reserve(pairs_.size());
    for (std::size_t k = 0; k < pairs_.size(); ++k)
      if (!carried_[k]) (pairs_[k].segment_end ? ends_only : known).push_back({pairs_[k].i, pairs_[k].j});
    std::sort(known.begin(), known.end());
    std::sort(ends_only.begin(), ends_only.end());
    std::set<Key> added_keys;  // `found` may name a pair twice
    std::size_t added = 0;
    const std::size_t first = pairs_.size();
    std::vector<char> split;
    for (const ContactPair& p : found) {
      const Key key{p.i, p.j};
      if (std::binary_search(known.begin(), known.end(), key) || !added_keys.insert(key).second) continue;
      pairs_.push_back(detail::contact_pair(problem_.shapes, std::span<const Pose>(trial_), p.i, p.j, problem_.box));
      carried_.emplace_back();
      split.push_back(!std::binary_search(ends_only.begin(), ends_only.end(), key));
      ++added;
    }
    split_overlap_ends_from(first, split);
    if (added > 0) rebuild();
    return added;
  }

  // Adds contacts for pairs that overlap inside the step on the motion with velocities V: a
  // carried contact from where the pair first comes within d_hat on it; for a pair that
  // already has one (its end gap holds, yet it overlaps on the way: a rotation's arc), an
  // interior contact at the time it comes closest, unless it has one within dt / 1000 of
  // that time. Returns how many were new.
  std::size_t add_crossings(std::span<const TrajectoryCrossing> found, const VecX& V) {
    std::set<std::pair<Eigen::Index, Eigen::Index>> carried;
    std::multimap<std::pair<Eigen::Index, Eigen::Index>, double> interior_times;
    for (std::size_t k = 0; k < pairs_.size(); ++k) {
      if (!carried_[k]) continue;
      const std::pair<Eigen::Index, Eigen::Index> key{pairs_[k].i, pairs_[k].j};
      if (carried_[k]->interior)
        interior_times.insert({key, carried_[k]->time});
      else
        carried.insert(key);
    }
    std::size_t added = 0;
    for (const TrajectoryCrossing& c : found) {
      if (carried.insert({c.i, c.j}).second) {
        carried_.push_back(carried_contact(c.i, c.j, c.image_shift, V, false));
      } else {
        CarriedContact closest = carried_contact(c.i, c.j, c.image_shift, V, true);
        const auto [first, last] = interior_times.equal_range({c.i, c.j});
        if (std::any_of(first, last, [&](const auto& t) { return std::abs(t.second - closest.time) < 1e-3 * problem_.dt; }))
          continue;
        interior_times.insert({{c.i, c.j}, closest.time});
        carried_.push_back(closest);
      }
      pairs_.push_back(carried_at(*carried_.back(), {c.i, c.j, c.image_shift, {}, std::nullopt, std::nullopt},
                                  problem_.U, std::span<const Pose>(trial_)));
      ++added;
    }
    if (added > 0) rebuild();
    return added;
  }

  // M D lambda: free for lambda = 0, for formed columns and with blocks, else one application.
  VecX MD_times(const VecX& lambda) {
    VecX out;
    MD_times(lambda, out);
    return out;
  }

  // The same into `out`, whose storage is kept when it has the size already.
  void MD_times(const VecX& lambda, VecX& out) {
    out.resize(mobility_.size());
    if (lambda.isZero(0.0)) {
      out.setZero();
    } else if (cost_ == MobilityCost::blocks) {
      out.noalias() = MD_ * lambda;
    } else if (cost_ == MobilityCost::matrix_free) {
      out = mobility_.apply(VecX(D_ * lambda));
    } else {
      out.setZero();
      for (Eigen::Index k = 0; k < lambda.size(); ++k)
        if (lambda(k) != 0.0) out += lambda(k) * formed_column(k);
    }
  }

  // c D^T v: c times the rates of change of the flagged pairs' distances under the rigid
  // motions v (contact_matrix.hpp), on the calling thread below 65536 pairs
  // (core/sparse_transpose_product.hpp).
  VecX D_transpose_times(const VecX& v, double c = 1.0) const { return sparse_transpose_times(D_, v, c); }

  // (M D)^T v = D^T M v (M symmetric): free once formed, else one application.
  VecX MD_transpose_times(const VecX& v) {
    if (v.isZero(0.0)) return VecX::Zero(nc());
    if (cost_ == MobilityCost::blocks) return sparse_transpose_times(MD_, v);
    if (cost_ == MobilityCost::matrix_free) return D_transpose_times(mobility_.apply(v));
    VecX out(nc());
    for (Eigen::Index k = 0; k < nc(); ++k) out(k) = formed_column(k).dot(v);
    return out;
  }

  // A x = dt D^T M D x, the LCP matrix about Q* (eq. 26 with d^P): one application, or free when formed.
  VecX A_times(const VecX& x) { return D_transpose_times(MD_times(x), problem_.dt); }

  // Q(lambda) and the flagged-pair distances there; the last evaluation is cached. The next
  // evaluation of another lambda reuses its storage (a reference returned before is then
  // the new evaluation): an evaluation of N bodies and Nc pairs touches no fresh memory, which
  // at 1e6 spheres (56 MB of poses, 100 MB of pairs) was most of the step's time in page faults.
  const ContactEvaluation& evaluate(const VecX& lambda) {
    if (last_valid_ && last_.lambda.size() == lambda.size() && last_.lambda == lambda) return last_;
    last_valid_ = false;
    MD_times(lambda, last_.MD_lambda);
    measure_into(last_);
    last_.lambda = lambda;
    last_valid_ = true;
    return last_;
  }

  // Q with velocities U + MD_lambda (M D lambda already known, e.g. scaled along a ray) and
  // the flagged pairs measured there, as evaluate() does (carried contacts by their gap);
  // no mobility application, nothing cached. `lambda` is left empty.
  ContactEvaluation measure(VecX MD_lambda) const {
    ContactEvaluation e;
    e.MD_lambda = std::move(MD_lambda);
    measure_into(e);
    return e;
  }

  // measure() into e, whose MD_lambda is set and whose other buffers are reused.
  // A body on which M D lambda is exactly zero (every body outside the pushed pairs of a local
  // model such as free draining) moves as in the trial step: it keeps its pose at Q*, and a
  // pair of two such bodies its measurement at Q* (pairs_), the same numbers as computing
  // them again. So an evaluation costs O(N) copies plus the pairs near pushed bodies.
  void measure_into(ContactEvaluation& e) const {
    const VecX& V = velocities(e.MD_lambda);
    const std::vector<char>& moved = mark_moved(e.MD_lambda);
    e.poses.assign(trial_.begin(), trial_.end());
    parallel_for(static_cast<std::ptrdiff_t>(trial_.size()), [&](std::ptrdiff_t body) {
      const auto b = static_cast<std::size_t>(body);
      if (moved[b]) e.poses[b] = advanced(b, V);
    });
    e.pairs.resize(pairs_.size());
    e.distances.resize(nc());
    parallel_for(nc(), [&](std::ptrdiff_t index) {
      const auto k = static_cast<std::size_t>(index);
      e.pairs[k] = kept_at_trial(k, moved) ? pairs_[k] : pair_at(k, V, std::span<const Pose>(e.poses));
      e.distances(index) = e.pairs[k].points.distance;
    });
  }

  // measure(MD_lambda).min_distance(), the same number, without forming Q: the bodies that
  // move are advanced in a configuration kept equal to Q* between calls (and put back), and
  // only their pairs are measured again. O(N) reads and O(pairs of moved bodies) distances,
  // no O(N) or O(Nc) copies or allocations: the cost of a sample of a ray search
  // (defect_correction.hpp).
  double min_distance_at(const VecX& MD_lambda) const {
    if (nc() == 0) return std::numeric_limits<double>::infinity();
    return min_distance_with(velocities(MD_lambda), mark_moved(MD_lambda));
  }

  // min_distance_at(MD_lambda) >= target, the same answer, usually without measuring every
  // pair: the pairs that were below the target when a call last measured them all (the
  // witnesses, up to kWitnesses of them, the lowest first) are measured first, alone, and the
  // first still below ends the call. The samples of a ray search that do not separate (all
  // but the last: on 1e5 spheres, 15 per converged round, each a pass over 3e4 pairs and the
  // moved bodies) then cost a few pairs each.
  bool separated_at(const VecX& MD_lambda, double target) const {
    if (nc() == 0) return true;
    for (std::size_t w = 0; w < witnesses_.size(); ++w)
      if (distance_alone(witnesses_[w], MD_lambda) < target) {
        std::swap(witnesses_[0], witnesses_[w]);  // tried first next time
        return false;
      }
    const double minimum = min_distance_with(velocities(MD_lambda), mark_moved(MD_lambda));
    witnesses_.clear();
    if (minimum >= target) return true;
    Eigen::Index lowest = 0;
    scratch_distances_.minCoeff(&lowest);
    witnesses_.push_back(static_cast<std::size_t>(lowest));
    for (Eigen::Index k = 0; k < nc() && witnesses_.size() < kWitnesses; ++k)
      if (scratch_distances_(k) < target && k != lowest) witnesses_.push_back(static_cast<std::size_t>(k));
    return false;
  }

 private:
  static constexpr std::size_t kWitnesses = 8;

  // Puts `bodies` of scratch_poses_ back at Q* when it goes out of scope, also when a
  // measurement throws.
  struct PutBack {
    std::vector<Pose>& poses;
    const std::vector<Pose>& trial;
    std::span<const std::size_t> bodies;
    ~PutBack() {
      for (std::size_t b : bodies) poses[b] = trial[b];
    }
  };

  // min_distance_at's measurement, given the velocities and the moved bodies; the pairs'
  // distances are left in scratch_distances_.
  double min_distance_with(const VecX& V, const std::vector<char>& moved) const {
    moved_bodies_.clear();
    for (std::size_t b = 0; b < moved.size(); ++b)
      if (moved[b]) moved_bodies_.push_back(b);
    const PutBack put_back{scratch_poses_, trial_, moved_bodies_};
    parallel_for(static_cast<std::ptrdiff_t>(moved_bodies_.size()), [&](std::ptrdiff_t m) {
      const std::size_t b = moved_bodies_[static_cast<std::size_t>(m)];
      scratch_poses_[b] = advanced(b, V);
    });
    scratch_distances_.resize(nc());
    parallel_for(nc(), [&](std::ptrdiff_t index) {
      const auto k = static_cast<std::size_t>(index);
      scratch_distances_(index) =
          kept_at_trial(k, moved) ? pairs_[k].points.distance
                                  : pair_at(k, V, std::span<const Pose>(scratch_poses_)).points.distance;
    });
    return scratch_distances_.minCoeff();
  }

  // Pair k's distance in min_distance_with, from its own two bodies alone: their rows of the
  // velocities (in scratch_velocities_, whose other rows are left as they are) and their
  // poses (in scratch_poses_, put back after). A pair's measurement reads no other body, so
  // this is an O(1) sample.
  double distance_alone(std::size_t k, const VecX& MD_lambda) const {
    const auto i = static_cast<std::size_t>(pairs_[k].i), j = static_cast<std::size_t>(pairs_[k].j);
    const auto moves = [&](std::size_t b) {
      return !MD_lambda.segment(static_cast<Eigen::Index>(b) * dofs_, dofs_).isZero(0.0);
    };
    const bool moved_i = moves(i), moved_j = moves(j);
    if (!carried_[k] && !moved_i && !moved_j) return pairs_[k].points.distance;  // kept_at_trial
    const std::array<std::size_t, 2> bodies{i, j};
    scratch_velocities_.resize(problem_.U.size());
    for (const std::size_t b : bodies) {
      const Eigen::Index row = static_cast<Eigen::Index>(b) * dofs_;
      scratch_velocities_.segment(row, dofs_) = problem_.U.segment(row, dofs_) + MD_lambda.segment(row, dofs_);
    }
    const PutBack put_back{scratch_poses_, trial_, bodies};
    if (moved_i) scratch_poses_[i] = advanced(i, scratch_velocities_);
    if (moved_j) scratch_poses_[j] = advanced(j, scratch_velocities_);
    return pair_at(k, scratch_velocities_, std::span<const Pose>(scratch_poses_)).points.distance;
  }

 public:
  // The contact matrix of the flagged pairs at an evaluated configuration: D_k, with
  // D_k^T U = the rate of change of their distances there.
  Eigen::SparseMatrix<double> contact_matrix_at(const ContactEvaluation& e) const {
    std::vector<Eigen::Index> all(pairs_.size());
    for (std::size_t k = 0; k < all.size(); ++k) all[k] = static_cast<Eigen::Index>(k);
    return contact_matrix_at(e, all);
  }
  // Its columns of the flagged pairs `which` only (indices into pairs(), in that order).
  Eigen::SparseMatrix<double> contact_matrix_at(const ContactEvaluation& e, std::span<const Eigen::Index> which) const {
    const VecX V = problem_.U + e.MD_lambda;
    std::vector<ContactColumn> columns(which.size());
    parallel_for(static_cast<std::ptrdiff_t>(which.size()), [&](std::ptrdiff_t c) {
      const auto k = static_cast<std::size_t>(which[static_cast<std::size_t>(c)]);
      columns[static_cast<std::size_t>(c)] =
          carried_[k] && carried_[k]->interior
              ? interior_column(*carried_[k], e.pairs[k], V)
              : detail::particle_contact_column(e.pairs[k], std::span<const Pose>(e.poses), "pairs[" + std::to_string(k) + "]");
    });
    return assemble_contact_matrix(columns, e.poses.size(), dofs_);
  }

  // The barrier of eq. 15: b of eq. 10 with eps_reg = d_try (Remark 4; the value is Sec. 2.3's).
  BarrierParameters barrier_parameters_eq15() const { return barrier_parameters(problem_.d_hat, d_try_); }

  // A d^P of some pair at an evaluated configuration, so at least the smallest over all pairs
  // (minimum_pair_distance's at_most): the least distance of a flagged pair that is not
  // carried (closest points, or an overlap end's gap, itself >= d^P); +inf when all are carried.
  double min_distance_bound(const ContactEvaluation& e) const {
    double bound = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < pairs_.size(); ++k)
      if (!carried_[k]) bound = std::min(bound, e.distances(static_cast<Eigen::Index>(k)));
    return bound;
  }

  // Per body, whether M D lambda moves it (nonzero in its rows); valid until the next call
  // that measures.
  const std::vector<char>& moved_by(const VecX& MD_lambda) const { return mark_moved(MD_lambda); }

  // The end check of run_contact_step at an iterate (e, an evaluation of this step), early:
  // adds the pairs not flagged that are below d_hat (1 - separation_margin) at Q(lambda) and
  // returns how many. Only where unflagged pairs stay clear along the trial motion
  // (DTryRule::relative): then such a pair has a body that M D lambda moves, and only those
  // bodies' neighbourhoods are searched (O(moved bodies) after the cell list's O(N) sort).
  // Elsewhere 0: the end check finds them.
  std::size_t add_pairs_closing_at(const ContactEvaluation& e) {
    if (!unflagged_stay_clear_) return 0;
    std::vector<ContactPair> closing =
        find_contact_pairs(problem_.shapes, std::span<const Pose>(e.poses), problem_.d_hat * (1.0 - options_.separation_margin),
                           problem_.box, &cells_, mark_moved(e.MD_lambda));
    std::erase_if(closing, [&](const ContactPair& p) { return separated(p.points.distance); });
    return add_pairs(closing);
  }

  // Whether every pair the step has not flagged stays above d_hat along the trial motion
  // (DTryRule::relative, find_pairs_relative): then only the flagged pairs and the pairs of
  // bodies a correction moves can cross along a corrected motion (CrossingScope).
  bool unflagged_pairs_stay_clear() const { return unflagged_stay_clear_; }
  // Whether flagged pair k is a contact carried from inside the step (measured by its gap
  // there), not measured at Q* like the others (pairs()[k].points: its distance at Q*).
  bool carried(std::size_t k) const { return carried_[k].has_value(); }

  // The bodies of the flagged pairs (i < j), each pair once, sorted.
  std::vector<BodyPair> flagged_body_pairs() const {
    std::vector<BodyPair> out;
    out.reserve(pairs_.size());
    for (const ContactPair& p : pairs_) out.push_back(p.i < p.j ? BodyPair{p.i, p.j} : BodyPair{p.j, p.i});
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  bool separated(double d) const { return d >= problem_.d_hat * (1.0 - options_.separation_margin); }
  bool all_separated(const ContactEvaluation& e) const { return nc() == 0 || separated(e.min_distance()); }

  Eigen::Index nc() const { return static_cast<Eigen::Index>(pairs_.size()); }
  std::size_t carried_count() const {
    return static_cast<std::size_t>(std::count_if(carried_.begin(), carried_.end(), [](const auto& c) { return c.has_value(); }));
  }
  int dofs_per_body() const { return dofs_; }
  const Eigen::SparseMatrix<double>& D() const { return D_; }
  // M D, exact and sparse, in blocks mode; nullptr in the other modes.
  const Eigen::SparseMatrix<double>* sparse_MD() const { return cost_ == MobilityCost::blocks ? &MD_ : nullptr; }
  MobilityCost cost() const { return cost_; }  // the mode in use (automatic resolved)
  const std::vector<ContactColumn>& columns() const { return columns_; }  // D's, one per pair
  const std::vector<ContactPair>& pairs() const { return pairs_; }
  // The broad phase's buffers, shared by every query of the step (detection, the end check,
  // the whole-step check): at 1e6 bodies each query's own would be ~100 MB of fresh pages.
  CellList& cells() const { return cells_; }
  // The flagged pairs, D's columns and Q of the last evaluation, moved out of a step that is
  // finished (nothing else may be called on it after): a result keeps them without a copy,
  // which at 1e6 spheres was 250 MB of fresh memory per step.
  std::vector<ContactPair> release_pairs() && { return std::move(pairs_); }
  std::vector<ContactColumn> release_columns() && { return std::move(columns_); }
  std::vector<Pose> release_last_poses() && { return std::move(last_.poses); }
  const ContactStepProblem<S>& problem() const { return problem_; }
  const ContactStepOptions& options() const { return options_; }
  double d_try() const { return d_try_; }
  std::size_t applications() const { return mobility_.applications() - start_applications_; }

 private:
  // Q_t must be contact free: `pairs` hold every pair of Q_t that could overlap, `d` their
  // distances there.
  static void require_contact_free(const std::vector<ContactPair>& pairs, const std::vector<double>& d) {
    const auto deepest = std::min_element(d.begin(), d.end());
    if (deepest == d.end() || !(*deepest < 0.0)) return;
    const ContactPair& p = pairs[static_cast<std::size_t>(deepest - d.begin())];
    fail_argument("poses", "Q_t must be contact free; bodies " + std::to_string(p.i) + " and " + std::to_string(p.j) +
                               " overlap, d = " + std::to_string(*deepest));
  }

  // Pairs are only ever appended (after the constructor's first call): the columns of D, the
  // columns of M D already formed and the measurements at Q* of the pairs before stay valid,
  // so only the new pairs' are computed (in parallel) and appended to D and, in blocks mode,
  // to M D (the earlier ones copied: O(Nc) memory traffic, O(new pairs) arithmetic).
  // A carried contact's column: its gap's gradient, in both modes (particle_contact_column
  // on its carried pair, whose two forces act at one point, the middle of the carried
  // points, so that the column keeps Newton's third law for torques too).
  void rebuild() {
    last_valid_ = false;  // its buffers are kept for the next evaluation
    const std::span<const Pose> trial(trial_);
    std::optional<BarrierParameters> weight_barrier;
    if (!nodes_.empty()) weight_barrier = detail::surface_weight_barrier(d_try_, options_.surface_weights);
    const std::size_t built = columns_.size();
    columns_.resize(pairs_.size());
    parallel_for(static_cast<std::ptrdiff_t>(pairs_.size() - built), [&](std::ptrdiff_t index) {
      const std::size_t k = built + static_cast<std::size_t>(index);
      const ContactPair& p = pairs_[k];
      const std::string field = "pairs[" + std::to_string(k) + "]";
      if (carried_[k] && carried_[k]->interior) {
        columns_[k] = interior_column(*carried_[k], p, problem_.U);
      } else if (!weight_barrier || carried_[k]) {
        columns_[k] = detail::particle_contact_column(p, trial, field);
      } else {
        const auto i = static_cast<std::size_t>(p.i), j = static_cast<std::size_t>(p.j);
        const SurfaceContact contact{p.i, p.j, p.image_shift,
                                     surface_distances(shape_of(problem_.shapes, i), trial_[i], nodes_of(i),
                                                       shape_of(problem_.shapes, j),
                                                       shifted(trial_[j], p.image_shift), nodes_of(j), d_try_)};
        columns_[k] = detail::surface_contact_column(contact, trial, *weight_barrier, options_.surface_weights, field);
      }
    });
    append_contact_columns(D_, columns_, trial_.size(), dofs_);
    // blocks mode, once M is set (the constructor's end)
    if (M_blocks_.rows() > 0) append_block_diagonal_product(MD_, M_blocks_, D_, trial_.size());
  }

  // With overlap_ends directions, the pairs from `first` on that are not carried become
  // their overlap-end contacts (carried ones keep their one carried contact); `split_pair`,
  // when given, says per pair from `first` whether it may be split.
  void split_overlap_ends_from(std::size_t first, std::span<const char> split_pair = {}) {
    if (options_.directions != ContactDirections::overlap_ends) return;
    std::vector<ContactPair> split(pairs_.begin() + static_cast<std::ptrdiff_t>(first), pairs_.end());
    std::vector<std::optional<CarriedContact>> carried(carried_.begin() + static_cast<std::ptrdiff_t>(first),
                                                       carried_.end());
    pairs_.resize(first);
    carried_.resize(first);
    for (std::size_t k = 0; k < split.size(); ++k) {
      if (carried[k] || (!split_pair.empty() && !split_pair[k])) {
        pairs_.push_back(split[k]);
        carried_.push_back(carried[k]);
        continue;
      }
      for (ContactPair& p : split_overlap_ends(std::vector<ContactPair>{split[k]}, problem_.shapes,
                                               std::span<const Pose>(trial_), options_.overlap_ends_angle,
                                               options_.overlap_ends_min_overlap)) {
        pairs_.push_back(std::move(p));
        carried_.emplace_back();
      }
    }
  }

  // Flagged pair k passes through or sweeps past in the trial step when its distance along
  // the trial motion has a minimum inside the step below min(d*, d_hat) (by a tenth of d_hat,
  // so rounding and the search tolerance decide nothing): it is then carried.
  void carry_if_passing(std::size_t k) {
    const ContactPair& p = pairs_[k];
    const auto i = static_cast<std::size_t>(p.i), j = static_cast<std::size_t>(p.j);
    const double margin = 0.1 * problem_.d_hat;
    const RigidVelocity vi = rigid_velocity(problem_.U, i, dofs_), vj = rigid_velocity(problem_.U, j, dofs_);
    const SweptDistance lowest =
        swept_minimum(shape_of(problem_.shapes, i), problem_.poses[i], vi, shape_of(problem_.shapes, j),
                      shifted(problem_.poses[j], p.image_shift), vj, problem_.dt, 0.5 * margin);
    if (!(lowest.points.distance < std::min(p.points.distance, problem_.d_hat) - margin)) return;
    carried_[k] = carried_contact(p.i, p.j, p.image_shift, problem_.U, false);
    pairs_[k] = carried_pair(*carried_[k], p.i, p.j, p.image_shift, std::span<const Pose>(trial_));
  }

  // The carried contact of a pair on the motion with velocities V: its closest points where
  // it first comes within d_hat (at t = 0 if it starts there) or, for an interior contact,
  // where it comes closest, carried with the bodies, with the normal of that moment.
  CarriedContact carried_contact(Eigen::Index i, Eigen::Index j, const Vec3& image_shift, const VecX& V,
                                 bool interior) const {
    const auto si = static_cast<std::size_t>(i), sj = static_cast<std::size_t>(j);
    const S& shape_i = shape_of(problem_.shapes, si);
    const S& shape_j = shape_of(problem_.shapes, sj);
    const RigidVelocity vi = rigid_velocity(V, si, dofs_), vj = rigid_velocity(V, sj, dofs_);
    const Pose start_j = shifted(problem_.poses[sj], image_shift);
    const double tolerance = 1e-3 * problem_.d_hat;
    const SweptDistance found =
        interior ? swept_minimum(shape_i, problem_.poses[si], vi, shape_j, start_j, vj, problem_.dt, tolerance)
                 : first_time_below(shape_i, problem_.poses[si], vi, shape_j, start_j, vj, problem_.dt,
                                    problem_.d_hat, tolerance);
    const Pose at_i = advance(problem_.poses[si], vi.u, vi.omega, found.time);
    const Pose at_j = advance(start_j, vj.u, vj.omega, found.time);
    return {at_i.to_body(found.points.curve_point_a), at_j.to_body(found.points.curve_point_b), found.points.normal,
            shape_i.radius, shape_j.radius, found.time, interior};
  }

  // The carried contact of pair i, j on the motion with velocities V measured at the end
  // (`at_end`: the configuration there) or, for an interior contact, at its own time, its
  // distance then raised by interior_offset() (the interior bound is half of d_hat).
  ContactPair carried_at(const CarriedContact& c, const ContactPair& p, const VecX& V,
                         std::span<const Pose> at_end) const {
    if (!c.interior) return carried_pair(c, p.i, p.j, p.image_shift, at_end);
    const auto [pose_i, pose_j] = poses_at(p, V, c.time);
    ContactPair out = carried_pair(c, p.i, p.j, p.image_shift, pose_i, pose_j);
    out.points.distance += interior_offset();
    return out;
  }

  // Bodies i and j (j as its image) of pair p at time t on the motion with velocities V.
  std::pair<Pose, Pose> poses_at(const ContactPair& p, const VecX& V, double t) const {
    const auto i = static_cast<std::size_t>(p.i), j = static_cast<std::size_t>(p.j);
    const RigidVelocity vi = rigid_velocity(V, i, dofs_), vj = rigid_velocity(V, j, dofs_);
    return {advance(problem_.poses[i], vi.u, vi.omega, t),
            advance(shifted(problem_.poses[j], p.image_shift), vj.u, vj.omega, t)};
  }

  // An interior contact's column at the motion with velocities V: the gradient of its gap at
  // t_c, where only t_c of the correction has acted, so dt D_k^T M D lambda is its change
  // (the gradient at the time, scaled by t_c / dt).
  ContactColumn interior_column(const CarriedContact& c, const ContactPair& p, const VecX& V) const {
    const auto [pose_i, pose_j] = poses_at(p, V, c.time);
    const ContactPair at = carried_pair(c, p.i, p.j, p.image_shift, pose_i, pose_j);
    ContactColumn column{p.i, p.j};
    detail::add_distance_gradient(column, at.points.normal, at.points.point_a - pose_i.x,
                                  at.points.point_b - pose_j.x, c.time / problem_.dt);
    return column;
  }

  // U + MD_lambda in a buffer kept between calls (valid until the next call).
  const VecX& velocities(const VecX& MD_lambda) const {
    scratch_velocities_.resize(problem_.U.size());
    scratch_velocities_.noalias() = problem_.U + MD_lambda;
    return scratch_velocities_;
  }

  // Per body, whether M D lambda moves it (nonzero in its rows); a buffer kept between calls.
  const std::vector<char>& mark_moved(const VecX& MD_lambda) const {
    moved_.resize(trial_.size());
    const double* rows = MD_lambda.data();
    const auto dofs = static_cast<std::ptrdiff_t>(dofs_);
    parallel_for(static_cast<std::ptrdiff_t>(trial_.size()), [&](std::ptrdiff_t body) {
      bool nonzero = false;  // a plain loop: Eigen's isZero on a segment of runtime size costs more than the pass
      for (std::ptrdiff_t k = body * dofs; k < (body + 1) * dofs; ++k) nonzero |= rows[k] != 0.0;
      moved_[static_cast<std::size_t>(body)] = nonzero;
    });
    return moved_;
  }

  // Body b at the end of the step with velocities V (eq. 13).
  Pose advanced(std::size_t b, const VecX& V) const {
    const Eigen::Index row = static_cast<Eigen::Index>(b) * dofs_;
    const Vec3 omega = dofs_ == 6 ? Vec3(V.segment<3>(row + 3)) : Vec3::Zero();
    return advance(problem_.poses[b], V.segment<3>(row), omega, problem_.dt);
  }

  // Whether pair k keeps its measurement at Q* (pairs_[k], measured there) when the bodies
  // marked in `moved` have left their trial poses: neither of its bodies moved, and it is not
  // carried.
  bool kept_at_trial(std::size_t k, const std::vector<char>& moved) const {
    const ContactPair& p = pairs_[k];
    return !carried_[k] && !moved[static_cast<std::size_t>(p.i)] &&
           !moved[static_cast<std::size_t>(p.j)];
  }

  // Pair k measured again at `poses`, reached with velocities V (a carried contact by its gap).
  ContactPair pair_at(std::size_t k, const VecX& V, std::span<const Pose> poses) const {
    if (carried_[k]) return carried_at(*carried_[k], pairs_[k], V, poses);
    return remeasured(pairs_[k], problem_.shapes, poses, problem_.box);
  }

  // Inside the step a pair need only stay apart: an interior contact holds its gap at d_hat
  // less this, half of d_hat (clear of the whole-step check's overlap threshold).
  double interior_offset() const { return 0.5 * problem_.d_hat; }

  const SurfaceNodes& nodes_of(std::size_t body) const { return nodes_.size() == 1 ? nodes_[0] : nodes_[body]; }

  // Column k of M D, formed on first need (one application).
  const VecX& formed_column(Eigen::Index k) {
    if (MD_columns_.size() < pairs_.size()) MD_columns_.resize(pairs_.size());
    VecX& column = MD_columns_[static_cast<std::size_t>(k)];
    if (column.size() == 0) column = mobility_.apply(VecX(D_.col(k)));
    return column;
  }

  ContactStepProblem<S> problem_;
  M& mobility_;
  ContactStepOptions options_;
  int dofs_ = 6;
  double d_try_ = 0.0;
  std::size_t start_applications_ = 0;
  std::vector<Pose> trial_;  // Q*
  // Q* again, in which min_distance_at moves bodies for one call and then puts them back.
  mutable std::vector<Pose> scratch_poses_;
  // Buffers of measure_into and min_distance_at, kept so that repeated evaluations of one step
  // touch no fresh memory.
  mutable VecX scratch_velocities_, scratch_distances_;
  mutable std::vector<char> moved_;
  mutable std::vector<std::size_t> moved_bodies_;
  mutable std::vector<std::size_t> witnesses_;  // separated_at's pairs to measure first
  std::vector<ContactPair> pairs_;                    // carried ones: their carried pair at Q*
  std::vector<std::optional<CarriedContact>> carried_;  // per pair: carried or not
  std::vector<SurfaceNodes> nodes_;  // per shape, for d^S directions (empty: d^P)
  Eigen::SparseMatrix<double> D_;
  std::vector<ContactColumn> columns_;  // D_'s columns
  std::vector<VecX> MD_columns_;  // the columns of M D formed so far (empty: not yet)
  MobilityCost cost_ = MobilityCost::formed;
  bool unflagged_stay_clear_ = false;  // flagged by DTryRule::relative
  Eigen::SparseMatrix<double> M_blocks_, MD_;  // blocks mode: M at Q_t and M D
  mutable CellList cells_;
  ContactEvaluation last_;  // the last evaluation, when last_valid_
  bool last_valid_ = false;
};

namespace detail {

inline double complementarity_residual(const VecX& lambda, const VecX& distances, double d_hat) {
  if (lambda.size() == 0) return 0.0;
  const double lambda_max = lambda.maxCoeff();
  if (!(lambda_max > 0.0)) return 0.0;
  double r = 0.0;
  for (Eigen::Index k = 0; k < lambda.size(); ++k)
    r = std::max(r, std::min(lambda(k) / lambda_max, std::max(0.0, distances(k) - d_hat) / d_hat));
  return r;
}

// The largest turn dt |omega| the correction velocities MD_lambda (per body: 3 translational,
// then 3 rotational dofs) give a body, and that body; (0, -1) without rotational dofs.
inline std::pair<double, Eigen::Index> max_correction_turn(const VecX& MD_lambda, Eigen::Index dofs_per_body,
                                                           double dt) {
  std::pair<double, Eigen::Index> out{0.0, -1};
  if (dofs_per_body != 6) return out;
  for (Eigen::Index b = 0; b < MD_lambda.size() / 6; ++b) {
    const double turn = dt * MD_lambda.segment<3>(6 * b + 3).norm();
    if (turn > out.first) out = {turn, b};
  }
  return out;
}

// Why a step is refused before its solve (ContactStepOptions::max_flagged_pairs_per_body),
// or "" when it is not: its flagged body pairs (a pair held at several points, or through
// several images, counts once) against the bodies.
template <class Step>
std::string refusal_of_crowded_step(const Step& step, const ContactStepOptions& options, std::size_t bodies) {
  const double limit = options.max_flagged_pairs_per_body * static_cast<double>(bodies);
  if (options.max_flagged_pairs_per_body == 0.0 || static_cast<double>(step.nc()) <= limit) return "";
  const std::size_t pairs = step.flagged_body_pairs().size();
  if (static_cast<double>(pairs) <= limit) return "";
  std::ostringstream os;
  os << "failed separation: the step was refused before its solve: " << pairs << " flagged body pairs for " << bodies
     << " bodies (" << static_cast<double>(pairs) / static_cast<double>(bodies)
     << " per body) exceed ContactStepOptions.max_flagged_pairs_per_body = " << options.max_flagged_pairs_per_body
     << "; the trial motions carry the bodies through many neighbours each, beyond what one linearised step "
        "holds: take a smaller step (TimeStepper halves it)";
  return os.str();
}

inline VecX padded(const VecX& lambda, Eigen::Index size) {
  VecX out = VecX::Zero(size);
  out.head(std::min(size, lambda.size())) = lambda.head(std::min(size, lambda.size()));
  return out;
}

}  // namespace detail

// Runs a solver core `solve(step, warm_start) -> ContactSolveOutcome` inside the guarantee loop
// and fills the result. Bad input throws std::invalid_argument before anything changes.
template <Shape S, MobilityOperator M, typename Solve>
ContactStepResult run_contact_step(const ContactStepProblem<S>& problem, M& mobility,
                                   const ContactStepOptions& options, Solve&& solve) {
  auto lap_start = std::chrono::steady_clock::now();
  const auto lap = [&lap_start](double& phase) {  // the time since the last lap, into `phase`
    const auto now = std::chrono::steady_clock::now();
    phase += std::chrono::duration<double>(now - lap_start).count();
    lap_start = now;
  };
  ContactStepResult r;
  ContactStepPhaseTimes& t = r.phase_times;
  ContactStep<S, M> step(problem, mobility, options);
  lap(t.setup_s);
  ContactSolveOutcome outcome;
  std::vector<ContactPair> violating;
  // The smallest d^P of the last Q(lambda) checked, when its end query held it (NaN: not known).
  double end_minimum = std::numeric_limits<double>::quiet_NaN();
  std::vector<TrajectoryCrossing> crossing;
  std::string beyond_box;  // why the corrected motion could not be checked in the box, if so
  bool solver_gave_up = false;  // a round not converged with its own flagged pairs overlapping
  // Overlaps deeper than separation_margin d_hat count, found within a tenth of that.
  const double overlap_tolerance = std::max(0.1 * options.separation_margin, 1e-6) * problem.d_hat;
  const std::string refused = detail::refusal_of_crowded_step(step, options, problem.poses.size());
  if (!refused.empty()) outcome.lambda = VecX::Zero(step.nc());  // the trial step, reported as it is
  for (int round = 0; refused.empty(); ++round) {
    const int iterations = r.iterations;
    outcome = solve(step, detail::padded(outcome.lambda, step.nc()));
    lap(t.solve_s);
    r.iterations = iterations + outcome.iterations;
    r.guarantee_rounds = round;
    const ContactEvaluation& e = step.evaluate(outcome.lambda);
    // The end: all pairs, not only the flagged ones. The query reaches the least flagged
    // distance too, so that its pairs hold the smallest d^P of Q(lambda) (the result's
    // min_distance_ratio): one broad phase for both.
    // (At most d_try: a reach the trial step's detection already used, so a periodic box holds it.)
    const double bound = step.min_distance_bound(e);
    const double below = problem.d_hat * (1.0 - options.separation_margin);
    const double reach = std::max(below, std::min(bound, step.d_try()));
    violating = find_contact_pairs(problem.shapes, std::span<const Pose>(e.poses), reach, problem.box, &step.cells());
    end_minimum = std::numeric_limits<double>::quiet_NaN();
    if (bound <= reach) {  // (bound is a pair's distance too, should rounding drop it at the cutoff)
      end_minimum = bound;
      for (const ContactPair& p : violating) end_minimum = std::min(end_minimum, p.points.distance);
    }
    std::erase_if(violating, [&](const ContactPair& p) { return step.separated(p.points.distance); });
    lap(t.end_check_s);
    // The interior: no overlap along the corrected motion.
    const VecX V = problem.U + e.MD_lambda;
    if (options.whole_step) {
      try {
        // Only pairs that can cross: those the correction moves and the flagged ones (O(moved
        // bodies + Nc) after the cell list's O(N) sort, not O(N) pair tests).
        std::vector<BodyPair> flagged;
        std::optional<CrossingScope> scope;
        if (step.unflagged_pairs_stay_clear()) {
          flagged = step.flagged_body_pairs();
          scope = CrossingScope{step.moved_by(e.MD_lambda), flagged};
        }
        crossing = trajectory_crossings(problem.shapes, problem.poses, V, step.dofs_per_body(), problem.dt,
                                        -options.separation_margin * problem.d_hat, overlap_tolerance, problem.box,
                                        &step.cells(), scope ? &*scope : nullptr);
      } catch (const MotionBeyondBox& e) {  // forces that fling a body: not a motion to check or keep
        beyond_box = e.what();
        lap(t.interior_check_s);
        break;
      }
      lap(t.interior_check_s);
    }
    if ((violating.empty() && crossing.empty()) || round == options.max_guarantee_rounds) break;
    // A round whose solver did not converge and left one of its own flagged pairs overlapping
    // (d < 0: not short of d_hat, through it) did not approach a solution of a problem with
    // fewer constraints than the next round's, which any solution of the larger problem
    // solves too. So the step ends here, failed (the overlapping pairs are in `violating`),
    // for the caller's fallbacks or the time stepper's halving, instead of guarantee rounds
    // that grow the working set around a diverging lambda (on 400 rods at eta 0.45 those
    // cost 1-27 s each against 0.2-0.3 s for the first; docs/results.md, "A diverging round
    // ends the step"). A round left short but not overlapping goes on: the next round
    // continues it (the LCP sequences stop a round after 20 LCPs).
    solver_gave_up = !outcome.converged && e.min_distance() < 0.0;
    if (solver_gave_up) break;
    // A pair too close at the end is held there by its end constraint; carried contacts are
    // for pairs that overlap inside the step only, or whose end constraint let them.
    std::vector<TrajectoryCrossing> inside = crossing;
    std::erase_if(inside, [&](const TrajectoryCrossing& c) {
      return std::any_of(violating.begin(), violating.end(),
                         [&](const ContactPair& p) { return p.i == c.i && p.j == c.j; });
    });
    const std::size_t added = step.add_pairs(violating) + step.add_crossings(inside, V);
    lap(t.add_pairs_s);
    if (added == 0) break;
  }
  const ContactEvaluation& e = step.evaluate(outcome.lambda);
  r.lambda = outcome.lambda;
  r.flagged_pairs = static_cast<std::size_t>(step.nc());
  r.carried_pairs = step.carried_count();
  r.contact_forces = step.D() * r.lambda;
  r.velocities = problem.U + e.MD_lambda;
  r.d_try = step.d_try();
  if (std::isnan(end_minimum))  // the end query did not reach it (no flagged pair below d_try)
    end_minimum = minimum_pair_distance(problem.shapes, std::span<const Pose>(e.poses), problem.box, &step.cells(),
                                        step.min_distance_bound(e))
                      .distance;
  r.min_distance_ratio = end_minimum / problem.d_hat;
  const std::vector<double> d(e.distances.begin(), e.distances.end());
  r.barrier_energy = barrier_energy(d, step.barrier_parameters_eq15());
  r.complementarity_residual = detail::complementarity_residual(r.lambda, e.distances, problem.d_hat);
  r.lambda_sum = r.lambda.sum();
  r.lambda_max = r.lambda.size() == 0 ? 0.0 : r.lambda.maxCoeff();
  r.mobility_applications = step.applications();
  r.cost = step.cost();
  std::tie(r.max_correction_turn, r.max_correction_turn_body) =
      detail::max_correction_turn(e.MD_lambda, step.dofs_per_body(), problem.dt);
  const bool over_turned = r.max_correction_turn > options.max_correction_turn;
  if (!refused.empty()) {
    r.status = ContactStepStatus::failed_separation;
    r.message = refused;
    r.refused = true;
  } else if (!violating.empty() || !crossing.empty() || !beyond_box.empty() || over_turned) {
    std::ostringstream os;
    os << "failed separation after " << r.guarantee_rounds << " guarantee round(s):";
    if (solver_gave_up) os << " the solver left flagged pairs overlapping (no further round);";
    if (!beyond_box.empty()) os << " the corrected motion: " << beyond_box << ";";
    if (over_turned)
      os << " the correction turns body " << r.max_correction_turn_body << " by " << r.max_correction_turn
         << " rad in the step, above ContactStepOptions.max_correction_turn = " << options.max_correction_turn
         << " (a far root of the linearised step, lambda_max = " << r.lambda_max << ");";
    if (!violating.empty())
      os << " " << violating.size() << " pair(s) below d_hat (1 - " << options.separation_margin
         << ") at the end, min d / d_hat = " << r.min_distance_ratio << " (bodies " << violating.front().i << ", "
         << violating.front().j << ");";
    if (!crossing.empty())
      os << " " << crossing.size() << " pair(s) overlap inside the step, first bodies " << crossing.front().i
         << ", " << crossing.front().j << " at t'/dt = " << crossing.front().first.time / problem.dt
         << " with d / d_hat = " << crossing.front().first.points.distance / problem.d_hat << ";";
    if (!outcome.message.empty()) os << " solver: " << outcome.message;
    r.status = ContactStepStatus::failed_separation;
    r.message = os.str();
  } else {
    r.status = outcome.converged ? ContactStepStatus::converged : ContactStepStatus::not_converged;
    r.message = outcome.message;
  }
  r.broad_phase_queries = static_cast<int>(step.cells().queries());
  r.broad_phase_reused = static_cast<int>(step.cells().reused_queries());
  r.pairs = std::move(step).release_pairs();  // the step is finished: e is not used below
  r.columns = std::move(step).release_columns();
  r.poses = std::move(step).release_last_poses();
  lap(t.finish_s);
  r.wall_time_s = t.total();
  return r;
}

}  // namespace stokescontact
