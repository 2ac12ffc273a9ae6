#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/contact_pairs.hpp"
#include "stokescontact/contact/surface_contacts.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace contact_pairs_tests {

namespace sc = stokescontact;
using test_support::expect_rejects;
using sc::Pose;
using sc::Vec3;

namespace {

struct BrutePair {
  Eigen::Index i, j;
  Vec3 shift;
  sc::ClosestPoints points;
};

// d^P of (i, j) over body j's 27 nearest images (centres lie in the box, so the nearest
// image is among them), or the plain pair in open space: independent of the minimum-image
// rule the code uses.
template <sc::Shape S>
BrutePair brute_pair(std::span<const S> shapes, std::span<const Pose> poses, Eigen::Index i, Eigen::Index j,
                     const std::optional<sc::PeriodicBox>& box) {
  const auto si = static_cast<std::size_t>(i), sj = static_cast<std::size_t>(j);
  const S& a = sc::shape_of(shapes, si);
  const S& b = sc::shape_of(shapes, sj);
  BrutePair best{i, j, Vec3::Zero(), sc::closest_points(a, poses[si], b, poses[sj])};
  if (!box) return best;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        const Vec3 shift = Vec3(x, y, z).cwiseProduct(box->lengths);
        const sc::ClosestPoints cp = sc::closest_points(a, poses[si], b, Pose{poses[sj].x + shift, poses[sj].q});
        if (cp.distance < best.points.distance) best = {i, j, shift, cp};
      }
  return best;
}

template <sc::Shape S>
std::vector<BrutePair> brute_flagged(std::span<const S> shapes, std::span<const Pose> poses, double d_try,
                                     const std::optional<sc::PeriodicBox>& box) {
  std::vector<BrutePair> out;
  const auto n = static_cast<Eigen::Index>(poses.size());
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = i + 1; j < n; ++j) {
      const BrutePair p = brute_pair(shapes, poses, i, j, box);
      if (p.points.distance <= d_try) out.push_back(p);
    }
  return out;
}

template <sc::Shape S>
double brute_minimum(std::span<const S> shapes, std::span<const Pose> poses, const std::optional<sc::PeriodicBox>& box) {
  double best = std::numeric_limits<double>::infinity();
  const auto n = static_cast<Eigen::Index>(poses.size());
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = i + 1; j < n; ++j) best = std::min(best, brute_pair(shapes, poses, i, j, box).points.distance);
  return best;
}

template <sc::Shape S>
void expect_flagged_equal_brute_force(std::span<const S> shapes, double box_length, int n, double d_try,
                                      std::uint64_t seed) {
  for (const bool periodic : {false, true}) {
    std::mt19937_64 rng(seed);
    const auto poses = test_support::random_poses(n, 0.0, box_length, rng);
    std::optional<sc::PeriodicBox> box;
    if (periodic) box = sc::PeriodicBox{Vec3::Constant(box_length)};
    const auto found = sc::find_contact_pairs(shapes, std::span<const Pose>(poses), d_try, box);
    const auto expected = brute_flagged(shapes, std::span<const Pose>(poses), d_try, box);
    ASSERT_EQ(found.size(), expected.size()) << "seed " << seed << " periodic " << periodic;
    ASSERT_FALSE(expected.empty()) << "seed " << seed << ": the scene should flag some pairs";
    int across = 0;  // pairs flagged through a periodic image
    for (const auto& p : expected) across += p.shift != Vec3::Zero();
    if (periodic) {
      EXPECT_GT(across, 0) << "seed " << seed << ": no pair across the boundary";
    }
    for (std::size_t k = 0; k < found.size(); ++k) {
      EXPECT_EQ(found[k].i, expected[k].i) << "seed " << seed;
      EXPECT_EQ(found[k].j, expected[k].j) << "seed " << seed;
      EXPECT_EQ(found[k].image_shift, expected[k].shift) << "seed " << seed;
      EXPECT_EQ(found[k].points.distance, expected[k].points.distance) << "seed " << seed;
      EXPECT_LT((found[k].points.normal - expected[k].points.normal).norm(), 1e-14) << "seed " << seed;
    }
    const sc::MinimumDistance m = sc::minimum_pair_distance(shapes, std::span<const Pose>(poses), box);
    EXPECT_EQ(m.distance, brute_minimum(shapes, std::span<const Pose>(poses), box))
        << "seed " << seed << " periodic " << periodic;
    EXPECT_EQ(m.distance, brute_pair(shapes, std::span<const Pose>(poses), m.i, m.j, box).points.distance);
  }
}

}  // namespace

