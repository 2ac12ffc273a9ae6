#pragma once
// Independent reference for the distance between two centre curves, sharing no code with
// segment_distance.hpp, arc_distance.hpp or closest_points.hpp: one curve is sampled
// densely against the other's exact point-to-curve distance (point_distance.hpp), every
// sampled local minimum is refined by golden-section search between its neighbours, and
// the same is done with the roles swapped. The result is realised by actual curve points,
// so it bounds the true distance from above; sampling both ways finds the right basin
// whenever it is wider than one sample spacing.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "stokescontact/geometry/centre_curve.hpp"
#include "common/test_support.hpp"

namespace brute_force {

namespace sc = stokescontact;

struct Result {
  double distance = std::numeric_limits<double>::infinity();
  sc::Vec3 point_a = sc::Vec3::Zero();  // on curve a
  sc::Vec3 point_b = sc::Vec3::Zero();  // on curve b
};

// The point at fraction v in [0, 1] along piece `i` (segments first, then arcs).
template <std::size_t NS, std::size_t NA>
sc::Vec3 piece_point(const sc::CentreCurve<NS, NA>& c, std::size_t i, double v) {
  if constexpr (NA > 0) {
    if (i >= NS) return c.arcs[i - NS].point(v * c.arcs[i - NS].angle);
  }
  return c.segments[i].point(v);
}

template <std::size_t NS, std::size_t NA>
double piece_length(const sc::CentreCurve<NS, NA>& c, std::size_t i) {
  if constexpr (NA > 0) {
    if (i >= NS) return c.arcs[i - NS].length();
  }
  return c.segments[i].length();
}

// Best of x's points against curve y: samples per piece, then golden-section refinement of
// each local minimum of the samples (a plateau is refined once, at its start).
template <std::size_t NSX, std::size_t NAX, std::size_t NSY, std::size_t NAY>
Result one_way(const sc::CentreCurve<NSX, NAX>& x, const sc::CentreCurve<NSY, NAY>& y,
               int per_piece) {
  Result best;
  const auto consider = [&](const sc::Vec3& p) {
    const sc::CurvePoint c = sc::closest_point(y, p);
    if (c.distance < best.distance) best = {c.distance, p, c.point};
    return c.distance;
  };
  std::vector<double> values;
  for (std::size_t i = 0; i < NSX + NAX; ++i) {
    const int n = piece_length(x, i) > 0.0 ? per_piece : 1;
    const auto at = [&](double v) { return consider(piece_point(x, i, v)); };
    values.assign(static_cast<std::size_t>(n + 1), 0.0);
    for (int k = 0; k <= n; ++k) values[k] = at(static_cast<double>(k) / n);
    for (int k = 0; k <= n; ++k) {
      const bool from_left = k == 0 || values[k] < values[k - 1];
      const bool to_right = k == n || values[k] <= values[k + 1];
      if (!(from_left && to_right) || n == 1) continue;
      // Golden section on [v_{k-1}, v_{k+1}]: 60 steps shrink it by 0.618^60 ~ 3e-13.
      double lo = static_cast<double>(std::max(k - 1, 0)) / n;
      double hi = static_cast<double>(std::min(k + 1, n)) / n;
      const double g = 0.5 * (std::sqrt(5.0) - 1.0);
      double m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo);
      double f1 = at(m1), f2 = at(m2);
      for (int step = 0; step < 60; ++step) {
        if (f1 <= f2) {
          hi = m2, m2 = m1, f2 = f1;
          m1 = hi - g * (hi - lo), f1 = at(m1);
        } else {
          lo = m1, m1 = m2, f1 = f2;
          m2 = lo + g * (hi - lo), f2 = at(m2);
        }
      }
    }
  }
  return best;
}

// Distance between curves a and b (points on a, on b), sampled both ways.
template <std::size_t NSA, std::size_t NAA, std::size_t NSB, std::size_t NAB>
Result curve_distance(const sc::CentreCurve<NSA, NAA>& a, const sc::CentreCurve<NSB, NAB>& b,
                      int per_piece = 24) {
  Result ab = one_way(a, b, per_piece);
  const Result ba = one_way(b, a, per_piece);
  if (ba.distance < ab.distance) ab = {ba.distance, ba.point_b, ba.point_a};
  return ab;
}

// Single pieces as curves.
inline sc::CentreCurve<1, 0> as_curve(const sc::Segment& s) {
  sc::CentreCurve<1, 0> c;
  c.segments[0] = s;
  return c;
}

inline sc::CentreCurve<0, 1> as_curve(const sc::Arc& a) {
  sc::CentreCurve<0, 1> c;
  c.arcs[0] = a;
  return c;
}

// Random inputs shared by the distance tests (fixed seeds in each test).
using Rng = std::mt19937_64;
using test_support::random_rotation;
using test_support::random_unit_vector;
using test_support::uniform;

// Sanitizer builds (GCC and Clang define __SANITIZE_ADDRESS__ under -fsanitize=address) run
// an order of magnitude slower: they check a tenth of the random pairs.
inline constexpr int random_pairs(int n) {
#if defined(__SANITIZE_ADDRESS__)
  return n / 10;
#else
  return n;
#endif
}

}  // namespace brute_force
