#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "stokescontact/contact/barrier.hpp"
#include "common/test_support.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace barrier_tests {

namespace sc = stokescontact;
using sc::BarrierFunction;
using sc::BarrierParameters;

namespace {

using test_support::expect_rejects;

constexpr std::array<BarrierFunction, 3> kAll = {BarrierFunction::b, BarrierFunction::b0, BarrierFunction::b1};

const char* name(BarrierFunction f) {
  switch (f) {
    case BarrierFunction::b: return "b";
    case BarrierFunction::b0: return "b0";
    case BarrierFunction::b1: return "b1";
  }
  return "?";
}

// Parameter sets covering: no shift, a shift as in the paper (eps_reg = d_hat_try), a
// non-unit scale.
std::vector<BarrierParameters> parameter_sets() {
  return {{1.0, 0.0, 1e-2}, {0.05, 0.05, 1e-3}, {3.0, 0.5, 0.2}};
}

}  // namespace

// Central differences with step s = 1e-6 d_hat at points at least 1e-3 d_hat from the
// kinks (d_hat, the cap): truncation ~ s^2 |f'''| and rounding ~ 1e-16 |f| / s stay below
// the stated tolerance 1e-6 max(1, |f'|) (relative to the derivative's own size).
TEST(Barrier, DerivativesMatchCentralDifferences) {
  for (const auto& p : parameter_sets()) {
    const double cap_d = p.eps_cap - p.eps_reg;  // d where the cap sits
    const double lo = cap_d - 0.5 * p.d_hat;     // reach into the linear extension
    const double s = 1e-6 * p.d_hat;
    for (const BarrierFunction f : kAll) {
      for (int k = 0; k <= 400; ++k) {
        const double d = lo + (p.d_hat - lo) * k / 400.0;
        if (std::abs(d - p.d_hat) < 1e-3 * p.d_hat || std::abs(d - cap_d) < 1e-3 * p.d_hat) continue;
        const sc::BarrierValue v = sc::barrier(f, d, p);
        const sc::BarrierValue plus = sc::barrier(f, d + s, p), minus = sc::barrier(f, d - s, p);
        const double fd1 = (plus.value - minus.value) / (2.0 * s);
        const double fd2 = (plus.first - minus.first) / (2.0 * s);
        EXPECT_NEAR(v.first, fd1, 1e-6 * std::max(1.0, std::abs(v.first)))
            << name(f) << " d = " << d << " d_hat = " << p.d_hat;
        EXPECT_NEAR(v.second, fd2, 1e-6 * std::max(1.0, std::abs(v.second)))
            << name(f) << " d = " << d << " d_hat = " << p.d_hat;
      }
    }
  }
}

// Regularity at d_hat: b is C2 (value, b', b'' -> 0), b1 is C1, b0 only C0 (b0' -> -1/h).
TEST(Barrier, RegularityAtThreshold) {
  for (const auto& p : parameter_sets()) {
    const double h = p.d_hat + p.eps_reg, delta = 1e-7 * p.d_hat;
    const auto b = sc::barrier_b(p.d_hat - delta, p);
    EXPECT_LT(std::abs(b.value), 1e-12);
    EXPECT_LT(std::abs(b.first), 1e-10);
    EXPECT_LT(std::abs(b.second), 1e-5);
    const auto b1 = sc::barrier_b1(p.d_hat - delta, p);
    EXPECT_LT(std::abs(b1.value), 1e-10);
    EXPECT_LT(std::abs(b1.first), 1e-5);
    EXPECT_NEAR(b1.second, 2.0 / h, 1e-5 / h);  // the jump that makes b1 only C1
    const auto b0 = sc::barrier_b0(p.d_hat - delta, p);
    EXPECT_LT(std::abs(b0.value), 1e-5);
    EXPECT_NEAR(b0.first, -1.0 / h, 1e-5 / h);  // the jump that makes b0 only C0
  }
}

// C0 and C1 at the cap: value and first derivative from both sides agree to O(delta).
TEST(Barrier, ContinuousWithContinuousSlopeAtCap) {
  for (const auto& p : parameter_sets()) {
    const double cap_d = p.eps_cap - p.eps_reg, delta = 1e-9 * p.d_hat;
    for (const BarrierFunction f : kAll) {
      const auto below = sc::barrier(f, cap_d - delta, p), above = sc::barrier(f, cap_d + delta, p);
      const double slope = std::abs(above.first), curvature = std::abs(above.second);
      EXPECT_NEAR(below.value, above.value, 4.0 * delta * slope + 1e-12 * std::abs(above.value)) << name(f);
      EXPECT_NEAR(below.first, above.first, 4.0 * delta * curvature + 1e-12 * slope) << name(f);
      EXPECT_EQ(below.second, 0.0) << name(f);  // linear below the cap
    }
  }
}

TEST(Barrier, ZeroAtAndBeyondThreshold) {
  for (const auto& p : parameter_sets())
    for (const BarrierFunction f : kAll)
      for (const double d : {p.d_hat, std::nextafter(p.d_hat, 2.0 * p.d_hat), 2.0 * p.d_hat, 1e300}) {
        const auto v = sc::barrier(f, d, p);
        EXPECT_EQ(v.value, 0.0) << name(f) << " d = " << d;
        EXPECT_EQ(v.first, 0.0) << name(f) << " d = " << d;
        EXPECT_EQ(v.second, 0.0) << name(f) << " d = " << d;
      }
}

