#pragma once
// A scene of N bodies of one shape type, as the contact layer takes it: `shapes` holds one
// shape per body, or a single shape shared by every body; `poses` one pose per body.
#include <cstddef>
#include <span>
#include <string>

#include "stokescontact/geometry/shapes.hpp"

namespace stokescontact {

// The shape of body k (the shared one when a single shape is given).
template <Shape S>
const S& shape_of(std::span<const S> shapes, std::size_t k) {
  return shapes.size() == 1 ? shapes[0] : shapes[k];
}

// Throws std::invalid_argument naming "shapes" (wrong count), the shape's field, or
// "poses[k].x" / "poses[k].q".
template <Shape S>
void validate_scene(std::span<const S> shapes, std::span<const Pose> poses) {
  if (!(shapes.size() == poses.size() || shapes.size() == 1))
    fail_argument("shapes", "must hold one shape per pose or a single shared shape, got " +
                                std::to_string(shapes.size()) + " shapes for " +
                                std::to_string(poses.size()) + " poses");
  for (const S& s : shapes) validate(s);
  validate(poses);
}

}  // namespace stokescontact
