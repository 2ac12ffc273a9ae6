#pragma once
// Sphere shells of 12, 42, 162 and 642 blobs: the vertices of an icosahedron and of its
// recursive subdivisions (each edge split at its midpoint, new vertices projected onto
// the sphere), geometric radius R_g, blob radius half the shortest blob-blob distance.
// These are the shells of the RigidMultiblobsWall "Structures" files (Usabiaga et al.,
// CAMCOS 2016); for R_g = 1 the shortest distances are 1.051462, 0.546533,
// 0.275904, 0.138283 and the published translational hydrodynamic radii
// R_h / R_g = 1.2625, 1.1220, 1.0530, 1.0239.
//
// sphere_shell(n, a) returns the shell scaled so that its translational hydrodynamic
// radius 1 / (6 pi eta M_tt) is a, to the 12 digits of the ratios in kShellRadii, which
// this library computed itself (RPY with the overlap branch, N = (K^T M^-1 K)^-1) and
// checks in its tests against the published four digits (they agree within 5.3e-5; the
// 12-blob 1.2625 matches 1 / 0.7921 = 1.26247, the R_g of the published R_h = 1 file).
// The rotational radius (1 / (8 pi eta M_rr))^(1/3) is then a little smaller than a: the
// blob cloud is not a sphere. No published rotational radii were found; ours are listed.
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "stokescontact/mobility/blob_model.hpp"

namespace stokescontact {

// One row per shell: blob count and the hydrodynamic radii over R_g: published (translation, four digits) and ours (free of eta and scale).
struct ShellRadii {
  int blobs = 0;
  double published_translational = 0.0;  // R_h / R_g, RigidMultiblobsWall file names
  double translational = 0.0;            // 1 / (6 pi eta M_tt R_g)
  double rotational = 0.0;               // (1 / (8 pi eta M_rr))^(1/3) / R_g
};

inline constexpr std::array<ShellRadii, 4> kShellRadii{{
    {12, 1.2625, 1.262447338247, 1.231344505749},
    {42, 1.1220, 1.122022087759, 1.101902319662},
    {162, 1.0530, 1.052965080502, 1.047197159128},
    {642, 1.0239, 1.023939840591, 1.022655910447},
}};

inline const ShellRadii& shell_hydrodynamic_radii(int blobs) {
  for (const ShellRadii& row : kShellRadii)
    if (row.blobs == blobs) return row;
  fail_argument("blobs", "a sphere shell has 12, 42, 162 or 642 blobs, got " + std::to_string(blobs));
}

namespace detail {

// Unit icosahedron (vertices the cyclic permutations of (0, +-1, +-phi)) subdivided
// `levels` times; 10 * 4^levels + 2 vertices.
inline std::vector<Vec3> icosphere_vertices(int levels) {
  const double phi = 0.5 * (1.0 + std::sqrt(5.0));
  std::vector<Vec3> v;
  for (double s1 : {-1.0, 1.0})
    for (double s2 : {-phi, phi}) {
      v.emplace_back(0.0, s1, s2);
      v.emplace_back(s1, s2, 0.0);
      v.emplace_back(s2, 0.0, s1);
    }
  // Faces: the triples of mutually adjacent vertices (edge length 2 before projection).
  std::vector<std::array<int, 3>> faces;
  const auto adjacent = [&](int i, int j) { return std::abs((v[i] - v[j]).norm() - 2.0) < 1e-9; };
  for (int i = 0; i < 12; ++i)
    for (int j = i + 1; j < 12; ++j)
      for (int k = j + 1; k < 12; ++k)
        if (adjacent(i, j) && adjacent(j, k) && adjacent(i, k)) faces.push_back({i, j, k});
  for (Vec3& p : v) p.normalize();
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoint;  // edge -> new vertex
    const auto split = [&](int i, int j) {
      const std::pair<int, int> key = std::minmax(i, j);
      auto [it, inserted] = midpoint.try_emplace(key, static_cast<int>(v.size()));
      if (inserted) v.push_back((v[i] + v[j]).normalized());
      return it->second;
    };
    std::vector<std::array<int, 3>> finer;
    finer.reserve(4 * faces.size());
    for (const auto& [a, b, c] : faces) {
      const int ab = split(a, b), bc = split(b, c), ca = split(c, a);
      finer.push_back({a, ab, ca});
      finer.push_back({b, bc, ab});
      finer.push_back({c, ca, bc});
      finer.push_back({ab, bc, ca});
    }
    faces = std::move(finer);
  }
  return v;
}

inline double shortest_distance(const Mat3X& x) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < x.cols(); ++i)
    for (Eigen::Index j = i + 1; j < x.cols(); ++j) best = std::min(best, (x.col(i) - x.col(j)).norm());
  return best;
}

}  // namespace detail

// The shell of `blobs` blobs on a sphere of geometric radius `geometric_radius`.
inline BlobModel sphere_shell_geometric(int blobs, double geometric_radius) {
  shell_hydrodynamic_radii(blobs);  // validates the count
  require_positive(geometric_radius, "geometric_radius");
  int levels = 0;
  while (10 * (1 << (2 * levels)) + 2 != blobs) ++levels;
  const std::vector<Vec3> unit = detail::icosphere_vertices(levels);
  BlobModel model;
  model.name = "shell_" + std::to_string(blobs);
  model.positions.resize(3, static_cast<Eigen::Index>(unit.size()));
  for (std::size_t i = 0; i < unit.size(); ++i)
    model.positions.col(static_cast<Eigen::Index>(i)) = geometric_radius * unit[i];
  model.blob_radius = 0.5 * detail::shortest_distance(model.positions);
  return model;
}

// The shell whose translational hydrodynamic radius is `hydrodynamic_radius`.
inline BlobModel sphere_shell(int blobs, double hydrodynamic_radius) {
  require_positive(hydrodynamic_radius, "hydrodynamic_radius");
  const ShellRadii& radii = shell_hydrodynamic_radii(blobs);
  return sphere_shell_geometric(blobs, hydrodynamic_radius / radii.translational);
}

}  // namespace stokescontact
