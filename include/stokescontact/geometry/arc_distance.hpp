#pragma once
// Segment-arc and arc-arc closest points, exact to rounding (no sampling).
//
// Along one arc C(t) = c + R (cos t e1 + sin t e2), t in [0, angle], the distance
// f(t) = dist(C(t), target piece) is exact from point_distance.hpp, and its slope is
// f'(t) = n . C'(t), n the unit vector from the target's closest point to C(t). We minimise
// f over t by best-first branch and bound with rigorous lower bounds on each interval,
// polish each bracketed local minimum (f' from - to +) with a root-finder on the slope,
// and stop when no interval's lower bound can beat the best distance by more than
// tau = 4 eps (|c|_inf + R + distance), a few units of the coordinates' rounding. Where the
// curves cross or touch at a small angle theta, f's valley has slope ~ R theta; the slope
// is taken along the velocity of C relative to the target's closest point (reach), whose
// rounding shrinks with theta, and the bounds allow for the rounding of n, so such
// crossings are found and polished to rounding too. Bounds on an interval of width w
// (several, the largest wins):
//  - Lipschitz: |C'| = R and f is 1-Lipschitz in the point: f >= (f(l) + f(r) - R w) / 2.
//  - Convexity: for a convex target (a segment, a point) the plane through the closest
//    point normal to n separates it from C(a), giving a concave quadratic below f from
//    each end (convex_bound): second order, so the search stops a few levels below a
//    polished minimum.
//  - Ranges: |C(t) - o|^2 and (C(t) - o) . u are sinusoids in t whose exact range on an
//    interval follows from end values and slopes. From them, the distance to a line or a
//    circle is bounded without loss where it is constant along the interval, as for a
//    segment on the arc's axis or coaxial arcs (stacked identical bodies), where the other
//    bounds alone would subdivide to the budget.
// An arc target is not convex: dist(x, arc) is the distance to the full circle where x's
// polar angle lies in the arc's range, else to the nearer end point. The end points'
// closest points on C are seeded as candidates up front (closed form), so only the circle
// term needs bounding, and only where the polar angle can reach the range. The distance
// to a circle has Hessian >= -1/rho (rho: distance from the circle's axis), so along C it
// is semiconvex with modulus R + R^2 / rho_min; from a point outside the circle's cylinder
// the circle lies behind a plane, as a convex target would.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "stokescontact/geometry/segment_distance.hpp"

