#pragma once
// Seeded configurations of N non-overlapping equal spheres in a cube of side L (Broms &
// Tornberg Sec. 3.1.1, Fig. 4): the packing fraction is the number density times the sphere
// volume, phi = N (4/3) pi a^3 / L^3, with every centre in [0, L)^3, in open space (no
// periodic box). A packing is made for unit spheres and scaled by the radius a, so one seed
// gives the same scene in units of a for every radius.
//
//   random_sequential_addition: centres drawn uniformly one at a time, rejected when they
//       overlap an earlier sphere. Fine well below RSA jamming (~0.384): phi 0.24 and 0.12.
//   dense_packing: a near-jammed packing (phi ~0.55) by compression with overlap relaxation.
//       Spheres of radius 1 + skin in a periodic cube are compressed in stages from phi_start;
//       after each stage the harmonic overlap energy sum (2 (1 + skin) - r_ij)_+^2 / 2 is
//       minimised with FIRE (Bitzek et al., PRL 97, 170201, 2006) on a cell list until no
//       overlap is left. A stage that cannot be relaxed ends the compression at the last
//       relaxed phi (reported). The periodic packing viewed in open space is contact free too:
//       an open-space distance is never below the minimum-image one. Most neighbours end near
//       the enlarged contact, so the smallest gaps are ~2 skin: a near-jammed test scene.
//
// Both end contact free, checked over all pairs in open space (SpherePacking::min_gap).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/core/types.hpp"
#include "stokescontact/geometry/broad_phase.hpp"
#include "stokescontact/geometry/closest_points.hpp"
#include "stokescontact/geometry/periodic_box.hpp"
#include "stokescontact/geometry/shapes.hpp"
#include "stokescontact/scenes/random.hpp"

