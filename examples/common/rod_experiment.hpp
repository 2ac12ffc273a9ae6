#pragma once
// What the rod drivers share (Broms & Tornberg Sec. 3.2): the paper's rod of length L_rod
// end to end and radius R_rod as a Spherocylinder (centre segment L_rod - 2 R_rod: the
// paper's boomerang, "a rod of L_rod / R_rod = 8 and R_rod = 0.5", is 4 long end to end, Sec.
// 3.3.1), the mobility models a rod driver can use, and the contact-direction option.
#include <stokescontact/contact/contact_step.hpp>
#include <stokescontact/geometry/line_contact.hpp>
#include <stokescontact/mobility/free_draining.hpp>
#include <stokescontact/mobility/multiblob_mobility.hpp>
#include <stokescontact/mobility/rod_blobs.hpp>

#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>

namespace examples {

namespace sc = stokescontact;

// L_rod end to end, R_rod the radius.
inline sc::Spherocylinder paper_rod(double L_rod, double R_rod) { return {L_rod - 2.0 * R_rod, R_rod}; }

enum class RodMobilityModel { multiblob, free_draining };

inline RodMobilityModel parse_rod_mobility(const std::string& name) {
  if (name == "multiblob") return RodMobilityModel::multiblob;
  if (name == "free-draining") return RodMobilityModel::free_draining;
  throw std::invalid_argument("unknown mobility '" + name + "' (known: multiblob, free-draining)");
}

inline const char* rod_mobility_name(RodMobilityModel m) {
  return m == RodMobilityModel::multiblob ? "multiblob" : "free-draining";
}

using RodMobility = std::variant<sc::MultiblobMobility, sc::FreeDrainingMobility>;

// The multiblob path a model takes ("dense", "matrix-free" or "adaptive"); "" for any other model.
template <typename M>
const char* multiblob_path(const M& mobility) {
  if constexpr (std::is_same_v<M, sc::MultiblobMobility>) return sc::multiblob_solver_name(mobility.solver());
  return "";
}

// 6 dofs per rod, viscosity 1. multiblob: the rod blob grid of mobility/rod_blobs.hpp with
// `blobs_per_ring` blobs per ring, solved by `solver` (matrix-free GMRES, one dense
// factorisation per configuration, adaptive or automatic: MultiblobOptions);
// free-draining: slender-body drag (Yan et al. eq. 45-50), no hydrodynamic interaction.
inline RodMobility make_rod_mobility(RodMobilityModel model, const sc::Spherocylinder& rod, std::size_t n,
                                     int blobs_per_ring, sc::MultiblobSolver solver) {
  if (model == RodMobilityModel::multiblob) {
    sc::MultiblobOptions options;
    options.solver = solver;
    sc::RodBlobResolution resolution;
    resolution.blobs_per_ring = blobs_per_ring;
    return RodMobility(std::in_place_type<sc::MultiblobMobility>, sc::rod_blob_model(rod, resolution), n, options);
  }
  return RodMobility(std::in_place_type<sc::FreeDrainingMobility>, sc::spherocylinder_mobility(rod, 1.0), n, 6);
}

// Contact directions: "particle" (d^P, Broms & Tornberg eq. 20-21: the closest points of the
// centre segments), "surface" (d^S, eq. 22-23: surface-node pairs), "line" (d^P constrained,
// the force of near-parallel pairs spread over their overlap: geometry/line_contact.hpp,
// rods as LineContactRod), "overlap-ends" (d^P, near-parallel pairs held at both ends of
// their overlap: geometry/overlap_ends.hpp).
enum class RodDirections { particle, surface, line, overlap_ends };

inline RodDirections parse_directions(const std::string& name) {
  if (name == "particle") return RodDirections::particle;
  if (name == "surface") return RodDirections::surface;
  if (name == "line") return RodDirections::line;
  if (name == "overlap-ends") return RodDirections::overlap_ends;
  throw std::invalid_argument("unknown contact directions '" + name + "' (known: particle, surface, line, overlap-ends)");
}

inline const char* directions_name(RodDirections d) {
  switch (d) {
    case RodDirections::particle: return "particle";
    case RodDirections::surface: return "surface";
    case RodDirections::line: return "line";
    case RodDirections::overlap_ends: return "overlap-ends";
  }
  return "?";
}

inline sc::ContactDirections contact_directions(RodDirections d) {
  return d == RodDirections::surface        ? sc::ContactDirections::surface
         : d == RodDirections::overlap_ends ? sc::ContactDirections::overlap_ends
                                            : sc::ContactDirections::particle;
}

// The line-contact rod of `rod`: full spreading below `angle` rad, force density falling to 0
// `width` above the closest gap.
inline sc::LineContactRod line_contact_rod(const sc::Spherocylinder& rod, double width, double angle) {
  sc::LineContactRod out{rod, {width, angle}};
  sc::validate(out);
  return out;
}

}  // namespace examples