namespace stokescontact {
namespace detail {

// The arc point, its offset from the centre and its velocity dC/dt (both of length R).
// (The search's sample types carry no default initialisers: its buffers stay unzeroed.)
struct ArcMotion {
  Vec3 point;
  Vec3 radial;
  Vec3 velocity;
};

// A bound on |C(t)|_inf over the whole circle.
inline double coordinate_bound(const Arc& a) { return a.centre.cwiseAbs().maxCoeff() + a.radius; }

inline ArcMotion arc_motion(const Arc& a, double t) {
  const double c = std::cos(t), s = std::sin(t);
  const Vec3 radial = a.radius * (c * a.e1 + s * a.e2);
  return {a.centre + radial, radial, a.radius * (c * a.e2 - s * a.e1)};
}

// Distance |x - y| from the arc point x to its closest point y on a target, its t-slope,
// the bend that bounds how fast it can fall below its tangent line (see convex_bound), the
// speed |w| of the relative velocity w the slope is taken along, and the rounding of the
// unit vector n = (x - y) / |x - y|: x - y carries ~ eps (|x| + |y|) of rounding, and
// `coordinates` bounds |x|_inf + |y|_inf (a constant of the search).
//
// The slope is n . C'. Where y lies inside a smooth piece of the target, n is normal to the
// target's tangent there, so n . C' = n . w for w = C' less its component along that
// tangent: w is the velocity of x relative to y, which slides along the target. Computed
// from C' the slope's rounding is |C'| times n's; from w it is |w| times n's, and |w|
// vanishes where the curves cross or touch at a small angle, exactly where f's valley is
// shallow: there, n . C' is pure rounding within |x - y| ~ eps |x| R / |w| of a crossing,
// and the polish would stop that far from it. Where y is an end point (it does not move),
// w = C'.
struct Reach {
  double distance;
  double slope;
  double bend;
  double speed;
  double rounding;  // |error of n|, so slope and bend are exact to rounding * |w|, * R
};

// C' relative to a closest point sliding along the unit tangent `along`.
inline Vec3 sliding(const ArcMotion& m, const Vec3& along) {
  return m.velocity - m.velocity.dot(along) * along;
}

inline Reach reach(const ArcMotion& m, const Vec3& y, const Vec3& w, double coordinates) {
  const Vec3 offset = m.point - y;
  const double d = offset.norm();
  if (!(d > 0.0)) return {0.0, 0.0, 0.0, w.norm(), 0.0};  // f >= 0 = f(t): any slope <= 0 holds
  const double inv = 1.0 / d;
  constexpr double eps = std::numeric_limits<double>::epsilon();
  return {d, offset.dot(w) * inv, std::max(offset.dot(m.radial) * inv, 0.0), w.norm(),
          8.0 * eps * coordinates * inv};
}

// One evaluation along the searched arc.
struct ArcSample {
  double t;
  double f;      // distance from C(t) to the target
  double df;     // df/dt (either one-sided value at a kink)
  double speed;  // |w|, the relative speed df is taken along (see reach)
  double u;      // target parameter of the closest point
  Vec3 point;
  Vec3 target_point;
};

// Lower bound of an L-Lipschitz function on an interval of width w from its end values.
inline double lipschitz_bound(double fl, double fr, double w, double lipschitz) {
  return 0.5 * (fl + fr - lipschitz * w);
}

// Lower bound on [l, l + w] of g with g + (m/2) t^2 convex, from the values and slopes at
// both ends: g lies above the concave parabolas g(e) + g'(e)(t - e) - m/2 (t - e)^2 from
// each end; their upper envelope is lowest at an end or where the two cross.
inline double semiconvex_bound(double gl, double dl, double gr, double dr, double w, double m) {
  double lower = std::min(gl, gr);
  const double denom = m * w + dr - dl;  // >= 0 by semiconvexity
  if (denom > 0.0) {
    const double x = (gl - gr + dr * w + 0.5 * m * w * w) / denom;
    if (x > 0.0 && x < w) lower = std::min(lower, gl + dl * x - 0.5 * m * x * x);
  }
  return lower;
}

// Lower bound on [l, l + w] of f(t) = dist(C(t), K), K convex, from both ends. With y the
// closest point of K to C(a) and n = (C(a) - y) / f(a), the plane through y normal to n
// separates K from C(a), so f(t) >= n . (C(t) - y), and as
// C(a + h) - C(a) = (cos h - 1) radial + sin h velocity,
//   f(a + h) >= f(a) + f'(a) sin h - (n . radial)(1 - cos h)
//            >= f(a) + f'(a) h - (max(n . radial, 0) + |f'(a)| w / 3) h^2 / 2
// by 1 - cos h <= h^2 / 2 and |sin h - h| <= |h|^3 / 6. The modulus is 0 for a target
// outside the bend and never needs to exceed R (f + R t^2 / 2 is convex anyway).
// Each end's own modulus also gives a bound alone (its parabola is lowest at an end of
// the interval); at a polished minimum (slope 0) facing a target outside the bend that
// alone certifies the whole interval, however steep f is at the other end.
// The computed n is off by up to `rounding`, which matters where f is small: the slope is
// taken at its least favourable within rounding * |w| (lowest going right, highest going
// left) and n . radial at its largest within rounding * R. (Without this, near-coincident
// arcs whose n . radial is below its rounding had an interval holding their crossing
// bounded away from 0 and dropped.)
inline double slope_rounding(const Reach& e) { return e.rounding * e.speed; }

inline double modulus(const Reach& e, double w, double radius) {
  const double bend = e.bend + e.rounding * radius;
  return std::min(bend + (std::abs(e.slope) + slope_rounding(e)) * w / 3.0, radius);
}

inline double one_end_bound(const Reach& e, double signed_w, double radius) {
  const double w = std::abs(signed_w);
  return std::min(e.distance, e.distance + e.slope * signed_w - slope_rounding(e) * w -
                                  0.5 * modulus(e, w, radius) * w * w);
}

// The semiconvex bound from both ends, slopes taken at their least favourable.
inline double semiconvex_bound(const Reach& l, const Reach& r, double w, double m) {
  return semiconvex_bound(l.distance, l.slope - slope_rounding(l), r.distance,
                          r.slope + slope_rounding(r), w, m);
}

inline double convex_bound(const Reach& l, const Reach& r, double w, double radius) {
  const double m = std::max(modulus(l, w, radius), modulus(r, w, radius));
  return std::max({semiconvex_bound(l, r, w, m), one_end_bound(l, w, radius),
                   one_end_bound(r, -w, radius)});
}

// Along C(t), the squared distance to a fixed point o and the height of C(t) - o along a
// fixed unit vector u are sinusoids mid + amplitude cos(t - t0). On an interval narrower
// than pi a sinusoid has an extreme inside only where its slope changes sign there, so
// its exact range follows from end values and slopes.
struct Sinusoid {
  double mid, amplitude;
};

struct Range {
  double lo, hi;
};

inline Range sinusoid_range(const Sinusoid& s, double vl, double dl, double vr, double dr) {
  Range r{std::min(vl, vr), std::max(vl, vr)};
  if (dl < 0.0 && dr > 0.0) r.lo = std::min(r.lo, s.mid - s.amplitude);
  if (dl > 0.0 && dr < 0.0) r.hi = std::max(r.hi, s.mid + s.amplitude);
  return r;
}

// Values and slopes of both sinusoids at a sample.
struct Probe {
  double square, square_slope;  // |C - o|^2
  double height, height_slope;  // (C - o) . u
};

struct ProbeShape {
  Vec3 u;
  Sinusoid square, height;

