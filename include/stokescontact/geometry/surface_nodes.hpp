#pragma once
// Quasi-uniform surface nodes of a shape in its body frame, at a chosen spacing h: the
// discretised surfaces whose nodes give the surface distances d^S (Broms Sec. 2.1, 3.2.1,
// 3.3.1). Upsampling = the same construction at spacing h / factor.
//
// Placement: every shape is a tube of radius R about its centre curve, closed by
// hemispherical caps (a sphere is two caps about a point).
//  - Tube (arms and bend): n_psi = 2 round(pi R / h) lines of constant angle psi around the
//    tube, psi_k = 2 pi (k + 1/2) / n_psi, in a frame (N, B) carried along the curve (on
//    the bend N points away from the bend's centre). Each line is a curve on the surface
//    of length Lambda(psi) = sum over straight pieces of their length plus, on the bend,
//    (R_b + R cos psi) times its angle; it gets round(Lambda / h) nodes at equal arclength,
//    offset by half a step from both ends. On the bend this puts nodes in proportion to
//    the local circumference, so the inner side of a horn torus (R_b = R) is not crowded.
//  - Caps: a pole node and latitude rings at meridian distance j delta from the pole, the
//    last half a step delta/2 short of the cap's rim, each with round(2 pi R sin(theta)/h)
//    nodes; a sphere has rings j pi/m, poles included.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <string>
#include <vector>

#include "stokescontact/geometry/shapes.hpp"

namespace stokescontact {

// A spacing that would give more nodes than this (estimated as area / h^2) is refused.
inline constexpr double kMaxSurfaceNodes = 4.0e6;

struct SurfaceNodes {
  Mat3X points;         // body frame, on the surface
  Mat3X normals;        // outward unit normals
  Mat3X curve_points;   // the centre-curve point each node lies over:
                        // points = curve_points + radius * normals
  double spacing = 0.0; // the h the nodes were placed at

  Eigen::Index size() const { return points.cols(); }
};

inline double surface_area(const Sphere& s) { return 4.0 * std::numbers::pi * s.radius * s.radius; }

inline double surface_area(const Spherocylinder& s) {
  return 2.0 * std::numbers::pi * s.radius * (s.length + 2.0 * s.radius);
}

// Two cylinders, a sphere from the two caps and a quarter torus (Pappus: 2 pi R times the
// length pi R_b / 2 of the bend's centre line).
inline double surface_area(const Boomerang& b) {
  const double pi = std::numbers::pi;
  return 2.0 * pi * b.radius * (2.0 * b.arm_length + 2.0 * b.radius + 0.5 * pi * b.bend_radius);
}

namespace detail {

struct NodeBuilder {
  double radius;
  std::vector<Vec3> points, normals, curve;

  void add(const Vec3& c, const Vec3& n) {
    curve.push_back(c);
    normals.push_back(n);
    points.push_back(c + radius * n);
  }

