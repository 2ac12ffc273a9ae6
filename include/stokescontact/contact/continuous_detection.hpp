#pragma once
// Contact detection over the whole step, not only at its end, and from relative motion only.
//
// Each body moves over the step with its constant rigid velocity (u, omega): Q(t') = Q_t +
// t' Psi U, t' in [0, dt] (Broms & Tornberg eq. 13/16). geometry/swept_distance.hpp bounds the
// rate of change of a pair's distance by L_ij = |u_i - u_j| + |omega_i| rho_i + |omega_j| rho_j.
//
// find_pairs_relative (DTryRule::relative): the trial step's flagged pairs with one threshold
// per pair, d_try_ij = m (d_hat + dt L_ij). Since d(dt) <= d(t') + (dt - t') L_ij, a pair that
// comes within d_hat at any t' of the trial step has d* <= d_try_ij: it is flagged even when
// its end state is separated (it passed through, or swept past). The broad phase works in
// the frame moving with the mean velocity, where body i's reach grows by m dt (|u_i - u_mean|
// + |omega_i| rho_i); a common velocity added to every body changes neither the flagged set
// nor the candidates (to rounding), unlike eq. 30/31.
//
// trajectory_crossings: every pair whose distance along a given motion drops to a threshold
// at some t' in [0, dt], with the first such time (conservative advancement; exact for
// spheres). Its broad phase tests, in the mean-velocity frame, the balls that hold each
// body's bounding ball over the step: centre x_i + (dt/2)(u_i - u_mean), radius r_i +
// (dt/2)|u_i - u_mean| (a bounding ball about the centre does not move under rotation).
//
// Both broad phases keep a few fast bodies from coarsening the cell list for all: a body
// whose grown ball is more than twice the largest bounding radius is tested against every
// body (detail::swept_candidates).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "stokescontact/contact/contact_pairs.hpp"
#include "stokescontact/contact/d_try.hpp"
#include "stokescontact/geometry/swept_distance.hpp"

namespace stokescontact {

// Body k's velocity from U stacked per body as (u) or (u, omega), dofs_per_body 3 or 6.
inline RigidVelocity rigid_velocity(const VecX& U, std::size_t body, int dofs_per_body) {
  const Eigen::Index row = static_cast<Eigen::Index>(body) * dofs_per_body;
  return {U.segment<3>(row), dofs_per_body == 6 ? Vec3(U.segment<3>(row + 3)) : Vec3::Zero()};
}

// The flagged pairs at Q* with their own thresholds d_try_ij.
struct RelativePairs {
  std::vector<ContactPair> pairs;  // measured at Q*, sorted by (i, j)
  std::vector<double> d_try;       // one per pair
};

// A motion over the step that reaches farther than the periodic box allows: some pair of swept
// balls spans more than half the shortest side, so the minimum image no longer names the one
// image within reach. The motion is at fault, not the input (e.g. contact forces that fling a
// body): a std::runtime_error, which the contact step reports as failed separation.
class MotionBeyondBox : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {

inline Vec3 mean_velocity(const VecX& U, std::size_t bodies, int dofs_per_body) {
  Vec3 sum = Vec3::Zero();
  for (std::size_t k = 0; k < bodies; ++k) sum += rigid_velocity(U, k, dofs_per_body).u;
  return bodies == 0 ? sum : Vec3(sum / static_cast<double>(bodies));
}

// The broad phase's input for a motion with velocities V: centres, bounding radii (to be grown
// by the caller), the largest bounding radius, each body's velocity and the mean velocity.
template <Shape S>
struct SweptBodies {
  Mat3X centres;
  VecX radii;
  double body_radius = 0.0;
  std::vector<RigidVelocity> v;
  Vec3 mean = Vec3::Zero();

