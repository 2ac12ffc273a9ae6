#pragma once
// Contact detection at the trial configuration (Broms & Tornberg Sec. 2.1, 2.3): every body
// pair (i, j) with particle distance d^P <= d_try, with its closest points, found through
// the broad phase (bounding balls within d_try) and then exact closest points. In a
// periodic box body j enters through its minimum image about body i; for a flagged pair
// that image is the only one within reach (the broad phase requires box sides of at least
// 2 (2 max bounding radius + d_try)).
//
// Also the smallest d^P over all pairs of a configuration, the measure the solvers report
// against d_hat.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>
#include <span>
#include <vector>

#include "stokescontact/contact/scene.hpp"
#include "stokescontact/core/parallel_for.hpp"
#include "stokescontact/geometry/broad_phase.hpp"
#include "stokescontact/geometry/closest_points.hpp"
#include "stokescontact/geometry/line_contact.hpp"
#include "stokescontact/geometry/overlap_ends.hpp"

namespace stokescontact {

// A flagged pair, i < j. The closest points run from body i to the image of body j at
// x_j + image_shift (image_shift = 0 in open space), normal from i towards j.
struct ContactPair {
  Eigen::Index i = 0;
  Eigen::Index j = 0;
  Vec3 image_shift = Vec3::Zero();
  ClosestPoints points;
  // Where the contact matrix applies the pair's force when it is not at the closest points:
  // a line contact of two LineContactRods (geometry/line_contact.hpp), its distance the gap
  // at those points. `points` keeps d^P, the distance the contact step constrains.
  std::optional<ClosestPoints> force_points;
  // One end of the overlap of two near-parallel rods (split_overlap_ends): the segment end
  // that was the overlap's end at Q*. `points` are the overlap's end on its side, where the
  // pair is now (that end or the other rod's end there, geometry/overlap_ends.hpp's
  // overlap_end_gap), and its closest point on the other rod; the distance constrained their gap.
  std::optional<SegmentEnd> segment_end;
};

inline Pose shifted(const Pose& pose, const Vec3& shift) { return {pose.x + shift, pose.q}; }

namespace detail {

// The broad phase's candidates measured in chunks (parallel_for within a chunk, so memory
// stays bounded by the chunk), handed to `use` in candidate order: the serial loop's results.
template <class Measure, class Use>
void measure_candidates(const std::vector<BodyPair>& candidates, Measure&& measure, Use&& use) {
  constexpr std::size_t kChunk = 16384;
  using Result = decltype(measure(candidates.front()));
  std::vector<Result> measured;
  for (std::size_t first = 0; first < candidates.size(); first += kChunk) {
    const std::size_t count = std::min(kChunk, candidates.size() - first);
    measured.resize(count);
    parallel_for(static_cast<std::ptrdiff_t>(count), [&](std::ptrdiff_t k) {
      measured[static_cast<std::size_t>(k)] = measure(candidates[first + static_cast<std::size_t>(k)]);
    });
    for (std::size_t k = 0; k < count; ++k) use(candidates[first + k], measured[k]);
  }
}

template <Shape S>
void broad_phase_input(std::span<const S> shapes, std::span<const Pose> poses, Mat3X& centres, VecX& radii) {
  const auto n = static_cast<Eigen::Index>(poses.size());
  centres.resize(3, n);
  radii.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    centres.col(k) = poses[static_cast<std::size_t>(k)].x;
    radii[k] = bounding_radius(shape_of(shapes, static_cast<std::size_t>(k)));
  }
}

template <Shape S>
ContactPair contact_pair(std::span<const S> shapes, std::span<const Pose> poses, Eigen::Index i, Eigen::Index j,
                         const std::optional<PeriodicBox>& box) {
  const auto si = static_cast<std::size_t>(i), sj = static_cast<std::size_t>(j);
  ContactPair pair{i, j, minimum_image_shift(poses[si].x, poses[sj].x, box), {}, std::nullopt, std::nullopt};
  const S& a = shape_of(shapes, si);
  const S& b = shape_of(shapes, sj);
  const Pose pose_b = shifted(poses[sj], pair.image_shift);
  pair.points = closest_points_of_valid(a, poses[si], b, pose_b);  // the callers validate the scene
  if constexpr (std::is_same_v<S, LineContactRod>) {
    const auto line = line_contact(to_world(centre_curve(a), poses[si]).segments[0],
                                   to_world(centre_curve(b), pose_b).segments[0],
                                   {std::min(a.line.width, b.line.width), std::min(a.line.angle, b.line.angle)});
    if (line) {
      ClosestPoints& f = pair.force_points.emplace();
      f.normal = line->normal;
      f.curve_point_a = line->point_a;
      f.curve_point_b = line->point_b;
      f.point_a = line->point_a + a.radius * line->normal;
      f.point_b = line->point_b - b.radius * line->normal;
      f.distance = (line->point_b - line->point_a).norm() - a.radius - b.radius;
    }
  }
  return pair;
}

// The contact of pair (i, j) at poses at the end of their overlap on segment end e's side:
// the gap there (overlap_end_gap: e's or the other rod's end on that side, the nearer).
inline ContactPair overlap_end_pair(const Spherocylinder& a, const Pose& pose_a, const Spherocylinder& b,
                                    const Pose& pose_b, Eigen::Index i, Eigen::Index j, const Vec3& image_shift,
                                    SegmentEnd e) {
  const Segment sa = to_world(centre_curve(a).segments[0], pose_a);
  const Segment sb = to_world(centre_curve(b).segments[0], pose_b);
  const CurveContact c{overlap_end_gap(sa, sb, e), unit_tangent(sa, 0.0), unit_tangent(sb, 0.0)};
  return {i, j, image_shift, finish(c, a.radius, b.radius, pose_a.x, pose_b.x), std::nullopt, e};
}

}  // namespace detail

