#pragma once
// Helpers shared by the test suites: the bad-input check, and the library's seeded random
// inputs (stokescontact/scenes/random.hpp) under the names the suites use.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>

#include "stokescontact/scenes/random.hpp"

namespace test_support {

using stokescontact::Rng;
using stokescontact::random_poses;
using stokescontact::random_rotation;
using stokescontact::random_unit_vector;
using stokescontact::uniform;
using stokescontact::uniform_vector;

// An n x n matrix of independent standard Gaussians (std::mt19937 from `seed`), for the
// Krylov tests (GMRES, Lanczos).
inline stokescontact::MatX random_matrix(Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  stokescontact::MatX a(n, n);
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i) a(i, j) = g(rng);
  return a;
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
