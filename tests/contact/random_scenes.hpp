#pragma once
// Seeded random scenes for the contact tests.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "stokescontact/core/pose.hpp"

namespace contact_test {

namespace sc = stokescontact;

inline double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

inline sc::Vec3 uniform_vector(std::mt19937_64& rng, double lo, double hi) {
  return {uniform(rng, lo, hi), uniform(rng, lo, hi), uniform(rng, lo, hi)};
}

inline sc::Quat random_rotation(std::mt19937_64& rng) {
  for (;;) {
    const Eigen::Vector4d v(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    if (v.norm() > 0.1 && v.norm() < 1.0) return sc::Quat(v[0], v[1], v[2], v[3]).normalized();
  }
}

// n poses with centres uniform in [lo, hi)^3 and random orientations (overlaps allowed).
inline std::vector<sc::Pose> random_poses(std::mt19937_64& rng, int n, double lo, double hi) {
  std::vector<sc::Pose> poses(static_cast<std::size_t>(n));
  for (auto& p : poses) p = {uniform_vector(rng, lo, hi), random_rotation(rng)};
  return poses;
}

// Runs f, expects std::invalid_argument whose message names `field`.
template <typename F>
void expect_rejects(F&& f, const std::string& field) {
  try {
    f();
    FAIL() << "expected std::invalid_argument naming " << field;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

}  // namespace contact_test