// Polydisperse spheres (one shape per body), overlaps included.
TEST(ContactPairs, SpheresMatchBruteForce) {
  for (const std::uint64_t seed : {11u, 12u}) {
    std::mt19937_64 rng(seed + 1000);
    std::vector<sc::Sphere> spheres(120);
    for (auto& s : spheres) s.radius = test_support::uniform(rng, 0.3, 0.7);
    expect_flagged_equal_brute_force(std::span<const sc::Sphere>(spheres), 10.0, 120, 0.3, seed);
  }
}

TEST(ContactPairs, RodsMatchBruteForce) {
  const sc::Spherocylinder rod{2.0, 0.4};
  for (const std::uint64_t seed : {21u, 22u})
    expect_flagged_equal_brute_force(std::span<const sc::Spherocylinder>(&rod, 1), 12.0, 90, 0.5, seed);
}

TEST(ContactPairs, BoomerangsMatchBruteForce) {
  const sc::Boomerang boomerang = sc::broms_tornberg_boomerang();
  for (const std::uint64_t seed : {31u, 32u})
    expect_flagged_equal_brute_force(std::span<const sc::Boomerang>(&boomerang, 1), 12.0, 60, 0.5, seed);
}

// A pair straddling the periodic boundary is found through the image, with its lever-arm
// shift, and its closest points run from body i to that image.
TEST(ContactPairs, PeriodicPairUsesMinimumImage) {
  const sc::Spherocylinder rod{2.0, 0.4};
  const sc::PeriodicBox box{Vec3(10.0, 11.0, 12.0)};
  const std::vector<Pose> poses = {{Vec3(0.2, 5.0, 6.0), sc::Quat::Identity()},
                                   {Vec3(9.3, 5.0, 6.0), sc::Quat::Identity()}};
  const auto pairs = sc::find_contact_pairs(rod, poses, 0.2, box);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].image_shift, Vec3(-10.0, 0.0, 0.0));
  EXPECT_NEAR(pairs[0].points.distance, 0.9 - 0.8, 1e-14);  // parallel rods 0.9 apart, radii 0.4
  EXPECT_NEAR(pairs[0].points.normal.x(), -1.0, 1e-15);     // towards the image at x = -0.7
  EXPECT_TRUE(sc::find_contact_pairs(rod, poses, 0.2).empty());  // no box: 9.1 apart
}

// Far-apart bodies: the cutoff grows until the minimum is reached (open space) or the box's
// reach is exhausted (periodic fallback over minimum images); fewer than 2 bodies: +inf.
TEST(ContactPairs, MinimumDistanceOfSparseScenes) {
  const sc::Sphere unit{1.0};
  std::mt19937_64 rng(41);
  const auto spread = test_support::random_poses(6, -1000.0, 1000.0, rng);
  EXPECT_EQ(sc::minimum_pair_distance(unit, spread).distance,
            brute_minimum(std::span<const sc::Sphere>(&unit, 1), std::span<const Pose>(spread), std::nullopt));

  const sc::PeriodicBox box{Vec3::Constant(100.0)};
  // Within the broad phase's reach (50 - 2 = 48): 40 apart between centres.
  const std::vector<Pose> near = {{Vec3(5, 5, 5), sc::Quat::Identity()}, {Vec3(45, 5, 5), sc::Quat::Identity()}};
  EXPECT_NEAR(sc::minimum_pair_distance(unit, near, box).distance, 38.0, 1e-12);
  // Beyond it: minimum image 49 (1, 1, 1) away, found by the fallback.
  const std::vector<Pose> far = {{Vec3(5, 5, 5), sc::Quat::Identity()}, {Vec3(54, 54, 54), sc::Quat::Identity()}};
  const sc::MinimumDistance m = sc::minimum_pair_distance(unit, far, box);
  EXPECT_NEAR(m.distance, 49.0 * std::sqrt(3.0) - 2.0, 1e-12);
  EXPECT_EQ(m.i, 0);
  EXPECT_EQ(m.j, 1);

  const std::vector<Pose> one = {Pose{}};
  EXPECT_EQ(sc::minimum_pair_distance(unit, one).distance, std::numeric_limits<double>::infinity());
  EXPECT_EQ(sc::minimum_pair_distance(unit, one).i, -1);
}

