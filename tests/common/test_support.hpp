#pragma once
// Helpers shared by the test suites: reproducible random inputs and the bad-input check.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>

#include "stokescontact/core/types.hpp"

namespace test_support {

namespace sc = stokescontact;
using Rng = std::mt19937_64;

// Uniform in [lo, hi) from 53 random bits: the same stream on every platform.
inline double uniform(Rng& rng, double lo, double hi) {
  return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

inline sc::Vec3 uniform_vector(Rng& rng, double lo, double hi) {
  return {uniform(rng, lo, hi), uniform(rng, lo, hi), uniform(rng, lo, hi)};
}

// Uniform on the sphere of directions (rejection from the unit ball).
inline sc::Vec3 random_unit_vector(Rng& rng) {
  for (;;) {
    const sc::Vec3 v = uniform_vector(rng, -1, 1);
    const double n = v.norm();
    if (n > 0.1 && n < 1.0) return v / n;
  }
}

// Uniform on SO(3): a uniform point of the unit 4-ball, normalised.
inline sc::Quat random_rotation(Rng& rng) {
  for (;;) {
    const Eigen::Vector4d v(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1),
                            uniform(rng, -1, 1));
    if (v.norm() > 0.1 && v.norm() < 1.0) return sc::Quat(v[0], v[1], v[2], v[3]).normalized();
  }
}

// Runs f, expects std::invalid_argument whose message names `field`.
template <typename F>
void expect_rejects(F&& f, const std::string& field) {
  try {
    f();
    ADD_FAILURE() << "no exception; expected std::invalid_argument naming " << field;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

}  // namespace test_support