  SurfaceNodes finish(double spacing) const {
    SurfaceNodes out;
    const auto n = static_cast<Eigen::Index>(points.size());
    out.points.resize(3, n);
    out.normals.resize(3, n);
    out.curve_points.resize(3, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      out.points.col(i) = points[k];
      out.normals.col(i) = normals[k];
      out.curve_points.col(i) = curve[k];
    }
    out.spacing = spacing;
    return out;
  }
};

inline int rounded_count(double x) { return static_cast<int>(std::lround(x)); }

// One latitude ring at polar angle theta about `pole`, frame (e1, e2) across it; rings
// alternate by half an azimuthal step so that neighbouring rings interlock.
inline void add_ring(NodeBuilder& nb, const Vec3& centre, const Vec3& pole, const Vec3& e1,
                     const Vec3& e2, double theta, int ring_index, double h) {
  const double pi = std::numbers::pi;
  const double st = std::sin(theta), ct = std::cos(theta);
  const int n = std::max(1, rounded_count(2.0 * pi * nb.radius * st / h));
  if (n == 1 && st < 0.5 * h / nb.radius) {  // a pole, or a ring too small to split
    nb.add(centre, (ct * pole + st * e1).normalized());
    return;
  }
  const double shift = 0.5 * static_cast<double>(ring_index % 2);
  for (int i = 0; i < n; ++i) {
    const double phi = 2.0 * pi * (static_cast<double>(i) + shift) / n;
    nb.add(centre, ct * pole + st * (std::cos(phi) * e1 + std::sin(phi) * e2));
  }
}

// Hemispherical cap about `centre`, outward axis `pole`, rim frame (e1, e2).
inline void add_cap(NodeBuilder& nb, const Vec3& centre, const Vec3& pole, const Vec3& e1,
                    const Vec3& e2, double h) {
  const double quarter = 0.5 * std::numbers::pi * nb.radius;  // pole-to-rim meridian
  const int m = std::max(0, rounded_count(quarter / h - 0.5));
  const double delta = quarter / (m + 0.5);                   // rim ring delta/2 short
  for (int j = 0; j <= m; ++j) add_ring(nb, centre, pole, e1, e2, j * delta / nb.radius, j, h);
}

// Whole sphere about `centre`: m + 1 rings at theta_j = j pi / m, both poles included.
inline void add_sphere(NodeBuilder& nb, const Vec3& centre, double h) {
  const double pi = std::numbers::pi;
  const int m = std::max(2, rounded_count(pi * nb.radius / h));
  for (int j = 0; j <= m; ++j)
    add_ring(nb, centre, Vec3::UnitZ(), Vec3::UnitX(), Vec3::UnitY(), j * pi / m, j, h);
}

// A piece of the tube: a segment with fixed frame vector N, or an arc whose N points away
// from its centre, N(t) = cos t e1 + sin t e2. B is common to the whole tube.
struct TubePiece {
  bool is_arc = false;
  Segment segment;
  Vec3 n = Vec3::UnitX();
  Arc arc;

