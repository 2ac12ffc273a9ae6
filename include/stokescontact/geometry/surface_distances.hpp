#pragma once
// Surface-node-to-surface distances d^S of a particle pair (Broms Sec. 2.1, 3.2.1, 3.3.1):
// each surface node of one body within the threshold d_try of the other body is paired
// with the point where its shortest-distance vector to the other body's centre curve cuts
// that body's surface; both directions (nodes of a against b, nodes of b against a), and
// the closest points of d^P added to the list "not to underestimate the closest distance".
// Every pair is stored in the world frame, oriented from a to b, with its signed distance:
//   point_b - point_a = distance * normal,  |normal| = 1,
// so that d^S >= d^P for all node pairs and the list feeds the columns of D (eq. 23).
#include <string_view>
#include <vector>

#include "stokescontact/geometry/closest_points.hpp"
#include "stokescontact/geometry/surface_nodes.hpp"

namespace stokescontact {

enum class PairSource {
  node_of_a,       // a surface node of body a against b's centre curve
  node_of_b,       // a surface node of body b against a's centre curve
  closest_points,  // the d^P pair from closest_points()
};

struct SurfacePair {
  PairSource source = PairSource::closest_points;
  Eigen::Index node = -1;       // index into the source body's nodes, -1 for d^P
  double distance = 0.0;        // signed surface distance, negative when overlapping
  Vec3 point_a = Vec3::Zero();  // on the surface of a (a node, or a target point)
  Vec3 point_b = Vec3::Zero();  // on the surface of b
  Vec3 normal = Vec3::UnitX();  // unit, from a to b
  Vec3 curve_point_a = Vec3::Zero();  // centre-curve point of a below point_a
  Vec3 curve_point_b = Vec3::Zero();  // centre-curve point of b below point_b
};

struct SurfaceDistances {
  std::vector<SurfacePair> pairs;  // d^P pair first (if within d_try), then a's, then b's
  ClosestPoints particle;          // d^P, always computed
};

namespace detail {

// Nodes of the source body (pose ps) against the centre curve of the other body (radius r_other):
// source point s, closest curve point c, target c + r_other (s - c) / |s - c|, distance
// |s - c| - r_other. A node exactly on the other curve (deep overlap) takes its own
// outward normal as the direction.
template <Shape Other>
void add_node_pairs(const Pose& ps, const SurfaceNodes& nodes,
                    const Other& other, const Pose& po, double d_try, bool src_is_a,
                    std::vector<SurfacePair>& out) {
  const auto curve = to_world(centre_curve(other), po);
  const double reach = bounding_radius(other) + d_try;  // farther nodes cannot qualify
  for (Eigen::Index i = 0; i < nodes.size(); ++i) {
    const Vec3 s = ps.to_world(nodes.points.col(i));
    if ((s - po.x).norm() > reach) continue;
    const CurvePoint c = closest_point(curve, s);
    const double d = c.distance - other.radius;
    if (!(d <= d_try)) continue;
    // u: unit direction from the other curve to the source node.
    const Vec3 u = c.distance > 0.0 ? Vec3((s - c.point) / c.distance)
                                    : Vec3(-ps.direction_to_world(nodes.normals.col(i)));
    const Vec3 target = c.point + other.radius * u;
    const Vec3 own_curve = ps.to_world(nodes.curve_points.col(i));
    SurfacePair p;
    p.node = i;
    p.distance = d;
    if (src_is_a) {
      p.source = PairSource::node_of_a;
      p.point_a = s, p.point_b = target, p.normal = -u;
      p.curve_point_a = own_curve, p.curve_point_b = c.point;
    } else {
      p.source = PairSource::node_of_b;
      p.point_a = target, p.point_b = s, p.normal = u;
      p.curve_point_a = c.point, p.curve_point_b = own_curve;
    }
    out.push_back(p);
  }
}

inline void require_nodes(const SurfaceNodes& n, std::string_view field) {
  if (n.normals.cols() != n.size() || n.curve_points.cols() != n.size())
    fail_argument(field, "points, normals and curve_points must have the same number of columns");
}

}  // namespace detail

// All surface pairs of bodies a and b with distance <= d_try (d_try >= 0). The nodes are
// the bodies' own body-frame surface nodes (surface_nodes(shape, h), upsampled as wanted).
template <Shape A, Shape B>
SurfaceDistances surface_distances(const A& shape_a, const Pose& pose_a, const SurfaceNodes& nodes_a,
                                   const B& shape_b, const Pose& pose_b, const SurfaceNodes& nodes_b,
                                   double d_try) {
  validate(shape_a);
  validate(shape_b);
  validate(pose_a, "pose_a");
  validate(pose_b, "pose_b");
  detail::require_nodes(nodes_a, "nodes_a");
  detail::require_nodes(nodes_b, "nodes_b");
  require_non_negative(d_try, "d_try");
  SurfaceDistances out;
  out.particle = closest_points(shape_a, pose_a, shape_b, pose_b);
  if (out.particle.distance <= d_try) {
    SurfacePair p;
    p.source = PairSource::closest_points;
    p.distance = out.particle.distance;
    p.point_a = out.particle.point_a, p.point_b = out.particle.point_b;
    p.normal = out.particle.normal;
    p.curve_point_a = out.particle.curve_point_a, p.curve_point_b = out.particle.curve_point_b;
    out.pairs.push_back(p);
  }
  detail::add_node_pairs(pose_a, nodes_a, shape_b, pose_b, d_try, true, out.pairs);
  detail::add_node_pairs(pose_b, nodes_b, shape_a, pose_a, d_try, false, out.pairs);
  return out;
}

}  // namespace stokescontact
