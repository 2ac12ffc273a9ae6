#pragma once
// Random sequential placement of identical bodies of any shape in a periodic cube, the start
// of a Brownian suspension (Yan et al. Sec. IV start "from a random placement and
// orientation"): centres uniform in [0, side)^3, orientations uniform on SO(3)
// (scenes/random.hpp), drawn one body at a time; a draw is kept only if its gap d^P to every
// kept body, each seen through its minimum image, exceeds min_gap, and otherwise drawn again.
// The start is therefore contact free in the box and fit for TimeStepper (whose box must be
// at least 2 (2 bounding radius + d_hat) on a side; checked here with min_gap in its place).
// Cost: O(count^2) bounding-ball tests and closest points only for balls within reach, fine
// for the dilute to moderate packings it is meant for (a few thousand bodies in seconds); the
// rejection rate grows steeply towards random sequential addition's jamming.
//
// periodic_aligned_columns: a dense start for spherocylinders, the aligned start of Yan et
// al. Sec. IV.B ("random center location but aligned orientation"), for packings beyond
// random placement's reach (brownian_rods with 400 rods of L/D = 5, placement and one step:
// 0.2, 1.4 and 19 s at packing 0.20, 0.25 and 0.29). Every rod lies along z; rods are
// stacked in columns along z, m per column at spacing side / m > end-to-end length + min_gap,
// each column shifted along z by its own uniform offset (no smectic layers), and the columns
// sit on the sites of a k x k square lattice in xy (a random k^2 - columns of them left
// empty), each moved by a uniform jitter that keeps neighbouring columns more than 2 radius +
// min_gap apart. The dynamics then melts the order (or keeps it, above the isotropic-nematic
// transition).
//
// rescale_centres: the affine rescaling of a placed suspension (compression towards a denser
// packing, expansion towards a more dilute one), with the reason an expansion is safe.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/geometry/closest_points.hpp"
#include "stokescontact/geometry/periodic_box.hpp"
#include "stokescontact/geometry/shapes.hpp"
#include "stokescontact/scenes/random.hpp"