  ProbeShape(const Arc& along, const Vec3& o, const Vec3& unit) : u(unit) {
    const Vec3 co = along.centre - o;
    const double r = along.radius;
    const auto norm2 = [](double x, double y) { return std::sqrt(x * x + y * y); };
    square = {co.squaredNorm() + r * r, 2.0 * r * norm2(co.dot(along.e1), co.dot(along.e2))};
    height = {co.dot(u), r * norm2(along.e1.dot(u), along.e2.dot(u))};
  }

  Probe probe(const Vec3& offset, const ArcMotion& m) const {
    return {offset.squaredNorm(), 2.0 * offset.dot(m.velocity), offset.dot(u), m.velocity.dot(u)};
  }

  // Ranges of |C - o|^2 and of (C - o) . u on [l, r].
  Range squares(const Probe& l, const Probe& r) const {
    return sinusoid_range(square, l.square, l.square_slope, r.square, r.square_slope);
  }
  Range heights(const Probe& l, const Probe& r) const {
    return sinusoid_range(height, l.height, l.height_slope, r.height, r.height_slope);
  }
};

inline Range squared(const Range& r) {
  const double a = r.lo * r.lo, b = r.hi * r.hi;
  return {r.lo <= 0.0 && r.hi >= 0.0 ? 0.0 : std::min(a, b), std::max(a, b)};
}

// Target: a segment (not a point, see is_point), a convex set. Its distance is the
// distance to its line plus, past an end, the overshoot along it: both bounded through the
// probe (o = p0, u along the segment).
class SegmentTarget {
 public:
  struct Sample : ArcSample {
    double bend, rounding;  // see reach
    Probe probe;
  };

