// Cell-list broad phase: exactly the pairs of an O(N^2) brute force over the same predicate.
#include "stokescontact/geometry/broad_phase.hpp"
#include "stokescontact/core/parallel_for.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace stokescontact {
// Readable pairs in failure messages.
inline void PrintTo(const BodyPair& p, std::ostream* os) { *os << "(" << p.i << "," << p.j << ")"; }
}  // namespace stokescontact

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace broad_phase_tests {

namespace {

using namespace stokescontact;
using Box = std::optional<PeriodicBox>;

std::vector<BodyPair> brute_force(const Mat3X& x, const VecX& r, double cutoff, const Box& box) {
  std::vector<BodyPair> pairs;
  for (Eigen::Index i = 0; i < x.cols(); ++i)
    for (Eigen::Index j = i + 1; j < x.cols(); ++j)
      if (is_candidate_pair(x.col(i), x.col(j), r[i], r[j], cutoff, box)) pairs.push_back({i, j});
  return pairs;
}

// Cell list == brute force, both for a fresh object and for one reused across scenes; and
// find_pairs_of == the brute-force pairs with a marked body, for none, a few, about half and
// all bodies marked.
void expect_matches_brute_force(CellList& reused, const Mat3X& x, const VecX& r, double cutoff,
                                const Box& box = {}) {
  const std::vector<BodyPair> expected = brute_force(x, r, cutoff, box);
  EXPECT_EQ(candidate_pairs(x, r, cutoff, box), expected);
  EXPECT_EQ(reused.find_pairs(x, r, cutoff, box), expected);
  std::mt19937_64 rng(static_cast<std::uint64_t>(x.cols()));
  for (const double fraction : {0.0, 0.05, 0.5, 1.0}) {
    std::vector<char> marked(static_cast<std::size_t>(x.cols()));
    for (char& m : marked) m = std::uniform_real_distribution<double>(0.0, 1.0)(rng) < fraction;
    std::vector<BodyPair> with_marked;
    for (const BodyPair& p : expected)
      if (marked[static_cast<std::size_t>(p.i)] || marked[static_cast<std::size_t>(p.j)]) with_marked.push_back(p);
    EXPECT_EQ(reused.find_pairs_of(x, r, cutoff, box, marked), with_marked) << "marked fraction " << fraction;
  }
}

Mat3X uniform_in(std::mt19937_64& rng, Eigen::Index n, const Vec3& lo, const Vec3& hi) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Mat3X x(3, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) x(k, i) = lo[k] + (hi[k] - lo[k]) * u(rng);
  return x;
}

// Side of a cube holding n spheres of radius a at packing fraction phi.
double cube_side(Eigen::Index n, double a, double phi) {
  return std::cbrt(static_cast<double>(n) * 4.0 / 3.0 * std::numbers::pi * a * a * a / phi);
}

TEST(BroadPhase, MatchesBruteForceUniformOpen) {
  CellList reused;
  for (std::uint64_t seed = 0; seed < 40; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    const Eigen::Index n = std::uniform_int_distribution<Eigen::Index>(0, 600)(rng);
    const double radius = std::uniform_real_distribution<double>(0.05, 1.0)(rng);
    const double phi = std::uniform_real_distribution<double>(0.01, 0.4)(rng);
    const double cutoff = seed % 4 == 0 ? 0.0 : std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    const double side = cube_side(std::max<Eigen::Index>(n, 1), radius, phi);
    const Vec3 shift = Vec3::Random() * 50.0;
    const Mat3X x = uniform_in(rng, n, shift, shift + Vec3(side, side, 0.5 * side));
    expect_matches_brute_force(reused, x, VecX::Constant(n, radius), cutoff);
    EXPECT_EQ(reused.find_pairs(x, radius, cutoff), brute_force(x, VecX::Constant(n, radius), cutoff, {}));
  }
}

// Enough bodies for the queries to run in chunks on threads (kParallelForMinCount): the
// same sorted pairs as brute force, open and periodic.
TEST(BroadPhase, MatchesBruteForceInChunks) {
  CellList reused;
  std::mt19937_64 rng(77);
  const Eigen::Index n = 3 * kParallelForMinCount;
  const double side = cube_side(n, 0.5, 0.3);
  const Mat3X x = uniform_in(rng, n, Vec3::Zero(), Vec3::Constant(side));
  expect_matches_brute_force(reused, x, VecX::Constant(n, 0.5), 0.1);
  expect_matches_brute_force(reused, x, VecX::Constant(n, 0.5), 0.1, PeriodicBox{Vec3::Constant(side)});
}

TEST(BroadPhase, MatchesBruteForceClustered) {
  CellList reused;
  for (std::uint64_t seed = 100; seed < 130; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    const int clusters = std::uniform_int_distribution<int>(1, 5)(rng);
    const Eigen::Index per = std::uniform_int_distribution<Eigen::Index>(1, 150)(rng);
    std::normal_distribution<double> g(0.0, std::uniform_real_distribution<double>(0.01, 3.0)(rng));
    Mat3X x(3, clusters * per + 50);
    for (int c = 0; c < clusters; ++c) {
      const Vec3 centre = Vec3::Random() * 30.0;
      for (Eigen::Index i = 0; i < per; ++i) x.col(c * per + i) = centre + Vec3(g(rng), g(rng), g(rng));
    }
    x.rightCols(50) = uniform_in(rng, 50, Vec3::Constant(-40.0), Vec3::Constant(40.0));
    expect_matches_brute_force(reused, x, VecX::Constant(x.cols(), 0.5), 0.1);
  }
}

TEST(BroadPhase, MatchesBruteForcePolydisperse) {
  CellList reused;
  for (std::uint64_t seed = 200; seed < 230; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    const Eigen::Index n = 500;
    std::uniform_real_distribution<double> log_r(std::log(0.01), std::log(1.0));
    VecX r(n);
    for (Eigen::Index i = 0; i < n; ++i) r[i] = std::exp(log_r(rng));
    for (Eigen::Index i = 0; i < 3; ++i) r[i] = 6.0;  // a few big bodies must find small partners
    const Box box = seed % 2 ? Box{PeriodicBox{Vec3(30.0, 26.0, 40.0)}} : Box{};
    const Mat3X x = uniform_in(rng, n, Vec3::Zero(), Vec3(30.0, 26.0, 40.0));
    expect_matches_brute_force(reused, x, r, 0.2, box);
  }
}

TEST(BroadPhase, MatchesBruteForcePeriodicAcrossTheBoundary) {
  CellList reused;
  for (std::uint64_t seed = 300; seed < 340; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Vec3 length(8.0 + 20.0 * u(rng), 8.0 + 20.0 * u(rng), 8.0 + 20.0 * u(rng));
    const Eigen::Index n = 400;
    // A third anywhere in [-3L, 4L), a third hugging a face (either side), a third in the box.
    Mat3X x = uniform_in(rng, n, -3.0 * length, 4.0 * length);
    for (Eigen::Index i = n / 3; i < 2 * n / 3; ++i) {
      const int k = static_cast<int>(i % 3);
      x(k, i) = (u(rng) < 0.5 ? 0.0 : length[k]) + 0.6 * (u(rng) - 0.5) + length[k] * std::floor(4.0 * u(rng) - 2.0);
    }
    x.rightCols(n - 2 * n / 3) = uniform_in(rng, n - 2 * n / 3, Vec3::Zero(), length);
    const double radius = 0.5 * u(rng) + 0.01;
    expect_matches_brute_force(reused, x, VecX::Constant(n, radius), 0.3 * u(rng), PeriodicBox{length});
  }
}

// Kept candidates (CellList::keep_candidates) answer every query as brute force does: queries
// of moved bodies (small moves, a few large ones, a common drift across the periodic seam),
// grown and shrunk radii, other cutoffs, marked bodies, the bodies reordered; open space far
// from the origin and periodic. Some answers must come from the kept pairs and some afresh,
// or the test would not test the reuse.
TEST(BroadPhase, KeptCandidatesAnswerAsBruteForce) {
  for (const bool periodic : {false, true}) {
    SCOPED_TRACE(periodic ? "periodic" : "open, centred at 1e4");
    std::mt19937_64 rng(periodic ? 71 : 72);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Eigen::Index n = 600;
    const double side = cube_side(n, 0.5, 0.3);
    const Box box = periodic ? Box(PeriodicBox{Vec3::Constant(side)}) : Box();
    const Vec3 origin = periodic ? Vec3::Zero() : Vec3::Constant(1e4);
    const Mat3X x0 = uniform_in(rng, n, origin, origin + Vec3::Constant(side));
    VecX r0(n);
    for (Eigen::Index i = 0; i < n; ++i) r0[i] = 0.3 + 0.4 * u(rng);
    CellList kept;
    kept.keep_candidates(0.3);
    EXPECT_EQ(kept.find_pairs(x0, r0, 0.05, box), brute_force(x0, r0, 0.05, box));
    EXPECT_FALSE(kept.last_query_reused());
    int reused = 0, fresh = 0;
    for (int trial = 0; trial < 120; ++trial) {
      SCOPED_TRACE("trial " + std::to_string(trial));
      // Moves of up to `reach`, a few bodies of up to 3, a common drift; radii within +-0.02.
      const double reach = 0.06 * u(rng);
      Mat3X x = x0;
      VecX r = r0;
      const Vec3 drift = trial % 3 == 0 ? Vec3(side * u(rng), 2.0, -5.0) : Vec3::Zero();
      for (Eigen::Index i = 0; i < n; ++i) {
        const Vec3 direction = Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5).normalized();
        x.col(i) += drift + reach * u(rng) * direction;
        r[i] += 0.04 * (u(rng) - 0.5) * (trial % 2);
      }
      if (trial % 5 == 1)
        for (int k = 0; k < 3; ++k) x.col(static_cast<Eigen::Index>(u(rng) * n)) += Vec3(3.0 * u(rng), 0.0, 0.0);
      if (trial % 7 == 2) {  // the same numbers for other bodies: columns reordered
        std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
        std::iota(order.begin(), order.end(), Eigen::Index{0});
        std::shuffle(order.begin(), order.end(), rng);
        const Mat3X y = x;
        const VecX s = r;
        for (Eigen::Index i = 0; i < n; ++i) {
          x.col(i) = y.col(order[static_cast<std::size_t>(i)]);
          r[i] = s[order[static_cast<std::size_t>(i)]];
        }
      }
      const double cutoff = 0.15 * u(rng);
      const std::vector<BodyPair> expected = brute_force(x, r, cutoff, box);
      if (trial % 4 == 3) {
        std::vector<char> marked(static_cast<std::size_t>(n));
        for (char& m : marked) m = u(rng) < 0.1;
        std::vector<BodyPair> with_marked;
        for (const BodyPair& p : expected)
          if (marked[static_cast<std::size_t>(p.i)] || marked[static_cast<std::size_t>(p.j)]) with_marked.push_back(p);
        EXPECT_EQ(kept.find_pairs_of(x, r, cutoff, box, marked), with_marked);
      } else {
        EXPECT_EQ(kept.find_pairs(x, r, cutoff, box), expected);
      }
      (kept.last_query_reused() ? reused : fresh) += 1;
    }
    EXPECT_GT(reused, 20);
    EXPECT_GT(fresh, 20);
  }
}

