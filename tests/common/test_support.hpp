#pragma once
// Helpers shared by the test suites: the bad-input check, and the library's seeded random
// inputs (stokescontact/scenes/random.hpp) under the names the suites use.
#include <gtest/gtest.h>

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
