#pragma once
// Surface-node contacts (Broms & Tornberg eq. 22, Sec. 3.2.1, 3.3.1): for every flagged
// body pair (d^P <= d_try), the surface-node pairs of surface_distances() within d_try,
// computed against the same periodic image of body j as the pair's closest points.
#include <span>
#include <string>
#include <vector>

#include "stokescontact/contact/contact_pairs.hpp"
#include "stokescontact/geometry/surface_distances.hpp"

namespace stokescontact {

// A flagged pair i < j with its node pairs, from body i to the image of body j at
// x_j + image_shift. distances.pairs is never empty: it starts with the d^P pair.
struct SurfaceContact {
  Eigen::Index i = 0;
  Eigen::Index j = 0;
  Vec3 image_shift = Vec3::Zero();
  SurfaceDistances distances;
};

// `nodes` holds each body's body-frame surface nodes (surface_nodes(shape, h)), one set per
// body or a single set shared by all bodies, like `shapes`.
template <Shape S>
std::vector<SurfaceContact> find_surface_contacts(std::span<const S> shapes, std::span<const Pose> poses,
                                                  std::span<const SurfaceNodes> nodes, double d_try,
                                                  const std::optional<PeriodicBox>& box = {},
                                                  CellList* cells = nullptr) {
  if (!(nodes.size() == poses.size() || nodes.size() == 1))
    fail_argument("nodes", "must hold one node set per pose or a single shared set, got " +
                               std::to_string(nodes.size()) + " sets for " + std::to_string(poses.size()) +
                               " poses");
  auto nodes_of = [&](Eigen::Index k) -> const SurfaceNodes& {
    return nodes.size() == 1 ? nodes[0] : nodes[static_cast<std::size_t>(k)];
  };
  std::vector<SurfaceContact> contacts;
  for (const ContactPair& p : find_contact_pairs(shapes, poses, d_try, box, cells)) {
    const auto si = static_cast<std::size_t>(p.i), sj = static_cast<std::size_t>(p.j);
    contacts.push_back({p.i, p.j, p.image_shift,
                        surface_distances(shape_of(shapes, si), poses[si], nodes_of(p.i), shape_of(shapes, sj),
                                          shifted(poses[sj], p.image_shift), nodes_of(p.j), d_try)});
  }
  return contacts;
}

template <Shape S>
std::vector<SurfaceContact> find_surface_contacts(const S& shape, std::span<const Pose> poses,
                                                  const SurfaceNodes& nodes, double d_try,
                                                  const std::optional<PeriodicBox>& box = {},
                                                  CellList* cells = nullptr) {
  return find_surface_contacts(std::span<const S>(&shape, 1), poses, std::span<const SurfaceNodes>(&nodes, 1),
                               d_try, box, cells);
}

}  // namespace stokescontact