// Near-parallel rods as line contacts held at both ends of their overlap (geometry/
// overlap_ends.hpp; ContactDirections::overlap_ends): each pair of Spherocylinders whose
// centre lines meet at an angle below max_angle, overlapping by at least min_overlap times
// the smaller radius, becomes one contact per overlap end, plus its closest points when those
// lie inside the overlap below both ends by more than rounding (the rods cross there). Other
// pairs, and pairs of other shapes, stay as they are. Order is kept: a pair's contacts
// replace it.
template <Shape S>
std::vector<ContactPair> split_overlap_ends(std::vector<ContactPair> pairs, std::span<const S> shapes,
                                            std::span<const Pose> poses, double max_angle,
                                            double min_overlap) {
  if constexpr (!std::is_same_v<S, Spherocylinder>) {
    return pairs;
  } else {
    std::vector<ContactPair> out;
    out.reserve(pairs.size());
    for (ContactPair& p : pairs) {
      if (p.segment_end) {
        out.push_back(std::move(p));
        continue;
      }
      const S& a = shape_of(shapes, static_cast<std::size_t>(p.i));
      const S& b = shape_of(shapes, static_cast<std::size_t>(p.j));
      const Pose& pose_a = poses[static_cast<std::size_t>(p.i)];
      const Pose pose_b = shifted(poses[static_cast<std::size_t>(p.j)], p.image_shift);
      const auto ends = overlap_ends(to_world(centre_curve(a).segments[0], pose_a),
                                     to_world(centre_curve(b).segments[0], pose_b), max_angle,
                                     min_overlap * std::min(a.radius, b.radius));
      if (!ends) {
        out.push_back(std::move(p));
        continue;
      }
      const ContactPair low = detail::overlap_end_pair(a, pose_a, b, pose_b, p.i, p.j, p.image_shift, (*ends)[0]);
      const ContactPair high = detail::overlap_end_pair(a, pose_a, b, pose_b, p.i, p.j, p.image_shift, (*ends)[1]);
      const double rounding = 1e-12 * (a.length + b.length + a.radius + b.radius);
      if (p.points.distance < std::min(low.points.distance, high.points.distance) - rounding)
        out.push_back(std::move(p));
      out.push_back(low);
      out.push_back(high);
    }
    return out;
  }
}

// Pair p (as flagged, perhaps an overlap end) measured again at poses, which must be valid
// (validate_scene): the contact step calls it per pair and correction on poses it made.
template <Shape S>
ContactPair remeasured(const ContactPair& p, std::span<const S> shapes, std::span<const Pose> poses,
                       const std::optional<PeriodicBox>& box) {
  if constexpr (std::is_same_v<S, Spherocylinder>) {
    if (p.segment_end)
      return detail::overlap_end_pair(shape_of(shapes, static_cast<std::size_t>(p.i)),
                                      poses[static_cast<std::size_t>(p.i)],
                                      shape_of(shapes, static_cast<std::size_t>(p.j)),
                                      shifted(poses[static_cast<std::size_t>(p.j)], p.image_shift), p.i, p.j,
                                      p.image_shift, *p.segment_end);
  }
  return detail::contact_pair(shapes, poses, p.i, p.j, box);
}