  SegmentTarget(const Segment& s, const Arc& along)
      : p0_(s.p0),
        direction_(s.p1 - s.p0),
        length_(direction_.norm()),
        inv_length2_(1.0 / direction_.squaredNorm()),
        unit_(direction_ / length_),
        coordinates_(coordinate_bound(along) +
                     std::max(s.p0.cwiseAbs().maxCoeff(), s.p1.cwiseAbs().maxCoeff())),
        probes_(along, s.p0, unit_),
        along_(along) {}

  std::array<Sample, 0> seeds() const { return {}; }

  Sample sample(double t) const {
    const ArcMotion m = arc_motion(along_, t);
    const Vec3 offset = m.point - p0_;
    const double projection = offset.dot(direction_) * inv_length2_;
    const double s = std::clamp(projection, 0.0, 1.0);
    const Vec3 q = p0_ + s * direction_;
    const bool inside = s == projection && s > 0.0 && s < 1.0;  // else q is an end
    const Reach r = reach(m, q, inside ? sliding(m, unit_) : m.velocity, coordinates_);
    Sample out;
    static_cast<ArcSample&>(out) = {t, r.distance, r.slope, r.speed, s, m.point, q};
    out.bend = r.bend, out.rounding = r.rounding;
    out.probe = probes_.probe(offset, m);
    return out;
  }

  double lower_bound(const Sample& l, const Sample& r) const {
    const double w = r.t - l.t, radius = along_.radius;
    const Range heights = probes_.heights(l.probe, r.probe);
    const double line2 = probes_.squares(l.probe, r.probe).lo - squared(heights).hi;
    const double overshoot = std::max({heights.lo - length_, -heights.hi, 0.0});
    return std::max({0.0, lipschitz_bound(l.f, r.f, w, radius),
                     convex_bound({l.f, l.df, l.bend, l.speed, l.rounding},
                                  {r.f, r.df, r.bend, r.speed, r.rounding}, w, radius),
                     std::sqrt(std::max(line2, 0.0) + overshoot * overshoot)});
  }

 private:
  Vec3 p0_, direction_;  // p0 + s direction, s in [0, 1]
  double length_, inv_length2_;
  Vec3 unit_;           // direction / length
  double coordinates_;  // bounds |arc point|_inf + |segment point|_inf
  ProbeShape probes_;
  Arc along_;
};

// Target: an arc, seen as its full circle (where the polar angle is in range) and its two
// end points, which are seeded (probe: o = centre, u = axis).
class ArcTarget {
 public:
  struct Sample : ArcSample {
    Reach circle;  // distance to the full circle
    double rho;    // distance from the circle's axis
    double gap;    // polar angle's distance from [0, angle], 0 inside
    Probe probe;
  };

  ArcTarget(const Arc& target, const Arc& along)
      : arc_(target),
        ends_{target.point(0.0), target.point(target.angle)},
        coordinates_(coordinate_bound(along) + coordinate_bound(target)),
        probes_(along, target.centre, target.axis()),
        along_(along) {}

  // The closest points on the searched arc to the target's ends, in closed form: every t
  // where the target's nearest point is an end then cannot beat these.
  std::array<Sample, 2> seeds() const {
    std::array<Sample, 2> out{};
    for (int k = 0; k < 2; ++k) {
      const CurvePoint c = closest_point(along_, ends_[k]);
      static_cast<ArcSample&>(out[k]) = {c.parameter, c.distance, 0.0, along_.radius,
                                         k == 0 ? 0.0 : arc_.angle, c.point, ends_[k]};
    }
    return out;
  }

