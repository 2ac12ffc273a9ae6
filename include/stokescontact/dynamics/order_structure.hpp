#pragma once
// Where the orientational order of rods lies in a periodic box. The nematic order S
// (nematic_order.hpp) is one number for the whole box: an intermediate S (0.3-0.5 for L/D = 5)
// can be a uniform, weakly ordered state or ordered and disordered regions side by side
// (coexistence across the isotropic-nematic transition, or domains left by a quench). The two
// measures below tell them apart on a saved state. u_i is rod i's axis (body z in the world
// frame, as in nematic_order.hpp), P2(c) = (3 c^2 - 1) / 2.
//
//   slab_order_profile: the box cut into `slabs` equal slabs across box axis `axis` (0, 1, 2:
//     x, y, z); per slab, the mean of P2(n . u_i) over the rods whose centres, wrapped into the
//     box, lie in it, n the director given (normalised here). A uniform nematic of order S
//     gives about S in every slab (each slab's mean carries the noise of its rods); coexisting
//     regions give slabs near the nematic S and slabs near 0. An empty slab's mean is NaN.
//   orientational_correlation: g2 over shells of centre distance r (minimum image),
//     g2(r_a, r_b] = the mean of P2(u_i . u_j) over the pairs i < j with r_a < r_ij <= r_b,
//     for consecutive `edges` r_a < r_b. It tends to S^2 beyond the range of local order in a
//     uniform nematic of order S and to 0 in an isotropic suspension; it is invariant under a
//     common rotation of the rods and a shift of every centre. Every pair is visited: O(N^2),
//     for analysing saved states of thousands of rods, not for use inside a time step. An
//     empty shell's mean is NaN. Shells beyond half the shortest box side count a pair once,
//     at its nearest image, so they are not full spherical shells.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/core/types.hpp"
#include "stokescontact/geometry/periodic_box.hpp"

namespace stokescontact {

struct SlabOrderProfile {
  std::vector<double> order;      // the mean of P2(n . u_i) per slab, NaN where empty
  std::vector<std::size_t> rods;  // rods per slab
};

struct OrientationalCorrelation {
  std::vector<double> g2;          // per shell (edges[k], edges[k + 1]], NaN where empty
  std::vector<std::size_t> pairs;  // pairs per shell
};

namespace detail {

inline double legendre_p2(double c) { return 1.5 * c * c - 0.5; }

inline void validate_order_input(std::span<const Pose> poses, const PeriodicBox& box) {
  if (poses.empty()) fail_argument("poses", "must hold at least one body");
  validate(poses);
  for (int k = 0; k < 3; ++k) require_positive(box.lengths[k], "box.lengths[" + std::to_string(k) + "]");
}

}  // namespace detail

inline SlabOrderProfile slab_order_profile(std::span<const Pose> poses, const PeriodicBox& box, const Vec3& director,
                                           int axis, int slabs) {
  detail::validate_order_input(poses, box);
  require_finite(director, "director");
  const double norm = director.norm();
  if (!(norm > 0.0)) fail_argument("director", "must be nonzero");
  if (axis < 0 || axis > 2) fail_argument("axis", "must be 0, 1 or 2 (x, y, z), got " + std::to_string(axis));
  if (slabs < 1) fail_argument("slabs", "must be >= 1, got " + std::to_string(slabs));
  const Vec3 n = director / norm;
  const double length = box.lengths[axis];
  std::vector<double> sum(static_cast<std::size_t>(slabs), 0.0);
  SlabOrderProfile out{{}, std::vector<std::size_t>(static_cast<std::size_t>(slabs), 0)};
  for (const Pose& p : poses) {
    const double x = wrap_coordinate(p.x[axis], length);  // in [0, length)
    const auto slab = std::min(static_cast<std::size_t>(x / length * slabs), static_cast<std::size_t>(slabs - 1));
    sum[slab] += detail::legendre_p2(n.dot(p.rotation().col(2)));
    ++out.rods[slab];
  }
  out.order.resize(sum.size());
  for (std::size_t s = 0; s < sum.size(); ++s)
    out.order[s] = out.rods[s] ? sum[s] / static_cast<double>(out.rods[s]) : std::numeric_limits<double>::quiet_NaN();
  return out;
}

inline OrientationalCorrelation orientational_correlation(std::span<const Pose> poses, const PeriodicBox& box,
                                                          std::span<const double> edges) {
  detail::validate_order_input(poses, box);
  if (edges.size() < 2) fail_argument("edges", "must hold at least two distances, got " + std::to_string(edges.size()));
  require_non_negative(edges[0], "edges[0]");
  for (std::size_t k = 1; k < edges.size(); ++k) {
    require_finite(edges[k], "edges[" + std::to_string(k) + "]");
    if (!(edges[k] > edges[k - 1]))
      fail_argument("edges", "must increase strictly, got " + std::to_string(edges[k]) + " after " +
                                 std::to_string(edges[k - 1]) + " at entry " + std::to_string(k));
  }
  const std::size_t shells = edges.size() - 1;
  std::vector<Vec3> axes(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) axes[i] = poses[i].rotation().col(2);
  std::vector<double> sum(shells, 0.0);
  OrientationalCorrelation out{{}, std::vector<std::size_t>(shells, 0)};
  const std::optional<PeriodicBox> periodic = box;
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (std::size_t j = i + 1; j < poses.size(); ++j) {
      const Vec3 xj = poses[j].x + minimum_image_shift(poses[i].x, poses[j].x, periodic);
      const double r = (xj - poses[i].x).norm();
      if (!(r > edges.front()) || r > edges.back()) continue;
      std::size_t shell = 0;
      while (r > edges[shell + 1]) ++shell;
      sum[shell] += detail::legendre_p2(axes[i].dot(axes[j]));
      ++out.pairs[shell];
    }
  out.g2.resize(shells);
  for (std::size_t s = 0; s < shells; ++s)
    out.g2[s] = out.pairs[s] ? sum[s] / static_cast<double>(out.pairs[s]) : std::numeric_limits<double>::quiet_NaN();
  return out;
}

}  // namespace stokescontact
