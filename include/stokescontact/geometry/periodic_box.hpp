#pragma once
// The orthorhombic periodic box: wrapping positions into it and the minimum image of a pair.
// Used by the broad phase, contact detection and the time stepper alike.
#include <cmath>
#include <optional>

#include "stokescontact/core/types.hpp"

namespace stokescontact {

// The box [0, Lx) x [0, Ly) x [0, Lz), repeated periodically.
struct PeriodicBox {
  Vec3 lengths = Vec3::Ones();
};

// x mapped into [0, length). fmod is exact, so only the shift of a negative remainder rounds.
inline double wrap_coordinate(double x, double length) {
  double r = std::fmod(x, length);
  if (r < 0.0) r += length;
  return r < length ? r : 0.0;  // -tiny + length may round up to length, i.e. 0 in the box
}

inline Vec3 wrap_into_box(const Vec3& x, const PeriodicBox& box) {
  return {wrap_coordinate(x.x(), box.lengths.x()), wrap_coordinate(x.y(), box.lengths.y()),
          wrap_coordinate(x.z(), box.lengths.z())};
}

// The lattice vector that takes x_j to its image nearest x_i (zero without a box).
inline Vec3 minimum_image_shift(const Vec3& x_i, const Vec3& x_j, const std::optional<PeriodicBox>& box) {
  if (!box) return Vec3::Zero();
  const Vec3 d = x_j - x_i;
  Vec3 shift;
  for (int k = 0; k < 3; ++k) shift[k] = -box->lengths[k] * std::round(d[k] / box->lengths[k]);
  return shift;
}

}  // namespace stokescontact
