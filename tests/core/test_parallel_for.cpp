#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "stokescontact/core/parallel_for.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace parallel_for_tests {

namespace sc = stokescontact;

// Every index runs once and writes its own slot: the serial loop's values, bit for bit, on
// both sides of the threshold where the loop starts to use threads.
TEST(ParallelFor, EveryIndexOnceWithTheSerialLoopsValues) {
  for (const std::ptrdiff_t count : {std::ptrdiff_t{0}, std::ptrdiff_t{1}, sc::kParallelForMinCount - 1,
                                     sc::kParallelForMinCount, 10 * sc::kParallelForMinCount + 7}) {
    std::vector<int> visits(static_cast<std::size_t>(count), 0);
    std::vector<double> value(static_cast<std::size_t>(count), 0.0), serial(static_cast<std::size_t>(count), 0.0);
    const auto f = [](std::ptrdiff_t k) { return std::sin(0.001 * static_cast<double>(k)) * std::exp(-1e-5 * static_cast<double>(k)); };
    sc::parallel_for(count, [&](std::ptrdiff_t k) {
      ++visits[static_cast<std::size_t>(k)];
      value[static_cast<std::size_t>(k)] = f(k);
    });
    for (std::ptrdiff_t k = 0; k < count; ++k) serial[static_cast<std::size_t>(k)] = f(k);
    EXPECT_EQ(visits, std::vector<int>(static_cast<std::size_t>(count), 1)) << "count " << count;
    EXPECT_EQ(value, serial) << "count " << count;
  }
}

// A loop of a few large items (chunks of a longer loop) with its own threshold: each chunk
// once, the same values, from two chunks on.
TEST(ParallelFor, FewChunksWithTheirOwnThreshold) {
  for (const std::ptrdiff_t chunks : {std::ptrdiff_t{0}, std::ptrdiff_t{1}, std::ptrdiff_t{2}, std::ptrdiff_t{64}}) {
    std::vector<int> visits(static_cast<std::size_t>(chunks), 0);
    std::vector<double> sums(static_cast<std::size_t>(chunks), 0.0), serial(static_cast<std::size_t>(chunks), 0.0);
    const auto chunk_sum = [](std::ptrdiff_t c) {
      double sum = 0.0;
      for (int k = 0; k < 1000; ++k) sum += std::sqrt(static_cast<double>(1000 * c + k));
      return sum;
    };
    sc::parallel_for(
        chunks,
        [&](std::ptrdiff_t c) {
          ++visits[static_cast<std::size_t>(c)];
          sums[static_cast<std::size_t>(c)] = chunk_sum(c);
        },
        2);
    for (std::ptrdiff_t c = 0; c < chunks; ++c) serial[static_cast<std::size_t>(c)] = chunk_sum(c);
    EXPECT_EQ(visits, std::vector<int>(static_cast<std::size_t>(chunks), 1)) << "chunks " << chunks;
    EXPECT_EQ(sums, serial) << "chunks " << chunks;
  }
}

// An exception leaves the loop on the calling thread: the one of the lowest index that threw,
// whichever thread ran it (a validation error names its pair; it must name the first).
TEST(ParallelFor, RethrowsTheExceptionOfTheLowestIndex) {
  for (const std::ptrdiff_t count : {sc::kParallelForMinCount / 2, 8 * sc::kParallelForMinCount}) {
    const std::ptrdiff_t first = count / 3, second = count - 5;
    try {
      sc::parallel_for(count, [&](std::ptrdiff_t k) {
        if (k == first || k == second) throw std::invalid_argument("pairs[" + std::to_string(k) + "]");
      });
      ADD_FAILURE() << "no exception for count " << count;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), "pairs[" + std::to_string(first) + "]");
    }
  }
}

}  // namespace parallel_for_tests
