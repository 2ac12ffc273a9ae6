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
#include <cstddef>
#include <cstdint>
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

}  // namespace stokescontact
