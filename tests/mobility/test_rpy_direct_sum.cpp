#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "stokescontact/mobility/rpy_direct_sum.hpp"
#include "stokescontact/mobility/rpy_kernel.hpp"
#include "stokescontact/mobility/rpy_rotation_kernel.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace rpy_direct_sum_tests {

namespace sc = stokescontact;

namespace {

constexpr unsigned kSeed = 4242;
constexpr sc::RpyInstructionSet kAllSets[] = {sc::RpyInstructionSet::baseline, sc::RpyInstructionSet::avx2_fma,
                                              sc::RpyInstructionSet::avx512};

std::vector<sc::RpyInstructionSet> supported_sets() {
  std::vector<sc::RpyInstructionSet> out;
  for (const auto isa : kAllSets)
    if (sc::rpy_instruction_set_supported(isa)) out.push_back(isa);
  return out;
}

// M / mu0 in blob units, assembled from the scalar reference blocks at a = 1, eta = 1
// (then mu_rt a / mu0 and mu_r a^2 / mu0 are the blocks over mu0 too).
sc::MatX reference_matrix(const sc::Mat3X& x, int dofs) {
  const Eigen::Index n = x.cols();
  const double mu0 = sc::stokes_mobility(1.0, 1.0);
  sc::MatX m(dofs * n, dofs * n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      const sc::Vec3 r = x.col(i) - x.col(j);
      m.block<3, 3>(dofs * i, dofs * j) = sc::rpy_translation(r, 1.0, 1.0) / mu0;
      if (dofs == 6) {
        const sc::Mat3 rt = sc::rpy_rotation_translation(r, 1.0, 1.0) / mu0;
        m.block<3, 3>(6 * i, 6 * j + 3) = rt;
        m.block<3, 3>(6 * i + 3, 6 * j) = rt;
        m.block<3, 3>(6 * i + 3, 6 * j + 3) = sc::rpy_rotation_rotation(r, 1.0, 1.0) / mu0;
      }
    }
  return m;
}

sc::Mat3X random_blobs(Eigen::Index n, double box, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, box);
  sc::Mat3X x(3, n);
  for (Eigen::Index i = 0; i < n; ++i) x.col(i) = sc::Vec3(u(rng), u(rng), u(rng));
  return x;
}

sc::VecX random_vector(Eigen::Index n, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  sc::VecX v(n);
  for (Eigen::Index i = 0; i < n; ++i) v(i) = g(rng);
  return v;
}

double max_relative_error(const sc::VecX& u, const sc::VecX& reference) {
  return (u - reference).cwiseAbs().maxCoeff() / reference.cwiseAbs().maxCoeff();
}

// Every branch: far, overlapping, exactly touching (r = 2a), coincident blobs (r = 0).
sc::Mat3X branch_blobs() {
  sc::Mat3X x(3, 9);
  x << 0.0, 2.0, 5.0, 1.3, 2.0, -0.4, 0.0, 7.0, 2.0,  //
      0.0, 0.0, 1.0, 0.4, 0.0, 0.2, 2.0, -3.0, 2.0,   //
      0.0, 0.0, -2.0, 0.2, 0.0, 0.1, 0.0, 1.0, 0.0;
  return x;  // blobs 1 and 4 coincide; 0-1, 0-6 and 1-8 are exactly 2 apart
}

}  // namespace

TEST(RpyDirectSum, InverseSqrtIsAccurateToAFewUlp) {
  double worst = 0.0;
  for (double e = -300.0; e <= 300.0; e += 0.37) {
    const double x = std::pow(10.0, e);
    const double exact = 1.0 / std::sqrt(x);
    worst = std::max(worst, std::abs(sc::detail::inverse_sqrt(x) - exact) / exact);
  }
  EXPECT_LT(worst, 4.0 * std::numeric_limits<double>::epsilon());
}

