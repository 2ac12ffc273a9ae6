#pragma once
// The bodies of a scene: its poses from the scene's list or generator, its forces stacked for
// the chosen dofs, and the checks a start must pass (contact free, inside the box).
#include <cmath>
#include <random>
#include <span>
#include <string>
#include <vector>

#include <stokescontact/scenes/random.hpp>
#include <stokescontact/scenes/sphere_packing.hpp>

#include "scene/scene_spec.hpp"

namespace stokescontact::apps {

namespace detail {

inline std::vector<Pose> lattice_poses(const LatticeSpec& l) {
  std::vector<Pose> poses;
  for (long long i = 0; i < l.counts[0]; ++i)
    for (long long j = 0; j < l.counts[1]; ++j)
      for (long long k = 0; k < l.counts[2]; ++k) {
        const Vec3 index(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
        const Vec3 middle = 0.5 * (Vec3(static_cast<double>(l.counts[0]), static_cast<double>(l.counts[1]),
                                        static_cast<double>(l.counts[2])) -
                                   Vec3::Ones());
        poses.push_back({l.centre + l.spacing.cwiseProduct(index - middle), l.orientation});
      }
  return poses;
}

// One at a time, each kept only if every gap to the kept bodies exceeds min_gap (Broms &
// Tornberg Sec. 3.3.2 place their boomerangs so).
template <Shape S>
std::vector<Pose> random_placement(const RandomPlacementSpec& p, const S& shape) {
  Rng rng(p.seed);
  std::vector<Pose> poses;
  const double reach = 2.0 * bounding_radius(shape) + p.min_gap;
  long long rejected = 0;
  while (poses.size() < p.count) {
    if (rejected == p.max_attempts)
      throw SceneError("bodies.random_placement", "placed only " + std::to_string(poses.size()) + " of " +
                                                      std::to_string(p.count) + " bodies after " +
                                                      std::to_string(p.max_attempts) +
                                                      " rejected draws in a row: enlarge side or lower count");
    const Pose candidate{uniform_vector(rng, 0.0, p.side), random_rotation(rng)};
    bool ok = true;
    for (const Pose& q : poses) {
      if ((candidate.x - q.x).norm() > reach) continue;
      if (!(closest_points(shape, candidate, shape, q).distance > p.min_gap)) {
        ok = false;
        break;
      }
    }
    if (!ok) {
      ++rejected;
      continue;
    }
    poses.push_back(candidate);
    rejected = 0;
  }
  return poses;
}

}  // namespace detail

template <Shape S>
std::vector<Pose> scene_poses(const SceneSpec& s, const S& shape) {
  return std::visit(
      [&](const auto& b) -> std::vector<Pose> {
        using B = std::decay_t<decltype(b)>;
        if constexpr (std::is_same_v<B, std::vector<Pose>>) {
          return b;
        } else if constexpr (std::is_same_v<B, LatticeSpec>) {
          return detail::lattice_poses(b);
        } else if constexpr (std::is_same_v<B, SpherePackingSpec>) {
          const double radius = std::get<Sphere>(s.shape).radius;
          return b.dense ? dense_packing(b.count, b.packing_fraction, b.seed, radius).poses
                         : random_sequential_addition(b.count, b.packing_fraction, b.seed, radius).poses;
        } else {
          return detail::random_placement(b, shape);
        }
      },
      s.bodies);
}

// A start the contact step can take: centres finite, a box larger than a body, every pair
// contact free (d^P >= 0). Returns the smallest gap (infinite for one body).
template <Shape S>
double check_start(const SceneSpec& s, const S& shape, std::span<const Pose> poses) {
  for (std::size_t k = 0; k < poses.size(); ++k)
    if (!poses[k].x.allFinite()) throw SceneError("bodies", "body " + std::to_string(k) + " has a non-finite centre");
  std::optional<PeriodicBox> box;
  if (s.box) {
    box = PeriodicBox{*s.box};
    for (int k = 0; k < 3; ++k)
      if ((*s.box)(k) < 2.0 * bounding_radius(shape) + 2.0 * s.contact.d_hat)
        throw SceneError("box", "is smaller than a body: length " + JsonReader::format((*s.box)(k)) +
                                    " < 2 x bounding radius " + JsonReader::format(bounding_radius(shape)) +
                                    " + 2 d_hat");
  }
  if (poses.size() < 2) return std::numeric_limits<double>::infinity();
  const MinimumDistance closest = minimum_pair_distance(shape, poses, box);
  if (closest.distance < 0.0)
    throw SceneError("bodies", "bodies " + std::to_string(closest.i) + " and " + std::to_string(closest.j) +
                                   " overlap (d = " + JsonReader::format(closest.distance) +
                                   "); a start must be contact free");
  return closest.distance;
}

// F_ext stacked for `dofs` per body (3: forces only).
inline VecX stacked_forces(const ForcesSpec& f, std::size_t bodies, int dofs) {
  const auto n = static_cast<Eigen::Index>(bodies);
  VecX F = VecX::Zero(n * dofs);
  if (f.kind == ForcesSpec::Kind::none) return F;
  std::vector<Vec3> forces(bodies, f.force), torques(bodies, f.torque);
  if (f.kind == ForcesSpec::Kind::random) {
    Rng rng(f.seed);
    forces = random_forces(bodies, f.magnitude, rng);
    torques.assign(bodies, Vec3::Zero());
  } else if (f.kind == ForcesSpec::Kind::per_body) {
    for (const char* key : {"force", "torque"}) {
      const std::vector<Vec3>& given = std::string(key) == "force" ? f.forces : f.torques;
      if (!given.empty() && given.size() != bodies)
        throw SceneError(std::string("forces.") + key, "has " + std::to_string(given.size()) + " entries for " +
                                                            std::to_string(bodies) + " bodies");
    }
    forces = f.forces.empty() ? std::vector<Vec3>(bodies, Vec3::Zero()) : f.forces;
    torques = f.torques.empty() ? std::vector<Vec3>(bodies, Vec3::Zero()) : f.torques;
  }
  for (Eigen::Index b = 0; b < n; ++b) {
    F.segment<3>(b * dofs) = forces[static_cast<std::size_t>(b)];
    if (dofs == 6) F.segment<3>(b * dofs + 3) = torques[static_cast<std::size_t>(b)];
  }
  return F;
}

}  // namespace stokescontact::apps