// The bound is tight: pairs just beyond the kept reach (gap C + 1e-3 at the reference) move
// straight at each other by delta each. Up to delta = (C - c) / 2 none comes within c and the
// kept pairs answer; beyond, pairs come within c and the query must collect afresh.
TEST(BroadPhase, KeptCandidatesAtTheEdgeOfTheSkin) {
  const double radius = 0.5, skin = 0.3, reference_cutoff = 0.05, cutoff = 0.02;
  const double kept_reach = reference_cutoff + skin;  // C
  const Eigen::Index pairs = 50;
  Mat3X x0(3, 2 * pairs);
  for (Eigen::Index k = 0; k < pairs; ++k) {
    x0.col(2 * k) = Vec3(10.0 * static_cast<double>(k), 1e4, -1e4);
    x0.col(2 * k + 1) = x0.col(2 * k) + Vec3(2.0 * radius + kept_reach + 1e-3, 0.0, 0.0);
  }
  const VecX r = VecX::Constant(2 * pairs, radius);
  for (const double excess : {-0.01, -1e-4, 1e-3, 0.01, 0.05}) {
    SCOPED_TRACE("delta - (C - c) / 2 = " + std::to_string(excess));
    CellList kept;
    kept.keep_candidates(skin);
    ASSERT_TRUE(kept.find_pairs(x0, r, reference_cutoff).empty());
    const double delta = 0.5 * (kept_reach - cutoff) + excess;
    Mat3X x = x0;
    for (Eigen::Index k = 0; k < pairs; ++k) {
      x(0, 2 * k) += delta;
      x(0, 2 * k + 1) -= delta;
    }
    const std::vector<BodyPair> expected = brute_force(x, r, cutoff, {});
    EXPECT_EQ(kept.find_pairs(x, r, cutoff), expected);
    EXPECT_EQ(expected.empty(), excess < 5e-4);
    EXPECT_EQ(kept.last_query_reused(), excess < 0.0);
  }
}