// The production coefficients against rpy_translation_coefficients and
// rpy_rotation_coefficients, on both branches, at r = 2 exactly and on either side of it.
TEST(RpyDirectSum, PairTermsAreTheReferenceCoefficientsInBlobUnits) {
  const double two = 2.0;
  for (const double r : {1e-9, 0.3, 1.0, 1.7, std::nextafter(two, 0.0), two, std::nextafter(two, 3.0), 2.3, 4.0,
                         17.0, 1e3}) {
    const sc::RpyCoefficients t = sc::rpy_translation_coefficients(r, 1.0);
    const sc::RpyRotationCoefficients q = sc::rpy_rotation_coefficients(r, 1.0);
    const sc::detail::RpyPairTerms c = sc::detail::rpy_pair_terms<true>(r * r);
    const sc::detail::RpyPairTerms c3 = sc::detail::rpy_pair_terms<false>(r * r);
    const std::string at = "r = " + std::to_string(r);
    // A few ulp of the value, or of the O(1) terms that cancel in the near branch.
    auto expect_close = [&](double value, double reference, const char* name) {
      const double scale = r <= 2.0 ? std::max(std::abs(reference), 1.0) : std::abs(reference);
      EXPECT_NEAR(value, reference, 1e-15 * scale) << name << ", " << at;
    };
    expect_close(c.tt_f, t.f, "tt_f");
    expect_close(c.tt_h, t.g / (r * r), "tt_h");
    expect_close(c.rt, 0.75 * q.w / r, "rt");
    expect_close(c.rr_f, 0.75 * q.f_r, "rr_f");
    expect_close(c.rr_h, 0.75 * q.g_r / (r * r), "rr_h");
    EXPECT_EQ(c3.tt_f, c.tt_f) << at;
    EXPECT_EQ(c3.tt_h, c.tt_h) << at;
  }
  // r = 0: the self mobility, and finite terms that multiply r = 0.
  const sc::detail::RpyPairTerms self = sc::detail::rpy_pair_terms<true>(0.0);
  EXPECT_EQ(self.tt_f, 1.0);
  EXPECT_EQ(self.rr_f, 0.75);
  EXPECT_TRUE(std::isfinite(self.tt_h) && std::isfinite(self.rt) && std::isfinite(self.rr_h));
}

TEST(RpyDirectSum, MatchesTheReferenceBlocksInEveryBranch) {
  std::mt19937 rng(kSeed);
  const sc::Mat3X x = branch_blobs();
  for (const int dofs : {3, 6}) {
    const sc::MatX m = reference_matrix(x, dofs);
    const sc::VecX F = random_vector(m.cols(), rng);
    for (const auto isa : supported_sets()) {
      SCOPED_TRACE(std::string(sc::rpy_instruction_set_name(isa)) + ", dofs " + std::to_string(dofs));
      EXPECT_LT(max_relative_error(sc::rpy_direct_sum(x, F, dofs, isa), m * F), 1e-14);
      // Each column: one blob pushed, every pair block seen on its own.
      for (Eigen::Index k = 0; k < m.cols(); ++k) {
        const sc::VecX e = sc::VecX::Unit(m.cols(), k);
        EXPECT_LT((sc::rpy_direct_sum(x, e, dofs, isa) - m.col(k)).cwiseAbs().maxCoeff(), 1e-15) << "column " << k;
      }
    }
  }
}

// Several blocks, padded, with overlaps.
TEST(RpyDirectSum, MatchesTheReferenceBlocksAcrossBlocks) {
  std::mt19937 rng(kSeed + 1);
  for (const Eigen::Index n : {1, 13, 300, 416}) {
    const sc::Mat3X x = random_blobs(n, std::cbrt(static_cast<double>(n)) * 1.2, rng);  // many overlaps
    for (const int dofs : {3, 6}) {
      const sc::MatX m = reference_matrix(x, dofs);
      const sc::VecX F = random_vector(m.cols(), rng);
      const sc::VecX expected = m * F;
      for (const auto isa : supported_sets()) {
        SCOPED_TRACE("seed " + std::to_string(kSeed + 1) + ", n " + std::to_string(n) + ", " +
                     sc::rpy_instruction_set_name(isa) + ", dofs " + std::to_string(dofs));
        EXPECT_LT(max_relative_error(sc::rpy_direct_sum(x, F, dofs, isa), expected), 1e-14);
        EXPECT_EQ(sc::rpy_direct_sum(x, sc::VecX::Zero(m.cols()), dofs, isa).cwiseAbs().maxCoeff(), 0.0);
      }
    }
  }
}