  Sample sample(double t) const {
    const ArcMotion m = arc_motion(along_, t);
    const Vec3 x = m.point - arc_.centre;
    const double px = x.dot(arc_.e1), py = x.dot(arc_.e2);
    Sample s;
    s.t = t;
    s.point = m.point;
    s.probe = probes_.probe(x, m);
    s.rho = std::sqrt(px * px + py * py);
    s.gap = 0.0;
    if (s.rho > 0.0) {
      const double inv_rho = 1.0 / s.rho;
      const Vec3 radial = inv_rho * (px * arc_.e1 + py * arc_.e2);
      const Vec3 tangent = inv_rho * (px * arc_.e2 - py * arc_.e1);  // the circle's, at y
      const Vec3 y = arc_.centre + arc_.radius * radial;
      s.circle = reach(m, y, sliding(m, tangent), coordinates_);
      double phi = std::atan2(py, px);
      if (phi < 0.0) phi += 2.0 * std::numbers::pi;
      if (phi > arc_.angle) s.gap = std::min(phi - arc_.angle, 2.0 * std::numbers::pi - phi);
      if (s.gap == 0.0) {
        s.f = s.circle.distance, s.df = s.circle.slope, s.speed = s.circle.speed, s.u = phi;
        s.target_point = y;
        return s;
      }
    }
    const Reach e0 = reach(m, ends_[0], m.velocity, coordinates_);
    const Reach e1 = reach(m, ends_[1], m.velocity, coordinates_);
    const bool second = e1.distance < e0.distance;  // the nearer end
    const Reach& e = second ? e1 : e0;
    if (!(s.rho > 0.0)) s.circle = {e.distance, e.slope, 0.0, e.speed, e.rounding};  // on the axis
    s.f = e.distance, s.df = e.slope, s.speed = e.speed;
    s.u = second ? arc_.angle : 0.0;
    s.target_point = ends_[second ? 1 : 0];
    return s;
  }

  // A lower bound on min(f over [l, r], seeds): only the circle term needs bounding.
  double lower_bound(const Sample& l, const Sample& r) const {
    const double w = r.t - l.t, radius = along_.radius;
    const Range z2 = squared(probes_.heights(l.probe, r.probe));
    const Range squares = probes_.squares(l.probe, r.probe);
    const double rho_lo = std::sqrt(std::max(squares.lo - z2.hi, 0.0));
    const double rho_hi = std::sqrt(std::max(squares.hi - z2.lo, 0.0));
    const double rho_min = std::max(rho_lo, lipschitz_bound(l.rho, r.rho, w, radius));
    // The polar angle turns at most R / rho_min per unit t: too far from the range, only
    // the (seeded) ends can be nearest.
    if (rho_min > 0.0 && std::max(l.gap, r.gap) * rho_min > radius * w)
      return std::numeric_limits<double>::infinity();
    const double off_circle = std::max({rho_lo - arc_.radius, arc_.radius - rho_hi, 0.0});
    double circle = std::max(lipschitz_bound(l.circle.distance, r.circle.distance, w, radius),
                             std::sqrt(off_circle * off_circle + z2.lo));
    if (rho_min > 0.0) {
      const double m = radius + radius * radius / rho_min;
      circle = std::max(circle, semiconvex_bound(l.circle, r.circle, w, m));
    }
    // From a sample outside the circle's cylinder (rho >= radius) the whole circle lies
    // behind the plane through its closest point normal to n: a convex target's bound.
    if (l.rho >= arc_.radius) circle = std::max(circle, one_end_bound(l.circle, w, radius));
    if (r.rho >= arc_.radius) circle = std::max(circle, one_end_bound(r.circle, -w, radius));
    return std::max({0.0, lipschitz_bound(l.f, r.f, w, radius), circle});
  }