  // Length of the line at angle psi over this piece.
  double line_length(double radius, double cos_psi) const {
    return is_arc ? (arc.radius + radius * cos_psi) * arc.angle : segment.length();
  }
  // Curve point and N at fraction f in [0, 1] along the piece.
  void locate(double f, Vec3& c, Vec3& frame_n) const {
    if (!is_arc) {
      c = segment.point(f);
      frame_n = n;
      return;
    }
    const double t = f * arc.angle;
    c = arc.point(t);
    frame_n = std::cos(t) * arc.e1 + std::sin(t) * arc.e2;
  }
};

template <std::size_t K>
void add_tube(NodeBuilder& nb, const std::array<TubePiece, K>& pieces, const Vec3& b, double h) {
  const double pi = std::numbers::pi;
  // An even count keeps every line off psi = pi, the inner side that a horn torus pinches
  // to a single point where the normal is undefined.
  const int lines = 2 * std::max(2, rounded_count(pi * nb.radius / h));
  for (int k = 0; k < lines; ++k) {
    const double psi = 2.0 * pi * (k + 0.5) / lines;
    const double cp = std::cos(psi), sp = std::sin(psi);
    std::array<double, K> len{};
    double total = 0.0;
    for (std::size_t p = 0; p < K; ++p) total += len[p] = pieces[p].line_length(nb.radius, cp);
    const int n = rounded_count(total / h);
    std::size_t p = 0;
    double start = 0.0;  // arclength where piece p begins on this line
    for (int i = 0; i < n; ++i) {
      const double u = (i + 0.5) * total / n;
      while (p + 1 < K && u >= start + len[p]) start += len[p++];
      const double f = len[p] > 0.0 ? std::min(1.0, (u - start) / len[p]) : 0.0;
      Vec3 c, frame_n;
      pieces[p].locate(f, c, frame_n);
      nb.add(c, cp * frame_n + sp * b);
    }
  }
}

inline void require_node_budget(double area, double h) {
  require_positive(h, "spacing");
  const double estimate = area / (h * h);
  if (estimate > kMaxSurfaceNodes)
    fail_argument("spacing", "h = " + std::to_string(h) + " would give about " +
                                 std::to_string(static_cast<long long>(estimate)) +
                                 " surface nodes, more than the limit of 4e6; use a larger h");
}

}  // namespace detail

inline SurfaceNodes surface_nodes(const Sphere& s, double spacing) {
  validate(s);
  detail::require_node_budget(surface_area(s), spacing);
  detail::NodeBuilder nb{s.radius, {}, {}, {}};
  detail::add_sphere(nb, Vec3::Zero(), spacing);
  return nb.finish(spacing);
}

inline SurfaceNodes surface_nodes(const Spherocylinder& s, double spacing) {
  validate(s);
  detail::require_node_budget(surface_area(s), spacing);
  detail::NodeBuilder nb{s.radius, {}, {}, {}};
  const Segment axis = centre_curve(s).segments[0];
  const Vec3 ex = Vec3::UnitX(), ey = Vec3::UnitY(), ez = Vec3::UnitZ();
  detail::add_cap(nb, axis.p0, -ez, ex, ey, spacing);
  detail::add_tube(nb, std::array<detail::TubePiece, 1>{{{false, axis, ex, {}}}}, ey, spacing);
  detail::add_cap(nb, axis.p1, ez, ex, ey, spacing);
  return nb.finish(spacing);
}

// Tube frame: N(t) = cos t e1 + sin t e2 on the bend, its end values on the arms; B the
// bend's axis. Caps point along the bend's end tangents (defined even for zero-length arms).
inline SurfaceNodes surface_nodes(const Boomerang& b, double spacing) {
  validate(b);
  detail::require_node_budget(surface_area(b), spacing);
  detail::NodeBuilder nb{b.radius, {}, {}, {}};
  const auto curve = centre_curve(b);
  const Arc& bend = curve.arcs[0];
  const Vec3 n0 = bend.e1;
  const Vec3 n1 = std::cos(bend.angle) * bend.e1 + std::sin(bend.angle) * bend.e2;
  const Vec3 axis = bend.axis();
  const std::array<detail::TubePiece, 3> pieces{{{false, curve.segments[0], n0, {}},
                                                 {true, {}, {}, bend},
                                                 {false, curve.segments[1], n1, {}}}};
  detail::add_cap(nb, curve.segments[0].p0, -bend.tangent(0.0), n0, axis, spacing);
  detail::add_tube(nb, pieces, axis, spacing);
  detail::add_cap(nb, curve.segments[1].p1, bend.tangent(bend.angle), n1, axis, spacing);
  return nb.finish(spacing);
}

// The node budget of contact_node_spacing: the finest spacing it picks gives about this many
// nodes per shape (area / h^2).
inline constexpr double kContactNodeBudget = 1.0e5;

// The surface-node spacing for contact directions d^S (Broms eq. 22-23) that resolves a gap of
// d_hat. The d^S pairs are the nodes of one body against the other body's exact surface, so
// a node at lateral offset x from the true closest point sits farther than d^P by the sagitta
// of the two surfaces, about x^2 / (2 R_rel), 1 / R_rel = 1 / R_a + 1 / R_b <= 2 / R for
// tubes of radius R; the nearest node has x <= h / 2, an error of at most h^2 / (4 R). Only
// node pairs within d_try (>= d_hat) join a contact, and their distances weight its force:
// when that error is comparable to d_hat the only pair near the contact is the d^P pair, the
// force is d^P's single direction (interlocked boomerangs at gap 0.01 with h = R / 2 were held
// by 80x the push they resisted). So h^2 / (4 R) <= d_hat / 4, h = sqrt(R d_hat), never coarser
// than half the radius (the tube then still has >= 12 lines around it), never so fine that the
// node count exceeds kContactNodeBudget (then the error is above d_hat / 4: very small d_hat).
template <Shape S>
double contact_node_spacing(const S& shape, double d_hat) {
  require_positive(d_hat, "d_hat");
  const double resolving = std::sqrt(shape.radius * d_hat);
  const double budget = std::sqrt(surface_area(shape) / kContactNodeBudget);
  return std::max(budget, std::min(0.5 * shape.radius, resolving));
}

// Upsampled nodes: the same construction at spacing h / factor, factor >= 1.
template <Shape S>
SurfaceNodes upsampled_surface_nodes(const S& shape, double spacing, int factor) {
  if (factor < 1) fail_argument("factor", "must be >= 1, got " + std::to_string(factor));
  require_positive(spacing, "spacing");
  return surface_nodes(shape, spacing / factor);
}

}  // namespace stokescontact