TEST(RpyDirectSum, SingleBlobIsItsSelfMobility) {
  const sc::Mat3X x = sc::Vec3(0.3, -1.0, 2.0);
  const sc::VecX F = (sc::VecX(6) << 1.0, -2.0, 0.5, 0.25, 3.0, -1.0).finished();
  for (const auto isa : supported_sets()) {
    EXPECT_EQ(sc::rpy_direct_sum(x, F.head<3>(), 3, isa), F.head<3>());
    const sc::VecX U = sc::rpy_direct_sum(x, F, 6, isa);
    EXPECT_EQ(U.head<3>(), F.head<3>());
    EXPECT_EQ(U.tail<3>(), 0.75 * F.tail<3>());  // mu_r a^2 / mu0 = 3/4
  }
}

// The dispatched instruction sets against the baseline loop: equal to rounding.
TEST(RpyDirectSum, InstructionSetsAgreeToRounding) {
  std::mt19937 rng(kSeed + 2);
  const sc::Mat3X x = random_blobs(1000, 14.0, rng);
  EXPECT_TRUE(sc::rpy_instruction_set_supported(sc::rpy_best_instruction_set()));
  for (const int dofs : {3, 6}) {
    const sc::VecX F = random_vector(dofs * x.cols(), rng);
    const sc::VecX baseline = sc::rpy_direct_sum(x, F, dofs, sc::RpyInstructionSet::baseline);
    for (const auto isa : supported_sets())
      EXPECT_LT(max_relative_error(sc::rpy_direct_sum(x, F, dofs, isa), baseline), 1e-14)
          << sc::rpy_instruction_set_name(isa) << ", dofs " << dofs;
    EXPECT_EQ(sc::rpy_direct_sum(x, F, dofs), sc::rpy_direct_sum(x, F, dofs, sc::rpy_best_instruction_set()));
  }
}

#ifdef _OPENMP
// Each blob sums its sources in one order, whatever the number of threads.
TEST(RpyDirectSum, ThreadCountDoesNotChangeTheSum) {
  std::mt19937 rng(kSeed + 3);
  const sc::Mat3X x = random_blobs(1100, 15.0, rng);
  ASSERT_GE(sc::detail::rpy_blocks(x.cols()).count, sc::detail::kRpyParallelMinBlocks);  // runs in parallel
  const int threads = omp_get_max_threads();
  for (const int dofs : {3, 6}) {
    const sc::VecX F = random_vector(dofs * x.cols(), rng);
    for (const auto isa : supported_sets()) {
      omp_set_num_threads(1);
      const sc::VecX serial = sc::rpy_direct_sum(x, F, dofs, isa);
      for (const int t : {2, 3}) {
        omp_set_num_threads(t);
        EXPECT_EQ(sc::rpy_direct_sum(x, F, dofs, isa), serial)
            << sc::rpy_instruction_set_name(isa) << ", dofs " << dofs << ", " << t << " threads";
      }
    }
  }
  omp_set_num_threads(threads);
}
#endif

TEST(RpyDirectSum, BlocksCoverTheBlobsWithLittlePadding) {
  for (Eigen::Index n = 1; n <= 2000; ++n) {
    const sc::detail::RpyBlocks b = sc::detail::rpy_blocks(n);
    EXPECT_GE(b.count * b.size, n);
    EXPECT_LT(b.count * b.size, n + b.count * sc::detail::kRpyLanes);
    EXPECT_LE(b.size, sc::detail::kRpyBlock);
    EXPECT_EQ(b.size % sc::detail::kRpyLanes, 0);
  }
}

TEST(RpyDirectSum, RefusesBadInput) {
  const sc::Mat3X x = sc::Mat3X::Zero(3, 2);
  EXPECT_THROW(sc::rpy_direct_sum(x, sc::VecX::Zero(8), 4), std::invalid_argument);
  EXPECT_THROW(sc::rpy_direct_sum(x, sc::VecX::Zero(5), 3), std::invalid_argument);
  EXPECT_THROW(sc::rpy_direct_sum(x, sc::VecX::Zero(6), 6), std::invalid_argument);
  for (const auto isa : kAllSets) {
    if (!sc::rpy_instruction_set_supported(isa)) {
      EXPECT_THROW(sc::rpy_direct_sum(x, sc::VecX::Zero(6), 3, isa), std::invalid_argument);
    }
  }
  EXPECT_EQ(sc::rpy_direct_sum(sc::Mat3X(3, 0), sc::VecX(0), 3).size(), 0);
}

}  // namespace rpy_direct_sum_tests