namespace stokescontact {

// random_sequential_addition takes phi below this: RSA jams at 0.384 (Torquato, Uche and
// Stillinger, PRE 74, 061308, 2006), and the last spheres take ever longer to place.
inline constexpr double kRandomSequentialAdditionLimit = 0.38;
// dense_packing takes phi below this: no packing of equal spheres is denser than
// pi / sqrt(18) = 0.7405 (fcc); relaxation jams well before it (random close packing ~0.64).
inline constexpr double kDensePackingLimit = 0.74;

struct SpherePacking {
  std::vector<Pose> poses;  // sphere centres in [0, side)^3, identity orientations
  double radius = 1.0;      // a
  double side = 0.0;        // L
  double phi = 0.0;         // N (4/3) pi a^3 / L^3 reached
  double min_gap = 0.0;     // smallest d^P = |x_i - x_j| - 2a over all pairs, open space (> 0)
};

// L for n spheres of radius `radius` at packing fraction phi.
inline double cube_side(std::size_t n, double phi, double radius = 1.0) {
  if (n < 1) fail_argument("n", "must be >= 1");
  require_positive(phi, "phi");
  require_positive(radius, "radius");
  return radius * std::cbrt(static_cast<double>(n) * (4.0 / 3.0) * std::numbers::pi / phi);
}

// The smallest gap between spheres of radius `radius` at these centres, open space (+infinity
// for fewer than 2): cell-list queries with a growing cutoff (from the radius, times 4 per
// round) until a pair lies within the cutoff, which is then the minimum, at the latest when
// the cutoff spans all centres. Each gap is d^P of closest_points, as the contact code has it.
inline double minimum_gap(std::span<const Pose> poses, double radius) {
  require_positive(radius, "radius");
  validate(poses);
  double best = std::numeric_limits<double>::infinity();
  if (poses.size() < 2) return best;
  Mat3X centres(3, static_cast<Eigen::Index>(poses.size()));
  for (std::size_t k = 0; k < poses.size(); ++k) centres.col(static_cast<Eigen::Index>(k)) = poses[k].x;
  const double reach = (centres.rowwise().maxCoeff() - centres.rowwise().minCoeff()).norm();
  const Sphere sphere{radius};
  CellList cells;
  for (double cutoff = std::min(radius, reach);; cutoff = std::min(4.0 * cutoff, reach)) {
    for (const BodyPair& p : cells.find_pairs(centres, radius, cutoff))
      best = std::min(best, closest_points(sphere, poses[static_cast<std::size_t>(p.i)], sphere,
                                           poses[static_cast<std::size_t>(p.j)]).distance);
    if (best <= cutoff || cutoff == reach) return best;
  }
}

namespace detail {

inline void require_sphere_count(std::size_t n) {
  if (n < 2) fail_argument("n", "must be >= 2, got " + std::to_string(n));
}

inline void require_packing_fraction(double phi, double limit, const char* generator) {
  if (!(phi > 0.0 && phi < limit))
    fail_argument("phi", "must lie in (0, " + std::to_string(limit) + ") for " + generator + ", got " +
                             std::to_string(phi));
}

// The packing of unit spheres at `centres` in a cube of `side`, scaled to `radius`; fills phi
// and min_gap and checks it is contact free: throws otherwise (a bug, not bad luck).
inline SpherePacking finished(const Mat3X& centres, double side, double radius, const char* generator) {
  SpherePacking p;
  p.poses.resize(static_cast<std::size_t>(centres.cols()));
  for (Eigen::Index i = 0; i < centres.cols(); ++i)
    p.poses[static_cast<std::size_t>(i)] = {radius * Vec3(centres.col(i)), Quat::Identity()};
  p.radius = radius;
  p.side = radius * side;
  p.phi = static_cast<double>(centres.cols()) * (4.0 / 3.0) * std::numbers::pi / (side * side * side);
  p.min_gap = minimum_gap(p.poses, radius);
  if (!(p.min_gap > 0.0))
    throw std::runtime_error(std::string(generator) + ": packing not contact free, min gap " +
                             std::to_string(p.min_gap));
  return p;
}

}  // namespace detail

// Random sequential addition of n spheres at packing fraction phi, well below RSA jamming.
// Each draw is checked against the spheres placed in the 27 grid cells (side >= 2, one
// diameter) around it, so a packing costs O(N) checks: 1e6 spheres in seconds. Throws
// std::runtime_error after max_attempts rejected draws in a row.
inline SpherePacking random_sequential_addition(std::size_t n, double phi, std::uint64_t seed, double radius = 1.0,
                                                int max_attempts = 1000000) {
  detail::require_sphere_count(n);
  detail::require_packing_fraction(phi, kRandomSequentialAdditionLimit, "random_sequential_addition");
  require_positive(radius, "radius");
  if (max_attempts < 1) fail_argument("max_attempts", "must be >= 1, got " + std::to_string(max_attempts));
  const double side = cube_side(n, phi);  // unit spheres, scaled at the end
  Rng rng(seed);
  Mat3X centres(3, static_cast<Eigen::Index>(n));
  const auto cells = std::max<std::int64_t>(1, static_cast<std::int64_t>(side / 2.0));  // per side
  const double cell = side / static_cast<double>(cells);                               // >= 2
  const auto cell_of = [&](double x) { return std::clamp<std::int64_t>(static_cast<std::int64_t>(x / cell), 0, cells - 1); };
  std::vector<std::vector<Eigen::Index>> grid(static_cast<std::size_t>(cells * cells * cells));
  // Unit spheres overlap when their centres are closer than 2.
  const auto overlaps = [&](const Vec3& x) {
    const std::int64_t cx = cell_of(x[0]), cy = cell_of(x[1]), cz = cell_of(x[2]);
    for (std::int64_t a = std::max<std::int64_t>(cx - 1, 0); a <= std::min(cx + 1, cells - 1); ++a)
      for (std::int64_t b = std::max<std::int64_t>(cy - 1, 0); b <= std::min(cy + 1, cells - 1); ++b)
        for (std::int64_t c = std::max<std::int64_t>(cz - 1, 0); c <= std::min(cz + 1, cells - 1); ++c)
          for (const Eigen::Index k : grid[static_cast<std::size_t>((a * cells + b) * cells + c)])
            if ((centres.col(k) - x).squaredNorm() <= 4.0) return true;
    return false;
  };
  Eigen::Index placed = 0;
  for (int attempt = 0; placed < centres.cols(); ++attempt) {
    if (attempt == max_attempts)
      throw std::runtime_error("random_sequential_addition: jammed after " + std::to_string(placed) +
                               " spheres, seed " + std::to_string(seed));
    const Vec3 x = uniform_vector(rng, 0.0, side);
    if (overlaps(x)) continue;
    grid[static_cast<std::size_t>((cell_of(x[0]) * cells + cell_of(x[1])) * cells + cell_of(x[2]))].push_back(placed);
    centres.col(placed++) = x;
    attempt = -1;
  }
  return detail::finished(centres, side, radius, "random_sequential_addition");
}

struct DensePackingOptions {
  double phi_start = 0.30;           // uniform random centres at this density, relaxed first
  int stages = 10;                   // compression stages from phi_start to the target
  double skin = 5e-4;                // relax radius (1 + skin) a: final gaps ~>= 2 skin a
  int max_relax_iterations = 20000;  // FIRE steps per stage
};

namespace detail {

// Minimum-image separation x_i - x_j in a periodic cube.
inline Vec3 minimum_image(const Vec3& d, double side) { return d - side * (d / side).array().round().matrix(); }

// Forces -grad of the harmonic overlap energy at diameter sigma; returns the largest overlap.
inline double overlap_forces(const Mat3X& x, double sigma, double side, CellList& cells, Mat3X& force) {
  force.setZero(3, x.cols());
  double worst = 0.0;
  const PeriodicBox box{Vec3::Constant(side)};
  for (const BodyPair& p : cells.find_pairs(x, 0.5 * sigma, 0.0, box)) {
    const Vec3 d = minimum_image(x.col(p.i) - x.col(p.j), side);
    const double r = d.norm();
    const double overlap = sigma - r;
    if (!(overlap > 0.0) || r == 0.0) continue;
    worst = std::max(worst, overlap);
    const Vec3 f = overlap / r * d;
    force.col(p.i) += f;
    force.col(p.j) -= f;
  }
  return worst;
}

// FIRE minimisation of the overlap energy at diameter sigma until the largest overlap is below
// tolerance. Positions stay wrapped into [0, side)^3. Returns false if it does not get there.
inline bool relax_overlaps(Mat3X& x, double sigma, double side, double tolerance, int max_iterations) {
  constexpr double kDtStart = 0.02, kDtMax = 0.2, kIncrease = 1.1, kDecrease = 0.5, kAlphaStart = 0.1,
                   kAlphaShrink = 0.99;
  constexpr int kDelay = 5;
  const PeriodicBox box{Vec3::Constant(side)};
  CellList cells;
  Mat3X v = Mat3X::Zero(3, x.cols()), f;
  double dt = kDtStart, alpha = kAlphaStart;
  int since_uphill = 0;
  for (int it = 0; it < max_iterations; ++it) {
    if (overlap_forces(x, sigma, side, cells, f) <= tolerance) return true;
    const double power = (f.array() * v.array()).sum();
    if (power > 0.0) {  // downhill: mix the velocity towards the force, speed up
      v = (1.0 - alpha) * v + alpha * v.norm() / f.norm() * f;
      if (++since_uphill > kDelay) {
        dt = std::min(dt * kIncrease, kDtMax);
        alpha *= kAlphaShrink;
      }
    } else {  // uphill: stop, slow down
      v.setZero();
      dt *= kDecrease;
      alpha = kAlphaStart;
      since_uphill = 0;
    }
    v += dt * f;  // unit masses, semi-implicit Euler
    x += dt * v;
    for (Eigen::Index i = 0; i < x.cols(); ++i) x.col(i) = wrap_into_box(Vec3(x.col(i)), box);
  }
  return false;
}

}  // namespace detail

// A near-jammed packing of n spheres, compressed towards phi_target (see the top). The
// result's phi is what was reached: phi_target, or the last stage that relaxed. Throws
// std::runtime_error if even the start at phi_start cannot be relaxed.
inline SpherePacking dense_packing(std::size_t n, double phi_target, std::uint64_t seed, double radius = 1.0,
                                   const DensePackingOptions& options = {}) {
  detail::require_sphere_count(n);
  detail::require_packing_fraction(phi_target, kDensePackingLimit, "dense_packing");
  require_positive(radius, "radius");
  require_positive(options.phi_start, "options.phi_start");
  require_positive(options.skin, "options.skin");
  if (options.stages < 1) fail_argument("options.stages", "must be >= 1, got " + std::to_string(options.stages));
  if (options.max_relax_iterations < 1)
    fail_argument("options.max_relax_iterations",
                  "must be >= 1, got " + std::to_string(options.max_relax_iterations));
  const double sigma = 2.0 * (1.0 + options.skin);  // enlarged diameter (unit spheres)
  const double tolerance = 0.1 * options.skin;      // leftover overlap: gaps >= 1.9 skin
  const double phi_start = std::min(options.phi_start, phi_target);
  Rng rng(seed);
  double side = cube_side(n, phi_start);
  Mat3X x(3, static_cast<Eigen::Index>(n));
  for (Eigen::Index i = 0; i < x.cols(); ++i) x.col(i) = uniform_vector(rng, 0.0, side);
  if (!detail::relax_overlaps(x, sigma, side, tolerance, options.max_relax_iterations))
    throw std::runtime_error("dense_packing: could not relax the start at phi " + std::to_string(phi_start));
  for (int stage = 1; stage <= options.stages; ++stage) {
    const double phi = phi_start + (phi_target - phi_start) * stage / options.stages;
    const double next_side = cube_side(n, phi);
    Mat3X trial = x * (next_side / side);  // affine compression
    if (!detail::relax_overlaps(trial, sigma, next_side, tolerance, options.max_relax_iterations)) break;
    x = std::move(trial);
    side = next_side;
  }
  return detail::finished(x, side, radius, "dense_packing");
}

}  // namespace stokescontact