// A subset of the bodies (fewer columns) collects afresh; keep_candidates(0) stops keeping.
TEST(BroadPhase, KeptCandidatesNeedTheSameBodyCount) {
  std::mt19937_64 rng(73);
  const Eigen::Index n = 300;
  const double side = cube_side(n, 0.5, 0.3);
  const Mat3X x = uniform_in(rng, n, Vec3::Zero(), Vec3::Constant(side));
  const VecX r = VecX::Constant(n, 0.5);
  CellList kept;
  kept.keep_candidates(0.2);
  kept.find_pairs(x, r, 0.1);
  EXPECT_EQ(kept.find_pairs(x, r, 0.1), brute_force(x, r, 0.1, {}));
  EXPECT_TRUE(kept.last_query_reused());
  const Mat3X head = x.leftCols(n - 1);
  EXPECT_EQ(kept.find_pairs(head, r.head(n - 1), 0.1), brute_force(head, r.head(n - 1), 0.1, {}));
  EXPECT_FALSE(kept.last_query_reused());
  kept.keep_candidates(0.0);
  kept.find_pairs(x, r, 0.1);
  EXPECT_EQ(kept.find_pairs(x, r, 0.1), brute_force(x, r, 0.1, {}));
  EXPECT_FALSE(kept.last_query_reused());
  EXPECT_THROW(kept.keep_candidates(-1.0), std::invalid_argument);
}

