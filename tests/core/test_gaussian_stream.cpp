#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "stokescontact/core/gaussian_stream.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace gaussian_stream_tests {

namespace sc = stokescontact;

TEST(GaussianStream, SameSeedGivesTheSameStream) {
  sc::GaussianStream a(42), b(42), c(43);
  EXPECT_EQ(a.seed(), 42u);
  const sc::VecX va = a.vector(101);
  for (Eigen::Index i = 0; i < va.size(); ++i) EXPECT_EQ(va(i), b()) << i;  // vector(n) = n calls
  EXPECT_NE(va, c.vector(101));
}

// The documented algorithm, rebuilt from the raw engine: the polar method on 53-bit uniforms
// of std::mt19937_64 (whose sequence the C++ standard fixes), pairs in order (x, y).
TEST(GaussianStream, IsThePolarMethodOnMt19937_64) {
  const std::uint64_t seed = 987654321;
  std::mt19937_64 engine(seed);
  sc::GaussianStream stream(seed);
  const auto uniform = [&] { return static_cast<double>(engine() >> 11) / 9007199254740992.0; };
  for (int pair = 0; pair < 50; ++pair) {
    double x, y, s;
    do {
      x = 2.0 * uniform() - 1.0;
      y = 2.0 * uniform() - 1.0;
      s = x * x + y * y;
    } while (s >= 1.0 || s == 0.0);
    const double f = std::sqrt(-2.0 * std::log(s) / s);
    EXPECT_EQ(stream(), x * f) << "pair " << pair;
    EXPECT_EQ(stream(), y * f) << "pair " << pair;
  }
}

// Moments of N(0, 1) within five standard errors of n samples.
TEST(GaussianStream, HasStandardNormalMoments) {
  const std::uint64_t seed = 2024;
  SCOPED_TRACE("seed " + std::to_string(seed));
  sc::GaussianStream stream(seed);
  const int n = 200000;
  double m1 = 0, m2 = 0, m4 = 0, inside = 0;
  for (int i = 0; i < n; ++i) {
    const double x = stream();
    m1 += x;
    m2 += x * x;
    m4 += x * x * x * x;
    inside += std::abs(x) < 1.0 ? 1.0 : 0.0;
  }
  m1 /= n;
  m2 /= n;
  m4 /= n;
  inside /= n;
  const double root_n = std::sqrt(static_cast<double>(n));
  const double p = std::erf(1.0 / std::sqrt(2.0));  // P(|x| < 1) = 0.6827
  EXPECT_LT(std::abs(m1), 5.0 / root_n);                                  // var x = 1
  EXPECT_LT(std::abs(m2 - 1.0), 5.0 * std::sqrt(2.0) / root_n);           // var x^2 = 2
  EXPECT_LT(std::abs(m4 - 3.0), 5.0 * std::sqrt(96.0) / root_n);          // var x^4 = 105 - 9
  EXPECT_LT(std::abs(inside - p), 5.0 * std::sqrt(p * (1.0 - p)) / root_n);
}

}  // namespace gaussian_stream_tests
