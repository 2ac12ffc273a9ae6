#pragma once
// Seeded configurations of N non-overlapping unit spheres in a cube of side L, for the sphere
// experiments (Broms & Tornberg Sec. 3.1.1, Fig. 4): the packing fraction is the number
// density times the sphere volume, phi = N (4/3) pi / L^3, with every centre in [0, L)^3.
// The contact step sees open space (no periodic box), as in the paper.
//
//   random_sequential_addition: centres drawn uniformly one at a time, rejected when they
//       overlap an earlier sphere. Fine well below RSA jamming (~0.38): phi 0.24 and 0.12.
//   dense_packing: a near-jammed packing (phi ~0.55) by compression with overlap relaxation.
//       Spheres of radius 1 + skin in a periodic cube are compressed in stages from phi_start;
//       after each stage the harmonic overlap energy sum (2 (1 + skin) - r_ij)_+^2 / 2 is
//       minimised with FIRE (Bitzek et al., PRL 97, 170201, 2006) on a cell list until no
//       overlap is left. A stage that cannot be relaxed ends the compression at the last
//       relaxed phi (reported). The periodic packing viewed in open space is contact free too:
//       an open-space distance is never below the minimum-image one. Most neighbours end near
//       the enlarged contact, so the smallest gaps are ~2 skin: a near-jammed test scene.
//
// Both end contact free, checked with stokescontact::minimum_pair_distance (open space).
#include <stokescontact/stokescontact.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace examples {

namespace sc = stokescontact;

struct SpherePacking {
  std::vector<sc::Pose> poses;  // unit spheres, centres in [0, side)^3, identity orientations
  double side = 0.0;            // L
  double phi = 0.0;             // N (4/3) pi / L^3 reached
  double min_gap = 0.0;         // smallest d^P over all pairs, open space (> 0)
};

// L for N unit spheres at packing fraction phi.
inline double cube_side(std::size_t n, double phi) {
  return std::cbrt(static_cast<double>(n) * (4.0 / 3.0) * std::numbers::pi / phi);
}

inline sc::Vec3 uniform_in_cube(std::mt19937_64& rng, double side) {
  std::uniform_real_distribution<double> u(0.0, side);
  const double x = u(rng), y = u(rng), z = u(rng);  // sequenced: the same on every compiler
  return {x, y, z};
}

// A direction uniform on the unit sphere (normalised Gaussian vector).
inline sc::Vec3 random_unit_vector(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  for (;;) {
    const double x = g(rng), y = g(rng), z = g(rng);
    const sc::Vec3 v(x, y, z);
    if (v.norm() > 1e-12) return v.normalized();
  }
}

// N forces with directions uniform on the sphere and |f_i| = magnitude (Sec. 3.1.1: 100).
inline std::vector<sc::Vec3> random_forces(std::size_t n, double magnitude, std::mt19937_64& rng) {
  std::vector<sc::Vec3> f(n);
  for (sc::Vec3& v : f) v = magnitude * random_unit_vector(rng);
  return f;
}

namespace detail {

inline std::vector<sc::Pose> poses_at(const sc::Mat3X& centres) {
  std::vector<sc::Pose> poses(static_cast<std::size_t>(centres.cols()));
  for (Eigen::Index i = 0; i < centres.cols(); ++i)
    poses[static_cast<std::size_t>(i)] = {sc::Vec3(centres.col(i)), sc::Quat::Identity()};
  return poses;
}

// Fills min_gap and checks the packing is contact free; throws otherwise (a bug, not bad luck).
inline SpherePacking finished(const sc::Mat3X& centres, double side, const char* generator) {
  SpherePacking p;
  p.poses = poses_at(centres);
  p.side = side;
  p.phi = static_cast<double>(centres.cols()) * (4.0 / 3.0) * std::numbers::pi / (side * side * side);
  p.min_gap = sc::minimum_pair_distance(sc::Sphere{1.0}, std::span<const sc::Pose>(p.poses)).distance;
  if (!(p.min_gap > 0.0))
    throw std::runtime_error(std::string(generator) + ": packing not contact free, min gap " +
                             std::to_string(p.min_gap));
  return p;
}

}  // namespace detail

// Random sequential addition of n unit spheres at packing fraction phi (O(N^2) checks; meant
// for N ~ 1e3 well below RSA jamming). Throws after max_attempts rejected draws in a row.
inline SpherePacking random_sequential_addition(std::size_t n, double phi, std::uint64_t seed,
                                                int max_attempts = 1000000) {
  if (n < 2) throw std::invalid_argument("random_sequential_addition: n must be >= 2");
  if (!(phi > 0.0 && phi < 0.38))
    throw std::invalid_argument("random_sequential_addition: phi must lie in (0, 0.38), got " + std::to_string(phi));
  const double side = cube_side(n, phi);
  std::mt19937_64 rng(seed);
  sc::Mat3X centres(3, static_cast<Eigen::Index>(n));
  Eigen::Index placed = 0;
  for (int attempt = 0; placed < centres.cols(); ++attempt) {
    if (attempt == max_attempts)
      throw std::runtime_error("random_sequential_addition: jammed after " + std::to_string(placed) +
                               " spheres, seed " + std::to_string(seed));
    const sc::Vec3 x = uniform_in_cube(rng, side);
    // Unit spheres overlap when their centres are closer than 2.
    if (placed > 0 && ((centres.leftCols(placed).colwise() - x).colwise().squaredNorm().minCoeff() <= 4.0)) continue;
    centres.col(placed++) = x;
    attempt = -1;
  }
  return detail::finished(centres, side, "random_sequential_addition");
}