// Sides of 1, 2 and 3 cells (and mixed) are where a naive periodic stencil counts twice.
TEST(BroadPhase, PeriodicBoxesWithOneTwoThreeCellsPerSide) {
  CellList reused;
  const double radius = 0.5, cutoff = 0.25, range = 2 * radius + cutoff;
  const std::vector<std::pair<Vec3, std::array<std::int64_t, 3>>> boxes = {
      {Vec3::Constant(2.0 * range), {1, 1, 1}},
      {Vec3::Constant(2.5 * range), {2, 2, 2}},
      {Vec3::Constant(3.5 * range), {3, 3, 3}},
      {Vec3(2.0 * range, 2.5 * range, 3.5 * range), {1, 2, 3}},
      {Vec3(3.5 * range, 2.0 * range, 9.5 * range), {3, 1, 9}}};
  for (std::uint64_t seed = 400; seed < 420; ++seed) {
    for (const auto& [length, expected_buckets] : boxes) {
      SCOPED_TRACE("seed " + std::to_string(seed) + " box " + std::to_string(length.x()) + " " +
                   std::to_string(length.y()) + " " + std::to_string(length.z()));
      std::mt19937_64 rng(seed);
      const Mat3X x = uniform_in(rng, 60, -length, 2.0 * length);
      expect_matches_brute_force(reused, x, VecX::Constant(60, radius), cutoff, PeriodicBox{length});
      EXPECT_EQ(reused.buckets_per_side(), expected_buckets);
    }
  }
}

