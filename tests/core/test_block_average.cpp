#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/core/block_average.hpp"
#include "stokescontact/core/gaussian_stream.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace block_average_tests {

namespace sc = stokescontact;

namespace {

using test_support::expect_rejects;

constexpr std::size_t kSamples = std::size_t{1} << 14;

// x_{k+1} = a x_k + sqrt(1 - a^2) e_k, started in its stationary distribution (unit variance).
std::vector<double> ar1_series(double a, std::size_t n, std::uint64_t seed) {
  sc::GaussianStream g(seed);
  std::vector<double> x(n);
  x[0] = g();
  for (std::size_t k = 1; k < n; ++k) x[k] = a * x[k - 1] + std::sqrt(1.0 - a * a) * g();
  return x;
}

sc::BlockAverageResult average(const std::vector<double>& x) {
  sc::BlockAverage b;
  for (double v : x) b.add(v);
  return b.result();
}

// The blocking transformation done by hand on the whole array (Flyvbjerg & Petersen's
// recipe: halve, dropping an odd last element), for comparison with the on-line levels.
std::vector<double> batch_std_errors(std::vector<double> x) {
  std::vector<double> out;
  while (x.size() >= 2) {
    const double n = static_cast<double>(x.size());
    double mean = 0.0;
    for (double v : x) mean += v / n;
    double ss = 0.0;
    for (double v : x) ss += (v - mean) * (v - mean);
    out.push_back(std::sqrt(ss / (n - 1.0) / n));
    std::vector<double> half(x.size() / 2);
    for (std::size_t k = 0; k < half.size(); ++k) half[k] = 0.5 * (x[2 * k] + x[2 * k + 1]);
    x = std::move(half);
  }
  return out;
}

TEST(BlockAverage, IidGaussianErrorBarIsSigmaOverRootN) {
  const std::vector<double> x = ar1_series(0.0, kSamples, 2024);
  const sc::BlockAverageResult r = average(x);
  const double expected = 1.0 / std::sqrt(static_cast<double>(kSamples));
  std::printf("[iid] se = %.6g, sigma/sqrt(n) = %.6g, ratio %.4f, level %zu (%zu blocks), mean %.4g\n",
              r.std_error(0), expected, r.std_error(0) / expected, r.level[0], r.levels[r.level[0]].blocks,
              r.mean(0));
  EXPECT_TRUE(r.all_converged());
  EXPECT_NEAR(r.std_error(0) / expected, 1.0, 0.15);
  EXPECT_LT(std::abs(r.mean(0)), 3.0 * expected);
}

TEST(BlockAverage, Ar1ErrorBarIsTheAsymptoticOneAndTheNaiveOneIsNot) {
  const double a = 0.9;
  const std::vector<double> x = ar1_series(a, kSamples, 77);
  const sc::BlockAverageResult r = average(x);
  const double n = static_cast<double>(kSamples);
  const double exact = std::sqrt((1.0 + a) / (1.0 - a)) / std::sqrt(n);  // sqrt(2 tau_int / n), unit variance
  const double naive = r.levels[0].std_error(0);                          // sigma / sqrt(n)
  std::printf("[AR(1) a = 0.9] se = %.6g, exact %.6g, ratio %.4f, level %zu (block %zu, %zu blocks); naive %.6g "
              "(ratio %.4f)\n",
              r.std_error(0), exact, r.std_error(0) / exact, r.level[0], r.levels[r.level[0]].block_size,
              r.levels[r.level[0]].blocks, naive, naive / exact);
  EXPECT_TRUE(r.all_converged());
  EXPECT_NEAR(r.std_error(0) / exact, 1.0, 0.20);
  EXPECT_LT(naive / exact, 0.5);  // sqrt((1 - a) / (1 + a)) = 0.23
  EXPECT_GT(r.level[0], 4u);      // blocks far longer than tau_int = 9.5
}

TEST(BlockAverage, LevelsMatchTheBatchTransformation) {
  const std::vector<double> x = ar1_series(0.5, 1000, 5);  // not a power of 2: odd levels drop a block
  const sc::BlockAverageResult r = average(x);
  const std::vector<double> batch = batch_std_errors(x);
  ASSERT_EQ(r.levels.size(), batch.size());
  for (std::size_t l = 0; l < batch.size(); ++l) {
    EXPECT_NEAR(r.levels[l].std_error(0), batch[l], 1e-12 * batch[l]) << "level " << l;
    EXPECT_EQ(r.levels[l].block_size, std::size_t{1} << l);
    EXPECT_NEAR(r.levels[l].std_error_error(0),
                batch[l] / std::sqrt(2.0 * (static_cast<double>(r.levels[l].blocks) - 1.0)), 1e-12 * batch[l]);
  }
  EXPECT_EQ(r.levels[0].blocks, 1000u);
  EXPECT_EQ(r.levels[3].blocks, 125u);
  EXPECT_EQ(r.levels[4].blocks, 62u);  // 125 blocks: the last one left out
  double mean = 0.0;
  for (double v : x) mean += v / 1000.0;
  EXPECT_NEAR(r.mean(0), mean, 1e-14);
}

// Tensor samples: each component is averaged as its own scalar series, with its own level.
TEST(BlockAverage, TensorComponentsAreIndependentScalarSeries) {
  std::vector<std::vector<double>> series;
  for (int c = 0; c < 9; ++c) series.push_back(ar1_series(0.1 * c, 4096, 300 + static_cast<std::uint64_t>(c)));
  sc::BlockAverage tensor;
  for (std::size_t k = 0; k < 4096; ++k) {
    sc::Mat3 m;
    for (int c = 0; c < 9; ++c) m(c % 3, c / 3) = series[static_cast<std::size_t>(c)][k] + c;
    tensor.add_tensor(m);
  }
  const sc::BlockAverageResult t = tensor.result();
  ASSERT_EQ(t.mean.size(), 9);
  for (int c = 0; c < 9; ++c) {
    std::vector<double> shifted = series[static_cast<std::size_t>(c)];
    for (double& v : shifted) v += c;
    const sc::BlockAverageResult s = average(shifted);
    EXPECT_NEAR(t.mean(c), s.mean(0), 1e-12) << "component " << c;
    EXPECT_NEAR(t.std_error(c), s.std_error(0), 1e-12 * s.std_error(0)) << "component " << c;
    EXPECT_EQ(t.level[static_cast<std::size_t>(c)], s.level[0]) << "component " << c;
  }
}

TEST(BlockAverage, RejectsBadInput) {
  expect_rejects([] { sc::BlockAverage().result(); }, "samples");
  expect_rejects(
      [] {
        sc::BlockAverage b;
        b.add(1.0);
        b.result();
      },
      "samples");
  expect_rejects([] { sc::BlockAverage b(1); }, "min_blocks");
  expect_rejects(
      [] {
        sc::BlockAverage b;
        b.add(1.0);
        b.add(sc::VecX::Zero(2));
      },
      "sample");
  expect_rejects([] { sc::BlockAverage().add(std::nan("")); }, "sample");
}

}  // namespace

}  // namespace block_average_tests
