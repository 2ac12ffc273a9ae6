#pragma once
// Seeded random scenes for the contact tests.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "stokescontact/core/pose.hpp"
#include "common/test_support.hpp"

namespace contact_test {

namespace sc = stokescontact;

using test_support::expect_rejects;
using test_support::random_rotation;
using test_support::uniform;
using test_support::uniform_vector;

// n poses with centres uniform in [lo, hi)^3 and random orientations (overlaps allowed).
inline std::vector<sc::Pose> random_poses(std::mt19937_64& rng, int n, double lo, double hi) {
  std::vector<sc::Pose> poses(static_cast<std::size_t>(n));
  for (auto& p : poses) p = {uniform_vector(rng, lo, hi), random_rotation(rng)};
  return poses;
}

}  // namespace contact_test