TEST(BroadPhase, RejectsBoxesTooSmallForMinimumImage) {
  const Mat3X x = Mat3X::Random(3, 10);
  // range 2 * 0.5 + 0.25 = 1.25; the box must be at least 2.5 on every side.
  EXPECT_NO_THROW(candidate_pairs(x, 0.5, 0.25, PeriodicBox{Vec3(2.5, 2.5, 2.5)}));
  for (const Vec3& length : {Vec3(2.49, 5.0, 5.0), Vec3(5.0, 5.0, 2.4999999)}) {
    try {
      candidate_pairs(x, 0.5, 0.25, PeriodicBox{length});
      ADD_FAILURE() << "no error for box " << length.transpose();
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("PeriodicBox.lengths"), std::string::npos) << e.what();
    }
  }
  // A big body decides: it is polydisperse max radius that sets the range.
  VecX r = VecX::Constant(10, 0.1);
  r[7] = 2.0;
  EXPECT_THROW(candidate_pairs(x, r, 0.0, PeriodicBox{Vec3::Constant(7.9)}), std::invalid_argument);
  EXPECT_NO_THROW(candidate_pairs(x, r, 0.0, PeriodicBox{Vec3::Constant(8.0)}));
}

// Lattice spacing 1 and reach exactly 1: every nearest neighbour sits on the threshold.
TEST(BroadPhase, PairsExactlyAtTheThreshold) {
  const Mat3X two = (Mat3X(3, 2) << 0.0, 3.0, 0.0, 0.0, 0.0, 0.0).finished();
  EXPECT_EQ(candidate_pairs(two, 1.0, 1.0), (std::vector<BodyPair>{{0, 1}}));
  Mat3X apart = two;
  apart(0, 1) = std::nextafter(3.0, 4.0);
  EXPECT_TRUE(candidate_pairs(apart, 1.0, 1.0).empty());
  // Across the seam: 0.5 and 9.5 in a box of 10 are 1 apart.
  const Mat3X seam = (Mat3X(3, 2) << 0.5, 9.5, 2.0, 2.0, 2.0, 2.0).finished();
  EXPECT_EQ(candidate_pairs(seam, 0.25, 0.5, PeriodicBox{Vec3::Constant(10.0)}), (std::vector<BodyPair>{{0, 1}}));

  CellList reused;
  for (const double offset : {0.0, -7.0, 1.0e6, 1.0e12, -1.0e14}) {
    SCOPED_TRACE("offset " + std::to_string(offset));
    const int side = 9;
    Mat3X x(3, side * side * side);
    for (int i = 0; i < x.cols(); ++i) x.col(i) = Vec3(i % side, (i / side) % side, i / (side * side)).array() + offset;
    const VecX r = VecX::Constant(x.cols(), 0.5);
    const std::vector<BodyPair> pairs = reused.find_pairs(x, r, 0.0);
    EXPECT_EQ(pairs.size(), 3u * side * side * (side - 1));  // the lattice's bonds
    EXPECT_EQ(pairs, brute_force(x, r, 0.0, {}));
    expect_matches_brute_force(reused, x, r, 0.0, PeriodicBox{Vec3::Constant(side)});
    expect_matches_brute_force(reused, x, r, 0.0, PeriodicBox{Vec3::Constant(2.0)});
  }
  // Periodic lattice: with the seam bonds every site has exactly 6 neighbours.
  const int side = 6;
  Mat3X x(3, side * side * side);
  for (int i = 0; i < x.cols(); ++i) x.col(i) = Vec3(i % side, (i / side) % side, i / (side * side));
  EXPECT_EQ(candidate_pairs(x, 0.5, 0.0, PeriodicBox{Vec3::Constant(side)}).size(), 3u * x.cols());
}