// Positive, strictly decreasing and with a negative slope everywhere below d_hat, the
// linear extension and deep overlaps included; finite for any finite d.
TEST(Barrier, PositiveAndDecreasingBelowThreshold) {
  for (const auto& p : parameter_sets())
    for (const BarrierFunction f : kAll) {
      double previous = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 1000; ++k) {
        const double d = -10.0 * p.d_hat + 11.0 * p.d_hat * k / 1000.0;
        if (d >= p.d_hat) break;
        const auto v = sc::barrier(f, d, p);
        ASSERT_TRUE(std::isfinite(v.value) && std::isfinite(v.first)) << name(f) << " d = " << d;
        EXPECT_GT(v.value, 0.0) << name(f) << " d = " << d;
        EXPECT_LT(v.first, 0.0) << name(f) << " d = " << d;
        EXPECT_LT(v.value, previous) << name(f) << " d = " << d;
        previous = v.value;
      }
      EXPECT_TRUE(std::isfinite(sc::barrier(f, -1e12, p).value));
    }
}

// Values worked out by hand from eq. 10 and 24.
TEST(Barrier, ClosedFormValues) {
  const double ln2 = std::numbers::ln2, ln10 = std::numbers::ln10;
  const BarrierParameters plain{1.0, 0.0, 1e-2};
  EXPECT_NEAR(sc::barrier_b(0.5, plain).value, 0.25 * ln2, 1e-15);         // -(1/4) ln(1/2)
  EXPECT_NEAR(sc::barrier_b(0.5, plain).first, -ln2 - 0.5, 1e-15);         // -2(-1/2)ln(1/2) - (1/4)/(1/2)
  EXPECT_NEAR(sc::barrier_b0(0.5, plain).value, ln2, 1e-15);
  EXPECT_NEAR(sc::barrier_b0(0.25, plain).first, -4.0, 1e-14);
  EXPECT_NEAR(sc::barrier_b1(0.5, plain).value, 0.5 * ln2, 1e-15);         // (-1/2)(-ln 2)
  EXPECT_NEAR(sc::barrier_b1(0.5, plain).second, 2.0 + 4.0, 1e-13);         // 1/x + h/x^2
  // eps_reg: x = d + 1, h = 2; at d = 0, b = -(1 - 2)^2 ln(1/2) = ln 2.
  const BarrierParameters shifted{1.0, 1.0, 1e-2};
  EXPECT_NEAR(sc::barrier_b(0.0, shifted).value, ln2, 1e-15);
  // eps_cap = 0.1: below the cap b0 is ln 10 - 10 (x - 0.1); at d = -1 that is ln 10 + 11.
  const BarrierParameters capped{1.0, 0.0, 0.1};
  EXPECT_NEAR(sc::barrier_b0(-1.0, capped).value, ln10 + 11.0, 1e-13);
  EXPECT_NEAR(sc::barrier_b0(-1.0, capped).first, -10.0, 1e-13);
  // Paper-style defaults: cap at 1e-2 (d_hat + eps_reg).
  const BarrierParameters def = sc::barrier_parameters(0.1, 0.1);
  EXPECT_DOUBLE_EQ(def.eps_cap, 2e-3);
}

TEST(Barrier, EnergySumsTheBarriers) {
  const BarrierParameters p{1.0, 0.0, 1e-2};
  const std::vector<double> d = {0.5, 2.0, 0.25, 1.0};
  const double expected = sc::barrier_b(0.5, p).value + sc::barrier_b(0.25, p).value;
  EXPECT_DOUBLE_EQ(sc::barrier_energy(d, p), expected);
  const std::vector<double> clear = {1.0, 1.5, 7.0};
  EXPECT_EQ(sc::barrier_energy(clear, p), 0.0);
}

TEST(Barrier, RejectsBadParameters) {
  expect_rejects([] { sc::barrier_b(0.5, {0.0, 0.0, 1e-3}); }, "BarrierParameters.d_hat");
  expect_rejects([] { sc::barrier_b(0.5, {-1.0, 0.0, 1e-3}); }, "BarrierParameters.d_hat");
  expect_rejects([] { sc::barrier_b(0.5, {1.0, -0.1, 1e-3}); }, "BarrierParameters.eps_reg");
  expect_rejects([] { sc::barrier_b(0.5, {1.0, 0.0, 0.0}); }, "BarrierParameters.eps_cap");
  expect_rejects([] { sc::barrier_b(0.5, {1.0, 0.5, 1.5}); }, "BarrierParameters.eps_cap");
  expect_rejects([] { sc::barrier_b(std::nan(""), {1.0, 0.0, 1e-3}); }, "d");
  expect_rejects([] { sc::barrier_parameters(-1.0); }, "d_hat");
  expect_rejects([] { sc::barrier_parameters(1.0, 0.0, 1.0); }, "cap_fraction");
}

}  // namespace barrier_tests