// All pairs with d^P <= d_try (d_try >= 0), sorted by (i, j). `cells`, when given, keeps
// the broad phase's buffers between calls. With `marked` (one entry per body), only the pairs
// that have a marked body (CellList::find_pairs_of: O(N) to sort, then O(marked)).
template <Shape S>
std::vector<ContactPair> find_contact_pairs(std::span<const S> shapes, std::span<const Pose> poses, double d_try,
                                            const std::optional<PeriodicBox>& box = {}, CellList* cells = nullptr,
                                            std::span<const char> marked = {}) {
  validate_scene(shapes, poses);
  require_non_negative(d_try, "d_try");
  Mat3X centres;
  VecX radii;
  detail::broad_phase_input(shapes, poses, centres, radii);
  CellList local;
  CellList& list = cells != nullptr ? *cells : local;
  const std::vector<BodyPair>& candidates = marked.empty() ? list.find_pairs(centres, radii, d_try, box)
                                                           : list.find_pairs_of(centres, radii, d_try, box, marked);
  std::vector<ContactPair> flagged;
  const auto measure = [&](const BodyPair& c) { return detail::contact_pair(shapes, poses, c.i, c.j, box); };
  if constexpr (std::is_same_v<S, Sphere>) {
    // A sphere is its bounding ball: (nearly) every candidate is flagged, so the candidates
    // are measured in place in the result, one buffer written once (growing it by push_back
    // and measuring through a chunk buffer touched three times the memory, in fresh pages).
    flagged.resize(candidates.size());
    parallel_for(static_cast<std::ptrdiff_t>(candidates.size()), [&](std::ptrdiff_t k) {
      flagged[static_cast<std::size_t>(k)] = measure(candidates[static_cast<std::size_t>(k)]);
    });
    std::erase_if(flagged, [&](const ContactPair& pair) { return !(pair.points.distance <= d_try); });
  } else {
    detail::measure_candidates(candidates, measure, [&](const BodyPair&, ContactPair& pair) {
      if (pair.points.distance <= d_try) flagged.push_back(std::move(pair));
    });
  }
  return flagged;
}

template <Shape S>
std::vector<ContactPair> find_contact_pairs(const S& shape, std::span<const Pose> poses, double d_try,
                                            const std::optional<PeriodicBox>& box = {}, CellList* cells = nullptr) {
  return find_contact_pairs(std::span<const S>(&shape, 1), poses, d_try, box, cells);
}

// The pair with the smallest d^P; distance = +infinity (i = j = -1) for fewer than 2 bodies.
struct MinimumDistance {
  double distance = std::numeric_limits<double>::infinity();
  Eigen::Index i = -1;
  Eigen::Index j = -1;
};

// Smallest d^P over all pairs: broad-phase queries with a growing cutoff (starting from the
// largest bounding radius, times 4 per round) until a pair lies within the cutoff, which is
// then the minimum. A caller that knows a pair's d^P passes it as `at_most`: the first
// cutoff is then max(at_most, 0), which already holds the minimum (a pair with d^P <= c has
// bounding balls within c), so one narrow query does (the contact step's end, where flagged
// pairs sit near d_hat). Open space ends at the latest once the cutoff spans all centres. In a
// periodic box the cutoff stops at the broad phase's reach, L_min/2 - 2 max bounding radius;
// if no pair lies within it, every pair is farther apart than that and the result is the
// minimum over all pairs' minimum images (found by brute force).
template <Shape S>
MinimumDistance minimum_pair_distance(std::span<const S> shapes, std::span<const Pose> poses,
                                      const std::optional<PeriodicBox>& box = {}, CellList* cells = nullptr,
                                      double at_most = std::numeric_limits<double>::infinity()) {
  validate_scene(shapes, poses);
  if (std::isnan(at_most)) fail_argument("at_most", "must not be NaN");
  MinimumDistance best;
  if (poses.size() < 2) return best;
  Mat3X centres;
  VecX radii;
  detail::broad_phase_input(shapes, poses, centres, radii);
  const double r_max = radii.maxCoeff();
  // Largest cutoff needed: open space, the span of the centres (every pair is then a
  // candidate); periodic, the broad phase's reach.
  double reach = (centres.rowwise().maxCoeff() - centres.rowwise().minCoeff()).norm();
  if (box) {
    const double half = 0.5 * box->lengths.minCoeff();
    reach = std::max(0.0, half - (r_max + r_max));
    while (reach > 0.0 && (r_max + r_max) + reach > half) reach = std::nextafter(reach, 0.0);
  }
  auto distance = [&](const BodyPair& c) { return detail::contact_pair(shapes, poses, c.i, c.j, box).points.distance; };
  auto consider = [&](const BodyPair& c, double d) {
    if (d < best.distance) best = {d, c.i, c.j};
  };
  CellList local;
  CellList& list = cells != nullptr ? *cells : local;
  for (double cutoff = std::min({r_max, reach, std::max(at_most, 0.0)});;
       cutoff = std::min(std::max(4.0 * cutoff, r_max), reach)) {
    detail::measure_candidates(list.find_pairs(centres, radii, cutoff, box), distance, consider);
    if (best.distance <= cutoff || (!box && cutoff == reach)) return best;
    if (cutoff == reach) break;
  }
  const auto n = static_cast<Eigen::Index>(poses.size());  // periodic, nothing within reach
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = i + 1; j < n; ++j) consider({i, j}, distance({i, j}));
  return best;
}

template <Shape S>
MinimumDistance minimum_pair_distance(const S& shape, std::span<const Pose> poses,
                                      const std::optional<PeriodicBox>& box = {}, CellList* cells = nullptr,
                                      double at_most = std::numeric_limits<double>::infinity()) {
  return minimum_pair_distance(std::span<const S>(&shape, 1), poses, box, cells, at_most);
}

}  // namespace stokescontact
