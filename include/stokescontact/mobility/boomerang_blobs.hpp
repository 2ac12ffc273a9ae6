#pragma once
// Blob models of a boomerang (shapes.hpp: two arms joined by a quarter bend, body frame
// with the origin at the centre of mass), at two resolutions:
//  - boomerang_curve_blobs: one chain of blobs along the centre curve (arm, bend, arm), both
//    ends included, at equal arclength spacing the nearest to `spacing` that fits; a coarse
//    model in the spirit of the 15-blob boomerang of Usabiaga et al. 2016.
//    Defaults: spacing = blob radius = the boomerang's radius (overlapping blobs).
//  - boomerang_surface_blobs: blobs at the quasi-uniform surface nodes of surface_nodes.hpp
//    at spacing h; blob radius h / 2 by default (the shells' rule).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "stokescontact/geometry/surface_nodes.hpp"
#include "stokescontact/mobility/blob_model.hpp"

namespace stokescontact {

inline BlobModel boomerang_curve_blobs(const Boomerang& b, double spacing = 0.0, double blob_radius = 0.0) {
  validate(b);
  require_non_negative(spacing, "spacing");
  require_non_negative(blob_radius, "blob_radius");
  const double h = spacing > 0.0 ? spacing : b.radius;
  const auto curve = centre_curve(b);
  const Segment& arm_z = curve.segments[0];  // tip -> bend
  const Arc& bend = curve.arcs[0];
  const Segment& arm_x = curve.segments[1];  // bend -> tip
  const double la = arm_z.length(), lb = bend.length();
  const double total = 2.0 * la + lb;
  const int gaps = std::max(2, static_cast<int>(std::lround(total / h)));
  BlobModel model;
  model.name = "boomerang_curve";
  model.positions.resize(3, gaps + 1);
  for (int k = 0; k <= gaps; ++k) {
    const double s = total * k / gaps;  // arclength from the z arm's tip
    Vec3 p;
    if (s <= la) p = la > 0.0 ? arm_z.point(s / la) : arm_z.p1;
    else if (s <= la + lb) p = bend.point((s - la) / bend.radius);
    else p = arm_x.point(la > 0.0 ? std::min(1.0, (s - la - lb) / la) : 1.0);
    model.positions.col(k) = p;
  }
  model.blob_radius = blob_radius > 0.0 ? blob_radius : b.radius;
  validate(model, "boomerang_curve_blobs");
  return model;
}

inline BlobModel boomerang_surface_blobs(const Boomerang& b, double spacing, double blob_radius = 0.0) {
  require_non_negative(blob_radius, "blob_radius");
  const SurfaceNodes nodes = surface_nodes(b, spacing);  // validates b and spacing
  BlobModel model;
  model.name = "boomerang_surface";
  model.positions = nodes.points;
  model.blob_radius = blob_radius > 0.0 ? blob_radius : 0.5 * spacing;
  validate(model, "boomerang_surface_blobs");
  return model;
}

}  // namespace stokescontact