namespace stokescontact {

// `count` bodies of `shape` in the periodic cube [0, side)^3 with every gap > min_gap (see
// the top). Throws std::invalid_argument naming "side" (too small for the shape), "min_gap"
// (< 0) or "max_attempts" (< 1), and std::runtime_error when max_attempts draws in a row are
// rejected (the message says how many bodies were placed).
template <Shape S>
std::vector<Pose> periodic_random_placement(const S& shape, std::size_t count, double side, double min_gap,
                                            std::uint64_t seed, long long max_attempts = 1000000) {
  validate(shape);
  require_non_negative(min_gap, "min_gap");
  if (max_attempts < 1) fail_argument("max_attempts", "must be >= 1, got " + std::to_string(max_attempts));
  const double reach = 2.0 * bounding_radius(shape) + min_gap;  // centres farther apart cannot touch
  if (!(side >= 2.0 * reach))
    fail_argument("side", "must be >= 2 (2 bounding radius + min_gap) = " + std::to_string(2.0 * reach) +
                              " for the minimum image, got " + std::to_string(side));
  const PeriodicBox box{Vec3::Constant(side)};
  Rng rng(seed);
  std::vector<Pose> poses;
  poses.reserve(count);
  long long rejected = 0;
  while (poses.size() < count) {
    if (rejected == max_attempts)
      throw std::runtime_error("periodic_random_placement: placed " + std::to_string(poses.size()) + " of " +
                               std::to_string(count) + " bodies, then " + std::to_string(max_attempts) +
                               " draws in a row were rejected (seed " + std::to_string(seed) + ")");
    const Pose candidate{uniform_vector(rng, 0.0, side), random_rotation(rng)};
    bool kept = true;
    for (const Pose& q : poses) {
      const Vec3 image = q.x + minimum_image_shift(candidate.x, q.x, box);
      if ((image - candidate.x).norm() > reach) continue;
      if (!(closest_points(shape, candidate, shape, Pose{image, q.q}).distance > min_gap)) {
        kept = false;
        break;
      }
    }
    if (!kept) {
      ++rejected;
      continue;
    }
    poses.push_back(candidate);
    rejected = 0;
  }
  return poses;
}

// `count` spherocylinders along z in the periodic box [0, Lx) x [0, Ly) x [0, Lz), every gap
// > min_gap (see the top), columns along z; the cross-section must be square (Lx = Ly), Lz
// any length (Lz > Lx: Yan et al.'s elongated box with the rods along its long side). Throws
// std::invalid_argument naming "box.lengths" (a side too small for the minimum image, or Lx !=
// Ly), "min_gap" (< 0) or "count" (the columns would be closer than 2 radius + min_gap: the
// packing is too high for aligned columns in this box).
inline std::vector<Pose> periodic_aligned_columns(const Spherocylinder& rod, std::size_t count, const PeriodicBox& box,
                                                  double min_gap, std::uint64_t seed) {
  validate(rod);
  require_non_negative(min_gap, "min_gap");
  require_finite(box.lengths, "box.lengths");
  const double reach = 2.0 * bounding_radius(rod) + min_gap;
  if (!(box.lengths.minCoeff() >= 2.0 * reach))
    fail_argument("box.lengths", "every side must be >= 2 (2 bounding radius + min_gap) = " + std::to_string(2.0 * reach) +
                                     " for the minimum image, got a side of " + std::to_string(box.lengths.minCoeff()));
  if (box.lengths.x() != box.lengths.y())
    fail_argument("box.lengths", "the columns' cross-section must be square (Lx = Ly), got " +
                                     std::to_string(box.lengths.x()) + " x " + std::to_string(box.lengths.y()));
  if (count == 0) return {};
  const double side = box.lengths.x(), height = box.lengths.z();
  // A column's period must exceed `extent`; height >= 2 reach = 2 extent leaves room for >= 1.
  const double extent = rod.length + 2.0 * rod.radius + min_gap;
  const auto per_column = static_cast<std::size_t>(std::ceil(height / extent)) - 1;
  const std::size_t columns = (count + per_column - 1) / per_column;
  const auto k = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(columns))));
  const double spacing = side / static_cast<double>(k);
  const double lateral = 2.0 * rod.radius + min_gap;  // columns closer than this (axis to axis) touch
  if (!(spacing > lateral))
    fail_argument("count", std::to_string(count) + " rods need " + std::to_string(columns) + " columns of " +
                               std::to_string(per_column) + " on a " + std::to_string(k) + " x " +
                               std::to_string(k) + " lattice of spacing " + std::to_string(spacing) +
                               ", not more than 2 radius + min_gap = " + std::to_string(lateral) + " apart");
  const double jitter = 0.5 * (spacing - lateral) * (1.0 - 1e-9);  // per coordinate, either way
  Rng rng(seed);
  std::vector<std::size_t> sites(k * k);
  for (std::size_t s = 0; s < sites.size(); ++s) sites[s] = s;
  std::shuffle(sites.begin(), sites.end(), rng);
  std::vector<Pose> poses;
  poses.reserve(count);
  for (std::size_t c = 0; c < columns; ++c) {
    // Rods of this column: count spread as evenly as the columns allow.
    const std::size_t here = count / columns + (c < count % columns ? 1 : 0);
    const double period = height / static_cast<double>(here);
    const double x = (static_cast<double>(sites[c] % k) + 0.5) * spacing + uniform(rng, -jitter, jitter);
    const double y = (static_cast<double>(sites[c] / k) + 0.5) * spacing + uniform(rng, -jitter, jitter);
    const double offset = uniform(rng, 0.0, height);
    for (std::size_t r = 0; r < here; ++r)
      poses.push_back(Pose{Vec3(x, y, std::fmod(offset + static_cast<double>(r) * period, height)), Quat::Identity()});
  }
  return poses;
}

// The same in the periodic cube [0, side)^3; "side" named where it is too small.
inline std::vector<Pose> periodic_aligned_columns(const Spherocylinder& rod, std::size_t count, double side,
                                                  double min_gap, std::uint64_t seed) {
  validate(rod);
  const double reach = 2.0 * bounding_radius(rod) + std::max(min_gap, 0.0);
  if (!(side >= 2.0 * reach))
    fail_argument("side", "must be >= 2 (2 bounding radius + min_gap) = " + std::to_string(2.0 * reach) +
                              " for the minimum image, got " + std::to_string(side));
  return periodic_aligned_columns(rod, count, PeriodicBox{Vec3::Constant(side)}, min_gap, seed);
}

// Every centre scaled by `factor` about the origin, orientations kept: the affine rescaling
// of a suspension in the cube [0, side)^3 to the cube [0, factor side)^3 (the caller scales
// the box; wrapped centres stay wrapped). An expansion (factor >= 1) shortens no gap between
// convex bodies that contain their own centre (spheres, spherocylinders), through any
// periodic image: with centre offset r the gap of a pair is dist(r, K), K = {a - b} over the
// two bodies placed at their centres, a convex set that holds 0; t -> dist(t r, K) is convex
// and 0 at t = 0, so it is nondecreasing for t >= 0, and every image's offset scales with
// the box. (A compression shortens gaps; a non-convex body, the boomerang, may come closer
// to a neighbour even as the suspension expands.) Throws std::invalid_argument naming
// "factor" unless it is positive and finite.
inline void rescale_centres(std::span<Pose> poses, double factor) {
  if (!(factor > 0.0 && std::isfinite(factor)))
    fail_argument("factor", "must be positive and finite, got " + std::to_string(factor));
  for (Pose& p : poses) p.x *= factor;
}

}  // namespace stokescontact
