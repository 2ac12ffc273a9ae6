#pragma once
// Seeded random inputs for scenes, tests and benchmarks: the engine the project uses and the
// draws made from it, so that a seed names the same scene everywhere.
//
//   uniform, uniform_vector: the engine's 64 bits scaled to [0, 1) as libstdc++'s
//       std::uniform_real_distribution does it for this engine (the same numbers as that
//       distribution there), written out so that every standard library gives them.
//   random_unit_vector, random_rotation: a normalised standard Gaussian vector in 3 and 4
//       dimensions. Its direction is uniform on the sphere S^2 or S^3; a uniform unit
//       quaternion (q and -q alike) is a uniformly distributed rotation, the Haar measure on
//       SO(3) (Shoemake, Graphics Gems III, 1992). The Gaussians come from
//       std::normal_distribution, whose algorithm is the standard library's (libstdc++: the
//       polar method), a fresh one per call.
//
// A single draw takes the engine first, uniform(rng, lo, hi); a batch of n takes n first and
// the engine last, random_poses(n, lo, hi, rng). Arguments that are read in one sequence are
// drawn in that sequence (x, y, z; w, x, y, z): the same on every compiler.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

// The seeded engine of every scene generator, test and benchmark.
using Rng = std::mt19937_64;

namespace detail {

// [0, 1): the engine's 64 bits rounded to a double, times 2^-64; a draw that rounds up to 1
// becomes the largest double below 1 (libstdc++'s generate_canonical for a 64-bit engine).
inline double unit_interval(Rng& rng) {
  static_assert(Rng::min() == 0 && Rng::max() == ~std::uint64_t{0}, "a full 64-bit engine");
  const double u = static_cast<double>(rng()) * 0x1p-64;
  return u < 1.0 ? u : std::nextafter(1.0, 0.0);
}

inline void require_interval(double lo, double hi) {
  require_finite(lo, "lo");
  require_finite(hi, "hi");
  if (!(lo <= hi)) fail_argument("hi", "must be >= lo = " + std::to_string(lo) + ", got " + std::to_string(hi));
}

}  // namespace detail

// Uniform in [lo, hi) (lo itself when lo = hi).
inline double uniform(Rng& rng, double lo, double hi) {
  detail::require_interval(lo, hi);
  return detail::unit_interval(rng) * (hi - lo) + lo;
}

// Uniform in the cube [lo, hi)^3.
inline Vec3 uniform_vector(Rng& rng, double lo, double hi) {
  const double x = uniform(rng, lo, hi), y = uniform(rng, lo, hi), z = uniform(rng, lo, hi);
  return {x, y, z};
}

// Uniform on the unit sphere: a normalised 3D standard Gaussian.
inline Vec3 random_unit_vector(Rng& rng) {
  std::normal_distribution<double> g;
  for (;;) {
    const double x = g(rng), y = g(rng), z = g(rng);
    const Vec3 v(x, y, z);
    if (v.norm() > 1e-12) return v.normalized();
  }
}

// A uniformly distributed rotation (Haar measure on SO(3)): a normalised 4D standard Gaussian.
inline Quat random_rotation(Rng& rng) {
  std::normal_distribution<double> g;
  for (;;) {
    const double w = g(rng), x = g(rng), y = g(rng), z = g(rng);
    const Quat q(w, x, y, z);
    if (q.norm() > 1e-12) return q.normalized();
  }
}

// n poses, each a centre uniform in [lo, hi)^3 and then a uniform rotation (overlaps allowed).
inline std::vector<Pose> random_poses(std::size_t n, double lo, double hi, Rng& rng) {
  detail::require_interval(lo, hi);
  std::vector<Pose> poses(n);
  for (Pose& p : poses) {
    p.x = uniform_vector(rng, lo, hi);
    p.q = random_rotation(rng);
  }
  return poses;
}

// n forces of length `magnitude` with directions uniform on the sphere.
inline std::vector<Vec3> random_forces(std::size_t n, double magnitude, Rng& rng) {
  require_non_negative(magnitude, "magnitude");
  std::vector<Vec3> forces(n);
  for (Vec3& f : forces) f = magnitude * random_unit_vector(rng);
  return forces;
}

}  // namespace stokescontact
