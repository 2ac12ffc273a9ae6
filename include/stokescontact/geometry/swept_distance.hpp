#pragma once
// Continuous distance of two rigid bodies over a time step: each body moves with a constant
// rigid velocity (u, omega) for t' in [0, T], its pose Q(t') = advance(Q, u, omega, t') (the
// step's motion Q_t + t' Psi U of Broms & Tornberg eq. 13/16, rotation exact). The distance
// d(t') is d^P of the two moved bodies (centre-curve distance less the radii).
//
// The bound everything rests on: a point r (body frame) of a centre curve moves at
// |u + omega x R r| <= |u| + |omega| |r|, so the distance, a minimum over centre-curve point
// pairs less constant radii, changes no faster than
//     L = |u_a - u_b| + |omega_a| rho_a + |omega_b| rho_b,      rho = max |r| over the curve,
// the relative translation and each body's own rotation: unchanged by a Galilean change of
// frame (a common velocity added to both bodies), unlike the absolute speeds of eq. 30/31.
//
// Two queries on that Lipschitz bound:
//   first_time_below: conservative advancement (Mirtich 1996): from t, no contact closer than
//     `threshold` can occur before t + (d(t) - threshold) / L, so the step advances by that
//     much; it stops at the first t with d(t) <= threshold (+ tolerance), or past T. A
//     crossing is never stepped over; a grazing approach within `tolerance` counts as one.
//   swept_minimum: the minimum of d over [0, T] within `tolerance`, by Piyavskii-Shubert
//     branch and bound (the lower envelope of the cones d(t_k) - L |t - t_k|).
// Spheres (no orientation in their distance) have the exact closed form: the nearest
// approach of two points in linear relative motion.
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <string>
#include <vector>

#include "stokescontact/core/rigid_motion.hpp"
#include "stokescontact/geometry/closest_points.hpp"
#include "stokescontact/geometry/shapes.hpp"

namespace stokescontact {

// A body's velocity over the step, constant in time; omega in the world frame.
struct RigidVelocity {
  Vec3 u = Vec3::Zero();
  Vec3 omega = Vec3::Zero();
};

// rho: the largest distance of a centre-curve point from the body's centre.
template <Shape S>
double centre_curve_reach(const S& shape) {
  return bounding_radius(shape) - shape.radius;
}

// L above: no pair distance changes faster (relative translation plus each body's rotation).
template <Shape A, Shape B>
double distance_rate_bound(const A& a, const RigidVelocity& va, const B& b, const RigidVelocity& vb) {
  return (va.u - vb.u).norm() + va.omega.norm() * centre_curve_reach(a) + vb.omega.norm() * centre_curve_reach(b);
}

// d at one time, with its closest points; `evaluations` counts closest-point computations.
struct SweptDistance {
  double time = 0.0;          // the time found (first_time_below: T when no crossing)
  bool below = false;         // first_time_below: a crossing of the threshold was found
  double lower_bound = 0.0;   // swept_minimum: min over [0, T] is >= lower_bound
  ClosestPoints points;       // at `time`
  int evaluations = 0;
};

namespace detail {

template <Shape A, Shape B>
struct SweptPair {
  const A& a;
  const Pose& pose_a;
  const RigidVelocity& va;
  const B& b;
  const Pose& pose_b;
  const RigidVelocity& vb;
  int evaluations = 0;