TEST(BroadPhase, ZeroCutoffAndZeroRadii) {
  std::mt19937_64 rng(500);
  Mat3X x = uniform_in(rng, 300, Vec3::Zero(), Vec3::Constant(4.0));
  x.rightCols(100) = x.leftCols(100);  // exact duplicates: the only pairs at reach 0
  const VecX zero = VecX::Zero(300);
  const std::vector<BodyPair> pairs = candidate_pairs(x, zero, 0.0);
  EXPECT_EQ(pairs.size(), 100u);
  EXPECT_EQ(pairs, brute_force(x, zero, 0.0, {}));
  EXPECT_EQ(candidate_pairs(x, zero, 0.0, PeriodicBox{Vec3::Constant(4.0)}),
            brute_force(x, zero, 0.0, PeriodicBox{Vec3::Constant(4.0)}));
}

TEST(BroadPhase, AllBodiesAtOnePoint) {
  for (const Vec3& point : {Vec3::Zero().eval(), Vec3(1.0e3, -2.0, 5.0)}) {
    const Mat3X x = point.replicate(1, 400);
    for (const double radius : {0.0, 0.5}) {
      const std::vector<BodyPair> pairs = candidate_pairs(x, radius, 0.0);
      EXPECT_EQ(pairs.size(), 400u * 399u / 2u);
      EXPECT_EQ(pairs, brute_force(x, VecX::Constant(400, radius), 0.0, {}));
      EXPECT_EQ(candidate_pairs(x, radius, 0.1, PeriodicBox{Vec3::Constant(3.0)}).size(), 400u * 399u / 2u);
    }
  }
}

TEST(BroadPhase, TinyScenes) {
  CellList cells;
  EXPECT_TRUE(cells.find_pairs(Mat3X(3, 0), VecX(0), 1.0).empty());
  EXPECT_TRUE(cells.find_pairs(Mat3X(3, 0), 1.0, 1.0, PeriodicBox{Vec3::Constant(5.0)}).empty());
  EXPECT_TRUE(cells.find_pairs(Mat3X::Zero(3, 1), 1.0, 1.0).empty());
  EXPECT_EQ(cells.pair_checks(), 0);
  const Mat3X two = (Mat3X(3, 2) << 0.0, 1.0, 0.0, 0.0, 0.0, 0.0).finished();
  EXPECT_EQ(cells.find_pairs(two, 0.5, 0.0), (std::vector<BodyPair>{{0, 1}}));
  EXPECT_EQ(cells.pair_checks(), 1);
  EXPECT_TRUE(cells.find_pairs(two, 0.4, 0.1).empty());
  EXPECT_EQ(cells.find_pairs(two, 0.4, 0.2), (std::vector<BodyPair>{{0, 1}}));
}