// A reused CellList gives the same answers as a fresh one.
TEST(ContactPairs, ReusedCellListGivesSameResults) {
  const sc::Boomerang boomerang = sc::broms_tornberg_boomerang();
  sc::CellList cells;
  for (const std::uint64_t seed : {51u, 52u, 53u}) {
    std::mt19937_64 rng(seed);
    const auto poses = test_support::random_poses(40, 0.0, 10.0, rng);
    const auto fresh = sc::find_contact_pairs(boomerang, poses, 0.3);
    const auto reused = sc::find_contact_pairs(boomerang, poses, 0.3, std::nullopt, &cells);
    ASSERT_EQ(fresh.size(), reused.size()) << "seed " << seed;
    for (std::size_t k = 0; k < fresh.size(); ++k) EXPECT_EQ(fresh[k].points.distance, reused[k].points.distance);
    EXPECT_EQ(sc::minimum_pair_distance(boomerang, poses, std::nullopt, &cells).distance,
              sc::minimum_pair_distance(boomerang, poses).distance);
  }
}

// Surface contacts: one per flagged pair, node pairs from i to the same image, the d^P pair first.
TEST(ContactPairs, SurfaceContactsFollowFlaggedPairs) {
  const sc::Spherocylinder rod{2.0, 0.4};
  const sc::SurfaceNodes nodes = sc::surface_nodes(rod, 0.2);
  const sc::PeriodicBox box{Vec3::Constant(9.0)};
  std::mt19937_64 rng(61);
  const auto poses = test_support::random_poses(50, 0.0, 9.0, rng);
  const auto pairs = sc::find_contact_pairs(rod, poses, 0.3, box);
  const auto contacts = sc::find_surface_contacts(rod, poses, nodes, 0.3, box);
  ASSERT_EQ(contacts.size(), pairs.size());
  ASSERT_FALSE(pairs.empty());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    EXPECT_EQ(contacts[k].i, pairs[k].i);
    EXPECT_EQ(contacts[k].j, pairs[k].j);
    EXPECT_EQ(contacts[k].image_shift, pairs[k].image_shift);
    ASSERT_FALSE(contacts[k].distances.pairs.empty());
    EXPECT_EQ(contacts[k].distances.pairs[0].source, sc::PairSource::closest_points);
    EXPECT_EQ(contacts[k].distances.particle.distance, pairs[k].points.distance);
    for (const auto& p : contacts[k].distances.pairs) EXPECT_LE(p.distance, 0.3);
  }
}

TEST(ContactPairs, RejectsBadInput) {
  const sc::Spherocylinder rod{2.0, 0.4};
  const std::vector<Pose> poses = {Pose{}, {Vec3(3, 0, 0), sc::Quat::Identity()}};
  expect_rejects([&] { sc::find_contact_pairs(rod, poses, -0.1); }, "d_try");
  expect_rejects([&] { sc::find_contact_pairs(rod, poses, std::nan("")); }, "d_try");
  const std::vector<sc::Spherocylinder> three(3, rod);
  expect_rejects([&] { sc::find_contact_pairs(std::span<const sc::Spherocylinder>(three), poses, 0.1); }, "shapes");
  std::vector<Pose> bad = poses;
  bad[1].q.coeffs() *= 1.1;
  expect_rejects([&] { sc::find_contact_pairs(rod, bad, 0.1); }, "poses[1].q");
  expect_rejects([&] { sc::minimum_pair_distance(rod, bad); }, "poses[1].q");
  expect_rejects([&] { sc::find_contact_pairs(sc::Spherocylinder{2.0, -1.0}, poses, 0.1); }, "Spherocylinder.radius");
  expect_rejects([&] { sc::find_contact_pairs(rod, poses, 0.1, sc::PeriodicBox{Vec3::Constant(4.0)}); },
                 "PeriodicBox.lengths");
  const sc::SurfaceNodes nodes = sc::surface_nodes(rod, 0.3);
  const std::vector<sc::SurfaceNodes> three_sets(3, nodes);
  expect_rejects(
      [&] {
        sc::find_surface_contacts(std::span<const sc::Spherocylinder>(&rod, 1), poses,
                                  std::span<const sc::SurfaceNodes>(three_sets), 0.1);
      },
      "nodes");
}

}  // namespace contact_pairs_tests
