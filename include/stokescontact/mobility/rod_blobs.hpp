#pragma once
// Blob model of a rod (spherocylinder, Yan et al. Appendix A: centre segment of length L
// along body z, radius R): blobs on the rod's surface, in rings.
//  - Cylinder: rings of `blobs_per_ring` blobs at z_k equally spaced over [-L/2, L/2], the
//    spacing the nearest to `ring_spacing` that fits (one ring at z = 0 when L = 0).
//  - Caps: latitude rings about each pole at polar angles j * delta < pi/2 with delta the
//    nearest to ring_spacing / R that divides pi/2; a ring of polar angle theta holds
//    round(blobs_per_ring * sin(theta)) blobs (at least one: the pole).
//  - Neighbouring rings are turned by half an azimuthal step, so that they interlock.
// Defaults: ring_spacing = the chord between neighbours on a ring, 2 R sin(pi / n), and
// blob_radius = half of it, the shells' rule (blob radius = half the nearest spacing).
// No hydrodynamic matching is done (cf. Broms, Sandberg & Tornberg 2022): the model's
// effective radius is somewhat larger than R; tests document its mobilities.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "stokescontact/geometry/shapes.hpp"
#include "stokescontact/mobility/blob_model.hpp"

namespace stokescontact {

struct RodBlobResolution {
  int blobs_per_ring = 8;
  double ring_spacing = 0.0;  // 0: 2 R sin(pi / blobs_per_ring)
  double blob_radius = 0.0;   // 0: ring_spacing / 2
};

inline BlobModel rod_blob_model(const Spherocylinder& rod, const RodBlobResolution& resolution = {}) {
  validate(rod);
  const double pi = std::numbers::pi;
  const int n = resolution.blobs_per_ring;
  if (n < 3) fail_argument("RodBlobResolution.blobs_per_ring", "must be >= 3, got " + std::to_string(n));
  require_non_negative(resolution.ring_spacing, "RodBlobResolution.ring_spacing");
  require_non_negative(resolution.blob_radius, "RodBlobResolution.blob_radius");
  const double R = rod.radius, L = rod.length;
  const double h = resolution.ring_spacing > 0.0 ? resolution.ring_spacing : 2.0 * R * std::sin(pi / n);
  std::vector<Vec3> blobs;
  int ring = 0;  // ring counter along the rod, for the half-step twist
  const auto add_ring = [&](double z, double rho, int count) {
    const double twist = 0.5 * (ring++ % 2);
    for (int k = 0; k < count; ++k) {
      const double phi = 2.0 * pi * (k + twist) / count;
      blobs.emplace_back(rho * std::cos(phi), rho * std::sin(phi), z);
    }
  };
  const int cap_rings = std::max(1, static_cast<int>(std::lround(0.5 * pi * R / h)));
  const double delta = 0.5 * pi / cap_rings;
  const auto add_cap_rings = [&](double pole_side, bool from_pole) {
    for (int jj = 0; jj < cap_rings; ++jj) {
      const int j = from_pole ? jj : cap_rings - 1 - jj;  // polar index, 0 = pole
      const double theta = j * delta;
      const int count = j == 0 ? 1 : std::max(1, static_cast<int>(std::lround(n * std::sin(theta))));
      add_ring(pole_side * (0.5 * L + R * std::cos(theta)), R * std::sin(theta), count);
    }
  };
  add_cap_rings(-1.0, true);  // bottom cap, pole first
  const int gaps = static_cast<int>(std::lround(L / h));
  for (int k = 0; k <= gaps; ++k) add_ring(gaps == 0 ? 0.0 : -0.5 * L + L * k / gaps, R, n);
  add_cap_rings(1.0, false);  // top cap, rim first

  BlobModel model;
  model.name = "rod";
  model.positions.resize(3, static_cast<Eigen::Index>(blobs.size()));
  for (std::size_t i = 0; i < blobs.size(); ++i) model.positions.col(static_cast<Eigen::Index>(i)) = blobs[i];
  model.blob_radius = resolution.blob_radius > 0.0 ? resolution.blob_radius : 0.5 * h;
  validate(model, "rod_blob_model");
  return model;
}

}  // namespace stokescontact