// Far outliers must not blow up the grid: a fixed bucket budget, few checks, fast.
TEST(BroadPhase, DistantOutliersStayCheap) {
  std::mt19937_64 rng(600);
  const Eigen::Index n = 3000;
  Mat3X x = uniform_in(rng, n, Vec3::Zero(), Vec3::Constant(cube_side(n, 0.5, 0.3)));
  x.col(0) = Vec3(1.0e12, 0.0, 0.0);
  x.col(1) = Vec3(0.0, -1.0e15, 3.0e14);
  x.col(2) = Vec3(-1.0e300, 1.0e300, 1.0e300);
  x.col(3) = Vec3(-1.0e300, 1.0e300, 1.0e300 * (1 + 1e-15));  // 1e285 from body 2
  x.col(4) = Vec3(1.0e12, 0.0, 0.5);                           // a pair at 1e12
  const VecX r = VecX::Constant(n, 0.5);
  CellList cells;
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<BodyPair> pairs = cells.find_pairs(x, r, 0.1);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(seconds, 2.0);
  const auto& b = cells.buckets_per_side();
  EXPECT_LE(b[0] * b[1] * b[2], 4 * n + 64);
  EXPECT_LT(cells.pair_checks(), 40 * n);
  EXPECT_EQ(pairs, brute_force(x, r, 0.1, {}));
  EXPECT_TRUE(std::find(pairs.begin(), pairs.end(), BodyPair{0, 4}) != pairs.end());
  // The folded grid from the marked bodies' side: the outliers and every tenth body.
  std::vector<char> marked(static_cast<std::size_t>(n), 0);
  for (std::size_t k = 0; k < marked.size(); k += 10) marked[k] = 1;
  marked[3] = marked[4] = 1;
  std::vector<BodyPair> with_marked;
  for (const BodyPair& p : pairs)
    if (marked[static_cast<std::size_t>(p.i)] || marked[static_cast<std::size_t>(p.j)]) with_marked.push_back(p);
  EXPECT_EQ(cells.find_pairs_of(x, r, 0.1, {}, marked), with_marked);
}

