#pragma once
// Line contacts of near-parallel rods: where a contact force acts when two centre segments
// are close along a stretch rather than at a point. Broms & Tornberg Sec. 4 item 2 trace the
// broken symmetry of their Fig. 8 to d^P (eq. 20-21), whose closest points of nearly parallel
// segments sit at an end of the overlap and jump to the other end as the pair turns through
// parallel, and propose a continuous contact potential over the surfaces close to contact.
// This is the one-dimensional version of that idea for two segments a and b.
//
// Over the overlap of the projections [s_lo, s_hi] (the s where a(s) projects inside b at
// tau(s)), the gap between the centre lines is g(s) = |b(tau(s)) - a(s)|. The force of the
// pair is spread over the overlap with the weight
//     w(s) = max(0, 1 - (g(s) - g_min) / width),     g_min = the smallest g on the overlap,
// a force density that decreases linearly with the extra gap and vanishes `width` above the
// closest gap, and acts at its resultant's point s_w = int s w ds / int w ds (a 64-point
// midpoint rule, so s_w is continuous in the poses). Parallel segments give the middle of
// the overlap; a pair tilted by theta over an overlap of length l has its force moved towards
// the closer end by about theta l^2 / (12 width) (a restoring torque); as the extra gap
// l theta grows past `width` the force concentrates at the closer end, as d^P has it.
//
// Crossing segments are not line contacts: the spreading applies fully for angles (between
// the lines, in [0, pi/2]) below `angle`, and its share falls linearly to 0 at 2 `angle`,
//     s = lerp(s_closest, s_w, clamp(2 - theta / angle, 0, 1)),
// so the point is continuous in the orientation at both ends of that range (s_closest, the
// exact minimiser, is continuous away from parallel). Without overlap (segments end to end
// or side by side beyond an end) there is no line contact: the closest points stand.
//
// The result is only where the force acts and in which direction (the separation there);
// the distance constrained stays d^P, the exact closest distance.
#include <algorithm>
#include <cmath>
#include <optional>

#include "stokescontact/geometry/segment_distance.hpp"
#include "stokescontact/geometry/shapes.hpp"

namespace stokescontact {

struct LineContactParameters {
  double width = 0.0;  // > 0: the extra gap over which the force density falls to 0
  double angle = 0.0;  // > 0: full spreading below this angle (radians), none above twice it
};

// The point pair on the centre segments where a line contact's force acts, and the unit
// separation there from a towards b; `share` the weight of the spread point in [0, 1].
struct LineContactPoints {
  double parameter_a = 0.0;
  double parameter_b = 0.0;
  Vec3 point_a = Vec3::Zero();
  Vec3 point_b = Vec3::Zero();
  Vec3 normal = Vec3::UnitX();
  double share = 0.0;
};

namespace detail {

inline constexpr int kLineContactNodes = 64;

// a the shorter segment (as closest_points orders them), neither of zero length.
inline std::optional<LineContactPoints> line_contact_ordered(const Segment& a, const Segment& b,
                                                             const LineContactParameters& p) {
  const Vec3 da = a.p1 - a.p0, db = b.p1 - b.p0;
  const double la = da.norm(), lb = db.norm();
  // The angle between the lines, in [0, pi/2].
  const double theta = std::atan2(da.cross(db).norm(), std::abs(da.dot(db)));
  const double share = std::clamp(2.0 - theta / p.angle, 0.0, 1.0);
  if (!(share > 0.0)) return std::nullopt;
  // a(s) projects onto b's line at tau(s) = tau0 + kappa s; the overlap in s.
  const double inv_bb = 1.0 / (lb * lb);
  const double tau0 = (a.p0 - b.p0).dot(db) * inv_bb, kappa = da.dot(db) * inv_bb;
  double lo = 0.0, hi = 1.0;
  if (kappa != 0.0) {
    const double s0 = -tau0 / kappa, s1 = (1.0 - tau0) / kappa;
    lo = std::max(lo, std::min(s0, s1));
    hi = std::min(hi, std::max(s0, s1));
  } else if (!(tau0 >= 0.0 && tau0 <= 1.0)) {
    return std::nullopt;
  }
  if (!(lo < hi)) return std::nullopt;
  const auto gap = [&](double s) {
    return (b.point(std::clamp(tau0 + kappa * s, 0.0, 1.0)) - a.point(s)).norm();
  };
  constexpr int n = kLineContactNodes;
  double g[n];
  double g_min = gap(lo);  // the overlap's ends and the nodes
  g_min = std::min(g_min, gap(hi));
  const double h = (hi - lo) / n;
  for (int k = 0; k < n; ++k) g_min = std::min(g_min, g[k] = gap(lo + (k + 0.5) * h));
  double weight = 0.0, moment = 0.0;
  for (int k = 0; k < n; ++k) {
    const double w = std::max(0.0, 1.0 - (g[k] - g_min) / p.width);
    weight += w;
    moment += w * (lo + (k + 0.5) * h);
  }
  if (!(weight > 0.0)) return std::nullopt;
  const PieceClosestPoints closest = closest_points(a, b);
  const double s = std::lerp(closest.parameter_a, moment / weight, share);
  const double t = std::clamp(tau0 + kappa * s, 0.0, 1.0);
  LineContactPoints out{s, t, a.point(s), b.point(t), Vec3::Zero(), share};
  const Vec3 separation = out.point_b - out.point_a;
  const double length = separation.norm();
  // Centre lines that meet at the point (a deep overlap): the closest points' direction.
  const Vec3 fallback = closest.point_b - closest.point_a;
  if (length > 1e-12 * std::max(la, lb)) {
    out.normal = separation / length;
  } else if (fallback.norm() > 0.0) {
    out.normal = fallback.normalized();
  } else {
    return std::nullopt;
  }
  return out;
}

}  // namespace detail

// The line contact of segments a and b, or none (crossing beyond 2 angle, no overlap, a
// segment of zero length). Symmetric: (b, a) gives the mirrored result (the shorter segment
// is measured against the longer one, unless the lengths tie). width and angle must be > 0.
inline std::optional<LineContactPoints> line_contact(const Segment& a, const Segment& b,
                                                     const LineContactParameters& p) {
  require_positive(p.width, "LineContactParameters.width");
  require_positive(p.angle, "LineContactParameters.angle");
  if (is_point(a) || is_point(b)) return std::nullopt;
  if ((a.p1 - a.p0).squaredNorm() > (b.p1 - b.p0).squaredNorm()) {
    std::optional<LineContactPoints> c = detail::line_contact_ordered(b, a, p);
    if (!c) return c;
    return LineContactPoints{c->parameter_b, c->parameter_a, c->point_b, c->point_a, -c->normal, c->share};
  }
  return detail::line_contact_ordered(a, b, p);
}

// A rod whose contacts with other LineContactRods are line contacts: the contact layer
// (contact/contact_pairs.hpp) constrains d^P as for any Spherocylinder and applies the force
// at line_contact's points (Broms & Tornberg eq. 21 with the point of eq. 20 moved along the
// overlap). Everything else (mobility, surface nodes, d_try) treats it as its Spherocylinder.
struct LineContactRod : Spherocylinder {
  LineContactParameters line;
};

inline void validate(const LineContactRod& rod) {
  validate(static_cast<const Spherocylinder&>(rod));
  require_positive(rod.line.width, "LineContactRod.line.width");
  require_positive(rod.line.angle, "LineContactRod.line.angle");
}

}  // namespace stokescontact
