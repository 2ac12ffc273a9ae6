#pragma once
// A centre curve: a fixed set of segments and arcs, in the body frame or the world frame.
#include <array>
#include <cstddef>
#include <limits>

#include "stokescontact/geometry/point_distance.hpp"

namespace stokescontact {

template <std::size_t NumSegments, std::size_t NumArcs>
struct CentreCurve {
  std::array<Segment, NumSegments> segments{};
  std::array<Arc, NumArcs> arcs{};
};

template <std::size_t NS, std::size_t NA>
CentreCurve<NS, NA> to_world(const CentreCurve<NS, NA>& curve, const Pose& pose) {
  CentreCurve<NS, NA> world;
  for (std::size_t i = 0; i < NS; ++i) world.segments[i] = to_world(curve.segments[i], pose);
  for (std::size_t i = 0; i < NA; ++i) world.arcs[i] = to_world(curve.arcs[i], pose);
  return world;
}

// Closest point on the whole curve to a query point (ties: the first piece wins).
template <std::size_t NS, std::size_t NA>
CurvePoint closest_point(const CentreCurve<NS, NA>& curve, const Vec3& query) {
  static_assert(NS + NA > 0, "a centre curve needs at least one piece");
  CurvePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  for (const Segment& s : curve.segments) {
    const CurvePoint c = closest_point(s, query);
    if (c.distance < best.distance) best = c;
  }
  for (const Arc& a : curve.arcs) {
    const CurvePoint c = closest_point(a, query);
    if (c.distance < best.distance) best = c;
  }
  return best;
}

}  // namespace stokescontact