TEST(BroadPhase, RejectsBadInput) {
  const Mat3X x = Mat3X::Random(3, 4);
  const VecX r = VecX::Constant(4, 0.5);
  auto expect_field = [](auto&& call, const std::string& field) {
    try {
      call();
      ADD_FAILURE() << "no error, expected one naming " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  Mat3X bad_x = x;
  bad_x(1, 2) = nan;
  expect_field([&] { candidate_pairs(bad_x, r, 0.1); }, "positions");
  bad_x(1, 2) = -inf;
  expect_field([&] { candidate_pairs(bad_x, r, 0.1); }, "positions");
  VecX bad_r = r;
  bad_r[3] = -0.1;
  expect_field([&] { candidate_pairs(x, bad_r, 0.1); }, "radii");
  bad_r[3] = inf;
  expect_field([&] { candidate_pairs(x, bad_r, 0.1); }, "radii");
  expect_field([&] { candidate_pairs(x, VecX::Constant(3, 0.5), 0.1); }, "radii");
  expect_field([&] { candidate_pairs(x, -0.5, 0.1); }, "radius");
  expect_field([&] { candidate_pairs(x, nan, 0.1); }, "radius");
  expect_field([&] { candidate_pairs(x, r, -1e-300); }, "cutoff");
  expect_field([&] { candidate_pairs(x, r, nan); }, "cutoff");
  expect_field([&] { candidate_pairs(x, r, 0.1, PeriodicBox{Vec3(10.0, 0.0, 10.0)}); }, "PeriodicBox.lengths");
  expect_field([&] { candidate_pairs(x, r, 0.1, PeriodicBox{Vec3(10.0, 10.0, -10.0)}); }, "PeriodicBox.lengths");
  expect_field([&] { candidate_pairs(x, r, 0.1, PeriodicBox{Vec3(10.0, inf, 10.0)}); }, "PeriodicBox.lengths");
  CellList cells;
  expect_field([&] { cells.find_pairs_of(x, r, 0.1, {}, std::vector<char>(3, 1)); }, "marked");
  // Validation comes first even when there is nothing to pair.
  expect_field([&] { candidate_pairs(Mat3X(3, 0), VecX(0), -1.0); }, "cutoff");
}

TEST(BroadPhase, MinimumImagePredicate) {
  const PeriodicBox box{Vec3(10.0, 20.0, 30.0)};
  EXPECT_TRUE(is_candidate_pair(Vec3(0.1, 5, 5), Vec3(9.9, 5, 5), 0.05, 0.05, 0.1, box));
  EXPECT_FALSE(is_candidate_pair(Vec3(0.1, 5, 5), Vec3(9.9, 5, 5), 0.05, 0.05, 0.1, {}));
  EXPECT_TRUE(is_candidate_pair(Vec3(0.1, 5, 5), Vec3(-29.9, 45, -55), 0.05, 0.05, 0.1, box));
  EXPECT_FALSE(is_candidate_pair(Vec3(0.1, 5, 5), Vec3(-29.9, 45.5, -55), 0.05, 0.05, 0.1, box));
  EXPECT_EQ(wrap_coordinate(-1e-300, 10.0), 0.0);  // 10 - 1e-300 rounds to 10, i.e. 0
  EXPECT_EQ(wrap_coordinate(-1e-15, 10.0), 10.0 - 1e-15);
  EXPECT_LT(wrap_coordinate(-1e-15, 10.0), 10.0);
  EXPECT_EQ(wrap_coordinate(-25.0, 10.0), 5.0);
  EXPECT_EQ(wrap_coordinate(30.0, 10.0), 0.0);
}

// The predicate against the nearest of the 27 images, computed independently.
TEST(BroadPhase, MinimumImageMatchesNearestOf27Images) {
  std::mt19937_64 rng(800);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int hits = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const PeriodicBox box{Vec3(1.0 + 9.0 * u(rng), 1.0 + 9.0 * u(rng), 1.0 + 9.0 * u(rng))};
    const Vec3 xi = (Vec3(u(rng), u(rng), u(rng)) * 6.0 - Vec3::Constant(3.0)).cwiseProduct(box.lengths);
    const Vec3 xj = (Vec3(u(rng), u(rng), u(rng)) * 6.0 - Vec3::Constant(3.0)).cwiseProduct(box.lengths);
    const double reach = 0.5 * box.lengths.minCoeff() * u(rng);  // up to the largest valid reach
    double nearest = std::numeric_limits<double>::infinity();
    const Vec3 d(std::remainder(xi.x() - xj.x(), box.lengths.x()), std::remainder(xi.y() - xj.y(), box.lengths.y()),
                 std::remainder(xi.z() - xj.z(), box.lengths.z()));
    for (int a = -1; a <= 1; ++a)
      for (int b = -1; b <= 1; ++b)
        for (int c = -1; c <= 1; ++c)
          nearest = std::min(nearest, (d + Vec3(a, b, c).cwiseProduct(box.lengths)).norm());
    const bool expected = nearest <= reach;
    hits += expected;
    EXPECT_EQ(is_candidate_pair(xi, xj, 0.3 * reach, 0.5 * reach, 0.2 * reach, box), expected) << "trial " << trial;
  }
  EXPECT_GT(hits, 100);  // the comparison saw both outcomes
}

// O(N): predicate evaluations per body do not grow with N at fixed density.
TEST(BroadPhase, ChecksPerBodyStayBoundedAsNGrows) {
  CellList cells;
  double per_body[2] = {};
  const Eigen::Index sizes[2] = {1000, 100000};
  for (int s = 0; s < 2; ++s) {
    std::mt19937_64 rng(700 + s);
    const double side = cube_side(sizes[s], 1.0, 0.24);
    const Mat3X x = uniform_in(rng, sizes[s], Vec3::Zero(), Vec3::Constant(side));
    const std::size_t found = cells.find_pairs(x, 1.0, 0.1).size();
    per_body[s] = static_cast<double>(cells.pair_checks()) / static_cast<double>(sizes[s]);
    EXPECT_GE(static_cast<double>(cells.pair_checks()), static_cast<double>(found));
    EXPECT_LT(per_body[s], 20.0) << "N = " << sizes[s];
    cells.find_pairs(x, 1.0, 0.1, PeriodicBox{Vec3::Constant(side)});
    EXPECT_LT(static_cast<double>(cells.pair_checks()) / static_cast<double>(sizes[s]), 20.0) << "periodic N = " << sizes[s];
  }
  EXPECT_LT(per_body[1], 1.2 * per_body[0]);
}

}  // namespace

}  // namespace broad_phase_tests
