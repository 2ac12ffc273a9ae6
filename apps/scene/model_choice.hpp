#pragma once
// Which mobility model a scene gets, and how many dofs per body: only what the scene needs.
// Spheres without torques run 3 dofs (translation); a background flow with vorticity or
// torques on spheres, and every non-spherical shape, run 6. "automatic" picks the cheapest
// model that meets the scene's stated accuracy, from the measured two-sphere table below.
#include <array>
#include <cstdio>
#include <string>
#include <variant>

#include "scene/scene_spec.hpp"

namespace stokescontact::apps {

struct ModelChoice {
  MobilityModel model = MobilityModel::free_draining;
  int dofs_per_body = 6;
  int shell_blobs = 12;  // spheres, multiblob
  std::string reason;    // printed by the runner
};

namespace detail {

// Largest error of the translational pair-mobility functions (x11a, x12a, y11a, y12a, in units
// of 1/(6 pi eta a)) against the exact two-sphere mobility (Jeffrey & Onishi), at gaps 0.1,
// 0.2, 0.5, 1, 2, 4 radii: docs/results.md "Two equal spheres: every model against the exact
// mobility", measured by examples/pair_mobility_accuracy. Cheapest model first.
struct PairErrorRow {
  const char* name;
  MobilityModel model;
  int shell_blobs;
  std::array<double, 6> error;
};
inline constexpr std::array<double, 6> kPairErrorGaps{0.1, 0.2, 0.5, 1.0, 2.0, 4.0};
inline constexpr std::array<PairErrorRow, 5> kPairErrors{{
    {"rpy", MobilityModel::rpy, 0, {0.164, 0.13, 0.0766, 0.0387, 0.0132, 0.00277}},
    {"multiblob shell12", MobilityModel::multiblob, 12, {0.0543, 0.0308, 0.00714, 0.00154, 0.000415, 0.000107}},
    {"multiblob shell42", MobilityModel::multiblob, 42, {0.0215, 0.00702, 0.0013, 0.00106, 0.000366, 7.43e-05}},
    {"multiblob shell162", MobilityModel::multiblob, 162, {0.00599, 0.00147, 0.00128, 0.00053, 0.00016, 3.14e-05}},
    {"multiblob shell642", MobilityModel::multiblob, 642, {0.00196, 0.000245, 0.00026, 0.000121, 4.03e-05, 8.99e-06}},
}};

inline std::string format_g(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

}  // namespace detail

// Whether the bodies' rotations matter: always for non-spheres; for spheres only when torques
// act (a flow's vorticity spins a sphere without moving it, so 3 dofs carry it exactly).
inline bool needs_rotation(const SceneSpec& s) {
  return !std::holds_alternative<Sphere>(s.shape) || s.forces.has_torques();
}

// `gap_over_radius`: the gap the contacts hold (d_hat / R); the table is read at the largest
// listed gap not above it (errors grow as the gap closes), at 0.1 below that.
inline ModelChoice choose_model(const SceneSpec& s, double gap_over_radius) {
  ModelChoice c;
  c.dofs_per_body = needs_rotation(s) ? 6 : 3;
  const MobilitySpec& m = s.mobility;
  const bool sphere = std::holds_alternative<Sphere>(s.shape);
  if (m.model != MobilityModel::automatic) {
    c.model = m.model;
    if (c.model == MobilityModel::rpy && !sphere) throw SceneError("mobility.model", "'rpy' is for spheres only");
    if (c.model == MobilityModel::multiblob) {
      c.dofs_per_body = 6;  // the rigid multiblob model carries rotations
      c.shell_blobs = m.shell_blobs > 0 ? m.shell_blobs : 12;
    }
    c.reason = "named by the scene";
    return c;
  }
  if (!m.hydrodynamic_interactions) {
    c.model = MobilityModel::free_draining;
    c.reason = "automatic: hydrodynamic_interactions is false, so each body moves by its own mobility";
    return c;
  }
  if (!sphere) {
    c.model = MobilityModel::multiblob;
    c.dofs_per_body = 6;
    c.reason = "automatic: the rigid multiblob model is the one model with hydrodynamic interactions for this "
               "shape (no pair-error table for it: accuracy not checked)";
    return c;
  }
  std::size_t column = 0;
  for (std::size_t k = 0; k < detail::kPairErrorGaps.size(); ++k)
    if (detail::kPairErrorGaps[k] <= gap_over_radius) column = k;
  const std::string at = "at gap " + detail::format_g(detail::kPairErrorGaps[column]) + " R";
  for (const detail::PairErrorRow& row : detail::kPairErrors) {
    if (row.error[column] > m.accuracy) continue;
    c.model = row.model;
    c.shell_blobs = row.shell_blobs > 0 ? row.shell_blobs : 12;
    if (c.model == MobilityModel::multiblob) c.dofs_per_body = 6;
    c.reason = "automatic: " + std::string(row.name) + " is the cheapest model with pair-mobility error " +
               detail::format_g(row.error[column]) + " <= accuracy " + detail::format_g(m.accuracy) + " " + at +
               " (d_hat / R = " + detail::format_g(gap_over_radius) + ")";
    return c;
  }
  throw SceneError("mobility.accuracy", "no model reaches " + detail::format_g(m.accuracy) + " " + at +
                                            " (the best, multiblob shell642, has " +
                                            detail::format_g(detail::kPairErrors.back().error[column]) + ")");
}

}  // namespace stokescontact::apps