struct DensePackingOptions {
  double phi_start = 0.30;        // uniform random centres at this density, relaxed first
  int stages = 10;                // compression stages from phi_start to the target
  double skin = 5e-4;             // relax radius 1 + skin: final gaps ~>= 2 skin
  int max_relax_iterations = 20000;  // FIRE steps per stage
};

namespace detail {

// Minimum-image separation x_i - x_j in a periodic cube.
inline sc::Vec3 minimum_image(const sc::Vec3& d, double side) {
  return d - side * (d / side).array().round().matrix();
}

// Forces -grad of the harmonic overlap energy at diameter sigma; returns the largest overlap.
inline double overlap_forces(const sc::Mat3X& x, double sigma, double side, sc::CellList& cells, sc::Mat3X& force) {
  force.setZero(3, x.cols());
  double worst = 0.0;
  const sc::PeriodicBox box{sc::Vec3::Constant(side)};
  for (const sc::BodyPair& p : cells.find_pairs(x, 0.5 * sigma, 0.0, box)) {
    const sc::Vec3 d = minimum_image(x.col(p.i) - x.col(p.j), side);
    const double r = d.norm();
    const double overlap = sigma - r;
    if (!(overlap > 0.0) || r == 0.0) continue;
    worst = std::max(worst, overlap);
    const sc::Vec3 f = overlap / r * d;
    force.col(p.i) += f;
    force.col(p.j) -= f;
  }
  return worst;
}

// FIRE minimisation of the overlap energy at diameter sigma until the largest overlap is below
// tolerance. Positions stay wrapped into [0, side)^3. Returns false if it does not get there.
inline bool relax_overlaps(sc::Mat3X& x, double sigma, double side, double tolerance, int max_iterations) {
  constexpr double kDtStart = 0.02, kDtMax = 0.2, kIncrease = 1.1, kDecrease = 0.5, kAlphaStart = 0.1,
                   kAlphaShrink = 0.99;
  constexpr int kDelay = 5;
  const sc::PeriodicBox box{sc::Vec3::Constant(side)};
  sc::CellList cells;
  sc::Mat3X v = sc::Mat3X::Zero(3, x.cols()), f;
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
    for (Eigen::Index i = 0; i < x.cols(); ++i) x.col(i) = sc::wrap_into_box(sc::Vec3(x.col(i)), box);
  }
  return false;
}

}  // namespace detail

// A near-jammed packing of n unit spheres, compressed towards phi_target (see the top).
// The result's phi is what was reached: phi_target, or the last stage that relaxed.
inline SpherePacking dense_packing(std::size_t n, double phi_target, std::uint64_t seed,
                                   const DensePackingOptions& options = {}) {
  if (n < 2) throw std::invalid_argument("dense_packing: n must be >= 2");
  if (!(phi_target > 0.0 && phi_target < 0.74))
    throw std::invalid_argument("dense_packing: phi must lie in (0, 0.74), got " + std::to_string(phi_target));
  if (!(options.skin > 0.0) || options.stages < 1 || options.max_relax_iterations < 1)
    throw std::invalid_argument("dense_packing: skin must be > 0, stages and max_relax_iterations >= 1");
  const double sigma = 2.0 * (1.0 + options.skin);  // enlarged diameter
  const double tolerance = 0.1 * options.skin;      // leftover overlap: gaps >= 1.9 skin
  const double phi_start = std::min(options.phi_start, phi_target);
  std::mt19937_64 rng(seed);
  double side = cube_side(n, phi_start);
  sc::Mat3X x(3, static_cast<Eigen::Index>(n));
  for (Eigen::Index i = 0; i < x.cols(); ++i) x.col(i) = uniform_in_cube(rng, side);
  if (!detail::relax_overlaps(x, sigma, side, tolerance, options.max_relax_iterations))
    throw std::runtime_error("dense_packing: could not relax the start at phi " + std::to_string(phi_start));
  for (int stage = 1; stage <= options.stages; ++stage) {
    const double phi = phi_start + (phi_target - phi_start) * stage / options.stages;
    const double next_side = cube_side(n, phi);
    sc::Mat3X trial = x * (next_side / side);  // affine compression
    if (!detail::relax_overlaps(trial, sigma, next_side, tolerance, options.max_relax_iterations)) break;
    x = std::move(trial);
    side = next_side;
  }
  return detail::finished(x, side, "dense_packing");
}

}  // namespace examples
