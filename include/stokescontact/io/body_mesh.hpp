#pragma once
// Closed triangle meshes of the shapes' true surfaces, for visualisation (io/vtk_polydata.hpp).
// A shape is the set of points within `radius` of its centre curve (geometry/shapes.hpp), so
// its surface is a tube of that radius swept along the curve and closed by a hemisphere at
// each free end; a sphere (a curve of one point) is the two hemispheres alone, a UV sphere.
//
// The curve is sampled at its segments' ends and along each arc; each sample carries a ring
// of `ring_points` vertices in the plane normal to the curve, in a frame carried from sample
// to sample by the smallest rotation taking one tangent to the next (a rotation-minimising,
// parallel-transported frame: the rings do not twist through a bend). Each cap adds
// `cap_rings - 1` latitude rings between its pole and the end ring. Every vertex lies exactly
// (to rounding) one radius from the centre curve, triangles are oriented counter-clockwise
// seen from outside, and the mesh is closed. With M = ring_points, L = cap_rings and K curve
// samples (1 for a sphere, 2 for a rod, arc_pieces + 3 for a boomerang with arms), there are
// R = 2 (L - 1) + K rings, M R + 2 vertices and 2 M R triangles.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <string>
#include <vector>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/geometry/shapes.hpp"

namespace stokescontact {

struct BodyMeshOptions {
  int ring_points = 16;  // vertices around each ring, >= 3
  int cap_rings = 8;     // latitude bands from a cap's pole to its end ring, >= 1
  int arc_pieces = 0;    // tube pieces along each arc; 0: one per pi / ring_points of angle (>= 2)
};

inline void validate(const BodyMeshOptions& o) {
  if (o.ring_points < 3)
    fail_argument("BodyMeshOptions.ring_points", "must be >= 3, got " + std::to_string(o.ring_points));
  if (o.cap_rings < 1)
    fail_argument("BodyMeshOptions.cap_rings", "must be >= 1, got " + std::to_string(o.cap_rings));
  if (o.arc_pieces < 0)
    fail_argument("BodyMeshOptions.arc_pieces", "must be >= 0, got " + std::to_string(o.arc_pieces));
}

struct BodyMesh {
  std::vector<Vec3> vertices;
  std::vector<Vec3> normals;  // outward unit normal at each vertex (exact, not from the facets)
  std::vector<std::array<std::size_t, 3>> triangles;  // counter-clockwise seen from outside
};

namespace detail {

struct TubeSample {
  Vec3 centre;
  Vec3 tangent;
};

inline int arc_piece_count(const Arc& arc, const BodyMeshOptions& o) {
  if (o.arc_pieces > 0) return o.arc_pieces;
  const double step = std::numbers::pi / o.ring_points;
  return std::max(2, static_cast<int>(std::ceil(arc.angle / step - 1e-9)));
}

// The curve's samples in order: segment, arc, segment, ... (as the shapes build them); a
// sample within `merge` of the previous one (a join, a zero-length piece) is dropped.
template <std::size_t NS, std::size_t NA>
std::vector<TubeSample> tube_samples(const CentreCurve<NS, NA>& curve, double merge, const BodyMeshOptions& o) {
  static_assert(NS == NA + 1, "body_mesh: a centre curve must run segment, arc, segment, ..., segment");
  std::vector<TubeSample> samples;
  const auto add = [&](const Vec3& c, const Vec3& t) {
    if (samples.empty() || (c - samples.back().centre).norm() > merge) samples.push_back({c, t});
  };
  for (std::size_t i = 0; i < NS; ++i) {
    const Segment& s = curve.segments[i];
    if (s.length() > merge) {
      const Vec3 t = (s.p1 - s.p0).normalized();
      add(s.p0, t);
      add(s.p1, t);
    }
    if constexpr (NA > 0) {
      if (i < NA) {
        const Arc& a = curve.arcs[i];
        const int pieces = arc_piece_count(a, o);
        for (int k = 0; k <= pieces; ++k) {
          const double t = a.angle * k / pieces;
          add(a.point(t), a.tangent(t));
        }
      }
    }
  }
  if (samples.empty()) samples.push_back({curve.segments[0].p0, Vec3::UnitZ()});  // a sphere
  return samples;
}

// A unit vector normal to t: the coordinate axis least aligned with t, made orthogonal.
inline Vec3 some_normal(const Vec3& t) {
  Eigen::Index axis = 0;
  t.cwiseAbs().minCoeff(&axis);
  const Vec3 e = Vec3::Unit(axis);
  return (e - e.dot(t) * t).normalized();
}

}  // namespace detail

// The mesh of `shape` in its body frame (the origin at the centre of mass).
template <Shape S>
BodyMesh body_mesh(const S& shape, const BodyMeshOptions& options = {}) {
  validate(shape);
  validate(options);
  const double r = shape.radius;
  const std::vector<detail::TubeSample> samples = detail::tube_samples(centre_curve(shape), 1e-9 * r, options);
  const std::size_t m = static_cast<std::size_t>(options.ring_points);
  const int caps = options.cap_rings;

  // Frames (n, b, t), right-handed, carried along the samples by the minimal rotations.
  std::vector<Vec3> n(samples.size()), b(samples.size());
  n[0] = detail::some_normal(samples[0].tangent);
  for (std::size_t k = 1; k < samples.size(); ++k) {
    const Vec3& t = samples[k].tangent;
    const Vec3 carried = Quat::FromTwoVectors(samples[k - 1].tangent, t) * n[k - 1];
    n[k] = (carried - carried.dot(t) * t).normalized();
  }
  for (std::size_t k = 0; k < samples.size(); ++k) b[k] = samples[k].tangent.cross(n[k]);

  BodyMesh mesh;
  const auto add_vertex = [&](const Vec3& centre, const Vec3& normal) {
    mesh.vertices.push_back(centre + r * normal);
    mesh.normals.push_back(normal);
  };
  // A ring about sample k: normal = axial t + radial (cos theta n + sin theta b).
  const auto add_ring = [&](std::size_t k, double axial, double radial) {
    for (std::size_t j = 0; j < m; ++j) {
      const double theta = 2.0 * std::numbers::pi * static_cast<double>(j) / static_cast<double>(m);
      add_vertex(samples[k].centre,
                 axial * samples[k].tangent + radial * (std::cos(theta) * n[k] + std::sin(theta) * b[k]));
    }
  };
  const auto latitude = [&](int i) { return 0.5 * std::numbers::pi * i / caps; };  // from the pole
  const std::size_t last = samples.size() - 1;
  add_vertex(samples[0].centre, -samples[0].tangent);
  for (int i = 1; i < caps; ++i) add_ring(0, -std::cos(latitude(i)), std::sin(latitude(i)));
  for (std::size_t k = 0; k < samples.size(); ++k) add_ring(k, 0.0, 1.0);
  for (int i = caps - 1; i >= 1; --i) add_ring(last, std::cos(latitude(i)), std::sin(latitude(i)));
  add_vertex(samples[last].centre, samples[last].tangent);

  const std::size_t rings = (mesh.vertices.size() - 2) / m, end_pole = mesh.vertices.size() - 1;
  const auto v = [m](std::size_t ring, std::size_t j) { return 1 + ring * m + j % m; };
  mesh.triangles.reserve(2 * m * rings);
  for (std::size_t j = 0; j < m; ++j) mesh.triangles.push_back({0, v(0, j + 1), v(0, j)});
  for (std::size_t q = 0; q + 1 < rings; ++q)
    for (std::size_t j = 0; j < m; ++j) {
      mesh.triangles.push_back({v(q, j), v(q, j + 1), v(q + 1, j + 1)});
      mesh.triangles.push_back({v(q, j), v(q + 1, j + 1), v(q + 1, j)});
    }
  for (std::size_t j = 0; j < m; ++j) mesh.triangles.push_back({v(rings - 1, j), v(rings - 1, j + 1), end_pole});
  return mesh;
}

// The body-frame mesh moved to `pose` (vertices and normals; the triangles are shared).
inline BodyMesh posed(const BodyMesh& body, const Pose& pose) {
  BodyMesh world = body;
  for (Vec3& p : world.vertices) p = pose.to_world(p);
  for (Vec3& d : world.normals) d = pose.direction_to_world(d);
  return world;
}

}  // namespace stokescontact