 private:
  Arc arc_;
  std::array<Vec3, 2> ends_;
  double coordinates_;  // bounds |arc point|_inf + |target point|_inf
  ProbeShape probes_;
  Arc along_;
};

// Search tuning: initial grid spacing (a quarter arc starts with 2 intervals), the
// tolerance tau relative to the searched arc's coordinates (|c|_inf + R) plus the best
// distance, and the budgets. The budget binds only where f stays within tau of its
// minimum along a stretch in a way no bound above sees (two linked rings, each through
// the other's centre, are 1 apart at every point): the best sample is then as good as any.
inline constexpr double kArcGridStep = std::numbers::pi / 4.0;
inline constexpr double kArcTolerance = 4 * std::numeric_limits<double>::epsilon();
inline constexpr int kArcMaxSamples = 160;
inline constexpr int kArcMaxEvaluations = 400;
inline constexpr int kArcMaxPolishSteps = 60;

// Global minimum of f(t) = dist(arc(t), target) over [0, angle] (the target samples along
// `arc`); intervals whose lower bound reaches `cutoff` are dropped (the caller already
// holds something as good), so a result with distance >= cutoff means "nothing below".
template <typename Target>
PieceClosestPoints minimise_along_arc(const Arc& arc, const Target& target, double cutoff) {
  using Sample = typename Target::Sample;
  struct Interval {
    double lower;
    int left, right;
  };
  std::array<Sample, kArcMaxSamples> samples;
  std::array<bool, kArcMaxSamples> polished;  // a polished minimum: never bracket it again
  std::array<Interval, kArcMaxSamples> heap;  // min-heap on `lower`
  int count = 0, heap_size = 0, best = 0, evaluations = 0;
  double best_f = std::numeric_limits<double>::infinity();
  const auto evaluate = [&](double t) {
    ++evaluations;
    return target.sample(t);
  };
  const auto later = [](const Interval& x, const Interval& y) { return x.lower > y.lower; };

  const auto add = [&](const Sample& s, bool is_polished) {
    samples[count] = s;
    polished[count] = is_polished;
    if (s.f < best_f) best = count, best_f = s.f;
    return count++;
  };
  double tau = 0.0;
  const auto threshold = [&] { return std::min(best_f, cutoff) - tau; };
  const auto push = [&](int left, int right) {
    const double lower = target.lower_bound(samples[left], samples[right]);
    if (!(lower < threshold()) || !(samples[right].t > samples[left].t)) return;
    heap[heap_size++] = {lower, left, right};
    std::push_heap(heap.begin(), heap.begin() + heap_size, later);
  };

  // Local minimum inside a bracket f'(l) < 0 < f'(r): the Illinois variant of regula
  // falsi on g' = f f' = (C - y) . w, the slope of f^2 / 2 (w: C' relative to y, see
  // reach), which stays smooth through a crossing (f = 0) where f' jumps. It converges
  // superlinearly and keeps the bracket; its sign can only turn from - to + at a local
  // minimum (f's kinks at the medial axis of an arc target are concave). g' is computed
  // to eps (|w| |C| + f |C'|): at a crossing at a small angle, g' ~ f |w|, so the search
  // stops only where f is down to a few eps |C|, however small the angle.
  const auto polish = [&](const Sample& l, const Sample& r) {
    constexpr double eps = std::numeric_limits<double>::epsilon();
    Sample lo = l, hi = r;
    double ga = l.f * l.df, gb = r.f * r.df;  // Illinois scales these down
    int side = 0;
    for (int step = 0; step < kArcMaxPolishSteps && evaluations < kArcMaxEvaluations; ++step) {
      const double a = lo.t, b = hi.t;
      if (b - a <= 4.0 * eps * (1.0 + a + b)) break;
      double x = a + (b - a) * (-ga / (gb - ga));
      if (!(x > a && x < b)) x = 0.5 * (a + b);
      const Sample s = evaluate(x);
      const double g = s.f * s.df;
      // Within its own rounding, g' has found its root.
      const double noise =
          8.0 * eps *
          (s.speed * (s.point.cwiseAbs().maxCoeff() + s.target_point.cwiseAbs().maxCoeff()) +
           s.f * arc.radius);
      if (std::abs(g) <= noise) return s;
      if (g > 0.0) {
        hi = s, gb = g;
        if (side == 1) ga *= 0.5;
        side = 1;
      } else {
        lo = s, ga = g;
        if (side == -1) gb *= 0.5;
        side = -1;
      }
    }
    // The bracket end nearer the root. (Not the lower f: f is flat here, and picking by its
    // rounding noise would scatter the witness along t.)
    return std::abs(lo.f * lo.df) <= std::abs(hi.f * hi.df) ? lo : hi;
  };

  const int n = std::clamp(static_cast<int>(std::ceil(arc.angle / kArcGridStep)), 1, 32);
  for (int i = 0; i <= n; ++i) add(evaluate(i == n ? arc.angle : arc.angle * i / n), false);
  for (const Sample& s : target.seeds()) add(s, true);  // candidates only, never interval ends
  tau = kArcTolerance * (arc.centre.cwiseAbs().maxCoeff() + arc.radius + best_f);
  for (int i = 0; i < n; ++i) push(i, i + 1);

  while (heap_size > 0 && count + 1 < kArcMaxSamples && evaluations < kArcMaxEvaluations) {
    std::pop_heap(heap.begin(), heap.begin() + heap_size, later);
    const Interval iv = heap[--heap_size];
    if (!(iv.lower < threshold())) break;  // best first: nothing left can do better
    const Sample& l = samples[iv.left];
    const Sample& r = samples[iv.right];
    const bool bracket = l.df < 0.0 && r.df > 0.0;
    const double t_mid = 0.5 * (l.t + r.t);
    if (!(t_mid > l.t && t_mid < r.t)) continue;  // a single point: its ends are sampled
    const bool fresh = bracket && !polished[iv.left] && !polished[iv.right];
    const int k = fresh ? add(polish(l, r), true) : add(evaluate(t_mid), false);
    push(iv.left, k);
    push(k, iv.right);
  }
  // The witness: the lowest sample, unless a polished minimum (or seed) lies within tau of
  // it. The search goes on bisecting around a polished minimum until its bounds clear tau,
  // and f is flat there to second order: samples up to ~ sqrt(tau / R) away along t tie
  // with it to rounding, and one that wins by a unit in the last place would move the
  // witness by ~ 1e-7 (and with it the normal), differently under a rigid motion. The slope
  // root places the polished one to rounding, so it wins such ties; its distance is within
  // tau of the lowest.
  int pick = best;
  for (int i = 0; i < count; ++i) {
    if (polished[i] && samples[i].f <= best_f + tau &&
        (!polished[pick] || samples[i].f < samples[pick].f))
      pick = i;
  }
  const Sample& s = samples[pick];
  return {s.t, s.u, s.point, s.target_point, s.f};
}

}  // namespace detail

// Closest points between a segment and an arc (parameters s in [0, 1], t in [0, angle]).
// With a cutoff, the answer is exact whenever the distance is below it; otherwise only a
// distance >= cutoff is promised (this lets a caller skip pieces that cannot win).
inline PieceClosestPoints closest_points(const Segment& s, const Arc& a,
                                         double cutoff = std::numeric_limits<double>::infinity()) {
  if (is_point(s)) {  // a point: the arc's closest point is exact in closed form
    const CurvePoint c = closest_point(a, s.p0);
    return {0.0, c.parameter, s.p0, c.point, c.distance};
  }
  return swapped(detail::minimise_along_arc(a, detail::SegmentTarget(s, a), cutoff));
}

inline PieceClosestPoints closest_points(const Arc& a, const Segment& s,
                                         double cutoff = std::numeric_limits<double>::infinity()) {
  return swapped(closest_points(s, a, cutoff));
}

// Closest points between two arcs. The search runs along the arc of smaller radius (ties:
// a), whose curvature enters the bounds' modulus.
inline PieceClosestPoints closest_points(const Arc& a, const Arc& b,
                                         double cutoff = std::numeric_limits<double>::infinity()) {
  if (b.radius < a.radius)
    return swapped(detail::minimise_along_arc(b, detail::ArcTarget(a, b), cutoff));
  return detail::minimise_along_arc(a, detail::ArcTarget(b, a), cutoff);
}

}  // namespace stokescontact