  SweptBodies(std::span<const S> shapes, std::span<const Pose> poses, const VecX& V, int dofs_per_body) {
    validate_scene(shapes, poses);
    require_velocities(V, poses.size(), dofs_per_body);
    mean = mean_velocity(V, poses.size(), dofs_per_body);
    broad_phase_input(shapes, poses, centres, radii);
    body_radius = radii.size() > 0 ? radii.maxCoeff() : 0.0;
    for (std::size_t k = 0; k < poses.size(); ++k) v.push_back(rigid_velocity(V, k, dofs_per_body));
  }
};

// Candidate pairs (i < j, sorted) of balls grown by each body's motion over the step. A few
// fast bodies would set the cell size for everyone (cells are 2 max radius + cutoff wide):
// balls more than twice the largest body's own bounding radius are tested against every
// body instead, O(N) each, as long as there are at most 64 of them.
// With `marked` (one entry per body), only the pairs that have a marked body (CellList::find_pairs_of).
inline std::vector<BodyPair> swept_candidates(const Mat3X& centres, const VecX& radii, double body_radius,
                                              double cutoff, const std::optional<PeriodicBox>& box, CellList& list,
                                              std::span<const char> marked = {}) {
  const auto n = centres.cols();
  if (box && n > 0) {  // the broad phase's condition (2 max radius + cutoff <= half a side), as a motion's failure
    Eigen::Index widest = 0;
    const double r_max = radii.maxCoeff(&widest);
    if (r_max + r_max + cutoff > 0.5 * box->lengths.minCoeff())
      throw MotionBeyondBox("body " + std::to_string(widest) + " moves too far in the step for the box: its swept " +
                            "ball of radius " + std::to_string(r_max) + " reaches beyond half the shortest side " +
                            std::to_string(0.5 * box->lengths.minCoeff()));
  }
  const auto find = [&](const Mat3X& x, const VecX& r, std::span<const char> m) -> const std::vector<BodyPair>& {
    return marked.empty() ? list.find_pairs(x, r, cutoff, box) : list.find_pairs_of(x, r, cutoff, box, m);
  };
  const auto is_marked = [&](Eigen::Index k) { return marked.empty() || marked[static_cast<std::size_t>(k)]; };
  std::vector<Eigen::Index> slow, fast;
  for (Eigen::Index k = 0; k < n; ++k) (radii[k] > 2.0 * body_radius ? fast : slow).push_back(k);
  if (fast.empty() || fast.size() > 64) return find(centres, radii, marked);
  Mat3X slow_centres(3, static_cast<Eigen::Index>(slow.size()));
  VecX slow_radii(static_cast<Eigen::Index>(slow.size()));
  std::vector<char> slow_marked;
  for (std::size_t k = 0; k < slow.size(); ++k) {
    slow_centres.col(static_cast<Eigen::Index>(k)) = centres.col(slow[k]);
    slow_radii[static_cast<Eigen::Index>(k)] = radii[slow[k]];
    if (!marked.empty()) slow_marked.push_back(marked[static_cast<std::size_t>(slow[k])]);
  }
  std::vector<BodyPair> out;
  for (const BodyPair& p : find(slow_centres, slow_radii, slow_marked))
    out.push_back({slow[static_cast<std::size_t>(p.i)], slow[static_cast<std::size_t>(p.j)]});
  for (const Eigen::Index f : fast) {
    for (Eigen::Index k = 0; k < n; ++k) {
      if (k == f || (radii[k] > 2.0 * body_radius && k < f)) continue;  // fast pairs once
      if (!is_marked(f) && !is_marked(k)) continue;
      if (is_candidate_pair(centres.col(f), centres.col(k), radii[f], radii[k], cutoff, box))
        out.push_back({std::min(f, k), std::max(f, k)});
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace detail

// DTryRule::relative at the trial configuration `trial` = Q_t + dt Psi U.
template <Shape S>
RelativePairs find_pairs_relative(std::span<const S> shapes, std::span<const Pose> trial, const VecX& U,
                                  int dofs_per_body, double dt, double d_hat, double multiplier,
                                  const std::optional<PeriodicBox>& box = {}, CellList* cells = nullptr) {
  detail::SweptBodies<S> b(shapes, trial, U, dofs_per_body);
  detail::d_try_from_speed(d_hat, dt, 0.0, multiplier);  // checks d_hat, dt, multiplier
  const std::vector<RigidVelocity>& v = b.v;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const double own = (v[k].u - b.mean).norm() + v[k].omega.norm() * centre_curve_reach(shape_of(shapes, k));
    b.radii[static_cast<Eigen::Index>(k)] += multiplier * dt * own;
  }
  CellList local;
  CellList& list = cells != nullptr ? *cells : local;
  // Each candidate's threshold (NaN where its bounding balls at Q* are beyond it), then the
  // pairs within reach measured in place in the result, a chunk at a time, and those within
  // their threshold kept (at 1e5 spheres a buffer of measurements moved into the result cost
  // a third more; chunks bound the memory where bounding balls are loose, as for rods).
  const std::vector<BodyPair>& candidates =
      detail::swept_candidates(b.centres, b.radii, b.body_radius, multiplier * d_hat, box, list);
  std::vector<double> threshold(candidates.size());
  parallel_for(static_cast<std::ptrdiff_t>(candidates.size()), [&](std::ptrdiff_t k) {
    const BodyPair& c = candidates[static_cast<std::size_t>(k)];
    const auto i = static_cast<std::size_t>(c.i), j = static_cast<std::size_t>(c.j);
    const S& si = shape_of(shapes, i);
    const S& sj = shape_of(shapes, j);
    const double d_try = multiplier * (d_hat + dt * distance_rate_bound(si, v[i], sj, v[j]));
    const bool near = is_candidate_pair(trial[i].x, trial[j].x, bounding_radius(si), bounding_radius(sj), d_try, box);
    threshold[static_cast<std::size_t>(k)] = near ? d_try : std::numeric_limits<double>::quiet_NaN();
  });
  std::vector<std::size_t> near;
  for (std::size_t k = 0; k < candidates.size(); ++k)
    if (!std::isnan(threshold[k])) near.push_back(k);
  RelativePairs out;
  constexpr std::size_t kChunk = 16384;
  for (std::size_t first = 0; first < near.size(); first += kChunk) {
    const std::size_t count = std::min(kChunk, near.size() - first), kept = out.pairs.size();
    out.pairs.resize(kept + count);
    parallel_for(static_cast<std::ptrdiff_t>(count), [&](std::ptrdiff_t k) {
      const BodyPair& c = candidates[near[first + static_cast<std::size_t>(k)]];
      out.pairs[kept + static_cast<std::size_t>(k)] = detail::contact_pair(shapes, trial, c.i, c.j, box);
    });
    std::size_t end = kept;  // those within their threshold, in order
    for (std::size_t k = 0; k < count; ++k) {
      const double d_try = threshold[near[first + k]];
      if (!(out.pairs[kept + k].points.distance <= d_try)) continue;
      if (end != kept + k) out.pairs[end] = std::move(out.pairs[kept + k]);
      out.d_try.push_back(d_try);
      ++end;
    }
    out.pairs.resize(end);
  }
  return out;
}

// A pair whose distance along the motion reaches the threshold, at the first such time.
struct TrajectoryCrossing {
  Eigen::Index i = 0;
  Eigen::Index j = 0;
  Vec3 image_shift = Vec3::Zero();  // body j enters as its image at x_j + image_shift
  SweptDistance first;              // first_time_below's answer (below = true)
};

// Where a motion can cross: the pairs with a body marked in `moved` (one entry per body) and
// the listed `pairs` (i < j, each once). trajectory_crossings given a scope tests only those, and
// returns the same crossings as without it when no other pair can cross: the contact step's
// guarantee after a correction of the trial motion with DTryRule::relative, where `moved` marks
// the bodies the correction moves and `pairs` are the flagged pairs. A pair of two bodies on
// their trial motion that was not flagged stays above d_hat over the whole step
// (find_pairs_relative), so it cannot reach a threshold below d_hat.
struct CrossingScope {
  std::span<const char> moved;
  std::span<const BodyPair> pairs;
};

// Every pair (i < j) whose d^P along Q_t + t' Psi V drops to `threshold` for some t' in
// [0, dt], found within `tolerance` (a pair that comes within tolerance of it counts); with a
// scope, among the scope's pairs only.
template <Shape S>
std::vector<TrajectoryCrossing> trajectory_crossings(std::span<const S> shapes, std::span<const Pose> poses,
                                                     const VecX& V, int dofs_per_body, double dt, double threshold,
                                                     double tolerance, const std::optional<PeriodicBox>& box = {},
                                                     CellList* cells = nullptr, const CrossingScope* scope = nullptr) {
  detail::SweptBodies<S> b(shapes, poses, V, dofs_per_body);
  require_positive(dt, "dt");
  require_finite(threshold, "threshold");
  require_positive(tolerance, "tolerance");
  const std::vector<RigidVelocity>& v = b.v;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const Vec3 drift = 0.5 * dt * (v[k].u - b.mean);
    b.centres.col(static_cast<Eigen::Index>(k)) += drift;
    b.radii[static_cast<Eigen::Index>(k)] += drift.norm();
  }
  CellList local;
  CellList& list = cells != nullptr ? *cells : local;
  std::vector<TrajectoryCrossing> out;
  const double cutoff = std::max(0.0, threshold) + tolerance;
  if (scope && static_cast<std::size_t>(scope->moved.size()) != poses.size())
    fail_argument("CrossingScope.moved", "has " + std::to_string(scope->moved.size()) + " entries for " +
                                             std::to_string(poses.size()) + " bodies");
  const std::span<const char> moved = scope ? scope->moved : std::span<const char>{};
  std::vector<BodyPair> candidates =
      detail::swept_candidates(b.centres, b.radii, b.body_radius, cutoff, box, list, moved);
  if (scope) {  // the listed pairs of two unmoved bodies, through the broad phase's own test
    const auto moves = [&](Eigen::Index k) { return moved[static_cast<std::size_t>(k)] != 0; };
    for (const BodyPair& p : scope->pairs) {
      const auto n = static_cast<Eigen::Index>(poses.size());
      if (!(0 <= p.i && p.i < n && 0 <= p.j && p.j < n && p.i != p.j))
        fail_argument("CrossingScope.pairs", "(" + std::to_string(p.i) + ", " + std::to_string(p.j) +
                                                 ") must be distinct indices into poses, N = " + std::to_string(n));
      if (!moves(p.i) && !moves(p.j) &&
          is_candidate_pair(b.centres.col(p.i), b.centres.col(p.j), b.radii[p.i], b.radii[p.j], cutoff, box))
        candidates.push_back(p.i < p.j ? p : BodyPair{p.j, p.i});
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  }
  const auto advance_to_threshold = [&](const BodyPair& c) -> std::optional<TrajectoryCrossing> {
    const auto i = static_cast<std::size_t>(c.i), j = static_cast<std::size_t>(c.j);
    const Vec3 shift = minimum_image_shift(b.centres.col(c.i), b.centres.col(c.j), box);
    SweptDistance first = first_time_below(shape_of(shapes, i), poses[i], v[i], shape_of(shapes, j),
                                           shifted(poses[j], shift), v[j], dt, threshold, tolerance);
    if (!first.below) return std::nullopt;
    return TrajectoryCrossing{c.i, c.j, shift, std::move(first)};
  };
  detail::measure_candidates(candidates, advance_to_threshold,
                             [&](const BodyPair&, std::optional<TrajectoryCrossing>& c) {
                               if (c) out.push_back(std::move(*c));
                             });
  return out;
}

}  // namespace stokescontact