  ClosestPoints at(double t) {
    ++evaluations;
    return closest_points(a, advance(pose_a, va.u, va.omega, t), b, advance(pose_b, vb.u, vb.omega, t));
  }
};

inline void require_sweep_interval(double T, double tolerance) {
  require_non_negative(T, "T");
  require_positive(tolerance, "tolerance");
}

// Sphere pair: centre separation s(t) = s0 + t v, its nearest approach on [0, T].
inline double nearest_approach_time(const Vec3& s0, const Vec3& v, double T) {
  const double vv = v.squaredNorm();
  if (!(vv > 0.0)) return 0.0;
  return std::clamp(-s0.dot(v) / vv, 0.0, T);
}

}  // namespace detail

// First time in [0, T] at which d(t) <= threshold, by conservative advancement. `below` is
// false when d stays above threshold on the whole interval (time = T then); when true,
// d(time) <= threshold + tolerance and d > threshold on [0, time). Grazing approaches that
// neither cross nor leave within max_evaluations count as crossings (the safe side).
template <Shape A, Shape B>
SweptDistance first_time_below(const A& a, const Pose& pose_a, const RigidVelocity& va, const B& b,
                               const Pose& pose_b, const RigidVelocity& vb, double T, double threshold,
                               double tolerance, int max_evaluations = 10000) {
  detail::require_sweep_interval(T, tolerance);
  require_finite(threshold, "threshold");
  detail::SweptPair<A, B> pair{a, pose_a, va, b, pose_b, vb};
  const double rate = distance_rate_bound(a, va, b, vb);
  SweptDistance out;
  for (double t = 0.0;;) {
    out.points = pair.at(t);
    out.time = t;
    const double gap = out.points.distance - threshold;
    if (gap <= tolerance || pair.evaluations >= max_evaluations) {
      out.below = true;
      break;
    }
    if (!(rate > 0.0) || t >= T) break;
    // Never past a crossing: |d(t + s) - d(t)| <= rate s.
    t = std::min(T, t + gap / rate);
  }
  out.lower_bound = out.points.distance;
  out.evaluations = pair.evaluations;
  return out;
}

inline SweptDistance first_time_below(const Sphere& a, const Pose& pose_a, const RigidVelocity& va,
                                      const Sphere& b, const Pose& pose_b, const RigidVelocity& vb, double T,
                                      double threshold, double tolerance, int = 0) {
  detail::require_sweep_interval(T, tolerance);
  require_finite(threshold, "threshold");
  // |s0 + t v| = reach solved for its first root on [0, T].
  const Vec3 s0 = pose_b.x - pose_a.x, v = vb.u - va.u;
  const double reach = a.radius + b.radius + threshold;
  double t = 0.0;
  if (s0.norm() - reach > tolerance) {
    const double vv = v.squaredNorm(), sv = s0.dot(v), c = s0.squaredNorm() - reach * reach;
    const double disc = sv * sv - vv * c;
    t = (vv > 0.0 && sv < 0.0 && disc >= 0.0) ? c / (-sv + std::sqrt(disc)) : T + 1.0;  // smaller root, stably
  }
  SweptDistance out;
  out.below = t <= T;
  out.time = std::min(t, T);
  out.points = closest_points(a, advance(pose_a, va.u, va.omega, out.time), b, advance(pose_b, vb.u, vb.omega, out.time));
  out.lower_bound = out.points.distance;
  out.evaluations = 1;
  return out;
}

// min over t in [0, T] of d(t), within tolerance: points/time at the best time found,
// lower_bound <= the true minimum <= points.distance, points.distance - lower_bound <=
// tolerance unless max_evaluations ran out first.
template <Shape A, Shape B>
SweptDistance swept_minimum(const A& a, const Pose& pose_a, const RigidVelocity& va, const B& b, const Pose& pose_b,
                            const RigidVelocity& vb, double T, double tolerance, int max_evaluations = 200) {
  detail::require_sweep_interval(T, tolerance);
  detail::SweptPair<A, B> pair{a, pose_a, va, b, pose_b, vb};
  const double rate = distance_rate_bound(a, va, b, vb);
  SweptDistance best;
  best.points = pair.at(T);  // the end first: the minimum of an approach
  best.time = T;
  if (!(rate > 0.0) || T == 0.0) {
    best.lower_bound = best.points.distance;
    best.evaluations = pair.evaluations;
    return best;
  }
  auto consider = [&](double t, const ClosestPoints& p) {
    if (p.distance < best.points.distance) {
      best.points = p;
      best.time = t;
    }
  };
  struct Interval {
    double t0, d0, t1, d1, bound;
    bool operator<(const Interval& o) const { return bound > o.bound; }  // smallest bound on top
  };
  auto interval = [&](double t0, double d0, double t1, double d1) {
    return Interval{t0, d0, t1, d1, 0.5 * (d0 + d1) - 0.5 * rate * (t1 - t0)};
  };
  const ClosestPoints start = pair.at(0.0);
  consider(0.0, start);
  std::priority_queue<Interval> open;
  open.push(interval(0.0, start.distance, T, best.points.distance));
  double lower = open.top().bound;
  while (!open.empty()) {
    const Interval top = open.top();
    lower = top.bound;
    if (best.points.distance - top.bound <= tolerance || pair.evaluations >= max_evaluations) break;
    open.pop();
    // Where the two cones from the ends meet: the lowest point of this interval's envelope.
    const double t = std::clamp(0.5 * (top.t0 + top.t1) + 0.5 * (top.d0 - top.d1) / rate, top.t0, top.t1);
    const ClosestPoints p = pair.at(t);
    consider(t, p);
    if (t > top.t0) open.push(interval(top.t0, top.d0, t, p.distance));
    if (t < top.t1) open.push(interval(t, p.distance, top.t1, top.d1));
  }
  best.lower_bound = open.empty() ? best.points.distance : std::min(lower, best.points.distance);
  best.evaluations = pair.evaluations;
  return best;
}

inline SweptDistance swept_minimum(const Sphere& a, const Pose& pose_a, const RigidVelocity& va, const Sphere& b,
                                   const Pose& pose_b, const RigidVelocity& vb, double T, double tolerance, int = 0) {
  detail::require_sweep_interval(T, tolerance);
  SweptDistance out;
  out.time = detail::nearest_approach_time(pose_b.x - pose_a.x, vb.u - va.u, T);
  out.points = closest_points(a, advance(pose_a, va.u, va.omega, out.time), b, advance(pose_b, vb.u, vb.omega, out.time));
  out.lower_bound = out.points.distance;
  out.evaluations = 1;
  return out;
}

}  // namespace stokescontact
